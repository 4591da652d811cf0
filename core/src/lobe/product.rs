//! Products of two cosine lobes as one lobe (cosine-lobe paper, section 4.1):
//! `s1·max(a1·v, 0)^e1 · s2·max(a2·v, 0)^e2 ≈ s1·s2·p·max(a_r·v, 0)^e_r`.
//!
//! **Geometry (closed form, exact).** The product peaks on the great arc from `a1` to
//! `a2`, at the angle `t*` from `a1` with `sin(2t* − α) = ((e2 − e1)/(e1 + e2))·sin α`
//! (setting `d/dt [e1·ln cos t + e2·ln cos(α − t)] = 0` gives `e1·sin t·cos(α − t) =
//! e2·sin(α − t)·cos t`, and the product-to-sum identities turn both sides into
//! `sin α ± sin(2t − α)`); the result axis `a_r` is that direction and `p` is the product's peak value
//! `cos^e1(t*)·cos^e2(α − t*)`, so the result equals the product at its maximum.
//!
//! **Integral (table).** The exponent is chosen so that the result integrates to the
//! exact product integral, `2π·p/(e_r + 1) = I(e1, e2, α)` (the "exact integral" fit: a
//! rendering sum of lobe integrals is then exact for the product itself). `I` comes from a
//! closed-form baseline corrected by a table:
//!
//! `ln I = ln B(e1, e2, α) + g(u1, u2, w)`, with `B` Laplace's method applied to
//! `I = K(e1 + e2)·∫_0^L sin^e1(x)·sin^e2(L − x) dx` (`L = π − α`, `x` the distance to the
//! horizon of `a1`; harness `reference::product`) in the logit variable `s = ln(x/(L − x))`,
//! expanded to second order around the peak of `sin^(e1+1)·sin^(e2+1)` (closed form, the
//! formula above with exponents `+1`). In `s` the end points of the lune are at infinity,
//! so the baseline stays within about 12 % of `I` everywhere, including a hemisphere
//! (`e = 0`) against a lobe of exponent `1e5` at the horizon, where Laplace's method in
//! `x` is off by orders of magnitude and the spherical Gaussian product is off by 50 %. The
//! table stores the smooth remainder `g = ln I − ln B` on the grid
//!
//! - `u = ln(1 + e/ε)/ln(1 + E/ε)` for each exponent (`ε = 0.05`, `E = 1e5`; symmetric in
//!   `(e1, e2)`, stored once as a packed triangle),
//! - `w = √min(Δ/Λ, 1)`, `Δ = −((e1+1)·ln sin x* + (e2+1)·ln sin(L − x*))` the log-drop of
//!   that `+1` peak from its value at `α = 0` (`Λ = 30`): monotone in `α`, uniform in `α`
//!   for sharp lobes and stretched across the horizon where a sharp lobe meets a broad one,
//!
//! interpolated trilinearly. Beyond `w = 1` the product integral is below `e^(−30)` of the
//! lobes' own integrals and `g` is held at its last value. Exponents above `E` use the
//! table's last row: there the baseline's own error is `O(1/e)`.
//!
//! **Error bound** (tests against the exact f64 integral, harness): with the built-in table
//! (64 exponent samples, 128 angle samples, 1.06 MB), the relative error of
//! `2π·p/(e_r + 1)` against `I` over `e1, e2 ∈ {0} ∪ [1e−3, 1e5]` log-uniform and `α`
//! uniform in `[0, π)` is below [`INTEGRAL_REL_MEAN`] on average, [`INTEGRAL_REL_P99`] at
//! the 99th percentile and [`INTEGRAL_REL_MAX`] everywhere, wherever
//! `I ≥ 1e−6·min(∫c1, ∫c2)`; below that the absolute error is below
//! `1e−8·min(∫c1, ∫c2)`.
//!
//! The shape is not exact: a product of lobes is not a lobe (its cross-section is
//! anisotropic). The harness reports the relative L2 shape error over the domain.
//!
//! **Evaluation.** The closed form evaluates one peak formula four times (the horizons'
//! peak for `B`, the product's peak for the axis, each from both axes): they run side by
//! side in the lanes of a `Vec4` (`Arcs`), with one [`math::ln_x4`] for their four
//! logarithms, and no division before them. The default fit never forms `ln B`:
//! `e_r + 1 = 2π·p/(B·e^g)` is a product of an exponential that needs only the arcs, two
//! square roots and a short polynomial in the small `quad + g` (see [`product_with`];
//! test `quad_and_g_stay_small` checks that they are). Its speed: criterion
//! `lobe-product/table/scalar` (`cargo bench -p steradian-benches --bench product`) and
//! the report's `lobe-product` section; its error: the bounds above.

use crate::lobe::CosineLobe;
use crate::math;
use crate::table::{HEADER_LEN, Header, TableError, TableView};
use crate::{TWO_PI, Vec3};
use glam::{BVec4A, Vec4};

/// `ln 2π`.
const LN_TWO_PI: f32 = 1.837_877_1;

/// Name of the product table in its header.
pub const TABLE_NAME: &str = "lobe-product";
/// Exponent samples of the built-in table.
pub const TABLE_EXPONENTS: usize = 64;
/// Angle samples of the built-in table.
pub const TABLE_ANGLES: usize = 128;
/// Values in the built-in table: `TABLE_EXPONENTS·(TABLE_EXPONENTS + 1)/2·TABLE_ANGLES`.
pub const TABLE_LEN: usize = TABLE_EXPONENTS * (TABLE_EXPONENTS + 1) / 2 * TABLE_ANGLES;
/// `ε` of the exponent coordinate `u = ln(1 + e/ε)/ln(1 + E/ε)`.
pub const EXPONENT_EPS: f32 = 0.05;
/// `E`, the largest tabulated exponent.
pub const EXPONENT_MAX: f32 = 1.0e5;
/// `Λ`, the log-drop at `w = 1`.
pub const ANGLE_LOG_DROP: f32 = 30.0;

/// Measured mean relative integral error of the built-in table (see the module docs).
pub const INTEGRAL_REL_MEAN: f64 = 1e-4;
/// Measured 99th-percentile relative integral error of the built-in table.
pub const INTEGRAL_REL_P99: f64 = 1e-3;
/// Bound on the relative integral error of the built-in table.
pub const INTEGRAL_REL_MAX: f64 = 1e-2;

