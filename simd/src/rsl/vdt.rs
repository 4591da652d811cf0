//! Visibility distance table queries, 8 (or 16) lanes at a time (mirrors
//! `steradian_core::rsl::vdt`).
//!
//! [`query`] performs exactly the operations of `steradian_core::rsl::vdt::VdtView::query` lane
//! by lane, so every lane is **bit-identical** to the scalar query of that lane, for every
//! input (NaN-ness matches):
//!
//! - **Eq. 9** reads the four samples of the bilinear cell: the clamped cell index and
//!   fraction per axis (`floor` written as `−ceil(−x)`, which is exact),
//!   `lerp(a, b, t) = (1 − t)·a + t·b`, then `eq9_from`.
//! - **The straight-edge fraction** reads the 16 samples of the scalar `VdtView::stencil`:
//!   per axis the coordinate clamped to the table, the cell index of `axis`, the four centre
//!   indices at offsets `−1, 0, +1, +2` (`−3, −1, +2, +4` in the lanes where
//!   `r ≥ FIT_WIDE_R`; NaN `r` is narrow, as the scalar comparison is false) clamped to the
//!   table, and their positions relative to the clamped coordinate, all computed lane-wise;
//!   then `fit_stencil` (the least-squares plane through the raw samples, the zero-level
//!   correction driven by its gradient, the plane through the corrected samples) and
//!   `gradient_from` (`square_halfplane_fraction`).
//!
//! Bit-identity holds because every step is a correctly rounded IEEE operation (`+ − × ÷`,
//! `sqrt`, `abs`, comparisons), done in the scalar kernel's order: the same `sum4` pairing
//! `(a₀ + a₁) + (a₂ + a₃)`, the same `x − mean` deviations, no fused multiply–add (Rust
//! never contracts, and neither does `wide`). The scalar kernel's branches (`if ss > 0`,
//! `if hi > 0`, the `|D| < 0.6 / < 1.1` choice of the correction,
//! `if x < 0 { x − c } else { x + c }`, the pieces of the half-plane fraction) become selects
//! on the same comparisons, and `f32::clamp` (NaN kept) and `f32::max`/`min` (NaN ignored)
//! have lane-wise spellings with the same NaN rules. `wide` has no gather: each lane's
//! samples are read by scalar indexing from its lane-wise indices (one pass over the lanes,
//! 4 reads for eq. 9 and 16 for the stencil), converted with the scalar kernel's `as usize`
//! (saturating, NaN → 0), so the same texels are read.
//!
//! The straight-edge code is shared with the SIMD shading kernel ([`crate::rsl::shade`]),
//! whose lanes may each read a different table of the same size.

use steradian_core::grid::Q_MIN;
use steradian_core::rsl::vdt::{FIT_KAPPA, FIT_WIDE_R, R_MAX, R_MIN, VdtView};
use wide::f32x8;

use crate::lanes::{ColumnKernel, Lanes, SliceVec, clamp, drive, max_num, min_num};

const SQRT_2: f32 = core::f32::consts::SQRT_2;
const FRAC_1_SQRT_2: f32 = core::f32::consts::FRAC_1_SQRT_2;

/// Per axis: the clamped cell index (as an exact `f32`) and fraction (scalar `vdt::axis`).
#[inline(always)]
fn axis<W: Lanes>(x: W, len: usize) -> (W, W) {
    let c = x - W::splat(0.5);
    let hi_index = if len >= 2 { (len - 2) as f32 } else { 0.0 };
    let hi_frac = if len >= 2 { 1.0 } else { 0.0 };
    let fl = -(-c).ceil();
    let i0 = clamp(fl, W::splat(0.0), W::splat(hi_index));
    let f = clamp(c - i0, W::splat(0.0), W::splat(hi_frac));
    (i0, f)
}

#[inline(always)]
fn lerp<W: Lanes>(a: W, b: W, t: W) -> W {
    (W::splat(1.0) - t) * a + t * b
}

