//! Lobe products, SIMD (`steradian_simd::lobe::product`) vs scalar
//! (`steradian_core::lobe::product::product_with`) on arbitrary lobes from raw bytes: every field
//! an arbitrary `f32` (NaN, ±∞, ±0, subnormals, huge values), or, per lane when a flag bit
//! says so, the exponent folded into the table's domain `[0, 1e5]` so that the vector path
//! (not only the scalar fallback) sees most inputs. Checked, for `product_x8` and for
//! `product_slices` (16 lanes on AVX-512 builds):
//!
//! - never a panic;
//! - the axis bit-identical to the scalar kernel's (NaN-ness equal);
//! - scale, exponent and integral within the module's documented bounds
//!   (`SCALE_REL_TOL`, `EXPONENT_REL_TOL`, `INTEGRAL_REL_TOL` per unit of
//!   `1 + |ln p| + |ln I|`, `UNDERFLOW_ABS` where the peak underflows), or the same
//!   special value (NaN-ness and infinities equal, one side allowed to overflow to ±∞
//!   within the tolerance of `f32::MAX`);
//! - never a negative exponent, for any input; never a negative scale when both input
//!   scales are `≥ 0` and not NaN (`+0·∞` is NaN, which is not negative). NaN and ±∞ inputs
//!   give whatever the scalar kernel gives, bit for bit: those lanes are computed by it
//!   (its documented rules: scales multiply, so a NaN scale gives a NaN scale; a NaN
//!   exponent is treated as 0 by its `max(0)` clamps; a non-finite axis component gives a
//!   NaN axis).

use steradian_core::Vec3;
use steradian_core::lobe::CosineLobe;
use steradian_core::lobe::product::{self, ProductFit, ProductTable};
use steradian_simd::lobe::product::{
    EXPONENT_REL_TOL, INTEGRAL_REL_TOL, SCALE_REL_TOL, UNDERFLOW_ABS, product_slices, product_x8,
};
use steradian_simd::{LobeX8, Vec3x8, f32x8};

