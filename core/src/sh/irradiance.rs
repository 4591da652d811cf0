//! Irradiance from radiance SH coefficients, every band (HVL paper appendix B; the
//! clamped-cosine convolution of Ramamoorthi and Hanrahan).
//!
//! ## The π convention, once
//!
//! The input is **radiance** `L(ω) = Σ L_l^m·Y_l^m(ω)` (W·sr⁻¹·m⁻², per unit solid angle);
//! the output of [`irradiance`] is the **irradiance** `E(n) = ∫ L(ω)·max(n·ω, 0) dω`
//! (W·m⁻²), *not* divided by π. A Lambertian surface of albedo `ρ` reflects the radiance
//! `ρ·E/π`: that division is the caller's, and [`lambert_radiance`] names it.
//!
//! ## The clamped-cosine factors
//!
//! By Funk–Hecke, convolving with the zonal kernel `max(t, 0)` scales band `l` by
//! `A_l = 2π·∫_0^1 t·P_l(t) dt`: `A_0 = π`, `A_1 = 2π/3`, `A_l = 0` for odd `l > 1`, and for
//! even `l ≥ 2`
//!
//! ```text
//!   A_l = 2π·(−1)^(l/2 − 1)/((l + 2)(l − 1)) · C(l, l/2)/2^l
//! ```
//!
//! (`∫_0^1 t P_l(t) dt` from `P_l(0)` and the three-term recurrence). The central binomial
//! ratio is formed without factorials, `C(l, l/2)/2^l = Π_{k=1}^{l/2} (2k − 1)/(2k)`, so
//! every band is finite and accurate (it decays like `l^(−5/2)`; pbrt and Filament stop or
//! overflow at 18–50 bands). Then `E(n) = Σ_l A_l·Σ_m L_l^m·Y_l^m(n)`.
//!
//! **Accuracy** (tests below): the factors to 1 ulp of `f32` against the closed form in
//! `f64`; the irradiance against the `f64` quadrature of `∫ L·max(n·ω, 0) dω` for
//! band-limited radiance, to `1e-6` of `Σ|A_l|·|L_l^m|`-weighted sums (the evaluation's
//! error).

use crate::sh::{bands_of, eval_into};
use crate::{Error, Vec3};

/// `A_l`, the clamped-cosine convolution factor of band `l` (module docs), in `f64`.
pub fn clamped_cosine(l: usize) -> f64 {
    let pi = core::f64::consts::PI;
    match l {
        0 => pi,
        1 => 2.0 * pi / 3.0,
        _ if l % 2 == 1 => 0.0,
        _ => {
            let mut c = 1.0f64;
            for k in 1..=l / 2 {
                c *= (2 * k - 1) as f64 / (2 * k) as f64;
            }
            let sign = if (l / 2) % 2 == 1 { 1.0 } else { -1.0 };
            let lf = l as f64;
            2.0 * pi * sign * c / ((lf + 2.0) * (lf - 1.0))
        }
    }
}

/// The irradiance `E(n) = ∫ L(ω)·max(n·ω, 0) dω` of the radiance with SH coefficients
/// `radiance` (length `n²` for `n` bands) at the normal `normal` (any length; zero → `+z`),
/// not divided by π (module docs). `scratch` holds `n²` values (the basis at `n`).
///
/// Errors: `radiance.len()` not a square of at most `MAX_BANDS²`, or `scratch` shorter.
pub fn irradiance(radiance: &[f32], normal: Vec3, scratch: &mut [f32]) -> Result<f32, Error> {
    let bands = bands_of(radiance.len())?;
    eval_into(normal, bands, scratch)?;
    let mut e = 0.0f64;
    for l in 0..bands {
        let a = clamped_cosine(l);
        if a == 0.0 {
            continue;
        }
        let band: f64 = (l * l..(l + 1) * (l + 1))
            .map(|i| f64::from(radiance[i]) * f64::from(scratch[i]))
            .sum();
        e += a * band;
    }
    Ok(e as f32)
}

/// The radiance `ρ·E/π` a Lambertian surface of albedo `albedo` reflects under the
/// irradiance `irradiance` (the one place the π of the convention is divided out).
#[inline]
pub fn lambert_radiance(albedo: f32, irradiance: f32) -> f32 {
    albedo * irradiance * core::f32::consts::FRAC_1_PI
}

#[cfg(all(test, feature = "alloc"))]
mod tests {
    use super::*;
    use alloc::vec;
    use alloc::vec::Vec;
    use steradian_reference::sh as reference;

    #[test]
    fn factors_match_the_integral_and_stay_finite() {
        let pi = core::f64::consts::PI;
        assert_eq!(clamped_cosine(0), pi);
        assert!((clamped_cosine(2) - pi / 4.0).abs() < 1e-15);
        assert!((clamped_cosine(4) + pi / 24.0).abs() < 1e-15);
        for l in 0..40 {
            let want = reference::clamped_cosine(l);
            assert!(
                (clamped_cosine(l) - want).abs() <= 1e-13 * (1.0 + want.abs()),
                "l {l}"
            );
        }
        for l in [100usize, 1000, 10_000] {
            let a = clamped_cosine(l);
            assert!(a.is_finite() && a.abs() < 1e-3, "l {l}: {a}");
        }
    }

    #[test]
    fn irradiance_against_quadrature() {
        let n = 8;
        let mut s = 0x1d_u64;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
        };
        let coeffs: Vec<f32> = (0..n * n).map(|_| next()).collect();
        let mut scratch = vec![0.0; n * n];
        for normal in [Vec3::Z, Vec3::new(0.3, -0.4, 0.5), -Vec3::X] {
            let e = irradiance(&coeffs, normal, &mut scratch).unwrap();
            let u = normal.normalize();
            let c64: Vec<f64> = coeffs.iter().map(|&c| f64::from(c)).collect();
            let want = reference::irradiance(&c64, [u.x as f64, u.y as f64, u.z as f64]);
            let scale: f64 = c64.iter().map(|c| c.abs()).sum();
            assert!(
                (f64::from(e) - want).abs() < 1e-6 * scale,
                "{normal}: {e} vs {want}"
            );
        }
        // Constant radiance L: E = π·L (the π of the convention).
        let mut c = vec![0.0f32; 9];
        c[0] = 2.0 / crate::sh::Y00; // L = 2
        let e = irradiance(&c, Vec3::Y, &mut scratch).unwrap();
        assert!((e - 2.0 * crate::PI).abs() < 1e-5, "{e}");
        assert!((lambert_radiance(0.5, e) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn bad_lengths() {
        let mut scratch = [0.0; 16];
        assert!(irradiance(&[0.0; 5], Vec3::Z, &mut scratch).is_err());
        assert!(irradiance(&[0.0; 16], Vec3::Z, &mut scratch[..8]).is_err());
        assert_eq!(irradiance(&[], Vec3::Z, &mut []).unwrap(), 0.0);
    }
}
