//! Spherical caps and the cap → lobe fit (cosine-lobe paper, eq. 31–34).
//!
//! A spherical light seen from a point subtends a cap of half-angle `α` (`sin α = r/d`).
//! The paper replaces its indicator `f_cap` by the unit-scale lobe `max(a·v, 0)^e` whose
//! exponent minimises the L2 distance (eq. 32), which has the closed-form objective
//!
//! `J(e) = 2π(1 − cos α) − 4π(1 − cos^(e+1) α)/(e + 1) + 2π/(2e + 1)`.
//!
//! The optimum `e*(α)` has no closed form. As the paper does, it is looked up in a
//! precomputed table with linear interpolation; unlike the paper's table (1000 samples of
//! `e`, uniform in `α`), ours stores the bounded `h(α) = e*(α)·α²` on a grid uniform in
//! `x = 1 − sqrt(1 − α/(π/2))` and returns `e = h(α)/α²`. The grid is dense near `π/2`,
//! where `e* ≈ c(1 − ln c)/2` (`c = cos α`) has a logarithmic kink that a grid uniform in
//! `α` resolves only with ~4000 samples; the lookup costs one exact `sqrt`, no trigonometry. For small caps `e*·α²/2 → k*` with
//! `e^(−k*)(1 + k*) = 3/4` (`k* ≈ 0.9613`), so the table stays accurate for caps of
//! `1e-4` rad, where `e* ≈ 1.9e8`, and below. `h(π/2) = 0`: a hemisphere is fitted by
//! the `e = 0` indicator exactly.
//!
//! **Error bound** (checked against the exact f64 optimum in the harness): over
//! `α ∈ [1e-18, π/2]` (caps of `1e-4` rad and far smaller) the looked-up exponent's objective exceeds the optimum by at most
//! [`EXCESS_L2_REL`] relative, `J(e)/J(e*) − 1 ≤ EXCESS_L2_REL` (so the L2 error itself is
//! within half of that).
//!
//! **Which fit.** [`CapFit::L2`] keeps the shape of the cap best pointwise; its integral
//! `2π/(e+1)` overestimates the cap's solid angle (by 4 % for small caps, up to 2× near a
//! hemisphere). [`CapFit::EnergyPreserving`] keeps the same exponent and rescales so the
//! lobe integral equals the solid angle `2π(1 − cos α)`: where only the total power
//! reaching the point matters (the cosine, occluders' visible fractions). Both lobes are
//! wider than the cap: for small caps the L2 lobe's angular variance is `α²/0.96` against
//! the cap's `α²/2`. So a product with a lobe narrower than ~`2/α²` is blurred: a Phong
//! highlight of the light comes out too low at its centre and too bright around it.
//! [`CapFit::Moments`] matches the cap's solid angle *and* its mean cosine in closed form
//! (no table): its product with any lobe about the cap's axis is exact to second order in
//! `x = n(1 − cos α)` (`n` that lobe's exponent), so it is the lobe for products with
//! glossy lobes as long as `x` stays small ([`moments_lobe_relative_error`] gives the
//! error on the axis for every `x`; [`MOMENTS_MAX_X`] is where the energy-preserving lobe
//! becomes the better one).

use crate::frame::{check_dir, normalize_or_zero};
use crate::lobe::CosineLobe;
use crate::math;
use crate::table::{Header, decode_const};
use crate::{Error, Vec3};

use core::f32::consts::FRAC_PI_2;

/// Number of samples in the built-in cap-exponent table.
pub const TABLE_LEN: usize = 512;
/// Name of the cap-exponent table in its header.
pub const TABLE_NAME: &str = "cap-exponent";
/// The committed table bytes (header + `h(α) = e*(α)·α²` at `α_i = (π/2)(1 − (1 − i/(N−1))²)`).
pub static TABLE_BYTES: &[u8] = include_bytes!("tables/cap_exponent.bin");
const DECODED: (Header, [f32; TABLE_LEN]) =
    decode_const(include_bytes!("tables/cap_exponent.bin"), TABLE_NAME);
/// The decoded built-in table.
pub static TABLE: [f32; TABLE_LEN] = DECODED.1;

/// Relative bound on `J(e)/J(e*) − 1` of [`exponent_l2`] over [`DOMAIN`] (measured worst
/// case with the 512-sample table: 1.6e-6, at `α = π/2 − 8e-7`, over 600k log- and
/// uniformly spaced angles plus every f32 within 2e-3 of π/2).
pub const EXCESS_L2_REL: f64 = 1e-4;
/// Smallest half-angle the lookup uses: smaller (or negative) angles are clamped to it, so
/// the exponent stays finite (`≈ 1.9e36`).
pub const MIN_HALF_ANGLE: f32 = 1e-18;
/// The half-angle domain over which [`EXCESS_L2_REL`] is guaranteed.
pub const DOMAIN: (f32, f32) = (MIN_HALF_ANGLE, FRAC_PI_2);

/// The L2-optimal exponent of a unit-scale lobe for a cap of half-angle `α` (eq. 32–34),
/// from the built-in table.
///
/// Saturating: `α` is clamped to `[MIN_HALF_ANGLE, π/2]` (a cap larger than a hemisphere
/// gets `e = 0`); NaN gives NaN.
#[inline]
pub fn exponent_l2(half_angle: f32) -> f32 {
    lookup(&TABLE, half_angle)
}

/// [`exponent_l2`] with a caller-supplied table of `h(α) = e*·α²` samples at
/// `α_i = (π/2)(1 − (1 − i/(N−1))²)` (for instance one loaded with
/// [`crate::table::TableView`]). A table with fewer than two samples gives NaN.
///
/// With `u = π/2 − α` (computed with a two-part π/2, so it keeps its relative precision
/// next to the hemisphere) and `r = (N − 1)·sqrt(2u/π)`, the sample interval is
/// `k = max(⌈r⌉, 1)` counted from the end, and the interpolation is linear in `α` between
/// its knots: the fraction `(u_i − u)/(u_i − u_{i+1})` simplifies to
/// `(k − r)(k + r)/(2k − 1)`. Linear in `α` (not in the grid coordinate) matters in the
/// last intervals, where `e* ∝ u(1 − ln u)`. Every step is monotone, so the lookup is
/// non-increasing in `α` for every `f32` input (checked exhaustively in the harness).
#[inline]
pub fn lookup(table: &[f32], half_angle: f32) -> f32 {
    let n = table.len();
    if n < 2 {
        return f32::NAN;
    }
    let last = (n - 1) as f32;
    // `clamp` keeps NaN; the final division then returns it.
    let a = half_angle.clamp(MIN_HALF_ANGLE, FRAC_PI_2);
    let u = ((FRAC_PI_2 - a) + FRAC_PI_2_LO).max(0.0);
    let r = (math::sqrtf(u * (2.0 / core::f32::consts::PI)) * last).min(last);
    let k = math::ceilf(r).max(1.0);
    // `min` only matters for tables beyond 2²⁴ samples, where `last` rounds up.
    let i = ((last - k) as usize).min(n - 2);
    let f = ((k - r) * (k + r) / (2.0 * k - 1.0)).min(1.0);
    let (h0, h1) = (table[i], table[i + 1]);
    (h0 + f * (h1 - h0)) / (a * a)
}

