//! The `rsl` method (rotatable-square-lights paper): environment lighting through `K`
//! rotatable square lights, BRDF summed-area tables and per-point visibility moment tables
//! ([`steradian_core::rsl::shade::shade_moments`], eq. 5 with first-order visibility).
//!
//! - The environment (times its scale) is resampled to a cube map of [`Options::face`]²
//!   texels per face and decomposed into `K` RSLs by bottom-up merging
//!   ([`crate::env::decompose`]).
//! - BRDF SATs are fitted for what the scene's materials need: one for the diffuse part
//!   (Lambert, albedo 1, times each material's diffuse RGB) and one per distinct Phong
//!   exponent or GGX `(f0, α)` for the specular part (modified Phong with `k_s = 1`, or
//!   core's `Ggx` with `k_d = 0`, times the specular RGB).
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
use steradian_core::lobe::brdf::{Ggx, Lambert, Phong};
use steradian_core::lobe::cap::SphericalCap;
use steradian_core::rsl::brdf_sat::BrdfSat;
use steradian_core::rsl::shade::{self, ShadeLight};
use steradian_core::rsl::vis_moments::VisMoments;
use steradian_core::rsl::visibility::{Outside, coverage_into_depth, local_cap};

use super::image::Image;
use super::material::Material;
use super::{Rgb, Scene, Seen, ShadingPoint, Shape, render_centres};
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
    /// The specular SATs by [`SpecKey`].
    pub specular: BTreeMap<SpecKey, BrdfSat>,
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
    let mut specular = BTreeMap::new();
    for m in &scene.materials {
        let Some(key) = spec_key(m) else { continue };
        if let std::collections::btree_map::Entry::Vacant(e) = specular.entry(key) {
            let sat = match *m {
                Material::Phong { exponent, .. } => {
                    let b = Phong::new(0.0, 1.0, exponent as f32).map_err(|e| e.to_string())?;
                    crate::shade::fit_sat(&b, &refs, o.sat_target)
                }
                Material::Ggx { f0, alpha, .. } => {
                    let b = Ggx::new(0.0, f0 as f32, alpha as f32).map_err(|e| e.to_string())?;
                    crate::shade::fit_sat(&b, &refs, o.sat_target)
                }
                _ => continue,
            };
            e.insert(sat);
        }
    }
    Ok(Built {
        lights,
        lambert,
        specular,
    })
}

/// The visibility moment tables of a surface point (module docs), `None` where the point
/// has no frame or its map cannot be built (it is then shaded black).
pub fn point_moments(
    scene: &Scene,
    o: &Options,
    p: &ShadingPoint,
    cov: &mut [f32],
) -> Option<(Frame, VisMoments)> {
    let frame = Frame::from_normal(p.n.as_vec3()).ok()?;
    let x = p.x;
    let mut caps = Vec::new();
    for (id, obj) in scene.objects.iter().enumerate() {
        if id == p.object {
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
    coverage_into_depth(&caps, o.vis_side, Outside::Visible, o.vis_depth, cov).ok()?;
    let moments = VisMoments::build_coverage(o.vis_side, cov).ok()?;
    Some((frame, moments))
}

/// The reflected radiance from the diffuse and specular integrals `d`, `s` (each
/// [`shade::shade_moments`] with the Lambert and the material's Phong SAT).
fn combine(mat: &Material, d: [f32; 3], s: Option<[f32; 3]>) -> Rgb {
    let diffuse = mat.diffuse();
    let mut out: Rgb = core::array::from_fn(|c| diffuse[c] * d[c] as f64);
    if let (Material::Phong { specular, .. } | Material::Ggx { specular, .. }, Some(s)) = (mat, s) {
        for c in 0..3 {
            out[c] += specular[c] * s[c] as f64;
        }
    }
    out
}

/// Which specular SAT a material needs: `(0, exponent bits, 0)` for modified Phong,
/// `(1, f0 bits, α bits)` for GGX, `None` for the others.
pub type SpecKey = (u8, u64, u64);

/// The [`SpecKey`] of a material.
pub fn spec_key(mat: &Material) -> Option<SpecKey> {
    match *mat {
        Material::Phong { exponent, .. } => Some((0, exponent.to_bits(), 0)),
        Material::Ggx { f0, alpha, .. } => Some((1, f0.to_bits(), alpha.to_bits())),
        _ => None,
    }
}

/// The specular SAT of a material, if it has one.
fn specular_sat<'a>(b: &'a Built, mat: &Material) -> Option<&'a BrdfSat> {
    b.specular.get(&spec_key(mat)?)
}

