//! Cosine lobes, 8 lanes at a time (mirrors `steradian_core::lobe`).
//!
//! - [`integral`] performs the scalar kernel's operations in the same order: every lane is
//!   **bit-identical** to `steradian_core::lobe::integral`.
//! - [`eval`] computes `s·exp(e·log1p(−t))`, `t = |a − v|²/2`, like the scalar kernel, but
//!   with wide's polynomial `ln_1p` (Goldberg's `ln(u)·x/(u − 1)`, `u = 1 + x`) and `exp`
//!   instead of the standard library's. `t` and the horizon test are the scalar kernel's
//!   operations, so:
//!   - the result is `0·s` (so `±0`, or NaN for non-finite `s`) **exactly** where the scalar
//!     kernel takes its `t ≥ 1` branch, bit for bit;
//!   - it is zero exactly where the scalar kernel's result is zero by underflow too: lanes
//!     whose `exp` argument is within 0.1 of the underflow threshold `−103.97`, or whose
//!     product `s·exp(…)` is within a subnormal unit (and 2e-4 relative) of rounding to
//!     zero, are recomputed with the scalar kernel (so they are bit-identical; such lanes
//!     are rare, their result is about 1e-45, and each costs a scalar call);
//!   - with `e = 0` (or a negative `e`, clamped to 0) it is exactly `s` inside the horizon;
//!   - it is NaN exactly where the scalar kernel is NaN;
//!   - elsewhere its difference `Δ` from the scalar kernel's value `c` satisfies
//!     `|Δ| ≤ EVAL_REL_TOL·(1 + |ln(c/s)|)·|c| + EVAL_UNDERFLOW_ABS·(1 + |s|)` (the second
//!     term only matters where the result is subnormal: both results are then rounded to
//!     the subnormal grid from values a few ulps apart).
//!
//! The bound is the natural one for `exp(y)`: an error `δ` relative in `y = e·log1p(−t)`
//! becomes `δ·|y| = δ·|ln(c/s)|` relative in the result. It is checked by the tests of this
//! crate against the scalar kernel on pseudo-random and special inputs.
//!
//! # References
//!
//! Those of `steradian_core::lobe` (the cosine-lobe paper).

use core::f32::consts::TAU;

use wide::f32x8;

use crate::batch::{LobeX8, PAD_F32, PAD_VEC3, Vec3x8};
use crate::lanes::{ColumnKernel, Lanes, SliceVec, drive};

pub mod cap;
pub mod product;

impl LobeX8 {
    /// [`eval`] of this batch.
    #[inline]
    pub fn eval(self, v: Vec3x8) -> f32x8 {
        eval(self, v)
    }

    /// [`integral`] of this batch.
    #[inline]
    pub fn integral(self) -> f32x8 {
        integral(self.exponent, self.scale)
    }
}

/// Relative tolerance of [`eval`] against `steradian_core::lobe::eval`, per unit of
/// `1 + |ln(c/s)|` (see the module docs). Measured maximum: `3.1e-7` over 2·10⁷
/// pseudo-random lanes (`eval_survey` in `tests/contract.rs`).
pub const EVAL_REL_TOL: f32 = 5.0e-7;

/// Absolute allowance of [`eval`] against the scalar kernel, per unit of `1 + |s|`, where the
/// `exp` factor underflows into subnormals: two subnormal units (`2·2⁻¹⁴⁹`).
pub const EVAL_UNDERFLOW_ABS: f32 = 2.0 * f32::from_bits(1);

/// `exp(y)` lane-wise with gradual underflow, for `y ≤ 0` or NaN, and the mask of the lanes
/// set to zero outright (`y < −104`).
///
/// wide's `exp` flushes results below about `e^−103.6` to zero (the correctly rounded `e^y`
/// reaches `0` only below `−150·ln 2 ≈ −103.97`) and takes a slow path for subnormal
/// results; lanes whose result may be subnormal (`y < −87`) are computed as `exp(y/2)²`
/// instead: `y/2` is exact, `exp(y/2)` is normal, and the square rounds once onto the
/// subnormal grid. Lanes with `y < −104` (`e^y < 0.98·2⁻¹⁵⁰`, zero in a correctly rounded
/// `exp`, also for the scalar kernel's `y`, a few ulps away) are set to `0` without
/// computing anything that underflows (subnormal arithmetic is slow on some CPUs).
#[inline(always)]
fn exp_gradual<W: Lanes>(y: W) -> (W, W) {
    let zero = W::splat(0.0);
    let low = y.lt(W::splat(-87.0));
    let dead = y.lt(W::splat(-104.0));
    let arg = low.select(dead.select(zero, y * W::splat(0.5)), y);
    let r = arg.exp();
    (dead.select(zero, low.select(r * r, r)), dead)
}