/// The committed table bytes (header + `g` values, packed triangle × angles).
pub static TABLE_BYTES: &[u8] = include_bytes!("tables/lobe_product.bin");
/// The header, checked at compile time (name and length; the checksum of this 1 MB table
/// is verified by a test and by `steradian tables --check`).
const HEADER: Header = match Header::parse_shape(include_bytes!("tables/lobe_product.bin")) {
    Ok(h) if h.has_name(TABLE_NAME) && h.count == TABLE_LEN as u64 => h,
    _ => panic!("built-in lobe-product table failed validation"),
};

/// A product table: `g = ln I − ln B` at `exponents × angles` nodes, the exponent pairs
/// `i ≤ j` packed as `j(j+1)/2 + i`, each followed by its `angles` values.
#[derive(Clone, Copy, Debug)]
pub struct ProductTable<'a> {
    exponents: usize,
    angles: usize,
    /// Little-endian f32 values.
    payload: &'a [u8],
}

impl<'a> ProductTable<'a> {
    /// The built-in table.
    pub fn builtin() -> ProductTable<'static> {
        let _ = HEADER;
        ProductTable {
            exponents: TABLE_EXPONENTS,
            angles: TABLE_ANGLES,
            payload: TABLE_BYTES.split_at(HEADER_LEN).1,
        }
    }

    /// A table from table-file bytes (`steradian_core::table` format, name
    /// [`TABLE_NAME`], rank 2 with dims `[exponents·(exponents + 1)/2, angles]`), fully
    /// validated (checksum included; every value finite). The harness generates tables of
    /// other resolutions for the report's speed-against-error curve.
    pub fn from_bytes(bytes: &'a [u8]) -> Result<Self, TableError> {
        let view = TableView::parse(bytes)?;
        let h = view.header();
        if !h.has_name(TABLE_NAME) || h.rank != 2 || h.channels != 1 {
            return Err(TableError::BadShape);
        }
        let (pairs, angles) = (h.dims[0] as usize, h.dims[1] as usize);
        // exponents = the n with n(n + 1)/2 = pairs.
        let mut n = 0usize;
        while (n + 1) * (n + 2) / 2 <= pairs {
            n += 1;
        }
        if n < 2 || n * (n + 1) / 2 != pairs || angles < 2 {
            return Err(TableError::BadShape);
        }
        let payload = bytes.split_at(HEADER_LEN).1;
        if payload
            .chunks_exact(4)
            .any(|b| !f32::from_le_bytes([b[0], b[1], b[2], b[3]]).is_finite())
        {
            return Err(TableError::BadShape);
        }
        Ok(ProductTable {
            exponents: n,
            angles,
            payload,
        })
    }

    /// Exponent samples.
    pub fn exponents(&self) -> usize {
        self.exponents
    }

    /// Angle samples.
    pub fn angles(&self) -> usize {
        self.angles
    }

    /// Size of the values in bytes.
    pub fn bytes(&self) -> usize {
        self.payload.len()
    }

    /// The table in the layout of `wgsl::LOBE_PRODUCT` (binding 3): `[exponents, angles]` as
    /// `f32`, then every value of the packed layout in order.
    #[cfg(feature = "alloc")]
    pub fn gpu_table(&self) -> alloc::vec::Vec<f32> {
        let mut t = alloc::vec::Vec::with_capacity(2 + self.payload.len() / 4);
        t.push(self.exponents as f32);
        t.push(self.angles as f32);
        t.extend(
            self.payload
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        );
        t
    }

    /// Values `idx` and `idx + 1` of the packed layout, behind one bound check (0 outside,
    /// which validation rules out): a cell's two angle nodes.
    #[inline(always)]
    pub fn pair(&self, idx: usize) -> (f32, f32) {
        match self.payload.get(4 * idx..4 * idx + 8) {
            Some(v) => (
                f32::from_le_bytes([v[0], v[1], v[2], v[3]]),
                f32::from_le_bytes([v[4], v[5], v[6], v[7]]),
            ),
            None => (0.0, 0.0),
        }
    }

    /// `g` interpolated trilinearly at `(u1, u2, w) ∈ [0, 1]³` (clamped; NaN → NaN).
    #[inline]
    pub fn correction(&self, u1: f32, u2: f32, w: f32) -> f32 {
        if u1.is_nan() || u2.is_nan() || w.is_nan() {
            return f32::NAN;
        }
        let (i, fi) = cell(u1, self.exponents);
        let (j, fj) = cell(u2, self.exponents);
        let (k, fk) = cell(w, self.angles);
        // Entries k and k + 1 of the row of the exponent pair (a, b) (the table is symmetric
        // and stores a ≤ b; min/max, not a branch random pairs would mispredict).
        let at = |a: usize, b: usize| {
            let (lo, hi) = (a.min(b), a.max(b));
            let (g0, g1) = self.pair((hi * (hi + 1) / 2 + lo) * self.angles + k);
            g0 + fk * (g1 - g0)
        };
        let g00 = at(i, j);
        let g01 = at(i, j + 1);
        let g10 = at(i + 1, j);
        let g11 = at(i + 1, j + 1);
        let g0 = g00 + fj * (g01 - g00);
        let g1 = g10 + fj * (g11 - g10);
        g0 + fi * (g1 - g0)
    }
}

/// Cell index and fraction of `x ∈ [0, 1]` on `n` nodes (clamped).
#[inline]
fn cell(x: f32, n: usize) -> (usize, f32) {
    let last = (n - 1) as f32;
    let t = (x * last).clamp(0.0, last);
    // `as u32`, not `as usize`: the same value (t ∈ [0, n − 1]) in a third of the
    // instructions of the saturating 64-bit conversion.
    let i = (t as u32).min(n as u32 - 2);
    (i as usize, t - i as f32)
}

/// The table's exponent coordinate `u = ln(1 + e/ε)/ln(1 + E/ε)`, clamped to `[0, 1]`
/// (the first of [`exponent_coords`]).
#[inline]
pub fn exponent_coord(e: f32) -> f32 {
    exponent_coords(e, e).0
}

