//! Report section: control-point spherical functions (Chatelier and Malgouyres, GRAPP 2007).
//! Query throughput per subdivision level — the O(1) location with area and gnomonic
//! weights, scalar and SIMD, against a brute-force scan of every triangle — in the same run;
//! the measured difference between the two weights and the area weights' jump across
//! triangle edges; and the least-squares fit's cost against its sample count.

use std::error::Error;
use std::fmt::Write as _;
use std::hint::black_box;

use serde_json::json;
use steradian_core::Vec3;
use steradian_core::cp::{Icosphere, MAX_LEVEL, Weights};
use steradian_reference::cp as reference;

use super::Options;
use super::section::Section;
use super::timing::{median_time, median_times_in_turns, ns_per, timed};
use crate::backend::gpu::{self, Custom, Gpu};
use crate::cp::{BruteForce, LeastSquares, Linf, fit_linf};
use crate::kernels::Columns;
use crate::rng::Rng;
use steradian_core::wgsl;

const SEED: u64 = 0x0c90_5eed;
/// Levels of the fit table and its sample counts.
pub const FIT_LEVELS: [u32; 3] = [2, 3, 4];
/// Sample counts of the fit table.
pub const FIT_SAMPLES: [usize; 3] = [1_000, 10_000, 100_000];

/// One level of the query table: ns per query.
struct QueryRow {
    level: u32,
    scalar_area: f64,
    scalar_gnomonic: f64,
    simd_area: f64,
    simd_gnomonic: f64,
    brute_force: f64,
    /// wgpu (area weights), upload and read-back included; `None` without an adapter.
    wgpu: Option<f64>,
}

/// One level of the weight comparison.
struct WeightRow {
    level: u32,
    /// max and mean of `|q_area − q_gnomonic|` over random directions, for values in [0, 1].
    max_diff: f64,
    mean_diff: f64,
    /// The largest jump of an area weight across an edge (f64 areas, both triangles).
    max_jump: f64,
}

struct FitRow {
    level: u32,
    samples: usize,
    build_ms: f64,
    fit_ms: f64,
    factor_nonzeros: usize,
    /// `V²/2`: the factor's non-zeros if it filled in completely.
    dense_nonzeros: usize,
}

fn directions(n: usize, rng: &mut Rng) -> Vec<Vec3> {
    (0..n)
        .map(|_| {
            let p = rng.sphere();
            Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32)
        })
        .collect()
}

fn query_rows(opts: &Options, rng: &mut Rng, gpu: &mut Option<Gpu>) -> Vec<QueryRow> {
    let n = opts.scaled(8192).max(256);
    let dirs = directions(n, rng);
    let (x, y, z): (Vec<f32>, Vec<f32>, Vec<f32>) = (
        dirs.iter().map(|d| d.x).collect(),
        dirs.iter().map(|d| d.y).collect(),
        dirs.iter().map(|d| d.z).collect(),
    );
    let rows: Vec<[f32; 3]> = dirs.iter().map(|d| d.to_array()).collect();
    let columns = Columns::from_rows(&rows);
    (0..=MAX_LEVEL)
        .map(|level| {
            let mesh = Icosphere::new(level).expect("level in range");
            let values: Vec<f32> = (0..mesh.vertices().len())
                .map(|_| rng.unit() as f32)
                .collect();
            let wgpu = gpu.as_mut().and_then(|g| {
                let table = mesh.gpu_table(&values, Weights::Area).ok()?;
                let custom = Custom {
                    label: "cp-query",
                    source: wgsl::CP_QUERY,
                    table: Some(&table),
                };
                let mut out = Columns::zeros(1, n);
                let t = median_time(opts.repeats.min(5), || {
                    g.run_custom(&custom, &columns, &mut out)
                        .expect("cp kernel runs");
                });
                Some(ns_per(n, t))
            });
            let brute = BruteForce::new(&mesh);
            // The scan costs 20·4^L plane tests per query: fewer queries for it.
            let brute_n = (n >> (2 * level)).clamp(16, n);
            let mut out = vec![0.0f32; n];
            let t = median_times_in_turns(opts.repeats.min(5), 5, |k| match k {
                0 | 1 => {
                    let w = if k == 0 {
                        Weights::Area
                    } else {
                        Weights::Gnomonic
                    };
                    for (o, d) in out.iter_mut().zip(&dirs) {
                        *o = mesh.query(&values, black_box(*d), w).unwrap_or(f32::NAN);
                    }
                    black_box(&out);
                }
                2 | 3 => {
                    let w = if k == 2 {
                        Weights::Area
                    } else {
                        Weights::Gnomonic
                    };
                    steradian_simd::cp::query_slices(&mesh, &values, w, &x, &y, &z, &mut out)
                        .expect("shapes");
                    black_box(&out);
                }
                _ => {
                    for (o, d) in out.iter_mut().zip(&dirs[..brute_n]) {
                        *o = brute.query(&values, black_box(*d));
                    }
                    black_box(&out);
                }
            });
            QueryRow {
                level,
                scalar_area: ns_per(n, t[0]),
                scalar_gnomonic: ns_per(n, t[1]),
                simd_area: ns_per(n, t[2]),
                simd_gnomonic: ns_per(n, t[3]),
                brute_force: ns_per(brute_n, t[4]),
                wgpu,
            }
        })
        .collect()
}

