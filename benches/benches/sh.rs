//! Real SH evaluation, directions per second at 3, 5, 10, 20 and 30 bands: the scalar
//! kernel (`steradian_core::sh::eval_into`), its SIMD twin (`steradian_simd::sh::eval_slices`,
//! bit-identical) and, as the baseline of the same run, a plain `f64` evaluation (the
//! reference's factorial normalisation, unnormalised Legendre recurrence and `cos(mφ)`).
//!
//! `cargo bench -p steradian-benches --bench sh`

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use steradian_core::{Vec3, sh};
use steradian_harness::rng::Rng;

const DIRS: usize = 1024;

fn eval(c: &mut Criterion) {
    let mut rng = Rng::new(0x5eed);
    let dirs: Vec<Vec3> = (0..DIRS)
        .map(|_| {
            let d = rng.sphere();
            Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)
        })
        .collect();
    let (x, y, z): (Vec<f32>, Vec<f32>, Vec<f32>) = (
        dirs.iter().map(|d| d.x).collect(),
        dirs.iter().map(|d| d.y).collect(),
        dirs.iter().map(|d| d.z).collect(),
    );
    let mut g = c.benchmark_group("sh-eval");
    g.throughput(Throughput::Elements(DIRS as u64));
    for bands in [3usize, 5, 10, 20, 30] {
        let mut out = vec![0.0f32; bands * bands];
        g.bench_with_input(BenchmarkId::new("scalar", bands), &bands, |b, &n| {
            b.iter(|| {
                for d in &dirs {
                    sh::eval_into(black_box(*d), n, &mut out).unwrap();
                }
                black_box(&out);
            })
        });
        let mut cols = vec![0.0f32; bands * bands * DIRS];
        g.bench_with_input(BenchmarkId::new("simd", bands), &bands, |b, &n| {
            b.iter(|| {
                steradian_simd::sh::eval_slices(black_box(&x), &y, &z, n, &mut cols).unwrap();
                black_box(&cols);
            })
        });
        g.bench_with_input(BenchmarkId::new("plain f64", bands), &bands, |b, &n| {
            b.iter(|| {
                for d in &dirs {
                    black_box(steradian_reference::sh::eval(
                        [d.x as f64, d.y as f64, d.z as f64],
                        n,
                    ));
                }
            })
        });
    }
    g.finish();
}

criterion_group!(benches, eval);
criterion_main!(benches);
