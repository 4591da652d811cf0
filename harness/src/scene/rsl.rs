//! The `rsl` method (rotatable-square-lights paper): environment lighting through `K`
//! rotatable square lights, BRDF summed-area tables and per-point visibility moment tables
//! ([`steradian_core::rsl::shade::shade_moments`], eq. 5 with first-order visibility).
//!
//! - The environment (times its scale) is resampled to a cube map of [`Options::face`]²
//!   texels per face and decomposed into `K` RSLs by bottom-up merging
//!   ([`mod@crate::env::decompose`]).
//! - BRDF SATs are fitted for what the scene's materials need: one for the diffuse part
//!   (Lambert, albedo 1, times each material's diffuse RGB) and one per distinct specular
//!   part ([`SpecKey`]): a Phong exponent, a GGX `(f0, α)` or a Lafortune lobe (modified
//!   Phong with `k_s = 1`, core's `Ggx` with `k_d = 0`, or the lobe with `ρ = 1`), times
//!   the specular RGB or the lobe's `ρ`.
//! - Visibility at a point is the coverage map of the caps of every other sphere, and of
//!   every plane the point is not on (a plane seen from a point off it is exactly the
//!   hemisphere of directions toward it: a cap of half-angle π/2), on an
//!   [`Options::vis_side`]² grid of the hemisphere map, turned into moment tables.
//! - By default ([`Options::exact_unshadowed`], an addition to the paper) each part's
//!   value is its exact integral under the point's planes ([`super::unshadowed`], per
//!   [`PlaneSides`]) times the kernel's ratio `S/U` of the point's value to the same under
//!   its planes alone ([`Base`]), where the part has such an integral (Lambert, Phong and
//!   Lafortune lobes up to exponent [`super::unshadowed::MAX_EXPONENT`]); GGX keeps `S`.
//! - Spherical lights are not lit by this method (the `lobes` method lights with them);
//!   they are seen by the camera and occlude.

use std::collections::BTreeMap;
use std::f32::consts::FRAC_PI_2;

use glam::DVec3;

use indicatif::ProgressBar;
use steradian_core::frame::Frame;
use steradian_core::lobe::brdf::{Ggx, Lambert, Phong};
use steradian_core::lobe::cap::SphericalCap;
use steradian_core::lobe::{Lafortune, LafortuneLobe};
use steradian_core::rsl::brdf_sat::BrdfSat;
use steradian_core::rsl::shade::{self, ShadeLight, Unoccluded};
use steradian_core::rsl::vis_moments::VisMoments;
use steradian_core::rsl::visibility::{Outside, coverage_into_depth, local_cap};

use super::image::Image;
use super::material::{Material, reflect};
use super::unshadowed::EnvTables;
use super::{Rgb, Scene, Seen, ShadingPoint, Shape, footprint, render_centres};
use crate::env::Equirect;
use crate::env::decompose::{Decomposition, decompose};

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
    /// The shadow ratio (an addition to the paper's pipeline, on by default): each BRDF
    /// part's exact integral under the point's planes from environment tables
    /// ([`super::unshadowed::EnvTables`]) times the kernel's ratio `S/U` of its value under
    /// every occluder to its value under the planes alone (both over the same squares),
    /// instead of `S` alone. Off, the method is the paper's pipeline.
    pub exact_unshadowed: bool,
    /// The footprint threshold of [`super::footprint::refine`], relative to the image's
    /// largest value: the pixels whose centre alone is estimated to miss the pixel's mean
    /// by that much are re-shaded at four points. 0 (the default, the paper): pixel
    /// centres only; `steradian render` plans its target error.
    pub footprint: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            k: 30,
            face: 32,
            vis_side: 32,
            sat_target: 0.005,
            vis_depth: coverage_depth_for(super::DEFAULT_TARGET_ERROR),
            exact_unshadowed: true,
            footprint: 0.0,
        }
    }
}

/// The coarsest coverage depth whose asserted visible-solid-angle bound
/// ([`steradian_core::rsl::visibility::DEPTH_BOUNDS`]) is within a tenth of `target`
/// (the render's mean |difference| over the maximum radiance); the full depth when none is.
pub fn coverage_depth_for(target: f64) -> u32 {
    use steradian_core::rsl::visibility::{DEPTH_BOUNDS, LEAF_DEPTH};
    (0..=LEAF_DEPTH)
        .find(|&d| f64::from(DEPTH_BOUNDS[d as usize].1) <= target / 10.0)
        .unwrap_or(LEAF_DEPTH)
}

/// What the method built for a scene.
pub struct Built {
    /// The square lights.
    pub lights: Vec<ShadeLight>,
    /// The diffuse SAT.
    pub lambert: BrdfSat,
    /// The specular SATs by [`SpecKey`].
    pub specular: BTreeMap<SpecKey, BrdfSat>,
    /// The exact unshadowed integrals per [`PlaneSides`] ([`Options::exact_unshadowed`]).
    pub unshadowed: Option<BTreeMap<PlaneSides, EnvTables>>,
}

/// Decomposes the environment and fits the SATs the materials need.
pub fn build(scene: &Scene, o: &Options) -> Result<Built, String> {
    let mut many = build_many(scene, o, &[o.k])?;
    Ok(Built {
        lights: many.lights.remove(0).1,
        lambert: many.lambert,
        specular: many.specular,
        unshadowed: many.unshadowed,
    })
}

/// The environment tables of [`Options::exact_unshadowed`], per [`PlaneSides`] a shaded
/// point can have ([`plane_signatures`]; the environment seen through the half-spaces its
/// planes leave open): the diffuse one and one per glossy lobe exponent of the specular
/// parts (Phong, Lafortune; GGX keeps the squares' estimate).
fn env_tables(
    scene: &Scene,
    specular: &BTreeMap<SpecKey, BrdfSat>,
) -> Option<BTreeMap<PlaneSides, EnvTables>> {
    let env = scene.environment.as_ref()?;
    let exponents: Vec<f64> = specular
        .keys()
        .filter_map(|k| match *k {
            SpecKey::Phong(e) | SpecKey::Lafortune(_, _, e) => Some(f64::from_bits(e)),
            SpecKey::Ggx(..) => None,
        })
        .collect();
    Some(
        plane_signatures(scene)
            .into_iter()
            .map(|sides| {
                let open = open_half_spaces(scene, &sides);
                let t = EnvTables::build(env, &open, &exponents);
                (sides, t)
            })
            .collect(),
    )
}

