//! The closed-form cap integrals of `steradian_core::lobe::cap` on arbitrary caps and
//! normals from raw bytes: `SphericalCap::clipped_cosine` (a sphere light's cosine-weighted
//! solid angle above a receiver's horizon) and `SphericalCap::overlap_moment` (the vector
//! moment of two caps' overlap, which the `lobes` method subtracts for its occluders).
//!
//! Input: eleven `f32` (axis `a`, half-angle `α_a`, axis `b`, half-angle `α_b`, normal
//! `n`, little-endian, missing bytes zero) and a flag byte; with its bit 0 the half-angles
//! are folded into `(0, π]` and with bit 1 the axis `b` is moved to within a few half-angles
//! of `a`, so that most inputs reach the formulas (crossing, nested, tangent, opposite
//! axes) rather than the constructors' errors. Checked:
//!
//! - never a panic; `SphericalCap::new` accepts exactly the finite non-zero axes
//!   (subnormal ones included) and half-angles in `(0, π]`;
//! - for a unit `n`: `clipped_cosine` finite, in `[0, π sin²α]` (`[0, π]` past a
//!   hemisphere), equal to `π sin²α·(n·a)` within its documented `5e-7·π sin²α` (plus the
//!   `f32` rounding of `n·a`) where the cap is wholly above the horizon and within the bound
//!   of 0 where wholly below; a non-finite `n` gives NaN;
//! - every cap → lobe fit (`SphericalCap::lobe`: L2, energy-preserving, moments) gives a
//!   finite non-negative exponent and scale; the energy-preserving and moments lobes
//!   integrate to the cap's solid angle within `1e-4` relative (the moments lobe of a cap
//!   up to a hemisphere; past it, its solid angle);
//! - `overlap_moment` finite, no longer than the smaller cap's own moment, symmetric in the
//!   two caps within `1e-5` of that scale, 0 for caps clearly apart and the inner cap's own
//!   moment `π sin²α·axis` for a cap clearly inside the other; and where `a` is wholly above
//!   the horizon, `n·overlap ≤ clipped_cosine` (an occluder hides at most the light).

use steradian_core::Vec3;
use steradian_core::lobe::cap::{CapFit, SphericalCap};

const PI: f32 = core::f32::consts::PI;

fn floats(data: &[u8]) -> ([f32; 11], u8) {
    let mut v = [0.0f32; 11];
    for (k, x) in v.iter_mut().enumerate() {
        let mut b = [0u8; 4];
        for (i, byte) in b.iter_mut().enumerate() {
            *byte = data.get(4 * k + i).copied().unwrap_or(0);
        }
        *x = f32::from_le_bytes(b);
    }
    (v, data.get(44).copied().unwrap_or(0))
}

/// `x` folded into `(0, π]` (finite `x`; others unchanged).
fn fold_angle(x: f32) -> f32 {
    if !x.is_finite() {
        return x;
    }
    let r = x.abs() % PI;
    if r > 0.0 { r } else { PI }
}

/// `∫_cap ω dω`'s length: `π sin²α`, and `π` past a hemisphere (the bound the tests use).
fn own_moment(c: &SphericalCap) -> f32 {
    if c.half_angle() <= core::f32::consts::FRAC_PI_2 {
        PI * c.half_angle().sin().powi(2)
    } else {
        PI
    }
}

