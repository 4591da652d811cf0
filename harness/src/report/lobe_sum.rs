//! Report section "lobe-sum": the rendering integral `∫ R·L·V` as a chain of lobe products
//! (`steradian_core::lobe::sum::triple`) on a Figure-16-like scene of the cosine-lobe paper —
//! shaded points on a plane, one spherical light, a cluster of sphere occluders, a glossy
//! Phong material — for a range of pruning thresholds `t` (section 4.3): error against f64
//! quadrature together with the number of products computed and the time per point, i.e.
//! a speed-against-error curve, for each product fit the kernel offers and both places of
//! the cosine term.
//!
//! Error metric: `|chain − reference|` over the brightest unshadowed value of the scene
//! (image units), against the *lobe-model* reference (`reference::triple`, the same light
//! and occluder lobes, exact cosine), which isolates the chain's own error. The error of the
//! lobe model itself against the *physical* reference (cap indicator light, exact
//! occluders) is given beside it. The time ratio baseline is the same curve at `t = 0`
//! (every product computed) in the same run.

use std::error::Error;
use std::hint::black_box;

use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use steradian_core::Vec3;
use steradian_core::lobe::cap::{CapFit, SphericalCap};
use steradian_core::lobe::product::{self, ProductFit, ProductTable};
use steradian_core::lobe::sum::{
    Cosine, LobeSum, ProductCounts, light_with_cosine, phong_reflectance, triple_with,
};
use steradian_core::lobe::{CosineLobe, Phong};

use super::Options;
use super::plot::{Axis, Chart, Pt, Scale, Series};
use super::section::Section;
use super::timing::{median_time, ns_per, timed};
use crate::reference as adapt;
use crate::reference::triple::{self as reference, Scene, Term, Visibility};
use crate::rng::Rng;

/// Pruning thresholds, in units of the brightest unshadowed value of the scene.
const THRESHOLDS: [f64; 10] = [0.0, 1e-6, 1e-5, 1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1];
/// Shaded points (a grid on the plane) and occluders.
const GRID: (usize, usize) = (8, 5);
const OCCLUDERS: usize = 32;
/// Quadrature tolerance of the references.
const REF_TOL: f64 = 1e-6;
/// Passes over every point per timed run at the default `--n` ([`Options::scaled`]).
const TIMED_PASSES: usize = 1;

struct Point {
    r: [LobeSum<2>; 2],
    l: [LobeSum<1>; 2],
    v: LobeSum<OCCLUDERS>,
    lobe_ref: f64,
    phys_ref: f64,
    unshadowed: f64,
    half_angle: f32,
}

/// One curve: a product fit and a place for the cosine.
struct Curve {
    name: &'static str,
    fit: ProductFit,
    cosine: Cosine,
}

const CURVES: [Curve; 4] = [
    Curve {
        name: "exact integral, cos on light",
        fit: ProductFit::ExactIntegral,
        cosine: Cosine::WithLight,
    },
    Curve {
        name: "exact integral + curvature, cos on light",
        fit: ProductFit::ExactIntegralCurvature,
        cosine: Cosine::WithLight,
    },
    Curve {
        name: "SG closed form, cos on light",
        fit: ProductFit::SphericalGaussian,
        cosine: Cosine::WithLight,
    },
    Curve {
        name: "exact integral, cos on BRDF",
        fit: ProductFit::ExactIntegral,
        cosine: Cosine::WithBrdf,
    },
];

