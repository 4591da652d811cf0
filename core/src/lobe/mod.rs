//! Cosine lobes and the BRDFs written as lobe sums (cosine-lobe paper, eq. 4–5, 24–30).
//!
//! A cosine lobe is `c(v) = s·max(a·v, 0)^e` (eq. 4) with unit axis `a`, scale `s` and
//! exponent `e ≥ 0`. Its integral over the sphere is exact in closed form,
//! `∫ c = 2π·s/(e + 1)`, so the paper's lobe-integral table (section 4.2) is not needed.
//!
//! **Evaluation.** [`CosineLobe::eval`] computes `t = 1 − a·v` as `|a − v|²/2` (exact for
//! unit vectors) and the power as `exp(e·log1p(−t))`. A plain `powf(a·v, e)` loses
//! `e·2⁻²⁴` relative accuracy to the rounding of the dot product near the axis — 0.6 % at
//! `e = 1e5` — while this form keeps `t` to a few ulps there.
//!
//! **Error bound** (checked against an f64 reference in the harness), for unit `a`, `v`
//! and `c* = s·(a·v)^e > 0`:
//! `|c − c*| ≤ |c*|·(EVAL_REL_ERROR·(1 + |ln(c*/s)|) + e·EVAL_DOT_ERROR/(a·v))`.
//! The first term is the rounding of `t` and of `exp`/`log1p`; the second is the lobe's
//! own sensitivity near its horizon, where `a·v → 0` and a change of `a·v` by the `2⁻²⁴`
//! to which an f32 unit vector is unit changes `c` by `e·δ/(a·v)` relative: no f32 kernel
//! does better there.
//!
//! **Integral.** [`integral`] is within [`INTEGRAL_REL_ERROR`] relative (two roundings).
//!
//! # References
//!
//! - S. Meunier, R. Perrot, L. Aveneau, D. Meneveaux, D. Ghazanfarpour, "Cosine lobes for
//!   interactive direct lighting in dynamic scenes", *Computers & Graphics* 34(6),
//!   pp. 767–778, 2010. DOI: 10.1016/j.cag.2010.08.002. The equation numbers cited in this
//!   folder are those of the earlier technical report (XLIM, HAL hal-00401728, 2009), the
//!   text this crate implements.
//! - R. R. Lewis, "Making shaders more physically plausible", *Computer Graphics Forum*
//!   13(2), pp. 109–120, 1994. DOI: 10.1111/1467-8659.1320109 (the modified Phong model).
//! - E. P. F. Lafortune, S.-C. Foo, K. E. Torrance, D. P. Greenberg, "Non-linear
//!   approximation of reflectance functions", *SIGGRAPH 97 Conference Proceedings*,
//!   pp. 117–126, 1997 (the Lafortune lobes).

pub mod brdf;
pub mod cap;
pub mod mask;
pub mod product;
pub mod sum;

use crate::frame::{Frame, check_dir};
use crate::math;
use crate::{Error, TWO_PI, Vec3};

/// Relative error bound of [`CosineLobe::eval`] per unit of `1 + |ln(c/s)|` (unit `v`).
pub const EVAL_REL_ERROR: f32 = 4.0e-6;
/// Absolute error of the cosine `a·v` implied by f32 unit inputs (two ulps of 1), which
/// enters the bound as `e·EVAL_DOT_ERROR/(a·v)` relative near the horizon.
pub const EVAL_DOT_ERROR: f32 = 2.4e-7;
/// Relative error bound of [`integral`].
pub const INTEGRAL_REL_ERROR: f32 = 2.5e-7;

/// A cosine lobe `s·max(a·v, 0)^e` with unit axis, finite scale and finite exponent `≥ 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct CosineLobe {
    axis: Vec3,
    scale: f32,
    exponent: f32,
}

impl CosineLobe {
    /// The byte layout of the `#[repr(C)]` type, which `wgsl::TYPES` declares as `CosineLobe`.
    pub const LAYOUT: crate::wgsl::Layout = crate::wgsl::Layout {
        name: "CosineLobe",
        size: core::mem::size_of::<CosineLobe>(),
        fields: &[
            ("axis", core::mem::offset_of!(CosineLobe, axis)),
            ("scale", core::mem::offset_of!(CosineLobe, scale)),
            ("exponent", core::mem::offset_of!(CosineLobe, exponent)),
        ],
    };

