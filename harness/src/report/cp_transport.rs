//! The direction-driven transport benchmark of the control-point paper's section 3.5,
//! modelled on its experiment (a cube scene of about 13 000 voxels, diffuse surfaces, five
//! iterations), run with 162 control points and with 64 SH coefficients per voxel.
//!
//! **Scene.** A `24³` grid: its outer shell and two boxes are solid, the rest is air. Every
//! solid voxel with an air neighbour is a surface voxel: a diffuse reflector (albedo 0.6)
//! with the normal of its first air neighbour; a square of the ceiling emits radiance 1.
//!
//! **Transport.** Light moves only along a fixed set of `D` directions (a spiral). Visibility
//! is factored per direction once, before timing: for each surface voxel `s` and direction
//! `d` from its hemisphere, the first surface voxel `u` upstream (marching from `s` along
//! `−d`). Each iteration then gathers, per direction, the radiance leaving `u` along `d` —
//! a query of `u`'s outgoing spherical function at `d`, whose weights (control points) or
//! basis values (SH) are computed once per direction and shared by every voxel — into `s`'s
//! irradiance `E_s = Σ_d L_u(d)·max(n_s·(−d), 0)·4π/D`; then sets each outgoing function to
//! `(emission + 0.6·E_s/π)·H_{n_s}`, `H_n` the representation (a least-squares fit) of the
//! hemisphere indicator `[n·ω > 0]`. Per voxel and direction: three multiply-adds for
//! control points, 64 for SH; per voxel and iteration: 162 or 64 to set the function.

use std::time::Instant;

use steradian_core::Vec3;
use steradian_core::cp::{Icosphere, Location, Weights};

use crate::cp::LeastSquares;
use crate::rng::Rng;

/// Grid side (`24³ = 13 824` voxels; the paper: 13 000).
pub const SIDE: usize = 24;
/// Transport iterations (the paper: 5).
pub const ITERATIONS: usize = 5;
/// Direction counts (the paper's).
pub const DIRECTIONS: [usize; 6] = [45, 111, 223, 489, 1131, 2013];
const ALBEDO: f64 = 0.6;

/// The scene: surface voxels, their normals and emission.
pub struct Scene {
    solid: Vec<bool>,
    /// Surface voxel → grid index.
    cells: Vec<usize>,
    /// Grid index → surface index (`u32::MAX` elsewhere).
    surface_of: Vec<u32>,
    normals: Vec<Vec3>,
    emission: Vec<f64>,
}

fn idx(x: usize, y: usize, z: usize) -> usize {
    (z * SIDE + y) * SIDE + x
}

impl Scene {
    /// The cube scene of the module docs.
    pub fn cubes() -> Self {
        let n = SIDE;
        let inside = |x: usize, y: usize, z: usize, lo: [usize; 3], hi: [usize; 3]| {
            (lo[0]..hi[0]).contains(&x)
                && (lo[1]..hi[1]).contains(&y)
                && (lo[2]..hi[2]).contains(&z)
        };
        let mut solid = vec![false; n * n * n];
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let shell = [x, y, z].iter().any(|c| *c == 0 || *c == n - 1);
                    solid[idx(x, y, z)] = shell
                        || inside(x, y, z, [5, 1, 5], [11, 7, 11])
                        || inside(x, y, z, [14, 1, 12], [20, 13, 18]);
                }
            }
        }
        let dirs: [(i32, i32, i32); 6] = [
            (1, 0, 0),
            (-1, 0, 0),
            (0, 1, 0),
            (0, -1, 0),
            (0, 0, 1),
            (0, 0, -1),
        ];
        let (mut cells, mut normals, mut emission) = (Vec::new(), Vec::new(), Vec::new());
        let mut surface_of = vec![u32::MAX; n * n * n];
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    if !solid[idx(x, y, z)] {
                        continue;
                    }
                    let air = dirs.iter().find(|(dx, dy, dz)| {
                        let (a, b, c) = (x as i32 + dx, y as i32 + dy, z as i32 + dz);
                        let ok = |v: i32| (0..n as i32).contains(&v);
                        ok(a) && ok(b) && ok(c) && !solid[idx(a as usize, b as usize, c as usize)]
                    });
                    if let Some((dx, dy, dz)) = air {
                        surface_of[idx(x, y, z)] = cells.len() as u32;
                        cells.push(idx(x, y, z));
                        normals.push(Vec3::new(*dx as f32, *dy as f32, *dz as f32));
                        let light = y == n - 1 && (8..16).contains(&x) && (8..16).contains(&z);
                        emission.push(if light { 1.0 } else { 0.0 });
                    }
                }
            }
        }
        Self {
            solid,
            cells,
            surface_of,
            normals,
            emission,
        }
    }

    /// Number of surface voxels.
    pub fn surfaces(&self) -> usize {
        self.cells.len()
    }

    /// The first surface voxel met marching from surface voxel `s` along `−d` (half-voxel
    /// steps from its face on the normal's side), or `None` if the ray leaves the grid.
    fn upstream(&self, s: usize, d: Vec3) -> Option<u32> {
        let c = self.cells[s];
        let (x, y, z) = (c % SIDE, (c / SIDE) % SIDE, c / (SIDE * SIDE));
        let mut p =
            Vec3::new(x as f32 + 0.5, y as f32 + 0.5, z as f32 + 0.5) + self.normals[s] * 0.5;
        let step = -d * 0.5;
        for _ in 0..(4 * SIDE) {
            p += step;
            if p.min_element() < 0.0 || p.max_element() >= SIDE as f32 {
                return None;
            }
            let g = idx(p.x as usize, p.y as usize, p.z as usize);
            if g != c && self.solid[g] {
                let u = self.surface_of[g];
                return (u != u32::MAX).then_some(u);
            }
        }
        None
    }
}

