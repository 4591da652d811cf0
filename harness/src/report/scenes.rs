//! Report section "scenes": whole images of the built-in scenes by each method against the
//! path-traced reference, and the speed-against-error curve of each pipeline beside the
//! path tracer's own (error against samples per pixel), so that a method reads as "the
//! path tracer would need N× longer for the same error".
//!
//! Per scene of [`SCENES`] (at [`WIDTH`] columns): the reference is the path tracer at
//! [`REFERENCE_SPP`] samples per pixel ([`ROOM_REFERENCE_SPP`] for `room` and
//! [`ENVIRONMENT_REFERENCE_SPP`] for `environment`, whose references are the noisiest per
//! sample), direct light for `lobes` and `cluster` and
//! one bounce for `room`; the path tracer's curve is the same tracer with other seeds at
//! [`PATH_SPP`] samples. The default point of `lobes` and `hvl` is what `steradian render`
//! plans at the default target error (`planned`: the product table among its choices, the
//! built-in table a `lobes` variant); that of `rsl` is its plan with `K` set
//! to the paper's 30 (its curve sweeps `K` at the plan's cube face, visibility side and
//! coverage depth). Every method renders with its SIMD path (the default of `steradian
//! render`), its scalar path at the default setting a variant. The
//! `lobes` method's curve is its
//! pruning threshold at the planned quadtree depth and every other depth at the planned
//! threshold, with the L2 cap fit and
//! one lobe per occluder (instead of the default energy-preserving fit and quadtree mask)
//! beside it; the `hvl` method's curve is its HVL count at the planned lattice stride
//! (`scene::lattice`), with every pixel computed (the paper), the other lattice spacings,
//! the paper's choice of no HVL visibility and the direct light alone beside it (the
//! one-core throughputs of its kernels are measured with every pixel computed); the `rsl`
//! method's is its number of square lights `K`. Times
//! are wall-clock seconds of whole renders on this machine's thread pool, both sides alike
//! (the best of at least three runs, repeated for 0.25 s, for both).
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
use crate::scene::image::Image;
use crate::scene::metrics::{self, Metrics};
use crate::scene::{Scene, Seen, hvl, lobes, path, render, rsl};

/// Image width of the section's renders (the height follows each scene's aspect ratio).
pub const WIDTH: u32 = 96;
/// Samples per pixel of the `lobes` and `cluster` references. A noisy reference inflates
/// the method's error and the path tracer's alike, and the path tracer's curve,
/// extrapolated as `spp^−½` from a point that carries that noise, then reaches the method's
/// error in too few samples; each point reports the reference's noise
/// (`reference_noise_over_max`) beside its errors, so the choice can be judged per run.
pub const REFERENCE_SPP: u32 = 2048;
/// Samples per pixel of the `room` reference (one bounce), noisier per sample than the
/// direct-light scenes'.
pub const ROOM_REFERENCE_SPP: u32 = 4096;
/// Samples per pixel of the `environment` reference, the noisiest per sample (a sun in
/// the environment and a glossy sphere): at 4096 its noise was larger than the `rsl`
/// method's own mean |difference|, so that measure read the reference, not the method
/// (each point reports `reference_noise_over_max` beside its errors).
pub const ENVIRONMENT_REFERENCE_SPP: u32 = 16384;

/// The reference's samples per pixel for a scene.
fn reference_spp(name: &str) -> u32 {
    match name {
        "environment" => ENVIRONMENT_REFERENCE_SPP,
        "room" => ROOM_REFERENCE_SPP,
        _ => REFERENCE_SPP,
    }
}
/// Samples per pixel of the path tracer's own curve.
pub const PATH_SPP: &[u32] = &[1, 2, 4, 8, 16, 64, 256];
/// Pruning thresholds of the `lobes` curve.
const THRESHOLDS: &[f32] = &[0.0, 1e-4, 1e-3, 1e-2, 5e-2];
/// Reflective-shadow-map face sides of the `hvl` curve.
const HVL_SIDES: &[usize] = &[2, 4, 8, 12];
/// Square-light counts of the `rsl` curve (the paper's Figures 9–10 use 10–100).
const RSL_KS: &[usize] = &[10, 30, 100, 300];

