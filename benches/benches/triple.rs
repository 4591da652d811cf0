//! Criterion bench of the lobe-sum rendering integral `∫ R·L·V`
//! (`steradian_core::lobe::sum::triple`): a Phong BRDF (cosine on the light), one spherical
//! light and 1, 4, 16, 64 occluder lobes around it, at pruning thresholds `t = 0` (every
//! product) and `t = 1e-3` of the unshadowed value (the paper's setting, section 4.3).
//! The throughput unit is one shaded point; a product kernel call is the unit of work, so
//! the number of products per point is printed beside each group.
//!
//! `cargo bench -p steradian-benches --bench triple`

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use steradian_core::Vec3;
use steradian_core::lobe::Phong;
use steradian_core::lobe::cap::{CapFit, SphericalCap};
use steradian_core::lobe::sum::{
    Cosine, LobeSum, ProductCounts, light_with_cosine, phong_reflectance, triple,
};
use steradian_harness::rng::Rng;

/// One shading point: reflectance, light (with the cosine), visibility of `k` occluders.
fn scene(k: usize, rng: &mut Rng) -> (LobeSum<2>, LobeSum<1>, LobeSum<64>) {
    let mut c = ProductCounts::default();
    let n = Vec3::Z;
    let wo = Vec3::new(0.5, 0.1, 0.86).normalize();
    let p = Phong::modified(0.3, 0.6, 200.0).unwrap();
    let r = phong_reflectance(&p, n, wo, Cosine::WithLight, &mut c);
    let mirror = steradian_core::lobe::reflect(wo, n);
    let light_axis = (mirror + Vec3::new(0.05, 0.0, 0.0)).normalize();
    let mut l = LobeSum::<1>::new();
    l.push_cap(
        &SphericalCap::new(light_axis, 0.15).unwrap(),
        4.0,
        CapFit::L2,
    );
    let l = light_with_cosine(&l, n, Cosine::WithLight, &mut c);
    let mut v = LobeSum::<64>::unoccluded();
    for _ in 0..k {
        let d = Vec3::from(rng.sphere().map(|x| x as f32));
        let axis = (light_axis + 0.3 * d).normalize();
        let cap = SphericalCap::new(axis, rng.log_range(0.005, 0.05) as f32).unwrap();
        v.push_occluder(&cap, 1.0, CapFit::L2);
    }
    (r, l, v)
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("lobe_sum_triple");
    g.throughput(Throughput::Elements(1));
    for k in [1usize, 4, 16, 64] {
        let mut rng = Rng::new(0x7219 + k as u64);
        let (r, l, v) = scene(k, &mut rng);
        let mut c0 = ProductCounts::default();
        let open = triple(&r, &l, &LobeSum::<0>::with_constant(1.0), 0.0, &mut c0);
        for (name, t) in [("t=0", 0.0f32), ("t=1e-3", 1e-3 * open)] {
            let mut counts = ProductCounts::default();
            let value = triple(&r, &l, &v, t, &mut counts);
            eprintln!(
                "{k} occluders, {name}: value {value:.5e}, {} products computed, {} dropped",
                counts.computed,
                counts.dropped()
            );
            g.bench_with_input(BenchmarkId::new(name, k), &k, |b, _| {
                b.iter(|| {
                    let mut counts = ProductCounts::default();
                    triple(
                        black_box(&r),
                        black_box(&l),
                        black_box(&v),
                        black_box(t),
                        &mut counts,
                    )
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
