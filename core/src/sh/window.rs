//! Windows against ringing: band `l` of an `n`-band expansion scaled by `w_l` before
//! reconstruction, so that truncating a sharp function (a small light, a glossy lobe) does
//! not leave negative lobes and halos.
//!
//! ## The windows, for the band limit `n` (`l = 0..n−1`, `w_0 = 1`)
//!
//! | window | `w_l` | from |
//! |---|---|---|
//! | [`Window::Hanning`] | `½·(1 + cos(π·l/n))` | Sloan, "Stupid SH tricks" |
//! | [`Window::Lanczos`] | `sinc(π·l/n)`, `sinc x = sin x / x` | Lanczos σ-factors |
//! | [`Window::Sinc`] `{ power: k }` | `sinc(π·l/n)^k` (Filament uses `k = 4`) | |
//! | [`Window::Damping`] `{ lambda: λ }` | `1/(1 + λ·l²(l+1)²)` | pbrt-v2 `SHReduceRinging` |
//! | [`Window::Cesaro`] | `(n − l)(n − l + 1)/(n(n + 1))` | Cesàro `(C, 2)` means |
//!
//! **Which guarantees a non-negative result.** Windowing a zonal function `f` is convolving
//! it with the zonal kernel `K_n(t) = Σ_l w_l·(2l+1)/(4π)·P_l(t)` (Funk–Hecke), so if
//! `K_n ≥ 0` on `[−1, 1]` every non-negative function — a lobe, a cap, a whole environment
//! — reconstructs non-negative, for every band count. For the Legendre series the Cesàro
//! means of order 2 have exactly this property (Kogbetliantz's theorem: the `(C, δ)` means
//! of ultraspherical series of index `λ` have a positive kernel for `δ ≥ 2λ + 1`, and the
//! Legendre series has `λ = ½`); their weights are `A²_{N−l}/A²_N` with `N = n − 1` and
//! `A²_k = (k+1)(k+2)/2`, the table's formula. The tests below check `K_n ≥ 0` for every
//! `n ≤ 64` and the reconstruction of caps and clamped-cosine powers for every `n ≤ 40`,
//! and measure how far below zero the others go on the same lobes (caps of 0.05, 0.3, 1 and
//! 2.5 rad and `max(cos θ, 0)`, all peaking at 1, over 2–40 bands): the most negative value
//! is −0.40 truncated, −0.070 Hanning, −0.11 Lanczos, −0.042 sinc⁴, −0.29 pbrt's damping
//! with `λ = 0.005`, and 0 for Cesàro.
//! The price is blur: the Cesàro window damps the upper bands more than Hanning.
//!
//! **Bad input.** A band count of 0 has no weights; `λ < 0` or NaN is an error (a
//! negative damping amplifies); every weight is in `[0, 1]` and finite.

use crate::Error;
use crate::math;
use crate::sh::bands_of;

/// A window (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Window {
    /// `w_l = 1`: plain truncation.
    None,
    /// `½·(1 + cos(π·l/n))`.
    Hanning,
    /// `sinc(π·l/n)`.
    Lanczos,
    /// `sinc(π·l/n)^power`.
    Sinc {
        /// The power `k` (Filament: 4).
        power: u32,
    },
    /// `1/(1 + λ·l²(l+1)²)`.
    Damping {
        /// `λ ≥ 0` (pbrt-v2's default is 0.005).
        lambda: f32,
    },
    /// `(n − l)(n − l + 1)/(n(n + 1))`: non-negative reconstruction of non-negative
    /// functions for every `n`.
    Cesaro,
}

impl Window {
    /// Checks the parameters. Errors: `λ` negative or not finite.
    pub fn validate(&self) -> Result<(), Error> {
        if let Window::Damping { lambda } = *self {
            if !lambda.is_finite() {
                return Err(Error::NonFinite {
                    what: "damping lambda",
                });
            }
            if lambda < 0.0 {
                return Err(Error::OutOfRange {
                    what: "damping lambda",
                    value: lambda,
                    min: 0.0,
                    max: f32::INFINITY,
                });
            }
        }
        Ok(())
    }