/// The reflected radiance at a surface point.
pub fn shade_point(
    scene: &Scene,
    b: &Built,
    o: &Options,
    p: &ShadingPoint,
    cov: &mut [f32],
) -> Rgb {
    let Some((frame, moments)) = point_moments(scene, o, p, cov) else {
        return [0.0; 3];
    };
    let wo = p.wo.as_vec3();
    let mat = &scene.materials[p.material];
    let d = shade::shade_moments(&frame, wo, &b.lambert, &moments, &b.lights);
    let s =
        specular_sat(b, mat).map(|sat| shade::shade_moments(&frame, wo, sat, &moments, &b.lights));
    combine(mat, d, s)
}

/// [`render_built`] through the SIMD moments kernel: per row, each surface point's moment
/// tables as in [`shade_point`], then eight points at a time through
/// [`steradian_simd::rsl::shade::shade_moments_batch`] with the Lambert SAT and with each
/// Phong SAT its points need. Each pixel is within the kernel's
/// [`steradian_simd::rsl::shade::MOMENTS_REL_TOL`] of [`render_built`] (relative to the
/// pixel's largest channel; the harness test asserts it). `Err` for a BRDF SAT the SIMD
/// kernel does not take (anisotropic).
pub fn render_built_simd(
    scene: &Scene,
    built: &Built,
    o: &Options,
    bar: &ProgressBar,
) -> Result<Image, String> {
    use rayon::prelude::*;
    use steradian_core::rsl::shade::gpu::iso_views;
    use steradian_simd::rsl::shade::{IsoBrdfTables, MomentsInput, shade_moments_batch};

    fn iso(sat: &BrdfSat) -> Result<Vec<steradian_core::rsl::sat::SatView<'_>>, String> {
        iso_views(sat).ok_or_else(|| "the SIMD kernel takes isotropic BRDF SATs".to_string())
    }
    let lambert_views = iso(&built.lambert)?;
    let specular_views = built
        .specular
        .iter()
        .map(|(k, sat)| Ok((*k, (iso(sat)?, sat.s_max()))))
        .collect::<Result<BTreeMap<_, _>, String>>()?;
    let lambert = IsoBrdfTables {
        tables: &lambert_views,
        s_max: built.lambert.s_max(),
    };
    let cam = scene.camera;
    let (w, h) = (cam.width as usize, cam.height as usize);
    let rows: Vec<Result<Vec<Rgb>, String>> = (0..h)
        .into_par_iter()
        .map(|j| {
            let mut cov = vec![0.0f32; o.vis_side * o.vis_side];
            let mut row = vec![[0.0; 3]; w];
            // (pixel, point, frame, tables) of the row's shaded points.
            let mut pts = Vec::with_capacity(w);
            for (i, px) in row.iter_mut().enumerate() {
                match scene.see(&cam.centre_ray(i as u32, j as u32)) {
                    Seen::Radiance(l) => *px = l,
                    Seen::Surface(p) => {
                        if let Some((frame, m)) = point_moments(scene, o, &p, &mut cov) {
                            pts.push((i, p, frame, m));
                        }
                    }
                }
            }
            let input = |sel: &[usize]| -> Vec<MomentsInput<'_>> {
                sel.iter()
                    .map(|&k| MomentsInput {
                        frame: pts[k].2,
                        wo: pts[k].1.wo.as_vec3(),
                        vis: pts[k].3.view(),
                    })
                    .collect()
            };
            let all: Vec<usize> = (0..pts.len()).collect();
            let mut d = vec![[0.0f32; 3]; pts.len()];
            if !shade_moments_batch(&input(&all), &lambert, &built.lights, &mut d) {
                return Err("visibility tables of different sizes".to_string());
            }
            let mut s: Vec<Option<[f32; 3]>> = vec![None; pts.len()];
            for (key, (views, s_max)) in &specular_views {
                let sel: Vec<usize> = all
                    .iter()
                    .copied()
                    .filter(|&k| spec_key(&scene.materials[pts[k].1.material]) == Some(*key))
                    .collect();
                if sel.is_empty() {
                    continue;
                }
                let tables = IsoBrdfTables {
                    tables: views,
                    s_max: *s_max,
                };
                let mut out = vec![[0.0f32; 3]; sel.len()];
                if !shade_moments_batch(&input(&sel), &tables, &built.lights, &mut out) {
                    return Err("visibility tables of different sizes".to_string());
                }
                for (k, v) in sel.into_iter().zip(out) {
                    s[k] = Some(v);
                }
            }
            for (k, (i, p, _, _)) in pts.iter().enumerate() {
                row[*i] = combine(&scene.materials[p.material], d[k], s[k]);
            }
            bar.inc(1);
            Ok(row)
        })
        .collect();
    let mut img = Image::new(w, h);
    for (j, row) in rows.into_iter().enumerate() {
        img.data[j * w..(j + 1) * w].copy_from_slice(&row?);
    }
    Ok(img)
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
