//! The `steradian eval` handlers of the kernels that need no table of the caller: one
//! function per kernel, a validated input line in, its JSON answer out. The table-driven
//! kernels keep theirs beside their harness code (`product`, `sat`, `vdt`); the registry
//! (`crate::registry`) names each kernel's handler.

use serde_json::{Map, Value, json};
use steradian_core::{Vec2, Vec3, cp, lobe, lobe::cap, rsl::hemisphere, sh};

use crate::json::{bands, exponent, matrix3, nonzero, num, number, scale, sh_coeffs, vector};

/// `lobe-integral`: `{"exponent": e, "scale": s}` → `{"integral": 2πs/(e+1)}`.
pub fn lobe_integral(obj: &Map<String, Value>) -> Result<Value, String> {
    let (e, s) = (exponent(obj)?, scale(obj)?);
    Ok(json!({ "integral": num(lobe::integral(e, s)) }))
}

/// `lobe-eval`: `{"axis", "exponent", "scale", "dir"}` → `{"value": s·max(a·v, 0)^e}`.
pub fn lobe_eval(obj: &Map<String, Value>) -> Result<Value, String> {
    let l = lobe::CosineLobe::new(
        nonzero(vector::<3>(obj, "axis")?, "axis")?,
        scale(obj)?,
        exponent(obj)?,
    )
    .map_err(|e| e.to_string())?;
    let d = steradian_core::frame::normalize_or_zero(nonzero(vector::<3>(obj, "dir")?, "dir")?);
    Ok(json!({ "value": num(l.eval(d)) }))
}

/// `cap-exponent`: `{"half_angle": α}` → `{"exponent": e}` (the table's L2 fit).
pub fn cap_exponent(obj: &Map<String, Value>) -> Result<Value, String> {
    let a = number(obj, "half_angle")?;
    let (lo, hi) = cap::DOMAIN;
    if !(lo..=hi).contains(&a) {
        return Err(format!(
            "half_angle = {a} is outside [{lo:e}, {hi}] (radians)"
        ));
    }
    Ok(json!({ "exponent": num(cap::exponent_l2(a)) }))
}

/// `hemisphere-map`: `{"dir": [x, y, z]}` (z ≥ 0) → `{"p": [u, v]}`.
pub fn hemisphere_map(obj: &Map<String, Value>) -> Result<Value, String> {
    let d = nonzero(vector::<3>(obj, "dir")?, "dir")?;
    if d.z < 0.0 {
        return Err(format!("dir has z = {} < 0: below the hemisphere", d.z));
    }
    let p = hemisphere::map(d);
    Ok(json!({ "p": [num(p.x), num(p.y)] }))
}

