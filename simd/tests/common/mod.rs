//! Helpers shared by the test modules: a seeded generator, the special values every lane
//! position is tested with, and the lane helpers (bit equality, every lane position, slice
//! lengths).

pub mod lanes;
pub mod rng;
pub mod specials;