/// The visibility moment tables of a point that sees everything, at `o.vis_side`²: the
/// wgpu path's `U` of the shadow ratio (the CPU paths take `(f, m) = (1, 0)` exactly, in
/// the pair kernels).
pub fn free_moments(o: &Options) -> Result<VisMoments, String> {
    let mut cov = vec![0.0f32; o.vis_side * o.vis_side];
    coverage_into_depth(&[], o.vis_side, Outside::Visible, o.vis_depth, &mut cov)
        .map_err(|e| e.to_string())?;
    VisMoments::build_coverage(o.vis_side, &cov).map_err(|e| e.to_string())
}

/// The environment (times its scale) resampled to a cube map of `face`² texels per face and
/// decomposed into each of `ks` square lights: `(K, lights)` in the order asked, and the
/// partitions themselves (one per distinct `K`, largest first).
#[allow(clippy::type_complexity)]
fn decompose_env(
    scene: &Scene,
    face: usize,
    ks: &[usize],
) -> Result<(Vec<(usize, Vec<ShadeLight>)>, Vec<Decomposition>), String> {
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
    let cube = eq.to_cubemap(face).map_err(|e| e.to_string())?;
    let decs =
        decompose(&cube, &crate::env::decompose::Options::quiet(ks)).map_err(|e| e.to_string())?;
    let lights = ks
        .iter()
        .map(|&k| {
            let d = decs
                .iter()
                .find(|d| d.k == k)
                .ok_or_else(|| format!("no partition into {k} lights"))?;
            let l = d.rsls().map_err(|e| e.to_string())?;
            Ok((k, l.iter().map(ShadeLight::from).collect()))
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok((lights, decs))
}

/// [`build`] for several `K` at once: one decomposition run (the partitions are nested)
/// and one set of BRDF SATs fitted over all of them.
pub struct BuiltMany {
    /// `(K, lights)` per requested `K` (in the order asked).
    pub lights: Vec<(usize, Vec<ShadeLight>)>,
    /// The diffuse SAT.
    pub lambert: BrdfSat,
    /// The specular SATs by [`SpecKey`].
    pub specular: BTreeMap<SpecKey, BrdfSat>,
    /// The exact unshadowed integrals per [`PlaneSides`] ([`Options::exact_unshadowed`]).
    pub unshadowed: Option<BTreeMap<PlaneSides, EnvTables>>,
}

/// The environment (times its scale) decomposed into each of `ks` square lights, and the
/// SATs the materials need, fitted over every decomposition.
pub fn build_many(scene: &Scene, o: &Options, ks: &[usize]) -> Result<BuiltMany, String> {
    let (lights, decs) = decompose_env(scene, o.face, ks)?;
    let refs: Vec<_> = decs.iter().collect();
    let lambert = crate::shade::fit_sat(
        &Lambert::new(1.0).map_err(|e| e.to_string())?,
        &refs,
        o.sat_target,
    );
    let mut specular = BTreeMap::new();
    for m in &scene.materials {
        for (key, _) in specular_parts(m) {
            if let std::collections::btree_map::Entry::Vacant(e) = specular.entry(key) {
                e.insert(fit_part(key, &refs, o.sat_target)?);
            }
        }
    }
    let unshadowed = if o.exact_unshadowed {
        env_tables(scene, &specular)
    } else {
        None
    };
    Ok(BuiltMany {
        lights,
        lambert,
        specular,
        unshadowed,
    })
}

/// The `K` a plan tries, smallest first ([`choose_k`]).
pub const K_CANDIDATES: [usize; 5] = [10, 30, 100, 300, 1000];

/// The visibility-map sides a plan tries, smallest first ([`choose_k`]).
pub const VIS_SIDE_CANDIDATES: [usize; 4] = [8, 16, 32, 64];

/// The cube-map face sides a plan tries, smallest first ([`choose_k`]).
pub const FACE_CANDIDATES: [usize; 3] = [16, 32, 64];

/// What [`choose_k`] chose and what it measured.
#[derive(Clone, Debug)]
pub struct KChoice {
    /// The chosen `K`.
    pub k: usize,
    /// `(K, estimate)`: the probes' mean |difference| from the largest candidate over its
    /// largest value.
    pub estimates: Vec<(usize, f64)>,
    /// The chosen side of each point's visibility map.
    pub vis_side: usize,
    /// `(side, estimate)` with the chosen `K`, as for `estimates`.
    pub side_estimates: Vec<(usize, f64)>,
    /// The chosen coverage depth.
    pub vis_depth: u32,
    /// `(depth, estimate)` with the chosen `K` and side, as for `estimates`.
    pub depth_estimates: Vec<(u32, f64)>,
    /// The chosen cube-map face side.
    pub face: usize,
    /// `(face, estimate)` with the chosen `K`, as for `estimates`.
    pub face_estimates: Vec<(usize, f64)>,
}

/// The smallest `K` of [`K_CANDIDATES`] whose light decomposition alone keeps the shaded
/// probes within [`super::PLAN_SHARE`] of `target` (mean |difference| over the maximum
/// radiance, the render's measure) of the largest candidate's
/// ([`super::probe_estimates`]): the probes are the [`super::probe_points`] grid, shaded
/// with the same visibility and BRDF SATs for every `K`, so the difference is the
/// decomposition's alone (the error that dominates `rsl` on the built-in scenes; the rest
/// of the target is left to visibility and the SATs). The largest candidate if none is
/// within.
///
/// Then, with the chosen `K`'s lights, the smallest visibility-map side of
/// [`VIS_SIDE_CANDIDATES`] by the same rule against the largest side (the probes' maps
/// built at each side, at `o.vis_depth`): the cost of a point's map grows with its area
/// while its error stops falling once the texels resolve the occluders' caps.
///
/// Then, with the chosen `K` and side, the coarsest coverage depth from 0 to `o.vis_depth`
/// (the deepest the asserted bounds ask for, [`coverage_depth_for`]) by the same rule
/// against `o.vis_depth`: each level below a texel costs about as much again, while the
/// texels' coverage error is already small against the decomposition's.
///
/// Last, with the chosen `K`, side and depth, the smallest cube-map face of [`FACE_CANDIDATES`]
/// (holding at least `K` texels) by the same rule against the largest face: the
/// decomposition's cost grows with the face's area, while `K` squares cannot show detail
/// finer than they are.
pub fn choose_k(scene: &Scene, o: &Options, target: f64) -> Result<KChoice, String> {
    let texels = 6 * o.face * o.face;
    let ks: Vec<usize> = K_CANDIDATES
        .iter()
        .copied()
        .filter(|&k| k <= texels)
        .collect();
    let BuiltMany {
        lights: by_k,
        lambert,
        specular,
        unshadowed,
    } = build_many(scene, o, &ks)?;
    let mut cov = vec![0.0f32; o.vis_side * o.vis_side];
    let points = super::probe_points(scene);
    let probes: Vec<_> = points
        .iter()
        .filter_map(|p| point_vis(scene, o, p, &mut cov).map(|t| (p, t)))
        .collect();
    // The probes shaded with each K's lights (the SATs shared).
    let mut b = Built {
        lights: Vec::new(),
        lambert,
        specular,
        unshadowed,
    };
    let (mut order, mut images, mut lights_of) = (Vec::new(), Vec::new(), Vec::new());
    for (k, lights) in by_k {
        b.lights = lights;
        images.push(
            probes
                .iter()
                .map(|(p, (frame, m, base))| shade_with(scene, &b, p, frame, m, base))
                .collect::<Vec<Rgb>>(),
        );
        order.push(k);
        lights_of.push(std::mem::take(&mut b.lights));
    }
    let (k, estimates) =
        super::plan_choice(&order, &images, target).ok_or("no candidate K fits the cube map")?;
    // The visibility-map side with the chosen K's lights.
    let pos = order.iter().position(|&c| c == k).unwrap_or(0);
    b.lights = lights_of.swap_remove(pos);
    // The probes shaded with the chosen K's lights and the maps of `os`.
    let shaded = |os: &Options| -> Vec<Rgb> {
        let mut cov = vec![0.0f32; os.vis_side * os.vis_side];
        points
            .iter()
            .map(|p| match point_vis(scene, os, p, &mut cov) {
                Some((frame, m, base)) => shade_with(scene, &b, p, &frame, &m, &base),
                None => [0.0; 3],
            })
            .collect()
    };
    let mut side_images: Vec<Vec<Rgb>> = VIS_SIDE_CANDIDATES
        .iter()
        .map(|&vis_side| shaded(&Options { vis_side, ..*o }))
        .collect();
    let (vis_side, side_estimates) = super::plan_choice(&VIS_SIDE_CANDIDATES, &side_images, target)
        .ok_or("no visibility-map side")?;
    // The coverage depth with the chosen K and side; the deepest (`o.vis_depth`) is the
    // chosen side's image above.
    let depths: Vec<u32> = (0..=o.vis_depth).collect();
    let mut depth_images: Vec<Vec<Rgb>> = depths[..depths.len() - 1]
        .iter()
        .map(|&vis_depth| {
            shaded(&Options {
                vis_side,
                vis_depth,
                ..*o
            })
        })
        .collect();
    let side_pos = VIS_SIDE_CANDIDATES
        .iter()
        .position(|&c| c == vis_side)
        .unwrap_or(0);
    depth_images.push(side_images.swap_remove(side_pos));
    let (vis_depth, depth_estimates) =
        super::plan_choice(&depths, &depth_images, target).ok_or("no coverage depth")?;
    // The cube-map face with the chosen K, side and depth (the SATs shared, fitted above).
    let os = Options {
        vis_side,
        vis_depth,
        ..*o
    };
    let mut cov = vec![0.0f32; vis_side * vis_side];
    let probes: Vec<_> = points
        .iter()
        .filter_map(|p| point_vis(scene, &os, p, &mut cov).map(|t| (p, t)))
        .collect();
    let faces: Vec<usize> = FACE_CANDIDATES
        .iter()
        .copied()
        .filter(|&f| 6 * f * f >= k)
        .collect();
    // At `o.face` the chosen K's lights are those above.
    let at_face = std::mem::take(&mut b.lights);
    let mut face_images = Vec::new();
    for &f in &faces {
        b.lights = if f == o.face {
            at_face.clone()
        } else {
            decompose_env(scene, f, &[k])?.0.remove(0).1
        };
        face_images.push(
            probes
                .iter()
                .map(|(p, (frame, m, base))| shade_with(scene, &b, p, frame, m, base))
                .collect::<Vec<Rgb>>(),
        );
    }
    let (face, face_estimates) =
        super::plan_choice(&faces, &face_images, target).ok_or("no cube-map face holds K")?;
    Ok(KChoice {
        k,
        estimates,
        vis_side,
        side_estimates,
        vis_depth,
        depth_estimates,
        face,
        face_estimates,
    })
}

/// The planes a point is not on, each with the side it is on (`true`: the side its normal
/// points to). A plane hides exactly the half of the directions that head toward it, so
/// these sides alone say what the planes leave open: `v·ω > 0` with `v` the normal, or its
/// opposite, per plane ([`open_half_spaces`]).
pub type PlaneSides = Vec<(usize, bool)>;

/// The side of the plane through `point` with unit `normal` that `x` is on (`true`: the
/// side the normal points to), `None` when `x` is on the plane (within `1e-6` of its
/// scale).
fn side_of(point: DVec3, normal: DVec3, x: DVec3) -> Option<bool> {
    let s = normal.dot(x - point);
    (s.abs() > 1e-6 * (1.0 + x.abs().max_element())).then_some(s > 0.0)
}

/// The planes `x` (on object `own`) is not on, with its side of each ([`PlaneSides`]).
pub fn plane_sides(scene: &Scene, x: DVec3, own: usize) -> PlaneSides {
    let mut out = Vec::new();
    for (id, obj) in scene.objects.iter().enumerate() {
        if let (true, Shape::Plane { point, normal }) = (id != own, obj.shape)
            && let Some(up) = side_of(point, normal, x)
        {
            out.push((id, up));
        }
    }
    out
}

/// The unit vectors `v` of the half-spaces `v·ω > 0` that the planes of `sides` leave open.
pub fn open_half_spaces(scene: &Scene, sides: &PlaneSides) -> Vec<DVec3> {
    sides
        .iter()
        .filter_map(|&(id, up)| match scene.objects.get(id)?.shape {
            Shape::Plane { normal, .. } => Some(if up { normal } else { -normal }),
            Shape::Sphere { .. } => None,
        })
        .collect()
}

/// Every [`PlaneSides`] a shaded point of the scene can have: per surface, each plane
/// it is not on with the side it lies on, or both sides for a sphere the plane cuts and a
/// plane it crosses. At most 64 per surface (more planes cut it: the rest keep the
/// squares' estimate).
fn plane_signatures(scene: &Scene) -> Vec<PlaneSides> {
    let planes: Vec<(usize, DVec3, DVec3)> = scene
        .objects
        .iter()
        .enumerate()
        .filter_map(|(id, o)| match o.shape {
            Shape::Plane { point, normal } => Some((id, point, normal)),
            Shape::Sphere { .. } => None,
        })
        .collect();
    let mut all = std::collections::BTreeSet::new();
    for (id, obj) in scene.objects.iter().enumerate() {
        if !matches!(obj.kind, super::Kind::Surface(_)) {
            continue;
        }
        let mut combos: Vec<PlaneSides> = vec![Vec::new()];
        for &(pid, point, normal) in &planes {
            if pid == id {
                continue;
            }
            let sides: Vec<bool> = match obj.shape {
                Shape::Sphere { center, radius } => {
                    let d = normal.dot(center - point);
                    if d.abs() >= radius {
                        vec![d > 0.0]
                    } else {
                        vec![true, false]
                    }
                }
                Shape::Plane {
                    point: q,
                    normal: m,
                } => {
                    if normal.dot(m).abs() >= 1.0 - 1e-12 {
                        // Parallel: one side, or none for the same plane twice.
                        let Some(up) = side_of(point, normal, q) else {
                            continue;
                        };
                        vec![up]
                    } else {
                        vec![true, false]
                    }
                }
            };
            if combos.len() * sides.len() > 64 {
                continue;
            }
            combos = combos
                .into_iter()
                .flat_map(|c| {
                    sides.iter().map(move |&up| {
                        let mut c = c.clone();
                        c.push((pid, up));
                        c
                    })
                })
                .collect();
        }
        all.extend(combos);
    }
    all.into_iter().collect()
}

/// What the shadow ratio's `U` is taken under at a point: the visibility of its planes
/// alone, which its exact integral already holds ([`EnvTables`] of its [`PlaneSides`]).
pub enum Base {
    /// No plane occludes the point: nothing occluded (`(f, m) = (1, 0)`).
    Free,
    /// Only planes occlude it: its own tables (so `S = U`).
    Same,
    /// Planes and spheres occlude it: the moment tables of its planes alone.
    Map(VisMoments),
}

/// The caps of the other spheres, then of the planes the point is not on (module docs).
fn occluder_caps(
    scene: &Scene,
    p: &ShadingPoint,
    frame: &Frame,
) -> (Vec<SphericalCap>, Vec<SphericalCap>) {
    let x = p.x;
    let (mut spheres, mut planes) = (Vec::new(), Vec::new());
    for (id, obj) in scene.objects.iter().enumerate() {
        if id == p.object {
            continue;
        }
        if let Shape::Sphere { center, radius } = obj.shape
            && let Ok(c) = local_cap(x.as_vec3(), frame, center.as_vec3(), radius as f32)
        {
            spheres.push(c);
        }
    }
    for (id, up) in plane_sides(scene, x, p.object) {
        if let Shape::Plane { normal, .. } = scene.objects[id].shape {
            let toward = if up { -normal } else { normal };
            if let Ok(c) = SphericalCap::new(frame.to_local(toward.as_vec3()), FRAC_PI_2) {
                planes.push(c);
            }
        }
    }
    (spheres, planes)
}

/// The visibility moment tables of a surface point (module docs), `None` where the point
/// has no frame or its map cannot be built (it is then shaded black).
pub fn point_moments(
    scene: &Scene,
    o: &Options,
    p: &ShadingPoint,
    cov: &mut [f32],
) -> Option<(Frame, VisMoments)> {
    let o = Options {
        exact_unshadowed: false,
        ..*o
    };
    point_vis(scene, &o, p, cov).map(|(frame, moments, _)| (frame, moments))
}

/// [`point_moments`] with the point's [`Base`] (its planes' own map built where spheres
/// occlude it too); [`Base::Free`] without the shadow ratio.
pub fn point_vis(
    scene: &Scene,
    o: &Options,
    p: &ShadingPoint,
    cov: &mut [f32],
) -> Option<(Frame, VisMoments, Base)> {
    let frame = Frame::from_normal(p.n.as_vec3()).ok()?;
    let (spheres, planes) = occluder_caps(scene, p, &frame);
    let base = if !o.exact_unshadowed || planes.is_empty() {
        Base::Free
    } else if spheres.is_empty() {
        Base::Same
    } else {
        coverage_into_depth(&planes, o.vis_side, Outside::Visible, o.vis_depth, cov).ok()?;
        Base::Map(VisMoments::build_coverage(o.vis_side, cov).ok()?)
    };
    let mut caps = spheres;
    caps.extend(planes);
    coverage_into_depth(&caps, o.vis_side, Outside::Visible, o.vis_depth, cov).ok()?;
    let moments = VisMoments::build_coverage(o.vis_side, cov).ok()?;
    Some((frame, moments, base))
}

/// A specular BRDF the method fits one SAT for, with unit scale: modified Phong
/// (`k_s = 1`) of an exponent, core's `Ggx` (`k_d = 0`) of `(f0, α)`, or one Lafortune
/// lobe (`ρ = 1`) of `(c, c_z, e)`; parameters as `f64` bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum SpecKey {
    /// Modified Phong exponent.
    Phong(u64),
    /// GGX `(f0, α)`.
    Ggx(u64, u64),
    /// A Lafortune lobe `(c, c_z, e)`.
    Lafortune(u64, u64, u64),
}

/// The specular parts of a material: each SAT it needs and the RGB that scales it
/// (Phong's and GGX's `specular`, each Lafortune lobe's `ρ`), without allocating (it runs
/// per shading point).
pub fn specular_parts(mat: &Material) -> impl Iterator<Item = (SpecKey, Rgb)> + '_ {
    let single = match *mat {
        Material::Phong {
            specular, exponent, ..
        } => Some((SpecKey::Phong(exponent.to_bits()), specular)),
        Material::Ggx {
            specular,
            f0,
            alpha,
            ..
        } => Some((SpecKey::Ggx(f0.to_bits(), alpha.to_bits()), specular)),
        _ => None,
    };
    let lobes = match mat {
        Material::Lafortune { lobes, .. } => lobes.as_slice(),
        _ => &[],
    };
    single.into_iter().chain(lobes.iter().map(|l| {
        let k = SpecKey::Lafortune(l.c.to_bits(), l.cz.to_bits(), l.exponent.to_bits());
        (k, l.rho)
    }))
}

