//! The lobe-product section: what each byte of table buys. Integral error against the
//! exact f64 product integral and scalar throughput for tables of several resolutions and
//! for the spherical-Gaussian closed form (no table); the relative L2 shape error of the
//! result lobe for each fit; SIMD and wgpu throughput of the built-in table.

use std::error::Error;
use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;
use std::hint::black_box;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use steradian_core::lobe::CosineLobe;
use steradian_core::lobe::product::{self, ProductFit, ProductTable};

use super::Options;
use super::plot::{Axis, Chart, Pt, Scale, Series};
use super::section::Section;
use super::timing::{median_times_in_turns, per_second, timed};
use crate::generate::lobe_product;
use crate::product::canonical_lobes;
use crate::reference::product::{coplanar_triple, ln_product_integral, product_integral};
use crate::rng::Rng;

/// Seed of this section's inputs (not the generator's grid: these points are unseen).
const SEED: u64 = 0x10be_9a0d;
/// Points for the integral error.
const ERROR_POINTS: usize = 4000;
/// Points for the shape error.
const SHAPE_POINTS: usize = 800;
/// Products per timed run at the default `--n` ([`Options::scaled`]).
const SPEED_N: usize = 1 << 15;
/// Table resolutions generated at run time, besides the built-in one.
const RESOLUTIONS: [(usize, usize); 3] = [(12, 16), (24, 32), (40, 64)];

/// `e = 0` with probability 5 %, else log-uniform in `[1e−3, 1e5]`.
pub fn exponent(rng: &mut Rng) -> f32 {
    if rng.unit() < 0.05 {
        0.0
    } else {
        rng.log_range(1e-3, 1e5) as f32
    }
}

/// Relative errors of the result's integral where `I ≥ 1e−6·min(∫c1, ∫c2)`.
fn integral_errors(
    table: &ProductTable<'_>,
    fit: ProductFit,
    points: &[(f32, f32, f32, f64)],
) -> Vec<f64> {
    let mut errs: Vec<f64> = points
        .iter()
        .filter_map(|&(e1, e2, a, ln_exact)| {
            let min_int = TAU / (e1.max(e2) as f64 + 1.0);
            let exact = ln_exact.exp();
            (exact >= 1e-6 * min_int).then(|| {
                let (l1, l2) = canonical_lobes(e1, e2, a);
                let r = product::product_with(table, fit, &l1, &l2);
                let got = TAU * r.scale() as f64 / (r.exponent() as f64 + 1.0);
                (got / exact - 1.0).abs()
            })
        })
        .collect();
    errs.sort_by(f64::total_cmp);
    errs
}

fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// Relative L2 distance `‖c_r − c1·c2‖/‖c1·c2‖` of a product lobe (unit lobes, canonical
/// configuration), from exact one-dimensional integrals.
pub fn shape_error(e1: f32, e2: f32, alpha: f32, r: &CosineLobe) -> f64 {
    let (e1d, e2d, ad) = (e1 as f64, e2 as f64, alpha as f64);
    let beta = (r.axis().x as f64).atan2(r.axis().z as f64);
    let (p, er) = (r.scale() as f64, r.exponent() as f64);
    let c = product_integral(2.0 * e1d, 2.0 * e2d, ad);
    let a = p * p * TAU / (2.0 * er + 1.0);
    let b = p * coplanar_triple(e1d, e2d, ad, er, beta.clamp(0.0, ad));
    ((a - 2.0 * b + c).max(0.0) / c).sqrt()
}

/// Relative error of `∫ c_r·c3` against the exact `∫ c1·c2·c3` for a third unit lobe `c3`
/// (exponent `e3`) on the same great circle at angle `gamma` from `a1` (toward `a2`):
/// the rendering error the fit causes when its result is multiplied once more.
pub fn third_lobe_error(
    e1: f32,
    e2: f32,
    alpha: f32,
    r: &CosineLobe,
    e3: f64,
    gamma: f64,
) -> Option<f64> {
    let (e1d, e2d, ad) = (e1 as f64, e2 as f64, alpha as f64);
    let exact = coplanar_triple(e1d, e2d, ad, e3, gamma);
    let beta = (r.axis().x as f64).atan2(r.axis().z as f64);
    let approx = r.scale() as f64 * product_integral(r.exponent() as f64, e3, (gamma - beta).abs());
    (exact > 1e-6 * TAU / (e1.max(e2) as f64 + 1.0).max(e3 + 1.0) && exact.is_finite())
        .then(|| (approx / exact - 1.0).abs())
}

