//! Products and convolutions of SH expansions (HVL paper section 4.3 and 6.3; Sloan et
//! al.'s PRT framework; Ramamoorthi and Hanrahan's convolution).
//!
//! ## The three products, derived
//!
//! - **Dot product.** The basis is orthonormal, so `∫ f·g dω = Σ f_i·g_i` ([`dot`]): the
//!   shading of the HVL paper (eq. 19–22) is one such sum per light.
//! - **Zonal kernel ⋆ SH (Funk–Hecke), O(n²).** A circularly symmetric kernel `k(ω·ω′)` with
//!   zonal coefficients `k_l = ∫ k(z)·Y_l^0 dω` (around `+z`) acts on each band by one
//!   factor: `(k ⋆ f)(ω) = ∫ k(ω·ω′)·f(ω′) dω′` has coefficients `√(4π/(2l+1))·k_l·f_l^m`
//!   (expand `k(ω·ω′) = Σ_l k_l·√((2l+1)/4π)·P_l(ω·ω′)` and apply the addition theorem
//!   `P_l(ω·ω′) = 4π/(2l+1)·Σ_m Y_l^m(ω)·Y_l^m(ω′)`) — [`convolve_zonal_into`]. The irradiance
//!   of [`crate::sh::irradiance`] is the case `k = max(z, 0)`, with
//!   `√(4π/(2l+1))·k_l = A_l`.
//! - **Zonal × zonal about two axes, O(n).** For `f` zonal about `a` and `g` zonal about `b`,
//!   the addition theorem collapses the sum over `m`:
//!   `∫ f·g dω = Σ_l f_l·g_l·P_l(a·b)` ([`zonal_dot`]), with `P_l` by the three-term
//!   recurrence in `f64` (the section 6.3 speed-up for circularly symmetric lobes).
//!   Convolving two zonal functions about the same axis is zonal again with
//!   `√(4π/(2l+1))·k_l·f_l` ([`convolve_zonal_zonal_into`]).
//!
//! **Accuracy** (tests below, against `f64` quadrature of the products on the exact grid of
//! `steradian-reference`): every product sums in `f64` and rounds once, so each result is
//! within `1e-7` relative of `Σ|terms|` (the products of `f32` inputs are exact in `f64`);
//! [`zonal_dot`] is tested on equal, opposite, generic and nearly opposite axes (at
//! `t = ±1` the recurrence gives `P_l(±1) = (±1)^l` exactly).
//!
//! # References
//!
//! - R. Ramamoorthi, P. Hanrahan, "An Efficient Representation for Irradiance Environment
//!   Maps", SIGGRAPH 2001. DOI: 10.1145/383259.383317.
//! - P.-P. Sloan, J. Kautz, J. Snyder, "Precomputed Radiance Transfer for Real-Time
//!   Rendering in Dynamic, Low-Frequency Lighting Environments", SIGGRAPH 2002.
//!   DOI: 10.1145/566654.566612.

use crate::math;
use crate::sh::{bands_of, check_shape, unit_direction};
use crate::{Error, Vec3};

fn same_len(a: usize, b: usize) -> Result<(), Error> {
    if a != b {
        return Err(Error::OutOfRange {
            what: "SH coefficient count of the second operand",
            value: b as f32,
            min: a as f32,
            max: a as f32,
        });
    }
    Ok(())
}

/// `∫ f·g dω = Σ f_i·g_i` for two expansions of the same length (summed in `f64`).
///
/// Errors: lengths that differ.
pub fn dot(f: &[f32], g: &[f32]) -> Result<f32, Error> {
    same_len(f.len(), g.len())?;
    Ok(f.iter()
        .zip(g)
        .map(|(&a, &b)| f64::from(a) * f64::from(b))
        .sum::<f64>() as f32)
}

/// `√(4π/(2l+1))`, the factor of Funk–Hecke for band `l`.
#[inline]
pub fn funk_hecke(l: usize) -> f64 {
    math::sqrt64(4.0 * core::f64::consts::PI / (2 * l + 1) as f64)
}

/// The coefficients of `k ⋆ f` (module docs) for the kernel with zonal coefficients
/// `kernel[l]` (at least `n` of them) and `f` of `n²` coefficients, into `out[..n²]`.
///
/// Errors: a length of `f` that is not a square, a short `kernel` or `out`.
pub fn convolve_zonal_into(kernel: &[f32], f: &[f32], out: &mut [f32]) -> Result<(), Error> {
    let n = bands_of(f.len())?;
    check_shape(n, out.len())?;
    if kernel.len() < n {
        return Err(Error::OutOfRange {
            what: "zonal kernel length",
            value: kernel.len() as f32,
            min: n as f32,
            max: f32::INFINITY,
        });
    }
    for (l, &kl) in kernel[..n].iter().enumerate() {
        let k = funk_hecke(l) * f64::from(kl);
        for i in l * l..(l + 1) * (l + 1) {
            out[i] = (k * f64::from(f[i])) as f32;
        }
    }
    Ok(())
}

