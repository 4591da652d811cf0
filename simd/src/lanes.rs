//! The lane layer under the kernels: one private trait over `wide::f32x8` and
//! `wide::f32x16`, so each kernel is written once and runs on the 8-lane batches of the
//! public API and on the widest vector of the build in the slice functions.
//!
//! Also the lane-wise spellings of the scalar `f32` semantics that SIMD instructions do not
//! share (`f32::max`/`min` ignore NaN, `f32::clamp` keeps it), and the column driver of
//! the slice functions.

use core::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

use wide::{f32x8, f32x16, f64x8, i64x8, u64x8};

/// `x as f64` lane-wise: the nearest `f64`, ties to even, for every `i64`, as the scalar
/// kernels' `as f64`.
///
/// With AVX-512DQ one `vcvtqq2pd`; elsewhere (AVX2 has no such conversion, and `wide`
/// converts lane by lane) with two exact conversions and one rounding: write the biased
/// `x + 2⁶³ = h·2³² + l` (`h, l < 2³²`); the bit patterns `0x453…h` and `0x433…l` are
/// `H = 2⁸⁴ + h·2³²` and `L = 2⁵² + l`, so `(H − (2⁸⁴ + 2⁶³ + 2⁵²)) + L = x`, where the
/// subtraction is exact (its result `(h − 2³¹)·2³² − 2⁵²`, a multiple of 2³² below 2⁶⁴ in
/// magnitude, needs at most 32 significant bits) and the addition is the one rounding.
#[inline(always)]
pub(crate) fn to_f64(x: i64x8) -> f64x8 {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx512dq"))]
    {
        x.round_float()
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx512dq")))]
    {
        to_f64_split(x)
    }
}

/// The split conversion of [`to_f64`] (also tested where `to_f64` does not use it).
#[cfg_attr(
    all(target_arch = "x86_64", target_feature = "avx512dq"),
    allow(dead_code)
)]
#[inline(always)]
pub(crate) fn to_f64_split(x: i64x8) -> f64x8 {
    let u = bytemuck::cast::<i64x8, u64x8>(x) ^ u64x8::splat(1 << 63);
    let h = u.unbounded_shr_scalar(32) | u64x8::splat(0x4530_0000_0000_0000);
    let l = (u & u64x8::splat(0xffff_ffff)) | u64x8::splat(0x4330_0000_0000_0000);
    // 2⁸⁴ + 2⁶³ + 2⁵² (the bits of 2⁸⁴·(1 + 2⁻²¹ + 2⁻³²)).
    let c = f64x8::splat(f64::from_bits(0x4530_0000_8010_0000));
    (bytemuck::cast::<u64x8, f64x8>(h) - c) + bytemuck::cast::<u64x8, f64x8>(l)
}

/// Eight `f32` lanes as `f64` (exact).
#[inline(always)]
pub(crate) fn widen(x: f32x8) -> f64x8 {
    f64x8::new(x.to_array().map(f64::from))
}

/// Eight `f64` lanes rounded to `f32` (as `as f32` rounds each).
#[inline(always)]
pub(crate) fn narrow(x: f64x8) -> f32x8 {
    f32x8::new(x.to_array().map(|v| v as f32))
}

/// The vector the slice functions use: `f32x16` (one AVX-512 register) where the build
/// enables AVX-512F, `f32x8` otherwise (one AVX register, or two 128-bit halves).
#[cfg(target_feature = "avx512f")]
pub(crate) type SliceVec = f32x16;
/// The vector the slice functions use: `f32x16` (one AVX-512 register) where the build
/// enables AVX-512F, `f32x8` otherwise (one AVX register, or two 128-bit halves).
#[cfg(not(target_feature = "avx512f"))]
pub(crate) type SliceVec = f32x8;

