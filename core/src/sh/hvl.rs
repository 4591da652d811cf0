//! Harmonics Virtual Lights (HVL paper section 5, eq. 19–26): secondary spherical lights
//! whose emission is an SH-projected BRDF, shading a point with two dot products each.
//!
//! ## One HVL's contribution (eq. 19–22)
//!
//! An HVL `j` at `y` (radius `r`, surface normal `n_j`, power `Φ` received from a primary
//! light in the direction `ω_l`) seen from the shading point `x` (normal `n_x`) in the unit
//! direction `ω_j = (y − x)/d` subtends the cap of half-angle `a = asin(r/d)`. With the
//! receiver's BRDF coefficients `F` (with the cosine, [`crate::sh::brdf`]) in its view frame:
//!
//! ```text
//!   L_o = L_j·(L·F),                 L = ∫_cap Y dω            (eq. 19, eq. 15: sh::cap)
//!   L_j = Φ·(F′·Y(−ω_j))·G_j                                  (eq. 20)
//!   G_j = max(0, n_j·(−ω_j))·H(n_x, ω_j)/(π r²)               (eq. 21)
//! ```
//!
//! `F′·Y(−ω_j)` is the HVL material's BRDF from `ω_l` toward `x`, reconstructed from the
//! `F′` table at `θ_l` in the HVL's own view frame (`x` toward `ω_l`; reciprocity). Units:
//! the disk `πr²` receiving `Φ` reflects the radiance `f·Φ/(πr²)`, seen over its projected
//! area, i.e. `f·Φ·cos/(πr²)` spread over a cap of the same solid angle.
//!
//! **`H`, the part of the cap above the receiver's horizon (eq. 22, derived).** With `θ` the
//! angle between `n_x` and the cap's axis, the cap lies wholly above the horizon for
//! `θ ≤ π/2 − a` and wholly below for `θ ≥ π/2 + a`, and it is cut in half at `θ = π/2`;
//! the smoothstep `S(t) = 3t² − 2t³` of `t = (ā − clamp(θ, π/2 − a, ā))/(2a)`,
//! `ā = π/2 + a`, has exactly these three values (1, 0, ½). The extracted text reads the
//! lower clamp as `a − π/2`, which would leave `t > 1` (and `S(t) < 1`, falling) for caps
//! well above the horizon: only `π/2 − a` fits the geometry. [`Horizon::Exact`] is the
//! exact fraction instead, from the area of the intersection of two caps
//! (Tovchigrechko–Vakser) with one of them the hemisphere:
//! `A = 2·(π(1 − cos a) − acos(cos θ/sin a) + cos a·acos(cot θ·cot a))`, divided by the
//! cap's `2π(1 − cos a)`, in `f64` (tested against quadrature; the two are compared in the
//! tests: at most 0.09 apart for caps up to 1.5 rad).
//!
//! **Saturation, never an error on the hot path.** A point inside an HVL (`d ≤ r`) sees it
//! as the hemisphere-sized cap `a = π/2` around `ω_j`; a point at the HVL's centre or
//! infinitely far, an HVL facing away (`n_j·ω_j ≥ 0`) or a cap wholly below the horizon
//! contributes 0; a NaN point gives NaN.
//!
//! ## The radius heuristics (eq. 23–26)
//!
//! - [`radius_from_neighbours`] (`r1`, eq. 23): `k·Σ w_n·|p − p_n| / Σ w_n` over the
//!   neighbours in the reflective shadow map, `w_n = 1/(|d − d_n| + ε)` with `d` the depths
//!   in light space.
//! - [`radius_from_fov`] (`r2`, eq. 24–25): `√M × √M` HVLs in a square map of field of view
//!   `λ` are `λ/√M` apart in angle, diagonal neighbours `γ = √2·λ/√M`; the right triangle
//!   at the HVL gives the distance `d·tan γ`, so `r2 = k·d·tan γ`. [`radius_from_fov_taylor`]
//!   (eq. 26) uses `tan γ ≈ γ + γ³/3`, within `0.01` for `γ ≤ 0.575` (tested), i.e. for
//!   `λ/√M ≤ 0.41` — with the map's *half*-angle `λ/2`, the paper's `λ/√M ≲ 0.2` (a spot of
//!   half-angle 45° needs `M ≥ 16`, of 90° `M ≥ 64`; tested).
//!
//! **Accuracy** against the `f64` quadrature of the exact integrand — constant emission
//! `Φ·f_j·max(0, n_j·(−ω_j))/(πr²)` over the cap, times the receiver's BRDF and clamped
//! cosine — per band limit (relative L2 over four placements: overhead, toward the glossy
//! direction, off to the side, near the receiver's horizon; a Lambertian HVL with
//! [`lambert_emission`]; tests below):
//!
//! | receiver | 1 | 2 | 3 | 5 | 7 | 9 | 14 bands |
//! |---|---|---|---|---|---|---|---|
//! | Lambert ([`crate::sh::brdf::lambert`]) | 0.70 | 0.21 | 0.021 | 0.015 | | | |
//! | Phong 30 ([`crate::sh::brdf::phong`]) | | | 0.83 | 0.59 | 0.35 | 0.17 | 0.013 |
//!
//! The smoothstep `H` changes these by less than `1e-3`. Reconstructing a Lambertian HVL's
//! emission from the 5-band `F′` table instead of [`lambert_emission`] costs 12 % (the ringing
//! of the hemisphere's indicator). The report's HVL section (the paper's Table 1) measures
//! whole sets of HVLs.
//!
//! # References
//!
//! - The HVL paper (see [`crate::sh`]), section 5.
//! - A. Tovchigrechko, I. A. Vakser, "How common is the funnel-like energy landscape in
//!   protein-protein interactions?", *Protein Science* 10, 2001 (the area of the
//!   intersection of two spherical caps). DOI: 10.1110/ps.8701.

