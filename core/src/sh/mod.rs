//! Real spherical harmonics (HVL paper, eq. 7–8): evaluation of all `n²` functions of the
//! first `n` bands at a direction, for any `n ≤ MAX_BANDS`.
//!
//! ## Convention
//!
//! `Y_l^m` for `l = 0..n−1`, `m = −l..l`, at flat index `l² + l + m` ([`index`]), with the
//! Condon–Shortley phase in `P_l^m`:
//!
//! ```text
//!   Y_l^m  = √2·K_l^m·P_l^m(cos θ)·cos(mφ)      m > 0
//!   Y_l^0  =    K_l^0·P_l^0(cos θ)
//!   Y_l^−m = √2·K_l^m·P_l^m(cos θ)·sin(mφ)      m > 0,     K_l^m = √((2l+1)/(4π)·(l−m)!/(l+m)!)
//! ```
//!
//! so `Y_1^−1 = −√(3/4π)·y`, `Y_1^0 = √(3/4π)·z`, `Y_1^1 = −√(3/4π)·x`, and the functions are
//! orthonormal over the sphere.
//!
//! ## The recurrence (no factorial, no trigonometry)
//!
//! Write `P_l^m(z)·cos(mφ) = Π̃_l^m(z)·C_m` and `P_l^m(z)·sin(mφ) = Π̃_l^m(z)·S_m` with
//! `C_m + i·S_m = (x + i·y)^m = sin^mθ·e^{imφ}`, so the angular factors are polynomials in
//! `x, y` (`C_{m+1} = x·C_m − y·S_m`, `S_{m+1} = x·S_m + y·C_m`) and `Π_l^m = K_l^m·Π̃_l^m` is a
//! polynomial in `z`. From the textbook recurrences of `P_l^m` —
//! `P_m^m = (−1)^m(2m−1)!!·sin^mθ`, `P_{m+1}^m = (2m+1)·z·P_m^m`,
//! `(l−m)·P_l^m = (2l−1)·z·P_{l−1}^m − (l+m−1)·P_{l−2}^m` — dividing by `sin^mθ` and
//! multiplying by `K_l^m`, the ratios of the `K` collapse into square roots of small
//! rationals and no factorial is ever formed:
//!
//! ```text
//!   Π_0^0 = 1/√(4π)
//!   Π_m^m = −√((2m+1)/(2m))·Π_{m−1}^{m−1}                  (K_m^m/K_{m−1}^{m−1} = 1/√(2m(2m−1))·√((2m+1)/(2m−1)))
//!   Π_{m+1}^m = √(2m+3)·z·Π_m^m                             ((2m+1)·K_{m+1}^m/K_m^m = √(2m+3))
//!   Π_l^m = a_l^m·(z·Π_{l−1}^m − b_l^m·Π_{l−2}^m),  a_l^m = √((4l²−1)/(l²−m²)),  b_l^m = 1/a_{l−1}^m
//! ```
//!
//! The coefficients are computed in `f64` at compile time ([`A`], [`AB`] `= a·b`, [`DIAG`],
//! [`SUB`]: no table file, no square root at run time) and kept in `f64`; a step is
//! `Π_l^m = (a_l^m·z)·Π_{l−1}^m − (a_l^m·b_l^m·r²)·Π_{l−2}^m`, one multiply and one subtract
//! on the dependency chain (see "Two forms" for `r²`). The `f64` direction is consistent
//! (`r² = x² + y² + z²` to `3e-16`): the `1 − z²` that the textbook form eliminates through
//! that identity costs nothing (in `f32` the same inconsistency, a few `1e-8`, is amplified
//! by the Legendre polynomials' large coefficients to `5e-5` at 30 bands near the poles,
//! one reason the recurrence is not run in `f32`). Cost per direction: about seven
//! multiplications per coefficient, one square root and one division.
//!
//! ## Two forms: homogeneous (few bands) and normalised
//!
//! For the unnormalised point `(x, y, z)`, `r² = x² + y² + z²`, let `Q_l^m = r^{l−m}·Π_l^m(z/r)`.
//! Multiplying the recurrence by `r^{l−m}` gives `Q_m^m = Π_m^m`,
//! `Q_{m+1}^m = √(2m+3)·z·Q_m^m` and `Q_l^m = (a·z)·Q_{l−1}^m − (a·b·r²)·Q_{l−2}^m`; and
//! `r^m·C_m(x/r, y/r) = C_m(x, y)`. So the recurrence on the raw point gives `r^l·Y_l^m`,
//! and each value times `r^−l` is `Y_l^m` (on the unit sphere, `r = 1`, it is the plain
//! recurrence). The recurrence therefore need not wait for `1/r`: the square root and the
//! division run beside it, and meet it in one product per value. For a few bands the evaluation's time
//! is that latency, and the homogeneous form ([`point`], through
//! [`HOMOGENEOUS_MAX_BANDS`] = 6) is faster; for more bands it is bound by its operation
//! count, and the normalised form ([`Point::normalized`]: the same code on `(x, y, z)/r`
//! with `r² = r^−l = 1`, whose products by 1 are exact and fold away) saves that product.
//! [`form`] picks one per band count; both are within the same bound of the reference
//! (tested at every length an `f32` vector can have).
//!
//! **Precision: `f64` inside, `f32` in and out.** The crate's kernels compute in `f32`; this
//! one normalises the `f32` direction in `f64`, runs its recurrence in `f64` with `f64`
//! coefficients and rounds each output once. In `f32` the rounding errors of the
//! three-term recurrence grow like `l²` (measured `3.1e-5` at band 29, `1e-5` only through
//! band 17), which misses the `1e-5` target; an `f32` normalisation of the direction alone
//! (an angular error of `6e-8`, times the slope `~l·|Y|`) costs `3e-6` at band 29, and `f32`
//! coefficients another `1e-6`. In `f64` all three are negligible and what remains is the
//! rounding of the output (`1.1e-7` through band 29). On x86-64 and AArch64 a scalar `f64`
//! multiply-add costs what an `f32` one does.
//!
//! **Exact cases.** At the poles (`x = y = 0`) every `C_m`, `S_m` with `m ≥ 1` is exactly 0,
//! so every `m ≠ 0` function is exactly 0; at the equator (`z = 0`) the recurrence gives
//! exactly 0 wherever `l − m` is odd (`P_l^m(0) = 0`), because `z·Π = 0` and the other term
//! is a multiple of an exact 0.
//!
//! **Range.** `|Π_l^m|` stays below `10²¹` through 128 bands (its largest value is at the
//! poles, `K_l^m·(l+m)!/(2^m·m!·(l−m)!)`) and `|C_m|, |S_m| ≤ 1`, so every value is finite
//! for every finite direction (tested through [`MAX_BANDS`] bands).
//!
//! ## Accuracy
//!
//! Against the independent `f64` reference of `steradian-reference` (factorial
//! normalisation, the unnormalised recurrence, `cos(mφ)` from `atan2`) at the exact
//! direction of the input, over 2000 random directions and the hard cases (poles, equator,
//! 1e-7 from the poles), the largest absolute error in band `l` is within
//! [`eval_abs_error`]`(l) = 1e-7 + 1e-8·l`: below `4e-7` through 30 bands (tests in this
//! module; measured 6e-8 at band 10, 1.1e-7 at band 28).
//!
//! ## Bad input
//!
//! The direction need not be unit: `r²` of no `f32` vector overflows or underflows in
//! `f64`, nor do `r^l`, `r^−l` through 6 bands. The zero vector evaluates at the pole `+z`; a
//! non-finite direction gives NaN in every value. A band count above [`MAX_BANDS`] or an
//! output slice shorter than `n²` is an error, not a panic.
//!
//! # References
//!
//! - P. Mézières, F. Desrichard, D. Vanderhaeghe, M. Paulin, "Harmonics Virtual Lights:
//!   fast projection of luminance field on spherical harmonics for efficient rendering",
//!   *Computer Graphics Forum* 41(6), 2022. DOI: 10.1111/cgf.14564 (arXiv: 2201.01487).
//!   Equation numbers in this folder are the arXiv version's.

