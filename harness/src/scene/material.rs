//! Materials in f64: evaluation, importance sampling and its density, for the path tracer;
//! and the parameters the lobe methods read.
//!
//! Every BRDF is `diffuse/π + Σ_k ρ_k·max(a_k·ωi, 0)^{e_k}` with lobe axes `a_k` that
//! depend on the view: modified Phong has one lobe `ρ = specular·(n+2)/(2π)` about the
//! mirror direction; a Lafortune lobe `ρ·max(ωi·M·ωo, 0)^e` (`M = diag(c, c, c_z)` in the
//! shading frame) is `ρ·|M·ωo|^e·max(ωi·a, 0)^e` with `a = M·ωo/|M·ωo|`. The value is 0
//! when `ωi` or `ωo` is below the surface.
//!
//! Sampling picks the diffuse part with probability ∝ its albedo's luminance and lobe `k`
//! ∝ its luminance times its directional albedo bound `2π·ρ_k/(e_k + 1)`; diffuse
//! directions are cosine distributed (pdf `cos θ/π`), lobe directions `cos^e` about the
//! axis (pdf `(e+1)/(2π)·max(a·ωi, 0)^e`). [`Material::pdf`] is the mixture's density,
//! which MIS needs. A GGX material adds its microfacet term (core's `Ggx` in `f64`, tinted
//! by `specular`), picked ∝ the tint's luminance (its albedo bound), with `ωi` the
//! reflection of `ωo` about a normal drawn from `D(h)·cos θh` (pdf
//! `D(h)·cos θh/(4|ωo·h|)`).

use std::f64::consts::{PI, TAU};

use glam::DVec3;

use super::Rgb;
use super::file::MaterialFile;

/// A Lafortune lobe, isotropic (`c_x = c_y = c`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LafortuneLobe {
    /// `c_x = c_y`.
    pub c: f64,
    /// `c_z`.
    pub cz: f64,
    /// Exponent.
    pub exponent: f64,
    /// RGB scale.
    pub rho: Rgb,
}

/// A material.
#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    /// `albedo/π`.
    Lambert {
        /// RGB albedo.
        albedo: Rgb,
    },
    /// Energy-normalised modified Phong.
    Phong {
        /// RGB diffuse albedo.
        diffuse: Rgb,
        /// RGB specular albedo.
        specular: Rgb,
        /// Exponent.
        exponent: f64,
    },
    /// GGX microfacet (core's `Ggx` with an RGB tint): `diffuse/π +
    /// specular·D(h)·G₁(ωi)G₁(ωo)·F(ωi·h)/(4 cos θi cos θo)`.
    Ggx {
        /// RGB diffuse albedo.
        diffuse: Rgb,
        /// RGB tint of the specular term.
        specular: Rgb,
        /// Schlick's reflectance at normal incidence.
        f0: f64,
        /// GGX `α`.
        alpha: f64,
    },
    /// Lafortune with isotropic lobes.
    Lafortune {
        /// RGB diffuse albedo.
        diffuse: Rgb,
        /// The lobes.
        lobes: Vec<LafortuneLobe>,
    },
}

/// One lobe of a material at a given view: `scale·max(axis·ωi, 0)^exponent`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewLobe {
    /// Unit axis.
    pub axis: DVec3,
    /// Exponent.
    pub exponent: f64,
    /// RGB scale (BRDF units).
    pub scale: Rgb,
}

fn lum(c: Rgb) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// `2(n·wo)n − wo`.
pub fn reflect(wo: DVec3, n: DVec3) -> DVec3 {
    2.0 * n.dot(wo) * n - wo
}

/// A unit vector orthogonal to unit `n` and a third completing a right-handed frame
/// (Duff et al. 2017, "Building an orthonormal basis, revisited").
pub fn basis(n: DVec3) -> (DVec3, DVec3) {
    let s = 1f64.copysign(n.z);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
        DVec3::new(b, s + n.y * n.y * a, -n.y),
    )
}

/// A direction with density `(e+1)/(2π)·cos^e θ` about unit `axis`.
fn sample_power_cosine(axis: DVec3, e: f64, u1: f64, u2: f64) -> DVec3 {
    let cos_t = u1.powf(1.0 / (e + 1.0));
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let (t, b) = basis(axis);
    let phi = TAU * u2;
    (sin_t * phi.cos() * t + sin_t * phi.sin() * b + cos_t * axis).normalize()
}

