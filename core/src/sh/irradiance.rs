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
//! **The closed forms of three bands.** [`irradiance_9`] is Ramamoorthi and Hanrahan's
//! 4×4 quadratic form of the nine coefficients and [`irradiance_zonal`] the HVL paper's
//! 2×2 form (appendix B) for radiance symmetric about an axis; both are derived again from
//! `A_l` and the polynomial forms of bands 0–2 and tested equal to [`irradiance`].
//!
//! **Accuracy** (tests below): the factors to 1 ulp of `f32` against the closed form in
//! `f64`; the irradiance against the `f64` quadrature of `∫ L·max(n·ω, 0) dω` for
//! band-limited radiance, to `1e-6` of `Σ|A_l|·|L_l^m|`-weighted sums (the evaluation's
//! error).

use crate::math;
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
    // In f64, band by band, each band's products summed in index order from +0 (the SIMD
    // twin, `steradian_simd::sh::irradiance`, adds in the same order).
    let mut e = 0.0f64;
    for l in 0..bands {
        let a = clamped_cosine(l);
        if a == 0.0 {
            continue;
        }
        let span = l * l..(l + 1) * (l + 1);
        let mut band = 0.0f64;
        for (r, y) in radiance[span.clone()].iter().zip(&scratch[span]) {
            band += f64::from(*r) * f64::from(*y);
        }
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

/// The classic 9-coefficient form (Ramamoorthi and Hanrahan 2001, eq. 12–13): for 3-band
/// radiance, `E(n) = nᵀ·M·n` with `n = (x, y, z, 1)` and the symmetric 4×4 matrix
///
/// ```text
///   ( c₁L₂²    c₁L₂⁻²   c₁L₂¹    c₂L₁¹ )
///   ( c₁L₂⁻²  −c₁L₂²    c₁L₂⁻¹   c₂L₁⁻¹ )
///   ( c₁L₂¹    c₁L₂⁻¹   c₃L₂⁰    c₂L₁⁰ )
///   ( c₂L₁¹    c₂L₁⁻¹   c₂L₁⁰    c₄L₀⁰ − c₅L₂⁰ )
/// ```
///
/// in their basis, where `Y₁^{±1}` and `Y₂^{±1}` carry the opposite sign of this crate's
/// (no Condon–Shortley phase): those four coefficients enter negated here. Derived, not
/// copied: `E = Σ A_l·L_l^m·Y_l^m(n)` with the polynomial forms of bands 0–2 gives
/// `c₁ = A₂·√(15/π)/4`, `c₂ = A₁·√(3/(4π))/2` (the off-diagonal entries count twice in
/// `nᵀMn`), `c₃ = 3·A₂·√(5/π)/4`, `c₄ = A₀/√(4π)`,
/// `c₅ = A₂·√(5/π)/4` (0.429043, 0.511663, 0.743124, 0.886227, 0.247708; the published
/// `c₃ = 0.743125` is 1.1e-6 above the exact value), computed here in
/// `f64` from [`clamped_cosine`]. Equal to [`irradiance`] at 3 bands (tested).
pub fn irradiance_9(radiance: &[f32; 9], normal: Vec3) -> f32 {
    let n = crate::sh::unit_direction(normal);
    let pi = core::f64::consts::PI;
    let (a0, a1, a2) = (clamped_cosine(0), clamped_cosine(1), clamped_cosine(2));
    let c1 = a2 * math::sqrt64(15.0 / pi) / 4.0;
    let c2 = a1 * math::sqrt64(3.0 / (4.0 * pi)) / 2.0;
    let c3 = 3.0 * a2 * math::sqrt64(5.0 / pi) / 4.0;
    let c4 = a0 / math::sqrt64(4.0 * pi);
    let c5 = a2 * math::sqrt64(5.0 / pi) / 4.0;
    let l = radiance.map(f64::from);
    // Their basis: flip the sign of m = ±1 (indices 1, 3, 5, 7).
    let (l00, l1m, l10, l1p) = (l[0], -l[1], l[2], -l[3]);
    let (l2mm, l2m, l20, l2p, l2pp) = (l[4], -l[5], l[6], -l[7], l[8]);
    let (x, y, z) = (n.x, n.y, n.z);
    let e = c1 * l2pp * (x * x - y * y) + c3 * l20 * z * z + c4 * l00 - c5 * l20
        + 2.0 * c1 * (l2mm * x * y + l2p * x * z + l2m * y * z)
        + 2.0 * c2 * (l1p * x + l1m * y + l10 * z);
    e as f32
}

/// The HVL paper's 2×2 form (appendix B) for radiance symmetric about an axis `ω_l` with
/// zonal coefficients `L_0, L_1, L_2` (about that axis): with `z = ω_l·n`,
/// `E = (z, 1)·M·(z, 1)ᵀ`, `M = ((c₃L₂, c₂L₁), (c₂L₁, c₄L₀ − c₅L₂))`, i.e.
/// `E(z) = c₃L₂z² + 2c₂L₁z + c₄L₀ − c₅L₂` — the 4×4 form of [`irradiance_9`] with the axis
/// along `z` (only `m = 0` survives). Derived constants as there.
pub fn irradiance_zonal(zonal: [f32; 3], axis: Vec3, normal: Vec3) -> f32 {
    let z = crate::sh::unit_direction(axis).dot(crate::sh::unit_direction(normal));
    let pi = core::f64::consts::PI;
    let (a0, a1, a2) = (clamped_cosine(0), clamped_cosine(1), clamped_cosine(2));
    let c2 = a1 * math::sqrt64(3.0 / (4.0 * pi)) / 2.0;
    let c3 = 3.0 * a2 * math::sqrt64(5.0 / pi) / 4.0;
    let c4 = a0 / math::sqrt64(4.0 * pi);
    let c5 = a2 * math::sqrt64(5.0 / pi) / 4.0;
    let [l0, l1, l2] = zonal.map(f64::from);
    (c3 * l2 * z * z + 2.0 * c2 * l1 * z + c4 * l0 - c5 * l2) as f32
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
        let mut next = crate::sh::test_rng(0x1d);
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

    #[test]
    fn the_nine_coefficient_and_two_by_two_forms_equal_the_general_one() {
        let mut r = crate::sh::test_rng(11);
        let mut scratch = [0.0f32; 9];
        for _ in 0..200 {
            let c: [f32; 9] = core::array::from_fn(|_| r());
            let n = Vec3::new(r(), r(), r() + 0.01);
            let want = irradiance(&c, n, &mut scratch).unwrap();
            let got = irradiance_9(&c, n);
            assert!((got - want).abs() < 1e-5, "{got} vs {want}");
            // A zonal function about `axis`: its full coefficients by eq. 15.
            let axis = Vec3::new(r(), r(), r() + 0.01);
            let zonal = [r(), r(), r()];
            let mut y = [0.0f32; 9];
            crate::sh::eval_into(axis, 3, &mut y).unwrap();
            let full: [f32; 9] = core::array::from_fn(|i| {
                let l = (i as f32).sqrt() as usize;
                (f64::from(y[i])
                    * (4.0 * core::f64::consts::PI / (2 * l + 1) as f64).sqrt()
                    * f64::from(zonal[l])) as f32
            });
            let want = irradiance(&full, n, &mut scratch).unwrap();
            let got = irradiance_zonal(zonal, axis, n);
            assert!((got - want).abs() < 1e-5, "zonal: {got} vs {want}");
        }
        // The published constants.
        let pi = core::f64::consts::PI;
        let c1 = clamped_cosine(2) * (15.0 / pi).sqrt() / 4.0;
        assert!((c1 - 0.429043).abs() < 1e-6);
        assert!((clamped_cosine(1) * (3.0 / (4.0 * pi)).sqrt() / 2.0 - 0.511664).abs() < 1e-6);
        assert!((3.0 * clamped_cosine(2) * (5.0 / pi).sqrt() / 4.0 - 0.743125).abs() < 1.5e-6);
        assert!((clamped_cosine(0) / (4.0 * pi).sqrt() - 0.886227).abs() < 1e-6);
        assert!((clamped_cosine(2) * (5.0 / pi).sqrt() / 4.0 - 0.247708).abs() < 1e-6);
    }
}