pub mod brdf;
pub mod cap;
pub mod convolve;
pub mod hvl;
pub mod irradiance;
pub mod light;
pub mod rotate;
#[rustfmt::skip]
mod fixed;
pub mod window;

use crate::math;
use crate::{Error, Vec3};
use glam::DVec3;

/// Largest band count the recurrence tables cover (`MAX_BANDS²` = 16 384 coefficients).
pub const MAX_BANDS: usize = 128;

/// `Y_0^0 = 1/√(4π)`.
pub const Y00: f32 = 0.282_094_8;

/// `Y_0^0 = 1/√(4π)` in `f64`, the recurrence's start.
pub const Y00_F64: f64 = 0.282_094_791_773_878_14;

/// The flat index `l² + l + m` of `Y_l^m` (`|m| ≤ l`).
#[inline]
pub const fn index(l: usize, m: isize) -> usize {
    (l * l + l).wrapping_add_signed(m)
}

/// Number of coefficients of `bands` bands, `bands²`.
#[inline]
pub const fn coefficients(bands: usize) -> usize {
    bands * bands
}

/// The largest absolute error of [`eval_into`] in band `l` against the `f64` reference at
/// the exact direction of the input (module docs): `1e-7 + 1e-8·l`, so `4e-7` at band 29,
/// 25× inside the `1e-5` the kernel is asked for (measured: 1.5e-8 at `l = 0`, 6e-8 at 10,
/// 1.1e-7 at 28; the `f32` rounding of the output is most of it). Tested per band.
pub fn eval_abs_error(l: usize) -> f32 {
    1.0e-7 + 1.0e-8 * l as f32
}

// ---- Compile-time coefficients -----------------------------------------------------------

/// `√x` for `x ≥ 0` in a `const` context, correctly rounded: Newton's iteration from the
/// exponent-halved guess, then the last ulp settled by the exact residual `x − r²` (Dekker's
/// exact square): `r` is the rounding of `√x` exactly when `x` lies between the squares of
/// the midpoints `r ± u/2`, i.e. `−(r·u⁻ − u⁻²/4) ≤ x − r² ≤ r·u + u²/4` (`u`, `u⁻` the ulps
/// above and below `r`). Tested against `f64::sqrt` for every table entry.
const fn sqrt_const(x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    // Halve the exponent for the first guess.
    let bits = x.to_bits();
    let mut r = f64::from_bits((bits >> 1) + (1023u64 << 51));
    let mut k = 0;
    while k < 8 {
        r = 0.5 * (r + x / r);
        k += 1;
    }
    let mut k = 0;
    while k < 4 {
        let e = residual(x, r);
        let up = f64::from_bits(r.to_bits() + 1) - r;
        let down = r - f64::from_bits(r.to_bits() - 1);
        if e > r * up + 0.25 * up * up {
            r += up;
        } else if -e > r * down - 0.25 * down * down {
            r -= down;
        } else {
            break;
        }
        k += 1;
    }
    r
}

