//! The scalar CPU backends: one call per input behind `black_box` (`cpu-scalar`), and a
//! plain loop the compiler may vectorise (`cpu-scalar-loop`).

use std::hint::black_box;

use steradian_core::{Vec2, Vec3, lobe, lobe::cap, rsl::hemisphere};

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

#[inline(always)]
fn bb<T>(x: T, opaque: bool) -> T {
    if opaque { black_box(x) } else { x }
}

#[allow(clippy::needless_range_loop)] // one index walks several columns
/// Runs the scalar kernel over every row. With `opaque`, each input and output goes
/// through `black_box` so the compiler cannot vectorise across rows.
#[inline(always)]
pub fn run_scalar(k: Kernel, input: &Columns, out: &mut Columns, opaque: bool) {
    let n = input.n;
    let i = &input.data;
    match k {
        Kernel::HemisphereMap => {
            let (u, v) = out.data.split_at_mut(n);
            for r in 0..n {
                let d = bb(Vec3::new(i[r], i[n + r], i[2 * n + r]), opaque);
                let p = bb(hemisphere::map(d), opaque);
                u[r] = p.x;
                v[r] = p.y;
            }
        }
        Kernel::HemisphereUnmap => {
            let (x, rest) = out.data.split_at_mut(n);
            let (y, z) = rest.split_at_mut(n);
            for r in 0..n {
                let p = bb(Vec2::new(i[r], i[n + r]), opaque);
                let d = bb(hemisphere::unmap(p), opaque);
                x[r] = d.x;
                y[r] = d.y;
                z[r] = d.z;
            }
        }
        Kernel::LobeEval => {
            for r in 0..n {
                let a = bb(Vec3::new(i[r], i[n + r], i[2 * n + r]), opaque);
                let (s, e) = bb((i[3 * n + r], i[4 * n + r]), opaque);
                let v = bb(Vec3::new(i[5 * n + r], i[6 * n + r], i[7 * n + r]), opaque);
                out.data[r] = bb(lobe::eval(a, s, e, v), opaque);
            }
        }
        Kernel::LobeIntegral => {
            for r in 0..n {
                let (e, s) = bb((i[r], i[n + r]), opaque);
                out.data[r] = bb(lobe::integral(e, s), opaque);
            }
        }
        Kernel::CapExponent => {
            for r in 0..n {
                let a = bb(i[r], opaque);
                out.data[r] = bb(cap::exponent_l2(a), opaque);
            }
        }
    }
}
