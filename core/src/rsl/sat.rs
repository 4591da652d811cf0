//! Summed-area tables (rotatable-square-lights paper, section 2 eq. 2 and section 4.2).
//!
//! A summed-area table (Crow 1984) of a grid of texels `t(i, j)` stores the integrals
//! `S(k, l) = Σ_{i<k, j<l} t(i, j)` over `[0, k]×[0, l]`, so that the integral over any box
//! takes four lookups (paper eq. 2): `∫_R t = S(r, b) − S(l, b) − S(r, t) + S(l, t)`.
//! Texel `(i, j)` covers `[i, i+1]×[j, j+1]` in texel units (rows in `v`); the texels are
//! piecewise constant, and bilinear interpolation of `S` at fractional corners is the exact
//! integral of that piecewise-constant function (`S(i+a, j+b) = S(i,j) + a·(S(i+1,j) − S(i,j))
//! + b·(S(i,j+1) − S(i,j)) + a·b·t(i,j)`), so [`Sat::box_sum`] accepts any real corners.
//!
//! ## The precision problem, and the storage chosen here
//!
//! The paper notes the "precision problem" of SATs on graphics hardware. A box sum subtracts
//! table entries that grow like the whole table's sum, so an `f32` table loses `log2` of
//! (table sum / box sum) bits: at 1024² with texels in `[0, 1)` an `f32` SAT is off by about
//! 1 on a 16×16 box near the far corner (≈ 9 % of it). Subtracting the mean, local offsets
//! per tile, or hi/lo `f32` pairs shrink that but keep an error that grows with the table
//! (the harness report measures every option against resolution).
//!
//! This table stores **exact fixed-point integers**: every texel is rounded to a multiple of
//! the quantum `q = 2^e`, `e = ⌈log2 T⌉ − 60` with `T = Σ|t|` the table's absolute sum, and
//! `S` is summed exactly in `i64` (every partial sum is below `2^61 + 2^47` in magnitude, so
//! nothing overflows). A box query first forms, **exactly in integers**, the nine sub-box
//! sums it needs (the integer box, its four edge strips and four corner texels, each a
//! double difference of `S`), and only then weights them by the corner fractions in `f64`
//! and rounds once to `f32`. The bilinear form is rearranged so that:
//!
//! ```text
//! X(l, m) = P(l, m) + a1·E1(l, m) − a0·E0(l, m)                (per pair of rows l < m)
//! box     = X(J0, J1) + b1·X(J1, J1+1) − b0·X(J0, J0+1)
//! P(l, m)  = [S(I1,m) − S(I0,m)] − [S(I1,l) − S(I0,l)]           (exact i64)
//! Ek(l, m) = [S(Ik+1,m) − S(Ik,m)] − [S(Ik+1,l) − S(Ik,l)]       (exact i64)
//! ```
//!
//! with `u0 = I0 + a0`, `u1 = I1 + a1`, `v0 = J0 + b0`, `v1 = J1 + b1`
//! (`I = ⌊u⌋`, `0 ≤ a < 1`, except `I = width − 1, a = 1` at the right edge).
//! Integer subtraction cannot lose precision, and the same table works in WGSL as pairs
//! of `u32` words (no `f64` and no `i64` there; see `wgsl::SAT_BOX`).
//!
//! ## Error bound (checked against an f64 brute-force sum by the harness property tests)
//!
//! For texels `t` (finite `f32` or `f64`), a box `B` (after ordering and clipping) with exact
//! integral `I = ∫_B t`, `T = Σ|t|` over the whole table, and, over the `n` texels that
//! the query reads (`I0 ≤ i ≤ I1`, `J0 ≤ j ≤ J1`), `A = Σ|t|`:
//!
//! ```text
//! |box_sum − I| ≤ 2⁻²⁴·|I| + 2⁻¹⁵⁰ + 2⁻⁴⁶·A + n·2⁻⁵⁹·T
//! ```
//!
//! (unless `|I|` overflows `f32`, where the result is `±∞`). The first two terms are the
//! final rounding to `f32` (relative `2⁻²⁴`, or half the subnormal spacing `2⁻¹⁵⁰` for
//! results below `2⁻¹²⁶`): the result is within one ulp of `I`, and correctly rounded
//! unless `I` lies within `2⁻⁴⁶·A + n·2⁻⁵⁹·T` of a rounding boundary. The third is the `f64`
//! combination of the nine exact sub-sums; the fourth the quantisation of the texels
//! (`|t − q·round(t/q)| ≤ q/2·(1 + 2⁻⁵²)`, `q < 2⁻⁵⁹·T`). At 1024² with texels in `[0, 1)`,
//! `n·2⁻⁵⁹·T` is below `10⁻¹⁰` for any box up to 256×256, so box sums are within one `f32`
//! ulp of their own magnitude anywhere in the table, and so at 2048² and beyond (the last
//! term grows like `n·T`: for a whole-table box of `N` cells it is `N·2⁻³⁵` ulps, `2⁻¹¹` ulp at
//! 2²⁴ cells = 4096²). What no summed-area table can do — and this one does not claim — is
//! resolve a box whose integral is below `2⁻⁵⁹·T` (a region of tiny texels in a table
//! dominated by huge ones): such boxes get an absolute, not relative, accuracy.
//!
//! **Bad input** (never panics): [`Sat::build`] rejects empty or oversized grids, a texel
//! slice of the wrong length, and non-finite texels. [`SatView::box_sum`] takes the box
//! spanned by its two corners in **any order** (`box_sum(u0, v0, u1, v1)` is the same as
//! `box_sum(u1, v1, u0, v0)` and as `box_sum(u1, v0, u0, v1)`: an unsigned box, never a
//! negative orientation), clips it to `[0, width]×[0, height]` (a box outside the table
//! gives 0; `±∞` corners are clipped like any other), and returns NaN if any corner is NaN.
//! The result is `±∞` only if the true integral overflows `f32`.
//!
//! **Cost.** A query with fractional corners reads 16 table entries (4 pairs of adjacent
//! entries in each of 4 rows; fewer cache lines than that), does 27 `i64` subtractions, 9
//! conversions and 10 `f64` operations (out of line). A query whose four corners are
//! integers strictly inside the far edges is the four lookups of eq. 2, inlined: three
//! exact `i64` operations, one conversion, one scaling, one rounding (the same bits as the
//! general path); [`SatView::box_sum_cells`] is that query for `usize` corners (exact up to
//! the far edges too), without the float-to-index work. The table takes 8 bytes per entry,
//! `(width + 1)·(height + 1)` entries.