    /// `w_l` for band `l` of an `n`-band expansion, in `f64` (`0` for `l ≥ n`).
    pub fn weight(&self, l: usize, n: usize) -> f64 {
        if l >= n {
            return 0.0;
        }
        let pi = core::f64::consts::PI;
        let x = pi * l as f64 / n as f64;
        let sinc = if l == 0 { 1.0 } else { math::sin64(x) / x };
        match *self {
            Window::None => 1.0,
            Window::Hanning => 0.5 * (1.0 + math::cos64(x)),
            Window::Lanczos => sinc,
            Window::Sinc { power } => (0..power).fold(1.0, |a, _| a * sinc),
            Window::Damping { lambda } => {
                let t = (l * (l + 1)) as f64;
                1.0 / (1.0 + f64::from(lambda.max(0.0)) * t * t)
            }
            Window::Cesaro => {
                let (n, l) = (n as f64, l as f64);
                (n - l) * (n - l + 1.0) / (n * (n + 1.0))
            }
        }
    }

    /// The windowed zonal function `Σ_l w_l·c_l·√((2l+1)/(4π))·P_l(t)` at `t = cos θ`, for the
    /// zonal coefficients `zonal` (`n = zonal.len()` bands, `P_l` by the three-term
    /// recurrence), in `f64`: the reconstruction the windows are judged on (module docs).
    pub fn reconstruct_zonal(&self, zonal: &[f64], t: f64) -> f64 {
        let n = zonal.len();
        let (mut p0, mut p1) = (1.0f64, t);
        let mut s = 0.0;
        for (l, &c) in zonal.iter().enumerate() {
            let p = if l == 0 { 1.0 } else { p1 };
            s += self.weight(l, n)
                * c
                * math::sqrt64((2 * l + 1) as f64 / (4.0 * core::f64::consts::PI))
                * p;
            if l >= 1 {
                let lf = l as f64;
                let next = ((2.0 * lf + 1.0) * t * p1 - lf * p0) / (lf + 1.0);
                (p0, p1) = (p1, next);
            }
        }
        s
    }

    /// Scales each band of the full expansion `coeffs` (`n²` values) by `w_l`, in place.
    ///
    /// Errors: a length that is not a square; invalid parameters ([`Window::validate`]).
    pub fn apply(&self, coeffs: &mut [f32]) -> Result<(), Error> {
        self.validate()?;
        let n = bands_of(coeffs.len())?;
        for l in 0..n {
            let w = self.weight(l, n);
            for c in &mut coeffs[l * l..(l + 1) * (l + 1)] {
                *c = (f64::from(*c) * w) as f32;
            }
        }
        Ok(())
    }

    /// Scales the zonal coefficients `zonal[l]` (`n = zonal.len()` bands) by `w_l`.
    ///
    /// Errors: invalid parameters.
    pub fn apply_zonal(&self, zonal: &mut [f32]) -> Result<(), Error> {
        self.validate()?;
        let n = zonal.len();
        for (l, z) in zonal.iter_mut().enumerate() {
            *z = (f64::from(*z) * self.weight(l, n)) as f32;
        }
        Ok(())
    }
}

#[cfg(all(test, feature = "alloc"))]
#[allow(clippy::needless_range_loop)] // l indexes several per-band tables
mod tests {
    use super::*;
    use alloc::vec;
    use alloc::vec::Vec;
    extern crate std;
    use std::println;

    const ALL: [Window; 7] = [
        Window::None,
        Window::Hanning,
        Window::Lanczos,
        Window::Sinc { power: 4 },
        Window::Damping { lambda: 0.005 },
        Window::Damping { lambda: 0.0 },
        Window::Cesaro,
    ];

    /// Points in `[−1, 1]`: uniform plus clustered at both ends (where `P_l` oscillates
    /// fastest in `t`).
    fn ts() -> Vec<f64> {
        let mut v: Vec<f64> = (0..=4000).map(|i| -1.0 + i as f64 / 2000.0).collect();
        v.extend((0..400).map(|i| (core::f64::consts::PI * i as f64 / 399.0).cos()));
        v
    }

    #[test]
    fn weights_start_at_one_stay_in_the_unit_interval_and_decrease() {
        for w in ALL {
            for n in 1..=64 {
                assert_eq!(w.weight(0, n), 1.0, "{w:?}");
                let mut prev = 1.0;
                for l in 0..n {
                    let v = w.weight(l, n);
                    assert!(
                        v.is_finite() && (0.0..=1.0).contains(&v),
                        "{w:?} {l} {n}: {v}"
                    );
                    assert!(v <= prev + 1e-15, "{w:?} not decreasing at {l}/{n}");
                    prev = v;
                }
                assert_eq!(w.weight(n, n), 0.0);
            }
        }
    }

