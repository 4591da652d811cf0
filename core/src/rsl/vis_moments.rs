//! Visibility moment tables: the visible fraction **and the first moment of the visible
//! part** of any square, from three exact summed-area tables of a binary visibility map.
//! An extension of the rotatable-square-lights shading (section 3, eq. 5), not in the
//! paper; [`crate::rsl::shade::shade_moments`] uses it.
//!
//! ## Why
//!
//! Eq. 5 replaces `∫_R ρ·V` over a light's square `R` by `ρ̄·V̄·|R|`. The error is the
//! covariance of `ρ` and `V` over `R` (eq. 13's `u_L·σ_V·σ_ρ` term): large for the big,
//! partly shadowed squares of a sky, where the cosine-weighted BRDF changes by a factor of
//! two across the square. With `ρ` linear over the square, `φ(x) ≈ φ̄ + g·(x − c)` (a
//! density per unit parametrisation area, [`crate::rsl::shade::BrdfIntegral::integral_gradient`]),
//!
//! ```text
//!   ∫_R φ·V dA ≈ φ̄·∫_R V dA + g·∫_R (x − c)·V dA = I·f + g·|R|·m,
//!   f = (1/|R|)∫_R V dA,   m = (1/|R|)∫_R (x − c)·V dA,
//! ```
//!
//! exact for a linear `φ` and any visibility. `f` and `m` are box sums of `V`, `u·V` and
//! `v·V`: three summed-area tables ([`crate::rsl::sat`], exact `i64` fixed point). A query
//! reads 32 distinct entries: `V` at the 4 × 4 knots of its box ([`axis_knots`]), the
//! moment tables at 8 each.
//!
//! ## Grid, units, accuracy
//!
//! The map is `n × n` over the parametrisation square `[−1, 1]²` (texel `(i, j)` covers
//! `[i, i+1]×[j, j+1]` in texel units, as [`crate::rsl::vdt`] and [`crate::rsl::visibility`]),
//! `V` = 1 where visible. The map is binary ([`VisMoments::build`]) or a coverage map
//! ([`VisMoments::build_coverage`], `V` the visible fraction of each texel): a binary map
//! moves every edge of the visible region by up to half a texel, which for the small
//! squares of a sun a few texels wide is most of the kernel's error (measured in the
//! harness: at 256², `K = 30`, the default sky's moments-kernel error is 0.35 % from a
//! binary map and 0.24 % from the coverage map, against 0.26 % for the exact integral over
//! the same squares). The moment tables hold `(i + ½ − n/2)·V` and `(j + ½ − n/2)·V`; a
//! query reads the knots around its four corners from all three tables and corrects the
//! moment of the partly covered edge columns and rows from their texels' centres to the
//! exact `∫x dx`, using the `V` knots it has read anyway, so `f` and `m` are exact for the
//! piecewise-constant map up to `f64` rounding, for squares of any size (a square inside
//! one texel included: a centre-moment table alone would put its moment up to half a
//! texel away). Outside the table counts as visible (as
//! [`crate::rsl::visibility::Outside::Visible`]: it is below the horizon, where the
//! cosine-weighted BRDF is 0). Queries take the centre and half-diagonal in disk units, as
//! [`crate::rsl::shade::SquareVisibility`]; `m` is returned in disk units.
//!
//! **Cost:** three tables of `(n + 1)²` `i64` entries, 1.6 MB at `n = 256` (the VDT: 256 KB).
//!
//! **Bad input.** Construction validates the size; NaN in a query gives NaN; a zero or
//! negative half-diagonal (an empty square) gives `f = 1`, `m = 0`. Nothing panics.

#[cfg(feature = "alloc")]
use alloc::vec::Vec;

#[cfg(feature = "alloc")]
use crate::rsl::sat::Sat;
use crate::rsl::sat::{SatView, corner_box};
use crate::{Error, Vec2};