    /// Validating constructor: `axis` finite and non-zero (normalised here), `scale` finite
    /// (negative scales are allowed: visibility is `1 − Σ w·c`), `exponent` finite and `≥ 0`.
    pub fn new(axis: Vec3, scale: f32, exponent: f32) -> Result<Self, Error> {
        let axis = check_dir(axis, "lobe axis")?;
        if !scale.is_finite() {
            return Err(Error::NonFinite { what: "lobe scale" });
        }
        if !exponent.is_finite() {
            return Err(Error::NonFinite {
                what: "lobe exponent",
            });
        }
        if exponent < 0.0 {
            return Err(Error::OutOfRange {
                what: "lobe exponent",
                value: exponent,
                min: 0.0,
                max: f32::MAX,
            });
        }
        Ok(CosineLobe {
            axis,
            scale,
            exponent,
        })
    }

    /// Saturating constructor for hot paths: the axis is normalised (zero → `+z`), a
    /// negative exponent is clamped to 0, NaN stays NaN (and makes `eval` NaN).
    #[inline]
    pub fn saturating(axis: Vec3, scale: f32, exponent: f32) -> Self {
        let a = crate::frame::normalize_or_zero(axis);
        let axis = if a == Vec3::ZERO { Vec3::Z } else { a };
        // `f32::max` would turn NaN into 0; keep NaN visible.
        let exponent = if exponent < 0.0 { 0.0 } else { exponent };
        CosineLobe {
            axis,
            scale,
            exponent,
        }
    }

    /// Unit axis `a`.
    #[inline]
    pub fn axis(&self) -> Vec3 {
        self.axis
    }
    /// Scale `s`.
    #[inline]
    pub fn scale(&self) -> f32 {
        self.scale
    }
    /// Exponent `e`.
    #[inline]
    pub fn exponent(&self) -> f32 {
        self.exponent
    }

    /// `s·max(a·v, 0)^e` for a unit direction `v` (see the module docs for accuracy).
    /// Zero on and below the lobe's horizon, `s` inside it when `e = 0`.
    #[inline]
    pub fn eval(&self, v: Vec3) -> f32 {
        eval(self.axis, self.scale, self.exponent, v)
    }

    /// The exact integral over the sphere, `2π·s/(e + 1)`.
    #[inline]
    pub fn integral(&self) -> f32 {
        integral(self.exponent, self.scale)
    }
}

/// `s·max(a·v, 0)^e` for unit `a` and `v`, as `s·exp(e·log1p(−|a − v|²/2))`; `0·s` where
/// `a·v ≤ 0` (whatever the exponent). A negative exponent is clamped to 0; NaN in the axis,
/// the direction or the scale gives NaN, and so does a NaN exponent above the horizon.
#[inline]
pub fn eval(axis: Vec3, scale: f32, exponent: f32, v: Vec3) -> f32 {
    let exponent = if exponent < 0.0 { 0.0 } else { exponent };
    let d = axis - v;
    let t = 0.5 * (d.x * d.x + d.y * d.y + d.z * d.z);
    if t >= 1.0 {
        return 0.0 * scale;
    }
    scale * math::expf(exponent * math::log1pf(-t))
}

/// The exact sphere integral of a cosine lobe, `2π·s/(e + 1)`. A negative exponent is
/// clamped to 0; NaN gives NaN; `e = +∞` gives 0.
#[inline]
pub fn integral(exponent: f32, scale: f32) -> f32 {
    let e = if exponent < 0.0 { 0.0 } else { exponent };
    // Divide first: 2π·s overflows for |s| > 5.4e37 even where the integral is finite.
    TWO_PI * (scale / (e + 1.0))
}

/// Reflection of the unit view direction `wo` about the unit normal `n`: `2(n·wo)n − wo`.
#[inline]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    n * (2.0 * n.dot(wo)) - wo
}

/// The Phong reflection model as two lobes (eq. 24–27).
///
/// Original Phong: diffuse lobe `k_d·max(n·v, 0)^1` (the cosine term folded in, eq. 26)
/// and specular lobe `k_s·max(r·v, 0)^e` around the mirror direction `r` of the view
/// (eq. 27, no cosine term, as in the paper). The energy-normalised modified Phong of
/// Lewis (1994), [`Phong::modified`], scales them to `k_d/π` and `k_s·(e + 2)/(2π)`, so
/// that `k_d + k_s ≤ 1` conserves energy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phong {
    kd: f32,
    ks: f32,
    exponent: f32,
    normalised: bool,
}