/// The exponent coordinates of two exponents (the kernel's two, one logarithm for both).
///
/// `ln` of the rounded `1 + e/ε`, not `log1p`: a coordinate needs absolute, not relative,
/// precision, and rounding `1 + e/ε` moves `ln` by at most `2⁻²⁴` (`u` by `4e-9`, a
/// `2.6e-7` fraction of a cell of the built-in table).
#[inline(always)]
pub fn exponent_coords(e1: f32, e2: f32) -> (f32, f32) {
    // ln(1 + E/ε) = ln(2e6 + 1).
    const INV_LN_SPAN: f32 = 1.0 / 14.508_658;
    let arg = |e: f32| 1.0 + e.max(0.0) * (1.0 / EXPONENT_EPS);
    let u = (math::ln_x4(Vec4::new(arg(e1), arg(e2), 1.0, 1.0)) * INV_LN_SPAN).min(Vec4::ONE);
    (u.x, u.y)
}

/// `(1 ± cos φ)` of the angle `φ = atan2(sn, cs)` (`sn ≥ 0`), each without cancellation:
/// `(1 − cos φ, 1 + cos φ)`.
#[inline]
fn one_pm_cos(sn: f32, cs: f32) -> (f32, f32) {
    let h = math::sqrtf(sn * sn + cs * cs);
    if h == 0.0 {
        return (1.0, 1.0);
    }
    let s2 = sn * sn / h;
    if cs >= 0.0 {
        (s2 / (h + cs), (h + cs) / h)
    } else {
        ((h - cs) / h, s2 / (h - cs))
    }
}

/// Lanes 0–1 of a [`Vec4`]: the two horizon arcs of [`Arcs`].
const HORIZON_LANES: BVec4A = BVec4A::new(true, true, false, false);

/// The four arcs of the closed form, one per lane: the same formulas with other signs and
/// exponents, so the kernel computes them side by side (one division or square root for
/// four, one [`math::ln_x4`] for four logarithms).
///
/// - lane 0: `x`, from `a1`'s horizon to the peak of `sin^f1(x)·sin^f2(y)` on the lune
///   (`f = e + 1`, `x + y = π − α`: the peak Laplace's method expands around);
/// - lane 1: `y`, from `a2`'s horizon to that peak;
/// - lane 2: `t*`, from `a1` to the peak of the product `cos^e1(t)·cos^e2(α − t)`;
/// - lane 3: `α − t*`, from `a2` to that peak.
///
/// **Peak** (module docs): `2t* = α − asin(r'·sin α)` with `r' = (e1 − e2)/(e1 + e2)`; with
/// `cos(asin(r·s)) = cy = √(c² + (1 − r²)·s²)`, `sin 2t* = s·(cy − rc)` and `cos 2t* =
/// c·cy − r·s²` (`rc = −r·c`), the sine taken as `s·(1 − r²)/(cy + rc)` where `rc ≥ 0`
/// (the same value: `(cy − rc)(cy + rc) = 1 − r²`, without the cancellation), so a tiny
/// `t*` keeps full relative precision. The horizon angles are `π/2 − t` of the same
/// formulas with `f` for `e` and `−c` for `c`. The kernel carries all of it times `e1 +
/// e2`, which removes the divisions from `r` and `1 − r²`, and uses `sn² + cs² = (c² +
/// s²)²` (expand with `cy²`; the cross terms cancel) for the length of `(sn, cs)`.
#[derive(Clone, Copy, Debug)]
struct Arcs {
    /// `sin 2θ` of each lane's angle `θ`.
    sn: Vec4,
    /// `cos 2θ`.
    cs: Vec4,
    /// `1 − cos 2θ`, without cancellation.
    omc: Vec4,
    /// `1 + cos 2θ`, without cancellation.
    opc: Vec4,
    /// `(ln sin x, ln sin y, ln cos t*, ln cos(α − t*))`.
    ln: Vec4,
}

/// [`Arcs`] of exponents `e1, e2 ≥ 0` (not NaN) whose axes are `α` apart (`c = cos α`,
/// `s = sin α ≥ 0`). Lanes 2–3 are NaN where `e1 + e2` is 0 or infinite (no single peak).
///
/// `(1 ∓ cos φ)` of `φ = atan2(sn, cs)`: with `h = |(sn, cs)|` (`= n·(c² + s²)`, no root)
/// and `d = h + |cs|`, the larger is `d/h` and the smaller `sn²/(h·d)` (their product is
/// `sin²φ`). `ln cos θ` from `(1 ∓ cos 2θ)`: `½·ln((1 + cos 2θ)/2)`, and where `θ` is
/// small `½·ln(1 + x)` with `x = −(1 − cos 2θ)/2`, as `ln(u)·x/(u − 1)` with `u = 1 + x`
/// rounded (Goldberg 1991, theorem 4: the rounding of `u` cancels between `ln u` and
/// `u − 1`), `x` itself where `u = 1`, so that `e·ln cos t*` keeps its relative precision
/// at `e = 1e5`; `ln sin x = ln cos(π/2 − x)` swaps the pair.
#[inline(always)]
fn arcs(e1: f32, e2: f32, c: f32, s: f32) -> Arcs {
    // Everything times n = f1 + f2 (no division): n·r = f2 − f1 (signed per lane),
    // n²·(1 − r²) = 4·f1·f2, n·cy = √(n²·c² + 4·f1·f2·s²); (sn, cs) come out times n. The
    // exponents are first scaled by a power of two (exact) that keeps n² within the normal
    // range for any exponents.
    let a = Vec4::new(e1 + 1.0, e1 + 1.0, e1, e1);
    let b = Vec4::new(e2 + 1.0, e2 + 1.0, e2, e2);
    let k = pow2_range(a + b);
    let (a, b) = (a * k, b * k);
    let n = a + b;
    let r = (b - a) * Vec4::new(-1.0, 1.0, 1.0, -1.0);
    let ab4 = 4.0 * a * b;
    let c4 = Vec4::new(-c, -c, c, c);
    let cy = (n * n * (c * c) + ab4 * (s * s)).sqrt();
    let rc = -r * c4;
    let den = cy + rc;
    let pos = Vec4::select(den.cmpgt(Vec4::ZERO), s * ab4 / den, Vec4::ZERO);
    let sn = Vec4::select(rc.cmpge(Vec4::ZERO), pos, s * (cy - rc));
    let cs = c4 * cy - r * s * s;
    // 1 ∓ cos 2θ: |(sn, cs)| = n·(c² + s²) exactly (expand sn² + cs² with cy²), no root.
    let h = n * (c * c + s * s);
    let d = h + cs.abs();
    let (small, big) = (sn * sn / (h * d), d / h);
    let cpos = cs.cmpge(Vec4::ZERO);
    let zero = h.cmpeq(Vec4::ZERO);
    let omc = Vec4::select(zero, Vec4::ONE, Vec4::select(cpos, small, big));
    let opc = Vec4::select(zero, Vec4::ONE, Vec4::select(cpos, big, small));
    // ln cos θ (lanes 2–3) and ln sin θ = ln cos(π/2 − θ) (lanes 0–1).
    let p = Vec4::select(HORIZON_LANES, opc, omc);
    let q = Vec4::select(HORIZON_LANES, omc, opc);
    let near = p.cmplt(q);
    let x = -0.5 * p;
    let u = 1.0 + x;
    let l = math::ln_x4(Vec4::select(near, u, 0.5 * q));
    let l1p = Vec4::select(u.cmpeq(Vec4::ONE), x, l * (x / (u - 1.0)));
    Arcs {
        sn,
        cs,
        omc,
        opc,
        ln: 0.5 * Vec4::select(near, l1p, l),
    }
}

