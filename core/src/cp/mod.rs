//! Control-point spherical functions: values at the vertices of a subdivided icosahedron,
//! interpolated inside spherical triangles with area-ratio weights.
//!
//! Source: P. Y. Chatelier and R. Malgouyres, "A fast interpolation method to represent
//! the BRDF in global illumination", GRAPP 2007 (`shared/seeds/001_*.txt`), sections 2–3.
//!
//! - [`Icosphere`] (`mesh.rs`): the mesh at levels 0–4 (12, 42, 162, 642, 2562 vertices),
//!   the point location in O(1) and the two interpolation weights.
//! - A spherical function is a `&[f32]` of one value per vertex, in the order of
//!   [`Icosphere::vertices`]; [`Icosphere::query`] interpolates it, [`deform`] is the local
//!   deformation of section 3.3 (eq. 8). Scale and add are the element-wise operations on
//!   the values (the interpolation is linear in them).
//! - [`fit::Design`] (`fit.rs`): the least-squares fit of eq. 3, as a design matrix and
//!   its normal equations (factored by the harness).
//! - [`rotate::Operator`] (`rotate.rs`): rotation by permutation (section 3.4.1), by the
//!   continuous re-weighting (section 3.4.2), or by resampling, as sparse operators.
//!
//! Requires the `alloc` feature (the mesh is built at run time, deterministically).

pub mod fit;
mod mesh;
pub mod rotate;

pub use fit::Design;
pub use mesh::{Icosphere, Location, MAX_LEVEL, OCTANT_EDGES, WEIGHT_ABS_ERROR, Weights};

/// The local deformation of section 3.3, eq. 8: raise the interpolated value at the
/// direction of `at` by `delta` by moving only its three control points,
/// `δr_i = ω_i·δr / Σ_j ω_j²`.
///
/// Derivation: with `δr_i = k·ω_i` (each point moves in proportion to its weight), the
/// new value is `Σ ω_i (r_i + k ω_i) = r + k Σ ω_i²`, so `k = δr / Σ ω_j²` (the seed's text
/// "proportional to ω_i r_i" is garbled; this is the only reading that makes the new value
/// exactly `r + δr`, which the test `deform_is_exact_at_its_point` asserts).
pub fn deform(values: &mut [f32], at: &Location, delta: f32) {
    let s: f32 = at.weights.iter().map(|w| w * w).sum();
    if s.is_nan() || s <= 0.0 || !delta.is_finite() {
        return;
    }
    for (v, w) in at.vertices.iter().zip(at.weights) {
        if let Some(x) = values.get_mut(*v as usize) {
            *x += w * delta / s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;
    use alloc::vec::Vec;

    #[test]
    fn deform_is_exact_at_its_point() {
        let m = Icosphere::new(2).unwrap();
        let mut values: Vec<f32> = (0..m.vertices().len()).map(|k| (k % 7) as f32).collect();
        let d = Vec3::new(0.3, -0.5, 0.8);
        let before = m.query(&values, d, Weights::Area).unwrap();
        let at = m.locate(d, Weights::Area).unwrap();
        deform(&mut values, &at, 0.25);
        let after = m.query(&values, d, Weights::Area).unwrap();
        assert!((after - before - 0.25).abs() < 1e-5, "{before} → {after}");
        // Only the three control points moved.
        let moved = (0..values.len())
            .filter(|k| values[*k] != (k % 7) as f32)
            .count();
        assert!(moved <= 3);
    }
}
