//! Helpers shared by the test modules.

pub mod gpu;
pub mod proptest_config;