/// One table (or the closed form) of the section: its integral error and scalar speed.
#[derive(Clone, Debug)]
pub struct TableResult {
    /// What the integral comes from.
    pub name: String,
    /// Bytes of the table (0 for the closed form).
    pub bytes: usize,
    /// Median scalar products per second.
    pub products_per_s: f64,
    /// Mean relative integral error.
    pub mean: f64,
    /// Its 99th percentile.
    pub p99: f64,
    /// Its maximum.
    pub max: f64,
    /// Points the errors are over.
    pub points: usize,
}

/// Batch throughput of the built-in table, timed in turns.
#[derive(Clone, Debug)]
pub struct BatchResult {
    /// cpu-scalar products per second.
    pub scalar: f64,
    /// cpu-simd products per second.
    pub simd: f64,
    /// wgpu products per second and the adapter, or why not.
    pub gpu: Result<(f64, String), String>,
}

/// The error distribution of one product fit (shape or rendering error).
#[derive(Clone, Debug)]
pub struct FitErrors {
    /// The fit.
    pub fit: &'static str,
    /// Median.
    pub median: f64,
    /// 90th percentile.
    pub p90: f64,
    /// 99th percentile.
    pub p99: f64,
    /// Maximum.
    pub max: f64,
    /// Mean.
    pub mean: f64,
    /// Points.
    pub points: usize,
}

impl FitErrors {
    fn of(fit: &'static str, sorted: &[f64]) -> Self {
        FitErrors {
            fit,
            median: quantile(sorted, 0.5),
            p90: quantile(sorted, 0.9),
            p99: quantile(sorted, 0.99),
            max: quantile(sorted, 1.0),
            mean: mean(sorted),
            points: sorted.len(),
        }
    }
}

/// Everything the section measures.
#[derive(Clone, Debug)]
pub struct ProductResults {
    /// Generated tables, the built-in one, then the closed form.
    pub tables: Vec<TableResult>,
    /// Index of the built-in table in `tables`.
    pub builtin: usize,
    /// Batch throughput of the built-in table.
    pub batch: BatchResult,
    /// The tables generated in this run and how long each took.
    pub generated: Vec<(String, Duration)>,
    /// Points of the shape and rendering errors.
    pub shape_points: usize,
    /// Relative L2 shape error per fit.
    pub shapes: Vec<FitErrors>,
    /// Rendering (third-lobe) error per fit.
    pub renders: Vec<FitErrors>,
}

/// Computes `fit` with `table` for every pair of `lobes` into `out`, each call behind
/// `black_box` (one product at a time, as a renderer calls it).
fn run_scalar(
    table: &ProductTable<'_>,
    fit: ProductFit,
    lobes: &[(CosineLobe, CosineLobe)],
    out: &mut [CosineLobe],
) {
    for ((a, b), o) in lobes.iter().zip(out.iter_mut()) {
        *o = product::product_with(black_box(table), fit, black_box(a), black_box(b));
    }
    black_box(&out);
}

