//! The WGSL moments kernel (`wgsl::SHADE_MOMENTS`) against the scalar one
//! (`shade::shade_moments`), lane by lane and channel by channel: the standard scene
//! (g = 8) plus a grazing view and points whose normals lie near the horizon (so that
//! light squares straddle it), the default sky decomposed into K = 30 RSLs with their
//! radiance gradients, a Lambert and a glossy Phong BRDF SAT, and 256² coverage-map moment
//! tables (the accuracy tests' resolution: 1.6 MB per point, so the batch is split into
//! several dispatches to keep each table under 128 MiB).
//!
//! Run as CI does: `cargo test --release -p steradian-harness --test shade_moments_gpu`
//! (`STERADIAN_REQUIRE_GPU=1` makes a missing adapter a failure).

#![allow(clippy::needless_range_loop)] // RGB channels are indexed in parallel arrays

use std::time::Instant;

use glam::{DVec3, Vec3};
use steradian_core::frame::Frame;
use steradian_core::lobe::brdf::{Brdf, Lambert, Phong};
use steradian_core::rsl::shade::ShadeLight;
use steradian_core::rsl::vis_moments::VisMoments;
use steradian_core::wgsl::SHADE_MOMENTS_REL_TOL;
use steradian_harness::env::decompose::{Decomposition, Options, decompose};
use steradian_harness::env::{self};
use steradian_harness::shade::{self as sh, Scene, ShadePoint};

use crate::common::gpu as gpu_common;
use gpu_common::{gpu, say};

/// Side of the coverage maps (as the accuracy tests of `tests/shade.rs`).
const VIS_N: usize = 256;

/// A point at `pos` with normal `n`, seen from `eye`, occluded by `occ`.
fn point(pos: DVec3, n: DVec3, wo: DVec3, occ: Vec<usize>) -> ShadePoint {
    let t = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    ShadePoint {
        pos,
        frame: Frame::from_normal_tangent(n.as_vec3(), t.as_vec3()).unwrap(),
        wo: wo.normalize().as_vec3(),
        occluders: occ,
    }
}

/// The standard scene with extra hard cases: grazing views on the ground next to the
/// spheres, and points on sphere 0 whose normals are within a few degrees of horizontal
/// (the ground and half the sky cross their horizon).
fn scene() -> Scene {
    let mut s = Scene::standard(8);
    let s0 = s.spheres[0];
    for (pos, wo) in [
        (DVec3::new(0.6, 0.2, 0.0), DVec3::new(1.0, 0.3, 0.02)),
        (DVec3::new(-0.3, -0.7, 0.0), DVec3::new(-0.2, 1.0, 0.05)),
        (DVec3::new(1.2, -1.1, 0.0), DVec3::new(-1.0, 0.0, 0.01)),
    ] {
        s.points.push(point(pos, DVec3::Z, wo, vec![0, 1, 2]));
    }
    for (az, el) in [(0.3f64, 0.05f64), (2.0, 0.1), (-1.2, 0.02), (3.5, 0.3)] {
        let n = DVec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
        let pos = s0.centre + n * s0.radius;
        // a view tilted off the normal towards the sky, and one grazing the surface
        let up = (DVec3::Z - n * n.z).normalize();
        s.points.push(point(pos, n, n + 0.8 * up, vec![1, 2]));
        s.points.push(point(pos, n, 0.03 * n + up, vec![1, 2]));
    }
    s
}

struct Coverage {
    gradient_lights: usize,
    straddling: usize,
    grazing: usize,
}

/// What the scene exercises: lights with a non-zero gradient above a point's horizon,
/// squares that cross it, and grazing views (cosine below 0.1).
fn coverage(scene: &Scene, lights: &[ShadeLight]) -> Coverage {
    let mut c = Coverage {
        gradient_lights: 0,
        straddling: 0,
        grazing: 0,
    };
    for p in &scene.points {
        if p.frame.to_local(p.wo).z < 0.1 {
            c.grazing += 1;
        }
        for l in lights {
            let Some((centre, r)) = l.square_above_horizon(&p.frame) else {
                continue;
            };
            if l.gradient() != [Vec3::ZERO; 3] {
                c.gradient_lights += 1;
            }
            if centre.length() + r > 1.0 {
                c.straddling += 1;
            }
        }
    }
    c
}

#[test]
fn gpu_moments_kernel_matches_scalar_lane_by_lane() {
    let Some(mut g) = gpu() else { return };
    let t0 = Instant::now();
    let cube = env::default_sky(16).unwrap();
    let decs = decompose(&cube, &Options::quiet(&[30])).unwrap();
    let lights: Vec<ShadeLight> = decs[0]
        .rsls()
        .unwrap()
        .iter()
        .map(ShadeLight::from)
        .collect();
    let scene = scene();
    let moments: Vec<VisMoments> =
        sh::par_map(&scene.points, |p| sh::point_moments(&scene, p, VIS_N));
    let cov = coverage(&scene, &lights);
    say(&format!(
        "{} points, {} lights; {} light-point pairs with a radiance gradient, {} squares \
         across the horizon, {} grazing views; setup {:?}",
        scene.points.len(),
        lights.len(),
        cov.gradient_lights,
        cov.straddling,
        cov.grazing,
        t0.elapsed()
    ));
    assert!(cov.gradient_lights > 100 && cov.straddling > 100 && cov.grazing >= 5);
    let per_point = moments[0].bytes() + 3 * 4;
    assert!(
        per_point * moments.len() > sh::GPU_MOMENTS_MAX_TABLE_BYTES,
        "the batch should need several dispatches"
    );
    let refs: Vec<&Decomposition> = decs.iter().collect();
    let mut worst_all = 0.0f32;
    for glossy in [false, true] {
        let brdf: Box<dyn Brdf> = if glossy {
            Box::new(Phong::new(0.3, 0.5, 30.0).unwrap())
        } else {
            Box::new(Lambert::new(0.8).unwrap())
        };
        let sat = sh::fit_sat(brdf.as_ref(), &refs, 0.02);
        let t = Instant::now();
        let gpu_out = sh::shade_points_moments_gpu(
            &mut g,
            &scene,
            &sat,
            &moments,
            &lights,
            sh::GPU_MOMENTS_MAX_TABLE_BYTES,
        )
        .expect("moments kernel runs");
        let t_gpu = t.elapsed();
        let scalar = sh::shade_points_moments(&scene, &sat, &moments, &lights);
        let (mut worst, mut at) = (0.0f32, 0);
        for (p, (a, b)) in scalar.iter().zip(&gpu_out).enumerate() {
            let m = a.iter().fold(0.0f32, |m, x| m.max(x.abs())).max(1e-30);
            assert!(m > 1e-30, "point {p}: scalar result {a:?} is 0");
            for c in 0..3 {
                let d = (a[c] - b[c]).abs() / m;
                if d > worst {
                    (worst, at) = (d, p);
                }
                assert!(
                    d <= SHADE_MOMENTS_REL_TOL,
                    "glossy {glossy} point {p} channel {c}: scalar {a:?} gpu {b:?} \
                     (relative difference {d:.2e})"
                );
            }
        }
        worst_all = worst_all.max(worst);
        say(&format!(
            "moments kernel GPU vs scalar (glossy {glossy}): largest relative difference \
             {worst:.2e} (point {at}), GPU run {t_gpu:?}"
        ));
    }
    say(&format!(
        "moments kernel GPU vs scalar: largest relative difference {worst_all:.2e}, \
         tolerance {SHADE_MOMENTS_REL_TOL:.1e}"
    ));
}
