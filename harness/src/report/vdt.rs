//! Report section: visibility distance tables. Exact-EDT build time per texel, query
//! throughput (scalar, SIMD, wgpu) next to the 4-lookup SAT query of the same binary map
//! measured in the same run, and the error distributions of eq. 9, the straight-edge
//! (gradient) variant and the SAT of the binary map against exact coverage for straight
//! edges, corners and the discs of sphere occluders, with an SVG of the error against the
//! edge orientation.

use std::error::Error;
use std::fmt::Write as _;
use std::hint::black_box;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use steradian_core::rsl::sat::Sat;
use steradian_core::rsl::vdt::{Vdt, scratch_len, signed_distance_into};
use steradian_core::{Vec2, wgsl};

use super::Options;
use super::plot::{Axis, Chart, Pt, Scale, Series};
use super::section::Section;
use super::timing::{median_time, ns_per};
use crate::backend::gpu::{self, Custom, Gpu};
use crate::kernels::Columns;
use crate::rng::Rng;
use crate::vdt::{Dist, Family, FamilyErrors, edge_error_by_angle, errors, spheres_mask, study};

const SEED: u64 = 0x0bd7_5eed;
/// Queries per timed run at the default `--n` ([`Options::scaled`]).
const QUERIES: usize = 1 << 18;
/// Side of the EDT build timing.
const BUILD_SIDE: usize = 512;
/// Sides of the query timings.
const QUERY_SIDES: [usize; 2] = [64, 512];

/// Median query times on one table size.
#[derive(Clone, Debug)]
pub struct Speed {
    /// Table side.
    pub n: usize,
    /// Scalar VDT query (both estimates).
    pub scalar: Duration,
    /// SIMD VDT query.
    pub simd: Duration,
    /// Scalar SAT square of the same map.
    pub sat: Duration,
    /// wgpu VDT query, upload and read-back included.
    pub gpu: Option<Duration>,
    /// The query's loads alone (the same samples in the same order, summed; no
    /// arithmetic): the memory floor of the kernel's layout.
    pub loads: Duration,
    /// Samples read per query (4 for eq. 9's bilinear cell, 16 for the straight-edge
    /// stencil).
    pub loads_per_query: f64,
}

/// The flat indices of the samples `VdtView::query` reads for each query, in its order:
/// eq. 9's bilinear cell (`vdt::axis` per axis), then the straight-edge variant's stencil
/// (`vdt::stencil_axis`, narrow or wide by `r`).
fn load_plan(w: usize, h: usize, u: &[f32], v: &[f32], r: &[f32]) -> Vec<usize> {
    use steradian_core::rsl::vdt::{FIT_WIDE_R, axis, stencil_axis};
    let mut plan = Vec::with_capacity(20 * u.len());
    for k in 0..u.len() {
        let (i0, _) = axis(u[k], w);
        let (j0, _) = axis(v[k], h);
        let (i0, j0) = (i0 as usize, j0 as usize);
        let (i1, j1) = ((i0 + 1).min(w - 1), (j0 + 1).min(h - 1));
        plan.extend([(i0, j0), (i1, j0), (i0, j1), (i1, j1)].map(|(i, j)| j * w + i));
        let wide = r[k] >= FIT_WIDE_R;
        let (ix, _) = stencil_axis(u[k], w, wide);
        let (jy, _) = stencil_axis(v[k], h, wide);
        for j in jy {
            plan.extend(ix.map(|i| j as usize * w + i as usize));
        }
    }
    plan
}

/// Everything the section measures.
#[derive(Clone, Debug)]
pub struct VdtResults {
    /// Exact signed EDT, ns per texel at `BUILD_SIDE`².
    pub edt_ns: f64,
    /// SAT build of the same map, ns per texel.
    pub sat_build_ns: f64,
    /// Queries per timed run.
    pub queries: usize,
    /// Timed repeats.
    pub repeats: usize,
    /// The GPU adapter, or why there is none.
    pub gpu_note: String,
    /// Query times per table side.
    pub speeds: Vec<Speed>,
    /// Error distributions per family.
    pub families: Vec<(Family, FamilyErrors)>,
    /// Straight edges: (angle in degrees, mean |error| of [eq. 9, gradient, SAT]).
    pub angles: Vec<(f64, [f64; 3])>,
    /// Oblique straight edges (`|sin 2θ| ≥ ½`, `r ∈ [4, 12]`): mean |error| of the
    /// straight-edge variant and of eq. 9 fed the exact distance to the edge line
    /// ([`crate::vdt::oblique_edges`], the test's seed and size).
    pub oblique: (f64, f64),
}