pub fn check(data: &[u8]) {
    let (v, flags) = floats(data);
    let (mut aa, mut ab) = (v[3], v[7]);
    if flags & 1 != 0 {
        aa = fold_angle(aa);
        ab = fold_angle(ab);
    }
    let a_axis = Vec3::new(v[0], v[1], v[2]);
    let mut b_axis = Vec3::new(v[4], v[5], v[6]);
    if flags & 2 != 0 && a_axis.is_finite() && b_axis.is_finite() {
        // `b` near `a`: `a` plus a perturbation of a few half-angles.
        let t = b_axis.clamp_length_max(1.0) * (aa.abs() + ab.abs()).min(4.0);
        let a_unit = a_axis.normalize_or_zero();
        b_axis = a_unit + t;
    }
    let n = Vec3::new(v[8], v[9], v[10]);

    let valid = |axis: Vec3, angle: f32| {
        axis.is_finite() && axis != Vec3::ZERO && angle.is_finite() && angle > 0.0 && angle <= PI
    };
    let ca = SphericalCap::new(a_axis, aa);
    let cb = SphericalCap::new(b_axis, ab);
    // Accepted exactly where valid (subnormal and huge axes are normalised without
    // underflow or overflow).
    assert_eq!(ca.is_ok(), valid(a_axis, aa), "{a_axis} {aa}: {ca:?}");
    assert_eq!(cb.is_ok(), valid(b_axis, ab), "{b_axis} {ab}: {cb:?}");
    let (Ok(a), Ok(b)) = (ca, cb) else { return };

    // The cap → lobe fits.
    for fit in [CapFit::L2, CapFit::EnergyPreserving, CapFit::Moments] {
        let l = a.lobe(1.0, fit);
        assert!(
            l.exponent().is_finite() && l.exponent() >= 0.0 && l.scale().is_finite(),
            "{fit:?} lobe of {a:?}: {l:?}"
        );
        assert!(l.scale() >= 0.0, "{fit:?} lobe of {a:?}: {l:?}");
        // The solid angle, where it is a normal f32 (tiny caps' `1 − cos α` underflows).
        let omega = a.solid_angle();
        if fit != CapFit::L2 && omega > 1e-30 {
            let got = l.integral();
            assert!(
                (got / omega - 1.0).abs() <= 1e-4,
                "{fit:?} lobe of {a:?} integrates to {got}, the cap's solid angle is {omega}"
            );
        }
    }

    if !n.is_finite() {
        assert!(a.clipped_cosine(n).is_nan(), "non-finite normal {n}");
        return;
    }
    let n = n.normalize_or_zero();
    if n == Vec3::ZERO || (n.length() - 1.0).abs() > 1e-6 {
        return;
    }

    // clipped_cosine.
    let top = own_moment(&a);
    let c = a.clipped_cosine(n);
    let ctx = || format!("a = {a:?}, b = {b:?}, n = {n}");
    assert!(
        c.is_finite() && c >= 0.0 && c <= top * (1.0 + 1e-5) + 1e-30,
        "clipped_cosine {c} outside [0, {top}]: {}",
        ctx()
    );
    let s = a.half_angle().sin();
    let cos_t = n.dot(a.axis());
    if a.half_angle() <= core::f32::consts::FRAC_PI_2 {
        let scale = PI * s * s;
        // The bound plus the f32 rounding of `n·a` (a few ulps of 1, times π s²).
        let tol = 5e-7 * scale + 4.0 * f32::EPSILON * scale + 1e-30;
        if cos_t >= s + 1e-5 {
            let want = scale * cos_t;
            assert!((c - want).abs() <= tol, "above: {c} vs {want}: {}", ctx());
        }
        if cos_t <= -s - 1e-5 {
            assert!(c <= tol, "below: {c}: {}", ctx());
        }
    }

    // overlap_moment.
    let m = a.overlap_moment(&b);
    let cap = own_moment(&a).min(own_moment(&b));
    assert!(
        m.is_finite() && m.length() <= cap * (1.0 + 1e-4) + 1e-12,
        "overlap {m} longer than {cap}: {}",
        ctx()
    );
    let back = b.overlap_moment(&a);
    assert!(
        (back - m).length() <= 1e-5 * cap + 1e-12,
        "not symmetric: {m} vs {back}: {}",
        ctx()
    );
    let d = a.axis().dot(b.axis()).clamp(-1.0, 1.0).acos();
    let (ra, rb) = (a.half_angle(), b.half_angle());
    // Clearly apart or clearly nested (margins above the f32 rounding of the angles).
    if d >= ra + rb + 1e-3 {
        assert!(m.length() <= 1e-5 * cap + 1e-12, "apart: {m}: {}", ctx());
    }
    for (outer, inner, r_in, r_out) in [(&a, &b, rb, ra), (&b, &a, ra, rb)] {
        if d + r_in <= r_out - 1e-3 && r_in <= core::f32::consts::FRAC_PI_2 {
            let want = inner.axis() * (PI * r_in.sin().powi(2));
            assert!(
                (m - want).length() <= 1e-4 * want.length() + 1e-12,
                "nested in {outer:?}: {m} vs {want}: {}",
                ctx()
            );
        }
    }
    if a.half_angle() <= core::f32::consts::FRAC_PI_2 && cos_t >= s {
        assert!(
            n.dot(m) <= c * (1.0 + 1e-4) + 1e-12,
            "hides more than the light: {} vs {c}: {}",
            n.dot(m),
            ctx()
        );
    }
}