/// One point of a curve.
#[derive(Clone, Debug)]
struct Point {
    setting: String,
    seconds: f64,
    metrics: Metrics,
    products_per_pixel: Option<f64>,
    /// Seconds of one-time precomputation not in `seconds` (`rsl`: decomposition and
    /// BRDF tables).
    build_seconds: Option<f64>,
}

/// One scene's measurements.
struct SceneResult {
    name: &'static str,
    method: &'static str,
    bounces: u32,
    width: u32,
    height: u32,
    reference_seconds: f64,
    path: Vec<Point>,
    /// The method's curve over its main setting.
    curve: Vec<Point>,
    /// Single points: the method with one choice changed.
    variants: Vec<Point>,
    /// Shading throughput on one core: (kernel, setting, seconds, surface points).
    per_core: Vec<(&'static str, String, f64, usize)>,
    /// The path tracer's time at the default point's error over that point's time.
    equal_error_ratio: f64,
    /// Index of the default point in `curve`.
    default: usize,
    files: Vec<(String, Vec<u8>)>,
}

fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t = Instant::now();
    let v = f();
    (v, t.elapsed().as_secs_f64())
}

/// The last result of `f` and its best time over at least three runs, repeated until
/// [`BEST_OF_SECONDS`] have passed (at most 100 runs): renders of a millisecond fall
/// inside the host's slow spells often enough that three runs are not enough. The path
/// tracer's curve and the methods are timed alike.
fn best_of<T>(f: impl Fn() -> T) -> (T, f64) {
    let start = Instant::now();
    let (mut last, mut best) = timed(&f);
    for runs in 1..100 {
        if runs >= 3 && start.elapsed().as_secs_f64() >= BEST_OF_SECONDS {
            break;
        }
        let (r, s) = timed(&f);
        best = best.min(s);
        last = r;
    }
    (last, best)
}

/// How long [`best_of`] repeats a render.
const BEST_OF_SECONDS: f64 = 0.25;

/// The path tracer's seconds at `err` of the measure `m`, interpolated log–log on its
/// curve (extrapolated with slope −2 in time per decade of error beyond its ends); `None`
/// when `err` or a curve point is not positive (a noise-corrected error below the
/// reference's resolution).
fn path_seconds_at(curve: &[Point], err: f64, m: fn(&Metrics) -> f64) -> Option<f64> {
    let positive = |v: f64| v > 0.0;
    if !positive(err) || curve.iter().any(|p| !positive(m(&p.metrics))) || curve.is_empty() {
        return None;
    }
    let pts: Vec<(f64, f64)> = curve
        .iter()
        .map(|p| (m(&p.metrics).ln(), p.seconds.ln()))
        .collect();
    let e = err.ln();
    for w in pts.windows(2) {
        let ((e0, t0), (e1, t1)) = (w[0], w[1]);
        if (e <= e0 && e >= e1) || (e >= e0 && e <= e1) {
            let f = if e1 == e0 { 0.0 } else { (e - e0) / (e1 - e0) };
            return Some((t0 + f * (t1 - t0)).exp());
        }
    }
    // Beyond the curve: error ∝ spp^−½ ∝ time^−½.
    let (e_end, t_end) = if e < pts[pts.len() - 1].0 {
        pts[pts.len() - 1]
    } else {
        pts[0]
    };
    Some((t_end - 2.0 * (e - e_end)).exp())
}

/// The three measures the equal-error cost is read on, one per paper: mean |difference|
/// over the maximum (the cosine-lobe paper's), noise-corrected relative L2 (the RSL
/// paper's) and the RMSE of the tone-mapped images (the HVL paper's), each over the shaded
/// pixels (silhouettes apart: there a pixel-centre method and the box-filtered reference
/// legitimately differ, and the whole-image RMSE measures that).
fn mean_abs(m: &Metrics) -> f64 {
    m.mean_abs_over_max
}
fn rel_l2_corrected(m: &Metrics) -> f64 {
    m.rel_l2_noise_corrected
}
fn rmse(m: &Metrics) -> f64 {
    m.rmse_shaded
}

/// The path tracer's time at a point's error over the point's time, on each measure:
/// `[mean |diff|, noise-corrected rel L2, RMSE]`.
fn cost_ratios(path: &[Point], p: &Point) -> [Option<f64>; 3] {
    let r = |m: fn(&Metrics) -> f64| path_seconds_at(path, m(&p.metrics), m).map(|t| t / p.seconds);
    [r(mean_abs), r(rel_l2_corrected), r(rmse)]
}

