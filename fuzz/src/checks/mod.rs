//! The invariant checks of every fuzz target, one module per target: the fuzz targets run
//! them on libFuzzer's inputs, and the harness test `fuzz_replay` (stable, part of
//! `cargo test --workspace`) runs them on every input of the committed corpora
//! (`fuzz/corpus/<target>/`).

pub mod cap_integrals;
pub mod cp;
pub mod eval_lines;
pub mod lobe_product;
pub mod map_roundtrip;
pub mod moments_kernel;
pub mod sat_query;
pub mod sh;
pub mod simd_vs_scalar;
pub mod table_lookup;
pub mod vdt;

/// A target's checks on one input.
pub type Check = fn(&[u8]);

/// Every target, by name (the corpus folder).
pub const TARGETS: [(&str, Check); 11] = [
    ("cap_integrals", cap_integrals::check),
    ("cp", cp::check),
    ("eval_lines", eval_lines::check),
    ("lobe_product", lobe_product::check),
    ("map_roundtrip", map_roundtrip::check),
    ("moments_kernel", moments_kernel::check),
    ("sat_query", sat_query::check),
    ("sh", sh::check),
    ("simd_vs_scalar", simd_vs_scalar::check),
    ("table_lookup", table_lookup::check),
    ("vdt", vdt::check),
];