/// Batch throughput of the built-in table: cpu-scalar, cpu-simd and wgpu (or why not),
/// timed in turns over `repeats` rounds.
fn batch_speeds(lobes: &[(CosineLobe, CosineLobe)], gpu: bool, repeats: usize) -> BatchResult {
    let n = lobes.len();
    let col = |f: &dyn Fn(&(CosineLobe, CosineLobe)) -> f32| -> Vec<f32> {
        lobes.iter().map(f).collect()
    };
    let a_axis = [
        col(&|l| l.0.axis().x),
        col(&|l| l.0.axis().y),
        col(&|l| l.0.axis().z),
    ];
    let b_axis = [
        col(&|l| l.1.axis().x),
        col(&|l| l.1.axis().y),
        col(&|l| l.1.axis().z),
    ];
    let (a_s, a_e) = (col(&|l| l.0.scale()), col(&|l| l.0.exponent()));
    let (b_s, b_e) = (col(&|l| l.1.scale()), col(&|l| l.1.exponent()));
    let mut out = [
        vec![0f32; n],
        vec![0f32; n],
        vec![0f32; n],
        vec![0f32; n],
        vec![0f32; n],
    ];
    let table = ProductTable::builtin();
    let mut gpu_state = if gpu {
        crate::backend::gpu::try_gpu().map(|g| {
            let info = g.adapter_info();
            (g, info)
        })
    } else {
        Err("--no-gpu".to_string())
    };
    let input = crate::backend::gpu_product::lobe_product_input(lobes.iter().map(|(x, y)| (x, y)));
    let mut gout = crate::kernels::Columns::zeros(5, n);
    let gtable = crate::backend::gpu_product::ProductGpuTable::builtin();
    let mut scalar_out = vec![lobes[0].0; n];
    let mut gpu_err = None;
    let times = median_times_in_turns(repeats, 3, |i| match i {
        0 => run_scalar(&table, ProductFit::ExactIntegral, lobes, &mut scalar_out),
        1 => {
            let [o0, o1, o2, o3, o4] = &mut out;
            steradian_simd::lobe::product::product_slices(
                &table,
                ProductFit::ExactIntegral,
                [&a_axis[0], &a_axis[1], &a_axis[2]],
                &a_s,
                &a_e,
                [&b_axis[0], &b_axis[1], &b_axis[2]],
                &b_s,
                &b_e,
                [o0, o1, o2],
                o3,
                o4,
            );
            black_box(&out);
        }
        _ => {
            if let (Ok((g, _)), Ok(gt), None) = (&mut gpu_state, &gtable, &gpu_err) {
                let r =
                    crate::backend::gpu_product::run_lobe_product_columns(g, gt, &input, &mut gout);
                if let Err(e) = r {
                    gpu_err = Some(e.to_string());
                }
            }
        }
    });
    let gpu = match (gpu_state, gtable, gpu_err) {
        (Err(why), _, _) => Err(why),
        (_, Err(e), _) => Err(e.to_string()),
        (_, _, Some(e)) => Err(e),
        (Ok((_, info)), Ok(_), None) => Ok((per_second(n, times[2]), info)),
    };
    BatchResult {
        scalar: per_second(n, times[0]),
        simd: per_second(n, times[1]),
        gpu,
    }
}

/// The product fits of the shape and rendering errors.
const FITS: [(&str, ProductFit); 3] = [
    (
        "exact integral, peak-matched (default)",
        ProductFit::ExactIntegral,
    ),
    (
        "exact integral, curvature-matched",
        ProductFit::ExactIntegralCurvature,
    ),
    ("spherical Gaussian", ProductFit::SphericalGaussian),
];