/// `r` clamped to `[R_MIN, R_MAX]`, NaN kept (scalar `vdt::clamp_r`).
#[inline(always)]
fn clamp_r<W: Lanes>(r: W) -> W {
    clamp(r, W::splat(R_MIN), W::splat(R_MAX))
}

/// Eq. 9 lane-wise, `steradian_core::rsl::vdt::eq9_from` operation for operation, for a
/// half-diagonal `rr` already clamped to `[R_MIN, R_MAX]` (the one copy the VDT query and
/// the SIMD shading kernel share).
#[inline(always)]
pub(crate) fn eq9_lanes<W: Lanes>(dd: W, rr: W) -> W {
    let k = W::splat(SQRT_2) * rr;
    clamp((W::splat(0.5) * k + dd) / k, W::splat(0.0), W::splat(1.0))
}

/// `steradian_core::grid::square_halfplane_fraction(t, nx, ny)` lane-wise: the normal
/// reduced to `q = min/max` of its absolute components, then the three pieces and the
/// scalar kernel's choice between them as selects.
#[inline(always)]
fn halfplane_lanes<W: Lanes>(t: W, nx: W, ny: W) -> W {
    let (zero, one) = (W::splat(0.0), W::splat(1.0));
    let (ax, ay) = (nx.abs(), ny.abs());
    let m = max_num(ax, ay);
    let q = m.gt(zero).select(min_num(ax, ay) / m, zero);
    let len = (one + q * q).sqrt();
    let hi = one + q;
    let tt = clamp(t * len, -hi, hi);
    let den = W::splat(8.0) * max_num(q, W::splat(Q_MIN));
    let lo_e = tt + hi;
    let lo_v = lo_e * lo_e / den;
    let hi_e = hi - tt;
    let hi_v = one - hi_e * hi_e / den;
    let mid = (tt + one) * W::splat(0.5);
    let r = tt.ge(one - q).select(hi_v, mid);
    tt.le(q - one).select(lo_v, r)
}

/// `(a₀ + a₁) + (a₂ + a₃)` (scalar `vdt::sum4`).
#[inline(always)]
fn sum4<W: Lanes>(a: [W; 4]) -> W {
    (a[0] + a[1]) + (a[2] + a[3])
}

/// One axis of the straight-edge stencil lane-wise (scalar `vdt::stencil_axis`): the four
/// centre indices (exact integers, or NaN) and their positions relative to the coordinate
/// clamped to `[0, len]`. `wide` is a mask: the lanes reading offsets `−3, −1, +2, +4`.
#[inline(always)]
fn stencil_axis<W: Lanes>(x: W, len: usize, wide: W) -> ([W; 4], [W; 4]) {
    let (zero, one) = (W::splat(0.0), W::splat(1.0));
    let xc = clamp(x, zero, W::splat(len as f32));
    let (i0, _) = axis(xc, len);
    // The scalar kernel's constants, chosen per lane.
    let outer = wide.select(W::splat(3.0), one);
    let inner = wide.select(one, zero);
    let last = W::splat((len - 1) as f32);
    let idx = [
        clamp(i0 - outer, zero, last),
        clamp(i0 - inner, zero, last),
        clamp(i0 + one + inner, zero, last),
        clamp(i0 + one + outer, zero, last),
    ];
    let half = W::splat(0.5);
    (idx, idx.map(|k| k + half - xc))
}