/// `x − r²` with `r²` formed exactly as `p + q` (Dekker's split into 26-bit halves).
const fn residual(x: f64, r: f64) -> f64 {
    let c = 134_217_729.0 * r; // 2^27 + 1
    let hi = c - (c - r);
    let lo = r - hi;
    let p = r * r;
    let q = ((hi * hi - p) + 2.0 * hi * lo) + lo * lo;
    (x - p) - q
}

/// Entries of a lower-triangular `(l, m)` table, `0 ≤ m ≤ l < MAX_BANDS`.
const TRI: usize = MAX_BANDS * (MAX_BANDS + 1) / 2;

/// The position of `(l, m)`, `m ≤ l`, in the triangular tables [`A`] and [`AB`].
#[inline(always)]
pub const fn tri(l: usize, m: usize) -> usize {
    l * (l + 1) / 2 + m
}

const fn table_a() -> [f64; TRI] {
    let mut t = [0.0f64; TRI];
    let mut l = 2;
    while l < MAX_BANDS {
        let mut m = 0;
        while m + 2 <= l {
            let (lf, mf) = (l as f64, m as f64);
            t[tri(l, m)] = sqrt_const((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf));
            m += 1;
        }
        l += 1;
    }
    t
}

const fn table_ab() -> [f64; TRI] {
    let mut t = [0.0f64; TRI];
    let mut l = 2;
    while l < MAX_BANDS {
        let mut m = 0;
        while m + 2 <= l {
            let (lf, l1, mf) = (l as f64, (l - 1) as f64, m as f64);
            // a·b = √((4l²−1)·((l−1)²−m²) / ((l²−m²)·(4(l−1)²−1))): integers below 2^53,
            // one rounding of the quotient, one of the root.
            t[tri(l, m)] = sqrt_const(
                ((4.0 * lf * lf - 1.0) * (l1 * l1 - mf * mf))
                    / ((lf * lf - mf * mf) * (4.0 * l1 * l1 - 1.0)),
            );
            m += 1;
        }
        l += 1;
    }
    t
}

const fn table_diag() -> [f64; MAX_BANDS] {
    let mut t = [0.0f64; MAX_BANDS];
    let mut m = 1;
    while m < MAX_BANDS {
        let mf = m as f64;
        t[m] = -sqrt_const((2.0 * mf + 1.0) / (2.0 * mf));
        m += 1;
    }
    t
}

const fn table_sub() -> [f64; MAX_BANDS] {
    let mut t = [0.0f64; MAX_BANDS];
    let mut m = 0;
    while m < MAX_BANDS {
        t[m] = sqrt_const(2.0 * m as f64 + 3.0);
        m += 1;
    }
    t
}

/// `a_l^m = √((4l²−1)/(l²−m²))` at `tri(l, m)` for `l ≥ m + 2` (0 elsewhere).
pub static A: [f64; TRI] = table_a();
/// `a_l^m·b_l^m = √((4l²−1)·((l−1)²−m²) / ((l²−m²)·(4(l−1)²−1)))` at `tri(l, m)` for
/// `l ≥ m + 2` (0 elsewhere): the recurrence's second coefficient, `b_l^m = 1/a_{l−1}^m`.
pub static AB: [f64; TRI] = table_ab();
/// `−√((2m+1)/(2m))` at `m ≥ 1`: `Π_m^m = DIAG[m]·Π_{m−1}^{m−1}`.
pub static DIAG: [f64; MAX_BANDS] = table_diag();
/// `√(2m+3)`: `Π_{m+1}^m = SUB[m]·z·Π_m^m`.
pub static SUB: [f64; MAX_BANDS] = table_sub();

// ---- Evaluation --------------------------------------------------------------------------

/// `d` normalised in `f64` (so the direction is the input's to `3e-16`, not to the `6e-8`
/// of an `f32` unit vector, which alone would cost `3e-6` at 30 bands); the zero vector →
/// `+z`; NaN for a non-finite component: [`point`]`(d).normalized().p`, for the SH kernels
/// that need the direction itself (convolution, irradiance).
#[inline]
pub fn unit_direction(d: Vec3) -> DVec3 {
    point(d).normalized().p
}

/// The point the recurrence of [`eval_into`] runs on (module docs, "Two forms"): `p` is `d`
/// in `f64`, `r2 = |p|²` summed left to right, `inv = 1/√r2` (one correctly rounded square
/// root, one division). The zero vector → `+z` (`r2 = inv = 1`); a non-finite component →
/// NaN everywhere. `r2` of an `f32` vector cannot overflow or underflow in `f64`
/// (`3·f32::MAX² ≈ 3.5e77`, the smallest subnormal squared `2e-90`), so no pre-scaling is
/// needed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// The direction, unnormalised.
    pub p: DVec3,
    /// `|p|²`.
    pub r2: f64,
    /// `1/√r2`.
    pub inv: f64,
}

