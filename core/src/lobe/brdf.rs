//! Analytic BRDF models in the local shading frame, with the cosine term folded in.
//!
//! The rotatable-square-lights paper (section 4.2) tabulates `ρ(ω, ω₀)` integrated over
//! squares of the equal-area hemisphere parametrisation; as there (and as the cosine-lobe
//! paper's eq. 26 does for the diffuse lobe), every model here returns the **cosine-weighted
//! BRDF** `ρ(wᵢ, wₒ)·cos θᵢ`, so that `∫_Ω eval(wᵢ, wₒ) dωᵢ` is the directional albedo and a
//! summed-area table of it sums to the reflected radiance of a unit-radiance light.
//!
//! **Frame.** `z` = surface normal, `x` = tangent, `y` = bitangent (crate conventions);
//! `wᵢ` (towards the light) and `wₒ` (towards the viewer) are **unit** vectors in that frame.
//! `h = wᵢ + wₒ` is the unnormalised half vector, `ĥ = h/|h|`, `|h|² = 2(1 + wᵢ·wₒ)`.
//!
//! | model | `ρ(wᵢ, wₒ)` | source |
//! |---|---|---|
//! | [`Lambert`] | `a/π` | — |
//! | [`Phong`] | `k_d/π + k_s·(e+2)/(2π)·max(r·wᵢ, 0)^e`, `r = (−wₒx, −wₒy, wₒz)` | Lewis 1994 ("modified Phong"); the same normalisation as [`crate::lobe::Phong::modified`] |
//! | [`BlinnPhong`] | `k_d/π + k_s·(e+8)/(8π)·(ĥ_z)^e` | Blinn 1977; normalisation of Akenine-Möller, Haines & Hoffman, *Real-Time Rendering* 3rd ed., eq. 7.49 |
//! | [`Ward`] | `ρ_d/π + ρ_s·exp(−((h_x/α_x)² + (h_y/α_y)²)/h_z²)/(4π·α_x·α_y·√(cos θᵢ cos θₒ))` | Ward 1992, eq. 5a (isotropic eq. 4a: `α_x = α_y`) |
//! | [`crate::lobe::Lafortune`] | `Σ_k ρ_k·max(C_x wᵢx wₒx + C_y wᵢy wₒy + C_z wᵢz wₒz, 0)^(e_k)` | Lafortune, Foo, Torrance, Greenberg 1997 |
//! | [`Ggx`] | `k_d/π + D(ĥ)·G₂·F/(4 cos θᵢ cos θₒ)` | Cook & Torrance 1982 microfacet form; GGX `D` of Walter et al. 2007 eq. 33; separable Smith `G₂ = G₁(wᵢ)G₁(wₒ)` with Walter eq. 34; Schlick 1994 Fresnel |
//!
//! GGX details: `D = α²/(π((α²−1)ĥ_z² + 1)²)`, written as `α²|h|⁴/(π(h_x² + h_y² + α²h_z²)²)`
//! (no cancellation at the peak); `G₁(v) = 2v_z/(v_z + √(α² + (1−α²)v_z²))`, so that
//! `G₂/(4 cos θᵢ cos θₒ) = 1/((cᵢ + sᵢ)(cₒ + sₒ))` with `s = √(α² + (1−α²)c²)`: no division
//! by a vanishing cosine at grazing angles; `F = F₀ + (1 − F₀)(1 − wᵢ·ĥ)⁵` with
//! `wᵢ·ĥ = √((1 + wᵢ·wₒ)/2)`.
//!
//! **Energy** (directional albedo `∫ρ cos θᵢ dωᵢ`, measured against the `f64` reference in
//! `harness/tests/brdf.rs` for views up to 89°; the tests `energy_at_most_one` and
//! `albedo_claims_blinn_phong_bound_and_ward_at_89_degrees` assert the bounds below):
//! - Lambert: exactly `a`. Phong: `k_d·(…) + k_s·(…) ≤ k_d + k_s`, with the specular albedo
//!   exactly `k_s` at normal incidence (`∫cos^(e+1) = 2π/(e+2)`) and falling towards
//!   grazing views.
//! - Blinn–Phong: `(e+8)/(8π)` is an approximate normalisation; the specular albedo reaches
//!   [`BLINN_PHONG_ALBEDO_BOUND`]`·k_s` (measured: 1.075 at `e = 10`, 1.054 at `e = 3`,
//!   1.018 at `e = 100`, 1.002 at `e = 1000`), so `k_d + k_s ≤ 1/1.08` conserves energy.
//! - Ward (original normalisation): the specular albedo is `≈ ρ_s` at normal incidence and
//!   falls roughly like `cos θₒ` for small `α` (measured ≤ 0.5·ρ_s at 89° for `α ≤ 1`):
//!   `ρ_d + ρ_s ≤ 1` conserves energy.
//! - GGX: single scattering with `F ≤ 1` loses energy, the specular albedo is `≤ 1`
//!   (measured for `α` = 0.01, 0.3, 1 with `F₀ = 1`); `k_d + 1 ≤ 1` is the safe bound, and
//!   `k_d + F₀` is not (the Lambert term ignores the light the specular part took).
//!
//! **Reciprocity.** Every model is symmetric in `wᵢ ↔ wₒ` as a BRDF:
//! `eval(wᵢ, wₒ)/cos θᵢ = eval(wₒ, wᵢ)/cos θₒ` (tested in the harness).
//!
//! **Accuracy.** `eval` is `f32` arithmetic on closed forms. Against an `f64` evaluation of
//! the textbook formulas on the same (f32-rounded) directions, the relative error is at most
//! [`EVAL_REL_ERROR`]` + `[`EVAL_SHARPNESS_ERROR`]`/a²` with `a` = [`Brdf::feature_angle`],
//! where the value exceeds `10⁻⁶` of the model's peak (checked in `harness/tests/brdf.rs`;
//! measured 1.4e-6 for smooth models, 6.9e-4 for Phong `e = 10⁴`, 2.8e-5 for GGX
//! `α = 0.01`). The second term is the lobe's sensitivity to the `~6e-8` by which f32
//! "unit" vectors miss unit length (`e·δ` for an exponent `e ≈ 1/a²`).
//!
//! **Bad input** (never panics): `eval` returns NaN when any component of `wᵢ` or `wₒ` is
//! NaN, `0` when `wᵢ` or `wₒ` is on or below the horizon (`z ≤ 0`). Non-unit inputs are not
//! normalised (the caller's frame transform produces unit vectors); the result is finite for
//! any finite input. Constructors validate parameters and return [`Error`].
//!
//! # References
//!
//! - R. R. Lewis, "Making shaders more physically plausible", *Computer Graphics Forum*
//!   13(2), pp. 109–120, 1994. DOI: 10.1111/1467-8659.1320109.
//! - J. F. Blinn, "Models of light reflection for computer synthesized pictures",
//!   *SIGGRAPH '77* (Computer Graphics 11(2)), pp. 192–198, 1977.
//!   DOI: 10.1145/965141.563893.
//! - G. J. Ward, "Measuring and modeling anisotropic reflection", *SIGGRAPH '92*
//!   (Computer Graphics 26(2)), pp. 265–272, 1992.
//! - R. L. Cook, K. E. Torrance, "A reflectance model for computer graphics", *ACM
//!   Transactions on Graphics* 1(1), pp. 7–24, 1982. DOI: 10.1145/357290.357293.
//! - B. Walter, S. R. Marschner, H. Li, K. E. Torrance, "Microfacet models for refraction
//!   through rough surfaces", *Eurographics Symposium on Rendering*, 2007.
//! - C. Schlick, "An inexpensive BRDF model for physically-based rendering", *Computer
//!   Graphics Forum* 13(3), pp. 233–246, 1994. DOI: 10.1111/1467-8659.1330233.