/// The zonal coefficients of `k ⋆ f` for two zonal functions about the same axis:
/// `out[l] = √(4π/(2l+1))·k_l·f_l`, `l < f.len()`.
///
/// Errors: `kernel` or `out` shorter than `f`.
pub fn convolve_zonal_zonal_into(kernel: &[f32], f: &[f32], out: &mut [f32]) -> Result<(), Error> {
    if kernel.len() < f.len() || out.len() < f.len() {
        return Err(Error::OutOfRange {
            what: "zonal operand length",
            value: kernel.len().min(out.len()) as f32,
            min: f.len() as f32,
            max: f32::INFINITY,
        });
    }
    for (l, (o, (&k, &v))) in out.iter_mut().zip(kernel.iter().zip(f)).enumerate() {
        *o = (funk_hecke(l) * f64::from(k) * f64::from(v)) as f32;
    }
    Ok(())
}

/// `∫ f·g dω` for `f` zonal about `a` with coefficients `f[l]` and `g` zonal about `b` with
/// `g[l]` (module docs): `Σ_l f_l·g_l·P_l(a·b)`, O(n). The axes need not be unit (zero →
/// `+z`, as [`crate::sh::eval_into`]); the shorter of `f`, `g` sets the band count.
pub fn zonal_dot(f: &[f32], a: Vec3, g: &[f32], b: Vec3) -> f32 {
    let t = unit_direction(a).dot(unit_direction(b)).clamp(-1.0, 1.0);
    let mut sum = 0.0f64;
    let (mut p_prev, mut p) = (0.0f64, 1.0f64);
    for (l, (&x, &y)) in f.iter().zip(g).enumerate() {
        sum += f64::from(x) * f64::from(y) * p;
        let lf = l as f64;
        let next = ((2.0 * lf + 1.0) * t * p - lf * p_prev) / (lf + 1.0);
        (p_prev, p) = (p, next);
    }
    sum as f32
}

#[cfg(all(test, feature = "alloc"))]
#[allow(clippy::needless_range_loop)] // l indexes several per-band tables
mod tests {
    use super::*;
    use crate::sh::eval_into;
    use alloc::vec;
    use alloc::vec::Vec;
    extern crate std;
    use steradian_reference::sh as reference;

    use crate::sh::test_rng as rng;

    /// The zonal function `Σ z_l·Y_l^0` rotated to the unit axis `a`, as full coefficients.
    fn zonal_to_full(z: &[f64], a: [f64; 3]) -> Vec<f64> {
        let n = z.len();
        let y = reference::eval(a, n);
        let mut out = vec![0.0; n * n];
        for l in 0..n {
            let k = (4.0 * core::f64::consts::PI / (2 * l + 1) as f64).sqrt();
            for i in l * l..(l + 1) * (l + 1) {
                out[i] = k * z[l] * y[i];
            }
        }
        out
    }

    fn quad_dot(f: &[f64], g: &[f64]) -> f64 {
        let n = (f.len() as f64).sqrt() as usize;
        reference::exact_grid(n)
            .iter()
            .map(|(d, w)| {
                let y = reference::eval(*d, n);
                let fv: f64 = y.iter().zip(f).map(|(a, b)| a * b).sum();
                let gv: f64 = y.iter().zip(g).map(|(a, b)| a * b).sum();
                w * fv * gv
            })
            .sum()
    }

    #[test]
    fn dot_is_the_integral_of_the_product() {
        let n = 8;
        let mut r = rng(1);
        let f: Vec<f32> = (0..n * n).map(|_| r()).collect();
        let g: Vec<f32> = (0..n * n).map(|_| r()).collect();
        let want = quad_dot(
            &f.iter().map(|&x| f64::from(x)).collect::<Vec<_>>(),
            &g.iter().map(|&x| f64::from(x)).collect::<Vec<_>>(),
        );
        let got = dot(&f, &g).unwrap();
        assert!((f64::from(got) - want).abs() < 1e-6, "{got} vs {want}");
        assert!(dot(&f, &g[1..]).is_err());
    }

