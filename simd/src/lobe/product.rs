//! Products of two cosine lobes as one lobe, 8 (or 16) lanes at a time (mirrors
//! `steradian_core::lobe::product`; see it for the formulas, their source in the cosine-lobe
//! paper, section 4.1, and the table).
//!
//! Lane `k` of [`product_x8`] is `steradian_core::lobe::product::product_with(table, fit, a_k,
//! b_k)` with `a_k`, `b_k` lane `k` of the inputs as [`LobeX8::to_array`] builds them
//! (`CosineLobe::saturating`: the axis normalised, a zero axis replaced by `+z`, a negative
//! exponent clamped to 0). The kernel performs the scalar kernel's operations in the same
//! order; only the transcendental functions differ (wide's polynomial `ln`, `exp`,
//! `exp_m1` and `atan2` instead of the scalar kernel's four-lane `ln_x4`, `exp_x4` and
//! `atan2_pos` and the standard library's; `ln` extended to subnormal arguments, `exp` to
//! subnormal results), so:
//!
//! - the **axis** comes from correctly rounded operations only (the arc frame, the peak's
//!   `(cos t*, sin t*)`, the final normalisation): it is **bit-identical** to the scalar
//!   kernel's;
//! - the **scale**, **exponent** and **integral** `2π·s/(e_r + 1)` are exponentials of sums
//!   of logarithms (`ln p`, a sum of `e·ln cos t` terms; `ln I`, the logit-Laplace baseline
//!   plus the table's correction at slightly different coordinates). An absolute error `δ`
//!   in a logarithm `y` is a relative error `δ` in `e^y`, and wide's functions are good to
//!   a few ulps of `|y|`, so the bounds are relative per unit of
//!   `1 + L`, `L = |ln p| + |ln I|` (`p` the peak value and `I` the integral of the product
//!   of the unit lobes):
//!   - `|Δs| ≤ `[`SCALE_REL_TOL`]`·(1 + L)·|s| + u`,
//!   - `|Δe_r| ≤ `[`EXPONENT_REL_TOL`]`·(1 + L)·(1 + e_r)`,
//!   - `|ΔI_r| ≤ `[`INTEGRAL_REL_TOL`]`·(1 + L)·|I_r| + u/(1 + e_r)`, `I_r = s/(1 + e_r)`,
//!
//!   where `u = `[`UNDERFLOW_ABS`]`·(1 + |s1·s2|)` (times `max(1, (1 + e_r)/2π)` for
//!   `ExactIntegralCurvature`, whose scale is `exp(ln I)·(1 + e_r)/2π`) matters only where a
//!   subnormal intermediate is rounded onto the subnormal grid on both sides. Where `|ln I|
//!   < 20` the measured relative integral difference is below `6e-6`, far below the table's
//!   own error against the exact integral (`steradian_core::lobe::product::INTEGRAL_REL_MEAN`);
//!   a result within the tolerance of `f32::MAX` may overflow to `±∞` on one side only.
//!
//! **Lanes recomputed by the scalar kernel** (bit-identical): a lane with a non-finite
//! field (NaN or ±∞ in an axis component, scale or exponent), an exponent above
//! [`MAX_WIDE_EXPONENT`] (ten times the table's range, where `f32` logarithms of the size
//! `e·ln cos t` lose all digits in either kernel), or axes within about `1e-18` of opposite
//! (the scalar kernel's `α = π` branch and its neighbourhood, where the baseline's
//! half-angles underflow). So NaN and infinities give exactly what the scalar kernel gives:
//! scales multiply (a NaN scale gives a NaN scale), a NaN exponent gives a NaN scale and
//! exponent, a non-finite axis component gives a NaN axis. Lanes whose `s1·s2` overflows,
//! curvature-fit lanes whose peak sits on an `e < 1` lobe's horizon, and exact-integral
//! lanes whose baseline overflows (`hq = ∞`) or whose exponent `ln p − ln_sines` leaves
//! `[−80, 80]` (where the scalar kernel forms `ln I` whole) go to the scalar kernel too.
//! Such lanes are rare in rendering
//! (exactly opposite axes are the common one) and cost one scalar call each.
//!
//! Table lookups are scalar loads per lane (wide has no gather); the trilinear arithmetic is
//! vectorised in the scalar kernel's order.
//!
//! **Measured** (`tests/product.rs`, `survey_max_differences`, 2·10⁶ lanes per fit,
//! exponents `{0} ∪ [1e-3, 1e5]` log-uniform, angles uniform in `[0, π)`, scales in
//! `±[0.1, 10]`; the named cases and arbitrary bit patterns stay within the same bounds):
//! per unit of `1 + L`, at most `8e-7` for the scale, the exponent and the integral (the
//! test asserts it and prints what it measured). **Speed:** criterion
//! `lobe-product/table/simd` against `lobe-product/table/scalar` (`cargo bench -p
//! steradian-benches --bench product`), and the report's `lobe-product` section.

