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

use crate::registry;

/// Evaluates one input line of `kernel`; `Err` is the message for `{"error": ...}`.
pub fn eval_line(kernel: &str, line: &str) -> Result<Value, String> {
    let v: Value = serde_json::from_str(line).map_err(|e| format!("not JSON: {e}"))?;
    let obj = v
        .as_object()
        .ok_or_else(|| "each line must be a JSON object".to_string())?;
    match registry::find(kernel).and_then(|k| k.eval.get()) {
        Some(handler) => handler(obj),
        None => Err(format!("unknown kernel {kernel}")),
    }
}

/// Whether `eval` has a handler for `kernel`.
pub fn accepts(kernel: &str) -> bool {
    registry::find(kernel).is_some_and(|k| k.eval.get().is_some())
}

/// The help text: every kernel `eval` accepts with its input and output (from the registry).
pub fn help() -> String {
    let mut s = String::from("Kernels:\n");
    for k in registry::KERNELS {
        if k.eval.get().is_some() {
            s += &format!("  {:<17} {}\n", k.name, k.contract);
        }
    }
    s + "A bad line gets {\"error\": \"...\"} and the run goes on; the exit status is 1 if any line erred."
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
    use crate::json::num;

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