/// The BRDF SAT of one specular part, fitted to `target` over the decompositions.
fn fit_part(
    key: SpecKey,
    refs: &[&crate::env::decompose::Decomposition],
    target: f32,
) -> Result<BrdfSat, String> {
    let f = |b: u64| f64::from_bits(b) as f32;
    let e = |e: steradian_core::Error| e.to_string();
    Ok(match key {
        SpecKey::Phong(x) => {
            crate::shade::fit_sat(&Phong::new(0.0, 1.0, f(x)).map_err(e)?, refs, target)
        }
        SpecKey::Ggx(f0, a) => {
            crate::shade::fit_sat(&Ggx::new(0.0, f(f0), f(a)).map_err(e)?, refs, target)
        }
        SpecKey::Lafortune(c, cz, x) => {
            let lobe = LafortuneLobe {
                c: steradian_core::Vec3::new(f(c), f(c), f(cz)),
                exponent: f(x),
                rho: 1.0,
            };
            crate::shade::fit_sat(&Lafortune::new([lobe]).map_err(e)?, refs, target)
        }
    })
}

/// The exact unshadowed integral of one BRDF part at a point, with unit scale like its
/// SAT, and its weight ([`EnvTables::lobe`]): Lambert `(1/π)∫L·cos⁺`; modified Phong
/// `(e+2)/(2π)·∫L·(r·ω)₊^e·cos⁺` about the mirror direction `r`; a Lafortune lobe
/// `∫L·(m·ω)₊^e·cos⁺ = |m|^e·∫L·(â·ω)₊^e·cos⁺` with `m = (c·ωo_x, c·ωo_y, c_z·ωo_z)` in
/// the local frame and `â = m/|m|`. `None` where the tables have none (GGX, a sharper
/// lobe than [`super::unshadowed::MAX_EXPONENT`], an axis too near the horizon).
fn exact_part(t: &EnvTables, key: Option<SpecKey>, p: &ShadingPoint) -> Option<(Rgb, f64)> {
    let (n, wo) = (p.n, p.wo);
    match key {
        None => Some((t.diffuse(n), 1.0)),
        Some(SpecKey::Phong(e)) => {
            let e = f64::from_bits(e);
            let (v, w) = t.lobe(e, reflect(wo, n), n)?;
            let k = (e + 2.0) / std::f64::consts::TAU;
            Some((v.map(|x| x * k), w))
        }
        Some(SpecKey::Lafortune(c, cz, e)) => {
            let (c, cz, e) = (f64::from_bits(c), f64::from_bits(cz), f64::from_bits(e));
            let z = wo.dot(n);
            let m = c * (wo - z * n) + cz * z * n;
            let len = m.length();
            if len.is_nan() || len <= 0.0 {
                return None;
            }
            let (v, w) = t.lobe(e, m / len, n)?;
            let k = len.powf(e);
            Some((v.map(|x| x * k), w))
        }
        Some(SpecKey::Ggx(..)) => None,
    }
}

