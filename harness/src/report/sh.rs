//! Report section: spherical harmonics and Harmonics Virtual Lights. Evaluation speed at 3–30
//! bands (scalar, SIMD) against a plain `f64` evaluation and the `sphrs` crate on the same
//! directions in the same run, with a convention-free correctness check of each and the
//! machine's multiply–add rate; rotation (ZXZXZ per vector, the built operator) and cap
//! projection speed; the HVL paper's Table 1 (band limit × HVL count → time per shading
//! point and error against the exact integral); the BRDF tables' truncation error per band
//! limit with and without windows; and the windows' negativity.

use std::error::Error;
use std::fmt::Write as _;
use std::hint::black_box;

use serde_json::json;
use steradian_core::Vec3;
use steradian_core::sh::{self, brdf, hvl, rotate, window::Window};

use super::Options;
use super::section::Section;
use super::timing::{median_time, median_times_in_turns, ns_per};
use crate::backend::gpu::{self, Custom, Gpu};
use crate::generate::brdf_sh;
use crate::kernels::Columns;
use crate::sh as study;
use steradian_core::wgsl;

const SEED: u64 = 0x0005_4a11;
/// Band counts of the evaluation table.
pub const EVAL_BANDS: [usize; 5] = [3, 5, 10, 20, 30];
/// Band counts of the rotation table.
pub const ROTATE_BANDS: [usize; 4] = [3, 5, 10, 30];
/// Band limits of Table 1.
pub const HVL_BANDS: [usize; 4] = [3, 5, 7, 9];
/// HVL counts of Table 1 (`side²`).
pub const HVL_SIDES: [usize; 3] = [8, 14, 20];

/// One row of the evaluation table.
struct EvalRow {
    bands: usize,
    ns: [f64; 4],
    identity: [f64; 4],
    /// wgpu, upload and read-back included (bands ≤ `wgsl::SH_EVAL_MAX_BANDS`).
    gpu_ns: Option<f64>,
}

fn eval_rows(opts: &Options, gpu: &mut Option<Gpu>) -> Vec<EvalRow> {
    let dirs = study::directions(opts.scaled(4096).max(64), SEED);
    let rows: Vec<[f32; 3]> = dirs.clone();
    let columns = Columns::from_rows(&rows);
    EVAL_BANDS
        .iter()
        .map(|&n| {
            let nn = n * n;
            // sphrs costs O(n⁴)-ish: fewer directions for it at high band counts.
            let peer_dirs = if n >= 20 { 16 } else { dirs.len().min(1024) };
            let norms = study::plain_norms(n);
            let set = study::sphrs_set(n);
            let (x, y, z): (Vec<f32>, Vec<f32>, Vec<f32>) = (
                dirs.iter().map(|d| d[0]).collect(),
                dirs.iter().map(|d| d[1]).collect(),
                dirs.iter().map(|d| d[2]).collect(),
            );
            // The SIMD kernel writes eight directions' columns per call (`8·n²` values), the
            // scalar kernel one direction's `n²` values, each into one reused buffer (in L1
            // or L2 through 30 bands): neither pays for a scatter to memory. Each call starts
            // 64 bytes after the last one (modulo `RING` steps, the buffer `RING·64` bytes
            // longer than one call's output), so over a run the output takes every alignment
            // modulo 4 KiB. Where the output aliased the stack modulo 4 KiB, one fixed
            // position made a run's scalar 5-band time 1.3× (a false store-to-load
            // dependence at the call's return; which runs, by where the stack started).
            const RING: usize = 64;
            let chunk = 8;
            let mut out = vec![0.0f32; nn + 16 * RING];
            let mut cols = vec![0.0f32; nn * chunk + 16 * RING];
            let mut plain = vec![0.0f64; nn];
            let counts = [dirs.len(), dirs.len(), dirs.len(), peer_dirs];
            // Three times the report's rounds: a round is short (from 0.3 ms at 3 bands), and
            // on a shared host a kernel runs about 1.6× slower in bursts of up to a few ms,
            // which five rounds could fall inside.
            let t = median_times_in_turns(3 * opts.repeats, 4, |k| match k {
                0 => {
                    for (i, d) in dirs.iter().enumerate() {
                        let at = (i % RING) * 16;
                        sh::eval_into(Vec3::from(*d), n, &mut out[at..at + nn]).expect("shape");
                        black_box(&out);
                    }
                }
                1 => {
                    for s in (0..dirs.len()).step_by(chunk) {
                        let e = (s + chunk).min(dirs.len());
                        let at = (s / chunk % RING) * 16;
                        steradian_simd::sh::eval_slices(
                            &x[s..e],
                            &y[s..e],
                            &z[s..e],
                            n,
                            &mut cols[at..at + nn * (e - s)],
                        )
                        .expect("shape");
                        black_box(&cols);
                    }
                }
                2 => {
                    for d in &dirs {
                        study::plain_eval(d.map(f64::from), n, &norms, &mut plain);
                        black_box(&plain);
                    }
                }
                _ => {
                    for d in &dirs[..peer_dirs] {
                        black_box(study::sphrs_eval(&set, d.map(f64::from)));
                    }
                }
            });
            let ns = std::array::from_fn(|k| ns_per(counts[k], t[k]));
            // Correctness on 64 directions, every implementation.
            let mut identity = [0.0f64; 4];
            for d in dirs.iter().take(64) {
                sh::eval_into(Vec3::from(*d), n, &mut out[..nn]).expect("shape");
                let ours: Vec<f64> = out[..nn].iter().map(|&v| f64::from(v)).collect();
                study::plain_eval(d.map(f64::from), n, &norms, &mut plain);
                let peer = study::sphrs_eval(&set, d.map(f64::from));
                let errs = [
                    study::band_identity_error(&ours, n),
                    study::band_identity_error(&ours, n),
                    study::band_identity_error(&plain, n),
                    if peer.len() == nn && peer.iter().all(|v| v.is_finite()) {
                        study::band_identity_error(&peer, n)
                    } else {
                        f64::INFINITY
                    },
                ];
                for (a, b) in identity.iter_mut().zip(errs) {
                    *a = a.max(b);
                }
            }
            let gpu_ns = match gpu.as_mut() {
                Some(g) if n <= wgsl::SH_EVAL_MAX_BANDS => {
                    let table = [n as f32];
                    let custom = Custom {
                        label: "sh-eval",
                        source: wgsl::SH_EVAL,
                        table: Some(&table),
                    };
                    let mut out = Columns::zeros(nn, dirs.len());
                    let t = median_time(opts.repeats.min(5), || {
                        g.run_custom(&custom, &columns, &mut out)
                            .expect("SH kernel runs");
                    });
                    Some(ns_per(dirs.len(), t))
                }
                _ => None,
            };
            EvalRow {
                bands: n,
                ns,
                identity,
                gpu_ns,
            }
        })
        .collect()
}

