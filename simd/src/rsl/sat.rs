//! Summed-area table box queries, 8 lanes at a time (mirrors `steradian_core::rsl::sat`).
//!
//! [`box_sum`] performs the operations of `steradian_core::rsl::sat::SatView::box_sum` lane-wise:
//! the ordering and clipping of the corners with comparisons and selects, `floor`, the
//! exact fractions, the sixteen table reads (eight adjacent pairs per lane: hardware
//! gathers on x86-64 with AVX-512 or AVX2, the crate's only `unsafe` code, see `gather`;
//! elsewhere a plain loop over the lanes; every index is clipped into the table, so they
//! need no mask), the 27 exact `i64` subtractions in `i64x8`, the nine exact
//! `i64 → f64` conversions, the `f64` combination in the scalar kernel's order (no fused
//! multiply-add), the scaling by the quantum and the one rounding to `f32`. So every lane
//! is **bit-identical** to the scalar kernel, NaN lanes included (NaN exactly where a
//! corner is NaN).

use steradian_core::rsl::sat::{SatView, square_half_side};
use wide::{f32x8, f64x8, i32x8, i64x8};

use crate::lanes::{ColumnKernel, Lanes, drive, to_f64, widen};

/// One axis of 8 boxes, lane-wise `steradian_core::rsl::sat::axis`: `(I0, a0, I1, a1)`, the
/// indices as exact integers in `f32` lanes. A NaN lane gives NaN indices and fractions
/// (`entries` clips the indices into the table).
#[inline(always)]
fn axis(c0: f32x8, c1: f32x8, n: usize) -> (f32x8, f32x8, f32x8, f32x8) {
    let nf = f32x8::splat(n as f32);
    let zero = f32x8::splat(0.0);
    let clip = |x: f32x8| {
        let x = x.simd_gt(nf).select(nf, x);
        x.simd_lt(zero).select(zero, x)
    };
    let swap = c1.simd_lt(c0);
    let lo = clip(swap.select(c1, c0));
    let hi = clip(swap.select(c0, c1));
    let last = f32x8::splat((n - 1) as f32);
    let floor_min = |x: f32x8| {
        let f = x.floor();
        f.simd_gt(last).select(last, f)
    };
    let (i0, i1) = (floor_min(lo), floor_min(hi));
    (i0, lo - i0, i1, hi - i1)
}

/// Exact integers `0 ≤ x < 2²⁴` in `f32` lanes as indices (the integer path: no NaN lane).
#[inline(always)]
fn indices(x: f32x8) -> [usize; 8] {
    x.trunc_int().to_array().map(|i| i as u32 as usize)
}

/// Eight box sums: lane `k` is `sat.box_sum(u0[k], v0[k], u1[k], v1[k])`, bit-identical.
#[inline]
pub fn box_sum(sat: &SatView<'_>, u0: f32x8, v0: f32x8, u1: f32x8, v1: f32x8) -> f32x8 {
    // No NaN test, as in the scalar kernel: a NaN corner flows through `axis` without harm
    // (its indices are clipped into the table, as in `entries`) and makes its
    // fraction NaN, so its lane takes the fractional path and every term of the final
    // combination carries that fraction: the lane is NaN.
    let (i0, a0, i1, a1) = axis(u0, u1, sat.width());
    let (j0, b0, j1, b1) = axis(v0, v1, sat.height());
    let q = f64x8::splat(sat.quantum());
    // The fractions are 0 or positive (never −0), or NaN: a sum of them is 0 exactly when
    // all are 0.
    let zero = f32x8::splat(0.0);
    let integer = (a0 + a1 + b0 + b1).simd_eq(zero).all();
    if integer {
        // Every lane has integer corners: the scalar kernel's four-lookup path in every
        // lane (the same `i64` box sum, conversion, scaling and rounding).
        let (i0, i1, j0, j1) = (indices(i0), indices(i1), indices(j0), indices(j1));
        let (sums, w1) = (sat.sums(), sat.width() + 1);
        let at = |k: usize| sums.get(k).copied().unwrap_or(0);
        let s: [i64; 8] = core::array::from_fn(|k| {
            let (r0, r1) = (j0[k] * w1, j1[k] * w1);
            at(r1 + i1[k])
                .wrapping_sub(at(r1 + i0[k]))
                .wrapping_sub(at(r0 + i1[k]).wrapping_sub(at(r0 + i0[k])))
        });
        let r = (to_f64(i64x8::new(s)) * q).to_array();
        f32x8::new(r.map(|v| v as f32))
    } else {
        fractional(sat, [i0, i1, j0, j1], [a0, a1, b0, b1])
    }
}