use crate::grid::{check_len, check_side, checked_product};
use crate::math;
use crate::{Error, Vec2};

/// Largest width or height of a table: every texel coordinate is then an exact `f32`.
pub const MAX_SIDE: usize = 1 << 24;

/// The quantum `q = 2^e` of a table is `e = ⌈log2 T⌉ − QUANTUM_HEADROOM_BITS` with `T` the
/// absolute sum of its texels, so every partial sum stays below `2^61` quanta (`i64` holds
/// `2^63`).
pub const QUANTUM_HEADROOM_BITS: i32 = 60;

/// The smallest quantum exponent: quanta are never finer than `2^-209` (`2^-60` of the
/// smallest `f32` subnormal), so texel magnitudes below `2^-210` round to 0.
pub const MIN_EXPONENT: i32 = -149 - QUANTUM_HEADROOM_BITS;

/// The largest quantum exponent a [`SatView`] accepts (a table of `2^48` texels of
/// `f32::MAX` has `e = 117`).
pub const MAX_EXPONENT: i32 = 128;

/// Number of `u32` words before the entries in the GPU layout ([`SatView::gpu_words`]):
/// `[width, height, exponent as i32 bits, 0]`.
pub const GPU_HEADER_WORDS: usize = 4;

/// `2^k` as an `f64`, for `−1022 ≤ k ≤ 1023` (clamped to that range otherwise).
#[inline]
fn pow2(k: i32) -> f64 {
    let k = k.clamp(-1022, 1023);
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// `⌈log2 x⌉` of a positive, finite, normal `f64`.
fn ceil_log2(x: f64) -> i32 {
    let bits = x.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i32 - 1023;
    let mantissa = bits & ((1u64 << 52) - 1);
    e + i32::from(mantissa != 0)
}

/// `x` rounded to an integer within `1/2 + 2⁻⁵³` of it (nearest, ties away from zero, up
/// to the rounding of `x ± 1/2` just below one half), `|x| < 2^62`.
#[inline(always)]
fn round_i64(x: f64) -> i64 {
    // Below 2^52, truncating x ± 0.5 rounds to nearest; from 2^52 on, x is already an
    // integer. Branch-free, so the build loop pipelines.
    const SIGN: u64 = 1 << 63;
    let half = f64::from_bits(0.5f64.to_bits() | (x.to_bits() & SIGN));
    let y = if x.abs() < 4_503_599_627_370_496.0 {
        x + half
    } else {
        x
    };
    y as i64
}

/// Texels are within `±f32::MAX` and at most `2^48` of them, so `abs_sum < 2^177` and
/// `e ≤ 117`; `e` is kept at or above [`MIN_EXPONENT`].
fn quantum_exponent(abs_sum: f64) -> i32 {
    if abs_sum > 0.0 {
        (ceil_log2(abs_sum) - QUANTUM_HEADROOM_BITS).max(MIN_EXPONENT)
    } else {
        MIN_EXPONENT
    }
}

/// One axis of a box: the ordered, clipped interval `[lo, hi]` of `[0, n]` as
/// `(I0, a0, I1, a1)` with `lo = I0 + a0`, `hi = I1 + a1`, `0 ≤ I ≤ n − 1`, `0 ≤ a ≤ 1`.
/// The corners must not be NaN. Every step is exact. An empty axis (`n = 0`) gives
/// `(0, 0, 0, 0)`.
///
/// Spelled with comparisons and selects only (no `f32::min`/`max`, which may return either
/// zero of `±0`), so that the SIMD kernel can repeat it bit for bit.
#[inline(always)]
pub fn axis(c0: f32, c1: f32, n: usize) -> (usize, f32, usize, f32) {
    let nf = n as f32;
    let clip = |x: f32| {
        if x < 0.0 {
            0.0
        } else if x > nf {
            nf
        } else {
            x
        }
    };
    let (lo, hi) = if c1 < c0 { (c1, c0) } else { (c0, c1) };
    let (lo, hi) = (clip(lo), clip(hi));
    let last = n.saturating_sub(1) as f32;
    let floor_min = |x: f32| {
        let f = math::floorf(x);
        if f > last { last } else { f }
    };
    let (i0, i1) = (floor_min(lo), floor_min(hi));
    (index(i0), lo - i0, index(i1), hi - i1)
}

/// `[P, E1, E0]` between two rows `l` (lower) and `m` of corner entries, on the column
/// pairs starting at `lo` and `hi` (`row[lo], row[lo + 1]` are `S(I0), S(I0 + 1)`, and
/// likewise at `hi` for `I1`): each the difference of the per-row differences, in
/// wrapping integer arithmetic ([`BoxTerms::k`]).
#[inline(always)]
fn row_pair_terms(l: &[i64], m: &[i64], lo: usize, hi: usize) -> [i64; 3] {
    let p = m[hi]
        .wrapping_sub(m[lo])
        .wrapping_sub(l[hi].wrapping_sub(l[lo]));
    let e1 = m[hi + 1]
        .wrapping_sub(m[hi])
        .wrapping_sub(l[hi + 1].wrapping_sub(l[hi]));
    let e0 = m[lo + 1]
        .wrapping_sub(m[lo])
        .wrapping_sub(l[lo + 1].wrapping_sub(l[lo]));
    [p, e1, e0]
}

/// The exact integer box between corners `(c0, r0)` and `(c1, r1)` of a grid read by
/// [`SatView::corners`] (`g[row][col]`): `integer_box`'s four-entry formula, wrapping.
#[inline(always)]
pub fn corner_box<const C: usize, const R: usize>(
    g: &[[i64; C]; R],
    (c0, c1): (usize, usize),
    (r0, r1): (usize, usize),
) -> i64 {
    g[r1][c1]
        .wrapping_sub(g[r1][c0])
        .wrapping_sub(g[r0][c1].wrapping_sub(g[r0][c0]))
}

/// The entries of table row `l` (rows of `w1` entries), or `None` where the range
/// overflows `usize` (such a row is past any table; the callers read it as zeros).
#[inline(always)]
fn row_range(l: usize, w1: usize) -> Option<core::ops::Range<usize>> {
    let start = l.checked_mul(w1)?;
    Some(start..start.checked_add(w1)?)
}

/// An exact integer `0 ≤ x < 2³²` in an `f32` as a `usize` (NaN gives 0, as `x as usize`
/// would), branch-free: the low word of the `f64` `2⁵² + x`, which holds `x` exactly.
/// (`x as usize` saturates, which costs compares and branches on every query.)
#[inline(always)]
fn index(x: f32) -> usize {
    ((f64::from(x) + 4_503_599_627_370_496.0).to_bits() & 0xffff_ffff) as usize
}

/// A summed-area table borrowed from stored slices: the query side of [`Sat`], and what a
/// renderer without `alloc` keeps (entries from [`Sat::sums`], saved and loaded by the
/// caller). See the module docs for the format, the error bound and the bad-input rules.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SatView<'a> {
    width: usize,
    height: usize,
    exponent: i32,
    /// The quantum `2^exponent` (kept so that a query does not rebuild it).
    scale: f64,
    sums: &'a [i64],
}

