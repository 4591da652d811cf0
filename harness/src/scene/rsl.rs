//! The `rsl` method (rotatable-square-lights paper): environment lighting through `K`
//! rotatable square lights, BRDF summed-area tables and per-point visibility moment tables
//! ([`steradian_core::rsl::shade::shade_moments`], eq. 5 with first-order visibility).
//!
//! - The environment (times its scale) is resampled to a cube map of [`Options::face`]²
//!   texels per face and decomposed into `K` RSLs by bottom-up merging
//!   ([`crate::env::decompose`]).
//! - BRDF SATs are fitted for what the scene's materials need: one for the diffuse part
//!   (Lambert, albedo 1, times each material's diffuse RGB) and one per distinct Phong
//!   exponent for the specular part (modified Phong with `k_s = 1`, times the specular RGB).
//!   Lafortune lobes are not carried by this method (their diffuse part is).
//! - Visibility at a point is the coverage map of the caps of every other sphere, and of
//!   every plane the point is not on (a plane seen from a point off it is exactly the
//!   hemisphere of directions toward it: a cap of half-angle π/2), on an
//!   [`Options::vis_side`]² grid of the hemisphere map, turned into moment tables.
//! - Spherical lights are not lit by this method (the `lobes` method lights with them);
//!   they are seen by the camera and occlude.

use std::collections::BTreeMap;
use std::f32::consts::FRAC_PI_2;

use indicatif::ProgressBar;
use steradian_core::frame::Frame;
use steradian_core::lobe::brdf::{Lambert, Phong};
use steradian_core::lobe::cap::SphericalCap;
use steradian_core::rsl::brdf_sat::BrdfSat;
use steradian_core::rsl::shade::{self, ShadeLight};
use steradian_core::rsl::vis_moments::VisMoments;
use steradian_core::rsl::visibility::{Outside, coverage_into_depth, local_cap};

use super::image::Image;
use super::material::Material;
use super::{Rgb, Scene, ShadingPoint, Shape, render_centres};
use crate::env::Equirect;
use crate::env::decompose::decompose;

/// Settings of the `rsl` method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Number of square lights.
    pub k: usize,
    /// Cube-map face side the environment is decomposed at.
    pub face: usize,
    /// Side of each point's visibility map.
    pub vis_side: usize,
    /// Target error of the BRDF SAT fits ([`BrdfSat::fit`]).
    pub sat_target: f32,
    /// Subdivision levels below a visibility texel
    /// ([`steradian_core::rsl::visibility::coverage_into_depth`]).
    pub vis_depth: u32,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            k: 30,
            face: 32,
            vis_side: 32,
            sat_target: 0.005,
            vis_depth: 2,
        }
    }
}

/// What the method built for a scene.
pub struct Built {
    /// The square lights.
    pub lights: Vec<ShadeLight>,
    /// The diffuse SAT.
    pub lambert: BrdfSat,
    /// The specular SATs by exponent (as bits).
    pub phong: BTreeMap<u64, BrdfSat>,
}

/// Decomposes the environment and fits the SATs the materials need.
pub fn build(scene: &Scene, o: &Options) -> Result<Built, String> {
    let env = scene
        .environment
        .as_ref()
        .ok_or("method rsl lights with an environment; this scene has none")?;
    let scaled: Vec<[f32; 3]> = env
        .image
        .data()
        .iter()
        .map(|p| p.map(|v| (v as f64 * env.scale) as f32))
        .collect();
    let eq =
        Equirect::new(env.image.width(), env.image.height(), scaled).map_err(|e| e.to_string())?;
    let cube = eq.to_cubemap(o.face).map_err(|e| e.to_string())?;
    let decs = decompose(&cube, &crate::env::decompose::Options::quiet(&[o.k]))
        .map_err(|e| e.to_string())?;
    let lights: Vec<ShadeLight> = decs[0]
        .rsls()
        .map_err(|e| e.to_string())?
        .iter()
        .map(ShadeLight::from)
        .collect();
    let refs: Vec<_> = decs.iter().collect();
    let lambert = crate::shade::fit_sat(
        &Lambert::new(1.0).map_err(|e| e.to_string())?,
        &refs,
        o.sat_target,
    );
    let mut phong = BTreeMap::new();
    for m in &scene.materials {
        if let Material::Phong { exponent, .. } = m {
            let key = exponent.to_bits();
            if let std::collections::btree_map::Entry::Vacant(e) = phong.entry(key) {
                let b = Phong::new(0.0, 1.0, *exponent as f32).map_err(|e| e.to_string())?;
                e.insert(crate::shade::fit_sat(&b, &refs, o.sat_target));
            }
        }
    }
    Ok(Built {
        lights,
        lambert,
        phong,
    })
}

/// The reflected radiance at a surface point.
pub fn shade_point(
    scene: &Scene,
    b: &Built,
    o: &Options,
    p: &ShadingPoint,
    cov: &mut [f32],
) -> Rgb {
    let ShadingPoint {
        object,
        material: mi,
        x,
        n,
        wo,
    } = *p;
    let Ok(frame) = Frame::from_normal(n.as_vec3()) else {
        return [0.0; 3];
    };
    let mut caps = Vec::new();
    for (id, obj) in scene.objects.iter().enumerate() {
        if id == object {
            continue;
        }
        match obj.shape {
            Shape::Sphere { center, radius } => {
                if let Ok(c) = local_cap(x.as_vec3(), &frame, center.as_vec3(), radius as f32) {
                    caps.push(c);
                }
            }
            Shape::Plane { point, normal } => {
                let s = normal.dot(x - point);
                if s.abs() <= 1e-6 * (1.0 + x.abs().max_element()) {
                    continue;
                }
                let toward = -normal * s.signum();
                if let Ok(c) = SphericalCap::new(frame.to_local(toward.as_vec3()), FRAC_PI_2) {
                    caps.push(c);
                }
            }
        }
    }
    if coverage_into_depth(&caps, o.vis_side, Outside::Visible, o.vis_depth, cov).is_err() {
        return [0.0; 3];
    }
    let Ok(moments) = VisMoments::build_coverage(o.vis_side, cov) else {
        return [0.0; 3];
    };
    let wo = wo.as_vec3();
    let mat = &scene.materials[mi];
    let d = shade::shade_moments(&frame, wo, &b.lambert, &moments, &b.lights);
    let mut out = [0.0; 3];
    let diffuse = mat.diffuse();
    for c in 0..3 {
        out[c] = diffuse[c] * d[c] as f64;
    }
    if let Material::Phong {
        specular, exponent, ..
    } = mat
        && let Some(sat) = b.phong.get(&exponent.to_bits())
    {
        let s = shade::shade_moments(&frame, wo, sat, &moments, &b.lights);
        for c in 0..3 {
            out[c] += specular[c] * s[c] as f64;
        }
    }
    out
}

/// One pixel-centre sample per pixel ([`super::render_centres`]), building first.
pub fn render(scene: &Scene, o: &Options, bar: &ProgressBar) -> Result<Image, String> {
    let built = build(scene, o)?;
    Ok(render_built(scene, &built, o, bar))
}

/// [`render`] with what [`build`] made: the per-frame work once the environment is
/// decomposed and the BRDF tables fitted (the paper's precomputation).
pub fn render_built(scene: &Scene, built: &Built, o: &Options, bar: &ProgressBar) -> Image {
    let new_cov = || vec![0.0f32; o.vis_side * o.vis_side];
    let (img, _) = render_centres(scene, bar, new_cov, |cov, p| {
        shade_point(scene, built, o, p, cov)
    });
    img
}