/// One part's integral: the kernel's `s`, or with the shadow ratio
/// ([`Options::exact_unshadowed`]) `x·clamp(s/u, 0, 1)` per channel (`u` the kernel's
/// unshadowed twin, `x` the exact unshadowed integral), blended with `s` by `x`'s weight.
/// `s` alone where `u` is not positive (the squares bring that channel no light).
fn part_value(s: [f32; 3], u: Option<[f32; 3]>, x: Option<(Rgb, f64)>) -> Rgb {
    let mut out = s.map(f64::from);
    if let (Some(u), Some((x, w))) = (u, x) {
        for c in 0..3 {
            let (sc, uc) = (s[c] as f64, u[c] as f64);
            if uc > 0.0 && sc.is_finite() && x[c].is_finite() {
                let ratio = (sc / uc).clamp(0.0, 1.0);
                out[c] = w * x[c] * ratio + (1.0 - w) * sc;
            }
        }
    }
    out
}

/// The reflected radiance from each part's value with its RGB scale (the diffuse part's
/// scale is the material's diffuse RGB).
fn combine(mat: &Material, d: Rgb, parts: impl IntoIterator<Item = (Rgb, Rgb)>) -> Rgb {
    let diffuse = mat.diffuse();
    let mut out: Rgb = core::array::from_fn(|c| diffuse[c] * d[c]);
    for (scale, s) in parts {
        for c in 0..3 {
            out[c] += scale[c] * s[c];
        }
    }
    out
}

