//! Report section: summed-area tables. Error against the f64 brute force for every storage
//! option measured (plain `f32`, mean subtracted, `f32` with an `f64` offset per tile, hi/lo
//! `f32` pairs, `f64`, and the `i64` fixed point of `steradian_core::rsl::sat`) at 64² … 2048²,
//! bytes per option, build time and query throughput (scalar, SIMD, wgpu) with the
//! baselines measured in the same run.
//!
//! The roofline puts the fractional box query beside its load-only floor: the sixteen `i64`
//! entries it reads (eight adjacent pairs over four rows) in the same order, summed. The
//! floor issues them as plain scalar loads; the SIMD query's gathers issue the same loads
//! with fewer instructions, so it can come out slightly below the floor when both wait on
//! DRAM (the cold runs). Only the layout moves the floor: fewer loads per box (rows `J` and
//! `J + 1` interleaved, so that each 2 × 2 corner block is one 32-byte read, at twice the
//! table's bytes), fewer lines per box (tiling the table so that a small box's rows share
//! cache lines), or narrower entries (`i32` differences to a per-tile `i64` base).

use std::error::Error;
use std::fmt::Write as _;
use std::hint::black_box;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use steradian_core::rsl::sat::Sat;

use super::Options;
use super::memory;
use super::plot::{Axis, Chart, Pt, Scale, Series};
use super::section::Section;
use super::timing::{median_time, median_times_in_turns, ns_per};
use crate::backend::gpu::try_gpu;
use crate::kernels::Columns;
use crate::rng::Rng;
use crate::sat::options::{Fixed, HiLoF32, MeanOffsetF32, PlainF32, PlainF64, Storage, TiledF32};
use crate::sat::{Grid, gpu_box_sums, gpu_table, ulp};

/// Seed of the section's grids and boxes.
const SEED: u64 = 0x5a7_5eed;
/// Resolutions of the error-growth table.
const SIDES: [usize; 6] = [64, 128, 256, 512, 1024, 2048];
/// Random boxes per resolution for the error table.
const ERROR_BOXES: usize = 1500;
/// Queries per timed run at the default `--n` ([`Options::scaled`]).
const QUERIES: usize = 1 << 18;
/// Queries of the warm (in-cache) runs, repeated to make up the timed run's queries.
const WARM: usize = 4096;
/// Side of the speed measurements and of the high-dynamic-range grid.
const SIDE: usize = 1024;
/// Boxes of the wgpu error check (the first of the timed queries).
const GPU_CHECKED: usize = 4000;

/// A grid of texels uniform in `[0, 1)` (the measurement).
pub fn uniform_grid(n: usize, seed: u64) -> Grid {
    let mut rng = Rng::new(seed);
    let texels = (0..n * n).map(|_| rng.unit() as f32).collect();
    Grid {
        width: n,
        height: n,
        texels,
    }
}

/// Random boxes with fractional corners anywhere in an `n × n` table, sides log-uniform in
/// `[0.5, min(64, n)]`, plus the 16×16 integer box next to the far corner.
pub fn random_boxes(n: usize, count: usize, seed: u64) -> Vec<[f32; 4]> {
    let mut rng = Rng::new(seed);
    let m = (n as f64).min(64.0);
    let mut v: Vec<[f32; 4]> = (0..count)
        .map(|_| {
            let w = rng.log_range(0.5, m);
            let h = rng.log_range(0.5, m);
            let u0 = rng.range(0.0, n as f64 - w);
            let v0 = rng.range(0.0, n as f64 - h);
            [u0 as f32, v0 as f32, (u0 + w) as f32, (v0 + h) as f32]
        })
        .collect();
    if n >= 20 {
        let f = (n - 17) as f32;
        v.push([f, f, f + 16.0, f + 16.0]);
    }
    v
}

/// Per-option error statistics, in f32 ulps of each box's exact value.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ErrRow {
    /// Storage option.
    pub option: &'static str,
    /// Table side.
    pub side: usize,
    /// Bytes of the table.
    pub bytes: usize,
    /// Largest error.
    pub max_ulps: f64,
    /// Mean error.
    pub mean_ulps: f64,
    /// |error| on the 16×16 box next to the far corner.
    pub far_box_abs: f64,
}

