//! Report section "scenes": whole images of the built-in scenes by each method against the
//! path-traced reference, and the speed-against-error curve of each pipeline beside the
//! path tracer's own (error against samples per pixel), so that a method reads as "the
//! path tracer would need N× longer for the same error".
//!
//! Per scene (`lobes`, `cluster`, at [`WIDTH`] columns): the reference is the path tracer
//! at [`REFERENCE_SPP`] samples per pixel (direct light); the path tracer's curve is the
//! same tracer with other seeds at 1–64 samples; the `lobes` method's curve is its
//! pruning threshold, with the L2 cap fit and one lobe per occluder (instead of the
//! default energy-preserving fit and quadtree mask) beside it. Times
//! are wall-clock seconds of whole renders on this machine's thread pool, both sides alike.
//! "Equal-error cost": the path tracer's time at the method's error, interpolated on its
//! curve in log–log (error falls as `spp^−½`), over the method's time.

use std::error::Error;
use std::fmt::Write as _;
use std::time::Instant;

use indicatif::ProgressBar;
use serde_json::json;
use steradian_core::lobe::cap::CapFit;

use super::Options;
use super::plot::{Axis, Chart, Pt, Scale, Series};
use super::section::Section;
use crate::scene::metrics::{self, Metrics};
use crate::scene::{Scene, lobes, path};

/// Image width of the section's renders (the height follows each scene's aspect ratio).
pub const WIDTH: u32 = 128;
/// Samples per pixel of the reference.
pub const REFERENCE_SPP: u32 = 512;
/// The path tracer's own curve.
const PATH_SPP: &[u32] = &[1, 2, 4, 8, 16, 64];
/// Pruning thresholds of the `lobes` curve.
const THRESHOLDS: &[f32] = &[0.0, 1e-4, 1e-3, 1e-2, 5e-2];

/// One point of a curve.
#[derive(Clone, Debug)]
struct Point {
    setting: String,
    seconds: f64,
    metrics: Metrics,
    products_per_pixel: Option<f64>,
}

/// One scene's measurements.
struct SceneResult {
    name: &'static str,
    width: u32,
    height: u32,
    reference_seconds: f64,
    path: Vec<Point>,
    lobes: Vec<Point>,
    lobes_l2: Point,
    lobes_per: Point,
    /// The path tracer's time at the default `lobes` point's error over that point's time.
    equal_error_ratio: f64,
    files: Vec<(String, Vec<u8>)>,
}

fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t = Instant::now();
    let v = f();
    (v, t.elapsed().as_secs_f64())
}

/// The path tracer's seconds at `err`, interpolated log–log on its curve (extrapolated
/// with slope −2 in time per decade of error beyond its ends).
fn path_seconds_at(curve: &[Point], err: f64) -> f64 {
    let pts: Vec<(f64, f64)> = curve
        .iter()
        .map(|p| (p.metrics.mean_abs_over_max.ln(), p.seconds.ln()))
        .collect();
    let e = err.ln();
    for w in pts.windows(2) {
        let ((e0, t0), (e1, t1)) = (w[0], w[1]);
        if (e <= e0 && e >= e1) || (e >= e0 && e <= e1) {
            let f = if e1 == e0 { 0.0 } else { (e - e0) / (e1 - e0) };
            return (t0 + f * (t1 - t0)).exp();
        }
    }
    // Beyond the curve: error ∝ spp^−½ ∝ time^−½.
    let (e_end, t_end) = if e < pts[pts.len() - 1].0 {
        pts[pts.len() - 1]
    } else {
        pts[0]
    };
    (t_end - 2.0 * (e - e_end)).exp()
}