/// Runs the section's measurements.
pub fn measure(opts: &Options) -> Result<ProductResults, Box<dyn Error>> {
    let steps = (RESOLUTIONS.len() + 5) as u64;
    let bar = ProgressBar::new(steps).with_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message("lobe products: exact integrals");
    let mut rng = Rng::new(SEED);
    let points: Vec<(f32, f32, f32, f64)> = (0..ERROR_POINTS)
        .map(|_| {
            let (e1, e2) = (exponent(&mut rng), exponent(&mut rng));
            let a = (PI * rng.unit()) as f32;
            (
                e1,
                e2,
                a,
                ln_product_integral(e1 as f64, e2 as f64, a as f64),
            )
        })
        .collect();
    bar.inc(1);

    // Tables: generated ones, then the built-in one.
    let mut owned: Vec<(String, Vec<u8>, Duration)> = Vec::new();
    for (ne, nw) in RESOLUTIONS {
        bar.set_message(format!("lobe products: generating a {ne}×{ne}×{nw} table"));
        let (bytes, d) = timed(|| lobe_product::encode(ne, nw));
        owned.push((format!("{ne}×{ne}×{nw} table"), bytes, d));
        bar.inc(1);
    }
    let mut tables: Vec<(String, ProductTable<'_>, ProductFit)> = owned
        .iter()
        .map(|(n, b, _)| {
            (
                n.clone(),
                ProductTable::from_bytes(b).expect("generated table is valid"),
                ProductFit::ExactIntegral,
            )
        })
        .collect();
    tables.push((
        format!(
            "{}×{}×{} table (built in)",
            product::TABLE_EXPONENTS,
            product::TABLE_EXPONENTS,
            product::TABLE_ANGLES
        ),
        ProductTable::builtin(),
        ProductFit::ExactIntegral,
    ));
    tables.push((
        "spherical Gaussian (no table)".into(),
        ProductTable::builtin(),
        ProductFit::SphericalGaussian,
    ));

    bar.set_message("lobe products: errors and scalar throughput");
    let speed_n = opts.scaled(SPEED_N);
    let lobes: Vec<(CosineLobe, CosineLobe)> = (0..speed_n)
        .map(|_| {
            let (e1, e2) = (exponent(&mut rng), exponent(&mut rng));
            canonical_lobes(e1, e2, (PI * rng.unit()) as f32)
        })
        .collect();
    let mut out = vec![lobes[0].0; speed_n];
    // Tables take turns within each repeat, so noise hits them alike.
    let times = median_times_in_turns(opts.repeats, tables.len(), |i| {
        let (_, t, fit) = &tables[i];
        run_scalar(t, *fit, &lobes, &mut out);
    });
    let rows: Vec<TableResult> = tables
        .iter()
        .zip(&times)
        .map(|((name, t, fit), &d)| {
            let errs = integral_errors(t, *fit, &points);
            TableResult {
                name: name.clone(),
                bytes: if *fit == ProductFit::SphericalGaussian {
                    0
                } else {
                    t.bytes()
                },
                products_per_s: per_second(speed_n, d),
                mean: mean(&errs),
                p99: quantile(&errs, 0.99),
                max: quantile(&errs, 1.0),
                points: errs.len(),
            }
        })
        .collect();
    bar.set_message("lobe products: SIMD and wgpu throughput");
    let batch = batch_speeds(&lobes, opts.gpu, opts.repeats);
    bar.inc(1);

    bar.set_message("lobe products: shape errors");
    let shape_points: Vec<(f32, f32, f32)> = points
        .iter()
        .filter(|&&(e1, e2, _, ln_i)| ln_i.exp() >= 1e-6 * TAU / (e1.max(e2) as f64 + 1.0))
        .take(SHAPE_POINTS)
        .map(|&(e1, e2, a, _)| (e1, e2, a))
        .collect();
    let builtin = ProductTable::builtin();
    let shapes: Vec<FitErrors> = FITS
        .iter()
        .map(|&(name, fit)| {
            let mut v: Vec<f64> = shape_points
                .iter()
                .map(|&(e1, e2, a)| {
                    let (l1, l2) = canonical_lobes(e1, e2, a);
                    shape_error(e1, e2, a, &product::product_with(&builtin, fit, &l1, &l2))
                })
                .filter(|x| x.is_finite())
                .collect();
            v.sort_by(f64::total_cmp);
            FitErrors::of(name, &v)
        })
        .collect();
    // Rendering error: one more lobe on the arc, around the product's peak.
    let mut third_rng = Rng::new(SEED ^ 3);
    let thirds: Vec<(f64, f64)> = shape_points
        .iter()
        .map(|&(_, _, a)| {
            (
                third_rng.log_range(1.0, 1e4),
                third_rng.range(-0.25, 1.25) * a as f64,
            )
        })
        .collect();
    let renders: Vec<FitErrors> = FITS
        .iter()
        .map(|&(name, fit)| {
            let mut v: Vec<f64> = shape_points
                .iter()
                .zip(&thirds)
                .filter_map(|(&(e1, e2, a), &(e3, g))| {
                    let (l1, l2) = canonical_lobes(e1, e2, a);
                    let r = product::product_with(&builtin, fit, &l1, &l2);
                    third_lobe_error(e1, e2, a, &r, e3, g.clamp(0.0, a as f64))
                })
                .collect();
            v.sort_by(f64::total_cmp);
            FitErrors::of(name, &v)
        })
        .collect();
    bar.inc(1);
    bar.finish_and_clear();
    Ok(ProductResults {
        tables: rows,
        builtin: RESOLUTIONS.len(),
        batch,
        generated: owned.into_iter().map(|(n, _, d)| (n, d)).collect(),
        shape_points: shape_points.len(),
        shapes,
        renders,
    })
}

/// The line of the wgpu batch rate, or why there is none.
fn gpu_line(b: &BatchResult) -> String {
    match &b.gpu {
        Ok((r, info)) => format!(
            "wgpu {:.2} M/s ({:.2}× scalar, upload and read-back included, on {info})",
            r / 1e6,
            r / b.scalar
        ),
        Err(why) => format!("wgpu: not run ({why})"),
    }
}

/// "name in 0.12 s" for each generated table.
fn generated(r: &ProductResults) -> Vec<String> {
    r.generated
        .iter()
        .map(|(n, d)| format!("{n} in {:.2} s", d.as_secs_f64()))
        .collect()
}

/// The summary text of the section.
fn summary(r: &ProductResults) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "  {:<34} {:>10} {:>12} {:>10} {:>10} {:>10}",
        "lobe product (scalar, 1 core)", "bytes", "Mproducts/s", "mean", "p99", "max"
    );
    for t in &r.tables {
        let _ = writeln!(
            s,
            "  {:<34} {:>10} {:>12.2} {:>10.2e} {:>10.2e} {:>10.2e}",
            t.name,
            t.bytes,
            t.products_per_s / 1e6,
            t.mean,
            t.p99,
            t.max
        );
    }
    let b = &r.batch;
    let _ = writeln!(
        s,
        "  built-in table, same run: cpu-scalar {:.2} M/s, cpu-simd {:.2} M/s ({:.2}× scalar, {} lanes, {}), {}",
        b.scalar / 1e6,
        b.simd / 1e6,
        b.simd / b.scalar,
        steradian_simd::slice_lanes(),
        steradian_simd::isa(),
        gpu_line(b)
    );
    let _ = writeln!(
        s,
        "  contract for the built-in table: mean ≤ {:.0e}, p99 ≤ {:.0e}, max ≤ {:.0e}",
        product::INTEGRAL_REL_MEAN,
        product::INTEGRAL_REL_P99,
        product::INTEGRAL_REL_MAX
    );
    let _ = writeln!(s, "  generated here: {}", generated(r).join(", "));
    let _ = writeln!(
        s,
        "  relative L2 shape error of the result lobe ({} points, built-in table):",
        r.shape_points
    );
    for e in &r.shapes {
        let _ = writeln!(
            s,
            "    {:<40} median {:.2e}  p90 {:.2e}  p99 {:.2e}  max {:.2e}",
            e.fit, e.median, e.p90, e.p99, e.max
        );
    }
    let _ = writeln!(
        s,
        "  rendering error: ∫ c_r·c3 against the exact ∫ c1·c2·c3, c3 a third lobe (e3 log-uniform in [1, 1e4]) on the arc:"
    );
    for e in &r.renders {
        let _ = writeln!(
            s,
            "    {:<40} median {:.2e}  p90 {:.2e}  p99 {:.2e}  mean {:.2e}",
            e.fit, e.median, e.p90, e.p99, e.mean
        );
    }
    s
}

