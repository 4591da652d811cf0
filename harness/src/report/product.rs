//! The lobe-product section: what each byte of table buys. Integral error against the
//! exact f64 product integral and scalar throughput for tables of several resolutions and
//! for the spherical-Gaussian closed form (no table); the relative L2 shape error of the
//! result lobe for each fit; SIMD and wgpu throughput of the built-in table.

use std::error::Error;
use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;
use std::hint::black_box;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use steradian_core::lobe::CosineLobe;
use steradian_core::lobe::product::{self, ProductFit, ProductTable};

use super::Options;
use super::plot::{Pt, Scale, Series, chart};
use super::section::Section;
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
/// Products per timed run.
const SPEED_N: usize = 1 << 15;
/// Timed repeats (median reported).
const REPEATS: usize = 5;
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

struct TableRow {
    name: String,
    bytes: usize,
    errs: Vec<f64>,
    per_s: f64,
}

/// Median products per second of `fit` with `table` over `lobes`, each call behind
/// `black_box` (one product at a time, as a renderer calls it).
fn time_scalar(
    table: &ProductTable<'_>,
    fit: ProductFit,
    lobes: &[(CosineLobe, CosineLobe)],
    out: &mut [CosineLobe],
) -> Duration {
    let t = Instant::now();
    for ((a, b), o) in lobes.iter().zip(out.iter_mut()) {
        *o = product::product_with(black_box(table), fit, black_box(a), black_box(b));
    }
    black_box(&out);
    t.elapsed()
}

/// Batch throughput of the built-in table: `(cpu-simd products/s, wgpu products/s or why
/// not)`, timed in turns with the scalar kernel, and the scalar rate of the same run.
fn batch_speeds(
    lobes: &[(CosineLobe, CosineLobe)],
    gpu: bool,
) -> (f64, f64, Result<(f64, String), String>) {
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
    let (mut ts, mut tv, mut tg) = (Vec::new(), Vec::new(), Vec::new());
    let mut gpu_err = None;
    for rep in 0..=REPEATS {
        let d = time_scalar(&table, ProductFit::ExactIntegral, lobes, &mut scalar_out);
        let t = Instant::now();
        {
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
        }
        black_box(&out);
        let dv = t.elapsed();
        if let (Ok((g, _)), Ok(gt), None) = (&mut gpu_state, &gtable, &gpu_err) {
            let t = Instant::now();
            match crate::backend::gpu_product::run_lobe_product_columns(g, gt, &input, &mut gout) {
                Ok(()) if rep > 0 => tg.push(t.elapsed()),
                Ok(()) => {}
                Err(e) => gpu_err = Some(e.to_string()),
            }
        }
        if rep > 0 {
            ts.push(d);
            tv.push(dv);
        }
    }
    let rate = |v: &mut Vec<Duration>| {
        v.sort();
        n as f64 / v[v.len() / 2].as_secs_f64().max(1e-12)
    };
    let gpu = match (gpu_state, gpu_err) {
        (Err(why), _) => Err(why),
        (_, Some(e)) => Err(e),
        (Ok((_, info)), None) if !tg.is_empty() => Ok((rate(&mut tg), info)),
        (Ok(_), None) => Err(match gtable {
            Err(e) => e.to_string(),
            Ok(_) => "no timing".into(),
        }),
    };
    (rate(&mut ts), rate(&mut tv), gpu)
}