/// A method's render under one setting: the image and its kernel products per pixel.
type Render<'a> = Box<dyn Fn() -> (Image, Option<f64>) + Sync + 'a>;

/// One setting to measure: its label, the render, and whether it is the default.
struct Setting<'a> {
    label: String,
    render: Render<'a>,
    default: bool,
    /// Seconds of precomputation done before the timed render, if any.
    build_seconds: Option<f64>,
    /// The kernel this setting's one-core throughput is reported under (`per_core[]`),
    /// if it is measured.
    per_core: Option<&'static str>,
}

/// The options `steradian render` plans for `scene` and `method` at the default target
/// error (`scene::render::plan`), so that a default point is what a user gets; the
/// methods' own defaults where the plan refuses the scene.
fn planned(scene: &Scene, method: render::Method) -> Option<render::Plan> {
    render::plan(
        scene,
        &render::Options {
            method,
            quiet: true,
            ..render::Options::default()
        },
    )
    .ok()
}

/// The depth of a mask visibility (the deepest level for one lobe per occluder).
fn mask_depth(v: lobes::Visibility) -> u32 {
    match v {
        lobes::Visibility::Mask { depth, .. } => depth,
        lobes::Visibility::PerOccluder => steradian_core::lobe::mask::MAX_DEPTH,
    }
}

fn lobes_settings<'a>(
    scene: &'a Scene,
    gpu: Option<&'a std::sync::Mutex<crate::backend::gpu::Gpu>>,
) -> (Vec<Setting<'a>>, Vec<Setting<'a>>) {
    let px = scene.camera.pixels() as f64;
    let d = planned(scene, render::Method::Lobes).map_or_else(lobes::Options::default, |p| p.lobes);
    // Renders with the SIMD path, `steradian render`'s default; the scalar path at the
    // default setting is a variant.
    let mk_with = move |label: String, o: lobes::Options, default: bool, simd: bool| Setting {
        label,
        render: Box::new(move || {
            let hidden = ProgressBar::hidden();
            let (img, c) = if simd {
                lobes::render_simd(scene, &o, &hidden)
            } else {
                lobes::render(scene, &o, &hidden)
            };
            (img, Some(c.computed as f64 / px))
        }),
        default,
        build_seconds: None,
        per_core: if simd {
            default.then_some("simd")
        } else {
            Some("scalar")
        },
    };
    let mk =
        move |label: String, o: lobes::Options, default: bool| mk_with(label, o, default, true);
    let mk_gpu = move |gpu: &'a std::sync::Mutex<crate::backend::gpu::Gpu>| Setting {
        label: format!(
            "t = {:.0e}, depth {}, wgpu (every chain on the adapter)",
            d.threshold,
            mask_depth(d.visibility)
        ),
        render: Box::new(move || {
            let blank = || Image::new(scene.camera.width as usize, scene.camera.height as usize);
            gpu.lock()
                .map_err(|_| "adapter lock poisoned".to_string())
                .and_then(|mut g| lobes::render_gpu(scene, &d, &mut g, &ProgressBar::hidden()))
                .map_or_else(
                    |_| (blank(), None),
                    |(img, c)| (img, Some(c.computed as f64 / px)),
                )
        }),
        default: false,
        build_seconds: None,
        per_core: Some("wgpu"),
    };
    let depth = mask_depth(d.visibility);
    // The curve's thresholds and the planned one (`--target-error`/10).
    let mut thresholds = THRESHOLDS.to_vec();
    if !thresholds.contains(&d.threshold) {
        thresholds.push(d.threshold);
        thresholds.sort_by(f32::total_cmp);
    }
    let mut curve: Vec<Setting<'_>> = thresholds
        .iter()
        .map(|&t| {
            mk(
                format!("t = {t:.0e}, depth {depth}"),
                lobes::Options { threshold: t, ..d },
                t == d.threshold,
            )
        })
        .collect();
    // The quadtree depths the plan did not choose, at its threshold.
    if let lobes::Visibility::Mask { leaves, .. } = d.visibility {
        for k in (1..=steradian_core::lobe::mask::MAX_DEPTH).filter(|&k| k != depth) {
            curve.push(mk(
                format!("t = {:.0e}, depth {k}", d.threshold),
                lobes::Options {
                    visibility: lobes::Visibility::Mask { depth: k, leaves },
                    ..d
                },
                false,
            ));
        }
    }
    let mut variants = vec![
        mk_with(
            format!("t = {:.0e}, depth {depth}, scalar kernel", d.threshold),
            d,
            false,
            false,
        ),
        mk(
            format!("L2 cap fit, t = {:.0e}, depth {depth}", d.threshold),
            lobes::Options {
                fit: CapFit::L2,
                ..d
            },
            false,
        ),
        mk(
            format!(
                "energy-preserving light lobe in the glossy chains (the paper's fit), t = {:.0e}, depth {depth}",
                d.threshold
            ),
            lobes::Options {
                glossy_fit: CapFit::EnergyPreserving,
                ..d
            },
            false,
        ),
        mk(
            format!(
                "pixel centres only (no footprint refinement), t = {:.0e}, depth {depth}",
                d.threshold
            ),
            lobes::Options {
                footprint: 0.0,
                ..d
            },
            false,
        ),
        mk(
            format!(
                "lobe product for the unshadowed diffuse term (the paper), t = {:.0e}, depth {depth}",
                d.threshold
            ),
            lobes::Options {
                exact_diffuse: false,
                ..d
            },
            false,
        ),
        mk(
            format!("one lobe per occluder, t = {:.0e}", d.threshold),
            lobes::Options {
                visibility: lobes::Visibility::PerOccluder,
                ..d
            },
            false,
        ),
        mk(
            format!(
                "built-in product table ({}), t = {:.0e}, depth {depth}",
                lobes::TableSize::BuiltIn,
                d.threshold
            ),
            lobes::Options {
                table: lobes::TableSize::BuiltIn,
                ..d
            },
            false,
        ),
    ];
    variants.extend(gpu.map(mk_gpu));
    (curve, variants)
}

