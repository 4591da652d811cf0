//! Real spherical harmonics, four or eight directions at a time (mirrors
//! `steradian_core::sh`).
//!
//! [`eval_x4`] ([`eval_x8`]) forms the point of `steradian_core::sh::point` on `wide::f64x4`
//! (`f64x8`) lanes (one correctly rounded square root and division per lane), in the form
//! `steradian_core::sh::form` picks for the band count, and runs the scalar kernel's `f64`
//! recurrence on the lanes with
//! the same operations in the same order, the same orders `m` grouped by
//! `steradian_core::sh::CHAINS` (the per-order constants `Π_m^m` and `√2·Π_m^m` do not
//! depend on the direction and are computed once per batch), so every lane is
//! **bit-identical** to `steradian_core::sh::eval_into`, NaN included. [`eval_slices`] runs
//! it over structure-of-arrays columns, eight directions per pass where the build enables
//! AVX-512F (one `f64x8` per 512-bit register), four otherwise.
//!
//! # References
//!
//! Those of `steradian_core::sh` (the HVL paper, eq. 7–8).

pub mod cap;
pub mod hvl;
pub mod irradiance;
pub mod rotate;

use core::ops::{Add, Mul, Sub};
use steradian_core::sh::{
    A, AB, CHAINS, DIAG, HOMOGENEOUS_MAX_BANDS, MAX_BANDS, MAX_GROUP, SUB, Y00_F64, check_shape,
    group, tri,
};
#[rustfmt::skip]
mod fixed;

use steradian_core::{Error, Vec3};
use wide::{f64x4, f64x8};

/// `f64` lanes of any width: what [`fill`] needs.
trait F64Lanes: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> {
    fn splat(v: f64) -> Self;
}

macro_rules! lanes_kernels {
    ($t:ident, $n:literal, $eval:ident, $narrow:ident, $point:ident, $words:literal) => {
        impl F64Lanes for $t {
            #[inline(always)]
            fn splat(v: f64) -> Self {
                $t::splat(v)
            }
        }

        #[doc = concat!("All `bands²` real SH at ", $words, " directions: `out[k][lane]` is coefficient `k`")]
        /// (index `l² + l + m`) of `dirs[lane]`, lane-wise `steradian_core::sh::eval_into`,
        /// bit-identical.
        ///
        /// Errors: `bands > MAX_BANDS` or `out` shorter than `bands²`.
        pub fn $eval(dirs: [Vec3; $n], bands: usize, out: &mut [[f32; $n]]) -> Result<(), Error> {
            check_shape(bands, out.len())?;
            let lanes = |f: fn(&Vec3) -> f32| $t::new(dirs.each_ref().map(|d| f64::from(f(d))));
            let u = $point(lanes(|d| d.x), lanes(|d| d.y), lanes(|d| d.z));
            fill(u, bands, &mut |k, v| out[k] = $narrow(v));
            Ok(())
        }

        /// The lanes rounded to `f32` (the scalar kernel's `as f32`).
        #[inline(always)]
        fn $narrow(v: $t) -> [f32; $n] {
            let a = v.to_array();
            core::array::from_fn(|k| a[k] as f32)
        }

        /// `steradian_core::sh::point` on the lanes, `[x, y, z, r², 1/√r²]`: the same
        /// operations (`r²` summed left to right, one square root and one division), `+z`
        /// with `r² = 1/√r² = 1` where `r² = 0`, NaN where `r²` is not finite.
        #[inline(always)]
        fn $point(x: $t, y: $t, z: $t) -> [$t; 5] {
            let r2 = x * x + y * y + z * z;
            let zero = r2.simd_eq($t::ZERO);
            let finite = r2.simd_lt($t::splat(f64::INFINITY));
            let inv = $t::ONE / r2.sqrt();
            let nan = $t::splat(f64::NAN);
            let fix = |v: $t, at_zero: f64| finite.select(zero.select($t::splat(at_zero), v), nan);
            [fix(x, 0.0), fix(y, 0.0), fix(z, 1.0), fix(r2, 1.0), fix(inv, 1.0)]
        }
    };
}

lanes_kernels!(f64x4, 4, eval_x4, narrow4, point_lanes4, "four");
lanes_kernels!(f64x8, 8, eval_x8, narrow8, point_lanes8, "eight");