/// The 16 stencil samples `d[b][a]` (column `a`, row `b`): lane `k` reads `table(k)`
/// (row-major, `w` wide) at column `ix[a]` and row `jy[b]`, converted as the scalar
/// `VdtView::stencil` does (`as usize`: saturating, NaN → 0; the indices are clamped to
/// the table, so every read is in range). One pass over the lanes.
#[inline(always)]
fn gather_stencil<'t, W: Lanes>(
    table: impl Fn(usize) -> &'t [f32],
    w: usize,
    ix: &[W; 4],
    jy: &[W; 4],
) -> [[W; 4]; 4] {
    // g[4·b + a][lane]: each vector is then one contiguous load (so the lane loop writes
    // lane `k` of 16 arrays, which an iterator over `g` cannot express).
    let mut g = [[0.0f32; 16]; 16];
    // The indices of every lane, converted a vector at a time.
    let (mut cols, mut rows) = ([[0usize; 16]; 4], [[0usize; 16]; 4]);
    for ((c, x), (r, y)) in cols.iter_mut().zip(ix).zip(rows.iter_mut().zip(jy)) {
        x.to_indices(c);
        y.to_indices(r);
    }
    #[allow(clippy::needless_range_loop)]
    for k in 0..W::N {
        let d = table(k);
        for (b, r) in rows.iter().enumerate() {
            let row = r[k] * w;
            for (a, c) in cols.iter().enumerate() {
                g[4 * b + a][k] = d.get(row + c[k]).copied().unwrap_or(0.0);
            }
        }
    }
    core::array::from_fn(|b| core::array::from_fn(|a| W::load(&g[4 * b + a][..W::N])))
}

/// Sample positions of one stencil axis: mean, deviations from it, sum of squares (scalar
/// `vdt::FitAxis`).
struct FitAxis<W> {
    mean: W,
    dev: [W; 4],
    ss: W,
}

#[inline(always)]
fn fit_axis<W: Lanes>(p: [W; 4]) -> FitAxis<W> {
    let mean = sum4(p) * W::splat(0.25);
    let dev = p.map(|x| x - mean);
    FitAxis {
        mean,
        dev,
        ss: sum4(dev.map(|e| e * e)),
    }
}

/// The least-squares plane through `d` (scalar `vdt::plane`): `[value, gx, gy]`.
#[inline(always)]
fn plane<W: Lanes>(d: &[[W; 4]; 4], ax: &FitAxis<W>, ay: &FitAxis<W>) -> [W; 3] {
    let (zero, quarter) = (W::splat(0.0), W::splat(0.25));
    let col: [W; 4] =
        core::array::from_fn(|a| sum4([d[0][a], d[1][a], d[2][a], d[3][a]]) * quarter);
    let row: [W; 4] = core::array::from_fn(|b| sum4(d[b]) * quarter);
    let mean = sum4(col) * quarter;
    let sx = sum4(core::array::from_fn(|a| ax.dev[a] * (col[a] - mean)));
    let sy = sum4(core::array::from_fn(|b| ay.dev[b] * (row[b] - mean)));
    let gx = ax.ss.gt(zero).select(sx / ax.ss, zero);
    let gy = ay.ss.gt(zero).select(sy / ay.ss, zero);
    [mean - gx * ax.mean - gy * ay.mean, gx, gy]
}

/// The samples with their zero level corrected for the staircase (scalar
/// `vdt::zero_level_corrected`).
#[inline(always)]
fn zero_level_corrected<W: Lanes>(d: [[W; 4]; 4], gx: W, gy: W) -> [[W; 4]; 4] {
    let (zero, one, half) = (W::splat(0.0), W::splat(1.0), W::splat(0.5));
    let (ax, ay) = (gx.abs(), gy.abs());
    let hi = max_num(ax, ay);
    let q = hi.gt(zero).select(min_num(ax, ay) / hi, zero);
    let m = one / (one + q * q).sqrt();
    let p = q * m;
    let c_half = half * m - half;
    let c_diag = m + half * p - W::splat(FRAC_1_SQRT_2);
    let c_far = W::splat(FIT_KAPPA) * p * (one - p);
    let (near, mid) = (W::splat(0.6), W::splat(1.1));
    d.map(|row| {
        row.map(|x| {
            let a = x.abs();
            let c = a.lt(near).select(c_half, a.lt(mid).select(c_diag, c_far));
            x.lt(zero).select(x - c, x + c)
        })
    })
}