/// A power of two `k` (exact to multiply by) with `k·n ∈ [2⁻⁴⁹, 2⁴⁴]` for any `n ≥ 0` from
/// the smallest subnormal to `f32::MAX`, `1` for `n ∈ [2⁻²⁰, 2²⁰]`: `(k·n)²` and the
/// products of two such numbers are normal.
#[inline(always)]
fn pow2_range(n: Vec4) -> Vec4 {
    let p = |e: i32| Vec4::splat(f32::from_bits(((127 + e) as u32) << 23));
    let up = Vec4::select(n.cmplt(p(-60)), p(100), p(64));
    let down = Vec4::select(n.cmpgt(p(60)), p(-100), p(-40));
    Vec4::select(
        n.cmplt(p(-20)),
        up,
        Vec4::select(n.cmpgt(p(20)), down, Vec4::ONE),
    )
}

/// The table's angle coordinate `w = √min(Δ/Λ, 1)` from the arcs, `Δ = −(f1·ln sin x +
/// f2·ln sin y)` (module docs).
#[inline(always)]
fn angle_coord(e1: f32, e2: f32, arcs: &Arcs) -> f32 {
    let drop = -((e1 + 1.0) * arcs.ln.x + (e2 + 1.0) * arcs.ln.y);
    math::sqrtf((drop * (1.0 / ANGLE_LOG_DROP)).clamp(0.0, 1.0))
}

/// `atan2(y, x)` for `y ≥ 0` (`[0, π]`), NaN for NaN, on four lanes: Cephes' `atanf`
/// (Moshier 1989) after the reduction to `[0, tan(π/8)]` — `atan t = π/4 + atan((t − 1)/(t +
/// 1))` above `tan(π/8)`, `atan t = π/2 − atan(1/t)` above 1 (by swapping `y` and `|x|`), `π −
/// ·` for `x < 0` — whose degree-9 odd polynomial is within `1.9e-7` relative of `atan`
/// there; full relative precision for small results (`atan z = z + z³·p(z²)`). The same
/// function as the WGSL twin's `atan2_`. The baseline needs its angles to a few ulps, not
/// correctly rounded: they enter `ln B` through `1/x`, `x·y/(x + y)` and their logarithms.
#[inline(always)]
fn atan2_pos(y: Vec4, x: Vec4) -> Vec4 {
    let ax = x.abs();
    let swap = y.cmpgt(ax);
    let (num, den) = (Vec4::select(swap, ax, y), Vec4::select(swap, y, ax));
    // t = num/den ∈ [0, 1]; above tan(π/8), z = (t − 1)/(t + 1) = (num − den)/(num + den):
    // one division either way. den = 0 only for y = x = 0: atan2(0, ±0) is 0 or π, as for
    // z = 0 below.
    let big = num.cmpgt(0.414_213_57 * den);
    let zn = Vec4::select(big, num - den, num);
    let zd = Vec4::select(big, num + den, den);
    let z = Vec4::select(zd.cmpgt(Vec4::ZERO), zn / zd, Vec4::ZERO);
    let base = Vec4::select(big, Vec4::splat(core::f32::consts::FRAC_PI_4), Vec4::ZERO);
    let zz = z * z;
    let p = ((0.080_537_445 * zz - 0.138_776_86) * zz + 0.199_777_11) * zz - 0.333_329_5;
    let r = base + (z + z * zz * p);
    let r = Vec4::select(swap, core::f32::consts::FRAC_PI_2 - r, r);
    // atan2(y, −0) is π/2 for y > 0 (r = π/2 already) and π for y = 0 (r = 0).
    let r = Vec4::select(x.is_negative_mask(), crate::PI - r, r);
    Vec4::select(y.is_nan_mask() | x.is_nan_mask(), Vec4::NAN, r)
}

/// `e^(−g)` for the table's correction `g` (plus the baseline's `quad`): where `|g| ≤ 1/4`
/// (the built-in table's values lie in `[0, 0.19]`, test `quad_and_g_stay_small`) its
/// Taylor polynomial of degree 6 (remainder below `g⁷/7! ≤ 1.3e-8`,
/// a tenth of an ulp; Estrin's scheme), else [`math::exp_x4`]. Within 1 ulp over `[−1/4,
/// 1/4]` (test `exp_neg_small_against_f64`).
#[inline(always)]
fn exp_neg_small(g: f32) -> f32 {
    if g.abs() <= 0.25 {
        // 1 − g·q, q = 1 − g/2 + g²/6 − g³/24 + g⁴/120 − g⁵/720: q's rounding reaches the
        // result times |g| ≤ 1/4.
        let g2 = g * g;
        let q = (1.0 - g * 0.5)
            + g2 * (1.0 / 6.0 - g * (1.0 / 24.0))
            + (g2 * g2) * (1.0 / 120.0 - g * (1.0 / 720.0));
        1.0 - g * q
    } else {
        math::exp_x4(Vec4::splat(-g)).x
    }
}