/// Runs the section.
pub fn section(opts: &Options) -> Result<Section, Box<dyn Error>> {
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
        let t = Instant::now();
        let bytes = lobe_product::encode(ne, nw);
        owned.push((format!("{ne}×{ne}×{nw} table"), bytes, t.elapsed()));
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
    let lobes: Vec<(CosineLobe, CosineLobe)> = (0..SPEED_N)
        .map(|_| {
            let (e1, e2) = (exponent(&mut rng), exponent(&mut rng));
            canonical_lobes(e1, e2, (PI * rng.unit()) as f32)
        })
        .collect();
    let mut out = vec![lobes[0].0; SPEED_N];
    let mut times: Vec<Vec<Duration>> = vec![Vec::new(); tables.len()];
    for rep in 0..=REPEATS {
        // Tables take turns within each repeat, so noise hits them alike.
        for (i, (_, t, fit)) in tables.iter().enumerate() {
            let d = time_scalar(t, *fit, &lobes, &mut out);
            if rep > 0 {
                times[i].push(d);
            }
        }
    }
    let rows: Vec<TableRow> = tables
        .iter()
        .zip(times.iter_mut())
        .map(|((name, t, fit), ts)| {
            ts.sort();
            TableRow {
                name: name.clone(),
                bytes: if *fit == ProductFit::SphericalGaussian {
                    0
                } else {
                    t.bytes()
                },
                errs: integral_errors(t, *fit, &points),
                per_s: SPEED_N as f64 / ts[ts.len() / 2].as_secs_f64().max(1e-12),
            }
        })
        .collect();
    bar.set_message("lobe products: SIMD and wgpu throughput");
    let (batch_scalar, batch_simd, batch_gpu) = batch_speeds(&lobes, opts.gpu);
    bar.inc(1);

    bar.set_message("lobe products: shape errors");
    let fits = [
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
    let shape_points: Vec<(f32, f32, f32)> = points
        .iter()
        .filter(|&&(e1, e2, _, ln_i)| ln_i.exp() >= 1e-6 * TAU / (e1.max(e2) as f64 + 1.0))
        .take(SHAPE_POINTS)
        .map(|&(e1, e2, a, _)| (e1, e2, a))
        .collect();
    let builtin = ProductTable::builtin();
    let shapes: Vec<(&str, Vec<f64>)> = fits
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
            (name, v)
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
    let renders: Vec<(&str, Vec<f64>)> = fits
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
            (name, v)
        })
        .collect();
    bar.inc(1);
    bar.finish_and_clear();

    // Text, HTML, JSON, plot.
    let mut summary = String::new();
    let _ = writeln!(
        summary,
        "  {:<34} {:>10} {:>12} {:>10} {:>10} {:>10}",
        "lobe product (scalar, 1 core)", "bytes", "Mproducts/s", "mean", "p99", "max"
    );
    let mut html = String::from(
        "<p>Relative error of the result lobe's integral <code>2πp/(e_r+1)</code> against the exact \
         product integral (f64), on unseen points: <code>e</code> = 0 with probability 5 %, else \
         log-uniform in [1e-3, 1e5]; <code>α</code> uniform in [0, π); where \
         <code>I ≥ 1e-6·min(∫c1, ∫c2)</code>. Scalar throughput is one product per call, \
         tables taking turns in each timed repeat; the ratio is to the built-in table in the \
         same run.</p>\n<table><tr><th>integral from</th><th>bytes</th><th>Mproducts/s</th>\
         <th>×built-in</th><th>mean</th><th>p99</th><th>max</th></tr>\n",
    );
    let builtin_speed = rows[RESOLUTIONS.len()].per_s;
    let mut points_svg = Vec::new();
    let mut json_rows = Vec::new();
    for r in &rows {
        let (m, p99, mx) = (
            mean(&r.errs),
            quantile(&r.errs, 0.99),
            quantile(&r.errs, 1.0),
        );
        let _ = writeln!(
            summary,
            "  {:<34} {:>10} {:>12.2} {:>10.2e} {:>10.2e} {:>10.2e}",
            r.name,
            r.bytes,
            r.per_s / 1e6,
            m,
            p99,
            mx
        );
        let _ = writeln!(
            html,
            "<tr><td>{}</td><td>{}</td><td>{:.2}</td><td>{:.2}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.2e}</td></tr>",
            r.name,
            r.bytes,
            r.per_s / 1e6,
            r.per_s / builtin_speed,
            m,
            p99,
            mx
        );
        points_svg.push(Series {
            label: r.name.clone(),
            points: vec![Pt {
                y_hi: Some(mx),
                ..Pt::new(r.per_s, m)
            }],
            line: false,
        });
        json_rows.push(json!({
            "name": r.name, "bytes": r.bytes, "products_per_s": r.per_s,
            "mean": m, "p99": p99, "max": mx, "points": r.errs.len(),
        }));
    }
    html += "</table>\n";
    let simd_ratio = batch_simd / batch_scalar;
    let gpu_line = match &batch_gpu {
        Ok((r, info)) => format!(
            "wgpu {:.2} M/s ({:.2}× scalar, upload and read-back included, on {info})",
            r / 1e6,
            r / batch_scalar
        ),
        Err(why) => format!("wgpu: not run ({why})"),
    };
    let _ = writeln!(
        summary,
        "  built-in table, same run: cpu-scalar {:.2} M/s, cpu-simd {:.2} M/s ({:.2}× scalar, {} lanes, {}), {gpu_line}",
        batch_scalar / 1e6,
        batch_simd / 1e6,
        simd_ratio,
        steradian_simd::slice_lanes(),
        steradian_simd::isa()
    );
    html += &format!(
        "<p>Batches with the built-in table, timed in turns in this run: cpu-scalar {:.2} M products/s, \
         cpu-simd {:.2} M/s (<b>{:.2}×</b> scalar, {} lanes, {}), {}.</p>\n",
        batch_scalar / 1e6,
        batch_simd / 1e6,
        simd_ratio,
        steradian_simd::slice_lanes(),
        steradian_simd::isa(),
        gpu_line
    );
    let _ = writeln!(
        summary,
        "  contract for the built-in table: mean ≤ {:.0e}, p99 ≤ {:.0e}, max ≤ {:.0e}",
        product::INTEGRAL_REL_MEAN,
        product::INTEGRAL_REL_P99,
        product::INTEGRAL_REL_MAX
    );
    let generated: Vec<String> = owned
        .iter()
        .map(|(n, _, d)| format!("{n} in {:.2} s", d.as_secs_f64()))
        .collect();
    let _ = writeln!(summary, "  generated here: {}", generated.join(", "));
    html += &format!(
        "<p>Generated in this run (f64 exact integrals): {}.</p>\n",
        generated.join(", ")
    );
    html += "<img src=\"lobe_product.svg\" alt=\"lobe product: speed against error\">\n";

    let _ = writeln!(
        summary,
        "  relative L2 shape error of the result lobe ({} points, built-in table):",
        shape_points.len()
    );
    html += &format!(
        "<p>Relative L2 shape error <code>‖c_r − c1·c2‖/‖c1·c2‖</code> of the result lobe \
         over {} of those points (exact 1-D integrals). It cannot be 0: a product of lobes is \
         not a lobe.</p>\n<table><tr><th>fit</th><th>median</th><th>p90</th><th>p99</th><th>max</th></tr>\n",
        shape_points.len()
    );
    let mut json_shapes = Vec::new();
    for (name, v) in &shapes {
        let q = [0.5, 0.9, 0.99, 1.0].map(|q| quantile(v, q));
        let _ = writeln!(
            summary,
            "    {:<40} median {:.2e}  p90 {:.2e}  p99 {:.2e}  max {:.2e}",
            name, q[0], q[1], q[2], q[3]
        );
        let _ = writeln!(
            html,
            "<tr><td>{name}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.2e}</td></tr>",
            q[0], q[1], q[2], q[3]
        );
        json_shapes
            .push(json!({"fit": name, "median": q[0], "p90": q[1], "p99": q[2], "max": q[3]}));
    }
    html += "</table>\n";

    let _ = writeln!(
        summary,
        "  rendering error: ∫ c_r·c3 against the exact ∫ c1·c2·c3, c3 a third lobe (e3 log-uniform in [1, 1e4]) on the arc:"
    );
    html += "<p>Rendering error of each fit: the result multiplied by a third lobe \
             <code>c3</code> (exponent log-uniform in [1, 1e4], axis on the arc around the peak), \
             <code>|∫c_r·c3 − ∫c1·c2·c3|/∫c1·c2·c3</code> with both integrals exact. This is the \
             measure the default fit was chosen by.</p>\n<table><tr><th>fit</th><th>median</th>\
             <th>p90</th><th>p99</th><th>mean</th></tr>\n";
    let mut json_renders = Vec::new();
    for (name, v) in &renders {
        let q = [0.5, 0.9, 0.99].map(|q| quantile(v, q));
        let m = mean(v);
        let _ = writeln!(
            summary,
            "    {:<40} median {:.2e}  p90 {:.2e}  p99 {:.2e}  mean {:.2e}",
            name, q[0], q[1], q[2], m
        );
        let _ = writeln!(
            html,
            "<tr><td>{name}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.2e}</td></tr>",
            q[0], q[1], q[2], m
        );
        json_renders.push(json!({"fit": name, "median": q[0], "p90": q[1], "p99": q[2], "mean": m, "points": v.len()}));
    }
    html += "</table>\n";

    let svg = chart(
        "Lobe product: scalar speed against integral error",
        ("products per second (one core)", Scale::Log),
        (
            "relative integral error (dot: mean, bar to max)",
            Scale::Log,
        ),
        &points_svg,
    );
    Ok(Section {
        id: "lobe-product",
        title: "Lobe products".into(),
        summary,
        html,
        data: json!({
            "tables": json_rows,
            "shape_error": json_shapes,
            "third_lobe_error": json_renders,
            "batch": {
                "cpu_scalar_per_s": batch_scalar,
                "cpu_simd_per_s": batch_simd,
                "simd_over_scalar": simd_ratio,
                "wgpu_per_s": batch_gpu.as_ref().ok().map(|g| g.0),
            },
        }),
        files: vec![("lobe_product.svg".into(), svg.into_bytes())],
    })
}
