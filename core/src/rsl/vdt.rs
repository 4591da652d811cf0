//! Visibility distance tables (rotatable-square-lights paper, section 4.3, Figure 7, eq. 9).
//!
//! A **visibility distance table** (VDT) of a binary visibility map `v` over the hemisphere's
//! parametrisation square stores the signed distance `D(p) = sign(p)·d(p)` from each texel
//! centre `p` to the visibility boundary: positive where `v(p) = 1` (visible), negative where
//! `v(p) = 0` (occluded). The visible fraction of an axis-aligned square `R` (centre `p`,
//! half-diagonal `r`) then takes **one** interpolated lookup instead of the four of a
//! summed-area table.
//!
//! ## Grid and boundary (the definitions every function here uses)
//!
//! Texel `(i, j)` of a `w × h` map covers `[i, i+1]×[j, j+1]` in texel units (`i` along
//! `u`, `j` along `v`, row-major storage `j·w + i`), as in [`crate::rsl::sat`]. The map is the
//! piecewise-constant function of its texels, and its **boundary** `B` is the union of the
//! texel edges that separate a visible texel from an occluded one (the border of the grid is
//! not a boundary: nothing is known beyond it). `D` is sampled at texel centres:
//!
//! ```text
//! D(i + ½, j + ½) = ±min_{q ∈ B} |(i + ½, j + ½) − q|        (+ visible, − occluded)
//! ```
//!
//! the exact Euclidean distance from the centre to the boundary curve of the piecewise-
//! constant map — the distance that makes eq. 9 integrate *that* map: a texel next to a
//! texel of the other class has `|D| = ½`, a straight axis-aligned boundary gives `D` equal
//! to the signed distance to that line at every centre, so the interpolated `D` is exact
//! there and both queries below return the exact coverage of every square cut by such a
//! boundary. (Centre-to-centre distances, the definition of most EDT libraries, are ½ too
//! large for axis-aligned boundaries and would bias eq. 9 towards the texel's own class.)
//! A map without any boundary (all visible or all occluded) has `D = ±`[`NO_BOUNDARY`].
//!
//! **Exactness.** [`signed_distance_into`] finds, for every texel, the exact squared distance
//! (`k/4` for an integer `k`) and returns `(√k/2)` as the correctly rounded `f64` root
//! rounded to `f32` (the harness checks it for bitwise equality against a brute-force
//! minimum over every boundary edge, computed in `f64` the same way). The nearest point
//! of `B` to a texel centre is a lattice corner on `B` or the midpoint of a boundary edge in
//! the texel's own row or column; the distance transform of Felzenszwalb and Huttenlocher
//! (2012, the paper's reference \[4\]) runs over the corners in doubled integer coordinates
//! (a nearest-site sweep along `v`, then the lower envelope of parabolas along `u`), and two
//! 1-D sweeps give the row and column runs. All squared distances are integers (exact in
//! `f64`); the time is linear in the number of texels. (The rounding of an envelope
//! intersection cannot reorder it across a query point: an intersection that is not exactly
//! at a query point is at least `1/(4w)` away from one, far beyond `f64` rounding.)
//!
//! ## Queries
//!
//! `D(p)` at any point is the **bilinear** interpolation of the samples at the four nearest
//! texel centres, `lerp(a, b, t) = (1 − t)·a + t·b` (exact at the centres), clamped to the
//! edge outside the band of centres. Two estimates of the visible fraction of the square:
//!
//! - [`VdtView::eq9`], the paper's eq. 9: `clamp(((√2/2)·r + D)/(√2·r), 0, 1)`
//!   `= clamp(½ + D/(√2·r), 0, 1)`. The extracted text is garbled; the geometry it
//!   describes reads one way only: a square of half-diagonal `r` has half-side `h = r/√2`
//!   and side `√2·r`, and a straight boundary parallel to a side at signed distance `D`
//!   from the centre leaves exactly `(h + D)/(2h) = ½ + D/(√2·r)` of it visible, saturating
//!   at `|D| = h`, where the boundary leaves the square. Eq. 9 is therefore exact for every
//!   square cut by an axis-aligned straight edge (tested), and for other boundaries it is
//!   the axis-aligned ramp: a diagonal edge needs a quadratic (off by up to ≈ 0.06 at
//!   `|D| ≈ h/2`, measured in the harness `vdt` tests and the report). (A ramp of width
//!   `2√2·r`, the other reading of the garbled text, saturates only at `|D| = √2·r`, beyond
//!   the square's reach: a square wholly on the occluded side would still be 5 % visible.)
//! - [`VdtView::gradient`], the straight-edge variant: a straight edge is estimated from the
//!   table around `p` — a least-squares plane through a 4 × 4 stencil of samples whose zero
//!   level has been corrected for the staircase of the binary map (below) — and the visible
//!   fraction is the **exact** area of the square on the visible side `n·(x − p) ≥ −d` of
//!   that line, `d` the plane's value at `p` and `n` its gradient
//!   ([`crate::grid::square_halfplane_fraction`]). Exact for every square cut by one straight
//!   edge along texel boundaries (any axis-aligned edge) and for maps without a boundary; on
//!   oblique straight edges its mean error is below 0.45 times that of eq. 9 fed the
//!   *exact* distance to the true line (harness test
//!   `gradient_variant_against_exact_distance_eq9_on_oblique_edges`; the report prints the
//!   ratio). The bilinear `D` with its in-cell slope, the previous estimate of the line, lost
//!   to eq. 9 there: the staircase's distance is biased toward the texels, which the
//!   zero-level correction removes. For curved boundaries its error is the curvature within
//!   the square.
//!
//! ## The straight-edge variant: stencil, zero level, plane
//!
//! **Stencil.** Per axis, four texel centres around the cell `i0` of [`axis`]: offsets
//! `−1, 0, +1, +2` (a 4 × 4 block) for `r <` [`FIT_WIDE_R`], and `−3, −1, +2, +4` (16 centres
//! over an 8 × 8 block) from there on, each index clamped to the table; the sample positions
//! are the clamped centres, so a clamped stencil is a smaller (possibly repeated) one, never
//! a wrong one. `(u, v)` is first clamped to the table `[0, w] × [0, h]`.
//!
//! **Zero level.** `D` is the distance to the *staircase*, not to the edge the map
//! rasterises. For a straight edge with unit normal of components `p = min(|nx|, |ny|)`,
//! `m = max(|nx|, |ny|)` and signed distance `s` of a centre, the centre is visible iff
//! `s ≥ 0`, and the texel at integer offset `(i, j)` from it is of the other class iff
//! `|i|·p + |j|·m > |s|` (orienting the axes), so
//! `|D| = min{ boxdist(i, j) : |i|·p + |j|·m > |s| }`, `boxdist` the distance from the
//! centre to that texel: a step function of `|s|`.
//! Its first two steps invert in closed form, with `s` uniform over the lattice offsets of
//! the edge: `|D| = ½ ⇔ |s| ∈ [0, m)` (a 4-neighbour of the other class), mean `m/2`;
//! `|D| = √2/2 ⇔ |s| ∈ [m, p + m)` (only a diagonal neighbour), mean `m + p/2`. Farther out
//! the staircase's outer envelope lies `(p + m)/2` beyond the edge, less the gap between the
//! edge and the nearest row of lattice corners: averaging `|s| − |D|` over `|s| ∈ [p + m, 8]`
//! in that exact lattice model gives a curve `c(θ)` that is 0 for axis-aligned normals
//! (the boundary *is* the staircase) and lower at 45° than near 33° (a rational slope whose
//! corner rows are `1/√2` apart); [`FIT_KAPPA`]`·p·(1 − p)` is its least-squares fit. The
//! harness test `staircase_steps_of_straight_edges` checks the two closed-form steps sample
//! by sample on rasterised edges and the fit against the measured mean offset in 5° bands
//! (within 0.03). Each sample becomes `D + sign(D)·c(|D|)` with
//! `c = m/2 − ½` for `|D| < 0.6`, `m + p/2 − √2/2` for `|D| < 1.1` and `κ·p·(1 − p)` beyond
//! (the possible values of `|D|` are ½, √2/2 and then ≥ 1.5), `p` and `m` from the gradient
//! of the plane through the raw samples.
//!
//! **Plane.** The stencil is a tensor grid, so the unweighted least-squares plane separates
//! per axis: with the sample positions `X_a` relative to `u`, their mean `X̄` and deviations
//! `δ_a`, and the column means `C_a` of the samples (row means `R_b` along `v`) and their
//! mean `M`, the slope is `Σ δ_a·(C_a − M) / Σ δ_a²` (0 when all positions coincide) and the
//! plane at the query point is `M − gx·X̄ − gy·Ȳ`. Linear samples are reproduced exactly
//! (up to rounding), whatever the clamping: with an axis-aligned edge on texel boundaries `D`
//! is linear in one coordinate and constant along the other, the other slope is exactly 0
//! (the deviations `R_b − M` are exactly 0), so `p = 0`, `m = 1`, every correction is
//! exactly 0 and the fraction is exact. A map without boundary has constant samples: zero
//! slopes, `D = ±`[`NO_BOUNDARY`] and saturation, as for the other queries. Cost: 16 reads,
//! two plane fits (≈ 150 flops), one square root, six divisions, selects only (no loop
//! depends on the data).
//!
//! Queries are in texel units: centre `(u, v)`, half-diagonal `r` (half-side `r/√2`).
//!
//! **Bad input** (never panics). Constructors validate sizes, lengths and values and return
//! [`Error`]. Queries saturate: `r` is clamped to `[`[`R_MIN`]`, `[`R_MAX`]`]` (so `r ≤ 0`
//! queries the point `p`: 1 visible, 0 occluded, ½ on the boundary), infinite coordinates
//! clamp to the edge of the table, and NaN in `u`, `v` or `r` gives NaN.