fn f64v(v: Vec3) -> [f64; 3] {
    [f64::from(v.x), f64::from(v.y), f64::from(v.z)]
}

fn weight_rows(rng: &mut Rng) -> Vec<WeightRow> {
    let dirs = directions(20_000, rng);
    (0..=MAX_LEVEL)
        .map(|level| {
            let mesh = Icosphere::new(level).expect("level in range");
            let values: Vec<f32> = (0..mesh.vertices().len())
                .map(|_| rng.unit() as f32)
                .collect();
            let (mut max_diff, mut sum) = (0.0f64, 0.0f64);
            for d in &dirs {
                let a = mesh.query(&values, *d, Weights::Area).unwrap_or(f32::NAN);
                let g = mesh
                    .query(&values, *d, Weights::Gnomonic)
                    .unwrap_or(f32::NAN);
                let e = f64::from((a - g).abs());
                max_diff = max_diff.max(e);
                sum += e;
            }
            // The jump: a point on the edge (a, b) shared by triangles (a, b, c) and
            // (b, a, c'), weighted in each with f64 areas; the weight of a differs.
            let v = mesh.vertices();
            let mut max_jump = 0.0f64;
            for (t, tri) in mesh.triangles().iter().enumerate().step_by(7) {
                let across = mesh.triangle_neighbours()[t][2];
                let other = mesh.triangles()[across as usize];
                let (a, b, c) = (
                    f64v(v[tri[0] as usize]),
                    f64v(v[tri[1] as usize]),
                    f64v(v[tri[2] as usize]),
                );
                let Some(&c2) = other.iter().find(|k| **k != tri[0] && **k != tri[1]) else {
                    continue;
                };
                let c2 = f64v(v[c2 as usize]);
                for s in [0.2, 0.5, 0.7] {
                    let p: [f64; 3] = std::array::from_fn(|k| a[k] * (1.0 - s) + b[k] * s);
                    let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
                    let p = p.map(|x| x / l);
                    let wa = |c: [f64; 3]| {
                        let (aa, ab, ac) = (
                            reference::triangle_area(p, b, c),
                            reference::triangle_area(a, p, c),
                            reference::triangle_area(a, b, p),
                        );
                        aa / (aa + ab + ac)
                    };
                    max_jump = max_jump.max((wa(c) - wa(c2)).abs());
                }
            }
            WeightRow {
                level,
                max_diff,
                mean_diff: sum / dirs.len() as f64,
                max_jump,
            }
        })
        .collect()
}

fn fit_rows(opts: &Options, rng: &mut Rng) -> Vec<FitRow> {
    let mut rows = Vec::new();
    for &level in &FIT_LEVELS {
        let mesh = Icosphere::new(level).expect("level in range");
        let nv = mesh.vertices().len();
        for &samples in &FIT_SAMPLES {
            let samples = opts.scaled(samples).clamp(100, samples);
            let dirs = directions(samples, rng);
            let values: Vec<f64> = dirs
                .iter()
                .map(|d| f64::from((3.0 * d.x).sin() * d.z + d.y))
                .collect();
            let (ls, build) = timed(|| LeastSquares::new(&mesh, &dirs));
            let Ok(ls) = ls else { continue };
            let t = median_times_in_turns(opts.repeats.min(3), 1, |_| {
                black_box(ls.fit(&values).ok());
            });
            rows.push(FitRow {
                level,
                samples,
                build_ms: build.as_secs_f64() * 1e3,
                fit_ms: t[0].as_secs_f64() * 1e3,
                factor_nonzeros: ls.factor_nonzeros(),
                dense_nonzeros: nv * (nv + 1) / 2,
            });
        }
    }
    rows
}

// ---- Representation and rotation, against SH ------------------------------------------

/// Control-point levels of the comparison (42, 162, 642 points).
pub const COMPARE_LEVELS: [u32; 3] = [1, 2, 3];
/// SH band counts of the comparison (16, 64, 169, 256 coefficients).
pub const COMPARE_BANDS: [usize; 4] = [4, 8, 13, 16];
/// Successive rotations after which the rotation error is measured.
pub const ROTATION_STEPS: [usize; 3] = [1, 10, 100];
/// Rotation angles (radians) of the rotation table: below half an edge of the 162-point
/// mesh (0.28 rad), where the permutation can only be the identity, and above it.
pub const ROTATION_ANGLES: [f64; 2] = [0.1, 0.5];
/// The rotation axis: far from the test lobes' axis, so that rotating moves them.
pub const ROTATION_AXIS: Vec3 = Vec3::new(1.0, -1.0, 0.2);

/// A test function of a direction (unit length).
pub type TestFunction = fn(Vec3) -> f64;