/// The scalar kernel's recurrence (`steradian_core::sh`'s `fill`) on the lanes;
/// `put(k, v)` receives coefficient `k` (the sine part of each `(l, m)` before its cosine
/// part, coefficient 0 last, as the scalar kernel writes them).
#[inline(always)]
fn fill<F: F64Lanes>(u: [F; 5], bands: usize, put: &mut impl FnMut(usize, F)) {
    // The straight-line code generated from this recurrence for 2–10 bands (the same
    // operations per value, as the scalar kernel's).
    match bands {
        0 => {}
        2 => fixed::fill_2(form(u, 2), put),
        3 => fixed::fill_3(form(u, 3), put),
        4 => fixed::fill_4(form(u, 4), put),
        5 => fixed::fill_5(form(u, 5), put),
        6 => fixed::fill_6(form(u, 6), put),
        7 => fixed::fill_7(form(u, 7), put),
        8 => fixed::fill_8(form(u, 8), put),
        9 => fixed::fill_9(form(u, 9), put),
        10 => fixed::fill_10(form(u, 10), put),
        _ if bands > HOMOGENEOUS_MAX_BANDS => fill_loop::<false, F>(form(u, bands), bands, put),
        _ => fill_short(u, bands, put),
    }
}

/// The homogeneous loop for 0 and 1 bands, out of line (as the scalar kernel's
/// `fill_short`: a second inlined copy of the loop slows the normalised one).
#[inline(never)]
fn fill_short<F: F64Lanes>(u: [F; 5], bands: usize, put: &mut impl FnMut(usize, F)) {
    fill_loop::<true, F>(u, bands, put);
}

/// `steradian_core::sh::form` on the lanes: `[x·inv, y·inv, z·inv, 1, 1]` beyond
/// `HOMOGENEOUS_MAX_BANDS` (`Point::normalized`), the homogeneous point otherwise.
#[inline(always)]
fn form<F: F64Lanes>(u: [F; 5], bands: usize) -> [F; 5] {
    if bands <= HOMOGENEOUS_MAX_BANDS {
        u
    } else {
        let [x, y, z, _, inv] = u;
        [x * inv, y * inv, z * inv, F::splat(1.0), F::splat(1.0)]
    }
}

/// The loop of [`fill`] (band counts without straight-line code), on the point `u` of the
/// form [`form`] chose; `H = false` skips the products by `r^−l = 1` (the scalar loop's
/// `H`).
// `l` is the band: it indexes the coefficient tables and the output as well as `il`.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn fill_loop<const H: bool, F: F64Lanes>(u: [F; 5], bands: usize, put: &mut impl FnMut(usize, F)) {
    let scaled = |v: F, il: F| if H { v * il } else { v };
    let [x, y, z, r2, inv] = u;
    let sp = F::splat;
    let step = |k: usize, q1: F, q2: F| sp(A[k]) * z * q1 - sp(AB[k]) * r2 * q2;
    // r^−l as the scalar kernel's `il[l] = il[l−1]·inv`; unused in the normalised form.
    let mut il = [sp(1.0); MAX_BANDS];
    if H {
        for l in 1..bands {
            il[l] = il[l - 1] * inv;
        }
    }
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
                put(at - m, scaled(q * ss[j], il[l]));
                put(at + m, scaled(q * cc[j], il[l]));
            }
            (q1[j], q2[j]) = (p1, p2);
        }
        // The long run in `l` (`g = CHAINS` here): the chains' state in fixed-size copies,
        // indexed only by constants, so that it stays in registers.
        let (mut p1, mut p2) = (chains(&q1), chains(&q2));
        let (ss, cc) = (chains(&ss), chains(&cc));
        for l in head..bands {
            let at = l * l + l;
            let k = tri(l, m0);
            for j in 0..CHAINS {
                let q = step(k + j, p1[j], p2[j]);
                (p2[j], p1[j]) = (p1[j], q);
                put(at - m0 - j, scaled(q * ss[j], il[l]));
                put(at + m0 + j, scaled(q * cc[j], il[l]));
            }
        }
        m0 += g;
    }
    put(0, sp(Y00_F64) + sp(0.0) * z);
}

/// The first [`CHAINS`] entries of a group's state.
#[inline(always)]
fn chains<F: F64Lanes>(v: &[F; MAX_GROUP]) -> [F; CHAINS] {
    core::array::from_fn(|j| v[j])
}

/// Directions per pass of [`eval_slices`]: 8 where the build enables AVX-512F, 4 otherwise.
pub const SLICE_LANES: usize = slice_lanes::N;

