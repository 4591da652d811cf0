//! Visibility distance table queries, 8 (or 16) lanes at a time (mirrors
//! `steradian_core::rsl::vdt`).
//!
//! [`query`] performs exactly the operations of `steradian_core::rsl::vdt::VdtView::query` lane
//! by lane: the clamped cell index and fraction per axis (`floor` written as `−ceil(−x)`,
//! which is exact), the four samples, `lerp(a, b, t) = (1 − t)·a + t·b`, the in-cell
//! gradient, eq. 9 and the straight-edge fraction with the scalar kernel's NaN-keeping
//! clamps and NaN-ignoring `max`/`min`, and selects where the scalar kernel branches. All
//! of them are correctly rounded IEEE operations, so every lane is **bit-identical** to the
//! scalar query of that lane, for every input (NaN-ness matches). `wide` has no gather: the
//! four samples of each lane are read by scalar indexing from the lanes' cell indices.

use steradian_core::grid::Q_MIN;
use steradian_core::rsl::vdt::{R_MAX, R_MIN, VdtView};
use wide::f32x8;

use crate::lanes::{ColumnKernel, Lanes, SliceVec, clamp, drive, max_num, min_num};

const SQRT_2: f32 = core::f32::consts::SQRT_2;

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

/// Eq. 9 lane-wise, `steradian_core::rsl::vdt::eq9_from` operation for operation, for a
/// half-diagonal `rr` already clamped to `[R_MIN, R_MAX]` (the one copy the VDT query and
/// the SIMD shading kernel share).
#[inline(always)]
pub(crate) fn eq9_lanes<W: Lanes>(dd: W, rr: W) -> W {
    let k = W::splat(SQRT_2) * rr;
    clamp((W::splat(0.5) * k + dd) / k, W::splat(0.0), W::splat(1.0))
}

/// The scalar `VdtView::query`, operation for operation: `[eq9, gradient]`.
#[inline(always)]
fn query_lanes<W: Lanes>(view: &VdtView<'_>, [u, v, r]: [W; 3]) -> [W; 2] {
    let (w, h) = (view.width(), view.height());
    let d = view.samples();
    let (i0, fx) = axis(u, w);
    let (j0, fy) = axis(v, h);
    // Gather: `as usize` saturates and maps NaN to 0, as in the scalar kernel.
    let (ia, ja) = (i0.lanes(), j0.lanes());
    // `i0 ≤ w − 2` when `w ≥ 2`, so the scalar `i1 = min(i0 + 1, w − 1)` is `i0 + 1`, and
    // `i0` itself when `w = 1`: constant steps to the other three samples.
    let di = usize::from(w >= 2);
    let dj = if h >= 2 { w } else { 0 };
    let mut base = [0usize; 16];
    for (k, b) in base.iter_mut().take(W::N).enumerate() {
        *b = ja[k] as usize * w + ia[k] as usize;
    }
    let at = |k: usize, off: usize| -> f32 { d.get(base[k] + off).copied().unwrap_or(0.0) };
    let d00 = W::from_fn(|k| at(k, 0));
    let d10 = W::from_fn(|k| at(k, di));
    let d01 = W::from_fn(|k| at(k, dj));
    let d11 = W::from_fn(|k| at(k, dj + di));
    let d0 = lerp(d00, d10, fx);
    let d1 = lerp(d01, d11, fx);
    let dd = lerp(d0, d1, fy);
    let gx = lerp(d10 - d00, d11 - d01, fy);
    let gy = lerp(d01 - d00, d11 - d10, fx);
    let zero = W::splat(0.0);
    let one = W::splat(1.0);
    let rr = clamp(r, W::splat(R_MIN), W::splat(R_MAX));
    let e9 = eq9_lanes(dd, rr);
    // Straight-edge fraction.
    let (ax, ay) = (gx.abs(), gy.abs());
    let m = max_num(ax, ay);
    let q = m.gt(zero).select(min_num(ax, ay) / m, zero);
    let t = dd * W::splat(SQRT_2) / rr;
    let len = (one + q * q).sqrt();
    let hi = one + q;
    let tt = clamp(t * len, -hi, hi);
    let den = W::splat(8.0) * max_num(q, W::splat(Q_MIN));
    let lo_e = tt + hi;
    let lo_v = lo_e * lo_e / den;
    let hi_e = hi - tt;
    let hi_v = one - hi_e * hi_e / den;
    let mid = (tt + one) * W::splat(0.5);
    let is_lo = tt.le(q - one);
    let is_hi = tt.ge(one - q);
    let g = is_lo.select(lo_v, is_hi.select(hi_v, mid));
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
        let mut s = 12345u64;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
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