/// The reflected radiance at a surface point.
pub fn shade_point(
    scene: &Scene,
    b: &Built,
    o: &Options,
    p: &ShadingPoint,
    cov: &mut [f32],
) -> Rgb {
    let Some((frame, moments, base)) = point_vis(scene, o, p, cov) else {
        return [0.0; 3];
    };
    shade_with(scene, b, p, &frame, &moments, &base)
}

/// The exact-integral tables of a point's [`PlaneSides`], with the shadow ratio.
fn tables_at<'a>(scene: &Scene, b: &'a Built, p: &ShadingPoint) -> Option<&'a EnvTables> {
    b.unshadowed
        .as_ref()?
        .get(&plane_sides(scene, p.x, p.object))
}

/// [`shade_point`] with the point's frame, moment tables and [`Base`] already built.
fn shade_with(
    scene: &Scene,
    b: &Built,
    p: &ShadingPoint,
    frame: &Frame,
    moments: &VisMoments,
    base: &Base,
) -> Rgb {
    let wo = p.wo.as_vec3();
    let mat = &scene.materials[p.material];
    let tables = tables_at(scene, b, p);
    let part = |key: Option<SpecKey>, sat: &BrdfSat| {
        let x = tables.and_then(|t| exact_part(t, key, p));
        if x.is_none() {
            return part_value(
                shade::shade_moments(frame, wo, sat, moments, &b.lights),
                None,
                None,
            );
        }
        let (s, u) = match base {
            Base::Free => {
                shade::shade_moments_pair(frame, wo, sat, moments, &Unoccluded, &b.lights)
            }
            // Only planes occlude: `U = S`, one pass.
            Base::Same => {
                let s = shade::shade_moments(frame, wo, sat, moments, &b.lights);
                (s, s)
            }
            Base::Map(m) => shade::shade_moments_pair(frame, wo, sat, moments, m, &b.lights),
        };
        part_value(s, Some(u), x)
    };
    let d = part(None, &b.lambert);
    let parts = specular_parts(mat).filter_map(|(key, scale)| {
        let sat = b.specular.get(&key)?;
        Some((scale, part(Some(key), sat)))
    });
    combine(mat, d, parts)
}