/// Everything the kernel derives in closed form from `(e1, e2, cos α, sin α)`.
#[derive(Clone, Copy, Debug)]
pub struct Baseline {
    /// `ln B`, Laplace's method in the logit variable (module docs).
    pub ln_b: f32,
    /// The angle coordinate `w ∈ [0, 1]` of the table.
    pub w: f32,
    /// `(cos t*, sin t*)` of the product's peak direction, from `a1` toward `a2`.
    pub peak_dir: (f32, f32),
    /// `ln` of the product's peak value `cos^e1(t*)·cos^e2(α − t*)`.
    pub ln_peak: f32,
    /// Curvature of `−ln(product)` at the peak along the arc,
    /// `e1·sec²t* + e2·sec²(α − t*)` (across the arc it is `e1 + e2`).
    pub arc_curvature: f32,
}

/// The peak of the product itself (exponents `e1, e2 ≥ 0`, not NaN) from lanes 2–3 of the
/// arcs: `(cos t*, sin t*)`, `ln` of the peak value and the curvature along the arc (see
/// [`Baseline`]).
#[inline(always)]
fn peak(e1: f32, e2: f32, c: f32, s: f32, arcs: &Arcs) -> ((f32, f32), f32, f32) {
    if e1 + e2 > 0.0 && (e1 + e2).is_finite() {
        // e·ln cos t and e·sec²t = 2e/(1 + cos 2t) in lanes 2–3, 0 for e = 0 (whose
        // logarithm may be −∞): lane selects, not branches (random pairs take both).
        let e = Vec4::new(0.0, 0.0, e1, e2);
        let none = e.cmpeq(Vec4::ZERO);
        let term = Vec4::select(none, Vec4::ZERO, e * arcs.ln);
        let curv = Vec4::select(none, Vec4::ZERO, e * 2.0 / arcs.opc);
        let (opc1, omc1) = (arcs.opc.z, arcs.omc.z);
        (
            (math::sqrtf(0.5 * opc1), math::sqrtf(0.5 * omc1)),
            term.z + term.w,
            curv.z + curv.w,
        )
    } else {
        // Both exponents 0 (a lune: constant on it) or infinite: the bisector.
        let (omc, opc) = one_pm_cos(s, c);
        (
            (math::sqrtf(0.5 * opc), math::sqrtf(0.5 * omc)),
            0.0,
            e1 + e2,
        )
    }
}

/// The logit-Laplace baseline in parts: `ln B = ln_sines + quad + ln 2π − ½·ln((n + 1.5)·hq)`
/// (see [`baseline_parts`]), so that a caller that wants `B` itself takes a square root
/// where `ln B` takes a logarithm.
#[derive(Clone, Copy, Debug)]
struct BaselineParts {
    /// `e1·ln sin x + e2·ln sin y`.
    ln_sines: f32,
    /// `φ'²/(−2φ'') ≥ 0`.
    quad: f32,
    /// `n + 1.5 = e1 + e2 + 1.5`.
    n15: f32,
    /// `−φ''/m²`, floored at `1e-30`.
    hq: f32,
}

impl BaselineParts {
    /// `ln B`.
    #[inline(always)]
    fn ln_b(&self) -> f32 {
        let l = math::ln_x4(Vec4::new(self.n15, self.hq, 1.0, 1.0));
        self.ln_sines + (LN_TWO_PI - 0.5 * (l.x + l.y)) + self.quad
    }
}

/// The parts of `ln B` from lanes 0–1 of the arcs (module docs); `None` where the open
/// hemispheres are disjoint (`α = π`: `ln B = −∞`).
#[inline(always)]
fn baseline_parts(e1: f32, e2: f32, arcs: &Arcs) -> Option<BaselineParts> {
    let angles = 0.5 * atan2_pos(arcs.sn, arcs.cs);
    let (x, y) = (angles.x, angles.y);
    if !(x > 0.0 && y > 0.0) {
        // α = π: the open hemispheres are disjoint.
        return None;
    }
    // Reciprocals once (each is used twice), and cot²x = (1 + cos 2x)/(1 − cos 2x),
    // csc²x = 2/(1 − cos 2x) (these do not wait for the angles).
    let rec = Vec4::ONE / Vec4::new(x, y, 1.0, 1.0);
    let (ix, iy) = (rec.x, rec.y);
    let (omcx, omcy) = (arcs.omc.x, arcs.omc.y);
    let trig = Vec4::new(arcs.opc.x, arcs.opc.y, 2.0, 2.0) / Vec4::new(omcx, omcy, omcx, omcy);
    let cot = Vec4::new(trig.x, trig.y, 0.0, 0.0).sqrt();
    // In the logit variable, with m = x·y/(x + y): φ' = m·d at the peak and −φ'' = m²·hq,
    // d = (e1·cot x + 1/x) − (e2·cot y + 1/y), hq = e1·csc²x + e2·csc²y + 1/x² + 1/y² −
    // d·(y − x)/(x·y). Then ln K + ln m + ½·ln(2π/(−φ'')) = ln 2π − ½·ln((n + 1.5)·hq) with
    // K ≈ √(2π/(n + 1.5)) (`m` cancels) and φ'²/(−2φ'') = d²/(2·hq).
    let d = (e1 * cot.x + ix) - (e2 * cot.y + iy);
    let ap = e1 * trig.z + ix * ix;
    let bp = e2 * trig.w + iy * iy;
    // Floored so that a degenerate case cannot divide by zero; it overflows only where `x`
    // or `y` is below 1e-19 (α within 1e-14 of π), where `ln B = −∞` is within the bound.
    let hq = (ap + bp - d * (y - x) * (ix * iy)).max(1e-30);
    if hq == f32::INFINITY {
        return None;
    }
    let quad = 0.5 * d * (d / hq);
    Some(BaselineParts {
        ln_sines: e1 * arcs.ln.x + e2 * arcs.ln.y,
        quad,
        n15: e1 + e2 + 1.5,
        hq,
    })
}

