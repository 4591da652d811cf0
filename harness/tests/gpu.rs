//! The WGSL kernels on a real adapter against the scalar kernels, within the tolerances
//! documented in `steradian_core::wgsl`, on deterministic pseudo-random finite inputs plus
//! hand-picked hard cases; and the batching of the `wgpu` backend (n = 0, n = 1, batches
//! larger than one dispatch row, chunked batches).
//!
//! Without an adapter the tests print `GPU tests skipped: <reason>` and pass, unless
//! `STERADIAN_REQUIRE_GPU=1`, in which case they fail.

use std::time::Instant;

use steradian_core::wgsl;
use steradian_harness::backend::gpu::Gpu;
use steradian_harness::backend::{Backend, cpu};
use steradian_harness::batch;
use steradian_harness::kernels::{Columns, Kernel};

use core::f32::consts::{FRAC_PI_2, PI};

use crate::common::gpu as gpu_common;
use gpu_common::gpu;

/// The harness's deterministic generator, with the f32 helpers these tests want.
struct Rng(steradian_harness::rng::Rng);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }
    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }
    /// `±10^U(lo, hi)` with a random sign.
    fn log_signed(&mut self, lo: f32, hi: f32) -> f32 {
        let m = 10f32.powf(self.range(lo, hi));
        if self.next_u64() & 1 == 0 { m } else { -m }
    }
    /// A unit vector (rejection sampling of the ball).
    fn dir(&mut self) -> [f32; 3] {
        loop {
            let v = [
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            ];
            let l2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            if l2 > 1e-4 && l2 <= 1.0 {
                return normalize(v);
            }
        }
    }
}

