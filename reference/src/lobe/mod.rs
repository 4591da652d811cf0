//! References for the cosine-lobe paper (`steradian_core::lobe`): lobe values and
//! integrals, the cap → lobe exponent optimum ([`cap`]), the exact product integral of two
//! lobes ([`product`]), the triple-product rendering integral ([`triple`]) and the BRDF
//! models ([`brdf`]).
//!
//! # References
//!
//! Those of `steradian_core::lobe`, whose kernels these references check (the cosine-lobe paper).

pub mod brdf;
pub mod cap;
pub mod product;
pub mod triple;

use std::f64::consts::{PI, TAU};

/// `v` normalised in f64 after scaling by its largest component (no overflow).
pub fn normalize(v: [f32; 3]) -> Option<[f64; 3]> {
    let v = v.map(f64::from);
    let m = v[0].abs().max(v[1].abs()).max(v[2].abs());
    if !(m > 0.0 && m.is_finite()) {
        return None;
    }
    let s = v.map(|c| c / m);
    let l = libm::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    Some(s.map(|c| c / l))
}

/// `s·max(â·v̂, 0)^e` with axis and direction normalised in f64 and `1 − â·v̂` computed as
/// `|â − v̂|²/2` (no cancellation near the axis).
pub fn lobe_eval(axis: [f32; 3], scale: f32, exponent: f32, v: [f32; 3]) -> f64 {
    let (Some(a), Some(v)) = (normalize(axis), normalize(v)) else {
        return f64::NAN;
    };
    let e = (exponent as f64).max(0.0);
    let d = [a[0] - v[0], a[1] - v[1], a[2] - v[2]];
    let t = 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if t >= 1.0 {
        return 0.0;
    }
    scale as f64 * libm::exp(e * libm::log1p(-t))
}

/// `2π·s/(e + 1)`.
pub fn lobe_integral(exponent: f32, scale: f32) -> f64 {
    TAU * scale as f64 / ((exponent as f64).max(0.0) + 1.0)
}

/// Solid angle of a cap, `2π(1 − cos α)` = `4π·sin²(α/2)`.
pub fn cap_solid_angle(half_angle: f64) -> f64 {
    let s = libm::sin(0.5 * half_angle);
    4.0 * PI * s * s
}