use crate::Error;
use crate::grid::square_halfplane_fraction;
use crate::grid::{check_len, check_side, checked_product};
use crate::math;
use core::f32::consts::{FRAC_1_SQRT_2, SQRT_2};

/// Largest width or height of a table: every texel coordinate is an exact `f32`, and every
/// doubled squared distance an exact `f64` integer.
pub const MAX_SIDE: usize = 1 << 24;

/// `|D|` of a map without a boundary (every texel of one class): `2¹⁰⁰`, larger than any
/// distance in a table of at most [`MAX_SIDE`]² texels and than `√2·`[`R_MAX`]`·2²⁰`, so both
/// queries saturate to 1 (all visible) or 0 (all occluded) for every `r`, yet finite
/// everywhere (WGSL promises nothing for infinities) and bilinear interpolation of it cannot
/// overflow.
pub const NO_BOUNDARY: f32 = 1.267_650_6e30;

/// Smallest half-diagonal of a query (texel units); smaller ones (and `r ≤ 0`) are clamped
/// up to it, which queries the point: 1, 0, or ½ exactly on the boundary.
pub const R_MIN: f32 = 1.0e-12;
/// Largest half-diagonal of a query (texel units), `2⁸⁰`; larger ones are clamped to it.
pub const R_MAX: f32 = 1.208_925_8e24;

