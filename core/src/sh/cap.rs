//! The SH projection of a spherical cap (HVL paper, section 4.2, eq. 12–15): the zonal
//! coefficients of the cap's indicator around `+z`, and their rotation to any axis.
//!
//! ## Zonal coefficients (eq. 12–14), without the cancellation
//!
//! For the cap of half-angle `a` around `+z` and `x = cos a`,
//! `L̃_l = ∫_cap Y_l^0 dω = 2π·K_l^0·∫_0^a P_l(cos θ)·sin θ dθ`, and eq. 13 gives the integral
//! as `(P_{l−1}(x) − P_{l+1}(x))/(2l + 1)`, so eq. 14 reads
//! `L̃_l = √(π/(2l+1))·(P_{l−1}(x) − P_{l+1}(x))` (`√π·(1 − x)` for `l = 0`). For small caps the
//! two Legendre values agree to `l²a²/2` of their size and the difference cancels
//! catastrophically (in `f32` nothing is left below `a ≈ 3e-4`). The Legendre identity
//! `(1 − x²)·P_l′(x) = l(l+1)/(2l+1)·(P_{l−1}(x) − P_{l+1}(x))` removes the subtraction:
//!
//! ```text
//!   L̃_0 = 2√π·sin²(a/2),      L̃_l = √(π(2l+1))·sin²a·P_l′(cos a) / (l(l+1))   (l ≥ 1)
//! ```
//!
//! with `sin²a` and `sin²(a/2)` from `a` itself and `P_l′` by the derivative recurrence
//! `P_{l+1}′ = P_{l−1}′ + (2l+1)·P_l` (`P_0′ = 0`, `P_1′ = 1`), a sum of positive terms near
//! `x = 1`. The recurrences run in `f64` (as the evaluation's, [`crate::sh`]), so every
//! coefficient keeps full `f32` relative accuracy from `a = 1e-4` to `a = π`. A cap beyond
//! the hemisphere is legal; at `a = π` (the whole sphere) `L̃_0 = 2√π` and the others vanish.
//!
//! ## Rotation into SH (eq. 15)
//!
//! The cap around the unit axis `ω` has `L_l^m = √(4π/(2l+1))·Y_l^m(ω)·L̃_l` (the rotation of
//! a zonal function: Funk–Hecke with the addition theorem), with `Y` from
//! [`crate::sh::eval_into`].
//!
//! **Accuracy** (tests below, against the `f64` quadrature of `steradian-reference`): the
//! zonal coefficients within [`ZONAL_REL_ERROR`] relative (or `1e-9` of the cap's solid
//! angle where a coefficient vanishes) for every half-angle from `1e-4` to `π` through 30
//! bands; the rotated coefficients within `eval_abs_error(l)·√(4π/(2l+1))·|L̃_l|` plus that
//! relative error.
//!
//! **Bad input.** The half-angle must lie in `[0, π]` (`0` gives zeros); outside, NaN, a band
//! count above `MAX_BANDS` or a short output slice is an error. The axis follows
//! [`crate::sh::eval_into`] (any length; zero → `+z`).

use crate::math;
use crate::sh::{check_shape, eval_into};
use crate::{Error, Vec3};

/// Relative error bound of [`zonal_into`] per coefficient (`f32` rounding of the `f64`
/// result and of the half-angle's trigonometry).
pub const ZONAL_REL_ERROR: f32 = 4.0e-7;

fn check(half_angle: f32, bands: usize, len: usize, need: usize) -> Result<(), Error> {
    if half_angle.is_nan() {
        return Err(Error::NonFinite {
            what: "cap half-angle",
        });
    }
    if !(0.0..=crate::PI).contains(&half_angle) {
        return Err(Error::OutOfRange {
            what: "cap half-angle",
            value: half_angle,
            min: 0.0,
            max: crate::PI,
        });
    }
    // The band limit as every SH entry point checks it; the output length against `need`
    // (`bands` zonal or `bands²` full coefficients).
    check_shape(bands, usize::MAX)?;
    if len < need {
        return Err(Error::OutOfRange {
            what: "SH output length",
            value: len as f32,
            min: need as f32,
            max: f32::INFINITY,
        });
    }
    Ok(())
}

/// Calls `f(l, L̃_l)` for `l < bands`, the zonal coefficients in `f64` (module docs).
fn zonal_each(half_angle: f32, bands: usize, mut f: impl FnMut(usize, f64)) {
    if bands == 0 {
        return;
    }
    let a = f64::from(half_angle);
    let pi = core::f64::consts::PI;
    let sh = math::sin64(0.5 * a);
    f(0, 2.0 * math::sqrt64(pi) * sh * sh);
    let (s, x) = (math::sin64(a), math::cos64(a));
    let s2 = s * s;
    // P_{l−1}, P_l and P′_{l−1}, P′_l, starting at l = 1.
    let (mut p_prev, mut p) = (1.0f64, x);
    let (mut dp_prev, mut dp) = (0.0f64, 1.0f64);
    for l in 1..bands {
        let lf = l as f64;
        f(
            l,
            math::sqrt64(pi * (2.0 * lf + 1.0)) * s2 * dp / (lf * (lf + 1.0)),
        );
        let p_next = ((2.0 * lf + 1.0) * x * p - lf * p_prev) / (lf + 1.0);
        let dp_next = dp_prev + (2.0 * lf + 1.0) * p;
        (p_prev, p) = (p, p_next);
        (dp_prev, dp) = (dp, dp_next);
    }
}

