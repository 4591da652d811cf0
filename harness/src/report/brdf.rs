//! Report section: BRDF summed-area tables (`steradian_core::rsl::brdf_sat`). Per BRDF model, the
//! resolution [`BrdfSat::fit`] chose for a modest target, the bytes, the achieved error on
//! its test set, the error on fresh queries against the `f64` reference, the fit (build)
//! time, and the query throughput against the baseline measured in the same run: a 4×4
//! Gauss–Legendre quadrature of `ρ cos θᵢ` over the same square (16 BRDF evaluations, what
//! the table replaces), whose error on the same queries is shown too.

use std::error::Error;
use std::fmt::Write as _;
use std::hint::black_box;

use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use steradian_core::lobe::brdf::{BlinnPhong, Brdf, Ggx, Lambert, Phong, Ward};
use steradian_core::rsl::brdf_sat::{BrdfSat, Fit, FitOptions, Resolution};
use steradian_core::{Vec2, Vec3, rsl::hemisphere};

use super::Options;
use super::section::Section;
use super::timing::{median_time, per_second, timed};
use crate::reference::AsModel;
use crate::reference::brdf::{self as rb, Model};
use crate::rng::Rng;

/// Target error of every model's fit (module docs of `brdf_sat` for the metric).
pub const TARGET: f32 = 0.05;
/// Smallest square half-diagonal the report's "scene" needs.
pub const R_MIN: f32 = 0.1;
/// Largest half-diagonal.
pub const R_MAX: f32 = 0.5;
/// Largest view angle tabulated (degrees).
pub const THETA_MAX_DEG: f32 = 80.0;
/// Largest view angle tabulated for anisotropic BRDFs (degrees).
pub const ANISO_THETA_MAX_DEG: f32 = 60.0;
/// Cap on each model's tables.
pub const MAX_BYTES: usize = 16 << 20;
/// Queries per timed run at the default `--n` ([`Options::scaled`]).
const QUERIES: usize = 1 << 14;
/// Fresh queries compared against the f64 reference per model.
const CHECKED: usize = 60;
/// Seed of the queries.
const QUERY_SEED: u64 = 0x00b5_d5a7;

/// One BRDF-SAT query.
#[derive(Clone, Copy, Debug)]
pub struct Query {
    /// Local view direction.
    pub wo: Vec3,
    /// Square centre (disk units).
    pub centre: Vec2,
    /// Half-diagonal.
    pub r: f32,
}

/// `n` queries: views up to `theta_max` at any azimuth (a new view every 4 queries); squares centred on the mirror
/// direction, with an edge through it, or anywhere in the disk (a third each); half-diagonals
/// log-uniform in `[r_min, r_max]`.
pub fn queries(n: usize, r_min: f32, r_max: f32, theta_max: f32, seed: u64) -> Vec<Query> {
    let mut rng = Rng::new(seed);
    let smax = (1.0 - (theta_max as f64).cos()).sqrt();
    let (mut s, mut phi) = (0.0, 0.0);
    (0..n)
        .map(|k| {
            if k % 4 == 0 {
                s = smax * rng.unit().sqrt();
                phi = rng.range(0.0, std::f64::consts::TAU);
            }
            let wo = hemisphere::unmap(Vec2::new((s * phi.cos()) as f32, (s * phi.sin()) as f32));
            let r = rng.log_range(r_min as f64, r_max as f64);
            let h = r * std::f64::consts::FRAC_1_SQRT_2;
            let pk = [-s * phi.cos(), -s * phi.sin()];
            let c = match k % 3 {
                0 => pk,
                1 => [pk[0] + h, pk[1] + h * rng.range(-1.0, 1.0)],
                _ => {
                    let (rr, t) = (rng.unit().sqrt(), rng.range(0.0, std::f64::consts::TAU));
                    [rr * t.cos(), rr * t.sin()]
                }
            };
            Query {
                wo,
                centre: Vec2::new(c[0] as f32, c[1] as f32),
                r: r as f32,
            }
        })
        .collect()
}

