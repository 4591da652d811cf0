//! Batch kernels of the rotatable-square-lights paper: the equal-area hemisphere map and its
//! inverse (`steradian_core::rsl::hemisphere`).

use std::f64::consts::TAU;

use steradian_core::rsl::hemisphere;
use steradian_core::{Vec2, Vec3};

use crate::kernels::{Batch, Kernel, bb};
use crate::reference;
use crate::rng::Rng;

/// Largest absolute difference over the components.
fn max_abs(_row: &[f32], got: &[f64], want: &[f64]) -> f64 {
    got.iter()
        .zip(want)
        .map(|(g, w)| (g - w).abs())
        .fold(0.0, f64::max)
}

/// Equal-area hemisphere map: `[x, y, z] → [u, v]`.
pub const HEMISPHERE_MAP: Kernel = Kernel(&Batch {
    name: "hemisphere-map",
    inputs: 3,
    outputs: 2,
    seed: 0,
    scalar: |input, out, opaque| {
        let (n, i) = (input.n, &input.data);
        let (u, v) = out.data.split_at_mut(n);
        for r in 0..n {
            let d = bb(Vec3::new(i[r], i[n + r], i[2 * n + r]), opaque);
            let p = bb(hemisphere::map(d), opaque);
            u[r] = p.x;
            v[r] = p.y;
        }
    },
    simd: |input, out| {
        let (u, v) = out.data.split_at_mut(input.n);
        steradian_simd::rsl::hemisphere::map_slices(input.col(0), input.col(1), input.col(2), u, v);
    },
    cap_table: false,
    hard_cases: || {
        let s = 1e-7f32;
        let c = (1.0f32 - s * s).sqrt();
        vec![
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
        ]
    },
    random_row: |r: &mut Rng| {
        let d = r.sphere();
        let k = r.log_range(1e-3, 1e3);
        d.iter().map(|c| (c * k) as f32).collect()
    },
    reference: |r| reference::hemisphere_map([r[0], r[1], r[2]]).to_vec(),
    error: max_abs,
});

/// Its inverse: `[u, v] → [x, y, z]`.
pub const HEMISPHERE_UNMAP: Kernel = Kernel(&Batch {
    name: "hemisphere-unmap",
    inputs: 2,
    outputs: 3,
    seed: 1,
    scalar: |input, out, opaque| {
        let (n, i) = (input.n, &input.data);
        let (x, rest) = out.data.split_at_mut(n);
        let (y, z) = rest.split_at_mut(n);
        for r in 0..n {
            let p = bb(Vec2::new(i[r], i[n + r]), opaque);
            let d = bb(hemisphere::unmap(p), opaque);
            x[r] = d.x;
            y[r] = d.y;
            z[r] = d.z;
        }
    },
    simd: |input, out| {
        let (x, rest) = out.data.split_at_mut(input.n);
        let (y, z) = rest.split_at_mut(input.n);
        steradian_simd::rsl::hemisphere::unmap_slices(input.col(0), input.col(1), x, y, z);
    },
    cap_table: false,
    hard_cases: || {
        vec![
            ("pole", vec![0.0, 0.0]),
            ("horizon", vec![1.0, 0.0]),
            ("horizon diagonal", vec![-0.70710677, 0.70710677]),
            ("just inside", vec![0.99999994, 0.0]),
            ("tiny", vec![1e-30, -1e-30]),
            ("outside", vec![3.0, 4.0]),
        ]
    },
    random_row: |r: &mut Rng| {
        let rad = r.unit().sqrt();
        let phi = r.range(0.0, TAU);
        vec![(rad * phi.cos()) as f32, (rad * phi.sin()) as f32]
    },
    reference: |r| reference::hemisphere_unmap([r[0], r[1]]).to_vec(),
    error: max_abs,
});