use core::f32::consts::TAU;

use steradian_core::lobe::CosineLobe;
use steradian_core::lobe::product::{
    ANGLE_LOG_DROP, EXPONENT_EPS, ProductFit, ProductTable, product_with,
};

use crate::batch::{LobeX8, Vec3x8};
use crate::lanes::{ColumnKernel, Lanes, SliceVec, clamp, drive, max_num, min_num};

/// `ln(2π)` of the `f32` `2π`, correctly rounded (the value `TAU.ln()` gives): a constant so
/// that the crate needs no float functions of the standard library.
const LN_TAU: f32 = f32::from_bits(0x3feb_3f8e);
/// `ln(4π)` of the `f32` `4π`, correctly rounded.
const LN_2TAU: f32 = f32::from_bits(0x4021_fc4d);

/// Bound on the scale's difference from the scalar kernel, relative, per unit of `1 + L`
/// (see the module docs). Measured: at most `8e-7` (asserted).
pub const SCALE_REL_TOL: f32 = 2.0e-6;
/// Bound on the exponent's difference from the scalar kernel, relative to `1 + e_r`, per
/// unit of `1 + L` (see the module docs). Measured: at most `8e-7` (asserted).
pub const EXPONENT_REL_TOL: f32 = 2.0e-6;
/// Bound on the difference of the result's integral `2π·s/(e_r + 1)` from the scalar
/// kernel's, relative, per unit of `1 + L` (see the module docs). Measured: at most `8e-7`
/// (asserted).
pub const INTEGRAL_REL_TOL: f32 = 2.0e-6;
/// Absolute allowance on the scale, per unit of `1 + |s1·s2|`, where an intermediate
/// underflows into subnormals: two subnormal units (see the module docs).
pub const UNDERFLOW_ABS: f32 = 2.0 * f32::from_bits(1);
/// Exponents above this (and NaN, ±∞) are handed to the scalar kernel (see the module
/// docs): below it every intermediate of the baseline stays finite.
pub const MAX_WIDE_EXPONENT: f32 = 1.0e6;
/// Lanes whose `sin 2x` or `sin 2y` (the doubled angles from the lobes' horizons to the
/// baseline's peak, `x + y = π − α`) is below this are handed to the scalar kernel: the
/// products `x·y` and `x²` of the baseline would be subnormal.
const MIN_WIDE_SIN: f32 = 1.0e-18;

/// `1/ln(1 + E/ε)` of `steradian_core::lobe::product::exponent_coord` (the same literal).
const INV_LN_SPAN: f32 = 1.0 / 14.508_658;

/// `ln x` for `x ≥ 0` including subnormals (wide's `ln` returns `−∞` for them): those are
/// scaled by `2²⁴` first (exact) and `24·ln 2` subtracted.
#[inline(always)]
fn ln_full<W: Lanes>(x: W) -> W {
    let tiny = x.lt(W::splat(f32::MIN_POSITIVE));
    let xs = tiny.select(x * W::splat(16_777_216.0), x);
    xs.ln() - tiny.select(W::splat(24.0 * core::f32::consts::LN_2), W::splat(0.0))
}

/// `exp(y)` with gradual underflow (wide's `exp` flushes below about `e^−103.6`): where the
/// result may be subnormal (`y < −87`) it is `exp(y/2)²`, rounded once onto the subnormal
/// grid; `y < −104` gives 0 (as the correctly rounded `exp` does below `−103.97`).
#[inline(always)]
fn exp_gradual<W: Lanes>(y: W) -> W {
    let zero = W::splat(0.0);
    let low = y.lt(W::splat(-87.0));
    let dead = y.lt(W::splat(-104.0));
    let arg = low.select(dead.select(zero, y * W::splat(0.5)), y);
    let r = arg.exp();
    dead.select(zero, low.select(r * r, r))
}

