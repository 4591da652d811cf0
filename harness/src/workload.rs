//! The default workload of `steradian report`: per kernel, the named hard cases first,
//! then deterministic pseudo-random inputs spread over the kernel's whole domain.

use crate::kernels::{Columns, Kernel};
use crate::rng::Rng;

/// Named hard cases of a kernel, one row each, with their names ([`crate::kernels::Batch`]).
pub fn hard_cases(kernel: Kernel) -> Vec<(&'static str, Vec<f32>)> {
    (kernel.spec().hard_cases)()
}

/// `v` normalised and rounded to f32.
pub fn unit32(v: [f64; 3]) -> [f32; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [(v[0] / l) as f32, (v[1] / l) as f32, (v[2] / l) as f32]
}

/// The direction at polar angle `theta` and azimuth `phi` around the unit axis `a`.
pub fn direction_at(a: [f64; 3], theta: f64, phi: f64) -> [f64; 3] {
    let (u, w) = perpendiculars(a);
    std::array::from_fn(|i| {
        theta.cos() * a[i] + theta.sin() * (phi.cos() * u[i] + phi.sin() * w[i])
    })
}

use steradian_reference::perpendiculars;

/// `n` rows for `kernel`: the hard cases, then random rows from `seed`.
pub fn generate(kernel: Kernel, n: usize, seed: u64) -> Columns {
    let arity = kernel.input_arity();
    let mut cols = Columns::zeros(arity, n);
    let mut rng = Rng::new(seed ^ kernel.spec().seed.wrapping_mul(0x9e37_79b9));
    let hard = hard_cases(kernel);
    for i in 0..n {
        let row = match hard.get(i) {
            Some((_, r)) => r.clone(),
            None => (kernel.spec().random_row)(&mut rng),
        };
        for (c, v) in row.into_iter().enumerate() {
            cols.data[c * n + i] = v;
        }
    }
    cols
}
