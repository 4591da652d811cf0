//! RSL shading against the exact rendering integral (rotatable-square-lights paper, eq. 3–5,
//! Figure 8, section 6, Figures 9–10).
//!
//! ## Scene
//!
//! [`Scene::standard`]: a ground plane (`z = 0`) with three occluder spheres resting on it,
//! shading points on a grid over the ground and on the upper half of the largest sphere
//! (the half that faces the viewer), one viewer. Points on a sphere are occluded by the
//! other spheres (a sphere cannot shadow its own convex surface: its own horizon is the
//! cosine's); ground points by all three.
//!
//! ## The exact reference
//!
//! `B(x, wₒ) = ∫ L(ω)·ρ(ω, wₒ)·cos θ·V(x, ω) dω` with `L` the cube map (piecewise constant per
//! texel, exact texel solid angles), `ρ·cos` the BRDF model ([`steradian_core::lobe::brdf`],
//! evaluated at `f32`, accumulated in `f64`) and `V` exact ray–sphere visibility (`f64`).
//! Every texel of every face is summed; each texel is split into `sub × sub` sub-texels
//! with exact solid angles and `ρ·V` is taken at their centres, so `sub = 1` is the sum over
//! texel centres and larger `sub` converges to the exact integral of the piecewise-constant
//! environment (the report and tests state the difference between `sub` levels).
//!
//! ## Factor analysis
//!
//! [`Analysis`] evaluates, per point and per decomposition, the RSL estimate with the
//! approximate factors swapped for exact ones one at a time (see [`Variant`]), so the
//! share of each approximation in the total error is measured rather than guessed:
//! the multi-product approximation itself over the true regions (bounded by eq. 13, which
//! is evaluated alongside), the square-for-region replacement of eq. 6, the BRDF SAT and the
//! VDT.

#![allow(clippy::needless_range_loop)] // RGB channels are indexed in parallel arrays

use std::f64::consts::FRAC_1_SQRT_2;

use glam::{DVec2, DVec3, Vec2, Vec3};
use steradian_core::frame::Frame;
use steradian_core::lobe::brdf::Brdf;
use steradian_core::rsl::brdf_sat::{BrdfSat, FitOptions};
use steradian_core::rsl::shade::gpu as shade_gpu;
use steradian_core::rsl::shade::{
    self, Moments, ShadeLight, VdtQuery, VdtVisibility, multi_product_bound,
};
use steradian_core::rsl::vdt::Vdt;
use steradian_core::rsl::vis_moments::VisMoments;
use steradian_core::rsl::visibility::{Outside, binary_into, coverage_into, local_cap};
use steradian_simd::rsl::shade::{
    IsoBrdfTables, MomentsInput, ShadeInput, shade_batch, shade_moments_batch,
};

use crate::env::cubemap::for_each_sub_texel;
use crate::env::{CubeMap, Decomposition};

/// A sphere (occluder).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub centre: DVec3,
    /// Radius.
    pub radius: f64,
}

impl Sphere {
    /// Whether the ray `o + t·d`, `t > 0` (`d` unit, `o` outside the sphere) hits it.
    #[inline]
    pub fn blocks(&self, o: DVec3, d: DVec3) -> bool {
        let oc = self.centre - o;
        let b = oc.dot(d);
        let c = oc.length_squared() - self.radius * self.radius;
        b > 0.0 && b * b >= c
    }
}

/// One shading point.
#[derive(Clone, Debug)]
pub struct ShadePoint {
    /// Position.
    pub pos: DVec3,
    /// The local frame (normal = z).
    pub frame: Frame,
    /// Unit direction towards the viewer (world).
    pub wo: Vec3,
    /// Indices of the spheres that can occlude this point.
    pub occluders: Vec<usize>,
}

impl ShadePoint {
    /// Exact visibility of direction `d` (unit, world).
    #[inline]
    pub fn visible(&self, spheres: &[Sphere], d: DVec3) -> bool {
        !self
            .occluders
            .iter()
            .any(|&k| spheres[k].blocks(self.pos, d))
    }
    /// The frame's axes in `f64` `(t, b, n)`.
    pub fn axes(&self) -> (DVec3, DVec3, DVec3) {
        (
            self.frame.tangent().as_dvec3(),
            self.frame.bitangent().as_dvec3(),
            self.frame.normal().as_dvec3(),
        )
    }
}