/// `π/2 − FRAC_PI_2`: the f32 constant rounds π/2 up by this much; `(FRAC_PI_2 − α) +
/// FRAC_PI_2_LO` is `π/2 − α` to a few ulps even next to the hemisphere.
pub const FRAC_PI_2_LO: f32 = -4.371_139e-8;

/// `1 − cos α` without cancellation: `2·sin²(α/2)`.
#[inline]
pub fn one_minus_cos(half_angle: f32) -> f32 {
    let s = math::sinf(0.5 * half_angle);
    2.0 * s * s
}

/// How a cap becomes a lobe (see the module docs for when each is better).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum CapFit {
    /// Unit scale times radiance, L2-optimal exponent (eq. 32).
    #[default]
    L2,
    /// Same exponent, scale chosen so the lobe integral equals the cap's solid angle.
    EnergyPreserving,
    /// The cap's solid angle and mean cosine, in closed form: `e = 2c/(1 − c)`, scale
    /// `1 + c` (`c = cos α`). From `∫ s·(a·ω)^e dω = 2πs/(e + 1) = 2π(1 − c)` and
    /// `∫ s·(a·ω)^(e+1) dω = 2πs/(e + 2) = π(1 − c²)`. Exact for the hemisphere (`e = 0`,
    /// scale 1); for small caps `e ≈ 4/α²`, the cap's angular variance `α²/2`. A cap
    /// wider than a hemisphere (`c < 0`) gets `e = 0` and scale `1 − c` (solid angle only).
    Moments,
}

/// Where [`CapFit::Moments`] stops being the better lobe for a product with a lobe of
/// exponent `n` about the cap's axis: above `x = n(1 − cos α) = 2.7` the
/// energy-preserving lobe's error on the axis is the smaller (small-cap limit of
/// [`moments_lobe_relative_error`] against the same for the energy-preserving lobe; test
/// `moments_fit_against_energy_preserving_on_the_axis`).
pub const MOMENTS_MAX_X: f32 = 2.7;

/// Relative error of the [`CapFit::Moments`] lobe's product with a unit lobe of exponent
/// `n` about the cap's axis, against the exact `∫_cap (a·ω)^n dω = 2π(1 − c^(n+1))/(n+1)`:
/// the lobe gives `2π(1 + c)/(e + n + 1)`. In the small-cap limit, with `x = n(1 − c)`,
/// this is `2x/((2 + x)(1 − e^(−x))) − 1`: `O(x²)` (1 % at `x = 0.35`, 5.5 % at `x = 1`),
/// tending to +100 % (the lobe's peak is twice the cap's radiance). Evaluated in `f64`.
pub fn moments_lobe_relative_error(half_angle: f64, n: f64) -> f64 {
    let s = math::sin64(0.5 * half_angle);
    let p = 2.0 * s * s;
    let c = 1.0 - p;
    // (1 − c^(n+1))/(n + 1) without cancellation: −expm1((n + 1)·ln(1 − p))/(n + 1).
    let exact = -math::expm1_64((n + 1.0) * math::log1p_64(-p)) / (n + 1.0);
    let lobe = (1.0 + c) / (2.0 * c / p + n + 1.0);
    lobe / exact - 1.0
}

/// A spherical cap: unit axis and half-angle `α ∈ (0, π]`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct SphericalCap {
    axis: Vec3,
    half_angle: f32,
    one_minus_cos: f32,
}

impl SphericalCap {
    /// The byte layout of the `#[repr(C)]` type, which `wgsl::TYPES` declares as `SphericalCap`.
    pub const LAYOUT: crate::wgsl::Layout = crate::wgsl::Layout {
        name: "SphericalCap",
        size: core::mem::size_of::<SphericalCap>(),
        fields: &[
            ("axis", core::mem::offset_of!(SphericalCap, axis)),
            (
                "half_angle",
                core::mem::offset_of!(SphericalCap, half_angle),
            ),
            (
                "one_minus_cos",
                core::mem::offset_of!(SphericalCap, one_minus_cos),
            ),
        ],
    };

    /// A cap from its axis (non-zero, finite; normalised here) and half-angle in `(0, π]`.
    pub fn new(axis: Vec3, half_angle: f32) -> Result<Self, Error> {
        let axis = check_dir(axis, "cap axis")?;
        if !half_angle.is_finite() {
            return Err(Error::NonFinite {
                what: "cap half-angle",
            });
        }
        if !(half_angle > 0.0 && half_angle <= crate::PI) {
            return Err(Error::OutOfRange {
                what: "cap half-angle",
                value: half_angle,
                min: 0.0,
                max: crate::PI,
            });
        }
        Ok(SphericalCap {
            axis,
            half_angle,
            one_minus_cos: one_minus_cos(half_angle),
        })
    }

