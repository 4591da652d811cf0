//! Cap → lobe exponent lookup, 8 lanes at a time (mirrors `steradian_core::lobe::cap`).
//!
//! [`lookup`] performs exactly the operations of `steradian_core::lobe::cap::lookup` lane-wise
//! (the NaN-keeping clamp of `α`, `u = π/2 − α` with a two-part π/2,
//! `r = (N − 1)·sqrt(2u/π)` with their NaN-ignoring `max` and `min`, the interval
//! `k = max(⌈r⌉, 1)`, the fraction `(k − r)(k + r)/(2k − 1)`, linear interpolation, division
//! by `α²`), so every lane is **bit-identical** to the scalar kernel for every input (checked
//! on every `f32` by the ignored test `cap_exhaustive`). `wide` has no gather: the two table
//! samples of each lane are read with scalar indexing from the lanes' indices.

use core::f32::consts::{FRAC_PI_2, PI};

use steradian_core::lobe::cap::{MIN_HALF_ANGLE, TABLE};
use wide::f32x8;

use crate::batch::PAD_F32;
use crate::lanes::{ColumnKernel, Lanes, SliceVec, clamp, drive, max_num, min_num};

/// `π/2 − FRAC_PI_2` (the `f32` constant rounds π/2 up by this much); the same literal as
/// `steradian_core::lobe::cap`'s private constant.
use steradian_core::lobe::cap::FRAC_PI_2_LO;

/// Tables up to this length are looked up lane-wise: every grid coordinate and index is
/// then an exact `f32` integer (`≤ 2²⁴`). Longer tables go through the scalar kernel lane by
/// lane.
const MAX_WIDE_TABLE: usize = 1 << 24;

/// The L2-optimal exponent of a unit-scale lobe for caps of half-angles `half_angle`, from the
/// built-in table: lane-wise `steradian_core::lobe::cap::exponent_l2`, bit-identical.
///
/// Saturating: `α` is clamped to `[MIN_HALF_ANGLE, π/2]`; NaN gives NaN.
#[inline]
pub fn exponent_l2(half_angle: f32x8) -> f32x8 {
    lookup_lanes(&TABLE, half_angle)
}

/// [`exponent_l2`] with a caller-supplied table of `h(α) = e*·α²` samples on the grid of
/// `steradian_core::lobe::cap::lookup`: lane-wise `steradian_core::lobe::cap::lookup`, bit-identical. A
/// table with fewer than two samples gives NaN.
#[inline]
pub fn lookup(table: &[f32], half_angle: f32x8) -> f32x8 {
    lookup_lanes(table, half_angle)
}

/// The scalar `lookup`, operation for operation.
#[inline(always)]
fn lookup_lanes<W: Lanes>(table: &[f32], half_angle: W) -> W {
    let n = table.len();
    if n < 2 {
        return W::splat(f32::NAN);
    }
    if n > MAX_WIDE_TABLE {
        let a = half_angle.lanes();
        return W::from_fn(|k| steradian_core::lobe::cap::lookup(table, a[k]));
    }
    let one = W::splat(1.0);
    let last = W::splat((n - 1) as f32);
    // Scalar: `half_angle.clamp(MIN_HALF_ANGLE, FRAC_PI_2)` keeps NaN.
    let a = clamp(half_angle, W::splat(MIN_HALF_ANGLE), W::splat(FRAC_PI_2));
    // Scalar: `u = ((π/2)_hi − α + (π/2)_lo).max(0)`, `r = (sqrt(u·(2/π))·last).min(last)`.
    // Both `max` and `min` are NaN-ignoring, so a NaN lane gets `u = 0`, `r = 0` and a valid
    // index; the final division returns the NaN.
    let u = max_num(
        (W::splat(FRAC_PI_2) - a) + W::splat(FRAC_PI_2_LO),
        W::splat(0.0),
    );
    let r = min_num((u * W::splat(2.0 / PI)).sqrt() * last, last);
    // Scalar: `k = ceil(r).max(1)`, `i = (last − k) as usize`,
    // `f = ((k − r)·(k + r)/(2k − 1)).min(1)`. With `0 ≤ r ≤ last ≤ 2²⁴` every value is an
    // exact `f32` integer, `i ≤ n − 2`.
    let k = max_num(r.ceil(), one);
    let i = last - k;
    let f = min_num((k - r) * (k + r) / (W::splat(2.0) * k - one), one);
    // No gather in wide: read each lane's two samples by scalar indexing.
    let (h0, h1) = i.gather_pair(table);
    (h0 + f * (h1 - h0)) / (a * a)
}

struct LookupK<'a>(&'a [f32]);
impl ColumnKernel<1, 1> for LookupK<'_> {
    const PADS: [f32; 1] = [PAD_F32];
    #[inline(always)]
    fn apply<W: Lanes>(&self, [a]: [W; 1]) -> ([W; 1], W) {
        ([lookup_lanes(self.0, a)], W::splat(0.0))
    }
}

/// [`exponent_l2`] over a column: `out[i] = exponent_l2(half_angle[i])`. Any length (tail
/// padded with [`PAD_F32`]); runs on the build's widest vector, same results.
///
/// # Panics
/// If the two columns have different lengths.
pub fn exponent_l2_slices(half_angle: &[f32], out: &mut [f32]) {
    // Inlined with the built-in table, so its length is a constant in the gather.
    drive::<SliceVec, _, 1, 1>(
        "cap::exponent_l2_slices",
        &LookupK(&TABLE),
        [half_angle],
        [out],
    );
}

/// [`lookup`] over a column: `out[i] = lookup(table, half_angle[i])`. Any length (tail
/// padded with [`PAD_F32`]); runs on the build's widest vector, same results.
///
/// # Panics
/// If the two columns have different lengths.
pub fn lookup_slices(table: &[f32], half_angle: &[f32], out: &mut [f32]) {
    drive::<SliceVec, _, 1, 1>("cap::lookup_slices", &LookupK(table), [half_angle], [out]);
}
