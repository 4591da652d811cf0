//! Report section: RSL shading accuracy against the exact integral (the paper's Figures
//! 9–10: relative L2 error for K = 10, 30, 60, 100), the eq. 13 bound, the share of each
//! approximate factor (harness `shade` factor analysis), and throughput of the scalar,
//! SIMD and wgpu kernels in RSL evaluations per second next to the paper's ~19 M/s.

use std::error::Error;
use std::fmt::Write as _;
use std::hint::black_box;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use steradian_core::lobe::brdf::Lambert;
use steradian_core::rsl::shade::{self, ShadeLight, VdtQuery, VdtVisibility};

use super::Options;
use super::section::Section;
use super::timing::{median_time_for, median_times_in_turns, per_second, timed};
use crate::backend::gpu::{Custom, try_gpu};
use crate::env::decompose::{Decomposition, Objective, Options as DecOptions, PAPER_KS, decompose};
use crate::env::{self, CubeMap};
use crate::kernels::Columns;
use crate::shade::{self as sh, Samples, Scene, Settings, VARIANTS, Variant};

/// The paper's Figure 9 (buddha in Kitchen) and Figure 10 (teapot in Grace Cathedral).
const PAPER: [(usize, f64, f64); 4] = [
    (10, 0.72, 0.79),
    (30, 0.35, 0.49),
    (60, 0.11, 0.03),
    (100, 0.07, 0.02),
];
/// The paper's throughput: 60k vertices × 30 RSLs at 10.8 fps (2005 GPU).
const PAPER_EVALS_PER_S: f64 = 60_000.0 * 30.0 * 10.8;
/// VDT side of the accuracy study.
const VDT_N: usize = 256;
/// BRDF SAT target of the accuracy study.
const SAT_TARGET: f32 = 0.005;

/// Sub-texels per cube-texel side of the reference (8 × 8 is within 0.06 % of 16 × 16;
/// 2 × 2 is 0.35–0.44 % away: `reference_converges_with_sub_texels` in
/// `harness/tests/shade.rs`).
const SUB: usize = 8;
/// The merge objectives compared, the default first.
const OBJECTIVES: [Objective; 2] = [Objective::Bound, Objective::Paper];
/// Least total time of each CPU throughput measurement at the default `--n`, in ms
/// ([`Options::scaled`]).
const CPU_MIN_MS: usize = 400;
/// Least total time of the wgpu throughput measurement at the default `--n`, in ms.
const GPU_MIN_MS: usize = 600;
/// Copies of the point set in the wgpu dispatch at the default `--n`.
const GPU_COPIES: usize = 64;

/// The errors of one decomposition.
#[derive(Clone, Debug)]
pub struct Row {
    /// Merge objective.
    pub objective: Objective,
    /// Regions.
    pub k: usize,
    /// Relative L2 per variant.
    pub errors: Vec<f64>,
    /// Eq. 13 summed over the regions, as a relative L2.
    pub bound: f64,
}

/// The accuracy study of one environment.
#[derive(Clone, Debug)]
pub struct EnvResult {
    /// Name.
    pub name: String,
    /// One row per objective and `K`.
    pub rows: Vec<Row>,
    /// Shading points.
    pub points: usize,
}

fn study(name: &str, cube: &CubeMap) -> Result<EnvResult, Box<dyn Error>> {
    let mut decs = Vec::new();
    for objective in OBJECTIVES {
        let mut d = decompose(
            cube,
            &DecOptions {
                objective,
                ..DecOptions::quiet(&PAPER_KS)
            },
        )?;
        d.reverse();
        decs.extend(d);
    }
    let refs: Vec<&Decomposition> = decs.iter().collect();
    let brdf = Lambert::new(0.8)?;
    let sat = sh::fit_sat(&brdf, &refs, SAT_TARGET);
    let scene = Scene::standard(12);
    let vdts = sh::par_map(&scene.points, |p| sh::point_vdt(&scene, p, VDT_N));
    let samples = Samples::new(cube, SUB);
    let setup = sh::Setup {
        cube,
        samples: &samples,
        scene: &scene,
        brdf: &brdf,
        sat: &sat,
        vdts: &vdts,
    };
    let a = sh::analyse(&setup, &refs, Settings::default());
    Ok(EnvResult {
        name: name.to_string(),
        rows: decs
            .iter()
            .enumerate()
            .map(|(d, dec)| Row {
                objective: dec.merge,
                k: dec.k,
                errors: VARIANTS.iter().map(|&v| a.error(d, v)).collect(),
                bound: a.bound(d),
            })
            .collect(),
        points: scene.points.len(),
    })
}

