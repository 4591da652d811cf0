//! RSL shading (`steradian_core::rsl::shade`): scalar vs SIMD (8 points per call) over the same
//! points × K lights, for a diffuse and a glossy BRDF SAT, and the scalar moments kernel
//! (`shade_moments`: linear BRDF, linear light, visibility moments) and its SIMD twin beside
//! them, and the pair kernels of the `rsl` method's shadow ratio (`shade_moments_pair`: the
//! same pass with a second visibility, here the point's own tables) to read their cost
//! against the single kernels. Throughput is in RSL evaluations (points × K) per second.
//!
//! `cargo bench -p steradian-benches --bench shade`

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use steradian_core::lobe::brdf::{Brdf, Lambert, Phong};
use steradian_core::rsl::shade::{self, ShadeLight, VdtQuery, VdtVisibility};
use steradian_harness::env::{self, decompose};
use steradian_harness::shade::{self as sh, Scene};
use steradian_simd::rsl::shade::{
    IsoBrdfTables, MomentsInput, shade_batch, shade_moments_batch, shade_moments_pair_batch,
};

fn bench(c: &mut Criterion) {
    let cube = env::default_sky(32).unwrap();
    let ks = [10usize, 30, 100];
    let decs = decompose::decompose(&cube, &decompose::Options::quiet(&ks)).unwrap();
    let scene = Scene::standard(12);
    let vdts = sh::par_map(&scene.points, |p| sh::point_vdt(&scene, p, 128));
    let moments = sh::par_map(&scene.points, |p| sh::point_moments(&scene, p, 128));
    let materials: [(&str, Box<dyn Brdf>); 2] = [
        ("lambert", Box::new(Lambert::new(0.8).unwrap())),
        ("phong30", Box::new(Phong::new(0.3, 0.5, 30.0).unwrap())),
    ];
    let mut g = c.benchmark_group("shade");
    g.sample_size(10);
    for (mname, brdf) in &materials {
        let refs: Vec<_> = decs.iter().collect();
        let sat = sh::fit_sat(brdf.as_ref(), &refs, 0.01);
        let views = sh::iso_views(&sat).unwrap();
        let tables = IsoBrdfTables {
            tables: &views,
            s_max: sat.s_max(),
        };
        let inputs = sh::simd_inputs(&scene, &vdts);
        let minputs: Vec<MomentsInput<'_>> = scene
            .points
            .iter()
            .zip(&moments)
            .map(|(p, m)| MomentsInput {
                frame: p.frame,
                wo: p.wo,
                vis: m.view(),
            })
            .collect();
        for d in &decs {
            let lights: Vec<ShadeLight> = d.rsls().unwrap().iter().map(ShadeLight::from).collect();
            g.throughput(Throughput::Elements(
                (scene.points.len() * lights.len()) as u64,
            ));
            g.bench_function(format!("{mname}/K{}/scalar", d.k), |b| {
                b.iter(|| {
                    let mut s = 0.0f32;
                    for (p, v) in scene.points.iter().zip(&vdts) {
                        let vis = VdtVisibility::new(v.view(), VdtQuery::Gradient).unwrap();
                        s += shade::shade(&p.frame, p.wo, &sat, &vis, black_box(&lights))[1];
                    }
                    s
                })
            });
            g.bench_function(format!("{mname}/K{}/moments_scalar", d.k), |b| {
                b.iter(|| {
                    let mut s = 0.0f32;
                    for (p, m) in scene.points.iter().zip(&moments) {
                        s += shade::shade_moments(&p.frame, p.wo, &sat, m, black_box(&lights))[1];
                    }
                    s
                })
            });
            g.bench_function(format!("{mname}/K{}/moments_pair_scalar", d.k), |b| {
                b.iter(|| {
                    let mut s = 0.0f32;
                    for (p, m) in scene.points.iter().zip(&moments) {
                        let (a, u) = shade::shade_moments_pair(
                            &p.frame,
                            p.wo,
                            &sat,
                            m,
                            m,
                            black_box(&lights),
                        );
                        s += a[1] + u[1];
                    }
                    s
                })
            });
            let mut out = vec![[0.0f32; 3]; inputs.len()];
            g.bench_function(format!("{mname}/K{}/moments_simd", d.k), |b| {
                b.iter(|| {
                    shade_moments_batch(&minputs, &tables, black_box(&lights), &mut out);
                    out[0][1]
                })
            });
            let base: Vec<_> = minputs.iter().map(|m| m.vis).collect();
            let mut free = vec![[0.0f32; 3]; inputs.len()];
            g.bench_function(format!("{mname}/K{}/moments_pair_simd", d.k), |b| {
                b.iter(|| {
                    shade_moments_pair_batch(
                        &minputs,
                        &tables,
                        black_box(&lights),
                        Some(&base),
                        &mut out,
                        &mut free,
                    );
                    out[0][1] + free[0][1]
                })
            });
            g.bench_function(format!("{mname}/K{}/simd", d.k), |b| {
                b.iter(|| {
                    shade_batch(
                        &inputs,
                        &tables,
                        VdtQuery::Gradient,
                        black_box(&lights),
                        &mut out,
                    );
                    out[0][1]
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