/// Median query times on an `n × n` table of the spheres mask, `queries` random squares.
fn query_speed(
    n: usize,
    queries: usize,
    repeats: usize,
    gpu: &mut Option<Gpu>,
) -> Result<Speed, Box<dyn Error>> {
    let m = spheres_mask(n);
    let vdt = Vdt::build(n, n, &m)?;
    let view = vdt.view();
    let texels: Vec<f32> = m.iter().map(|&b| b as u8 as f32).collect();
    let sat = Sat::build(n, n, &texels)?;
    let mut rng = Rng::new(SEED ^ n as u64);
    let u: Vec<f32> = (0..queries)
        .map(|_| rng.range(0.0, n as f64) as f32)
        .collect();
    let v: Vec<f32> = (0..queries)
        .map(|_| rng.range(0.0, n as f64) as f32)
        .collect();
    let r: Vec<f32> = (0..queries)
        .map(|_| rng.log_range(0.5, n as f64 / 8.0) as f32)
        .collect();
    let (mut a, mut b) = (vec![0.0f32; queries], vec![0.0f32; queries]);
    let scalar = median_time(repeats, || {
        for k in 0..queries {
            let (x, y) = view.query(u[k], v[k], r[k]);
            a[k] = x;
            b[k] = y;
        }
        black_box(&a);
    });
    let simd = median_time(repeats, || {
        steradian_simd::rsl::vdt::query_slices(&view, &u, &v, &r, &mut a, &mut b);
        black_box(&a);
    });
    let sat_t = median_time(repeats, || {
        for k in 0..queries {
            a[k] = sat.square(Vec2::new(u[k], v[k]), r[k]);
        }
        black_box(&a);
    });
    let plan = load_plan(n, n, &u, &v, &r);
    let samples = view.samples();
    let loads = median_time(repeats, || {
        let mut acc = [0.0f32; 4];
        for c in black_box(&plan).chunks(4) {
            for (a, &i) in acc.iter_mut().zip(c) {
                *a += samples[i];
            }
        }
        black_box(acc);
    });
    let gpu_t = match gpu {
        Some(g) => {
            let rows: Vec<[f32; 3]> = (0..queries).map(|k| [u[k], v[k], r[k]]).collect();
            let input = Columns::from_rows(&rows);
            let mut out = Columns::zeros(2, queries);
            let table = vdt.gpu_table();
            let custom = Custom {
                label: "vdt-query",
                source: wgsl::VDT_QUERY,
                table: Some(&table),
            };
            g.run_custom(&custom, &input, &mut out)?;
            Some(median_time(repeats, || {
                g.run_custom(&custom, &input, &mut out).expect("GPU run");
            }))
        }
        None => None,
    };
    Ok(Speed {
        n,
        scalar,
        simd,
        sat: sat_t,
        gpu: gpu_t,
        loads,
        loads_per_query: plan.len() as f64 / queries as f64,
    })
}

