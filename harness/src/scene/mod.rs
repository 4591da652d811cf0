//! Scenes: spheres and planes with materials, spherical lights and an environment, a pinhole
//! camera; read from JSON ([`mod@file`]), rendered by the methods of [`render`] and compared
//! with the path-traced reference of [`path`].
//!
//! Conventions (the scene-file contract, README "Scene files"):
//! - Camera: forward `f = normalize(target − eye)`, right `r = normalize(f × up)`,
//!   up `u = r × f`; pixel `(i, j)` (column from the left, row from the top) at offset
//!   `(x, y)` in `[0, 1)²` inside the pixel looks along
//!   `normalize(f + X·r + Y·u)` with `X = (2(i + x)/W − 1)·tan(fov_y/2)·W/H` and
//!   `Y = (1 − 2(j + y)/H)·tan(fov_y/2)`; the pixel centre is `x = y = ½`.
//! - A spherical light emits its radiance uniformly from its surface, is seen by the camera
//!   at that radiance, reflects nothing and occludes everything behind it.
//! - An environment is seen by rays that escape; its image is sampled bilinearly
//!   ([`crate::env::Equirect::sample_bilinear`]: column ↔ `φ = 2πu` from `+x` toward `+y`,
//!   row ↔ `θ = πv` from `+z`), times `scale`.
//! - Planes are two-sided (the normal is flipped toward the viewer); spheres are seen from
//!   outside.

pub mod builtin;
pub mod file;
pub mod footprint;
pub mod geom;
pub mod hvl;
pub mod image;
pub mod lattice;
pub mod light;
pub mod lobes;
pub mod material;
pub mod metrics;
pub mod path;
pub mod render;
pub mod rsl;
pub mod unshadowed;

use std::path::Path;

use glam::DVec3;
use indicatif::ProgressBar;
use rayon::prelude::*;

/// The default `--target-error` of every approximating method: half the cosine-lobe
/// paper's mean |difference| over the maximum radiance (0.0039 / 0.70 = 0.56 %, its
/// Figure 15), as the scenes issue asks.
pub const DEFAULT_TARGET_ERROR: f64 = 0.0028;

pub use geom::{Camera, Hit, Ray, Shape};
pub use image::Image;
pub use light::{Environment, SphereLight};
pub use material::Material;

/// RGB radiance in f64.
pub type Rgb = [f64; 3];

/// What an object is: a surface with a material, or a light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A reflecting surface; index into [`Scene::materials`].
    Surface(usize),
    /// An emitter; index into [`Scene::lights`].
    Light(usize),
}

/// One intersectable object.
#[derive(Clone, Copy, Debug)]
pub struct Object {
    /// Its shape.
    pub shape: Shape,
    /// Surface or light.
    pub kind: Kind,
}

/// A validated scene, ready to render.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The camera.
    pub camera: Camera,
    /// Materials, indexed by [`Kind::Surface`].
    pub materials: Vec<Material>,
    /// Material names, parallel to `materials`.
    pub material_names: Vec<String>,
    /// All objects: surfaces first (spheres, then planes), then the light spheres.
    pub objects: Vec<Object>,
    /// The spherical lights, indexed by [`Kind::Light`].
    pub lights: Vec<SphereLight>,
    /// The environment, if any.
    pub environment: Option<Environment>,
}

/// A scene that could not be read: the message names the field.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneError(pub String);

impl std::fmt::Display for SceneError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SceneError {}

fn v3(a: [f64; 3]) -> DVec3 {
    DVec3::from_array(a)
}

impl Scene {
    /// Reads `builtin:NAME` or a scene file.
    pub fn load(spec: &str) -> Result<Scene, SceneError> {
        if let Some(name) = spec.strip_prefix("builtin:") {
            let text = builtin::text(name).ok_or_else(|| {
                SceneError(format!(
                    "unknown built-in scene {name:?} (known: {})",
                    builtin::NAMES.join(", ")
                ))
            })?;
            return Scene::from_json(text, &builtin::dir());
        }
        let path = Path::new(spec);
        let text = std::fs::read_to_string(path)
            .map_err(|e| SceneError(format!("reading {}: {e}", path.display())))?;
        let dir = path.parent().unwrap_or(Path::new("."));
        Scene::from_json(&text, dir)
    }

    /// Parses and validates JSON text; relative environment files are resolved from `dir`.
    pub fn from_json(text: &str, dir: &Path) -> Result<Scene, SceneError> {
        let f = file::parse(text).map_err(SceneError)?;
        Scene::from_file(&f, dir)
    }

