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
