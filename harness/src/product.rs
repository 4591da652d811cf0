//! The lobe product in the harness: `steradian eval lobe-product`, and the canonical
//! configuration shared by the eval kernel, the tests and the report (`a1 = +z`,
//! `a2 = z` rotated by `α` toward `+x`).

use serde_json::{Map, Value, json};
use steradian_core::lobe::CosineLobe;
use steradian_core::lobe::product;
use steradian_core::{TWO_PI, Vec3};

use crate::json::{num, number};

/// Unit lobes in the canonical configuration.
pub fn canonical_lobes(e1: f32, e2: f32, alpha: f32) -> (CosineLobe, CosineLobe) {
    let a2 = Vec3::new(alpha.sin(), 0.0, alpha.cos());
    (
        CosineLobe::saturating(Vec3::Z, 1.0, e1),
        CosineLobe::saturating(a2, 1.0, e2),
    )
}

/// `{"e1", "e2", "alpha"}` → `{"scale", "exponent", "axis_angle", "integral"}` for unit
/// lobes in the canonical configuration (built-in table, exact-integral fit).
/// `e1, e2 ∈ [0, 1e5]` (beyond, the table's last row is used; accepted up to 1e7) and
/// `alpha ∈ [0, π]`.
pub fn eval_lobe_product(obj: &Map<String, Value>) -> Result<Value, String> {
    let (e1, e2, alpha) = (
        number(obj, "e1")?,
        number(obj, "e2")?,
        number(obj, "alpha")?,
    );
    for (name, e) in [("e1", e1), ("e2", e2)] {
        if !(0.0..=1e7).contains(&e) {
            return Err(format!("{name} = {e} is outside [0, 1e7]"));
        }
    }
    if !(0.0..=std::f32::consts::PI).contains(&alpha) {
        return Err(format!("alpha = {alpha} is outside [0, π] (radians)"));
    }
    let (a, b) = canonical_lobes(e1, e2, alpha);
    let r = product::product(&a, &b);
    let beta = r.axis().x.atan2(r.axis().z);
    Ok(json!({
        "scale": num(r.scale()),
        "exponent": num(r.exponent()),
        "axis_angle": num(beta),
        "integral": num(TWO_PI * r.scale() / (r.exponent() + 1.0)),
    }))
}
