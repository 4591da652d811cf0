//! BRDF models and BRDF summed-area tables against the `f64` references of
//! `steradian_harness::reference::brdf`: the models' formulas, reciprocity, energy, closed-form
//! albedos, and `BrdfSat` queries against exact square integrals, with named hard cases
//! (grazing and normal views, Phong `e = 10⁴`, GGX `α = 0.01` and `1`, anisotropic Ward).

use std::f64::consts::{FRAC_PI_2, TAU};

use steradian_core::lobe::brdf::{BlinnPhong, Brdf, Ggx, Lambert, Phong, Ward};
use steradian_core::rsl::brdf_sat::{BrdfSat, FitOptions, Resolution};
use steradian_core::{Vec2, Vec3};
use steradian_harness::reference::AsModel;
use steradian_harness::reference::brdf::{self as rb, Model};
use steradian_harness::rng::Rng;

type Pair = (Box<dyn Brdf>, Model);

fn pair<B: Brdf + Copy + AsModel + 'static>(b: B) -> Pair {
    (Box::new(b), b.model())
}

/// Every model, with the hard parameters of the issue.
fn models() -> Vec<Pair> {
    vec![
        pair(Lambert::new(0.8).unwrap()),
        pair(Phong::new(0.3, 0.6, 20.0).unwrap()),
        pair(Phong::new(0.0, 1.0, 1e4).unwrap()),
        pair(BlinnPhong::new(0.3, 0.6, 200.0).unwrap()),
        pair(Ward::isotropic(0.3, 0.2, 0.15).unwrap()),
        pair(Ward::anisotropic(0.3, 0.2, 0.05, 0.3).unwrap()),
        pair(Ggx::new(0.3, 0.04, 0.01).unwrap()),
        pair(Ggx::new(0.3, 0.9, 1.0).unwrap()),
        pair(Ggx::new(0.0, 0.5, 0.3).unwrap()),
    ]
}

fn hemi(rng: &mut Rng, zmin: f64) -> [f64; 3] {
    let z = rng.range(zmin, 1.0);
    let phi = rng.range(0.0, TAU);
    let s = (1.0 - z * z).sqrt();
    [s * phi.cos(), s * phi.sin(), z]
}

fn v3(d: [f64; 3]) -> Vec3 {
    Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)
}

