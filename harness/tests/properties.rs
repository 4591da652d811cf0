//! Property tests: every scalar kernel against its f64 reference over the whole domain,
//! with a fixed seed (`PROPTEST_CASES` raises the case count), plus the named hard cases.

use std::f64::consts::{FRAC_PI_2, PI};

use proptest::prelude::*;
use proptest::test_runner::Config;

use crate::common::proptest_config;
use steradian_core::frame::Frame;
use steradian_core::lobe::cap::{self, CapFit, SphericalCap};
use steradian_core::lobe::{self, CosineLobe, Lafortune, LafortuneLobe, Phong};
use steradian_core::{Vec2, Vec3, rsl::hemisphere};
use steradian_harness::workload::{self, unit32};
use steradian_harness::{accuracy, reference};

fn config() -> Config {
    proptest_config::config(4000, 0x5732_ad1a)
}

/// A direction of any length from 1e-30 to 1e30, any hemisphere.
fn direction() -> impl Strategy<Value = [f32; 3]> {
    (-1.0f64..1.0, 0.0..std::f64::consts::TAU, -30.0f64..30.0).prop_map(|(z, phi, lg)| {
        let r = (1.0 - z * z).sqrt();
        let k = 10f64.powf(lg);
        [
            (r * phi.cos() * k) as f32,
            (r * phi.sin() * k) as f32,
            (z * k) as f32,
        ]
    })
}

fn map_err(d: [f32; 3]) -> f64 {
    let got = hemisphere::map(Vec3::from(d));
    let want = reference::hemisphere_map(d);
    (got.x as f64 - want[0])
        .abs()
        .max((got.y as f64 - want[1]).abs())
}

fn unmap_err(p: [f32; 2]) -> f64 {
    let got = hemisphere::unmap(Vec2::from(p));
    let want = reference::hemisphere_unmap(p);
    [got.x, got.y, got.z]
        .iter()
        .zip(want)
        .map(|(g, w)| (*g as f64 - w).abs())
        .fold(0.0, f64::max)
}

/// The lobe-eval metric (see `accuracy::lobe_eval_error`).
fn lobe_err(axis: [f32; 3], s: f32, e: f32, v: [f32; 3]) -> f64 {
    let got = lobe::eval(Vec3::from(axis), s, e, Vec3::from(v)) as f64;
    accuracy::lobe_eval_error(axis, s, e, v, got)
}