fn measure_scene(name: &'static str, bar: &ProgressBar) -> Result<SceneResult, Box<dyn Error>> {
    let mut scene = Scene::load(&format!("builtin:{name}"))?;
    scene.camera = scene.camera.resized(WIDTH)?;
    let hidden = ProgressBar::hidden();
    let settings = |spp, seed| path::Settings {
        spp,
        bounces: 0,
        seed,
    };
    let (reference, reference_seconds) =
        timed(|| path::render(&scene, &settings(REFERENCE_SPP, 1), &hidden));
    bar.inc(1);
    let compare = |img: &crate::scene::image::Image| {
        metrics::compare(&scene, img, &reference.image, Some(&reference.stderr), 0.0)
    };
    let mut path_curve = Vec::new();
    for &spp in PATH_SPP {
        let (out, s) = timed(|| path::render(&scene, &settings(spp, 1000 + spp as u64), &hidden));
        path_curve.push(Point {
            setting: format!("{spp} spp"),
            seconds: s,
            metrics: compare(&out.image)?,
            products_per_pixel: None,
        });
    }
    bar.inc(1);
    let px = scene.camera.pixels() as f64;
    let run_lobes = |o: &lobes::Options| -> Result<(Point, crate::scene::image::Image), String> {
        // The best of three runs: one render is a few milliseconds.
        let mut best = f64::INFINITY;
        let mut last = None;
        for _ in 0..3 {
            let ((img, counts), s) = timed(|| lobes::render(&scene, o, &hidden));
            best = best.min(s);
            last = Some((img, counts));
        }
        let (img, counts) = last.expect("three runs");
        Ok((
            Point {
                setting: format!("t = {:.0e}", o.threshold),
                seconds: best,
                metrics: compare(&img)?,
                products_per_pixel: Some(counts.computed as f64 / px),
            },
            img,
        ))
    };
    let mut lobes_curve = Vec::new();
    let mut default_img = None;
    let default = lobes::Options::default();
    for &t in THRESHOLDS {
        let o = lobes::Options {
            threshold: t,
            ..default
        };
        let (p, img) = run_lobes(&o)?;
        if t == default.threshold {
            default_img = Some((p.clone(), img));
        }
        lobes_curve.push(p);
    }
    let (mut lobes_l2, _) = run_lobes(&lobes::Options {
        fit: CapFit::L2,
        ..default
    })?;
    lobes_l2.setting = format!("L2 fit, t = {:.0e}", default.threshold);
    let (mut lobes_per, _) = run_lobes(&lobes::Options {
        visibility: lobes::Visibility::PerOccluder,
        ..default
    })?;
    lobes_per.setting = format!("one lobe per occluder, t = {:.0e}", default.threshold);
    bar.inc(1);
    let (dp, dimg) = default_img.ok_or("the default threshold is on the curve")?;
    let equal_error_ratio = path_seconds_at(&path_curve, dp.metrics.mean_abs_over_max) / dp.seconds;
    let png = |img: &crate::scene::image::Image| -> Result<Vec<u8>, String> {
        let mut bytes = Vec::new();
        img.to_rgb8(0.0)
            .write_to(
                &mut std::io::Cursor::new(&mut bytes),
                image::ImageFormat::Png,
            )
            .map_err(|e| e.to_string())?;
        Ok(bytes)
    };
    let diff = metrics::difference_image(
        &scene,
        &dimg,
        &reference.image,
        dp.metrics.max_radiance,
        0.05,
    );
    let files = vec![
        (format!("scene_{name}_path.png"), png(&reference.image)?),
        (format!("scene_{name}_lobes.png"), png(&dimg)?),
        (format!("scene_{name}_lobes_diff.png"), png(&diff)?),
    ];
    Ok(SceneResult {
        name,
        width: scene.camera.width,
        height: scene.camera.height,
        reference_seconds,
        path: path_curve,
        lobes: lobes_curve,
        lobes_l2,
        lobes_per,
        equal_error_ratio,
        files,
    })
}

fn point_json(p: &Point) -> serde_json::Value {
    json!({
        "setting": p.setting,
        "seconds": p.seconds,
        "products_per_pixel": p.products_per_pixel,
        "errors": p.metrics,
    })
}

fn plot(r: &SceneResult) -> String {
    let pts = |c: &[Point]| -> Vec<Pt> {
        c.iter()
            .map(|p| Pt {
                note: Some(p.setting.clone()),
                ..Pt::new(p.seconds, p.metrics.mean_abs_over_max)
            })
            .collect()
    };
    Chart::new(
        format!("Scene {}: error against time", r.name),
        Axis::new("seconds per image", Scale::Log),
        Axis::new("mean |diff| / max radiance", Scale::Log),
        vec![
            Series::line("path tracer (spp)", pts(&r.path)),
            Series::line("lobes (threshold)", pts(&r.lobes)).wide(),
            Series::dots("lobes, L2 cap fit", pts(std::slice::from_ref(&r.lobes_l2))),
            Series::dots(
                "lobes, one lobe per occluder",
                pts(std::slice::from_ref(&r.lobes_per)),
            ),
        ],
    )
    .svg()
}

