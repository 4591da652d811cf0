//! Visibility distance tables: the exact signed distance transform against imageproc's
//! `euclidean_squared_distance_transform` on the same 512² map (a visibility map of three
//! sphere occluders), and query throughput: eq. 9 + gradient variant per query, scalar and
//! SIMD, next to the 4-lookup summed-area-table query of the same map.
//!
//! `cargo bench -p steradian-benches --bench vdt`
//!
//! imageproc computes an *unsigned* squared distance from every pixel to the nearest
//! foreground pixel centre (one class); a signed field needs it twice (once per class),
//! which the `imageproc x2 (signed)` row measures. Ours is signed, to the texel-edge
//! boundary, exact, in one pass.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use imageproc::distance_transform::euclidean_squared_distance_transform;
use imageproc::image::{GrayImage, Luma};
use steradian_core::Vec2;
use steradian_core::rsl::sat::Sat;
use steradian_core::rsl::vdt::{Vdt, scratch_len, signed_distance_into};
use steradian_harness::rng::Rng;
use steradian_harness::vdt::spheres_mask;

const N: usize = 512;
const Q: usize = 1 << 16;

fn edt(c: &mut Criterion) {
    let m = spheres_mask(N);
    // Foreground (255) where the map is `class`: imageproc's distances are to it.
    let image = |class: bool| {
        GrayImage::from_fn(N as u32, N as u32, |x, y| {
            Luma([if m[y as usize * N + x as usize] == class {
                255
            } else {
                0
            }])
        })
    };
    let (occluded, visible) = (image(false), image(true));
    let mut out = vec![0.0f32; N * N];
    let mut scratch = vec![0.0f64; scratch_len(N, N)];
    let mut g = c.benchmark_group("edt-512");
    g.throughput(Throughput::Elements((N * N) as u64));
    g.sample_size(20);
    g.bench_function("steradian signed exact", |b| {
        b.iter(|| signed_distance_into(N, N, black_box(&m), &mut out, &mut scratch).unwrap())
    });
    g.bench_function("imageproc x1 (unsigned)", |b| {
        b.iter(|| euclidean_squared_distance_transform(black_box(&occluded)))
    });
    g.bench_function("imageproc x2 (signed)", |b| {
        b.iter(|| {
            (
                euclidean_squared_distance_transform(black_box(&occluded)),
                euclidean_squared_distance_transform(black_box(&visible)),
            )
        })
    });
    g.finish();
}

fn queries(c: &mut Criterion) {
    let m = spheres_mask(N);
    let vdt = Vdt::build(N, N, &m).unwrap();
    let view = vdt.view();
    let texels: Vec<f32> = m.iter().map(|&b| b as u8 as f32).collect();
    let sat = Sat::build(N, N, &texels).unwrap();
    let mut rng = Rng::new(5);
    let u: Vec<f32> = (0..Q).map(|_| rng.range(0.0, N as f64) as f32).collect();
    let v: Vec<f32> = (0..Q).map(|_| rng.range(0.0, N as f64) as f32).collect();
    let r: Vec<f32> = (0..Q).map(|_| rng.log_range(1.0, 32.0) as f32).collect();
    let mut e9 = vec![0.0f32; Q];
    let mut gr = vec![0.0f32; Q];
    let mut g = c.benchmark_group("vdt-query");
    g.throughput(Throughput::Elements(Q as u64));
    g.bench_function("scalar", |b| {
        b.iter(|| {
            for k in 0..Q {
                let (a, bb) = view.query(u[k], v[k], r[k]);
                e9[k] = a;
                gr[k] = bb;
            }
            black_box(&e9);
        })
    });
    g.bench_function("simd", |b| {
        b.iter(|| {
            steradian_simd::rsl::vdt::query_slices(&view, &u, &v, &r, &mut e9, &mut gr);
            black_box(&e9);
        })
    });
    g.bench_function("sat square (4 lookups)", |b| {
        b.iter(|| {
            for k in 0..Q {
                e9[k] = sat.square(Vec2::new(u[k], v[k]), r[k]);
            }
            black_box(&e9);
        })
    });
    g.finish();
}

criterion_group!(benches, edt, queries);
criterion_main!(benches);