fn cap_excess(a: f32) -> f64 {
    let e = cap::exponent_l2(a) as f64;
    reference::cap::excess(e, a as f64)
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn map_within_bound(d in direction()) {
        prop_assert!(map_err(d) <= hemisphere::MAP_ABS_ERROR as f64, "{d:?}: {}", map_err(d));
    }

    #[test]
    fn unmap_within_bound(r in 0.0f64..=1.0, phi in 0.0..std::f64::consts::TAU) {
        let p = [(r.sqrt() * phi.cos()) as f32, (r.sqrt() * phi.sin()) as f32];
        prop_assert!(unmap_err(p) <= hemisphere::UNMAP_ABS_ERROR as f64, "{p:?}: {}", unmap_err(p));
    }

    #[test]
    fn map_unmap_round_trip(d in direction()) {
        let n = reference::normalize(d).unwrap();
        let back = hemisphere::unmap(hemisphere::map(Vec3::from(d)));
        // unmap∘map is the identity on the upper hemisphere (z mirrored).
        let want = [n[0], n[1], n[2].abs()];
        for (g, w) in [back.x, back.y, back.z].iter().zip(want) {
            prop_assert!((*g as f64 - w).abs() < 1e-6, "{d:?} → {back:?}");
        }
    }

    #[test]
    fn lobe_eval_within_bound(
        a in direction(), e in prop_oneof![Just(0.0f64), 0.0f64..2.0, 1e-3f64..1e5],
        width_mult in 0.0f64..4.0, phi in 0.0..std::f64::consts::TAU, s in 0.01f64..100.0,
    ) {
        let an = reference::normalize(a).unwrap();
        let theta = (width_mult / (e + 1.0).sqrt()).min(PI);
        let axis = unit32(an);
        let v = unit32(workload::direction_at(an, theta, phi));
        let err = lobe_err(axis, s as f32, e as f32, v);
        prop_assert!(err <= lobe::EVAL_REL_ERROR as f64, "axis {axis:?} e {e} v {v:?}: {err}");
    }

    #[test]
    fn lobe_integral_within_bound(e in prop_oneof![Just(0.0f32), 0.0f32..1e5, 1e-7f32..1.0], s in -1e30f32..1e30) {
        let got = lobe::integral(e, s) as f64;
        let want = reference::lobe_integral(e, s);
        prop_assert!(want == 0.0 || ((got - want) / want).abs() <= lobe::INTEGRAL_REL_ERROR as f64);
    }

    #[test]
    fn cap_exponent_within_bound_log(lg in -18.0f64..FRAC_PI_2.log10()) {
        let a = 10f64.powf(lg) as f32;
        prop_assert!(cap_excess(a) <= cap::EXCESS_L2_REL, "α = {a}: {}", cap_excess(a));
    }

    #[test]
    fn cap_exponent_within_bound_uniform(a in 1e-4f64..=FRAC_PI_2) {
        let a = a as f32;
        prop_assert!(cap_excess(a) <= cap::EXCESS_L2_REL, "α = {a}: {}", cap_excess(a));
    }

    #[test]
    fn cap_from_sphere_matches_f64(d in direction(), ratio in 1e-6f64..0.999) {
        let n = reference::normalize(d).unwrap();
        let dist = 10f64.powf(((d[0] as f64).abs() + 1.0).log10().min(20.0));
        let centre = n.map(|c| (c * dist) as f32);
        let r = ratio * dist;
        let cap = SphericalCap::from_sphere(Vec3::ZERO, Vec3::from(centre), r as f32).unwrap();
        let c64 = centre.map(f64::from);
        let d64 = (c64[0] * c64[0] + c64[1] * c64[1] + c64[2] * c64[2]).sqrt();
        let sin_a = (r as f32) as f64 / d64;
        let want = sin_a.asin();
        prop_assert!(((cap.half_angle() as f64 - want) / want).abs() < 2e-6, "{}", cap.half_angle());
        let omc = sin_a * sin_a / (1.0 + (1.0 - sin_a * sin_a).sqrt());
        prop_assert!(((cap.one_minus_cos() as f64 - omc) / omc).abs() < 2e-6);
    }

    #[test]
    fn phong_lobes_equal_the_brdf(n in direction(), wo in direction(), v in direction(),
                                  kd in 0.0f32..1.0, ks in 0.0f32..1.0, e in 0.0f32..200.0) {
        let (n, wo, v) = (reference::normalize(n).unwrap(), reference::normalize(wo).unwrap(), reference::normalize(v).unwrap());
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let k = 2.0 * dot(n, wo);
        let r = [k * n[0] - wo[0], k * n[1] - wo[1], k * n[2] - wo[2]];
        let want = kd as f64 * dot(n, v).max(0.0) + ks as f64 * dot(r, v).max(0.0).powf(e as f64);
        let p = Phong::new(kd, ks, e).unwrap();
        let [dl, sl] = p.lobes(Vec3::from(unit32(n)), Vec3::from(unit32(wo)));
        let vv = Vec3::from(unit32(v));
        let got = (dl.eval(vv) + sl.eval(vv)) as f64;
        // absolute in units of the BRDF's scale; the reflection is formed in f32.
        prop_assert!((got - want).abs() <= 1e-4 * (kd + ks) as f64 * (1.0 + e as f64).sqrt(), "{got} vs {want}");
    }
}

#[test]
fn hard_case_map_pole_horizon_and_grazing() {
    for (name, d) in [
        ("pole", [0.0, 0.0, 1.0]),
        ("horizon", [1.0, 0.0, 0.0]),
        ("z = 1e-7", [(1.0f32 - 1e-14).sqrt(), 0.0, 1e-7]),
        ("huge", [3e38, -3e38, 3e38]),
        ("tiny", [1e-38, 1e-38, 1e-38]),
        ("subnormal", [1e-45, 0.0, 1e-45]),
        ("below horizon", [0.3, 0.4, -0.5]),
    ] {
        assert!(
            map_err(d) <= hemisphere::MAP_ABS_ERROR as f64,
            "{name}: {}",
            map_err(d)
        );
    }
    assert_eq!(
        hemisphere::map(Vec3::ZERO),
        Vec2::ZERO,
        "zero vector → pole"
    );
}

#[test]
fn hard_case_unmap_horizon() {
    for p in [
        [1.0f32, 0.0],
        [0.0, -1.0],
        [0.70710677, 0.70710677],
        [0.99999994, 0.0],
        [0.0, 0.0],
    ] {
        assert!(unmap_err(p) <= hemisphere::UNMAP_ABS_ERROR as f64, "{p:?}");
    }
}

#[test]
fn hard_case_lobe_exponent_zero_and_1e5() {
    let z = [0.0f32, 0.0, 1.0];
    for (e, theta) in [
        (0.0f32, 1.0f64),
        (0.0, 1.5),
        (1e5, 0.0),
        (1e5, 1e-3),
        (1e5, 3e-3),
        (1e5, 1e-2),
    ] {
        let v = unit32([theta.sin(), 0.0, theta.cos()]);
        let err = lobe_err(z, 1.0, e, v);
        assert!(
            err <= lobe::EVAL_REL_ERROR as f64,
            "e = {e}, θ = {theta}: {err}"
        );
    }
    // A plain powf(a·v, e) loses about e·2⁻²⁴ relative at 1e5; the kernel does not.
    let v = unit32([(3e-3f64).sin(), 0.0, (3e-3f64).cos()]);
    let naive = (Vec3::from(z).dot(Vec3::from(v))).powf(1e5) as f64;
    let want = reference::lobe_eval(z, 1.0, 1e5, v);
    let ours = lobe::eval(Vec3::from(z), 1.0, 1e5, Vec3::from(v)) as f64;
    assert!((ours / want - 1.0).abs() < (naive / want - 1.0).abs());
    // The integral of the e = 0 lobe is the hemisphere's 2π.
    assert_eq!(
        CosineLobe::new(Vec3::Z, 1.0, 0.0).unwrap().integral(),
        steradian_core::TWO_PI
    );
}

