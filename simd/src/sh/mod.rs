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

pub mod rotate;

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
    // m ≥ 1, two orders per pass (the scalar kernel's pairing: same operations per value).
    let step = |l: usize, m: usize, q1: f64x4, q2: f64x4| {
        let k = tri(l, m);
        sp(A[k]) * (z * q1 - sp(B[k]) * r2 * q2)
    };
    let (mut pmm, mut c, mut s) = (y00, sp(1.0), sp(0.0));
    let mut m = 1;
    while m < bands {
        pmm *= DIAG[m];
        (c, s) = (x * c - y * s, x * s + y * c);
        let (ca, sa) = (c, s);
        let mut a2 = sp(core::f64::consts::SQRT_2 * pmm);
        let at = m * m + m;
        put(at + m, a2 * ca);
        put(at - m, a2 * sa);
        if m + 1 == bands {
            break;
        }
        let mut a1 = sp(SUB[m]) * z * a2;
        let at = (m + 1) * (m + 1) + m + 1;
        put(at + m, a1 * ca);
        put(at - m, a1 * sa);
        pmm *= DIAG[m + 1];
        (c, s) = (x * c - y * s, x * s + y * c);
        let (cb, sb) = (c, s);
        let mut b2 = sp(core::f64::consts::SQRT_2 * pmm);
        put(at + m + 1, b2 * cb);
        put(at - m - 1, b2 * sb);
        if m + 2 == bands {
            break;
        }
        let q = step(m + 2, m, a1, a2);
        let at = (m + 2) * (m + 2) + m + 2;
        put(at + m, q * ca);
        put(at - m, q * sa);
        (a2, a1) = (a1, q);
        let mut b1 = sp(SUB[m + 1]) * z * b2;
        put(at + m + 1, b1 * cb);
        put(at - m - 1, b1 * sb);
        for l in m + 3..bands {
            let qa = step(l, m, a1, a2);
            let qb = step(l, m + 1, b1, b2);
            let at = l * l + l;
            put(at + m, qa * ca);
            put(at - m, qa * sa);
            put(at + m + 1, qb * cb);
            put(at - m - 1, qb * sb);
            (a2, a1) = (a1, qa);
            (b2, b1) = (b1, qb);
        }
        m += 2;
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
            let a = v.to_array().map(|x| x as f32);
            let at = c * len + i;
            if live == 4 {
                // One 16-byte store per coefficient.
                out[at..at + 4].copy_from_slice(&a);
            } else {
                out[at..at + live].copy_from_slice(&a[..live]);
            }
        };
        fill(u, bands, &mut put);
        i += 4;
    }
    Ok(())
}