use crate::frame::Frame;
use crate::math;
use crate::sh::{brdf::view_frame, cap, eval_into};
use crate::{Error, Vec3};

/// How [`contribution`] weighs the part of the HVL below the receiver's horizon.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Horizon {
    /// The paper's smoothstep (eq. 22, module docs).
    Smoothstep,
    /// The exact fraction of the cap above the horizon.
    Exact,
}

/// A Harmonics Virtual Light (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hvl {
    position: Vec3,
    frame: Frame,
    theta_l: f32,
    radius: f32,
    power: f32,
}

impl Hvl {
    /// The HVL at `position` on a surface of normal `normal`, lit from the direction
    /// `to_light` (toward the primary light), of radius `radius > 0` and power `power`
    /// (W, per channel, `≥ 0`).
    ///
    /// Errors: non-finite input, a zero normal or light direction, a radius `≤ 0`, a negative
    /// power.
    pub fn new(
        position: Vec3,
        normal: Vec3,
        to_light: Vec3,
        radius: f32,
        power: f32,
    ) -> Result<Self, Error> {
        if !position.is_finite() || !radius.is_finite() || !power.is_finite() {
            return Err(Error::NonFinite { what: "HVL" });
        }
        if radius <= 0.0 {
            return Err(Error::OutOfRange {
                what: "HVL radius",
                value: radius,
                min: f32::MIN_POSITIVE,
                max: f32::MAX,
            });
        }
        if power < 0.0 {
            return Err(Error::OutOfRange {
                what: "HVL power",
                value: power,
                min: 0.0,
                max: f32::MAX,
            });
        }
        let frame = view_frame(normal, to_light)?;
        let l = crate::frame::normalize_or_zero(to_light);
        if l == Vec3::ZERO {
            return Err(Error::ZeroVector {
                what: "HVL light direction",
            });
        }
        let theta_l = math::acosf(l.dot(frame.normal()).clamp(-1.0, 1.0));
        Ok(Hvl {
            position,
            frame,
            theta_l,
            radius,
            power,
        })
    }

    /// The centre.
    pub fn position(&self) -> Vec3 {
        self.position
    }
    /// The radius.
    pub fn radius(&self) -> f32 {
        self.radius
    }
    /// The power (W, per channel).
    pub fn power(&self) -> f32 {
        self.power
    }
    /// The angle `θ_l` between the normal and the light: where to look up the emission's
    /// `F′` table.
    pub fn theta_l(&self) -> f32 {
        self.theta_l
    }
    /// The view frame of the HVL's surface toward its light (the emission's frame).
    pub fn frame(&self) -> &Frame {
        &self.frame
    }
}