/// Shading points and occluders.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Occluder spheres.
    pub spheres: Vec<Sphere>,
    /// Shading points.
    pub points: Vec<ShadePoint>,
}

impl Scene {
    /// The standard scene (module docs): a `g × g` grid of ground points over
    /// `[−1.6, 1.6]²` (points within 2 % of a sphere's radius from its contact point are
    /// left out) and points on the upper half of sphere 0 facing the viewer at the nodes of
    /// a `g × g` grid in (azimuth, elevation).
    pub fn standard(g: usize) -> Scene {
        let spheres = vec![
            Sphere {
                centre: DVec3::new(0.0, 0.0, 0.5),
                radius: 0.5,
            },
            Sphere {
                centre: DVec3::new(0.95, -0.55, 0.3),
                radius: 0.3,
            },
            Sphere {
                centre: DVec3::new(-0.8, 0.75, 0.25),
                radius: 0.25,
            },
        ];
        let eye = DVec3::new(3.0, -4.0, 3.0);
        let mut points = Vec::new();
        let g = g.max(2);
        for j in 0..g {
            for i in 0..g {
                let x = -1.6 + 3.2 * (i as f64 + 0.5) / g as f64;
                let y = -1.6 + 3.2 * (j as f64 + 0.5) / g as f64;
                let pos = DVec3::new(x, y, 0.0);
                if spheres
                    .iter()
                    .any(|s| pos.distance(s.centre) < s.radius * 1.02)
                {
                    continue;
                }
                push_point(&mut points, pos, DVec3::Z, eye, vec![0, 1, 2]);
            }
        }
        let s0 = spheres[0];
        for j in 0..g {
            for i in 0..g {
                let az = std::f64::consts::TAU * (i as f64 + 0.5) / g as f64;
                let el = 0.5 * std::f64::consts::FRAC_PI_2 * (1.0 + (j as f64 + 0.5) / g as f64)
                    - 0.25 * std::f64::consts::FRAC_PI_2;
                let n = DVec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
                let pos = s0.centre + n * s0.radius;
                if n.dot((eye - pos).normalize()) < 0.1 {
                    continue;
                }
                push_point(&mut points, pos, n, eye, vec![1, 2]);
            }
        }
        Scene { spheres, points }
    }
}

fn push_point(points: &mut Vec<ShadePoint>, pos: DVec3, n: DVec3, eye: DVec3, occ: Vec<usize>) {
    // A tangent from the world x axis (or y where the normal is along x).
    let t = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let frame = Frame::from_normal_tangent(n.as_vec3(), t.as_vec3()).expect("valid normal");
    points.push(ShadePoint {
        pos,
        frame,
        wo: (eye - pos).normalize().as_vec3(),
        occluders: occ,
    });
}

/// The visibility map of a point on an `n × n` grid: coverage of the union of its
/// occluders' caps ([`Outside::Visible`]), thresholded at ½, and its VDT.
pub fn point_vdt(scene: &Scene, p: &ShadePoint, n: usize) -> Vdt {
    Vdt::build(n, n, &point_mask(scene, p, n)).expect("valid map")
}

/// The visibility moment tables of a point ([`VisMoments`]) over its `n × n` coverage map
/// ([`point_coverage`]; the binary map of [`point_vdt`] moves every shadow edge by up to
/// half a texel, [`VisMoments::build_coverage`]).
pub fn point_moments(scene: &Scene, p: &ShadePoint, n: usize) -> VisMoments {
    VisMoments::build_coverage(n, &point_coverage(scene, p, n)).expect("valid map")
}

/// The binary visibility map of a point on an `n × n` grid (module docs of [`point_vdt`]).
pub fn point_mask(scene: &Scene, p: &ShadePoint, n: usize) -> Vec<bool> {
    let cov = point_coverage(scene, p, n);
    let mut mask = vec![false; n * n];
    binary_into(&cov, &mut mask);
    mask
}

