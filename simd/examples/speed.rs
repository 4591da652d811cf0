//! Speed of the SIMD slice functions against the scalar kernels, in ns per element.
//!
//! ```text
//! cargo run --release -p steradian-simd --example speed [-- N [REPEATS [KERNEL]]]
//! ```
//!
//! Three ways to run each kernel over `N` inputs (default 2²¹) in the harness's batch layout
//! (column `c` at `data[c·n .. (c+1)·n]`):
//!
//! - `scalar-opaque`: the scalar kernel one input at a time, each input and output through
//!   `std::hint::black_box` (like the harness's `cpu-scalar` backend);
//! - `scalar-loop`: a plain loop over the scalar kernel, which LLVM may vectorise (like
//!   `cpu-scalar-loop`);
//! - `simd`: the slice function of `steradian-simd` (like `cpu-simd`).
//!
//! Each is run `REPEATS` times (default 15), the three in turn in every round; the best
//! time is reported. The example also
//! checks that the SIMD results equal the scalar ones (bit for bit where the contract says
//! so).

use std::hint::black_box;
use std::time::Instant;

use steradian_core::{Vec2, Vec3, lobe, lobe::cap, rsl::hemisphere};
use steradian_simd as simd;

#[derive(Clone, Copy, PartialEq, Eq)]
enum K {
    Map,
    Unmap,
    Eval,
    Integral,
    Cap,
}

impl K {
    const ALL: [K; 5] = [K::Map, K::Unmap, K::Eval, K::Integral, K::Cap];
    fn name(self) -> &'static str {
        match self {
            K::Map => "hemisphere-map",
            K::Unmap => "hemisphere-unmap",
            K::Eval => "lobe-eval",
            K::Integral => "lobe-integral",
            K::Cap => "cap-exponent",
        }
    }
    fn arity(self) -> (usize, usize) {
        match self {
            K::Map => (3, 2),
            K::Unmap => (2, 3),
            K::Eval => (8, 1),
            K::Integral => (2, 1),
            K::Cap => (1, 1),
        }
    }
}

#[inline(always)]
fn bb<T, const OPAQUE: bool>(x: T) -> T {
    if OPAQUE { black_box(x) } else { x }
}

/// The harness's `run_scalar`, kernel by kernel.
#[inline(never)]
fn run_scalar<const OPAQUE: bool>(k: K, i: &[f32], n: usize, out: &mut [f32]) {
    match k {
        K::Map => {
            let (u, v) = out.split_at_mut(n);
            for r in 0..n {
                let d = bb::<_, OPAQUE>(Vec3::new(i[r], i[n + r], i[2 * n + r]));
                let p = bb::<_, OPAQUE>(hemisphere::map(d));
                u[r] = p.x;
                v[r] = p.y;
            }
        }
        K::Unmap => {
            let (x, rest) = out.split_at_mut(n);
            let (y, z) = rest.split_at_mut(n);
            for r in 0..n {
                let p = bb::<_, OPAQUE>(Vec2::new(i[r], i[n + r]));
                let d = bb::<_, OPAQUE>(hemisphere::unmap(p));
                x[r] = d.x;
                y[r] = d.y;
                z[r] = d.z;
            }
        }
        K::Eval => {
            for r in 0..n {
                let a = bb::<_, OPAQUE>(Vec3::new(i[r], i[n + r], i[2 * n + r]));
                let (s, e) = bb::<_, OPAQUE>((i[3 * n + r], i[4 * n + r]));
                let v = bb::<_, OPAQUE>(Vec3::new(i[5 * n + r], i[6 * n + r], i[7 * n + r]));
                out[r] = bb::<_, OPAQUE>(lobe::eval(a, s, e, v));
            }
        }
        K::Integral => {
            for r in 0..n {
                let (e, s) = bb::<_, OPAQUE>((i[r], i[n + r]));
                out[r] = bb::<_, OPAQUE>(lobe::integral(e, s));
            }
        }
        K::Cap => {
            for r in 0..n {
                let a = bb::<_, OPAQUE>(i[r]);
                out[r] = bb::<_, OPAQUE>(cap::exponent_l2(a));
            }
        }
    }
}

/// The `cpu-simd` backend's dispatch.
#[inline(never)]
fn run_simd(k: K, input: &[f32], n: usize, out: &mut [f32]) {
    let col = |c: usize| &input[c * n..(c + 1) * n];
    match k {
        K::Map => {
            let (u, v) = out.split_at_mut(n);
            simd::rsl::hemisphere::map_slices(col(0), col(1), col(2), u, v);
        }
        K::Unmap => {
            let (x, rest) = out.split_at_mut(n);
            let (y, z) = rest.split_at_mut(n);
            simd::rsl::hemisphere::unmap_slices(col(0), col(1), x, y, z);
        }
        K::Eval => simd::lobe::eval_slices(
            [col(0), col(1), col(2)],
            col(3),
            col(4),
            [col(5), col(6), col(7)],
            out,
        ),
        K::Integral => simd::lobe::integral_slices(col(0), col(1), out),
        K::Cap => simd::lobe::cap::exponent_l2_slices(col(0), out),
    }
}