fn options(g: &Grid) -> Result<Vec<Box<dyn Storage>>, Box<dyn Error>> {
    Ok(vec![
        Box::new(PlainF32::build(g)),
        Box::new(MeanOffsetF32::build(g)),
        Box::new(TiledF32::build(g, 16)),
        Box::new(HiLoF32::build(g)),
        Box::new(PlainF64::build(g)),
        Box::new(Fixed(Sat::build(g.width, g.height, &g.texels)?)),
    ])
}

/// Median times of the speed measurements at `SIDE`².
#[derive(Clone, Debug)]
pub struct SatTimes {
    /// Build, ours (i64).
    pub build_ours: Duration,
    /// Build, plain f32.
    pub build_f32: Duration,
    /// Build, f64.
    pub build_f64: Duration,
    /// Fractional queries, ours, scalar.
    pub scalar: Duration,
    /// Fractional queries, ours, SIMD.
    pub simd: Duration,
    /// Fractional queries, plain f32.
    pub f32: Duration,
    /// Fractional queries, f64.
    pub f64: Duration,
    /// Integer queries, plain f32 (4 lookups).
    pub int_f32: Duration,
    /// Integer queries, ours (`box_sum_cells`).
    pub int_ours: Duration,
    /// Warm fractional queries, scalar.
    pub warm_scalar: Duration,
    /// Warm fractional queries, SIMD.
    pub warm_simd: Duration,
    /// Warm integer queries, plain f32.
    pub warm_f32_int: Duration,
    /// Warm integer queries, ours.
    pub warm_int: Duration,
    /// The warm fractional queries' loads alone (the same entries in the same order,
    /// summed; no arithmetic): the memory floor of the kernel's layout.
    pub warm_loads: Duration,
    /// The cold fractional queries' loads alone.
    pub cold_loads: Duration,
}

/// The wgpu measurements.
#[derive(Clone, Debug)]
pub struct SatGpu {
    /// The adapter, or why there is none.
    pub note: String,
    /// Median time of the timed queries, upload and read-back included.
    pub time: Option<Duration>,
    /// Largest error in ulps against f64 over the checked boxes.
    pub max_ulps: Option<f64>,
    /// Largest |gpu − cpu| relative to the absolute sum read.
    pub max_rel_vs_cpu: Option<f64>,
}

/// Everything the section measures.
#[derive(Clone, Debug)]
pub struct SatResults {
    /// Error per storage option and side.
    pub rows: Vec<ErrRow>,
    /// Storage options, in table order.
    pub names: Vec<&'static str>,
    /// Queries per timed run.
    pub queries: usize,
    /// Distinct queries of the warm runs.
    pub warm: usize,
    /// Queries per warm timed run (`warm` repeated).
    pub warm_total: usize,
    /// Timed repeats.
    pub repeats: usize,
    /// Median times.
    pub times: SatTimes,
    /// Whether SIMD agrees bit for bit with the scalar query.
    pub simd_bit_exact: bool,
    /// wgpu.
    pub gpu: SatGpu,
    /// Worst error over its stated bound on the high-dynamic-range grid.
    pub hdr_worst_of_bound: f64,
    /// Table entries (`i64`) the warm queries read, per query (the load-only floor reads
    /// 16, repeating a row where the kernel reuses it).
    pub loads_per_query: f64,
    /// Distinct cache lines the warm queries read, per query.
    pub lines_per_query: f64,
    /// The memory hierarchy, measured in the same run.
    pub memory: Vec<memory::Level>,
}

/// Where `SatView::box_sum` reads for each box, as 24 bytes per box: per axis `sat::axis`,
/// then the starts of rows `J0`, `J1` and, where the fraction is not 0, `J0 + 1` and
/// `J1 + 1` (else `J0`, `J1` again), and the columns `I0`, `I1` (clamped to `w − 1`); it
/// reads entries `I0`, `I0 + 1`, `I1`, `I1 + 1` of each of the four rows.
fn load_plan(view: &steradian_core::rsl::sat::SatView<'_>, boxes: &[[f32; 4]]) -> Vec<[u32; 6]> {
    let (w, h) = (view.width(), view.height());
    boxes
        .iter()
        .map(|q| {
            let (i0, _, i1, _) = steradian_core::rsl::sat::axis(q[0], q[2], w);
            let (j0, b0, j1, b1) = steradian_core::rsl::sat::axis(q[1], q[3], h);
            let (i0, i1) = (i0.min(w - 1), i1.min(w - 1));
            let j0p = if b0 != 0.0 { j0 + 1 } else { j0 };
            let j1p = if b1 != 0.0 { j1 + 1 } else { j1 };
            let s = |l: usize| (l * (w + 1)) as u32;
            [s(j0), s(j1), s(j0p), s(j1p), i0 as u32, i1 as u32]
        })
        .collect()
}

