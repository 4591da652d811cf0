//! The `cpu-simd` backend: the structure-of-arrays kernels of `steradian-simd`, run directly
//! on the batch's columns (no row shuffles), on the widest vector of the build
//! (`steradian_simd::slice_lanes()`: 16 lanes with AVX-512F, 8 otherwise; the instruction
//! set is fixed at compile time, `steradian_simd::isa()`).
//!
//! Results are bit-identical to the scalar backends for the hemisphere map and unmap, the
//! lobe integral and the cap exponent; lobe evaluation is within
//! `steradian_simd::lobe::EVAL_REL_TOL·(1 + |ln(c/s)|)` relative of the scalar kernel, and
//! zero and NaN exactly where it is (see the crate docs of `steradian-simd`).

use super::{Backend, BackendError, check_shapes};
use crate::kernels::{Columns, Kernel};

/// `cpu-simd`: the slice functions of `steradian-simd` over the input columns.
pub struct Simd;

impl Backend for Simd {
    fn name(&self) -> &'static str {
        "cpu-simd"
    }

    fn run(&mut self, k: Kernel, input: &Columns, out: &mut Columns) -> Result<(), BackendError> {
        check_shapes(k, input, out)?;
        (k.spec().simd)(input, out);
        Ok(())
    }
}