/// The test functions: Phong lobes of three exponents, a diffuse + specular radiance
/// distribution, and a stretched sphere (the paper's Figure 4 shape is not given in numbers;
/// ours is a unit sphere with two smooth bumps).
pub fn test_functions() -> Vec<(&'static str, TestFunction)> {
    fn lobe(d: Vec3, e: f64) -> f64 {
        let a = Vec3::new(0.3, 0.5, 0.81).normalize();
        f64::from(d.dot(a)).max(0.0).powf(e)
    }
    vec![
        ("Phong e = 1", |d| lobe(d, 1.0)),
        ("Phong e = 10", |d| lobe(d, 10.0)),
        ("Phong e = 50", |d| lobe(d, 50.0)),
        ("diffuse 0.2 + specular e = 20", |d| {
            0.2 + 0.8 * lobe(d, 20.0)
        }),
        ("stretched sphere", |d| {
            let b = Vec3::new(-0.6, 0.2, -0.77).normalize();
            1.0 + 0.5 * lobe(d, 8.0) + 0.3 * f64::from(d.dot(b)).max(0.0).powi(4)
        }),
    ]
}

/// Relative L2 error `‖rep − F‖ / ‖F‖` over `dirs`.
fn rel_l2(dirs: &[Vec3], mut rep: impl FnMut(Vec3) -> f64, f: impl Fn(Vec3) -> f64) -> f64 {
    let (mut e, mut n) = (0.0, 0.0);
    for d in dirs {
        let (r, t) = (rep(*d), f(*d));
        e += (r - t) * (r - t);
        n += t * t;
    }
    (e / n.max(1e-300)).sqrt()
}

/// The least-squares SH fit of `f` with `bands` bands from samples at `dirs` (dense normal
/// equations, nalgebra's Cholesky).
fn sh_fit(bands: usize, dirs: &[Vec3], f: impl Fn(Vec3) -> f64) -> Vec<f32> {
    let n = bands * bands;
    let mut ata = nalgebra::DMatrix::<f64>::zeros(n, n);
    let mut atb = nalgebra::DVector::<f64>::zeros(n);
    let mut y = vec![0.0f32; n];
    for d in dirs {
        steradian_core::sh::eval_into(*d, bands, &mut y).expect("bands");
        let fv = f(*d);
        for a in 0..n {
            let ya = f64::from(y[a]);
            atb[a] += ya * fv;
            for b in 0..=a {
                ata[(a, b)] += ya * f64::from(y[b]);
            }
        }
    }
    for a in 0..n {
        for b in 0..a {
            ata[(b, a)] = ata[(a, b)];
        }
    }
    match ata.cholesky() {
        Some(c) => c.solve(&atb).iter().map(|v| *v as f32).collect(),
        None => vec![0.0; n],
    }
}

fn sh_value(c: &[f32], bands: usize, d: Vec3, y: &mut [f32]) -> f64 {
    steradian_core::sh::eval_into(d, bands, y).expect("bands");
    c.iter().zip(y.iter()).map(|(a, b)| f64::from(a * b)).sum()
}

struct Representation {
    function: &'static str,
    /// (points, rel. L2) per control-point level.
    cp: Vec<(usize, f64)>,
    /// (coefficients, rel. L2) per band count.
    sh: Vec<(usize, f64)>,
}

struct RotationRow {
    angle: f64,
    function: &'static str,
    method: &'static str,
    size: usize,
    /// Error before rotating, then after each of `ROTATION_STEPS`.
    errors: Vec<f64>,
    apply_ns: f64,
    /// Largest angle between a rotated point and its match (permutation only).
    worst_match: Option<f64>,
}

fn representation_rows(rng: &mut Rng) -> Vec<Representation> {
    let fit_dirs = directions(20_000, rng);
    let sh_dirs = directions(4_096, rng);
    let test_dirs = directions(20_000, rng);
    let meshes: Vec<(Icosphere, LeastSquares)> = COMPARE_LEVELS
        .iter()
        .map(|l| {
            let m = Icosphere::new(*l).expect("level");
            let ls = LeastSquares::new(&m, &fit_dirs).expect("unit directions");
            (m, ls)
        })
        .collect();
    test_functions()
        .into_iter()
        .map(|(name, f)| {
            let samples: Vec<f64> = fit_dirs.iter().map(|d| f(*d)).collect();
            let cp = meshes
                .iter()
                .map(|(m, ls)| {
                    let v: Vec<f32> = ls
                        .fit(&samples)
                        .unwrap_or_default()
                        .iter()
                        .map(|x| *x as f32)
                        .collect();
                    let e = rel_l2(
                        &test_dirs,
                        |d| f64::from(m.query(&v, d, Weights::Area).unwrap_or(f32::NAN)),
                        f,
                    );
                    (m.vertices().len(), e)
                })
                .collect();
            let sh = COMPARE_BANDS
                .iter()
                .map(|&b| {
                    let c = sh_fit(b, &sh_dirs, f);
                    let mut y = vec![0.0f32; b * b];
                    (b * b, rel_l2(&test_dirs, |d| sh_value(&c, b, d, &mut y), f))
                })
                .collect();
            Representation {
                function: name,
                cp,
                sh,
            }
        })
        .collect()
}

/// A fit's values, or why the solver gave none.
type FitResult = Result<Vec<f64>, String>;

