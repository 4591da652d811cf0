//! Batch kernels of the cosine-lobe paper: lobe evaluation, the exact lobe integral and the
//! cap → lobe exponent (`steradian_core::lobe`, `steradian_core::lobe::cap`).

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use steradian_core::Vec3;
use steradian_core::lobe::{self, cap};

use crate::kernels::{Batch, Kernel, bb};
use crate::reference;
use crate::rng::Rng;
use crate::workload::{direction_at, unit32};

/// The lobe-eval metric `|c − c*| / (|c*|·κ)` with
/// `κ = 1 + |ln(c*/s)| + (EVAL_DOT_ERROR/EVAL_REL_ERROR)·e/(a·v)`, so that the documented
/// bound of `steradian_core::lobe` reads `metric ≤ EVAL_REL_ERROR`. Where `c*` is below
/// `1e-30·|s|` (f32 cannot hold it relative to `s`) it is the absolute error over `|s|`.
pub fn lobe_eval_error(axis: [f32; 3], s: f32, e: f32, v: [f32; 3], got: f64) -> f64 {
    use steradian_core::lobe::{EVAL_DOT_ERROR, EVAL_REL_ERROR};
    let want = reference::lobe_eval(axis, s, e, v);
    let s = s as f64;
    if want.abs() < 1e-30 * s.abs() || want == 0.0 {
        return (got - want).abs() / s.abs().max(f64::MIN_POSITIVE);
    }
    let (Some(a), Some(v)) = (reference::normalize(axis), reference::normalize(v)) else {
        return f64::INFINITY;
    };
    let d = a[0] * v[0] + a[1] * v[1] + a[2] * v[2];
    let e = (e as f64).max(0.0);
    let kappa = 1.0 + (want / s).ln().abs() + (EVAL_DOT_ERROR / EVAL_REL_ERROR) as f64 * e / d;
    (got - want).abs() / (want.abs() * kappa)
}

/// Cosine lobe evaluation: `[ax, ay, az, s, e, vx, vy, vz] → [value]`.
pub const LOBE_EVAL: Kernel = Kernel(&Batch {
    name: "lobe-eval",
    inputs: 8,
    outputs: 1,
    seed: 2,
    scalar: |input, out, opaque| {
        let (n, i) = (input.n, &input.data);
        for r in 0..n {
            let a = bb(Vec3::new(i[r], i[n + r], i[2 * n + r]), opaque);
            let (s, e) = bb((i[3 * n + r], i[4 * n + r]), opaque);
            let v = bb(Vec3::new(i[5 * n + r], i[6 * n + r], i[7 * n + r]), opaque);
            out.data[r] = bb(lobe::eval(a, s, e, v), opaque);
        }
    },
    simd: |input, out| {
        let col = |c: usize| input.col(c);
        steradian_simd::lobe::eval_slices(
            [col(0), col(1), col(2)],
            col(3),
            col(4),
            [col(5), col(6), col(7)],
            &mut out.data,
        )
    },
    cap_table: false,
    hard_cases: || {
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
    },
    random_row: |r: &mut Rng| {
        let a = r.sphere();
        let e = if r.unit() < 0.05 {
            0.0
        } else {
            r.log_range(1e-3, 1e5)
        };
        // Directions where the lobe matters: angle ~ a few widths 1/sqrt(e+1).
        let width = (1.0 / (e + 1.0)).sqrt();
        let theta = (r.unit() * 3.0 * width).min(PI);
        let phi = r.range(0.0, TAU);
        let dir = direction_at(a, theta, phi);
        let s = r.range(0.1, 10.0);
        let an = unit32(a);
        let dn = unit32(dir);
        vec![an[0], an[1], an[2], s as f32, e as f32, dn[0], dn[1], dn[2]]
    },
    reference: |r| {
        vec![reference::lobe_eval(
            [r[0], r[1], r[2]],
            r[3],
            r[4],
            [r[5], r[6], r[7]],
        )]
    },
    error: |r, got, _want| {
        lobe_eval_error([r[0], r[1], r[2]], r[3], r[4], [r[5], r[6], r[7]], got[0])
    },
});

/// Exact lobe integral: `[e, s] → [integral]`.
pub const LOBE_INTEGRAL: Kernel = Kernel(&Batch {
    name: "lobe-integral",
    inputs: 2,
    outputs: 1,
    seed: 3,
    scalar: |input, out, opaque| {
        let (n, i) = (input.n, &input.data);
        for r in 0..n {
            let (e, s) = bb((i[r], i[n + r]), opaque);
            out.data[r] = bb(lobe::integral(e, s), opaque);
        }
    },
    simd: |input, out| {
        steradian_simd::lobe::integral_slices(input.col(0), input.col(1), &mut out.data)
    },
    cap_table: false,
    hard_cases: || {
        vec![
            ("e = 0", vec![0.0, 1.0]),
            ("e = 1", vec![1.0, 1.0]),
            ("e = 1e5", vec![1e5, 1.0]),
            ("e = 1e-7", vec![1e-7, 1.0]),
            ("negative scale", vec![3.0, -2.0]),
            ("huge scale", vec![2.0, 1e37]),
        ]
    },
    random_row: |r: &mut Rng| vec![r.log_range(1e-4, 1e5) as f32, r.range(-10.0, 10.0) as f32],
    reference: |r| vec![reference::lobe_integral(r[0], r[1])],
    error: |_r, got, want| {
        let (g, w) = (got[0], want[0]);
        if w == 0.0 {
            g.abs()
        } else {
            ((g - w) / w).abs()
        }
    },
});

/// Cap → lobe L2 exponent from the table: `[half_angle] → [exponent]`. The reference holds
/// `[e*, J(e*)]` (the optimum and its objective); the metric is the objective's excess.
pub const CAP_EXPONENT: Kernel = Kernel(&Batch {
    name: "cap-exponent",
    inputs: 1,
    outputs: 1,
    seed: 4,
    scalar: |input, out, opaque| {
        for r in 0..input.n {
            let a = bb(input.data[r], opaque);
            out.data[r] = bb(cap::exponent_l2(a), opaque);
        }
    },
    simd: |input, out| steradian_simd::lobe::cap::exponent_l2_slices(input.col(0), &mut out.data),
    cap_table: true,
    hard_cases: || {
        vec![
            ("1e-4 rad", vec![1e-4]),
            ("1e-18 rad", vec![1e-18]),
            ("1e-9 rad", vec![1e-9]),
            ("hemisphere", vec![FRAC_PI_2 as f32]),
            ("hemisphere − 1e-6", vec![FRAC_PI_2 as f32 - 1e-6]),
            ("hemisphere − 1e-3", vec![FRAC_PI_2 as f32 - 1e-3]),
            ("1 rad", vec![1.0]),
        ]
    },
    random_row: |r: &mut Rng| vec![r.log_range(1e-4, FRAC_PI_2) as f32],
    reference: |r| {
        let a = r[0] as f64;
        let e = reference::cap::optimal_exponent(a);
        vec![e, reference::cap::objective(e, a)]
    },
    error: |r, got, want| {
        let a = r[0] as f64;
        let best = want[1];
        let j = reference::cap::objective(got[0], a);
        if best > 0.0 {
            (j / best - 1.0).max(0.0)
        } else {
            j / reference::cap_solid_angle(a)
        }
    },
});
