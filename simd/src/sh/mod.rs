//! Real spherical harmonics, four directions at a time (mirrors `steradian_core::sh`).
//!
//! [`eval_x4`] normalises the four directions on `wide::f64x4` lanes with the operations of
//! `steradian_core::sh::unit_direction` (one correctly rounded square root, division and
//! three products per lane) and runs the scalar kernel's `f64` recurrence on the lanes with
//! the same operations in the same order, the same orders `m` grouped by
//! `steradian_core::sh::CHAINS` (the per-order constants `Π_m^m` and `√2·Π_m^m` do not
//! depend on the direction and are computed once per batch), so every lane is
//! **bit-identical** to `steradian_core::sh::eval_into`, NaN included. [`eval_slices`] runs
//! it over structure-of-arrays columns.
//!
//! # References
//!
//! Those of `steradian_core::sh` (the HVL paper, eq. 7–8).

pub mod cap;
pub mod hvl;
pub mod irradiance;
pub mod rotate;

use steradian_core::sh::{A, AB, CHAINS, DIAG, MAX_GROUP, SUB, Y00_F64, check_shape, group, tri};
use steradian_core::{Error, Vec3};
use wide::f64x4;

/// All `bands²` real SH at four directions: `out[k][lane]` is coefficient `k`
/// (index `l² + l + m`) of `dirs[lane]`, lane-wise `steradian_core::sh::eval_into`,
/// bit-identical.
///
/// Errors: `bands > MAX_BANDS` or `out` shorter than `bands²`.
pub fn eval_x4(dirs: [Vec3; 4], bands: usize, out: &mut [[f32; 4]]) -> Result<(), Error> {
    check_shape(bands, out.len())?;
    let lanes = |f: fn(&Vec3) -> f32| f64x4::new(dirs.each_ref().map(|d| f64::from(f(d))));
    let u = unit_lanes(lanes(|d| d.x), lanes(|d| d.y), lanes(|d| d.z));
    fill(u, bands, &mut |k, v| out[k] = narrow(v));
    Ok(())
}

/// The four lanes rounded to `f32` (the scalar kernel's `as f32`).
#[inline(always)]
fn narrow(v: f64x4) -> [f32; 4] {
    let a = v.to_array();
    [a[0] as f32, a[1] as f32, a[2] as f32, a[3] as f32]
}

/// `steradian_core::sh::unit_direction` on four lanes: the same operations (`r²` summed
/// left to right, `1/√r²`, three products), `+z` where `r² = 0`, NaN where `r²` is not
/// finite.
#[inline(always)]
fn unit_lanes(x: f64x4, y: f64x4, z: f64x4) -> [f64x4; 3] {
    let r2 = x * x + y * y + z * z;
    let inv = f64x4::ONE / r2.sqrt();
    let zero = r2.simd_eq(f64x4::ZERO);
    let finite = r2.simd_lt(f64x4::splat(f64::INFINITY));
    let nan = f64x4::splat(f64::NAN);
    let fix =
        |v: f64x4, at_zero: f64| finite.select(zero.select(f64x4::splat(at_zero), v * inv), nan);
    [fix(x, 0.0), fix(y, 0.0), fix(z, 1.0)]
}

/// The scalar kernel's recurrence (`steradian_core::sh`'s `fill`) on four lanes;
/// `put(k, v)` receives coefficient `k` (the sine part of each `(l, m)` before its cosine
/// part, coefficient 0 last, as the scalar kernel writes them).
#[inline(always)]
fn fill(u: [f64x4; 3], bands: usize, put: &mut impl FnMut(usize, f64x4)) {
    if bands == 0 {
        return;
    }
    let [x, y, z] = u;
    let sp = f64x4::splat;
    let step = |k: usize, q1: f64x4, q2: f64x4| sp(A[k]) * z * q1 - sp(AB[k]) * q2;
    let (mut pmm, mut c, mut s) = (Y00_F64, sp(1.0), sp(0.0));
    let mut m0 = 0;
    while m0 < bands {
        let g = group(bands - m0);
        let (mut cc, mut ss) = ([sp(1.0); MAX_GROUP], [sp(0.0); MAX_GROUP]);
        let (mut q1, mut q2) = ([sp(0.0); MAX_GROUP], [sp(0.0); MAX_GROUP]);
        for j in 0..g {
            let m = m0 + j;
            if m > 0 {
                pmm *= DIAG[m];
                (c, s) = (x * c - y * s, x * s + y * c);
            }
            (cc[j], ss[j]) = (c, s);
            q1[j] = sp(if m == 0 {
                Y00_F64
            } else {
                core::f64::consts::SQRT_2 * pmm
            });
        }
        let head = (m0 + g + 1).min(bands);
        for j in 0..g {
            let m = m0 + j;
            let (mut p1, mut p2) = (q1[j], sp(0.0));
            for l in m..head {
                let q = if l == m {
                    p1
                } else if l == m + 1 {
                    sp(SUB[m]) * z * p1
                } else {
                    step(tri(l, m), p1, p2)
                };
                if l > m {
                    (p2, p1) = (p1, q);
                }
                let at = l * l + l;
                put(at - m, q * ss[j]);
                put(at + m, q * cc[j]);
            }
            (q1[j], q2[j]) = (p1, p2);
        }
        for l in head..bands {
            let at = l * l + l;
            let k = tri(l, m0);
            for j in 0..CHAINS {
                let q = step(k + j, q1[j], q2[j]);
                (q2[j], q1[j]) = (q1[j], q);
                put(at - m0 - j, q * ss[j]);
                put(at + m0 + j, q * cc[j]);
            }
        }
        m0 += g;
    }
    put(0, sp(Y00_F64) + sp(0.0) * z);
}

/// [`eval_x4`] over structure-of-arrays columns: coefficient `k` of direction
/// `(x[i], y[i], z[i])` goes to `out[k·len + i]` (`len = x.len()`). Any length (the tail is
/// padded with `+z` and not written).
///
/// Errors: the direction columns of different lengths, `bands > MAX_BANDS`, or `out` not of
/// length `bands²·len`.
pub fn eval_slices(
    x: &[f32],
    y: &[f32],
    z: &[f32],
    bands: usize,
    out: &mut [f32],
) -> Result<(), Error> {
    let len = x.len();
    check_shape(bands, usize::MAX)?;
    if y.len() != len || z.len() != len || out.len() != bands * bands * len {
        return Err(Error::OutOfRange {
            what: "SH column length",
            value: out.len() as f32,
            min: (bands * bands * len) as f32,
            max: (bands * bands * len) as f32,
        });
    }
    // Whole groups of four: one 16-byte store per coefficient.
    let whole = len - len % 4;
    let col = |v: &[f32], i: usize| f64x4::new(core::array::from_fn(|k| f64::from(v[i + k])));
    for i in (0..whole).step_by(4) {
        let u = unit_lanes(col(x, i), col(y, i), col(z, i));
        fill(u, bands, &mut |c, v| {
            let at = c * len + i;
            out[at..at + 4].copy_from_slice(&narrow(v));
        });
    }
    // The tail, padded with `+z` and not written.
    if whole < len {
        let live = len - whole;
        let pad = |v: &[f32], fill: f32| {
            f64x4::new(core::array::from_fn(|k| {
                f64::from(if k < live { v[whole + k] } else { fill })
            }))
        };
        let u = unit_lanes(pad(x, 0.0), pad(y, 0.0), pad(z, 1.0));
        fill(u, bands, &mut |c, v| {
            let at = c * len + whole;
            out[at..at + live].copy_from_slice(&narrow(v)[..live]);
        });
    }
    Ok(())
}