/// One fit of one test function at 162 points.
struct FitCompare {
    function: &'static str,
    fit: &'static str,
    rel_l2: f64,
    max_abs: f64,
    /// `max |rep − F| / F` over the test directions (the functions are positive).
    max_rel: f64,
    ms: f64,
}

/// Least squares against the three L∞ fits (eq. 5–7) at level 2 from 2000 samples, errors
/// over 20 000 other directions.
fn fit_compare_rows(rng: &mut Rng) -> Vec<FitCompare> {
    let mesh = Icosphere::new(2).expect("level");
    let dirs = directions(2_000, rng);
    let test_dirs = directions(20_000, rng);
    let design = steradian_core::cp::Design::new(&mesh, &dirs).expect("unit directions");
    let ls = LeastSquares::new(&mesh, &dirs).expect("unit directions");
    let mut rows = Vec::new();
    for (name, f) in test_functions() {
        // Positive versions: the relative fits divide by the value.
        let g = move |d: Vec3| f(d) + 0.05;
        let values: Vec<f64> = dirs.iter().map(|d| g(*d)).collect();
        let mut fits: Vec<(&'static str, FitResult, f64)> = Vec::new();
        let (v, t) = timed(|| ls.fit(&values));
        fits.push(("least squares (eq. 3)", v, t.as_secs_f64() * 1e3));
        for kind in Linf::ALL {
            let (v, t) = timed(|| fit_linf(&design, &values, kind).map(|r| r.0));
            fits.push((kind.name(), v, t.as_secs_f64() * 1e3));
        }
        for (fit, v, ms) in fits {
            let Ok(v) = v else { continue };
            let v: Vec<f32> = v.iter().map(|x| *x as f32).collect();
            let (mut max_abs, mut max_rel) = (0.0f64, 0.0f64);
            let q = |d: Vec3| f64::from(mesh.query(&v, d, Weights::Area).unwrap_or(f32::NAN));
            for d in &test_dirs {
                let (r, t) = (q(*d), g(*d));
                max_abs = max_abs.max((r - t).abs());
                max_rel = max_rel.max((r - t).abs() / t);
            }
            rows.push(FitCompare {
                function: name,
                fit,
                rel_l2: rel_l2(&test_dirs, q, g),
                max_abs,
                max_rel,
                ms,
            });
        }
    }
    rows
}

/// The relative L2 error of `v0` rotated 0 times and then each of [`ROTATION_STEPS`] times in
/// succession by `apply` (`value(v, d)` the represented function at `d`), against
/// `exact(d, steps)`; and the ns per application (median over runs of 100).
fn rotation_errors(
    opts: &Options,
    v0: &[f32],
    mut apply: impl FnMut(&[f32], &mut [f32]),
    mut value: impl FnMut(&[f32], Vec3) -> f64,
    test_dirs: &[Vec3],
    exact: impl Fn(Vec3, usize) -> f64,
) -> (Vec<f64>, f64) {
    let mut v = v0.to_vec();
    let mut tmp = vec![0.0f32; v.len()];
    let (mut errors, mut done) = (Vec::new(), 0);
    for &steps in std::iter::once(&0).chain(ROTATION_STEPS.iter()) {
        while done < steps {
            apply(&v, &mut tmp);
            std::mem::swap(&mut v, &mut tmp);
            done += 1;
        }
        errors.push(rel_l2(test_dirs, |d| value(&v, d), |d| exact(d, steps)));
    }
    let t = median_times_in_turns(opts.repeats.min(5), 1, |_| {
        for _ in 0..100 {
            apply(black_box(v0), &mut tmp);
        }
        black_box(&tmp);
    });
    (errors, ns_per(100, t[0]))
}

fn rotation_rows(opts: &Options, rng: &mut Rng) -> Vec<RotationRow> {
    use steradian_core::cp::rotate::Operator;
    use steradian_core::sh::rotate::{Operator as ShOperator, Rotation};
    let fit_dirs = directions(20_000, rng);
    let sh_dirs = directions(4_096, rng);
    let test_dirs = directions(4_000, rng);
    let funcs = test_functions();
    let picked = [&funcs[1], &funcs[4]];
    let mut rows = Vec::new();
    let level = 2;
    let mesh = Icosphere::new(level).expect("level");
    let ls = LeastSquares::new(&mesh, &fit_dirs).expect("unit directions");
    for angle in ROTATION_ANGLES {
        let rot = Rotation::from_axis_angle(ROTATION_AXIS, angle as f32).expect("rotation");
        let m = rot.matrix();
        // R^{-n} applied to a direction: the exact rotated function is f(R^{-n} d).
        let back = |d: Vec3, n: usize| -> Vec3 {
            let mut p = d.as_dvec3();
            for _ in 0..n {
                p = m.transpose() * p;
            }
            p.as_vec3()
        };
        let (perm, worst) = Operator::permutation(&mesh, &rot).expect("rotation");
        let ops = [
            ("permutation (3.4.1)", perm, Some(f64::from(worst))),
            (
                "continuous (3.4.2)",
                Operator::continuous(&mesh, &rot).expect("rotation"),
                None,
            ),
            (
                "resampling",
                Operator::resample(&mesh, &rot).expect("rotation"),
                None,
            ),
        ];
        let bands = 8;
        let sh_op = ShOperator::new(&rot, bands).expect("bands");
        for (name, f) in picked {
            let samples: Vec<f64> = fit_dirs.iter().map(|d| f(*d)).collect();
            let v0: Vec<f32> = ls
                .fit(&samples)
                .unwrap_or_default()
                .iter()
                .map(|x| *x as f32)
                .collect();
            for (method, op, worst) in &ops {
                let (errors, apply_ns) = rotation_errors(
                    opts,
                    &v0,
                    |v, out| op.apply(v, out).expect("lengths"),
                    |v, d| f64::from(mesh.query(v, d, Weights::Area).unwrap_or(f32::NAN)),
                    &test_dirs,
                    |d, steps| f(back(d, steps)),
                );
                rows.push(RotationRow {
                    angle,
                    function: name,
                    method,
                    size: v0.len(),
                    errors,
                    apply_ns,
                    worst_match: *worst,
                });
            }
            let c0 = sh_fit(bands, &sh_dirs, f);
            let mut y = vec![0.0f32; c0.len()];
            let (errors, apply_ns) = rotation_errors(
                opts,
                &c0,
                |c, out| sh_op.apply(c, out).expect("lengths"),
                |c, d| sh_value(c, bands, d, &mut y),
                &test_dirs,
                |d, steps| f(back(d, steps)),
            );
            rows.push(RotationRow {
                angle,
                function: name,
                method: "SH operator (Ivanic–Ruedenberg)",
                size: c0.len(),
                errors,
                apply_ns,
                worst_match: None,
            });
        }
    }
    rows
}

/// One row of the transport benchmark: both representations at one direction count.
struct TransportRow {
    directions: usize,
    links: usize,
    cp_s: f64,
    sh_s: f64,
    /// Mean `|E_cp − E_sh| / E_sh` over the surface voxels with `E_sh > 1e-3·max E_sh`.
    mean_rel_diff: f64,
}

fn transport_rows(opts: &Options) -> Vec<TransportRow> {
    use super::cp_transport::{self as tr, ControlPoints, Harmonics, Scene, Visibility};
    let scene = Scene::cubes();
    let (cp, sh) = (ControlPoints::new(2), Harmonics::new(8));
    // Quick runs (`--n` below the default) stop at 489 directions.
    let counts: Vec<usize> = tr::DIRECTIONS
        .iter()
        .copied()
        .filter(|d| opts.n >= super::DEFAULT_N || *d <= 489)
        .collect();
    counts
        .into_iter()
        .map(|directions| {
            let vis = Visibility::new(&scene, directions);
            let (cp_s, e_cp) = tr::run(&cp, &scene, &vis);
            let (sh_s, e_sh) = tr::run(&sh, &scene, &vis);
            let max = e_sh.iter().fold(0.0f64, |m, v| m.max(*v));
            let (mut sum, mut count) = (0.0, 0usize);
            for (a, b) in e_cp.iter().zip(&e_sh) {
                if *b > 1e-3 * max {
                    sum += (a - b).abs() / b;
                    count += 1;
                }
            }
            TransportRow {
                directions,
                links: vis.links(),
                cp_s,
                sh_s,
                mean_rel_diff: sum / count.max(1) as f64,
            }
        })
        .collect()
}

/// Operation times of the two representations at comparable sizes (162 control points,
/// 64 SH coefficients): ns per query (locating or evaluating the basis included), per query
/// when the weights or basis values are shared along a direction, per add and per scale.
struct OpTimes {
    cp: [f64; 4],
    sh: [f64; 4],
}

fn op_times(opts: &Options, rng: &mut Rng) -> OpTimes {
    let mesh = Icosphere::new(2).expect("level");
    let nv = mesh.vertices().len();
    let bands = 8;
    let nn = bands * bands;
    let dirs = directions(opts.scaled(4096).max(256), rng);
    let f: Vec<f32> = (0..nv).map(|_| rng.unit() as f32).collect();
    let c: Vec<f32> = (0..nn).map(|_| rng.unit() as f32).collect();
    let loc = mesh
        .locate(Vec3::new(0.3, 0.5, 0.8), Weights::Area)
        .expect("unit");
    let mut y = vec![0.0f32; nn];
    steradian_core::sh::eval_into(Vec3::new(0.3, 0.5, 0.8), bands, &mut y).expect("bands");
    let (mut fa, mut ca) = (f.clone(), c.clone());
    let reps = 1000;
    let dot = super::cp_transport::dot;
    let t = median_times_in_turns(opts.repeats.min(5), 8, |k| match k {
        0 => {
            for d in &dirs {
                black_box(mesh.query(&f, black_box(*d), Weights::Area).ok());
            }
        }
        1 => {
            let mut yy = vec![0.0f32; nn];
            for d in &dirs {
                steradian_core::sh::eval_into(black_box(*d), bands, &mut yy).expect("bands");
                black_box(dot(&c, &yy));
            }
        }
        2 => {
            for _ in 0..reps {
                black_box(black_box(&loc).interpolate(black_box(&f)));
            }
        }
        3 => {
            for _ in 0..reps {
                black_box(dot(black_box(&c), black_box(&y)));
            }
        }
        4 => {
            for _ in 0..reps {
                for (a, b) in fa.iter_mut().zip(black_box(&f)) {
                    *a += b;
                }
                black_box(&fa);
            }
        }
        5 => {
            for _ in 0..reps {
                for (a, b) in ca.iter_mut().zip(black_box(&c)) {
                    *a += b;
                }
                black_box(&ca);
            }
        }
        6 => {
            for _ in 0..reps {
                let k = black_box(0.999f32);
                fa.iter_mut().for_each(|a| *a *= k);
                black_box(&fa);
            }
        }
        _ => {
            for _ in 0..reps {
                let k = black_box(0.999f32);
                ca.iter_mut().for_each(|a| *a *= k);
                black_box(&ca);
            }
        }
    });
    let n = dirs.len();
    OpTimes {
        cp: [
            ns_per(n, t[0]),
            ns_per(reps, t[2]),
            ns_per(reps, t[4]),
            ns_per(reps, t[6]),
        ],
        sh: [
            ns_per(n, t[1]),
            ns_per(reps, t[3]),
            ns_per(reps, t[5]),
            ns_per(reps, t[7]),
        ],
    }
}

/// The section.
pub fn section(opts: &Options) -> Result<Section, Box<dyn Error>> {
    let mut rng = Rng::new(SEED);
    let (mut gpu, gpu_note) = gpu::if_requested(opts.gpu);
    let query = query_rows(opts, &mut rng, &mut gpu);
    let weights = weight_rows(&mut rng);
    let fit = fit_rows(opts, &mut rng);
    let repr = representation_rows(&mut rng);
    let compare = fit_compare_rows(&mut rng);
    let rotation = rotation_rows(opts, &mut rng);
    let transport = transport_rows(opts);
    let ops = op_times(opts, &mut rng);

    let mut summary = String::new();
    let l3 = query.iter().find(|r| r.level == 3);
    if let Some(r) = l3 {
        writeln!(
            summary,
            "level 3: O(1) location + area weights {:.0} ns/query, {:.0}× the brute-force scan \
             ({:.0} ns); SIMD {:.2}× scalar (area), {:.2}× (gnomonic)",
            r.scalar_area,
            r.brute_force / r.scalar_area,
            r.brute_force,
            r.scalar_area / r.simd_area,
            r.scalar_gnomonic / r.simd_gnomonic
        )?;
    }
    if let (Some(a), Some(b)) = (query.first(), query.last()) {
        writeln!(
            summary,
            "scalar query at level {} / level {}: {:.2}× (the cost does not grow with the level)",
            b.level,
            a.level,
            b.scalar_area / a.scalar_area
        )?;
    }
    if let Some(w) = weights.last() {
        writeln!(
            summary,
            "level {}: |area − gnomonic| ≤ {:.1e} (mean {:.1e}) for values in [0, 1]; area weights jump by up to {:.1e} across an edge",
            w.level, w.max_diff, w.mean_diff, w.max_jump
        )?;
    }
    if let Some(f) = fit.iter().max_by_key(|f| (f.level, f.samples)) {
        writeln!(
            summary,
            "least-squares fit, level {} from {} samples: {:.1} ms to locate and factor, {:.2} ms per fit; factor {} non-zeros ({:.1} % of dense)",
            f.level,
            f.samples,
            f.build_ms,
            f.fit_ms,
            f.factor_nonzeros,
            100.0 * f.factor_nonzeros as f64 / f.dense_nonzeros as f64
        )?;
    }

    let mut html = String::new();
    writeln!(
        html,
        "<p>ns per query (one function, many directions), median of runs taken in turns. The \
         brute force scans every triangle's three edge planes (precomputed) and takes the one \
         whose nearest plane is farthest; wgpu: {gpu_note}, upload and read-back included.\
         </p><table><tr><th>level</th><th>triangles</th>\
         <th>scalar area</th><th>scalar gnomonic</th><th>SIMD area</th><th>SIMD gnomonic</th>\
         <th>brute force</th><th>wgpu (area)</th><th>SIMD ×scalar (area)</th>\
         <th>O(1) ×brute force</th></tr>"
    )?;
    for r in &query {
        writeln!(
            html,
            "<tr><td>{}</td><td>{}</td><td>{:.1}</td><td>{:.1}</td><td>{:.1}</td><td>{:.1}</td>\
             <td>{:.0}</td><td>{}</td><td>{:.2}</td><td>{:.0}</td></tr>",
            r.level,
            20usize << (2 * r.level),
            r.scalar_area,
            r.scalar_gnomonic,
            r.simd_area,
            r.simd_gnomonic,
            r.brute_force,
            r.wgpu.map_or("—".to_string(), |g| format!("{g:.1}")),
            r.scalar_area / r.simd_area,
            r.brute_force / r.scalar_area
        )?;
    }
    writeln!(
        html,
        "</table><p>Area (eq. 2–4) against gnomonic weights on 20 000 random directions, \
         values uniform in [0, 1]; the area weights' jump across edges (f64 areas of both \
         triangles at points on a shared edge).</p><table><tr><th>level</th>\
         <th>max |area − gnomonic|</th><th>mean</th><th>max jump across an edge</th></tr>"
    )?;
    for w in &weights {
        writeln!(
            html,
            "<tr><td>{}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.2e}</td></tr>",
            w.level, w.max_diff, w.mean_diff, w.max_jump
        )?;
    }
    writeln!(
        html,
        "</table><p>Least-squares fit (eq. 3): locate the samples and factor the normal \
         equations once, then one fit per set of values.</p><table><tr><th>level</th>\
         <th>samples</th><th>locate + factor (ms)</th><th>fit (ms)</th>\
         <th>factor non-zeros</th><th>of dense</th></tr>"
    )?;
    for f in &fit {
        writeln!(
            html,
            "<tr><td>{}</td><td>{}</td><td>{:.2}</td><td>{:.3}</td><td>{}</td><td>{:.1} %</td></tr>",
            f.level,
            f.samples,
            f.build_ms,
            f.fit_ms,
            f.factor_nonzeros,
            100.0 * f.factor_nonzeros as f64 / f.dense_nonzeros as f64
        )?;
    }
    html.push_str("</table>");
    writeln!(
        html,
        "<p>Representation error (relative L2 over 20 000 random directions) of least-squares \
         fits: control points (area weights, fitted from 20 000 samples) against SH (fitted \
         from 4096 samples).</p><table><tr><th>function</th>{}{}</tr>",
        COMPARE_LEVELS
            .iter()
            .map(|l| format!("<th>{} CP</th>", 10 * (1usize << (2 * l)) + 2))
            .collect::<String>(),
        COMPARE_BANDS
            .iter()
            .map(|b| format!("<th>{} SH</th>", b * b))
            .collect::<String>()
    )?;
    for r in &repr {
        writeln!(
            html,
            "<tr><td>{}</td>{}{}</tr>",
            r.function,
            r.cp.iter()
                .map(|(_, e)| format!("<td>{e:.2e}</td>"))
                .collect::<String>(),
            r.sh.iter()
                .map(|(_, e)| format!("<td>{e:.2e}</td>"))
                .collect::<String>()
        )?;
    }
    writeln!(
        html,
        "</table><p>Fits compared at 162 points from 2000 samples (each function + 0.05, so \
         that the relative fits are defined), errors over 20 000 other directions.</p>\
         <table><tr><th>function</th><th>fit</th><th>rel. L2</th><th>max abs</th>\
         <th>max rel</th><th>ms</th></tr>"
    )?;
    for c in &compare {
        writeln!(
            html,
            "<tr><td>{}</td><td>{}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.2e}</td>\
             <td>{:.1}</td></tr>",
            c.function, c.fit, c.rel_l2, c.max_abs, c.max_rel, c.ms
        )?;
    }
    writeln!(
        html,
        "</table><p>Rotation by 0.1 and 0.5 rad about (1, −1, 0.2), applied 1, 10 and 100 \
         times: \
         relative L2 error against the function rotated exactly (first column: before \
         rotating, the representation error). 162 control points, 64 SH coefficients.</p>\
         <table><tr><th>angle</th><th>function</th><th>method</th><th>size</th><th>0</th><th>1</th>\
         <th>10</th><th>100</th><th>ns per rotation</th><th>worst match (rad)</th></tr>"
    )?;
    for r in &rotation {
        writeln!(
            html,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td>{}<td>{:.0}</td><td>{}</td></tr>",
            r.angle,
            r.function,
            r.method,
            r.size,
            r.errors
                .iter()
                .map(|e| format!("<td>{e:.2e}</td>"))
                .collect::<String>(),
            r.apply_ns,
            r.worst_match.map_or("".into(), |w| format!("{w:.3}"))
        )?;
    }
    html.push_str("</table>");
    writeln!(
        html,
        "<p>Operation times, ns (162 control points, 64 SH coefficients; one rotation in the \
         table above).</p><table><tr><th></th><th>query</th><th>query, shared weights / \
         basis</th><th>add</th><th>scale</th></tr><tr><td>control points</td><td>{:.1}</td>\
         <td>{:.1}</td><td>{:.1}</td><td>{:.1}</td></tr><tr><td>SH</td><td>{:.1}</td>\
         <td>{:.1}</td><td>{:.1}</td><td>{:.1}</td></tr></table>",
        ops.cp[0], ops.cp[1], ops.cp[2], ops.cp[3], ops.sh[0], ops.sh[1], ops.sh[2], ops.sh[3]
    )?;
    writeln!(
        summary,
        "ns per query / shared-weight query / add / scale: 162 CP {:.1} / {:.1} / {:.1} / {:.1}, 64 SH {:.1} / {:.1} / {:.1} / {:.1}",
        ops.cp[0], ops.cp[1], ops.cp[2], ops.cp[3], ops.sh[0], ops.sh[1], ops.sh[2], ops.sh[3]
    )?;
    writeln!(
        html,
        "<p>Direction-driven transport (section 3.5): a 24³ voxel cube scene, {} surface \
         voxels, diffuse, {} iterations, visibility factored per direction before timing; \
         162 control points against 64 SH coefficients per voxel. The paper: 4 / 10 / 19 / \
         41 / 96 / 171 s against 19 / 45 / 89 / 195 / 451 / 808 s (about 4.7×).</p>\
         <table><tr><th>directions</th><th>links</th><th>CP (s)</th><th>SH (s)</th>\
         <th>SH / CP</th><th>mean |E_cp − E_sh| / E_sh</th></tr>",
        super::cp_transport::Scene::cubes().surfaces(),
        super::cp_transport::ITERATIONS
    )?;
    for t in &transport {
        writeln!(
            html,
            "<tr><td>{}</td><td>{}</td><td>{:.3}</td><td>{:.3}</td><td>{:.2}</td>\
             <td>{:.2e}</td></tr>",
            t.directions,
            t.links,
            t.cp_s,
            t.sh_s,
            t.sh_s / t.cp_s,
            t.mean_rel_diff
        )?;
    }
    html.push_str("</table>");
    if let Some(t) = transport.last() {
        writeln!(
            summary,
            "transport (section 3.5), {} directions: 162 CP {:.3} s, 64 SH {:.3} s ({:.2}×; the paper 4.7×); irradiance differs by {:.1e} on average",
            t.directions,
            t.cp_s,
            t.sh_s,
            t.sh_s / t.cp_s,
            t.mean_rel_diff
        )?;
    }
    for r in rotation.iter().filter(|r| r.function == "stretched sphere") {
        writeln!(
            summary,
            "stretched sphere rotated by {} rad 0/1/10/100 times, {} ({}): rel. L2 {}",
            r.angle,
            r.method,
            r.size,
            r.errors
                .iter()
                .map(|e| format!("{e:.1e}"))
                .collect::<Vec<_>>()
                .join(" → ")
        )?;
    }
    if let Some(r) = repr.iter().find(|r| r.function == "stretched sphere") {
        writeln!(
            summary,
            "stretched sphere, rel. L2: {} | {}",
            r.cp.iter()
                .map(|(n, e)| format!("{n} CP {e:.1e}"))
                .collect::<Vec<_>>()
                .join(", "),
            r.sh.iter()
                .map(|(n, e)| format!("{n} SH {e:.1e}"))
                .collect::<Vec<_>>()
                .join(", ")
        )?;
    }

    let data = json!({
        "gpu": gpu_note,
        "query": query.iter().map(|r| json!({
            "level": r.level,
            "ns_per_query": {
                "scalar_area": r.scalar_area,
                "scalar_gnomonic": r.scalar_gnomonic,
                "simd_area": r.simd_area,
                "simd_gnomonic": r.simd_gnomonic,
                "brute_force": r.brute_force,
                "wgpu": r.wgpu,
            },
        })).collect::<Vec<_>>(),
        "weights": weights.iter().map(|w| json!({
            "level": w.level,
            "max_area_minus_gnomonic": w.max_diff,
            "mean_area_minus_gnomonic": w.mean_diff,
            "max_area_jump": w.max_jump,
        })).collect::<Vec<_>>(),
        "representation": repr.iter().map(|r| json!({
            "function": r.function,
            "cp": r.cp.iter().map(|(n, e)| json!({"points": n, "rel_l2": e})).collect::<Vec<_>>(),
            "sh": r.sh.iter().map(|(n, e)| json!({"coefficients": n, "rel_l2": e})).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
        "fits": compare.iter().map(|c| json!({
            "function": c.function,
            "fit": c.fit,
            "rel_l2": c.rel_l2,
            "max_abs": c.max_abs,
            "max_rel": c.max_rel,
            "ms": c.ms,
        })).collect::<Vec<_>>(),
        "rotation": rotation.iter().map(|r| json!({
            "angle": r.angle,
            "function": r.function,
            "method": r.method,
            "size": r.size,
            "steps": [0, 1, 10, 100],
            "rel_l2": r.errors,
            "apply_ns": r.apply_ns,
            "worst_match_rad": r.worst_match,
        })).collect::<Vec<_>>(),
        "ops_ns": {
            "cp": {"query": ops.cp[0], "shared_query": ops.cp[1], "add": ops.cp[2], "scale": ops.cp[3]},
            "sh": {"query": ops.sh[0], "shared_query": ops.sh[1], "add": ops.sh[2], "scale": ops.sh[3]},
        },
        "transport": transport.iter().map(|t| json!({
            "directions": t.directions,
            "links": t.links,
            "cp_seconds": t.cp_s,
            "sh_seconds": t.sh_s,
            "mean_rel_diff": t.mean_rel_diff,
        })).collect::<Vec<_>>(),
        "fit": fit.iter().map(|f| json!({
            "level": f.level,
            "samples": f.samples,
            "build_ms": f.build_ms,
            "fit_ms": f.fit_ms,
            "factor_nonzeros": f.factor_nonzeros,
        })).collect::<Vec<_>>(),
    });
    Ok(Section {
        id: "control-points",
        title: "Control-point spherical functions".into(),
        summary,
        html,
        data,
        files: Vec::new(),
    })
}