/// RSL evaluations/s of each backend (wgpu's, or why not), and the workload.
#[derive(Clone, Debug)]
pub struct Throughput {
    /// Scalar kernel.
    pub scalar: f64,
    /// SIMD kernel.
    pub simd: f64,
    /// wgpu kernel, or why not.
    pub gpu: Result<f64, String>,
    /// Moments kernel, scalar.
    pub moments: f64,
    /// Moments kernel, SIMD.
    pub moments_simd: f64,
    /// Shading points.
    pub points: usize,
    /// Lights.
    pub lights: usize,
    /// Copies of the points in the wgpu dispatch.
    pub gpu_copies: usize,
}

/// Everything the section measures.
#[derive(Clone, Debug)]
pub struct ShadeResults {
    /// The default sky's accuracy study.
    pub sky: EnvResult,
    /// The real environment's.
    pub real: EnvResult,
    /// Throughput.
    pub throughput: Throughput,
}

/// Throughput in RSL evaluations per second: scalar, SIMD, wgpu (or why not).
fn throughput(opts: &Options) -> Result<Throughput, Box<dyn Error>> {
    let cube = env::default_sky(32)?;
    let decs = decompose(&cube, &DecOptions::quiet(&[30]))?;
    let lights: Vec<ShadeLight> = decs[0].rsls()?.iter().map(ShadeLight::from).collect();
    let brdf = Lambert::new(0.8)?;
    let refs: Vec<&Decomposition> = decs.iter().collect();
    let sat = sh::fit_sat(&brdf, &refs, SAT_TARGET);
    let scene = Scene::standard(12);
    let vdts = sh::par_map(&scene.points, |p| sh::point_vdt(&scene, p, 64));
    let evals = scene.points.len() * lights.len();
    let cpu_min = Duration::from_millis(opts.scaled(CPU_MIN_MS) as u64);
    let moments: Vec<_> = sh::par_map(&scene.points, |p| sh::point_moments(&scene, p, 64));
    // The four CPU kernels take turns (scalar eq. 5, moments scalar, moments SIMD, eq. 5
    // SIMD), so that a noisy machine slows them alike and their ratios stay meaningful;
    // rounds until the scalar kernel's runs fill `cpu_min` (at least `--repeats`, at most 50).
    let run = |i: usize| match i {
        0 => {
            for (p, v) in scene.points.iter().zip(&vdts) {
                if let Ok(vis) = VdtVisibility::new(v.view(), VdtQuery::Gradient) {
                    black_box(shade::shade(&p.frame, p.wo, &sat, &vis, black_box(&lights)));
                }
            }
        }
        1 => {
            for (p, m) in scene.points.iter().zip(&moments) {
                black_box(shade::shade_moments(
                    &p.frame,
                    p.wo,
                    &sat,
                    m,
                    black_box(&lights),
                ));
            }
        }
        2 => {
            black_box(sh::shade_points_moments_simd(
                &scene,
                &sat,
                &moments,
                black_box(&lights),
            ));
        }
        _ => {
            black_box(sh::shade_points_simd(
                &scene,
                &sat,
                &vdts,
                black_box(&lights),
                VdtQuery::Gradient,
            ));
        }
    };
    let (_, once) = timed(|| run(0));
    let rounds = (cpu_min.as_secs_f64() / once.as_secs_f64().max(1e-9)).ceil() as usize;
    let rounds = rounds.clamp(opts.repeats.max(3), opts.repeats.max(50));
    let t = median_times_in_turns(rounds, 4, run);
    let (t_scalar, t_moments, t_moments_simd, t_simd) = (t[0], t[1], t[2], t[3]);
    let gpu_copies = opts.scaled(GPU_COPIES);
    let gpu = if !opts.gpu {
        Err("not requested".to_string())
    } else {
        match try_gpu() {
            Err(e) => Err(format!("no adapter: {e}")),
            Ok(mut g) => {
                // Copies of the point set (each row names its point's VDT), one dispatch.
                let table = sh::gpu_table(&sat, &vdts, &lights, VdtQuery::Gradient)
                    .ok_or("anisotropic SAT")?;
                let base = sh::gpu_input(&scene);
                let reps = gpu_copies;
                let n = base.n * reps;
                let mut input = Columns::zeros(base.arity, n);
                for c in 0..base.arity {
                    for r in 0..reps {
                        input.data[c * n + r * base.n..c * n + (r + 1) * base.n]
                            .copy_from_slice(&base.data[c * base.n..(c + 1) * base.n]);
                    }
                }
                let mut out = Columns::zeros(3, n);
                let custom = Custom {
                    label: "rsl-shade",
                    source: steradian_core::wgsl::SHADE,
                    table: Some(&table),
                };
                match g.run_custom(&custom, &input, &mut out) {
                    Err(e) => Err(format!("kernel failed: {e}")),
                    Ok(()) => {
                        let min = Duration::from_millis(opts.scaled(GPU_MIN_MS) as u64);
                        let t = median_time_for(opts.repeats, min, || {
                            let _ = g.run_custom(&custom, &input, &mut out);
                        });
                        Ok(per_second(n * lights.len(), t))
                    }
                }
            }
        }
    };
    Ok(Throughput {
        scalar: per_second(evals, t_scalar),
        simd: per_second(evals, t_simd),
        gpu,
        moments: per_second(evals, t_moments),
        moments_simd: per_second(evals, t_moments_simd),
        points: scene.points.len(),
        lights: lights.len(),
        gpu_copies,
    })
}