/// Three exact summed-area tables of a visibility map: `V`, `u·V`, `v·V` (module docs).
#[cfg(feature = "alloc")]
#[derive(Clone, Debug, PartialEq)]
pub struct VisMoments {
    n: usize,
    v: Sat,
    xv: Sat,
    yv: Sat,
}

/// The query side of [`VisMoments`], borrowed (what a renderer without `alloc` keeps, and
/// what the SIMD kernel reads): the three tables as [`SatView`]s of one `n × n` map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VisMomentsView<'a> {
    n: usize,
    v: SatView<'a>,
    xv: SatView<'a>,
    yv: SatView<'a>,
}

#[cfg(feature = "alloc")]
impl VisMoments {
    /// The tables of an `n × n` binary map, row-major (`mask[j·n + i]`, `true` = visible).
    /// Errors: `n` outside the SAT's range or `mask.len() ≠ n²`.
    pub fn build(n: usize, mask: &[bool]) -> Result<VisMoments, Error> {
        let cov: Vec<f32> = mask.iter().map(|&m| if m { 1.0 } else { 0.0 }).collect();
        Self::build_coverage(n, &cov)
    }

    /// The tables of an `n × n` coverage map, row-major (`coverage[j·n + i]`, the visible
    /// fraction of each texel, as [`crate::rsl::visibility::coverage_into`] makes it): the
    /// edges of the visible region are then resolved below a texel, which a binary map
    /// rounds to half a texel (module docs). Errors: `n` outside the SAT's range,
    /// `coverage.len() ≠ n²`, or a value that is not in `[0, 1]` (NaN included).
    pub fn build_coverage(n: usize, coverage: &[f32]) -> Result<VisMoments, Error> {
        let len = n.checked_mul(n).ok_or(Error::OutOfRange {
            what: "visibility map side",
            value: n as f32,
            min: 1.0,
            max: crate::rsl::sat::MAX_SIDE as f32,
        })?;
        crate::grid::check_len("visibility map length", coverage.len(), len)?;
        if let Some(&bad) = coverage.iter().find(|c| !(0.0..=1.0).contains(*c)) {
            return Err(Error::OutOfRange {
                what: "visibility coverage",
                value: bad,
                min: 0.0,
                max: 1.0,
            });
        }
        let half = 0.5 * n as f64;
        let mut v = Vec::with_capacity(len);
        let mut xv = Vec::with_capacity(len);
        let mut yv = Vec::with_capacity(len);
        for (j, row) in coverage.chunks(n.max(1)).enumerate() {
            for (i, &c) in row.iter().enumerate() {
                // Exact in f64: a 24-bit coverage times an offset that is a multiple of ½
                // below 2^24.
                let w = f64::from(c);
                v.push(w);
                xv.push(w * (i as f64 + 0.5 - half));
                yv.push(w * (j as f64 + 0.5 - half));
            }
        }
        Ok(VisMoments {
            n,
            v: Sat::build_f64(n, n, &v)?,
            xv: Sat::build_f64(n, n, &xv)?,
            yv: Sat::build_f64(n, n, &yv)?,
        })
    }

    /// Side of the map.
    pub fn side(&self) -> usize {
        self.n
    }

    /// Bytes of the three tables.
    pub fn bytes(&self) -> usize {
        self.v.bytes() + self.xv.bytes() + self.yv.bytes()
    }

    /// The borrowed view (all queries live there).
    pub fn view(&self) -> VisMomentsView<'_> {
        VisMomentsView {
            n: self.n,
            v: self.v.view(),
            xv: self.xv.view(),
            yv: self.yv.view(),
        }
    }

    /// The three summed-area tables `[V, (i + ½ − n/2)·V, (j + ½ − n/2)·V]` (module docs;
    /// texel-unit offsets from the table's centre), each `n × n` with its own quantum, for
    /// kernels that read them directly (the WGSL moments kernel, `wgsl::SHADE_MOMENTS`,
    /// uploads their entries; [`VisMomentsView::tables`]).
    pub fn tables(&self) -> [SatView<'_>; 3] {
        [self.v.view(), self.xv.view(), self.yv.view()]
    }

    /// [`VisMomentsView::moments`].
    pub fn moments(&self, centre: Vec2, half_diagonal: f32) -> (f32, Vec2) {
        self.view().moments(centre, half_diagonal)
    }
}