fn hvl_settings<'a>(
    scene: &'a Scene,
    gpu: Option<&'a std::sync::Mutex<crate::backend::gpu::Gpu>>,
) -> (Vec<Setting<'a>>, Vec<Setting<'a>>) {
    let d = planned(scene, render::Method::Hvl).map_or_else(hvl::Options::default, |p| p.hvl);
    // The planned options sum the HVLs with the SIMD kernels (`steradian render`'s default);
    // the scalar kernels at the default setting are a variant.
    let mk = move |label: String, o: hvl::Options, default: bool| Setting {
        label,
        render: Box::new(move || (hvl::render(scene, &o, &ProgressBar::hidden()).0, None)),
        default,
        build_seconds: None,
        per_core: (!o.simd).then_some("scalar"),
    };
    let curve = HVL_SIDES
        .iter()
        .map(|&side| {
            mk(
                format!("{} HVLs", 6 * side * side * scene.lights.len()),
                hvl::Options { side, ..d },
                side == d.side,
            )
        })
        .collect();
    let px = scene.camera.pixels() as f64;
    let direct = d.direct;
    let hvls = 6 * d.side * d.side * scene.lights.len();
    // The one-core throughputs compare kernels, so they are measured where every pixel is
    // computed (the wgpu path interpolates none): the SIMD and scalar kernels at stride 1.
    let every = hvl::Options { stride: 1, ..d };
    let mut variants = vec![
        Setting {
            per_core: Some("simd"),
            ..mk(
                format!("{hvls} HVLs, every pixel (the paper)"),
                every,
                false,
            )
        },
        mk(
            format!("{hvls} HVLs, every pixel, scalar kernels"),
            hvl::Options {
                simd: false,
                ..every
            },
            false,
        ),
        mk(
            format!("{hvls} HVLs, every pixel, no HVL visibility (the paper's pipeline)"),
            hvl::Options {
                visibility: false,
                ..every
            },
            false,
        ),
        mk(
            format!("{hvls} HVLs, diffuse receivers only (no glossy tables)"),
            hvl::Options { glossy: false, ..d },
            false,
        ),
    ];
    // The other lattice spacings the plan weighs, for the speed-against-error trade.
    variants.extend(
        crate::scene::lattice::STRIDE_CANDIDATES
            .iter()
            .filter(|&&s| s != 1 && s != d.stride)
            .map(|&stride| {
                mk(
                    format!("{hvls} HVLs, lattice spacing {stride}"),
                    hvl::Options { stride, ..d },
                    false,
                )
            }),
    );
    if let Some(gpu) = gpu {
        variants.push(Setting {
            label: format!(
                "{hvls} HVLs, every pixel, wgpu (direct and diffuse indirect on the adapter)"
            ),
            render: Box::new(move || {
                let blank =
                    || Image::new(scene.camera.width as usize, scene.camera.height as usize);
                let img = gpu
                    .lock()
                    .map_err(|_| "adapter lock poisoned".to_string())
                    .and_then(|mut g| {
                        hvl::render_gpu(scene, &every, &mut g, &ProgressBar::hidden())
                    })
                    .map_or_else(|_| blank(), |(img, _)| img);
                (img, None)
            }),
            default: false,
            build_seconds: None,
            per_core: Some("wgpu"),
        });
    }
    variants.extend([Setting {
        label: "direct light only (lobes)".into(),
        render: Box::new(move || {
            let (img, c) = lobes::render(scene, &direct, &ProgressBar::hidden());
            (img, Some(c.computed as f64 / px))
        }),
        default: false,
        build_seconds: None,
        per_core: None,
    }]);
    (curve, variants)
}