/// The scalar `one_pm_cos`: `(1 − cos φ, 1 + cos φ)` of `φ = atan2(sn, cs)`.
#[inline(always)]
fn one_pm_cos<W: Lanes>(sn: W, cs: W) -> (W, W) {
    let (zero, one) = (W::splat(0.0), W::splat(1.0));
    let h = (sn * sn + cs * cs).sqrt();
    let s2 = sn * sn / h;
    let (hp, hm) = (h + cs, h - cs);
    let pos = cs.ge(zero);
    let omc = pos.select(s2 / hp, hm / h);
    let opc = pos.select(hp / h, s2 / hm);
    let hz = h.eq(zero);
    (hz.select(one, omc), hz.select(one, opc))
}

/// Two lanes of the scalar kernel's `arcs` (see there) that share their exponents: the
/// doubled angles from an axis (`c4 = c`) or from a horizon (`c4 = −c`) to a peak, for
/// exponents `(a, b)` of the two lobes, with `r = b − a` and with `r = −(b − a)`;
/// everything times `n = a + b`. Returns `(sn, cs, 1 − cos, 1 + cos)` for each sign.
#[inline(always)]
fn arc_pair<W: Lanes>(a: W, b: W, c4: W, c: W, s: W) -> [(W, W, W, W); 2] {
    let (zero, one) = (W::splat(0.0), W::splat(1.0));
    // The scalar `pow2_range`: an exact power of two that keeps n² normal.
    let p = |e: i32| W::splat(f32::from_bits(((127 + e) as u32) << 23));
    let n = a + b;
    let k = n.lt(p(-20)).select(
        n.lt(p(-60)).select(p(100), p(64)),
        n.gt(p(20)).select(n.gt(p(60)).select(p(-100), p(-40)), one),
    );
    let (a, b) = (a * k, b * k);
    let n = a + b;
    let ab4 = W::splat(4.0) * a * b;
    let cy = (n * n * (c * c) + ab4 * (s * s)).sqrt();
    // |(sn, cs)| = n·(c² + s²) for either sign.
    let h = n * (c * c + s * s);
    let hz = h.eq(zero);
    let lane = |r: W| {
        let rc = -r * c4;
        let den = cy + rc;
        let pos = den.gt(zero).select(s * ab4 / den, zero);
        let sn = rc.ge(zero).select(pos, s * (cy - rc));
        let cs = c4 * cy - r * s * s;
        let d = h + cs.abs();
        let (small, big) = (sn * sn / (h * d), d / h);
        let cpos = cs.ge(zero);
        let omc = hz.select(one, cpos.select(small, big));
        let opc = hz.select(one, cpos.select(big, small));
        (sn, cs, omc, opc)
    };
    let r = b - a;
    [lane(r), lane(-r)]
}

/// The scalar kernel's logarithm of a lane of `arcs`: `½·ln(1 + x)`, `x = −p/2`, where
/// `p < q` (as `ln(u)·x/(u − 1)`, `u = 1 + x`), else `½·ln(q/2)`; `(p, q) = (1 − cos, 1 +
/// cos)` gives `ln cos θ`, swapped `ln sin θ`.
#[inline(always)]
fn ln_half<W: Lanes>(p: W, q: W) -> W {
    let (one, half) = (W::splat(1.0), W::splat(0.5));
    let near = p.lt(q);
    let x = W::splat(-0.5) * p;
    let u = one + x;
    let l = ln_full(near.select(u, half * q));
    let l1p = u.eq(one).select(x, l * (x / (u - one)));
    half * near.select(l1p, l)
}

/// The scalar `exponent_coord`.
#[inline(always)]
fn exponent_coord<W: Lanes>(e: W) -> W {
    let u = ln_full(W::splat(1.0) + max_num(e, W::splat(0.0)) * W::splat(1.0 / EXPONENT_EPS))
        * W::splat(INV_LN_SPAN);
    min_num(u, W::splat(1.0))
}