/// The report section (see the module docs).
pub fn section(_opts: &Options) -> Result<Section, Box<dyn Error>> {
    let bar = ProgressBar::new(6);
    bar.set_message("scenes");
    let results = ["lobes", "cluster"]
        .into_iter()
        .map(|n| measure_scene(n, &bar))
        .collect::<Result<Vec<_>, _>>()?;
    bar.finish_and_clear();
    let default_t = lobes::Options::default().threshold;
    let mut summary = String::new();
    let mut html = String::new();
    let mut files = Vec::new();
    let mut data = Vec::new();
    writeln!(
        html,
        "<p>Built-in scenes at {WIDTH} columns, direct light. Reference: the path tracer at \
         {REFERENCE_SPP} samples per pixel. Errors over shaded, non-silhouette pixels (see the \
         README, \"Errors\"); times are whole renders on this machine's thread pool.</p>"
    )?;
    for r in &results {
        let d = r
            .lobes
            .iter()
            .find(|p| p.setting == format!("t = {default_t:.0e}"))
            .ok_or("default point")?;
        writeln!(
            summary,
            "  {}: lobes {:.2e} of max radiance in {:.1} ms (L2 fit {:.2e}, one lobe per occluder {:.2e}); path tracer {:.2e} at 1 spp, {:.2e} at 64 spp; reference noise {:.1e}; equal-error cost ratio {:.1}×",
            r.name,
            d.metrics.mean_abs_over_max,
            d.seconds * 1e3,
            r.lobes_l2.metrics.mean_abs_over_max,
            r.lobes_per.metrics.mean_abs_over_max,
            r.path[0].metrics.mean_abs_over_max,
            r.path[r.path.len() - 1].metrics.mean_abs_over_max,
            d.metrics.reference_noise_over_max,
            r.equal_error_ratio
        )?;
        writeln!(
            html,
            "<h3>{}</h3><p>{}×{}; reference {:.1} s. The path tracer needs {:.1}× the time of \
             <code>lobes</code> (t = {default_t:.0e}) for its error.</p>\
             <p><img src=\"scene_{0}_path.png\" alt=\"path\"> <img src=\"scene_{0}_lobes.png\" alt=\"lobes\"> \
             <img src=\"scene_{0}_lobes_diff.png\" alt=\"difference\"> (reference, lobes, difference: red brighter, blue darker, full at 5 % of the maximum)</p>\
             <img src=\"scene_{0}.svg\" alt=\"curve\">",
            r.name, r.width, r.height, r.reference_seconds, r.equal_error_ratio
        )?;
        html.push_str("<table><tr><th>method</th><th>setting</th><th>s</th><th>mean |diff|/max</th><th>rel L2</th><th>PSNR dB</th><th>SSIM</th><th>products/px</th></tr>");
        for (m, p) in r
            .path
            .iter()
            .map(|p| ("path", p))
            .chain(r.lobes.iter().map(|p| ("lobes", p)))
            .chain([("lobes", &r.lobes_l2), ("lobes", &r.lobes_per)])
        {
            write!(
                html,
                "<tr><td>{m}</td><td>{}</td><td>{:.4}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.1}</td><td>{:.4}</td><td>{}</td></tr>",
                p.setting,
                p.seconds,
                p.metrics.mean_abs_over_max,
                p.metrics.rel_l2,
                p.metrics.psnr_db,
                p.metrics.ssim,
                p.products_per_pixel
                    .map_or("–".into(), |v| format!("{v:.1}"))
            )?;
        }
        html.push_str("</table>");
        files.extend(r.files.iter().cloned());
        files.push((format!("scene_{}.svg", r.name), plot(r).into_bytes()));
        data.push(json!({
            "scene": r.name,
            "width": r.width,
            "height": r.height,
            "reference_spp": REFERENCE_SPP,
            "reference_seconds": r.reference_seconds,
            "path": r.path.iter().map(point_json).collect::<Vec<_>>(),
            "lobes": r.lobes.iter().map(point_json).collect::<Vec<_>>(),
            "lobes_l2_fit": point_json(&r.lobes_l2),
            "lobes_per_occluder": point_json(&r.lobes_per),
            "equal_error_cost_ratio": r.equal_error_ratio,
        }));
    }
    Ok(Section {
        id: "scenes",
        title: "Scenes: whole images against the path tracer".into(),
        summary,
        html,
        data: json!({ "scenes": data }),
        files,
    })
}