/// How an `rsl` setting shades: its label suffix and its `per_core[]` kernel name.
#[derive(Clone, Copy, PartialEq)]
enum RslKernel {
    Scalar,
    Simd,
    Wgpu,
}

fn rsl_settings<'a>(
    scene: &'a Scene,
    gpu: Option<&'a std::sync::Mutex<crate::backend::gpu::Gpu>>,
) -> (Vec<Setting<'a>>, Vec<Setting<'a>>) {
    // What `steradian render` plans (K, cube face, visibility side, coverage depth), K
    // swept over `RSL_KS` and the plan's own; the paper's pipeline at the paper's K = 30.
    let paper_k = rsl::Options::default().k;
    let d = planned(scene, render::Method::Rsl).map_or_else(rsl::Options::default, |p| p.rsl);
    // `ratio`: the shadow ratio (the default), or the paper's pipeline without it;
    // `refined`: the planned footprint refinement, or pixel centres only.
    let setting = |k: usize, kernel: RslKernel, ratio: bool, refined: bool| {
        let o = rsl::Options {
            k,
            exact_unshadowed: ratio,
            footprint: if refined { d.footprint } else { 0.0 },
            ..d
        };
        let (built, build_seconds) = timed(|| rsl::build(scene, &o));
        let (suffix, name) = match kernel {
            RslKernel::Scalar => (", scalar kernel", "scalar"),
            RslKernel::Simd => ("", "simd"),
            RslKernel::Wgpu => (", wgpu", "wgpu"),
        };
        let what = match (ratio, refined) {
            (true, true) => "",
            (false, false) => ", the paper's pipeline (no shadow ratio, pixel centres)",
            (true, false) => ", pixel centres only (no footprint refinement)",
            (false, true) => ", no shadow ratio",
        };
        let planned = ratio == d.exact_unshadowed && refined == (d.footprint > 0.0);
        let default = k == d.k && kernel == RslKernel::Simd && planned;
        Setting {
            label: format!("K = {k}{suffix}{what}"),
            render: Box::new(move || {
                let hidden = ProgressBar::hidden();
                let img = built
                    .as_ref()
                    .map_err(Clone::clone)
                    .and_then(|b| match kernel {
                        RslKernel::Scalar => rsl::render_built(scene, b, &o, &hidden),
                        RslKernel::Simd => rsl::render_built_simd(scene, b, &o, &hidden),
                        RslKernel::Wgpu => {
                            let mut g = gpu
                                .ok_or("no adapter")?
                                .lock()
                                .map_err(|_| "adapter lock poisoned")?;
                            rsl::render_built_gpu(scene, b, &o, &mut g, &hidden)
                        }
                    });
                let blank =
                    || Image::new(scene.camera.width as usize, scene.camera.height as usize);
                (img.unwrap_or_else(|_| blank()), None)
            }),
            default,
            build_seconds: Some(build_seconds),
            per_core: (planned && (default || kernel != RslKernel::Simd)).then_some(name),
        }
    };
    let (ratio, refined) = (d.exact_unshadowed, d.footprint > 0.0);
    let mut ks = RSL_KS.to_vec();
    if !ks.contains(&d.k) {
        ks.push(d.k);
        ks.sort_unstable();
    }
    let curve = ks
        .iter()
        .map(|&k| setting(k, RslKernel::Simd, ratio, refined))
        .collect();
    let mut variants = vec![
        setting(paper_k, RslKernel::Simd, false, false),
        setting(d.k, RslKernel::Simd, true, false),
        setting(d.k, RslKernel::Scalar, ratio, refined),
    ];
    if gpu.is_some() {
        variants.push(setting(d.k, RslKernel::Wgpu, ratio, refined));
    }
    (curve, variants)
}