fn v3(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

fn order_index(c: Cosine) -> usize {
    usize::from(c == Cosine::WithBrdf)
}

/// The scene: points on the plane z = 0, light above, occluders in between.
fn build_points(bar: &ProgressBar) -> Result<Vec<Point>, Box<dyn Error>> {
    let mut rng = Rng::new(0x1f16_0b5e);
    let light_c = Vec3::new(0.6, 0.2, 3.0);
    let light_r = 0.35f32;
    let eye = Vec3::new(-0.4, -3.0, 2.2);
    let phong = Phong::modified(0.3, 0.6, 150.0)?;
    // A cluster of spheres ("the bunny") between the light and the plane.
    let blob = Vec3::new(0.35, 0.1, 1.3);
    let mut spheres: Vec<(Vec3, f32)> = Vec::new();
    while spheres.len() < OCCLUDERS {
        let d = Vec3::from(rng.sphere().map(|x| x as f32)) * (rng.unit().cbrt() as f32 * 0.4);
        let r = rng.range(0.04, 0.1) as f32;
        let c = blob + d;
        if spheres.iter().all(|(o, ro)| (*o - c).length() > *ro + r) {
            spheres.push((c, r));
        }
    }
    let n = Vec3::Z;
    let mut points = Vec::new();
    for j in 0..GRID.1 {
        for i in 0..GRID.0 {
            let x = Vec3::new(
                -0.6 + 1.6 * i as f32 / (GRID.0 - 1) as f32,
                -0.8 + 1.6 * j as f32 / (GRID.1 - 1) as f32,
                0.0,
            );
            let wo = (eye - x).normalize();
            let cap = SphericalCap::from_sphere(x, light_c, light_r)?;
            let caps: Vec<SphericalCap> = spheres
                .iter()
                .map(|(c, r)| SphericalCap::from_sphere(x, *c, *r))
                .collect::<Result<_, _>>()?;
            let mut c = ProductCounts::default();
            let mut raw = LobeSum::<1>::new();
            raw.push_cap(&cap, 1.0, CapFit::L2);
            let mut v = LobeSum::<OCCLUDERS>::unoccluded();
            for oc in &caps {
                v.push_occluder(oc, 1.0, CapFit::L2);
            }
            let r = [Cosine::WithLight, Cosine::WithBrdf]
                .map(|o| phong_reflectance(&phong, n, wo, o, &mut c));
            let l = [Cosine::WithLight, Cosine::WithBrdf]
                .map(|o| light_with_cosine(&raw, n, o, &mut c));
            // Exact reflectance: Phong's diffuse lobe (f_d·cos) and the specular lobe times
            // the exact cosine.
            let [d, s] = phong.lobes(n, wo);
            let refl = vec![
                Term::Lobe(adapt::lobe_of(&d)),
                Term::LobeTimesCosine(adapt::lobe_of(&s), v3(n)),
            ];
            let lobe_ref = reference::triple(
                &Scene {
                    reflectance: refl.clone(),
                    light: adapt::terms_of(&raw),
                    visibility: Visibility::Lobes(adapt::terms_of(&v)),
                },
                REF_TOL,
            );
            let phys_ref = reference::triple(
                &Scene {
                    reflectance: refl,
                    light: vec![Term::Cap(adapt::cap_of(&cap), 1.0)],
                    visibility: Visibility::Occluders(caps.iter().map(adapt::cap_of).collect()),
                },
                REF_TOL,
            );
            points.push(Point {
                r,
                l,
                v,
                lobe_ref: lobe_ref.value,
                phys_ref: phys_ref.value,
                unshadowed: lobe_ref.scale,
                half_angle: cap.half_angle(),
            });
            bar.inc(1);
        }
    }
    Ok(points)
}

fn kernel(fit: ProductFit) -> impl Fn(&CosineLobe, &CosineLobe) -> CosineLobe {
    move |a, b| product::product_with(&ProductTable::builtin(), fit, a, b)
}

fn run_curve(points: &[Point], ci: usize, t: f32) -> (Vec<f32>, ProductCounts) {
    let c = &CURVES[ci];
    let k = kernel(c.fit);
    let o = order_index(c.cosine);
    let mut counts = ProductCounts::default();
    let vals = points
        .iter()
        .map(|p| triple_with(&k, &p.r[o], &p.l[o], &p.v, t, &mut counts))
        .collect();
    (vals, counts)
}

/// One point of a curve: a threshold, its products, time and error.
#[derive(Clone, Debug)]
pub struct Row {
    /// Index into the curves (product fit and place of the cosine).
    pub curve: usize,
    /// Pruning threshold over the brightest unshadowed value.
    pub t: f64,
    /// Products computed per point.
    pub products: f64,
    /// Products dropped per point.
    pub dropped: f64,
    /// Median nanoseconds per point.
    pub ns_per_point: f64,
    /// Largest error over the brightest unshadowed value.
    pub err_max: f64,
    /// Mean error over the brightest unshadowed value.
    pub err_mean: f64,
}

/// Everything the section measures.
#[derive(Clone, Debug)]
pub struct LobeSumResults {
    /// Shaded points.
    pub points: usize,
    /// Smallest and largest half-angle of the light's cap over the points.
    pub half_angles: (f32, f32),
    /// The brightest unshadowed value of the scene (the error unit).
    pub max_unshadowed: f64,
    /// Seconds the f64 references took.
    pub reference_seconds: f64,
    /// Lobe model against the physical reference at `t = 0`: (max, mean) over max S.
    pub model_error: (f64, f64),
    /// Every curve at every threshold.
    pub rows: Vec<Row>,
}

/// The curve's name.
fn name(r: &Row) -> &'static str {
    CURVES[r.curve].name
}

