//! The `hvl` method (HVL paper, section 5.2): one bounce of indirect light from harmonics
//! virtual lights placed from a reflective shadow map of each spherical light, plus the
//! direct light of the `lobes` method.
//!
//! **Placement.** A sphere of radius `r` and radiance `L` radiates the intensity
//! `I = L·πr²` in every direction (its projected area is `πr²` from anywhere), so a cube
//! map of `6·s²` texels around its centre (field of view 90° per face) sends the power
//! `Φ = I·Ω_texel` (the texel's exact solid angle) along each texel's
//! centre ray; the first surface hit `y` (normal `n_y` toward the light) receives it and
//! becomes an HVL of radius `r2 = k·t·tan γ` (eq. 24–25, `t` the ray's length, `γ` the
//! diagonal angle of an `s × s` face of field of view 90°, `k = 1`). Rays that escape or
//! hit another light place nothing.
//!
//! **Emission and reception** (eq. 19–22, `steradian_core::sh::hvl::contribution`): an HVL
//! reflects its surface's *diffuse* albedo (Lambertian emission, exact in one band); a
//! receiver's diffuse albedo times the 5-band Lambert table. Both are linear, so the
//! scalar contribution of a unit HVL is computed once per pair and scaled in RGB by the
//! light's radiance and the two albedos. Glossy parts are not carried by the indirect
//! term (a BRDF table per material would be: not built here). The paper does not test
//! visibility between an HVL and the receiver; here a shadow ray per pair does by default
//! ([`Options::visibility`]), which the harness measures on the `room` scene.

use std::f64::consts::FRAC_PI_2;

use glam::DVec3;
use indicatif::ProgressBar;
use steradian_core::lobe::sum::ProductCounts;
use steradian_core::sh::{brdf, hvl as core_hvl};

use super::image::Image;
use super::{Kind, Ray, Rgb, Scene, ShadingPoint, lobes, path, render_centres};

/// Settings of the `hvl` method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Cube-map face side of each light's reflective shadow map (`6·side²` rays).
    pub side: usize,
    /// The `lobes` method's settings for the direct light.
    pub direct: lobes::Options,
    /// Test each HVL–receiver pair with a shadow ray (the paper does not: `false`).
    pub visibility: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            side: 8,
            direct: lobes::Options::default(),
            visibility: true,
        }
    }
}

/// One placed HVL: the core light (unit power) and its RGB power × albedo.
#[derive(Clone, Copy, Debug)]
pub struct Placed {
    /// The core HVL with unit power.
    pub hvl: core_hvl::Hvl,
    /// `Φ·albedo` in RGB: what multiplies the unit contribution.
    pub weight: Rgb,
}

/// The HVLs of every spherical light.
pub fn place(scene: &Scene, side: usize) -> Vec<Placed> {
    let side = side.max(1);
    let m = (side * side) as u32;
    let du = 2.0 / side as f64;
    let mut out = Vec::new();
    for light in &scene.lights {
        let intensity = light
            .radiance
            .map(|l| l * std::f64::consts::PI * light.radius.powi(2));
        for face in 0..6 {
            let (axis, t, b) = face_frame(face);
            for i in 0..side {
                for j in 0..side {
                    let (u, v) = (-1.0 + (i as f64 + 0.5) * du, -1.0 + (j as f64 + 0.5) * du);
                    let omega = texel_solid_angle(u - du / 2.0, v - du / 2.0, du);
                    let d = (axis + u * t + v * b).normalize();
                    let ray = Ray {
                        o: light.center + d * light.radius * (1.0 + 1e-9),
                        d,
                    };
                    let Some(hit) = scene.intersect(&ray, 0.0, f64::INFINITY) else {
                        continue;
                    };
                    let obj = scene.objects[hit.object];
                    let Kind::Surface(mi) = obj.kind else {
                        continue;
                    };
                    let y = ray.o + hit.t * d;
                    let mut n = obj.shape.normal(y);
                    if n.dot(d) > 0.0 {
                        n = -n;
                    }
                    let dist = (y - light.center).length();
                    let r = core_hvl::radius_from_fov(dist as f32, FRAC_PI_2 as f32, m, 1.0);
                    let Ok(h) = core_hvl::Hvl::new(
                        y.as_vec3(),
                        n.as_vec3(),
                        (-d).as_vec3(),
                        r.max(1e-6),
                        1.0,
                    ) else {
                        continue;
                    };
                    let albedo = scene.materials[mi].diffuse();
                    let mut w = [0.0; 3];
                    for c in 0..3 {
                        w[c] = intensity[c] * omega * albedo[c];
                    }
                    out.push(Placed { hvl: h, weight: w });
                }
            }
        }
    }
    out
}

