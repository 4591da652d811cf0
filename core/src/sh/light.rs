//! Lights as SH radiance (HVL paper section 4.2): the incident radiance at a point from a
//! point, spot or directional light (a Dirac in one direction) and from a spherical light
//! (constant radiance over the cap it subtends, eq. 9–15).
//!
//! **The Dirac projections.** A light seen from the point in the single direction `ω₀`,
//! delivering the irradiance `E` on a surface facing it, has `L(ω) = E·δ(ω, ω₀)` and so the
//! coefficients `∫ L·Y_l^m = E·Y_l^m(ω₀)`: `E = I/d²` for a point light of intensity `I`
//! (W/sr) at distance `d`, times the spot's angular profile for a spot light, and `E` itself
//! for a directional light. They are exact as distributions; reconstructed at `n` bands they
//! ring, which is what the windows of [`crate::sh::window`] are for.
//!
//! **Spherical lights.** The sphere of radius `r` at distance `d` subtends the cap of
//! half-angle `asin(r/d)` around the direction to its centre; constant radiance `L_e` over it
//! gives `L_e` times the cap coefficients of [`crate::sh::cap`] (cancellation-free for tiny
//! caps).
//!
//! **Bad input** (every function): a non-finite point or light, a light at the point, a
//! point inside a spherical light, a spot with `cos_inner < cos_outer`, a band count above
//! `MAX_BANDS` or a short output are errors.

use crate::lobe::cap::SphericalCap;
use crate::sh::{cap, check_shape, eval_into};
use crate::{Error, Vec3};

/// `out = weight·Y(dir)` over `bands` bands: a Dirac of weight `weight` in direction `dir`
/// (any non-zero length).
///
/// Errors: a zero or non-finite `dir`, a non-finite weight, the shapes.
pub fn dirac_into(dir: Vec3, weight: f32, bands: usize, out: &mut [f32]) -> Result<(), Error> {
    if !dir.is_finite() {
        return Err(Error::NonFinite { what: "direction" });
    }
    if dir == Vec3::ZERO {
        return Err(Error::ZeroVector { what: "direction" });
    }
    if !weight.is_finite() {
        return Err(Error::NonFinite { what: "weight" });
    }
    eval_into(dir, bands, out)?;
    for v in &mut out[..bands * bands] {
        *v *= weight;
    }
    Ok(())
}

/// `(unit direction from point to light, distance²)`, in `f64` so that far lights do not
/// overflow.
fn towards(point: Vec3, light: Vec3) -> Result<(Vec3, f32), Error> {
    if !point.is_finite() || !light.is_finite() {
        return Err(Error::NonFinite {
            what: "point or light position",
        });
    }
    let v = light.as_dvec3() - point.as_dvec3();
    let d2 = v.length_squared();
    if d2 == 0.0 {
        return Err(Error::ZeroVector {
            what: "light − point",
        });
    }
    Ok(((v / crate::math::sqrt64(d2)).as_vec3(), d2 as f32))
}

/// A point light of intensity `intensity` (W/sr, per channel) at `position`, seen from
/// `point`: `(I/d²)·Y(ω₀)`.
pub fn point_light_into(
    point: Vec3,
    position: Vec3,
    intensity: f32,
    bands: usize,
    out: &mut [f32],
) -> Result<(), Error> {
    let (w, d2) = towards(point, position)?;
    dirac_into(w, intensity / d2, bands, out)
}

/// A spot light at `position` pointing along `axis`, of intensity `intensity` on its axis:
/// full inside the cone `cos ≥ cos_inner`, zero outside `cos_outer`, and a smoothstep in
/// between (the usual renderer spot), seen from `point`.
///
/// Errors: as [`point_light_into`], a zero axis, `cos_inner < cos_outer` or either outside
/// `[−1, 1]`.
#[allow(clippy::too_many_arguments)] // the spot's own parameters
pub fn spot_light_into(
    point: Vec3,
    position: Vec3,
    axis: Vec3,
    cos_outer: f32,
    cos_inner: f32,
    intensity: f32,
    bands: usize,
    out: &mut [f32],
) -> Result<(), Error> {
    if !(-1.0..=1.0).contains(&cos_outer) || !(cos_outer..=1.0).contains(&cos_inner) {
        return Err(Error::OutOfRange {
            what: "spot cos_inner (must lie in [cos_outer, 1])",
            value: cos_inner,
            min: cos_outer,
            max: 1.0,
        });
    }
    if !axis.is_finite() || axis == Vec3::ZERO {
        return Err(Error::ZeroVector { what: "spot axis" });
    }
    let (w, d2) = towards(point, position)?;
    // The direction from the light to the point is −w.
    let c = -w.dot(axis.normalize());
    let profile = if c >= cos_inner {
        1.0
    } else if c <= cos_outer {
        0.0
    } else {
        let t = (c - cos_outer) / (cos_inner - cos_outer);
        t * t * (3.0 - 2.0 * t)
    };
    dirac_into(w, intensity * profile / d2, bands, out)
}

/// A directional light: irradiance `irradiance` (on a surface facing it) arriving from the
/// direction `towards_light`.
pub fn directional_into(
    towards_light: Vec3,
    irradiance: f32,
    bands: usize,
    out: &mut [f32],
) -> Result<(), Error> {
    dirac_into(towards_light, irradiance, bands, out)
}

