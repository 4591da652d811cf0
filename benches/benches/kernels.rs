//! Criterion benches: every kernel on every backend over the report's default workload
//! (fixed seed, hard cases included), `Throughput::Elements`, so criterion prints
//! elements per second and the backends of one kernel sit side by side.
//!
//! `cargo bench -p steradian-benches` — set `STERADIAN_BENCH_GPU=0` to skip the wgpu rows.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use steradian_harness::backend::{self, Backend};
use steradian_harness::kernels::Columns;
use steradian_harness::{report, workload};

const N: usize = 1 << 16;

fn backends() -> Vec<Box<dyn Backend>> {
    let mut b = backend::cpu_backends();
    if std::env::var("STERADIAN_BENCH_GPU").as_deref() != Ok("0") {
        match backend::gpu::try_gpu() {
            Ok(g) => {
                eprintln!("wgpu adapter: {}", g.adapter_info());
                b.push(Box::new(g));
            }
            Err(why) => eprintln!("no wgpu rows: {why}"),
        }
    }
    b
}

fn kernels(c: &mut Criterion) {
    eprintln!("SIMD build: {}", steradian_simd::isa());
    let mut bs = backends();
    for k in steradian_harness::registry::batch_kernels() {
        let input = workload::generate(k, N, report::SEED);
        let mut out = Columns::zeros(k.output_arity(), N);
        let mut g = c.benchmark_group(k.name());
        g.throughput(Throughput::Elements(N as u64));
        for b in bs.iter_mut() {
            if b.name() == "wgpu" {
                g.sample_size(10);
            }
            g.bench_function(b.name(), |bench| {
                bench.iter(|| b.run(k, &input, &mut out).expect("backend run"))
            });
        }
        g.finish();
    }
}

criterion_group!(benches, kernels);
criterion_main!(benches);
