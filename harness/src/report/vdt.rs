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
use super::sat::{REPEATS, time};
use super::section::Section;
use crate::backend::gpu::{Custom, try_gpu};
use crate::kernels::Columns;
use crate::rng::Rng;
use crate::vdt::{Dist, Family, edge_error_by_angle, errors, spheres_mask, study};

const SEED: u64 = 0x0bd7_5eed;
const QUERIES: usize = 1 << 18;

struct Speed {
    n: usize,
    scalar: Duration,
    simd: Duration,
    sat: Duration,
    gpu: Option<Duration>,
}

fn query_speed(
    n: usize,
    gpu: &mut Option<crate::backend::gpu::Gpu>,
) -> Result<Speed, Box<dyn Error>> {
    let m = spheres_mask(n);
    let vdt = Vdt::build(n, n, &m)?;
    let view = vdt.view();
    let texels: Vec<f32> = m.iter().map(|&b| b as u8 as f32).collect();
    let sat = Sat::build(n, n, &texels)?;
    let mut rng = Rng::new(SEED ^ n as u64);
    let u: Vec<f32> = (0..QUERIES)
        .map(|_| rng.range(0.0, n as f64) as f32)
        .collect();
    let v: Vec<f32> = (0..QUERIES)
        .map(|_| rng.range(0.0, n as f64) as f32)
        .collect();
    let r: Vec<f32> = (0..QUERIES)
        .map(|_| rng.log_range(0.5, n as f64 / 8.0) as f32)
        .collect();
    let (mut a, mut b) = (vec![0.0f32; QUERIES], vec![0.0f32; QUERIES]);
    let scalar = time(|| {
        for k in 0..QUERIES {
            let (x, y) = view.query(u[k], v[k], r[k]);
            a[k] = x;
            b[k] = y;
        }
        black_box(&a);
    });
    let simd = time(|| {
        steradian_simd::rsl::vdt::query_slices(&view, &u, &v, &r, &mut a, &mut b);
        black_box(&a);
    });
    let sat_t = time(|| {
        for k in 0..QUERIES {
            a[k] = sat.square(Vec2::new(u[k], v[k]), r[k]);
        }
        black_box(&a);
    });
    let gpu_t = match gpu {
        Some(g) => {
            let rows: Vec<[f32; 3]> = (0..QUERIES).map(|k| [u[k], v[k], r[k]]).collect();
            let input = Columns::from_rows(&rows);
            let mut out = Columns::zeros(2, QUERIES);
            let table = vdt.gpu_table();
            let custom = Custom {
                label: "vdt-query",
                source: wgsl::VDT_QUERY,
                table: Some(&table),
            };
            g.run_custom(&custom, &input, &mut out)?;
            Some(time(|| {
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
    })
}

fn svg_angles(pts: &[(f64, [f64; 3])]) -> String {
    let (w, h, l, b, t, r) = (560.0, 320.0, 60.0, 40.0, 30.0, 20.0);
    let ymax = pts
        .iter()
        .flat_map(|p| p.1)
        .fold(0.0f64, f64::max)
        .max(1e-3)
        * 1.1;
    let x = |a: f64| l + a / 90.0 * (w - l - r);
    let y = |e: f64| h - b - e / ymax * (h - b - t);
    let mut s = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="11"><rect width="100%" height="100%" fill="white"/>
<line x1="{l}" y1="{}" x2="{}" y2="{}" stroke="black"/><line x1="{l}" y1="{t}" x2="{l}" y2="{}" stroke="black"/>
<text x="{}" y="{}" text-anchor="middle">edge normal angle (degrees, folded into [0, 90))</text>
<text x="14" y="{}" transform="rotate(-90 14 {})" text-anchor="middle">mean |error| of the visible fraction</text>
"#,
        h - b,
        w - r,
        h - b,
        h - b,
        (l + w - r) / 2.0,
        h - 8.0,
        h / 2.0,
        h / 2.0
    );
    for k in 0..=6 {
        let a = k as f64 * 15.0;
        let _ = write!(
            s,
            r#"<text x="{}" y="{}" text-anchor="middle">{a}</text>"#,
            x(a),
            h - b + 14.0
        );
    }
    for k in 0..=4 {
        let e = ymax * k as f64 / 4.0;
        let _ = write!(
            s,
            r#"<text x="{}" y="{}" text-anchor="end">{e:.3}</text><line x1="{l}" x2="{}" y1="{}" y2="{}" stroke="lightgray"/>"#,
            l - 4.0,
            y(e) + 4.0,
            w - r,
            y(e),
            y(e)
        );
    }
    for (c, (name, color)) in [
        ("eq. 9", "#d62728"),
        ("gradient variant", "#2ca02c"),
        ("SAT of binary map", "#1f77b4"),
    ]
    .iter()
    .enumerate()
    {
        let path: Vec<String> = pts
            .iter()
            .map(|p| format!("{:.1},{:.1}", x(p.0), y(p.1[c])))
            .collect();
        let _ = write!(
            s,
            r#"<polyline fill="none" stroke="{color}" stroke-width="2" points="{}"/><text x="{}" y="{}" fill="{color}">{name}</text>"#,
            path.join(" "),
            l + 10.0 + 150.0 * c as f64,
            t - 10.0
        );
    }
    s.push_str("</svg>");
    s
}

fn row(name: &str, d: &Dist) -> String {
    format!(
        "<td>{name}</td><td>{:.4}</td><td>{:.4}</td><td>{:.4}</td>",
        d.mean, d.p99, d.max
    )
}

/// The section.
pub fn section(opts: &Options) -> Result<Section, Box<dyn Error>> {
    let bar = ProgressBar::new(7).with_style(
        ProgressStyle::with_template("vdt      {bar:30} {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    // EDT build time at 512².
    bar.set_message("exact EDT 512²");
    let n = 512;
    let m = spheres_mask(n);
    let mut out = vec![0.0f32; n * n];
    let mut scratch = vec![0.0f64; scratch_len(n, n)];
    let t_edt = time(|| {
        signed_distance_into(n, n, &m, &mut out, &mut scratch).expect("valid map");
    });
    let texels: Vec<f32> = m.iter().map(|&b| b as u8 as f32).collect();
    let t_sat_build = time(|| {
        black_box(Sat::build(n, n, &texels).expect("valid map"));
    });
    let edt_ns = t_edt.as_secs_f64() * 1e9 / (n * n) as f64;
    let sat_build_ns = t_sat_build.as_secs_f64() * 1e9 / (n * n) as f64;
    bar.inc(1);

    bar.set_message("query speed");
    let mut gpu = None;
    let mut gpu_note = "not requested".to_string();
    if opts.gpu {
        match try_gpu() {
            Ok(g) => {
                gpu_note = g.adapter_info();
                gpu = Some(g);
            }
            Err(e) => gpu_note = format!("no adapter: {e}"),
        }
    }
    let speeds = [query_speed(64, &mut gpu)?, query_speed(512, &mut gpu)?];
    bar.inc(2);

    bar.set_message("error study");
    let mut fam = Vec::new();
    for f in Family::ALL {
        fam.push((f, errors(&study(f, SEED, 12, 80))));
        bar.inc(1);
    }
    let angles = edge_error_by_angle(SEED, 180, 12, 18);
    bar.inc(1);
    bar.finish_and_clear();

    let ns = |d: Duration| d.as_secs_f64() * 1e9 / QUERIES as f64;
    let mut summary = format!(
        "exact signed EDT {edt_ns:.1} ns/texel at 512² (SAT build of the same map {sat_build_ns:.1} ns/texel)\n"
    );
    for s in &speeds {
        let _ = writeln!(
            summary,
            "VDT query at {}²: scalar {:.2} ns, SIMD {:.2} ns ({:.2}× scalar), SAT square {:.2} ns{}",
            s.n,
            ns(s.scalar),
            ns(s.simd),
            s.scalar.as_secs_f64() / s.simd.as_secs_f64(),
            ns(s.sat),
            s.gpu
                .map(|g| format!(", wgpu {:.2} ns (upload + read-back)", ns(g)))
                .unwrap_or_default()
        );
    }
    for (f, e) in &fam {
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

    let mut html = String::new();
    let _ = write!(
        html,
        "<p>The VDT stores the exact signed Euclidean distance from each texel centre to the \
         boundary of the binary map (the texel edges between classes), positive where visible. \
         Eq. 9 is the paper's <code>clamp((√2·r + D)/(2√2·r), 0, 1)</code>; the gradient variant \
         takes the edge normal from the bilinear D's gradient and returns the exact area of the \
         square on the visible side of that line. Both read one bilinear cell (4 samples); the \
         SAT of the binary map (4 lookups, exact for the map) is the reference point.</p>\
         <h3>Build</h3><table><tr><th>what</th><th>ns per texel at 512²</th></tr>\
         <tr><td>exact signed EDT (ours)</td><td>{edt_ns:.1}</td></tr>\
         <tr><td>SAT build of the same map (same run)</td><td>{sat_build_ns:.1}</td></tr></table>\
         <p>imageproc's <code>euclidean_squared_distance_transform</code> (unsigned, to pixel \
         centres of one class) on the same map is in <code>cargo bench -p steradian-benches \
         --bench vdt</code> (not a harness dependency).</p>\
         <h3>Queries ({QUERIES} random squares, median of {REPEATS}, SIMD {})</h3>\
         <table><tr><th>table</th><th>scalar (both estimates)</th><th>SIMD</th><th>SIMD/scalar</th>\
         <th>SAT square, scalar</th><th>wgpu ({gpu_note})</th></tr>",
        steradian_simd::isa()
    );
    for s in &speeds {
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
    for (f, e) in &fam {
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
    let svg = svg_angles(&angles);
    html.push_str(&svg);

    let fam_json: Vec<_> = fam
        .iter()
        .map(|(f, e)| json!({"family": f.name(), "errors": e}))
        .collect();
    let data = json!({
        "edt_ns_per_texel_512": edt_ns,
        "sat_build_ns_per_texel_512": sat_build_ns,
        "query_ns": speeds.iter().map(|s| json!({
            "side": s.n, "scalar": ns(s.scalar), "simd": ns(s.simd), "sat_square": ns(s.sat),
            "wgpu": s.gpu.map(ns),
        })).collect::<Vec<_>>(),
        "gpu": gpu_note,
        "errors": fam_json,
        "edge_error_by_angle": angles.iter().map(|(a, e)| json!({"angle": a, "eq9": e[0], "gradient": e[1], "sat": e[2]})).collect::<Vec<_>>(),
    });
    Ok(Section {
        id: "vdt",
        title: "Visibility distance tables".into(),
        summary,
        html,
        data,
        files: vec![("vdt_error_by_angle.svg".into(), svg.into_bytes())],
    })
}