/// The sum of the sixteen entries of each box of `plan` (four accumulators, one per row):
/// the loads of the kernel alone, with as little index traffic as the kernel's own input.
fn sum_loads(sums: &[i64], plan: &[[u32; 6]]) -> i64 {
    let mut acc = [0i64; 4];
    for p in plan {
        let (c0, c1) = (p[4] as usize, p[5] as usize);
        for (a, &r) in acc.iter_mut().zip(&p[..4]) {
            let r = r as usize;
            *a = a
                .wrapping_add(sums[r + c0])
                .wrapping_add(sums[r + c0 + 1])
                .wrapping_add(sums[r + c1])
                .wrapping_add(sums[r + c1 + 1]);
        }
    }
    acc.iter().fold(0, |x, &y| x.wrapping_add(y))
}

/// Error growth with resolution, per storage option.
fn error_growth() -> Result<Vec<ErrRow>, Box<dyn Error>> {
    let mut rows = Vec::new();
    for (si, &n) in SIDES.iter().enumerate() {
        let g = uniform_grid(n, SEED + si as u64);
        let boxes = random_boxes(n, ERROR_BOXES, SEED ^ n as u64);
        let refs: Vec<f64> = boxes
            .iter()
            .map(|b| g.reference(b[0], b[1], b[2], b[3]).value)
            .collect();
        for opt in options(&g)? {
            let mut max: f64 = 0.0;
            let mut sum = 0.0;
            let mut far = 0.0;
            for (k, (b, r)) in boxes.iter().zip(&refs).enumerate() {
                let got = opt.box_sum(b[0], b[1], b[2], b[3]);
                let e = (got - r).abs() / ulp(*r);
                max = max.max(e);
                sum += e;
                if k == ERROR_BOXES {
                    far = (got - r).abs();
                }
            }
            rows.push(ErrRow {
                option: opt.name(),
                side: n,
                bytes: opt.bytes(),
                max_ulps: max,
                mean_ulps: sum / boxes.len() as f64,
                far_box_abs: far,
            });
        }
    }
    Ok(rows)
}

/// The wgpu queries on `view` of `g`: timed on `cols`, checked on the first
/// [`GPU_CHECKED`] boxes of the timed queries' seed against f64 and the CPU.
fn gpu_queries(
    opts: &Options,
    g: &Grid,
    view: &steradian_core::rsl::sat::SatView<'_>,
    cols: &Columns,
) -> SatGpu {
    let mut r = SatGpu {
        note: String::from("not tried"),
        time: None,
        max_ulps: None,
        max_rel_vs_cpu: None,
    };
    if !opts.gpu {
        return r;
    }
    let mut gpu = match try_gpu() {
        Err(why) => {
            r.note = format!("none ({why})");
            return r;
        }
        Ok(gpu) => gpu,
    };
    r.note = gpu.adapter_info();
    let table = gpu_table(view);
    let mut gout = Columns::zeros(1, cols.n);
    let mut fail = None;
    let t = median_time(opts.repeats, || {
        if let Err(e) = gpu_box_sums(&mut gpu, &table, cols, &mut gout) {
            fail = Some(e.to_string());
        }
    });
    let check = &random_boxes(SIDE, GPU_CHECKED, SEED + 99)[..GPU_CHECKED];
    let mut cout = Columns::zeros(1, check.len());
    if fail.is_none()
        && let Err(e) = gpu_box_sums(&mut gpu, &table, &Columns::from_rows(check), &mut cout)
    {
        fail = Some(e.to_string());
    }
    match fail {
        Some(e) => r.note = format!("{}: failed: {e}", r.note),
        None => {
            r.time = Some(t);
            let mut worst: f64 = 0.0;
            let mut worst_rel: f64 = 0.0;
            for (k, q) in check.iter().enumerate() {
                let reference = g.reference(q[0], q[1], q[2], q[3]);
                let got = cout.data[k] as f64;
                let cpu = view.box_sum(q[0], q[1], q[2], q[3]) as f64;
                worst = worst.max((got - reference.value).abs() / ulp(reference.value));
                worst_rel = worst_rel.max((got - cpu).abs() / reference.abs_read.max(1e-300));
            }
            r.max_ulps = Some(worst);
            r.max_rel_vs_cpu = Some(worst_rel);
        }
    }
    r
}