/// The coverage map of a point on an `n × n` grid: the visible fraction of each texel
/// (the union of its occluders' caps, [`coverage_into`], [`Outside::Visible`]).
pub fn point_coverage(scene: &Scene, p: &ShadePoint, n: usize) -> Vec<f32> {
    let caps: Vec<_> = p
        .occluders
        .iter()
        .map(|&k| {
            let s = scene.spheres[k];
            local_cap(
                p.pos.as_vec3(),
                &p.frame,
                s.centre.as_vec3(),
                s.radius as f32,
            )
            .expect("point outside its occluders")
        })
        .collect();
    let mut cov = vec![0.0f32; n * n];
    coverage_into(&caps, n, Outside::Visible, &mut cov).expect("valid grid");
    cov
}

/// Sub-texel samples of a cube map: direction, exact solid angle, texel index.
#[derive(Clone, Debug)]
pub struct Samples {
    /// Sub-texels per texel side.
    pub sub: usize,
    /// Unit directions of the sub-texel centres.
    pub dirs: Vec<DVec3>,
    /// Exact solid angles.
    pub weights: Vec<f64>,
    /// Cube texel of each sample.
    pub texel: Vec<u32>,
}

impl Samples {
    /// `sub × sub` samples per texel of `cube`, in texel order.
    pub fn new(cube: &CubeMap, sub: usize) -> Samples {
        let sub = sub.max(1);
        let cap = cube.len() * sub * sub;
        let (mut dirs, mut weights, mut texel) = (
            Vec::with_capacity(cap),
            Vec::with_capacity(cap),
            Vec::with_capacity(cap),
        );
        for_each_sub_texel(cube.n(), sub, |k, d, w| {
            dirs.push(d);
            weights.push(w);
            texel.push(k as u32);
        });
        Samples {
            sub,
            dirs,
            weights,
            texel,
        }
    }
}

/// The exact reference `∫ L·ρcos·V dω` (module docs) at every point, RGB.
pub fn reference(
    cube: &CubeMap,
    samples: &Samples,
    scene: &Scene,
    brdf: &(dyn Brdf + Sync),
) -> Vec<[f64; 3]> {
    par_map(&scene.points, |p| {
        let (t, b, n) = p.axes();
        let wo = p.frame.to_local(p.wo);
        let mut acc = [0.0f64; 3];
        for (s, d) in samples.dirs.iter().enumerate() {
            let z = d.dot(n);
            if z <= 0.0 {
                continue;
            }
            let wi = DVec3::new(d.dot(t), d.dot(b), z).as_vec3();
            let rho = brdf.eval(wi, wo) as f64;
            if rho == 0.0 || !p.visible(&scene.spheres, *d) {
                continue;
            }
            let l = cube.texels()[samples.texel[s] as usize];
            let w = rho * samples.weights[s];
            for c in 0..3 {
                acc[c] += l[c] as f64 * w;
            }
        }
        acc
    })
}

/// Maps `f` over `items` on all available cores, in order.
pub fn par_map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(8);
    let mut out: Vec<Option<R>> = items.iter().map(|_| None).collect();
    if items.is_empty() {
        return Vec::new();
    }
    let chunk = items.len().div_ceil(threads);
    std::thread::scope(|s| {
        for (inp, o) in items.chunks(chunk).zip(out.chunks_mut(chunk)) {
            let f = &f;
            s.spawn(move || {
                for (x, y) in inp.iter().zip(o.iter_mut()) {
                    *y = Some(f(x));
                }
            });
        }
    });
    out.into_iter().flatten().collect()
}

/// Exact square integrals for one point and one light, `f64` (midpoint rule, `m × m`).
struct ExactSquare {
    /// `ρ̄ = (1/Ω)∫_R ρcos dω`.
    rho: f64,
    /// `V̄`, the visible fraction of the square.
    vis: f64,
    /// `(1/Ω)∫_R ρcos·V dω`.
    joint: f64,
    /// `∫_R ρcos·V·(ω − c) dω` (world), the first moment that the light's radiance gradient
    /// multiplies.
    moment: DVec3,
}