fn power_cosine_pdf(axis: DVec3, e: f64, wi: DVec3) -> f64 {
    let c = axis.dot(wi);
    if c <= 0.0 {
        0.0
    } else {
        (e + 1.0) / TAU * c.powf(e)
    }
}

/// The energy bound of a diffuse-plus-specular material: `diffuse + specular ≤ 1` per
/// channel (the error names the material kind).
fn energy(kind: &str, diffuse: Rgb, specular: Rgb) -> Result<(), String> {
    for c in 0..3 {
        if diffuse[c] + specular[c] > 1.0 {
            return Err(format!(
                "{kind}: diffuse + specular must be ≤ 1 per channel (channel {c}: {})",
                diffuse[c] + specular[c]
            ));
        }
    }
    Ok(())
}

impl Material {
    /// From the validated file form; the error names the sub-field.
    pub fn from_file(m: &MaterialFile) -> Result<Material, String> {
        Ok(match m {
            MaterialFile::Lambert { albedo } => Material::Lambert { albedo: albedo.0 },
            MaterialFile::Phong {
                diffuse,
                specular,
                exponent,
            } => {
                energy("phong", diffuse.0, specular.0)?;
                Material::Phong {
                    diffuse: diffuse.0,
                    specular: specular.0,
                    exponent: exponent.0,
                }
            }
            MaterialFile::Ggx {
                diffuse,
                specular,
                f0,
                roughness,
            } => {
                energy("ggx", diffuse.0, specular.0)?;
                Material::Ggx {
                    diffuse: diffuse.0,
                    specular: specular.0,
                    f0: f0.0,
                    alpha: roughness.0,
                }
            }
            MaterialFile::Lafortune { diffuse, lobes } => {
                if lobes.is_empty() || lobes.len() > 4 {
                    return Err(format!(
                        "lafortune.lobes: must hold 1 to 4 lobes (got {})",
                        lobes.len()
                    ));
                }
                let mut out = Vec::new();
                for (k, l) in lobes.iter().enumerate() {
                    if l.c.0[0] != l.c.0[1] {
                        return Err(format!(
                            "lafortune.lobes[{k}].c: must be isotropic, c[0] == c[1] (got {:?})",
                            l.c.0
                        ));
                    }
                    out.push(LafortuneLobe {
                        c: l.c.0[0],
                        cz: l.c.0[2],
                        exponent: l.exponent.0,
                        rho: l.rho.0,
                    });
                }
                Material::Lafortune {
                    diffuse: diffuse.0,
                    lobes: out,
                }
            }
        })
    }

    /// The diffuse albedo.
    pub fn diffuse(&self) -> Rgb {
        match self {
            Material::Lambert { albedo } => *albedo,
            Material::Phong { diffuse, .. }
            | Material::Lafortune { diffuse, .. }
            | Material::Ggx { diffuse, .. } => *diffuse,
        }
    }

    /// The glossy lobes at unit normal `n` and unit view `wo` (toward the viewer); at most
    /// [`MAX_LOBES`] (a Lafortune material is validated to 1–4 lobes; more are ignored).
    pub fn lobes(&self, n: DVec3, wo: DVec3) -> ViewLobes {
        let mut out = ViewLobes::default();
        match self {
            Material::Lambert { .. } | Material::Ggx { .. } => {}
            Material::Phong {
                specular, exponent, ..
            } => {
                let k = (exponent + 2.0) / TAU;
                out.push(ViewLobe {
                    axis: reflect(wo, n),
                    exponent: *exponent,
                    scale: specular.map(|s| s * k),
                });
            }
            Material::Lafortune { lobes, .. } => {
                let z = wo.dot(n);
                for l in lobes {
                    let m = l.c * (wo - z * n) + l.cz * z * n;
                    let len = m.length();
                    if len > 0.0 {
                        let k = len.powf(l.exponent);
                        out.push(ViewLobe {
                            axis: m / len,
                            exponent: l.exponent,
                            scale: l.rho.map(|r| r * k),
                        });
                    }
                }
            }
        }
        out
    }

