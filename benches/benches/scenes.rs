//! Whole shading points of the built-in `cluster` scene (64 occluder spheres): the `lobes`
//! method with the quadtree mask (scalar, and its SIMD path eight points at a time) and with
//! one lobe per occluder, against one path-traced
//! sample of the same pixels (direct light) as the baseline of the same run; one thread.
//! (One sample is not equal error: the report's `scenes` section compares at equal error.)
//!
//! `cargo bench -p steradian-benches --bench scenes`

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use steradian_harness::rng::Rng;
use steradian_harness::scene::lobes::{self, Visibility};
use steradian_harness::scene::{Ray, Scene, Seen, ShadingPoint, path};

/// The shading points of a 48-column render whose centre ray meets a surface, with the rays.
fn points(scene: &Scene) -> Vec<(Ray, ShadingPoint)> {
    let cam = scene.camera;
    let mut out = Vec::new();
    for j in 0..cam.height {
        for i in 0..cam.width {
            let ray = cam.centre_ray(i, j);
            if let Seen::Surface(p) = scene.see(&ray) {
                out.push((ray, p));
            }
        }
    }
    out
}

fn scenes(c: &mut Criterion) {
    let mut scene = Scene::load("builtin:cluster").expect("built-in scene");
    scene.camera = scene.camera.resized(48).expect("valid width");
    let pts = points(&scene);
    let mut g = c.benchmark_group("scene-cluster");
    g.throughput(Throughput::Elements(pts.len() as u64));
    for (name, vis) in [
        ("lobes-mask", lobes::Options::default().visibility),
        ("lobes-per-occluder", Visibility::PerOccluder),
    ] {
        let o = lobes::Options {
            visibility: vis,
            ..Default::default()
        };
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut counts = Default::default();
                for (_, p) in &pts {
                    black_box(lobes::shade(&scene, black_box(p), &o, &mut counts));
                }
            })
        });
    }
    // The SIMD path of `steradian render`: eight points per `shade_x8`.
    let batch: Vec<ShadingPoint> = pts.iter().map(|(_, p)| *p).collect();
    let o = lobes::Options::default();
    g.bench_function("lobes-mask-simd", |b| {
        let mut out = [[0.0; 3]; 8];
        b.iter(|| {
            let mut counts = Default::default();
            for ps in batch.chunks(8) {
                let out = &mut out[..ps.len()];
                lobes::shade_x8(&scene, black_box(ps), &o, &mut counts, out);
                black_box(&*out);
            }
        })
    });
    g.bench_function("path-1-sample", |b| {
        let mut rng = Rng::new(1);
        b.iter(|| {
            for (ray, _) in &pts {
                black_box(path::radiance(&scene, *ray, 0, &mut rng));
            }
        })
    });
    g.finish();
}

criterion_group!(benches, scenes);
criterion_main!(benches);