fn exact_square(
    scene: &Scene,
    p: &ShadePoint,
    brdf: &dyn Brdf,
    wo: Vec3,
    light: &ShadeLight,
    (centre, r): (Vec2, f32),
    m: usize,
) -> ExactSquare {
    let h = f64::from(r) * FRAC_1_SQRT_2;
    let c = centre.as_dvec2();
    let lc = light.centre().as_dvec3();
    let step = 2.0 * h / m as f64;
    let (t, b, n) = p.axes();
    let (mut sr, mut sv, mut sj, mut sm) = (0.0, 0.0, 0.0, DVec3::ZERO);
    for j in 0..m {
        for i in 0..m {
            let q = c + DVec2::new(-h + step * (i as f64 + 0.5), -h + step * (j as f64 + 0.5));
            if q.length_squared() >= 1.0 {
                sv += 1.0; // outside the disk counts as visible (Outside::Visible)
                continue;
            }
            let wi = steradian_core::rsl::hemisphere::unmap(q.as_vec2());
            let d = (t * f64::from(wi.x) + b * f64::from(wi.y) + n * f64::from(wi.z)).normalize();
            let vis = p.visible(&scene.spheres, d) as u32 as f64;
            let rho = f64::from(brdf.eval(wi, wo));
            sr += rho;
            sv += vis;
            sj += rho * vis;
            sm += (d - lc) * (rho * vis);
        }
    }
    let dw = 2.0 * step * step; // dω = 2·du·dv
    let omega = 8.0 * h * h; // 2·(2h)²
    ExactSquare {
        rho: sr * dw / omega,
        vis: sv / (m * m) as f64,
        joint: sj * dw / omega,
        moment: sm * dw,
    }
}

/// The estimates compared in the factor analysis, per point, RGB.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Variant {
    /// Eq. 5 over the true regions with exact means: `Σ |Sᵢ|·u_L·u_ρ·u_V` (only the
    /// multi-product approximation; eq. 13 bounds its error).
    MultiProduct,
    /// Light uniform over the square: `Σ Eᵢ·(1/Ωᵢ)∫_{Rᵢ} ρV` (only the light's region → square).
    SquareJoint,
    /// The linear light of the moments kernel over the square, exact `ρV`:
    /// `Σ Eᵢ·(1/Ωᵢ)∫_{Rᵢ} ρV + Gᵢ·∫_{Rᵢ} ρV·(ω − cᵢ)` (the floor of [`Variant::Moments`]).
    SquareLinear,
    /// Eq. 5 with exact square means: `Σ Eᵢ·ρ̄ᵢ·V̄ᵢ` (square + multi-product, exact factors).
    SquareExact,
    /// BRDF SAT, exact square visibility.
    SatExactV,
    /// Exact square BRDF, VDT visibility (gradient variant).
    ExactBrdfVdt,
    /// The kernel: BRDF SAT × VDT (gradient variant), [`shade::shade`].
    Kernel,
    /// The kernel with the paper's eq. 9 VDT query.
    KernelEq9,
    /// The moments kernel: BRDF SAT with its gradient, visibility fraction and first moment
    /// from the coverage map, the light's radiance gradient ([`shade::shade_moments`]).
    Moments,
}

/// Every variant, in the order of [`PointResult::values`].
pub const VARIANTS: [Variant; 9] = [
    Variant::MultiProduct,
    Variant::SquareJoint,
    Variant::SquareLinear,
    Variant::SquareExact,
    Variant::SatExactV,
    Variant::ExactBrdfVdt,
    Variant::Kernel,
    Variant::KernelEq9,
    Variant::Moments,
];

/// Results of one point for one decomposition.
#[derive(Clone, Debug, Default)]
pub struct PointResult {
    /// One RGB estimate per [`VARIANTS`] entry.
    pub values: Vec<[f64; 3]>,
    /// Eq. 13 summed over the regions, per channel: bounds `|MultiProduct − reference|`.
    pub bound: [f64; 3],
}

/// Settings of [`analyse`].
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// Cells per side of the exact square integrals.
    pub square_cells: usize,
    /// Compute the exact-square variants (slow for large `K`); otherwise only the region
    /// variant and the kernels.
    pub exact_squares: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            square_cells: 24,
            exact_squares: true,
        }
    }
}

/// Per-region data (point independent): the samples in the region, `|S|`, `E`, and the
/// per-channel moments of `L`.
struct RegionL {
    members: Vec<usize>,
    area: f64,
    energy: [f64; 3],
    moments: [Moments; 3],
}