use crate::lobe;
use crate::math;
use crate::{Error, PI, TWO_PI, Vec3};

/// Largest directional albedo of [`BlinnPhong`] with `k_d = 0, k_s = 1` over exponents and
/// views up to 89° (measured in the harness; 1.075 at `e = 10`; asserted for
/// `e ∈ {0, 1, 3, 10, 30, 100, 1000}`).
pub const BLINN_PHONG_ALBEDO_BOUND: f32 = 1.08;

/// Relative error bound of the models' `eval` against an `f64` evaluation of the same
/// formulas, plus [`EVAL_SHARPNESS_ERROR`]`/a²` (module docs).
pub const EVAL_REL_ERROR: f32 = 1.0e-5;
/// Sharp-lobe term of the `eval` error bound, divided by `feature_angle²` (module docs).
pub const EVAL_SHARPNESS_ERROR: f32 = 1.0e-7;

/// A BRDF in the local shading frame with the cosine term folded in.
pub trait Brdf {
    /// `ρ(wᵢ, wₒ)·cos θᵢ` for unit `wᵢ` (towards the light) and `wₒ` (towards the viewer)
    /// in the local frame; `0` on or below either horizon; NaN in → NaN out.
    fn eval(&self, wi: Vec3, wo: Vec3) -> f32;

