//! The JSON helpers of `steradian eval`: reading validated numbers and vectors from an input
//! line, and printing an `f32` as the shortest decimal that reads back to it. Every eval
//! kernel parses its line with these, so a bad line gets the same kind of message whatever
//! the kernel.

use serde_json::{Map, Value};
use steradian_core::Vec3;

/// An f32 as a JSON number with the shortest round-tripping decimal.
pub fn num(x: f32) -> Value {
    let short: f64 = format!("{x}").parse().unwrap_or(f64::NAN);
    serde_json::Number::from_f64(short).map_or(Value::Null, Value::Number)
}

/// Field `name` of `obj`, or the error message for a missing field.
pub fn field<'a>(obj: &'a Map<String, Value>, name: &str) -> Result<&'a Value, String> {
    obj.get(name)
        .ok_or_else(|| format!("missing field \"{name}\""))
}

/// The one number parser of `eval`: `v` as a finite `f32`, or the message `not_a_number`
/// (when `v` is not a JSON number) or `non_finite(x)` (when it overflows `f32`) gives.
/// The helpers below and the kernels' own parsers (`sat-box`, `vdt-box`) differ only in
/// their messages.
pub fn parse_f32(
    v: &Value,
    not_a_number: impl FnOnce() -> String,
    non_finite: impl FnOnce(f64) -> String,
) -> Result<f32, String> {
    let x = v.as_f64().ok_or_else(not_a_number)?;
    let f = x as f32;
    if !f.is_finite() {
        return Err(non_finite(x));
    }
    Ok(f)
}

/// `v` as a finite `f32`; `name` is the field it came from.
pub fn finite_f32(v: &Value, name: &str) -> Result<f32, String> {
    parse_f32(
        v,
        || format!("field \"{name}\" must be a number"),
        |x| format!("field \"{name}\" = {x} is not a finite f32"),
    )
}

/// Field `name` of `obj` as a finite f32, or the error message for the line.
pub fn number(obj: &Map<String, Value>, name: &str) -> Result<f32, String> {
    finite_f32(field(obj, name)?, name)
}

/// Field `name` of `obj` as `N` finite `f32`s.
pub fn vector<const N: usize>(obj: &Map<String, Value>, name: &str) -> Result<[f32; N], String> {
    let arr = field(obj, name)?
        .as_array()
        .ok_or_else(|| format!("field \"{name}\" must be an array of {N} numbers"))?;
    if arr.len() != N {
        return Err(format!(
            "field \"{name}\" must have {N} components, got {}",
            arr.len()
        ));
    }
    let mut out = [0f32; N];
    for (o, v) in out.iter_mut().zip(arr) {
        *o = finite_f32(v, name)?;
    }
    Ok(out)
}

/// `v` as a vector, or the error message if it is zero.
pub fn nonzero(v: [f32; 3], name: &str) -> Result<Vec3, String> {
    let v = Vec3::from(v);
    if v == Vec3::ZERO {
        return Err(format!("field \"{name}\" must not be the zero vector"));
    }
    Ok(v)
}

/// Field `"exponent"` as a finite `f32 ≥ 0`.
pub fn exponent(obj: &Map<String, Value>) -> Result<f32, String> {
    let e = number(obj, "exponent")?;
    if e < 0.0 {
        return Err(format!("exponent = {e} must be ≥ 0"));
    }
    Ok(e)
}

/// Field `"bands"` as an integer in `1..=max` (a JSON integer, or a number with no
/// fractional part).
pub fn bands(obj: &Map<String, Value>, max: usize) -> Result<usize, String> {
    let v = field(obj, "bands")?;
    let n = match v.as_u64() {
        Some(n) => n,
        None => match v.as_f64() {
            Some(x) if x.fract() == 0.0 && x >= 0.0 && x <= u64::MAX as f64 => x as u64,
            _ => return Err(format!("bands must be a positive integer, got {v}")),
        },
    };
    if n == 0 || n > max as u64 {
        return Err(format!("bands = {n} is outside 1..={max}"));
    }
    Ok(n as usize)
}

/// Field `"scale"` as a finite `f32`, 1 when absent.
pub fn scale(obj: &Map<String, Value>) -> Result<f32, String> {
    match obj.get("scale") {
        None => Ok(1.0),
        Some(v) => finite_f32(v, "scale"),
    }
}

/// An array element (or other value) as a finite `f32`; `what` names it in the error
/// (`queries[2][1] must be a number, got "x"`).
pub fn element_f32(v: &Value, what: &str) -> Result<f32, String> {
    parse_f32(
        v,
        || format!("{what} must be a number, got {v}"),
        |x| format!("{what} = {x} is not a finite f32"),
    )
}

/// Field `name` as a list of finite `f32`s; an element that is not one is named
/// (`values[3] must be a number, got "x"`).
pub fn numbers(obj: &Map<String, Value>, name: &str) -> Result<Vec<f32>, String> {
    field(obj, name)?
        .as_array()
        .ok_or_else(|| format!("{name} must be an array of numbers"))?
        .iter()
        .enumerate()
        .map(|(i, v)| element_f32(v, &format!("{name}[{i}]")))
        .collect()
}

/// Field `"coeffs"` as an SH coefficient vector: finite `f32`s, `n²` of them for a band count
/// `n` in `1..=max`. Returns the values and `n`.
pub fn sh_coeffs(obj: &Map<String, Value>, max: usize) -> Result<(Vec<f32>, usize), String> {
    let c = numbers(obj, "coeffs")?;
    let n = (c.len() as f64).sqrt() as usize;
    if n * n != c.len() || n == 0 || n > max {
        return Err(format!(
            "coeffs has {} values: not n² for a band count n in 1..={max}",
            c.len()
        ));
    }
    Ok((c, n))
}

/// Field `name` as a 3×3 matrix given by rows, `[[r00, r01, r02], [r10, …], […]]`, of finite
/// `f32`s.
pub fn matrix3(obj: &Map<String, Value>, name: &str) -> Result<[[f32; 3]; 3], String> {
    let rows = field(obj, name)?
        .as_array()
        .filter(|r| r.len() == 3)
        .ok_or_else(|| format!("field \"{name}\" must be 3 rows of 3 numbers"))?;
    let mut out = [[0.0f32; 3]; 3];
    for (i, (o, row)) in out.iter_mut().zip(rows).enumerate() {
        let row = row
            .as_array()
            .filter(|r| r.len() == 3)
            .ok_or_else(|| format!("{name}[{i}] must be a row of 3 numbers"))?;
        for (j, (e, v)) in o.iter_mut().zip(row).enumerate() {
            *e = element_f32(v, &format!("{name}[{i}][{j}]"))?;
        }
    }
    Ok(out)
}