/// The baseline: 4×4 Gauss–Legendre quadrature (f32) of `ρ cos θᵢ` over the square of
/// centre `c` and half-diagonal `r`, turned by the view azimuth when `turn` (the
/// isotropic table's square), zero outside the disk.
pub fn gl4_square(b: &dyn Brdf, wo: Vec3, c: Vec2, r: f32, turn: bool) -> f32 {
    const X: [f32; 4] = [-0.861_136_3, -0.339_981_05, 0.339_981_05, 0.861_136_3];
    const W: [f32; 4] = [0.347_854_85, 0.652_145_15, 0.652_145_15, 0.347_854_85];
    let h = r * std::f32::consts::FRAC_1_SQRT_2;
    let (cs, sn) = if turn {
        let p = hemisphere::map(wo);
        let l = p.length();
        if l > 0.0 {
            (p.x / l, p.y / l)
        } else {
            (1.0, 0.0)
        }
    } else {
        (1.0, 0.0)
    };
    let mut s = 0.0;
    for (y, wy) in X.iter().zip(W) {
        for (x, wx) in X.iter().zip(W) {
            let (a, bb) = (x * h, y * h);
            let p = Vec2::new(c.x + cs * a - sn * bb, c.y + sn * a + cs * bb);
            if p.length_squared() < 1.0 {
                s += wx * wy * b.eval(hemisphere::unmap(p), wo);
            }
        }
    }
    // weights sum to 2 per axis over [-1, 1]: area h², and dω = 2 du dv
    2.0 * s * h * h
}

/// The models of the section.
pub fn models() -> Vec<(String, Box<dyn Brdf>, Model)> {
    fn m<B: Brdf + Copy + AsModel + 'static>(name: &str, b: B) -> (String, Box<dyn Brdf>, Model) {
        (name.to_string(), Box::new(b), b.model())
    }
    // Parameters are valid constants: the constructors cannot fail on them.
    let ok = "valid BRDF parameters";
    vec![
        m("Lambert a=0.8", Lambert::new(0.8).expect(ok)),
        m("Phong e=10", Phong::new(0.3, 0.6, 10.0).expect(ok)),
        m("Phong e=100", Phong::new(0.3, 0.6, 100.0).expect(ok)),
        m("Phong e=1000", Phong::new(0.0, 1.0, 1000.0).expect(ok)),
        m(
            "Blinn-Phong e=100",
            BlinnPhong::new(0.3, 0.6, 100.0).expect(ok),
        ),
        m("Ward α=0.2", Ward::isotropic(0.3, 0.2, 0.2).expect(ok)),
        m(
            "Ward αx=0.15 αy=0.4",
            Ward::anisotropic(0.3, 0.2, 0.15, 0.4).expect(ok),
        ),
        m("GGX α=0.3", Ggx::new(0.3, 0.04, 0.3).expect(ok)),
        m("GGX α=1", Ggx::new(0.3, 0.9, 1.0).expect(ok)),
    ]
}

/// One model's tables: what the fit chose and achieved, the errors on fresh queries, the
/// times.
#[derive(Clone, Debug)]
pub struct ModelResult {
    /// Model name.
    pub name: String,
    /// Whether the BRDF is isotropic.
    pub isotropic: bool,
    /// Largest view angle tabulated (degrees).
    pub theta_max_deg: f32,
    /// The resolution the fit chose.
    pub resolution: Resolution,
    /// Bytes of the tables.
    pub bytes: usize,
    /// The fit's own report.
    pub fit: Fit,
    /// Largest table error on the fresh queries.
    pub fresh_max: f64,
    /// RMS table error on the fresh queries.
    pub fresh_rms: f64,
    /// Largest 4×4 Gauss–Legendre error on the same queries.
    pub gl_max: f64,
    /// Its RMS.
    pub gl_rms: f64,
    /// Seconds the fit took.
    pub fit_seconds: f64,
    /// Table queries per second.
    pub queries_per_s: f64,
    /// 4×4 Gauss–Legendre queries per second.
    pub gl_queries_per_s: f64,
}

/// Everything the section measures.
#[derive(Clone, Debug)]
pub struct BrdfResults {
    /// Queries per timed run.
    pub queries: usize,
    /// Timed repeats.
    pub repeats: usize,
    /// One entry per model.
    pub models: Vec<ModelResult>,
}

