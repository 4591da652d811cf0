//! The four SH `eval` kernels on inputs drawn at random, through the line contract
//! (`steradian eval` handlers), against the `f64` references of `steradian-reference`: each
//! answer within the bound the kernel states.

use proptest::prelude::*;
use proptest::test_runner::Config;
use serde_json::{Value, json};
use steradian_core::sh;
use steradian_harness::eval::eval_line;
use steradian_reference::sh as reference;

use crate::common::proptest_config;

fn config(cases: u32) -> Config {
    proptest_config::config(cases, 0x5a_0013)
}

fn direction() -> impl Strategy<Value = [f32; 3]> {
    (
        prop_oneof![-1.0f32..1.0, Just(0.0f32), Just(1e-7f32)],
        -1.0f32..1.0,
        prop_oneof![-1.0f32..1.0, Just(1.0f32), Just(-1.0f32)],
        prop_oneof![Just(1.0f32), 1e-20f32..1e20],
    )
        .prop_filter("non-zero", |(x, y, z, _)| x * x + y * y + z * z > 1e-6)
        .prop_map(|(x, y, z, s)| [x * s, y * s, z * s])
}

/// A band count in 1..=30, one in four from 13 up (where the references' quadratures cost
/// most).
fn some_to_30() -> impl Strategy<Value = usize> {
    prop_oneof![3 => 1usize..=12, 1 => 13usize..=30]
}

/// `bands²` coefficients uniform in `[−1, 1)` from `seed`.
fn coefficients(bands: usize, seed: u64) -> Vec<f32> {
    let mut rng = steradian_harness::rng::Rng::new(seed);
    (0..bands * bands)
        .map(|_| rng.range(-1.0, 1.0) as f32)
        .collect()
}

fn unit64(d: [f32; 3]) -> [f64; 3] {
    let d = d.map(f64::from);
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    d.map(|x| x / n)
}

fn numbers(v: &Value, key: &str) -> Vec<f64> {
    v[key]
        .as_array()
        .unwrap_or_else(|| panic!("{v}"))
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn band(i: usize) -> usize {
    (i as f64).sqrt() as usize
}

/// The nearest rotation to `m` (rows), by the polar iteration `X ← ½(X + X⁻ᵀ)` in `f64`.
fn polar(m: [[f32; 3]; 3]) -> [[f64; 3]; 3] {
    let mut x = m.map(|r| r.map(f64::from));
    for _ in 0..6 {
        let c = |i: usize, j: usize| {
            let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
            x[i1][j1] * x[i2][j2] - x[i1][j2] * x[i2][j1]
        };
        let det: f64 = (0..3).map(|j| x[0][j] * c(0, j)).sum();
        // X⁻ᵀ = cofactor matrix / det.
        let inv_t: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| c(i, j) / det));
        x = std::array::from_fn(|i| std::array::from_fn(|j| 0.5 * (x[i][j] + inv_t[i][j])));
    }
    x
}

/// A rotation matrix (rows, `f32`) from an axis and an angle by Rodrigues' formula.
fn rotation(axis: [f32; 3], angle: f32) -> [[f32; 3]; 3] {
    let a = unit64(axis);
    let (s, c) = f64::from(angle).sin_cos();
    let k = [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]];
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let id = if i == j { 1.0 } else { 0.0 };
            let kk: f64 = (0..3).map(|t| k[i][t] * k[t][j]).sum();
            (id + s * k[i][j] + (1.0 - c) * kk) as f32
        })
    })
}

proptest! {
    #![proptest_config(config(300))]

    #[test]
    fn sh_eval_within_bound(d in direction(), bands in 1usize..=30) {
        let v = eval_line("sh-eval", &json!({"dir": d, "bands": bands}).to_string()).unwrap();
        let y = numbers(&v, "y");
        let want = reference::eval(unit64(d), bands);
        prop_assert_eq!(y.len(), bands * bands);
        for (i, (g, w)) in y.iter().zip(&want).enumerate() {
            prop_assert!((g - w).abs() <= f64::from(sh::eval_abs_error(band(i))),
                "{:?} n {} i {}: {} vs {}", d, bands, i, g, w);
        }
    }

    #[test]
    fn sh_rotate_within_bound(
        axis in direction(), angle in -7.0f32..7.0, bands in some_to_30(),
        seed in any::<u64>(),
    ) {
        let c = coefficients(bands, seed);
        let r = rotation(axis, angle);
        let v = eval_line("sh-rotate", &json!({"coeffs": c, "rotation": r}).to_string()).unwrap();
        let got = numbers(&v, "coeffs");
        let want = reference::rotate(&c.iter().map(|&x| f64::from(x)).collect::<Vec<_>>(), polar(r));
        let err: f64 = got.iter().zip(&want).map(|(g, w)| (g - w).powi(2)).sum::<f64>().sqrt();
        let norm: f64 = c.iter().map(|&x| f64::from(x).powi(2)).sum::<f64>().sqrt();
        prop_assert!(err <= f64::from(sh::rotate::rotate_rel_error(bands)) * norm,
            "n {}: {} of {}", bands, err, norm);
    }
}