    /// The cap subtended by the sphere `(centre, radius)` seen from `point`:
    /// `sin α = r/d`. The point must be strictly outside the sphere; every input finite and
    /// the radius positive. `α` and `1 − cos α` are within 2e-6 relative of f64 (tested for
    /// distances up to 1e20); `d` is formed without overflow, so centres at 3e38 and 3e-38
    /// give the right cap too.
    pub fn from_sphere(point: Vec3, centre: Vec3, radius: f32) -> Result<Self, Error> {
        if !point.is_finite() {
            return Err(Error::NonFinite { what: "point" });
        }
        if !centre.is_finite() {
            return Err(Error::NonFinite {
                what: "sphere centre",
            });
        }
        if !radius.is_finite() {
            return Err(Error::NonFinite {
                what: "sphere radius",
            });
        }
        if radius <= 0.0 {
            return Err(Error::OutOfRange {
                what: "sphere radius",
                value: radius,
                min: f32::MIN_POSITIVE,
                max: f32::MAX,
            });
        }
        let v = centre - point;
        if !v.is_finite() {
            return Err(Error::NonFinite {
                what: "centre − point",
            });
        }
        let m = v.x.abs().max(v.y.abs()).max(v.z.abs());
        let axis = normalize_or_zero(v);
        // d = m·|v/m| without overflow; sin α = r/d computed as (r/m)/|v/m|.
        // v/m has length in [1, √3]; dividing (not multiplying by 1/m) stays exact for
        // subnormal m.
        let unit_len = if m > 0.0 {
            let s = v / m;
            math::sqrtf(s.dot(s))
        } else {
            0.0
        };
        let sin_a = (radius / m) / unit_len;
        if m == 0.0 || sin_a.is_nan() || sin_a >= 1.0 {
            return Err(Error::InsideSphere {
                distance: m * unit_len,
                radius,
            });
        }
        let half_angle = math::asinf(sin_a);
        // 1 − cos α = sin²α/(1 + cos α), no cancellation for small caps.
        let cos_a = math::sqrtf((1.0 - sin_a) * (1.0 + sin_a));
        let one_minus_cos = sin_a * sin_a / (1.0 + cos_a);
        Ok(SphericalCap {
            axis,
            half_angle,
            one_minus_cos,
        })
    }

    /// Unit axis.
    pub fn axis(&self) -> Vec3 {
        self.axis
    }
    /// Half-angle `α` in radians.
    pub fn half_angle(&self) -> f32 {
        self.half_angle
    }
    /// `1 − cos α`, accurate for tiny caps.
    pub fn one_minus_cos(&self) -> f32 {
        self.one_minus_cos
    }
    /// Solid angle `2π(1 − cos α)`.
    pub fn solid_angle(&self) -> f32 {
        crate::TWO_PI * self.one_minus_cos
    }
    /// Whether unit direction `v` is inside the cap (`a·v ≥ cos α`, tested as
    /// `|a − v|²/2 ≤ 1 − cos α` so tiny caps are exact).
    pub fn contains(&self, v: Vec3) -> bool {
        let d = self.axis - v;
        0.5 * d.dot(d) <= self.one_minus_cos
    }

    /// The L2-optimal exponent for this cap ([`exponent_l2`]).
    pub fn exponent_l2(&self) -> f32 {
        exponent_l2(self.half_angle)
    }

    /// The cosine lobe standing for this cap with radiance `radiance` (eq. 31).
    pub fn lobe(&self, radiance: f32, fit: CapFit) -> CosineLobe {
        match fit {
            CapFit::L2 => CosineLobe::saturating(self.axis, radiance, self.exponent_l2()),
            CapFit::EnergyPreserving => {
                let e = self.exponent_l2();
                CosineLobe::saturating(self.axis, radiance * self.one_minus_cos * (e + 1.0), e)
            }
            CapFit::Moments => {
                // `1 − c` held apart (exact for tiny caps), floored where it underflows so
                // the exponent stays finite (≈ 4e36 at `MIN_HALF_ANGLE`).
                let p = self
                    .one_minus_cos
                    .max(0.5 * MIN_HALF_ANGLE * MIN_HALF_ANGLE);
                let c = 1.0 - p;
                if c > 0.0 {
                    CosineLobe::saturating(self.axis, radiance * (1.0 + c), 2.0 * c / p)
                } else {
                    CosineLobe::saturating(self.axis, radiance * p, 0.0)
                }
            }
        }
    }

    /// `∫_cap max(n·ω, 0) dω`: the cosine-weighted solid angle of the cap above the plane
    /// of the unit normal `n` (a sphere light's irradiance over its radiance; Snyder,
    /// *Area light sources for real-time graphics*, Microsoft Research MSR-TR-96-11, 1996).
    ///
    /// With `θ` the angle from `n` to the axis and `s = sin α`, `c = cos α`: a cap wholly
    /// above the horizon (`cos θ ≥ s`) gives `π s² cos θ` (`∫_cap ω dω = π s²·axis`), one
    /// wholly below gives 0. Between, Lambert's contour form `n·½∮ω × dω` over the clipped
    /// cap's boundary has two arcs: the cap's circle above the horizon, which it leaves at
    /// azimuth `±acos y` with `y = −c·cos θ/(s·sin θ)`, giving `s²·cos θ·acos y − s·c·sin θ·√(1 − y²)`,
    /// and the horizon inside the cap, of half-length `β = atan2(√(sin²θ − c²), c)`, giving
    /// `β`. A cap wider than a hemisphere is `π` less its complement's value. Evaluated in
    /// `f64` (the clipped terms cancel to `O(α³)` from `O(α)` for small caps).
    ///
    /// **Error bound:** within `5e-7·π s²` of the exact integral (`5e-7·π` for a cap wider
    /// than a hemisphere) for every unit `n` and cap; measured 1.4e-7, the `f32` rounding of
    /// the inputs (test `clipped_cosine_matches_quadrature`, which integrates the azimuth in
    /// closed form and the polar angle numerically, for caps of 1e-4 rad to 3 rad and axes
    /// from the pole through both sides of the horizon to straight below). A non-finite `n`
    /// gives NaN.
    pub fn clipped_cosine(&self, n: Vec3) -> f32 {
        if !n.is_finite() {
            return f32::NAN;
        }
        let (n, a) = (n.as_dvec3(), self.axis.as_dvec3());
        // Clamped: an `f32` unit normal may be an ulp or so longer than 1, and a cosine past
        // ±1 would push the value out of `[0, π]` (past the top of a cap, below 0 beneath a
        // cap wider than a hemisphere).
        let (cos_t, sin_t) = (n.dot(a).clamp(-1.0, 1.0), n.cross(a).length());
        let omc = f64::from(self.one_minus_cos);
        let s2 = omc * (2.0 - omc);
        let pi = core::f64::consts::PI;
        let clipped = |cos_t: f64, c: f64| -> f64 {
            let s = math::sqrt64(s2);
            if cos_t >= s {
                return pi * s2 * cos_t;
            }
            if cos_t <= -s {
                return 0.0;
            }
            let y = (-c * cos_t / (s * sin_t)).clamp(-1.0, 1.0);
            let q = math::sqrt64((1.0 - y) * (1.0 + y));
            let arc = s2 * cos_t * math::atan2_64(q, y) - s * c * sin_t * q;
            let horizon = math::atan2_64(s * sin_t * q, c);
            (arc + horizon).max(0.0)
        };
        let v = if omc <= 1.0 {
            clipped(cos_t, 1.0 - omc)
        } else {
            (pi - clipped(-cos_t, omc - 1.0)).max(0.0)
        };
        v as f32
    }