/// The closed-form part of the product of unit lobes with exponents `e1, e2` (clamped to
/// `≥ 0`) whose axes are `α` apart, given `cos α` and `sin α ≥ 0`. For `α = π` (`sin α = 0`,
/// `cos α < 0`) `ln_b = −∞`. NaN in → NaN out.
pub fn baseline(e1: f32, e2: f32, cos_a: f32, sin_a: f32) -> Baseline {
    let (e1, e2) = (e1.max(0.0), e2.max(0.0));
    let (s, c) = (sin_a.max(0.0), cos_a);
    let nan = e1.is_nan() || e2.is_nan() || s.is_nan() || c.is_nan();
    if nan {
        return Baseline {
            ln_b: f32::NAN,
            w: f32::NAN,
            peak_dir: (f32::NAN, f32::NAN),
            ln_peak: f32::NAN,
            arc_curvature: f32::NAN,
        };
    }
    let arcs = arcs(e1, e2, c, s);
    let (peak_dir, ln_peak, arc_curvature) = peak(e1, e2, c, s, &arcs);
    let ln_b = baseline_parts(e1, e2, &arcs).map(|p| p.ln_b());
    Baseline {
        ln_b: ln_b.unwrap_or(f32::NEG_INFINITY),
        w: if ln_b.is_some() {
            angle_coord(e1, e2, &arcs)
        } else {
            1.0
        },
        peak_dir,
        ln_peak,
        arc_curvature,
    }
}

/// `(cos α, sin α, w)` of two unit axes, `w` the unit vector perpendicular to `a1` in the
/// plane of both, toward `a2` (a fixed perpendicular of `a1` when the axes are
/// (anti)parallel).
#[inline]
fn arc_frame(a1: Vec3, a2: Vec3) -> (f32, f32, Vec3) {
    let c = a1.dot(a2);
    let perp = a2 - a1 * c;
    let s = perp.length();
    let w = if s > 1e-30 {
        perp / s
    } else {
        crate::frame::Frame::from_unit_normal(a1).tangent()
    };
    (c.clamp(-1.0, 1.0), s.min(1.0), w)
}

/// The result lobe, [`CosineLobe::saturating`] without its general normalisation: the
/// axis `a1·cos t* + w·sin t*` is a unit vector up to rounding (`a1` and `w` orthonormal,
/// `(cos t*, sin t*)` a unit pair), so it is divided by its length directly, and
/// `saturating` (scaled by the largest component first) takes only what leaves `[1/4, 4]`
/// in squared length, NaN included.
#[inline(always)]
fn result_lobe(axis: Vec3, scale: f32, exponent: f32) -> CosineLobe {
    let l2 = axis.length_squared();
    if (0.25..=4.0).contains(&l2) {
        CosineLobe {
            axis: axis * (1.0 / math::sqrtf(l2)),
            scale,
            // `f32::max` would turn NaN into 0.
            exponent: if exponent < 0.0 { 0.0 } else { exponent },
        }
    } else {
        CosineLobe::saturating(axis, scale, exponent)
    }
}

/// Which exponent the result lobe gets. The scale is the product's peak value in both.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ProductFit {
    /// `2π·p/(e_r + 1) = I` from the table, `p` the product's peak value: the result
    /// integrates exactly and equals the product at its peak (default).
    #[default]
    ExactIntegral,
    /// `I` from the table, exponent from the product's curvature at its peak,
    /// `e_r = √((e1 + e2)·(e1·sec²t* + e2·sec²(α − t*)))` (the geometric mean of its
    /// curvatures across and along the arc), scale `p = I·(e_r + 1)/(2π)`: integrates
    /// exactly and matches the width of the peak instead of its height.
    ExactIntegralCurvature,
    /// `I` from the spherical-Gaussian closed form (no table): `λ = e` for each lobe,
    /// `∫ = 2π(1 − e^(−2λ_r))/λ_r·e^(λ_r − λ1 − λ2)`. Off by `1/(2e)` at `α = 0`, by 50 %
    /// when a sharp lobe meets a hemisphere at the horizon, by orders of magnitude at wide
    /// angles between sharp lobes (where both are tiny). The baseline the table beats.
    SphericalGaussian,
}

/// `ln` of the integral of the product of two spherical Gaussians `exp(λ_i(a_i·v − 1))`,
/// `λ_i = e_i`, axes `α` apart: `ln s + ln(2π(1 − e^(−2λ_r))/λ_r)` with
/// `λ_r² = (λ1 − λ2)² + 4λ1λ2·cos²(α/2)` and `ln s = −4λ1λ2·sin²(α/2)/(λ_r + λ1 + λ2)`.
pub fn ln_sg_integral(e1: f32, e2: f32, cos_a: f32, sin_a: f32) -> f32 {
    let (l1, l2) = (e1.max(0.0), e2.max(0.0));
    let (omc, opc) = one_pm_cos(sin_a.max(0.0), cos_a);
    // sin²(α/2) = (1 − cos α)/2, cos²(α/2) = (1 + cos α)/2.
    let (sh2, ch2) = (0.5 * omc, 0.5 * opc);
    let lr = math::sqrtf((l1 - l2) * (l1 - l2) + 4.0 * l1 * l2 * ch2);
    let den = lr + l1 + l2;
    let ln_s = if den > 0.0 {
        -4.0 * l1 * l2 * sh2 / den
    } else {
        0.0
    };
    let ln_int = if lr == 0.0 {
        math::logf(2.0 * TWO_PI)
    } else {
        math::logf(TWO_PI) + math::logf(-math::expm1f(-2.0 * lr)) - math::logf(lr)
    };
    ln_s + ln_int
}

/// The product of `a` and `b` as one lobe with the built-in table (see the module docs).
///
/// Never panics. Scales multiply (a negative or NaN scale propagates as the lobes' own
/// `eval` would); exponents are clamped to `≥ 0`; the result's exponent is `≥ 0`, finite
/// for finite inputs; axes exactly opposite give a zero-scale lobe.
#[inline]
pub fn product(a: &CosineLobe, b: &CosineLobe) -> CosineLobe {
    product_with(&ProductTable::builtin(), ProductFit::ExactIntegral, a, b)
}

