//! `cp-vertices` and `cp-query` through `eval`, on inputs the kernels' own tests do not use:
//! the answer is checked against the brute-force f64 scan of `steradian_reference::cp`.

use serde_json::{Value, json};
use steradian_harness::eval::eval_line;
use steradian_reference::cp as reference;

fn vertices(level: u32) -> Vec<[f64; 3]> {
    let v = eval_line("cp-vertices", &json!({ "level": level }).to_string()).unwrap();
    v["vertices"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let p: Vec<f64> = p
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            [p[0], p[1], p[2]]
        })
        .collect()
}

#[test]
fn vertices_are_unit_distinct_and_counted() {
    for level in 0..=4u32 {
        let v = vertices(level);
        assert_eq!(v.len(), 10 * 4usize.pow(level) + 2);
        for p in &v {
            assert!(((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 1.0).abs() < 1e-6);
        }
        // Nearest-neighbour spacing bounded away from zero: no duplicated vertex.
        let min = v
            .iter()
            .enumerate()
            .flat_map(|(i, p)| {
                v[i + 1..]
                    .iter()
                    .map(move |q| (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>())
            })
            .fold(f64::INFINITY, f64::min);
        assert!(
            min.sqrt() > 0.5 / (1 << level) as f64,
            "level {level}: {min}"
        );
    }
    for bad in [
        json!({"level": 5}),
        json!({"level": -1}),
        json!({"level": 1.5}),
        json!({}),
    ] {
        assert!(eval_line("cp-vertices", &bad.to_string()).is_err(), "{bad}");
    }
}

#[test]
fn query_matches_the_brute_force_interpolation() {
    let level = 3;
    let v = vertices(level);
    let mesh = steradian_core::cp::Icosphere::new(level).unwrap();
    let values: Vec<f64> = v.iter().map(|p| (3.0 * p[0]).sin() + p[1] * p[2]).collect();
    let dirs: Vec<[f64; 3]> = (0..300)
        .map(|i| {
            let t = i as f64 * 2.399_963;
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / 300.0;
            let r = (1.0 - z * z).sqrt();
            [r * t.cos() * 7.0, r * t.sin() * 7.0, z * 7.0]
        })
        .collect();
    let line = json!({ "level": level, "values": values, "dirs": dirs }).to_string();
    let out = eval_line("cp-query", &line).unwrap();
    let out: Vec<f64> = out["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    for (d, got) in dirs.iter().zip(out) {
        let (t, w) = reference::locate(&v, mesh.triangles(), *d);
        let want: f64 = mesh.triangles()[t]
            .iter()
            .zip(w)
            .map(|(k, w)| w * values[*k as usize])
            .sum();
        assert!((got - want).abs() < 1e-5, "{d:?}: {got} vs {want}");
    }
    let (v11, v12) = (vec![1.0; 11], vec![1.0; 12]);
    let bad = [
        json!({ "level": 0, "values": v11, "dirs": [[0, 0, 1]] }),
        json!({ "level": 0, "values": v12, "dirs": [[0, 0, 0]] }),
        json!({ "level": 0, "values": v12, "dirs": [[0, 0]] }),
        json!({ "level": 0, "values": v12, "dirs": [["x", 0, 1]] }),
    ];
    for b in bad {
        let e: Result<Value, String> = eval_line("cp-query", &b.to_string());
        assert!(e.is_err(), "{b}");
    }
}

/// Directions on a spiral, scaled to length `len` (the fit normalises them).
fn spiral(n: usize, len: f64) -> Vec<[f64; 3]> {
    (0..n)
        .map(|i| {
            let t = i as f64 * 2.399_963;
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            [r * t.cos() * len, r * t.sin() * len, z * len]
        })
        .collect()
}

fn fit_line(level: u32, samples: &[[f64; 4]]) -> Result<Vec<f64>, String> {
    let line = json!({ "level": level, "samples": samples }).to_string();
    let out = eval_line("cp-fit", &line)?;
    Ok(out["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect())
}

fn design(level: u32, samples: &[[f64; 4]]) -> steradian_core::cp::Design {
    let mesh = steradian_core::cp::Icosphere::new(level).unwrap();
    let dirs: Vec<steradian_core::Vec3> = samples
        .iter()
        .map(|s| steradian_core::Vec3::new(s[0] as f32, s[1] as f32, s[2] as f32))
        .collect();
    steradian_core::cp::Design::new(&mesh, &dirs).unwrap()
}

#[test]
fn fit_recovers_a_function_the_mesh_represents() {
    // Samples of the interpolant of known values: the least-squares minimiser is those
    // values (every triangle holds samples enough to pin its three vertices).
    let level = 2;
    let mesh = steradian_core::cp::Icosphere::new(level).unwrap();
    let truth: Vec<f32> = (0..mesh.vertices().len())
        .map(|k| ((k * 37 % 101) as f32 / 50.0) - 1.0)
        .collect();
    let samples: Vec<[f64; 4]> = spiral(4000, 3.0)
        .into_iter()
        .map(|d| {
            let v = mesh
                .query(
                    &truth,
                    steradian_core::Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32),
                    steradian_core::cp::Weights::Area,
                )
                .unwrap();
            [d[0], d[1], d[2], f64::from(v)]
        })
        .collect();
    let got = fit_line(level, &samples).unwrap();
    for (k, (g, t)) in got.iter().zip(&truth).enumerate() {
        assert!((g - f64::from(*t)).abs() < 2e-5, "vertex {k}: {g} vs {t}");
    }
}

#[test]
fn fit_residual_equals_the_svd_minimisers() {
    use steradian_harness::cp::{RESIDUAL_REL_ERROR, fit_dense_reference, residual};
    // A Phong-like lobe the mesh does not represent, on sample sets that over-determine,
    // barely determine and under-determine the values; the dense SVD pseudo-inverse is an
    // exact minimiser.
    let f = |d: [f64; 3]| {
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        (0.3 * d[0] + 0.5 * d[1] + 0.81 * d[2]).max(0.0).powi(8) / l.powi(8) + 0.1
    };
    let vertex_samples = |level: u32| -> Vec<[f64; 4]> {
        vertices(level)
            .into_iter()
            .map(|p| [p[0], p[1], p[2], f(p)])
            .collect()
    };
    let cases: Vec<(&str, u32, Vec<[f64; 4]>)> = vec![
        (
            "2000 samples, level 1",
            1,
            spiral(2000, 1.0)
                .into_iter()
                .map(|d| [d[0], d[1], d[2], f(d)])
                .collect(),
        ),
        (
            "3000 samples, level 2",
            2,
            spiral(3000, 0.01)
                .into_iter()
                .map(|d| [d[0], d[1], d[2], f(d)])
                .collect(),
        ),
        (
            "30 samples, level 2 (under-determined)",
            2,
            spiral(30, 1.0)
                .into_iter()
                .map(|d| [d[0], d[1], d[2], f(d)])
                .collect(),
        ),
        ("one sample per vertex, level 2", 2, vertex_samples(2)),
        (
            "the same direction twice with different values, level 0",
            0,
            vec![
                [0.2, 0.3, 0.9, 1.0],
                [0.2, 0.3, 0.9, 3.0],
                [-1.0, 0.1, 0.0, 2.0],
            ],
        ),
    ];
    for (name, level, samples) in cases {
        let got = fit_line(level, &samples).unwrap();
        let d = design(level, &samples);
        let values: Vec<f64> = samples.iter().map(|s| s[3] as f32 as f64).collect();
        let want = fit_dense_reference(&d, &values);
        let norm = values.iter().map(|v| v * v).sum::<f64>().sqrt();
        // The fit's values are printed in f32: compare residuals at f32-rounded values of
        // both, so that the rounding is not counted as excess.
        let round = |v: &[f64]| -> Vec<f64> { v.iter().map(|x| *x as f32 as f64).collect() };
        let (r_got, r_want) = (
            residual(&d, &got, &values),
            residual(&d, &round(&want), &values),
        );
        let exact = residual(&d, &want, &values);
        // The f64 fit itself: its excess residual is within the bound.
        let mesh = steradian_core::cp::Icosphere::new(level).unwrap();
        let rows: Vec<[f32; 4]> = samples.iter().map(|s| s.map(|x| x as f32)).collect();
        let inner = steradian_harness::cp::fit(&mesh, &rows).unwrap();
        let excess = (residual(&d, &inner, &values) - exact) / norm;
        assert!(
            excess <= RESIDUAL_REL_ERROR,
            "{name}: excess residual {excess:.2e} of ‖f‖"
        );
        // The printed (f32) values: no worse than the minimiser's rounded to f32, up to the
        // same bound.
        assert!(
            r_got - exact <= RESIDUAL_REL_ERROR * norm + 2.0 * (r_want - exact).abs() + 1e-12,
            "{name}: residual {r_got} against the minimiser's {exact} (f32-rounded {r_want})"
        );
        // Components the samples do not touch are zero.
        let touched: std::collections::HashSet<u32> =
            d.rows().iter().flat_map(|r| r.vertices).collect();
        for (k, v) in got.iter().enumerate() {
            if !touched.contains(&(k as u32)) {
                assert_eq!(*v, 0.0, "{name}: untouched vertex {k} is {v}");
            }
        }
    }
}

#[test]
fn fit_at_level_4_solves_the_normal_equations() {
    // No dense reference at 2562 unknowns: the gradient Aᵀ(A v − f) of the residual vanishes
    // at a minimiser (relative to ‖Aᵀf‖).
    let level = 4;
    let samples: Vec<[f64; 4]> = spiral(20_000, 1.0)
        .into_iter()
        .map(|d| [d[0], d[1], d[2], (5.0 * d[0]).sin() * d[2] + d[1]])
        .collect();
    let mesh = steradian_core::cp::Icosphere::new(level).unwrap();
    let rows: Vec<[f32; 4]> = samples.iter().map(|s| s.map(|x| x as f32)).collect();
    let v = steradian_harness::cp::fit(&mesh, &rows).unwrap();
    let d = design(level, &samples);
    let values: Vec<f64> = rows.iter().map(|s| f64::from(s[3])).collect();
    let av = d.apply(&v).unwrap();
    let r: Vec<f64> = av.iter().zip(&values).map(|(a, f)| a - f).collect();
    let grad = d.project(&r).unwrap();
    let atf = d.project(&values).unwrap();
    let n = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>().sqrt();
    assert!(n(&grad) <= 1e-10 * n(&atf), "{} vs {}", n(&grad), n(&atf));
}

#[test]
fn fit_bad_lines_and_edge_cases() {
    // No samples: every vertex is undetermined, so 0.
    let v = fit_line(1, &[]).unwrap();
    assert_eq!(v, vec![0.0; 42]);
    // Huge values stay finite and exact where determined.
    let big = fit_line(0, &[[0.0, 0.0, 1.0, 1e38]]).unwrap();
    assert!(big.iter().all(|x| x.is_finite()));
    for bad in [
        json!({ "level": 5, "samples": [] }),
        json!({ "level": 0 }),
        json!({ "level": 0, "samples": 3 }),
        json!({ "level": 0, "samples": [[0, 0, 1]] }),
        json!({ "level": 0, "samples": [[0, 0, 0, 1]] }),
        json!({ "level": 0, "samples": [[0, 0, 1, "x"]] }),
        json!({ "level": 0, "samples": [[0, 0, 1, 1e39]] }),
    ] {
        let e: Result<Value, String> = eval_line("cp-fit", &bad.to_string());
        assert!(e.is_err(), "{bad}");
    }
}

#[test]
fn brute_force_baseline_agrees_with_the_o1_query() {
    // The report's and the bench's speed baseline must answer the same question.
    for level in 0..=3u32 {
        let mesh = steradian_core::cp::Icosphere::new(level).unwrap();
        let values: Vec<f32> = (0..mesh.vertices().len())
            .map(|k| (k as f32 * 0.618).fract())
            .collect();
        let brute = steradian_harness::cp::BruteForce::new(&mesh);
        for d in spiral(500, 2.0) {
            let d = steradian_core::Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
            let a = mesh
                .query(&values, d, steradian_core::cp::Weights::Area)
                .unwrap();
            let b = brute.query(&values, d);
            assert!((a - b).abs() < 1e-5, "level {level}, {d}: {a} vs {b}");
        }
    }
}

#[test]
fn linf_fits_are_optimal_and_exact_where_the_mesh_represents() {
    use steradian_harness::cp::{Linf, fit_dense_reference, fit_linf};
    let level = 1;
    let mesh = steradian_core::cp::Icosphere::new(level).unwrap();
    let samples: Vec<[f64; 4]> = spiral(600, 1.0)
        .into_iter()
        .map(|d| {
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            [
                d[0],
                d[1],
                d[2],
                0.1 + (0.6 * d[0] + 0.8 * d[2]).max(0.0).powi(6) / l.powi(6),
            ]
        })
        .collect();
    let d = design(level, &samples);
    let values: Vec<f64> = samples.iter().map(|s| s[3]).collect();
    let ls = fit_dense_reference(&d, &values);
    let max_err = |v: &[f64], scale: &dyn Fn(f64) -> f64| {
        d.apply(v)
            .unwrap()
            .iter()
            .zip(&values)
            .map(|(a, f)| (a - f).abs() / scale(*f))
            .fold(0.0f64, f64::max)
    };
    for kind in Linf::ALL {
        let (v, h) = fit_linf(&d, &values, kind).unwrap();
        let scale = |f: f64| match kind {
            Linf::Absolute => 1.0,
            Linf::Relative => f.abs(),
            Linf::SqrtRelative => f.abs().sqrt(),
        };
        // The optimum h is the fit's own worst scaled residual, and no larger than the
        // least-squares fit's (which the linear program could have chosen).
        let own = max_err(&v, &scale);
        assert!(
            (own - h).abs() <= 1e-6 * h.max(1e-12),
            "{kind:?}: h {h} vs {own}"
        );
        assert!(h <= max_err(&ls, &scale) * (1.0 + 1e-9), "{kind:?}");
    }
    // Samples of the interpolant itself: every L∞ fit reproduces it (h = 0, the values).
    let truth: Vec<f32> = (0..mesh.vertices().len())
        .map(|k| 1.0 + (k % 5) as f32 * 0.25)
        .collect();
    let exact: Vec<f64> = d
        .apply(&truth.iter().map(|t| f64::from(*t)).collect::<Vec<_>>())
        .unwrap();
    for kind in Linf::ALL {
        let (v, h) = fit_linf(&d, &exact, kind).unwrap();
        assert!(h < 1e-9, "{kind:?}: h = {h}");
        for (a, b) in v.iter().zip(&truth) {
            assert!((a - f64::from(*b)).abs() < 1e-6, "{kind:?}: {a} vs {b}");
        }
    }
}

#[test]
fn transport_benchmark_agrees_between_representations() {
    // The section 3.5 benchmark computes the same irradiance with control points and SH,
    // up to their representation errors; the lit scene has positive, finite irradiance.
    use steradian_harness::report::cp_transport::{
        ControlPoints, Harmonics, Scene, Visibility, run,
    };
    let scene = Scene::cubes();
    let vis = Visibility::new(&scene, 45);
    assert!(vis.links() > 0);
    let (_, a) = run(&ControlPoints::new(2), &scene, &vis);
    let (_, b) = run(&Harmonics::new(8), &scene, &vis);
    assert_eq!(a.len(), scene.surfaces());
    assert!(a.iter().chain(&b).all(|e| e.is_finite() && *e >= 0.0));
    let max = b.iter().fold(0.0f64, |m, v| m.max(*v));
    assert!(max > 0.0);
    let lit: Vec<(f64, f64)> = a
        .iter()
        .zip(&b)
        .filter(|(_, y)| **y > 1e-3 * max)
        .map(|(x, y)| (*x, *y))
        .collect();
    let mean = lit.iter().map(|(x, y)| (x - y).abs() / y).sum::<f64>() / lit.len() as f64;
    assert!(
        lit.len() > scene.surfaces() / 2 && mean < 0.05,
        "{} lit, mean rel. diff {mean}",
        lit.len()
    );
}