/// [`Point`] of `d`: the operations its SIMD twin (`steradian_simd::sh`) repeats on each
/// lane.
#[inline]
pub fn point(d: Vec3) -> Point {
    let (x, y, z) = (f64::from(d.x), f64::from(d.y), f64::from(d.z));
    let r2 = x * x + y * y + z * z;
    if r2 == 0.0 {
        return Point {
            p: DVec3::Z,
            r2: 1.0,
            inv: 1.0,
        };
    }
    if !r2.is_finite() {
        return Point {
            p: DVec3::splat(f64::NAN),
            r2: f64::NAN,
            inv: f64::NAN,
        };
    }
    Point {
        p: DVec3::new(x, y, z),
        r2,
        inv: 1.0 / math::sqrt64(r2),
    }
}

impl Point {
    /// The same direction normalised, `p·inv` with `r2 = inv = 1`: the homogeneous
    /// recurrence on it is the normalised one (`1·Π`, `Π·1` are exact), bit for bit.
    #[inline(always)]
    pub fn normalized(self) -> Point {
        Point {
            p: self.p * self.inv,
            r2: 1.0,
            inv: 1.0,
        }
    }
}

/// The most bands evaluated in the homogeneous form (module docs, "Two forms"): where the
/// evaluation is short its time is the latency of the normalisation followed by the
/// recurrence's chain, and the homogeneous form runs the two side by side; beyond, the
/// evaluation is bound by its operation count and the normalised form, one multiply per
/// value fewer, is faster (`steradian report --section sh`). At most 7, so that `r^l` and
/// `r^−l`, `l ≤ 6`, of any non-zero finite `f32` vector (`|d|` from `1.4e-45` to `5.9e38`)
/// stay normal `f64`s: `1.4e-45⁶ ≈ 7e-271`, `5.9e38⁶ ≈ 4e232`.
pub const HOMOGENEOUS_MAX_BANDS: usize = 6;
const _: () = assert!(HOMOGENEOUS_MAX_BANDS <= 7);

/// The point `pt` (of [`point`]) in the form [`eval_into`] uses for `bands` bands:
/// homogeneous through [`HOMOGENEOUS_MAX_BANDS`], [`Point::normalized`] beyond. Called with a
/// constant band count, the choice and the normalised form's products by 1 fold away.
#[inline(always)]
pub fn form(pt: Point, bands: usize) -> Point {
    if bands <= HOMOGENEOUS_MAX_BANDS {
        pt
    } else {
        pt.normalized()
    }
}

/// Orders `m` whose recurrences in `l` run together in one pass of [`eval_into`] (and of
/// its SIMD twin): four independent chains hide the latency of each one's multiply and
/// subtract. Part of the kernel's definition only through speed: every value is computed by
/// the same operations whatever the grouping.
pub const CHAINS: usize = 4;

/// The most orders one pass takes: the last pass takes all that remain when they are at
/// most `CHAINS + 2`, so that no pass is left with one or two short chains.
pub const MAX_GROUP: usize = CHAINS + 2;

/// The number of orders the next pass takes when `left` remain.
#[inline(always)]
pub const fn group(left: usize) -> usize {
    if left <= MAX_GROUP { left } else { CHAINS }
}

/// One step of the homogeneous recurrence,
/// `Π_l^m = (a_l^m·z)·Π_{l−1}^m − (a_l^m·b_l^m·r²)·Π_{l−2}^m` at `k = tri(l, m)`: the
/// coefficient products are off the chain, so each step adds one multiply and one subtract
/// of latency.
#[inline(always)]
fn step(k: usize, z: f64, r2: f64, q1: f64, q2: f64) -> f64 {
    A[k] * z * q1 - AB[k] * r2 * q2
}