/// Runs the section's measurements.
pub fn measure(opts: &Options) -> Result<VdtResults, Box<dyn Error>> {
    let bar = ProgressBar::new(7).with_style(
        ProgressStyle::with_template("vdt      {bar:30} {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    // EDT build time at 512².
    bar.set_message("exact EDT 512²");
    let n = BUILD_SIDE;
    let m = spheres_mask(n);
    let mut out = vec![0.0f32; n * n];
    let mut scratch = vec![0.0f64; scratch_len(n, n)];
    let t_edt = median_time(opts.repeats, || {
        signed_distance_into(n, n, &m, &mut out, &mut scratch).expect("valid map");
    });
    let texels: Vec<f32> = m.iter().map(|&b| b as u8 as f32).collect();
    let t_sat_build = median_time(opts.repeats, || {
        black_box(Sat::build(n, n, &texels).expect("valid map"));
    });
    bar.inc(1);

    bar.set_message("query speed");
    let (mut gpu, gpu_note) = gpu::if_requested(opts.gpu);
    let queries = opts.scaled(QUERIES);
    let speeds = QUERY_SIDES
        .iter()
        .map(|&side| query_speed(side, queries, opts.repeats, &mut gpu))
        .collect::<Result<Vec<_>, _>>()?;
    bar.inc(2);

    bar.set_message("error study");
    let mut families = Vec::new();
    for f in Family::ALL {
        families.push((f, errors(&study(f, SEED, 12, 80))));
        bar.inc(1);
    }
    let angles = edge_error_by_angle(SEED, 180, 12, 18);
    let oblique = crate::vdt::oblique_edges(0x0b1e, 60, 40);
    bar.inc(1);
    bar.finish_and_clear();
    Ok(VdtResults {
        edt_ns: ns_per(n * n, t_edt),
        sat_build_ns: ns_per(n * n, t_sat_build),
        queries,
        repeats: opts.repeats,
        gpu_note,
        speeds,
        families,
        angles,
        oblique,
    })
}

/// Mean |error| against the edge orientation, a line per estimate.
fn plot(angles: &[(f64, [f64; 3])]) -> String {
    let ymax = angles
        .iter()
        .flat_map(|p| p.1)
        .fold(0.0f64, f64::max)
        .max(1e-3)
        * 1.1;
    let series = ["eq. 9", "gradient variant", "SAT of binary map"]
        .iter()
        .enumerate()
        .map(|(c, name)| Series::line(*name, angles.iter().map(|p| Pt::new(p.0, p.1[c])).collect()))
        .collect();
    let ticks = (0..=6)
        .map(|k| (k as f64 * 15.0, format!("{}", k * 15)))
        .collect();
    Chart::new(
        "Straight edges: mean |error| against the edge orientation",
        Axis::new(
            "edge normal angle (degrees, folded into [0, 90))",
            Scale::Linear,
        )
        .range(0.0, 90.0)
        .ticks(ticks),
        Axis::new("mean |error| of the visible fraction", Scale::Linear).range(0.0, ymax),
        series,
    )
    .svg()
}

fn row(name: &str, d: &Dist) -> String {
    format!(
        "<td>{name}</td><td>{:.4}</td><td>{:.4}</td><td>{:.4}</td>",
        d.mean, d.p99, d.max
    )
}

/// The summary text of the section.
fn summary(r: &VdtResults) -> String {
    let ns = |d: Duration| ns_per(r.queries, d);
    let mut summary = format!(
        "exact signed EDT {:.1} ns/texel at 512² (SAT build of the same map {:.1} ns/texel)\n",
        r.edt_ns, r.sat_build_ns
    );
    for s in &r.speeds {
        let _ = writeln!(
            summary,
            "VDT query at {}²: scalar {:.2} ns, SIMD {:.2} ns ({:.2}× scalar), loads alone ({:.0} per query) {:.2} ns (SIMD at {:.2}× that floor), SAT square {:.2} ns{}",
            s.n,
            ns(s.scalar),
            ns(s.simd),
            s.scalar.as_secs_f64() / s.simd.as_secs_f64(),
            s.loads_per_query,
            ns(s.loads),
            s.simd.as_secs_f64() / s.loads.as_secs_f64(),
            ns(s.sat),
            s.gpu
                .map(|g| format!(", wgpu {:.2} ns (upload + read-back)", ns(g)))
                .unwrap_or_default()
        );
    }
    let (og, o9) = r.oblique;
    let _ = writeln!(
        summary,
        "oblique edges (|sin 2θ| ≥ ½, r 4–12): straight-edge variant {og:.4}, eq. 9 on the exact distance {o9:.4}, ratio {:.3}",
        og / o9
    );
    for (f, e) in &r.families {
        let _ = writeln!(
            summary,
            "{:15} mean |err| vs exact: eq.9 {:.4}, gradient {:.4}, SAT of binary map {:.4} (max {:.3} / {:.3} / {:.3})",
            f.name(),
            e.eq9.mean,
            e.gradient.mean,
            e.sat.mean,
            e.eq9.max,
            e.gradient.max,
            e.sat.max
        );
    }
    summary
}

/// The HTML of the section, with the figure `svg` inline.
fn html(r: &VdtResults, svg: &str) -> String {
    let ns = |d: Duration| ns_per(r.queries, d);
    let mut html = String::new();
    let _ = write!(
        html,
        "<p>The VDT stores the exact signed Euclidean distance from each texel centre to the \
         boundary of the binary map (the texel edges between classes), positive where visible. \
         Eq. 9 is the paper's <code>clamp(½ + D/(√2·r), 0, 1)</code>, exact for a straight edge parallel to a side of the square; the straight-edge \
         (gradient) variant fits a line to a 4 × 4 stencil of distances whose zero level is \
         corrected for the binary map's staircase and returns the exact area of the square on \
         the visible side of that line. Eq. 9 reads one bilinear cell (4 samples), the \
         straight-edge variant 16; the SAT of the binary map (4 lookups, exact for the map) is \
         the reference point. On oblique straight edges (|sin 2θ| ≥ ½, r 4–12 texels) the \
         straight-edge variant's mean error is {:.4}, against {:.4} for eq. 9 fed the exact \
         distance to the line: {:.3}×.</p>\
         <h3>Build</h3><table><tr><th>what</th><th>ns per texel at 512²</th></tr>\
         <tr><td>exact signed EDT (ours)</td><td>{:.1}</td></tr>\
         <tr><td>SAT build of the same map (same run)</td><td>{:.1}</td></tr></table>\
         <p>imageproc's <code>euclidean_squared_distance_transform</code> (unsigned, to pixel \
         centres of one class) on the same map is in <code>cargo bench -p steradian-benches \
         --bench vdt</code> (not a harness dependency).</p>\
         <h3>Queries ({} random squares, median of {}, SIMD {})</h3>\
         <table><tr><th>table</th><th>scalar (both estimates)</th><th>SIMD</th><th>SIMD/scalar</th>\
         <th>SAT square, scalar</th><th>wgpu ({})</th></tr>",
        r.oblique.0,
        r.oblique.1,
        r.oblique.0 / r.oblique.1,
        r.edt_ns,
        r.sat_build_ns,
        r.queries,
        r.repeats,
        steradian_simd::isa(),
        r.gpu_note
    );
    for s in &r.speeds {
        let _ = write!(
            html,
            "<tr><td>{}²</td><td>{:.2} ns</td><td>{:.2} ns</td><td>{:.2}×</td><td>{:.2} ns</td><td>{}</td></tr>",
            s.n,
            ns(s.scalar),
            ns(s.simd),
            s.scalar.as_secs_f64() / s.simd.as_secs_f64(),
            ns(s.sat),
            s.gpu
                .map(|g| format!("{:.2} ns (upload + read-back)", ns(g)))
                .unwrap_or_else(|| "—".into())
        );
    }
    html.push_str(
        "</table><h3>Error of the visible fraction (64² maps, boundary-crossing squares of \
         half-diagonal 1–8 texels)</h3><table><tr><th>family</th><th>queries</th>\
         <th>estimate</th><th>mean |err|</th><th>p99</th><th>max</th></tr>",
    );
    for (f, e) in &r.families {
        for (k, (name, d)) in [
            ("eq. 9 vs exact", &e.eq9),
            ("gradient vs exact", &e.gradient),
            ("SAT of binary map vs exact", &e.sat),
            ("eq. 9 vs binary map", &e.eq9_mask),
            ("gradient vs binary map", &e.gradient_mask),
        ]
        .iter()
        .enumerate()
        {
            let head = if k == 0 {
                format!("<td rowspan=5>{}</td><td rowspan=5>{}</td>", f.name(), e.n)
            } else {
                String::new()
            };
            let _ = write!(html, "<tr>{head}{}</tr>", row(name, d));
        }
    }
    html.push_str(
        "</table><p>\"Exact\" is the true shape's coverage of the square (polygon clipping for \
         edges and corners; for sphere discs, 16² samples per texel of the exact cap test in \
         f64). The SAT of the binary map carries only the rasterisation error.</p>\
         <h3>Straight edges: mean |error| against the edge orientation</h3>",
    );
    html.push_str(svg);
    html
}

/// The data of the section in `report.json`.
fn data(r: &VdtResults) -> serde_json::Value {
    let ns = |d: Duration| ns_per(r.queries, d);
    let fam_json: Vec<_> = r
        .families
        .iter()
        .map(|(f, e)| json!({"family": f.name(), "errors": e}))
        .collect();
    json!({
        "edt_ns_per_texel_512": r.edt_ns,
        "sat_build_ns_per_texel_512": r.sat_build_ns,
        "query_ns": r.speeds.iter().map(|s| json!({
            "side": s.n, "scalar": ns(s.scalar), "simd": ns(s.simd), "sat_square": ns(s.sat),
            "wgpu": s.gpu.map(ns), "loads_only": ns(s.loads), "loads_per_query": s.loads_per_query,
        })).collect::<Vec<_>>(),
        "gpu": r.gpu_note,
        "errors": fam_json,
        "edge_error_by_angle": r.angles.iter().map(|(a, e)| json!({"angle": a, "eq9": e[0], "gradient": e[1], "sat": e[2]})).collect::<Vec<_>>(),
        "oblique_edges": {"gradient": r.oblique.0, "eq9_exact_distance": r.oblique.1, "ratio": r.oblique.0 / r.oblique.1},
    })
}

/// The section of measured results.
pub fn render(r: &VdtResults) -> Section {
    let svg = plot(&r.angles);
    Section {
        id: "vdt",
        title: "Visibility distance tables".into(),
        summary: summary(r),
        html: html(r, &svg),
        data: data(r),
        files: vec![("vdt_error_by_angle.svg".into(), svg.into_bytes())],
    }
}

/// The section.
pub fn section(opts: &Options) -> Result<Section, Box<dyn Error>> {
    Ok(render(&measure(opts)?))
}