struct RotateRow {
    bands: usize,
    zxzxz_ns: f64,
    simd_zxzxz_ns: f64,
    build_ns: f64,
    apply_ns: f64,
    simd_apply_ns: f64,
}

fn rotate_rows(opts: &Options) -> Vec<RotateRow> {
    let rot = rotate::Rotation::from_axis_angle(Vec3::new(0.3, -0.5, 0.8), 1.1).expect("valid");
    ROTATE_BANDS
        .iter()
        .map(|&n| {
            let vectors = opts.scaled(if n >= 30 { 64 } else { 1024 }).max(8);
            let input: Vec<f32> = (0..n * n).map(|i| ((i * 7919) % 13) as f32 - 6.0).collect();
            let mut out = vec![0.0f32; n * n];
            let rz = rotate::Rotator::new(n).expect("bands");
            let many: Vec<f32> = (0..vectors).flat_map(|_| input.iter().copied()).collect();
            let mut many_out = vec![0.0f32; many.len()];
            let rots = vec![rot; vectors];
            // The ZXZXZ path, scalar and SIMD (each vector with its rotation), in turns.
            let zx = median_times_in_turns(opts.repeats, 2, |k| {
                if k == 0 {
                    for _ in 0..vectors {
                        rz.rotate(&rot, black_box(&input), &mut out).expect("shape");
                    }
                    black_box(&out);
                } else {
                    steradian_simd::sh::rotate::rotate_zxzxz_slices(
                        rz.table(),
                        &rots,
                        n,
                        black_box(&many),
                        &mut many_out,
                    )
                    .expect("shape");
                    black_box(&many_out);
                }
            });
            let build = median_time(opts.repeats, || {
                black_box(rotate::Operator::new(&rot, n).expect("bands"));
            });
            let op = rotate::Operator::new(&rot, n).expect("bands");
            let apply = median_time(opts.repeats, || {
                for _ in 0..vectors {
                    op.apply(black_box(&input), &mut out).expect("shape");
                }
                black_box(&out);
            });
            let simd = median_time(opts.repeats, || {
                steradian_simd::sh::rotate::apply_operator_slices(
                    op.blocks(),
                    n,
                    black_box(&many),
                    &mut many_out,
                )
                .expect("shape");
                black_box(&many_out);
            });
            RotateRow {
                bands: n,
                zxzxz_ns: ns_per(vectors, zx[0]),
                simd_zxzxz_ns: ns_per(vectors, zx[1]),
                build_ns: build.as_secs_f64() * 1e9,
                apply_ns: ns_per(vectors, apply),
                simd_apply_ns: ns_per(vectors, simd),
            }
        })
        .collect()
}