fn same(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

/// `[ax, ay, az, s, e]` of lobe 1 then lobe 2.
type Raw = [f32; 10];

fn lobes(r: &Raw) -> (CosineLobe, CosineLobe) {
    (
        CosineLobe::saturating(Vec3::new(r[0], r[1], r[2]), r[3], r[4]),
        CosineLobe::saturating(Vec3::new(r[5], r[6], r[7]), r[8], r[9]),
    )
}

/// Checks one lane's output `[ax, ay, az, s, e]` against the scalar kernel.
fn check_lane(fit: ProductFit, r: &Raw, got: [f32; 5]) {
    let (a, b) = lobes(r);
    let want = product::product_with(&ProductTable::builtin(), fit, &a, &b);
    let wa = want.axis();
    let ctx = || format!("{fit:?} in={r:?} got={got:?} want={want:?}");
    for (g, w) in got[..3].iter().zip([wa.x, wa.y, wa.z]) {
        assert!(same(*g, w), "axis: {}", ctx());
    }
    let (gs, ge, ws, we) = (got[3], got[4], want.scale(), want.exponent());
    assert!(ge.is_nan() || ge >= 0.0, "negative exponent: {}", ctx());
    if r[3] >= 0.0 && r[8] >= 0.0 {
        assert!(gs.is_nan() || gs >= 0.0, "negative scale: {}", ctx());
    }
    // The logarithms the outputs are exponentials of: ln p (closed form) and ln I.
    let c = a.axis().dot(b.axis()).clamp(-1.0, 1.0);
    let s = (b.axis() - a.axis() * c).length().min(1.0);
    let ln_p = product::baseline(a.exponent(), b.exponent(), c, s).ln_peak as f64;
    let ln_p = if ln_p.is_finite() { ln_p } else { 0.0 };
    let s12 = a.scale() as f64 * b.scale() as f64;
    let ln_scale = if ws != 0.0 && ws.is_finite() && s12 != 0.0 && s12.is_finite() {
        (ws as f64 / s12).abs().ln()
    } else {
        ln_p
    };
    let ln_i = if we.is_finite() {
        ln_scale + (std::f64::consts::TAU / (1.0 + we as f64)).ln()
    } else {
        ln_scale
    };
    let l = 1.0 + ln_p.abs() + ln_i.abs();
    let l = if l.is_finite() { l } else { 0.0 };
    let sub = UNDERFLOW_ABS as f64
        * (1.0 + s12.abs().min(f32::MAX as f64))
        * if fit == ProductFit::ExactIntegralCurvature && we.is_finite() {
            ((1.0 + we as f64) / std::f64::consts::TAU).max(1.0)
        } else {
            1.0
        };
    let pair = |g: f32, w: f32, tol: f32| -> bool {
        if g.is_finite() && w.is_finite() {
            return true;
        }
        let (inf, fin) = if g.is_finite() { (w, g) } else { (g, w) };
        assert!(
            same(g, w)
                || (inf.is_infinite()
                    && fin.signum() == inf.signum()
                    && fin.abs() as f64 >= f32::MAX as f64 * (1.0 - 2.0 * tol as f64 * l)),
            "non-finite mismatch: {}",
            ctx()
        );
        false
    };
    let scale_ok = pair(gs, ws, SCALE_REL_TOL);
    let exp_ok = pair(ge, we, EXPONENT_REL_TOL);
    if scale_ok {
        let d = ((gs as f64 - ws as f64).abs() - sub).max(0.0);
        assert!(
            d <= SCALE_REL_TOL as f64 * l * (ws as f64).abs(),
            "scale: {}",
            ctx()
        );
    }
    if exp_ok {
        let d = (ge as f64 - we as f64).abs();
        assert!(
            d <= EXPONENT_REL_TOL as f64 * l * (1.0 + we as f64),
            "exponent: {}",
            ctx()
        );
    }
    if scale_ok && exp_ok {
        let (gi, wi) = (gs as f64 / (1.0 + ge as f64), ws as f64 / (1.0 + we as f64));
        let d = ((gi - wi).abs() - sub / (1.0 + we as f64)).max(0.0);
        assert!(
            d <= INTEGRAL_REL_TOL as f64 * l * wi.abs(),
            "integral: {}",
            ctx()
        );
    }
}

/// The target's checks on one input.
pub fn check(data: &[u8]) {
    let (Some(&sel), Some(&flags)) = (data.first(), data.get(1)) else {
        return;
    };
    let fit = match sel % 3 {
        0 => ProductFit::ExactIntegral,
        1 => ProductFit::ExactIntegralCurvature,
        _ => ProductFit::SphericalGaussian,
    };
    let body = &data[2..];
    let n = body.len() / 40;
    let rows: Vec<Raw> = (0..n)
        .map(|i| {
            let mut r: Raw = core::array::from_fn(|f| {
                let at = i * 40 + f * 4;
                f32::from_le_bytes([body[at], body[at + 1], body[at + 2], body[at + 3]])
            });
            if flags >> (i % 8) & 1 == 1 {
                // Fold the exponents into [0, 1e5] (bit patterns are mostly huge or tiny).
                for f in [4, 9] {
                    let e = r[f].abs();
                    r[f] = if e.is_finite() { e % 1.0e5 } else { 0.0 };
                }
            }
            r
        })
        .collect();
    let table = ProductTable::builtin();

    // 8 lanes at a time (the last batch padded with copies of row 0's fields).
    for chunk in rows.chunks(8) {
        let col = |f: usize| {
            f32x8::from(core::array::from_fn(|k| {
                chunk.get(k).unwrap_or(&chunk[0])[f]
            }))
        };
        let a = LobeX8::new(Vec3x8::new(col(0), col(1), col(2)), col(3), col(4));
        let b = LobeX8::new(Vec3x8::new(col(5), col(6), col(7)), col(8), col(9));
        let p = product_x8(&table, fit, &a, &b);
        for (k, r) in chunk.iter().enumerate() {
            let ax = p.axis.lane(k);
            check_lane(
                fit,
                r,
                [
                    ax.x,
                    ax.y,
                    ax.z,
                    p.scale.as_array()[k],
                    p.exponent.as_array()[k],
                ],
            );
        }
    }

    // The slice function (16 lanes on AVX-512), with its padded tail.
    let cols: Vec<Vec<f32>> = (0..10)
        .map(|f| rows.iter().map(|r| r[f]).collect())
        .collect();
    let mut o: [Vec<f32>; 5] = core::array::from_fn(|_| vec![0.0; n]);
    let [ox, oy, oz, os, oe] = &mut o;
    product_slices(
        &table,
        fit,
        [&cols[0], &cols[1], &cols[2]],
        &cols[3],
        &cols[4],
        [&cols[5], &cols[6], &cols[7]],
        &cols[8],
        &cols[9],
        [ox, oy, oz],
        os,
        oe,
    );
    for (i, r) in rows.iter().enumerate() {
        check_lane(fit, r, core::array::from_fn(|c| o[c][i]));
    }
}
