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

pub mod lobe;
pub mod quad;
pub mod rsl;
pub mod sh;
