//! Criterion bench of the lobe product (`steradian_core::lobe::product`): the scalar kernel with
//! the built-in table, the same kernel as a batch (`steradian_simd::lobe::product::product_slices`,
//! 16 lanes on AVX-512 builds, else 8), and the spherical-Gaussian closed form with no
//! table (`ProductFit::SphericalGaussian`) both ways; also the 8-lane batch kernel
//! `product_x8` (`table/simd-x8`). Same inputs for every row: `N` pairs
//! of lobes from a fixed seed, exponents `{0}` (one in ten) or log-uniform in
//! `[1e-3, 1e5]`, angles uniform in `[0, π)`. `Throughput::Elements` counts products.
//!
//! `cargo bench -p steradian-benches --bench product`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use steradian_core::Vec3;
use steradian_core::lobe::CosineLobe;
use steradian_core::lobe::product::{ProductFit, ProductTable, product_with};
use steradian_harness::rng::Rng;
use steradian_simd::LobeX8;
use steradian_simd::lobe::product::{product_slices, product_x8};

const N: usize = 1 << 14;
const SEED: u64 = 0x10be_0001;

/// `N` pairs of lobes (see the module docs).
fn inputs() -> Vec<(CosineLobe, CosineLobe)> {
    let mut rng = Rng::new(SEED);
    let exponent = |rng: &mut Rng| {
        if rng.next_u64().is_multiple_of(10) {
            0.0
        } else {
            rng.log_range(1e-3, 1e5) as f32
        }
    };
    (0..N)
        .map(|_| {
            let a1 = Vec3::from(rng.sphere().map(|x| x as f32)).normalize();
            let t = a1.any_orthonormal_vector();
            let alpha = rng.range(0.0, std::f64::consts::PI) as f32;
            let a2 = (a1 * alpha.cos() + t * alpha.sin()).normalize();
            let (e1, e2) = (exponent(&mut rng), exponent(&mut rng));
            let (s1, s2) = (rng.range(0.1, 2.0) as f32, rng.range(0.1, 2.0) as f32);
            (
                CosineLobe::new(a1, s1, e1).unwrap(),
                CosineLobe::new(a2, s2, e2).unwrap(),
            )
        })
        .collect()
}

/// The structure-of-arrays columns of one side: `[ax, ay, az, s, e]`.
fn columns(l: impl Iterator<Item = CosineLobe>) -> [Vec<f32>; 5] {
    let mut c: [Vec<f32>; 5] = Default::default();
    for l in l {
        let a = l.axis();
        for (col, v) in c.iter_mut().zip([a.x, a.y, a.z, l.scale(), l.exponent()]) {
            col.push(v);
        }
    }
    c
}

fn product(c: &mut Criterion) {
    eprintln!(
        "SIMD build: {} ({} lanes in the slice functions)",
        steradian_simd::isa(),
        steradian_simd::slice_lanes()
    );
    let table = ProductTable::builtin();
    let pairs = inputs();
    let a = columns(pairs.iter().map(|p| p.0));
    let b = columns(pairs.iter().map(|p| p.1));
    let mut out: Vec<CosineLobe> = pairs.iter().map(|p| p.0).collect();
    let mut o: [Vec<f32>; 5] = core::array::from_fn(|_| vec![0.0; N]);

    let mut g = c.benchmark_group("lobe-product");
    g.throughput(Throughput::Elements(N as u64));
    for (name, fit) in [
        ("table", ProductFit::ExactIntegral),
        ("sg-closed-form", ProductFit::SphericalGaussian),
    ] {
        g.bench_function(format!("{name}/scalar"), |bench| {
            bench.iter(|| {
                for (r, (x, y)) in out.iter_mut().zip(&pairs) {
                    *r = product_with(&table, fit, black_box(x), black_box(y));
                }
            })
        });
        g.bench_function(format!("{name}/simd"), |bench| {
            bench.iter(|| {
                let [ox, oy, oz, os, oe] = &mut o;
                product_slices(
                    &table,
                    fit,
                    [&a[0], &a[1], &a[2]],
                    &a[3],
                    black_box(&a[4]),
                    [&b[0], &b[1], &b[2]],
                    &b[3],
                    black_box(&b[4]),
                    [ox, oy, oz],
                    os,
                    oe,
                );
            })
        });
    }
    // The 8-lane batch kernel, one `LobeX8` pair at a time.
    let batches: Vec<(LobeX8, LobeX8)> = pairs
        .chunks(8)
        .map(|c| {
            let (x, y): (Vec<_>, Vec<_>) = c.iter().copied().unzip();
            (LobeX8::from_slice(&x), LobeX8::from_slice(&y))
        })
        .collect();
    let mut r = vec![LobeX8::default(); batches.len()];
    g.bench_function("table/simd-x8", |bench| {
        bench.iter(|| {
            for (o, (x, y)) in r.iter_mut().zip(&batches) {
                *o = product_x8(
                    &table,
                    ProductFit::ExactIntegral,
                    black_box(x),
                    black_box(y),
                );
            }
        })
    });
    g.finish();
}

criterion_group!(benches, product);
criterion_main!(benches);