#[path = "../tests/common/rng.rs"]
mod rng;
use rng::Rng;

/// Typical inputs in the batch layout.
fn inputs(k: K, n: usize, rng: &mut Rng) -> Vec<f32> {
    let (ar, _) = k.arity();
    let mut d = vec![0.0f32; ar * n];
    for r in 0..n {
        let row: Vec<f32> = match k {
            K::Map => rng.dir().to_array().to_vec(),
            K::Unmap => vec![rng.range(-1.05, 1.05), rng.range(-1.05, 1.05)],
            K::Eval => {
                let a = rng.dir();
                let v = (a + rng.dir() * rng.range(0.0, 1.5)).normalize();
                let e = 10f32.powf(rng.range(0.0, 4.0));
                vec![a.x, a.y, a.z, rng.range(0.1, 2.0), e, v.x, v.y, v.z]
            }
            K::Integral => vec![10f32.powf(rng.range(0.0, 4.0)), rng.range(0.1, 2.0)],
            K::Cap => vec![rng.range(1e-4, std::f32::consts::FRAC_PI_2)],
        };
        for (c, x) in row.into_iter().enumerate() {
            d[c * n + r] = x;
        }
    }
    d
}

/// Times one run of `f`.
fn time(f: &mut dyn FnMut()) -> f64 {
    let t = Instant::now();
    f();
    t.elapsed().as_secs_f64()
}

/// The best time of each of `fs` over `repeats` rounds; each round runs every `f` once, in
/// turn, so slow phases of a shared machine hit all of them alike.
fn best_of(repeats: usize, fs: &mut [&mut dyn FnMut()]) -> Vec<f64> {
    let mut best = vec![f64::INFINITY; fs.len()];
    for f in fs.iter_mut() {
        f(); // warm-up
    }
    for _ in 0..repeats {
        for (b, f) in best.iter_mut().zip(fs.iter_mut()) {
            *b = b.min(time(*f));
        }
    }
    best
}

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().map_or(1 << 21, |a| a.parse().expect("N"));
    let repeats: usize = args.next().map_or(15, |a| a.parse().expect("REPEATS"));
    let only = args.next();
    println!(
        "steradian-simd speed: N = {n}, best of {repeats}, f32x8 on {}, slice functions {} lanes",
        simd::isa(),
        simd::slice_lanes()
    );
    println!(
        "{:<18} {:>14} {:>12} {:>10} {:>12} {:>12}",
        "kernel", "scalar-opaque", "scalar-loop", "simd", "vs opaque", "vs loop"
    );
    let mut rng = Rng(42);
    for k in K::ALL {
        if only.as_deref().is_some_and(|o| o != k.name()) {
            continue;
        }
        let input = inputs(k, n, &mut rng);
        let out_len = k.arity().1 * n;
        let mut o_opaque = vec![0.0f32; out_len];
        let mut o_loop = vec![0.0f32; out_len];
        let mut o_simd = vec![0.0f32; out_len];
        let (mut f_opaque, mut f_loop, mut f_simd) = (
            || {
                run_scalar::<true>(k, black_box(&input), n, &mut o_opaque);
                black_box(&mut o_opaque);
            },
            || {
                run_scalar::<false>(k, black_box(&input), n, &mut o_loop);
                black_box(&mut o_loop);
            },
            || {
                run_simd(k, black_box(&input), n, &mut o_simd);
                black_box(&mut o_simd);
            },
        );
        let t = best_of(repeats, &mut [&mut f_opaque, &mut f_loop, &mut f_simd]);
        let (t_opaque, t_loop, t_simd) = (t[0], t[1], t[2]);
        // The contract, as a sanity check of what was timed.
        assert_eq!(o_opaque, o_loop);
        for (c, w) in o_loop.iter().zip(&o_simd) {
            let ok = if k == K::Eval {
                (c - w).abs() <= 1e-4 * c.abs() + 1e-30
            } else {
                c.to_bits() == w.to_bits()
            };
            assert!(ok, "{}: scalar {c:e} simd {w:e}", k.name());
        }
        let ns = |t: f64| t * 1e9 / n as f64;
        println!(
            "{:<18} {:>11.3} ns {:>9.3} ns {:>7.3} ns {:>11.2}x {:>11.2}x",
            k.name(),
            ns(t_opaque),
            ns(t_loop),
            ns(t_simd),
            t_opaque / t_simd,
            t_loop / t_simd
        );
    }
}
