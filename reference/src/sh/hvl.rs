//! The exact contribution of one Harmonics Virtual Light (`steradian_core::sh::hvl`), in
//! `f64`: the HVL paper's eq. 3 with constant emission over the subtended cap —
//! `L_e = Φ·f_j(ω_l, −ω_j)·max(0, n_j·(−ω_j))/(πr²)` from the emitter's own BRDF, no SH —
//! times `∫_cap f_x(ω, ωₒ)·max(n_x·ω, 0) dω` by Gauss–Legendre in the polar angle around the
//! cap's axis and the midpoint rule in azimuth. No horizon factor: the clamped cosine is
//! the exact horizon.

use crate::lobe::brdf::Model;
use std::f64::consts::{PI, TAU};

/// One spherical light with an emitting BRDF.
#[derive(Clone, Copy, Debug)]
pub struct Light {
    /// Centre.
    pub position: [f64; 3],
    /// Unit normal of the surface it sits on.
    pub normal: [f64; 3],
    /// Unit direction toward the primary light (`normal·to_light > 0`).
    pub to_light: [f64; 3],
    /// Radius.
    pub radius: f64,
    /// Power received.
    pub power: f64,
    /// The surface's BRDF.
    pub model: Model,
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The local coordinates of `v` in the frame `z = n`, `x` toward the tangential part of
/// `toward` (any tangent if none), as a closure.
pub fn frame(n: [f64; 3], toward: [f64; 3]) -> impl Fn([f64; 3]) -> [f64; 3] {
    let k = dot(toward, n);
    let mut t = [
        toward[0] - k * n[0],
        toward[1] - k * n[1],
        toward[2] - k * n[2],
    ];
    let tl = dot(t, t).sqrt();
    if tl < 1e-12 {
        t = crate::perpendiculars(n).0;
    } else {
        t = t.map(|c| c / tl);
    }
    let b = [
        n[1] * t[2] - n[2] * t[1],
        n[2] * t[0] - n[0] * t[2],
        n[0] * t[1] - n[1] * t[0],
    ];
    move |v: [f64; 3]| [dot(v, t), dot(v, b), dot(v, n)]
}

/// The radiance `light` sends toward `wo` from the point `x` of unit normal `nx` whose BRDF
/// is `rx` (module docs), with `nodes` Gauss–Legendre nodes in the polar angle (and `4·nodes`
/// azimuths).
pub fn contribution(
    light: &Light,
    x: [f64; 3],
    nx: [f64; 3],
    wo: [f64; 3],
    rx: &Model,
    nodes: usize,
) -> f64 {
    let v = [
        light.position[0] - x[0],
        light.position[1] - x[1],
        light.position[2] - x[2],
    ];
    let d = dot(v, v).sqrt();
    let w = v.map(|c| c / d);
    let cos_j = -dot(w, light.normal);
    if cos_j <= 0.0 || d == 0.0 {
        return 0.0;
    }
    let fj = frame(light.normal, light.to_light);
    let f_emit = light.model.rho(fj(light.to_light), fj(w.map(|c| -c)));
    let le = light.power * f_emit * cos_j / (PI * light.radius * light.radius);
    let fx = frame(nx, wo);
    let wo_l = fx(wo);
    let a = (light.radius / d).min(1.0).asin();
    let (t1, t2) = crate::perpendiculars(w);
    let (gx, gw) = crate::quad::gauss_legendre(nodes);
    let nphi = 4 * nodes;
    let mut sum = 0.0;
    for (xq, wq) in gx.iter().zip(&gw) {
        let t = 0.5 * a * (1.0 + xq);
        let (s, c) = t.sin_cos();
        for j in 0..nphi {
            let p = (j as f64 + 0.5) * TAU / nphi as f64;
            let dir: [f64; 3] =
                std::array::from_fn(|i| c * w[i] + s * (p.cos() * t1[i] + p.sin() * t2[i]));
            sum += wq * 0.5 * a * s * TAU / nphi as f64 * rx.rho_cos(fx(dir), wo_l);
        }
    }
    le * sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_lambertian_light_over_a_lambertian_point_is_the_point_light_formula() {
        // Far and small: E = I·cos/d² with I = L_e·πr², reflected ρ/π·E.
        let light = Light {
            position: [0.0, 0.0, 10.0],
            normal: [0.0, 0.0, -1.0],
            to_light: [0.0, 0.0, -1.0],
            radius: 0.01,
            power: 3.0,
            model: Model::Lambert { a: 0.5 },
        };
        let got = contribution(
            &light,
            [0.0; 3],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
            &Model::Lambert { a: 1.0 },
            16,
        );
        let le = 3.0 * 0.5 / PI / (PI * 1e-4);
        let want = le * PI * 1e-4 / 100.0 / PI;
        assert!((got / want - 1.0).abs() < 1e-5, "{got} vs {want}");
    }
}