impl Phong {
    /// Original Phong with diffuse `kd`, specular `ks` (finite, `≥ 0`) and exponent `e ≥ 0`.
    pub fn new(kd: f32, ks: f32, exponent: f32) -> Result<Self, Error> {
        Self::build(kd, ks, exponent, false)
    }

    /// Energy-normalised modified Phong (Lewis 1994).
    pub fn modified(kd: f32, ks: f32, exponent: f32) -> Result<Self, Error> {
        Self::build(kd, ks, exponent, true)
    }

    fn build(kd: f32, ks: f32, exponent: f32, normalised: bool) -> Result<Self, Error> {
        for (what, v) in [("kd", kd), ("ks", ks), ("Phong exponent", exponent)] {
            if !v.is_finite() {
                return Err(Error::NonFinite { what });
            }
            if v < 0.0 {
                return Err(Error::OutOfRange {
                    what,
                    value: v,
                    min: 0.0,
                    max: f32::MAX,
                });
            }
        }
        Ok(Phong {
            kd,
            ks,
            exponent,
            normalised,
        })
    }

    /// The two lobes `[diffuse, specular]` for unit normal `n` and unit direction toward the
    /// viewer `wo` (both in the same frame). A view below the surface still mirrors.
    pub fn lobes(&self, n: Vec3, wo: Vec3) -> [CosineLobe; 2] {
        let (kd, ks) = if self.normalised {
            (
                self.kd / crate::PI,
                self.ks * (self.exponent + 2.0) / TWO_PI,
            )
        } else {
            (self.kd, self.ks)
        };
        let r = reflect(wo, n);
        [
            CosineLobe::saturating(n, kd, 1.0),
            CosineLobe::saturating(r, ks, self.exponent),
        ]
    }
}

/// One lobe of a Lafortune BRDF: `ρ·max(v·M·wo, 0)^e` with `M = diag(cx, cy, cz)` in the
/// shading frame (eq. 28). `cx = cy = −1, cz = 1` is a Phong-like lobe around the mirror
/// direction; `cx ≠ cy` makes it anisotropic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LafortuneLobe {
    /// Diagonal of `M` in the shading frame.
    pub c: Vec3,
    /// Exponent `e ≥ 0`.
    pub exponent: f32,
    /// Scale `ρ`.
    pub rho: f32,
}

/// A Lafortune BRDF with `N` lobes (eq. 28–30).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lafortune<const N: usize> {
    lobes: [LafortuneLobe; N],
}

impl<const N: usize> Lafortune<N> {
    /// Validates every lobe: all fields finite, exponents `≥ 0`.
    pub fn new(lobes: [LafortuneLobe; N]) -> Result<Self, Error> {
        for l in &lobes {
            if !(l.c.is_finite() && l.exponent.is_finite() && l.rho.is_finite()) {
                return Err(Error::NonFinite {
                    what: "Lafortune lobe",
                });
            }
            if l.exponent < 0.0 {
                return Err(Error::OutOfRange {
                    what: "Lafortune exponent",
                    value: l.exponent,
                    min: 0.0,
                    max: f32::MAX,
                });
            }
        }
        Ok(Lafortune { lobes })
    }

    /// The validated lobes.
    pub fn lobe_params(&self) -> &[LafortuneLobe; N] {
        &self.lobes
    }