/// The HTML of the section.
fn html(r: &ProductResults) -> String {
    let mut html = String::from(
        "<p>Relative error of the result lobe's integral <code>2πp/(e_r+1)</code> against the exact \
         product integral (f64), on unseen points: <code>e</code> = 0 with probability 5 %, else \
         log-uniform in [1e-3, 1e5]; <code>α</code> uniform in [0, π); where \
         <code>I ≥ 1e-6·min(∫c1, ∫c2)</code>. Scalar throughput is one product per call, \
         tables taking turns in each timed repeat; the ratio is to the built-in table in the \
         same run.</p>\n<table><tr><th>integral from</th><th>bytes</th><th>Mproducts/s</th>\
         <th>×built-in</th><th>mean</th><th>p99</th><th>max</th></tr>\n",
    );
    let builtin_speed = r.tables[r.builtin].products_per_s;
    for t in &r.tables {
        let _ = writeln!(
            html,
            "<tr><td>{}</td><td>{}</td><td>{:.2}</td><td>{:.2}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.2e}</td></tr>",
            t.name,
            t.bytes,
            t.products_per_s / 1e6,
            t.products_per_s / builtin_speed,
            t.mean,
            t.p99,
            t.max
        );
    }
    html += "</table>\n";
    let b = &r.batch;
    html += &format!(
        "<p>Batches with the built-in table, timed in turns in this run: cpu-scalar {:.2} M products/s, \
         cpu-simd {:.2} M/s (<b>{:.2}×</b> scalar, {} lanes, {}), {}.</p>\n",
        b.scalar / 1e6,
        b.simd / 1e6,
        b.simd / b.scalar,
        steradian_simd::slice_lanes(),
        steradian_simd::isa(),
        gpu_line(b)
    );
    html += &format!(
        "<p>Generated in this run (f64 exact integrals): {}.</p>\n",
        generated(r).join(", ")
    );
    html += "<img src=\"lobe_product.svg\" alt=\"lobe product: speed against error\">\n";
    html += &format!(
        "<p>Relative L2 shape error <code>‖c_r − c1·c2‖/‖c1·c2‖</code> of the result lobe \
         over {} of those points (exact 1-D integrals). It cannot be 0: a product of lobes is \
         not a lobe.</p>\n<table><tr><th>fit</th><th>median</th><th>p90</th><th>p99</th><th>max</th></tr>\n",
        r.shape_points
    );
    for e in &r.shapes {
        let _ = writeln!(
            html,
            "<tr><td>{}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.2e}</td></tr>",
            e.fit, e.median, e.p90, e.p99, e.max
        );
    }
    html += "</table>\n";
    html += "<p>Rendering error of each fit: the result multiplied by a third lobe \
             <code>c3</code> (exponent log-uniform in [1, 1e4], axis on the arc around the peak), \
             <code>|∫c_r·c3 − ∫c1·c2·c3|/∫c1·c2·c3</code> with both integrals exact. This is the \
             measure the default fit was chosen by.</p>\n<table><tr><th>fit</th><th>median</th>\
             <th>p90</th><th>p99</th><th>mean</th></tr>\n";
    for e in &r.renders {
        let _ = writeln!(
            html,
            "<tr><td>{}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.2e}</td></tr>",
            e.fit, e.median, e.p90, e.p99, e.mean
        );
    }
    html += "</table>\n";
    html
}