/// The zonal coefficients `L̃_l = ∫_cap Y_l^0 dω`, `l < bands`, of the cap of half-angle
/// `half_angle` around `+z` into `out[..bands]` (module docs).
///
/// Errors: `half_angle` outside `[0, π]` or NaN, `bands > MAX_BANDS`, `out` shorter than
/// `bands`.
pub fn zonal_into(half_angle: f32, bands: usize, out: &mut [f32]) -> Result<(), Error> {
    check(half_angle, bands, out.len(), bands)?;
    zonal_each(half_angle, bands, |l, v| out[l] = v as f32);
    Ok(())
}

/// The SH coefficients `∫_cap Y_l^m dω` of the cap of half-angle `half_angle` around `axis`
/// into `out[..bands²]` (eq. 15, module docs).
///
/// Errors: as [`zonal_into`] (with `bands²` outputs).
pub fn coefficients_into(
    axis: Vec3,
    half_angle: f32,
    bands: usize,
    out: &mut [f32],
) -> Result<(), Error> {
    check(half_angle, bands, out.len(), bands * bands)?;
    eval_into(axis, bands, out)?;
    band_scales(half_angle, bands, |l, k| {
        for v in &mut out[l * l..(l + 1) * (l + 1)] {
            *v = (f64::from(*v) * k) as f32;
        }
    });
    Ok(())
}

/// Calls `f(l, k_l)` for `l < bands` with `k_l = √(4π/(2l+1))·L̃_l`, the factor that turns
/// the SH basis at the cap's axis into the cap's coefficients of band `l` (eq. 15: rotating
/// a zonal function to the axis `d` multiplies `Y_l^m(d)` by `√(4π/(2l+1))·L̃_l`); the
/// argument is not checked (the callers check it). With the zonal form of the module docs
/// the square roots cancel: `k_0 = 4π·sin²(a/2)`, `k_l = 2π·sin²a·P_l′(cos a)/(l(l+1))`.
/// [`coefficients_into`] and its SIMD twin scale by these same `f64` values, one product
/// and one rounding per coefficient; the twin runs this recurrence on `f64` lanes from
/// [`cap_trig`].
pub fn band_scales(half_angle: f32, bands: usize, mut f: impl FnMut(usize, f64)) {
    if bands == 0 {
        return;
    }
    let [h2, s2, x] = cap_trig(half_angle);
    let pi = core::f64::consts::PI;
    f(0, 4.0 * pi * h2);
    let (mut p_prev, mut p) = (1.0f64, x);
    let (mut dp_prev, mut dp) = (0.0f64, 1.0f64);
    for l in 1..bands {
        let lf = l as f64;
        f(l, 2.0 * pi * s2 * dp / (lf * (lf + 1.0)));
        let p_next = ((2.0 * lf + 1.0) * x * p - lf * p_prev) / (lf + 1.0);
        let dp_next = dp_prev + (2.0 * lf + 1.0) * p;
        (p_prev, p) = (p, p_next);
        (dp_prev, dp) = (dp, dp_next);
    }
}

/// `[sin²(a/2), sin²a, cos a]` of the half-angle `a` in `f64` from one sine and one cosine
/// of `a/2` (`sin a = 2·sin(a/2)·cos(a/2)`, `cos a = 1 − 2·sin²(a/2)`): the start of
/// [`band_scales`], shared with its SIMD twin.
#[inline]
pub fn cap_trig(half_angle: f32) -> [f64; 3] {
    let h = 0.5 * f64::from(half_angle);
    let (sh, ch) = (math::sin64(h), math::cos64(h));
    let s = 2.0 * sh * ch;
    [sh * sh, s * s, 1.0 - 2.0 * sh * sh]
}

/// The checks of [`coefficients_into`] for `bands²` outputs in `len` values: the half-angle
/// in `[0, π]`, `bands ≤ MAX_BANDS`, `len ≥ bands²`.
pub fn check_coefficients(half_angle: f32, bands: usize, len: usize) -> Result<(), Error> {
    check(half_angle, bands, len, bands * bands)
}

#[cfg(all(test, feature = "alloc"))]
#[allow(clippy::needless_range_loop)] // l indexes the kernel's and the reference's bands
mod tests {
    use super::*;
    use crate::sh::{MAX_BANDS, eval_abs_error};
    use alloc::vec;
    use steradian_reference::sh as reference;

    const ANGLES: [f32; 10] = [
        1e-4,
        3e-4,
        1e-3,
        0.01,
        0.1,
        1.0,
        core::f32::consts::FRAC_PI_2,
        2.0,
        3.0,
        core::f32::consts::PI,
    ];

