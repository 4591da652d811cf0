//! `steradian eval KERNEL`: JSON Lines in, JSON Lines out.
//!
//! Each input line is user data and is validated like every public constructor: a line
//! that is not UTF-8, longer than [`MAX_LINE_BYTES`], not a JSON object, a missing or
//! mistyped field, a vector of the wrong length, a non-finite number, a zero direction, a
//! negative exponent, an angle outside the kernel's domain, a disk point outside the unit
//! disk, or a result that overflows `f32` yields `{"error": "..."}` for that line and the
//! run goes on. Lines end at `\n` (a
//! `\r` before it is dropped); a last line without `\n` counts; an empty or
//! whitespace-only line is skipped (no output line). Input is read as bytes, so no byte
//! sequence stops the run; only an I/O error of the streams does. Numbers are printed as
//! the shortest decimal that reads back to the same `f32`.

use std::io::{BufRead, Write};

use serde_json::{Value, json};

use crate::registry;

/// Evaluates one input line of `kernel`; `Err` is the message for `{"error": ...}`.
pub fn eval_line(kernel: &str, line: &str) -> Result<Value, String> {
    let v: Value = serde_json::from_str(line).map_err(|e| format!("not JSON: {e}"))?;
    let obj = v
        .as_object()
        .ok_or_else(|| "each line must be a JSON object".to_string())?;
    let out = match registry::find(kernel).and_then(|k| k.eval.get()) {
        Some(handler) => handler(obj)?,
        None => return Err(format!("unknown kernel {kernel}")),
    };
    match first_null(&out, String::new()) {
        Some(at) => Err(format!(
            "the result {at} is not a finite f32 (it overflows f32's range)"
        )),
        None => Ok(out),
    }
}

/// The path of the first `null` in `v` (where `json::num` wrote a non-finite `f32`), such
/// as `coeffs[3]`: no handler answers `null` on purpose, so a `null` is a result that
/// overflowed, and the line is a bad line rather than an answer with a hole in it.
fn first_null(v: &Value, at: String) -> Option<String> {
    match v {
        Value::Null => Some(at),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| first_null(x, format!("{at}[{i}]"))),
        Value::Object(o) => o.iter().find_map(|(k, x)| {
            first_null(
                x,
                if at.is_empty() {
                    k.clone()
                } else {
                    format!("{at}.{k}")
                },
            )
        }),
        _ => None,
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

/// The longest input line `eval` reads (256 MiB); a longer line is a bad line, read past
/// without being held in memory.
pub const MAX_LINE_BYTES: usize = 256 << 20;

/// One line of the input as `eval` sees it.
#[derive(Debug, PartialEq)]
pub enum Line<'a> {
    /// The line's text (no `\n`, no trailing `\r`).
    Text(&'a str),
    /// The line is not UTF-8; `valid_up_to` bytes are.
    NotUtf8 {
        /// Length of the valid prefix.
        valid_up_to: usize,
    },
    /// The line has more than the limit's bytes (its length).
    TooLong(usize),
}

/// Reads the next line of `input` into `buf` (cleared first; at most `limit` bytes kept),
/// `None` at the end of the input.
pub fn next_line<'b>(
    input: &mut impl BufRead,
    buf: &'b mut Vec<u8>,
    limit: usize,
) -> std::io::Result<Option<Line<'b>>> {
    buf.clear();
    let (mut total, mut any) = (0usize, false);
    loop {
        let avail = input.fill_buf()?;
        if avail.is_empty() {
            break;
        }
        any = true;
        let (chunk, used, done) = match avail.iter().position(|&b| b == b'\n') {
            Some(i) => (&avail[..i], i + 1, true),
            None => (avail, avail.len(), false),
        };
        total = total.saturating_add(chunk.len());
        if total <= limit {
            buf.extend_from_slice(chunk);
        } else {
            buf.clear();
        }
        input.consume(used);
        if done {
            break;
        }
    }
    if !any {
        return Ok(None);
    }
    if total > limit {
        return Ok(Some(Line::TooLong(total)));
    }
    if buf.last() == Some(&b'\r') {
        buf.pop();
    }
    Ok(Some(match std::str::from_utf8(buf) {
        Ok(t) => Line::Text(t),
        Err(e) => Line::NotUtf8 {
            valid_up_to: e.valid_up_to(),
        },
    }))
}

/// Runs `kernel` over every line of `input` (module docs), writing one JSON line per
/// non-blank input line. Returns the number of lines that erred.
pub fn run(kernel: &str, input: impl BufRead, output: impl Write) -> std::io::Result<usize> {
    run_limited(kernel, input, output, MAX_LINE_BYTES)
}