/// Worst error over the stated bound of ours at [`SIDE`]² on a grid with a huge dynamic
/// range (log-uniform magnitudes 1e-6 … 1e6, mixed signs): the bound, not ulps, is the
/// promise there.
fn hdr_worst_of_bound() -> Result<f64, Box<dyn Error>> {
    let n = SIDE;
    let mut rng = Rng::new(SEED + 7);
    let hdr = Grid {
        width: n,
        height: n,
        texels: (0..n * n)
            .map(|_| {
                let m = rng.log_range(1e-6, 1e6);
                (if rng.unit() < 0.3 { -m } else { m }) as f32
            })
            .collect(),
    };
    let hsat = Sat::build(n, n, &hdr.texels)?;
    let t_abs = hdr.abs_sum();
    let mut worst: f64 = 0.0;
    for b in random_boxes(n, 1000, SEED + 8) {
        let r = hdr.reference(b[0], b[1], b[2], b[3]);
        let got = hsat.box_sum(b[0], b[1], b[2], b[3]) as f64;
        worst = worst.max((got - r.value).abs() / crate::sat::error_bound(&r, t_abs));
    }
    Ok(worst)
}

/// Runs the section's measurements.
pub fn measure(opts: &Options) -> Result<SatResults, Box<dyn Error>> {
    let bar = ProgressBar::new(5).with_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );

    // 1. Error growth with resolution, per storage option.
    bar.set_message(format!("SAT error at {SIDES:?}²"));
    let rows = error_growth()?;
    let names = rows
        .iter()
        .filter(|r| r.side == SIDES[0])
        .map(|r| r.option)
        .collect();
    bar.inc(1);

    // 2. Build time and query throughput at 1024².
    let n = SIDE;
    let reps = opts.repeats;
    bar.set_message("SAT build times at 1024²");
    let g = uniform_grid(n, SEED + 4);
    let build_ours = median_time(reps, || {
        black_box(Sat::build(n, n, black_box(&g.texels)).ok());
    });
    let build_f32 = median_time(reps, || {
        black_box(PlainF32::build(black_box(&g)));
    });
    let build_f64 = median_time(reps, || {
        black_box(PlainF64::build(black_box(&g)));
    });
    bar.inc(1);

    bar.set_message("SAT queries at 1024²");
    let sat = Sat::build(n, n, &g.texels)?;
    let view = sat.view();
    let plain = PlainF32::build(&g);
    let f64s = PlainF64::build(&g);
    let queries = opts.scaled(QUERIES);
    let qs = random_boxes(n, queries, SEED + 99);
    let qs = &qs[..queries];
    let cols = Columns::from_rows(qs);
    let mut out = vec![0.0f32; queries];
    let mut simd_out = vec![0.0f32; queries];
    // The loads alone, the same entries in the same order: the floor of this layout.
    let sums = view.sums();
    let cold_plan = load_plan(&view, qs);
    // Scalar (contestant 0), SIMD (1) and the floor (2) on the boxes `qs` (columns `c`,
    // plan `plan`), `out` written by the first two.
    let contest = |k: usize, qs: &[[f32; 4]], c: &Columns, plan: &[[u32; 6]], out: &mut [f32]| {
        match k {
            0 => {
                for (o, q) in out.iter_mut().zip(qs) {
                    *o = view.box_sum(q[0], q[1], q[2], q[3]);
                }
            }
            1 => steradian_simd::rsl::sat::box_sum_slices(
                &view,
                c.col(0),
                c.col(1),
                c.col(2),
                c.col(3),
                out,
            ),
            _ => {
                black_box(sum_loads(sums, black_box(plan)));
            }
        }
        black_box(&*out);
    };
    // The three take turns, so that the host's bursts of interference slow them alike and
    // the ratios between them hold.
    let cold = median_times_in_turns(reps, 3, |k| {
        let o = if k == 1 { &mut simd_out } else { &mut out };
        contest(k, qs, &cols, &cold_plan, o);
    });
    let (scalar, simd, cold_loads) = (cold[0], cold[1], cold[2]);
    let scalar_out = out.clone();
    let simd_bit_exact = scalar_out
        .iter()
        .zip(&simd_out)
        .all(|(a, b)| a.to_bits() == b.to_bits());
    let f32_t = median_time(reps, || {
        for (o, q) in out.iter_mut().zip(qs) {
            *o = plain.box_sum_f32(q[0], q[1], q[2], q[3]);
        }
        black_box(&out);
    });
    let f64_t = median_time(reps, || {
        for (o, q) in out.iter_mut().zip(qs) {
            *o = f64s.box_sum(q[0], q[1], q[2], q[3]) as f32;
        }
        black_box(&out);
    });
    // Integer corners: the peers' four-lookup query against ours (`box_sum_cells`, the
    // same `usize` corners) on the same boxes.
    let iq: Vec<[usize; 4]> = qs.iter().map(|q| q.map(|c| (c as usize).min(n))).collect();
    let int_f32 = median_time(reps, || {
        for (o, q) in out.iter_mut().zip(&iq) {
            *o = plain.box_sum_int(q[0], q[1], q[2], q[3]);
        }
        black_box(&out);
    });
    let int_ours = median_time(reps, || {
        for (o, q) in out.iter_mut().zip(&iq) {
            *o = view.box_sum_cells(q[0], q[1], q[2], q[3]);
        }
        black_box(&out);
    });
    // Warm: the first `warm` queries, repeated (the table lines they touch stay in cache):
    // the arithmetic alone, where the cold runs above are bound by memory latency.
    let warm_n = WARM.min(queries);
    let rounds = (queries / warm_n).max(1);
    let warm = &qs[..warm_n];
    let wc = Columns::from_rows(warm);
    let mut wout = vec![0.0f32; warm_n];
    let warm_plan = load_plan(&view, warm);
    let warm_t = median_times_in_turns(reps, 3, |k| {
        for _ in 0..rounds {
            contest(k, warm, &wc, &warm_plan, &mut wout);
        }
    });
    let (warm_scalar, warm_simd, warm_loads) = (warm_t[0], warm_t[1], warm_t[2]);
    let warm_f32_int = median_time(reps, || {
        for _ in 0..rounds {
            for (o, q) in wout.iter_mut().zip(&iq[..warm_n]) {
                *o = plain.box_sum_int(q[0], q[1], q[2], q[3]);
            }
            black_box(&wout);
        }
    });
    let warm_int = median_time(reps, || {
        for _ in 0..rounds {
            for (o, q) in wout.iter_mut().zip(&iq[..warm_n]) {
                *o = view.box_sum_cells(q[0], q[1], q[2], q[3]);
            }
            black_box(&wout);
        }
    });
    // Entries read per box (rows reused where a fraction is 0 are not read again) and
    // distinct cache lines (two per row unless the two column pairs share one).
    let rows_read = |p: &[u32; 6]| 2 + usize::from(p[2] != p[0]) + usize::from(p[3] != p[1]);
    let loads_per_query =
        warm_plan.iter().map(|p| 4 * rows_read(p)).sum::<usize>() as f64 / warm_n as f64;
    let lines_per_query = warm_plan
        .iter()
        .map(|p| {
            let per_row = |r: u32| {
                let line = |c: u32| (r as usize + c as usize) * 8 / memory::LINE;
                let mut l = [line(p[4]), line(p[4] + 1), line(p[5]), line(p[5] + 1)];
                l.sort_unstable();
                1 + l.windows(2).filter(|x| x[0] != x[1]).count()
            };
            let mut rows = vec![p[0], p[1]];
            if p[2] != p[0] {
                rows.push(p[2]);
            }
            if p[3] != p[1] {
                rows.push(p[3]);
            }
            rows.into_iter().map(per_row).sum::<usize>()
        })
        .sum::<usize>() as f64
        / warm_n as f64;
    let memory = memory::measure(reps, opts.scaled(QUERIES) as f64 / QUERIES as f64);
    bar.inc(1);

    // 3. GPU.
    bar.set_message("SAT on the GPU");
    let gpu = gpu_queries(opts, &g, &view, &cols);
    bar.inc(1);

    // 4. The stated bound on a high-dynamic-range grid.
    bar.set_message("SAT error on a high-dynamic-range grid");
    let hdr_worst_of_bound = hdr_worst_of_bound()?;
    bar.inc(1);
    bar.finish_and_clear();

    Ok(SatResults {
        rows,
        names,
        queries,
        warm: warm_n,
        warm_total: warm_n * rounds,
        repeats: reps,
        times: SatTimes {
            build_ours,
            build_f32,
            build_f64,
            scalar,
            simd,
            f32: f32_t,
            f64: f64_t,
            int_f32,
            int_ours,
            warm_scalar,
            warm_simd,
            warm_f32_int,
            warm_int,
            warm_loads,
            cold_loads,
        },
        simd_bit_exact,
        gpu,
        hdr_worst_of_bound,
        loads_per_query,
        lines_per_query,
        memory,
    })
}