/// `H` of eq. 22 (module docs): the smoothstep of the part of a cap of half-angle `a`
/// whose axis makes the cosine `cos_theta` with the normal that lies above the horizon.
pub fn horizon_smoothstep(cos_theta: f32, a: f32) -> f32 {
    // t = (ā − clamp(θ, π/2 − a, ā))/(2a) with π/2 − θ = asin(cos θ): no cancellation
    // against π/2 for small caps.
    let c = cos_theta.clamp(-1.0, 1.0);
    if a.is_nan() {
        return f32::NAN;
    }
    if a <= 0.0 {
        return if c > 0.0 { 1.0 } else { 0.0 };
    }
    let t = ((a + math::asinf(c)) / (2.0 * a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The exact fraction of a cap of half-angle `a ∈ [0, π/2]` above the horizon, its axis at
/// the cosine `cos_theta` from the normal (module docs; `f64` inside).
///
/// The area of the cap above the horizon is `2(π(1 − cos a) − acos u + cos a·acos w)`
/// with `u = c/sin a`, `w = c·cos a/(sin θ·sin a)` (module docs). For small caps the two
/// `acos` nearly cancel, so it is rearranged without cancellation: with `R = √(sin²a − c²)`
/// one finds `√(1 − u²) = R/sin a` and `√(1 − w²) = R/(sin θ·sin a)`, so
/// `acos w = atan2(R, c·cos a)`, and `Δ = acos w − acos u` has
/// `sin Δ ∝ c·R` and `cos Δ ∝ 1 + cos a − c²` (the same positive factor), whence the
/// fraction `1 − acos(w)/π + Δ/(π(1 − cos a))`, every term at full relative precision
/// (`1 − cos a = 2 sin²(a/2)`). For a small cap with `c = k·sin a` it tends to the flat
/// disc's `1 − (acos k − k√(1 − k²))/π` (test below).
pub fn horizon_exact(cos_theta: f32, a: f32) -> f32 {
    let (c, a) = (f64::from(cos_theta.clamp(-1.0, 1.0)), f64::from(a));
    let (sa, ca) = (math::sin64(a), math::cos64(a));
    // Wholly above (θ ≤ π/2 − a ⇔ cos θ ≥ sin a) or below.
    if c >= sa {
        return 1.0;
    }
    if -c >= sa {
        return 0.0;
    }
    let r = math::sqrt64((sa - c) * (sa + c));
    let acos_w = math::atan2_64(r, c * ca);
    let delta = math::atan2_64(c * r, 1.0 + ca - c * c);
    let one_minus_cos = 2.0 * math::sin64(0.5 * a) * math::sin64(0.5 * a);
    let pi = core::f64::consts::PI;
    (1.0 - acos_w / pi + delta / (pi * one_minus_cos)).clamp(0.0, 1.0) as f32
}

/// The receiver of [`contribution`]: the shading point, its view frame
/// ([`crate::sh::brdf::view_frame`] of its normal and view) and its BRDF's `F` coefficients
/// in that frame (`n²`, e.g. from [`crate::sh::brdf::BrdfSh::lookup_into`]).
#[derive(Clone, Copy, Debug)]
pub struct Receiver<'a> {
    /// The shading point.
    pub point: Vec3,
    /// Its view frame.
    pub frame: Frame,
    /// `F` in the view frame.
    pub coeffs: &'a [f32],
}

/// The radiance one HVL sends toward the receiver's view (eq. 19–22, module docs).
/// `emission` holds the HVL material's `F′` at the HVL's `θ_l` in its frame (any band
/// count, 1 for an isotropic emitter); `scratch` at least `max(n², n_e²)` values.
///
/// The geometry is [`prepare`]; then `P·e·G·s` (left to right) with
/// `e = Σ F′_k·Y_k(−ω_j)` in the HVL's frame and `s = Σ F_k·C_k` of the cap `C` toward the
/// HVL in the receiver's frame, each sum in index order from `+0` in `f32` (the SIMD twin,
/// `steradian_simd::sh::hvl`, does the same operations on four HVLs at once).
///
/// Errors: coefficient counts that are not squares, a short `scratch`.
pub fn contribution(
    hvl: &Hvl,
    emission: &[f32],
    rx: &Receiver<'_>,
    horizon: Horizon,
    scratch: &mut [f32],
) -> Result<f32, Error> {
    let n = crate::sh::bands_of(rx.coeffs.len())?;
    let ne = crate::sh::bands_of(emission.len())?;
    crate::sh::check_shape(n.max(ne), scratch.len())?;
    let (e, cap_axis, half_angle, power, g) =
        match lit(hvl, emission, ne, rx.point, &rx.frame, horizon, scratch)? {
            Ok(lit) => lit,
            Err(v) => return Ok(v),
        };
    // The cap in the receiver's frame, dotted with F.
    cap::coefficients_into(cap_axis, half_angle, n, scratch)?;
    let mut sum = 0.0f32;
    for (f, c) in rx.coeffs.iter().zip(scratch.iter()) {
        sum += f * c;
    }
    Ok(power * e * g * sum)
}

/// What both contribution kernels share: the geometry ([`prepare`]) and the emission toward
/// the receiver, `e = Σ F′_k·Y_k(−ω_j)` in the HVL's frame (index order from `+0`, `f32`):
/// `Ok((e, cap axis, half-angle, P, G))`, or `Err(value)` when the geometry settles the
/// contribution.
#[allow(clippy::type_complexity)]
fn lit(
    hvl: &Hvl,
    emission: &[f32],
    ne: usize,
    point: Vec3,
    frame: &Frame,
    horizon: Horizon,
    scratch: &mut [f32],
) -> Result<Result<(f32, Vec3, f32, f32, f32), f32>, Error> {
    let (emit_dir, cap_axis, half_angle, power, g) = match prepare(hvl, point, frame, horizon) {
        Prepared::Value(v) => return Ok(Err(v)),
        Prepared::Lit {
            emit_dir,
            cap_axis,
            half_angle,
            power,
            g,
        } => (emit_dir, cap_axis, half_angle, power, g),
    };
    eval_into(emit_dir, ne, scratch)?;
    let mut e = 0.0f32;
    for (a, y) in emission.iter().zip(scratch.iter()) {
        e += a * y;
    }
    Ok(Ok((e, cap_axis, half_angle, power, g)))
}

/// A receiver whose coefficients are zonal around its normal, `F_l = F_l^0` (`l < n`), in
/// its view frame: a Lambertian surface, whose `f·max(cos θ_i, 0)` does not depend on the
/// azimuth (its `F_l^m`, `m ≠ 0`, vanish).
#[derive(Clone, Copy, Debug)]
pub struct ZonalReceiver<'a> {
    /// The shading point.
    pub point: Vec3,
    /// Its view frame (the normal is `+z`).
    pub frame: Frame,
    /// `F_l^0` for `l < n`.
    pub coeffs: &'a [f32],
}

/// [`contribution`] for a [`ZonalReceiver`]: `s = Σ_l F_l·C_l^0` with the cap's `m = 0`
/// coefficients alone, `C_l^0 = k_l·Y_l^0(ω_j)` (eq. 15, [`cap::band_scales`]) from
/// [`crate::sh::eval_zonal_into`] — `n` basis values instead of `n²`. Each `C_l^0` is
/// computed by the operations [`cap::coefficients_into`] applies to it and the sum skips
/// only the terms `F_l^m·C_l^m` with `F_l^m = 0`, which add `±0`; so the result is
/// **bit-identical** to [`contribution`] with the full vector whose `m ≠ 0` entries are zero
/// (tested). `scratch` at least `max(n, n_e²)` values.
///
/// Errors: an emission count that is not a square, `n > MAX_BANDS`, a short `scratch`.
pub fn contribution_zonal(
    hvl: &Hvl,
    emission: &[f32],
    rx: &ZonalReceiver<'_>,
    horizon: Horizon,
    scratch: &mut [f32],
) -> Result<f32, Error> {
    let n = rx.coeffs.len();
    let ne = crate::sh::bands_of(emission.len())?;
    crate::sh::check_shape(n.max(ne), usize::MAX)?;
    if scratch.len() < n.max(ne * ne) {
        return Err(Error::OutOfRange {
            what: "HVL scratch length",
            value: scratch.len() as f32,
            min: n.max(ne * ne) as f32,
            max: f32::INFINITY,
        });
    }
    let (e, cap_axis, half_angle, power, g) =
        match lit(hvl, emission, ne, rx.point, &rx.frame, horizon, scratch)? {
            Ok(lit) => lit,
            Err(v) => return Ok(v),
        };
    crate::sh::eval_zonal_into(cap_axis, n, scratch)?;
    let mut sum = 0.0f32;
    cap::band_scales(half_angle, n, |l, k| {
        sum += rx.coeffs[l] * (f64::from(scratch[l]) * k) as f32;
    });
    Ok(power * e * g * sum)
}

/// The geometry of one HVL seen from a receiver (eq. 20–22): either the contribution is
/// settled without any SH (`Value`: NaN for a NaN distance, 0 for a coincident or infinitely
/// far HVL, one facing away, or one wholly below the horizon), or it is `Lit` and
/// [`contribution`] needs the emission direction `−ω_j` in the HVL's frame, the cap's axis
/// `ω_j` in the receiver's frame, its half-angle `a = asin(min(r/d, 1))`, the power `P` and
/// `G = cos θ_j·H/(π r²)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Prepared {
    /// The contribution, without SH.
    Value(f32),
    /// What the SH part needs.
    Lit {
        /// `−ω_j` in the HVL's frame.
        emit_dir: Vec3,
        /// `ω_j` in the receiver's frame.
        cap_axis: Vec3,
        /// The cap's half-angle (radians, in `[0, π/2]`).
        half_angle: f32,
        /// The HVL's power.
        power: f32,
        /// `G_j = cos θ_j·H/(π r²)`.
        g: f32,
    },
}