/// Largest and RMS error of the table `t` and of the 4×4 Gauss–Legendre baseline on `qs`
/// against the f64 reference: `(table max, table rms, GL max, GL rms)`.
fn fresh_errors(b: &dyn Brdf, model: &Model, t: &BrdfSat, qs: &[Query]) -> (f64, f64, f64, f64) {
    let (mut e_tab, mut e_gl, mut s_tab, mut s_gl) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let (mut last_wo, mut albedo) = (Vec3::NAN, 0.0);
    for x in qs {
        let wo = [x.wo.x as f64, x.wo.y as f64, x.wo.z as f64];
        if x.wo != last_wo {
            albedo = rb::albedo(model, wo, 1e-5);
            last_wo = x.wo;
        }
        let pm = rb::map(wo);
        let angle = if b.is_isotropic() {
            pm[1].atan2(pm[0])
        } else {
            0.0
        };
        let r = x.r as f64;
        let c = [x.centre.x as f64, x.centre.y as f64];
        let exact = rb::square_integral(model, wo, c, r, angle, 1e-4 * albedo * r * r);
        let et = rb::table_error(t.integral(x.wo, x.centre, x.r) as f64, exact, albedo, r);
        let eg = rb::table_error(
            gl4_square(b, x.wo, x.centre, x.r, b.is_isotropic()) as f64,
            exact,
            albedo,
            r,
        );
        e_tab = e_tab.max(et);
        e_gl = e_gl.max(eg);
        s_tab += et * et;
        s_gl += eg * eg;
    }
    let n = qs.len() as f64;
    (e_tab, (s_tab / n).sqrt(), e_gl, (s_gl / n).sqrt())
}

/// Runs the section's measurements.
pub fn measure(opts: &Options) -> Result<BrdfResults, Box<dyn Error>> {
    let models = models();
    let bar = ProgressBar::new(models.len() as u64).with_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let theta_max = THETA_MAX_DEG.to_radians();
    let iso_opts = FitOptions {
        r_min: R_MIN,
        r_max: R_MAX,
        theta_max,
        max_grid: 256,
        max_polar: 65,
        max_azimuth: 64,
        max_bytes: MAX_BYTES,
        ..FitOptions::new(TARGET)
    };
    // Anisotropic: views up to 60° (between azimuth nodes the mirror direction sweeps a
    // long arc at grazing views; linear interpolation there needs many nodes).
    let aniso_opts = FitOptions {
        theta_max: ANISO_THETA_MAX_DEG.to_radians(),
        ..iso_opts
    };
    let n_timed = opts.scaled(QUERIES);
    let mut rows = Vec::new();
    for (name, b, model) in &models {
        bar.set_message(name.clone());
        let fo = if b.is_isotropic() {
            &iso_opts
        } else {
            &aniso_opts
        };
        let (t, fit_time) = timed(|| BrdfSat::fit(b.as_ref(), fo));
        let t = t?;
        let fit = t
            .fit_report()
            .ok_or("BrdfSat::fit returned no fit report")?;
        // Fresh queries against the f64 reference: table and baseline errors.
        let checked = queries(CHECKED, R_MIN, R_MAX, fo.theta_max, QUERY_SEED);
        let (fresh_max, fresh_rms, gl_max, gl_rms) = fresh_errors(b.as_ref(), model, &t, &checked);
        let q = queries(n_timed, R_MIN, R_MAX, fo.theta_max, QUERY_SEED);
        let t_tab = median_time(opts.repeats, || {
            black_box(
                q.iter()
                    .map(|x| t.integral(x.wo, x.centre, x.r))
                    .sum::<f32>(),
            );
        });
        let t_gl = median_time(opts.repeats, || {
            black_box(
                q.iter()
                    .map(|x| gl4_square(b.as_ref(), x.wo, x.centre, x.r, b.is_isotropic()))
                    .sum::<f32>(),
            );
        });
        rows.push(ModelResult {
            name: name.clone(),
            isotropic: b.is_isotropic(),
            theta_max_deg: fo.theta_max.to_degrees(),
            resolution: t.resolution(),
            bytes: t.bytes(),
            fit,
            fresh_max,
            fresh_rms,
            gl_max,
            gl_rms,
            fit_seconds: fit_time.as_secs_f64(),
            queries_per_s: per_second(n_timed, t_tab),
            gl_queries_per_s: per_second(n_timed, t_gl),
        });
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(BrdfResults {
        queries: n_timed,
        repeats: opts.repeats,
        models: rows,
    })
}

/// `""`, or `" (not met)"` when the fit missed its target.
fn not_met(m: &ModelResult) -> &'static str {
    if m.fit.met { "" } else { " (not met)" }
}

