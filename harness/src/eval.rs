//! `steradian eval KERNEL`: JSON Lines in, JSON Lines out.
//!
//! Each input line is user data and is validated like every public constructor: a line
//! that is not a JSON object, a missing or mistyped field, a vector of the wrong length,
//! a non-finite number, a zero direction, a negative exponent, an angle outside the kernel's
//! domain or a disk point outside the unit disk yields `{"error": "..."}` for that line
//! and the run goes on. Numbers are printed as the shortest decimal that reads back to the
//! same `f32`.

use std::io::{BufRead, Write};

use serde_json::{Value, json};
use steradian_core::{Vec2, lobe, lobe::cap, rsl::hemisphere};

use crate::json::{exponent, nonzero, num, number, scale, vector};

/// The kernels `eval` accepts, with their input and output, for `--help` and errors.
pub const KERNELS: &[(&str, &str)] = &[
    (
        "lobe-integral",
        r#"{"exponent": e, "scale": s (default 1)} -> {"integral": 2πs/(e+1)}"#,
    ),
    (
        "lobe-eval",
        r#"{"axis": [x,y,z], "exponent": e, "scale": s (default 1), "dir": [x,y,z]} -> {"value": s·max(a·v,0)^e}"#,
    ),
    (
        "cap-exponent",
        r#"{"half_angle": α in [1e-18, π/2]} -> {"exponent": e} (L2 fit, from the table)"#,
    ),
    (
        "hemisphere-map",
        r#"{"dir": [x,y,z] with z ≥ 0, any non-zero length} -> {"p": [u,v]}"#,
    ),
    (
        "hemisphere-unmap",
        r#"{"p": [u,v] with u²+v² ≤ 1} -> {"dir": [x,y,z]}"#,
    ),
    (
        "lobe-product",
        r#"{"e1": e1, "e2": e2, "alpha": α} -> {"scale": p, "exponent": e_r, "axis_angle": β, "integral": 2πp/(e_r+1)} (unit lobes, a1 = +z, a2 toward +x)"#,
    ),
    (
        "sat-box",
        r#"{"grid": [[t00, t10, …], …] (rows in v), "queries": [[u0, v0, u1, v1], …] (texel units)} -> {"values": [∫ over each box]}"#,
    ),
    (
        "vdt-box",
        r#"{"mask": ["0110…", …] rows of '0'/'1' ('1' visible, row j along v), "queries": [[u, v, r], …] centre and half-diagonal in texel units} -> {"values": [visible fraction, eq. 9], "values_gradient": [straight-edge variant]}"#,
    ),
];

/// Evaluates one input line of `kernel`; `Err` is the message for `{"error": ...}`.
pub fn eval_line(kernel: &str, line: &str) -> Result<Value, String> {
    let v: Value = serde_json::from_str(line).map_err(|e| format!("not JSON: {e}"))?;
    let obj = v
        .as_object()
        .ok_or_else(|| "each line must be a JSON object".to_string())?;
    match kernel {
        "sat-box" => crate::sat::eval_sat_box(obj),
        "lobe-product" => crate::product::eval_lobe_product(obj),
        "lobe-integral" => {
            let (e, s) = (exponent(obj)?, scale(obj)?);
            Ok(json!({ "integral": num(lobe::integral(e, s)) }))
        }
        "lobe-eval" => {
            let l = lobe::CosineLobe::new(
                nonzero(vector::<3>(obj, "axis")?, "axis")?,
                scale(obj)?,
                exponent(obj)?,
            )
            .map_err(|e| e.to_string())?;
            let d =
                steradian_core::frame::normalize_or_zero(nonzero(vector::<3>(obj, "dir")?, "dir")?);
            Ok(json!({ "value": num(l.eval(d)) }))
        }
        "cap-exponent" => {
            let a = number(obj, "half_angle")?;
            let (lo, hi) = cap::DOMAIN;
            if !(lo..=hi).contains(&a) {
                return Err(format!(
                    "half_angle = {a} is outside [{lo:e}, {hi}] (radians)"
                ));
            }
            Ok(json!({ "exponent": num(cap::exponent_l2(a)) }))
        }
        "hemisphere-map" => {
            let d = nonzero(vector::<3>(obj, "dir")?, "dir")?;
            if d.z < 0.0 {
                return Err(format!("dir has z = {} < 0: below the hemisphere", d.z));
            }
            let p = hemisphere::map(d);
            Ok(json!({ "p": [num(p.x), num(p.y)] }))
        }
        "hemisphere-unmap" => {
            let [u, v] = vector::<2>(obj, "p")?;
            let r2 = u as f64 * u as f64 + v as f64 * v as f64;
            if r2 > 1.0 {
                return Err(format!(
                    "p = [{u}, {v}] is outside the unit disk (|p|² = {r2})"
                ));
            }
            let d = hemisphere::unmap(Vec2::new(u, v));
            Ok(json!({ "dir": [num(d.x), num(d.y), num(d.z)] }))
        }
        "vdt-box" => crate::vdt::eval_vdt_box(obj),
        other => Err(format!("unknown kernel {other}")),
    }
}

