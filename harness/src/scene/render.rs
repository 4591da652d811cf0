//! `steradian render SCENE --method M`: plans, renders and writes `M.exr`, `M.png` and
//! `M.json` (plus `path_stderr.exr` for the reference), and compares with `path.exr`
//! when the output folder holds one.

use std::path::PathBuf;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use serde_json::json;

use super::image::Image;
use super::metrics::{self, Metrics};
use super::{Scene, lobes, path};

/// A rendering method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// The path-traced reference.
    Path,
    /// Cosine lobes (direct light from spherical lights).
    Lobes,
    /// Harmonics virtual lights (one indirect bounce) plus the direct light of `lobes`.
    Hvl,
    /// Rotatable square lights: environment lighting.
    Rsl,
}

impl Method {
    /// Parses a method name; the error lists the known ones.
    pub fn parse(s: &str) -> Result<Method, String> {
        match s {
            "path" => Ok(Method::Path),
            "lobes" => Ok(Method::Lobes),
            "hvl" => Ok(Method::Hvl),
            "rsl" => Ok(Method::Rsl),
            _ => Err(format!(
                "unknown method {s:?} (available: path, lobes, hvl, rsl)"
            )),
        }
    }

    /// The file stem of its outputs.
    pub fn name(self) -> &'static str {
        match self {
            Method::Path => "path",
            Method::Lobes => "lobes",
            Method::Hvl => "hvl",
            Method::Rsl => "rsl",
        }
    }
}

/// Settings of one render.
#[derive(Clone, Debug)]
pub struct Options {
    /// The method.
    pub method: Method,
    /// Output folder (created).
    pub out: PathBuf,
    /// Samples per pixel (`path`).
    pub spp: u32,
    /// Indirect bounces (`path`).
    pub bounces: u32,
    /// The error the approximations aim at (mean |difference| over the maximum radiance).
    pub target_error: f64,
    /// Exposure of the PNG and of the tone-mapped metrics (EV).
    pub exposure: f64,
    /// Seed (`path`).
    pub seed: u64,
    /// Hide the progress bar.
    pub quiet: bool,
    /// Shade with the scalar kernels (`rsl`, `lobes` and `hvl` use SIMD kernels otherwise).
    pub scalar: bool,
    /// Shade on the wgpu backend (`lobes`, `rsl` and `hvl`; an error without an adapter).
    pub gpu: bool,
}

pub use super::DEFAULT_TARGET_ERROR;

impl Default for Options {
    fn default() -> Self {
        Options {
            method: Method::Path,
            out: PathBuf::from("render"),
            spp: 64,
            bounces: 0,
            target_error: DEFAULT_TARGET_ERROR,
            exposure: 0.0,
            seed: 1,
            quiet: false,
            scalar: false,
            gpu: false,
        }
    }
}

/// One line of the plan: a choice and why.
#[derive(Clone, Debug, Serialize)]
pub struct PlanItem {
    /// What was chosen.
    pub item: String,
    /// The value.
    pub value: serde_json::Value,
    /// Why.
    pub reason: String,
}

/// What a render produced.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The image.
    pub image: Image,
    /// Its standard error (`path` only).
    pub stderr: Option<Image>,
    /// The plan.
    pub plan: Vec<PlanItem>,
    /// Seconds spent rendering (not loading or writing).
    pub seconds: f64,
    /// Errors against `path.exr` of the output folder, when present.
    pub metrics: Option<Metrics>,
    /// The `M.json` written.
    pub json: serde_json::Value,
}

/// What a method will build for a scene, and why ([`plan`]).
#[derive(Clone, Debug)]
pub struct Plan {
    /// The choices with their reasons, as printed and kept in `M.json`.
    pub items: Vec<PlanItem>,
    /// Settings of the `lobes` method (also the direct light of `hvl`).
    pub lobes: lobes::Options,
    /// Settings of the `hvl` method.
    pub hvl: super::hvl::Options,
    /// Settings of the `rsl` method.
    pub rsl: super::rsl::Options,
}