fn normalize(v: [f32; 3]) -> [f32; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

/// Distance in units in the last place (`+0` and `−0` are equal).
fn ulps(a: f32, b: f32) -> u64 {
    fn ord(x: f32) -> i64 {
        let i = x.to_bits() as i32 as i64;
        if i < 0 { i64::from(i32::MIN) - i } else { i }
    }
    (ord(a) - ord(b)).unsigned_abs()
}

/// Worst differences seen for one kernel, for the report printed with `--nocapture`.
/// Rows whose scalar result is in the flush-to-zero range are counted apart.
#[derive(Default, Debug)]
struct Stats {
    max_abs: f64,
    max_rel: f64,
    max_ulps: u64,
    /// Largest error in the unit of the kernel's tolerance (see [`Allowed::unit`]).
    max_units: f64,
    /// Largest error as a fraction of the allowed difference.
    max_ratio: f64,
    /// The row where that happened: inputs, GPU and scalar output.
    worst: String,
    /// Rows whose scalar result is below the flush-to-zero floor.
    flushed: usize,
}

impl Stats {
    fn add(&mut self, g: f32, c: f32, a: &Allowed, row: impl FnOnce() -> String) {
        let diff = (g as f64 - c as f64).abs();
        if a.flushed {
            self.flushed += 1;
            return;
        }
        self.max_abs = self.max_abs.max(diff);
        if c != 0.0 {
            self.max_rel = self.max_rel.max(diff / (c as f64).abs());
        }
        self.max_ulps = self.max_ulps.max(ulps(g, c));
        if a.unit > 0.0 {
            self.max_units = self.max_units.max(diff / a.unit);
        }
        let ratio = if a.tol > 0.0 { diff / a.tol } else { 0.0 };
        if ratio > self.max_ratio {
            self.max_ratio = ratio;
            self.worst = format!("{}: GPU {g:e}, scalar {c:e}", row());
        }
    }
}

/// The allowed difference `|gpu − cpu|` for one output.
struct Allowed {
    /// The allowed absolute difference.
    tol: f64,
    /// The unit the kernel's tolerance constant is expressed in (`tol ≈ constant · unit`).
    unit: f64,
    /// The scalar result is below the flush-to-zero floor, where only `tol` applies.
    flushed: bool,
}

/// The allowed difference for an output of row `row` whose scalar value is `c`, per the
/// constants of `steradian_core::wgsl`. Results that are subnormal on the CPU may be
/// flushed to 0 on the GPU.
fn allowed(kernel: Kernel, input: &Columns, row: usize, c: f32) -> Allowed {
    let c64 = c as f64;
    let min_normal = f32::MIN_POSITIVE as f64;
    let abs = |tol: f32| Allowed {
        tol: tol as f64,
        unit: 1.0,
        flushed: false,
    };
    match kernel.name() {
        "hemisphere-map" => abs(wgsl::HEMISPHERE_MAP_ABS_TOL),
        "hemisphere-unmap" => abs(wgsl::HEMISPHERE_UNMAP_ABS_TOL),
        "lobe-eval" => {
            let s = input.data[3 * input.n + row] as f64;
            let floor = s.abs() * min_normal;
            if c64.abs() <= floor {
                Allowed {
                    tol: floor,
                    unit: 0.0,
                    flushed: true,
                }
            } else {
                let unit = (1.0 + (c64 / s).ln().abs()) * c64.abs();
                Allowed {
                    tol: wgsl::LOBE_EVAL_REL_TOL as f64 * unit + floor,
                    unit,
                    flushed: false,
                }
            }
        }
        "lobe-integral" => {
            if c64.abs() < min_normal {
                Allowed {
                    tol: min_normal,
                    unit: 0.0,
                    flushed: true,
                }
            } else {
                // an ulp of c, counted from below
                let unit = c64.abs() - f32::from_bits(c.abs().to_bits() - 1) as f64;
                Allowed {
                    tol: wgsl::LOBE_INTEGRAL_ULP_TOL as f64 * unit * 1.000_001,
                    unit,
                    flushed: false,
                }
            }
        }
        "cap-exponent" => Allowed {
            tol: wgsl::CAP_EXPONENT_REL_TOL as f64 * c64.abs() + wgsl::CAP_EXPONENT_ABS_TOL as f64,
            unit: c64.abs(),
            flushed: false,
        },
        other => panic!("{other}: no GPU tolerance in this test"),
    }
}

/// Runs `input` on the GPU and the scalar CPU kernel and compares every output.
fn check(gpu: &mut Gpu, kernel: Kernel, input: &Columns) -> Stats {
    for &v in &input.data {
        assert!(v.is_finite(), "test inputs must be finite");
    }
    let mut g = Columns::zeros(kernel.output_arity(), input.n);
    g.data.fill(f32::NAN);
    gpu.run(kernel, input, &mut g)
        .unwrap_or_else(|e| panic!("{kernel}: GPU run failed: {e}"));
    let mut c = Columns::zeros(kernel.output_arity(), input.n);
    cpu::run_scalar(kernel, input, &mut c, false);
    let mut stats = Stats::default();
    for row in 0..input.n {
        for col in 0..kernel.output_arity() {
            let (gv, cv) = (g.col(col)[row], c.col(col)[row]);
            let a = allowed(kernel, input, row, cv);
            let tol = a.tol;
            let diff = (gv as f64 - cv as f64).abs();
            assert!(
                gv.is_finite() && diff <= tol,
                "{kernel}: row {row}, output column {col}: inputs {:?}: GPU {gv:e} vs scalar \
                 {cv:e} (|diff| = {diff:e} > allowed {tol:e}; all GPU outputs {:?}, scalar {:?})",
                input.row(row),
                g.row(row),
                c.row(row),
            );
            stats.add(gv, cv, &a, || format!("row {row} {:?}", input.row(row)));
        }
    }
    stats
}

const RANDOM_ROWS: usize = 20_000;

fn map_inputs(rng: &mut Rng) -> Columns {
    let mut rows: Vec<[f32; 3]> = vec![
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.6, 0.8, 0.0],
        [1.0, 0.0, 1e-7],
        [0.6, -0.8, -1e-7],
        [1e-7, 0.0, 1.0],
        [3e38, 3e38, 3e38],
        [-3e38, 1e30, 1.0],
        [3e38, 0.0, -2e38],
        [1e-30, 2e-30, -1e-30],
        [1e-30, 0.0, 0.0],
        [0.0, 0.0, -1e-35],
        [1.0, 1e-20, 0.0],
        [5.0, -5.0, 5.0],
    ];
    for k in 0..RANDOM_ROWS {
        let d = rng.dir();
        let m = match k % 4 {
            0 => 1.0,
            1 => rng.range(0.1, 10.0),
            2 => 10f32.powf(rng.range(-30.0, 30.0)),
            _ => 10f32.powf(rng.range(30.0, 38.0)),
        };
        // near the horizon and near the poles, too
        let d = match k % 7 {
            0 => [d[0], d[1], d[2] * 1e-6],
            1 => [d[0] * 1e-4, d[1] * 1e-4, d[2]],
            _ => d,
        };
        rows.push([d[0] * m, d[1] * m, d[2] * m]);
    }
    Columns::from_rows(&rows)
}