/// Per band count: ns per cap, scalar and SIMD (`coefficients_slices` over 64-cap chunks),
/// taking turns on the same caps.
fn cap_rows(opts: &Options) -> Vec<(usize, f64, f64)> {
    let dirs = study::directions(opts.scaled(4096).max(64), SEED ^ 1);
    let angle = |i: usize| 0.01 + (i % 100) as f32 * 0.01;
    let angles: Vec<f32> = (0..dirs.len()).map(angle).collect();
    let col = |k: usize| dirs.iter().map(|d| d[k]).collect::<Vec<f32>>();
    let (x, y, z) = (col(0), col(1), col(2));
    [3usize, 5, 9]
        .iter()
        .map(|&n| {
            let mut out = vec![0.0f32; n * n];
            let chunk = 64;
            let mut cols = vec![0.0f32; n * n * chunk];
            let t = median_times_in_turns(opts.repeats, 2, |k| {
                if k == 0 {
                    for (i, d) in dirs.iter().enumerate() {
                        sh::cap::coefficients_into(Vec3::from(*d), angle(i), n, &mut out)
                            .expect("shape");
                        black_box(&out);
                    }
                } else {
                    for s in (0..dirs.len()).step_by(chunk) {
                        let e = (s + chunk).min(dirs.len());
                        steradian_simd::sh::cap::coefficients_slices(
                            &x[s..e],
                            &y[s..e],
                            &z[s..e],
                            &angles[s..e],
                            n,
                            &mut cols[..n * n * (e - s)],
                        )
                        .expect("shape");
                        black_box(&cols);
                    }
                }
            });
            (n, ns_per(dirs.len(), t[0]), ns_per(dirs.len(), t[1]))
        })
        .collect()
}

/// Table 1: `[side][bands]` → (µs per shading point, error per material).
struct Table1 {
    rows: Vec<(usize, usize, f64, [f64; 2])>,
    /// The error per material (Lambert, Phong 30) at the last row's HVL count and band
    /// limit with the smoothstep `H` and with the exact horizon fraction.
    horizon: [[f64; 2]; 2],
}

fn table1(opts: &Options) -> Table1 {
    let mats = study::materials();
    let mut rows = Vec::new();
    // The error per material with the exact horizon fraction, on the last scene at the
    // last band limit (its smoothstep twin is that row's).
    let mut exact_horizon = [0.0f64; 2];
    for (si, &side) in HVL_SIDES.iter().enumerate() {
        let scene = study::hvl_scene(side);
        let exact: Vec<Vec<f64>> = mats
            .iter()
            .map(|m| study::shade_exact(&scene, &m.model))
            .collect();
        for &n in &HVL_BANDS {
            let mut errs = [0.0f64; 2];
            let mut us = 0.0;
            for (k, m) in mats.iter().enumerate() {
                let (got, _) = study::shade(&scene, m, n);
                errs[k] = study::rel_rms(&got, &exact[k]);
                if k == 1 {
                    let t = median_time(opts.repeats.min(5), || {
                        black_box(study::shade(&scene, m, n));
                    });
                    us = t.as_secs_f64() * 1e6 / scene.points.len() as f64;
                }
            }
            rows.push((side * side, n, us, errs));
        }
        if si + 1 == HVL_SIDES.len() {
            let n = HVL_BANDS[HVL_BANDS.len() - 1];
            for (k, m) in mats.iter().enumerate() {
                let (got, _) = study::shade_with(&scene, m, n, hvl::Horizon::Exact);
                exact_horizon[k] = study::rel_rms(&got, &exact[k]);
            }
        }
    }
    let smoothstep = rows.last().map_or([0.0; 2], |r| r.3);
    let horizon = [smoothstep, exact_horizon];
    Table1 { rows, horizon }
}

/// One row of the HVL speed table: bands, ns per contribution scalar, SIMD, wgpu (upload
/// and read-back included; `None` without an adapter).
/// `(bands, scalar ns, SIMD ns, wgpu ns, zonal scalar ns, zonal SIMD ns)`.
type HvlRow = (usize, f64, f64, Option<f64>, f64, f64);

