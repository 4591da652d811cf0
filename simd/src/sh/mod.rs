//! Real spherical harmonics, four directions at a time (mirrors `steradian_core::sh`).
//!
//! [`eval_x4`] normalises each direction with the scalar kernel's own function
//! (`steradian_core::sh::unit_direction`) and runs the scalar kernel's `f64` recurrence on
//! `wide::f64x4` lanes with the same operations in the same order (the per-band constants
//! `Π_m^m` and `√2·Π_m^m` do not depend on the direction and are computed once per batch),
//! so every lane is **bit-identical** to `steradian_core::sh::eval_into`, NaN included.
//! [`eval_slices`] runs it over structure-of-arrays columns.
//!
//! # References
//!
//! Those of `steradian_core::sh` (the HVL paper, eq. 7–8).

use glam::DVec3;
use steradian_core::sh::{A, B, DIAG, SUB, Y00_F64, check_shape, tri, unit_direction};
use steradian_core::{Error, Vec3};
use wide::f64x4;

/// All `bands²` real SH at four directions: `out[k][lane]` is coefficient `k`
/// (index `l² + l + m`) of `dirs[lane]`, lane-wise `steradian_core::sh::eval_into`,
/// bit-identical.
///
/// Errors: `bands > MAX_BANDS` or `out` shorter than `bands²`.
pub fn eval_x4(dirs: [Vec3; 4], bands: usize, out: &mut [[f32; 4]]) -> Result<(), Error> {
    check_shape(bands, out.len())?;
    let u = dirs.map(unit_direction);
    let mut put = |k: usize, v: f64x4| out[k] = v.to_array().map(|x| x as f32);
    fill(u, bands, &mut put);
    // The first coefficient is written in f32 like the scalar kernel's (`Y00 + 0·z`).
    if bands > 0 {
        out[0] = u.map(|d| (Y00_F64 + 0.0 * d.z) as f32);
    }
    Ok(())
}

/// The scalar kernel's recurrence on four lanes; `put(k, v)` receives coefficient `k ≥ 1`.
#[inline(always)]
fn fill(u: [DVec3; 4], bands: usize, put: &mut impl FnMut(usize, f64x4)) {
    if bands < 2 {
        return;
    }
    let lane = |f: fn(&DVec3) -> f64| f64x4::new(u.each_ref().map(f));
    let (x, y, z) = (lane(|d| d.x), lane(|d| d.y), lane(|d| d.z));
    let r2 = x * x + y * y + z * z;
    let y00 = Y00_F64;
    let sp = f64x4::splat;
    let (mut p2, mut p1) = (sp(y00), sp(SUB[0]) * z * sp(y00));
    put(2, p1);
    for l in 2..bands {
        let k = tri(l, 0);
        let p = sp(A[k]) * (z * p1 - sp(B[k]) * r2 * p2);
        put(l * l + l, p);
        (p2, p1) = (p1, p);
    }
    let (mut pmm, mut c, mut s) = (y00, sp(1.0), sp(0.0));
    for m in 1..bands {
        pmm *= DIAG[m];
        (c, s) = (x * c - y * s, x * s + y * c);
        let q = core::f64::consts::SQRT_2 * pmm;
        let mut q2 = sp(q);
        let at = m * m + m;
        put(at + m, q2 * c);
        put(at - m, q2 * s);
        if m + 1 == bands {
            break;
        }
        let mut q1 = sp(SUB[m]) * z * q2;
        let at = at + 2 * m + 2;
        put(at + m, q1 * c);
        put(at - m, q1 * s);
        for l in m + 2..bands {
            let k = tri(l, m);
            let q = sp(A[k]) * (z * q1 - sp(B[k]) * r2 * q2);
            let at = l * l + l;
            put(at + m, q * c);
            put(at - m, q * s);
            (q2, q1) = (q1, q);
        }
    }
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
    let mut i = 0;
    while i < len {
        let live = (len - i).min(4);
        let dirs: [Vec3; 4] = core::array::from_fn(|k| {
            if k < live {
                Vec3::new(x[i + k], y[i + k], z[i + k])
            } else {
                Vec3::Z
            }
        });
        let u = dirs.map(unit_direction);
        if bands > 0 {
            for k in 0..live {
                out[i + k] = (Y00_F64 + 0.0 * u[k].z) as f32;
            }
        }
        let mut put = |c: usize, v: f64x4| {
            let a = v.to_array();
            for k in 0..live {
                out[c * len + i + k] = a[k] as f32;
            }
        };
        fill(u, bands, &mut put);
        i += 4;
    }
    Ok(())
}