fn unmap_inputs(rng: &mut Rng) -> Columns {
    let mut rows: Vec<[f32; 2]> = vec![
        [0.0, 0.0],
        [1.0, 0.0],
        [0.0, -1.0],
        [0.6, 0.8],
        [-0.6, 0.8],
        [0.999_999_94, 0.0],
        [1.000_000_1, 0.0],
        [0.707_106_77, 0.707_106_77],
        [1e-7, 0.0],
        [1e-30, -1e-30],
        [3.0, 4.0],
        [1e18, -1e18],
        [-3e18, 0.0],
    ];
    for k in 0..RANDOM_ROWS {
        let p = match k % 3 {
            0 => [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)],
            1 => {
                // near the circle
                let phi = rng.range(0.0, 2.0 * PI);
                let r = 1.0 + rng.range(-1e-5, 1e-5);
                [r * phi.cos(), r * phi.sin()]
            }
            _ => {
                let phi = rng.range(0.0, 2.0 * PI);
                let r = 10f32.powf(rng.range(-8.0, 18.0));
                [r * phi.cos(), r * phi.sin()]
            }
        };
        rows.push(p);
    }
    Columns::from_rows(&rows)
}

fn lobe_eval_inputs(rng: &mut Rng) -> Columns {
    let z = [0.0, 0.0, 1.0];
    let x = [1.0, 0.0, 0.0];
    let near = normalize([1.0, 0.0, 1e-7]);
    let off = normalize([1e-3, 0.0, 1.0]);
    let tiny = normalize([1e-6, 0.0, 1.0]);
    let row = |a: [f32; 3], s: f32, e: f32, v: [f32; 3]| [a[0], a[1], a[2], s, e, v[0], v[1], v[2]];
    let mut rows: Vec<[f32; 8]> = vec![
        // zero vectors
        row([0.0; 3], 1.0, 1.0, z),
        row(z, 1.0, 3.0, [0.0; 3]),
        row([0.0; 3], 2.0, 7.0, [0.0; 3]),
        // on the axis, on the horizon, opposite
        row(z, 1.5, 1e5, z),
        row(z, 1.5, 0.0, z),
        row(z, 2.0, 0.0, x),
        row(z, 2.0, 1.0, x),
        row(x, 2.0, 1e5, [0.0, 1.0, 0.0]),
        row(z, 2.0, 4.0, [0.0, 0.0, -1.0]),
        // z = 1e-7 just above the horizon
        row(z, 1.0, 1.0, near),
        row(z, 1.0, 0.0, near),
        row(z, 1.0, 0.5, near),
        // exponent 0 and 1e5 near the axis
        row(z, 3.0, 1e5, off),
        row(z, 3.0, 1e5, tiny),
        row(z, 3.0, 0.0, off),
        row(off, -3.0, 1e5, tiny),
        // negative exponents are clamped to 0
        row(z, 1.0, -1.0, off),
        row(z, 1.0, -1e30, [0.6, 0.0, 0.8]),
        // huge and tiny scales
        row(z, 1e30, 10.0, [0.6, 0.0, 0.8]),
        row(z, -1e-30, 10.0, [0.6, 0.0, 0.8]),
        row(z, 0.0, 10.0, [0.6, 0.0, 0.8]),
    ];
    for k in 0..RANDOM_ROWS {
        let a = rng.dir();
        let v = match k % 3 {
            0 => rng.dir(),
            _ => {
                // near the axis: a + a perturbation of size 10^U(-6, 0)
                let p = rng.dir();
                let eps = 10f32.powf(rng.range(-6.0, 0.0));
                normalize([a[0] + eps * p[0], a[1] + eps * p[1], a[2] + eps * p[2]])
            }
        };
        let s = match k % 5 {
            0 => rng.log_signed(-30.0, 30.0),
            _ => rng.range(-10.0, 10.0),
        };
        let e = match k % 6 {
            0 => 0.0,
            1 => 1.0,
            2 => 1e5,
            3 => -rng.range(0.0, 10.0),
            _ => 10f32.powf(rng.range(-2.0, 5.0)),
        };
        rows.push(row(a, s, e, v));
    }
    Columns::from_rows(&rows)
}