impl<'a> VisMomentsView<'a> {
    /// A view of the tables `V`, `u·V`, `v·V` of one `n × n` map (module docs; e.g. saved
    /// from a [`VisMoments`] and loaded by the caller). Errors: tables that are not square
    /// or not all of one size.
    pub fn new(v: SatView<'a>, xv: SatView<'a>, yv: SatView<'a>) -> Result<Self, Error> {
        let n = v.width();
        if [v, xv, yv]
            .iter()
            .any(|t| t.width() != n || t.height() != n)
        {
            return Err(Error::OutOfRange {
                what: "visibility moment tables (must be square and of one size)",
                value: n as f32,
                min: n as f32,
                max: n as f32,
            });
        }
        Ok(VisMomentsView { n, v, xv, yv })
    }

    /// Side of the map.
    pub fn side(&self) -> usize {
        self.n
    }

    /// The three tables `[V, u·V, v·V]` (module docs), for kernels that read them
    /// directly (the SIMD mirror of [`VisMomentsView::moments`]).
    pub fn tables(&self) -> [SatView<'a>; 3] {
        [self.v, self.xv, self.yv]
    }

    /// `(f, m)` of the square with centre `centre` and half-diagonal `half_diagonal` (disk
    /// units): the visible fraction and the mean of `(x − c)·V` over the square (module
    /// docs), `f ∈ [0, 1]`, `|m| ≤ half-side`.
    pub fn moments(&self, centre: Vec2, half_diagonal: f32) -> (f32, Vec2) {
        if centre.is_nan() || half_diagonal.is_nan() {
            return (f32::NAN, Vec2::NAN);
        }
        let hn = 0.5 * self.n as f64;
        let h = f64::from(crate::rsl::sat::square_half_side(half_diagonal)) * hn;
        if h <= 0.0 {
            return (1.0, Vec2::ZERO);
        }
        let cu = (f64::from(centre.x) + 1.0) * hn;
        let cv = (f64::from(centre.y) + 1.0) * hn;
        // The part of the square inside the table.
        let n = self.n as f64;
        let (a0, a1) = ((cu - h).clamp(0.0, n), (cu + h).clamp(0.0, n));
        let (b0, b1) = ((cv - h).clamp(0.0, n), (cv + h).clamp(0.0, n));
        let (sv, mx_in, my_in) = self.inside(a0, a1, b0, b1, cu, cv);
        let area = 4.0 * h * h;
        let area_in = (a1 - a0) * (b1 - b0);
        // Outside is visible: ∫_out (x − c) = −∫_in (x − c) (the whole square's is 0).
        let mx_out = -area_in * (0.5 * (a0 + a1) - cu);
        let my_out = -area_in * (0.5 * (b0 + b1) - cv);
        let f = ((sv + (area - area_in)) / area).clamp(0.0, 1.0);
        let to_disk = 1.0 / (area * hn);
        let m = Vec2::new(
            ((mx_in + mx_out) * to_disk) as f32,
            ((my_in + my_out) * to_disk) as f32,
        );
        (f as f32, m)
    }