/// The kernel the options select.
fn kernel_name(o: &Options) -> &'static str {
    if o.gpu {
        "wgpu"
    } else if o.scalar {
        "scalar"
    } else {
        "simd"
    }
}

/// The plan item of a method's footprint refinement (`scene::footprint`): `value` is
/// `factor` times the target error `target`; `what` says where it refines.
fn footprint_item(value: f64, factor: f64, target: f64, what: &str) -> PlanItem {
    PlanItem {
        item: "footprint".into(),
        value: json!(value),
        reason: format!(
            "pixels whose centre alone is estimated to miss the pixel's mean (the path tracer's \
             box filter) by {factor:.2} times the target {target} of the maximum or more, from \
             the image's Laplacian over neighbours on the same object (|Δf|/24), and every \
             pixel of an object fewer than {small} pixel centres see, are re-shaded at the 2×2 \
             Gauss–Legendre points of the pixel and averaged: {what}",
            small = super::footprint::SMALL_OBJECT_PIXELS
        ),
    }
}

/// A plan's estimates as text: `"{name}{candidate}: {estimate}"`, comma-separated.
fn estimates_text<T: std::fmt::Display>(name: &str, estimates: &[(T, f64)]) -> String {
    estimates
        .iter()
        .map(|(c, e)| format!("{name}{c}: {e:.1e}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The plan of a method for a scene: what it builds and why.
pub fn plan(scene: &Scene, o: &Options) -> Result<Plan, String> {
    let mut p = Vec::new();
    let mut lo = lobes::Options::default();
    let mut r = super::rsl::Options::default();
    let mut hv = super::hvl::Options::default();
    if o.gpu && !matches!(o.method, Method::Lobes | Method::Rsl | Method::Hvl) {
        return Err(format!(
            "--gpu: only methods lobes, rsl and hvl have a wgpu path (not {})",
            o.method.name()
        ));
    }
    match o.method {
        Method::Path => {
            p.push(PlanItem {
                item: "spp".into(),
                value: json!(o.spp),
                reason: "samples per pixel, uniform over the pixel (box filter)".into(),
            });
            p.push(PlanItem {
                item: "bounces".into(),
                value: json!(o.bounces),
                reason: "indirect bounces (0: direct light only)".into(),
            });
        }
        Method::Rsl => {
            if scene.environment.is_none() {
                return Err("method rsl lights with an environment; this scene has none".into());
            }
            // The coverage depth first: the choice of K shades probes with it.
            use steradian_core::rsl::visibility::DEPTH_BOUNDS;
            r.vis_depth = super::rsl::coverage_depth_for(o.target_error);
            let max_depth = r.vis_depth;
            let choice = super::rsl::choose_k(scene, &r, o.target_error)?;
            let k_face = r.face;
            r.k = choice.k;
            r.vis_side = choice.vis_side;
            r.vis_depth = choice.vis_depth;
            r.face = choice.face;
            let est = estimates_text("K = ", &choice.estimates);
            p.push(PlanItem {
                item: "rsls".into(),
                value: json!(r.k),
                reason: format!(
                    "K square lights: the smallest of {:?} whose decomposition of a 6 × {}² \
                     cube map alone keeps {} probe pixels within {} of the target {} of the \
                     largest ({}; the RSL paper uses K = 30)",
                    super::rsl::K_CANDIDATES,
                    k_face,
                    super::PROBES.0 * super::PROBES.1,
                    super::PLAN_SHARE,
                    o.target_error,
                    est
                ),
            });
            p.push(PlanItem {
                item: "cube_face".into(),
                value: json!(r.face),
                reason: format!(
                    "the environment resampled to a 6 × {0}² cube map before the decomposition: \
                     {0} is the smallest side of {1:?} (at least K texels) whose {2} lights keep \
                     the probe pixels within {3} of the target {4} of the largest side's, with \
                     the chosen visibility maps ({5})",
                    r.face,
                    super::rsl::FACE_CANDIDATES,
                    r.k,
                    super::PLAN_SHARE,
                    o.target_error,
                    estimates_text("face ", &choice.face_estimates)
                ),
            });
            p.push(PlanItem {
                item: "shadow_ratio".into(),
                value: json!(r.exact_unshadowed),
                reason: format!(
                    "each BRDF part's exact integral under the point's planes from environment \
                     tables (the diffuse one; one per glossy lobe exponent up to {}, not GGX; \
                     per side of the planes) times the squares' ratio of its value under every \
                     occluder to its value under the planes alone; off, the RSL paper's eq. 5 \
                     alone",
                    super::unshadowed::MAX_EXPONENT
                ),
            });
            r.footprint = super::footprint::PLAN_FACTOR * o.target_error;
            p.push(footprint_item(
                r.footprint,
                super::footprint::PLAN_FACTOR,
                o.target_error,
                "the sun's glossy highlight and sharp shadow edges",
            ));
            p.push(PlanItem {
                item: "brdf_sats".into(),
                value: json!(r.sat_target),
                reason: "one Lambert SAT and one per distinct specular part (Phong exponent, \
                         GGX (f0, roughness), Lafortune lobe), fitted to this target"
                    .into(),
            });
            p.push(PlanItem {
                item: "visibility".into(),
                value: json!(format!(
                    "{0}×{0} coverage → moment tables per point",
                    r.vis_side
                )),
                reason: format!(
                    "caps of the other spheres and the planes the point is not on; {} is the \
                     smallest side of {:?} whose maps keep {} probe pixels within {} of the \
                     target {} of the largest side's, with the chosen K ({})",
                    r.vis_side,
                    super::rsl::VIS_SIDE_CANDIDATES,
                    super::PROBES.0 * super::PROBES.1,
                    super::PLAN_SHARE,
                    o.target_error,
                    estimates_text("side ", &choice.side_estimates)
                ),
            });
            p.push(PlanItem {
                item: "kernel".into(),
                value: json!(kernel_name(o)),
                reason: if o.gpu {
                    format!(
                        "--gpu: the WGSL moments kernel on the wgpu backend, {} points per \
                         batch (their visibility tables built on the CPU)",
                        super::rsl::GPU_BATCH
                    )
                } else if o.scalar {
                    "--scalar: the scalar moments kernel, one point at a time".into()
                } else {
                    "the SIMD moments kernel, eight points at a time (--scalar for the scalar \
                     one, --gpu for wgpu)"
                        .into()
                },
            });
            p.push(PlanItem {
                item: "coverage_depth".into(),
                value: json!(r.vis_depth),
                reason: format!(
                    "subdivision levels below a visibility texel: the coarsest of 0–{} (the \
                     deepest whose asserted visible-solid-angle bound, {:.1e} relative, is \
                     within a tenth of the target error {}) that keeps {} probe pixels within \
                     {} of the target of depth {}'s, with the chosen K and side ({})",
                    max_depth,
                    DEPTH_BOUNDS[max_depth as usize].1,
                    o.target_error,
                    super::PROBES.0 * super::PROBES.1,
                    super::PLAN_SHARE,
                    max_depth,
                    estimates_text("depth ", &choice.depth_estimates)
                ),
            });
            if !scene.lights.is_empty() {
                p.push(PlanItem {
                    item: "spherical_lights".into(),
                    value: json!(scene.lights.len()),
                    reason: "seen and occluding only: the lobes method lights with them".into(),
                });
            }
        }
        Method::Lobes | Method::Hvl => {
            if scene.environment.is_some() {
                return Err(
                    "method lobes lights with spherical lights only; this scene has an \
                     environment (the rsl method lights with it)"
                        .into(),
                );
            }
            if scene.lights.is_empty() {
                return Err("method lobes needs at least one spherical light".into());
            }
            if let Some(k) = scene
                .materials
                .iter()
                .position(|m| matches!(m, super::material::Material::Ggx { .. }))
            {
                return Err(format!(
                    "material {:?} is GGX, which has no cosine-lobe form: methods lobes and hvl \
                     do not carry it (path and rsl do)",
                    scene.material_names[k]
                ));
            }
            lo.threshold = (o.target_error / 10.0) as f32;
            p.push(PlanItem {
                item: "threshold".into(),
                value: json!(lo.threshold),
                reason: format!(
                    "pruning threshold relative to each chain's unshadowed value: a tenth of \
                     the target error {}",
                    o.target_error
                ),
            });
            p.push(PlanItem {
                item: "cap_fit".into(),
                value: json!("energy-preserving"),
                reason: "cap → lobe with the L2 exponent (eq. 32) scaled to the cap's solid \
                         angle, in the diffuse chain and for occluders: closer to the path \
                         tracer than the plain L2 lobe (the scene tests assert it), and the \
                         lobe the mask's weights were fitted for"
                    .into(),
            });
            p.push(PlanItem {
                item: "glossy_cap_fit".into(),
                value: json!("moments"),
                reason: format!(
                    "in the glossy chains the light's lobe has the cap's solid angle and mean \
                     cosine (closed form): its product with a glossy lobe of exponent n is \
                     exact to second order in n(1 − cos α), where the energy-preserving \
                     lobe, wider than the cap, blurs the highlight; the energy-preserving \
                     lobe where n(1 − cos α) > {}",
                    steradian_core::lobe::cap::MOMENTS_MAX_X
                ),
            });
            // `hvl` refines its direct light alone, on every path: its indirect light
            // varies slowly across a pixel (the premise of its lattice).
            // Three significant digits: the plan prints it.
            let t = super::footprint::LOBES_PLAN_FACTOR * o.target_error;
            lo.footprint = format!("{t:.2e}").parse().unwrap_or(t);
            p.push(footprint_item(
                lo.footprint,
                super::footprint::LOBES_PLAN_FACTOR,
                o.target_error,
                if o.method == Method::Lobes {
                    "highlights, shadow edges and the rims of spheres (the method's own \
                     error at pixel centres is a fraction of the target)"
                } else {
                    "the direct light's highlights, shadow edges and the rims of spheres \
                     (the lobes method's rule); the indirect light is added at pixel \
                     centres, where it varies slowly"
                },
            ));
            p.push(PlanItem {
                item: "diffuse_term".into(),
                value: json!("closed form × visible fraction"),
                reason: "each light's unshadowed diffuse term is the sphere's exact \
                         cosine-weighted solid angle above the horizon (Snyder 1996), less \
                         the exact cap overlaps of pairwise disjoint occluders of a light \
                         above the horizon, else times the visible fraction of the lobe \
                         chain; the cap lobe × cosine product \
                         of the paper has at least 1.4× (measured 1.7×) its error on `lobes` and \
                         `cluster` (the scene tests assert it)"
                    .into(),
            });
            // The table before the depth: the depth's probes read the chosen table.
            let table = lobes::choose_table(scene, &lo, o.target_error);
            lo.table = table.size;
            p.push(PlanItem {
                item: "product_table".into(),
                value: json!(lo.table.describe()),
                reason: format!(
                    "every lobe product reads it (each covers exponents 0–1e5): the coarsest \
                     of {} (tried in that order, each generated on first use) that keeps {} \
                     probe pixels, at the deepest mask, within {} of the target {} of the \
                     built-in table's ({}); the report section lobe-product gives each \
                     table's error against the exact product integral",
                    lobes::TableSize::ALL.map(|t| t.to_string()).join(", "),
                    super::PROBES.0 * super::PROBES.1,
                    super::PLAN_SHARE,
                    o.target_error,
                    estimates_text("", &table.estimates)
                ),
            });
            let choice = lobes::choose_depth(scene, &lo, o.target_error);
            if let lobes::Visibility::Mask { leaves, .. } = lo.visibility {
                lo.visibility = lobes::Visibility::Mask {
                    depth: choice.depth,
                    leaves,
                };
            }
            let est = estimates_text("depth ", &choice.estimates);
            p.push(PlanItem {
                item: "visibility".into(),
                value: json!(format!("quadtree mask, depth {}", choice.depth)),
                reason: format!(
                    "section 5.3: one lobe per shadow leaf with the weights w(dist, depth) fitted \
                     for the deepest level, overlapping occluders counted once, a partially \
                     covered leaf at the deepest level scaled by the covered share of the lit \
                     directions of a 4 × 4 grid over it; {} is the shallowest depth that keeps \
                     {} probe pixels within {} of the target {} of depth {} ({})",
                    choice.depth,
                    super::PROBES.0 * super::PROBES.1,
                    super::PLAN_SHARE,
                    o.target_error,
                    steradian_core::lobe::mask::MAX_DEPTH,
                    est
                ),
            });
            if o.method == Method::Hvl {
                p.push(PlanItem {
                    item: "kernel".into(),
                    value: json!(kernel_name(o)),
                    reason: if o.gpu {
                        "--gpu: the diffuse indirect light by the WGSL HVL sum, one receiver \
                         per invocation, and the direct light by the lobes wgpu path; the glossy \
                         parts on the CPU"
                            .into()
                    } else if o.scalar {
                        "--scalar: every HVL by the scalar kernels, one at a time".into()
                    } else {
                        "each receiver's HVLs by the SIMD kernels: the diffuse part eight at a \
                         time, the glossy parts four at a time; the direct light by the lobes \
                         SIMD path (--scalar for the scalar ones, --gpu for wgpu)"
                            .into()
                    },
                });
            }
            if o.method == Method::Lobes {
                p.push(PlanItem {
                    item: "kernel".into(),
                    value: json!(kernel_name(o)),
                    reason: if o.gpu {
                        format!(
                            "--gpu: every lobe chain by the WGSL chain kernel, one chain per \
                             invocation, {} points per dispatch; each point's caps, occluders and \
                             quadtree mask on the CPU",
                            lobes::GPU_BATCH
                        )
                    } else if o.scalar {
                        "--scalar: every product by the scalar kernel, one point at a time".into()
                    } else {
                        "each light's lobe times the cosine by the SIMD product kernel, eight \
                         points at a time, the rest lane by lane (--scalar for the scalar one, \
                         --gpu for wgpu)"
                            .into()
                    },
                });
            }
            if o.method == Method::Hvl {
                hv.direct = lo;
                hv.simd = !o.scalar;
                // The glossy tables first (generated once per process): the side's probes
                // shade with them, and their time is the method's, reported here.
                let t = Instant::now();
                let glossy = super::hvl::Glossy::build(scene);
                let glossy_seconds = t.elapsed().as_secs_f64();
                let choice = super::hvl::choose_side(scene, &hv, o.target_error);
                hv.side = choice.side;
                let est = estimates_text("side ", &choice.estimates);
                p.push(PlanItem {
                    item: "hvls".into(),
                    value: json!(6 * hv.side * hv.side * scene.lights.len()),
                    reason: format!(
                        "a reflective shadow map of 6 × {0}² rays per light, one HVL per hit: \
                         {0} is the smallest face side of {1:?} whose HVLs keep {2} probe \
                         pixels within {3} of the target {4} of the largest side's ({5})",
                        hv.side,
                        super::hvl::SIDE_CANDIDATES,
                        super::PROBES.0 * super::PROBES.1,
                        super::PLAN_SHARE,
                        o.target_error,
                        est
                    ),
                });
                let bands = super::hvl::choose_bands(scene, &hv, o.target_error);
                hv.bands = bands.bands;
                p.push(PlanItem {
                    item: "sh_bands".into(),
                    value: json!(hv.bands),
                    reason: format!(
                        "the receiver's diffuse albedo times the first {} bands of the \
                         committed Lambert BRDF table (with the cosine): the fewest that keep \
                         {} probe pixels within {} of the target {} of its full {} ({}); \
                         Lambertian emission is exact in one band",
                        hv.bands,
                        super::PROBES.0 * super::PROBES.1,
                        super::PLAN_SHARE,
                        o.target_error,
                        steradian_core::sh::brdf::lambert().bands(),
                        estimates_text("bands ", &bands.estimates)
                    ),
                });
                let views = glossy.views();
                let tables: Vec<String> = scene
                    .material_names
                    .iter()
                    .zip(&views.parts)
                    .flat_map(|(name, parts)| {
                        parts.iter().map(move |(t, _)| {
                            format!("{name}: {} bands × {} views", t.bands(), t.samples())
                        })
                    })
                    .collect();
                p.push(PlanItem {
                    item: "glossy_tables".into(),
                    value: json!(tables),
                    reason: format!(
                        "each glossy part of a receiver (Phong's specular term, each Lafortune \
                         lobe) through its own BRDF SH table, generated with the fewest bands \
                         and views that keep its truncation at θₒ = 45° within {} relative L2 \
                         and its interpolation within a tenth of that ({:.2} s); the HVLs emit \
                         their diffuse part only",
                        super::hvl::GLOSSY_TARGET,
                        glossy_seconds
                    ),
                });
                p.push(PlanItem {
                    item: "hvl_visibility".into(),
                    value: json!(hv.visibility),
                    reason: "a shadow ray per HVL–receiver pair (the paper tests none)".into(),
                });
                if o.gpu {
                    hv.stride = 1;
                    p.push(PlanItem {
                        item: "indirect_stride".into(),
                        value: json!(1),
                        reason: "--gpu: the indirect light at every pixel (the wgpu path \
                                 interpolates none)"
                            .into(),
                    });
                } else {
                    let stride = super::hvl::choose_stride(scene, &hv, o.target_error);
                    hv.stride = stride.stride;
                    p.push(PlanItem {
                        item: "indirect_stride".into(),
                        value: json!(hv.stride),
                        reason: format!(
                            "{0}: {1} is the coarsest of {2:?} that keeps {3} probe pixels \
                             within {4} of the target {5} of every pixel computed ({6})",
                            if hv.stride == 1 {
                                "the indirect light computed at every pixel (the paper)".into()
                            } else {
                                format!(
                                    "the indirect light computed every {} pixels across and \
                                     down, more densely where a cell's corners differ in \
                                     object, normal or value by more than half, and \
                                     interpolated between on the same object and normal \
                                     (scene::lattice)",
                                    hv.stride
                                )
                            },
                            hv.stride,
                            super::lattice::STRIDE_CANDIDATES,
                            super::PROBES.0 * super::PROBES.1,
                            super::PLAN_SHARE,
                            o.target_error,
                            estimates_text("stride ", &stride.estimates)
                        ),
                    });
                }
            }
        }
    }
    hv.direct = lo;
    Ok(Plan {
        items: p,
        lobes: lo,
        hvl: hv,
        rsl: r,
    })
}

fn bar(rows: u64, quiet: bool, label: &str) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::new(rows);
    b.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} rows, {eta} left")
            .expect("valid template")
            .progress_chars("=> "),
    );
    b.set_message(label.to_string());
    b
}