/// Milliseconds of `d`.
fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// `a / b` of two durations.
fn ratio(a: Duration, b: Duration) -> f64 {
    a.as_secs_f64() / b.as_secs_f64()
}

impl SatResults {
    /// Nanoseconds per query of a cold timed run.
    fn ns(&self, d: Duration) -> f64 {
        ns_per(self.queries, d)
    }

    /// Nanoseconds per query of a warm timed run.
    fn warm_ns(&self, d: Duration) -> f64 {
        ns_per(self.warm_total, d)
    }

    /// The error row of option `name` at `side`.
    fn at(&self, side: usize, name: &str) -> Option<&ErrRow> {
        self.rows
            .iter()
            .find(|r| r.side == side && r.option == name)
    }
}

/// The summary text of the section.
fn summary(r: &SatResults) -> String {
    let (t, n) = (&r.times, SIDE);
    let mut summary = String::new();
    let _ = writeln!(
        summary,
        "SAT, 1024² texels in [0,1), {} random fractional boxes (sides 0.5–64) + the 16×16 box at the far corner:",
        ERROR_BOXES
    );
    for name in &r.names {
        if let Some(e) = r.at(1024, name) {
            let _ = writeln!(
                summary,
                "  {:<32} max {:>10.3} ulps, mean {:>9.3} ulps, far 16×16 box off by {:.3e}, {:.1} bytes/texel",
                name,
                e.max_ulps,
                e.mean_ulps,
                e.far_box_abs,
                e.bytes as f64 / (n * n) as f64
            );
        }
    }
    let _ = writeln!(
        summary,
        "  build 1024²: ours {:.2} ms, plain f32 {:.2} ms ({:.2}×), f64 {:.2} ms",
        ms(t.build_ours),
        ms(t.build_f32),
        ratio(t.build_ours, t.build_f32),
        ms(t.build_f64)
    );
    let _ = writeln!(
        summary,
        "  query (fractional corners) ns/query: scalar {:.2}, SIMD {:.2} ({:.2}× scalar, bit-exact: {}), plain f32 {:.2}, f64 {:.2}{}",
        r.ns(t.scalar),
        r.ns(t.simd),
        ratio(t.scalar, t.simd),
        r.simd_bit_exact,
        r.ns(t.f32),
        r.ns(t.f64),
        r.gpu.time.map_or(String::new(), |g| format!(
            ", wgpu {:.2} (round trip)",
            r.ns(g)
        ))
    );
    let _ = writeln!(
        summary,
        "  query (integer corners) ns/query: ours (box_sum_cells) {:.2}, plain f32 4-lookup {:.2} ({:.2}×)",
        r.ns(t.int_ours),
        r.ns(t.int_f32),
        ratio(t.int_ours, t.int_f32)
    );
    let _ = writeln!(
        summary,
        "  warm ({} queries repeated, in cache) ns/query: fractional scalar {:.2}, SIMD {:.2} ({:.2}× scalar); integer ours {:.2}, plain f32 4-lookup {:.2}",
        r.warm,
        r.warm_ns(t.warm_scalar),
        r.warm_ns(t.warm_simd),
        ratio(t.warm_scalar, t.warm_simd),
        r.warm_ns(t.warm_int),
        r.warm_ns(t.warm_f32_int)
    );
    let _ = writeln!(
        summary,
        "  roofline: {:.1} i64 loads ({:.1} cache lines) per query; the loads alone take {:.2} ns/query warm, {:.2} cold; SIMD at {:.2}× (warm) and {:.2}× (cold) of that floor, scalar at {:.2}× and {:.2}×",
        r.loads_per_query,
        r.lines_per_query,
        r.warm_ns(t.warm_loads),
        r.ns(t.cold_loads),
        ratio(t.warm_simd, t.warm_loads),
        ratio(t.simd, t.cold_loads),
        ratio(t.warm_scalar, t.warm_loads),
        ratio(t.scalar, t.cold_loads)
    );
    let _ = writeln!(summary, "  {}", memory::summary(&r.memory));
    if let (Some(e), Some(rel)) = (r.gpu.max_ulps, r.gpu.max_rel_vs_cpu) {
        let _ = writeln!(
            summary,
            "  wgpu ({}): max {e:.2} ulps vs f64; |gpu − cpu| ≤ {rel:.2e}·A (tolerance {:.1e})",
            r.gpu.note,
            steradian_core::wgsl::SAT_BOX_REL_TOL
        );
    } else {
        let _ = writeln!(summary, "  wgpu: {}", r.gpu.note);
    }
    let _ = writeln!(
        summary,
        "  high-dynamic-range grid (|t| in 1e-6…1e6, mixed signs): worst error / stated bound = {:.3}",
        r.hdr_worst_of_bound
    );
    summary
}