    /// Validates the cross-field rules of a parsed file and builds the scene.
    pub fn from_file(f: &file::SceneFile, dir: &Path) -> Result<Scene, SceneError> {
        let err = |s: String| SceneError(s);
        let c = &f.camera;
        let camera = Camera::new(
            v3(c.eye.0),
            v3(c.target.0),
            v3(c.up.0),
            c.fov_y.0,
            c.width.0,
            c.height.0,
        )
        .map_err(|m| err(format!("camera.{m}")))?;
        let mut materials = Vec::new();
        let mut material_names = Vec::new();
        for (name, m) in &f.materials {
            materials
                .push(Material::from_file(m).map_err(|e| err(format!("materials.{name}.{e}")))?);
            material_names.push(name.clone());
        }
        let find = |name: &str, at: String| -> Result<usize, SceneError> {
            material_names
                .iter()
                .position(|n| n == name)
                .ok_or_else(|| {
                    err(format!(
                        "{at}.material: unknown material {name:?} (defined: {})",
                        material_names.join(", ")
                    ))
                })
        };
        let mut objects = Vec::new();
        for (i, s) in f.spheres.iter().enumerate() {
            let m = find(&s.material, format!("spheres[{i}]"))?;
            objects.push(Object {
                shape: Shape::Sphere {
                    center: v3(s.center.0),
                    radius: s.radius.0,
                },
                kind: Kind::Surface(m),
            });
        }
        for (i, p) in f.planes.iter().enumerate() {
            let m = find(&p.material, format!("planes[{i}]"))?;
            objects.push(Object {
                shape: Shape::Plane {
                    point: v3(p.point.0),
                    normal: v3(p.normal.0).normalize(),
                },
                kind: Kind::Surface(m),
            });
        }
        let mut lights = Vec::new();
        let mut environment = None;
        for (i, l) in f.lights.iter().enumerate() {
            match l {
                file::LightFile::Sphere {
                    center,
                    radius,
                    radiance,
                } => {
                    let light = SphereLight {
                        center: v3(center.0),
                        radius: radius.0,
                        radiance: radiance.0,
                    };
                    objects.push(Object {
                        shape: Shape::Sphere {
                            center: light.center,
                            radius: light.radius,
                        },
                        kind: Kind::Light(lights.len()),
                    });
                    lights.push(light);
                }
                file::LightFile::Environment { file, scale } => {
                    if environment.is_some() {
                        return Err(err(format!(
                            "lights[{i}].environment: only one environment is allowed"
                        )));
                    }
                    environment = Some(
                        Environment::load(file, dir, scale.0)
                            .map_err(|e| err(format!("lights[{i}].environment.file: {e}")))?,
                    );
                }
            }
        }
        let scene = Scene {
            camera,
            materials,
            material_names,
            objects,
            lights,
            environment,
        };
        if scene.camera_inside_sphere() {
            return Err(err("camera.eye: inside a sphere".into()));
        }
        Ok(scene)
    }

    fn camera_inside_sphere(&self) -> bool {
        self.objects.iter().any(|o| match o.shape {
            Shape::Sphere { center, radius } => (self.camera.eye - center).length() <= radius,
            Shape::Plane { .. } => false,
        })
    }

    /// The closest hit along `ray` with `t` in `(t_min, t_max)`.
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut t_far = t_max;
        for (id, o) in self.objects.iter().enumerate() {
            if let Some(t) = o.shape.intersect(ray, t_min, t_far) {
                t_far = t;
                best = Some(Hit { t, object: id });
            }
        }
        best
    }

    /// Whether anything blocks `ray` within `(t_min, t_max)`.
    pub fn occluded(&self, ray: &Ray, t_min: f64, t_max: f64) -> bool {
        self.objects
            .iter()
            .any(|o| o.shape.intersect(ray, t_min, t_max).is_some())
    }

    /// Environment radiance toward `d` (black without an environment).
    pub fn environment_radiance(&self, d: DVec3) -> Rgb {
        self.environment
            .as_ref()
            .map_or([0.0; 3], |e| e.radiance(d))
    }

    /// What `ray` meets first: the environment (black without one) when it escapes, a
    /// light's radiance, or a surface point with its normal turned toward the viewer
    /// (planes are two-sided).
    pub fn see(&self, ray: &Ray) -> Seen {
        let Some(hit) = self.intersect(ray, 0.0, f64::INFINITY) else {
            return Seen::Radiance(self.environment_radiance(ray.d));
        };
        let obj = self.objects[hit.object];
        match obj.kind {
            Kind::Light(li) => Seen::Radiance(self.lights[li].radiance),
            Kind::Surface(material) => {
                let x = ray.o + hit.t * ray.d;
                let wo = -ray.d;
                let mut n = obj.shape.normal(x);
                if n.dot(wo) < 0.0 {
                    n = -n;
                }
                Seen::Surface(ShadingPoint {
                    object: hit.object,
                    material,
                    x,
                    n,
                    wo,
                })
            }
        }
    }
}