/// Runs the section's measurements.
pub fn measure(opts: &Options) -> Result<ShadeResults, Box<dyn Error>> {
    let bar = ProgressBar::new(3).with_style(
        ProgressStyle::with_template("shade    {bar:30} {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message("default sky");
    let sky = study("default sky", &env::default_sky(32)?)?;
    bar.inc(1);
    bar.set_message("sky.exr");
    let real = study(
        "harness/data/sky.exr",
        &env::load_cubemap(&env::real_env_path(), 32)?,
    )?;
    bar.inc(1);
    bar.set_message("throughput");
    let throughput = throughput(opts)?;
    bar.inc(1);
    bar.finish_and_clear();
    Ok(ShadeResults {
        sky,
        real,
        throughput,
    })
}

/// The section of measured results.
pub fn render(r: &ShadeResults) -> Section {
    let (sky, real) = (&r.sky, &r.real);
    let Throughput {
        scalar,
        simd,
        ref gpu,
        moments,
        moments_simd,
        points: np,
        lights: nk,
        gpu_copies,
    } = r.throughput;

    let vi = |v: Variant| VARIANTS.iter().position(|&x| x == v).unwrap_or(0);
    let mut html = String::new();
    let mut summary = String::new();
    let _ = writeln!(
        html,
        "<p>Relative L2 error (RGB, over {} shading points: ground plane and a sphere, three \
         sphere occluders) of the RSL kernel (BRDF SAT × VDT, gradient query) against the exact \
         integral of L·ρ·V over every cube-map texel (6 × 32², {SUB} × {SUB} sub-texels, exact \
         ray–sphere visibility); Lambert albedo 0.8, BRDF SAT fitted to {SAT_TARGET}, \
         {VDT_N}² VDT per point. Eq. 13 is the paper's multi-product bound summed over the \
         regions (an upper bound on the <i>multi-product</i> column, checked per point by \
         <code>harness/tests/shade.rs</code>). The middle columns swap the approximate factors \
         for exact ones one at a time (harness <code>shade::Variant</code>). Two merge \
         objectives (<code>env::decompose::Objective</code>): <i>Bound</i>, the increase of \
         the modelled eq. 13 bound (default), and <i>Paper</i>, the merged region's eq. 7 \
         objective.</p>",
        sky.points
    );
    for e in [sky, real] {
        let _ = writeln!(
            html,
            "<h3>{}</h3><table><tr><th>merge</th><th>K</th><th>kernel</th><th>kernel, eq. 9 VDT</th>\
             <th>eq. 13 bound</th><th>multi-product (true regions)</th><th>square, light only</th>\
             <th>square, exact ρ̄ and V̄</th><th>SAT ρ̄, exact V̄</th><th>exact ρ̄, VDT V̄</th>\
             <th>linear light over the square, exact ρV</th>\
             <th>moments kernel</th><th>paper Fig. 9 / 10</th></tr>",
            e.name
        );
        for row in &e.rows {
            let (k, er, obj) = (row.k, &row.errors, row.objective);
            let p = PAPER.iter().find(|x| x.0 == k);
            let _ = writeln!(
                html,
                "<tr><td>{obj:?}</td><td>{k}</td><td><b>{:.3} %</b></td><td>{:.3} %</td><td>{:.3} %</td>\
                 <td>{:.3} %</td><td>{:.3} %</td><td>{:.3} %</td><td>{:.3} %</td><td>{:.3} %</td>\
                 <td>{:.3} %</td><td><b>{:.3} %</b></td><td>{}</td></tr>",
                100.0 * er[vi(Variant::Kernel)],
                100.0 * er[vi(Variant::KernelEq9)],
                100.0 * row.bound,
                100.0 * er[vi(Variant::MultiProduct)],
                100.0 * er[vi(Variant::SquareJoint)],
                100.0 * er[vi(Variant::SquareExact)],
                100.0 * er[vi(Variant::SatExactV)],
                100.0 * er[vi(Variant::ExactBrdfVdt)],
                100.0 * er[vi(Variant::SquareLinear)],
                100.0 * er[vi(Variant::Moments)],
                p.map_or(String::new(), |p| format!("{:.2} % / {:.2} %", p.1, p.2)),
            );
            let _ = writeln!(
                summary,
                "shade {:<22} {:<5} K = {k:3}: error {:.3} % (eq. 9 VDT {:.3} %, moments kernel {:.3} %, exact over the squares {:.3} % uniform / {:.3} % linear light), eq. 13 bound {:.3} % (multi-product {:.3} %)",
                e.name,
                format!("{obj:?}"),
                100.0 * er[vi(Variant::Kernel)],
                100.0 * er[vi(Variant::KernelEq9)],
                100.0 * er[vi(Variant::Moments)],
                100.0 * er[vi(Variant::SquareJoint)],
                100.0 * er[vi(Variant::SquareLinear)],
                100.0 * row.bound,
                100.0 * er[vi(Variant::MultiProduct)],
            );
        }
        let _ = writeln!(html, "</table>");
    }
    let gpu_s = match gpu {
        Ok(x) => format!("{:.1} M/s", x / 1e6),
        Err(e) => format!("n/a ({e})"),
    };
    let _ = writeln!(
        html,
        "<h3>Throughput</h3><p>{np} points × K = {nk} RSLs, Lambert, 64² VDTs, gradient query \
         (wgpu: {gpu_copies} copies of the points in one dispatch, full round trip including the table \
         upload).</p><table><tr><th>backend</th><th>RSL evaluations/s</th><th>vs scalar</th>\
         <th>vs paper (19.4 M/s, 2005 GPU)</th></tr>\
         <tr><td>scalar</td><td>{:.1} M/s</td><td>1</td><td>{:.2}</td></tr>\
         <tr><td>SIMD (8 points per call)</td><td>{:.1} M/s</td><td>{:.2}</td><td>{:.2}</td></tr>\
         <tr><td>wgpu</td><td>{gpu_s}</td><td>{}</td><td>{}</td></tr>\
         <tr><td>moments kernel, scalar (64² moment tables)</td><td>{:.1} M/s</td><td>{:.2}</td><td>{:.2}</td></tr>\
         <tr><td>moments kernel, SIMD (8 points per call)</td><td>{:.1} M/s</td><td>{:.2}</td><td>{:.2}</td></tr></table>",
        scalar / 1e6,
        scalar / PAPER_EVALS_PER_S,
        simd / 1e6,
        simd / scalar,
        simd / PAPER_EVALS_PER_S,
        gpu.as_ref()
            .map_or("—".into(), |g| format!("{:.2}", g / scalar)),
        gpu.as_ref()
            .map_or("—".into(), |g| format!("{:.2}", g / PAPER_EVALS_PER_S)),
        moments / 1e6,
        moments / scalar,
        moments / PAPER_EVALS_PER_S,
        moments_simd / 1e6,
        moments_simd / scalar,
        moments_simd / PAPER_EVALS_PER_S,
    );
    let _ = writeln!(
        summary,
        "shade throughput (RSL evals/s): scalar {:.1} M, SIMD {:.1} M ({:.2}× scalar), wgpu {gpu_s}, moments kernel scalar {:.1} M ({:.2}× scalar), SIMD {:.1} M ({:.2}× its scalar); paper 19.4 M",
        scalar / 1e6,
        simd / 1e6,
        simd / scalar,
        moments / 1e6,
        moments / scalar,
        moments_simd / 1e6,
        moments_simd / moments,
    );
    let env_json = |e: &EnvResult| {
        json!({
            "name": e.name,
            "points": e.points,
            "sub_texels": SUB,
            "variants": VARIANTS.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>(),
            "rows": e.rows.iter().map(|r| json!({
                "objective": format!("{:?}", r.objective),
                "k": r.k,
                "bound_eq13": r.bound,
                "errors": r.errors,
            })).collect::<Vec<_>>(),
        })
    };
    Section {
        id: "shade",
        title: "RSL shading: accuracy per K and throughput".into(),
        summary,
        html,
        data: json!({
            "environments": [env_json(sky), env_json(real)],
            "paper": PAPER.iter().map(|p| json!({"k": p.0, "fig9": p.1, "fig10": p.2})).collect::<Vec<_>>(),
            "throughput": {
                "scalar": scalar, "simd": simd, "moments_scalar": moments,
                "moments_simd": moments_simd,
                "gpu": gpu.as_ref().ok(),
                "paper": PAPER_EVALS_PER_S,
                "points": np, "k": nk,
            },
        }),
        files: Vec::new(),
    }
}

/// The report section.
pub fn section(opts: &Options) -> Result<Section, Box<dyn Error>> {
    Ok(render(&measure(opts)?))
}