/// Half-diagonal (texel units) from which [`VdtView::gradient`] reads its wide stencil (centre
/// offsets `−3, −1, +2, +4` per axis instead of `−1, 0, +1, +2`): the half-side `r/√2` then
/// reaches about as far as the outer samples.
pub const FIT_WIDE_R: f32 = 4.5;

/// `κ` of the far zero-level correction `κ·p·(1 − p)` of [`VdtView::gradient`] (module docs): the
/// least-squares fit of the staircase's mean envelope offset over the edge orientations.
pub const FIT_KAPPA: f32 = 1.6;

/// Length of the `f64` scratch buffer [`signed_distance_into`] needs for a `w × h` map:
/// `(w + 1)·(h + 5)`.
pub const fn scratch_len(w: usize, h: usize) -> usize {
    (w + 1) * (h + 5)
}

/// `w·h` after checking both sides (`1 ≤ side ≤ MAX_SIDE`, and the product in `usize`).
fn texel_count(w: usize, h: usize) -> Result<usize, Error> {
    check_side("VDT width", w, MAX_SIDE)?;
    check_side("VDT height", h, MAX_SIDE)?;
    checked_product("VDT texel count", w, h)
}

/// The exact signed distance transform of a `w × h` binary map (`visible[j·w + i]`), written
/// to `out` (same length) as defined in the module docs: `+d` at visible texels, `−d` at
/// occluded ones, `±`[`NO_BOUNDARY`] when the map has a single class. Linear time; no
/// allocation (`scratch` holds at least [`scratch_len`]`(w, h)` values; its contents on
/// return are unspecified).
///
/// Errors: `w` or `h` zero or above [`MAX_SIDE`], `w·h` overflowing, `visible` or `out` of
/// the wrong length, `scratch` too short.
pub fn signed_distance_into(
    w: usize,
    h: usize,
    visible: &[bool],
    out: &mut [f32],
    scratch: &mut [f64],
) -> Result<(), Error> {
    let n = texel_count(w, h)?;
    check_len("visibility map length", visible.len(), n)?;
    check_len("VDT output length", out.len(), n)?;
    let need = scratch_len(w, h);
    if scratch.len() < need {
        return Err(Error::OutOfRange {
            what: "VDT scratch length",
            value: scratch.len() as f32,
            min: need as f32,
            max: f32::MAX,
        });
    }
    // Doubled coordinates: lattice point (x, y) is (2x, 2y), texel centre (i, j) is
    // (2i + 1, 2j + 1); every squared distance is an integer. The nearest point of B to a
    // centre is a lattice point of B (a corner of the boundary), or the midpoint of a
    // boundary edge in the centre's own column (a horizontal edge: the "column run") or own
    // row (a vertical edge: the "row run"); a boundary-edge midpoint in another row or
    // column is never nearest, one of its endpoints being closer.
    let cols = w + 1;
    let (g, rest) = scratch.split_at_mut(cols * h);
    let (last, rest) = rest.split_at_mut(cols);
    let (last_h, rest) = rest.split_at_mut(cols);
    let (env_v, rest) = rest.split_at_mut(cols);
    let (env_z, rest) = rest.split_at_mut(cols + 1);
    let row_run = &mut rest[..w];
    let row = |j: usize| &visible[j * w..(j + 1) * w];
    // Lattice row y of B: `site[x]` for x = 0..=w (the up to four texels around (x, y) are
    // not all of one class), written as the doubled coordinate 2y into `last[x]`.
    let mark_sites = |y: usize, last: &mut [f64]| {
        let yy = (2 * y) as f64;
        match (
            y.checked_sub(1).filter(|_| y <= h).map(row),
            (y < h).then(|| row(y)),
        ) {
            (Some(a), Some(b)) => {
                // x = 0 and x = w: two texels; inside: four.
                if a[0] != b[0] {
                    last[0] = yy;
                }
                if a[w - 1] != b[w - 1] {
                    last[w] = yy;
                }
                for x in 1..w {
                    let (p, q, r, t) = (a[x - 1], a[x], b[x - 1], b[x]);
                    if (p != q) | (q != t) | (r != t) {
                        last[x] = yy;
                    }
                }
            }
            (Some(a), None) | (None, Some(a)) => {
                // The top or bottom border: two texels per interior point, one at the ends.
                for x in 1..w {
                    if a[x - 1] != a[x] {
                        last[x] = yy;
                    }
                }
            }
            (None, None) => {}
        }
    };
    let inf = f64::INFINITY;
    // Pass 1, along v. Upward sweep: nearest lattice site at or below each centre row
    // (into g) and nearest horizontal boundary edge at or below in the texel's column
    // (the column run, into `out` as a doubled distance, an exact small integer).
    last.fill(-inf);
    last_h.fill(-inf);
    for j in 0..h {
        mark_sites(j, last);
        if j > 0 {
            let (a, b) = (row(j - 1), row(j));
            for i in 0..w {
                if a[i] != b[i] {
                    last_h[i] = (2 * j) as f64;
                }
            }
        }
        let yc = (2 * j + 1) as f64;
        for (gv, &l) in g[j * cols..(j + 1) * cols].iter_mut().zip(last.iter()) {
            let d = yc - l;
            *gv = d * d;
        }
        for (o, &l) in out[j * w..(j + 1) * w].iter_mut().zip(last_h.iter()) {
            *o = (yc - l) as f32;
        }
    }
    // Downward sweep: the same from above, keeping the smaller.
    last.fill(inf);
    last_h.fill(inf);
    for j in (0..h).rev() {
        mark_sites(j + 1, last);
        if j + 1 < h {
            let (a, b) = (row(j), row(j + 1));
            for i in 0..w {
                if a[i] != b[i] {
                    last_h[i] = (2 * j + 2) as f64;
                }
            }
        }
        let yc = (2 * j + 1) as f64;
        for (gv, &l) in g[j * cols..(j + 1) * cols].iter_mut().zip(last.iter()) {
            let d = l - yc;
            let d2 = d * d;
            if d2 < *gv {
                *gv = d2;
            }
        }
        for (o, &l) in out[j * w..(j + 1) * w].iter_mut().zip(last_h.iter()) {
            let d = (l - yc) as f32;
            if d < *o {
                *o = d;
            }
        }
    }
    // Pass 2, along u, per centre row: the row run (two sweeps), then the lower envelope of
    // the parabolas (Q − X)² + g[x] over the lattice columns X = 2x, evaluated at the
    // centres Q = 2i + 1 (Felzenszwalb–Huttenlocher), and the minimum of the three.
    let mut any_boundary = false;
    for j in 0..h {
        let m = row(j);
        let mut l = -inf;
        for i in 0..w {
            if i > 0 && m[i - 1] != m[i] {
                l = (2 * i) as f64;
            }
            row_run[i] = (2 * i + 1) as f64 - l;
        }
        let mut r = inf;
        for i in (0..w).rev() {
            if i + 1 < w && m[i] != m[i + 1] {
                r = (2 * i + 2) as f64;
            }
            let d = r - (2 * i + 1) as f64;
            if d < row_run[i] {
                row_run[i] = d;
            }
        }
        let gr = &g[j * cols..(j + 1) * cols];
        let mut k = 0usize;
        let mut any = false;
        for (x, &gx) in gr.iter().enumerate() {
            if gx == inf {
                continue;
            }
            let q = (2 * x) as f64;
            if !any {
                env_v[0] = q;
                env_z[0] = -inf;
                env_z[1] = inf;
                any = true;
                continue;
            }
            loop {
                let p = env_v[k];
                let gp = gr[(p as usize) / 2];
                // Intersection of the parabolas of p and q (q > p). Exact integer inputs;
                // the rounding of s cannot move it across a query point (module docs).
                let s = ((gx + q * q) - (gp + p * p)) / (2.0 * (q - p));
                if s <= env_z[k] {
                    // k ≥ 1 here: env_z[0] = −∞ < s.
                    k -= 1;
                } else {
                    k += 1;
                    env_v[k] = q;
                    env_z[k] = s;
                    env_z[k + 1] = inf;
                    break;
                }
            }
        }
        any_boundary |= any;
        let out_row = &mut out[j * w..(j + 1) * w];
        let mut k = 0usize;
        for i in 0..w {
            let qq = (2 * i + 1) as f64;
            let mut d2 = inf;
            if any {
                while env_z[k + 1] < qq {
                    k += 1;
                }
                let p = env_v[k];
                d2 = (qq - p) * (qq - p) + gr[(p as usize) / 2];
            }
            let c = out_row[i] as f64;
            let rr = row_run[i];
            d2 = d2.min(c * c).min(rr * rr);
            out_row[i] = if d2 == inf {
                0.0
            } else {
                // √(d2)/2, d2 ≥ 1: the nearest boundary point is at least ½ away.
                (math::sqrt64(d2) * 0.5) as f32
            };
            if !m[i] {
                out_row[i] = -out_row[i];
            }
        }
    }
    if !any_boundary {
        // No lattice site anywhere: the map has a single class (every boundary edge has
        // two lattice endpoints on B).
        let d = if visible[0] {
            NO_BOUNDARY
        } else {
            -NO_BOUNDARY
        };
        out.fill(d);
    }
    Ok(())
}