/// Per direction, the pairs `(s, u, cos)`: receiver, upstream surface voxel, `n_s·(−d)`.
pub struct Visibility {
    dirs: Vec<Vec3>,
    links: Vec<Vec<(u32, u32, f32)>>,
}

/// `count` directions on a spiral (deterministic).
pub fn spiral(count: usize) -> Vec<Vec3> {
    (0..count)
        .map(|k| {
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / count as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let t = k as f64 * 2.399_963_229_728_653;
            Vec3::new((r * t.cos()) as f32, (r * t.sin()) as f32, z as f32)
        })
        .collect()
}

impl Visibility {
    /// The factored visibility of `scene` along `count` directions.
    pub fn new(scene: &Scene, count: usize) -> Self {
        let dirs = spiral(count);
        let links = dirs
            .iter()
            .map(|d| {
                (0..scene.surfaces())
                    .filter_map(|s| {
                        let cos = scene.normals[s].dot(-*d);
                        if cos <= 0.0 {
                            return None;
                        }
                        scene.upstream(s, *d).map(|u| (s as u32, u, cos))
                    })
                    .collect()
            })
            .collect();
        Self { dirs, links }
    }

    /// Links in all (receiver–sender pairs over every direction).
    pub fn links(&self) -> usize {
        self.links.iter().map(Vec::len).sum()
    }
}

/// A per-voxel spherical-function representation for the benchmark.
pub trait Representation {
    /// What is shared along a direction (the weights, or the basis values).
    type Shared;
    /// Values per voxel.
    fn size(&self) -> usize;
    /// Computed once per direction.
    fn shared(&self, d: Vec3) -> Self::Shared;
    /// The value of `f` (this representation's values) along the shared direction.
    fn query(&self, f: &[f32], s: &Self::Shared) -> f32;
    /// The hemisphere indicator of normal `n`.
    fn hemisphere(&self, n: Vec3) -> Vec<f32>;
}

/// Control points at one level, area weights.
pub struct ControlPoints {
    mesh: Icosphere,
    dirs: Vec<Vec3>,
    fit: LeastSquares,
}

impl ControlPoints {
    /// The mesh of `level`, with a least-squares fit from 20 000 random directions.
    pub fn new(level: u32) -> Self {
        let mesh = Icosphere::new(level).expect("level");
        let mut rng = Rng::new(0x7a5);
        let dirs: Vec<Vec3> = (0..20_000)
            .map(|_| {
                let p = rng.sphere();
                Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32)
            })
            .collect();
        let fit = LeastSquares::new(&mesh, &dirs).expect("unit directions");
        Self { mesh, dirs, fit }
    }
}