/// The recurrence over `bands` bands at the point `pt` (of either form, module docs) into
/// `out[..bands²]` (`bands ≤ MAX_BANDS`, `out.len() ≥ bands²`: checked by the callers).
/// Shared by the fixed-size and the dynamic entry points, so both give the same bits.
///
/// The recurrence runs in `f64`, one rounding to `f32` per output (module docs,
/// "Accuracy"); each value is `q·S_m`, then `q·C_m`, times `r^−l` (the one product that
/// waits for the normalisation).
///
/// **[`CHAINS`] orders at a time.** The recurrence in `l` is a chain of dependent
/// operations per order `m`, so the orders `m0 .. m0 + 3` run in the same loop over `l`,
/// their steps independent (the last pass takes up to [`MAX_GROUP`] orders, see
/// [`group`]). Order `m`'s chain starts at `Π_m^m` (`Π_0^0` for `m = 0`,
/// `√2·Π_m^m` for `m ≥ 1`, the `√2` of the real functions carried by the chain) and
/// `Π_{m+1}^m = √(2m+3)·z·Π_m^m`; every value goes out as `q·S_m` at `l² + l − m` and then
/// `q·C_m` at `l² + l + m` (for `m = 0`, `C = 1` and `S = 0` make the second write the
/// value itself). The SIMD twin does the same operations in the same order and is tested
/// bit for bit.
///
/// `H` is the form: `false` skips the products by `r^−l`, all exactly 1 on a normalised
/// point, which the compiler cannot see through the loop (same bits, fewer operations).
// `l` is the band: it indexes the coefficient tables and the output as well as `il`.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn fill<const H: bool>(pt: Point, bands: usize, out: &mut [f32]) {
    let out = &mut out[..bands * bands];
    if bands == 0 {
        return;
    }
    let (x, y, z, r2, inv) = (pt.p.x, pt.p.y, pt.p.z, pt.r2, pt.inv);
    // r^−l by `il[l] = il[l−1]·inv` from `il[0] = 1` (the order the generated code
    // repeats); unused, and so not formed, in the normalised form.
    let mut il = [1.0f64; MAX_BANDS];
    if H {
        for l in 1..bands {
            il[l] = il[l - 1] * inv;
        }
    }
    let (mut pmm, mut c, mut s) = (Y00_F64, 1.0f64, 0.0f64);
    let mut m0 = 0;
    while m0 < bands {
        let g = group(bands - m0);
        // Each order's angular factors and the chain's first value.
        let (mut cc, mut ss) = ([1.0f64; MAX_GROUP], [0.0f64; MAX_GROUP]);
        let (mut q1, mut q2) = ([0.0f64; MAX_GROUP], [0.0f64; MAX_GROUP]);
        for j in 0..g {
            let m = m0 + j;
            if m > 0 {
                pmm *= DIAG[m];
                (c, s) = (x * c - y * s, x * s + y * c);
            }
            (cc[j], ss[j]) = (c, s);
            q1[j] = if m == 0 {
                Y00_F64
            } else {
                core::f64::consts::SQRT_2 * pmm
            };
        }
        // The first rows, one chain after the other: chain j starts at row m0 + j and
        // steps from row m0 + j + 2.
        let head = (m0 + g + 1).min(bands);
        for j in 0..g {
            let m = m0 + j;
            let (mut p1, mut p2) = (q1[j], 0.0);
            for l in m..head {
                let q = if l == m {
                    p1
                } else if l == m + 1 {
                    SUB[m] * z * p1
                } else {
                    step(tri(l, m), z, r2, p1, p2)
                };
                if l > m {
                    (p2, p1) = (p1, q);
                }
                let at = l * l + l;
                out[at - m] = scaled::<H>(q * ss[j], il[l]) as f32;
                out[at + m] = scaled::<H>(q * cc[j], il[l]) as f32;
            }
            (q1[j], q2[j]) = (p1, p2);
        }
        // The rest: every chain steps (only groups of `CHAINS` reach here: the last group,
        // of any other size, takes every remaining order, so its head ends at `bands`).
        for l in head..bands {
            let at = l * l + l;
            let k = tri(l, m0);
            let (a, ab) = (&A[k..k + CHAINS], &AB[k..k + CHAINS]);
            let (mut sin, mut cos) = ([0.0f32; CHAINS], [0.0f32; CHAINS]);
            for j in 0..CHAINS {
                let q = a[j] * z * q1[j] - ab[j] * r2 * q2[j];
                (q2[j], q1[j]) = (q1[j], q);
                sin[CHAINS - 1 - j] = scaled::<H>(q * ss[j], il[l]) as f32;
                cos[j] = scaled::<H>(q * cc[j], il[l]) as f32;
            }
            // Orders m0 + 3 … m0 below the centre, m0 … m0 + 3 above (they meet at the
            // centre only for m0 = 0, where the cosine part, written last, is the value).
            let lo = at - m0 - (CHAINS - 1);
            out[lo..lo + CHAINS].copy_from_slice(&sin);
            out[at + m0..at + m0 + CHAINS].copy_from_slice(&cos);
        }
        m0 += g;
    }
    // `+ 0·z`: NaN for a NaN direction (crate convention), exactly `Y00` otherwise.
    out[0] = (Y00_F64 + 0.0 * z) as f32;
}

/// [`fill`] in the homogeneous form for the counts without straight-line code below
/// [`HOMOGENEOUS_MAX_BANDS`] (0 and 1 bands), out of line: a second inlined copy of the loop
/// made the normalised one slower at 20 bands (`steradian report --section sh`).
#[inline(never)]
fn fill_short(pt: Point, bands: usize, out: &mut [f32]) {
    fill::<true>(pt, bands, out);
}

/// `v·il` in the homogeneous form, `v` in the normalised one (where `il = 1`).
#[inline(always)]
fn scaled<const H: bool>(v: f64, il: f64) -> f64 {
    if H { v * il } else { v }
}

/// All `bands²` real SH at `dir` (any non-zero length; module docs) into `out[..bands²]`.
///
/// Errors: `bands > MAX_BANDS`, or `out` shorter than `bands²`.
pub fn eval_into(dir: Vec3, bands: usize, out: &mut [f32]) -> Result<(), Error> {
    check_shape(bands, out.len())?;
    fill_any(point(dir), bands, out);
    Ok(())
}

/// [`fill`], through the straight-line code of `fixed` (generated by the harness from
/// this recurrence: each value by the same operations, bit-identical, tested) for the band
/// counts renderers use most, 2–10.
#[inline(always)]
fn fill_any(pt: Point, bands: usize, out: &mut [f32]) {
    match bands {
        2 => fixed::fill_2(form(pt, 2), out),
        3 => fixed::fill_3(form(pt, 3), out),
        4 => fixed::fill_4(form(pt, 4), out),
        5 => fixed::fill_5(form(pt, 5), out),
        6 => fixed::fill_6(form(pt, 6), out),
        7 => fixed::fill_7(form(pt, 7), out),
        8 => fixed::fill_8(form(pt, 8), out),
        9 => fixed::fill_9(form(pt, 9), out),
        10 => fixed::fill_10(form(pt, 10), out),
        _ if bands > HOMOGENEOUS_MAX_BANDS => fill::<false>(pt.normalized(), bands, out),
        _ => fill_short(pt, bands, out),
    }
}