/// What a fractional-corner query reads, as the nine exact sub-box sums (in quanta, from at
/// most sixteen entries) and the four corner fractions: the first half of the scalar query
/// ([`SatView::terms`]), whose second half is [`BoxTerms::combine`]. The SIMD kernel reads
/// the same nine sums per lane ([`SatView::integer_terms`]) and combines them with the same
/// operations lane-wise; the WGSL kernel (`sat_lib.wgsl`) mirrors both.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxTerms {
    /// `[P, E1, E0]` for the row pairs `(J0, J1)`, `(J1, J1+1)`, `(J0, J0+1)`.
    pub k: [[i64; 3]; 3],
    /// `a0, a1` (fractions of the `u` corners) and `b0, b1` (of the `v` corners).
    pub a0: f32,
    /// See [`BoxTerms::a0`].
    pub a1: f32,
    /// See [`BoxTerms::a0`].
    pub b0: f32,
    /// See [`BoxTerms::a0`].
    pub b1: f32,
}

impl BoxTerms {
    /// The weighted sum of the nine terms in quanta, in the documented `f64` order
    /// (the SIMD kernel performs the same operations lane-wise).
    ///
    /// Neither `X(J0, J1)` nor the partial sum `X(J0, J1) + b1·X(J1, J1+1)` can be `−0`
    /// (an integer converts to `+0`, and `+0 ± 0` is `+0`), so where a weight `b` is 0 its
    /// term `±0` leaves the result unchanged bit for bit: the query may skip reading it.
    #[inline(always)]
    pub fn combine(&self) -> f64 {
        let (a0, a1) = (f64::from(self.a0), f64::from(self.a1));
        let x = |t: [i64; 3]| (t[0] as f64 + a1 * t[1] as f64) - a0 * t[2] as f64;
        let (x_box, x_top, x_bottom) = (x(self.k[0]), x(self.k[1]), x(self.k[2]));
        (x_box + f64::from(self.b1) * x_top) - f64::from(self.b0) * x_bottom
    }
}