    /// Whether `ρ` depends only on `θᵢ`, `θₒ` and `φᵢ − φₒ` (rotations about the normal).
    fn is_isotropic(&self) -> bool;

    /// An angular scale (radians) of the narrowest feature of `ρ` in `wᵢ`, about the width
    /// of the specular lobe; table builders refine their quadrature to a fraction of it.
    fn feature_angle(&self) -> f32;

    /// A short name for reports.
    fn name(&self) -> &'static str;
}

/// `NaN` if any component of either direction is NaN, `0` if either is on or below the
/// horizon, `None` otherwise.
#[inline]
fn guard(wi: Vec3, wo: Vec3) -> Option<f32> {
    if wi.is_nan() || wo.is_nan() {
        Some(f32::NAN)
    } else if wi.z <= 0.0 || wo.z <= 0.0 {
        Some(0.0)
    } else {
        None
    }
}

fn check(what: &'static str, v: f32, min: f32, max: f32) -> Result<f32, Error> {
    if !v.is_finite() {
        return Err(Error::NonFinite { what });
    }
    if !(min..=max).contains(&v) {
        return Err(Error::OutOfRange {
            what,
            value: v,
            min,
            max,
        });
    }
    Ok(v)
}

/// The Lambertian BRDF `a/π`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambert {
    albedo: f32,
}

impl Lambert {
    /// Albedo `a ∈ [0, 1]`.
    pub fn new(albedo: f32) -> Result<Self, Error> {
        Ok(Lambert {
            albedo: check("albedo", albedo, 0.0, 1.0)?,
        })
    }
    /// The albedo `a`.
    pub fn albedo(&self) -> f32 {
        self.albedo
    }
}

impl Brdf for Lambert {
    #[inline]
    fn eval(&self, wi: Vec3, wo: Vec3) -> f32 {
        if let Some(g) = guard(wi, wo) {
            return g;
        }
        self.albedo / PI * wi.z
    }
    fn is_isotropic(&self) -> bool {
        true
    }
    fn feature_angle(&self) -> f32 {
        1.0
    }
    fn name(&self) -> &'static str {
        "Lambert"
    }
}

/// Energy-normalised modified Phong (Lewis 1994):
/// `ρ = k_d/π + k_s·(e+2)/(2π)·max(r·wᵢ, 0)^e` with `r` the mirror direction of `wₒ`.
///
/// The same model as [`crate::lobe::Phong::modified`]: its diffuse lobe (which already has
/// the cosine folded in) plus its specular lobe times `cos θᵢ`. With the cosine, the
/// specular albedo at normal incidence is exactly `k_s` (`∫cos^(e+1) = 2π/(e+2)`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phong {
    kd: f32,
    ks: f32,
    exponent: f32,
}

impl Phong {
    /// Diffuse `k_d ≥ 0`, specular `k_s ≥ 0` (both finite; `k_d + k_s ≤ 1` conserves
    /// energy) and exponent `e ∈ [0, 1e6]`.
    pub fn new(kd: f32, ks: f32, exponent: f32) -> Result<Self, Error> {
        Ok(Phong {
            kd: check("kd", kd, 0.0, f32::MAX)?,
            ks: check("ks", ks, 0.0, f32::MAX)?,
            exponent: check("Phong exponent", exponent, 0.0, 1e6)?,
        })
    }
    /// `(k_d, k_s, e)`.
    pub fn params(&self) -> (f32, f32, f32) {
        (self.kd, self.ks, self.exponent)
    }
}