/// The exact solid angle of the cube-face texel `[u, u + du] × [v, v + du]` at unit
/// distance: `F(u₁, v₁) − F(u₀, v₁) − F(u₁, v₀) + F(u₀, v₀)`, `F = atan(uv/√(1 + u² + v²))`
/// (the solid angle of the rectangle from the face centre to `(u, v)`), so a face sums to
/// `4·F(1, 1) = 4π/6` exactly.
fn texel_solid_angle(u: f64, v: f64, du: f64) -> f64 {
    let f = |a: f64, b: f64| (a * b / (1.0 + a * a + b * b).sqrt()).atan();
    f(u + du, v + du) - f(u, v + du) - f(u + du, v) + f(u, v)
}

/// Axis, and two tangents, of cube face `f` (±x, ±y, ±z).
fn face_frame(f: usize) -> (DVec3, DVec3, DVec3) {
    let axis = match f {
        0 => DVec3::X,
        1 => -DVec3::X,
        2 => DVec3::Y,
        3 => -DVec3::Y,
        4 => DVec3::Z,
        _ => -DVec3::Z,
    };
    let (t, b) = super::material::basis(axis);
    (axis, t, b)
}

/// Per-thread buffers of [`indirect`]: the receiver's coefficients, their zonal part and
/// the SH scratch.
pub struct Scratch {
    coeffs: Vec<f32>,
    zonal: Vec<f32>,
    sh: Vec<f32>,
}

impl Default for Scratch {
    fn default() -> Self {
        let n = brdf::lambert().bands();
        Scratch {
            coeffs: vec![0.0; n * n],
            zonal: vec![0.0; n],
            sh: vec![0.0; n * n],
        }
    }
}

/// The indirect radiance at a shading point from the placed HVLs. The receiver is its
/// diffuse part, whose Lambert coefficients are zonal in its view frame (the table's
/// `m ≠ 0` entries are below `1e-6` of `F_0^0`, asserted in core), so each HVL goes through
/// [`core_hvl::contribution_zonal`] with the `m = 0` entries: `n` basis values per HVL
/// instead of `n²`.
pub fn indirect(
    scene: &Scene,
    p: &ShadingPoint,
    hvls: &[Placed],
    visibility: bool,
    scratch: &mut Scratch,
) -> Rgb {
    let table = brdf::lambert();
    let albedo = scene.materials[p.material].diffuse();
    if albedo.iter().all(|&a| a == 0.0) {
        return [0.0; 3];
    }
    let Ok(frame) = brdf::view_frame(p.n.as_vec3(), p.wo.as_vec3()) else {
        return [0.0; 3];
    };
    let theta = frame.to_local(p.wo.as_vec3()).z.clamp(-1.0, 1.0).acos();
    let Scratch { coeffs, zonal, sh } = scratch;
    let n = table.bands();
    if table
        .lookup_into(brdf::Part::WithCosine, theta, n, coeffs)
        .is_err()
    {
        return [0.0; 3];
    }
    for (l, z) in zonal.iter_mut().enumerate().take(n) {
        *z = coeffs[l * l + l];
    }
    let rx = core_hvl::ZonalReceiver {
        point: p.x.as_vec3(),
        frame,
        coeffs: &zonal[..n],
    };
    let emission = core_hvl::lambert_emission(1.0);
    let origin = path::offset(p.x, p.n);
    let mut acc = [0.0f64; 3];
    for h in hvls {
        let c =
            core_hvl::contribution_zonal(&h.hvl, &emission, &rx, core_hvl::Horizon::Smoothstep, sh)
                .unwrap_or(0.0) as f64;
        if c <= 0.0 {
            continue;
        }
        if visibility {
            let to = h.hvl.position().as_dvec3() - origin;
            let d = to.length();
            let ray = Ray {
                o: origin,
                d: to / d,
            };
            if scene.occluded(&ray, 0.0, d * (1.0 - 1e-4)) {
                continue;
            }
        }
        for (a, w) in acc.iter_mut().zip(h.weight) {
            *a += c * w;
        }
    }
    [acc[0] * albedo[0], acc[1] * albedo[1], acc[2] * albedo[2]]
}