impl Representation for ControlPoints {
    type Shared = Location;
    fn size(&self) -> usize {
        self.mesh.vertices().len()
    }
    fn shared(&self, d: Vec3) -> Location {
        self.mesh.locate(d, Weights::Area).expect("unit direction")
    }
    #[inline]
    fn query(&self, f: &[f32], l: &Location) -> f32 {
        l.interpolate(f)
    }
    fn hemisphere(&self, n: Vec3) -> Vec<f32> {
        let f: Vec<f64> = self
            .dirs
            .iter()
            .map(|d| f64::from(u8::from(n.dot(*d) > 0.0)))
            .collect();
        let v = self.fit.fit(&f).unwrap_or_default();
        v.iter().map(|x| *x as f32).collect()
    }
}

/// Real SH of `bands` bands.
pub struct Harmonics {
    bands: usize,
}

impl Harmonics {
    /// `bands` bands (`bands²` coefficients).
    pub fn new(bands: usize) -> Self {
        Self { bands }
    }
}

impl Representation for Harmonics {
    type Shared = Vec<f32>;
    fn size(&self) -> usize {
        self.bands * self.bands
    }
    fn shared(&self, d: Vec3) -> Vec<f32> {
        let mut y = vec![0.0f32; self.size()];
        steradian_core::sh::eval_into(d, self.bands, &mut y).expect("bands");
        y
    }
    #[inline]
    fn query(&self, f: &[f32], y: &Vec<f32>) -> f32 {
        dot(f, y)
    }
    fn hemisphere(&self, n: Vec3) -> Vec<f32> {
        // The L2 projection of [n·ω > 0]: the coefficients of the cap of half-angle π/2.
        let mut c = vec![0.0f32; self.size()];
        let _ = steradian_core::sh::cap::coefficients_into(
            n,
            core::f32::consts::FRAC_PI_2,
            self.bands,
            &mut c,
        );
        c
    }
}

/// `Σ a_k b_k` with eight partial sums, so that it vectorises (a single running sum is bound
/// by the latency of its dependent additions): the SH side's query along a shared direction.
#[inline]
pub fn dot(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [0.0f32; 8];
    let (ac, bc) = (a.chunks_exact(8), b.chunks_exact(8));
    let tail: f32 = ac
        .remainder()
        .iter()
        .zip(bc.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ac.zip(bc) {
        for k in 0..8 {
            acc[k] += x[k] * y[k];
        }
    }
    acc.iter().sum::<f32>() + tail
}

/// One run: seconds of the timed iterations and the final irradiance per surface voxel.
pub fn run<R: Representation>(rep: &R, scene: &Scene, vis: &Visibility) -> (f64, Vec<f64>) {
    let size = rep.size();
    let hemis: Vec<Vec<f32>> = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z]
        .iter()
        .map(|n| rep.hemisphere(*n))
        .collect();
    let which: Vec<usize> = scene
        .normals
        .iter()
        .map(|n| {
            let a = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
            a.iter().position(|m| m == n).unwrap_or(0)
        })
        .collect();
    let shared: Vec<R::Shared> = vis.dirs.iter().map(|d| rep.shared(*d)).collect();
    let ns = scene.surfaces();
    let mut out = vec![0.0f32; ns * size];
    let set = |out: &mut [f32], e: &[f64]| {
        for s in 0..ns {
            let k = (scene.emission[s] + ALBEDO * e[s] / std::f64::consts::PI) as f32;
            let h = &hemis[which[s]];
            for (o, v) in out[s * size..(s + 1) * size].iter_mut().zip(h) {
                *o = k * v;
            }
        }
    };
    let mut e = vec![0.0f64; ns];
    let w = 4.0 * std::f64::consts::PI / vis.dirs.len() as f64;
    let start = Instant::now();
    set(&mut out, &e);
    for _ in 0..ITERATIONS {
        e.iter_mut().for_each(|x| *x = 0.0);
        for (links, sh) in vis.links.iter().zip(&shared) {
            for (s, u, cos) in links {
                let u = *u as usize;
                let l = rep.query(&out[u * size..(u + 1) * size], sh);
                e[*s as usize] += f64::from(l.max(0.0) * cos) * w;
            }
        }
        set(&mut out, &e);
    }
    (start.elapsed().as_secs_f64(), e)
}
