//! Exact `f64` references for every steradian kernel: closed forms where they exist,
//! brute forces and adaptive quadrature where they do not. One reference per kernel, used
//! by the harness (accuracy tables, table generators, the report), by the tests of
//! `steradian-core` and the harness, and by the fuzz targets (the SIMD kernels are checked
//! lane by lane against the scalar ones, not against a reference).
//!
//! The folders mirror core's: [`lobe`] for the cosine-lobe paper, [`rsl`] for the
//! rotatable-square-lights paper, [`sh`] for spherical harmonics (HVL paper); [`quad`] is
//! the shared quadrature rule. Nothing here
//! depends on `steradian-core`: a reference written without the kernel's code checks the
//! algebra as well as the rounding. Transcendental functions come from the pure-Rust `libm`
//! crate where a result feeds a committed table, so those bytes are the same on every
//! machine.

pub mod cp;
pub mod lobe;
pub mod quad;
pub mod rsl;
pub mod sh;

/// Two unit vectors completing the unit `a` to a right-handed frame `(u, w, a)`: `u` is
/// `a × x̂` (or `a × ŷ` when `a` is within 26° of `x̂`), normalised, and `w = a × u`.
pub fn perpendiculars(a: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let t = if a[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let cross = |p: [f64; 3], q: [f64; 3]| {
        [
            p[1] * q[2] - p[2] * q[1],
            p[2] * q[0] - p[0] * q[2],
            p[0] * q[1] - p[1] * q[0],
        ]
    };
    let u = cross(a, t);
    let l = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let u = u.map(|c| c / l);
    (u, cross(a, u))
}
