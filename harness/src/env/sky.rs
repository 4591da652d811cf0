//! The embedded default environment: a procedural sky with a sun, defined analytically so
//! that its exact integral is known (world `+z` up).
//!
//! ```text
//!   L(d) = Z + (H − Z)·(1 − z)^m      z ≥ 0   (sky: zenith Z, horizon H)
//!        = G                           z < 0   (ground)
//!        + E_sun · λ/(2π(1 − e^(−2λ))) · exp(λ(d·s − 1))   (sun: unit-integral lobe)
//! ```
//!
//! `∫ L dω = 2π·Z + 2π·(H − Z)/(m + 1) + 2π·G + E_sun`, because
//! `∫_{z≥0} (1 − z)^m dω = 2π/(m + 1)` and the sun lobe integrates to 1 over the sphere.

use std::f64::consts::PI;

use glam::DVec3;

use super::EnvError;
use super::cubemap::CubeMap;

/// Parameters of the procedural sky.
#[derive(Clone, Copy, Debug)]
pub struct Sky {
    /// Zenith radiance.
    pub zenith: [f64; 3],
    /// Horizon radiance.
    pub horizon: [f64; 3],
    /// Exponent `m` of the horizon brightening.
    pub m: i32,
    /// Ground radiance.
    pub ground: [f64; 3],
    /// Unit direction to the sun.
    pub sun_dir: DVec3,
    /// Sun sharpness `λ` (angular radius about `1/sqrt(λ)` rad).
    pub sun_lambda: f64,
    /// Integral of the sun over the sphere, RGB.
    pub sun_energy: [f64; 3],
}

impl Default for Sky {
    /// A clear afternoon: sun at 35° elevation, azimuth 40°; the sun carries about 3/4 of
    /// the energy, the sky and ground the rest.
    fn default() -> Self {
        let (el, az) = (35f64.to_radians(), 40f64.to_radians());
        Sky {
            zenith: [0.20, 0.38, 0.85],
            horizon: [0.75, 0.82, 0.95],
            m: 4,
            ground: [0.10, 0.085, 0.07],
            sun_dir: DVec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin()),
            sun_lambda: 3000.0,
            sun_energy: [16.0, 15.0, 13.5],
        }
    }
}

impl Sky {
    /// Radiance in direction `d` (unit).
    pub fn radiance(&self, d: DVec3) -> [f64; 3] {
        let lam = self.sun_lambda;
        let sun_norm = lam / (2.0 * PI * (-(-2.0 * lam).exp_m1()));
        let sun = sun_norm * (lam * (d.dot(self.sun_dir) - 1.0)).exp();
        std::array::from_fn(|c| {
            let base = if d.z >= 0.0 {
                self.zenith[c] + (self.horizon[c] - self.zenith[c]) * (1.0f64 - d.z).powi(self.m)
            } else {
                self.ground[c]
            };
            base + self.sun_energy[c] * sun
        })
    }

    /// The exact integral `∫ L dω`, RGB.
    pub fn integral(&self) -> [f64; 3] {
        std::array::from_fn(|c| {
            2.0 * PI * self.zenith[c]
                + 2.0 * PI * (self.horizon[c] - self.zenith[c]) / (self.m as f64 + 1.0)
                + 2.0 * PI * self.ground[c]
                + self.sun_energy[c]
        })
    }

    /// The box-filtered cube map of face size `n` (16 × 16 sub-texels each, which resolves
    /// the sun: the test `default_sky_cubemap_matches_its_analytic_integral` states the
    /// measured error).
    pub fn cubemap(&self, n: usize) -> Result<CubeMap, EnvError> {
        CubeMap::from_fn(n, 16, |d| self.radiance(d)).map_err(EnvError::from)
    }
}