/// Lanes of [`eval_slices`]: `f64x8` where the build enables AVX-512F, `f64x4` otherwise.
#[cfg(target_feature = "avx512f")]
mod slice_lanes {
    pub(super) use super::{narrow8 as narrow, point_lanes8 as point_lanes};
    pub(super) use wide::f64x8 as L;
    pub(super) const N: usize = 8;
}
#[cfg(not(target_feature = "avx512f"))]
mod slice_lanes {
    pub(super) use super::{narrow4 as narrow, point_lanes4 as point_lanes};
    pub(super) use wide::f64x4 as L;
    pub(super) const N: usize = 4;
}

/// [`eval_x8`] (AVX-512F builds) or [`eval_x4`] over structure-of-arrays columns:
/// coefficient `k` of direction `(x[i], y[i], z[i])` goes to `out[k·len + i]`
/// (`len = x.len()`). Any length (the tail is padded with `+z` and not written).
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
    // Straight-line code for the band counts renderers use most, as the scalar kernel
    // (the count a constant: same operations, same bits).
    match bands {
        2 => columns::<false>(x, y, z, 2, out),
        3 => columns::<false>(x, y, z, 3, out),
        4 => columns::<false>(x, y, z, 4, out),
        5 => columns::<false>(x, y, z, 5, out),
        6 => columns::<false>(x, y, z, 6, out),
        7 => columns::<false>(x, y, z, 7, out),
        8 => columns::<false>(x, y, z, 8, out),
        9 => columns::<false>(x, y, z, 9, out),
        10 => columns::<false>(x, y, z, 10, out),
        _ => columns_any(x, y, z, bands, out),
    }
    Ok(())
}

/// [`columns`] for the band counts without straight-line code, out of line (inlined beside
/// the ten constant-count copies it ran slower).
#[inline(never)]
fn columns_any(x: &[f32], y: &[f32], z: &[f32], bands: usize, out: &mut [f32]) {
    columns::<true>(x, y, z, bands, out);
}

/// The loops of [`eval_slices`] (shapes checked by it).
///
/// `LOOP`: the band count is not a constant (`fill_loop` runs). Then a single pass
/// (`len = N`) stores whole rows of `out.as_chunks_mut::<N>()`, one bound check per
/// coefficient instead of the slice's two; and over several passes the store closure owns
/// its copies of the row, the length and the output slice, so the loop does not reload
/// them after each store. Both are faster for the loop and were slower for the
/// straight-line code (`steradian report --section sh`).
#[inline(always)]
fn columns<const LOOP: bool>(x: &[f32], y: &[f32], z: &[f32], bands: usize, out: &mut [f32]) {
    use slice_lanes::{L, N, narrow, point_lanes};
    let len = x.len();
    // Whole groups of lanes: one store of `N` values per coefficient.
    let whole = len - len % N;
    let col = |v: &[f32], i: usize| L::new(core::array::from_fn(|k| f64::from(v[i + k])));
    if LOOP && len == N {
        // One pass: `out` is `bands²` rows of `N` lanes, and each store is one row.
        let u = point_lanes(col(x, 0), col(y, 0), col(z, 0));
        let (rows, _) = out.as_chunks_mut::<N>();
        fill(u, bands, &mut |c, v| rows[c] = narrow(v));
        return;
    }
    for i in (0..whole).step_by(N) {
        let u = point_lanes(col(x, i), col(y, i), col(z, i));
        if LOOP {
            let dst = &mut *out;
            fill(u, bands, &mut move |c, v| {
                let at = c * len + i;
                dst[at..at + N].copy_from_slice(&narrow(v));
            });
        } else {
            fill(u, bands, &mut |c, v| {
                let at = c * len + i;
                out[at..at + N].copy_from_slice(&narrow(v));
            });
        }
    }
    // The tail, padded with `+z` and not written.
    if whole < len {
        let live = len - whole;
        let pad = |v: &[f32], fill: f32| {
            L::new(core::array::from_fn(|k| {
                f64::from(if k < live { v[whole + k] } else { fill })
            }))
        };
        let u = point_lanes(pad(x, 0.0), pad(y, 0.0), pad(z, 1.0));
        fill(u, bands, &mut |c, v| {
            let at = c * len + whole;
            out[at..at + live].copy_from_slice(&narrow(v)[..live]);
        });
    }
}