/// The closed-form part (scalar `baseline`) for finite lanes away from `α = π`: `(ln B, w,
/// (cos t*, sin t*), ln p, arc curvature)`. `e1`, `e2` are already clamped to `≥ 0`.
#[inline(always)]
fn baseline<W: Lanes>(e1: W, e2: W, c: W, s: W) -> Baseline<W> {
    let (zero, one, half) = (W::splat(0.0), W::splat(1.0), W::splat(0.5));
    // The peak of the product (exponents e1, e2), for e1 + e2 > 0: lanes 2 and 3 of the
    // scalar kernel's arcs.
    let [(_, _, omc1, opc1), (_, _, omc2, opc2)] = arc_pair(e1, e2, c, c, s);
    let term = |e: W, omc: W, opc: W| e.eq(zero).select(zero, e * ln_half(omc, opc));
    let curv = |e: W, opc: W| e.eq(zero).select(zero, e * W::splat(2.0) / opc);
    let peak_ln = term(e1, omc1, opc1) + term(e2, omc2, opc2);
    let peak_curv = curv(e1, opc1) + curv(e2, opc2);
    // Both exponents 0: the bisector (finite lanes only reach here, so no infinite sum).
    let (omc0, opc0) = one_pm_cos(s, c);
    let lune = (e1 + e2).gt(zero);
    let peak_dir = (
        (half * lune.select(opc1, opc0)).sqrt(),
        (half * lune.select(omc1, omc0)).sqrt(),
    );
    let ln_peak = lune.select(peak_ln, zero);
    let arc_curvature = lune.select(peak_curv, e1 + e2);

    // Laplace in the logit variable around the peak of sin^(e1+1)·sin^(e2+1): lanes 0 and
    // 1 of the arcs (their sines times f1 + f2).
    let (f1, f2) = (e1 + one, e2 + one);
    let [(sny, csy, omcy, opcy), (snx, csx, omcx, opcx)] = arc_pair(f1, f2, -c, c, s);
    // Lanes near α = π go to the scalar kernel (see `MIN_WIDE_SIN`).
    let min_sn = W::splat(MIN_WIDE_SIN) * (f1 + f2);
    let redo = !(snx.ge(min_sn) & sny.ge(min_sn));
    let x = half * snx.atan2(csx);
    let y = half * sny.atan2(csy);
    let ln_sin_x = ln_half(opcx, omcx);
    let ln_sin_y = ln_half(opcy, omcy);
    let w = clamp(
        -(f1 * ln_sin_x + f2 * ln_sin_y) * W::splat(1.0 / ANGLE_LOG_DROP),
        zero,
        one,
    )
    .sqrt();
    let (ix, iy) = (one / x, one / y);
    let (cot2x, cot2y) = (opcx / omcx, opcy / omcy);
    let (csc2x, csc2y) = (W::splat(2.0) / omcx, W::splat(2.0) / omcy);
    let d = (e1 * cot2x.sqrt() + ix) - (e2 * cot2y.sqrt() + iy);
    let ap = e1 * csc2x + ix * ix;
    let bp = e2 * csc2y + iy * iy;
    let hq = max_num(ap + bp - d * (y - x) * (ix * iy), W::splat(1e-30));
    // The scalar kernel answers ln B = −∞ where hq overflows.
    let redo = redo | hq.eq(W::splat(f32::INFINITY));
    Baseline {
        ln_sines: e1 * ln_sin_x + e2 * ln_sin_y,
        quad: half * d * (d / hq),
        n15: e1 + e2 + W::splat(1.5),
        hq,
        w,
        peak_dir,
        ln_peak,
        arc_curvature,
        redo,
    }
}

/// The scalar `BaselineParts` and the rest of the closed form.
struct Baseline<W> {
    ln_sines: W,
    quad: W,
    n15: W,
    hq: W,
    w: W,
    peak_dir: (W, W),
    ln_peak: W,
    arc_curvature: W,
    /// Lanes to recompute with the scalar kernel.
    redo: W,
}

impl<W: Lanes> Baseline<W> {
    /// The scalar `BaselineParts::ln_b`.
    #[inline(always)]
    fn ln_b(&self) -> W {
        let logs = W::splat(LN_TAU) - W::splat(0.5) * (ln_full(self.n15) + ln_full(self.hq));
        self.ln_sines + logs + self.quad
    }
}