impl<'a> SatView<'a> {
    /// Builds the table of `height` rows of `width` texels (row-major, `texels[j·width + i]`
    /// is texel `(i, j)`) into caller storage of exactly `(width + 1)·(height + 1)` entries,
    /// without allocating: the `no_std` counterpart of `Sat::build`, same errors (plus a
    /// `sums` of the wrong length).
    pub fn build_into(
        width: usize,
        height: usize,
        texels: &[f32],
        sums: &'a mut [i64],
    ) -> Result<SatView<'a>, Error> {
        let exponent = build_entries(width, height, texels, |t| f64::from(*t), sums)?;
        Ok(SatView {
            width,
            height,
            exponent,
            scale: pow2(exponent),
            sums,
        })
    }

    /// A view of a table of `width × height` texels: `sums` holds the
    /// `(width + 1)·(height + 1)` entries `S(k, l)` at `l·(width + 1) + k` (row 0 and column
    /// 0 zero) in quanta of `2^exponent`. Checks the shape and that the first row and
    /// column are zero; the other entries are trusted (a corrupt table gives wrong sums,
    /// never a panic).
    pub fn new(
        width: usize,
        height: usize,
        exponent: i32,
        sums: &'a [i64],
    ) -> Result<SatView<'a>, Error> {
        check_side("width", width, MAX_SIDE)?;
        check_side("height", height, MAX_SIDE)?;
        check_len("sums.len()", sums.len(), entries(width, height)?)?;
        if !(MIN_EXPONENT..=MAX_EXPONENT).contains(&exponent) {
            return Err(Error::OutOfRange {
                what: "exponent",
                value: exponent as f32,
                min: MIN_EXPONENT as f32,
                max: MAX_EXPONENT as f32,
            });
        }
        let first_row_zero = sums[..=width].iter().all(|&s| s == 0);
        let first_col_zero = sums.iter().step_by(width + 1).all(|&s| s == 0);
        if !(first_row_zero && first_col_zero) {
            return Err(Error::OutOfRange {
                what: "first row and column of sums",
                value: f32::NAN,
                min: 0.0,
                max: 0.0,
            });
        }
        Ok(SatView {
            width,
            height,
            exponent,
            scale: pow2(exponent),
            sums,
        })
    }

    /// Texels per row.
    #[inline]
    pub fn width(&self) -> usize {
        self.width
    }

    /// Rows of texels.
    #[inline]
    pub fn height(&self) -> usize {
        self.height
    }

    /// The quantum exponent `e`: entries are in units of `2^e`.
    #[inline]
    pub fn exponent(&self) -> i32 {
        self.exponent
    }

    /// The quantum `2^e` as an `f64`.
    #[inline]
    pub fn quantum(&self) -> f64 {
        self.scale
    }

    /// The entries `S(k, l)` at `l·(width + 1) + k`, in quanta.
    #[inline]
    pub fn sums(&self) -> &'a [i64] {
        self.sums
    }

    /// Bytes of the entries (8 per entry).
    #[inline]
    pub fn bytes(&self) -> usize {
        core::mem::size_of_val(self.sums)
    }

    /// The integral over the box spanned by the corners `(u0, v0)` and `(u1, v1)` (texel
    /// units, any order), clipped to the table, rounded once to `f32`. Within the bound of
    /// the module docs; NaN if a corner is NaN.
    #[inline(always)]
    pub fn box_sum(&self, u0: f32, v0: f32, u1: f32, v1: f32) -> f32 {
        (self.box_sum_f64(u0, v0, u1, v1)) as f32
    }

    /// [`SatView::box_sum`] before its final rounding to `f32` (for callers that combine
    /// several box sums, e.g. interpolate between tables, before rounding). Within
    /// `2⁻⁴⁶·A + n·2⁻⁵⁹·T` of the exact integral (module docs); NaN if a corner is NaN.
    #[inline(always)]
    pub fn box_sum_f64(&self, u0: f32, v0: f32, u1: f32, v1: f32) -> f64 {
        // No NaN test up front: a NaN corner flows through `axis` without harm (its
        // index becomes 0) and makes its fraction NaN, so it never takes the integer path.
        let (i0, a0, i1, a1) = axis(u0, u1, self.width);
        let (j0, b0, j1, b1) = axis(v0, v1, self.height);
        // The fractions are `+0` or positive (`x − ⌊x⌋` is never `−0`), or NaN: all four
        // are zero exactly when their bits are.
        if (a0.to_bits() | a1.to_bits() | b0.to_bits() | b1.to_bits()) == 0 {
            // Integer corners: the four lookups of eq. 2. `combine` would give the same
            // bits (every other term has weight 0; see `BoxTerms::combine`).
            return self.integer_box(i0, i1, j0, j1) as f64 * self.scale;
        }
        self.fractional_box(u0, v0, u1, v1)
    }

    /// The three boxes `[whole, right, top]` = `[x0, x1] × [y0, y1]`, `[xc, x1] × [y0, y1]`,
    /// `[x0, x1] × [yc, y1]` for `x0 ≤ xc ≤ x1`, `y0 ≤ yc ≤ y1` (texel units): each the same
    /// bits as [`SatView::box_sum_f64`] on its box, with the corners the boxes share read
    /// once (32 entries instead of 48, three corner positions per axis instead of six).
    /// The BRDF gradient of [`crate::rsl::brdf_sat::BrdfSat::integral_gradient`] takes
    /// these three. Any NaN gives NaN in all three.
    #[inline]
    pub fn box3_f64(&self, [x0, xc, x1]: [f32; 3], [y0, yc, y1]: [f32; 3]) -> [f64; 3] {
        if [x0, xc, x1, y0, yc, y1].iter().any(|v| v.is_nan()) {
            return [f64::NAN; 3];
        }
        // `axis` corner by corner: the boxes' corners are ordered, so each corner's index
        // and fraction are what `axis` gives it within any of the boxes.
        let corner = |x: f32, n: usize| -> (usize, f32) {
            let (i, a, _, _) = axis(x, x, n);
            (i, a)
        };
        let (w, h) = (self.width, self.height);
        let ((i0, a0), (ic, ac), (i1, a1)) = (corner(x0, w), corner(xc, w), corner(x1, w));
        let ((j0, b0), (jc, bc), (j1, b1)) = (corner(y0, h), corner(yc, h), corner(y1, h));
        let w1 = w + 1;
        let (i0, ic, i1) = (i0.min(w - 1), ic.min(w - 1), i1.min(w - 1));
        // Per row: [S(I0), S(I0+1), S(Ic), S(Ic+1), S(I1), S(I1+1)].
        let row = |l: usize| -> [i64; 6] {
            match row_range(l, w1).and_then(|range| self.sums.get(range)) {
                Some(r) => [r[i0], r[i0 + 1], r[ic], r[ic + 1], r[i1], r[i1 + 1]],
                None => [0; 6],
            }
        };
        let next = |l: usize, b: f32, r: [i64; 6]| {
            if b != 0.0 {
                row(l.saturating_add(1))
            } else {
                r
            }
        };
        let (r0, r1, rc) = (row(j0), row(j1), row(jc));
        let (r0p, r1p, rcp) = (next(j0, b0, r0), next(j1, b1, r1), next(jc, bc, rc));
        let d = |l: [i64; 6], m: [i64; 6], lo: usize, hi: usize| row_pair_terms(&l, &m, lo, hi);
        let bx = |(l, lp, bl): ([i64; 6], [i64; 6], f32), lo: usize, a_lo: f32, hi: usize| {
            BoxTerms {
                k: [d(l, r1, lo, hi), d(r1, r1p, lo, hi), d(l, lp, lo, hi)],
                a0: a_lo,
                a1,
                b0: bl,
                b1,
            }
            .combine()
                * self.scale
        };
        [
            bx((r0, r0p, b0), 0, a0, 4),
            bx((r0, r0p, b0), 2, ac, 4),
            bx((rc, rcp, bc), 0, a0, 4),
        ]
    }

    /// The rest of [`SatView::box_sum_f64`]: fractional (or NaN) corners, the nine-term
    /// combination. Kept out of line (it repeats the two `axis` calls rather than take
    /// their results through memory) so that the integer path inlines into callers' loops.
    #[inline(never)]
    fn fractional_box(&self, u0: f32, v0: f32, u1: f32, v1: f32) -> f64 {
        self.terms(u0, v0, u1, v1)
            .map_or(f64::NAN, |t| t.combine() * self.scale)
    }

    /// The integral over the box between the integer corners `(x0, y0)` and `(x1, y1)`
    /// (texel units, any order, clipped to the table): the integer-coordinate query the
    /// other summed-area-table crates offer. The exact `i64` box sum rounded once to `f32`:
    /// the bound of the module docs without its `2⁻⁴⁶·A` term (there is no `f64`
    /// combination), `2⁻²⁴·|I| + 2⁻¹⁵⁰ + n·2⁻⁵⁹·T`.
    /// The same bits as `box_sum(x0 as f32, y0 as f32, x1 as f32, y1 as f32)` when both
    /// corners lie before the last column and row; a box reaching `x = width` or
    /// `y = height` is read exactly here, where `box_sum` weights the last texel by a
    /// fraction of 1 and may round its `f64` combination (within that query's bound).
    ///
    /// Ordered corners inside the table are the four lookups of eq. 2 behind four
    /// compare-and-branch tests; inverted or clipped boxes take an out-of-line path that
    /// orders and clips the corners and comes back.
    #[inline(always)]
    pub fn box_sum_cells(&self, x0: usize, y0: usize, x1: usize, y1: usize) -> f32 {
        let (w, h) = (self.width, self.height);
        if x0 <= x1 && x1 <= w && y0 <= y1 && y1 <= h {
            // `x0 ≤ x1 ≤ w`, `y0 ≤ y1 ≤ h`: every index is inside the table, and no
            // product overflows (the table has `(w + 1)·(h + 1)` entries). `b` runs from
            // `(0, y0)` to `(x1, y1)`, so the four reads sit at `x` and `d + x` and the
            // compiler keeps one range check instead of four.
            let w1 = w + 1;
            let d = (y1 - y0) * w1;
            let r0 = y0 * w1;
            if let Some(b) = self.sums.get(r0..).and_then(|s| s.get(..=d + x1)) {
                let k = b[d + x1]
                    .wrapping_sub(b[d + x0])
                    .wrapping_sub(b[x1].wrapping_sub(b[x0]));
                return (k as f64 * self.scale) as f32;
            }
        }
        self.box_sum_cells_general(x0, y0, x1, y1)
    }

    /// The rest of [`SatView::box_sum_cells`]: orders and clips the corners, then takes
    /// the four lookups (out of line, so the ordered in-table query stays small).
    #[inline(never)]
    fn box_sum_cells_general(&self, x0: usize, y0: usize, x1: usize, y1: usize) -> f32 {
        let (w, h) = (self.width, self.height);
        let (xl, xh) = (x0.min(x1).min(w), x0.max(x1).min(w));
        let (yl, yh) = (y0.min(y1).min(h), y0.max(y1).min(h));
        (self.integer_box(xl, xh, yl, yh) as f64 * self.scale) as f32
    }

    /// `S(I1,J1) − S(I0,J1) − S(I1,J0) + S(I0,J0)` in quanta, exact (wrapping) `i64`, for
    /// `I ≤ width`, `J ≤ height` (larger column indices are clamped, and a row past the
    /// table reads as zeros: wrong sums, never a panic). One range check per row; the
    /// column indices are then provably in it. (The per-lane reads of the SIMD kernel.)
    #[inline(always)]
    pub fn integer_box(&self, i0: usize, i1: usize, j0: usize, j1: usize) -> i64 {
        let w = self.width;
        let w1 = w + 1;
        let (i0, i1) = (i0.min(w), i1.min(w));
        let row = |l: usize| self.sums.get(row_range(l, w1)?);
        match (row(j0), row(j1)) {
            (Some(r0), Some(r1)) => r1[i1]
                .wrapping_sub(r1[i0])
                .wrapping_sub(r0[i1].wrapping_sub(r0[i0])),
            _ => 0,
        }
    }

    /// The entries `S(cols[c], rows[r])` in quanta, `out[r][c]` (columns clamped to the
    /// width; a row past the table reads as zeros): the corners that several
    /// [`SatView::integer_box`] queries on one grid of knots share, each read once. A box
    /// between knots is then [`corner_box`], the same bits as `integer_box`.
    #[inline(always)]
    pub fn corners<const C: usize, const R: usize>(
        &self,
        cols: [usize; C],
        rows: [usize; R],
    ) -> [[i64; C]; R] {
        let w = self.width;
        let w1 = w + 1;
        let cols = cols.map(|c| c.min(w));
        rows.map(
            |l| match row_range(l, w1).and_then(|range| self.sums.get(range)) {
                Some(r) => cols.map(|c| r[c]),
                None => [0; C],
            },
        )
    }

    /// The integral over the axis-aligned square with centre `c` and half-diagonal `r`
    /// (half-side `r/√2`, computed as `r·(1/√2)`), in texel units: the query of the paper
    /// (section 4.2, a rotatable square light of half-diagonal `r` seen in the
    /// parametrisation plane). A negative `r` counts as 0 (an empty square, 0); NaN in `c`
    /// or `r` gives NaN.
    #[inline]
    pub fn square(&self, c: Vec2, r: f32) -> f32 {
        let h = square_half_side(r);
        self.box_sum(c.x - h, c.y - h, c.x + h, c.y + h)
    }

    /// The nine exact sub-box sums and the corner fractions of a query, `None` if a corner
    /// is NaN (the first half of [`SatView::box_sum`]).
    #[inline(always)]
    pub fn terms(&self, u0: f32, v0: f32, u1: f32, v1: f32) -> Option<BoxTerms> {
        if u0.is_nan() || v0.is_nan() || u1.is_nan() || v1.is_nan() {
            return None;
        }
        let (i0, a0, i1, a1) = axis(u0, u1, self.width);
        let (j0, b0, j1, b1) = axis(v0, v1, self.height);
        Some(BoxTerms {
            k: self.integer_terms((i0, i1), (j0, j1), (b0, b1)),
            a0,
            a1,
            b0,
            b1,
        })
    }

    /// The nine exact sub-box sums `[[P, E1, E0]; 3]` of [`BoxTerms::k`] for columns
    /// `I0, I1` and rows `J0, J1` as [`axis`] gives them (`I < width`, `J < height`;
    /// larger column indices are clamped, and a row past the table reads as zeros: wrong
    /// sums, never a panic). Rows `J0 + 1` and `J1 + 1` are read only where their weight
    /// `b0`, `b1` is non-zero (otherwise their terms are 0, which changes no bit of the
    /// result: see `BoxTerms::combine`), so that an integer-corner query reads two rows,
    /// as a plain four-lookup query does. (The per-lane table reads of the SIMD kernel.)
    #[inline(always)]
    pub fn integer_terms(
        &self,
        (i0, i1): (usize, usize),
        (j0, j1): (usize, usize),
        (b0, b1): (f32, f32),
    ) -> [[i64; 3]; 3] {
        let w = self.width;
        let w1 = w + 1;
        // Integer facts that let the compiler drop the per-entry bounds checks: every
        // index below is then provably inside `r` (`i + 1 ≤ w < w1 = r.len()`; `w ≥ 1`
        // is an invariant of every constructor).
        let (i0, i1) = (i0.min(w - 1), i1.min(w - 1));
        // Per row: [S(I0), S(I0+1), S(I1), S(I1+1)] (one range check per row; a row past
        // the table, which the callers never ask for, reads as zeros).
        let row = |l: usize| -> [i64; 4] {
            match row_range(l, w1).and_then(|range| self.sums.get(range)) {
                Some(r) => [r[i0], r[i0 + 1], r[i1], r[i1 + 1]],
                None => [0; 4],
            }
        };
        let (r0, r1) = (row(j0), row(j1));
        let r0p = if b0 != 0.0 {
            row(j0.saturating_add(1))
        } else {
            r0
        };
        let r1p = if b1 != 0.0 {
            row(j1.saturating_add(1))
        } else {
            r1
        };
        let d = |l: [i64; 4], m: [i64; 4]| row_pair_terms(&l, &m, 0, 2);
        [d(r0, r1), d(r1, r1p), d(r0, r0p)]
    }

    /// The number of `u32` words of the GPU layout: [`GPU_HEADER_WORDS`] + 2 per entry.
    pub fn gpu_len(&self) -> usize {
        GPU_HEADER_WORDS + 2 * self.sums.len()
    }

    /// The table in the layout of `wgsl::SAT_BOX` (binding 3, `array<u32>`): the header
    /// `[width, height, exponent as i32 bits, 0]`, then each entry as its low and high
    /// 32-bit words (two's complement, little-endian word order).
    pub fn gpu_words(&self) -> impl Iterator<Item = u32> + 'a {
        let header = [
            self.width as u32,
            self.height as u32,
            self.exponent as u32,
            0u32,
        ];
        header.into_iter().chain(
            self.sums
                .iter()
                .flat_map(|&s| [s as u64 as u32, ((s as u64) >> 32) as u32]),
        )
    }
}