/// The zonal functions `Y_l^0`, `l < bands`, at `dir` into `out[..bands]`: the `m = 0`
/// chain of [`eval_into`]'s recurrence alone (`Π_0^0`, `Π_1^0 = √3·z·Π_0^0`, then
/// `step`, each times `r^−l`), the same operations on the same point, so each value is
/// bit-identical to `eval_into`'s at index `l² + l` (tested). What a receiver whose
/// coefficients are zonal around its normal needs (`sh::hvl::contribution_zonal`): `bands`
/// values instead of `bands²`.
///
/// Errors: `bands > MAX_BANDS`, or `out` shorter than `bands`.
pub fn eval_zonal_into(dir: Vec3, bands: usize, out: &mut [f32]) -> Result<(), Error> {
    check_shape(bands, usize::MAX)?;
    if out.len() < bands {
        return Err(Error::OutOfRange {
            what: "SH output length",
            value: out.len() as f32,
            min: bands as f32,
            max: f32::INFINITY,
        });
    }
    if bands == 0 {
        return Ok(());
    }
    let pt = form(point(dir), bands);
    let (z, r2) = (pt.p.z, pt.r2);
    out[0] = (Y00_F64 + 0.0 * z) as f32;
    let (mut q1, mut q2) = (Y00_F64, 0.0f64);
    let mut il = 1.0f64;
    for (l, o) in out[..bands].iter_mut().enumerate().skip(1) {
        let q = if l == 1 {
            SUB[0] * z * q1
        } else {
            step(tri(l, 0), z, r2, q1, q2)
        };
        (q2, q1) = (q1, q);
        il *= pt.inv;
        *o = (q * il) as f32;
    }
    Ok(())
}

/// The checks of every SH entry point: `bands ≤ MAX_BANDS` and an output of at least
/// `bands²` values (`len`).
pub fn check_shape(bands: usize, len: usize) -> Result<(), Error> {
    if bands > MAX_BANDS {
        return Err(Error::OutOfRange {
            what: "SH bands",
            value: bands as f32,
            min: 0.0,
            max: MAX_BANDS as f32,
        });
    }
    if len < bands * bands {
        return Err(Error::OutOfRange {
            what: "SH output length",
            value: len as f32,
            min: (bands * bands) as f32,
            max: f32::INFINITY,
        });
    }
    Ok(())
}

/// The band count `n` of a coefficient vector of length `n²`; an error for a length that is
/// not a square.
pub fn bands_of(len: usize) -> Result<usize, Error> {
    let mut n = math::sqrt64(len as f64) as usize;
    while n * n > len {
        n -= 1;
    }
    while (n + 1) * (n + 1) <= len {
        n += 1;
    }
    if n * n != len {
        return Err(Error::OutOfRange {
            what: "SH coefficient count (must be a square n²)",
            value: len as f32,
            min: 0.0,
            max: (crate::sh::MAX_BANDS * crate::sh::MAX_BANDS) as f32,
        });
    }
    check_shape(n, len)?;
    Ok(n)
}

/// All `C = n²` real SH of the first `n` bands at `dir` (module docs), as an array: the
/// same code as [`eval_into`] (the generated straight-line code for 2–10 bands, the loop
/// beyond; same bits) without the runtime shape check. `C` must be a perfect square of at
/// most `MAX_BANDS²` (checked at compile time).
#[inline]
pub fn eval_fixed<const C: usize>(dir: Vec3) -> [f32; C] {
    const {
        assert!(
            is_square(C) && C <= MAX_BANDS * MAX_BANDS,
            "C must be n² with n ≤ MAX_BANDS"
        )
    };
    let mut out = [0.0f32; C];
    fill_any(point(dir), isqrt(C), &mut out);
    out
}

/// `⌊√c⌋` in a `const` context.
const fn isqrt(c: usize) -> usize {
    let mut n = 0;
    while (n + 1) * (n + 1) <= c {
        n += 1;
    }
    n
}

/// Whether `c` is a perfect square.
const fn is_square(c: usize) -> bool {
    let n = isqrt(c);
    n * n == c
}

/// Uniform values in `[−1, 1)` from a 64-bit LCG: the one generator of the SH tests (the
/// same seed gives the same inputs on every machine).
#[cfg(test)]
pub(crate) fn test_rng(seed: u64) -> impl FnMut() -> f32 {
    let mut s = seed;
    move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    }
}

#[cfg(all(test, feature = "alloc"))]
#[allow(clippy::needless_range_loop)] // (l, m) index several tables at once
mod tests {
    use super::*;
    use alloc::vec;
    use alloc::vec::Vec;
    extern crate std;
    use steradian_reference::sh as reference;

    fn eval(d: Vec3, n: usize) -> Vec<f32> {
        let mut out = vec![0.0; n * n];
        eval_into(d, n, &mut out).unwrap();
        out
    }

    /// Directions: random, the poles, the equator, 1e-7 from the poles, the axes.
    fn directions() -> Vec<Vec3> {
        let mut v = vec![
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            -Vec3::Y,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(1e-7, 0.0, 1.0),
            Vec3::new(0.0, -1e-7, -1.0),
            Vec3::new(0.3, -0.4, 1e-7),
        ];
        let mut next = test_rng(0x5eed);
        while v.len() < 2000 {
            let d = Vec3::new(next(), next(), next());
            if d.length_squared() > 1e-4 && d.length_squared() <= 1.0 {
                v.push(d.normalize());
            }
        }
        v
    }