fn region_l(cube: &CubeMap, samples: &Samples, d: &Decomposition) -> Vec<RegionL> {
    let k = d.regions.len();
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); k];
    for (s, &t) in samples.texel.iter().enumerate() {
        members[d.region_of[t as usize] as usize].push(s);
    }
    members
        .into_iter()
        .map(|ms| {
            let area: f64 = ms.iter().map(|&s| samples.weights[s]).sum();
            let mut energy = [0.0; 3];
            let moments = std::array::from_fn(|c| {
                let it = ms.iter().map(|&s| {
                    (
                        f64::from(cube.texels()[samples.texel[s] as usize][c]),
                        samples.weights[s],
                    )
                });
                energy[c] = it.clone().map(|(l, w)| l * w).sum();
                Moments::of_weighted(it)
            });
            RegionL {
                members: ms,
                area,
                energy,
                moments,
            }
        })
        .collect()
}

/// Everything [`analyse`] needs.
pub struct Setup<'a> {
    /// Environment.
    pub cube: &'a CubeMap,
    /// Reference samples.
    pub samples: &'a Samples,
    /// Scene.
    pub scene: &'a Scene,
    /// Material.
    pub brdf: &'a (dyn Brdf + Sync),
    /// Its summed-area tables.
    pub sat: &'a BrdfSat,
    /// One VDT per point.
    pub vdts: &'a [Vdt],
}

/// Per decomposition, per point: the reference and every [`Variant`] (module docs).
pub struct Analysis {
    /// Reference per point (same sub-sampling as the region means).
    pub reference: Vec<[f64; 3]>,
    /// `results[d][p]` for decomposition `d` and point `p`.
    pub results: Vec<Vec<PointResult>>,
}

/// Runs the factor analysis for each decomposition.
pub fn analyse(setup: &Setup<'_>, decs: &[&Decomposition], settings: Settings) -> Analysis {
    let regions: Vec<Vec<RegionL>> = decs
        .iter()
        .map(|d| region_l(setup.cube, setup.samples, d))
        .collect();
    let lights: Vec<Vec<ShadeLight>> = decs
        .iter()
        .map(|d| {
            d.rsls()
                .expect("valid RSLs")
                .iter()
                .map(ShadeLight::from)
                .collect()
        })
        .collect();
    let idx: Vec<usize> = (0..setup.scene.points.len()).collect();
    let per_point = par_map(&idx, |&pi| {
        let p = &setup.scene.points[pi];
        let (t, b, n) = p.axes();
        let wo = p.frame.to_local(p.wo);
        let ns = setup.samples.dirs.len();
        let mut rho = vec![0.0f64; ns];
        let mut vis = vec![0.0f64; ns];
        let mut refc = [0.0f64; 3];
        for (s, d) in setup.samples.dirs.iter().enumerate() {
            let z = d.dot(n);
            if z > 0.0 {
                let wi = DVec3::new(d.dot(t), d.dot(b), z).as_vec3();
                rho[s] = f64::from(setup.brdf.eval(wi, wo));
            }
            vis[s] = p.visible(&setup.scene.spheres, *d) as u32 as f64;
            let l = setup.cube.texels()[setup.samples.texel[s] as usize];
            let w = rho[s] * vis[s] * setup.samples.weights[s];
            for c in 0..3 {
                refc[c] += f64::from(l[c]) * w;
            }
        }
        let vdt = setup.vdts[pi].view();
        let vis_g = VdtVisibility::new(vdt, VdtQuery::Gradient).expect("square VDT");
        let vis_9 = VdtVisibility::new(vdt, VdtQuery::Eq9).expect("square VDT");
        let vis_m = point_moments(setup.scene, p, vdt.width());
        let mut out = Vec::with_capacity(decs.len());
        for (regions, lights) in regions.iter().zip(&lights) {
            let mut res = PointResult {
                values: vec![[0.0; 3]; VARIANTS.len()],
                bound: [0.0; 3],
            };
            for rl in regions {
                // Moments of ρ and V over the region (solid-angle weights).
                let of = |f: &[f64]| {
                    Moments::of_weighted(
                        rl.members.iter().map(|&s| (f[s], setup.samples.weights[s])),
                    )
                };
                let (mr, mv) = (of(&rho), of(&vis));
                for c in 0..3 {
                    res.values[0][c] += rl.energy[c] * mr.mean * mv.mean;
                    res.bound[c] += multi_product_bound(rl.area, &rl.moments[c], &mv, &mr);
                }
            }
            // Squares.
            for l in lights {
                let Some((pc, r)) = l.square_above_horizon(&p.frame) else {
                    continue;
                };
                let e = l.energy().map(f64::from);
                let sat = f64::from(setup.sat.integral(wo, pc, r) * l.inv_solid_angle());
                let vg = f64::from(shade::SquareVisibility::fraction(&vis_g, pc, r));
                let v9 = f64::from(shade::SquareVisibility::fraction(&vis_9, pc, r));
                // Scalar factors per variant (times Eᵢ), and the RGB terms of the linear
                // light (added as they are).
                let mut f = [0.0f64; VARIANTS.len()];
                let mut rgb = [[0.0f64; 3]; VARIANTS.len()];
                if settings.exact_squares {
                    let ex = exact_square(
                        setup.scene,
                        p,
                        setup.brdf,
                        wo,
                        l,
                        (pc, r),
                        settings.square_cells,
                    );
                    f[1] = ex.joint;
                    f[2] = ex.joint;
                    rgb[2] = l.gradient().map(|g| g.as_dvec3().dot(ex.moment));
                    f[3] = ex.rho * ex.vis;
                    f[4] = sat * ex.vis;
                    f[5] = ex.rho * vg;
                }
                f[6] = sat * vg;
                f[7] = sat * v9;
                rgb[8] = shade::light_moments(&p.frame, wo, setup.sat, &vis_m, l).map(f64::from);
                for v in 1..VARIANTS.len() {
                    for c in 0..3 {
                        res.values[v][c] += e[c] * f[v] + rgb[v][c];
                    }
                }
            }
            out.push(res);
        }
        (refc, out)
    });
    let reference = per_point.iter().map(|(r, _)| *r).collect();
    let mut results: Vec<Vec<PointResult>> = vec![Vec::new(); decs.len()];
    for (_, rs) in per_point {
        for (d, r) in rs.into_iter().enumerate() {
            results[d].push(r);
        }
    }
    Analysis { reference, results }
}

