//! Summed-area tables against the peers on the same data: a 1024² grid of `u8` values
//! (imageproc's `integral_image` takes only `u8` images; the same values as `f32` for ours
//! and the `summed-area` crate). Build, and integer-corner box queries (all the peers
//! offer); ours also with fractional corners, scalar and SIMD. Before timing, the error of
//! each on random integer boxes and on the 16×16 box next to the far corner is printed
//! (exact reference: `u64` sums).
//!
//! `cargo bench -p steradian-benches --bench sat`

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use imageproc::image::{GrayImage, Luma};
use imageproc::integral_image::{integral_image, sum_image_pixels};
use steradian_core::rsl::sat::Sat;
use steradian_harness::rng::Rng;
use summed_area::SummedArea;

const N: usize = 1024;
const Q: usize = 1 << 12;

struct Data {
    bytes: Vec<u8>,
    texels: Vec<f32>,
    image: GrayImage,
    /// Integer boxes `[x0, y0, x1, y1)` (half-open, x1 > x0, y1 > y0).
    boxes: Vec<[usize; 4]>,
    /// Fractional boxes.
    frac: Vec<[f32; 4]>,
}

fn data() -> Data {
    let mut rng = Rng::new(0x5a7);
    let bytes: Vec<u8> = (0..N * N).map(|_| rng.next_u64() as u8).collect();
    let texels = bytes.iter().map(|&b| b as f32).collect();
    let image = GrayImage::from_raw(N as u32, N as u32, bytes.clone()).expect("image");
    let mut boxes: Vec<[usize; 4]> = (0..Q)
        .map(|_| {
            let w = 1 + (rng.next_u64() % 64) as usize;
            let h = 1 + (rng.next_u64() % 64) as usize;
            let x = (rng.next_u64() % (N - w + 1) as u64) as usize;
            let y = (rng.next_u64() % (N - h + 1) as u64) as usize;
            [x, y, x + w, y + h]
        })
        .collect();
    boxes[0] = [N - 17, N - 17, N - 1, N - 1];
    let frac = boxes
        .iter()
        .map(|b| {
            let j = rng.unit() as f32;
            [
                b[0] as f32 + 0.5 * j,
                b[1] as f32 + 0.25,
                b[2] as f32 - 0.5,
                b[3] as f32 - 0.125 * j,
            ]
        })
        .collect();
    Data {
        bytes,
        texels,
        image,
        boxes,
        frac,
    }
}

fn exact(d: &Data, b: [usize; 4]) -> u64 {
    let mut s = 0u64;
    for y in b[1]..b[3] {
        for x in b[0]..b[2] {
            s += d.bytes[y * N + x] as u64;
        }
    }
    s
}

fn print_errors(d: &Data) {
    let ours = Sat::build(N, N, &d.texels).expect("sat");
    let sa32 = SummedArea::<f32>::new_slice::<f32>(&d.texels, N);
    let ip32 = integral_image::<Luma<u8>, f32>(&d.image);
    let mut worst = [0f64; 3];
    let mut far = [0f64; 3];
    for (k, &b) in d.boxes.iter().enumerate() {
        let e = exact(d, b) as f64;
        let got = [
            ours.box_sum(b[0] as f32, b[1] as f32, b[2] as f32, b[3] as f32) as f64,
            sa32.sum_rect(b[0], b[1], b[2] - b[0], b[3] - b[1]) as f64,
            sum_image_pixels(
                &ip32,
                b[0] as u32,
                b[1] as u32,
                b[2] as u32 - 1,
                b[3] as u32 - 1,
            )[0] as f64,
        ];
        for i in 0..3 {
            worst[i] = worst[i].max((got[i] - e).abs());
            if k == 0 {
                far[i] = (got[i] - e).abs();
            }
        }
    }
    eprintln!(
        "SAT 1024² u8 data, {Q} integer boxes: max |error| ours {:.3e}, summed-area f32 {:.3e}, imageproc f32 {:.3e}; far 16×16 box: {:.3e}, {:.3e}, {:.3e}",
        worst[0], worst[1], worst[2], far[0], far[1], far[2]
    );
}