/// The fractional path of [`box_sum`]: the scalar kernel's sixteen entries per lane
/// (`SatView::integer_terms`: rows `J0`, `J1`, and `J + 1` where the fraction is non-zero,
/// else `J` again; columns `I0`, `I0 + 1`, `I1`, `I1 + 1`), loaded lane-wise into sixteen `i64x8`, then its 27 wrapping subtractions
/// lane-wise (wrapping `i64` arithmetic is exact modulo 2⁶⁴: the scalar terms, bit for
/// bit) and the `f64` combination.
#[inline(always)]
fn fractional(sat: &SatView<'_>, ij: [f32x8; 4], [a0, a1, b0, b1]: [f32x8; 4]) -> f32x8 {
    let (rows, cols) = entries(sat, ij, [b0, b1]);
    combine(sat, &gather(sat.sums(), &rows, &cols), [a0, a1, b0, b1])
}

/// Row offsets (`J0`, `J1`, `J0 + 1` or `J0`, `J1 + 1` or `J1`) and columns (`I0`, `I1`)
/// of the sixteen entries of [`fractional`], from the indices `I0, I1, J0, J1` of [`axis`]
/// (exact integers `0 ≤ I ≤ width − 1`, `0 ≤ J ≤ height − 1` in `f32` lanes, or NaN), in
/// `i64` lanes: sides are at most `MAX_SIDE` = 2²⁴, so `width + 1` fits in `i32` and a row
/// offset `J·(width + 1)` is exact in the widening multiply's `i64`. A NaN lane's indices
/// are clipped into the table: its result is NaN whatever it reads.
#[inline(always)]
fn entries(
    sat: &SatView<'_>,
    [i0, i1, j0, j1]: [f32x8; 4],
    [b0, b1]: [f32x8; 2],
) -> ([i64x8; 4], [i64x8; 2]) {
    let side = |n: usize| i32x8::splat(n as i32);
    let (h, w1, wl) = (
        side(sat.height()),
        side(sat.width() + 1),
        side(sat.width() - 1),
    );
    let index = |x: f32x8| x.fast_trunc_int().max(i32x8::ZERO);
    // Rows are at most `height` (`J ≤ height − 1`, so `J + 1 ≤ height`).
    let row = |j: i32x8| j.min(h).widening_mul(w1);
    // `J + 1` where the fraction is non-zero, else `J` again (exact: `J + 1 ≤ 2²⁴`).
    let next = |j: f32x8, b: f32x8| j + b.simd_ne(f32x8::ZERO).select(f32x8::ONE, f32x8::ZERO);
    let rows = [
        row(index(j0)),
        row(index(j1)),
        row(index(next(j0, b0))),
        row(index(next(j1, b1))),
    ];
    // Times 1 only to widen to `i64` lanes (`wide` has no other `i32x8 → i64x8`).
    let col = |i: f32x8| index(i).min(wl).widening_mul(i32x8::ONE);
    (rows, [col(i0), col(i1)])
}

/// `st[4·row + col]`: lane `k` of each row's two column pairs, entries `rows[r][k] +
/// cols[c][k]` and the one after it. A column is at most `width − 1` and a row offset at
/// most `height·(width + 1)`, so a pair starts at most two entries before the end of the
/// table; the index is clipped into `0 ..= len − 2` as an unsigned integer all the same,
/// so that reading the pair is in bounds whatever the lanes hold (a valid view's table
/// holds at least 2 × 2 entries; one too small for a pair reads nothing).
///
/// On x86-64 the reads are hardware gathers: sixteen 8-lane ones with AVX-512
/// (`gather_avx512`), thirty-two 4-lane ones with AVX2 (`gather_avx2`); elsewhere
/// `gather_lanes`. LLVM does not make the best of that loop on x86-64: with AVX-512 it
/// forms only 4-lane gathers (it prefers 256-bit vectors on current Intel cores), and
/// for AVX2 alone (`x86-64-v3`) none at all: it loads every entry on its own and stages
/// it through memory.
#[inline(always)]
fn gather(sums: &[i64], rows: &[i64x8; 4], cols: &[i64x8; 2]) -> [i64x8; 16] {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
    {
        gather_avx512(sums, rows, cols)
    }
    #[cfg(all(
        target_arch = "x86_64",
        target_feature = "avx2",
        not(target_feature = "avx512f")
    ))]
    {
        gather_avx2(sums, rows, cols)
    }
    #[cfg(not(all(
        target_arch = "x86_64",
        any(target_feature = "avx512f", target_feature = "avx2")
    )))]
    {
        gather_lanes(sums, rows, cols)
    }
}

