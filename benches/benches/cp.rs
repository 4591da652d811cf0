//! Control-point queries, directions per second at levels 0, 2 and 4: the scalar kernel
//! (`Icosphere::query`, area and gnomonic weights), its SIMD twin
//! (`steradian_simd::cp::query_slices`) and, as the baseline of the same run, the brute-force
//! scan of every triangle (`steradian_harness::cp::BruteForce`). Also the least-squares fit
//! at level 3: locating and factoring 10 000 samples, and one fit of their values.
//!
//! `cargo bench -p steradian-benches --bench cp`

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use steradian_core::Vec3;
use steradian_core::cp::{Icosphere, Weights};
use steradian_harness::cp::{BruteForce, LeastSquares};
use steradian_harness::rng::Rng;

const DIRS: usize = 1024;

fn directions(n: usize, rng: &mut Rng) -> Vec<Vec3> {
    (0..n)
        .map(|_| {
            let d = rng.sphere();
            Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)
        })
        .collect()
}

fn query(c: &mut Criterion) {
    let mut rng = Rng::new(0x0c90);
    let dirs = directions(DIRS, &mut rng);
    let (x, y, z): (Vec<f32>, Vec<f32>, Vec<f32>) = (
        dirs.iter().map(|d| d.x).collect(),
        dirs.iter().map(|d| d.y).collect(),
        dirs.iter().map(|d| d.z).collect(),
    );
    let mut g = c.benchmark_group("cp-query");
    g.throughput(Throughput::Elements(DIRS as u64));
    for level in [0u32, 2, 4] {
        let mesh = Icosphere::new(level).unwrap();
        let values: Vec<f32> = (0..mesh.vertices().len())
            .map(|_| rng.unit() as f32)
            .collect();
        let mut out = vec![0.0f32; DIRS];
        for (name, w) in [("area", Weights::Area), ("gnomonic", Weights::Gnomonic)] {
            g.bench_with_input(
                BenchmarkId::new(format!("scalar {name}"), level),
                &w,
                |b, &w| {
                    b.iter(|| {
                        for (o, d) in out.iter_mut().zip(&dirs) {
                            *o = mesh.query(&values, black_box(*d), w).unwrap();
                        }
                        black_box(&out);
                    })
                },
            );
            g.bench_with_input(
                BenchmarkId::new(format!("simd {name}"), level),
                &w,
                |b, &w| {
                    b.iter(|| {
                        steradian_simd::cp::query_slices(
                            &mesh,
                            &values,
                            w,
                            black_box(&x),
                            &y,
                            &z,
                            &mut out,
                        )
                        .unwrap();
                        black_box(&out);
                    })
                },
            );
        }
        let brute = BruteForce::new(&mesh);
        g.bench_with_input(BenchmarkId::new("brute force", level), &level, |b, _| {
            b.iter(|| {
                for (o, d) in out.iter_mut().zip(&dirs) {
                    *o = brute.query(&values, black_box(*d));
                }
                black_box(&out);
            })
        });
    }
    g.finish();
}

fn fit(c: &mut Criterion) {
    let mut rng = Rng::new(0x0f17);
    let mesh = Icosphere::new(3).unwrap();
    let dirs = directions(10_000, &mut rng);
    let values: Vec<f64> = dirs.iter().map(|d| f64::from(d.x * d.y + d.z)).collect();
    let mut g = c.benchmark_group("cp-fit");
    g.sample_size(20);
    g.bench_function("locate and factor, level 3, 10k samples", |b| {
        b.iter(|| black_box(LeastSquares::new(&mesh, black_box(&dirs)).unwrap()))
    });
    let ls = LeastSquares::new(&mesh, &dirs).unwrap();
    g.bench_function("one fit, level 3, 10k samples", |b| {
        b.iter(|| black_box(ls.fit(black_box(&values)).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, query, fit);
criterion_main!(benches);