/// `max(r, 0)·(1/√2)`, NaN kept: the half-side of the square of half-diagonal `r`.
#[inline(always)]
pub fn square_half_side(r: f32) -> f32 {
    // `f32::max` would turn NaN into 0: keep it.
    let r = if r < 0.0 { 0.0 } else { r };
    r * core::f32::consts::FRAC_1_SQRT_2
}

/// Checks the texels and writes the entries into `sums` (of exactly `(width + 1)·(height
/// + 1)` entries); returns the quantum exponent.
fn build_entries<T>(
    width: usize,
    height: usize,
    texels: &[T],
    get: impl Fn(&T) -> f64,
    sums: &mut [i64],
) -> Result<i32, Error> {
    check_shape(width, height, texels.len())?;
    let w1 = width + 1;
    check_len(
        "sums.len() (must be (width + 1)·(height + 1))",
        sums.len(),
        entries(width, height)?,
    )?;
    // Eight partial sums (the order does not matter: the sum only sets the quantum, with
    // headroom) and a flag, so that the pass vectorises; the error, if any, is found after.
    let mut partial = [0.0f64; 8];
    let mut bad = false;
    for chunk in texels.chunks(8) {
        for (p, t) in partial.iter_mut().zip(chunk) {
            let a = get(t).abs();
            bad |= a.is_nan() | (a > f64::from(f32::MAX));
            *p += a;
        }
    }
    if bad {
        for t in texels {
            let x = get(t);
            if !x.is_finite() {
                return Err(Error::NonFinite { what: "texel" });
            }
            if x.abs() > f64::from(f32::MAX) {
                return Err(Error::OutOfRange {
                    what: "texel",
                    value: x as f32,
                    min: -f32::MAX,
                    max: f32::MAX,
                });
            }
        }
    }
    let abs_sum: f64 = partial.iter().sum();
    let exponent = quantum_exponent(abs_sum);
    let inv_q = pow2(-exponent);
    let (first, rest) = sums.split_at_mut(w1);
    first.fill(0);
    let mut above: &[i64] = first;
    for (row, out) in texels.chunks_exact(width).zip(rest.chunks_exact_mut(w1)) {
        out[0] = 0;
        let mut acc = 0i64;
        for ((t, o), a) in row.iter().zip(&mut out[1..]).zip(&above[1..]) {
            acc = acc.wrapping_add(round_i64(get(t) * inv_q));
            *o = a.wrapping_add(acc);
        }
        above = out;
    }
    Ok(exponent)
}