/// A shading point: where, on what, seen from where.
#[derive(Clone, Copy, Debug)]
pub struct ShadingPoint {
    /// Index of the object shaded (it does not occlude itself).
    pub object: usize,
    /// Its material.
    pub material: usize,
    /// The point.
    pub x: DVec3,
    /// Unit normal, on the viewer's side.
    pub n: DVec3,
    /// Unit direction toward the viewer.
    pub wo: DVec3,
}

/// What a ray sees first ([`Scene::see`]).
#[derive(Clone, Copy, Debug)]
pub enum Seen {
    /// A light or the environment, at this radiance.
    Radiance(Rgb),
    /// A surface point to shade.
    Surface(ShadingPoint),
}

/// The object each pixel's centre ray meets first (row-major), `None` where it sees a light
/// or the environment: kept from the centre pass for the footprint refinement, which
/// compares neighbours by it ([`footprint::refine`]), rather than cast again.
pub type Objects = Vec<Option<usize>>;

/// [`Objects`] of the pixels of a [`centre_queue`]: `pixels` of them in all, those in
/// `queue` on their surface's object (a queued index past `pixels` is left out).
pub fn queue_objects(pixels: usize, queue: &[(usize, ShadingPoint)]) -> Objects {
    let mut objects = vec![None; pixels];
    for (k, p) in queue {
        if let Some(o) = objects.get_mut(*k) {
            *o = Some(p.object);
        }
    }
    objects
}

/// The image of the pixel-centre rays, rows in parallel: a light or the environment as
/// seen, a surface by `shade(state, point)`. Each row gets a fresh `new_state()` (scratch
/// buffers, counters), returned row by row with the image and its [`Objects`].
pub fn render_centres<S: Send>(
    scene: &Scene,
    bar: &ProgressBar,
    new_state: impl Fn() -> S + Sync,
    shade: impl Fn(&mut S, &ShadingPoint) -> Rgb + Sync,
) -> (Image, Vec<S>, Objects) {
    // The same walk as the batched one, each point alone (in the same order per row).
    render_centres_x8(scene, bar, new_state, |state, points, out| {
        for (p, o) in points.iter().zip(out.iter_mut()) {
            *o = shade(state, p);
        }
    })
}

/// Every pixel's centre ray, for the paths that shade in batches of their own (the wgpu
/// paths): the image with what the camera sees where it is not a surface (lights, the
/// environment), and the surface points queued with their pixel index (row-major).
pub fn centre_queue(scene: &Scene) -> (Image, Vec<(usize, ShadingPoint)>) {
    let cam = scene.camera;
    let (w, h) = (cam.width as usize, cam.height as usize);
    let mut img = Image::new(w, h);
    let mut queue = Vec::new();
    for j in 0..h {
        for i in 0..w {
            match scene.see(&cam.centre_ray(i as u32, j as u32)) {
                Seen::Radiance(l) => img.data[j * w + i] = l,
                Seen::Surface(p) => queue.push((j * w + i, p)),
            }
        }
    }
    (img, queue)
}

/// [`render_centres`] with the surface points of a row shaded eight at a time by
/// `shade(state, points, out)` (`out[k]` for `points[k]`; the last batch of a row may be
/// shorter).
pub fn render_centres_x8<S: Send>(
    scene: &Scene,
    bar: &ProgressBar,
    new_state: impl Fn() -> S + Sync,
    shade: impl Fn(&mut S, &[ShadingPoint], &mut [Rgb]) + Sync,
) -> (Image, Vec<S>, Objects) {
    render_centres_x8_at(scene, bar, new_state, |state, _, ps, out| {
        shade(state, ps, out)
    })
}