    /// `f_r(ωi, ωo)` (no cosine), 0 unless both are above the surface.
    pub fn eval(&self, n: DVec3, wo: DVec3, wi: DVec3) -> Rgb {
        if n.dot(wi) <= 0.0 || n.dot(wo) <= 0.0 {
            return [0.0; 3];
        }
        let mut f = self.diffuse().map(|d| d / PI);
        if let Material::Ggx {
            specular,
            f0,
            alpha,
            ..
        } = self
        {
            let s = ggx_specular(n, wo, wi, *f0, *alpha);
            for (fc, k) in f.iter_mut().zip(specular) {
                *fc += k * s;
            }
        }
        for l in self.lobes(n, wo).iter() {
            let c = l.axis.dot(wi);
            if c > 0.0 {
                let v = c.powf(l.exponent);
                for (fc, s) in f.iter_mut().zip(l.scale) {
                    *fc += s * v;
                }
            }
        }
        f
    }

    /// The sampling mixture at this view: `None` when the material reflects nothing.
    fn mixture(&self, n: DVec3, wo: DVec3) -> Option<Mixture> {
        if n.dot(wo) <= 0.0 {
            return None;
        }
        let lobes = self.lobes(n, wo);
        let mut w = [0.0; MAX_LOBES];
        for (wk, l) in w.iter_mut().zip(lobes.iter()) {
            *wk = lum(l.scale) * TAU / (l.exponent + 1.0);
        }
        let d = lum(self.diffuse());
        // GGX: its specular albedo is at most the tint's (F ≤ 1, G₂ ≤ 1).
        let ggx = match self {
            Material::Ggx {
                specular, alpha, ..
            } => Some((lum(*specular), *alpha)),
            _ => None,
        };
        let total = d + w.iter().sum::<f64>() + ggx.map_or(0.0, |g| g.0);
        (total > 0.0 && total.is_finite()).then_some(Mixture {
            n,
            wo,
            lobes,
            d,
            w,
            ggx,
            total,
        })
    }

    /// Samples `ωi`; returns it with the mixture density, or `None` when the material
    /// reflects nothing from this view.
    pub fn sample(&self, n: DVec3, wo: DVec3, u: [f64; 3]) -> Option<(DVec3, f64)> {
        let m = self.mixture(n, wo)?;
        let mut pick = u[0] * m.total;
        let wi = if pick < m.d || (m.lobes.is_empty() && m.ggx.is_none()) {
            sample_power_cosine(n, 1.0, u[1], u[2])
        } else if let Some((_, alpha)) = m.ggx {
            let h = sample_ggx_normal(n, alpha, u[1], u[2]);
            reflect(wo, h)
        } else {
            pick -= m.d;
            let mut k = m.lobes.len() - 1;
            for (i, wk) in m.w.iter().enumerate().take(m.lobes.len()) {
                if pick < *wk {
                    k = i;
                    break;
                }
                pick -= wk;
            }
            sample_power_cosine(m.lobes[k].axis, m.lobes[k].exponent, u[1], u[2])
        };
        let pdf = m.pdf(wi);
        (pdf > 0.0).then_some((wi, pdf))
    }

    /// The density [`Material::sample`] draws `ωi` with.
    pub fn pdf(&self, n: DVec3, wo: DVec3, wi: DVec3) -> f64 {
        self.mixture(n, wo).map_or(0.0, |m| m.pdf(wi))
    }
}

/// Most glossy lobes a material has.
pub const MAX_LOBES: usize = 4;

/// The glossy lobes of a material at one view, without allocating.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewLobes {
    lobes: [ViewLobe; MAX_LOBES],
    len: usize,
}

impl ViewLobes {
    fn push(&mut self, l: ViewLobe) {
        if self.len < MAX_LOBES {
            self.lobes[self.len] = l;
            self.len += 1;
        }
    }
}

impl std::ops::Deref for ViewLobes {
    type Target = [ViewLobe];
    fn deref(&self) -> &[ViewLobe] {
        &self.lobes[..self.len]
    }
}

/// The sampling mixture of one view: diffuse weight `d`, lobe weights `w`, and the GGX
/// weight and `α` of a GGX material.
struct Mixture {
    n: DVec3,
    wo: DVec3,
    lobes: ViewLobes,
    d: f64,
    w: [f64; MAX_LOBES],
    ggx: Option<(f64, f64)>,
    total: f64,
}