/// The scalar `exp_neg_small`: `e^(−g)` by its degree-6 Taylor polynomial where `|g| ≤
/// 1/4`, wide's `exp` on the other lanes (computed only when some lane needs it).
#[inline(always)]
fn exp_neg_small<W: Lanes>(g: W) -> W {
    let one = W::splat(1.0);
    let g2 = g * g;
    let q = (one - g * W::splat(0.5))
        + g2 * (W::splat(1.0 / 6.0) - g * W::splat(1.0 / 24.0))
        + (g2 * g2) * (W::splat(1.0 / 120.0) - g * W::splat(1.0 / 720.0));
    let poly = one - g * q;
    let far = !g.abs().le(W::splat(0.25));
    if far.any() {
        far.select((-g).exp(), poly)
    } else {
        poly
    }
}

/// The scalar `ln_sg_integral`.
#[inline(always)]
fn ln_sg_integral<W: Lanes>(l1: W, l2: W, c: W, s: W) -> W {
    let (zero, half) = (W::splat(0.0), W::splat(0.5));
    let (omc, opc) = one_pm_cos(max_num(s, zero), c);
    let (sh2, ch2) = (half * omc, half * opc);
    let lr = ((l1 - l2) * (l1 - l2) + W::splat(4.0) * l1 * l2 * ch2).sqrt();
    let den = lr + l1 + l2;
    let ln_s = den
        .gt(zero)
        .select(W::splat(-4.0) * l1 * l2 * sh2 / den, zero);
    let ln_int = W::splat(LN_TAU) + ln_full(-(W::splat(-2.0) * lr).exp_m1()) - ln_full(lr);
    ln_s + lr.eq(zero).select(W::splat(LN_2TAU), ln_int)
}

/// The scalar `ProductTable::correction` at `(u1, u2, w)`: cell indices per lane, the eight
/// table values read with scalar loads, the trilinear arithmetic lane-wise in the scalar
/// order. NaN coordinates give NaN.
#[inline(always)]
fn correction<W: Lanes>(table: &ProductTable<'_>, u1: W, u2: W, w: W) -> W {
    let ne = table.exponents();
    let na = table.angles();
    let cell = |x: W, n: usize| {
        let last = W::splat((n - 1) as f32);
        let t = clamp(x * last, W::splat(0.0), last);
        let i = min_num(t.trunc(), W::splat((n - 2) as f32));
        (i, t - i)
    };
    let (i, fi) = cell(u1, ne);
    let (j, fj) = cell(u2, ne);
    let (k, fk) = cell(w, na);
    // The cell indices of every lane, converted a vector at a time (`as usize`: NaN lanes
    // index 0; their result is replaced below).
    let (mut il, mut jl, mut kl) = ([0usize; 16], [0usize; 16], [0usize; 16]);
    i.to_indices(&mut il);
    j.to_indices(&mut jl);
    k.to_indices(&mut kl);
    let mut g = [[0.0f32; 16]; 8];
    for lane in 0..W::N {
        let (i, j, k) = (il[lane], jl[lane], kl[lane]);
        let base = |a: usize, b: usize| {
            let (lo, hi) = (a.min(b), a.max(b));
            (hi * (hi + 1) / 2 + lo) * na + k
        };
        for (c, (a, b)) in [(i, j), (i, j + 1), (i + 1, j), (i + 1, j + 1)]
            .into_iter()
            .enumerate()
        {
            let idx = base(a, b);
            (g[2 * c][lane], g[2 * c + 1][lane]) = table.pair(idx);
        }
    }
    let at = |c: usize| {
        let g0 = W::from_fn(|l| g[2 * c][l]);
        let g1 = W::from_fn(|l| g[2 * c + 1][l]);
        g0 + fk * (g1 - g0)
    };
    let (g00, g01, g10, g11) = (at(0), at(1), at(2), at(3));
    let g0 = g00 + fj * (g01 - g00);
    let g1 = g10 + fj * (g11 - g10);
    let r = g0 + fi * (g1 - g0);
    (u1.is_nan() | u2.is_nan() | w.is_nan()).select(W::splat(f32::NAN), r)
}