/// A kernel run over a set of points with one BRDF SAT: `None` the Lambert SAT, `Some(key)`
/// a specular part's; `sel` indexes the caller's points; one `(S, U)` per selected point,
/// `U` under the point's [`Base`] when `pair` is set (zeros otherwise).
type PartBatch<'a> =
    dyn FnMut(Option<SpecKey>, &[usize], bool) -> Result<Vec<([f32; 3], [f32; 3])>, String> + 'a;

/// The radiance of points shaded part by part, the batched twin of [`shade_with`]:
/// `batch` shades all `points` with the Lambert SAT, then, per specular part of
/// [`Built::specular`], the points whose material has it (and, with the shadow ratio, the
/// same seeing everything, where the part has an exact value); each point's integrals are
/// then combined with its diffuse RGB and the parts' scales.
fn shade_by_part(
    scene: &Scene,
    built: &Built,
    points: &[ShadingPoint],
    batch: &mut PartBatch<'_>,
) -> Result<Vec<Rgb>, String> {
    // Each point's tables, once for all its parts.
    let tables: Vec<Option<&EnvTables>> =
        points.iter().map(|p| tables_at(scene, built, p)).collect();
    // One part over the points `sel`: the kernel's values through the ratio.
    let mut part = |key: Option<SpecKey>, sel: &[usize]| -> Result<Vec<Rgb>, String> {
        let x: Vec<Option<(Rgb, f64)>> = sel
            .iter()
            .map(|&q| tables[q].and_then(|t| exact_part(t, key, &points[q])))
            .collect();
        let pair = x.iter().any(Option::is_some);
        let su = batch(key, sel, pair)?;
        Ok(su
            .into_iter()
            .zip(x)
            .map(|((s, u), x)| part_value(s, x.is_some().then_some(u), x))
            .collect())
    };
    let all: Vec<usize> = (0..points.len()).collect();
    let d = part(None, &all)?;
    let mut parts: Vec<Vec<(Rgb, Rgb)>> = vec![Vec::new(); points.len()];
    for key in built.specular.keys() {
        let (sel, scales): (Vec<usize>, Vec<Rgb>) = all
            .iter()
            .filter_map(|&q| {
                specular_parts(&scene.materials[points[q].material])
                    .find(|(pk, _)| pk == key)
                    .map(|(_, scale)| (q, scale))
            })
            .unzip();
        if sel.is_empty() {
            continue;
        }
        let s = part(Some(*key), &sel)?;
        for ((&q, v), scale) in sel.iter().zip(s).zip(scales) {
            parts[q].push((scale, v));
        }
    }
    Ok((0..points.len())
        .map(|q| {
            combine(
                &scene.materials[points[q].material],
                d[q],
                parts[q].iter().copied(),
            )
        })
        .collect())
}

