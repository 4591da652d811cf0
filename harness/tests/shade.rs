//! RSL shading (core `shade`, SIMD, WGSL) against the exact rendering integral of
//! `L·ρ·V` (harness `shade` module docs): accuracy per K for the default sky and the real
//! HDR environment, the eq. 13 bound, and the SIMD and GPU kernels against the scalar one.
//!
//! Setup per environment (shared by the tests): 6 × 32² cube map, decomposition into
//! K = 10, 30, 60, 100 RSLs, Lambert (albedo 0.8) material with its BRDF SAT fitted to
//! 0.5 %, a 256² VDT per point, the standard scene with g = 12 (226 points), the
//! reference with 8 × 8 sub-texels per cube texel (the test
//! `reference_converges_with_sub_texels` measures why: 2 × 2 is 0.35–0.44 % away from the
//! converged integral, as much as the K = 30 target; 8 × 8 is within 0.06 %).

#![allow(clippy::needless_range_loop)] // RGB channels are indexed in parallel arrays

use std::sync::OnceLock;
use std::time::Instant;

use steradian_core::Vec3;
use steradian_core::lobe::brdf::{Brdf, Lambert, Phong};
use steradian_core::rsl::brdf_sat::BrdfSat;
use steradian_core::rsl::shade::{ShadeLight, VdtQuery};
use steradian_core::rsl::vdt::Vdt;
use steradian_harness::backend::gpu::Custom;
use steradian_harness::env::decompose::{Decomposition, Options, PAPER_KS, decompose};
use steradian_harness::env::{self, CubeMap};
use steradian_harness::kernels::Columns;
use steradian_harness::shade::{self as sh, Analysis, Samples, Scene, Settings, VARIANTS, Variant};

use crate::common::gpu as gpu_common;
use gpu_common::{gpu, say};

/// VDT resolution of the accuracy tests (the report measures 64, 128, 256).
const VDT_N: usize = 256;
/// Target of the K = 30 tests (the paper's Figure 9 value).
const TARGET: f64 = 0.0035;
/// Sub-texels per cube-texel side of the reference.
const SUB: usize = 8;

struct Env {
    name: &'static str,
    decs: Vec<Decomposition>,
    analysis: Analysis,
}

fn build(name: &'static str, cube: CubeMap) -> Env {
    let t0 = Instant::now();
    let mut decs = decompose(&cube, &Options::quiet(&PAPER_KS)).expect("decomposition");
    decs.reverse(); // K ascending
    let refs: Vec<&Decomposition> = decs.iter().collect();
    let brdf = Lambert::new(0.8).unwrap();
    let sat = sh::fit_sat(&brdf, &refs, 0.005);
    let scene = Scene::standard(12);
    let vdts = sh::par_map(&scene.points, |p| sh::point_vdt(&scene, p, VDT_N));
    let samples = Samples::new(&cube, SUB);
    let setup = sh::Setup {
        cube: &cube,
        samples: &samples,
        scene: &scene,
        brdf: &brdf,
        sat: &sat,
        vdts: &vdts,
    };
    let analysis = sh::analyse(&setup, &refs, Settings::default());
    say(&format!("{name}: setup and analysis in {:?}", t0.elapsed()));
    for (d, dec) in decs.iter().enumerate() {
        let mut line = format!("  {name} K = {:3}:", dec.k);
        for v in VARIANTS {
            line += &format!(" {v:?} {:.3} %", 100.0 * analysis.error(d, v));
        }
        line += &format!(" | eq. 13 bound {:.3} %", 100.0 * analysis.bound(d));
        say(&line);
    }
    Env {
        name,
        decs,
        analysis,
    }
}

fn sky() -> &'static Env {
    static E: OnceLock<Env> = OnceLock::new();
    E.get_or_init(|| build("default sky", env::default_sky(32).unwrap()))
}

fn real() -> &'static Env {
    static E: OnceLock<Env> = OnceLock::new();
    E.get_or_init(|| {
        build(
            "harness/data/sky.exr",
            env::load_cubemap(&env::real_env_path(), 32).unwrap(),
        )
    })
}

fn k_index(e: &Env, k: usize) -> usize {
    e.decs.iter().position(|d| d.k == k).expect("K decomposed")
}

/// The K = 30 target for one kernel (`Variant::Kernel`, the paper's eq. 5, or
/// `Variant::Moments`, the visibility-moments kernel).
fn check_k30(e: &Env, variant: Variant) {
    let err = e.analysis.error(k_index(e, 30), variant);
    say(&format!(
        "{}: K = 30 {variant:?} relative L2 error {:.3} %",
        e.name,
        100.0 * err
    ));
    assert!(
        err <= TARGET,
        "{}: K = 30 {variant:?} error {:.3} % > 0.35 %",
        e.name,
        100.0 * err
    );
}