/// `steradian_core::frame::normalize_or_zero` followed by `CosineLobe::saturating`'s
/// zero → `+z`, lane-wise (finite lanes).
#[inline(always)]
fn normalize<W: Lanes>(x: W, y: W, z: W) -> (W, W, W) {
    let zero = W::splat(0.0);
    let m = max_num(max_num(x.abs(), y.abs()), z.abs());
    let k = min_num(W::splat(1.0) / m, W::splat(f32::MAX));
    let (sx, sy, sz) = (x * k, y * k, z * k);
    let inv = W::splat(1.0) / (sx * sx + sy * sy + sz * sz).sqrt();
    let mz = m.eq(zero);
    (
        mz.select(zero, sx * inv),
        mz.select(zero, sy * inv),
        mz.select(W::splat(1.0), sz * inv),
    )
}

/// The scalar `result_lobe`'s axis: divided by its length where its squared length is in
/// `[1/4, 4]`, [`normalize`] (as `CosineLobe::saturating`) elsewhere.
#[inline(always)]
fn normalize_result<W: Lanes>(x: W, y: W, z: W) -> (W, W, W) {
    let l2 = x * x + y * y + z * z;
    let inv = W::splat(1.0) / l2.sqrt();
    let near = l2.ge(W::splat(0.25)) & l2.le(W::splat(4.0));
    let (gx, gy, gz) = normalize(x, y, z);
    (
        near.select(x * inv, gx),
        near.select(y * inv, gy),
        near.select(z * inv, gz),
    )
}

/// The product lane-wise, outputs `[ax, ay, az, scale, exponent]`, and the mask of lanes
/// to recompute with the scalar kernel.
#[inline(always)]
fn product_lanes<W: Lanes>(
    table: &ProductTable<'_>,
    fit: ProductFit,
    [a1x, a1y, a1z, s1, e1, a2x, a2y, a2z, s2, e2]: [W; 10],
) -> ([W; 5], W) {
    let (zero, one) = (W::splat(0.0), W::splat(1.0));
    let big = W::splat(MAX_WIDE_EXPONENT);
    // Non-finite fields (x·0 is NaN exactly for NaN and ±∞), huge exponents.
    let nonfinite = [a1x, a1y, a1z, s1, a2x, a2y, a2z, s2]
        .into_iter()
        .fold(zero, |acc, v| acc + v * zero)
        .is_nan();
    let redo_in = nonfinite | !(e1.le(big) & e2.le(big));
    // `CosineLobe::saturating`: normalised axes, negative exponents → 0; then the kernel's
    // own `max(0)` (a no-op on the finite lanes computed here).
    let (a1x, a1y, a1z) = normalize(a1x, a1y, a1z);
    let (a2x, a2y, a2z) = normalize(a2x, a2y, a2z);
    let e1 = e1.lt(zero).select(zero, e1);
    let e2 = e2.lt(zero).select(zero, e2);

    // The scalar `arc_frame`.
    let c = a1x * a2x + a1y * a2y + a1z * a2z;
    let (px, py, pz) = (a2x - a1x * c, a2y - a1y * c, a2z - a1z * c);
    let s = (px * px + py * py + pz * pz).sqrt();
    // `Frame::from_unit_normal(a1).tangent()` where the axes are (anti)parallel.
    let sign = a1z.ge(zero).select(one, W::splat(-1.0));
    let fa = W::splat(-1.0) / (sign + a1z);
    let fb = a1x * a1y * fa;
    let (tx, ty, tz) = (one + sign * a1x * a1x * fa, sign * fb, -sign * a1x);
    let apart = s.gt(W::splat(1e-30));
    let (wx, wy, wz) = (
        apart.select(px / s, tx),
        apart.select(py / s, ty),
        apart.select(pz / s, tz),
    );
    let c = clamp(c, W::splat(-1.0), one);
    let s = min_num(s, one);

    let base = baseline(e1, e2, c, s);
    let g = match fit {
        ProductFit::ExactIntegral | ProductFit::ExactIntegralCurvature => {
            correction(table, exponent_coord(e1), exponent_coord(e2), base.w)
        }
        ProductFit::SphericalGaussian => zero,
    };
    let (ct, st) = base.peak_dir;
    let (ax, ay, az) = normalize_result(a1x * ct + wx * st, a1y * ct + wy * st, a1z * ct + wz * st);
    let scale = s1 * s2;
    // s1·s2 overflowing (the scalar kernel then multiplies in another order).
    let redo_in = redo_in | (scale * zero).is_nan();
    // As the scalar kernel: the peak-matched exponent from ln I whole for the curvature
    // (its fallback) and spherical-Gaussian fits; for the exact-integral fit
    // e_r + 1 = e^(ln p − ln_sines)·√(n + 1.5)·√hq·e^(−(quad + g)), lanes whose first
    // exponent leaves [−80, 80] to the scalar kernel.
    let (out_scale, e_r, redo_in, ln_i) = match fit {
        ProductFit::ExactIntegralCurvature => {
            let ln_i = base.ln_b() + g;
            let e_r = ((e1 + e2) * base.arc_curvature).sqrt();
            let p = exp_gradual(ln_i + ln_full((e_r + one) * W::splat(1.0 / TAU)));
            // An infinite curvature (peak on an e < 1 lobe's horizon): the scalar kernel
            // falls back to the peak-matched exponent.
            (scale * p, e_r, redo_in | (e_r * zero).is_nan(), ln_i)
        }
        ProductFit::SphericalGaussian => {
            let ln_i = ln_sg_integral(e1, e2, c, s);
            let e_r = (W::splat(LN_TAU) + base.ln_peak - ln_i).exp() - one;
            let out = scale * exp_gradual(base.ln_peak);
            (out, max_num(e_r, zero), redo_in, ln_i)
        }
        ProductFit::ExactIntegral => {
            let arg = base.ln_peak - base.ln_sines;
            let roots = base.n15.sqrt() * base.hq.sqrt();
            let e_r = arg.exp() * roots * exp_neg_small(base.quad + g) - one;
            let out = scale * exp_gradual(base.ln_peak);
            let redo_in = redo_in | !arg.abs().lt(W::splat(80.0));
            // ln I = −∞ only on lanes the scalar kernel recomputes (α = π, hq = ∞).
            (out, max_num(e_r, zero), redo_in, zero)
        }
    };
    // Scalar: `ln I = −∞` (the baseline's `h` overflowed, or `α = π`, which the scalar
    // fallback handles) gives a zero-scale lobe of exponent 0.
    let none = ln_i.eq(W::splat(f32::NEG_INFINITY));
    let out_scale = none.select(zero * scale, out_scale);
    let e_r = none.select(zero, e_r.lt(zero).select(zero, e_r));
    ([ax, ay, az, out_scale, e_r], redo_in | base.redo)
}