impl Brdf for Phong {
    #[inline]
    fn eval(&self, wi: Vec3, wo: Vec3) -> f32 {
        if let Some(g) = guard(wi, wo) {
            return g;
        }
        let r = Vec3::new(-wo.x, -wo.y, wo.z);
        let spec = lobe::eval(
            r,
            self.ks * (self.exponent + 2.0) / TWO_PI,
            self.exponent,
            wi,
        );
        (self.kd / PI + spec) * wi.z
    }
    fn is_isotropic(&self) -> bool {
        true
    }
    fn feature_angle(&self) -> f32 {
        if self.ks == 0.0 {
            1.0
        } else {
            (1.0 / math::sqrtf(self.exponent + 1.0)).min(1.0)
        }
    }
    fn name(&self) -> &'static str {
        "Phong"
    }
}

/// Blinn–Phong with the normalisation `(e+8)/(8π)`:
/// `ρ = k_d/π + k_s·(e+8)/(8π)·ĥ_z^e`.
///
/// `(e+8)/(8π)` is the usual approximate normalisation (Real-Time Rendering 3rd ed., eq. 7.49);
/// the harness measures the resulting albedo (≤ 1 for `k_d + k_s ≤ 1`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlinnPhong {
    kd: f32,
    ks: f32,
    exponent: f32,
}

impl BlinnPhong {
    /// Diffuse `k_d ≥ 0`, specular `k_s ≥ 0` (finite) and exponent `e ∈ [0, 1e6]`.
    pub fn new(kd: f32, ks: f32, exponent: f32) -> Result<Self, Error> {
        Ok(BlinnPhong {
            kd: check("kd", kd, 0.0, f32::MAX)?,
            ks: check("ks", ks, 0.0, f32::MAX)?,
            exponent: check("Blinn-Phong exponent", exponent, 0.0, 1e6)?,
        })
    }
    /// `(k_d, k_s, e)`.
    pub fn params(&self) -> (f32, f32, f32) {
        (self.kd, self.ks, self.exponent)
    }
}

impl Brdf for BlinnPhong {
    #[inline]
    fn eval(&self, wi: Vec3, wo: Vec3) -> f32 {
        if let Some(g) = guard(wi, wo) {
            return g;
        }
        let h = wi + wo;
        // ĥ_z^e = exp(e/2·ln(h_z²/|h|²)) = exp(e/2·log1p(−(h_x² + h_y²)/|h|²)).
        let hh = h.dot(h);
        let t = (h.x * h.x + h.y * h.y) / hh;
        let spec = if t < 1.0 {
            self.ks * (self.exponent + 8.0) / (8.0 * PI)
                * math::expf(0.5 * self.exponent * math::log1pf(-t))
        } else {
            0.0
        };
        (self.kd / PI + spec) * wi.z
    }
    fn is_isotropic(&self) -> bool {
        true
    }
    fn feature_angle(&self) -> f32 {
        if self.ks == 0.0 {
            1.0
        } else {
            (2.0 / math::sqrtf(self.exponent + 1.0)).min(1.0)
        }
    }
    fn name(&self) -> &'static str {
        "Blinn-Phong"
    }
}

/// Ward's anisotropic Gaussian model (Ward 1992, eq. 5a):
/// `ρ = ρ_d/π + ρ_s·exp(−((h_x/α_x)² + (h_y/α_y)²)/h_z²)/(4π·α_x·α_y·√(cos θᵢ cos θₒ))`,
/// roughness `α_x` along the tangent (`x`) and `α_y` along the bitangent (`y`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ward {
    rd: f32,
    rs: f32,
    ax: f32,
    ay: f32,
}

impl Ward {
    /// Isotropic Ward (eq. 4a): `α_x = α_y = α`.
    pub fn isotropic(rd: f32, rs: f32, alpha: f32) -> Result<Self, Error> {
        Self::anisotropic(rd, rs, alpha, alpha)
    }
    /// Anisotropic Ward: `ρ_d, ρ_s ≥ 0` finite, roughness `α_x, α_y ∈ [1e-3, 1]`.
    pub fn anisotropic(rd: f32, rs: f32, ax: f32, ay: f32) -> Result<Self, Error> {
        Ok(Ward {
            rd: check("rho_d", rd, 0.0, f32::MAX)?,
            rs: check("rho_s", rs, 0.0, f32::MAX)?,
            ax: check("alpha_x", ax, 1e-3, 1.0)?,
            ay: check("alpha_y", ay, 1e-3, 1.0)?,
        })
    }
    /// `(ρ_d, ρ_s, α_x, α_y)`.
    pub fn params(&self) -> (f32, f32, f32, f32) {
        (self.rd, self.rs, self.ax, self.ay)
    }
}