    /// `(∫V, ∫(x − cu)·V, ∫(y − cv)·V)` over `[a0, a1] × [b0, b1]` (texel units, inside
    /// the table) for the piecewise-constant map, exact up to `f64` rounding and free of
    /// cancellation for boxes of any size: each axis splits into a partly covered first
    /// texel, a run of whole texels and a partly covered last texel ([`axis_knots`]); each
    /// of the nine blocks takes its `∫V` from an exact integer box of the `V` table times
    /// the covered fractions, and its moment from the partial texel's covered centre or,
    /// over the run of whole texels, from the moment table (texel centres, exact there).
    fn inside(&self, a0: f64, a1: f64, b0: f64, b1: f64, cu: f64, cv: f64) -> (f64, f64, f64) {
        let hn = 0.5 * self.n as f64;
        let [v, xv, yv] = self.tables();
        let (kx, ky) = (axis_knots(a0, a1, self.n), axis_knots(b0, b1, self.n));
        let (x, y) = (kx.knots, ky.knots);
        // The nine `V` blocks share a 4 × 4 grid of corners, the three `u·V` run boxes a
        // 4 × 2 one and the three `v·V` run boxes a 2 × 4 one: 32 reads instead of 60,
        // the same exact integer boxes as `integer_box` on each block.
        let (gv, gx, gy) = (
            v.corners(x, y),
            xv.corners([x[1], x[2]], y),
            yv.corners(x, [y[1], y[2]]),
        );
        let bv: [[f64; 3]; 3] = core::array::from_fn(|i| {
            core::array::from_fn(|j| corner_box(&gv, (i, i + 1), (j, j + 1)) as f64 * v.quantum())
        });
        let bx: [f64; 3] =
            core::array::from_fn(|j| corner_box(&gx, (0, 1), (j, j + 1)) as f64 * xv.quantum());
        let by: [f64; 3] =
            core::array::from_fn(|i| corner_box(&gy, (i, i + 1), (0, 1)) as f64 * yv.quantum());
        combine_blocks(&kx, &ky, &bv, &bx, &by, cu - hn, cv - hn, cu, cv)
    }
}

/// The nine blocks of a query combined (the shared second half of [`VisMoments::moments`]
/// and its SIMD mirror): `bv[i][j]` the `V` box of x-block `i`, y-block `j` (first, run,
/// last), `bx[j]` the `u·V` box of the x-run, `by[i]` the `v·V` box of the y-run, `ou =
/// cu − n/2`, `ov = cv − n/2` (the moment tables' origin seen from the centre).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn combine_blocks(
    kx: &AxisKnots,
    ky: &AxisKnots,
    bv: &[[f64; 3]; 3],
    bx: &[f64; 3],
    by: &[f64; 3],
    ou: f64,
    ov: f64,
    cu: f64,
    cv: f64,
) -> (f64, f64, f64) {
    let (wx, wy) = (kx.weights(), ky.weights());
    let (mut s, mut mx, mut my) = (0.0f64, 0.0f64, 0.0f64);
    for j in 0..3 {
        for i in 0..3 {
            s += wx[i] * wy[j] * bv[i][j];
        }
        mx += wy[j]
            * ((kx.w_first * bv[0][j] * (kx.mid_first - cu) + (bx[j] - ou * bv[1][j]))
                + kx.w_last * bv[2][j] * (kx.mid_last - cu));
    }
    for i in 0..3 {
        my += wx[i]
            * ((ky.w_first * bv[i][0] * (ky.mid_first - cv) + (by[i] - ov * bv[i][1]))
                + ky.w_last * bv[i][2] * (ky.mid_last - cv));
    }
    (s, mx, my)
}

/// One axis `[lo, hi] ⊂ [0, n]` of a query as three blocks of texels: the partly covered
/// first texel `[X0, X1)`, the run of whole texels `[X1, X2)` and the partly covered last
/// texel `[X2, X3)` (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AxisKnots {
    /// `X0 ≤ X1 ≤ X2 ≤ X3 ≤ n`.
    pub knots: [usize; 4],
    /// Covered length of the first texel (0 when both ends share a texel).
    pub w_first: f64,
    /// Covered length of the last texel (the whole `hi − lo` when both ends share it).
    pub w_last: f64,
    /// Centre of the covered part of the first texel.
    pub mid_first: f64,
    /// Centre of the covered part of the last texel.
    pub mid_last: f64,
}