/// Lane `k` of `r`, or the scalar kernel on lane `k` of the inputs (`input(column, k)`)
/// where `mask` is set. Out of line and cold.
#[cold]
#[inline(never)]
fn scalar_lanes<W: Lanes>(
    table: &ProductTable<'_>,
    fit: ProductFit,
    input: impl Fn(usize, usize) -> f32,
    mask: W,
    r: [W; 5],
) -> [W; 5] {
    let mk = mask.lanes();
    let mut out: [[f32; 16]; 5] = [[0.0; 16]; 5];
    for (o, v) in out.iter_mut().zip(r.iter()) {
        o[..W::N].copy_from_slice(v.lanes());
    }
    for k in 0..W::N {
        if mk[k].to_bits() != 0 {
            let l = |i: usize| input(i, k);
            let a = CosineLobe::saturating(glam::Vec3::new(l(0), l(1), l(2)), l(3), l(4));
            let b = CosineLobe::saturating(glam::Vec3::new(l(5), l(6), l(7)), l(8), l(9));
            let p = product_with(table, fit, &a, &b);
            let ax = p.axis();
            for (o, v) in out
                .iter_mut()
                .zip([ax.x, ax.y, ax.z, p.scale(), p.exponent()])
            {
                o[k] = v;
            }
        }
    }
    core::array::from_fn(|c| W::from_fn(|k| out[c][k]))
}