/// `(1 − t)·a + t·b`: exact at `t = 0` and `t = 1`.
#[inline(always)]
fn lerp(a: f32, b: f32, t: f32) -> f32 {
    (1.0 - t) * a + t * b
}

/// The four samples and fractions of a bilinear lookup.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell {
    /// `D` at the centres `(i0, j0)`, `(i1, j0)`, `(i0, j1)`, `(i1, j1)`.
    pub d: [f32; 4],
    /// Fractions along `u` and `v`, in `[0, 1]` (NaN for a NaN coordinate).
    pub fx: f32,
    /// See `fx`.
    pub fy: f32,
}

/// `D` and its gradient at a point: the bilinear interpolant's ([`VdtView::sample`]) or
/// the straight-edge variant's fitted line ([`VdtView::line`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Interpolated signed distance (texel units).
    pub d: f32,
    /// `∂D/∂u` (texel units).
    pub gx: f32,
    /// `∂D/∂v` (texel units).
    pub gy: f32,
}

/// The 16 samples of a [`VdtView::gradient`] stencil and their positions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stencil {
    /// `D` at column `a` and row `b` of the stencil: `d[b][a]`.
    pub d: [[f32; 4]; 4],
    /// Positions of the four columns minus the query's `u` (texel units).
    pub x: [f32; 4],
    /// Positions of the four rows minus the query's `v`.
    pub y: [f32; 4],
}