/// The data of the section in `report.json`.
fn data(r: &ProductResults) -> serde_json::Value {
    let b = &r.batch;
    json!({
        "tables": r.tables.iter().map(|t| json!({
            "name": t.name, "bytes": t.bytes, "products_per_s": t.products_per_s,
            "mean": t.mean, "p99": t.p99, "max": t.max, "points": t.points,
        })).collect::<Vec<_>>(),
        "shape_error": r.shapes.iter().map(|e| json!({
            "fit": e.fit, "median": e.median, "p90": e.p90, "p99": e.p99, "max": e.max,
        })).collect::<Vec<_>>(),
        "third_lobe_error": r.renders.iter().map(|e| json!({
            "fit": e.fit, "median": e.median, "p90": e.p90, "p99": e.p99, "mean": e.mean,
            "points": e.points,
        })).collect::<Vec<_>>(),
        "batch": {
            "cpu_scalar_per_s": b.scalar,
            "cpu_simd_per_s": b.simd,
            "simd_over_scalar": b.simd / b.scalar,
            "wgpu_per_s": b.gpu.as_ref().ok().map(|g| g.0),
        },
    })
}

/// Scalar speed against integral error, a point per table with a bar from mean to max.
fn plot(r: &ProductResults) -> String {
    let series = r
        .tables
        .iter()
        .map(|t| {
            let pt = Pt {
                y_hi: Some(t.max),
                ..Pt::new(t.products_per_s, t.mean)
            };
            Series::dots(t.name.clone(), vec![pt])
        })
        .collect();
    Chart::new(
        "Lobe product: scalar speed against integral error",
        Axis::new("products per second (one core)", Scale::Log),
        Axis::new(
            "relative integral error (dot: mean, bar to max)",
            Scale::Log,
        ),
        series,
    )
    .svg()
}

/// The section of measured results.
pub fn render(r: &ProductResults) -> Section {
    Section {
        id: "lobe-product",
        title: "Lobe products".into(),
        summary: summary(r),
        html: html(r),
        data: data(r),
        files: vec![("lobe_product.svg".into(), plot(r).into_bytes())],
    }
}

/// Runs the section.
pub fn section(opts: &Options) -> Result<Section, Box<dyn Error>> {
    Ok(render(&measure(opts)?))
}