impl Brdf for Ward {
    #[inline]
    fn eval(&self, wi: Vec3, wo: Vec3) -> f32 {
        if let Some(g) = guard(wi, wo) {
            return g;
        }
        let h = wi + wo;
        let (qx, qy) = (h.x / self.ax, h.y / self.ay);
        let k = (qx * qx + qy * qy) / (h.z * h.z);
        // ρ_s·e^(−k)·cos θᵢ/(4π α_x α_y √(cos θᵢ cos θₒ)) = … ·√(cos θᵢ/cos θₒ)
        let spec =
            self.rs * math::expf(-k) / (4.0 * PI * self.ax * self.ay) * math::sqrtf(wi.z / wo.z);
        self.rd / PI * wi.z + spec
    }
    fn is_isotropic(&self) -> bool {
        self.ax == self.ay
    }
    fn feature_angle(&self) -> f32 {
        if self.rs == 0.0 {
            1.0
        } else {
            self.ax.min(self.ay)
        }
    }
    fn name(&self) -> &'static str {
        if self.ax == self.ay {
            "Ward"
        } else {
            "Ward anisotropic"
        }
    }
}

/// Cook–Torrance microfacet BRDF with the GGX distribution, separable Smith masking and
/// Schlick's Fresnel, plus a Lambertian term:
/// `ρ = k_d/π + D(ĥ)·G₁(wᵢ)G₁(wₒ)·F(wᵢ·ĥ)/(4 cos θᵢ cos θₒ)` (formulas in the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    kd: f32,
    f0: f32,
    alpha: f32,
}

impl Ggx {
    /// Diffuse `k_d ≥ 0` (finite), normal-incidence reflectance `F₀ ∈ [0, 1]` and roughness
    /// `α ∈ [1e-3, 1]` (`α` = perceptual roughness squared).
    pub fn new(kd: f32, f0: f32, alpha: f32) -> Result<Self, Error> {
        Ok(Ggx {
            kd: check("kd", kd, 0.0, f32::MAX)?,
            f0: check("F0", f0, 0.0, 1.0)?,
            alpha: check("GGX alpha", alpha, 1e-3, 1.0)?,
        })
    }
    /// `(k_d, F₀, α)`.
    pub fn params(&self) -> (f32, f32, f32) {
        (self.kd, self.f0, self.alpha)
    }
}

impl Brdf for Ggx {
    #[inline]
    fn eval(&self, wi: Vec3, wo: Vec3) -> f32 {
        if let Some(g) = guard(wi, wo) {
            return g;
        }
        let a2 = self.alpha * self.alpha;
        let h = wi + wo;
        let hh = h.dot(h);
        let den = h.x * h.x + h.y * h.y + a2 * h.z * h.z;
        let d = a2 * (hh / den) * (hh / den) / PI;
        let (ci, co) = (wi.z, wo.z);
        let si = math::sqrtf(a2 + (1.0 - a2) * ci * ci);
        let so = math::sqrtf(a2 + (1.0 - a2) * co * co);
        let cos_d = math::sqrtf((0.5 * hh * 0.5).clamp(0.0, 1.0));
        let m = 1.0 - cos_d;
        let m2 = m * m;
        let f = self.f0 + (1.0 - self.f0) * m2 * m2 * m;
        let spec = d * f / ((ci + si) * (co + so));
        (self.kd / PI + spec) * ci
    }
    fn is_isotropic(&self) -> bool {
        true
    }
    fn feature_angle(&self) -> f32 {
        self.alpha
    }
    fn name(&self) -> &'static str {
        "GGX"
    }
}