/// A vector of `f32` lanes. Masks are vectors too (all-ones or all-zeros lanes), as in
/// `wide`. Every method is the lane-wise IEEE operation of the same name.
pub(crate) trait Lanes:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + BitOr<Output = Self>
    + BitAnd<Output = Self>
    + Not<Output = Self>
{
    /// Number of lanes.
    const N: usize;
    fn splat(x: f32) -> Self;
    /// Lane `k` is `f(k)`.
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self;
    /// Loads exactly `N` values (`s.len() == N`).
    fn load(s: &[f32]) -> Self;
    /// Stores exactly `N` values (`s.len() == N`).
    fn store(self, s: &mut [f32]);
    fn lanes(&self) -> &[f32];
    fn abs(self) -> Self;
    fn sqrt(self) -> Self;
    /// Round up to an integer (IEEE `ceil`, exact).
    fn ceil(self) -> Self;
    fn exp(self) -> Self;
    fn ln_1p(self) -> Self;
    fn ln(self) -> Self;
    fn exp_m1(self) -> Self;
    /// `atan2(self, x)`.
    fn atan2(self, x: Self) -> Self;
    /// Round toward zero (IEEE `trunc`, exact).
    fn trunc(self) -> Self;
    fn is_nan(self) -> Self;
    /// x86 `maxps` semantics where the build has SSE: `if self > o { self } else { o }`.
    fn fast_max(self, o: Self) -> Self;
    /// x86 `minps` semantics where the build has SSE: `if self < o { self } else { o }`.
    fn fast_min(self, o: Self) -> Self;
    fn lt(self, o: Self) -> Self;
    fn le(self, o: Self) -> Self;
    fn gt(self, o: Self) -> Self;
    fn ge(self, o: Self) -> Self;
    fn eq(self, o: Self) -> Self;
    /// `self` is a mask: lane-wise `if self { t } else { f }`.
    fn select(self, t: Self, f: Self) -> Self;
    /// `self` is a mask: whether any lane is set.
    fn any(self) -> bool;
    /// `(table[i], table[i + 1])` for each lane's index `i` (`self` holds exact integers
    /// `0 ≤ i ≤ table.len() − 2`, `table.len() ≤ 2²⁴`; out-of-range lanes are clamped to
    /// `table.len() − 2`, and a table shorter than 2 panics).
    fn gather_pair(self, table: &[f32]) -> (Self, Self);
    /// Each lane `as usize` (saturating: NaN and negatives to 0) into `out[..N]`, for
    /// lanes below `2³¹` (one vector conversion instead of one per lane).
    fn to_indices(self, out: &mut [usize; 16]);
}