    #[test]
    fn compile_time_coefficients_are_the_correctly_rounded_roots() {
        for l in 2..MAX_BANDS {
            for m in 0..=l - 2 {
                let (lf, mf) = (l as f64, m as f64);
                let a = ((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf)).sqrt();
                let l1 = lf - 1.0;
                let ab = (((4.0 * lf * lf - 1.0) * (l1 * l1 - mf * mf))
                    / ((lf * lf - mf * mf) * (4.0 * l1 * l1 - 1.0)))
                    .sqrt();
                assert_eq!((A[tri(l, m)], AB[tri(l, m)]), (a, ab), "l {l} m {m}");
            }
        }
        for m in 1..MAX_BANDS {
            let mf = m as f64;
            assert_eq!(DIAG[m], -((2.0 * mf + 1.0) / (2.0 * mf)).sqrt());
        }
        for m in 0..MAX_BANDS {
            assert_eq!(SUB[m], (2.0 * m as f64 + 3.0).sqrt());
        }
    }

    #[test]
    fn first_bands_are_the_closed_forms() {
        let d = Vec3::new(0.48, -0.6, 0.64);
        let y = eval(d, 3);
        let k1 = (3.0 / (4.0 * core::f64::consts::PI)).sqrt();
        let k2 = 0.5 * (15.0 / core::f64::consts::PI).sqrt();
        let (x, yy, z) = (0.48f64, -0.6f64, 0.64f64);
        let want = [
            0.5 / core::f64::consts::PI.sqrt(),
            -k1 * yy,
            k1 * z,
            -k1 * x,
            k2 * x * yy,
            -k2 * yy * z,
            0.25 * (5.0 / core::f64::consts::PI).sqrt() * (3.0 * z * z - 1.0),
            -k2 * x * z,
            0.5 * k2 * (x * x - yy * yy),
        ];
        for (k, (g, w)) in y.iter().zip(want).enumerate() {
            assert!((*g as f64 - w).abs() < 1e-6, "index {k}: {g} vs {w}");
        }
    }

    /// The homogeneous form (1–6 bands) and the first normalised count (7) within the
    /// per-band bound of the reference, at unit directions and at the extreme lengths of
    /// `f32` vectors (where `r^l`, `r^−l` are largest and smallest), the zero vector at `+z`.
    #[test]
    fn both_forms_within_the_bound_at_any_length() {
        let mut worst = 0.0f64;
        for n in 1..=HOMOGENEOUS_MAX_BANDS + 1 {
            let tiny = f32::from_bits(1);
            // The ends of the range the docs quote: the smallest subnormal and f32::MAX.
            let extremes = [
                Vec3::new(tiny, 0.0, 0.0),
                Vec3::new(0.0, -tiny, tiny),
                Vec3::splat(tiny),
                Vec3::new(f32::MAX, 0.0, 0.0),
                Vec3::new(f32::MAX, -f32::MAX, f32::MAX),
            ];
            let scaled = directions()
                .into_iter()
                .step_by(4)
                .flat_map(|d| [1.0f32, 1e-40, 1e-20, 3e18, 1e38].map(|s| d * s));
            for v in scaled.chain(extremes) {
                let got = eval(v, n);
                let want = reference::eval([v.x as f64, v.y as f64, v.z as f64], n);
                for l in 0..n {
                    for m in -(l as isize)..=l as isize {
                        let i = index(l, m);
                        let err = (got[i] as f64 - want[i]).abs();
                        worst = worst.max(err);
                        assert!(
                            err <= eval_abs_error(l) as f64,
                            "{v:?} n {n} ({l}, {m}): {} vs {}",
                            got[i],
                            want[i]
                        );
                    }
                }
            }
            assert_eq!(eval(Vec3::ZERO, n), eval(Vec3::Z, n));
            assert!(
                eval(Vec3::new(f32::NAN, 0.0, 1.0), n)
                    .iter()
                    .all(|v| v.is_nan())
            );
            assert!(
                eval(Vec3::new(f32::INFINITY, 0.0, 1.0), n)
                    .iter()
                    .all(|v| v.is_nan())
            );
        }
        std::println!("both forms, 1-7 bands, any length: worst {worst:e}");
    }

    /// The stated per-band bound against the independent f64 reference, and 1e-5 through
    /// 30 bands.
    #[test]
    fn within_the_per_band_bound_of_the_reference_through_30_bands() {
        let n = 30;
        let mut worst = vec![0.0f64; n];
        for d in directions() {
            let got = eval(d, n);
            let want = reference::eval([d.x as f64, d.y as f64, d.z as f64], n);
            for l in 0..n {
                for m in -(l as isize)..=l as isize {
                    let i = index(l, m);
                    worst[l] = worst[l].max((got[i] as f64 - want[i]).abs());
                }
            }
        }
        std::println!(
            "max error per band: {:?}",
            worst.iter().map(|w| *w as f32).collect::<Vec<_>>()
        );
        for (l, w) in worst.iter().enumerate() {
            assert!(
                *w <= eval_abs_error(l) as f64,
                "band {l}: {w:e} > {:e}",
                eval_abs_error(l)
            );
            assert!(*w <= 1e-5, "band {l}: {w:e}");
        }
        // The measured figures the docs and the README quote (deterministic: f64 inside,
        // a fixed direction set).
        assert!(
            worst[10] <= 7e-8 && worst[28] <= 1.2e-7,
            "{:e} {:e}",
            worst[10],
            worst[28]
        );
    }