proptest! {
    #![proptest_config(config(120))]

    #[test]
    fn sh_cap_within_bound(d in direction(), lg in -4.0f64..std::f64::consts::PI.log10(),
                           bands in 1usize..=30) {
        let a = 10f64.powf(lg) as f32;
        let v = eval_line("sh-cap", &json!({"dir": d, "half_angle": a, "bands": bands}).to_string())
            .unwrap();
        let got = numbers(&v, "coeffs");
        let zonal = reference::cap_zonal(f64::from(a), bands);
        let y = reference::eval(unit64(d), bands);
        let omega = 2.0 * std::f64::consts::PI * (1.0 - f64::from(a).cos());
        for (i, g) in got.iter().enumerate() {
            let l = band(i);
            let k = (4.0 * std::f64::consts::PI / (2 * l + 1) as f64).sqrt();
            let want = k * y[i] * zonal[l];
            let bound = f64::from(sh::eval_abs_error(l)) * k * zonal[l].abs()
                + f64::from(sh::cap::ZONAL_REL_ERROR) * want.abs() * 2.0
                + 1e-9 * omega;
            prop_assert!((g - want).abs() <= bound, "a {} n {} i {}: {} vs {}", a, bands, i, g, want);
        }
    }

    #[test]
    fn sh_irradiance_within_bound(n in direction(), bands in some_to_30(), seed in any::<u64>()) {
        let c = coefficients(bands, seed);
        let v = eval_line("sh-irradiance", &json!({"coeffs": c, "normal": n}).to_string()).unwrap();
        let got = v["irradiance"].as_f64().unwrap();
        let want = reference::irradiance(&c.iter().map(|&x| f64::from(x)).collect::<Vec<_>>(), unit64(n));
        let sum: f64 = c.iter().map(|&x| f64::from(x).abs()).sum();
        prop_assert!((got - want).abs() <= 1e-6 * sum, "{} vs {}", got, want);
    }
}

#[test]
fn bad_lines_of_the_sh_kernels() {
    let bad = [
        ("sh-eval", r#"{"dir": [0, 0, 0], "bands": 3}"#),
        ("sh-eval", r#"{"dir": [0, 0, 1], "bands": 0}"#),
        ("sh-eval", r#"{"dir": [0, 0, 1], "bands": 2.5}"#),
        (
            "sh-cap",
            r#"{"dir": [0, 0, 1], "half_angle": 4, "bands": 3}"#,
        ),
        (
            "sh-irradiance",
            r#"{"coeffs": [1, 2, 3], "normal": [0, 0, 1]}"#,
        ),
        ("sh-irradiance", r#"{"coeffs": [1], "normal": [0, 0, 0]}"#),
        (
            "sh-rotate",
            r#"{"coeffs": [1, 0, 0], "rotation": [[1,0,0],[0,1,0],[0,0,1]]}"#,
        ),
        (
            "sh-rotate",
            r#"{"coeffs": [1], "rotation": [[1,0,0],[0,1,0],[0,0,-1]]}"#,
        ),
        (
            "sh-rotate",
            r#"{"coeffs": [1], "rotation": [[1,0,0],[0,1,0],[0,0,1.0001]]}"#,
        ),
        (
            "sh-rotate",
            r#"{"coeffs": [1], "rotation": [[2,0,0],[0,0.5,0],[0,0,1]]}"#,
        ),
        (
            "sh-rotate",
            r#"{"coeffs": [1], "rotation": [[1,0,0],[0,1,0]]}"#,
        ),
        (
            "sh-rotate",
            r#"{"coeffs": [], "rotation": [[1,0,0],[0,1,0],[0,0,1]]}"#,
        ),
    ];
    for (k, line) in bad {
        assert!(eval_line(k, line).is_err(), "{k}: {line}");
    }
    // Within the tolerance: accepted.
    let ok = r#"{"coeffs": [1, 0, 0, 0], "rotation": [[1,0,0],[0,1,0],[0,0,1.000004]]}"#;
    assert!(eval_line("sh-rotate", ok).is_ok());
}

#[test]
fn the_peers_of_the_report_against_the_addition_theorem() {
    // The report's plain f64 evaluation is a correct baseline (it matches the reference), and
    // `sphrs` 0.2.2 breaks the addition theorem from 20 bands on (README).
    use steradian_harness::sh as study;
    for d in study::directions(16, 3) {
        let d = d.map(f64::from);
        for n in [3usize, 10, 20, 30] {
            let mut plain = vec![0.0; n * n];
            study::plain_eval(d, n, &study::plain_norms(n), &mut plain);
            let want = reference::eval(d, n);
            for (a, b) in plain.iter().zip(&want) {
                assert!((a - b).abs() < 1e-12, "{n}: {a} vs {b}");
            }
            let peer = study::sphrs_eval(&study::sphrs_set(n), d);
            let e = study::band_identity_error(&peer, n);
            if n <= 10 {
                assert!(e < 1e-12, "sphrs at {n} bands: {e}");
            }
        }
        let e20 = study::band_identity_error(&study::sphrs_eval(&study::sphrs_set(20), d), 20);
        assert!(e20.is_nan() || e20 >= 1.0, "sphrs at 20 bands: {e20}");
    }
}