/// [`gather`] with AVX2's 4-lane `vpgatherqq`, four per row and column (the entry and the
/// one after it, for each half of the lanes), where the build has AVX2 but not AVX-512.
#[cfg(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    not(target_feature = "avx512f")
))]
#[allow(unsafe_code)]
#[inline(always)]
fn gather_avx2(sums: &[i64], rows: &[i64x8; 4], cols: &[i64x8; 2]) -> [i64x8; 16] {
    use core::arch::x86_64::{__m256i, _mm256_i64gather_epi64};
    use wide::{i64x4, u64x8};
    let mut st = [i64x8::ZERO; 16];
    let Some(last) = sums.len().checked_sub(2) else {
        return st;
    };
    let last = u64x8::splat(last as u64);
    let base = sums.as_ptr();
    for (r, rk) in rows.iter().enumerate() {
        for (c, ck) in cols.iter().enumerate() {
            // Clipped as unsigned, as in `gather_avx512`.
            let at = bytemuck::cast::<i64x8, u64x8>(*rk + *ck).min(last);
            let pair = |h: i64x4| -> [i64x4; 2] {
                let h = __m256i::from(h);
                // SAFETY: as in `gather_avx512`: every lane of `h` is in
                // `0 ..= sums.len() − 2` (clipped above), so the gathers read `sums[h]` and
                // `sums[h + 1]` inside the slice; the target has AVX2 (`cfg` above).
                unsafe {
                    [
                        i64x4::from(_mm256_i64gather_epi64::<8>(base, h)),
                        i64x4::from(_mm256_i64gather_epi64::<8>(base.add(1), h)),
                    ]
                }
            };
            let [lo, hi] = bytemuck::cast::<u64x8, [i64x4; 2]>(at);
            let ([e0, n0], [e1, n1]) = (pair(lo), pair(hi));
            st[4 * r + 2 * c] = bytemuck::cast([e0, e1]);
            st[4 * r + 2 * c + 1] = bytemuck::cast([n0, n1]);
        }
    }
    st
}

/// [`gather`] as a plain loop over the lanes.
#[cfg_attr(
    all(
        target_arch = "x86_64",
        any(target_feature = "avx512f", target_feature = "avx2")
    ),
    allow(dead_code)
)]
#[inline(always)]
fn gather_lanes(sums: &[i64], rows: &[i64x8; 4], cols: &[i64x8; 2]) -> [i64x8; 16] {
    let mut st = [[0i64; 8]; 16];
    let Some(last) = sums.len().checked_sub(2) else {
        return [i64x8::ZERO; 16];
    };
    let (rows, cols) = (rows.map(|r| r.to_array()), cols.map(|c| c.to_array()));
    for k in 0..8 {
        for (r, rk) in rows.iter().enumerate() {
            for (c, ck) in cols.iter().enumerate() {
                // Clipped as unsigned, as `gather_avx512` does.
                let at = (rk[k].wrapping_add(ck[k]) as u64).min(last as u64) as usize;
                st[4 * r + 2 * c][k] = sums[at];
                st[4 * r + 2 * c + 1][k] = sums[at + 1];
            }
        }
    }
    st.map(i64x8::new)
}