/// `hemisphere-unmap`: `{"p": [u, v]}` (inside the unit disk) → `{"dir": [x, y, z]}`.
pub fn hemisphere_unmap(obj: &Map<String, Value>) -> Result<Value, String> {
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

/// `sh-eval`: `{"dir": [x, y, z], "bands": n}` → `{"y": [n² values]}` (index `l² + l + m`).
pub fn sh_eval(obj: &Map<String, Value>) -> Result<Value, String> {
    let d = nonzero(vector::<3>(obj, "dir")?, "dir")?;
    let n = bands(obj, sh::MAX_BANDS)?;
    let mut y = vec![0.0f32; n * n];
    sh::eval_into(d, n, &mut y).map_err(|e| e.to_string())?;
    Ok(json!({ "y": y.into_iter().map(num).collect::<Vec<_>>() }))
}

/// `sh-cap`: `{"dir": [x, y, z], "half_angle": a, "bands": n}` → `{"coeffs": [n² values of
/// ∫_cap Y_l^m dω]}` (`a` in `[0, π]` radians).
pub fn sh_cap(obj: &Map<String, Value>) -> Result<Value, String> {
    let d = nonzero(vector::<3>(obj, "dir")?, "dir")?;
    let a = number(obj, "half_angle")?;
    let n = bands(obj, sh::MAX_BANDS)?;
    let mut c = vec![0.0f32; n * n];
    sh::cap::coefficients_into(d, a, n, &mut c).map_err(|e| e.to_string())?;
    Ok(json!({ "coeffs": c.into_iter().map(num).collect::<Vec<_>>() }))
}

/// `sh-irradiance`: `{"coeffs": [n² radiance coefficients], "normal": [x, y, z]}` →
/// `{"irradiance": E}`, `E = ∫ L(ω)·max(n·ω, 0) dω` (not divided by π).
pub fn sh_irradiance(obj: &Map<String, Value>) -> Result<Value, String> {
    let (c, _) = sh_coeffs(obj, sh::MAX_BANDS)?;
    let normal = nonzero(vector::<3>(obj, "normal")?, "normal")?;
    let mut scratch = vec![0.0f32; c.len()];
    let e = sh::irradiance::irradiance(&c, normal, &mut scratch).map_err(|e| e.to_string())?;
    Ok(json!({ "irradiance": num(e) }))
}

/// `sh-rotate`: `{"coeffs": [n² values], "rotation": [[r00, r01, r02], [r10, …], […]]}`
/// (rows; `max |RᵀR − I| ≤ 1e-5` and `det R > 0`) → `{"coeffs": [n² values]}` of
/// `g(ω) = f(Rᵀω)`, by the ZXZXZ path.
pub fn sh_rotate(obj: &Map<String, Value>) -> Result<Value, String> {
    let (c, n) = sh_coeffs(obj, sh::MAX_BANDS)?;
    let rot = sh::rotate::Rotation::new(matrix3(obj, "rotation")?).map_err(|e| e.to_string())?;
    let rotator = sh::rotate::Rotator::new(n).map_err(|e| e.to_string())?;
    let mut out = vec![0.0f32; c.len()];
    rotator
        .rotate(&rot, &c, &mut out)
        .map_err(|e| e.to_string())?;
    Ok(json!({ "coeffs": out.into_iter().map(num).collect::<Vec<_>>() }))
}

/// The level field of the control-point kernels: an integer in `0..=4`.
fn cp_level(obj: &Map<String, Value>) -> Result<cp::Icosphere, String> {
    let v = crate::json::field(obj, "level")?;
    let level = v
        .as_u64()
        .filter(|l| *l <= cp::MAX_LEVEL as u64)
        .ok_or_else(|| format!("level must be an integer in 0..={}, got {v}", cp::MAX_LEVEL))?;
    cp::Icosphere::new(level as u32).map_err(|e| e.to_string())
}

/// `cp-vertices`: `{"level": L}` → `{"vertices": [[x, y, z], …]}` in the order of the values
/// of `cp-query` (printed at round-trip precision).
pub fn cp_vertices(obj: &Map<String, Value>) -> Result<Value, String> {
    let mesh = cp_level(obj)?;
    let v: Vec<Value> = mesh
        .vertices()
        .iter()
        .map(|p| json!([num(p.x), num(p.y), num(p.z)]))
        .collect();
    Ok(json!({ "vertices": v }))
}

/// `cp-query`: `{"level": L, "values": [one per vertex], "dirs": [[x, y, z], …]}` →
/// `{"values": [one per direction]}`, with the paper's area weights.
pub fn cp_query(obj: &Map<String, Value>) -> Result<Value, String> {
    let mesh = cp_level(obj)?;
    let values = crate::json::numbers(obj, "values")?;
    mesh.check(&values).map_err(|e| e.to_string())?;
    let dirs = crate::json::field(obj, "dirs")?
        .as_array()
        .ok_or_else(|| "dirs must be an array of [x, y, z]".to_string())?;
    let mut out = Vec::with_capacity(dirs.len());
    for (i, d) in dirs.iter().enumerate() {
        let xyz = d
            .as_array()
            .filter(|a| a.len() == 3)
            .ok_or_else(|| format!("dirs[{i}] must be [x, y, z]"))?;
        let p: Vec<f32> = xyz
            .iter()
            .enumerate()
            .map(|(k, v)| crate::json::element_f32(v, &format!("dirs[{i}][{k}]")))
            .collect::<Result<_, _>>()?;
        let d = Vec3::new(p[0], p[1], p[2]);
        let v = mesh
            .query(&values, d, cp::Weights::Area)
            .map_err(|e| format!("dirs[{i}]: {e}"))?;
        out.push(num(v));
    }
    Ok(json!({ "values": out }))
}

/// `cp-fit`: `{"level": L, "samples": [[x, y, z, value], …]}` → `{"values": [one per
/// vertex]}`, the least-squares minimiser of eq. 3 (`crate::cp::fit`; the undetermined
/// components, if any, are 0).
pub fn cp_fit(obj: &Map<String, Value>) -> Result<Value, String> {
    let mesh = cp_level(obj)?;
    let rows = crate::json::field(obj, "samples")?
        .as_array()
        .ok_or_else(|| "samples must be an array of [x, y, z, value]".to_string())?;
    let mut samples = Vec::with_capacity(rows.len());
    for (i, r) in rows.iter().enumerate() {
        let s = r
            .as_array()
            .filter(|a| a.len() == 4)
            .ok_or_else(|| format!("samples[{i}] must be [x, y, z, value]"))?;
        let p: Vec<f32> = s
            .iter()
            .enumerate()
            .map(|(k, v)| crate::json::element_f32(v, &format!("samples[{i}][{k}]")))
            .collect::<Result<_, _>>()?;
        if p[..3].iter().all(|c| *c == 0.0) {
            return Err(format!("samples[{i}]: the direction is zero"));
        }
        samples.push([p[0], p[1], p[2], p[3]]);
    }
    let v = crate::cp::fit(&mesh, &samples)?;
    if let Some(k) = v.iter().position(|x| x.abs() > f64::from(f32::MAX)) {
        return Err(format!("the fit's value {k} overflows f32 ({})", v[k]));
    }
    Ok(json!({ "values": v.into_iter().map(|x| num(x as f32)).collect::<Vec<_>>() }))
}