fn lobe_integral_inputs(rng: &mut Rng) -> Columns {
    let mut rows: Vec<[f32; 2]> = vec![
        [0.0, 1.0],
        [1.0, 1.0],
        [1e5, 1.0],
        [-1.0, 1.0],
        [-1e30, 2.0],
        [0.0, 0.0],
        [3.0, -0.0],
        [0.0, 1e36],
        [1e30, 1e36],
        [1e37, 1.0],
        [1e37, 1e36],
        [0.0, 1e-30],
        [1e5, -1e-30],
        [1e-30, 1.0],
    ];
    for k in 0..RANDOM_ROWS {
        let e = match k % 4 {
            0 => 10f32.powf(rng.range(-3.0, 37.0)),
            1 => rng.range(0.0, 100.0),
            2 => -rng.range(0.0, 10.0),
            _ => 10f32.powf(rng.range(-3.0, 6.0)),
        };
        let s = rng.log_signed(-30.0, 36.0);
        rows.push([e, s]);
    }
    Columns::from_rows(&rows)
}

fn cap_inputs(rng: &mut Rng) -> Columns {
    let mut rows: Vec<[f32; 1]> = [
        1e-4,
        FRAC_PI_2,
        f32::from_bits(FRAC_PI_2.to_bits() - 1),
        f32::from_bits(FRAC_PI_2.to_bits() + 1),
        3.0,
        PI,
        1e30,
        0.0,
        -0.0,
        -1.0,
        -1e30,
        1e-18,
        1e-19,
        1e-30,
        0.5,
        1.0,
        1.5,
        1.57,
    ]
    .iter()
    .map(|a| [*a])
    .collect();
    for k in 0..RANDOM_ROWS {
        let a = match k % 3 {
            0 => rng.range(-0.5, 2.0),
            1 => 10f32.powf(rng.range(-20.0, 0.2)),
            _ => FRAC_PI_2 - 10f32.powf(rng.range(-7.0, 0.0)),
        };
        rows.push([a]);
    }
    Columns::from_rows(&rows)
}

fn inputs(kernel: Kernel, seed: u64) -> Columns {
    let mut rng = Rng(steradian_harness::rng::Rng::new(seed));
    match kernel.name() {
        "hemisphere-map" => map_inputs(&mut rng),
        "hemisphere-unmap" => unmap_inputs(&mut rng),
        "lobe-eval" => lobe_eval_inputs(&mut rng),
        "lobe-integral" => lobe_integral_inputs(&mut rng),
        "cap-exponent" => cap_inputs(&mut rng),
        other => panic!("{other}: no GPU inputs in this test"),
    }
}

#[test]
fn kernels_match_scalar_within_documented_tolerance() {
    let Some(mut gpu) = gpu() else { return };
    for kernel in steradian_harness::registry::batch_kernels() {
        let input = inputs(kernel, 0x5EED ^ kernel.spec().seed);
        let stats = check(&mut gpu, kernel, &input);
        eprintln!(
            "{kernel:>16}: {} rows ({} in the flush-to-zero range), max |diff| {:.3e}, \
             max rel {:.3e}, max ulps {}, max {:.3e} in tolerance units; worst = {:.2} of \
             the allowed difference at {}",
            input.n,
            stats.flushed,
            stats.max_abs,
            stats.max_rel,
            stats.max_ulps,
            stats.max_units,
            stats.max_ratio,
            stats.worst
        );
    }
}

#[test]
fn tiny_batches_and_reuse() {
    let Some(mut gpu) = gpu() else { return };
    for kernel in steradian_harness::registry::batch_kernels() {
        // n = 0: no dispatch, no error
        let empty_in = Columns::zeros(kernel.input_arity(), 0);
        let mut empty_out = Columns::zeros(kernel.output_arity(), 0);
        gpu.run(kernel, &empty_in, &mut empty_out)
            .unwrap_or_else(|e| panic!("{kernel}: n = 0 failed: {e}"));
        // n = 1, then a larger batch, then n = 1 again (buffers are reused and only grow)
        let all = inputs(kernel, 7);
        for n in [1, 65, all.n, 1, 3] {
            let mut cols = Columns::zeros(kernel.input_arity(), n);
            for c in 0..kernel.input_arity() {
                cols.col_mut(c).copy_from_slice(&all.col(c)[all.n - n..]);
            }
            check(&mut gpu, kernel, &cols);
        }
    }
    // shape errors are errors, not panics
    let bad = Columns::zeros(2, 4);
    let mut out = Columns::zeros(1, 4);
    assert!(gpu.run(batch::lobe::LOBE_EVAL, &bad, &mut out).is_err());
}