/// The scalar `eval`, with wide's `ln_1p` and `exp`, and the mask of the lanes at risk of
/// underflowing differently from the scalar kernel, to recompute with it (see [`eval`]).
#[inline(always)]
fn eval_lanes<W: Lanes>([ax, ay, az, scale, exponent, vx, vy, vz]: [W; 8]) -> (W, W) {
    let (zero, one) = (W::splat(0.0), W::splat(1.0));
    // Scalar: `if exponent < 0.0 { 0.0 } else { exponent }` (NaN stays NaN).
    let e = exponent.lt(zero).select(zero, exponent);
    let (dx, dy, dz) = (ax - vx, ay - vy, az - vz);
    let t = W::splat(0.5) * (dx * dx + dy * dy + dz * dz);
    let beyond = t.ge(one);
    // Lanes beyond the horizon get `0·s` below; give them a harmless `log1p` argument so
    // wide's `ln` stays on its fast path.
    let t_in = beyond.select(zero, t);
    let y = e * (-t_in).ln_1p();
    let (p, dead) = exp_gradual(y);
    let c = scale * p;
    // Where the result underflows, `y`'s few-ulp difference from the scalar kernel's could
    // round to zero on one side only: near `exp`'s own underflow (`y ≈ −103.97`), and where
    // `|s|·p` is next to half a subnormal unit `u/2` (the product's rounding to zero), with
    // `p` possibly one unit `u` off the scalar kernel's where it is subnormal and a few ulps
    // (under 2e-4 relative) off elsewhere. The test runs scaled by 2⁶⁴, where nothing
    // underflows. Those lanes (the result is then about 1e-45: rare) take the scalar
    // kernel, so zero-ness is exact.
    let near_exp_underflow = y.gt(W::splat(-104.0)) & y.lt(W::splat(-103.9));
    let (two64, unit, half_unit) = (
        W::splat(f32::from_bits((127 + 64) << 23)),
        W::splat(f32::from_bits((127 - 85) << 23)),
        W::splat(f32::from_bits((127 - 86) << 23)),
    );
    let (ps, sa) = (p * two64, scale.abs());
    let lo = sa * (ps - unit) * W::splat(1.0 - 2e-4);
    let hi = sa * (ps + unit) * W::splat(1.0 + 2e-4);
    let straddles = lo.le(half_unit) & hi.ge(half_unit);
    let risky = !(beyond | dead) & (near_exp_underflow | straddles);
    (beyond.select(zero * scale, c), risky)
}

/// Lane `k` of `c`, or the scalar kernel on lane `k` of the inputs (`input(column, k)`)
/// where `mask` is set. Out of line and cold.
#[cold]
#[inline(never)]
fn scalar_lanes<W: Lanes>(input: impl Fn(usize, usize) -> f32, mask: W, c: W) -> W {
    let (mk, ck) = (mask.lanes(), c.lanes());
    W::from_fn(|k| {
        if mk[k].to_bits() != 0 {
            let l = |i: usize| input(i, k);
            steradian_core::lobe::eval(
                glam::Vec3::new(l(0), l(1), l(2)),
                l(3),
                l(4),
                glam::Vec3::new(l(5), l(6), l(7)),
            )
        } else {
            ck[k]
        }
    })
}

