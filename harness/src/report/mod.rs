//! `steradian report`: every kernel on every available backend, throughput and error
//! against the f64 references on the default workload, written as `report.json`,
//! `index.html` (tables and SVG speed-against-error plots) and a summary on stdout.

pub mod brdf;
pub mod cp;
pub mod cp_transport;
pub mod lobe_sum;
pub mod memory;
pub mod plot;
pub mod product;
pub mod rsl;
pub mod sat;
pub mod scenes;
pub mod section;
pub mod sections;
pub mod sh;
pub mod shade;
pub mod timing;
pub mod vdt;

use std::path::PathBuf;

use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

use plot::{Axis, Chart, Pt, Scale, Series};

use crate::accuracy::{self, ErrorStats};
use crate::backend;
use crate::kernels::Columns;
use crate::registry;
use crate::workload;

/// Seed of the default workload.
pub const SEED: u64 = 0x57e4_ad1a;

/// The default of [`Options::n`]: the workload sizes written in the sections are theirs at
/// this `n`.
pub const DEFAULT_N: usize = 1 << 20;

/// What to run.
#[derive(Clone, Debug)]
pub struct Options {
    /// Output directory.
    pub out: PathBuf,
    /// Size of the throughput workloads: inputs per kernel of the top table; every section's
    /// throughput workload (queries, products, … per timed run) is its default times
    /// `n / DEFAULT_N` ([`Options::scaled`]). The sections' error samples do not change with
    /// it; the top table's errors are over its first `min(n, error_rows)` inputs.
    pub n: usize,
    /// Timed runs of every throughput measurement, of the top table and of every section
    /// (after an untimed warm-up of at least `timing::WARM_UP`; the median is reported).
    pub repeats: usize,
    /// Rows compared against the f64 reference (hard cases first).
    pub error_rows: usize,
    /// Try the wgpu backend.
    pub gpu: bool,
    /// Run only the section with this id (and not the top table).
    pub only: Option<String>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            out: PathBuf::from("report"),
            n: DEFAULT_N,
            repeats: 7,
            error_rows: 1 << 16,
            gpu: true,
            only: None,
        }
    }
}

impl Options {
    /// A section's throughput workload size of `default` at the default `n`, scaled to this
    /// run's `n`: `max(1, default · n / DEFAULT_N)`.
    pub fn scaled(&self, default: usize) -> usize {
        (default as u128 * self.n as u128 / DEFAULT_N as u128).clamp(1, usize::MAX as u128) as usize
    }
}

/// The machine the report ran on.
#[derive(Clone, Debug, Serialize)]
pub struct Machine {
    /// CPU model name.
    pub cpu: String,
    /// Logical cores.
    pub cores: usize,
    /// Instruction set the SIMD batches were built for.
    pub simd: String,
    /// GPU adapter that ran the `wgpu` rows, or null.
    pub gpu_adapter: Option<String>,
    /// Why there is no GPU row, when there is none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gpu_unavailable: Option<String>,
}

impl Machine {
    /// The adapter, or why there is none.
    pub fn gpu_description(&self) -> String {
        match (&self.gpu_adapter, &self.gpu_unavailable) {
            (Some(a), _) => a.clone(),
            (None, Some(why)) => format!("none ({why})"),
            (None, None) => "not tried".into(),
        }
    }
}

/// One kernel × backend measurement.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// Kernel name.
    pub kernel: &'static str,
    /// Backend name.
    pub backend: &'static str,
    /// Median evaluations per second.
    pub evals_per_s: f64,
    /// Inputs per timed run.
    pub n: usize,
    /// Error against the f64 reference.
    pub error: ErrorStats,
    /// The kernel's documented bound in the same metric.
    pub bound: f64,
    /// Whether `error.max ≤ bound`.
    pub within_bound: bool,
}

/// The whole report (`report.json`).
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Where it ran.
    pub machine: Machine,
    /// Every measurement.
    pub results: Vec<Row>,
    /// Sections contributed by subsystems (lobe products, SAT/VDT, RSL shading, …), in order.
    pub sections: Vec<sections::Section>,
}

impl Report {
    /// The row of `kernel` on `backend`.
    pub fn get(&self, kernel: &str, backend: &str) -> Option<&Row> {
        self.results
            .iter()
            .find(|r| r.kernel == kernel && r.backend == backend)
    }
}

fn cpu_name() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