/// The index `i0` (an exact integer in `f32`, clamped to `[0, len − 2]`) of the first of
/// the two centres around `x` and the fraction towards the next one (clamped to `[0, 1]`;
/// 0 when `len = 1`), for one axis of `len` centres (texel units, centres at `k + ½`).
#[inline(always)]
pub fn axis(x: f32, len: usize) -> (f32, f32) {
    let c = x - 0.5;
    let hi_index = if len >= 2 { (len - 2) as f32 } else { 0.0 };
    let hi_frac = if len >= 2 { 1.0 } else { 0.0 };
    let i0 = math::floorf(c).clamp(0.0, hi_index);
    let f = (c - i0).clamp(0.0, hi_frac);
    (i0, f)
}

/// One axis of a [`VdtView::gradient`] stencil of `len` centres around `x`: the four centre
/// indices (exact integers in `f32`, clamped to `[0, len − 1]`) at offsets `−1, 0, +1, +2`
/// from the cell index `i0` of [`axis`] (`−3, −1, +2, +4` when `wide`), and their centres'
/// positions relative to `x` clamped to `[0, len]` (NaN stays NaN and reads index 0).
#[inline(always)]
pub fn stencil_axis(x: f32, len: usize, wide: bool) -> ([f32; 4], [f32; 4]) {
    let xc = x.clamp(0.0, len as f32);
    let (i0, _) = axis(xc, len);
    let (outer, inner) = if wide { (3.0, 1.0) } else { (1.0, 0.0) };
    let last = (len - 1) as f32;
    let idx = [
        (i0 - outer).clamp(0.0, last),
        (i0 - inner).clamp(0.0, last),
        (i0 + 1.0 + inner).clamp(0.0, last),
        (i0 + 1.0 + outer).clamp(0.0, last),
    ];
    (idx, idx.map(|k| k + 0.5 - xc))
}

/// A borrowed visibility distance table: `w × h` samples of `D`, row-major. The lookup
/// side (no allocation), e.g. over a table loaded from bytes or a GPU readback.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VdtView<'a> {
    w: usize,
    h: usize,
    d: &'a [f32],
}

impl<'a> VdtView<'a> {
    /// A view of `d` (`w·h` values, row-major). Every value must be finite with
    /// `|D| ≤ `[`NO_BOUNDARY`] (so interpolation and gradients cannot overflow).
    pub fn new(w: usize, h: usize, d: &'a [f32]) -> Result<Self, Error> {
        check_len("VDT length", d.len(), texel_count(w, h)?)?;
        for &x in d {
            if !x.is_finite() {
                return Err(Error::NonFinite { what: "VDT sample" });
            }
            if x.abs() > NO_BOUNDARY {
                return Err(Error::OutOfRange {
                    what: "VDT sample",
                    value: x,
                    min: -NO_BOUNDARY,
                    max: NO_BOUNDARY,
                });
            }
        }
        Ok(VdtView { w, h, d })
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.w
    }
    /// Height in texels.
    pub fn height(&self) -> usize {
        self.h
    }
    /// The samples, row-major.
    pub fn samples(&self) -> &'a [f32] {
        self.d
    }

    /// The four samples around `(u, v)` and the bilinear fractions (clamped to the edge).
    #[inline(always)]
    pub fn cell(&self, u: f32, v: f32) -> Cell {
        let (i0, fx) = axis(u, self.w);
        let (j0, fy) = axis(v, self.h);
        // `as usize` saturates and maps NaN to 0: always in range.
        let (i0, j0) = (i0 as usize, j0 as usize);
        let i1 = (i0 + 1).min(self.w - 1);
        let j1 = (j0 + 1).min(self.h - 1);
        let at = |i: usize, j: usize| self.d.get(j * self.w + i).copied().unwrap_or(0.0);
        Cell {
            d: [at(i0, j0), at(i1, j0), at(i0, j1), at(i1, j1)],
            fx,
            fy,
        }
    }

    /// `D` (bilinear) and its gradient at `(u, v)` (texel units).
    #[inline]
    pub fn sample(&self, u: f32, v: f32) -> Sample {
        sample_cell(self.cell(u, v))
    }

    /// `D` at `(u, v)`, bilinear.
    #[inline]
    pub fn distance(&self, u: f32, v: f32) -> f32 {
        self.sample(u, v).d
    }

    /// The visible fraction of the square with centre `(u, v)` and half-diagonal `r` by the
    /// paper's eq. 9: `clamp(½ + D/(√2·r), 0, 1)` (module docs).
    #[inline]
    pub fn eq9(&self, u: f32, v: f32, r: f32) -> f32 {
        eq9_from(self.sample(u, v).d, r)
    }

    /// The visible fraction of the same square by the straight-edge variant (module docs):
    /// the fraction of the square on the visible side of the fitted line [`Self::line`].
    #[inline]
    pub fn gradient(&self, u: f32, v: f32, r: f32) -> f32 {
        gradient_from(self.line(u, v, r), r)
    }

    /// Both estimates, `(eq9, gradient)`.
    #[inline]
    pub fn query(&self, u: f32, v: f32, r: f32) -> (f32, f32) {
        (self.eq9(u, v, r), self.gradient(u, v, r))
    }

    /// The 16 samples of the straight-edge stencil around `(u, v)` ([`stencil_axis`] per axis).
    #[inline(always)]
    pub fn stencil(&self, u: f32, v: f32, wide: bool) -> Stencil {
        let (ix, x) = stencil_axis(u, self.w, wide);
        let (jy, y) = stencil_axis(v, self.h, wide);
        // `as usize` saturates and maps NaN to 0: always in range.
        let at = |i: f32, j: f32| {
            let (i, j) = (i as usize, j as usize);
            self.d.get(j * self.w + i).copied().unwrap_or(0.0)
        };
        Stencil {
            d: core::array::from_fn(|b| core::array::from_fn(|a| at(ix[a], jy[b]))),
            x,
            y,
        }
    }

    /// The straight edge the straight-edge variant assumes at `(u, v)` for a square of
    /// half-diagonal `r` (which picks the stencil): the zero-level-corrected least-squares
    /// plane's value (the estimated signed distance from `(u, v)` to the edge) and gradient
    /// (module docs). NaN `r` reads the narrow stencil (the fraction is NaN anyway).
    #[inline]
    pub fn line(&self, u: f32, v: f32, r: f32) -> Sample {
        fit_stencil(&self.stencil(u, v, r >= FIT_WIDE_R))
    }
}