impl AxisKnots {
    /// The weights of the three blocks, `[w_first, 1, w_last]`.
    #[inline(always)]
    pub fn weights(&self) -> [f64; 3] {
        [self.w_first, 1.0, self.w_last]
    }
}

/// [`AxisKnots`] of `[lo, hi]` for `0 ≤ lo ≤ hi ≤ n` (no NaN): with `c0 = ⌊lo⌋`, `c1 = ⌊hi⌋`
/// (at most `n − 1`), knots `[c0, min(c0 + 1, c1), c1, c1 + 1]`. When both ends share a
/// texel the first block and the run are empty and the last block carries `[lo, hi]`.
#[inline(always)]
pub fn axis_knots(lo: f64, hi: f64, n: usize) -> AxisKnots {
    let last = n.saturating_sub(1);
    // `as usize` truncates, which is the floor for `0 ≤ x` (no float floor in no_std).
    let c0 = (lo as usize).min(last);
    let c1 = (hi as usize).min(last);
    let split = c0 < c1;
    let start = if split { c1 as f64 } else { lo };
    AxisKnots {
        knots: [c0, (c0 + 1).min(c1), c1, c1 + 1],
        w_first: if split { (c0 + 1) as f64 - lo } else { 0.0 },
        w_last: hi - start,
        mid_first: 0.5 * (lo + (c0 + 1) as f64),
        mid_last: 0.5 * (start + hi),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The f64 brute force of `steradian-reference`, at a `Vec2` centre.
    fn brute(n: usize, cov: &[f32], c: Vec2, r: f32) -> (f64, f64, f64) {
        steradian_reference::rsl::moments::square_moments(n, cov, c.to_array(), r)
    }

    #[test]
    fn matches_brute_force_on_a_disc_and_a_half_plane() {
        let n = 32;
        let mask: Vec<bool> = (0..n * n)
            .map(|k| {
                let (i, j) = ((k % n) as f64 + 0.5, (k / n) as f64 + 0.5);
                let disc = (i - 12.0).powi(2) + (j - 18.0).powi(2) < 49.0;
                let half = i + 0.4 * j > 26.0;
                !(disc || half)
            })
            .collect();
        let t = VisMoments::build(n, &mask).unwrap();
        assert_eq!(t.bytes(), 3 * 33 * 33 * 8);
        let cov: Vec<f32> = mask.iter().map(|&m| m as u32 as f32).collect();
        check_against_brute(&t, n, &cov, 2e-7);
        // A coverage map with fractional values (a deterministic ramp of odd fractions).
        let cov: Vec<f32> = (0..n * n)
            .map(|k| ((k * 37 + 11) % 101) as f32 / 100.0)
            .collect();
        let t = VisMoments::build_coverage(n, &cov).unwrap();
        check_against_brute(&t, n, &cov, 2e-7);
    }

    fn check_against_brute(t: &VisMoments, n: usize, cov: &[f32], tol: f64) {
        // centres include the pole, the table edge (horizon) and beyond it
        for (c, r) in [
            (Vec2::new(0.0, 0.0), 0.3),
            (Vec2::new(-0.2, 0.15), 0.55),
            (Vec2::new(0.31, -0.4), 0.05),
            // inside one texel (half-side 0.11 texel, off the texel's centre)
            (Vec2::new(0.013, -0.021), 0.01),
            (Vec2::new(0.9, 0.95), 0.4),
            (Vec2::new(-1.1, 0.2), 0.3),
            (Vec2::new(0.0, 0.0), 3.0),
        ] {
            let (f, m) = t.moments(c, r);
            let (bf, bx, by) = brute(n, cov, c, r);
            let h = f64::from(r) * core::f64::consts::FRAC_1_SQRT_2;
            // Exact up to the final rounding to f32 (of 1 and of the half-side)
            assert!((f64::from(f) - bf).abs() < tol, "{c} {r}: f {f} vs {bf}");
            assert!(
                (f64::from(m.x) - bx).abs() < tol * h,
                "{c} {r}: mx {} vs {bx}",
                m.x
            );
            assert!(
                (f64::from(m.y) - by).abs() < tol * h,
                "{c} {r}: my {} vs {by}",
                m.y
            );
        }
    }

    /// The blocks cover `[lo, hi]` exactly: lengths add up, centres are inside, knots
    /// ordered and in the table (one texel, texel edges, the far edge, empty, `n = 1`).
    #[test]
    fn axis_knots_cover_the_interval() {
        for (lo, hi, n) in [
            (2.25, 2.75, 8),
            (2.0, 3.0, 8),
            (2.5, 7.25, 8),
            (0.0, 8.0, 8),
            (7.5, 8.0, 8),
            (8.0, 8.0, 8),
            (3.0, 3.0, 8),
            (0.25, 0.5, 1),
            (0.0, 1.0, 1),
        ] {
            let k = axis_knots(lo, hi, n);
            let x = k.knots;
            assert!(
                x[0] <= x[1] && x[1] <= x[2] && x[2] <= x[3] && x[3] <= n,
                "{k:?}"
            );
            let run = (x[2] - x[1]) as f64;
            assert_eq!(k.w_first + run + k.w_last, hi - lo, "{lo} {hi}: {k:?}");
            if k.w_first > 0.0 {
                assert!(x[1] == x[0] + 1 && (x[0] as f64) <= k.mid_first, "{k:?}");
                assert!(k.mid_first <= x[1] as f64, "{k:?}");
            }
            if k.w_last > 0.0 {
                assert!(x[3] == x[2] + 1 && (x[2] as f64) <= k.mid_last, "{k:?}");
                assert!(k.mid_last <= x[3] as f64, "{k:?}");
            }
        }
    }

    #[test]
    fn all_visible_has_no_moment_and_bad_input_is_nan() {
        let t = VisMoments::build(8, &[true; 64]).unwrap();
        // a square on texel edges (half-side 0.5 = two texels): no centre-moment error
        let (f, m) = t.moments(Vec2::new(0.25, -0.5), 0.5 * core::f32::consts::SQRT_2);
        assert!((f - 1.0).abs() < 1e-6 && m.length() < 1e-6, "{f} {m}");
        // partly outside the table (below the horizon), which counts as visible
        let (f, m) = t.moments(Vec2::new(0.9, -0.95), 0.4);
        assert!((f - 1.0).abs() < 1e-6 && m.length() < 0.02, "{f} {m}");
        let (f, m) = t.moments(Vec2::new(f32::NAN, 0.0), 0.1);
        assert!(f.is_nan() && m.is_nan());
        assert_eq!(t.moments(Vec2::ZERO, -1.0), (1.0, Vec2::ZERO));
        assert!(VisMoments::build(8, &[true; 63]).is_err());
        for bad in [1.5, -0.1, f32::NAN, f32::INFINITY] {
            let mut cov = [1.0f32; 64];
            cov[9] = bad;
            assert!(VisMoments::build_coverage(8, &cov).is_err(), "{bad}");
        }
        // a view of the tables queries as the owned tables; tables of two sizes are refused
        let [v, x, y] = t.tables();
        let view = VisMomentsView::new(v, x, y).unwrap();
        let q = (Vec2::new(0.3, -0.2), 0.45);
        assert_eq!(view.moments(q.0, q.1), t.moments(q.0, q.1));
        let small = VisMoments::build(4, &[true; 16]).unwrap();
        assert!(VisMomentsView::new(v, small.tables()[1], y).is_err());
        // all occluded, square inside the table: f = 0, m = 0
        let t = VisMoments::build(8, &[false; 64]).unwrap();
        let (f, m) = t.moments(Vec2::new(0.1, 0.1), 0.4);
        assert!(f.abs() < 1e-6 && m.length() < 1e-6, "{f} {m}");
    }
}