/// [`contribution`]'s geometry for the receiver at `point` with view frame `frame`
/// ([`Prepared`]).
pub fn prepare(hvl: &Hvl, point: Vec3, frame: &Frame, horizon: Horizon) -> Prepared {
    let v = hvl.position - point;
    let d = math::sqrtf(v.dot(v));
    if d.is_nan() {
        return Prepared::Value(f32::NAN);
    }
    if d <= 0.0 || !d.is_finite() {
        return Prepared::Value(0.0);
    }
    let w = v / d;
    let cos_j = -w.dot(hvl.frame.normal());
    if cos_j <= 0.0 {
        return Prepared::Value(0.0);
    }
    let sin_a = (hvl.radius / d).min(1.0);
    let a = math::asinf(sin_a);
    let cos_x = w.dot(frame.normal());
    let h = match horizon {
        Horizon::Smoothstep => horizon_smoothstep(cos_x, a),
        Horizon::Exact => horizon_exact(cos_x, a),
    };
    if h == 0.0 {
        return Prepared::Value(0.0);
    }
    Prepared::Lit {
        emit_dir: hvl.frame.to_local(-w),
        cap_axis: frame.to_local(w),
        half_angle: a,
        power: hvl.power,
        g: cos_j * h / (core::f32::consts::PI * hvl.radius * hvl.radius),
    }
}

