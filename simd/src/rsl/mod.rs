//! The kernels of the rotatable-square-lights paper, 8 lanes at a time (mirrors
//! `steradian_core::rsl`): the equal-area hemisphere map, summed-area and visibility
//! distance table queries, and the shading kernels.
//!
//! # References
//!
//! Those of `steradian_core::rsl` (the rotatable-square-lights paper).

pub mod hemisphere;
pub mod sat;
pub mod shade;
pub mod vdt;