/// [`gather`] with AVX-512's 8-lane `vpgatherqq`, two per row and column (the entry and
/// the one after it, from the same index vector).
#[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
#[allow(unsafe_code)]
#[inline(always)]
fn gather_avx512(sums: &[i64], rows: &[i64x8; 4], cols: &[i64x8; 2]) -> [i64x8; 16] {
    use core::arch::x86_64::{__m512i, _mm512_i64gather_epi64};
    use wide::u64x8;
    let mut st = [i64x8::ZERO; 16];
    let Some(last) = sums.len().checked_sub(2) else {
        return st;
    };
    let last = u64x8::splat(last as u64);
    let base = sums.as_ptr();
    for (r, rk) in rows.iter().enumerate() {
        for (c, ck) in cols.iter().enumerate() {
            // Clipped as unsigned: a negative lane reads as 2⁶³ or more, so it too
            // becomes `last`.
            let at = __m512i::from(bytemuck::cast::<i64x8, u64x8>(*rk + *ck).min(last));
            // SAFETY: every lane of `at` is in `0 ..= sums.len() − 2` (clipped just above),
            // so both gathers read `sums[at]` and `sums[at + 1]` inside the slice; `base`
            // and `base.add(1)` point into it (`sums.len() ≥ 2`); `i64` has no invalid
            // values and no alignment beyond the slice's; the target has AVX-512F
            // (`cfg` above).
            let (lo, hi) = unsafe {
                (
                    _mm512_i64gather_epi64::<8>(at, base),
                    _mm512_i64gather_epi64::<8>(at, base.add(1)),
                )
            };
            st[4 * r + 2 * c] = i64x8::from(lo);
            st[4 * r + 2 * c + 1] = i64x8::from(hi);
        }
    }
    st
}

/// The scalar kernel's 27 subtractions, nine conversions and `f64` combination on the
/// entries `st` of [`gather`], in its order, then the quantum and the rounding to `f32`.
#[inline(always)]
fn combine(sat: &SatView<'_>, st: &[i64x8; 16], [a0, a1, b0, b1]: [f32x8; 4]) -> f32x8 {
    let row = |r: usize| -> [i64x8; 4] { core::array::from_fn(|c| st[4 * r + c]) };
    let (r0, r1, r0p, r1p) = (row(0), row(1), row(2), row(3));
    let d = |l: [i64x8; 4], m: [i64x8; 4]| -> [i64x8; 3] {
        [
            (m[2] - m[0]) - (l[2] - l[0]),
            (m[3] - m[2]) - (l[3] - l[2]),
            (m[1] - m[0]) - (l[1] - l[0]),
        ]
    };
    let [t0, t1, t2] = [d(r0, r1), d(r1, r1p), d(r0, r0p)];
    let t = [
        t0[0], t0[1], t0[2], t1[0], t1[1], t1[2], t2[0], t2[1], t2[2],
    ];
    let f = |n: usize| to_f64(t[n]);
    let (a0, a1, b0, b1) = (widen(a0), widen(a1), widen(b0), widen(b1));
    let x = |n: usize| (f(n) + a1 * f(n + 1)) - a0 * f(n + 2);
    let (x_box, x_top, x_bottom) = (x(0), x(3), x(6));
    let r = (((x_box + b1 * x_top) - b0 * x_bottom) * f64x8::splat(sat.quantum())).to_array();
    f32x8::new(r.map(|v| v as f32))
}

/// Eight squares: lane `k` is `sat.square(Vec2::new(cx[k], cy[k]), r[k])`, bit-identical.
#[inline]
pub fn square(sat: &SatView<'_>, cx: f32x8, cy: f32x8, r: f32x8) -> f32x8 {
    let h = f32x8::new(r.to_array().map(square_half_side));
    box_sum(sat, cx - h, cy - h, cx + h, cy + h)
}

/// Lanes `8c .. 8c + 8` of `x` (`W::N` is a multiple of 8).
#[inline(always)]
fn eighth<W: Lanes>(x: W, c: usize) -> f32x8 {
    f32x8::new(core::array::from_fn(|k| x.lanes()[8 * c + k]))
}

/// The 8-lane kernel `f` over every group of 8 lanes of a `W`.
#[inline(always)]
fn by_eights<W: Lanes>(f: impl Fn(usize) -> f32x8) -> W {
    let mut out = [0.0f32; 16];
    for c in 0..W::N / 8 {
        out[8 * c..8 * c + 8].copy_from_slice(f(c).as_array());
    }
    W::from_fn(|k| out[k])
}

struct BoxK<'a, 'b>(&'a SatView<'b>);
impl ColumnKernel<4, 1> for BoxK<'_, '_> {
    // Padding lanes: the empty box at the origin.
    const PADS: [f32; 4] = [0.0; 4];
    #[inline(always)]
    fn apply<W: Lanes>(&self, [u0, v0, u1, v1]: [W; 4]) -> ([W; 1], W) {
        let r = by_eights(|c| {
            box_sum(
                self.0,
                eighth(u0, c),
                eighth(v0, c),
                eighth(u1, c),
                eighth(v1, c),
            )
        });
        ([r], W::splat(0.0))
    }
}