impl<const N: usize> Brdf for crate::lobe::Lafortune<N> {
    /// `Σ_k ρ_k·max(C_x·wᵢx·wₒx + C_y·wᵢy·wₒy + C_z·wᵢz·wₒz, 0)^(e_k)·cos θᵢ` (Lafortune
    /// et al. 1997, eq. 28 of the cosine-lobe paper); a lobe with `C = (0, 0, 1)` and
    /// `e = 0` is a constant (diffuse) term.
    #[inline]
    fn eval(&self, wi: Vec3, wo: Vec3) -> f32 {
        if let Some(g) = guard(wi, wo) {
            return g;
        }
        let mut rho = 0.0;
        for l in &self.lobes {
            let d = l.c.x * wi.x * wo.x + l.c.y * wi.y * wo.y + l.c.z * wi.z * wo.z;
            if d > 0.0 {
                rho += l.rho
                    * if l.exponent == 0.0 {
                        1.0
                    } else {
                        math::powf(d, l.exponent)
                    };
            }
        }
        rho * wi.z
    }
    fn is_isotropic(&self) -> bool {
        self.lobes.iter().all(|l| l.c.x == l.c.y)
    }
    fn feature_angle(&self) -> f32 {
        self.lobes
            .iter()
            .filter(|l| l.exponent > 0.0)
            .map(|l| 1.0 / math::sqrtf(l.exponent + 1.0))
            .fold(1.0, f32::min)
    }
    fn name(&self) -> &'static str {
        "Lafortune"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(theta: f32, phi: f32) -> Vec3 {
        Vec3::new(
            math::sinf(theta) * math::cosf(phi),
            math::sinf(theta) * math::sinf(phi),
            math::cosf(theta),
        )
    }

    #[test]
    fn constructors_validate() {
        assert!(Lambert::new(1.5).is_err());
        assert!(Phong::new(f32::NAN, 0.0, 1.0).is_err());
        assert!(Phong::new(0.5, -0.1, 1.0).is_err());
        assert!(BlinnPhong::new(0.5, 0.1, f32::INFINITY).is_err());
        assert!(Ward::anisotropic(0.5, 0.1, 0.0, 0.1).is_err());
        assert!(Ggx::new(0.0, 1.5, 0.1).is_err());
        assert!(Ggx::new(0.0, 0.5, 0.0).is_err());
        assert!(Ggx::new(0.0, 0.5, 1.0).is_ok());
    }

    #[test]
    fn phong_matches_the_lobe_module() {
        let p = Phong::new(0.3, 0.6, 40.0).unwrap();
        let l = lobe::Phong::modified(0.3, 0.6, 40.0).unwrap();
        let wo = dir(0.7, 0.4);
        let [d, s] = l.lobes(Vec3::Z, wo);
        for k in 0..50 {
            let wi = dir(0.03 * k as f32, 3.7 + 0.01 * k as f32);
            let want = d.eval(wi) + s.eval(wi) * wi.z;
            let got = p.eval(wi, wo);
            assert!(
                (got - want).abs() <= 1e-5 * want.abs() + 1e-12,
                "{got} {want}"
            );
        }
    }

    #[test]
    fn horizon_nan_and_finite() {
        let models: [&dyn Brdf; 5] = [
            &Lambert::new(0.5).unwrap(),
            &Phong::new(0.2, 0.7, 1e4).unwrap(),
            &BlinnPhong::new(0.2, 0.7, 100.0).unwrap(),
            &Ward::anisotropic(0.2, 0.3, 0.05, 0.2).unwrap(),
            &Ggx::new(0.2, 0.04, 0.01).unwrap(),
        ];
        for m in models {
            assert!(m.eval(Vec3::new(f32::NAN, 0.0, 1.0), Vec3::Z).is_nan());
            assert!(m.eval(Vec3::Z, Vec3::new(0.0, f32::NAN, 1.0)).is_nan());
            assert_eq!(m.eval(Vec3::new(0.6, 0.0, -0.8), Vec3::Z), 0.0);
            assert_eq!(m.eval(Vec3::Z, Vec3::X), 0.0);
            assert_eq!(m.eval(Vec3::X, Vec3::Z), 0.0);
            // opposite grazing directions: h → 0
            let g = Vec3::new(1.0, 0.0, 1e-7);
            let g2 = Vec3::new(-1.0, 0.0, 1e-7);
            assert!(m.eval(g, g2).is_finite(), "{}", m.name());
            assert!(m.eval(Vec3::Z, Vec3::Z).is_finite());
            let big = Vec3::new(3e38, 3e38, 3e38);
            let _ = m.eval(big, Vec3::Z);
            let _ = m.eval(Vec3::new(f32::INFINITY, 0.0, 1.0), Vec3::Z);
        }
    }
}