/// The reflective-shadow-map face sides a plan tries, smallest first ([`choose_side`]):
/// `6·side²` HVLs per light.
pub const SIDE_CANDIDATES: [usize; 5] = [2, 4, 8, 12, 16];

/// What [`choose_side`] chose and what it measured.
#[derive(Clone, Debug)]
pub struct SideChoice {
    /// The chosen face side.
    pub side: usize,
    /// `(side, estimate)`: the probes' mean |difference| from the largest candidate over its
    /// largest value ([`super::probe_estimates`]).
    pub estimates: Vec<(usize, f64)>,
}

/// The smallest face side of [`SIDE_CANDIDATES`] whose HVLs keep the shaded probes within
/// [`super::PLAN_SHARE`] of `target` (mean |difference| over the maximum radiance, the
/// render's measure) of the largest candidate's. The probes are the [`super::probe_points`] grid; each is lit by
/// the same direct light (`o.direct`) for every side, so the difference is the HVL count's
/// alone, and the largest value includes the direct light as the render's does. The rest
/// of the target is left to the direct light and to the HVL approximation itself. The
/// largest candidate if none is within.
pub fn choose_side(scene: &Scene, o: &Options, target: f64) -> SideChoice {
    let probes = super::probe_points(scene);
    let mut counts = ProductCounts::default();
    let direct: Vec<Rgb> = probes
        .iter()
        .map(|p| lobes::shade(scene, p, &o.direct, &mut counts))
        .collect();
    let mut scratch = Scratch::default();
    let images: Vec<Vec<Rgb>> = SIDE_CANDIDATES
        .iter()
        .map(|&side| {
            let hvls = place(scene, side);
            probes
                .iter()
                .zip(&direct)
                .map(|(p, d)| {
                    let i = indirect(scene, p, &hvls, o.visibility, &mut scratch);
                    [d[0] + i[0], d[1] + i[1], d[2] + i[2]]
                })
                .collect()
        })
        .collect();
    let (side, estimates) = super::plan_choice(&SIDE_CANDIDATES, &images, target)
        .unwrap_or((SIDE_CANDIDATES[0], Vec::new()));
    SideChoice { side, estimates }
}

/// Direct light by the `lobes` method plus one bounce from HVLs, one pixel-centre sample
/// per pixel ([`super::render_centres`]); returns the image and the HVL count.
pub fn render(scene: &Scene, o: &Options, bar: &ProgressBar) -> (Image, usize) {
    let hvls = place(scene, o.side);
    let new_state = || (ProductCounts::default(), Scratch::default());
    let (img, _) = render_centres(scene, bar, new_state, |(counts, scratch), p| {
        let d = lobes::shade(scene, p, &o.direct, counts);
        let ind = indirect(scene, p, &hvls, o.visibility, scratch);
        [d[0] + ind[0], d[1] + ind[1], d[2] + ind[2]]
    });
    (img, hvls.len())
}