struct SquareK<'a, 'b>(&'a SatView<'b>);
impl ColumnKernel<3, 1> for SquareK<'_, '_> {
    const PADS: [f32; 3] = [0.0; 3];
    #[inline(always)]
    fn apply<W: Lanes>(&self, [cx, cy, r]: [W; 3]) -> ([W; 1], W) {
        let out = by_eights(|c| square(self.0, eighth(cx, c), eighth(cy, c), eighth(r, c)));
        ([out], W::splat(0.0))
    }
}

/// [`box_sum`] over columns: `out[i] = sat.box_sum(u0[i], v0[i], u1[i], v1[i])`. Any length
/// (the tail is padded with empty boxes).
///
/// # Panics
/// If the columns do not all have the same length.
pub fn box_sum_slices(
    sat: &SatView<'_>,
    u0: &[f32],
    v0: &[f32],
    u1: &[f32],
    v1: &[f32],
    out: &mut [f32],
) {
    drive::<f32x8, _, 4, 1>("sat::box_sum_slices", &BoxK(sat), [u0, v0, u1, v1], [out]);
}

/// [`square`] over columns: `out[i] = sat.square((cx[i], cy[i]), r[i])`. Any length.
///
/// # Panics
/// If the columns do not all have the same length.
pub fn square_slices(sat: &SatView<'_>, cx: &[f32], cy: &[f32], r: &[f32], out: &mut [f32]) {
    drive::<f32x8, _, 3, 1>("sat::square_slices", &SquareK(sat), [cx, cy, r], [out]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::tests::same;

    /// The x86 gathers (AVX-512 or AVX2, whichever the build has) read what the plain
    /// lane loop reads, for indices in the table, at its last pair, beyond its end,
    /// wrapping and negative (all clip them as unsigned integers: to the last pair), and
    /// on a table too small to hold a pair (all read nothing).
    #[cfg(all(
        target_arch = "x86_64",
        any(target_feature = "avx512f", target_feature = "avx2")
    ))]
    #[test]
    fn x86_gathers_read_what_the_lane_loop_reads() {
        let sums: Vec<i64> = (0..40i64).map(|k| k * k * 7919 - 3 * k).collect();
        let last = sums.len() as i64 - 2;
        let picks = [0, 1, 5, last - 1, last, last + 1, i64::MAX, -1, i64::MIN];
        for s in 0..picks.len() {
            let lane = |k: usize, m: usize| picks[(s + k * m) % picks.len()];
            let rows: [i64x8; 4] =
                core::array::from_fn(|r| i64x8::new(core::array::from_fn(|k| lane(k, r + 1))));
            // Columns are small and non-negative, as `entries` makes them, so a row's
            // extreme values stay extreme in the sum.
            let cols: [i64x8; 2] =
                core::array::from_fn(|c| i64x8::new(core::array::from_fn(|k| (k + c) as i64)));
            for table in [&sums[..], &sums[..2], &sums[..1], &[][..]] {
                let (a, b) = (
                    gather(table, &rows, &cols),
                    gather_lanes(table, &rows, &cols),
                );
                for (x, y) in a.iter().zip(&b) {
                    assert_eq!(x.to_array(), y.to_array(), "table of {}", table.len());
                }
            }
        }
    }

    #[test]
    fn lanes_match_scalar_on_special_corners() {
        let (w, h) = (7, 5);
        let t: Vec<f32> = (0..w * h)
            .map(|k| ((k * 37 % 11) as f32 - 4.0) * 0.3)
            .collect();
        let mut sums = vec![0i64; (w + 1) * (h + 1)];
        let v = SatView::build_into(w, h, &t, &mut sums).unwrap();
        let specials = [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            0.0,
            -0.0,
            1e-45,
            0.5,
            3.25,
            5.0,
            7.0,
            7.5,
            -2.0,
            f32::MAX,
        ];
        let mut us = Vec::new();
        for &a in &specials {
            for &b in &specials {
                us.push((a, b));
            }
        }
        for (k, &(a, b)) in us.iter().enumerate() {
            let (c, d) = us[(k * 7 + 3) % us.len()];
            let lanes = |x: f32| f32x8::new(core::array::from_fn(|l| x + l as f32 * 0.0));
            let r = box_sum(&v, lanes(a), lanes(c), lanes(b), lanes(d));
            let want = v.box_sum(a, c, b, d);
            for got in r.to_array() {
                assert!(same(got, want), "{a} {c} {b} {d}: {got} vs {want}");
            }
        }
    }
}