/// [`run`] with another line-length limit (the tests use a small one).
pub fn run_limited(
    kernel: &str,
    mut input: impl BufRead,
    mut output: impl Write,
    limit: usize,
) -> std::io::Result<usize> {
    let mut errors = 0;
    let mut buf = Vec::new();
    while let Some(line) = next_line(&mut input, &mut buf, limit)? {
        let answer = match line {
            Line::Text(t) if t.trim().is_empty() => continue,
            Line::Text(t) => eval_line(kernel, t),
            Line::NotUtf8 { valid_up_to } => Err(format!(
                "the line is not UTF-8 (invalid byte after {valid_up_to} valid bytes)"
            )),
            Line::TooLong(n) => Err(format!(
                "the line has {n} bytes, more than the limit of {limit}"
            )),
        };
        let out = answer.unwrap_or_else(|e| {
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
    fn results_that_overflow_f32_are_bad_lines() {
        // 2π·3e38, a rotation that adds two coefficients of 3e38, an irradiance of two.
        for (kernel, line, at) in [
            (
                "lobe-integral",
                r#"{"exponent": 0, "scale": 3e38}"#,
                "integral",
            ),
            (
                "sh-rotate",
                r#"{"coeffs": [0, 3e38, 0, 3e38], "rotation": [[0.70710678, -0.70710678, 0], [0.70710678, 0.70710678, 0], [0, 0, 1]]}"#,
                "coeffs[",
            ),
            (
                "sh-irradiance",
                r#"{"coeffs": [3e38, 0, 3e38, 0], "normal": [0, 0, 1]}"#,
                "irradiance",
            ),
        ] {
            let v = one(kernel, line);
            let e = v["error"]
                .as_str()
                .unwrap_or_else(|| panic!("{kernel}: {v}"));
            assert!(e.contains(at) && e.contains("overflows"), "{kernel}: {e}");
        }
        // The same kernels just below overflow answer in full.
        let v = one("lobe-integral", r#"{"exponent": 0, "scale": 5e37}"#);
        assert!(v["integral"].is_number(), "{v}");
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

    /// Bytes that are not UTF-8, a line over the limit, CRLF, blank lines and a last line
    /// without a newline: one answer per non-blank line, the run goes on.
    #[test]
    fn any_bytes_one_answer_per_line() {
        let mut input: Vec<u8> = Vec::new();
        input.extend_from_slice(b"{\"half_angle\": 0.5}\n");
        input.extend_from_slice(b"{\"x\": \"\xff\"}\n");
        input.extend_from_slice(b"\n   \n");
        input.extend_from_slice(b"{\"half_angle\": 0.25}\r\n");
        input.extend_from_slice(&[b'7'; 100]);
        input.extend_from_slice(b"\n\xc3\n{\"half_angle\": 0.125}");
        let mut out = Vec::new();
        let errors = run_limited("cap-exponent", input.as_slice(), &mut out, 64).unwrap();
        let lines: Vec<Value> = String::from_utf8(out)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(lines.len(), 6, "{lines:?}");
        assert_eq!(errors, 3);
        assert!(lines[0]["exponent"].is_number());
        assert!(lines[1]["error"].as_str().unwrap().contains("not UTF-8"));
        assert!(lines[2]["exponent"].is_number());
        assert!(lines[3]["error"].as_str().unwrap().contains("100 bytes"));
        assert!(lines[4]["error"].as_str().unwrap().contains("not UTF-8"));
        assert!(lines[5]["exponent"].is_number());
    }

    #[test]
    fn next_line_splits_and_limits() {
        let mut input: &[u8] = b"ab\r\n\ncd";
        let mut buf = Vec::new();
        assert_eq!(
            next_line(&mut input, &mut buf, 8).unwrap(),
            Some(Line::Text("ab"))
        );
        assert_eq!(
            next_line(&mut input, &mut buf, 8).unwrap(),
            Some(Line::Text(""))
        );
        assert_eq!(
            next_line(&mut input, &mut buf, 8).unwrap(),
            Some(Line::Text("cd"))
        );
        assert_eq!(next_line(&mut input, &mut buf, 8).unwrap(), None);
        let mut long: &[u8] = b"0123456789\nx";
        assert_eq!(
            next_line(&mut long, &mut buf, 4).unwrap(),
            Some(Line::TooLong(10))
        );
        assert!(buf.is_empty(), "a long line is not kept");
        assert_eq!(
            next_line(&mut long, &mut buf, 4).unwrap(),
            Some(Line::Text("x"))
        );
    }
}
