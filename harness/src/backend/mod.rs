//! Backends: one trait, several ways to run a batch of any kernel.
//!
//! | name (`report.json`) | what it measures |
//! |---|---|
//! | `cpu-scalar` | the scalar kernel called one input at a time, each input behind `black_box`, the way a renderer calls it per shading point |
//! | `cpu-scalar-loop` | a plain loop over the scalar kernel, which LLVM may vectorise |
//! | `cpu-simd` | the explicit batch of `steradian-simd` (8 lanes; its slice functions use 16 on AVX-512 builds) |
//! | `wgpu` | the WGSL kernel on a GPU adapter (upload, dispatch and read-back included) |

use crate::kernels::{Columns, Kernel};

pub mod cpu;
pub mod gpu;
pub mod gpu_product;
pub mod simd;

/// Why a backend could not run a batch.
#[derive(Debug)]
pub struct BackendError(pub String);

impl std::fmt::Display for BackendError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for BackendError {}

/// A way to run kernels over batches.
pub trait Backend {
    /// The backend's name in `report.json`.
    fn name(&self) -> &'static str;

    /// Runs `kernel` over `input` (`kernel.input_arity()` columns) into `out`
    /// (`kernel.output_arity()` columns of the same length).
    fn run(
        &mut self,
        kernel: Kernel,
        input: &Columns,
        out: &mut Columns,
    ) -> Result<(), BackendError>;
}

/// Checks the shapes of a batch; every backend calls it first.
pub fn check_shapes(kernel: Kernel, input: &Columns, out: &Columns) -> Result<(), BackendError> {
    if input.arity != kernel.input_arity() || out.arity != kernel.output_arity() {
        return Err(BackendError(format!(
            "{kernel}: expected {} input and {} output columns, got {} and {}",
            kernel.input_arity(),
            kernel.output_arity(),
            input.arity,
            out.arity
        )));
    }
    if input.n != out.n
        || input.data.len() != input.n * input.arity
        || out.data.len() != out.n * out.arity
    {
        return Err(BackendError(format!("{kernel}: column lengths disagree")));
    }
    Ok(())
}

/// The CPU backends (always available): scalar, scalar loop, SIMD.
pub fn cpu_backends() -> Vec<Box<dyn Backend>> {
    vec![
        Box::new(cpu::Scalar),
        Box::new(cpu::ScalarLoop),
        Box::new(simd::Simd),
    ]
}