impl Mixture {
    fn pdf(&self, wi: DVec3) -> f64 {
        let mut p = self.d / self.total * power_cosine_pdf(self.n, 1.0, wi);
        for (l, wk) in self.lobes.iter().zip(&self.w) {
            p += wk / self.total * power_cosine_pdf(l.axis, l.exponent, wi);
        }
        if let Some((wg, alpha)) = self.ggx {
            p += wg / self.total * ggx_reflection_pdf(self.n, self.wo, wi, alpha);
        }
        p
    }
}

/// The GGX normal distribution `D(h) = α²/(π((n·h)²(α² − 1) + 1)²)` (Walter et al. 2007,
/// eq. 33), 0 for `n·h ≤ 0`.
fn ggx_d(c: f64, alpha: f64) -> f64 {
    if c <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let t = c * c * (a2 - 1.0) + 1.0;
    a2 / (PI * t * t)
}

/// The GGX microfacet term (no diffuse, no cosine) of the f64 reference model
/// (`steradian_reference::lobe::brdf::Model::Ggx`: GGX `D`, separable Smith `G₁`,
/// Schlick's `F`, the formula of core's `Ggx`), with `ωi`, `ωo` taken into the frame of `n`.
fn ggx_specular(n: DVec3, wo: DVec3, wi: DVec3, f0: f64, alpha: f64) -> f64 {
    let (t, b) = basis(n);
    let local = |v: DVec3| [v.dot(t), v.dot(b), v.dot(n)];
    steradian_reference::lobe::brdf::Model::Ggx { kd: 0.0, f0, alpha }.rho(local(wi), local(wo))
}

/// A microfacet normal with density `D(h)·(n·h)`: `tan²θ = α²u/(1 − u)` (inverting the
/// GGX `D·cos` marginal), `φ = 2πu₂`.
fn sample_ggx_normal(n: DVec3, alpha: f64, u1: f64, u2: f64) -> DVec3 {
    let t2 = alpha * alpha * u1 / (1.0 - u1).max(1e-300);
    let cos_t = 1.0 / (1.0 + t2).sqrt();
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let (t, b) = basis(n);
    let phi = TAU * u2;
    (sin_t * phi.cos() * t + sin_t * phi.sin() * b + cos_t * n).normalize()
}