/// The straight-edge fraction of the squares `(u, v, r)` (texel units), lane-wise scalar
/// `VdtView::gradient` on a table of `w × h` samples: lane `k` reads `table(k)` (the VDT
/// query passes one table for all lanes, the shading kernel each lane's own), and is
/// bit-identical to `VdtView::gradient` of that table and lane.
#[inline(always)]
pub(crate) fn gradient_lanes<'t, W: Lanes>(
    table: impl Fn(usize) -> &'t [f32],
    w: usize,
    h: usize,
    [u, v, r]: [W; 3],
) -> W {
    // `r >= FIT_WIDE_R`: false for NaN (narrow), as in the scalar kernel.
    let wide = r.ge(W::splat(FIT_WIDE_R));
    let (ix, x) = stencil_axis(u, w, wide);
    let (jy, y) = stencil_axis(v, h, wide);
    let d = gather_stencil(table, w, &ix, &jy);
    // `fit_stencil`: the raw plane's gradient drives the correction of the second plane.
    let (ax, ay) = (fit_axis(x), fit_axis(y));
    let [_, rgx, rgy] = plane(&d, &ax, &ay);
    let [dd, gx, gy] = plane(&zero_level_corrected(d, rgx, rgy), &ax, &ay);
    // `gradient_from`: D in units of the half-side r/√2.
    halfplane_lanes(dd * W::splat(SQRT_2) / clamp_r(r), gx, gy)
}

/// The scalar `VdtView::query`, operation for operation: `[eq9, gradient]`.
#[inline(always)]
fn query_lanes<W: Lanes>(view: &VdtView<'_>, [u, v, r]: [W; 3]) -> [W; 2] {
    let (w, h) = (view.width(), view.height());
    let d = view.samples();
    // Eq. 9 of the bilinear D.
    let (i0, fx) = axis(u, w);
    let (j0, fy) = axis(v, h);
    // Gather: `as usize` saturates and maps NaN to 0, as in the scalar kernel (converted a
    // vector at a time).
    let (mut ia, mut ja) = ([0usize; 16], [0usize; 16]);
    i0.to_indices(&mut ia);
    j0.to_indices(&mut ja);
    // `i0 ≤ w − 2` when `w ≥ 2`, so the scalar `i1 = min(i0 + 1, w − 1)` is `i0 + 1`, and
    // `i0` itself when `w = 1`: constant steps to the other three samples.
    let di = usize::from(w >= 2);
    let dj = if h >= 2 { w } else { 0 };
    let mut base = [0usize; 16];
    for (k, b) in base.iter_mut().take(W::N).enumerate() {
        *b = ja[k] * w + ia[k];
    }
    let at = |k: usize, off: usize| -> f32 { d.get(base[k] + off).copied().unwrap_or(0.0) };
    let d00 = W::from_fn(|k| at(k, 0));
    let d10 = W::from_fn(|k| at(k, di));
    let d01 = W::from_fn(|k| at(k, dj));
    let d11 = W::from_fn(|k| at(k, dj + di));
    let d0 = lerp(d00, d10, fx);
    let d1 = lerp(d01, d11, fx);
    let e9 = eq9_lanes(lerp(d0, d1, fy), clamp_r(r));
    // The straight-edge fraction of the fitted line.
    let g = gradient_lanes(|_| d, w, h, [u, v, r]);
    [e9, g]
}

/// Both estimates of the visible fraction of the squares with centres `(u, v)` and
/// half-diagonals `r` (texel units): lane-wise `VdtView::query`, bit-identical.
/// Returns `(eq9, gradient)`.
#[inline]
pub fn query(view: &VdtView<'_>, u: f32x8, v: f32x8, r: f32x8) -> (f32x8, f32x8) {
    let [a, b] = query_lanes(view, [u, v, r]);
    (a, b)
}

struct QueryK<'a, 'b>(&'a VdtView<'b>);
impl ColumnKernel<3, 2> for QueryK<'_, '_> {
    const PADS: [f32; 3] = [0.5, 0.5, 1.0];
    #[inline(always)]
    fn apply<W: Lanes>(&self, v: [W; 3]) -> ([W; 2], W) {
        (query_lanes(self.0, v), W::splat(0.0))
    }
}