/// [`render_built`] through the SIMD moments kernel: per row, each surface point's moment
/// tables as in [`shade_point`], then eight points at a time through
/// [`steradian_simd::rsl::shade::shade_moments_batch`] with the Lambert SAT and with each
/// specular part's SAT (`shade_by_part`). Each pixel is within the kernel's
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
    use steradian_simd::rsl::shade::{
        IsoBrdfTables, MomentsInput, shade_moments_batch, shade_moments_pair_batch,
    };

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
    // The radiance of surface points (0 where no visibility tables are built), eight at a
    // time.
    let shade_points = |surface: &[ShadingPoint]| -> Result<Vec<Rgb>, String> {
        let mut cov = vec![0.0f32; o.vis_side * o.vis_side];
        let mut radiance = vec![[0.0; 3]; surface.len()];
        // (index, point, frame, tables) of the shaded points.
        let mut pts = Vec::with_capacity(surface.len());
        for (i, p) in surface.iter().enumerate() {
            if let Some((frame, m, base)) = point_vis(scene, o, p, &mut cov) {
                pts.push((i, *p, frame, m, base));
            }
        }
        {
            let points: Vec<ShadingPoint> = pts.iter().map(|p| p.1).collect();
            let mut batch = |key: Option<SpecKey>, sel: &[usize], pair: bool| {
                let tables = match key {
                    None => lambert,
                    Some(k) => {
                        let (views, s_max) = &specular_views[&k];
                        IsoBrdfTables {
                            tables: views,
                            s_max: *s_max,
                        }
                    }
                };
                let input: Vec<MomentsInput<'_>> = sel
                    .iter()
                    .map(|&q| MomentsInput {
                        frame: pts[q].2,
                        wo: pts[q].1.wo.as_vec3(),
                        vis: pts[q].3.view(),
                    })
                    .collect();
                let mut out = vec![[0.0f32; 3]; sel.len()];
                let mut free = vec![[0.0f32; 3]; sel.len()];
                let ok = if pair {
                    // Three runs by the points' bases: `U` seeing everything (`Free`),
                    // `U = S` (`Same`, one pass), `U` under the planes' own map (`Map`).
                    let mut ok = true;
                    for kind in 0..3 {
                        let group: Vec<usize> = (0..sel.len())
                            .filter(|&k| {
                                kind == match pts[sel[k]].4 {
                                    Base::Free => 0,
                                    Base::Same => 1,
                                    Base::Map(_) => 2,
                                }
                            })
                            .collect();
                        if group.is_empty() {
                            continue;
                        }
                        let inp: Vec<MomentsInput<'_>> = group.iter().map(|&k| input[k]).collect();
                        let n = group.len();
                        let (mut o2, mut f2) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
                        ok &= match kind {
                            0 => shade_moments_pair_batch(
                                &inp,
                                &tables,
                                &built.lights,
                                None,
                                &mut o2,
                                &mut f2,
                            ),
                            1 => {
                                let done =
                                    shade_moments_batch(&inp, &tables, &built.lights, &mut o2);
                                f2.copy_from_slice(&o2);
                                done
                            }
                            _ => {
                                let views: Vec<_> = group
                                    .iter()
                                    .filter_map(|&k| match &pts[sel[k]].4 {
                                        Base::Map(m) => Some(m.view()),
                                        _ => None,
                                    })
                                    .collect();
                                shade_moments_pair_batch(
                                    &inp,
                                    &tables,
                                    &built.lights,
                                    Some(&views),
                                    &mut o2,
                                    &mut f2,
                                )
                            }
                        };
                        for (j, &k) in group.iter().enumerate() {
                            out[k] = o2[j];
                            free[k] = f2[j];
                        }
                    }
                    ok
                } else {
                    shade_moments_batch(&input, &tables, &built.lights, &mut out)
                };
                if ok {
                    Ok(out.into_iter().zip(free).collect())
                } else {
                    Err("visibility tables of different sizes".to_string())
                }
            };
            let shaded = shade_by_part(scene, built, &points, &mut batch)?;
            for ((i, _, _, _, _), v) in pts.iter().zip(shaded) {
                radiance[*i] = v;
            }
        }
        Ok(radiance)
    };
    let rows: Vec<Result<(Vec<Rgb>, super::Objects), String>> = (0..h)
        .into_par_iter()
        .map(|j| {
            let mut row = vec![[0.0; 3]; w];
            let mut objects = vec![None; w];
            let (mut at, mut surface) = (Vec::with_capacity(w), Vec::with_capacity(w));
            for (i, (px, object)) in row.iter_mut().zip(&mut objects).enumerate() {
                match scene.see(&cam.centre_ray(i as u32, j as u32)) {
                    Seen::Radiance(l) => *px = l,
                    Seen::Surface(p) => {
                        *object = Some(p.object);
                        at.push(i);
                        surface.push(p);
                    }
                }
            }
            for (i, v) in at.into_iter().zip(shade_points(&surface)?) {
                row[i] = v;
            }
            bar.inc(1);
            Ok((row, objects))
        })
        .collect();
    let mut img = Image::new(w, h);
    let mut objects = Vec::with_capacity(w * h);
    for (j, row) in rows.into_iter().enumerate() {
        let (row, row_objects) = row?;
        img.data[j * w..(j + 1) * w].copy_from_slice(&row);
        objects.extend(row_objects);
    }
    footprint::refine(scene, &mut img, &objects, o.footprint, |points| {
        let parts = points
            .par_chunks(w.max(8))
            .map(shade_points)
            .collect::<Result<Vec<_>, String>>()?;
        Ok(parts.concat())
    })?;
    Ok(img)
}

/// One pixel-centre sample per pixel ([`super::render_centres`]), building first.
pub fn render(scene: &Scene, o: &Options, bar: &ProgressBar) -> Result<Image, String> {
    let built = build(scene, o)?;
    render_built(scene, &built, o, bar)
}

/// [`render`] with what [`build`] made: the per-frame work once the environment is
/// decomposed and the BRDF tables fitted (the paper's precomputation).
/// `Err` for a visibility-map side the moment tables do not take.
pub fn render_built(
    scene: &Scene,
    built: &Built,
    o: &Options,
    bar: &ProgressBar,
) -> Result<Image, String> {
    use rayon::prelude::*;
    let new_cov = || vec![0.0f32; o.vis_side * o.vis_side];
    let (mut img, _, objects) = render_centres(scene, bar, new_cov, |cov, p| {
        shade_point(scene, built, o, p, cov)
    });
    footprint::refine(scene, &mut img, &objects, o.footprint, |points| {
        Ok(points
            .par_iter()
            .map_init(new_cov, |cov, p| shade_point(scene, built, o, p, cov))
            .collect())
    })?;
    Ok(img)
}