/// The density of `ωi = reflect(ωo, h)` with `h` from [`sample_ggx_normal`]:
/// `D(h)(n·h)/(4|ωo·h|)` (the Jacobian of the reflection, Walter et al. eq. 14).
fn ggx_reflection_pdf(n: DVec3, wo: DVec3, wi: DVec3, alpha: f64) -> f64 {
    let h = wi + wo;
    let len = h.length();
    if len == 0.0 {
        return 0.0;
    }
    let h = h / len;
    let c = n.dot(h);
    let oh = wo.dot(h).abs();
    if c <= 0.0 || oh == 0.0 {
        return 0.0;
    }
    ggx_d(c, alpha) * c / (4.0 * oh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn materials() -> Vec<Material> {
        vec![
            Material::Lambert {
                albedo: [0.8, 0.5, 0.2],
            },
            Material::Phong {
                diffuse: [0.5, 0.1, 0.1],
                specular: [0.3, 0.3, 0.3],
                exponent: 80.0,
            },
            Material::Lafortune {
                diffuse: [0.2, 0.2, 0.2],
                lobes: vec![LafortuneLobe {
                    c: -0.9,
                    cz: 0.8,
                    exponent: 20.0,
                    rho: [0.5, 0.4, 0.3],
                }],
            },
            Material::Ggx {
                diffuse: [0.3, 0.2, 0.1],
                specular: [0.6, 0.6, 0.6],
                f0: 0.04,
                alpha: 0.2,
            },
            Material::Ggx {
                diffuse: [0.0; 3],
                specular: [1.0; 3],
                f0: 0.9,
                alpha: 0.05,
            },
        ]
    }

    /// The sampler draws with the density it reports: `E[f·cos/pdf]` equals the
    /// directional albedo computed by a midpoint quadrature over the hemisphere, and
    /// `E[1/pdf]` over the support equals its solid angle, within 4 standard errors.
    #[test]
    fn sampling_density_matches_pdf() {
        let n = DVec3::new(0.3, -0.2, 0.9).normalize();
        let wo = DVec3::new(-0.5, 0.1, 0.6).normalize();
        for m in materials() {
            let mut rng = Rng::new(7);
            let samples = 400_000;
            let (mut s, mut s2) = (0.0, 0.0);
            for _ in 0..samples {
                let u = [rng.unit(), rng.unit(), rng.unit()];
                let Some((wi, pdf)) = m.sample(n, wo, u) else {
                    continue;
                };
                assert!((pdf - m.pdf(n, wo, wi)).abs() <= 1e-9 * pdf);
                let v = m.eval(n, wo, wi)[1] * n.dot(wi).max(0.0) / pdf;
                s += v;
                s2 += v * v;
            }
            let mean = s / samples as f64;
            let se = ((s2 / samples as f64 - mean * mean) / samples as f64).sqrt();
            // Quadrature of the albedo in the frame of n (θ, φ midpoints).
            let (t, b) = basis(n);
            let (nt, np) = (2000, 800);
            let mut q = 0.0;
            for i in 0..nt {
                let th = (i as f64 + 0.5) / nt as f64 * PI / 2.0;
                for j in 0..np {
                    let ph = (j as f64 + 0.5) / np as f64 * TAU;
                    let wi = th.sin() * (ph.cos() * t + ph.sin() * b) + th.cos() * n;
                    q += m.eval(n, wo, wi)[1] * th.cos() * th.sin();
                }
            }
            q *= (PI / 2.0 / nt as f64) * (TAU / np as f64);
            assert!(
                (mean - q).abs() < 4.0 * se + 1e-4 * q,
                "{m:?}: sampled {mean} ± {se}, quadrature {q}"
            );
        }
    }

    /// The GGX material is core's `Ggx` (in `f64`, with an RGB tint): the same value at
    /// random directions, to `f32` precision (1e-4 relative: core's `f32` `D` loses a few
    /// bits at `α = 1e-3` where the half vector is nearly tangent).
    #[test]
    fn ggx_is_cores_ggx() {
        use steradian_core::lobe::brdf::{Brdf, Ggx};
        let mut rng = Rng::new(3);
        let n = DVec3::Z;
        for &(f0, alpha) in &[(0.04, 0.2), (0.9, 0.05), (0.5, 1.0), (0.0, 0.001)] {
            let m = Material::Ggx {
                diffuse: [0.0; 3],
                specular: [1.0; 3],
                f0,
                alpha,
            };
            let g = Ggx::new(0.0, f0 as f32, alpha as f32).unwrap();
            for _ in 0..2000 {
                let wi = DVec3::from(rng.sphere());
                let wo = DVec3::from(rng.sphere());
                let (wi, wo) = (
                    DVec3::new(wi.x, wi.y, wi.z.abs()),
                    DVec3::new(wo.x, wo.y, wo.z.abs()),
                );
                let ours = m.eval(n, wo, wi)[0] * wi.z;
                let core = g.eval(wi.as_vec3(), wo.as_vec3()) as f64;
                assert!(
                    (ours - core).abs() <= 1e-4 * ours.abs().max(1e-3),
                    "f0 {f0} α {alpha}: {ours} vs {core} at {wi} {wo}"
                );
            }
        }
    }

    #[test]
    fn below_the_surface_is_black() {
        let n = DVec3::Z;
        for m in materials() {
            assert_eq!(m.eval(n, DVec3::Z, -DVec3::Z), [0.0; 3]);
            assert_eq!(m.eval(n, -DVec3::Z, DVec3::Z), [0.0; 3]);
            assert!(m.sample(n, -DVec3::Z, [0.5; 3]).is_none());
        }
    }

    #[test]
    fn basis_is_orthonormal_at_the_poles() {
        for n in [DVec3::Z, -DVec3::Z, DVec3::X, DVec3::new(0.0, 1e-300, -1.0)] {
            let n = n.normalize();
            let (t, b) = basis(n);
            for (x, y) in [(t, b), (t, n), (b, n)] {
                assert!(x.dot(y).abs() < 1e-12);
            }
            assert!((t.cross(b) - n).length() < 1e-12);
        }
    }
}