/// Runs `kernel` over every line of `input`, writing one JSON line per input line (blank
/// lines are skipped). Returns the number of lines that erred.
pub fn run(kernel: &str, input: impl BufRead, mut output: impl Write) -> std::io::Result<usize> {
    let mut errors = 0;
    for line in input.lines() {
        let line = line?;
        if line.trim().is_empty() {
            continue;
        }
        let out = eval_line(kernel, &line).unwrap_or_else(|e| {
            errors += 1;
            json!({ "error": e })
        });
        writeln!(output, "{out}")?;
    }
    output.flush()?;
    Ok(errors)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(kernel: &str, line: &str) -> Value {
        let mut out = Vec::new();
        run(kernel, line.as_bytes(), &mut out).unwrap();
        serde_json::from_slice(&out).unwrap()
    }

    #[test]
    fn good_lines() {
        assert_eq!(
            one("lobe-integral", r#"{"exponent": 1}"#),
            json!({"integral": num(std::f32::consts::PI)})
        );
        assert_eq!(
            one("lobe-integral", r#"{"exponent": 0, "scale": 2}"#)["integral"],
            json!(12.566371)
        );
        assert_eq!(
            one("hemisphere-map", r#"{"dir": [0, 0, 5]}"#),
            json!({"p": [0.0, 0.0]})
        );
        assert_eq!(
            one("hemisphere-unmap", r#"{"p": [0, 0]}"#),
            json!({"dir": [0.0, 0.0, 1.0]})
        );
        let e = one("cap-exponent", r#"{"half_angle": 1.5707963267948966}"#);
        assert_eq!(e, json!({"exponent": 0.0}));
        let v = one(
            "lobe-eval",
            r#"{"axis": [0,0,1], "exponent": 2, "dir": [0, 0.6, 0.8]}"#,
        );
        assert!((v["value"].as_f64().unwrap() - 0.64).abs() < 1e-6);
    }

    #[test]
    fn bad_lines_are_errors_and_the_run_goes_on() {
        let input = "not json\n{\"exponent\": -1}\n{\"exponent\": \"x\"}\n{}\n[1]\n{\"exponent\": 1e300}\n{\"exponent\": 3}\n";
        let mut out = Vec::new();
        let errors = run("lobe-integral", input.as_bytes(), &mut out).unwrap();
        assert_eq!(errors, 6);
        let lines: Vec<Value> = String::from_utf8(out)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(lines.len(), 7);
        for l in &lines[..6] {
            assert!(l["error"].is_string(), "{l}");
        }
        assert!(lines[6]["integral"].is_number());
        for (k, line) in [
            ("hemisphere-map", r#"{"dir": [0, 0, 0]}"#),
            ("hemisphere-map", r#"{"dir": [0, 0]}"#),
            ("hemisphere-map", r#"{"dir": [0, 0.1, -1]}"#),
            ("hemisphere-unmap", r#"{"p": [0.8, 0.7]}"#),
            ("hemisphere-unmap", r#"{"p": [0.8, null]}"#),
            ("cap-exponent", r#"{"half_angle": 0}"#),
            ("cap-exponent", r#"{"half_angle": 2}"#),
            ("cap-exponent", r#"{"angle": 0.1}"#),
            (
                "lobe-eval",
                r#"{"axis": [0,0,0], "exponent": 1, "dir": [0,0,1]}"#,
            ),
        ] {
            assert!(eval_line(k, line).is_err(), "{k} {line}");
        }
    }
}