#[test]
fn hard_case_tiny_caps_and_hemisphere() {
    for a in [
        1e-4f32,
        1e-6,
        1e-12,
        1e-18,
        FRAC_PI_2 as f32,
        FRAC_PI_2 as f32 - 1e-6,
        1.0,
    ] {
        assert!(
            cap_excess(a) <= cap::EXCESS_L2_REL,
            "α = {a}: {}",
            cap_excess(a)
        );
    }
    // e ≈ 2k*/α² for tiny caps
    let e = cap::exponent_l2(1e-4) as f64;
    assert!(
        (e * 1e-8 / (2.0 * reference::cap::k_star()) - 1.0).abs() < 1e-5,
        "{e}"
    );
}

#[test]
fn energy_preserving_cap_lobe_integral_is_the_solid_angle() {
    for a in [1e-4f32, 0.05, 0.5, 1.2, 1.5] {
        let c = SphericalCap::new(Vec3::Z, a).unwrap();
        let l = c.lobe(1.0, CapFit::EnergyPreserving);
        let want = reference::cap_solid_angle(a as f64);
        assert!((l.integral() as f64 / want - 1.0).abs() < 2e-6, "α = {a}");
    }
}

#[test]
fn lafortune_lobes_equal_the_brdf() {
    let frame = Frame::from_normal_tangent(Vec3::new(0.1, 0.2, 1.0), Vec3::X).unwrap();
    let lobes = [
        LafortuneLobe {
            c: Vec3::new(-0.8, -0.5, 0.9),
            exponent: 12.0,
            rho: 0.7,
        },
        LafortuneLobe {
            c: Vec3::new(0.3, 0.3, 0.6),
            exponent: 1.5,
            rho: 0.2,
        },
    ];
    let brdf = Lafortune::new(lobes).unwrap();
    let wo = Vec3::new(0.4, -0.3, 0.8).normalize();
    let ls = brdf.lobes(&frame, wo);
    let wl = frame.to_local(wo);
    for i in 0..200 {
        let t = i as f32 * 0.37;
        let v = Vec3::new(
            t.sin() * (t * 0.7).cos(),
            t.sin() * (t * 0.7).sin(),
            t.cos(),
        )
        .normalize();
        let vl = frame.to_local(v);
        let want: f64 = lobes
            .iter()
            .map(|l| {
                let d = (vl * l.c * wl)
                    .to_array()
                    .iter()
                    .map(|x| *x as f64)
                    .sum::<f64>();
                l.rho as f64 * d.max(0.0).powf(l.exponent as f64)
            })
            .sum();
        let got: f64 = ls.iter().map(|l| l.eval(v) as f64).sum();
        assert!((got - want).abs() < 1e-5, "{v}: {got} vs {want}");
    }
}

/// Every f32 half-angle from `MIN_HALF_ANGLE` to π/2 (every 64th in debug builds): the
/// looked-up exponent is finite, non-negative and never increases.
#[test]
fn cap_exponent_monotone_over_every_f32() {
    let step = if cfg!(debug_assertions) { 64 } else { 1 };
    let (lo, hi) = (cap::MIN_HALF_ANGLE.to_bits(), (FRAC_PI_2 as f32).to_bits());
    let mut prev = f32::INFINITY;
    let mut bits = lo;
    while bits <= hi {
        let a = f32::from_bits(bits);
        let e = cap::exponent_l2(a);
        assert!(
            e.is_finite() && e >= 0.0 && e <= prev,
            "α = {a:e}: {e} after {prev}"
        );
        prev = e;
        bits += step;
    }
}

/// Every f32 within 2e-3 rad of the hemisphere (every 16th in debug builds), where
/// `e* ≈ c(1 − ln c)/2` has its logarithmic kink: the excess objective stays within bound.
#[test]
fn cap_exponent_every_f32_next_to_the_hemisphere() {
    let step = if cfg!(debug_assertions) { 16 } else { 1 };
    let hi = (FRAC_PI_2 as f32).to_bits();
    let lo = (FRAC_PI_2 as f32 - 2e-3).to_bits();
    let mut worst = (0.0, 0.0f32);
    let mut bits = lo;
    while bits <= hi {
        let a = f32::from_bits(bits);
        let x = cap_excess(a);
        if x > worst.0 {
            worst = (x, a);
        }
        bits += step;
    }
    assert!(
        worst.0 <= cap::EXCESS_L2_REL,
        "worst excess {:e} at α = {}",
        worst.0,
        worst.1
    );
}