macro_rules! impl_lanes {
    ($t:ident, $n:literal) => {
        impl Lanes for $t {
            const N: usize = $n;
            #[inline(always)]
            fn splat(x: f32) -> Self {
                $t::splat(x)
            }
            #[inline(always)]
            fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
                $t::new(core::array::from_fn(f))
            }
            #[inline(always)]
            fn load(s: &[f32]) -> Self {
                $t::new(s.try_into().unwrap())
            }
            #[inline(always)]
            fn store(self, s: &mut [f32]) {
                s.copy_from_slice(self.as_array());
            }
            #[inline(always)]
            fn lanes(&self) -> &[f32] {
                self.as_array()
            }
            #[inline(always)]
            fn abs(self) -> Self {
                $t::abs(self)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $t::sqrt(self)
            }
            #[inline(always)]
            fn ceil(self) -> Self {
                $t::ceil(self)
            }
            #[inline(always)]
            fn exp(self) -> Self {
                $t::exp(self)
            }
            #[inline(always)]
            fn ln_1p(self) -> Self {
                $t::ln_1p(self)
            }
            #[inline(always)]
            fn ln(self) -> Self {
                $t::ln(self)
            }
            #[inline(always)]
            fn exp_m1(self) -> Self {
                $t::exp_m1(self)
            }
            #[inline(always)]
            fn atan2(self, x: Self) -> Self {
                $t::atan2(self, x)
            }
            #[inline(always)]
            fn trunc(self) -> Self {
                $t::trunc(self)
            }
            #[inline(always)]
            fn is_nan(self) -> Self {
                $t::is_nan(self)
            }
            #[inline(always)]
            fn fast_max(self, o: Self) -> Self {
                $t::fast_max(self, o)
            }
            #[inline(always)]
            fn fast_min(self, o: Self) -> Self {
                $t::fast_min(self, o)
            }
            #[inline(always)]
            fn lt(self, o: Self) -> Self {
                self.simd_lt(o)
            }
            #[inline(always)]
            fn le(self, o: Self) -> Self {
                self.simd_le(o)
            }
            #[inline(always)]
            fn gt(self, o: Self) -> Self {
                self.simd_gt(o)
            }
            #[inline(always)]
            fn ge(self, o: Self) -> Self {
                self.simd_ge(o)
            }
            #[inline(always)]
            fn eq(self, o: Self) -> Self {
                self.simd_eq(o)
            }
            #[inline(always)]
            fn select(self, t: Self, f: Self) -> Self {
                $t::select(self, t, f)
            }
            #[inline(always)]
            fn any(self) -> bool {
                $t::any(self)
            }
            #[inline(always)]
            fn gather_pair(self, table: &[f32]) -> (Self, Self) {
                // Exact integers below 2²⁴: the conversion is exact.
                let idx = self.fast_trunc_int().to_array();
                let m = table.len() - 2;
                let mut h0 = [0.0f32; $n];
                let mut h1 = [0.0f32; $n];
                for k in 0..$n {
                    // `min` keeps every index in bounds (and lets the checks go).
                    let j = (idx[k] as u32 as usize).min(m);
                    h0[k] = table[j];
                    h1[k] = table[j + 1];
                }
                ($t::new(h0), $t::new(h1))
            }
            #[inline(always)]
            fn to_indices(self, out: &mut [usize; 16]) {
                // `fast_trunc_int` gives `i32::MIN` for NaN: `max(0)` makes it 0, as `as`.
                for (o, i) in out.iter_mut().zip(self.fast_trunc_int().to_array()) {
                    *o = i.max(0) as usize;
                }
            }
        }
    };
}

impl_lanes!(f32x8, 8);
impl_lanes!(f32x16, 16);

/// `f32::max` lane-wise: if one operand is NaN the other is returned. Used on operands
/// that are never `±0` of opposite signs, where `f32::max` leaves the choice open.
///
/// x86 `maxps` computes `if a > b { a } else { b }`, so it returns `b` when either operand
/// is NaN: right when `a` is NaN, and a blend fixes the lanes where `b` is NaN (the
/// sequence LLVM emits for `f32::max`). Elsewhere wide's fast max has other NaN rules, so
/// the selection is spelled out with comparisons.
#[inline(always)]
pub(crate) fn max_num<W: Lanes>(a: W, b: W) -> W {
    if cfg!(target_feature = "sse") {
        max_num_sse(a, b)
    } else {
        max_num_cmp(a, b)
    }
}

/// `f32::min` lane-wise: if one operand is NaN the other is returned (see [`max_num`]).
#[inline(always)]
pub(crate) fn min_num<W: Lanes>(a: W, b: W) -> W {
    if cfg!(target_feature = "sse") {
        min_num_sse(a, b)
    } else {
        min_num_cmp(a, b)
    }
}

#[inline(always)]
fn max_num_sse<W: Lanes>(a: W, b: W) -> W {
    b.is_nan().select(a, a.fast_max(b))
}

#[inline(always)]
fn min_num_sse<W: Lanes>(a: W, b: W) -> W {
    b.is_nan().select(a, a.fast_min(b))
}

#[inline(always)]
fn max_num_cmp<W: Lanes>(a: W, b: W) -> W {
    (a.ge(b) | b.is_nan()).select(a, b)
}

#[inline(always)]
fn min_num_cmp<W: Lanes>(a: W, b: W) -> W {
    (a.le(b) | b.is_nan()).select(a, b)
}