/// Bilinear value and in-cell gradient of a [`Cell`].
#[inline(always)]
pub fn sample_cell(c: Cell) -> Sample {
    let [d00, d10, d01, d11] = c.d;
    let d0 = lerp(d00, d10, c.fx);
    let d1 = lerp(d01, d11, c.fx);
    Sample {
        d: lerp(d0, d1, c.fy),
        gx: lerp(d10 - d00, d11 - d01, c.fy),
        gy: lerp(d01 - d00, d11 - d10, c.fx),
    }
}

/// `r` clamped to `[R_MIN, R_MAX]`, NaN kept.
#[inline(always)]
fn clamp_r(r: f32) -> f32 {
    r.clamp(R_MIN, R_MAX)
}

/// Eq. 9 for a sampled `D`: `clamp((½·√2·r + D)/(√2·r), 0, 1) = clamp(½ + D/(√2·r), 0, 1)`
/// (module docs: the visible fraction of a square of side `√2·r` cut by a straight edge
/// parallel to a side at distance `D`), `r` clamped to `[R_MIN, R_MAX]`.
#[inline(always)]
pub fn eq9_from(d: f32, r: f32) -> f32 {
    let k = SQRT_2 * clamp_r(r);
    ((0.5 * k + d) / k).clamp(0.0, 1.0)
}

/// The straight-edge fraction for a sampled `D` and gradient: the square of half-side
/// `r/√2` cut by the line at signed distance `D` with normal along the gradient.
#[inline(always)]
pub fn gradient_from(s: Sample, r: f32) -> f32 {
    // D in units of the half-side r/√2.
    square_halfplane_fraction(s.d * SQRT_2 / clamp_r(r), s.gx, s.gy)
}

/// `(a₀ + a₁) + (a₂ + a₃)`.
#[inline(always)]
fn sum4(a: [f32; 4]) -> f32 {
    (a[0] + a[1]) + (a[2] + a[3])
}

/// The sample positions of one stencil axis: mean, deviations from it, sum of squares.
#[derive(Clone, Copy, Debug)]
struct FitAxis {
    mean: f32,
    dev: [f32; 4],
    ss: f32,
}

#[inline(always)]
fn fit_axis(p: [f32; 4]) -> FitAxis {
    let mean = sum4(p) * 0.25;
    let dev = p.map(|x| x - mean);
    FitAxis {
        mean,
        dev,
        ss: sum4(dev.map(|e| e * e)),
    }
}

/// The least-squares plane through `d` over the tensor grid `ax × ay`: its value at the
/// query point (relative position 0) and its slopes (0 along an axis whose positions all
/// coincide). Slopes are built from deviations from the mean, so samples constant along an
/// axis give exactly 0 there.
#[inline(always)]
fn plane(d: &[[f32; 4]; 4], ax: &FitAxis, ay: &FitAxis) -> Sample {
    let col: [f32; 4] = core::array::from_fn(|a| sum4([d[0][a], d[1][a], d[2][a], d[3][a]]) * 0.25);
    let row: [f32; 4] = core::array::from_fn(|b| sum4(d[b]) * 0.25);
    let mean = sum4(col) * 0.25;
    let sx = sum4(core::array::from_fn(|a| ax.dev[a] * (col[a] - mean)));
    let sy = sum4(core::array::from_fn(|b| ay.dev[b] * (row[b] - mean)));
    let gx = if ax.ss > 0.0 { sx / ax.ss } else { 0.0 };
    let gy = if ay.ss > 0.0 { sy / ay.ss } else { 0.0 };
    Sample {
        d: mean - gx * ax.mean - gy * ay.mean,
        gx,
        gy,
    }
}

/// The samples with their zero level corrected for the staircase (module docs):
/// `D + sign(D)·c`, `c = m/2 − ½` at `|D| = ½`, `m + p/2 − √2/2` at `|D| = √2/2` and
/// [`FIT_KAPPA`]`·p·(1 − p)` beyond, `p ≤ m` the components of the unit normal along
/// `(gx, gy)` (`p = 0`, `m = 1` for a zero gradient). All corrections vanish for an
/// axis-aligned normal.
#[inline(always)]
pub fn zero_level_corrected(d: [[f32; 4]; 4], gx: f32, gy: f32) -> [[f32; 4]; 4] {
    let (ax, ay) = (gx.abs(), gy.abs());
    let hi = ax.max(ay);
    let q = if hi > 0.0 { ax.min(ay) / hi } else { 0.0 };
    let m = 1.0 / math::sqrtf(1.0 + q * q);
    let p = q * m;
    let c_half = 0.5 * m - 0.5;
    let c_diag = m + 0.5 * p - FRAC_1_SQRT_2;
    let c_far = FIT_KAPPA * p * (1.0 - p);
    d.map(|row| {
        row.map(|x| {
            let a = x.abs();
            let c = if a < 0.6 {
                c_half
            } else if a < 1.1 {
                c_diag
            } else {
                c_far
            };
            if x < 0.0 { x - c } else { x + c }
        })
    })
}