/// The HTML of the section.
fn html(r: &SatResults) -> String {
    let (t, n) = (&r.times, SIDE);
    let mut html = String::new();
    let _ = write!(
        html,
        "<p>Texels uniform in [0, 1); {ERROR_BOXES} random boxes with fractional corners \
         (sides 0.5–64 texels) per resolution plus the 16×16 integer box next to the far corner; \
         error = |box − exact| in f32 ulps of the exact box integral (f64 brute force). \
         Bound of <code>steradian_core::rsl::sat</code>: |err| ≤ 2⁻²⁴·|I| + 2⁻¹⁵⁰ + 2⁻⁴⁶·A + n·2⁻⁵⁹·T.</p>\
         <table><tr><th>option</th><th>bytes/texel (1024²)</th>"
    );
    for s in SIDES {
        let _ = write!(html, "<th>max ulps {s}²</th>");
    }
    html.push_str("<th>far 16×16 box |err| at 1024²</th></tr>");
    for name in &r.names {
        let _ = write!(html, "<tr><td>{name}</td>");
        let b = r
            .at(1024, name)
            .map_or(0.0, |e| e.bytes as f64 / (n * n) as f64);
        let _ = write!(html, "<td>{b:.2}</td>");
        for s in SIDES {
            let v = r.at(s, name).map_or(f64::NAN, |e| e.max_ulps);
            let _ = write!(html, "<td>{v:.3}</td>");
        }
        let far = r.at(1024, name).map_or(f64::NAN, |e| e.far_box_abs);
        let _ = write!(html, "<td>{far:.3e}</td></tr>");
    }
    html.push_str("</table>");
    html.push_str(&plot(r));
    let _ = write!(
        html,
        "<h3>Speed at 1024² ({} queries, median of {})</h3><table>\
         <tr><th>what</th><th>ns per query / build ms</th><th>ratio</th></tr>\
         <tr><td>build, ours (i64)</td><td>{:.2} ms</td><td>{:.2}× plain f32</td></tr>\
         <tr><td>build, plain f32</td><td>{:.2} ms</td><td>1</td></tr>\
         <tr><td>build, f64</td><td>{:.2} ms</td><td>{:.2}×</td></tr>\
         <tr><td>fractional query, scalar</td><td>{:.2} ns</td><td>1</td></tr>\
         <tr><td>fractional query, SIMD ({})</td><td>{:.2} ns</td><td>{:.2}× faster (bit-exact: {})</td></tr>\
         <tr><td>fractional query, plain f32 (4 bilinear corners)</td><td>{:.2} ns</td><td>{:.2}× ours</td></tr>\
         <tr><td>fractional query, f64 (4 bilinear corners)</td><td>{:.2} ns</td><td>{:.2}× ours</td></tr>\
         <tr><td>integer query, ours</td><td>{:.2} ns</td><td>1</td></tr>\
         <tr><td>integer query, plain f32 (4 lookups)</td><td>{:.2} ns</td><td>{:.2}× ours</td></tr>",
        r.queries,
        r.repeats,
        ms(t.build_ours),
        ratio(t.build_ours, t.build_f32),
        ms(t.build_f32),
        ms(t.build_f64),
        ratio(t.build_f64, t.build_f32),
        r.ns(t.scalar),
        steradian_simd::isa(),
        r.ns(t.simd),
        ratio(t.scalar, t.simd),
        r.simd_bit_exact,
        r.ns(t.f32),
        ratio(t.f32, t.scalar),
        r.ns(t.f64),
        ratio(t.f64, t.scalar),
        r.ns(t.int_ours),
        r.ns(t.int_f32),
        ratio(t.int_f32, t.int_ours),
    );
    let note = &r.gpu.note;
    if let Some(g) = r.gpu.time {
        let _ = write!(
            html,
            "<tr><td>fractional query, wgpu ({note}), upload + read-back included</td><td>{:.2} ns</td><td>{:.2}× scalar</td></tr>",
            r.ns(g),
            ratio(g, t.scalar)
        );
    } else {
        let _ = write!(html, "<tr><td>wgpu</td><td colspan=2>{note}</td></tr>");
    }
    let _ = write!(
        html,
        "<tr><td>warm: fractional query, scalar ({} queries repeated)</td><td>{:.2} ns</td><td>1</td></tr>\
         <tr><td>warm: fractional query, SIMD</td><td>{:.2} ns</td><td>{:.2}× faster</td></tr>\
         <tr><td>warm: integer query, ours</td><td>{:.2} ns</td><td>1</td></tr>\
         <tr><td>warm: integer query, plain f32 (4 lookups)</td><td>{:.2} ns</td><td>{:.2}× ours</td></tr>",
        r.warm,
        r.warm_ns(t.warm_scalar),
        r.warm_ns(t.warm_simd),
        ratio(t.warm_scalar, t.warm_simd),
        r.warm_ns(t.warm_int),
        r.warm_ns(t.warm_f32_int),
        ratio(t.warm_f32_int, t.warm_int),
    );
    let _ = write!(
        html,
        "</table><p>Cold rows: {} random boxes over the 8 MB table, bound by memory \
        latency (a query reads 8 cache lines in 4 rows where a plain integer query reads 4, and \
        its ~200 instructions leave fewer misses in flight). Warm rows: the arithmetic.</p>",
        power_of_two(r.queries)
    );
    html
}

