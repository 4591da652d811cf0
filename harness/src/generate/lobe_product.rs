//! The lobe-product table: `g = ln I − ln B` (see `steradian_core::lobe::product`) at
//! `exponents × exponents × angles` nodes, symmetric in the exponents and stored once as a
//! packed triangle. `I` is the exact f64 product integral
//! (`reference::product::ln_product_integral`), `B` the kernel's closed-form baseline
//! evaluated here in f64 with the same formulas (the pure-Rust `libm`, so the bytes are the
//! same on every machine). The node angle `α_k` is the root of `w(α) = k/(angles − 1)`,
//! found by bisection (`w` is monotone in `α`).

use std::f64::consts::{PI, TAU};

use steradian_core::lobe::product::{
    ANGLE_LOG_DROP, EXPONENT_EPS, EXPONENT_MAX, TABLE_ANGLES, TABLE_EXPONENTS, TABLE_NAME,
};
use steradian_core::table::{HEADER_LEN, Spec, encode_into};

use crate::reference::product::ln_product_integral;

/// `ln(1 + E/ε)`.
fn ln_span() -> f64 {
    libm::log1p(EXPONENT_MAX as f64 / EXPONENT_EPS as f64)
}

/// The exponent at table coordinate `u` (the inverse of `product::exponent_coord`),
/// rounded to f32 so that the kernel sees exactly this node.
pub fn node_exponent(i: usize, n: usize) -> f32 {
    if i == 0 {
        return 0.0;
    }
    let u = i as f64 / (n - 1) as f64;
    (EXPONENT_EPS as f64 * libm::expm1(u * ln_span())) as f32
}

/// `(1 − cos φ, 1 + cos φ)` of `φ = atan2(sn, cs)`, without cancellation.
fn one_pm_cos(sn: f64, cs: f64) -> (f64, f64) {
    let h = libm::hypot(sn, cs);
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

fn peak_pair(s: f64, c: f64, r: f64, omr2: f64, cy: f64) -> (f64, f64) {
    let rc = -r * c;
    let sn = if rc >= 0.0 {
        let den = cy + rc;
        if den > 0.0 { s * omr2 / den } else { 0.0 }
    } else {
        s * (cy - rc)
    };
    (sn, c * cy - r * s * s)
}

fn ln_cos_half(omc: f64, opc: f64) -> f64 {
    if omc < opc {
        0.5 * libm::log1p(-0.5 * omc)
    } else {
        0.5 * libm::log(0.5 * opc)
    }
}

/// `(ln B, w)` of the kernel's baseline in f64 (`steradian_core::lobe::product::baseline`).
pub fn baseline(e1: f64, e2: f64, alpha: f64) -> (f64, f64) {
    let (s, c) = (libm::sin(alpha), libm::cos(alpha));
    let (f1, f2) = (e1 + 1.0, e2 + 1.0);
    let n = f1 + f2;
    let (r, omr2) = ((f2 - f1) / n, 4.0 * (f1 / n) * (f2 / n));
    let cy = libm::sqrt(c * c + omr2 * s * s);
    let (snx, csx) = peak_pair(s, -c, -r, omr2, cy);
    let (sny, csy) = peak_pair(s, -c, r, omr2, cy);
    let x = 0.5 * libm::atan2(snx, csx);
    let y = 0.5 * libm::atan2(sny, csy);
    if !(x > 0.0 && y > 0.0) {
        return (f64::NEG_INFINITY, 1.0);
    }
    let (omcx, opcx) = one_pm_cos(snx, csx);
    let (omcy, opcy) = one_pm_cos(sny, csy);
    let ln_sin_x = ln_cos_half(opcx, omcx);
    let ln_sin_y = ln_cos_half(opcy, omcy);
    let w = libm::sqrt((-(f1 * ln_sin_x + f2 * ln_sin_y) / ANGLE_LOG_DROP as f64).clamp(0.0, 1.0));
    let l = x + y;
    let m = x * y / l;
    let (cot_x, cot_y) = (libm::sqrt(opcx / omcx), libm::sqrt(opcy / omcy));
    let d = (e1 * cot_x + 1.0 / x) - (e2 * cot_y + 1.0 / y);
    let phi0 = e1 * ln_sin_x + e2 * ln_sin_y + libm::log(m);
    let phi1 = d * m;
    let ap = e1 * 2.0 / omcx + 1.0 / (x * x);
    let bp = e2 * 2.0 / omcy + 1.0 / (y * y);
    let h = (m * m * (ap + bp) - d * (y - x) * m / l).max(1e-30);
    let ln_k = 0.5 * libm::log(TAU / (e1 + e2 + 1.5));
    (
        ln_k + phi0 + phi1 * phi1 / (2.0 * h) + 0.5 * libm::log(TAU / h),
        w,
    )
}

/// The angle where the baseline's `w` reaches `target` (bisection; `w` increases with `α`).
pub fn node_angle(e1: f64, e2: f64, target: f64) -> f64 {
    if target <= 0.0 {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0f64, PI);
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if baseline(e1, e2, mid).1 < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The `g` values of a table with `exponents × angles` samples (packed triangle, see
/// `steradian_core::lobe::product::ProductTable`). Calls `progress` after each exponent pair.
pub fn values(exponents: usize, angles: usize, progress: &dyn Fn(usize, usize)) -> Vec<f32> {
    let pairs = exponents * (exponents + 1) / 2;
    let mut out = vec![0f32; pairs * angles];
    let mut done = 0;
    for j in 0..exponents {
        for i in 0..=j {
            let (e1, e2) = (
                node_exponent(i, exponents) as f64,
                node_exponent(j, exponents) as f64,
            );
            let row = &mut out[(j * (j + 1) / 2 + i) * angles..][..angles];
            for (k, g) in row.iter_mut().enumerate() {
                let alpha = node_angle(e1, e2, k as f64 / (angles - 1) as f64);
                let exact = ln_product_integral(e1, e2, alpha);
                let (ln_b, _) = baseline(e1, e2, alpha);
                let v = exact - ln_b;
                *g = if v.is_finite() { v as f32 } else { 0.0 };
            }
            done += 1;
            progress(done, pairs);
        }
    }
    out
}

/// A complete table file of `exponents × angles` samples (the built-in one is
/// `TABLE_EXPONENTS × TABLE_ANGLES`; the report generates smaller ones).
pub fn encode(exponents: usize, angles: usize) -> Vec<u8> {
    let values = values(exponents, angles, &|_, _| {});
    let spec = Spec {
        name: TABLE_NAME,
        rank: 2,
        channels: 1,
        dims: [
            (exponents * (exponents + 1) / 2) as u32,
            angles as u32,
            1,
            1,
        ],
        lo: [0.0, 0.0, 0.0, 0.0],
        hi: [EXPONENT_MAX as f64, 1.0, 1.0, 1.0],
    };
    let mut out = vec![0u8; HEADER_LEN + 4 * values.len()];
    encode_into(&spec, &values, &mut out).expect("sizes agree by construction");
    out
}

/// The complete built-in table file.
pub fn generate() -> Vec<u8> {
    encode(TABLE_EXPONENTS, TABLE_ANGLES)
}
