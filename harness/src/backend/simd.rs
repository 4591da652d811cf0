//! The `cpu-simd` backend: the structure-of-arrays kernels of `steradian-simd`, run directly
//! on the batch's columns (no row shuffles), on the widest vector of the build
//! (`steradian_simd::slice_lanes()`: 16 lanes with AVX-512F, 8 otherwise; the instruction
//! set is fixed at compile time, `steradian_simd::isa()`).
//!
//! Results are bit-identical to the scalar backends for the hemisphere map and unmap, the
//! lobe integral and the cap exponent; lobe evaluation is within
//! `steradian_simd::lobe::EVAL_REL_TOL·(1 + |ln(c/s)|)` relative of the scalar kernel, and
//! zero and NaN exactly where it is (see the crate docs of `steradian-simd`).

use steradian_simd::{lobe, lobe::cap, rsl::hemisphere};

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
        let n = input.n;
        let col = |c: usize| input.col(c);
        match k {
            Kernel::HemisphereMap => {
                let (u, v) = out.data.split_at_mut(n);
                hemisphere::map_slices(col(0), col(1), col(2), u, v);
            }
            Kernel::HemisphereUnmap => {
                let (x, rest) = out.data.split_at_mut(n);
                let (y, z) = rest.split_at_mut(n);
                hemisphere::unmap_slices(col(0), col(1), x, y, z);
            }
            Kernel::LobeEval => lobe::eval_slices(
                [col(0), col(1), col(2)],
                col(3),
                col(4),
                [col(5), col(6), col(7)],
                &mut out.data,
            ),
            Kernel::LobeIntegral => lobe::integral_slices(col(0), col(1), &mut out.data),
            Kernel::CapExponent => cap::exponent_l2_slices(col(0), &mut out.data),
        }
        Ok(())
    }
}
