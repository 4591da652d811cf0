//! References for the rotatable-square-lights paper (`steradian_core::rsl`): the exact
//! equal-area hemisphere map, box integrals of a texel grid ([`sat`]), signed distances to a
//! visibility boundary and exact clipped coverage ([`vdt`]), and the coverage moments of a
//! query square ([`moments`]).
//!
//! # References
//!
//! Those of `steradian_core::rsl`, whose kernels these references check (the rotatable-square-lights paper).

pub mod moments;
pub mod sat;
pub mod vdt;

use crate::lobe::normalize;

/// Exact equal-area map of the normalised direction (lower hemisphere mirrored; zero → pole):
/// `(x, y)/√(1 + |z|)`.
pub fn hemisphere_map(dir: [f32; 3]) -> [f64; 2] {
    match normalize(dir) {
        None if dir == [0.0; 3] => [0.0, 0.0],
        None => [f64::NAN; 2],
        Some([x, y, z]) => {
            let s = 1.0 / libm::sqrt(1.0 + z.abs());
            [x * s, y * s]
        }
    }
}

/// Exact inverse map (points outside the disk clamped radially onto the circle):
/// `(u·√(2 − r²), v·√(2 − r²), 1 − r²)`.
pub fn hemisphere_unmap(p: [f32; 2]) -> [f64; 3] {
    let (mut u, mut v) = (p[0] as f64, p[1] as f64);
    let mut r2 = u * u + v * v;
    if r2 > 1.0 {
        let k = 1.0 / libm::sqrt(r2);
        u *= k;
        v *= k;
        r2 = 1.0;
    }
    let s = libm::sqrt(2.0 - r2);
    [u * s, v * s, 1.0 - r2]
}