    #[test]
    fn zonal_dot_matches_quadrature_for_equal_opposite_and_generic_axes() {
        let n = 12;
        let mut r = rng(2);
        let f: Vec<f32> = (0..n).map(|_| r()).collect();
        let g: Vec<f32> = (0..n).map(|_| r()).collect();
        let (f64s, g64s): (Vec<f64>, Vec<f64>) = (
            f.iter().map(|&x| x.into()).collect(),
            g.iter().map(|&x| x.into()).collect(),
        );
        let a = Vec3::new(0.3, -0.5, 0.81).normalize();
        let cases = [
            a,
            -a,
            Vec3::new(0.0, 0.6, 0.8),
            // Nearly opposite: 1e-3 rad from −a.
            (-a + a.any_orthonormal_vector() * 1e-3).normalize(),
        ];
        for b in cases {
            let ua = unit_direction(a).to_array();
            let ub = unit_direction(b).to_array();
            let want = quad_dot(&zonal_to_full(&f64s, ua), &zonal_to_full(&g64s, ub));
            let got = zonal_dot(&f, a, &g, b);
            let scale: f64 = f64s.iter().zip(&g64s).map(|(x, y)| (x * y).abs()).sum();
            assert!(
                (f64::from(got) - want).abs() <= 1e-7 * scale + 1e-12,
                "{b}: {got} vs {want}"
            );
        }
        // Equal axes: P_l(1) = 1, the plain sum; opposite: (−1)^l.
        let same: f64 = f64s.iter().zip(&g64s).map(|(x, y)| x * y).sum();
        assert!((f64::from(zonal_dot(&f, Vec3::Z, &g, Vec3::Z)) - same).abs() < 1e-6);
        let opp: f64 = f64s
            .iter()
            .zip(&g64s)
            .enumerate()
            .map(|(l, (x, y))| if l % 2 == 1 { -x * y } else { x * y })
            .sum();
        assert!((f64::from(zonal_dot(&f, Vec3::Z, &g, -Vec3::Z)) - opp).abs() < 1e-6);
    }

    #[test]
    fn convolution_with_the_clamped_cosine_is_the_irradiance() {
        let n = 9;
        let mut r = rng(3);
        let f: Vec<f32> = (0..n * n).map(|_| r()).collect();
        // k_l of max(z, 0) = A_l / √(4π/(2l+1)).
        let kernel: Vec<f32> = (0..n)
            .map(|l| (crate::sh::irradiance::clamped_cosine(l) / funk_hecke(l)) as f32)
            .collect();
        let mut conv = vec![0.0; n * n];
        convolve_zonal_into(&kernel, &f, &mut conv).unwrap();
        let mut y = vec![0.0; n * n];
        let mut scratch = vec![0.0; n * n];
        for d in [Vec3::Z, Vec3::new(0.2, -0.7, 0.3), -Vec3::X] {
            eval_into(d, n, &mut y).unwrap();
            let e: f32 = conv.iter().zip(&y).map(|(a, b)| a * b).sum();
            let want = crate::sh::irradiance::irradiance(&f, d, &mut scratch).unwrap();
            assert!((e - want).abs() < 1e-5, "{d}: {e} vs {want}");
        }
    }

    #[test]
    fn convolution_matches_quadrature_of_the_kernel_integral() {
        // (k ⋆ f)(ω) = ∫ k(ω·ω′) f(ω′) dω′ for a band-limited kernel, on the exact grid.
        let n = 6;
        let mut r = rng(4);
        let f: Vec<f32> = (0..n * n).map(|_| r()).collect();
        let k: Vec<f32> = (0..n).map(|_| r()).collect();
        let mut conv = vec![0.0; n * n];
        convolve_zonal_into(&k, &f, &mut conv).unwrap();
        let w = Vec3::new(0.48, 0.6, -0.64);
        let kz = |t: f64| -> f64 {
            (0..n)
                .map(|l| {
                    f64::from(k[l])
                        * ((2 * l + 1) as f64 / (4.0 * core::f64::consts::PI)).sqrt()
                        * reference::legendre(l, 0, t)
                })
                .sum()
        };
        let wd = unit_direction(w).to_array();
        let want: f64 = reference::exact_grid(n)
            .iter()
            .map(|(d, wt)| {
                let y = reference::eval(*d, n);
                let fv: f64 = y.iter().zip(&f).map(|(a, &b)| a * f64::from(b)).sum();
                let t = d[0] * wd[0] + d[1] * wd[1] + d[2] * wd[2];
                wt * kz(t) * fv
            })
            .sum();
        let mut y = vec![0.0; n * n];
        eval_into(w, n, &mut y).unwrap();
        let got: f32 = conv.iter().zip(&y).map(|(a, b)| a * b).sum();
        assert!((f64::from(got) - want).abs() < 1e-5, "{got} vs {want}");
        // Zonal ⋆ zonal is the same factor per band.
        let mut zz = vec![0.0; n];
        convolve_zonal_zonal_into(&k, &k, &mut zz).unwrap();
        for l in 0..n {
            let want = funk_hecke(l) * f64::from(k[l]) * f64::from(k[l]);
            assert!((f64::from(zz[l]) - want).abs() < 1e-7);
        }
    }

    #[test]
    fn shape_errors() {
        let mut out = vec![0.0; 9];
        assert!(convolve_zonal_into(&[1.0; 2], &[0.0; 9], &mut out).is_err());
        assert!(convolve_zonal_into(&[1.0; 3], &[0.0; 8], &mut out).is_err());
        assert!(convolve_zonal_into(&[1.0; 3], &[0.0; 9], &mut out[..4]).is_err());
        assert!(convolve_zonal_zonal_into(&[1.0; 2], &[0.0; 3], &mut out).is_err());
        assert_eq!(zonal_dot(&[], Vec3::Z, &[1.0], Vec3::X), 0.0);
        assert!(zonal_dot(&[1.0], Vec3::ZERO, &[1.0], Vec3::Z) == 1.0);
    }
}