    #[test]
    fn the_cesaro_kernel_is_non_negative_for_every_band_count() {
        // K_n(t) = Σ w_l (2l+1)/(4π) P_l(t): the window's reconstruction of a Dirac.
        let ts = ts();
        for n in 1..=64 {
            let dirac: Vec<f64> = (0..n)
                .map(|l| ((2 * l + 1) as f64 / (4.0 * core::f64::consts::PI)).sqrt())
                .collect();
            let k0 = Window::Cesaro.reconstruct_zonal(&dirac, 1.0);
            let min = ts
                .iter()
                .map(|&t| Window::Cesaro.reconstruct_zonal(&dirac, t))
                .fold(f64::INFINITY, f64::min);
            assert!(min >= -1e-13 * k0, "n {n}: min {min:e} of peak {k0:e}");
        }
    }

    /// Zonal coefficients of the named non-negative lobes for `n` bands.
    fn lobes(n: usize) -> Vec<(&'static str, Vec<f64>)> {
        let mut v = Vec::new();
        for (name, a) in [
            ("cap 0.05", 0.05),
            ("cap 0.3", 0.3),
            ("cap 1", 1.0),
            ("cap 2.5", 2.5),
        ] {
            let mut z = vec![0.0f32; n];
            crate::sh::cap::zonal_into(a, n, &mut z).unwrap();
            v.push((name, z.iter().map(|&x| f64::from(x)).collect()));
        }
        let cosine: Vec<f64> = (0..n)
            .map(|l| crate::sh::irradiance::clamped_cosine(l) / crate::sh::convolve::funk_hecke(l))
            .collect();
        v.push(("clamped cosine", cosine));
        v
    }

    #[test]
    fn only_the_cesaro_window_reconstructs_every_lobe_non_negative() {
        let ts: Vec<f64> = ts().into_iter().step_by(7).collect();
        let mut worst = [0.0f64; ALL.len()];
        for n in 2..=40 {
            for (name, c) in lobes(n) {
                // Every lobe peaks at 1 (indicators and max(cos θ, 0)).
                let peak = 1.0;
                for (k, w) in ALL.iter().enumerate() {
                    let min = ts
                        .iter()
                        .map(|&t| w.reconstruct_zonal(&c, t))
                        .fold(f64::INFINITY, f64::min);
                    worst[k] = worst[k].min(min / peak);
                    if *w == Window::Cesaro {
                        assert!(min >= -1e-6 * peak, "{name} n {n}: {min:e}");
                    }
                }
            }
        }
        for (w, m) in ALL.iter().zip(worst) {
            println!("{w:?}: most negative value {m:.2e} (the lobes peak at 1)");
        }
        // The others do go negative (the figures of the module docs).
        let quoted = [-0.396, -0.0702, -0.108, -0.0417, -0.291, -0.396];
        for (k, q) in quoted.iter().enumerate() {
            assert!(
                (worst[k] - q).abs() < 0.005 * q.abs(),
                "{:?}: {}",
                ALL[k],
                worst[k]
            );
        }
    }

    #[test]
    fn apply_scales_each_band_and_checks_its_input() {
        let mut c = vec![1.0f32; 16];
        Window::Cesaro.apply(&mut c).unwrap();
        for l in 0..4 {
            for i in l * l..(l + 1) * (l + 1) {
                assert_eq!(c[i], Window::Cesaro.weight(l, 4) as f32);
            }
        }
        assert!(Window::Hanning.apply(&mut [0.0; 5]).is_err());
        let bad = Window::Damping { lambda: -1.0 };
        assert!(bad.apply(&mut [0.0; 4]).is_err());
        assert!(
            Window::Damping { lambda: f32::NAN }
                .apply_zonal(&mut [0.0; 4])
                .is_err()
        );
        let mut z = [2.0f32; 3];
        Window::Hanning.apply_zonal(&mut z).unwrap();
        assert_eq!(z[0], 2.0);
        assert!(z[2] < z[1] && z[1] < 2.0);
    }
}
