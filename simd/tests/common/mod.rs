//! Helpers shared by the test modules: a seeded generator and the special values every
//! lane position is tested with.

pub mod rng;
pub mod specials;
