//! Criterion benches of BRDF summed-area tables: query throughput (isotropic: two square
//! lookups and a rotation; anisotropic: four lookups), against the baseline the table
//! replaces, a 4×4 Gauss–Legendre quadrature of `ρ cos θᵢ` over the same square (16 BRDF
//! evaluations); and table build time per grid size.
//!
//! `cargo bench -p steradian-benches --bench brdf_sat`

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use steradian_core::lobe::brdf::{Brdf, Phong, Ward};
use steradian_core::rsl::brdf_sat::{BrdfSat, Resolution};
use steradian_harness::report::brdf::{Query, gl4_square, queries};

const N: usize = 4096;

fn run_table(t: &BrdfSat, q: &[Query]) -> f32 {
    q.iter().map(|q| t.integral(q.wo, q.centre, q.r)).sum()
}

fn run_quadrature(b: &dyn Brdf, q: &[Query]) -> f32 {
    q.iter()
        .map(|q| gl4_square(b, q.wo, q.centre, q.r, b.is_isotropic()))
        .sum()
}

fn query(c: &mut Criterion) {
    let phong = Phong::new(0.3, 0.6, 100.0).unwrap();
    let ward = Ward::anisotropic(0.3, 0.2, 0.1, 0.3).unwrap();
    let iso = BrdfSat::build(
        &phong,
        Resolution {
            grid: 128,
            polar: 17,
            azimuth: 1,
        },
        80f32.to_radians(),
    )
    .unwrap();
    let aniso = BrdfSat::build(
        &ward,
        Resolution {
            grid: 64,
            polar: 9,
            azimuth: 16,
        },
        80f32.to_radians(),
    )
    .unwrap();
    let q = queries(N, 0.05, 0.5, 80f32.to_radians(), 0xbe7c);
    let mut g = c.benchmark_group("brdf_sat_query");
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("phong_sat", |b| b.iter(|| run_table(black_box(&iso), &q)));
    g.bench_function("phong_gl4x4", |b| {
        b.iter(|| run_quadrature(black_box(&phong), &q))
    });
    g.bench_function("ward_aniso_sat", |b| {
        b.iter(|| run_table(black_box(&aniso), &q))
    });
    g.bench_function("ward_aniso_gl4x4", |b| {
        b.iter(|| run_quadrature(black_box(&ward), &q))
    });
    g.finish();
}

fn build(c: &mut Criterion) {
    let phong = Phong::new(0.3, 0.6, 100.0).unwrap();
    let mut g = c.benchmark_group("brdf_sat_build");
    g.sample_size(10);
    for grid in [32usize, 64, 128] {
        let res = Resolution {
            grid,
            polar: 8,
            azimuth: 1,
        };
        g.throughput(Throughput::Elements((grid * grid * res.polar) as u64));
        g.bench_with_input(BenchmarkId::new("phong_8_views", grid), &res, |b, res| {
            b.iter(|| BrdfSat::build(&phong, *res, 80f32.to_radians()).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, query, build);
criterion_main!(benches);