/// Per band count (3, 5, 9): ns per HVL contribution, scalar and SIMD (four HVLs per pass),
/// taking turns, and on wgpu (`wgsl::SH_HVL`, one contribution per invocation), the 400 HVLs of Table 1's scene at its first receiver with the Phong 30
/// table's `F`.
fn hvl_rows(opts: &Options, gpu: &mut Option<Gpu>) -> Vec<HvlRow> {
    let scene = study::hvl_scene(20);
    let mats = study::materials();
    let em = hvl::lambert_emission(0.8);
    let v3 = |a: [f64; 3]| Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32);
    let p = scene.points[0];
    let wo = (v3(scene.eye) - v3(p)).normalize();
    let frame = brdf::view_frame(v3(scene.normal), wo).expect("unit normal");
    let theta = frame.to_local(wo).z.clamp(-1.0, 1.0).acos();
    let reps = opts.scaled(4096).max(64).div_ceil(scene.hvls.len()).max(1);
    [3usize, 5, 9]
        .iter()
        .map(|&n| {
            let n = n.min(mats[1].table.bands());
            let mut coeffs = vec![0.0f32; n * n];
            mats[1]
                .table
                .lookup_into(brdf::Part::WithCosine, theta, n, &mut coeffs)
                .expect("bands within the table");
            let rx = hvl::Receiver {
                point: v3(p),
                frame,
                coeffs: &coeffs,
            };
            let mut scratch = vec![0.0f32; n * n];
            let mut scratch4 = vec![[0.0f32; 4]; n * n];
            let mut out = vec![0.0f32; scene.hvls.len()];
            let t = median_times_in_turns(opts.repeats.min(5), 2, |k| {
                for _ in 0..reps {
                    if k == 0 {
                        for (h, o) in scene.hvls.iter().zip(out.iter_mut()) {
                            *o = hvl::contribution(
                                h,
                                &em,
                                &rx,
                                hvl::Horizon::Smoothstep,
                                &mut scratch,
                            )
                            .expect("shapes");
                        }
                    } else {
                        steradian_simd::sh::hvl::contributions(
                            &scene.hvls,
                            &em,
                            &rx,
                            hvl::Horizon::Smoothstep,
                            &mut scratch4,
                            &mut out,
                        )
                        .expect("shapes");
                    }
                    black_box(&out);
                }
            });
            let count = reps * scene.hvls.len();
            let gpu_ns = gpu.as_mut().map(|g| {
                let rows = study::hvl_gpu_rows(&scene.hvls);
                let table = study::hvl_gpu_table(&rx, &em);
                let input = Columns::from_rows(&rows);
                let mut out = Columns::zeros(1, rows.len());
                let custom = Custom {
                    label: "sh-hvl",
                    source: wgsl::SH_HVL,
                    table: Some(&table),
                };
                let t = median_time(opts.repeats.min(5), || {
                    g.run_custom(&custom, &input, &mut out)
                        .expect("HVL kernel runs");
                });
                ns_per(rows.len(), t)
            });
            // The zonal receiver (a Lambertian surface: the `m = 0` entries of the Lambert
            // table at the same view), scalar and SIMD (eight HVLs per pass) in turns.
            let nz = n.min(mats[0].table.bands());
            let mut full = vec![0.0f32; nz * nz];
            mats[0]
                .table
                .lookup_into(brdf::Part::WithCosine, theta, nz, &mut full)
                .expect("bands within the table");
            let zonal: Vec<f32> = (0..nz).map(|l| full[l * l + l]).collect();
            let zrx = hvl::ZonalReceiver {
                point: v3(p),
                frame,
                coeffs: &zonal,
            };
            let hz = hvl::Horizon::Smoothstep;
            let tz = median_times_in_turns(opts.repeats.min(5), 2, |k| {
                for _ in 0..reps {
                    if k == 0 {
                        for (h, o) in scene.hvls.iter().zip(out.iter_mut()) {
                            *o = hvl::contribution_zonal(h, &em, &zrx, hz, &mut scratch)
                                .expect("shapes");
                        }
                    } else {
                        steradian_simd::sh::hvl::contributions_zonal(
                            &scene.hvls,
                            &em,
                            &zrx,
                            hz,
                            &mut scratch,
                            &mut out,
                        )
                        .expect("shapes");
                    }
                    black_box(&out);
                }
            });
            (
                n,
                ns_per(count, t[0]),
                ns_per(count, t[1]),
                gpu_ns,
                ns_per(count, tz[0]),
                ns_per(count, tz[1]),
            )
        })
        .collect()
}

/// Per built-in material: the committed table's shape and bytes, the truncation errors at
/// `θₒ = 45°` for band limits [3, 5, 7, 9, 11, 14], and the committed table's own error over
/// every view; each for no window, Hanning and Cesàro.
struct BrdfRow {
    name: &'static str,
    bands: usize,
    samples: usize,
    bytes: usize,
    truncation: [[f64; 6]; 3],
    /// Mean and largest of `brdf_sh::table_errors` over [`BRDF_VIEWS`] views.
    table: [[f64; 2]; 3],
}

/// Views at which the committed tables are checked: `θₒ = (i + ½)·90°/180`, between the
/// stored views and beyond the last one (where the lookup holds the last view).
const BRDF_VIEWS: usize = 180;

fn brdf_rows() -> Vec<BrdfRow> {
    use rayon::prelude::*;
    let limits = [3usize, 5, 7, 9, 11, 14];
    let windows = [Window::None, Window::Hanning, Window::Cesaro];
    brdf_sh::materials()
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let t = brdf_sh::committed(k);
            let (bands, samples) = (t.bands(), t.samples());
            let bytes =
                steradian_core::table::HEADER_LEN + 4 * samples * 2 * sh::brdf::stored(bands);
            let nodes = brdf_sh::Nodes::new(m.model.feature_angle(), brdf_sh::MAX_BANDS, 1);
            let (f, _, n2, _) = brdf_sh::project(&m.model, &nodes, std::f64::consts::FRAC_PI_4);
            let truncation = windows.map(|w| {
                let e =
                    brdf_sh::truncation_errors(&f, n2, brdf_sh::MAX_BANDS, |l, n| w.weight(l, n));
                limits.map(|n| e[n - 1])
            });
            let per_view: Vec<Vec<f64>> = (0..BRDF_VIEWS)
                .into_par_iter()
                .map(|i| {
                    let th = (i as f64 + 0.5) * std::f64::consts::FRAC_PI_2 / BRDF_VIEWS as f64;
                    brdf_sh::table_errors(&m.model, &t, th, &windows)
                })
                .collect();
            let table = core::array::from_fn(|w| {
                let e = per_view.iter().map(|v| v[w]);
                [
                    e.clone().sum::<f64>() / BRDF_VIEWS as f64,
                    e.fold(0.0, f64::max),
                ]
            });
            BrdfRow {
                name: m.name,
                bands,
                samples,
                bytes,
                truncation,
                table,
            }
        })
        .collect()
}