/// The kernel itself at every point ([`shade::shade`], point `i` with VDT `i` queried by
/// `query`), `f32` RGB.
pub fn shade_points(
    scene: &Scene,
    sat: &BrdfSat,
    vdts: &[Vdt],
    lights: &[ShadeLight],
    query: VdtQuery,
) -> Vec<[f32; 3]> {
    scene
        .points
        .iter()
        .zip(vdts)
        .map(|(p, v)| {
            let vis = VdtVisibility::new(v.view(), query).expect("square VDT");
            shade::shade(&p.frame, p.wo, sat, &vis, lights)
        })
        .collect()
}

/// Relative L2 error over points and channels: `sqrt(Σ|a − ref|²/Σ|ref|²)`.
pub fn rel_l2(values: impl Iterator<Item = [f64; 3]>, reference: &[[f64; 3]]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (v, r) in values.zip(reference) {
        for c in 0..3 {
            num += (v[c] - r[c]) * (v[c] - r[c]);
            den += r[c] * r[c];
        }
    }
    if den > 0.0 { (num / den).sqrt() } else { 0.0 }
}

impl Analysis {
    /// Relative L2 error of `variant` for decomposition `d`.
    pub fn error(&self, d: usize, variant: Variant) -> f64 {
        let v = VARIANTS.iter().position(|&x| x == variant).unwrap_or(0);
        rel_l2(self.results[d].iter().map(|r| r.values[v]), &self.reference)
    }
    /// Eq. 13 as a relative L2 "error": `sqrt(Σ bound²/Σ|ref|²)`, an upper bound on
    /// `error(d, MultiProduct)`.
    pub fn bound(&self, d: usize) -> f64 {
        rel_l2(
            self.results[d]
                .iter()
                .zip(&self.reference)
                .map(|(r, x)| std::array::from_fn(|c| x[c] + r.bound[c])),
            &self.reference,
        )
    }
}