struct EvalK;
impl ColumnKernel<8, 1> for EvalK {
    const PADS: [f32; 8] = [
        LobeX8::PAD_AXIS.x,
        LobeX8::PAD_AXIS.y,
        LobeX8::PAD_AXIS.z,
        LobeX8::PAD_SCALE,
        LobeX8::PAD_EXPONENT,
        PAD_VEC3.x,
        PAD_VEC3.y,
        PAD_VEC3.z,
    ];
    #[inline(always)]
    fn apply<W: Lanes>(&self, v: [W; 8]) -> ([W; 1], W) {
        let (c, redo) = eval_lanes(v);
        ([c], redo)
    }
    fn redo<W: Lanes>(&self, ins: [&[f32]; 8], offset: usize, mask: W, [c]: [W; 1]) -> [W; 1] {
        // Masked lanes lie inside the columns; elsewhere the value is unused.
        let input = |col: usize, k: usize| ins[col].get(offset + k).copied().unwrap_or(0.0);
        [scalar_lanes(input, mask, c)]
    }
}

struct IntegralK;
impl ColumnKernel<2, 1> for IntegralK {
    const PADS: [f32; 2] = [PAD_F32; 2];
    #[inline(always)]
    fn apply<W: Lanes>(&self, v: [W; 2]) -> ([W; 1], W) {
        ([integral_lanes(v)], W::splat(0.0))
    }
}

/// The scalar `integral`, operation for operation.
#[inline(always)]
fn integral_lanes<W: Lanes>([exponent, scale]: [W; 2]) -> W {
    let zero = W::splat(0.0);
    let e = exponent.lt(zero).select(zero, exponent);
    // Divide first, as the scalar kernel does (2π·s overflows for |s| > 5.4e37).
    W::splat(TAU) * (scale / (e + W::splat(1.0)))
}

/// `s·max(a·v, 0)^e` lane-wise, `steradian_core::lobe::eval` of each lane (within
/// [`EVAL_REL_TOL`], zero and NaN exactly where it is; see the module docs):
/// `s·exp(e·log1p(−|a − v|²/2))`, `0·s` where `|a − v|²/2 ≥ 1`, a negative exponent clamped
/// to 0.
#[inline]
pub fn eval(lobe: LobeX8, v: Vec3x8) -> f32x8 {
    eval_parts(lobe.axis, lobe.scale, lobe.exponent, v)
}

/// [`eval`] with the lobe given by its fields, like `steradian_core::lobe::eval(axis,
/// scale, exponent, v)`.
#[inline]
pub fn eval_parts(axis: Vec3x8, scale: f32x8, exponent: f32x8, v: Vec3x8) -> f32x8 {
    let lanes = [axis.x, axis.y, axis.z, scale, exponent, v.x, v.y, v.z];
    let (c, redo) = eval_lanes(lanes);
    if redo.any() {
        scalar_lanes(|i, k| lanes[i].as_array()[k], redo, c)
    } else {
        c
    }
}

/// The exact sphere integral `2π·s/(e + 1)` lane-wise, bit-identical to
/// `steradian_core::lobe::integral`: a negative exponent is clamped to 0, NaN gives NaN,
/// `e = +∞` gives 0.
#[inline]
pub fn integral(exponent: f32x8, scale: f32x8) -> f32x8 {
    integral_lanes([exponent, scale])
}

/// [`eval`] over the `lobe-eval` columns `[ax, ay, az, s, e, vx, vy, vz] → out`:
/// `out[i] = eval(lobe i, v i)`. Any length (the tail is padded with the padding lobe of
/// [`LobeX8`] and direction [`PAD_VEC3`]); runs on the build's widest
/// vector (16 lanes with AVX-512F, else 8), same results.
///
/// # Panics
/// If the nine columns do not all have the same length.
pub fn eval_slices(
    axis: [&[f32]; 3],
    scale: &[f32],
    exponent: &[f32],
    v: [&[f32]; 3],
    out: &mut [f32],
) {
    drive::<SliceVec, _, 8, 1>(
        "lobe::eval_slices",
        &EvalK,
        [axis[0], axis[1], axis[2], scale, exponent, v[0], v[1], v[2]],
        [out],
    );
}

/// [`integral`] over the `lobe-integral` columns `[e, s] → out`. Any length (tail padded
/// with [`PAD_F32`]); runs on the build's widest vector, same results.
///
/// # Panics
/// If the three columns do not all have the same length.
pub fn integral_slices(exponent: &[f32], scale: &[f32], out: &mut [f32]) {
    drive::<SliceVec, _, 2, 1>(
        "lobe::integral_slices",
        &IntegralK,
        [exponent, scale],
        [out],
    );
}