fn png(img: &Image) -> Result<Vec<u8>, String> {
    let mut bytes = Vec::new();
    img.to_rgb8(0.0)
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .map_err(|e| e.to_string())?;
    Ok(bytes)
}

fn measure_scene(
    name: &'static str,
    method: &'static str,
    bounces: u32,
    gpu: Option<&std::sync::Mutex<crate::backend::gpu::Gpu>>,
    bar: &ProgressBar,
) -> Result<SceneResult, Box<dyn Error>> {
    let mut scene = Scene::load(&format!("builtin:{name}"))?;
    scene.camera = scene.camera.resized(WIDTH)?;
    let hidden = ProgressBar::hidden();
    let settings = |spp, seed| path::Settings { spp, bounces, seed };
    let (reference, reference_seconds) =
        timed(|| path::render(&scene, &settings(reference_spp(name), 1), &hidden));
    bar.inc(1);
    let class = metrics::classify(&scene);
    let compare =
        |img: &Image| metrics::compare(&class, img, &reference.image, Some(&reference.stderr), 0.0);
    let mut path_curve = Vec::new();
    for &spp in PATH_SPP {
        let (out, s) = best_of(|| path::render(&scene, &settings(spp, 1000 + spp as u64), &hidden));
        path_curve.push(Point {
            setting: format!("{spp} spp"),
            seconds: s,
            metrics: compare(&out.image)?,
            products_per_pixel: None,
            build_seconds: None,
        });
    }
    bar.inc(1);
    let (curve_settings, variant_settings) = match method {
        "hvl" => hvl_settings(&scene, gpu),
        "rsl" => rsl_settings(&scene, gpu),
        _ => lobes_settings(&scene, gpu),
    };
    let measure = |st: &Setting<'_>| -> Result<(Point, Image), String> {
        let ((img, products), best) = best_of(|| (st.render)());
        Ok((
            Point {
                setting: st.label.clone(),
                seconds: best,
                metrics: compare(&img)?,
                products_per_pixel: products,
                build_seconds: st.build_seconds,
            },
            img,
        ))
    };
    let mut curve = Vec::new();
    let mut default_img = None;
    for st in &curve_settings {
        let (p, img) = measure(st)?;
        if st.default {
            default_img = Some((curve.len(), p.clone(), img));
        }
        curve.push(p);
    }
    let variants = variant_settings
        .iter()
        .map(|st| measure(st).map(|(p, _)| p))
        .collect::<Result<Vec<_>, _>>()?;
    // Throughput on one core: the default setting (SIMD), the scalar variants and the wgpu
    // variants (one core preparing the points, the adapter shading), each the best of two
    // renders in a one-thread pool.
    let surface_points = (0..scene.camera.height)
        .flat_map(|j| (0..scene.camera.width).map(move |i| (i, j)))
        .filter(|&(i, j)| matches!(scene.see(&scene.camera.centre_ray(i, j)), Seen::Surface(_)))
        .count();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let mut per_core = Vec::new();
    for st in curve_settings.iter().chain(&variant_settings) {
        let Some(kernel) = st.per_core else { continue };
        let s = (0..2)
            .map(|_| timed(|| pool.install(|| (st.render)())).1)
            .fold(f64::INFINITY, f64::min);
        per_core.push((kernel, st.label.clone(), s, surface_points));
    }
    bar.inc(1);
    let (default, dp, dimg) = default_img.ok_or("the default setting is on the curve")?;
    let equal_error_ratio = cost_ratios(&path_curve, &dp)[0].unwrap_or(f64::NAN);
    let diff = metrics::difference_image(
        &class,
        &dimg,
        &reference.image,
        dp.metrics.max_radiance,
        0.05,
    );
    let files = vec![
        (format!("scene_{name}_path.png"), png(&reference.image)?),
        (format!("scene_{name}_{method}.png"), png(&dimg)?),
        (format!("scene_{name}_{method}_diff.png"), png(&diff)?),
    ];
    Ok(SceneResult {
        name,
        method,
        bounces,
        width: scene.camera.width,
        height: scene.camera.height,
        reference_seconds,
        path: path_curve,
        curve,
        variants,
        per_core,
        equal_error_ratio,
        default,
        files,
    })
}

