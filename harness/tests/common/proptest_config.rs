//! The proptest configuration of the property-test files (`properties.rs`, `sat.rs`,
//! `vdt.rs`), included by each with
//! `#[path = "common/proptest_config.rs"] mod proptest_config;`: a fixed seed per file (so
//! a failure reproduces), no failure persistence files, and `PROPTEST_CASES` overriding the
//! file's case count.

use proptest::test_runner::{Config, RngSeed};

/// `cases` cases (or `PROPTEST_CASES`) from the fixed seed `seed`.
pub fn config(cases: u32, seed: u64) -> Config {
    Config {
        cases: std::env::var("PROPTEST_CASES")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(cases),
        rng_seed: RngSeed::Fixed(seed),
        failure_persistence: None,
        ..Config::default()
    }
}