/// The summary text of the section.
fn summary(r: &BrdfResults) -> String {
    let mut summary = format!(
        "BRDF SATs (target {TARGET}, squares r {R_MIN}–{R_MAX}, views ≤ {THETA_MAX_DEG}° \
         (anisotropic ≤ {ANISO_THETA_MAX_DEG}°), ≤ {} MiB per model; baseline: 4×4 Gauss–Legendre over the square, same run):\n",
        MAX_BYTES >> 20
    );
    for m in &r.models {
        let views = format!("{}×{}", m.resolution.polar, m.resolution.azimuth);
        let _ = writeln!(
            summary,
            "  {:<22} grid {:>4} views {:>6} {:>7.2} MiB fit max {:.4}{} fresh max {:.4} \
             (GL4×4 {:.4}) fit {:.2} s, {:.1} M q/s = {:.1}× GL4×4",
            m.name,
            m.resolution.grid,
            views,
            m.bytes as f64 / (1 << 20) as f64,
            m.fit.max_error,
            not_met(m),
            m.fresh_max,
            m.gl_max,
            m.fit_seconds,
            m.queries_per_s / 1e6,
            m.queries_per_s / m.gl_queries_per_s
        );
    }
    summary
}

/// The HTML of the section.
fn html(r: &BrdfResults) -> String {
    let mut html = format!(
        "<p>Each model's tables are chosen by <code>BrdfSat::fit</code> for a target error of \
         {TARGET} (error = |T − R| / max(R, albedo·4r²/2π), see <code>brdf_sat</code>) on squares of \
         half-diagonal {R_MIN}–{R_MAX} (parametrisation units) and views up to {THETA_MAX_DEG}° (anisotropic: {ANISO_THETA_MAX_DEG}°), at most {} MiB of tables per model. \
         “fit” errors are over the fit's own test set, “fresh” over {CHECKED} other queries \
         against the f64 reference. Throughput over {} queries, median of {}; \
         the baseline is a 4×4 Gauss–Legendre quadrature of ρ·cos over the same square \
         (16 BRDF evaluations).</p><table><tr><th>model</th><th>grid</th><th>views</th>\
         <th>MiB</th><th>fit max / rms</th><th>fresh max / rms</th><th>GL 4×4 max / rms</th>\
         <th>fit s</th><th>M queries/s</th><th>× GL 4×4</th></tr>",
        MAX_BYTES >> 20,
        r.queries,
        r.repeats
    );
    for m in &r.models {
        let views = format!("{}×{}", m.resolution.polar, m.resolution.azimuth);
        let _ = write!(
            html,
            "<tr><td>{}</td><td>{}</td><td>{views}</td><td>{:.2}</td><td>{:.4} / {:.4}{}</td>\
             <td>{:.4} / {:.4}</td><td>{:.4} / {:.4}</td><td>{:.2}</td><td>{:.1}</td><td>{:.1}</td></tr>",
            m.name,
            m.resolution.grid,
            m.bytes as f64 / (1 << 20) as f64,
            m.fit.max_error,
            m.fit.rms_error,
            not_met(m),
            m.fresh_max,
            m.fresh_rms,
            m.gl_max,
            m.gl_rms,
            m.fit_seconds,
            m.queries_per_s / 1e6,
            m.queries_per_s / m.gl_queries_per_s
        );
    }
    html.push_str("</table>");
    html
}

/// The data of the section in `report.json`.
fn data(r: &BrdfResults) -> serde_json::Value {
    let models: Vec<_> = r
        .models
        .iter()
        .map(|m| {
            json!({
                "model": m.name,
                "isotropic": m.isotropic,
                "theta_max_deg": m.theta_max_deg,
                "grid": m.resolution.grid,
                "polar_views": m.resolution.polar,
                "azimuth_views": m.resolution.azimuth,
                "bytes": m.bytes,
                "target": m.fit.target,
                "met": m.fit.met,
                "fit_max_error": m.fit.max_error,
                "fit_rms_error": m.fit.rms_error,
                "fit_steps": m.fit.steps,
                "fresh_max_error": m.fresh_max,
                "fresh_rms_error": m.fresh_rms,
                "gl4x4_max_error": m.gl_max,
                "gl4x4_rms_error": m.gl_rms,
                "fit_seconds": m.fit_seconds,
                "queries_per_s": m.queries_per_s,
                "gl4x4_queries_per_s": m.gl_queries_per_s,
            })
        })
        .collect();
    json!({
        "target": TARGET,
        "r_min": R_MIN,
        "r_max": R_MAX,
        "theta_max_deg": THETA_MAX_DEG,
        "queries": r.queries,
        "checked": CHECKED,
        "models": models,
    })
}

/// The section of measured results.
pub fn render(r: &BrdfResults) -> Section {
    Section {
        id: "brdf_sat",
        title: "BRDF summed-area tables".into(),
        summary: summary(r),
        html: html(r),
        data: data(r),
        files: Vec::new(),
    }
}

/// The section.
pub fn section(opts: &Options) -> Result<Section, Box<dyn Error>> {
    Ok(render(&measure(opts)?))
}