/// `12.3×`, or `–` where the ratio is not defined.
fn ratio_text(r: Option<f64>) -> String {
    r.map_or("–".to_string(), |v| format!("{v:.1}×"))
}

fn point_json(p: &Point) -> serde_json::Value {
    json!({
        "setting": p.setting,
        "seconds": p.seconds,
        "products_per_pixel": p.products_per_pixel,
        "build_seconds": p.build_seconds,
        "errors": p.metrics,
    })
}

/// A method's point with its equal-error cost ratios against the path tracer's curve.
fn method_point_json(path: &[Point], p: &Point) -> serde_json::Value {
    let [a, l2, rmse] = cost_ratios(path, p);
    let mut v = point_json(p);
    v["equal_error_cost_ratio"] = json!(a);
    v["equal_error_cost_ratio_rel_l2"] = json!(l2);
    v["equal_error_cost_ratio_rmse"] = json!(rmse);
    v
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
            Series::line(r.method, pts(&r.curve)).wide(),
            Series::dots(format!("{}, variants", r.method), pts(&r.variants)),
        ],
    )
    .svg()
}

/// The scenes measured: (scene, method, bounces of the reference).
pub const SCENES: &[(&str, &str, u32)] = &[
    ("lobes", "lobes", 0),
    ("cluster", "lobes", 0),
    ("room", "hvl", 1),
    ("environment", "rsl", 0),
];