/// `f32::clamp` lane-wise (`lo ≤ hi`, neither NaN): NaN stays NaN.
///
/// `f32::clamp` is `if x < lo { lo }` then `if x > hi { hi }`. With SSE that is
/// `minps(hi, maxps(lo, x))`: `maxps(lo, x)` is `if lo > x { lo } else { x }`, which keeps
/// a NaN `x`, and likewise for `minps` (the sequence LLVM emits for `f32::clamp`).
#[inline(always)]
pub(crate) fn clamp<W: Lanes>(x: W, lo: W, hi: W) -> W {
    if cfg!(target_feature = "sse") {
        clamp_sse(x, lo, hi)
    } else {
        clamp_cmp(x, lo, hi)
    }
}

#[inline(always)]
fn clamp_sse<W: Lanes>(x: W, lo: W, hi: W) -> W {
    hi.fast_min(lo.fast_max(x))
}

#[inline(always)]
fn clamp_cmp<W: Lanes>(x: W, lo: W, hi: W) -> W {
    let x = x.lt(lo).select(lo, x);
    x.gt(hi).select(hi, x)
}

/// The lanes of `s` from `offset` that exist, the rest `pad`.
#[inline(always)]
pub(crate) fn load_padded<W: Lanes>(s: &[f32], offset: usize, pad: f32) -> W {
    W::from_fn(|k| {
        offset
            .checked_add(k)
            .and_then(|i| s.get(i))
            .copied()
            .unwrap_or(pad)
    })
}

/// Writes the lanes of `v` that fit in `s` from `offset` on.
#[inline(always)]
pub(crate) fn store_partial<W: Lanes>(v: W, s: &mut [f32], offset: usize) {
    let end = s.len().min(offset.saturating_add(W::N));
    if offset < end {
        s[offset..end].copy_from_slice(&v.lanes()[..end - offset]);
    }
}

/// A lane kernel from `I` input columns to `O` output columns, generic over the vector
/// width. Implementations mark `apply` `#[inline(always)]`, so it is inlined at both call
/// sites of [`drive`] (a closure would be outlined and called per vector).
pub(crate) trait ColumnKernel<const I: usize, const O: usize> {
    /// Values of the padding lanes of a tail, one per input column.
    const PADS: [f32; I];
    /// The outputs, and a mask of lanes to recompute with [`ColumnKernel::redo`] (all
    /// clear for kernels that never need it, which the compiler then folds away).
    fn apply<W: Lanes>(&self, v: [W; I]) -> ([W; O], W);
    /// Recomputes the lanes set in `mask` of the vector at `offset` from the input columns
    /// (read again from memory, so `apply` need not keep its inputs in registers). Lanes
    /// past the end of the columns are never set.
    fn redo<W: Lanes>(&self, ins: [&[f32]; I], offset: usize, mask: W, r: [W; O]) -> [W; O] {
        let _ = (ins, offset, mask);
        r
    }
}