/// Width, height and texel count of a grid to build.
fn check_shape(width: usize, height: usize, len: usize) -> Result<(), Error> {
    check_side("width", width, MAX_SIDE)?;
    check_side("height", height, MAX_SIDE)?;
    let n = checked_product("texel count", width, height)?;
    check_len("texels.len() (must be width·height)", len, n)
}

/// `(width + 1)·(height + 1)`, the number of table entries (sides already checked).
fn entries(width: usize, height: usize) -> Result<usize, Error> {
    checked_product("table entries", width + 1, height + 1)
}

#[cfg(feature = "alloc")]
pub use owned::Sat;

#[cfg(feature = "alloc")]
mod owned {
    use alloc::vec::Vec;

    use super::{SatView, build_entries, check_shape, entries};
    use crate::{Error, Vec2};

    /// An owned summed-area table (exact fixed-point `i64` entries); see the module docs.
    #[derive(Clone, Debug, PartialEq)]
    pub struct Sat {
        width: usize,
        height: usize,
        exponent: i32,
        sums: Vec<i64>,
    }

    impl Sat {
        /// Builds the table of `height` rows of `width` texels, row-major (`texels[j·width +
        /// i]` is texel `(i, j)`, covering `[i, i+1]×[j, j+1]`; rows in `v`).
        ///
        /// Errors: `width` or `height` outside `[1, MAX_SIDE]`, `texels.len() ≠
        /// width·height`, a non-finite texel, or no memory for the table.
        pub fn build(width: usize, height: usize, texels: &[f32]) -> Result<Sat, Error> {
            Self::build_with(width, height, texels, |t| f64::from(*t))
        }