/// Per window: the most negative value (peak 1) of caps of 0.05–2.5 rad and the clamped
/// cosine over 2–40 bands.
fn window_rows() -> Vec<(&'static str, f64)> {
    let windows = [
        ("none", Window::None),
        ("Hanning", Window::Hanning),
        ("Lanczos", Window::Lanczos),
        ("sinc⁴", Window::Sinc { power: 4 }),
        ("pbrt damping λ = 0.005", Window::Damping { lambda: 0.005 }),
        ("Cesàro (C, 2)", Window::Cesaro),
    ];
    let ts: Vec<f64> = (0..=600).map(|i| -1.0 + i as f64 / 300.0).collect();
    windows
        .iter()
        .map(|(name, w)| {
            let mut worst = 0.0f64;
            for n in 2..=40 {
                let mut lobes: Vec<Vec<f64>> = [0.05f32, 0.3, 1.0, 2.5]
                    .iter()
                    .map(|&a| {
                        let mut z = vec![0.0f32; n];
                        sh::cap::zonal_into(a, n, &mut z).expect("shape");
                        z.iter().map(|&v| f64::from(v)).collect()
                    })
                    .collect();
                lobes.push(
                    (0..n)
                        .map(|l| sh::irradiance::clamped_cosine(l) / sh::convolve::funk_hecke(l))
                        .collect(),
                );
                for c in &lobes {
                    for &t in &ts {
                        let s = w.reconstruct_zonal(c, t);
                        worst = worst.min(s);
                    }
                }
            }
            (*name, worst)
        })
        .collect()
}

/// Environment projection: (width, height, bands, ms) on the procedural sky, and the EXR
/// files of `sky.exr` rendered back at 9 bands (radiance and irradiance).
#[allow(clippy::type_complexity)]
fn env_rows(
    opts: &Options,
) -> Result<(Vec<(usize, usize, usize, f64)>, Vec<(String, Vec<u8>)>), Box<dyn Error>> {
    use crate::env::{Equirect, Sky, sh as esh};
    let sky = Sky::default();
    let mut rows = Vec::new();
    for (w, h) in [(256usize, 128usize), (512, 256), (1024, 512)] {
        let data = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| {
                let d = esh::texel_direction(x, y, w, h).as_dvec3();
                sky.radiance(d).map(|v| v as f32)
            })
            .collect();
        let env = Equirect::new(w, h, data)?;
        for n in [3usize, 9, 30] {
            let t = median_time(opts.repeats.min(3), || {
                black_box(esh::project(&env, n).expect("bands"));
            });
            rows.push((w, h, n, t.as_secs_f64() * 1e3));
        }
    }
    let mut files = Vec::new();
    if let Ok(real) = Equirect::load(&crate::env::real_env_path()) {
        let c = esh::project(&real, 9)?;
        let (w, h) = (real.width().min(512), real.height().min(256));
        for (name, img) in [
            ("sh_sky_radiance_9.exr", esh::render_radiance(&c, w, h)?),
            ("sh_sky_irradiance_9.exr", esh::render_irradiance(&c, w, h)?),
        ] {
            let buf = image::Rgb32FImage::from_raw(
                w as u32,
                h as u32,
                img.data().iter().flatten().copied().collect(),
            )
            .ok_or("image size")?;
            let mut bytes = std::io::Cursor::new(Vec::new());
            image::DynamicImage::ImageRgb32F(buf)
                .write_to(&mut bytes, image::ImageFormat::OpenExr)?;
            files.push((name.to_string(), bytes.into_inner()));
        }
    }
    Ok((rows, files))
}

/// Coefficients per ns the recurrence's op count allows at `pairs` multiply–add pairs per
/// ns: three operations per coefficient (the table's note), two per pair.
fn limit(pairs: f64) -> f64 {
    2.0 * pairs / 3.0
}

