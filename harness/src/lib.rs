//! # steradian-harness
//!
//! Wires the kernels of `steradian-core` and `steradian-simd` to backends (CPU scalar, CPU
//! SIMD, wgpu), holds the exact f64 references, the table generators and the report, and
//! provides the `steradian` command-line tool.

pub mod accuracy;
pub mod backend;
pub mod batch;
pub mod cp;
pub mod env;
pub mod eval;
pub mod generate;
pub mod handlers;
pub mod json;
pub mod kernels;
pub mod product;
pub mod reference;
pub mod registry;
pub mod report;
pub mod rng;
pub mod sat;
pub mod scene;
pub mod sh;
pub mod shade;
pub mod vdt;
pub mod workload;
