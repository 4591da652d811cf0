//! The `steradian eval` line layer on arbitrary bytes: for every registered eval kernel (the
//! first byte picks it), exactly one output line per non-blank input line, each a JSON
//! object with exactly one of the kernel's answer or `"error"`, no answer holding `null` (a
//! number that did not fit `f32`), and never a panic (a small line limit so that over-long
//! lines are exercised too).

use steradian_harness::{eval, registry};

/// The target's checks on one input.
pub fn check(data: &[u8]) {
    let Some((&pick, input)) = data.split_first() else {
        return;
    };
    let kernels: Vec<&str> = registry::KERNELS
        .iter()
        .filter(|k| k.eval.get().is_some())
        .map(|k| k.name)
        .collect();
    let kernel = kernels[pick as usize % kernels.len()];
    let mut out = Vec::new();
    let errors = eval::run_limited(kernel, input, &mut out, 4096).expect("in-memory I/O");
    // The expected count: lines split at \n, a last line without \n counts, blank ones
    // (after dropping a trailing \r, whitespace-only as UTF-8) are skipped.
    let mut want = 0;
    let mut parts: Vec<&[u8]> = input.split(|&b| b == b'\n').collect();
    if input.last() == Some(&b'\n') || input.is_empty() {
        parts.pop();
    }
    for p in parts {
        let p = p.strip_suffix(b"\r").unwrap_or(p);
        let blank = p.len() <= 4096 && std::str::from_utf8(p).is_ok_and(|t| t.trim().is_empty());
        if !blank {
            want += 1;
        }
    }
    let text = String::from_utf8(out).expect("output is UTF-8");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), want, "one answer per non-blank line");
    let mut seen_errors = 0;
    for l in lines {
        let v: serde_json::Value = serde_json::from_str(l).expect("each answer is JSON");
        let obj = v.as_object().expect("each answer is an object");
        if obj.contains_key("error") {
            assert_eq!(obj.len(), 1, "an error line holds only the error: {l}");
            seen_errors += 1;
        } else {
            assert!(!holds_null(&v), "an answer with a non-finite number: {l}");
        }
    }
    assert_eq!(seen_errors, errors);
}

/// Whether `v` holds a `null` anywhere.
fn holds_null(v: &serde_json::Value) -> bool {
    match v {
        serde_json::Value::Null => true,
        serde_json::Value::Array(a) => a.iter().any(holds_null),
        serde_json::Value::Object(o) => o.values().any(holds_null),
        _ => false,
    }
}