/// The section.
pub fn section(opts: &Options) -> Result<Section, Box<dyn Error>> {
    // The SIMD evaluation's f64 lanes; one lane at a time is that divided by the lane
    // count (the same units).
    let lanes = steradian_simd::sh::SLICE_LANES;
    let rate = study::mul_add_rate();
    let rate_lane = rate / lanes as f64;
    let (mut gpu, gpu_note) = gpu::if_requested(opts.gpu);
    let eval = eval_rows(opts, &mut gpu);
    let hvl_ns = hvl_rows(opts, &mut gpu);
    drop(gpu);
    let rot = rotate_rows(opts);
    let caps = cap_rows(opts);
    let t1 = table1(opts);
    let brdf = brdf_rows();
    let windows = window_rows();
    let (env, files) = env_rows(opts)?;

    let mut html = String::new();
    let mut summary = String::new();
    writeln!(
        html,
        "<h3>Evaluation</h3><p>ns per direction, all n² functions; the plain f64 evaluation and \
         <code>sphrs</code> 0.2.2 on the same directions in the same run (taking turns). \
         Correctness: the largest relative departure from the addition theorem \
         Σ<sub>m</sub> Y<sub>l</sub><sup>m</sup>² = (2l+1)/4π over 64 directions (convention-free). \
         Multiply–add rate of this binary in the same run (eight independent chains on {lanes} \
         f64 lanes, the SIMD evaluation's): {simd:.2} pairs/ns, {scalar:.2} one lane at a time (the same units). A step of the recurrence \
         is three multiplications and a subtraction per order and two output products per \
         (l, ±m) pair, three operations per coefficient, so with a pair counted as two \
         operations the op count allows {ls:.2} coefficients/ns on one lane and {lv:.2} on {lanes} \
         (conversions to f32 and stores not counted). The compiler packs the scalar kernel's \
         four chains into vector registers, so it can pass the one-lane limit.</p>",
        simd = rate,
        scalar = rate_lane,
        ls = limit(rate_lane),
        lv = limit(rate)
    )?;
    writeln!(
        html,
        "<p>wgpu: {gpu_note} (f32, up to {} bands, upload and read-back included).</p>",
        wgsl::SH_EVAL_MAX_BANDS
    )?;
    html.push_str("<table><tr><th>bands</th><th>scalar</th><th>SIMD</th><th>wgpu</th><th>plain f64</th><th>sphrs</th><th>plain / scalar</th><th>plain / SIMD</th><th>scalar / SIMD</th><th>coeff/ns scalar (of one-lane limit)</th><th>coeff/ns SIMD (of the SIMD lanes' limit)</th><th>identity error: ours, plain, sphrs</th></tr>");
    for r in &eval {
        let nn = (r.bands * r.bands) as f64;
        let (cs, cv) = (nn / r.ns[0], nn / r.ns[1]);
        writeln!(
            html,
            "<tr><td>{}</td><td>{:.1}</td><td>{:.1}</td><td>{}</td><td>{:.1}</td><td>{:.1}</td><td>{:.2}×</td><td>{:.2}×</td><td>{:.2}×</td><td>{:.2} ({:.0} %)</td><td>{:.2} ({:.0} %)</td><td>{:.1e}, {:.1e}, {:.1e}</td></tr>",
            r.bands,
            r.ns[0],
            r.ns[1],
            r.gpu_ns.map_or("—".to_string(), |g| format!("{g:.1}")),
            r.ns[2],
            r.ns[3],
            r.ns[2] / r.ns[0],
            r.ns[2] / r.ns[1],
            r.ns[0] / r.ns[1],
            cs,
            100.0 * cs / limit(rate_lane),
            cv,
            100.0 * cv / limit(rate),
            r.identity[0],
            r.identity[2],
            r.identity[3]
        )?;
        writeln!(
            summary,
            "sh-eval {:2} bands: scalar {:.1} ns, SIMD {:.1} ns ({:.2}× scalar), wgpu {}, plain f64 {:.1} ns ({:.2}× scalar, {:.2}× SIMD), sphrs {:.1} ns (identity error {:.1e})",
            r.bands,
            r.ns[0],
            r.ns[1],
            r.ns[0] / r.ns[1],
            r.gpu_ns.map_or("—".to_string(), |g| format!("{g:.1} ns")),
            r.ns[2],
            r.ns[2] / r.ns[0],
            r.ns[2] / r.ns[1],
            r.ns[3],
            r.identity[3]
        )?;
    }
    html.push_str("</table>");

    html.push_str("<h3>Rotation</h3><table><tr><th>bands</th><th>ZXZXZ per vector (ns)</th><th>SIMD ZXZXZ per vector (ns)</th><th>SIMD / scalar ZXZXZ</th><th>operator build (ns)</th><th>operator apply per vector (ns)</th><th>SIMD operator apply per vector (ns)</th><th>vectors to break even</th></tr>");
    for r in &rot {
        let even = r.build_ns / (r.zxzxz_ns - r.apply_ns).max(1e-9);
        writeln!(
            html,
            "<tr><td>{}</td><td>{:.0}</td><td>{:.0}</td><td>{:.2}×</td><td>{:.0}</td><td>{:.0}</td><td>{:.0}</td><td>{}</td></tr>",
            r.bands,
            r.zxzxz_ns,
            r.simd_zxzxz_ns,
            r.zxzxz_ns / r.simd_zxzxz_ns,
            r.build_ns,
            r.apply_ns,
            r.simd_apply_ns,
            if r.zxzxz_ns > r.apply_ns {
                format!("{even:.1}")
            } else {
                "never".into()
            }
        )?;
    }
    html.push_str("</table>");
    writeln!(
        summary,
        "sh-rotate: {}",
        rot.iter()
            .map(|r| format!(
                "{} bands {:.0} ns (ZXZXZ), SIMD {:.0} ns ({:.2}× scalar)",
                r.bands,
                r.zxzxz_ns,
                r.simd_zxzxz_ns,
                r.zxzxz_ns / r.simd_zxzxz_ns
            ))
            .collect::<Vec<_>>()
            .join(", ")
    )?;

    html.push_str("<h3>Cap projection (zonal coefficients and their rotation to the axis)</h3><table><tr><th>bands</th><th>ns per cap, scalar</th><th>ns per cap, SIMD</th><th>SIMD / scalar</th><th>caps per second (SIMD)</th></tr>");
    for (n, ns, simd) in &caps {
        writeln!(
            html,
            "<tr><td>{n}</td><td>{ns:.1}</td><td>{simd:.1}</td><td>{:.2}×</td><td>{:.2e}</td></tr>",
            ns / simd,
            1e9 / simd
        )?;
    }
    html.push_str("</table>");

    html.push_str(
        "<h3>HVL shading (the paper's Table 1)</h3><p>A spot light (90° field of view, \
         10 W/sr) 3 above a Lambertian floor (albedo 0.8) places M HVLs by a square \
         reflective shadow map, radius r2 (eq. 25, k = 1); 48 receivers on a wall beside it \
         seen from one eye. Time: all M contributions per shading point, scalar, smoothstep H, \
         Phong 30 receiver. Error: relative RMS over the receivers against the exact integral \
         of the same spherical lights (steradian_reference::sh::hvl). The Lambert receiver's \
         table has 9 bands here (the committed one has the 5 its 5 % target needs).</p>\
         <table><tr><th>M</th><th>bands</th><th>µs per point</th><th>error, Lambert</th><th>error, Phong 30</th></tr>",
    );
    for (m, n, us, e) in &t1.rows {
        writeln!(
            html,
            "<tr><td>{m}</td><td>{n}</td><td>{us:.1}</td><td>{:.4}</td><td>{:.4}</td></tr>",
            e[0], e[1]
        )?;
    }
    html.push_str("</table>");
    if let Some((m, n, us, e)) = t1.rows.last() {
        writeln!(
            summary,
            "HVL: {m} lights at {n} bands: {us:.1} µs per point, error {:.3} (Lambert) {:.3} (Phong 30)",
            e[0], e[1]
        )?;
        let [s, x] = t1.horizon;
        writeln!(
            html,
            "<p>The horizon term at M = {m}, {n} bands: error with the smoothstep H {:.4} \
             (Lambert) and {:.4} (Phong 30); with the exact fraction of the cap above the \
             receiver's horizon instead, {:.4} and {:.4}.</p>",
            s[0], s[1], x[0], x[1]
        )?;
        writeln!(
            summary,
            "HVL horizon term at {m} lights, {n} bands: smoothstep {:.4} / {:.4}, exact {:.4} / {:.4} (Lambert / Phong 30)",
            s[0], s[1], x[0], x[1]
        )?;
    }
    html.push_str(
        "<h3>HVL contributions per second</h3><p>One contribution (eq. 19–22: the cap toward \
         the HVL projected, rotated and dotted with the receiver's F, the emission F′·Y(−ω)), \
         the 400 HVLs of the M = 400 scene at one Phong 30 receiver, smoothstep H; scalar \
         and SIMD (four HVLs per pass, bit-identical) taking turns; wgpu (wgsl::SH_HVL, one \
         contribution per invocation, f32, upload and read-back included). Zonal: the same \
         HVLs at a Lambertian receiver (the m = 0 entries of the Lambert table, at most its 5 \
         bands), contribution_zonal against the SIMD contributions_zonal (eight HVLs per \
         pass, within ZONAL_TOL), taking turns.</p>\
         <table><tr><th>bands</th><th>ns, scalar</th><th>ns, SIMD</th><th>ns, wgpu</th><th>SIMD / scalar</th><th>contributions per second (SIMD)</th><th>zonal ns, scalar</th><th>zonal ns, SIMD</th><th>zonal SIMD / scalar</th></tr>",
    );
    for (n, sc, si, gp, zs, zi) in &hvl_ns {
        writeln!(
            html,
            "<tr><td>{n}</td><td>{sc:.1}</td><td>{si:.1}</td><td>{}</td><td>{:.2}×</td><td>{:.2e}</td><td>{zs:.1}</td><td>{zi:.1}</td><td>{:.2}×</td></tr>",
            gp.map_or("—".to_string(), |g| format!("{g:.1}")),
            sc / si,
            1e9 / si,
            zs / zi
        )?;
        writeln!(
            summary,
            "HVL contribution at {n} bands: scalar {sc:.1} ns, SIMD {si:.1} ns ({:.2}×), wgpu {}; zonal receiver: scalar {zs:.1} ns, SIMD {zi:.1} ns ({:.2}×)",
            sc / si,
            gp.map_or("—".to_string(), |g| format!("{g:.1} ns")),
            zs / zi
        )?;
    }
    html.push_str("</table>");

    html.push_str("<h3>BRDF SH tables</h3><p>Relative L2 error of F against the BRDF: the truncation error at θₒ = 45° per band limit (Parseval on 16 bands of coefficients), and the committed table's own error (its bands, interpolated between its views, f32) over 180 views θₒ = (i + ½)·0.5°, mean and largest; without a window, Hanning, Cesàro. The generator picks the fewest bands with a 45° truncation error of at most 5 % and the fewest views with a mid-view interpolation error of at most 0.5 %.</p><table><tr><th>material</th><th>table (bands × views, bytes)</th><th>window</th><th>3</th><th>5</th><th>7</th><th>9</th><th>11</th><th>14</th><th>table, mean over views</th><th>table, largest</th></tr>");
    for r in &brdf {
        for (k, w) in ["none", "Hanning", "Cesàro"].iter().enumerate() {
            write!(
                html,
                "<tr><td>{}</td><td>{} × {}, {}</td><td>{w}</td>",
                r.name, r.bands, r.samples, r.bytes
            )?;
            for e in r.truncation[k] {
                write!(html, "<td>{e:.3}</td>")?;
            }
            write!(
                html,
                "<td>{:.4}</td><td>{:.4}</td></tr>",
                r.table[k][0], r.table[k][1]
            )?;
        }
        writeln!(
            summary,
            "BRDF table {}: {} bands × {} views, error over every view mean {:.4}, largest {:.4} (no window)",
            r.name, r.bands, r.samples, r.table[0][0], r.table[0][1]
        )?;
    }
    html.push_str("</table>");

    html.push_str("<h3>Windows</h3><p>The most negative reconstructed value (the lobes peak at 1) of caps of 0.05, 0.3, 1 and 2.5 rad and of max(cos θ, 0), over 2–40 bands.</p><table><tr><th>window</th><th>most negative value</th></tr>");
    for (name, v) in &windows {
        writeln!(html, "<tr><td>{name}</td><td>{v:.4}</td></tr>")?;
    }
    html.push_str("</table>");

    writeln!(
        html,
        "<h3>Environment projection</h3><p>Exact texel integrals (separable: Gauss–Legendre per row, \
         closed-form column integrals), rows in parallel on {} threads, the procedural sky. \
         <code>sky.exr</code> rendered back at 9 bands: {}.</p>\
         <table><tr><th>image</th><th>texels</th><th>bands</th><th>ms</th></tr>",
        rayon::current_num_threads(),
        files
            .iter()
            .map(|(n, _)| format!("<a href=\"{n}\">{n}</a>"))
            .collect::<Vec<_>>()
            .join(", ")
    )?;
    for (w, h, n, ms) in &env {
        writeln!(
            html,
            "<tr><td>{w} × {h}</td><td>{}</td><td>{n}</td><td>{ms:.2}</td></tr>",
            w * h
        )?;
    }
    html.push_str("</table>");
    if let Some((w, h, n, ms)) = env.last() {
        writeln!(
            summary,
            "env projection: {w} × {h} onto {n} bands in {ms:.1} ms"
        )?;
    }

    let data = json!({
        "gpu": gpu_note,
        "env_projection": env.iter().map(|(w, h, n, ms)| json!({
            "width": w, "height": h, "bands": n, "ms": ms,
        })).collect::<Vec<_>>(),
        "mul_add_pairs_per_ns": rate_lane,
        "mul_add_pairs_per_ns_simd": rate,
        "simd_lanes": lanes,
        "eval": eval.iter().map(|r| json!({
            "bands": r.bands,
            "ns_per_dir": {"scalar": r.ns[0], "simd": r.ns[1], "wgpu": r.gpu_ns, "plain_f64": r.ns[2], "sphrs": r.ns[3]},
            "identity_error": {"ours": r.identity[0], "plain_f64": r.identity[2], "sphrs": r.identity[3]},
        })).collect::<Vec<_>>(),
        "rotate": rot.iter().map(|r| json!({
            "bands": r.bands, "zxzxz_ns": r.zxzxz_ns, "simd_zxzxz_ns": r.simd_zxzxz_ns, "operator_build_ns": r.build_ns,
            "operator_apply_ns": r.apply_ns, "simd_operator_apply_ns": r.simd_apply_ns,
        })).collect::<Vec<_>>(),
        "cap_ns": caps.iter().map(|(n, ns, simd)| json!({"bands": n, "ns": ns, "simd_ns": simd})).collect::<Vec<_>>(),
        "hvl_ns": hvl_ns.iter().map(|(n, sc, si, gp, zs, zi)| json!({"bands": n, "scalar_ns": sc, "simd_ns": si, "wgpu_ns": gp, "zonal_scalar_ns": zs, "zonal_simd_ns": zi})).collect::<Vec<_>>(),
        "hvl_table1": t1.rows.iter().map(|(m, n, us, e)| json!({
            "hvls": m, "bands": n, "us_per_point": us, "error_lambert": e[0], "error_phong30": e[1],
        })).collect::<Vec<_>>(),
        "hvl_horizon": {
            "smoothstep": {"error_lambert": t1.horizon[0][0], "error_phong30": t1.horizon[0][1]},
            "exact": {"error_lambert": t1.horizon[1][0], "error_phong30": t1.horizon[1][1]},
        },
        "brdf_tables": brdf.iter().map(|r| json!({
            "material": r.name, "bands": r.bands, "views": r.samples, "bytes": r.bytes,
            "band_limits": [3, 5, 7, 9, 11, 14],
            "error": {"none": r.truncation[0], "hanning": r.truncation[1], "cesaro": r.truncation[2]},
            "table_error": {
                "none": {"mean": r.table[0][0], "max": r.table[0][1]},
                "hanning": {"mean": r.table[1][0], "max": r.table[1][1]},
                "cesaro": {"mean": r.table[2][0], "max": r.table[2][1]},
            },
        })).collect::<Vec<_>>(),
        "windows": windows.iter().map(|(n, v)| json!({"window": n, "most_negative": v})).collect::<Vec<_>>(),
    });
    Ok(Section {
        id: "sh",
        title: "Spherical harmonics and Harmonics Virtual Lights".into(),
        summary,
        html,
        data,
        files,
    })
}
