//! The default workload of `steradian report`: per kernel, the named hard cases first,
//! then deterministic pseudo-random inputs spread over the kernel's whole domain.

use std::f64::consts::FRAC_PI_2;

use crate::kernels::{Columns, Kernel};
use crate::rng::Rng;

/// Named hard cases of a kernel, one row each, with their names.
pub fn hard_cases(kernel: Kernel) -> Vec<(&'static str, Vec<f32>)> {
    let s = 1e-7f32;
    let c = (1.0f32 - s * s).sqrt();
    match kernel {
        Kernel::HemisphereMap => vec![
            ("pole", vec![0.0, 0.0, 1.0]),
            ("horizon +x", vec![1.0, 0.0, 0.0]),
            ("horizon diagonal", vec![-0.70710677, 0.70710677, 0.0]),
            ("z = 1e-7", vec![c, 0.0, s]),
            ("near pole 1e-7", vec![s, 0.0, c]),
            ("zero vector", vec![0.0, 0.0, 0.0]),
            ("huge", vec![1e30, -2e30, 3e30]),
            ("tiny", vec![1e-30, 2e-30, 3e-30]),
            ("subnormal", vec![1e-40, 0.0, 1e-40]),
            ("max", vec![f32::MAX, f32::MAX, f32::MAX]),
            ("below horizon", vec![0.3, 0.4, -0.5]),
            ("straight down", vec![0.0, 0.0, -1.0]),
        ],
        Kernel::HemisphereUnmap => vec![
            ("pole", vec![0.0, 0.0]),
            ("horizon", vec![1.0, 0.0]),
            ("horizon diagonal", vec![-0.70710677, 0.70710677]),
            ("just inside", vec![0.99999994, 0.0]),
            ("tiny", vec![1e-30, -1e-30]),
            ("outside", vec![3.0, 4.0]),
        ],
        Kernel::LobeEval => {
            let z = [0.0, 0.0, 1.0];
            let row = |e: f32, v: [f32; 3]| vec![z[0], z[1], z[2], 1.0, e, v[0], v[1], v[2]];
            let at = |t: f32| [t.sin(), 0.0, t.cos()];
            vec![
                ("e = 0 inside", row(0.0, at(1.0))),
                ("e = 0 horizon", row(0.0, [1.0, 0.0, 0.0])),
                ("e = 0 opposite", row(0.0, [0.0, 0.0, -1.0])),
                ("e = 1e5 on axis", row(1e5, z)),
                ("e = 1e5 at 1e-3 rad", row(1e5, at(1e-3))),
                ("e = 1e5 at 3e-3 rad", row(1e5, at(3e-3))),
                ("e = 1e5 at 1e-2 rad", row(1e5, at(1e-2))),
                ("e = 1 horizon", row(1.0, [1.0, 0.0, 0.0])),
                ("e = 1 grazing 1e-4", row(1.0, at(FRAC_PI_2 as f32 - 1e-4))),
                ("e = 1e4 at 1e-2", row(1e4, at(1e-2))),
            ]
        }
        Kernel::LobeIntegral => vec![
            ("e = 0", vec![0.0, 1.0]),
            ("e = 1", vec![1.0, 1.0]),
            ("e = 1e5", vec![1e5, 1.0]),
            ("e = 1e-7", vec![1e-7, 1.0]),
            ("negative scale", vec![3.0, -2.0]),
            ("huge scale", vec![2.0, 1e37]),
        ],
        Kernel::CapExponent => vec![
            ("1e-4 rad", vec![1e-4]),
            ("1e-18 rad", vec![1e-18]),
            ("1e-9 rad", vec![1e-9]),
            ("hemisphere", vec![FRAC_PI_2 as f32]),
            ("hemisphere − 1e-6", vec![FRAC_PI_2 as f32 - 1e-6]),
            ("hemisphere − 1e-3", vec![FRAC_PI_2 as f32 - 1e-3]),
            ("1 rad", vec![1.0]),
        ],
    }
}

fn random_row(kernel: Kernel, r: &mut Rng) -> Vec<f32> {
    match kernel {
        Kernel::HemisphereMap => {
            let d = r.sphere();
            let k = r.log_range(1e-3, 1e3);
            d.iter().map(|c| (c * k) as f32).collect()
        }
        Kernel::HemisphereUnmap => {
            let rad = r.unit().sqrt();
            let phi = r.range(0.0, std::f64::consts::TAU);
            vec![(rad * phi.cos()) as f32, (rad * phi.sin()) as f32]
        }
        Kernel::LobeEval => {
            let a = r.sphere();
            let e = if r.unit() < 0.05 {
                0.0
            } else {
                r.log_range(1e-3, 1e5)
            };
            // Directions where the lobe matters: angle ~ a few widths 1/sqrt(e+1).
            let width = (1.0 / (e + 1.0)).sqrt();
            let theta = (r.unit() * 3.0 * width).min(std::f64::consts::PI);
            let phi = r.range(0.0, std::f64::consts::TAU);
            let dir = direction_at(a, theta, phi);
            let s = r.range(0.1, 10.0);
            let an = unit32(a);
            let dn = unit32(dir);
            vec![an[0], an[1], an[2], s as f32, e as f32, dn[0], dn[1], dn[2]]
        }
        Kernel::LobeIntegral => vec![r.log_range(1e-4, 1e5) as f32, r.range(-10.0, 10.0) as f32],
        Kernel::CapExponent => vec![r.log_range(1e-4, FRAC_PI_2) as f32],
    }
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

fn perpendiculars(a: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let t = if a[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let cross = |p: [f64; 3], q: [f64; 3]| {
        [
            p[1] * q[2] - p[2] * q[1],
            p[2] * q[0] - p[0] * q[2],
            p[0] * q[1] - p[1] * q[0],
        ]
    };
    let u = cross(a, t);
    let l = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let u = u.map(|c| c / l);
    (u, cross(a, u))
}

/// `n` rows for `kernel`: the hard cases, then random rows from `seed`.
pub fn generate(kernel: Kernel, n: usize, seed: u64) -> Columns {
    let arity = kernel.input_arity();
    let mut cols = Columns::zeros(arity, n);
    let mut rng = Rng::new(seed ^ (kernel as u64).wrapping_mul(0x9e37_79b9));
    let hard = hard_cases(kernel);
    for i in 0..n {
        let row = match hard.get(i) {
            Some((_, r)) => r.clone(),
            None => random_row(kernel, &mut rng),
        };
        for (c, v) in row.into_iter().enumerate() {
            cols.data[c * n + i] = v;
        }
    }
    cols
}