/// [`product`] with a chosen table and fit.
pub fn product_with(
    table: &ProductTable<'_>,
    fit: ProductFit,
    a: &CosineLobe,
    b: &CosineLobe,
) -> CosineLobe {
    let (e1, e2) = (a.exponent(), b.exponent());
    let (c, s, w) = arc_frame(a.axis(), b.axis());
    // `baseline`, in the order that starts the table's loads (four cache lines at random
    // places in 1 MB) before the rest of the closed form is computed, so that the two
    // overlap: first the arcs and `w`, then the lookup, then the rest. As in `baseline`,
    // the exponents are clamped (a NaN exponent becomes 0 here and is answered below) and
    // a NaN `cos α` (a NaN axis) makes everything NaN; `sin α` is never NaN.
    let (e1c, e2c) = (e1.max(0.0), e2.max(0.0));
    let arcs = arcs(e1c, e2c, c, s);
    let g = match fit {
        ProductFit::ExactIntegral | ProductFit::ExactIntegralCurvature => {
            let (u1, u2) = exponent_coords(e1, e2);
            table.correction(u1, u2, angle_coord(e1c, e2c, &arcs))
        }
        ProductFit::SphericalGaussian => 0.0,
    };
    let nan = f32::NAN;
    let ((peak_dir, ln_peak, arc_curvature), parts) = if c.is_nan() {
        let parts = BaselineParts {
            ln_sines: nan,
            quad: nan,
            n15: nan,
            hq: nan,
        };
        (((nan, nan), nan, nan), Some(parts))
    } else {
        (peak(e1c, e2c, c, s, &arcs), baseline_parts(e1c, e2c, &arcs))
    };
    let (ct, st) = peak_dir;
    let axis = a.axis() * ct + w * st;
    let scale = a.scale() * b.scale();
    if e1.is_nan() || e2.is_nan() {
        // A NaN exponent is not silently taken as 0 (the clamps above would).
        return result_lobe(axis, f32::NAN, f32::NAN);
    }
    // s1·s2·q, without `∞·0` when s1·s2 overflows but the product does not.
    let times_scale = |q: f32| {
        if scale.is_finite() || scale.is_nan() {
            scale * q
        } else {
            a.scale() * (b.scale() * q)
        }
    };
    // No baseline (α = π, or `hq` overflowed: `ln B = −∞`): a zero-scale lobe.
    let zero = || result_lobe(axis, 0.0 * scale, 0.0);
    // 2π·peak/(e_r + 1) = I, and the peak: both exponentials in one call.
    let peak_matched = |ln_i: f32| {
        let ex = math::exp_x4(Vec4::new(LN_TWO_PI + ln_peak - ln_i, ln_peak, 0.0, 0.0));
        result_lobe(axis, times_scale(ex.y), (ex.x - 1.0).max(0.0))
    };
    match (fit, parts) {
        (ProductFit::SphericalGaussian, _) => {
            let ln_i = ln_sg_integral(e1, e2, c, s);
            if ln_i == f32::NEG_INFINITY {
                return zero();
            }
            peak_matched(ln_i)
        }
        (_, None) => zero(),
        (ProductFit::ExactIntegral, Some(p)) => {
            // 2π·peak/(e_r + 1) = I = B·e^g with B = e^(ln_sines + quad)·2π/√((n + 1.5)·hq):
            // e_r + 1 = e^(ln p − ln_sines)·√(n + 1.5)·√hq·e^(−(quad + g)). The first
            // exponential needs only the arcs, so it is computed while the rest of the
            // baseline and the table are; a root replaces `ln B`'s logarithm; `quad + g` is
            // small (test `quad_and_g_stay_small`), its exponential a polynomial. Where the first exponent leaves [−80, 80] (or is
            // NaN) the whole `ln I` takes over.
            let arg = ln_peak - p.ln_sines;
            if arg.is_nan() || arg.abs() >= 80.0 {
                return peak_matched(p.ln_b() + g);
            }
            let ex = math::exp_x4(Vec4::new(arg, ln_peak, 0.0, 0.0));
            let roots = Vec4::new(p.n15, p.hq, 0.0, 0.0).sqrt();
            let e_r = ex.x * (roots.x * roots.y) * exp_neg_small(p.quad + g) - 1.0;
            result_lobe(axis, times_scale(ex.y), e_r.max(0.0))
        }
        (ProductFit::ExactIntegralCurvature, Some(p)) => {
            let ln_i = p.ln_b() + g;
            let e_r = math::sqrtf((e1c + e2c) * arc_curvature);
            // A peak on an e < 1 lobe's horizon has no curvature to match (the lobe has a
            // kink there): the peak-matched exponent takes over.
            if !e_r.is_finite() {
                return peak_matched(ln_i);
            }
            // p·2π/(e_r + 1) = I, with p = exp(ln I + ln((e_r + 1)/2π)) so that a tiny
            // `I` with a large `e_r` does not lose `p` to underflow.
            let p = ln_i + math::logf((e_r + 1.0) * (1.0 / TWO_PI));
            let q = math::exp_x4(Vec4::splat(p)).x;
            result_lobe(axis, times_scale(q), e_r)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `atan2_pos` against the `f64` `atan2` over every magnitude and both signs of `x`
    /// (within `4e-7` relative where the result is a normal `f32`: Cephes' `1.9e-7` plus the
    /// reduction's roundings; within one `f32::MIN_POSITIVE` below that), exact at
    /// the axes and signed zeros, NaN for NaN.
    #[test]
    fn atan2_pos_against_f64() {
        let mut worst = 0.0f64;
        let mut y = 1e-30f32;
        while y < 1e30 {
            let mut x = 1e-30f32;
            while x < 1e30 {
                for xs in [x, -x] {
                    // Lane k holds the case; the other lanes hold others.
                    let lanes = atan2_pos(Vec4::new(0.25, y, 0.5, y), Vec4::new(7.0, xs, -3.0, xs));
                    let got = lanes.y as f64;
                    let want = (y as f64).atan2(xs as f64);
                    // Results below f32's normal range are subnormal or 0 in f32.
                    let err = if want >= f32::MIN_POSITIVE as f64 {
                        (got - want).abs() / want
                    } else {
                        (got - want).abs() / f32::MIN_POSITIVE as f64
                    };
                    worst = worst.max(err);
                }
                x *= 1.37;
            }
            y *= 1.41;
        }
        assert!(worst < 4e-7, "{worst}");
        let at = |y: f32, x: f32| {
            let v = atan2_pos(Vec4::new(y, 1.0, 2.0, y), Vec4::new(x, 3.0, x, x)).to_array();
            assert_eq!(v[0].to_bits(), v[3].to_bits());
            v[0]
        };
        assert_eq!(at(0.0, 1.0), 0.0);
        assert_eq!(at(0.0, -1.0), crate::PI);
        assert_eq!(at(0.0, -0.0), crate::PI);
        assert_eq!(at(1.0, 0.0), core::f32::consts::FRAC_PI_2);
        assert_eq!(at(1.0, -0.0), core::f32::consts::FRAC_PI_2);
        assert!(at(f32::NAN, 1.0).is_nan() && at(1.0, f32::NAN).is_nan());
        // Every lane computes the same function.
        let ys = [0.3f32, 2.0, 1e-20, 0.0];
        let xs = [-0.5f32, 1e-3, 4.0, -2.0];
        let v = atan2_pos(Vec4::from_array(ys), Vec4::from_array(xs)).to_array();
        for k in 0..4 {
            let alone = atan2_pos(Vec4::splat(ys[k]), Vec4::splat(xs[k])).x;
            assert_eq!(v[k].to_bits(), alone.to_bits(), "lane {k}");
        }
    }

    /// The arcs' logarithms keep their relative precision from `θ = 1e-6` (where `e·ln cos t*`
    /// at `e = 1e5` needs it) to just below `π/2`, in all four lanes: equal exponents put the
    /// product's peak at `t* = α/2` (lanes 2–3, `ln cos(α/2)`) and the horizons' peak at
    /// `x = y = (π − α)/2` (lanes 0–1, `ln sin x = ln cos(α/2)` too), each within `1e-6` of
    /// the `f64` `ln cos(α/2)` of the `f32` `(cos α, sin α)` pair the kernel is given.
    #[test]
    fn arcs_logarithms_keep_relative_precision() {
        let mut t = 1e-6f64;
        while t < 1.57 {
            let (c, s) = ((2.0 * t).cos() as f32, (2.0 * t).sin() as f32);
            let half = (s as f64).atan2(c as f64) / 2.0;
            // ln cos h = ½·ln(1 − sin²h), without the cancellation of cos h near 1.
            let want = 0.5 * (-half.sin().powi(2)).ln_1p();
            for e in [0.5f32, 3.0, 1e5] {
                let got = arcs(e, e, c, s).ln.to_array();
                for (k, g) in got.iter().enumerate() {
                    let g = *g as f64;
                    assert!(
                        (g - want).abs() <= 1e-6 * want.abs(),
                        "t {t}, e {e}, lane {k}: {g} vs {want}"
                    );
                }
            }
            t *= 1.01;
        }
    }

    /// `exp_neg_small` within 1 ulp of the `f64` `e^(−g)` on a fine grid over `[−1/4, 1/4]`
    /// (its polynomial) and beyond (its fallback), NaN for NaN.
    #[test]
    fn exp_neg_small_against_f64() {
        let mut worst = 0.0f64;
        let mut g = -1.0f32;
        while g <= 1.0 {
            let want = (-(g as f64)).exp();
            let w = want as f32;
            let ulp = (f32::from_bits(w.to_bits() + 1) - w) as f64;
            worst = worst.max((exp_neg_small(g) as f64 - want).abs() / ulp);
            g += 1.0 / 65536.0;
        }
        assert!(worst <= 1.0, "{worst}");
        assert!(exp_neg_small(f32::NAN).is_nan());
    }

    /// What the root form's fast path relies on: every value of the built-in table lies in
    /// `[0, 0.19]`, and the baseline's `quad` stays below `0.01` over random pairs (the
    /// criterion bench's distribution: exponents 0 one time in ten, else log-uniform in
    /// `[1e-3, 1e5]`, angles uniform in `[0, π)`), so `quad + g` takes `exp_neg_small`'s
    /// polynomial.
    #[test]
    fn quad_and_g_stay_small() {
        let t = ProductTable::builtin();
        let n = t.bytes() / 4;
        let (mut lo, mut hi) = (f32::MAX, f32::MIN);
        for idx in (0..n - 1).step_by(2) {
            let (a, b) = t.pair(idx);
            (lo, hi) = (lo.min(a.min(b)), hi.max(a.max(b)));
        }
        assert!(lo >= 0.0 && hi <= 0.19, "{lo} {hi}");
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut unit = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut worst = 0.0f32;
        for _ in 0..100_000 {
            let mut exponent = || {
                if unit() < 0.1 {
                    0.0
                } else {
                    1e-3 * math::powf(1e8, unit())
                }
            };
            let (e1, e2) = (exponent(), exponent());
            let alpha = core::f32::consts::PI * unit();
            let (c, s) = (math::cosf(alpha), math::sinf(alpha));
            if let Some(p) = baseline_parts(e1, e2, &arcs(e1, e2, c, s)) {
                worst = worst.max(p.quad);
            }
        }
        assert!(worst < 0.01, "{worst}");
    }

    /// `pow2_range` on every binade from the smallest subnormal to `f32::MAX`: `k` is a power
    /// of two, `k·n` lies in `[2⁻⁴⁹, 2⁴⁴]` and is exact (`(k·n)/k = n`), `(k·n)²` is
    /// normal, and `k = 1` on `[2⁻²⁰, 2²⁰]`.
    #[test]
    fn pow2_range_keeps_the_square_normal() {
        let mut n = f32::from_bits(1);
        while n.is_finite() {
            for m in [
                n,
                n * 1.5,
                f32::from_bits(n.to_bits() | 0x007f_ffff).min(f32::MAX),
            ] {
                let k = pow2_range(Vec4::splat(m)).x;
                assert_eq!(k.to_bits() & 0x007f_ffff, 0, "{m}: k = {k}");
                let kn = k * m;
                assert!((2f32.powi(-49)..=2f32.powi(44)).contains(&kn), "{m}: {kn}");
                assert_eq!(kn / k, m, "{m}");
                assert!((kn * kn).is_normal(), "{m}");
                if (2f32.powi(-20)..=2f32.powi(20)).contains(&m) {
                    assert_eq!(k, 1.0, "{m}");
                }
            }
            n *= 2.0;
        }
    }
}