/// The BRDF SAT for a material and the RSL sizes of the decompositions: target error as
/// [`BrdfSat::fit`], `r_min`/`r_max` spanning every light's half-diagonal.
pub fn fit_sat(brdf: &dyn Brdf, decs: &[&Decomposition], target: f32) -> BrdfSat {
    let (mut lo, mut hi) = (f32::MAX, 0.0f32);
    for d in decs {
        for l in d.rsls().expect("valid RSLs") {
            lo = lo.min(l.half_diagonal());
            hi = hi.max(l.half_diagonal());
        }
    }
    let mut o = FitOptions::new(target);
    o.r_min = (0.9 * lo).clamp(1e-3, 1.0);
    o.r_max = hi.clamp(o.r_min, 2.0);
    BrdfSat::fit(brdf, &o).expect("valid fit options")
}

pub use steradian_core::rsl::shade::gpu::iso_views;

/// The SIMD kernel's inputs: every point with its VDT (point `i` uses VDT `i`).
pub fn simd_inputs<'a>(scene: &Scene, vdts: &'a [Vdt]) -> Vec<ShadeInput<'a>> {
    scene
        .points
        .iter()
        .zip(vdts)
        .map(|(p, v)| ShadeInput {
            frame: p.frame,
            wo: p.wo,
            vdt: v.view(),
        })
        .collect()
}

/// The SIMD kernel at every point (`steradian_simd::rsl::shade::shade_batch`).
pub fn shade_points_simd(
    scene: &Scene,
    sat: &BrdfSat,
    vdts: &[Vdt],
    lights: &[ShadeLight],
    query: VdtQuery,
) -> Option<Vec<[f32; 3]>> {
    let views = iso_views(sat)?;
    let tables = IsoBrdfTables {
        tables: &views,
        s_max: sat.s_max(),
    };
    let inputs = simd_inputs(scene, vdts);
    let mut out = vec![[0.0f32; 3]; inputs.len()];
    shade_batch(&inputs, &tables, query, lights, &mut out).then_some(out)
}

/// The moments kernel at every point ([`shade::shade_moments`], point `i` with moment
/// tables `i`), `f32` RGB.
pub fn shade_points_moments(
    scene: &Scene,
    sat: &BrdfSat,
    moments: &[VisMoments],
    lights: &[ShadeLight],
) -> Vec<[f32; 3]> {
    scene
        .points
        .iter()
        .zip(moments)
        .map(|(p, m)| shade::shade_moments(&p.frame, p.wo, sat, m, lights))
        .collect()
}

/// The SIMD moments kernel at every point (`steradian_simd::rsl::shade::shade_moments_batch`).
/// `None` for an anisotropic BRDF SAT or moment tables of different sizes.
pub fn shade_points_moments_simd(
    scene: &Scene,
    sat: &BrdfSat,
    moments: &[VisMoments],
    lights: &[ShadeLight],
) -> Option<Vec<[f32; 3]>> {
    let views = iso_views(sat)?;
    let tables = IsoBrdfTables {
        tables: &views,
        s_max: sat.s_max(),
    };
    let inputs: Vec<MomentsInput<'_>> = scene
        .points
        .iter()
        .zip(moments)
        .map(|(p, m)| MomentsInput {
            frame: p.frame,
            wo: p.wo,
            vis: m.view(),
        })
        .collect();
    let mut out = vec![[0.0f32; 3]; inputs.len()];
    shade_moments_batch(&inputs, &tables, lights, &mut out).then_some(out)
}

/// The binding-3 table of `wgsl::SHADE` (`steradian_core::rsl::shade::gpu::shade_table`),
/// as `f32` bits. `None` for an anisotropic BRDF SAT or VDTs of different sizes.
pub fn gpu_table(
    sat: &BrdfSat,
    vdts: &[Vdt],
    lights: &[ShadeLight],
    query: VdtQuery,
) -> Option<Vec<f32>> {
    let views: Vec<_> = vdts.iter().map(Vdt::view).collect();
    let w = shade_gpu::shade_table(sat, &views, lights, query)?;
    Some(w.into_iter().map(f32::from_bits).collect())
}

/// The input columns of `wgsl::SHADE` for every point (point `i` uses VDT `i`).
pub fn gpu_input(scene: &Scene) -> crate::kernels::Columns {
    gpu_input_points(&scene.points)
}