/// The report section (see the module docs).
pub fn section(opts: &Options) -> Result<Section, Box<dyn Error>> {
    let (gpu, gpu_note) = crate::backend::gpu::if_requested(opts.gpu);
    let gpu = gpu.map(std::sync::Mutex::new);
    let bar = ProgressBar::new(3 * SCENES.len() as u64);
    bar.set_message("scenes");
    let results = SCENES
        .iter()
        .map(|&(n, m, b)| measure_scene(n, m, b, gpu.as_ref(), &bar))
        .collect::<Result<Vec<_>, _>>()?;
    bar.finish_and_clear();
    let mut summary = String::new();
    let mut html = String::new();
    let mut files = Vec::new();
    let mut data = Vec::new();
    writeln!(
        html,
        "<p>Built-in scenes at {WIDTH} columns. Reference: the path tracer at {REFERENCE_SPP} \
         samples per pixel ({ROOM_REFERENCE_SPP} on <code>room</code>, {ENVIRONMENT_REFERENCE_SPP} on <code>environment</code>; direct light; one bounce for <code>room</code>). Errors over shaded, \
         non-silhouette pixels (see the README, \"Errors\"); times are whole renders on this \
         machine's thread pool, the best of at least three runs repeated for 0.25 s, the \
         path tracer's and the methods' alike. wgpu: {}.</p>",
        gpu_note
    )?;
    writeln!(summary, "  wgpu: {gpu_note}")?;
    for r in &results {
        let d = &r.curve[r.default];
        let variants: Vec<String> = r
            .variants
            .iter()
            .map(|v| format!("{} {:.2e}", v.setting, v.metrics.mean_abs_over_max))
            .collect();
        writeln!(
            summary,
            "  {} ({}, {} bounce(s)): {:.2e} of max radiance, noise-corrected rel L2 {:.4}, RMSE {:.4}, in {:.1} ms ({}); path tracer {:.2e} at {} spp, {:.2e} at {} spp; reference noise {:.1e}; equal-error cost ratio {:.1}× (on noise-corrected rel L2 {}, on RMSE {})",
            r.name,
            r.method,
            r.bounces,
            d.metrics.mean_abs_over_max,
            d.metrics.rel_l2_noise_corrected,
            d.metrics.rmse,
            d.seconds * 1e3,
            if variants.is_empty() {
                "no variants".to_string()
            } else {
                variants.join("; ")
            },
            r.path[0].metrics.mean_abs_over_max,
            PATH_SPP[0],
            r.path[r.path.len() - 1].metrics.mean_abs_over_max,
            PATH_SPP[PATH_SPP.len() - 1],
            d.metrics.reference_noise_over_max,
            r.equal_error_ratio,
            ratio_text(cost_ratios(&r.path, d)[1]),
            ratio_text(cost_ratios(&r.path, d)[2])
        )?;
        // The best equal-error cost over the method's curve, on each measure.
        let best = |k: usize| {
            r.curve
                .iter()
                .filter_map(|p| cost_ratios(&r.path, p)[k].map(|v| (v, p.setting.as_str())))
                .max_by(|a, b| a.0.total_cmp(&b.0))
                .map_or("–".to_string(), |(v, s)| format!("{v:.1}× ({s})"))
        };
        writeln!(
            summary,
            "    best equal-error cost ratio over the curve: {} on mean |diff|, {} on noise-corrected rel L2, {} on RMSE",
            best(0),
            best(1),
            best(2)
        )?;
        let per_core: Vec<String> = r
            .per_core
            .iter()
            .map(|(k, st, s, n)| format!("{k} ({st}) {:.0} points/s", *n as f64 / s))
            .collect();
        writeln!(summary, "    one core: {}", per_core.join(", "))?;
        writeln!(
            html,
            "<h3>{} ({})</h3><p>{}×{}; reference {:.1} s. The path tracer needs {:.1}× the time of \
             <code>{1}</code> ({}) for its error.</p>\
             <p><img src=\"scene_{0}_path.png\" alt=\"path\"> <img src=\"scene_{0}_{1}.png\" alt=\"{1}\"> \
             <img src=\"scene_{0}_{1}_diff.png\" alt=\"difference\"> (reference, {1}, difference: red brighter, \
             blue darker, full at 5 % of the maximum)</p><img src=\"scene_{0}.svg\" alt=\"curve\">",
            r.name,
            r.method,
            r.width,
            r.height,
            r.reference_seconds,
            r.equal_error_ratio,
            d.setting
        )?;
        html.push_str("<table><tr><th>method</th><th>setting</th><th>s</th><th>mean |diff|/max</th><th>rel L2</th><th>rel L2, noise-corrected</th><th>RMSE</th><th>PSNR dB</th><th>SSIM</th><th>products/px</th></tr>");
        for (m, p) in r
            .path
            .iter()
            .map(|p| ("path", p))
            .chain(r.curve.iter().chain(&r.variants).map(|p| (r.method, p)))
        {
            write!(
                html,
                "<tr><td>{m}</td><td>{}</td><td>{:.4}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.4}</td><td>{:.1}</td><td>{:.4}</td><td>{}</td></tr>",
                p.setting,
                p.seconds,
                p.metrics.mean_abs_over_max,
                p.metrics.rel_l2,
                p.metrics.rel_l2_noise_corrected,
                p.metrics.rmse,
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
            "method": r.method,
            "bounces": r.bounces,
            "width": r.width,
            "height": r.height,
            "reference_spp": reference_spp(r.name),
            "reference_seconds": r.reference_seconds,
            "path": r.path.iter().map(point_json).collect::<Vec<_>>(),
            "curve": r.curve.iter().map(|p| method_point_json(&r.path, p)).collect::<Vec<_>>(),
            "default": d.setting,
            "variants": r.variants.iter().map(|p| method_point_json(&r.path, p)).collect::<Vec<_>>(),
            "equal_error_cost_ratio": r.equal_error_ratio,
            "per_core": r.per_core.iter().map(|(kernel, setting, seconds, points)| json!({
                "kernel": kernel,
                "setting": setting,
                "seconds": seconds,
                "shading_points": points,
                "points_per_second": *points as f64 / seconds,
            })).collect::<Vec<_>>(),
        }));
    }
    Ok(Section {
        id: "scenes",
        title: "Scenes: whole images against the path tracer".into(),
        summary,
        html,
        data: json!({ "scenes": data, "gpu": gpu_note }),
        files,
    })
}