/// `n` as a power of two with a superscript exponent (`2¹⁸`) where it is one, else in digits.
fn power_of_two(n: usize) -> String {
    if !n.is_power_of_two() {
        return n.to_string();
    }
    const SUPERSCRIPTS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let exponent = n.trailing_zeros().to_string();
    let digits = exponent.bytes().map(|d| SUPERSCRIPTS[(d - b'0') as usize]);
    std::iter::once('2').chain(digits).collect()
}

/// The data of the section in `report.json`.
fn data(r: &SatResults) -> serde_json::Value {
    let t = &r.times;
    let warm = |d| r.warm_ns(d);
    json!({
        "error_growth": r.rows,
        "build_ms": {"ours": ms(t.build_ours), "plain_f32": ms(t.build_f32), "f64": ms(t.build_f64)},
        "query_ns": {
            "scalar": r.ns(t.scalar), "simd": r.ns(t.simd), "plain_f32": r.ns(t.f32), "f64": r.ns(t.f64),
            "wgpu": r.gpu.time.map(|g| r.ns(g)),
            "integer_ours": r.ns(t.int_ours), "integer_plain_f32": r.ns(t.int_f32),
            "warm_scalar": warm(t.warm_scalar), "warm_simd": warm(t.warm_simd),
            "warm_integer_ours": warm(t.warm_int), "warm_integer_plain_f32": warm(t.warm_f32_int),
            "warm_loads_only": warm(t.warm_loads), "cold_loads_only": r.ns(t.cold_loads),
        },
        "roofline": {
            "loads_per_query": r.loads_per_query, "lines_per_query": r.lines_per_query,
            "memory": r.memory,
        },
        "simd_bit_exact": r.simd_bit_exact,
        "gpu": {"adapter": r.gpu.note, "max_ulps_vs_f64": r.gpu.max_ulps, "max_rel_to_A_vs_cpu": r.gpu.max_rel_vs_cpu},
        "hdr_worst_error_over_bound": r.hdr_worst_of_bound,
    })
}

/// Max error (log, clamped to 1e-2 … 1e6 ulps) against the table side, a line per option.
fn plot(r: &SatResults) -> String {
    let series = r
        .names
        .iter()
        .map(|name| {
            let points = r
                .rows
                .iter()
                .filter(|e| e.option == *name)
                .map(|e| Pt::new(e.side as f64, e.max_ulps.clamp(1e-2, 1e6)))
                .collect();
            Series::line(*name, points)
        })
        .collect();
    let ticks = SIDES.iter().map(|&s| (s as f64, format!("{s}²"))).collect();
    Chart::new(
        "Summed-area tables: max error against resolution",
        Axis::new("table size (texels)", Scale::Log)
            .range(SIDES[0] as f64, SIDES[SIDES.len() - 1] as f64)
            .ticks(ticks),
        Axis::new("max error, f32 ulps of the box (log)", Scale::Log).range(1e-2, 1e6),
        series,
    )
    .svg()
}

/// The section of measured results.
pub fn render(r: &SatResults) -> Section {
    Section {
        id: "sat",
        title: "Summed-area tables".into(),
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