#[test]
fn k30_default_sky_within_0_35_percent() {
    check_k30(sky(), Variant::Moments);
}

#[test]
fn k30_real_hdr_within_0_35_percent() {
    check_k30(real(), Variant::Moments);
}

#[test]
#[ignore = "fails: measured 0.59 % (sky.exr; 0.60 % with the paper's merge): eq. 5 drops the BRDF-visibility covariance of the large sky squares; the moments kernel keeps it (0.30 %)"]
fn k30_real_hdr_within_0_35_percent_eq5_kernel() {
    check_k30(real(), Variant::Kernel);
}

/// The moments kernel keeps the covariances that eq. 5 drops: at K = 30 it is at least
/// 20 % more accurate than the eq. 5 kernel on both environments, and within 0.1
/// percentage points of the exact integral of its own light model over the same squares
/// (`SquareLinear`, its floor).
#[test]
fn moments_kernel_beats_eq5_and_nears_the_square_floor() {
    for e in [sky(), real()] {
        let d = k_index(e, 30);
        let (m, k, floor) = (
            e.analysis.error(d, Variant::Moments),
            e.analysis.error(d, Variant::Kernel),
            e.analysis.error(d, Variant::SquareLinear),
        );
        say(&format!(
            "{}: K = 30 moments {:.3} %, eq. 5 {:.3} %, linear-light square floor {:.3} %",
            e.name,
            100.0 * m,
            100.0 * k,
            100.0 * floor
        ));
        assert!(m <= 0.8 * k, "{}: {m} vs {k}", e.name);
        assert!(m <= floor + 0.001, "{}: {m} vs floor {floor}", e.name);
    }
}

/// The radiance gradient of the decomposition (moment-matched, `env::decompose` module
/// docs) lowers the light model's own floor: the exact integral over the squares with the
/// linear light is never worse than with the paper's uniform light at any K, and on the
/// default sky at K = 30 (a horizon-brightened sky in a few large regions) at least 30 %
/// better.
#[test]
fn radiance_gradient_lowers_the_square_floor() {
    for e in [sky(), real()] {
        for d in 0..e.decs.len() {
            let (lin, uni) = (
                e.analysis.error(d, Variant::SquareLinear),
                e.analysis.error(d, Variant::SquareJoint),
            );
            say(&format!(
                "{} K = {}: square floor, linear light {:.3} %, uniform {:.3} %",
                e.name,
                e.decs[d].k,
                100.0 * lin,
                100.0 * uni
            ));
            assert!(lin <= uni, "{} K = {}: {lin} > {uni}", e.name, e.decs[d].k);
        }
    }
    let s = sky();
    let d = k_index(s, 30);
    let (lin, uni) = (
        s.analysis.error(d, Variant::SquareLinear),
        s.analysis.error(d, Variant::SquareJoint),
    );
    assert!(lin <= 0.7 * uni, "default sky K = 30: {lin} vs {uni}");
}

fn check_decreasing(e: &Env) {
    for variant in [Variant::Kernel, Variant::Moments] {
        let errs: Vec<f64> = (0..e.decs.len())
            .map(|d| e.analysis.error(d, variant))
            .collect();
        say(&format!("{}: {variant:?} error per K {:?}", e.name, errs));
        for w in errs.windows(2) {
            assert!(
                w[1] < w[0],
                "{}: {variant:?} error does not decrease with K: {errs:?}",
                e.name
            );
        }
        // K = 100 beats K = 10 by a margin: the decomposition, not noise, drives it.
        assert!(errs[3] < 0.5 * errs[0], "{variant:?} {errs:?}");
    }
}

#[test]
fn error_decreases_with_k_default_sky() {
    check_decreasing(sky());
}

#[test]
fn error_decreases_with_k_real_hdr() {
    check_decreasing(real());
}

/// Eq. 13: at every point, for every K and channel, the multi-product error over the true
/// regions (exact region means) is within the bound summed over the regions.
fn check_bound(e: &Env) {
    let mp = VARIANTS
        .iter()
        .position(|&v| v == Variant::MultiProduct)
        .unwrap();
    let mut worst = 0.0f64;
    for (d, res) in e.analysis.results.iter().enumerate() {
        for (p, (r, x)) in res.iter().zip(&e.analysis.reference).enumerate() {
            for c in 0..3 {
                let err = (r.values[mp][c] - x[c]).abs();
                let slack = 1e-9 * x[c].abs() + 1e-15;
                assert!(
                    err <= r.bound[c] + slack,
                    "{} K = {} point {p} channel {c}: error {err} > bound {}",
                    e.name,
                    e.decs[d].k,
                    r.bound[c]
                );
                if r.bound[c] > 0.0 {
                    worst = worst.max(err / r.bound[c]);
                }
            }
        }
        let (err, bound) = (
            e.analysis.error(d, Variant::MultiProduct),
            e.analysis.bound(d),
        );
        assert!(
            err <= bound,
            "{}: L2 error {err} > L2 bound {bound}",
            e.name
        );
    }
    say(&format!(
        "{}: eq. 13 holds; largest error/bound {worst:.3}",
        e.name
    ));
}