/// [`render_centres_x8`] that also tells `shade` where its points are:
/// `shade(state, pixels, points, out)` with `pixels[k] = (i, j)`, the column and row of
/// `points[k]`.
pub fn render_centres_x8_at<S: Send>(
    scene: &Scene,
    bar: &ProgressBar,
    new_state: impl Fn() -> S + Sync,
    shade: impl Fn(&mut S, &[(usize, usize)], &[ShadingPoint], &mut [Rgb]) + Sync,
) -> (Image, Vec<S>, Objects) {
    let cam = scene.camera;
    let (w, h) = (cam.width as usize, cam.height as usize);
    let rows: Vec<(Vec<Rgb>, S, Objects)> = (0..h)
        .into_par_iter()
        .map(|j| {
            let mut state = new_state();
            let mut row = vec![[0.0; 3]; w];
            let mut objects = vec![None; w];
            let mut pixels = Vec::with_capacity(w);
            let mut points = Vec::with_capacity(w);
            for (i, (px, object)) in row.iter_mut().zip(&mut objects).enumerate() {
                match scene.see(&cam.centre_ray(i as u32, j as u32)) {
                    Seen::Radiance(l) => *px = l,
                    Seen::Surface(p) => {
                        *object = Some(p.object);
                        pixels.push((i, j));
                        points.push(p);
                    }
                }
            }
            let mut out = [[0.0; 3]; 8];
            for (is, ps) in pixels.chunks(8).zip(points.chunks(8)) {
                let out = &mut out[..ps.len()];
                shade(&mut state, is, ps, out);
                for (&(i, _), v) in is.iter().zip(out.iter()) {
                    row[i] = *v;
                }
            }
            bar.inc(1);
            (row, state, objects)
        })
        .collect();
    let mut img = Image::new(w, h);
    let mut states = Vec::with_capacity(h);
    let mut objects = Vec::with_capacity(w * h);
    for (j, (row, state, row_objects)) in rows.into_iter().enumerate() {
        img.data[j * w..(j + 1) * w].copy_from_slice(&row);
        states.push(state);
        objects.extend(row_objects);
    }
    (img, states, objects)
}

/// The share of `--target-error` each planned setting may add to a render ([`rsl::choose_k`],
/// [`hvl::choose_side`], [`lobes::choose_depth`]; the pruning threshold takes a tenth). The
/// methods' own models and pixel footprints take the rest, so a setting gets a quarter, not
/// a half (the report's `scenes` rows give each method's error at its default point beside
/// the target); the plan tests assert what each share buys.
pub const PLAN_SHARE: f64 = 0.25;

/// Probe pixels per image side of the plans' choices ([`rsl::choose_k`],
/// [`hvl::choose_side`], [`lobes::choose_depth`]): a grid of pixel centres.
pub const PROBES: (u32, u32) = (32, 24);

/// The surface points seen through a [`PROBES`] grid of pixel centres (pixels that see a
/// light or the environment are left out).
pub fn probe_points(scene: &Scene) -> Vec<ShadingPoint> {
    probe_pixels(scene).into_iter().map(|(_, _, p)| p).collect()
}

/// [`probe_points`] with their pixels: `(column, row, point)`.
pub fn probe_pixels(scene: &Scene) -> Vec<(usize, usize, ShadingPoint)> {
    let cam = scene.camera;
    let mut out = Vec::new();
    for b in 0..PROBES.1 {
        for a in 0..PROBES.0 {
            let i = ((2 * a + 1) * cam.width / (2 * PROBES.0)).min(cam.width - 1);
            let j = ((2 * b + 1) * cam.height / (2 * PROBES.1)).min(cam.height - 1);
            if let Seen::Surface(p) = scene.see(&cam.centre_ray(i, j)) {
                out.push((i as usize, j as usize, p));
            }
        }
    }
    out
}

/// A plan's choice among `candidates` (cheapest first), each with its shaded probes in
/// `shaded` (the same order): the estimates of [`probe_estimates`] beside their candidates,
/// and the first candidate within [`PLAN_SHARE`] of `target`, or the last (the finest) when
/// none is. `None` without candidates.
pub fn plan_choice<T: Copy>(
    candidates: &[T],
    shaded: &[Vec<Rgb>],
    target: f64,
) -> Option<(T, Vec<(T, f64)>)> {
    let last = *candidates.last()?;
    let estimates: Vec<(T, f64)> = candidates
        .iter()
        .copied()
        .zip(probe_estimates(shaded))
        .collect();
    let chosen = estimates
        .iter()
        .find(|&&(_, e)| e <= PLAN_SHARE * target)
        .map_or(last, |&(c, _)| c);
    Some((chosen, estimates))
}

/// The plans' error estimate: for each candidate's shaded probes (the last candidate the
/// finest), the mean |difference| from the last over the last's largest value — the
/// render's measure (mean |difference| over the maximum radiance) with the finest
/// candidate standing in for the reference (every candidate shaded at the same probes).
pub fn probe_estimates(shaded: &[Vec<Rgb>]) -> Vec<f64> {
    let Some(reference) = shaded.last() else {
        return Vec::new();
    };
    let max = reference
        .iter()
        .flat_map(|c| c.iter().copied())
        .fold(0.0, f64::max);
    shaded
        .iter()
        .map(|img| {
            let n = (3 * img.len()).max(1) as f64;
            let sum: f64 = img
                .iter()
                .zip(reference)
                .map(|(a, r)| (0..3).map(|c| (a[c] - r[c]).abs()).sum::<f64>())
                .sum();
            if max > 0.0 { sum / n / max } else { 0.0 }
        })
        .collect()
}
