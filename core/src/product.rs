//! Products of two cosine lobes (cosine-lobe paper, section 4.1):
//! `c1(v)·c2(v) ≈ s1·s2·p·max(a_r·v, 0)^e_r`.
//!
//! WORK IN PROGRESS: the geometry (axis angle, result axis) is final; the scale and exponent
//! come from the spherical-Gaussian closed form until the (e1, e2, α) table lands.

use crate::lobe::CosineLobe;
use crate::math;
use crate::{TWO_PI, Vec3};

/// Angle between two unit axes, `atan2(|a×b|, a·b)`: accurate at 0 and near π, where
/// `acos(a·b)` loses half the digits.
#[inline]
pub fn angle_between(a: Vec3, b: Vec3) -> f32 {
    math::atan2f(a.cross(b).length(), a.dot(b))
}

/// The angle `t* ∈ [0, α]` from `a1` toward `a2` where `cos^e1(t)·cos^e2(α − t)` peaks:
/// `t* = (α + asin(((e2 − e1)/(e1 + e2))·sin α))/2` (the root of `e1·tan t = e2·tan(α − t)`;
/// DESIGN.md). Written as `(α − asin(r·sin α))/2` with `r = (e1 − e2)/(e1 + e2)` through an
/// `atan2` that keeps full relative precision when the result is tiny. `α/2` when both
/// exponents are 0. Exponents are clamped to `≥ 0`; NaN in → NaN out.
pub fn peak_angle(e1: f32, e2: f32, alpha: f32) -> f32 {
    let (e1, e2) = (e1.max(0.0), e2.max(0.0));
    let n = e1 + e2;
    if n == 0.0 || !n.is_finite() {
        return if alpha.is_nan() || n.is_nan() {
            f32::NAN
        } else {
            0.5 * alpha
        };
    }
    let (s, c) = (math::sinf(alpha), math::cosf(alpha));
    // r = (e1 − e2)/n, 1 − r² = 4·e1·e2/n².
    let r = (e1 - e2) / n;
    let omr2 = 4.0 * (e1 / n) * (e2 / n);
    // A = α, y = asin(r·sin A): cos y = sqrt(c² + (1 − r²)s²) for A in [0, π] (cos y ≥ 0).
    let cy = math::sqrtf(c * c + omr2 * s * s);
    let rc = r * c;
    // sin(A − y) = s·cy − c·r·s = s·(cy − r·c); without cancellation when r·c ≥ 0:
    // cy − rc = (cy² − rc²)/(cy + rc) = s²·(1 − r²)... /(cy + rc) → s·omr2·s/(cy+rc)·(1/s)
    let sn = if rc >= 0.0 {
        let den = cy + rc;
        if den > 0.0 { s * omr2 / den } else { 0.0 }
    } else {
        s * (cy - rc)
    };
    // cos(A − y) = c·cy + s·r·s
    let cs = c * cy + r * s * s;
    0.5 * math::atan2f(sn, cs)
}

/// The direction `t` radians from `a1` toward `a2` on the great arc through both (unit
/// axes `alpha` apart). Falls back to a fixed perpendicular of `a1` when the axes are
/// (anti)parallel, where the arc is not unique.
#[inline]
pub fn along_arc(a1: Vec3, a2: Vec3, alpha: f32, t: f32) -> Vec3 {
    let w = a2 - a1 * a1.dot(a2);
    let len = w.length();
    let w = if len > 1e-30 && alpha > 0.0 {
        w / len
    } else {
        crate::frame::Frame::from_unit_normal(a1).tangent()
    };
    a1 * math::cosf(t) + w * math::sinf(t)
}

/// `ln` of the integral of the product of two spherical Gaussians `exp(λ(a·v − 1))` with
/// `λ_i = e_i` whose axes are `α` apart (closed form; see [`product_sg`]).
pub fn ln_sg_integral(e1: f32, e2: f32, alpha: f32) -> f32 {
    let (l1, l2) = (e1.max(0.0), e2.max(0.0));
    let (sh, ch) = (math::sinf(0.5 * alpha), math::cosf(0.5 * alpha));
    let lr = math::sqrtf((l1 - l2) * (l1 - l2) + 4.0 * l1 * l2 * ch * ch);
    let den = lr + l1 + l2;
    let ln_s = if den > 0.0 {
        -4.0 * l1 * l2 * sh * sh / den
    } else {
        0.0
    };
    let ln_int = if lr == 0.0 {
        math::logf(2.0 * TWO_PI)
    } else {
        math::logf(TWO_PI) + math::logf(-math::expm1f(-2.0 * lr)) - math::logf(lr)
    };
    ln_s + ln_int
}

/// `ln` of the peak value `cos^e1(t*)·cos^e2(α − t*)` of the product of two unit lobes.
#[inline]
pub fn ln_peak(e1: f32, e2: f32, alpha: f32, t: f32) -> f32 {
    let term = |e: f32, x: f32| {
        if e == 0.0 {
            0.0
        } else {
            e * math::logf(math::cosf(x))
        }
    };
    term(e1.max(0.0), t) + term(e2.max(0.0), alpha - t)
}

/// Builds the result lobe from the peak and the integral: peak value `P = s1·s2·peak`,
/// exponent from `P·2π/(e_r + 1) = I`.
fn lobe_from(axis: Vec3, ln_scale: f32, ln_peak: f32, ln_int: f32) -> CosineLobe {
    // e_r + 1 = 2π·peak/I.
    let e = math::expf(math::logf(TWO_PI) + ln_peak - ln_int) - 1.0;
    CosineLobe::saturating(axis, math::expf(ln_scale + ln_peak), e.max(0.0))
}

/// The spherical-Gaussian closed form (no table): the axis and peak of the exact product,
/// the integral of the SG product.
pub fn product_sg(a: &CosineLobe, b: &CosineLobe) -> CosineLobe {
    let (e1, e2) = (a.exponent(), b.exponent());
    let alpha = angle_between(a.axis(), b.axis());
    let t = peak_angle(e1, e2, alpha);
    let axis = along_arc(a.axis(), b.axis(), alpha, t);
    let ln_scale = math::logf(a.scale()) + math::logf(b.scale());
    lobe_from(
        axis,
        ln_scale,
        ln_peak(e1, e2, alpha, t),
        ln_sg_integral(e1, e2, alpha),
    )
}

/// The product of two lobes as one lobe. See the module docs.
pub fn product(a: &CosineLobe, b: &CosineLobe) -> CosineLobe {
    product_sg(a, b)
}