/// A spherical light of radiance `radiance` (per channel), centre `centre` and radius
/// `radius`, seen from `point` (eq. 9–15): `L_e·∫_cap Y`.
///
/// Errors: the point inside or on the sphere, a non-positive radius, non-finite input,
/// the shapes.
pub fn sphere_light_into(
    point: Vec3,
    centre: Vec3,
    radius: f32,
    radiance: f32,
    bands: usize,
    out: &mut [f32],
) -> Result<(), Error> {
    if !radiance.is_finite() {
        return Err(Error::NonFinite { what: "radiance" });
    }
    check_shape(bands, out.len())?;
    let c = SphericalCap::from_sphere(point, centre, radius)?;
    cap::coefficients_into(c.axis(), c.half_angle(), bands, out)?;
    for v in &mut out[..bands * bands] {
        *v *= radiance;
    }
    Ok(())
}

#[cfg(all(test, feature = "alloc"))]
mod tests {
    use super::*;
    use alloc::vec;

    #[test]
    fn a_dirac_is_the_basis_at_its_direction_times_its_weight() {
        let d = Vec3::new(0.3, -0.4, 0.5);
        let mut y = vec![0.0; 25];
        let mut c = vec![0.0; 25];
        eval_into(d, 5, &mut y).unwrap();
        dirac_into(d * 8.0, 2.5, 5, &mut c).unwrap(); // any length (8·d is exact)
        for (a, b) in y.iter().zip(&c) {
            assert_eq!(a * 2.5, *b);
        }
        assert!(dirac_into(Vec3::ZERO, 1.0, 5, &mut c).is_err());
        assert!(dirac_into(Vec3::X, f32::NAN, 5, &mut c).is_err());
    }

    #[test]
    fn point_lights_fall_off_with_the_inverse_square() {
        let mut a = vec![0.0; 16];
        let mut b = vec![0.0; 16];
        let p = Vec3::new(1.0, 2.0, 3.0);
        point_light_into(p, p + Vec3::new(0.0, 1.0, 1.0), 10.0, 4, &mut a).unwrap();
        point_light_into(p, p + Vec3::new(0.0, 2.0, 2.0), 10.0, 4, &mut b).unwrap();
        for (x, y) in a.iter().zip(&b) {
            assert!((x - 4.0 * y).abs() <= 1e-6 * x.abs().max(1e-6));
        }
        assert!(point_light_into(p, p, 1.0, 4, &mut a).is_err());
        // Far away without overflow: d² = 3e60 in f64, I/d² = 0 in f32, finite.
        point_light_into(Vec3::ZERO, Vec3::splat(1e30), 1.0, 4, &mut a).unwrap();
        assert!(a.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn spots_are_point_lights_inside_zero_outside_and_smooth_between() {
        let (pos, axis) = (Vec3::new(0.0, 0.0, 4.0), -Vec3::Z);
        let (co, ci) = (0.8f32, 0.9f32);
        let mut s = vec![0.0; 9];
        let mut p = vec![0.0; 9];
        // On the axis: the point light.
        spot_light_into(Vec3::ZERO, pos, axis, co, ci, 3.0, 3, &mut s).unwrap();
        point_light_into(Vec3::ZERO, pos, 3.0, 3, &mut p).unwrap();
        assert_eq!(s, p);
        // Outside the outer cone: zero.
        spot_light_into(Vec3::new(4.0, 0.0, 0.0), pos, axis, co, ci, 3.0, 3, &mut s).unwrap();
        assert!(s.iter().all(|&v| v == 0.0));
        // Between: strictly between.
        let q = Vec3::new(4.0 * 0.6, 0.0, 0.0); // cos = 4/√(16 + 5.76) ≈ 0.857
        spot_light_into(q, pos, axis, co, ci, 3.0, 3, &mut s).unwrap();
        point_light_into(q, pos, 3.0, 3, &mut p).unwrap();
        assert!(s[0] > 0.0 && s[0] < p[0]);
        assert!(spot_light_into(q, pos, axis, 0.9, 0.8, 3.0, 3, &mut s).is_err());
        assert!(spot_light_into(q, pos, Vec3::ZERO, co, ci, 3.0, 3, &mut s).is_err());
    }

    #[test]
    fn a_small_sphere_light_is_a_point_light_of_the_same_intensity() {
        // Radiance L over a sphere of radius r: intensity π r² L toward the point.
        let (c, r, l) = (Vec3::new(0.3, -1.0, 2.0), 1e-3f32, 5.0f32);
        let mut s = vec![0.0; 36];
        let mut p = vec![0.0; 36];
        sphere_light_into(Vec3::ZERO, c, r, l, 6, &mut s).unwrap();
        point_light_into(Vec3::ZERO, c, core::f32::consts::PI * r * r * l, 6, &mut p).unwrap();
        for (a, b) in s.iter().zip(&p) {
            assert!((a - b).abs() <= 1e-5 * p[0].abs(), "{a} vs {b}");
        }
        assert!(sphere_light_into(Vec3::ZERO, c, 10.0, l, 6, &mut s).is_err());
        assert!(sphere_light_into(Vec3::ZERO, c, -1.0, l, 6, &mut s).is_err());
    }
}