/// The emission coefficients of a Lambertian HVL of albedo `albedo`: the constant
/// `albedo/π` (one band, `albedo/(π·Y_0^0)`). Exact, not an approximation of the
/// hemisphere's indicator: [`contribution`] already gives 0 on the HVL's back side, so the
/// emission is only ever evaluated on its front, where a Lambertian surface's BRDF is that
/// constant (the `F′` table's 5-band reconstruction of `[cos > 0]/π` rings by 10–20 % near
/// the HVL's horizon; measured in the tests).
pub fn lambert_emission(albedo: f32) -> [f32; 1] {
    [albedo / (core::f32::consts::PI * crate::sh::Y00)]
}

/// `r1` of eq. 23: `k·Σ w_n·|p − p_n| / Σ w_n`, `w_n = 1/(|d − d_n| + ε)`, over the
/// neighbours `(p_n, d_n)` (positions and light-space depths). No neighbour gives 0.
pub fn radius_from_neighbours(
    p: Vec3,
    depth: f32,
    neighbours: &[(Vec3, f32)],
    k: f32,
    eps: f32,
) -> f32 {
    let (mut num, mut den) = (0.0f32, 0.0f32);
    for &(q, dq) in neighbours {
        let w = 1.0 / ((depth - dq).abs() + eps);
        num += w * (p - q).length();
        den += w;
    }
    if den > 0.0 { k * num / den } else { 0.0 }
}

/// `γ = √2·λ/√M` of eq. 24: the angle between diagonal neighbours among `M` HVLs in a
/// square map of field of view `fov` (radians, the full angle).
pub fn diagonal_angle(fov: f32, count: u32) -> f32 {
    core::f32::consts::SQRT_2 * fov / math::sqrtf(count.max(1) as f32)
}

/// `r2 = k·d·tan γ` of eq. 25 (module docs).
pub fn radius_from_fov(depth: f32, fov: f32, count: u32, k: f32) -> f32 {
    let g = diagonal_angle(fov, count);
    k * depth * math::sinf(g) / math::cosf(g)
}

/// `r2 ≈ k·d·(γ + γ³/3)` of eq. 26, within `0.01·k·d` of [`radius_from_fov`] for
/// `γ ≤ 0.575`.
pub fn radius_from_fov_taylor(depth: f32, fov: f32, count: u32, k: f32) -> f32 {
    let g = diagonal_angle(fov, count);
    k * depth * (g + g * g * g / 3.0)
}

#[cfg(all(test, feature = "alloc"))]
mod tests {
    use super::*;
    use crate::sh::brdf::{self, Part};
    use alloc::vec;
    use alloc::vec::Vec;
    extern crate std;
    use std::println;
    use steradian_reference::lobe::brdf::Model;

    #[test]
    fn the_smoothstep_has_the_three_exact_values_and_is_near_the_exact_fraction() {
        let mut worst = 0.0f32;
        for a in [1e-4f32, 0.05, 0.3, 0.8, 1.5] {
            let half_pi = core::f32::consts::FRAC_PI_2;
            assert_eq!(horizon_smoothstep(math::cosf(half_pi - a - 1e-3), a), 1.0);
            assert_eq!(
                horizon_smoothstep(
                    math::cosf((half_pi + a + 1e-3).min(core::f32::consts::PI)),
                    a
                ),
                0.0
            );
            assert!((horizon_smoothstep(0.0, a) - 0.5).abs() < 1e-5);
            assert!((horizon_exact(0.0, a) - 0.5).abs() < 1e-5);
            for i in 0..=200 {
                let th = half_pi - a + 2.0 * a * i as f32 / 200.0;
                let c = math::cosf(th);
                worst = worst.max((horizon_smoothstep(c, a) - horizon_exact(c, a)).abs());
            }
        }
        println!("smoothstep vs exact: {worst}");
        assert!(worst < 0.09, "{worst}");
    }