/// The input columns of `wgsl::SHADE` and `wgsl::SHADE_MOMENTS` for `points` (point `i`
/// of the slice uses table `i` of the kernel's table; `shade::gpu::input_row`).
pub fn gpu_input_points(points: &[ShadePoint]) -> crate::kernels::Columns {
    let rows: Vec<[f32; shade_gpu::INPUT_COLUMNS]> = points
        .iter()
        .enumerate()
        .map(|(i, p)| shade_gpu::input_row(&p.frame, p.wo, i))
        .collect();
    crate::kernels::Columns::from_rows(&rows)
}

/// The binding-3 table of `wgsl::SHADE_MOMENTS`
/// (`steradian_core::rsl::shade::gpu::moments_table`), as `f32` bits, for the points whose
/// moment tables are `moments`. `None` for an anisotropic BRDF SAT or maps of different
/// sizes. 1.6 MB per point at `n = 256`: [`shade_points_moments_gpu`] splits a batch so
/// that each table stays within a byte limit.
pub fn gpu_moments_table(
    sat: &BrdfSat,
    moments: &[&VisMoments],
    lights: &[ShadeLight],
) -> Option<Vec<f32>> {
    let views: Vec<_> = moments.iter().map(|m| m.view()).collect();
    let w = shade_gpu::moments_table(sat, &views, lights)?;
    Some(w.into_iter().map(f32::from_bits).collect())
}

/// wgpu's default `max_storage_buffer_binding_size` (128 MiB): the largest table
/// [`shade_points_moments_gpu`] uploads at once unless told otherwise.
pub const GPU_MOMENTS_MAX_TABLE_BYTES: usize = 128 << 20;

/// `wgsl::SHADE_MOMENTS` at every point (point `i` with `moments[i]`) on the GPU backend,
/// `f32` RGB: the points are split into consecutive chunks whose tables
/// ([`gpu_moments_table`]) stay within `max_table_bytes` (at least one point per chunk),
/// one dispatch per chunk. `Err` for an anisotropic BRDF SAT, maps of different sizes,
/// a count mismatch or a device error.
pub fn shade_points_moments_gpu(
    gpu: &mut crate::backend::gpu::Gpu,
    scene: &Scene,
    sat: &BrdfSat,
    moments: &[VisMoments],
    lights: &[ShadeLight],
    max_table_bytes: usize,
) -> Result<Vec<[f32; 3]>, crate::backend::BackendError> {
    let refs: Vec<&VisMoments> = moments.iter().collect();
    shade_moments_gpu_at(gpu, &scene.points, sat, &refs, lights, max_table_bytes)
}

/// [`shade_points_moments_gpu`] at any points (point `i` with `moments[i]`; only each
/// point's frame and view are read).
pub fn shade_moments_gpu_at(
    gpu: &mut crate::backend::gpu::Gpu,
    points: &[ShadePoint],
    sat: &BrdfSat,
    moments: &[&VisMoments],
    lights: &[ShadeLight],
    max_table_bytes: usize,
) -> Result<Vec<[f32; 3]>, crate::backend::BackendError> {
    use crate::backend::BackendError;
    if moments.len() != points.len() {
        return Err(BackendError(format!(
            "shade-moments: {} points, {} moment tables",
            points.len(),
            moments.len()
        )));
    }
    let polar = iso_views(sat).map_or(0, |v| v.len());
    let vn = moments.first().map_or(1, |m| m.side());
    let (fixed, per_point) =
        shade_gpu::moments_words(sat.resolution().grid, polar, lights.len(), vn);
    let chunk = (max_table_bytes / 4).saturating_sub(fixed) / per_point;
    let chunk = chunk.max(1);
    let mut out = Vec::with_capacity(moments.len());
    for (points, ms) in points.chunks(chunk).zip(moments.chunks(chunk)) {
        let table = gpu_moments_table(sat, ms, lights).ok_or_else(|| {
            BackendError("shade-moments: anisotropic BRDF SAT or maps of different sizes".into())
        })?;
        let input = gpu_input_points(points);
        let mut cols = crate::kernels::Columns::zeros(3, input.n);
        let custom = crate::backend::gpu::Custom {
            label: "rsl-shade-moments",
            source: steradian_core::wgsl::SHADE_MOMENTS,
            table: Some(&table),
        };
        gpu.run_custom(&custom, &input, &mut cols)?;
        out.extend((0..input.n).map(|p| [0, 1, 2].map(|c| cols.data[c * input.n + p])));
    }
    Ok(out)
}