    /// `∫ ω dω` over the overlap of this cap and `other`: the vector moment of the
    /// directions both contain, so that `n·overlap_moment` is the overlap's cosine-weighted
    /// solid angle about any `n` it lies above (how much of a spherical light an occluder's
    /// cap hides from a Lambertian receiver).
    ///
    /// With `r₁, r₂` the half-angles and `d` the angle between the axes: disjoint caps
    /// (`d ≥ r₁ + r₂`) give 0 and a cap inside the other its own moment `π sin²r·a`.
    /// Otherwise Stokes' `½∮ω × dω` runs over the overlap's two boundary arcs: the arc of
    /// cap `i` spans azimuths `±φᵢ` about its axis (`φᵢ` the angle at `aᵢ` of the
    /// triangle of the two axes and a corner, with sides `rᵢ`, `d` and opposite side `rⱼ`:
    /// `cos φ₁ = (cos r₂ − cos d cos r₁)/(sin d sin r₁)`, evaluated by the equivalent
    /// half-angle formula, stable for small `φ`) and gives
    /// `φᵢ sin²rᵢ·aᵢ − sin rᵢ cos rᵢ sin φᵢ·uᵢ`, `uᵢ` the unit tangent at `aᵢ` toward the
    /// other axis (a whole circle, `φ = π`, gives `π sin²r·a`). Where `d + r₁ + r₂ ≥ 2π`
    /// the circles do not meet (caps wider than a hemisphere that cover the sphere
    /// together, e.g. on opposite axes): the overlap is the band between them,
    /// `π(sin²r₁·a₁ + sin²r₂·a₂)`. Evaluated in `f64`.
    ///
    /// **Error bound:** within `3e-4·π·max(sin²r₁, sin²r₂)` per component of a `600 × 1200`
    /// midpoint quadrature, the quadrature's own resolution (test
    /// `overlap_moment_matches_quadrature`: caps of 1e-3 to 2 rad, disjoint, crossing and
    /// nested both ways), symmetric in the two caps within `1e-6` of that scale, and within
    /// `1e-6` relative of the closed forms of nested, identical and disjoint caps (test
    /// `overlap_moment_exact_cases`). The axes' `1 − cos d` is formed from their chord and
    /// the corner angles from differences of angles, so tiny caps keep their precision (a
    /// cap of 1e-7 rad on a hemisphere's boundary is within 1e-6 of its own moment's scale:
    /// test `overlap_moment_of_a_tiny_cap_on_a_boundary`).
    pub fn overlap_moment(&self, other: &SphericalCap) -> Vec3 {
        use glam::DVec3;
        let unit = |v: Vec3| {
            let v = v.as_dvec3();
            v / math::sqrt64(v.dot(v))
        };
        let (a1, a2) = (unit(self.axis), unit(other.axis));
        let (r1, r2) = (f64::from(self.half_angle), f64::from(other.half_angle));
        let (s1, c1) = (math::sin64(r1), math::cos64(r1));
        let (s2, c2) = (math::sin64(r2), math::cos64(r2));
        // `1 − cos d` from the chord, so that small angles keep their precision.
        let kd = 0.5 * (a1 - a2).length_squared();
        let (cd, sd) = (1.0 - kd, a1.cross(a2).length());
        let d = math::atan2_64(sd, cd);
        let pi = core::f64::consts::PI;
        let m: DVec3 = if d >= r1 + r2 {
            DVec3::ZERO
        } else if d + r2 <= r1 {
            pi * s2 * s2 * a2
        } else if d + r1 <= r2 {
            pi * s1 * s1 * a1
        } else if d + r1 + r2 >= 2.0 * pi {
            // The circles do not meet (each lies in the other cap): the caps cover the
            // sphere and overlap in a band, `∫_1 + ∫_2 − ∫_sphere` (two whole circles).
            pi * (s1 * s1 * a1 + s2 * s2 * a2)
        } else {
            // `φᵢ` by the half-angle formula of the triangle (`aᵢ`, `aⱼ`, a corner):
            // `tan(φᵢ/2) = √(sin(σ − rᵢ) sin(σ − d) / (sin σ sin(σ − rⱼ)))`, `σ` the
            // half-perimeter; every factor is positive here and formed from differences
            // of angles, so a small `φ` (a tiny cap on a large one's boundary) keeps its
            // relative precision, which `acos` of the law of cosines loses.
            let sigma = 0.5 * (r1 + r2 + d);
            let sin = |x: f64| math::sin64(x).max(0.0);
            let phi = |ri: f64, rj: f64| {
                let y = math::sqrt64(sin(sigma - ri) * sin(sigma - d));
                let x = math::sqrt64(sin(sigma) * sin(sigma - rj));
                2.0 * math::atan2_64(y, x)
            };
            let arc = |a: DVec3, b: DVec3, s: f64, c: f64, phi: f64| -> DVec3 {
                let u = (b - cd * a) / sd;
                phi * s * s * a - s * c * math::sin64(phi) * u
            };
            arc(a1, a2, s1, c1, phi(r1, r2)) + arc(a2, a1, s2, c2, phi(r2, r1))
        };
        if m.is_finite() {
            m.as_vec3()
        } else {
            Vec3::NAN
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_finite_nonnegative_and_ends_at_zero() {
        assert!(TABLE.iter().all(|h| h.is_finite() && *h >= 0.0));
        assert_eq!(TABLE[TABLE_LEN - 1], 0.0);
        assert_eq!(exponent_l2(FRAC_PI_2), 0.0);
        assert_eq!(exponent_l2(3.0), 0.0);
        assert!(exponent_l2(f32::NAN).is_nan());
        assert!(exponent_l2(0.0).is_finite() && exponent_l2(-1.0) == exponent_l2(0.0));
        assert!(exponent_l2(f32::NEG_INFINITY).is_finite());
        let tiny = exponent_l2(1e-4);
        assert!((tiny / 1.9226e8 - 1.0).abs() < 1e-3, "{tiny}");
    }

    #[test]
    fn huge_user_tables_do_not_panic() {
        extern crate std;
        let t = std::vec![1.0f32; (1 << 24) + 4];
        for a in [0.0, 1.0, FRAC_PI_2, 3.0] {
            assert!(lookup(&t, a).is_finite());
        }
        assert!(lookup(&[1.0], 0.5).is_nan() && lookup(&[], 0.5).is_nan());
    }

    #[test]
    fn lookup_is_monotone_decreasing() {
        let mut prev = f32::INFINITY;
        for i in 0..=20000 {
            let a = 1e-4 + (FRAC_PI_2 - 1e-4) * i as f32 / 20000.0;
            let e = exponent_l2(a);
            assert!(e <= prev, "not monotone at {a}: {e} > {prev}");
            prev = e;
        }
    }

    #[test]
    fn sphere_caps() {
        let c = SphericalCap::from_sphere(Vec3::ZERO, Vec3::new(0.0, 0.0, 2.0), 1.0).unwrap();
        assert!((c.half_angle() - core::f32::consts::FRAC_PI_6).abs() < 1e-6);
        assert!((c.one_minus_cos() - (1.0 - 0.75f32.sqrt())).abs() < 1e-6);
        assert_eq!(c.axis(), Vec3::Z);
        // huge and tiny coordinates
        let h = SphericalCap::from_sphere(Vec3::ZERO, Vec3::new(3e38, 0.0, 0.0), 3e34).unwrap();
        assert!((h.half_angle() - 1e-4).abs() < 1e-9);
        let t = SphericalCap::from_sphere(Vec3::ZERO, Vec3::new(0.0, 3e-38, 0.0), 3e-42).unwrap();
        assert!((t.half_angle() / 1e-4 - 1.0).abs() < 1e-2);
        // errors
        assert!(matches!(
            SphericalCap::from_sphere(Vec3::ZERO, Vec3::Z, 1.0),
            Err(Error::InsideSphere { .. })
        ));
        assert!(SphericalCap::from_sphere(Vec3::ZERO, Vec3::ZERO, 1.0).is_err());
        assert!(SphericalCap::from_sphere(Vec3::ZERO, Vec3::Z, 0.0).is_err());
        assert!(SphericalCap::from_sphere(Vec3::ZERO, Vec3::Z * 2.0, f32::NAN).is_err());
        assert!(SphericalCap::from_sphere(Vec3::NAN, Vec3::Z * 2.0, 1.0).is_err());
        assert!(
            SphericalCap::from_sphere(Vec3::new(-3e38, 0.0, 0.0), Vec3::new(3e38, 0.0, 0.0), 1.0)
                .is_err()
        );
        assert!(SphericalCap::new(Vec3::Z, 0.0).is_err());
        assert!(SphericalCap::new(Vec3::Z, 4.0).is_err());
    }

    #[test]
    fn energy_preserving_lobe_matches_solid_angle() {
        for a in [1e-4f32, 0.01, 0.3, 1.0, 1.5] {
            let c = SphericalCap::new(Vec3::Z, a).unwrap();
            let l = c.lobe(1.0, CapFit::EnergyPreserving);
            assert!((l.integral() / c.solid_angle() - 1.0).abs() < 1e-5, "{a}");
            let l2 = c.lobe(3.0, CapFit::L2);
            assert_eq!(l2.scale(), 3.0);
            assert_eq!(l2.exponent(), l.exponent());
        }
    }

    #[test]
    fn moments_lobe_matches_solid_angle_and_mean_cosine() {
        // The hemisphere is fitted exactly: the unit indicator of the upper half is `e = 0`.
        let h = SphericalCap::new(Vec3::Z, FRAC_PI_2)
            .unwrap()
            .lobe(2.0, CapFit::Moments);
        assert!(
            h.exponent().abs() < 1e-6 && (h.scale() - 2.0).abs() < 1e-6,
            "{h:?}"
        );
        for a in [1e-4f32, 1e-3, 0.01, 0.1, 0.5, 1.0, 1.5, 1.57] {
            let cap = SphericalCap::new(Vec3::Z, a).unwrap();
            let l = cap.lobe(1.0, CapFit::Moments);
            let (p, c) = (f64::from(cap.one_minus_cos()), f64::from(a).cos());
            let (s, e) = (f64::from(l.scale()), f64::from(l.exponent()));
            let tau = core::f64::consts::TAU;
            // ∫ lobe = solid angle, ∫ lobe·(a·ω) = ∫_cap a·ω = π(1 − c²).
            assert!((tau * s / (e + 1.0) / (tau * p) - 1.0).abs() < 1e-5, "{a}");
            let mean = core::f64::consts::PI * p * (1.0 + c);
            assert!((tau * s / (e + 2.0) / mean - 1.0).abs() < 1e-5, "{a}");
            // Small caps: `e ≈ 4/α²`, the cap's angular variance `α²/2` as `2/e`.
            if a <= 0.01 {
                let k = e * f64::from(a).powi(2) / 4.0;
                assert!((k - 1.0).abs() < 1e-4, "{a}: e·α²/4 = {k}");
            }
        }
        // Wider than a hemisphere: the solid angle only; below the smallest half-angle the
        // exponent stays finite.
        let w = SphericalCap::new(Vec3::Z, 2.5)
            .unwrap()
            .lobe(1.0, CapFit::Moments);
        assert_eq!(w.exponent(), 0.0);
        assert!((w.scale() - (1.0 - 2.5f32.cos())).abs() < 1e-6);
        for a in [1e-18f32, 1e-25, 1e-40] {
            let t = SphericalCap::new(Vec3::Z, a)
                .unwrap()
                .lobe(1.0, CapFit::Moments);
            assert!(t.exponent().is_finite() && t.scale() == 2.0, "{a}: {t:?}");
        }
    }

    /// The product of each fit with a unit lobe of exponent `n` about the cap's axis,
    /// against the exact `∫_cap (a·ω)^n dω = 2π(1 − c^(n+1))/(n+1)`, over `x = n(1 − c)`:
    /// the moments lobe is within its stated error, and the better of the two up to
    /// [`MOMENTS_MAX_X`]; beyond it the energy-preserving lobe is.
    #[test]
    fn moments_fit_against_energy_preserving_on_the_axis() {
        let on_axis =
            |l: &CosineLobe, n: f64| f64::from(l.scale()) / (f64::from(l.exponent()) + n + 1.0);
        for a in [1e-3f64, 0.01, 0.1] {
            let cap = SphericalCap::new(Vec3::Z, a as f32).unwrap();
            let p = 2.0 * (0.5 * a).sin().powi(2);
            for (x, moments_bound) in [(0.05, 1e-3), (0.35, 0.011), (1.0, 0.056), (2.0, 0.16)] {
                let n = x / p;
                let err = moments_lobe_relative_error(a, n);
                assert!(err.abs() <= moments_bound, "α {a}, x {x}: {err}");
                let exact = -math::expm1_64((n + 1.0) * math::log1p_64(-p)) / (n + 1.0);
                let m = on_axis(&cap.lobe(1.0, CapFit::Moments), n) / exact - 1.0;
                assert!(
                    (m - err).abs() < 1e-4 * (1.0 + err.abs()),
                    "α {a}, x {x}: {m} {err}"
                );
            }
            // Very sharp lobes see the moments lobe's peak, twice the cap's radiance.
            let far = moments_lobe_relative_error(a, 1e4 / p);
            assert!((0.99..=1.0).contains(&far), "α {a}: {far}");
            for x in [0.05, 0.35, 1.0, 2.0, 2.5, 2.9, 3.5, 10.0, 100.0] {
                let n = x / p;
                let exact = -math::expm1_64((n + 1.0) * math::log1p_64(-p)) / (n + 1.0);
                let m = moments_lobe_relative_error(a, n).abs();
                let ep = (on_axis(&cap.lobe(1.0, CapFit::EnergyPreserving), n) / exact - 1.0).abs();
                assert_eq!(
                    m < ep,
                    x < f64::from(MOMENTS_MAX_X),
                    "α {a}, x {x}: {m} vs {ep}"
                );
            }
        }
    }

    #[test]
    fn contains_tiny_cap() {
        let c = SphericalCap::new(Vec3::Z, 1e-4).unwrap();
        assert!(c.contains(Vec3::new(0.9e-4, 0.0, 1.0).normalize()));
        assert!(!c.contains(Vec3::new(1.1e-4, 0.0, 1.0).normalize()));
    }

    /// `∫_cap max(n·ω, 0) dω` with the azimuth about the axis integrated in closed form
    /// (`∫₀^{2π} max(A + B cos φ, 0) dφ`) and the polar angle by the midpoint rule.
    fn clipped_cosine_quadrature(cos_t: f64, alpha: f64) -> f64 {
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let m = 200_000;
        let h = alpha / m as f64;
        let mut sum = 0.0;
        for k in 0..m {
            let t = (k as f64 + 0.5) * h;
            let (a, b) = (cos_t * t.cos(), sin_t * t.sin());
            let ring = if a >= b {
                2.0 * core::f64::consts::PI * a
            } else if a <= -b {
                0.0
            } else {
                let p = (-a / b).acos();
                2.0 * (a * p + b * p.sin())
            };
            sum += ring * t.sin() * h;
        }
        sum
    }

    /// A normal an `f32` ulp or so longer than 1 (as `normalize` may leave it) stays within
    /// `[0, π s²]`: straight below a cap one ulp wider than a hemisphere (the fuzz target
    /// `cap_integrals` found −1.5e-6 there, from a cosine of −1.0000005) and straight above
    /// a hemisphere.
    #[test]
    fn clipped_cosine_of_a_slightly_long_normal_stays_in_range() {
        let wide = SphericalCap::new(Vec3::X, 1.570_796_8).unwrap();
        assert!(wide.one_minus_cos() > 1.0);
        let below = wide.clipped_cosine(Vec3::new(-1.000_000_5, 0.0, 0.0));
        assert!((0.0..1e-6).contains(&below), "{below}");
        let half = SphericalCap::new(Vec3::X, core::f32::consts::FRAC_PI_2).unwrap();
        let above = half.clipped_cosine(Vec3::new(1.000_000_5, 0.0, 0.0));
        assert!(above <= crate::PI && above > 0.999 * crate::PI, "{above}");
    }

    #[test]
    fn clipped_cosine_matches_quadrature() {
        extern crate std;
        use std::vec::Vec;
        // Caps of 1e-4 rad to wider than a hemisphere; axes from the pole through the
        // horizon to straight below, with the transitions `θ = π/2 ± α` on both sides.
        let mut worst = 0.0f64;
        for alpha in [
            1e-4f64,
            0.01,
            0.3,
            1.0,
            1.5,
            core::f64::consts::FRAC_PI_2,
            2.0,
            3.0,
        ] {
            let cap = SphericalCap::new(Vec3::Z, alpha as f32).unwrap();
            let alpha = f64::from(cap.half_angle());
            let s2 = f64::from(cap.one_minus_cos()) * (2.0 - f64::from(cap.one_minus_cos()));
            let half = core::f64::consts::FRAC_PI_2;
            let mut thetas: Vec<f64> = (0..=40)
                .map(|k| k as f64 * core::f64::consts::PI / 40.0)
                .collect();
            for edge in [half - alpha, half + alpha] {
                thetas.extend([edge - 1e-3 * alpha, edge, edge + 1e-3 * alpha]);
            }
            for theta in thetas {
                if !(0.0..=core::f64::consts::PI).contains(&theta) {
                    continue;
                }
                let n = Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32);
                let got = f64::from(cap.clipped_cosine(n));
                let cos_t = f64::from(n.normalize().dot(Vec3::Z));
                let want = clipped_cosine_quadrature(cos_t, alpha);
                let scale = if alpha > half { 1.0 } else { s2 };
                let err = (got - want).abs() / (core::f64::consts::PI * scale);
                worst = worst.max(err);
                assert!(
                    err <= 5e-7,
                    "α {alpha} θ {theta}: {got} vs {want} ({err:e})"
                );
            }
        }
        assert!(worst > 0.0);
    }

    #[test]
    fn clipped_cosine_exact_cases() {
        // Wholly above: π s² cos θ; the pole: π s²; a hemisphere about the normal: π; a
        // hemisphere on the horizon: π/2; wholly below: 0; a full sphere: π.
        let c = SphericalCap::new(Vec3::Z, 0.5).unwrap();
        let s2 = 0.5f32.sin().powi(2);
        assert!((c.clipped_cosine(Vec3::Z) / (crate::PI * s2) - 1.0).abs() < 1e-6);
        let n = Vec3::new(0.6, 0.0, 0.8);
        assert!((c.clipped_cosine(n) / (crate::PI * s2 * 0.8) - 1.0).abs() < 1e-6);
        assert_eq!(c.clipped_cosine(-Vec3::Z), 0.0);
        let h = SphericalCap::new(Vec3::Z, FRAC_PI_2).unwrap();
        assert!((h.clipped_cosine(Vec3::Z) - crate::PI).abs() < 1e-6);
        assert!((h.clipped_cosine(Vec3::X) - crate::PI / 2.0).abs() < 1e-6);
        let all = SphericalCap::new(Vec3::Z, crate::PI).unwrap();
        assert!((all.clipped_cosine(Vec3::new(0.0, 0.6, -0.8)) - crate::PI).abs() < 1e-6);
        // A cap of 1e-4 rad straddling the horizon: positive, below the unclipped value.
        let t = SphericalCap::new(Vec3::new(1.0, 0.0, 2e-5).normalize(), 1e-4).unwrap();
        let v = t.clipped_cosine(Vec3::Z);
        assert!(v > 0.0 && v < crate::PI * 1e-8 * 2e-5 * 2.0, "{v}");
        assert!(c.clipped_cosine(Vec3::splat(f32::NAN)).is_nan());
    }

    /// `∫ ω dω` over the directions of `a` that `b` contains, by the midpoint rule in `a`'s
    /// polar angle and azimuth (`f64`).
    fn overlap_quadrature(a: &SphericalCap, b: &SphericalCap) -> [f64; 3] {
        let (alpha, z) = (f64::from(a.half_angle()), a.axis().as_dvec3().normalize());
        let (bz, bk) = (
            b.axis().as_dvec3().normalize(),
            f64::from(b.one_minus_cos()),
        );
        let x = z.any_orthonormal_vector();
        let y = z.cross(x);
        let (nt, np) = (600, 1200);
        let mut m = [0.0; 3];
        for i in 0..nt {
            let t = (i as f64 + 0.5) * alpha / nt as f64;
            for j in 0..np {
                let p = (j as f64 + 0.5) * 2.0 * core::f64::consts::PI / np as f64;
                let w = t.cos() * z + t.sin() * (p.cos() * x + p.sin() * y);
                // `b` contains `w` (`1 − cos` from the chord, precise for tiny caps).
                if 0.5 * (w - bz).length_squared() <= bk {
                    let da =
                        t.sin() * (alpha / nt as f64) * (2.0 * core::f64::consts::PI / np as f64);
                    for k in 0..3 {
                        m[k] += w[k] * da;
                    }
                }
            }
        }
        m
    }

    #[test]
    fn overlap_moment_matches_quadrature() {
        let z = Vec3::Z;
        let tilt = |t: f32| Vec3::new(t.sin(), 0.0, t.cos());
        // (r₁, r₂, d): crossing, nested both ways, disjoint, equal, a hemisphere and a cap
        // wider than one.
        let cases = [
            (0.1f32, 0.05f32, 0.1f32),
            (0.1, 0.05, 0.02),
            (0.05, 0.1, 0.02),
            (0.1, 0.05, 0.2),
            (0.3, 0.3, 0.4),
            (0.5, 0.2, 0.6),
            (1e-3, 1e-3, 1.5e-3),
            (1.0, 0.5, 1.2),
            (FRAC_PI_2, 0.3, 1.5),
            (2.0, 0.4, 1.9),
        ];
        for (r1, r2, d) in cases {
            let a = SphericalCap::new(z, r1).unwrap();
            let b = SphericalCap::new(tilt(d), r2).unwrap();
            let got = a.overlap_moment(&b);
            let want = overlap_quadrature(&a, &b);
            let scale = core::f64::consts::PI * f64::from(r1.sin().max(r2.sin()).powi(2));
            for k in 0..3 {
                // The quadrature's own error is of its cell size along the boundary.
                let err = (f64::from(got[k]) - want[k]).abs() / scale;
                assert!(
                    err < 3e-4,
                    "r {r1} {r2} d {d}: {got:?} vs {want:?} ({err:e})"
                );
            }
            // Symmetric in the two caps.
            let back = b.overlap_moment(&a);
            assert!(
                (back - got).length() <= 1e-6 * scale as f32,
                "{back:?} vs {got:?}"
            );
        }
    }

    #[test]
    fn overlap_moment_exact_cases() {
        let a = SphericalCap::new(Vec3::Z, 0.2).unwrap();
        let s2 = 0.2f32.sin().powi(2);
        // Nested: the inner cap's moment; disjoint: 0; the same cap: its own moment.
        let inner = SphericalCap::new(Vec3::new(0.05, 0.0, 1.0).normalize(), 0.1).unwrap();
        let m = a.overlap_moment(&inner);
        let want = crate::PI * 0.1f32.sin().powi(2) * inner.axis();
        assert!(
            (m - want).length() <= 1e-6 * want.length(),
            "{m:?} vs {want:?}"
        );
        let far = SphericalCap::new(Vec3::X, 0.3).unwrap();
        assert_eq!(a.overlap_moment(&far), Vec3::ZERO);
        let m = a.overlap_moment(&a);
        assert!(
            (m - crate::PI * s2 * Vec3::Z).length() <= 1e-6 * crate::PI * s2,
            "{m:?}"
        );
        // Two equal caps crossing symmetrically: the moment lies on their bisector.
        let b = SphericalCap::new(Vec3::new(0.3f32.sin(), 0.0, 0.3f32.cos()), 0.2).unwrap();
        let m = a.overlap_moment(&b);
        let bisector = Vec3::new(0.15f32.sin(), 0.0, 0.15f32.cos());
        assert!(
            m.y.abs() < 1e-9 && m.normalize().dot(bisector) > 1.0 - 1e-6,
            "{m:?}"
        );
    }

    /// Hard case: caps on exactly opposite axes that overlap (their half-angles sum past
    /// `π`): the overlap is the band between them, `π(sin²r₁ − sin²r₂)·a₁`, where the
    /// general arcs have no tangent (they gave NaN; found by the fuzz target
    /// `cap_integrals`).
    #[test]
    fn overlap_moment_of_caps_on_opposite_axes() {
        for (r1, r2) in [(3.0f32, 0.5f32), (2.0, 2.0), (1.6, 1.6), (3.1, 0.05)] {
            let a = SphericalCap::new(Vec3::Z, r1).unwrap();
            let b = SphericalCap::new(-Vec3::Z, r2).unwrap();
            let want = f64::from(r1).sin().powi(2) - f64::from(r2).sin().powi(2);
            let want = core::f64::consts::PI * want;
            // The same vector both ways (`π(sin²r₂ − sin²r₁)·(−a₁)` from `b`).
            for m in [a.overlap_moment(&b), b.overlap_moment(&a)] {
                assert!(m.is_finite(), "{r1} {r2}: {m}");
                assert!(m.x.abs() < 1e-6 && m.y.abs() < 1e-6, "{r1} {r2}: {m}");
                assert!(
                    (f64::from(m.z) - want).abs() < 1e-6,
                    "{r1} {r2}: {m} vs {want}"
                );
            }
        }
    }

    /// Hard case: axes nearly opposite, where two wide caps stop crossing and start to
    /// cover the sphere together (`d + r₁ + r₂ = 2π`: the corners merge, `σ → π` in the
    /// half-angle formula): the arcs' moment meets the band's on both sides of the switch.
    #[test]
    fn overlap_moment_is_continuous_where_wide_caps_stop_crossing() {
        for (r1, r2) in [(1.6f64, 1.6f64), (2.0, 1.3), (2.9, 0.5)] {
            let switch = 2.0 * core::f64::consts::PI - r1 - r2;
            let at = |d: f64| {
                let a = SphericalCap::new(Vec3::Z, r1 as f32).unwrap();
                let axis = Vec3::new(d.sin() as f32, 0.0, d.cos() as f32);
                let b = SphericalCap::new(axis, r2 as f32).unwrap();
                a.overlap_moment(&b)
            };
            // Steps of 2e-4 rad in `d` across the switch: the moment turns with the axis
            // at a steady rate (measured 1.4e-4 to 6.3e-4 per step), so every step changes
            // it by the same amount within 20 %, with no jump at the switch.
            let ms: [Vec3; 9] = core::array::from_fn(|k| at(switch + (k as f64 - 4.0) * 2e-4));
            assert!(ms.iter().all(|m| m.is_finite()), "{r1} {r2}: {ms:?}");
            let steps: [f32; 8] = core::array::from_fn(|k| (ms[k + 1] - ms[k]).length());
            for w in steps.windows(2) {
                assert!(
                    w[1] <= 1.2 * w[0] && w[0] <= 1.2 * w[1] && w[1] < 1e-3,
                    "{r1} {r2}: {steps:?}"
                );
            }
        }
    }

    /// Hard case: a cap of 1e-7 rad centred on the boundary of a hemisphere (of the `f32`
    /// hemisphere, 4.4e-8 rad wider than π/2) and of caps of 1 and 0.3 rad. At that size
    /// the overlap is a flat circular segment: with `δ = d − r₁` the small cap's centre
    /// beyond the large one's circle (from the `f32` axes, in `f64`), its area is
    /// `r²·acos(δ/r) − δ·√(r² − δ²)` and its moment that area along the small cap's axis
    /// (the curvature of the large circle and the tilt across the segment change it by
    /// about `r` relative). Within 1e-6 of the small cap's moment `π r²` (measured 3.3e-8).
    /// The law of cosines' `acos` of a cosine within 1e-14 of 1 lost the 1e-7 rad arc angle's
    /// precision there, and the moment came out far beyond the cap's own (found by the fuzz
    /// target `cap_integrals`).
    #[test]
    fn overlap_moment_of_a_tiny_cap_on_a_boundary() {
        let r = 1e-7f32;
        for big in [FRAC_PI_2, 1.0, 0.3] {
            let a = SphericalCap::new(Vec3::X, big).unwrap();
            // The small cap's axis on the large cap's circle, in the xz-plane.
            let b_axis = Vec3::new(big.cos(), 0.0, big.sin());
            let b = SphericalCap::new(b_axis, r).unwrap();
            let (a1, a2) = (a.axis().as_dvec3(), b.axis().as_dvec3());
            let d = a1.cross(a2).length().atan2(a1.dot(a2));
            let (rr, delta) = (f64::from(r), d - f64::from(big));
            let x = (delta / rr).clamp(-1.0, 1.0);
            let area = rr * rr * (x.acos() - x * (1.0 - x * x).sqrt());
            let want = a2 * area;
            let scale = core::f64::consts::PI * rr * rr;
            for m in [a.overlap_moment(&b), b.overlap_moment(&a)] {
                let err = (m.as_dvec3() - want).length() / scale;
                assert!(err <= 1e-6, "{big}: {m} vs {want}: {err:e} of {scale:e}");
            }
        }
    }

    /// Random caps (1e-4 rad to a whole sphere) and directions: the clipped cosine is
    /// finite, within `[0, π·min(1, sin²α)]` for caps up to a hemisphere and `[0, π]`
    /// beyond; an overlap's moment is finite, no longer than the smaller cap's
    /// (`π sin²r` for caps up to a hemisphere), symmetric, and its cosine-weighted part
    /// above a normal that sees the whole first cap is at most that cap's clipped cosine.
    #[test]
    fn clipped_cosine_and_overlap_moment_on_random_caps() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let dir = |next: &mut dyn FnMut() -> f32| {
            let z = 2.0 * next() - 1.0;
            let phi = crate::TWO_PI * next();
            let r = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        };
        for _ in 0..20_000 {
            let alpha = |u: f32| 1e-4f32 * (crate::PI / 1e-4).powf(u);
            let a = SphericalCap::new(dir(&mut next), alpha(next())).unwrap();
            let b = SphericalCap::new(dir(&mut next), alpha(next())).unwrap();
            let n = dir(&mut next);
            let sa2 = a.half_angle().sin().powi(2);
            let top = if a.half_angle() <= FRAC_PI_2 {
                crate::PI * sa2
            } else {
                crate::PI
            };
            let c = a.clipped_cosine(n);
            assert!(
                c.is_finite() && c >= 0.0 && c <= top * (1.0 + 1e-5),
                "{a:?} {n} {c}"
            );
            let m = a.overlap_moment(&b);
            let moment = |c: &SphericalCap| {
                if c.half_angle() <= FRAC_PI_2 {
                    crate::PI * c.half_angle().sin().powi(2)
                } else {
                    crate::PI
                }
            };
            let cap = moment(&a).min(moment(&b));
            assert!(
                m.is_finite() && m.length() <= cap * (1.0 + 1e-4) + 1e-12,
                "{a:?} {b:?} {m}"
            );
            let back = b.overlap_moment(&a);
            assert!(
                (back - m).length() <= 1e-5 * cap + 1e-12,
                "{a:?} {b:?} {m} {back}"
            );
            if a.half_angle() <= FRAC_PI_2 && n.dot(a.axis()) >= a.half_angle().sin() {
                assert!(
                    n.dot(m) <= c * (1.0 + 1e-4) + 1e-12,
                    "{a:?} {b:?} {n}: {m} vs {c}"
                );
            }
        }
    }
}