fn f64v(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

fn dir(theta: f64, phi: f64) -> [f64; 3] {
    [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ]
}

/// Near-peak incident directions: around the mirror direction within a few lobe widths.
fn near_mirror(rng: &mut Rng, wo: [f64; 3], width: f64) -> [f64; 3] {
    let r = [-wo[0], -wo[1], wo[2]];
    let j = [
        r[0] + width * rng.range(-2.0, 2.0),
        r[1] + width * rng.range(-2.0, 2.0),
        r[2] + width * rng.range(-2.0, 2.0),
    ];
    let l = (j[0] * j[0] + j[1] * j[1] + j[2] * j[2]).sqrt();
    let mut d = j.map(|c| c / l);
    d[2] = d[2].abs().max(1e-3);
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    d.map(|c| c / l)
}

#[test]
fn eval_matches_f64_formulas() {
    let mut rng = Rng::new(0xb0d1);
    for (b, m) in models() {
        let mut worst = 0.0f64;
        let mut peak = 0.0f64;
        let mut cases = Vec::new();
        for k in 0..20_000 {
            let wo = hemi(&mut rng, 1e-3);
            let wi = if k % 2 == 0 {
                hemi(&mut rng, 1e-3)
            } else {
                near_mirror(&mut rng, wo, m.feature_angle())
            };
            // compare on the f32-rounded directions
            let (wi, wo) = (f64v(v3(wi)), f64v(v3(wo)));
            let want = m.rho_cos(wi, wo);
            peak = peak.max(want);
            cases.push((wi, wo, want));
        }
        for (wi, wo, want) in cases {
            if want < 1e-6 * peak {
                continue;
            }
            let got = steradian_harness::reference::core_eval(b.as_ref(), wi, wo) as f64;
            worst = worst.max((got - want).abs() / want);
        }
        // Sharp lobes amplify the rounding of the f32 inputs: `e·Δ(cos)` with Δ ≈ 1e-7.
        let a = b.feature_angle() as f64;
        let bound = steradian_core::lobe::brdf::EVAL_REL_ERROR as f64
            + steradian_core::lobe::brdf::EVAL_SHARPNESS_ERROR as f64 / (a * a);
        println!(
            "{}: worst relative error {worst:.3e} (bound {bound:.1e})",
            b.name()
        );
        assert!(worst <= bound, "{}: {worst}", b.name());
    }
}

fn reciprocity(b: &dyn Brdf) {
    let mut rng = Rng::new(0x5ec1);
    let mut worst = 0.0f64;
    for k in 0..20_000 {
        let wo = hemi(&mut rng, 1e-2);
        let wi = if k % 2 == 0 {
            hemi(&mut rng, 1e-2)
        } else {
            near_mirror(&mut rng, wo, b.feature_angle() as f64)
        };
        let (a, bb) = (v3(wi), v3(wo));
        let f = b.eval(a, bb) as f64 / a.z as f64;
        let g = b.eval(bb, a) as f64 / bb.z as f64;
        if f.max(g) < 1e-20 {
            continue;
        }
        worst = worst.max((f - g).abs() / f.max(g));
    }
    println!("{}: reciprocity worst {worst:.2e}", b.name());
    assert!(worst < 1e-4, "{}: {worst}", b.name());
}

#[test]
fn reciprocity_lambert() {
    reciprocity(&Lambert::new(0.7).unwrap());
}
#[test]
fn reciprocity_phong() {
    reciprocity(&Phong::new(0.3, 0.6, 300.0).unwrap());
}
#[test]
fn reciprocity_blinn_phong() {
    reciprocity(&BlinnPhong::new(0.3, 0.6, 300.0).unwrap());
}
#[test]
fn reciprocity_ward_isotropic() {
    reciprocity(&Ward::isotropic(0.3, 0.2, 0.1).unwrap());
}
#[test]
fn reciprocity_ward_anisotropic() {
    reciprocity(&Ward::anisotropic(0.3, 0.2, 0.05, 0.3).unwrap());
}
#[test]
fn reciprocity_ggx() {
    reciprocity(&Ggx::new(0.3, 0.04, 0.2).unwrap());
}

#[test]
fn lambert_albedo_is_the_albedo() {
    let m = Lambert::new(0.8).unwrap().model();
    for theta in [0.0, 1.0, 1.5] {
        let a = rb::albedo(&m, dir(theta, 0.3), 1e-10);
        assert!((a - 0.8).abs() < 1e-7, "{a}");
    }
}

#[test]
fn normal_incidence_phong_albedo_is_kd_plus_ks() {
    // ∫ (e+2)/(2π) cos^(e+1) dω = 1 at normal incidence, for any e (sharp lobes included).
    for e in [0.0, 1.0, 20.0, 1000.0, 1e4] {
        let m = Phong::new(0.25, 0.7, e as f32).unwrap().model();
        let a = rb::albedo(&m, [0.0, 0.0, 1.0], 1e-10);
        assert!((a - 0.95).abs() < 1e-6, "e = {e}: {a}");
    }
}

/// Directional albedo of each model over views up to 89°: ≤ 1 for weights summing to 1,
/// except Blinn–Phong's approximate normalisation (≤ `BLINN_PHONG_ALBEDO_BOUND`).
#[test]
fn energy_at_most_one() {
    let bp = steradian_core::lobe::brdf::BLINN_PHONG_ALBEDO_BOUND as f64;
    let cases: Vec<(Pair, f64)> = vec![
        (pair(Lambert::new(1.0).unwrap()), 1.0),
        (pair(Phong::new(0.3, 0.7, 1.0).unwrap()), 1.0),
        (pair(Phong::new(0.0, 1.0, 1e4).unwrap()), 1.0),
        (pair(BlinnPhong::new(0.0, 1.0, 10.0).unwrap()), bp),
        (pair(BlinnPhong::new(0.0, 1.0, 3.0).unwrap()), bp),
        (pair(BlinnPhong::new(0.0, 1.0, 1e3).unwrap()), bp),
        (pair(Ggx::new(0.0, 1.0, 0.01).unwrap()), 1.0),
        (pair(Ggx::new(0.0, 1.0, 1.0).unwrap()), 1.0),
        (pair(Ggx::new(0.0, 1.0, 0.3).unwrap()), 1.0),
        (pair(Ward::isotropic(0.5, 0.5, 0.2).unwrap()), 1.0),
        (pair(Ward::isotropic(0.0, 1.0, 1.0).unwrap()), 1.0),
        (pair(Ward::anisotropic(0.5, 0.5, 0.05, 0.2).unwrap()), 1.0),
    ];
    for ((b, m), bound) in cases {
        let mut worst = 0.0f64;
        for k in 0..=16 {
            let theta = (89.0 * k as f64 / 16.0).to_radians();
            let a = rb::albedo(&m, dir(theta, 0.7), 1e-7);
            worst = worst.max(a);
        }
        println!("{}: max albedo {worst:.5} (bound {bound})", b.name());
        assert!(worst <= bound + 1e-6, "{}: {worst}", b.name());
    }
}

/// The measured albedo claims of `steradian_core::lobe::brdf`: Blinn–Phong's largest albedo over
/// exponents and views up to 89° stays within `BLINN_PHONG_ALBEDO_BOUND` (1.075 at
/// `e = 10`), and Ward's specular albedo falls towards grazing views, at most `½·ρ_s` at 89°
/// for `α ≤ 1` (0.499 at `α = 0.5`).
#[test]
fn albedo_claims_blinn_phong_bound_and_ward_at_89_degrees() {
    let bp = steradian_core::lobe::brdf::BLINN_PHONG_ALBEDO_BOUND as f64;
    for e in [0.0, 1.0, 3.0, 10.0, 30.0, 100.0, 1000.0] {
        let m = BlinnPhong::new(0.0, 1.0, e as f32).unwrap().model();
        let w = (0..=30)
            .map(|k| rb::albedo(&m, dir((89.0 * k as f64 / 30.0).to_radians(), 0.0), 1e-7))
            .fold(0.0f64, f64::max);
        println!("Blinn-Phong e = {e}: max albedo {w:.5}");
        assert!(w <= bp, "Blinn-Phong e = {e}: {w}");
    }
    for a in [0.05, 0.1, 0.2, 0.3, 0.5, 1.0] {
        let m = Ward::isotropic(0.0, 1.0, a as f32).unwrap().model();
        let w: Vec<_> = [0.0, 60.0, 70.0, 80.0, 85.0, 89.0]
            .iter()
            .map(|t: &f64| rb::albedo(&m, dir(t.to_radians(), 0.0), 1e-7))
            .collect();
        println!("Ward α = {a}: albedo at 0/60/70/80/85/89°: {w:.4?}");
        assert!(w[5] <= 0.5, "Ward α = {a}: {w:?}");
    }
}

/// Fresh queries (views, squares and seed unlike the fit's) against the f64 reference:
/// the largest and the root-mean-square error over them.
fn fresh_error(t: &BrdfSat, b: &dyn Brdf, m: &Model, opts: &FitOptions, seed: u64) -> (f64, f64) {
    let mut rng = Rng::new(seed);
    let (mut worst, mut sum, mut n) = (0.0f64, 0.0f64, 0);
    let smax = (1.0 - (opts.theta_max as f64).cos()).sqrt();
    for v in 0..12 {
        let s = if v == 0 { 0.0 } else { smax * rng.unit() };
        let phi = rng.range(0.0, TAU);
        let wo = rb::unmap([s * phi.cos(), s * phi.sin()]);
        let wo = f64v(v3(wo));
        let albedo = rb::albedo(m, wo, 1e-8);
        let pm = rb::map(wo);
        for q in 0..10 {
            let r = (opts.r_min as f64) * ((opts.r_max / opts.r_min) as f64).powf(rng.unit());
            let h = r * std::f64::consts::FRAC_1_SQRT_2;
            let c = match q % 3 {
                0 => [-pm[0], -pm[1]],
                1 => [-pm[0] + h * rng.range(-1.0, 1.0), -pm[1] + h],
                _ => {
                    let (rr, t) = (rng.unit().sqrt(), rng.range(0.0, TAU));
                    [rr * t.cos(), rr * t.sin()]
                }
            };
            let c32 = Vec2::new(c[0] as f32, c[1] as f32);
            let got = t.integral(v3(wo), c32, r as f32) as f64;
            // isotropic tables turn the square by the view azimuth (brdf_sat docs)
            let angle = if b.is_isotropic() {
                pm[1].atan2(pm[0])
            } else {
                0.0
            };
            let exact = rb::square_integral(
                m,
                wo,
                [c32.x as f64, c32.y as f64],
                r as f32 as f64,
                angle,
                1e-3 * albedo * r * r,
            );
            let e = rb::table_error(got, exact, albedo, r);
            worst = worst.max(e);
            sum += e * e;
            n += 1;
        }
    }
    (worst, (sum / n as f64).sqrt())
}

fn check_met(b: &dyn Brdf, m: &Model, opts: &FitOptions) {
    let t = check_fit(b, m, opts);
    assert!(t.fit_report().unwrap().met, "{}: not met", b.name());
}

fn check_fit(b: &dyn Brdf, m: &Model, opts: &FitOptions) -> BrdfSat {
    let t0 = std::time::Instant::now();
    let t = BrdfSat::fit(b, opts).unwrap();
    let fit = t.fit_report().unwrap();
    let (worst, rms) = fresh_error(&t, b, m, opts, 0xf2e5);
    println!(
        "{}: {:?}, {} bytes, fit {:?} in {:?}; fresh queries: max {worst:.4}, rms {rms:.4}",
        b.name(),
        t.resolution(),
        t.bytes(),
        fit,
        t0.elapsed()
    );
    // Honest reporting: met means within the target on the test set, not met means the
    // caps stopped the refinement above it.
    assert_eq!(fit.met, fit.max_error <= opts.target, "{fit:?}");
    // The reported (test-set) error holds on queries the fit never saw: the max within
    // 1.5× (a different sample of squares), the RMS within the reported max.
    assert!(worst <= 1.5 * fit.max_error as f64, "{}: {worst}", b.name());
    assert!(rms <= fit.max_error as f64, "{}: {rms}", b.name());
    t
}

fn modest(target: f32) -> FitOptions {
    FitOptions {
        r_min: 0.1,
        theta_max: 80f32.to_radians(),
        max_grid: 128,
        max_polar: 33,
        max_azimuth: 16,
        max_bytes: 8 << 20,
        ..FitOptions::new(target)
    }
}

#[test]
fn brdf_sat_lambert_within_reported_error() {
    let b = Lambert::new(0.8).unwrap();
    check_met(&b, &b.model(), &modest(1e-3));
}

#[test]
fn brdf_sat_phong_within_reported_error() {
    let b = Phong::new(0.3, 0.6, 50.0).unwrap();
    check_met(&b, &b.model(), &modest(0.03));
}

#[test]
fn brdf_sat_blinn_phong_within_reported_error() {
    let b = BlinnPhong::new(0.3, 0.6, 100.0).unwrap();
    check_met(&b, &b.model(), &modest(0.02));
}

#[test]
fn brdf_sat_ward_within_reported_error() {
    let b = Ward::isotropic(0.3, 0.2, 0.2).unwrap();
    check_met(&b, &b.model(), &modest(0.02));
}

#[test]
fn brdf_sat_ggx_within_reported_error() {
    let b = Ggx::new(0.3, 0.04, 0.3).unwrap();
    check_met(&b, &b.model(), &modest(0.02));
}

#[test]
fn brdf_sat_ward_anisotropic_within_reported_error() {
    let b = Ward::anisotropic(0.3, 0.2, 0.15, 0.4).unwrap();
    // Views up to 60°: at grazing views the mirror direction sweeps a long arc per
    // azimuth step and linear interpolation between azimuth nodes needs many of them.
    let opts = FitOptions {
        r_min: 0.15,
        theta_max: 60f32.to_radians(),
        max_azimuth: 64,
        max_bytes: 32 << 20,
        ..modest(0.1)
    };
    check_met(&b, &b.model(), &opts);
}

/// Sharp lobes need a finer grid than diffuse ones ("model only what a scene needs").
#[test]
fn sharp_phong_e_1e4_needs_a_finer_grid_than_diffuse() {
    let opts = FitOptions {
        r_min: 0.1,
        ..modest(0.05)
    };
    let sharp = Phong::new(0.0, 1.0, 1e4).unwrap();
    let diffuse = Phong::new(1.0, 0.0, 1e4).unwrap();
    let ts = BrdfSat::fit(&sharp, &opts).unwrap();
    let td = BrdfSat::fit(&diffuse, &opts).unwrap();
    println!(
        "e = 1e4: sharp {:?} {:?}; diffuse {:?} {:?}",
        ts.resolution(),
        ts.fit_report(),
        td.resolution(),
        td.fit_report()
    );
    assert!(td.fit_report().unwrap().met);
    assert!(ts.resolution().bytes() > 4 * td.resolution().bytes());
    // The normal-incidence table integrates the whole lobe: albedo ks = 1 exactly.
    let whole = ts.integral(Vec3::Z, Vec2::ZERO, 2.0f32.sqrt());
    assert!((whole - 1.0).abs() < 1e-3, "{whole}");
}

#[test]
fn ggx_roughness_0_01_and_1() {
    for alpha in [0.01f32, 1.0] {
        let b = Ggx::new(0.2, 0.5, alpha).unwrap();
        let m = b.model();
        let opts = FitOptions {
            r_min: 0.15,
            ..modest(0.05)
        };
        check_fit(&b, &m, &opts);
    }
}

#[test]
fn normal_incidence_any_square() {
    let b = Phong::new(0.3, 0.6, 50.0).unwrap();
    let m = b.model();
    let t = BrdfSat::build(&b, res(128, 9, 1), 80f32.to_radians()).unwrap();
    let albedo = rb::albedo(&m, [0.0, 0.0, 1.0], 1e-9);
    assert!((albedo - 0.9).abs() < 1e-6);
    for (c, r) in [([0.0, 0.0], 0.3), ([0.4, -0.2], 0.2), ([0.0, 0.0], 1.5)] {
        let got = t.integral(Vec3::Z, Vec2::new(c[0] as f32, c[1] as f32), r as f32) as f64;
        let exact = rb::square_integral(&m, [0.0, 0.0, 1.0], c, r, 0.0, 1e-9);
        let e = rb::table_error(got, exact, albedo, r);
        assert!(e < 0.01, "{c:?} {r}: {got} {exact}");
    }
}

/// Views at 89°: the table reaches them (θ_max = 89°) within the fit's error; beyond
/// θ_max the last node is used (constant extension), and the result stays finite.
#[test]
fn grazing_view_89_degrees() {
    let b = Ggx::new(0.2, 0.5, 0.3).unwrap();
    let m = b.model();
    let opts = FitOptions {
        r_min: 0.15,
        theta_max: 89f32.to_radians(),
        ..FitOptions::new(0.05)
    };
    let t = BrdfSat::fit(&b, &opts).unwrap();
    let fit = t.fit_report().unwrap();
    println!("grazing: {:?} {fit:?}", t.resolution());
    let wo = dir(89f64.to_radians(), 0.4);
    let wo = f64v(v3(wo));
    let albedo = rb::albedo(&m, wo, 1e-9);
    let pm = rb::map(wo);
    for r in [0.15, 0.3, 0.5] {
        let c = [-pm[0] * 0.9, -pm[1] * 0.9];
        let got = t.integral(v3(wo), Vec2::new(c[0] as f32, c[1] as f32), r as f32) as f64;
        let exact = rb::square_integral(&m, wo, c, r, pm[1].atan2(pm[0]), 1e-7);
        let e = rb::table_error(got, exact, albedo, r);
        assert!(
            e <= 1.5 * fit.max_error as f64,
            "r {r}: {got} vs {exact}: {e}"
        );
    }
    let beyond = t.integral(
        Vec3::new(1.0, 0.0, 1e-4).normalize(),
        Vec2::new(-0.9, 0.0),
        0.2,
    );
    let last = t.integral(
        t.view_node(t.resolution().polar - 1, 0),
        Vec2::new(-0.9, 0.0),
        0.2,
    );
    assert!(beyond.is_finite() && (beyond - last).abs() <= 1e-6 * last.abs());
}

/// Anisotropic tables: Ward(αx, αy) seen from azimuth 90° equals Ward(αy, αx) seen from
/// azimuth 0 with the square turned by −90° (an axis-aligned square stays one).
#[test]
fn ward_anisotropic_quarter_turn_symmetry() {
    let rs = res(64, 9, 8);
    let a = BrdfSat::build(&Ward::anisotropic(0.2, 0.3, 0.1, 0.3).unwrap(), rs, 1.3).unwrap();
    let b = BrdfSat::build(&Ward::anisotropic(0.2, 0.3, 0.3, 0.1).unwrap(), rs, 1.3).unwrap();
    let mut rng = Rng::new(9);
    for _ in 0..200 {
        let theta = rng.range(0.0, 1.2);
        let wo_a = dir(theta, FRAC_PI_2);
        let wo_b = dir(theta, 0.0);
        let c = [rng.range(-0.7, 0.7), rng.range(-0.7, 0.7)];
        let r = rng.range(0.05, 0.5) as f32;
        let va = a.integral(v3(wo_a), Vec2::new(c[0] as f32, c[1] as f32), r);
        let vb = b.integral(v3(wo_b), Vec2::new(c[1] as f32, -c[0] as f32), r);
        assert!((va - vb).abs() <= 1e-4 * va.abs().max(1e-3), "{va} {vb}");
    }
}

/// An isotropic (`azimuth = 1`) or anisotropic resolution.
fn res(grid: usize, polar: usize, azimuth: usize) -> Resolution {
    Resolution {
        grid,
        polar,
        azimuth,
    }
}

#[test]
fn bad_input() {
    let b = Lambert::new(0.5).unwrap();
    assert!(BrdfSat::build(&b, res(1, 4, 1), 1.0).is_err());
    assert!(BrdfSat::build(&b, res(8, 4, 4), 1.0).is_err());
    let aniso = Ward::anisotropic(0.1, 0.1, 0.1, 0.2).unwrap();
    assert!(BrdfSat::build(&aniso, res(8, 4, 1), 1.0).is_err());
    assert!(BrdfSat::build(&b, res(8, 4, 1), f32::NAN).is_err());
    assert!(BrdfSat::for_target(&b, 0.0).is_err());
    assert!(BrdfSat::for_target(&b, f32::NAN).is_err());
    let t = BrdfSat::build(&b, res(8, 4, 1), 1.0).unwrap();
    assert!(
        t.integral(Vec3::new(f32::NAN, 0.0, 1.0), Vec2::ZERO, 0.1)
            .is_nan()
    );
    assert!(t.integral(Vec3::Z, Vec2::new(0.0, f32::NAN), 0.1).is_nan());
    assert!(t.integral(Vec3::Z, Vec2::ZERO, f32::NAN).is_nan());
    assert_eq!(t.integral(-Vec3::Z, Vec2::ZERO, 0.1), 0.0);
    assert_eq!(t.integral(Vec3::Z, Vec2::ZERO, -0.1), 0.0);
    assert!(t.integral(Vec3::Z, Vec2::ZERO, f32::INFINITY).is_finite());
}

/// The report section runs (≤ 10 s in release) and every model's fit is honest.
#[test]
#[ignore = "slow-ish (several seconds): run with --ignored to print the report section"]
fn report_section() {
    let t0 = std::time::Instant::now();
    let s = steradian_harness::report::brdf::section(&Default::default()).unwrap();
    println!("{}\nin {:?}", s.summary, t0.elapsed());
}
