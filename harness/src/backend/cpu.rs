//! The scalar CPU backends: one call per input behind `black_box` (`cpu-scalar`), and a
//! plain loop the compiler may vectorise (`cpu-scalar-loop`).

use super::{Backend, BackendError, check_shapes};
use crate::kernels::{Columns, Kernel};

/// `cpu-scalar`: each input passes through `black_box`, so nothing is batched across calls.
pub struct Scalar;
/// `cpu-scalar-loop`: a plain loop over the scalar kernel.
pub struct ScalarLoop;

impl Backend for Scalar {
    fn name(&self) -> &'static str {
        "cpu-scalar"
    }
    fn run(&mut self, k: Kernel, input: &Columns, out: &mut Columns) -> Result<(), BackendError> {
        check_shapes(k, input, out)?;
        run_scalar(k, input, out, true);
        Ok(())
    }
}

impl Backend for ScalarLoop {
    fn name(&self) -> &'static str {
        "cpu-scalar-loop"
    }
    fn run(&mut self, k: Kernel, input: &Columns, out: &mut Columns) -> Result<(), BackendError> {
        check_shapes(k, input, out)?;
        run_scalar(k, input, out, false);
        Ok(())
    }
}

/// The scalar kernel of `k` over columns (see [`crate::kernels::Batch::scalar`]).
#[inline(always)]
pub fn run_scalar(k: Kernel, input: &Columns, out: &mut Columns, opaque: bool) {
    (k.spec().scalar)(input, out, opaque)
}