/// Runs the report and writes `report.json` and `index.html` into `opts.out`.
pub fn run(opts: &Options) -> Result<Report, Box<dyn std::error::Error>> {
    let mut backends = backend::cpu_backends();
    let mut machine = Machine {
        cpu: cpu_name(),
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        simd: steradian_simd::isa().to_string(),
        gpu_adapter: None,
        gpu_unavailable: None,
    };
    if opts.gpu {
        match backend::gpu::try_gpu() {
            Ok(g) => {
                machine.gpu_adapter = Some(g.adapter_info());
                backends.push(Box::new(g));
            }
            Err(why) => machine.gpu_unavailable = Some(why),
        }
    }
    let steps = (registry::batch_kernels().count() * (backends.len() + 1)) as u64;
    let bar = ProgressBar::new(steps).with_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut results = Vec::new();
    // With one section asked for, the top table is skipped.
    let top = if opts.only.is_some() {
        None
    } else {
        Some(registry::batch_kernels())
    };
    for k in top.into_iter().flatten() {
        bar.set_message(format!("{k}: inputs and f64 reference"));
        let input = workload::generate(k, opts.n, SEED);
        let reference = accuracy::reference(k, &input, opts.error_rows);
        bar.inc(1);
        // Backends take turns within each repeat, so a noisy machine slows them alike and
        // the ratios between them stay meaningful; the warm-up round also compiles GPU
        // pipelines. A backend that fails is not run again.
        let mut outs: Vec<Columns> = backends
            .iter()
            .map(|_| Columns::zeros(k.output_arity(), opts.n))
            .collect();
        let mut failed: Vec<Option<String>> = vec![None; backends.len()];
        bar.set_message(format!("{k} on every backend ({} repeats)", opts.repeats));
        let times = timing::median_times_in_turns(opts.repeats, backends.len(), |bi| {
            if failed[bi].is_none()
                && let Err(e) = backends[bi].run(k, &input, &mut outs[bi])
            {
                failed[bi] = Some(e.to_string());
            }
        });
        for (bi, b) in backends.iter().enumerate() {
            if let Some(e) = &failed[bi] {
                bar.println(format!("{k} on {}: {e}", b.name()));
            } else {
                let error = accuracy::stats(&reference, &input, &outs[bi]);
                let bound = accuracy::bound(k);
                results.push(Row {
                    kernel: k.name(),
                    backend: b.name(),
                    evals_per_s: timing::per_second(opts.n, times[bi]),
                    n: opts.n,
                    within_bound: error.max <= bound,
                    error,
                    bound,
                });
            }
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    drop(backends);
    let sections = sections::run_all(opts)?;
    let report = Report {
        machine,
        results,
        sections,
    };
    std::fs::create_dir_all(&opts.out)?;
    std::fs::write(
        opts.out.join("report.json"),
        serde_json::to_string_pretty(&report)?,
    )?;
    for sec in &report.sections {
        for (name, bytes) in &sec.files {
            std::fs::write(opts.out.join(name), bytes)?;
        }
    }
    std::fs::write(opts.out.join("index.html"), html(&report))?;
    Ok(report)
}

fn ratio(r: &Report, row: &Row) -> Option<f64> {
    r.get(row.kernel, "cpu-scalar")
        .map(|base| row.evals_per_s / base.evals_per_s)
}

/// The summary table printed after a run.
pub fn summary(r: &Report) -> String {
    let mut s = format!(
        "steradian report — cpu: {} ({} cores), simd: {}, gpu: {}\n",
        r.machine.cpu,
        r.machine.cores,
        r.machine.simd,
        r.machine.gpu_description()
    );
    s += &format!(
        "{:<17} {:<16} {:>11} {:>9} {:<19} {:>10} {:>10} {:>10} {:>9}\n",
        "kernel", "backend", "Mevals/s", "×scalar", "error metric", "max", "p99", "mean", "bound"
    );
    for row in &r.results {
        s += &format!(
            "{:<17} {:<16} {:>11.1} {:>9} {:<19} {:>10.2e} {:>10.2e} {:>10.2e} {:>9}\n",
            row.kernel,
            row.backend,
            row.evals_per_s / 1e6,
            ratio(r, row).map_or("-".into(), |x| format!("{x:.2}")),
            row.error.metric,
            row.error.max,
            row.error.p99,
            row.error.mean,
            if row.within_bound { "ok" } else { "EXCEEDED" }
        );
    }
    s += "\nSIMD against the scalar rows of the same run:\n";
    for k in registry::batch_kernels() {
        let get = |b| r.get(k.name(), b).map(|row| row.evals_per_s);
        if let (Some(simd), Some(one), Some(lp)) =
            (get("cpu-simd"), get("cpu-scalar"), get("cpu-scalar-loop"))
        {
            s += &format!(
                "  {:<17} cpu-simd = {:>5.2}× cpu-scalar, {:>5.2}× cpu-scalar-loop (the plain loop is {:.1}× cpu-scalar)\n",
                k.name(),
                simd / one,
                simd / lp,
                lp / one
            );
        }
    }
    for sec in &r.sections {
        s += &format!("\n{}\n{}", sec.title, sec.summary);
    }
    s
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn html(r: &Report) -> String {
    let mut rows = String::new();
    for row in &r.results {
        rows += &format!(
            "<tr><td>{}</td><td>{}</td><td>{:.1}</td><td>{}</td><td>{}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.2e}</td><td>{:.1e}</td><td class=\"{}\">{}</td></tr>\n",
            row.kernel,
            row.backend,
            row.evals_per_s / 1e6,
            ratio(r, row).map_or("-".into(), |x| format!("{x:.2}")),
            esc(row.error.metric),
            row.error.max,
            row.error.p99,
            row.error.mean,
            row.bound,
            if row.within_bound { "ok" } else { "bad" },
            if row.within_bound { "ok" } else { "exceeded" }
        );
    }
    let m = &r.machine;
    format!(
        r#"<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>steradian report</title>
<style>
body {{ font-family: system-ui, sans-serif; margin: 2em; color: #222; }}
table {{ border-collapse: collapse; }} td, th {{ padding: 0.25em 0.7em; border-bottom: 1px solid #ddd; text-align: right; }}
td:first-child, td:nth-child(2), td:nth-child(5), th {{ text-align: left; }}
.ok {{ color: #176117; }} .bad {{ color: #b00; font-weight: bold; }}
</style></head><body>
<h1>steradian report</h1>
<p>CPU: {cpu} ({cores} cores) · SIMD build: {simd} · GPU adapter: {gpu}</p>
<p>Throughput is the median of timed runs over the default workload (hard cases first, then
pseudo-random inputs over each kernel's domain). <code>cpu-scalar</code> calls the scalar kernel one input at
a time behind <code>black_box</code>; <code>cpu-scalar-loop</code> is a plain loop the compiler may vectorise;
<code>cpu-simd</code> is the explicit 8-lane batch; <code>wgpu</code> includes upload and read-back. ×scalar is the
ratio to <code>cpu-scalar</code> in the same run. Errors are against f64 references; the bound is the one
documented on the kernel.</p>
<h2>Speed against error</h2>
{svg}
<h2>All measurements</h2>
<table><tr><th>kernel</th><th>backend</th><th>Mevals/s</th><th>×scalar</th><th>metric</th><th>max</th><th>p99</th><th>mean</th><th>bound</th><th></th></tr>
{rows}</table>
{sections}
</body></html>
"#,
        cpu = esc(&m.cpu),
        cores = m.cores,
        simd = esc(&m.simd),
        gpu = esc(&m.gpu_description()),
        svg = speed_vs_error(r),
        sections = r
            .sections
            .iter()
            .map(|sec| format!(
                "<h2 id=\"{}\">{}</h2>\n{}\n",
                sec.id,
                esc(&sec.title),
                sec.html
            ))
            .collect::<String>(),
    )
}

/// The speed-against-error figure: one panel per kernel, a point per backend, log axes,
/// the kernel's documented bound as a dashed line.
fn speed_vs_error(r: &Report) -> String {
    const BACKENDS: [&str; 4] = ["cpu-scalar", "cpu-scalar-loop", "cpu-simd", "wgpu"];
    let mut kernels: Vec<&str> = Vec::new();
    for row in &r.results {
        if !kernels.contains(&row.kernel) {
            kernels.push(row.kernel);
        }
    }
    let panels: Vec<Chart> = kernels
        .iter()
        .map(|&k| {
            let rows: Vec<&Row> = r.results.iter().filter(|row| row.kernel == k).collect();
            // Every panel lists every backend, so that each has one colour throughout.
            let series = BACKENDS
                .iter()
                .map(|&b| {
                    let points = rows
                        .iter()
                        .filter(|row| row.backend == b)
                        .map(|row| {
                            // A non-finite error is drawn at 1, an exact one on the floor.
                            let e = if row.error.max.is_finite() {
                                row.error.max
                            } else {
                                1.0
                            };
                            Pt {
                                note: Some(format!(
                                    "{k} {b}: {:.3e} evals/s, max error {:.3e}",
                                    row.evals_per_s, row.error.max
                                )),
                                ..Pt::new(row.evals_per_s.max(1.0), e)
                            }
                        })
                        .collect();
                    Series::dots(b, points)
                })
                .collect();
            let chart = Chart::new(
                k,
                Axis::new("evals/s", Scale::Log),
                Axis::new("max error", Scale::Log),
                series,
            );
            match rows.first() {
                Some(row) => chart.rule(row.bound, format!("bound ({})", row.error.metric)),
                None => chart,
            }
        })
        .collect();
    plot::grid(&panels, 3, (300.0, 220.0))
}