/// Surface points shaded per GPU batch by [`render_built_gpu`] (their moment tables are
/// built on the CPU first: about 26 KB each at the default 32² maps).
pub const GPU_BATCH: usize = 4096;

/// [`render_built`] on the wgpu backend: the surface points' moment tables as in
/// [`shade_point`] (CPU, in parallel), then `wgsl::SHADE_MOMENTS` for the Lambert SAT and
/// each specular part's SAT (`shade_by_part`, [`crate::shade::shade_moments_gpu_at`]),
/// [`GPU_BATCH`] points at a time. Each pixel is within `steradian_core::wgsl::SHADE_MOMENTS_REL_TOL` of
/// [`render_built`] (relative to the pixel's largest channel; the GPU scene test asserts
/// it). `Err` for a device error or a BRDF SAT the kernel does not take (anisotropic).
pub fn render_built_gpu(
    scene: &Scene,
    built: &Built,
    o: &Options,
    gpu: &mut crate::backend::gpu::Gpu,
    bar: &ProgressBar,
) -> Result<Image, String> {
    let (mut img, queue) = super::centre_queue(scene);
    bar.set_length(img.data.len() as u64);
    let points: Vec<ShadingPoint> = queue.iter().map(|q| q.1).collect();
    let shaded = shade_points_gpu(scene, built, o, gpu, &points, bar)?;
    for ((k, _), v) in queue.iter().zip(shaded) {
        img.data[*k] = v;
    }
    bar.set_position(img.data.len() as u64);
    let objects = super::queue_objects(img.data.len(), &queue);
    footprint::refine(scene, &mut img, &objects, o.footprint, |points| {
        shade_points_gpu(scene, built, o, gpu, points, &ProgressBar::hidden())
    })?;
    Ok(img)
}

/// The radiance of surface points by [`render_built_gpu`]'s kernels, [`GPU_BATCH`] at a
/// time (0 where no visibility tables are built); `bar` advances by each batch.
fn shade_points_gpu(
    scene: &Scene,
    built: &Built,
    o: &Options,
    gpu: &mut crate::backend::gpu::Gpu,
    surface: &[ShadingPoint],
    bar: &ProgressBar,
) -> Result<Vec<Rgb>, String> {
    use crate::shade::{GPU_MOMENTS_MAX_TABLE_BYTES, ShadePoint, shade_moments_gpu_at};
    use rayon::prelude::*;

    let free = free_moments(o)?;
    let mut radiance = vec![[0.0; 3]; surface.len()];
    let queue: Vec<(usize, ShadingPoint)> = surface.iter().copied().enumerate().collect();
    for chunk in queue.chunks(GPU_BATCH) {
        let tables: Vec<Option<(Frame, VisMoments, Base)>> = chunk
            .par_iter()
            .map_init(
                || vec![0.0f32; o.vis_side * o.vis_side],
                |cov, (_, p)| point_vis(scene, o, p, cov),
            )
            .collect();
        // The shaded points of the batch (those with tables) with their pixel.
        let mut points = Vec::new();
        let mut px = Vec::new();
        let mut pts = Vec::new();
        let mut ms = Vec::new();
        let mut bases = Vec::new();
        for ((k, p), t) in chunk.iter().zip(tables) {
            if let Some((frame, m, base)) = t {
                bases.push(base);
                points.push(*p);
                px.push((*k, p.material));
                pts.push(ShadePoint {
                    pos: p.x,
                    frame,
                    wo: p.wo.as_vec3(),
                    occluders: Vec::new(),
                });
                ms.push(m);
            }
        }
        // With `pair`, a second dispatch with each point's base (the WGSL kernel has no
        // pair twin; the free table's moments are `(1, 0)` to rounding).
        let mut batch = |key: Option<SpecKey>, sel: &[usize], pair: bool| {
            let sat = match key {
                None => &built.lambert,
                Some(k) => &built.specular[&k],
            };
            let sub_pts: Vec<ShadePoint> = sel.iter().map(|&q| pts[q].clone()).collect();
            let mut run = |ms: Vec<&VisMoments>| {
                shade_moments_gpu_at(
                    gpu,
                    &sub_pts,
                    sat,
                    &ms,
                    &built.lights,
                    GPU_MOMENTS_MAX_TABLE_BYTES,
                )
                .map_err(|e| e.to_string())
            };
            let s = run(sel.iter().map(|&q| &ms[q]).collect())?;
            // `U` for the points with another base than their own tables (`Same`: `U = S`).
            let other: Vec<usize> = (0..sel.len())
                .filter(|&k| pair && !matches!(bases[sel[k]], Base::Same))
                .collect();
            let mut u = if pair {
                s.clone()
            } else {
                vec![[0.0; 3]; sel.len()]
            };
            if !other.is_empty() {
                let sub_pts: Vec<ShadePoint> = other.iter().map(|&k| pts[sel[k]].clone()).collect();
                let base: Vec<&VisMoments> = other
                    .iter()
                    .map(|&k| match &bases[sel[k]] {
                        Base::Map(m) => m,
                        _ => &free,
                    })
                    .collect();
                let got = shade_moments_gpu_at(
                    gpu,
                    &sub_pts,
                    sat,
                    &base,
                    &built.lights,
                    GPU_MOMENTS_MAX_TABLE_BYTES,
                )
                .map_err(|e| e.to_string())?;
                for (&k, v) in other.iter().zip(got) {
                    u[k] = v;
                }
            }
            Ok(s.into_iter().zip(u).collect())
        };
        let shaded = shade_by_part(scene, built, &points, &mut batch)?;
        for (&(k, _), v) in px.iter().zip(shaded) {
            radiance[k] = v;
        }
        bar.inc(chunk.len() as u64);
    }
    Ok(radiance)
}