/// Runs the section's measurements.
pub fn measure(opts: &Options) -> Result<LobeSumResults, Box<dyn Error>> {
    let n_points = (GRID.0 * GRID.1) as u64;
    let bar = ProgressBar::new(n_points + (CURVES.len() * THRESHOLDS.len()) as u64).with_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message("lobe-sum: f64 references");
    let (points, ref_time) = timed(|| build_points(&bar));
    let points = points?;
    let scale = points.iter().map(|p| p.unshadowed).fold(0.0, f64::max);
    bar.set_message("lobe-sum: chains");
    let passes = opts.scaled(TIMED_PASSES);
    let mut rows = Vec::new();
    let mut model_err = (0.0f64, 0.0f64);
    for (ci, _) in CURVES.iter().enumerate() {
        for &k in &THRESHOLDS {
            let t = (k * scale) as f32;
            let (vals, counts) = run_curve(&points, ci, t);
            let errs: Vec<f64> = vals
                .iter()
                .zip(&points)
                .map(|(v, p)| (*v as f64 - p.lobe_ref).abs() / scale)
                .collect();
            if ci == 0 && k == 0.0 {
                for (v, p) in vals.iter().zip(&points) {
                    let e = (*v as f64 - p.phys_ref).abs() / scale;
                    model_err.0 = model_err.0.max(e);
                    model_err.1 += e / points.len() as f64;
                }
            }
            let d = median_time(opts.repeats, || {
                for _ in 0..passes {
                    black_box(run_curve(&points, ci, t));
                }
            });
            rows.push(Row {
                curve: ci,
                t: k,
                products: counts.computed as f64 / points.len() as f64,
                dropped: counts.dropped() as f64 / points.len() as f64,
                ns_per_point: ns_per(passes * points.len(), d),
                err_max: errs.iter().copied().fold(0.0, f64::max),
                err_mean: errs.iter().sum::<f64>() / errs.len() as f64,
            });
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    let half_angles = points.iter().map(|p| p.half_angle);
    Ok(LobeSumResults {
        points: points.len(),
        half_angles: (
            half_angles.clone().fold(f32::INFINITY, f32::min),
            half_angles.fold(0.0, f32::max),
        ),
        max_unshadowed: scale,
        reference_seconds: ref_time.as_secs_f64(),
        model_error: model_err,
        rows,
    })
}

impl LobeSumResults {
    /// Nanoseconds per point of curve `ci` at `t = 0` (the speed ratios' baseline).
    fn base(&self, ci: usize) -> f64 {
        self.rows
            .iter()
            .find(|r| r.curve == ci && r.t == 0.0)
            .map_or(1.0, |r| r.ns_per_point)
    }

    /// Speed of `r` relative to its curve at `t = 0`.
    fn speed(&self, r: &Row) -> f64 {
        self.base(r.curve) / r.ns_per_point
    }
}

/// The summary text of the section.
fn summary(r: &LobeSumResults) -> String {
    let mut summary = format!(
        "  {} points, 1 light, {OCCLUDERS} occluders; references {:.1} s; error vs lobe-model quadrature / brightest unshadowed value\n",
        r.points, r.reference_seconds
    );
    summary += &format!(
        "  {:<42} {:>8} {:>9} {:>9} {:>7} {:>10} {:>10}\n",
        "fit, cosine", "t/maxS", "products", "ns/point", "×(t=0)", "max err", "mean err"
    );
    for row in &r.rows {
        summary += &format!(
            "  {:<42} {:>8.0e} {:>9.1} {:>9.0} {:>7.2} {:>10.2e} {:>10.2e}\n",
            name(row),
            row.t,
            row.products,
            row.ns_per_point,
            r.speed(row),
            row.err_max,
            row.err_mean
        );
    }
    summary += &format!(
        "  lobe model vs physical (cap light, exact occluders), t = 0: max {:.2e}, mean {:.2e} of max S\n",
        r.model_error.0, r.model_error.1
    );
    summary
}

/// The HTML of the section.
fn html(r: &LobeSumResults) -> String {
    let mut table = String::from(
        "<table><tr><th>kernel fit, cosine</th><th>t / max S</th><th>products / point</th><th>dropped / point</th><th>ns / point</th><th>speed ×(t = 0)</th><th>max error / max S</th><th>mean error / max S</th></tr>\n",
    );
    for row in &r.rows {
        table += &format!(
            "<tr><td>{}</td><td>{:.0e}</td><td>{:.1}</td><td>{:.1}</td><td>{:.0}</td><td>{:.2}</td><td>{:.2e}</td><td>{:.2e}</td></tr>\n",
            name(row),
            row.t,
            row.products,
            row.dropped,
            row.ns_per_point,
            r.speed(row),
            row.err_max,
            row.err_mean
        );
    }
    table += "</table>\n";
    format!(
        "<p>Figure 16 of the cosine-lobe paper as a curve: {} shaded points on a plane under one \
         spherical light (cap half-angles {:.3}–{:.3} rad) and {OCCLUDERS} sphere occluders, modified \
         Phong (k<sub>d</sub> 0.3, k<sub>s</sub> 0.6, e = 150). For each pruning threshold t (in units of the \
         brightest unshadowed value, max S = {:.4e}) the chain <code>lobe_sum::triple</code> runs over every \
         point: products computed per point against the error against f64 quadrature of the same lobe \
         model (light and occluders as the chain's cap lobes, exact cosine). The speed ratio is to the \
         same curve at t = 0 in this run. The lobe model itself differs from the physical integral (cap \
         indicator light, exact occluders) by max {:.2e}, mean {:.2e} of max S: that is the caps-as-lobes \
         representation, which no product kernel removes.</p>\n<p><img src=\"lobe_sum.svg\" alt=\"error against products\"></p>\n{table}",
        r.points,
        r.half_angles.0,
        r.half_angles.1,
        r.max_unshadowed,
        r.model_error.0,
        r.model_error.1,
    )
}

/// The data of the section in `report.json`.
fn data(r: &LobeSumResults) -> serde_json::Value {
    json!({
        "points": r.points,
        "occluders": OCCLUDERS,
        "max_unshadowed": r.max_unshadowed,
        "reference_seconds": r.reference_seconds,
        "model_error_max": r.model_error.0,
        "model_error_mean": r.model_error.1,
        "rows": r.rows.iter().map(|row| json!({
            "fit": name(row),
            "threshold": row.t,
            "products_per_point": row.products,
            "dropped_per_point": row.dropped,
            "ns_per_point": row.ns_per_point,
            "speed_vs_t0": r.speed(row),
            "error_max": row.err_max,
            "error_mean": row.err_mean,
        })).collect::<Vec<_>>(),
    })
}

/// Max error (log y) against products per point (x), one line per curve, a point per
/// threshold; the first curve drawn wide, as the others lie on it.
fn plot(rows: &[Row]) -> String {
    let series: Vec<Series> = CURVES
        .iter()
        .enumerate()
        .map(|(ci, c)| {
            let points = rows
                .iter()
                .filter(|r| r.curve == ci)
                .map(|r| Pt {
                    note: Some(format!("{}: t = {:.0e}", c.name, r.t)),
                    ..Pt::new(r.products, r.err_max)
                })
                .collect();
            let s = Series::line(c.name, points);
            if ci == 0 { s.wide() } else { s }
        })
        .collect();
    Chart::new(
        "Lobe sums: error against products computed (pruning threshold t)",
        Axis::new("products computed per point", Scale::Linear),
        Axis::new("max error / brightest value", Scale::Log),
        series,
    )
    .svg()
}

/// The section of measured results.
pub fn render(r: &LobeSumResults) -> Section {
    Section {
        id: "lobe-sum",
        title: "Lobe sums: ∫ f_r·L·V, error against products (pruning threshold)".into(),
        summary: summary(r),
        html: html(r),
        data: data(r),
        files: vec![("lobe_sum.svg".into(), plot(&r.rows).into_bytes())],
    }
}

/// The report section (see the module docs).
pub fn section(opts: &Options) -> Result<Section, Box<dyn Error>> {
    Ok(render(&measure(opts)?))
}