/// [`VdtView::line`] of a stencil: the plane through the raw samples gives the
/// normal, the plane through the corrected samples the distance and the final normal.
#[inline(always)]
pub fn fit_stencil(s: &Stencil) -> Sample {
    let (ax, ay) = (fit_axis(s.x), fit_axis(s.y));
    let raw = plane(&s.d, &ax, &ay);
    plane(&zero_level_corrected(s.d, raw.gx, raw.gy), &ax, &ay)
}

#[cfg(feature = "alloc")]
pub use owned::Vdt;

#[cfg(feature = "alloc")]
mod owned {
    use super::*;
    use alloc::vec;
    use alloc::vec::Vec;

    /// An owned visibility distance table.
    #[derive(Clone, Debug, PartialEq)]
    pub struct Vdt {
        w: usize,
        h: usize,
        d: Vec<f32>,
    }

    impl Vdt {
        /// The VDT of a `w × h` binary map (`visible[j·w + i]`), exact
        /// ([`signed_distance_into`]).
        pub fn build(w: usize, h: usize, visible: &[bool]) -> Result<Vdt, Error> {
            // Checked before allocating: `signed_distance_into` checks again.
            let n = texel_count(w, h)?;
            check_len("visibility map length", visible.len(), n)?;
            let mut d = vec![0.0f32; n];
            let mut scratch = vec![0.0f64; scratch_len(w, h)];
            signed_distance_into(w, h, visible, &mut d, &mut scratch)?;
            Ok(Vdt { w, h, d })
        }

        /// The VDT of a coverage map (visible fraction per texel, finite): a texel is
        /// visible when its coverage is at least ½ ([`crate::rsl::visibility::binary_into`]).
        pub fn from_coverage(w: usize, h: usize, coverage: &[f32]) -> Result<Vdt, Error> {
            if coverage.iter().any(|c| !c.is_finite()) {
                return Err(Error::NonFinite { what: "coverage" });
            }
            let mut mask = vec![false; coverage.len()];
            crate::rsl::visibility::binary_into(coverage, &mut mask);
            Self::build(w, h, &mask)
        }

        /// An owned table from samples (validated as in [`VdtView::new`]).
        pub fn from_samples(w: usize, h: usize, d: Vec<f32>) -> Result<Vdt, Error> {
            VdtView::new(w, h, &d)?;
            Ok(Vdt { w, h, d })
        }