/// Runs `k` over `I` input columns into `O` output columns of one length: whole vectors of
/// `W::N` lanes, then one vector padded with `K::PADS` for the tail (its extra lanes are
/// computed and dropped).
///
/// # Panics
/// If the columns do not all have the same length (`what` names the caller).
#[inline(always)]
pub(crate) fn drive<W: Lanes, K: ColumnKernel<I, O>, const I: usize, const O: usize>(
    what: &str,
    k: &K,
    ins: [&[f32]; I],
    mut outs: [&mut [f32]; O],
) {
    let n = if O > 0 { outs[0].len() } else { 0 };
    assert!(
        ins.iter().all(|c| c.len() == n) && outs.iter().all(|c| c.len() == n),
        "{what}: column lengths differ"
    );
    let full = n - n % W::N;
    let mut i = 0;
    while i < full {
        let (mut r, redo) = k.apply::<W>(core::array::from_fn(|c| W::load(&ins[c][i..i + W::N])));
        if redo.any() {
            r = k.redo(ins, i, redo, r);
        }
        for (o, v) in outs.iter_mut().zip(r) {
            v.store(&mut o[i..i + W::N]);
        }
        i += W::N;
    }
    if full < n {
        let (mut r, redo) = k.apply::<W>(core::array::from_fn(|c| {
            load_padded(ins[c], full, K::PADS[c])
        }));
        // Padding lanes are dropped: never recompute them.
        let real = W::from_fn(|l| {
            if full + l < n {
                f32::from_bits(!0)
            } else {
                0.0
            }
        });
        let redo = redo & real;
        if redo.any() {
            r = k.redo(ins, full, redo, r);
        }
        for (o, v) in outs.iter_mut().zip(r) {
            store_partial(v, o, full);
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    const VALUES: [f32; 14] = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        0.0,
        -0.0,
        1e-45,
        -1e-40,
        f32::MIN_POSITIVE,
        1.0,
        -1.0,
        2.5,
        f32::MAX,
        -f32::MAX,
        1e30,
    ];

    /// Bitwise equality, any NaN equal to any NaN (the lane-by-lane test of the kernels).
    pub(crate) fn same(a: f32, b: f32) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    /// A seeded stream of uniform `f32` in `[0, 1)` (Knuth's MMIX LCG, the top 24 bits) for
    /// the unit tests' random inputs.
    pub(crate) fn uniform(seed: u64) -> impl FnMut() -> f32 {
        let mut s = seed;
        move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// The split `i64 → f64` conversion (and `to_f64`, whichever it uses) is `as f64` bit
    /// for bit in every lane: the ends of the range, the powers of two and their
    /// neighbours (where `f64` runs out of bits, ties included: 2⁵³ + 1 and 2⁶² + 2⁹ are
    /// halfway cases), the split's own boundary (2³² ± 1) and random patterns.
    #[test]
    fn i64_to_f64_is_correctly_rounded_in_every_lane() {
        let mut v = vec![0i64, 1, -1, i64::MAX, i64::MIN, i64::MIN + 1, i64::MAX - 1];
        for e in 0..63 {
            let p = 1i64 << e;
            for d in [-3i64, -1, 0, 1, 3] {
                v.extend([p.wrapping_add(d), p.wrapping_add(d).wrapping_neg()]);
            }
        }
        v.extend([
            (1i64 << 53) + 1,
            (1i64 << 62) + (1 << 9),
            (1i64 << 62) + (3 << 9),
        ]);
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..4000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            // Random magnitudes: shift the pattern right by 0–63 bits.
            v.push((s as i64) >> (s >> 58));
        }
        for (k, w) in v.chunks(8).enumerate() {
            // Each value visits every lane across the rotations.
            for r in 0..8 {
                let x: [i64; 8] = core::array::from_fn(|l| w[(l + r + k) % w.len()]);
                let want = x.map(|x| x as f64);
                for got in [to_f64_split(i64x8::new(x)), to_f64(i64x8::new(x))] {
                    for (g, (w, x)) in got.to_array().iter().zip(want.iter().zip(x)) {
                        assert_eq!(g.to_bits(), w.to_bits(), "{x}: {g} vs {w}");
                    }
                }
            }
        }
    }

    /// Every spelling of `max`/`min`/`clamp` against `f32::max`/`min`/`clamp`, on both
    /// vector widths (pairs of zeros of opposite signs excepted: `f32::max` may return
    /// either).
    #[test]
    fn nan_semantics_match_f32() {
        fn check<W: Lanes>() {
            for &x in &VALUES {
                for &y in &VALUES {
                    if x == 0.0 && y == 0.0 && x.to_bits() != y.to_bits() {
                        continue;
                    }
                    let (a, b) = (W::splat(x), W::splat(y));
                    for (got, want, what) in [
                        (max_num(a, b), x.max(y), "max_num"),
                        (max_num_sse(a, b), x.max(y), "max_num_sse"),
                        (max_num_cmp(a, b), x.max(y), "max_num_cmp"),
                        (min_num(a, b), x.min(y), "min_num"),
                        (min_num_sse(a, b), x.min(y), "min_num_sse"),
                        (min_num_cmp(a, b), x.min(y), "min_num_cmp"),
                        (
                            clamp(a, W::splat(-1.0), W::splat(2.5)),
                            x.clamp(-1.0, 2.5),
                            "clamp",
                        ),
                        (
                            clamp_sse(a, W::splat(-1.0), W::splat(2.5)),
                            x.clamp(-1.0, 2.5),
                            "clamp_sse",
                        ),
                        (
                            clamp_cmp(a, W::splat(-1.0), W::splat(2.5)),
                            x.clamp(-1.0, 2.5),
                            "clamp_cmp",
                        ),
                        (
                            clamp(a, W::splat(0.0), W::splat(f32::MAX)),
                            x.clamp(0.0, f32::MAX),
                            "clamp at 0",
                        ),
                    ] {
                        if what.ends_with("_sse") && !cfg!(target_feature = "sse") {
                            continue;
                        }
                        assert!(
                            got.lanes().iter().all(|&g| same(g, want)),
                            "{what}({x:e}, {y:e}): {:?} vs {want:e}",
                            got.lanes()
                        );
                    }
                }
            }
        }
        check::<f32x8>();
        check::<f32x16>();
    }

    #[test]
    fn padded_loads_and_partial_stores() {
        let s = [1.0f32, 2.0, 3.0];
        let v: f32x8 = load_padded(&s, 1, -7.0);
        assert_eq!(v.to_array(), [2.0, 3.0, -7.0, -7.0, -7.0, -7.0, -7.0, -7.0]);
        let v: f32x16 = load_padded(&s, usize::MAX, 5.0);
        assert!(v.lanes().iter().all(|&x| x == 5.0));
        let mut out = [0.0f32; 3];
        store_partial(f32x8::splat(4.0), &mut out, 2);
        assert_eq!(out, [0.0, 0.0, 4.0]);
        store_partial(f32x8::splat(4.0), &mut out, 3);
        store_partial(f32x8::splat(4.0), &mut out, usize::MAX);
        assert_eq!(out, [0.0, 0.0, 4.0]);
    }

    #[test]
    fn gather_pair_clamps() {
        let t: Vec<f32> = (0..10).map(|i| i as f32).collect();
        let (h0, h1) = f32x8::new([0.0, 1.0, 8.0, 9.0, 100.0, 3.0, 4.0, 5.0]).gather_pair(&t);
        assert_eq!(h0.to_array(), [0.0, 1.0, 8.0, 8.0, 8.0, 3.0, 4.0, 5.0]);
        assert_eq!(h1.to_array(), [1.0, 2.0, 9.0, 9.0, 9.0, 4.0, 5.0, 6.0]);
    }

    /// `to_indices` is `as usize` lane by lane, at every lane of both widths, for the special
    /// values below `2³¹` (NaN and negatives to 0, fractions truncated) and the largest
    /// `f32` below `2³¹`.
    #[test]
    fn to_indices_is_as_usize() {
        let below: Vec<f32> = VALUES
            .iter()
            .copied()
            .filter(|v| v.is_nan() || *v < 2_147_483_648.0)
            .chain([0.999_999_9, 16_777_215.0, 2_147_483_520.0])
            .collect();
        for &v in &below {
            for k in 0..16 {
                let lanes: [f32; 16] = core::array::from_fn(|j| if j == k { v } else { j as f32 });
                let want: [usize; 16] = lanes.map(|x| x as usize);
                let mut got = [usize::MAX; 16];
                f32x16::new(lanes).to_indices(&mut got);
                assert_eq!(got, want, "{v} in lane {k} of 16");
                if k < 8 {
                    let mut got8 = [usize::MAX; 16];
                    f32x8::new(lanes[..8].try_into().unwrap()).to_indices(&mut got8);
                    assert_eq!(got8[..8], want[..8], "{v} in lane {k} of 8");
                }
            }
        }
    }
}