#[test]
fn large_batches_fold_into_2d_and_split_into_chunks() {
    let Some(mut gpu) = gpu() else { return };
    // 5M rows: more than 65535 workgroups of 64, so the dispatch is 2-D.
    let n = 5_000_000;
    let mut rng = Rng(steradian_harness::rng::Rng::new(99));
    let mut input = Columns::zeros(2, n);
    for r in 0..n {
        input.data[r] = rng.range(-1.0, 1000.0);
        input.data[n + r] = rng.range(-10.0, 10.0);
    }
    let stats = check(&mut gpu, batch::lobe::LOBE_INTEGRAL, &input);
    eprintln!(
        "lobe-integral, 5M rows in one chunk: max ulps {}",
        stats.max_ulps
    );
    // The same batch in chunks of an odd number of rows (not a multiple of 64).
    gpu.set_max_chunk_rows(Some(1_234_567));
    assert_eq!(gpu.chunk_rows(batch::lobe::LOBE_INTEGRAL), 1_234_567);
    let stats = check(&mut gpu, batch::lobe::LOBE_INTEGRAL, &input);
    eprintln!(
        "lobe-integral, 5M rows in chunks: max ulps {}",
        stats.max_ulps
    );
    // Chunked multi-column kernels: columns are gathered per chunk.
    gpu.set_max_chunk_rows(Some(777));
    for kernel in [
        batch::lobe::LOBE_EVAL,
        batch::rsl::HEMISPHERE_MAP,
        batch::rsl::HEMISPHERE_UNMAP,
    ] {
        check(&mut gpu, kernel, &inputs(kernel, 3));
    }
    gpu.set_max_chunk_rows(None);
}

/// Round-trip time of 1M-row batches per kernel (upload, dispatch, read-back), best of 5
/// after a warm-up. Run with `--ignored --nocapture`, preferably in release.
#[test]
#[ignore]
fn timing_1m() {
    let Some(mut gpu) = gpu() else { return };
    let n = 1 << 20;
    for kernel in steradian_harness::registry::batch_kernels() {
        let base = inputs(kernel, 11);
        let mut input = Columns::zeros(kernel.input_arity(), n);
        for c in 0..kernel.input_arity() {
            let src = base.col(c);
            for (r, v) in input.col_mut(c).iter_mut().enumerate() {
                *v = src[r % base.n];
            }
        }
        let mut out = Columns::zeros(kernel.output_arity(), n);
        gpu.run(kernel, &input, &mut out).expect("warm-up");
        let mut best = f64::INFINITY;
        for _ in 0..5 {
            let t = Instant::now();
            gpu.run(kernel, &input, &mut out).expect("run");
            best = best.min(t.elapsed().as_secs_f64());
        }
        eprintln!(
            "{kernel:>16}: {n} rows in {:.2} ms ({:.1} Mrows/s)",
            best * 1e3,
            n as f64 / best / 1e6
        );
    }
}

/// The generic path for kernels outside the `Kernel` enum: a caller-supplied table at
/// binding 3, arities taken from the columns, chunking included.
#[test]
fn custom_kernel_with_a_caller_table() {
    use steradian_harness::backend::gpu::Custom;
    const SRC: &str = concat!(
        include_str!("../../core/src/wgsl/batch.wgsl"),
        "@group(0) @binding(3) var<storage, read> table: array<f32>;\n",
        "@compute @workgroup_size(64) fn main(@builtin(global_invocation_id) gid: vec3<u32>) {\n",
        "  let i = batch_row(gid); if (i >= params.n) { return; }\n",
        "  let x = input[i]; let y = input[params.n + i];\n",
        "  output[i] = x * y + table[u32(y)];\n",
        "}\n"
    );
    let Some(mut g) = gpu() else { return };
    let n = 1000;
    let rows: Vec<[f32; 2]> = (0..n).map(|i| [i as f32 * 0.5, (i % 7) as f32]).collect();
    let input = Columns::from_rows(&rows);
    let table: Vec<f32> = (0..7).map(|k| 100.0 * k as f32).collect();
    for chunk in [None, Some(33)] {
        g.set_max_chunk_rows(chunk);
        let mut out = Columns::zeros(1, n);
        let custom = Custom {
            label: "test-custom",
            source: SRC,
            table: Some(&table),
        };
        g.run_custom(&custom, &input, &mut out)
            .expect("custom kernel runs");
        for (i, r) in rows.iter().enumerate() {
            assert_eq!(out.data[i], r[0] * r[1] + table[r[1] as usize], "row {i}");
        }
    }
    let mut bad = Columns::zeros(1, n + 1);
    let custom = Custom {
        label: "test-custom",
        source: SRC,
        table: Some(&table),
    };
    assert!(g.run_custom(&custom, &input, &mut bad).is_err());
}