    #[test]
    fn the_exact_fraction_matches_quadrature() {
        // Fraction of the cap above z = 0 by sampling the cap on a polar grid.
        for (a, th) in [(0.3f64, 1.4f64), (0.8, 1.0), (0.05, 1.56), (1.2, 2.0)] {
            let axis = [th.sin(), 0.0, th.cos()];
            let (t1, t2) = steradian_reference::perpendiculars(axis);
            let (mut above, mut all) = (0.0, 0.0);
            let (gx, gw) = steradian_reference::quad::gauss_legendre(64);
            for (x, w) in gx.iter().zip(&gw) {
                let t = 0.5 * a * (1.0 + x);
                let (s, c) = t.sin_cos();
                for j in 0..512 {
                    let p = (j as f64 + 0.5) * core::f64::consts::TAU / 512.0;
                    let d: Vec<f64> = (0..3)
                        .map(|i| c * axis[i] + s * (p.cos() * t1[i] + p.sin() * t2[i]))
                        .collect();
                    let wt = w * s;
                    all += wt;
                    if d[2] > 0.0 {
                        above += wt;
                    }
                }
            }
            let want = above / all;
            let got = horizon_exact(th.cos() as f32, a as f32);
            assert!(
                (f64::from(got) - want).abs() < 2e-3,
                "a {a} θ {th}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn the_exact_fraction_of_a_tiny_cap_is_the_flat_discs() {
        // A cap of 1e-4 rad is a flat disc to 1e-8: the part above a line at signed
        // distance k·(its radius) below its centre is 1 − (acos k − k√(1 − k²))/π. The
        // rearranged form keeps this to f32 precision (in f32 arithmetic the textbook
        // form's two nearly cancelling acos would lose every digit; `wgsl::SH_HVL_EXACT`
        // computes in f32).
        let a = 1e-4f64;
        for k in [-0.999f64, -0.9, -0.5, -0.1, 0.0, 0.1, 0.5, 0.9, 0.999] {
            let c = (k * a.sin()) as f32;
            let k = f64::from(c) / a.sin();
            let want = 1.0 - (k.acos() - k * (1.0 - k * k).sqrt()) / core::f64::consts::PI;
            let got = f64::from(horizon_exact(c, a as f32));
            assert!((got - want).abs() < 1e-6, "k {k}: {got} vs {want}");
        }
    }

    #[test]
    fn the_taylor_radius_holds_in_the_papers_validity_domain() {
        // |tan γ − (γ + γ³/3)| ≤ 0.01 exactly up to γ ≈ 0.58.
        for i in 0..=575 {
            let g = i as f64 / 1000.0;
            assert!((g.tan() - (g + g * g * g / 3.0)).abs() <= 0.01, "{g}");
        }
        assert!((0.60f64.tan() - (0.6 + 0.216 / 3.0)) > 0.01);
        // Spots of half-angle 45° (fov 90°) need M ≥ 16, of 90° (fov 180°) M ≥ 64.
        let pi = core::f32::consts::PI;
        for (fov, m) in [(0.5 * pi, 16u32), (pi, 64)] {
            let (a, b) = (
                radius_from_fov(1.0, fov, m, 1.0),
                radius_from_fov_taylor(1.0, fov, m, 1.0),
            );
            assert!(
                diagonal_angle(fov, m) <= 0.58 && (a - b).abs() <= 0.01,
                "{fov} {m}: {a} {b}"
            );
            let small = (m as f32 * 0.5) as u32;
            assert!(diagonal_angle(fov, small) > 0.58);
        }
        assert!(
            (radius_from_fov(2.0, 0.1, 100, 1.5) - 1.5 * 2.0 * (0.1f32 * 2f32.sqrt() / 10.0).tan())
                .abs()
                < 1e-6
        );
    }

    #[test]
    fn the_neighbour_radius_weighs_by_depth() {
        let p = Vec3::ZERO;
        // Two neighbours at distance 1 with the same depth, one at distance 10 far behind.
        let nb = [
            (Vec3::X, 5.0),
            (Vec3::Y, 5.0),
            (Vec3::new(10.0, 0.0, 0.0), 50.0),
        ];
        let r = radius_from_neighbours(p, 5.0, &nb, 1.0, 1e-3);
        assert!(r > 1.0 && r < 1.01, "{r}");
        assert_eq!(radius_from_neighbours(p, 5.0, &[], 1.0, 1e-3), 0.0);
        assert!((radius_from_neighbours(p, 5.0, &nb[..2], 2.0, 1e-3) - 2.0).abs() < 1e-6);
    }

    fn v3(a: [f64; 3]) -> Vec3 {
        Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32)
    }

    /// Relative error per band limit of the HVL contribution against [`exact`], over a few
    /// placements, for the receiver table `rx` (model `rx_model`) and a Lambert HVL.
    fn errors(
        rx: brdf::BrdfSh<'_>,
        rx_model: &Model,
        bands: &[usize],
        horizon: Horizon,
        table_emission: bool,
    ) -> Vec<f64> {
        let lambert = brdf::lambert();
        let lm = Model::Lambert { a: 1.0 };
        let x = [0.0, 0.0, 0.0];
        let nx = [0.0, 0.0, 1.0];
        let wo = [0.6, 0.0, 0.8];
        let cases = [
            // (y, n_j, ω_l, r): overhead, off to the side (glossy direction), grazing.
            ([-0.6, 0.1, 0.8], [0.0, 0.0, -1.0], [0.3, 0.0, -1.0], 0.15),
            ([-0.9, 0.0, 1.2], [0.6, 0.0, -0.8], [0.0, 0.5, -1.0], 0.3),
            ([0.2, 0.5, 1.0], [0.0, -0.6, -0.8], [1.0, 0.0, -1.0], 0.1),
            ([1.5, 0.3, 0.1], [-1.0, 0.0, 0.0], [-1.0, 0.0, 1.0], 0.2),
        ];
        bands
            .iter()
            .map(|&n| {
                let mut coeffs = vec![0.0f32; n * n];
                let frame = view_frame(v3(nx), v3(wo)).unwrap();
                rx.lookup_into(Part::WithCosine, math::acosf(0.8), n, &mut coeffs)
                    .unwrap();
                let receiver = Receiver {
                    point: v3(x),
                    frame,
                    coeffs: &coeffs,
                };
                let (mut num, mut den) = (0.0f64, 0.0f64);
                for (y, nj, wl, r) in cases {
                    let nrm = |a: [f64; 3]| {
                        let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
                        a.map(|c| c / l)
                    };
                    let (nj, wl) = (nrm(nj), nrm(wl));
                    let wl_up = wl; // toward the light, on the normal's side
                    let hvl = Hvl::new(v3(y), v3(nj), v3(wl_up), r as f32, 2.0).unwrap();
                    let em = if table_emission {
                        let ne = lambert.bands();
                        let mut em = vec![0.0; ne * ne];
                        lambert
                            .lookup_into(Part::WithoutCosine, hvl.theta_l(), ne, &mut em)
                            .unwrap();
                        em
                    } else {
                        lambert_emission(1.0).to_vec()
                    };
                    let mut scratch = vec![0.0; 400];
                    let got = contribution(&hvl, &em, &receiver, horizon, &mut scratch).unwrap();
                    let want = steradian_reference::sh::hvl::contribution(
                        &steradian_reference::sh::hvl::Light {
                            position: y,
                            normal: nj,
                            to_light: wl_up,
                            radius: r,
                            power: 2.0,
                            model: lm,
                        },
                        x,
                        nx,
                        wo,
                        rx_model,
                        48,
                    );
                    num += (f64::from(got) - want).powi(2);
                    den += want * want;
                }
                (num / den).sqrt()
            })
            .collect()
    }

    #[test]
    fn one_hvl_against_the_exact_integral_per_band_limit() {
        let lm = Model::Lambert { a: 1.0 };
        let pm = Model::Phong {
            kd: 0.0,
            ks: 1.0,
            e: 30.0,
        };
        let d = errors(brdf::lambert(), &lm, &[1, 2, 3, 5], Horizon::Exact, false);
        let g = errors(brdf::phong(), &pm, &[3, 5, 7, 9, 14], Horizon::Exact, false);
        let ds = errors(brdf::lambert(), &lm, &[5], Horizon::Smoothstep, false);
        let gs = errors(brdf::phong(), &pm, &[14], Horizon::Smoothstep, false);
        let dt = errors(brdf::lambert(), &lm, &[5], Horizon::Exact, true);
        println!("diffuse receiver, bands 1 2 3 5: {d:.4?}");
        println!("glossy receiver, bands 3 5 7 9 14: {g:.4?}");
        println!("smoothstep H: diffuse 5 bands {ds:.4?}, glossy 14 bands {gs:.4?}");
        println!("diffuse 5 bands, emission from the 5-band F′ table: {dt:.4?}");
        // The figures of the module docs.
        assert!(d[2] <= 0.022 && d[3] <= 0.016, "{d:?}");
        assert!(
            g.windows(2).all(|w| w[1] < w[0]) && g[3] <= 0.18 && g[4] <= 0.014,
            "{g:?}"
        );
        assert!(ds[0] <= 0.016 && gs[0] <= 0.014, "{ds:?} {gs:?}");
        assert!(
            (ds[0] - d[3]).abs() < 1e-3 && (gs[0] - g[4]).abs() < 1e-3,
            "{ds:?} {gs:?}"
        );
        assert!(dt[0] > 0.1 && dt[0] < 0.13, "{dt:?}");
    }

    /// The zonal path is the full kernel bit for bit (up to the sign of a zero) when the
    /// receiver's `m ≠ 0` coefficients are zero: random HVLs around a receiver, both
    /// horizons, 1–30 bands, with hard cases (a cap of 1e-4 rad, one straddling the horizon,
    /// a point inside the HVL, one facing away); and the committed Lambert table is zonal in
    /// its view frame (every `m ≠ 0` coefficient below 1e-6 of `F_0^0`, so the zonal path
    /// is the full one to that relative amount).
    #[test]
    fn zonal_receivers_match_the_full_kernel() {
        let mut rng = crate::sh::test_rng(0x20_4a1);
        let mut u = || rng() * 2.0 - 1.0;
        let frame = view_frame(Vec3::new(0.1, -0.2, 1.0), Vec3::new(0.6, 0.1, 0.8)).unwrap();
        let x = Vec3::new(0.3, -0.1, 0.2);
        let n = frame.normal();
        let mut hvls = Vec::new();
        for _ in 0..1000 {
            let y = x + Vec3::new(u(), u(), u()) * 3.0;
            let nj = Vec3::new(u(), u(), u());
            let wl = Vec3::new(u(), u(), u());
            let r = 0.05 + (u() + 1.0);
            if let Ok(h) = Hvl::new(y, nj, wl, r, 1.5) {
                hvls.push(h);
            }
        }
        // Hard cases: a tiny cap overhead, one straddling the horizon, the point inside,
        // one facing away.
        let t = frame.tangent();
        hvls.push(Hvl::new(x + n * 1e4, -n, n, 1.0, 1.0).unwrap());
        hvls.push(Hvl::new(x + t * 2.0 + n * 0.01, -t, n, 0.5, 1.0).unwrap());
        hvls.push(Hvl::new(x + n * 0.1, -n, n, 0.5, 1.0).unwrap());
        hvls.push(Hvl::new(x + n * 2.0, n, n, 0.5, 1.0).unwrap());
        let em = lambert_emission(0.7);
        let mut scratch = vec![0.0f32; 900];
        for bands in [1usize, 2, 3, 5, 10, 30] {
            let zonal: Vec<f32> = (0..bands).map(|l| 1.0 / (1.0 + l as f32) - 0.3).collect();
            let mut full = vec![0.0f32; bands * bands];
            for (l, z) in zonal.iter().enumerate() {
                full[l * l + l] = *z;
            }
            let rf = Receiver {
                point: x,
                frame,
                coeffs: &full,
            };
            let rz = ZonalReceiver {
                point: x,
                frame,
                coeffs: &zonal,
            };
            let mut lit = 0;
            for h in &hvls {
                for horizon in [Horizon::Smoothstep, Horizon::Exact] {
                    let a = contribution(h, &em, &rf, horizon, &mut scratch).unwrap();
                    let b = contribution_zonal(h, &em, &rz, horizon, &mut scratch).unwrap();
                    assert!(
                        a == b && a.is_sign_negative() == b.is_sign_negative()
                            || a == 0.0 && b == 0.0,
                        "bands {bands}: {a} vs {b}"
                    );
                    lit += usize::from(a != 0.0);
                }
            }
            assert!(lit > 100, "{lit}");
        }
        // The Lambert table in its view frame is zonal.
        let t = brdf::lambert();
        let nb = t.bands();
        let mut c = vec![0.0f32; nb * nb];
        for theta in [0.0f32, 0.3, 0.8, 1.2, 1.5, 1.57] {
            t.lookup_into(Part::WithCosine, theta, nb, &mut c).unwrap();
            for l in 0..nb {
                for m in 1..=l {
                    for k in [l * l + l - m, l * l + l + m] {
                        assert!(
                            c[k].abs() <= 1e-6 * c[0].abs(),
                            "θ {theta}: F[{k}] = {}",
                            c[k]
                        );
                    }
                }
            }
        }
        // Bad input: a short scratch, too many bands.
        let rz = ZonalReceiver {
            point: x,
            frame,
            coeffs: &[1.0; 5],
        };
        assert!(contribution_zonal(&hvls[0], &em, &rz, Horizon::Exact, &mut [0.0; 4]).is_err());
        let many = vec![1.0f32; crate::sh::MAX_BANDS + 1];
        let rz = ZonalReceiver {
            point: x,
            frame,
            coeffs: &many,
        };
        assert!(contribution_zonal(&hvls[0], &em, &rz, Horizon::Exact, &mut scratch).is_err());
    }
}