        /// [`Sat::build`] from `f64` texels (quantised directly, without a detour through
        /// `f32`: for tables of values computed in `f64`, such as BRDF integrals).
        pub fn build_f64(width: usize, height: usize, texels: &[f64]) -> Result<Sat, Error> {
            Self::build_with(width, height, texels, |t| *t)
        }

        fn build_with<T>(
            width: usize,
            height: usize,
            texels: &[T],
            get: impl Fn(&T) -> f64,
        ) -> Result<Sat, Error> {
            check_shape(width, height, texels.len())?;
            let len = entries(width, height)?;
            let mut sums = Vec::new();
            sums.try_reserve_exact(len).map_err(|_| Error::OutOfRange {
                what: "table entries (allocation failed)",
                value: len as f32,
                min: 0.0,
                max: 0.0,
            })?;
            sums.resize(len, 0i64);
            let exponent = build_entries(width, height, texels, get, &mut sums)?;
            Ok(Sat {
                width,
                height,
                exponent,
                sums,
            })
        }

        /// The borrowed view (all queries live there).
        #[inline]
        pub fn view(&self) -> SatView<'_> {
            SatView {
                width: self.width,
                height: self.height,
                exponent: self.exponent,
                scale: super::pow2(self.exponent),
                sums: &self.sums,
            }
        }

        /// Texels per row.
        #[inline]
        pub fn width(&self) -> usize {
            self.width
        }

        /// Rows of texels.
        #[inline]
        pub fn height(&self) -> usize {
            self.height
        }

        /// The quantum exponent `e`: entries are in units of `2^e`.
        #[inline]
        pub fn exponent(&self) -> i32 {
            self.exponent
        }

        /// The entries `S(k, l)` at `l·(width + 1) + k`, in quanta of `2^exponent`.
        #[inline]
        pub fn sums(&self) -> &[i64] {
            &self.sums
        }

        /// Bytes of the entries (8 per entry, `(width + 1)·(height + 1)` entries).
        #[inline]
        pub fn bytes(&self) -> usize {
            self.view().bytes()
        }

        /// Integral over the box `[u0,u1]×[v0,v1]` in texel units of the piecewise-constant
        /// texels (exact bilinear interpolation at fractional corners), clipped to the
        /// table; corners in any order (the box between them, never negative orientation);
        /// NaN in → NaN out; never panics. See [`SatView::box_sum`] and the module docs for
        /// the error bound.
        #[inline]
        pub fn box_sum(&self, u0: f32, v0: f32, u1: f32, v1: f32) -> f32 {
            self.view().box_sum(u0, v0, u1, v1)
        }

        /// The axis-aligned square with centre `c` and half-diagonal `r` (half-side
        /// `r/√2`), texel units; see [`SatView::square`].
        #[inline]
        pub fn square(&self, c: Vec2, r: f32) -> f32 {
            self.view().square(c, r)
        }

        /// The table in the GPU layout of `wgsl::SAT_BOX` ([`SatView::gpu_words`]).
        pub fn gpu_table(&self) -> Vec<u32> {
            self.view().gpu_words().collect()
        }
    }
}

#[cfg(all(test, feature = "alloc"))]
mod tests {
    use super::*;
    use alloc::vec::Vec;

    use steradian_reference::rsl::sat::box_integral as brute;