/// Renders `scene` by `plan` (from [`plan`] with the same options) and writes the outputs.
pub fn run(scene: &Scene, scene_name: &str, o: &Options, plan: &Plan) -> Result<Outcome, String> {
    std::fs::create_dir_all(&o.out).map_err(|e| format!("{}: {e}", o.out.display()))?;
    let rows = scene.camera.height as u64;
    let b = bar(rows, o.quiet, o.method.name());
    let start = Instant::now();
    let (image, stderr, extra) = match o.method {
        Method::Path => {
            let out = path::render(
                scene,
                &path::Settings {
                    spp: o.spp,
                    bounces: o.bounces,
                    seed: o.seed,
                },
                &b,
            );
            (out.image, Some(out.stderr), json!({}))
        }
        Method::Lobes => {
            let (img, counts) = if o.gpu {
                let mut gpu = crate::backend::gpu::try_gpu()
                    .map_err(|e| format!("--gpu: no wgpu adapter: {e}"))?;
                lobes::render_gpu(scene, &plan.lobes, &mut gpu, &b)?
            } else if o.scalar {
                lobes::render(scene, &plan.lobes, &b)
            } else {
                lobes::render_simd(scene, &plan.lobes, &b)
            };
            let px = scene.camera.pixels().max(1) as f64;
            (
                img,
                None,
                json!({
                    "kernel": kernel_name(o),
                    "products_computed_per_pixel": counts.computed as f64 / px,
                    "products_pruned_per_pixel": counts.pruned as f64 / px,
                    "products_skipped_per_pixel": (counts.skipped_bound + counts.skipped_chain) as f64 / px,
                }),
            )
        }
        Method::Rsl => {
            let t = Instant::now();
            let built = super::rsl::build(scene, &plan.rsl)?;
            let build_seconds = t.elapsed().as_secs_f64();
            let img = if o.gpu {
                let mut gpu = crate::backend::gpu::try_gpu()
                    .map_err(|e| format!("--gpu: no wgpu adapter: {e}"))?;
                super::rsl::render_built_gpu(scene, &built, &plan.rsl, &mut gpu, &b)?
            } else if o.scalar {
                super::rsl::render_built(scene, &built, &plan.rsl, &b)?
            } else {
                super::rsl::render_built_simd(scene, &built, &plan.rsl, &b)?
            };
            (
                img,
                None,
                json!({
                    "rsls": plan.rsl.k,
                    "build_seconds": build_seconds,
                    "kernel": kernel_name(o),
                }),
            )
        }
        Method::Hvl => {
            let (img, count) = if o.gpu {
                let mut gpu = crate::backend::gpu::try_gpu()
                    .map_err(|e| format!("--gpu: no wgpu adapter: {e}"))?;
                super::hvl::render_gpu(scene, &plan.hvl, &mut gpu, &b)?
            } else {
                super::hvl::render(scene, &plan.hvl, &b)
            };
            (
                img,
                None,
                json!({ "hvls": count, "kernel": kernel_name(o) }),
            )
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    b.finish_and_clear();
    let name = o.method.name();
    image.write_exr(&o.out.join(format!("{name}.exr")))?;
    image.write_png(&o.out.join(format!("{name}.png")), o.exposure)?;
    if let Some(se) = &stderr {
        se.write_exr(&o.out.join("path_stderr.exr"))?;
    }
    // Errors against `DIR/path.exr` (and its standard error), when it exists and this
    // render is not the reference itself.
    let reference_path = o.out.join("path.exr");
    let metrics = if o.method != Method::Path && reference_path.exists() {
        let r = Image::read(&reference_path)?;
        let se = Image::read(&o.out.join("path_stderr.exr")).ok();
        let class = metrics::classify(scene);
        let m = metrics::compare(&class, &image, &r, se.as_ref(), o.exposure)?;
        let diff = metrics::difference_image(&class, &image, &r, m.max_radiance, 0.05);
        diff.write_png(&o.out.join(format!("{name}_diff.png")), 0.0)?;
        Some(m)
    } else {
        None
    };
    let px = scene.camera.pixels() as f64;
    let samples = match o.method {
        Method::Path => px * o.spp.max(1) as f64,
        Method::Lobes | Method::Hvl | Method::Rsl => px,
    };
    let json = json!({
        "scene": scene_name,
        "method": name,
        "width": scene.camera.width,
        "height": scene.camera.height,
        "settings": {
            "spp": o.spp, "bounces": o.bounces, "target_error": o.target_error,
            "exposure": o.exposure, "seed": o.seed,
        },
        "plan": plan.items,
        "seconds": seconds,
        "threads": rayon::current_num_threads(),
        "shading_points_per_second": samples / seconds.max(1e-9),
        "method_data": extra,
        "errors": metrics,
    });
    let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())?;
    std::fs::write(o.out.join(format!("{name}.json")), text + "\n")
        .map_err(|e| format!("writing {name}.json: {e}"))?;
    Ok(Outcome {
        image,
        stderr,
        plan: plan.items.clone(),
        seconds,
        metrics,
        json,
    })
}