fn sat(c: &mut Criterion) {
    let d = data();
    print_errors(&d);

    let mut g = c.benchmark_group("sat-build-1024");
    g.throughput(Throughput::Elements((N * N) as u64));
    g.sample_size(20);
    g.bench_function("steradian i64", |b| {
        b.iter(|| Sat::build(N, N, black_box(&d.texels)).expect("sat"))
    });
    g.bench_function("summed-area f32", |b| {
        b.iter(|| SummedArea::<f32>::new_slice::<f32>(black_box(&d.texels), N))
    });
    g.bench_function("summed-area f64", |b| {
        b.iter(|| SummedArea::<f64>::new_slice::<f32>(black_box(&d.texels), N))
    });
    g.bench_function("imageproc f32", |b| {
        b.iter(|| integral_image::<Luma<u8>, f32>(black_box(&d.image)))
    });
    g.finish();

    let ours = Sat::build(N, N, &d.texels).expect("sat");
    let view = ours.view();
    let sa32 = SummedArea::<f32>::new_slice::<f32>(&d.texels, N);
    let sa64 = SummedArea::<f64>::new_slice::<f32>(&d.texels, N);
    let ip32 = integral_image::<Luma<u8>, f32>(&d.image);
    let mut out = vec![0f32; Q];

    let mut g = c.benchmark_group("sat-query-1024");
    g.throughput(Throughput::Elements(Q as u64));
    g.bench_function("steradian integer corners", |b| {
        b.iter(|| {
            for (o, q) in out.iter_mut().zip(&d.boxes) {
                *o = view.box_sum(q[0] as f32, q[1] as f32, q[2] as f32, q[3] as f32);
            }
            black_box(&out);
        })
    });
    g.bench_function("steradian integer cells", |b| {
        b.iter(|| {
            for (o, q) in out.iter_mut().zip(&d.boxes) {
                *o = view.box_sum_cells(q[0], q[1], q[2], q[3]);
            }
            black_box(&out);
        })
    });
    let icols: [Vec<f32>; 4] =
        std::array::from_fn(|c| d.boxes.iter().map(|q| q[c] as f32).collect());
    g.bench_function("steradian integer corners SIMD", |b| {
        b.iter(|| {
            steradian_simd::rsl::sat::box_sum_slices(
                &view, &icols[0], &icols[1], &icols[2], &icols[3], &mut out,
            );
            black_box(&out);
        })
    });
    g.bench_function("summed-area f32", |b| {
        b.iter(|| {
            for (o, q) in out.iter_mut().zip(&d.boxes) {
                *o = sa32.sum_rect(q[0], q[1], q[2] - q[0], q[3] - q[1]);
            }
            black_box(&out);
        })
    });
    g.bench_function("summed-area f64", |b| {
        b.iter(|| {
            for (o, q) in out.iter_mut().zip(&d.boxes) {
                *o = sa64.sum_rect(q[0], q[1], q[2] - q[0], q[3] - q[1]) as f32;
            }
            black_box(&out);
        })
    });
    g.bench_function("imageproc f32", |b| {
        b.iter(|| {
            for (o, q) in out.iter_mut().zip(&d.boxes) {
                *o = sum_image_pixels(
                    &ip32,
                    q[0] as u32,
                    q[1] as u32,
                    q[2] as u32 - 1,
                    q[3] as u32 - 1,
                )[0];
            }
            black_box(&out);
        })
    });
    g.bench_function("steradian fractional scalar", |b| {
        b.iter(|| {
            for (o, q) in out.iter_mut().zip(&d.frac) {
                *o = view.box_sum(q[0], q[1], q[2], q[3]);
            }
            black_box(&out);
        })
    });
    let cols: [Vec<f32>; 4] = std::array::from_fn(|c| d.frac.iter().map(|q| q[c]).collect());
    g.bench_function("steradian fractional SIMD", |b| {
        b.iter(|| {
            steradian_simd::rsl::sat::box_sum_slices(
                &view, &cols[0], &cols[1], &cols[2], &cols[3], &mut out,
            );
            black_box(&out);
        })
    });
    g.finish();
}

criterion_group!(benches, sat);
criterion_main!(benches);