    #[test]
    fn small_table_matches_brute_force() {
        let (w, h) = (5, 3);
        let t: Vec<f32> = (0..w * h).map(|k| (k as f32 * 0.37).sin()).collect();
        let sat = Sat::build(w, h, &t).unwrap();
        for &(u0, v0, u1, v1) in &[
            (0.0, 0.0, 5.0, 3.0),
            (0.5, 0.25, 4.75, 2.5),
            (1.2, 1.3, 1.7, 1.9),
            (-3.0, -1.0, 10.0, 7.0),
            (4.0, 3.0, 0.0, 0.0),
            (2.0, 2.0, 2.0, 2.0),
        ] {
            let got = sat.box_sum(u0, v0, u1, v1) as f64;
            let want = brute(w, h, &t, u0, v0, u1, v1);
            assert!(
                (got - want).abs() <= 1e-6 * (1.0 + want.abs()),
                "{got} {want}"
            );
        }
    }

    /// `box3_f64` is three `box_sum_f64` calls bit for bit: fractional and integer
    /// corners, boxes reaching past the table, empty boxes, the last row and column, NaN.
    #[test]
    fn box3_is_three_box_queries_bit_for_bit() {
        let (w, h) = (7, 5);
        let t: Vec<f32> = (0..w * h).map(|k| (k as f32 * 0.61).cos() + 1.1).collect();
        let sat = Sat::build(w, h, &t).unwrap();
        let v = sat.view();
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut r = |lo: f32, hi: f32| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let u = (seed >> 40) as f32 / (1u64 << 24) as f32;
            // A quarter of the draws land on integers.
            let x = lo + (hi - lo) * u;
            if seed & 3 == 0 { math::floorf(x) } else { x }
        };
        let mut cases: Vec<([f32; 2], f32)> = (0..4000)
            .map(|_| ([r(-2.0, 9.0), r(-2.0, 7.0)], r(0.0, 4.0)))
            .collect();
        cases.extend([
            ([3.5, 2.5], 0.0),
            ([0.0, 0.0], 7.0),
            ([7.0, 5.0], 0.5),
            ([6.5, 4.5], 0.5),
            ([3.0, 2.0], 1.0),
        ]);
        for ([cx, cy], hs) in cases {
            let got = v.box3_f64([cx - hs, cx, cx + hs], [cy - hs, cy, cy + hs]);
            let want = [
                v.box_sum_f64(cx - hs, cy - hs, cx + hs, cy + hs),
                v.box_sum_f64(cx, cy - hs, cx + hs, cy + hs),
                v.box_sum_f64(cx - hs, cy, cx + hs, cy + hs),
            ];
            for k in 0..3 {
                assert_eq!(
                    got[k].to_bits(),
                    want[k].to_bits(),
                    "{cx} {cy} {hs} box {k}"
                );
            }
        }
        let nan = v.box3_f64([0.0, f32::NAN, 1.0], [0.0, 0.5, 1.0]);
        assert!(nan.iter().all(|x| x.is_nan()));
    }

    #[test]
    fn rejects_bad_input() {
        assert!(Sat::build(0, 1, &[]).is_err());
        assert!(Sat::build(2, 2, &[1.0; 3]).is_err());
        assert!(Sat::build(1, 1, &[f32::NAN]).is_err());
        assert!(Sat::build(1, 1, &[f32::INFINITY]).is_err());
        assert!(Sat::build_f64(1, 1, &[1e300]).is_err());
        assert!(Sat::build_f64(1, 1, &[f64::NAN]).is_err());
        assert!(SatView::new(1, 1, 0, &[0, 0, 0]).is_err());
        assert!(SatView::new(1, 1, 0, &[0, 0, 1, 5]).is_err());
        assert!(SatView::new(1, 1, 0, &[0, 0, 0, 5]).is_ok());
    }

    #[test]
    fn round_and_log2() {
        assert_eq!(round_i64(2.5), 3);
        assert_eq!(round_i64(-2.5), -3);
        assert_eq!(round_i64(2.4999), 2);
        assert_eq!(round_i64(-0.2), 0);
        assert_eq!(round_i64(4.0e18), 4_000_000_000_000_000_000);
        assert_eq!(ceil_log2(1.0), 0);
        assert_eq!(ceil_log2(1.5), 1);
        assert_eq!(ceil_log2(0.25), -2);
        assert_eq!(pow2(-3), 0.125);
    }

    #[test]
    fn axis_of_an_empty_grid_is_zero_and_does_not_overflow() {
        assert_eq!(axis(-1.0, 5.0, 0), (0, 0.0, 0, 0.0));
        assert_eq!(axis(0.0, 0.0, 0), (0, 0.0, 0, 0.0));
        assert_eq!(axis(3.0, -2.0, 1), (0, 0.0, 0, 1.0));
    }

    #[test]
    fn index_arithmetic_at_the_extremes_never_panics() {
        let t: Vec<f32> = (0..12).map(|k| k as f32).collect();
        let sat = Sat::build(4, 3, &t).unwrap();
        let view = sat.view();
        let m = usize::MAX;
        // Rows past the table (including those whose offset overflows usize) read as zero.
        assert_eq!(view.integer_box(0, m, m, m), 0);
        assert_eq!(view.integer_box(m, m, 0, m), 0);
        assert_eq!(view.integer_box(0, 4, 0, 3), view.integer_box(0, m, 0, 3));
        let _ = view.integer_terms((m, m), (m, m), (0.5, 0.5));
        let _ = view.integer_terms((0, m), (m - 1, m), (0.0, 0.5));
        // Integer corners anywhere, in any order, clip to the table.
        let all = view.box_sum_cells(0, 0, 4, 3);
        assert_eq!(all, 66.0);
        assert_eq!(view.box_sum_cells(m, m, 0, 0), all);
        assert_eq!(view.box_sum_cells(0, m, m, 0), all);
        assert_eq!(view.box_sum(f32::MAX, f32::MAX, -f32::MAX, -f32::MAX), all);
        // Zero-size and oversized grids are refused, not indexed.
        assert!(Sat::build(0, 0, &[]).is_err());
        assert!(Sat::build(MAX_SIDE + 1, 1, &[]).is_err());
        assert!(Sat::build(m, m, &[]).is_err());
    }
}