/// [`query`] over structure-of-arrays columns: `(eq9[i], gradient[i]) =
/// view.query(u[i], v[i], r[i])`. Any length (tail padded); runs on the build's widest
/// vector, same results.
///
/// # Panics
/// If the five columns do not all have the same length.
pub fn query_slices(
    view: &VdtView<'_>,
    u: &[f32],
    v: &[f32],
    r: &[f32],
    eq9: &mut [f32],
    gradient: &mut [f32],
) {
    drive::<SliceVec, _, 3, 2>(
        "vdt::query_slices",
        &QueryK(view),
        [u, v, r],
        [eq9, gradient],
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::tests::same;
    use steradian_core::rsl::vdt::{scratch_len, signed_distance_into};

    /// The exact table of a mask (the crate has no `alloc` feature of core).
    fn table(w: usize, h: usize, mask: &[bool]) -> Vec<f32> {
        let mut d = vec![0.0; w * h];
        let mut s = vec![0.0; scratch_len(w, h)];
        signed_distance_into(w, h, mask, &mut d, &mut s).unwrap();
        d
    }

    #[test]
    fn lanes_match_scalar_bit_for_bit() {
        let (w, h) = (23, 17);
        let mut next = crate::lanes::tests::uniform(12345u64);
        let mask: Vec<bool> = (0..w * h).map(|_| next() < 0.55).collect();
        let d = table(w, h, &mask);
        let view = VdtView::new(w, h, &d).unwrap();
        let specials = [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            0.0,
            -0.0,
            1e-30,
            -3.0,
            0.5,
            1e30,
            22.5,
            FIT_WIDE_R,
            FIT_WIDE_R.next_down(),
            FIT_WIDE_R.next_up(),
        ];
        let n = 4000;
        let mut cols: [Vec<f32>; 3] = Default::default();
        for k in 0..n {
            let pick = |x: f32, k: usize, c: usize| {
                if (k * 7 + c * 3).is_multiple_of(29) {
                    specials[(k + c) % specials.len()]
                } else {
                    x
                }
            };
            cols[0].push(pick(next() * 27.0 - 2.0, k, 0));
            cols[1].push(pick(next() * 21.0 - 2.0, k, 1));
            cols[2].push(pick(next() * next() * 12.0, k, 2));
        }
        let mut e9 = vec![0.0; n];
        let mut g = vec![0.0; n];
        query_slices(&view, &cols[0], &cols[1], &cols[2], &mut e9, &mut g);
        for k in 0..n {
            let (a, b) = view.query(cols[0][k], cols[1][k], cols[2][k]);
            assert!(same(a, e9[k]), "eq9 lane {k}: {a} vs {}", e9[k]);
            assert!(same(b, g[k]), "gradient lane {k}: {b} vs {}", g[k]);
        }
        // The 8-lane batch, and a 1-texel-wide table.
        let d1 = table(1, 3, &[true, false, true]);
        for view in [view, VdtView::new(1, 3, &d1).unwrap()] {
            let u = f32x8::new([0.5, 1.0, 3.3, -1.0, f32::NAN, 7.7, 0.2, 10.0]);
            let v = f32x8::new([0.5, 2.0, 1.3, 9.0, 0.0, 2.7, 0.9, 1.0]);
            let r = f32x8::new([1.0, 0.0, 2.0, 0.5, 1.0, f32::NAN, 1e-3, 1e9]);
            let (a, b) = query(&view, u, v, r);
            for k in 0..8 {
                let (x, y) = view.query(u.as_array()[k], v.as_array()[k], r.as_array()[k]);
                assert!(
                    same(x, a.as_array()[k]) && same(y, b.as_array()[k]),
                    "lane {k}"
                );
            }
        }
        // Lengths around the vector sizes.
        for len in [0usize, 1, 7, 8, 9, 15, 16, 17] {
            let mut e = vec![0.0; len];
            let mut gg = vec![0.0; len];
            query_slices(
                &view,
                &cols[0][..len],
                &cols[1][..len],
                &cols[2][..len],
                &mut e,
                &mut gg,
            );
            for k in 0..len {
                assert!(same(e[k], e9[k]) && same(gg[k], g[k]));
            }
        }
    }
}
