//! Real SH evaluation, directions per second at 3, 5, 10, 20 and 30 bands: the scalar
//! kernel (`steradian_core::sh::eval_into`), its SIMD twin (`steradian_simd::sh::eval_slices`,
//! bit-identical) and, as the baseline of the same run, a plain `f64` evaluation (the
//! reference's factorial normalisation, unnormalised Legendre recurrence and `cos(mφ)`).
//!
//! Also rotation per vector (ZXZXZ, the built operator's application and build) at 3, 5, 10
//! and 30 bands, and one HVL contribution and one cap projection at 3, 5 and 9 bands.
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
        // Each direction's output 64 bytes after the last one's (64 positions in one
        // buffer): over a pass the output takes every alignment modulo 4 KiB, so the time
        // does not depend on whether it happens to alias the stack (as `steradian report`).
        let nn = bands * bands;
        let mut out = vec![0.0f32; nn + 16 * 64];
        g.bench_with_input(BenchmarkId::new("scalar", bands), &bands, |b, &n| {
            b.iter(|| {
                for (i, d) in dirs.iter().enumerate() {
                    let at = i % 64 * 16;
                    sh::eval_into(black_box(*d), n, &mut out[at..at + nn]).unwrap();
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

/// Rotation per vector: the ZXZXZ path (scalar and SIMD) and the built operator's
/// application, at 3, 5, 10 and 30 bands, and the operator's build (what a batch sharing one
/// rotation pays once).
fn rotation(c: &mut Criterion) {
    use steradian_core::sh::rotate::{Operator, Rotation, Rotator};
    let rot = Rotation::from_axis_angle(Vec3::new(0.3, -0.5, 0.8), 1.1).unwrap();
    let mut g = c.benchmark_group("sh-rotate");
    for bands in [3usize, 5, 10, 30] {
        let input: Vec<f32> = (0..bands * bands)
            .map(|i| ((i * 7919) % 13) as f32 - 6.0)
            .collect();
        let mut out = vec![0.0f32; bands * bands];
        let rz = Rotator::new(bands).unwrap();
        g.throughput(Throughput::Elements(1));
        g.bench_with_input(BenchmarkId::new("zxzxz", bands), &bands, |b, _| {
            b.iter(|| rz.rotate(&rot, black_box(&input), &mut out).unwrap())
        });
        // The SIMD twin on 64 vectors, each with its rotation (throughput per vector).
        let many: Vec<f32> = (0..64).flat_map(|_| input.iter().copied()).collect();
        let mut many_out = vec![0.0f32; many.len()];
        let rots = vec![rot; 64];
        g.throughput(Throughput::Elements(64));
        g.bench_with_input(BenchmarkId::new("zxzxz simd", bands), &bands, |b, &n| {
            b.iter(|| {
                steradian_simd::sh::rotate::rotate_zxzxz_slices(
                    rz.table(),
                    &rots,
                    n,
                    black_box(&many),
                    &mut many_out,
                )
                .unwrap()
            })
        });
        g.throughput(Throughput::Elements(1));
        let op = Operator::new(&rot, bands).unwrap();
        g.bench_with_input(BenchmarkId::new("operator apply", bands), &bands, |b, _| {
            b.iter(|| op.apply(black_box(&input), &mut out).unwrap())
        });
        g.bench_with_input(
            BenchmarkId::new("operator build", bands),
            &bands,
            |b, &n| b.iter(|| black_box(Operator::new(&rot, n).unwrap())),
        );
    }
    g.finish();
}

/// One HVL's contribution (cap projection, rotation into the receiver's frame by
/// evaluation, two dot products) at 3, 5 and 9 bands, and the cap projection alone.
fn hvl(c: &mut Criterion) {
    use steradian_core::sh::{brdf, cap, hvl};
    let table = brdf::phong();
    let h = hvl::Hvl::new(
        Vec3::new(-0.6, 0.1, 0.8),
        -Vec3::Z,
        Vec3::new(0.3, 0.0, -1.0),
        0.15,
        2.0,
    )
    .unwrap();
    let em = hvl::lambert_emission(0.8);
    let wo = Vec3::new(0.6, 0.0, 0.8);
    let frame = brdf::view_frame(Vec3::Z, wo).unwrap();
    let mut g = c.benchmark_group("sh-hvl");
    g.throughput(Throughput::Elements(1));
    for bands in [3usize, 5, 9] {
        let mut coeffs = vec![0.0f32; bands * bands];
        table
            .lookup_into(brdf::Part::WithCosine, 0.64, bands, &mut coeffs)
            .unwrap();
        let rx = hvl::Receiver {
            point: Vec3::ZERO,
            frame,
            coeffs: &coeffs,
        };
        let mut scratch = vec![0.0f32; bands * bands];
        g.bench_with_input(BenchmarkId::new("contribution", bands), &bands, |b, _| {
            b.iter(|| {
                hvl::contribution(
                    black_box(&h),
                    &em,
                    &rx,
                    hvl::Horizon::Smoothstep,
                    &mut scratch,
                )
                .unwrap()
            })
        });
        g.bench_with_input(
            BenchmarkId::new("cap projection", bands),
            &bands,
            |b, &n| {
                b.iter(|| {
                    cap::coefficients_into(
                        black_box(Vec3::new(0.3, 0.2, 0.9)),
                        0.2,
                        n,
                        &mut scratch,
                    )
                    .unwrap()
                })
            },
        );
    }
    // A Lambertian receiver (zonal coefficients) summing 64 HVLs around it: the scalar
    // `contribution_zonal` one at a time against the SIMD `contributions_zonal`.
    let mut rng = 0x9e37_79b9_u32;
    let mut u = move || {
        rng ^= rng << 13;
        rng ^= rng >> 17;
        rng ^= rng << 5;
        rng as f32 / u32::MAX as f32
    };
    let hvls: Vec<hvl::Hvl> = (0..64)
        .filter_map(|_| {
            let p = Vec3::new(4.0 * u() - 2.0, 4.0 * u() - 2.0, 0.2 + 2.0 * u());
            let n = Vec3::new(u() - 0.5, u() - 0.5, -1.0).normalize();
            hvl::Hvl::new(p, n, Vec3::Z, 0.05 + 0.2 * u(), 1.0).ok()
        })
        .collect();
    g.throughput(Throughput::Elements(hvls.len() as u64));
    for bands in [3usize, 5] {
        let zonal: Vec<f32> = (0..bands).map(|l| 1.0 / (1.0 + l as f32)).collect();
        let zrx = hvl::ZonalReceiver {
            point: Vec3::ZERO,
            frame,
            coeffs: &zonal,
        };
        let mut scratch = vec![0.0f32; bands];
        let mut out = vec![0.0f32; hvls.len()];
        g.bench_with_input(
            BenchmarkId::new("zonal-64/scalar", bands),
            &bands,
            |b, _| {
                b.iter(|| {
                    for (h, o) in hvls.iter().zip(out.iter_mut()) {
                        *o = hvl::contribution_zonal(
                            black_box(h),
                            &em,
                            &zrx,
                            hvl::Horizon::Smoothstep,
                            &mut scratch,
                        )
                        .unwrap();
                    }
                    black_box(&out);
                })
            },
        );
        g.bench_with_input(BenchmarkId::new("zonal-64/simd", bands), &bands, |b, _| {
            b.iter(|| {
                steradian_simd::sh::hvl::contributions_zonal(
                    black_box(&hvls),
                    &em,
                    &zrx,
                    hvl::Horizon::Smoothstep,
                    &mut scratch,
                    &mut out,
                )
                .unwrap();
                black_box(&out);
            })
        });
    }
    g.finish();
}

criterion_group!(benches, eval, rotation, hvl);
criterion_main!(benches);