#[test]
fn eq13_bounds_the_multi_product_error_default_sky() {
    check_bound(sky());
}

#[test]
fn eq13_bounds_the_multi_product_error_real_hdr() {
    check_bound(real());
}

// ---- SIMD and GPU against the scalar kernel (a small setup: 64² VDTs) ----

struct Small {
    scene: Scene,
    sat: BrdfSat,
    vdts: Vec<Vdt>,
    /// The decomposition's lights, with their radiance gradients.
    lights: Vec<ShadeLight>,
    /// The same lights without gradients (the paper's uniform squares).
    uniform_lights: Vec<ShadeLight>,
}

fn small(glossy: bool) -> Small {
    let cube = env::default_sky(16).unwrap();
    let decs = decompose(&cube, &Options::quiet(&[30])).unwrap();
    let rsls = decs[0].rsls().unwrap();
    let lights: Vec<ShadeLight> = rsls.iter().map(ShadeLight::from).collect();
    let uniform_lights: Vec<ShadeLight> = rsls
        .iter()
        .map(|r| ShadeLight::from(&r.with_gradient([Vec3::ZERO; 3]).unwrap()))
        .collect();
    let brdf: Box<dyn Brdf> = if glossy {
        Box::new(Phong::new(0.3, 0.5, 30.0).unwrap())
    } else {
        Box::new(Lambert::new(0.8).unwrap())
    };
    let refs: Vec<&Decomposition> = decs.iter().collect();
    let sat = sh::fit_sat(brdf.as_ref(), &refs, 0.02);
    let scene = Scene::standard(8);
    let vdts = sh::par_map(&scene.points, |p| sh::point_vdt(&scene, p, 64));
    Small {
        scene,
        sat,
        vdts,
        lights,
        uniform_lights,
    }
}

fn close(a: [f32; 3], b: [f32; 3], tol: f32) -> bool {
    let m = a.iter().chain(&b).fold(0.0f32, |m, x| m.max(x.abs()));
    (0..3).all(|c| (a[c] - b[c]).abs() <= tol * m.max(1e-30))
}

/// Every point and channel of `other` within `tol` of `scalar` (relative to the point's
/// largest channel, [`close`]); prints the largest relative difference, labelled `what`.
fn assert_lane_by_lane(what: &str, scalar: &[[f32; 3]], other: &[[f32; 3]], tol: f32) {
    assert_eq!(scalar.len(), other.len(), "{what}");
    let mut worst = 0.0f32;
    for (p, (a, b)) in scalar.iter().zip(other).enumerate() {
        let m = a.iter().fold(0.0f32, |m, x| m.max(x.abs()));
        for c in 0..3 {
            worst = worst.max((a[c] - b[c]).abs() / m.max(1e-30));
        }
        assert!(
            close(*a, *b, tol),
            "{what} point {p}: scalar {a:?} vs {b:?}"
        );
    }
    say(&format!("{what}: largest relative difference {worst:.2e}"));
}

#[test]
fn kernel_matches_the_analysis_pipeline() {
    let s = small(false);
    let scalar = sh::shade_points(&s.scene, &s.sat, &s.vdts, &s.lights, VdtQuery::Gradient);
    for (p, v) in scalar.iter().enumerate() {
        let pt = &s.scene.points[p];
        let vis =
            steradian_core::rsl::shade::VdtVisibility::new(s.vdts[p].view(), VdtQuery::Gradient)
                .unwrap();
        let wo = pt.frame.to_local(pt.wo);
        let mut acc = [0.0f64; 3];
        for l in &s.lights {
            let f = steradian_core::rsl::shade::light_factor(&pt.frame, wo, &s.sat, &vis, l);
            for c in 0..3 {
                acc[c] += f64::from(l.energy()[c]) * f64::from(f);
            }
        }
        assert!(close(*v, acc.map(|x| x as f32), 1e-5), "{p}: {v:?} {acc:?}");
    }
}