/// The product of lobes `a` and `b` lane by lane, with `table` and `fit`: lane `k` is
/// `steradian_core::lobe::product::product_with(table, fit, a_k, b_k)` for the lobes of
/// [`LobeX8::to_array`] — axis bit-identical, scale and exponent within the bounds of the
/// module docs, non-finite or extreme lanes exactly (scalar kernel).
#[inline]
pub fn product_x8(table: &ProductTable<'_>, fit: ProductFit, a: &LobeX8, b: &LobeX8) -> LobeX8 {
    let lanes = [
        a.axis.x, a.axis.y, a.axis.z, a.scale, a.exponent, b.axis.x, b.axis.y, b.axis.z, b.scale,
        b.exponent,
    ];
    let (mut r, redo) = product_lanes(table, fit, lanes);
    if redo.any() {
        r = scalar_lanes(table, fit, |i, k| lanes[i].as_array()[k], redo, r);
    }
    LobeX8::new(Vec3x8::new(r[0], r[1], r[2]), r[3], r[4])
}

struct ProductK<'a> {
    table: ProductTable<'a>,
    fit: ProductFit,
}

impl ColumnKernel<10, 5> for ProductK<'_> {
    const PADS: [f32; 10] = [
        LobeX8::PAD_AXIS.x,
        LobeX8::PAD_AXIS.y,
        LobeX8::PAD_AXIS.z,
        LobeX8::PAD_SCALE,
        LobeX8::PAD_EXPONENT,
        LobeX8::PAD_AXIS.x,
        LobeX8::PAD_AXIS.y,
        LobeX8::PAD_AXIS.z,
        LobeX8::PAD_SCALE,
        LobeX8::PAD_EXPONENT,
    ];
    #[inline(always)]
    fn apply<W: Lanes>(&self, v: [W; 10]) -> ([W; 5], W) {
        product_lanes(&self.table, self.fit, v)
    }
    fn redo<W: Lanes>(&self, ins: [&[f32]; 10], offset: usize, mask: W, r: [W; 5]) -> [W; 5] {
        // Masked lanes lie inside the columns; elsewhere the value is unused.
        let input = |col: usize, k: usize| ins[col].get(offset + k).copied().unwrap_or(0.0);
        scalar_lanes(&self.table, self.fit, input, mask, r)
    }
}

/// [`product_x8`] over structure-of-arrays columns: lobe `i` of `a` is
/// `(a_axis[0][i], a_axis[1][i], a_axis[2][i])`, `a_scale[i]`, `a_exponent[i]`, likewise
/// `b`, and the product goes to `out_axis`, `out_scale`, `out_exponent`. Any length (the
/// tail is padded with the padding lobe of [`LobeX8`]); runs on the build's widest vector
/// (16 lanes with AVX-512F, else 8), same results.
///
/// # Panics
/// If the fifteen columns do not all have the same length.
#[allow(clippy::too_many_arguments)]
pub fn product_slices(
    table: &ProductTable<'_>,
    fit: ProductFit,
    a_axis: [&[f32]; 3],
    a_scale: &[f32],
    a_exponent: &[f32],
    b_axis: [&[f32]; 3],
    b_scale: &[f32],
    b_exponent: &[f32],
    out_axis: [&mut [f32]; 3],
    out_scale: &mut [f32],
    out_exponent: &mut [f32],
) {
    let [ox, oy, oz] = out_axis;
    drive::<SliceVec, _, 10, 5>(
        "product::product_slices",
        &ProductK { table: *table, fit },
        [
            a_axis[0], a_axis[1], a_axis[2], a_scale, a_exponent, b_axis[0], b_axis[1], b_axis[2],
            b_scale, b_exponent,
        ],
        [ox, oy, oz, out_scale, out_exponent],
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_constants_are_the_logarithms_they_stand_for() {
        // The constants replace `TAU.ln()` and `(2.0 * TAU).ln()` so that the crate needs no
        // std float functions; they must be the same bits.
        assert_eq!(LN_TAU.to_bits(), TAU.ln().to_bits());
        assert_eq!(LN_2TAU.to_bits(), (2.0 * TAU).ln().to_bits());
        // And the correctly rounded logarithms of the f32 values (checked in f64).
        assert_eq!(LN_TAU, (TAU as f64).ln() as f32);
        assert_eq!(LN_2TAU, ((2.0 * TAU) as f64).ln() as f32);
    }
}