    /// The band factors are `√(4π/(2l+1))` times the zonal coefficients (the square roots
    /// cancel in their closed form), to `f64` rounding: relative, or of the cap's solid
    /// angle where a factor vanishes (`cos a` near 0 comes from `1 − 2·sin²(a/2)`).
    #[test]
    fn band_scales_are_the_rotated_zonal_factors() {
        let n = 30;
        for a in ANGLES {
            let mut zonal = vec![0.0f64; n];
            zonal_each(a, n, |l, z| zonal[l] = z);
            band_scales(a, n, |l, k| {
                let want = (4.0 * core::f64::consts::PI / (2.0 * l as f64 + 1.0)).sqrt() * zonal[l];
                let omega = 4.0 * core::f64::consts::PI * (0.5 * f64::from(a)).sin().powi(2);
                let tol = 1e-12 * want.abs() + 1e-14 * omega;
                assert!((k - want).abs() <= tol, "a {a} l {l}: {k:e} vs {want:e}");
            });
        }
    }

    #[test]
    fn zonal_keeps_relative_accuracy_from_1e_4_rad_to_pi() {
        let n = 30;
        let mut out = vec![0.0; n];
        for a in ANGLES {
            zonal_into(a, n, &mut out).unwrap();
            let want = reference::cap_zonal(f64::from(a), n);
            let omega = 4.0 * core::f64::consts::PI * (0.5 * f64::from(a)).sin().powi(2);
            for l in 0..n {
                let (g, w) = (f64::from(out[l]), want[l]);
                let tol = f64::from(ZONAL_REL_ERROR) * w.abs() + 1e-9 * omega;
                assert!((g - w).abs() <= tol, "a {a} l {l}: {g:e} vs {w:e}");
            }
        }
    }

    /// The closed forms: `L̃_0 = 2π(1 − cos a)/√(4π)`, `L̃_1 = √(3π)·sin²a/2`; the hemisphere
    /// has no even coefficient beyond `l = 0`; the whole sphere only `L̃_0 = 2√π`.
    #[test]
    fn named_cases() {
        let mut z = [0.0f32; 8];
        zonal_into(0.5, 8, &mut z).unwrap();
        let pi = core::f64::consts::PI;
        assert!(
            (f64::from(z[0]) - 2.0 * pi * (1.0 - 0.5f64.cos()) / (4.0 * pi).sqrt()).abs() < 1e-7
        );
        assert!((f64::from(z[1]) - (3.0 * pi).sqrt() * 0.5f64.sin().powi(2) / 2.0).abs() < 1e-7);
        zonal_into(core::f32::consts::FRAC_PI_2, 8, &mut z).unwrap();
        for l in [2, 4, 6] {
            assert!(z[l].abs() < 1e-7, "hemisphere l {l}: {}", z[l]);
        }
        zonal_into(core::f32::consts::PI, 8, &mut z).unwrap();
        assert!((f64::from(z[0]) - 2.0 * pi.sqrt()).abs() < 1e-6);
        assert!(z[1..].iter().all(|v| v.abs() < 1e-6), "{z:?}");
        zonal_into(0.0, 8, &mut z).unwrap();
        assert!(z.iter().all(|v| *v == 0.0));
    }

    #[test]
    fn rotated_coefficients_against_the_reference() {
        let n = 20;
        let mut out = vec![0.0; n * n];
        for (axis, a) in [
            (Vec3::new(0.3, -0.5, 0.81), 0.2f32),
            (Vec3::Z, 1e-4),
            (-Vec3::X, 2.5),
        ] {
            coefficients_into(axis, a, n, &mut out).unwrap();
            let u = axis.normalize();
            let y = reference::eval([u.x as f64, u.y as f64, u.z as f64], n);
            let zl = reference::cap_zonal(f64::from(a), n);
            for l in 0..n {
                let k = (4.0 * core::f64::consts::PI / (2.0 * l as f64 + 1.0)).sqrt();
                for i in l * l..(l + 1) * (l + 1) {
                    let w = k * y[i] * zl[l];
                    let tol =
                        f64::from(eval_abs_error(l)) * k * zl[l].abs() + 1e-6 * w.abs() + 1e-12;
                    assert!(
                        (f64::from(out[i]) - w).abs() <= tol,
                        "a {a} i {i}: {} vs {w:e}",
                        out[i]
                    );
                }
            }
        }
    }

    #[test]
    fn bad_input() {
        let mut out = [0.0; 16];
        assert!(zonal_into(-1e-3, 4, &mut out).is_err());
        assert!(zonal_into(3.2, 4, &mut out).is_err());
        assert!(zonal_into(f32::NAN, 4, &mut out).is_err());
        assert!(coefficients_into(Vec3::Z, 0.1, 5, &mut out).is_err());
        assert!(coefficients_into(Vec3::Z, 0.1, 4, &mut out).is_ok());
        assert!(zonal_into(0.1, MAX_BANDS + 1, &mut [0.0; 200]).is_err());
    }
}