        /// The lookup view.
        pub fn view(&self) -> VdtView<'_> {
            VdtView {
                w: self.w,
                h: self.h,
                d: &self.d,
            }
        }
        /// Width in texels.
        pub fn width(&self) -> usize {
            self.w
        }
        /// Height in texels.
        pub fn height(&self) -> usize {
            self.h
        }
        /// The samples, row-major.
        pub fn samples(&self) -> &[f32] {
            &self.d
        }
        /// The table in the layout of `wgsl::VDT_QUERY` (binding 3): `[w, h]` as `f32`,
        /// then the samples row-major.
        pub fn gpu_table(&self) -> Vec<f32> {
            let mut t = Vec::with_capacity(self.d.len() + 2);
            t.push(self.w as f32);
            t.push(self.h as f32);
            t.extend_from_slice(&self.d);
            t
        }
        /// [`VdtView::query`].
        pub fn query(&self, u: f32, v: f32, r: f32) -> (f32, f32) {
            self.view().query(u, v, r)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn build(w: usize, h: usize, m: &[bool]) -> [f32; 64] {
        let mut out = [0.0f32; 64];
        let mut scratch = [0.0f64; 512];
        signed_distance_into(w, h, m, &mut out[..w * h], &mut scratch).unwrap();
        out
    }

    #[test]
    fn vertical_edge_is_linear_and_queries_exact() {
        // 4 × 2, columns 0,1 occluded, 2,3 visible: edge at u = 2.
        let m = [false, false, true, true, false, false, true, true];
        let d = build(4, 2, &m);
        assert_eq!(&d[..4], &[-1.5, -0.5, 0.5, 1.5]);
        let v = VdtView::new(4, 2, &d[..8]).unwrap();
        // Square of half-side 1 at u = 2.5: visible fraction (2.5 + 1 − 2)/2 = 0.75.
        let r = SQRT_2;
        let (e9, g) = v.query(2.5, 1.0, r);
        assert!((g - 0.75).abs() < 1e-6, "{g}");
        // Eq. 9, ½ + D/(√2·r) = ½ + 0.5/2: exact for an edge parallel to a side too.
        assert!((e9 - 0.75).abs() < 1e-6, "{e9}");
    }

    #[test]
    fn uniform_maps_saturate() {
        let d = build(3, 2, &[true; 6]);
        assert!(d[..6].iter().all(|&x| x == NO_BOUNDARY));
        let v = VdtView::new(3, 2, &d[..6]).unwrap();
        for r in [0.0, 1e-30, 1.0, 1e20, f32::INFINITY] {
            assert_eq!(v.query(1.0, 1.0, r), (1.0, 1.0), "r = {r}");
        }
        let d = build(3, 2, &[false; 6]);
        let v = VdtView::new(3, 2, &d[..6]).unwrap();
        assert_eq!(v.query(-5.0, 1e30, 3.0), (0.0, 0.0));
    }

    #[test]
    fn bad_input() {
        let mut s = [0.0f64; 8];
        let mut o = [0.0f32; 2];
        assert!(signed_distance_into(0, 1, &[], &mut o[..0], &mut s).is_err());
        assert!(signed_distance_into(2, 1, &[true], &mut o, &mut s).is_err());
        assert!(signed_distance_into(2, 1, &[true, false], &mut o, &mut s[..1]).is_err());
        assert!(VdtView::new(1, 1, &[f32::NAN]).is_err());
        assert!(VdtView::new(1, 1, &[3e30]).is_err());
        let d = [0.5f32, -0.5];
        let v = VdtView::new(2, 1, &d).unwrap();
        assert!(v.eq9(f32::NAN, 0.5, 1.0).is_nan());
        assert!(v.gradient(1.0, 0.5, f32::NAN).is_nan());
        assert!(v.gradient(f32::NAN, 0.5, 1.0).is_nan());
        // Point queries: r ≤ 0.
        assert_eq!(v.query(0.5, 0.5, 0.0), (1.0, 1.0));
        assert_eq!(v.query(1.5, 0.5, -1.0), (0.0, 0.0));
        assert_eq!(v.query(1.0, 0.5, 0.0), (0.5, 0.5));
        // Infinite coordinates clamp to the edge.
        assert_eq!(v.query(f32::INFINITY, 0.5, 0.0), (0.0, 0.0));
        assert_eq!(v.query(f32::NEG_INFINITY, 0.5, 0.0), (1.0, 1.0));
    }

    #[test]
    fn gradient_is_exact_on_axis_aligned_edges() {
        // 16 × 4 with the edge at u = k, and its transpose (4 × 16, edge at v = k): D is
        // linear across the edge and constant along it, so the fit is exact with either
        // stencil, clamped or not.
        for k in [1usize, 5, 8, 15] {
            let m: [bool; 64] = core::array::from_fn(|t| t % 16 >= k);
            let mt: [bool; 64] = core::array::from_fn(|t| t / 4 >= k);
            let (d, dt) = (build(16, 4, &m), build(4, 16, &mt));
            let (v, vt) = (
                VdtView::new(16, 4, &d).unwrap(),
                VdtView::new(4, 16, &dt).unwrap(),
            );
            for a in 0..=64 {
                let u = 0.5 + a as f32 * (15.0 / 64.0);
                for r in [0.05f32, 0.3, 1.0, 2.0, 4.4, 4.6, 9.0, 20.0] {
                    for y in [0.5f32, 1.7, 3.5] {
                        let hs = r as f64 / core::f64::consts::SQRT_2;
                        let exact = ((u as f64 + hs - k as f64) / (2.0 * hs)).clamp(0.0, 1.0);
                        let tol = 2e-6 * (1.0 + 1.0 / hs);
                        let g = v.gradient(u, y, r) as f64;
                        let gt = vt.gradient(y, u, r) as f64;
                        assert!((g - exact).abs() < tol, "k {k} u {u} r {r}: {g} vs {exact}");
                        assert!(
                            (gt - exact).abs() < tol,
                            "k {k} v {u} r {r}: {gt} vs {exact}"
                        );
                    }
                }
            }
            // Exactly on the edge: ½ with both stencils.
            for r in [3.0, 9.0] {
                assert_eq!(v.gradient(k as f32, 2.0, r), 0.5);
                assert_eq!(vt.gradient(2.0, k as f32, r), 0.5);
            }
        }
    }

    #[test]
    fn gradient_saturates_and_handles_bad_input() {
        let d = build(3, 2, &[true; 6]);
        let v = VdtView::new(3, 2, &d[..6]).unwrap();
        for r in [0.0, 1e-30, 1.0, 4.5, 1e20, f32::INFINITY] {
            assert_eq!(v.gradient(1.0, 1.0, r), 1.0, "r = {r}");
        }
        let d = build(3, 2, &[false; 6]);
        let v = VdtView::new(3, 2, &d[..6]).unwrap();
        assert_eq!(v.gradient(-5.0, 1e30, 3.0), 0.0);
        let d = [0.5f32, -0.5];
        let v = VdtView::new(2, 1, &d).unwrap();
        assert!(v.gradient(f32::NAN, 0.5, 1.0).is_nan());
        assert!(v.gradient(1.0, 0.5, f32::NAN).is_nan());
        assert_eq!(v.gradient(0.5, 0.5, 0.0), 1.0);
        assert_eq!(v.gradient(1.5, 0.5, 0.0), 0.0);
        assert_eq!(v.gradient(1.0, 0.5, 0.0), 0.5);
        assert_eq!(v.gradient(f32::INFINITY, 0.5, 0.0), 0.0);
        assert_eq!(v.gradient(f32::NEG_INFINITY, 0.5, 0.0), 1.0);
        // 1 × 1: no slope at all.
        let v = VdtView::new(1, 1, &[NO_BOUNDARY]).unwrap();
        assert_eq!(v.gradient(0.3, 0.9, 7.0), 1.0);
    }
}
