//! The harness's integration tests, one binary (as `wide` does): one module per subsystem,
//! sharing `common` (the GPU adapter helper and the proptest configuration). One binary
//! links wgpu, naga and image once instead of once per file.

mod brdf;
mod common;
mod coverage;
mod cp;
mod cp_gpu;
mod cycles;
mod env;
mod fuzz_replay;
mod gpu;
mod lobe_sum;
mod mask;
mod product;
mod product_gpu;
mod properties;
mod sat;
mod scene;
mod sh;
mod sh_gpu;
mod shade;
mod shade_moments_gpu;
mod vdt;
mod vdt_gpu;
mod wgsl_layout;
mod wgsl_validate;
