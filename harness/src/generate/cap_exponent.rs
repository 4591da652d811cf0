//! The cap-exponent table: `h(α) = e*(α)·α²` at `α_i = (π/2)·(1 − (1 − x_i)²)`,
//! `x_i = i/(N − 1)`, with `h(0) = 2k*` (the small-cap limit) and `h(π/2) = 0`. The grid
//! is uniform in `x` and dense near `π/2`, where `e*` behaves like `c·(1 − ln c)/2`
//! (`c = cos α`) and a grid uniform in `α` would need ~4000 samples. See
//! `steradian_core::lobe::cap`.

use std::f64::consts::FRAC_PI_2;

use steradian_core::lobe::cap::{TABLE_LEN, TABLE_NAME};
use steradian_core::table::{HEADER_LEN, Spec, encode_into};

use crate::reference::cap::h;

/// The half-angle of sample `i` of `n`: `(π/2)·(1 − (1 − i/(n−1))²)`.
pub fn grid_angle(i: usize, n: usize) -> f64 {
    let w = 1.0 - i as f64 / (n - 1) as f64;
    FRAC_PI_2 * (1.0 - w * w)
}

/// The `N` samples as f32 (rounded from f64).
pub fn samples(n: usize) -> Vec<f32> {
    (0..n)
        .map(|i| {
            if i + 1 == n {
                0.0
            } else {
                h(grid_angle(i, n)) as f32
            }
        })
        .collect()
}

/// The complete table file.
pub fn generate() -> Vec<u8> {
    let values = samples(TABLE_LEN);
    let spec = Spec {
        name: TABLE_NAME,
        rank: 1,
        channels: 1,
        dims: [TABLE_LEN as u32, 1, 1, 1],
        lo: [0.0; 4],
        hi: [FRAC_PI_2, 1.0, 1.0, 1.0],
    };
    let mut out = vec![0u8; HEADER_LEN + 4 * values.len()];
    encode_into(&spec, &values, &mut out).expect("sizes agree by construction");
    out
}