#[test]
fn simd_matches_scalar_lane_by_lane() {
    for glossy in [false, true] {
        let s = small(glossy);
        for q in [VdtQuery::Gradient, VdtQuery::Eq9] {
            let scalar = sh::shade_points(&s.scene, &s.sat, &s.vdts, &s.lights, q);
            let simd = sh::shade_points_simd(&s.scene, &s.sat, &s.vdts, &s.lights, q).unwrap();
            assert_lane_by_lane(
                &format!("SIMD vs scalar (glossy {glossy}, {q:?})"),
                &scalar,
                &simd,
                steradian_simd::rsl::shade::REL_TOL,
            );
        }
    }
}

/// The SIMD moments kernel against the scalar one, lane by lane and channel by channel:
/// Lambert and glossy Phong, lights with their radiance gradients (the decomposition's)
/// and without, on the standard point set (grazing views, squares across the horizon).
#[test]
fn simd_moments_matches_scalar_lane_by_lane() {
    for glossy in [false, true] {
        let s = small(glossy);
        let moments: Vec<_> = sh::par_map(&s.scene.points, |p| sh::point_moments(&s.scene, p, 64));
        let flat = &s.uniform_lights;
        assert!(s.lights.iter().any(|l| l.gradient() != [Vec3::ZERO; 3]));
        for (what, lights) in [("gradient", &s.lights), ("uniform", flat)] {
            let scalar = sh::shade_points_moments(&s.scene, &s.sat, &moments, lights);
            let simd = sh::shade_points_moments_simd(&s.scene, &s.sat, &moments, lights).unwrap();
            assert_lane_by_lane(
                &format!("SIMD moments vs scalar (glossy {glossy}, {what})"),
                &scalar,
                &simd,
                steradian_simd::rsl::shade::MOMENTS_REL_TOL,
            );
        }
    }
}

#[test]
fn gpu_matches_scalar() {
    let Some(mut g) = gpu() else { return };
    for glossy in [false, true] {
        let s = small(glossy);
        for q in [VdtQuery::Gradient, VdtQuery::Eq9] {
            let table = sh::gpu_table(&s.sat, &s.vdts, &s.lights, q).unwrap();
            let input = sh::gpu_input(&s.scene);
            let mut out = Columns::zeros(3, input.n);
            let custom = Custom {
                label: "rsl-shade",
                source: steradian_core::wgsl::SHADE,
                table: Some(&table),
            };
            g.run_custom(&custom, &input, &mut out)
                .expect("shade kernel runs");
            let scalar = sh::shade_points(&s.scene, &s.sat, &s.vdts, &s.lights, q);
            let gpu: Vec<[f32; 3]> = (0..input.n)
                .map(|p| [0, 1, 2].map(|c| out.data[c * input.n + p]))
                .collect();
            assert_lane_by_lane(
                &format!("GPU vs scalar (glossy {glossy}, {q:?})"),
                &scalar,
                &gpu,
                steradian_core::wgsl::SHADE_REL_TOL,
            );
        }
    }
}

/// The report section alone (`cargo test --release -p steradian-harness --test shade
/// report_section -- --ignored --nocapture`): prints its summary and time (≤ 20 s).
#[test]
#[ignore = "runs the report section (about 10 s)"]
fn report_section() {
    let t = Instant::now();
    let opts = steradian_harness::report::Options {
        gpu: true,
        ..Default::default()
    };
    let s = steradian_harness::report::shade::section(&opts).expect("section");
    say(&s.summary);
    say(&format!("section in {:?}", t.elapsed()));
}

/// The reference sums `ρ·V` at the centres of `sub × sub` sub-texels of every cube texel
/// (the environment itself is piecewise constant per texel, as the kernel's regions are);
/// a shadow edge across a sun texel makes coarse sub-sampling a visible error. Measured:
/// 2 × 2 is 0.35 % (default sky) and 0.44 % (sky.exr) from 16 × 16, 8 × 8 within 0.06 %.
#[test]
fn reference_converges_with_sub_texels() {
    let brdf = Lambert::new(0.8).unwrap();
    let scene = Scene::standard(12);
    for (name, cube) in [
        ("default sky", env::default_sky(32).unwrap()),
        (
            "sky.exr",
            env::load_cubemap(&env::real_env_path(), 32).unwrap(),
        ),
    ] {
        let r = |sub| sh::reference(&cube, &Samples::new(&cube, sub), &scene, &brdf);
        let fine = r(16);
        let d2 = sh::rel_l2(r(2).into_iter(), &fine);
        let d8 = sh::rel_l2(r(SUB).into_iter(), &fine);
        say(&format!(
            "{name}: reference 2×2 vs 16×16 {:.3} %, {SUB}×{SUB} vs 16×16 {:.3} %",
            100.0 * d2,
            100.0 * d8
        ));
        assert!(d8 < 0.2 * TARGET, "{name}: {d8}");
        assert!(d2 > 4.0 * d8, "{name}: 2×2 {d2}, {SUB}×{SUB} {d8}");
    }
}