    /// The cosine lobes for view `wo` (world frame) in shading frame `frame` (eq. 30):
    /// axis `M·wo/|M·wo|`, scale `ρ·|M·wo|^e`. A lobe with `M·wo = 0` gets scale 0 (its
    /// value is `0^e`) and the normal as axis (`1` when `e = 0`, as `0^0 = 1`).
    pub fn lobes(&self, frame: &Frame, wo: Vec3) -> [CosineLobe; N] {
        let w = frame.to_local(wo);
        self.lobes.map(|l| {
            let m = l.c * w;
            let len = math::sqrtf(m.dot(m));
            if len > 0.0 {
                let axis = frame.to_world(m / len);
                CosineLobe::saturating(axis, l.rho * math::powf(len, l.exponent), l.exponent)
            } else {
                let s = if l.exponent == 0.0 { l.rho } else { 0.0 };
                CosineLobe::saturating(frame.normal(), s, 0.0)
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn construction_validates() {
        assert!(CosineLobe::new(Vec3::ZERO, 1.0, 1.0).is_err());
        assert!(CosineLobe::new(Vec3::Z, f32::NAN, 1.0).is_err());
        assert!(CosineLobe::new(Vec3::Z, 1.0, -1.0).is_err());
        assert!(CosineLobe::new(Vec3::Z, 1.0, f32::INFINITY).is_err());
        let l = CosineLobe::new(Vec3::new(0.0, 0.0, 5.0), -2.0, 0.0).unwrap();
        assert_eq!(l.axis(), Vec3::Z);
        let s = CosineLobe::saturating(Vec3::ZERO, 1.0, -3.0);
        assert_eq!((s.axis(), s.exponent()), (Vec3::Z, 0.0));
        assert!(
            CosineLobe::saturating(Vec3::Z, 1.0, f32::NAN)
                .eval(Vec3::Z)
                .is_nan()
        );
    }

    #[test]
    fn exponent_zero_is_hemisphere_indicator() {
        let l = CosineLobe::new(Vec3::Z, 2.0, 0.0).unwrap();
        assert_eq!(l.eval(Vec3::new(0.6, 0.0, 0.8)), 2.0);
        assert_eq!(l.eval(Vec3::X), 0.0);
        assert_eq!(l.eval(-Vec3::Z), 0.0);
        assert_eq!(l.integral(), 2.0 * TWO_PI);
    }

    #[test]
    fn integral_edge_cases() {
        assert_eq!(integral(-5.0, 1.0), TWO_PI);
        assert_eq!(integral(f32::INFINITY, 1.0), 0.0);
        assert!(integral(f32::NAN, 1.0).is_nan());
        assert!((integral(1e5, 1.0) - TWO_PI / 100001.0).abs() < 1e-9);
        assert!(integral(9.0, 3e38).is_finite());
    }

    #[test]
    fn phong_lobes() {
        let p = Phong::new(0.5, 0.25, 20.0).unwrap();
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let [d, s] = p.lobes(Vec3::Z, wo);
        assert_eq!((d.axis(), d.scale(), d.exponent()), (Vec3::Z, 0.5, 1.0));
        assert!((s.axis() - Vec3::new(-0.6, 0.0, 0.8)).length() < 1e-6);
        let m = Phong::modified(0.5, 0.25, 20.0).unwrap();
        let [d, s] = m.lobes(Vec3::Z, wo);
        assert!((d.scale() - 0.5 / crate::PI).abs() < 1e-7);
        assert!((s.scale() - 0.25 * 22.0 / TWO_PI).abs() < 1e-6);
        assert!(Phong::new(-1.0, 0.0, 1.0).is_err());
    }

    #[test]
    fn lafortune_phong_like_lobe_mirrors() {
        let f = Frame::from_normal(Vec3::Z).unwrap();
        let brdf = Lafortune::new([LafortuneLobe {
            c: Vec3::new(-1.0, -1.0, 1.0),
            exponent: 10.0,
            rho: 1.0,
        }])
        .unwrap();
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let [l] = brdf.lobes(&f, wo);
        assert!((l.axis() - Vec3::new(-0.6, 0.0, 0.8)).length() < 1e-6);
        assert!((l.scale() - 1.0).abs() < 1e-6);
        // anisotropic: shrinks the x component
        let a = Lafortune::new([LafortuneLobe {
            c: Vec3::new(-0.5, -1.0, 1.0),
            exponent: 2.0,
            rho: 1.0,
        }])
        .unwrap();
        let [l] = a.lobes(&f, wo);
        let m = Vec3::new(-0.3, 0.0, 0.8);
        assert!((l.axis() - m.normalize()).length() < 1e-6);
        assert!((l.scale() - m.length_squared()).abs() < 1e-6);
        // zero lobe
        let z = Lafortune::new([LafortuneLobe {
            c: Vec3::ZERO,
            exponent: 3.0,
            rho: 1.0,
        }])
        .unwrap();
        assert_eq!(z.lobes(&f, wo)[0].scale(), 0.0);
    }
}