    #[test]
    fn poles_and_equator_are_exact() {
        let n = 40;
        for pole in [Vec3::Z, -Vec3::Z] {
            let y = eval(pole, n);
            let want = reference::eval([0.0, 0.0, pole.z as f64], n);
            for l in 0..n {
                for m in -(l as isize)..=l as isize {
                    if m != 0 {
                        assert_eq!(y[index(l, m)], 0.0, "pole {pole} l {l} m {m}");
                    }
                }
                let z = y[index(l, 0)] as f64;
                let e = (z - want[index(l, 0)]).abs();
                assert!(e <= eval_abs_error(l) as f64, "pole l {l}: {e:e}");
            }
        }
        let y = eval(Vec3::new(0.6, 0.8, 0.0), n);
        for l in 0..n {
            for m in -(l as isize)..=l as isize {
                if (l as isize - m.abs()) % 2 == 1 {
                    assert_eq!(y[index(l, m)], 0.0, "equator l {l} m {m}");
                }
            }
        }
    }

    #[test]
    fn finite_everywhere_through_max_bands() {
        let n = MAX_BANDS;
        let mut out = vec![0.0; n * n];
        for d in directions().into_iter().take(200) {
            eval_into(d, n, &mut out).unwrap();
            assert!(out.iter().all(|v| v.is_finite()), "{d}");
        }
    }

    #[test]
    fn fixed_size_path_gives_the_same_bits() {
        for d in directions().into_iter().take(100) {
            let a: [f32; 16] = eval_fixed(d);
            assert_eq!(a.as_slice(), eval(d, 4).as_slice());
            let b: [f32; 100] = eval_fixed(d);
            assert_eq!(b.as_slice(), eval(d, 10).as_slice());
        }
    }

    /// [`directions`] and the inputs the kernels special-case: zero, a non-unit pole,
    /// NaN, and components near the bottom of the `f32` range.
    fn hard_directions() -> Vec<Vec3> {
        let mut dirs = directions();
        dirs.extend([
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, -3.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(f32::NAN, 0.0, 1.0),
            Vec3::new(1e-30, -1e-30, 1e-30),
        ]);
        dirs
    }

    #[test]
    fn straight_line_code_is_the_recurrence_bit_for_bit() {
        let dirs = hard_directions();
        for n in 2..=10usize {
            for &d in &dirs {
                let u = point(d);
                let (mut a, mut b) = (vec![0.0f32; n * n], vec![0.0f32; n * n]);
                // The homogeneous loop on either form (on a normalised point its
                // products by r^−l are by exact 1s).
                fill::<true>(form(u, n), n, &mut a);
                fill_any(u, n, &mut b);
                for (k, (x, y)) in a.iter().zip(&b).enumerate() {
                    assert_eq!(x.to_bits(), y.to_bits(), "{d:?} n {n} index {k}");
                }
            }
            // A short output is left alone, not a panic.
            let mut short = vec![5.0f32; n * n - 1];
            fill_any(point(Vec3::Z), n, &mut short);
            assert!(short.iter().all(|&v| v == 5.0));
        }
    }

    #[test]
    fn zonal_chain_is_eval_into_at_m_zero_bit_for_bit() {
        let dirs = hard_directions();
        for n in [0usize, 1, 2, 3, 5, 10, 30, MAX_BANDS] {
            for &d in &dirs {
                let full = eval(d, n);
                let mut z = vec![7.0f32; n];
                eval_zonal_into(d, n, &mut z).unwrap();
                for (l, v) in z.iter().enumerate() {
                    assert_eq!(v.to_bits(), full[l * l + l].to_bits(), "{d:?} n {n} l {l}");
                }
            }
        }
        let mut short = [0.0f32; 2];
        assert!(eval_zonal_into(Vec3::Z, 3, &mut short).is_err());
        assert!(eval_zonal_into(Vec3::Z, MAX_BANDS + 1, &mut [0.0; 200]).is_err());
    }

    #[test]
    fn non_unit_zero_and_non_finite_directions() {
        let u = eval(Vec3::new(0.48, -0.6, 0.64), 6);
        for k in [1e-30f32, 1e30, f32::MAX] {
            let v = eval(Vec3::new(0.48, -0.6, 0.64) * k, 6);
            for (a, b) in u.iter().zip(&v) {
                assert!((a - b).abs() < 1e-6, "{k}: {a} vs {b}");
            }
        }
        assert_eq!(eval(Vec3::ZERO, 5), eval(Vec3::Z, 5));
        assert!(
            eval(Vec3::new(f32::NAN, 0.0, 1.0), 3)
                .iter()
                .all(|v| v.is_nan())
        );
        assert!(
            eval(Vec3::new(f32::INFINITY, 0.0, 1.0), 3)
                .iter()
                .all(|v| v.is_nan())
        );
        let mut short = [0.0; 8];
        assert!(eval_into(Vec3::Z, 3, &mut short).is_err());
        assert!(eval_into(Vec3::Z, MAX_BANDS + 1, &mut []).is_err());
        assert!(eval_into(Vec3::Z, 0, &mut []).is_ok());
    }
}
