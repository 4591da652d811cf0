//! The one math shim: every float function the kernels use goes through here, so no other
//! module needs a `cfg`. With the `std` feature the standard library is used, otherwise (or with
//! `force-libm`) the `libm` crate. Add a function with one line in the `shim!` list below.
//!
//! Below the shim, two functions of four lanes for kernels that take several logarithms or
//! exponentials side by side ([`ln_x4`], [`exp_x4`], used by the lobe product): polynomial,
//! branch-free, the same bits with every feature set, each within 1 ulp (tested here).

macro_rules! shim {
    ($( $name:ident ( $t:ty $(, $arg:ident)* ) => $method:ident, $libm:ident ; )*) => {
        #[cfg(all(feature = "std", not(feature = "force-libm")))]
        mod imp {
            $(
                #[doc = concat!("`", stringify!($t), "::", stringify!($method), "` of the standard library.")]
                #[inline(always)]
                pub fn $name(x: $t $(, $arg: $t)*) -> $t {
                    x.$method($($arg),*)
                }
            )*
        }

        #[cfg(any(all(not(feature = "std"), feature = "libm"), feature = "force-libm"))]
        mod imp {
            $(
                #[doc = concat!("`libm::", stringify!($libm), "`.")]
                #[inline(always)]
                pub fn $name(x: $t $(, $arg: $t)*) -> $t {
                    libm::$libm(x $(, $arg)*)
                }
            )*
        }

        #[cfg(not(any(feature = "std", feature = "libm")))]
        mod imp {
            // The crate root emits a `compile_error!`; these keep the rest of the build quiet.
            $(
                #[allow(dead_code)]
                pub fn $name(x: $t $(, $arg: $t)*) -> $t {
                    $( let _ = $arg; )*
                    x
                }
            )*
        }
    };
}

shim! {
    sqrtf(f32) => sqrt, sqrtf;
    expf(f32) => exp, expf;
    expm1f(f32) => exp_m1, expm1f;
    logf(f32) => ln, logf;
    log1pf(f32) => ln_1p, log1pf;
    powf(f32, y) => powf, powf;
    sinf(f32) => sin, sinf;
    cosf(f32) => cos, cosf; // used by `brdf_sat` (feature `alloc`) only
    asinf(f32) => asin, asinf;
    acosf(f32) => acos, acosf;
    atan2f(f32, x2) => atan2, atan2f;
    ceilf(f32) => ceil, ceilf;
    floorf(f32) => floor, floorf;
    // f64 for table builders, statistics and the environment decomposition, not hot paths.
    sqrt64(f64) => sqrt, sqrt;
    cbrt64(f64) => cbrt, cbrt;
    sin64(f64) => sin, sin;
    cos64(f64) => cos, cos;
    expm1_64(f64) => exp_m1, expm1;
    log1p_64(f64) => ln_1p, log1p;
    atan2_64(f64, x2) => atan2, atan2;
    floor64(f64) => floor, floor;
}

pub use imp::*;

/// `ln` of four lanes at once, for kernels that take several logarithms side by side: Cephes'
/// `logf` (Moshier 1989) — `x = m·2^k` with `m ∈ [√½, √2)`, `ln x = k·ln 2 + f − f²/2 +
/// f³·P(f)` with `f = m − 1` exact and `P` its degree-8 minimax polynomial, `ln 2` split in
/// two parts so that `k·ln 2` adds no rounding of its own; `P` by Estrin's scheme. No
/// branch, no table, no call:
/// the same instructions on every lane, and the same bits on every platform (no
/// `std`/`libm` difference). Within 1 ulp of the correctly rounded `ln` over every
/// positive `f32`, subnormals included (test `ln_x4_within_one_ulp`); near `x = 1` its
/// relative error stays at the ulp level because `f` is exact. `ln 0 = −∞`, `ln ∞ = ∞`,
/// NaN for NaN and negative lanes.
#[inline(always)]
pub fn ln_x4(x: glam::Vec4) -> glam::Vec4 {
    use glam::Vec4;
    // Subnormals scaled into the normal range (k takes the 24 back).
    let tiny = x.cmplt(Vec4::splat(f32::MIN_POSITIVE));
    let xs = Vec4::select(tiny, x * 16_777_216.0, x);
    let bits = xs.to_array().map(f32::to_bits);
    // m ∈ [0.5, 1) with its exponent k: x = m·2^k.
    let m = Vec4::from_array(bits.map(|b| f32::from_bits((b & 0x807f_ffff) | 0x3f00_0000)));
    let k = Vec4::from_array(bits.map(|b| ((b >> 23) & 0xff) as i32 as f32))
        - Vec4::select(tiny, Vec4::splat(126.0 + 24.0), Vec4::splat(126.0));
    // m < √½: use 2m − 1 and k − 1 (so that f ∈ [√½ − 1, √2 − 1)).
    let low = m.cmplt(Vec4::splat(core::f32::consts::FRAC_1_SQRT_2));
    let f = Vec4::select(low, m + m, m) - Vec4::ONE;
    let k = Vec4::select(low, k - Vec4::ONE, k);
    // P(f) = Σ c_i·f^i by Estrin's scheme (pairs, then pairs of pairs: a dependency chain
    // of four multiply-adds instead of Horner's eight).
    let z = f * f;
    let z4 = z * z;
    let p01 = 3.333_333e-1 + f * -2.499_999_4e-1;
    let p23 = 2.000_071_4e-1 + f * -1.666_805_8e-1;
    let p45 = 1.424_932_3e-1 + f * -1.242_014_1e-1;
    let p67 = 1.167_699_9e-1 + f * -1.151_461e-1;
    let p = (p01 + p23 * z) + (p45 + p67 * z) * z4 + 7.037_683_6e-2 * (z4 * z4);
    // ln 2 = 0.693359375 (exact in 10 bits) − 2.12194440e−4.
    let y = f * z * p + k * -2.121_944_4e-4 - 0.5 * z;
    let r = f + y + k * 0.693_359_4;
    let r = Vec4::select(x.cmpeq(Vec4::ZERO), Vec4::NEG_INFINITY, r);
    let r = Vec4::select(x.cmpeq(Vec4::INFINITY), Vec4::INFINITY, r);
    // NaN and negative lanes (comparisons with NaN are false).
    Vec4::select(x.cmpge(Vec4::ZERO), r, Vec4::NAN)
}

/// `e^y` of four lanes: Cephes' `expf` (Moshier 1989) — `y = k·ln 2 + r` with `k` the
/// nearest integer to `y/ln 2` and `ln 2` in two parts (the first exact in 10 bits, so `k·ln
/// 2` adds no rounding), `e^r = 1 + r + r²·P(r)` on `|r| ≤ ln 2/2` with `P` its degree-5
/// minimax polynomial (Estrin's scheme), times `2^k` built from its bits in two factors
/// (so that results in the subnormal range round once). No branch, no call. Within 1 ulp
/// of the correctly rounded `e^y` where that is a normal `f32`, within one subnormal step
/// below (test `exp_x4_within_one_ulp`); `0` below `−103.98`, `∞` above `88.73` (where
/// `e^y` rounds to them), NaN for NaN.
#[inline(always)]
pub fn exp_x4(y: glam::Vec4) -> glam::Vec4 {
    use glam::Vec4;
    let low = y.cmplt(Vec4::splat(-104.0));
    let high = y.cmpgt(Vec4::splat(88.722_84));
    let yc = Vec4::select(low | high | y.is_nan_mask(), Vec4::ZERO, y);
    // k = y/ln 2 rounded to the nearest integer by adding 1.5·2²³ (the sum's low mantissa
    // bits are then k + 2²², read back as an integer below).
    const SHIFTER: f32 = 12_582_912.0;
    let t = yc * core::f32::consts::LOG2_E + SHIFTER;
    let k = t - SHIFTER;
    let r = yc - k * 0.693_359_4 - k * -2.121_944_4e-4;
    let z = r * r;
    let p = (0.5 + r * 1.666_666_5e-1)
        + (4.166_579_6e-2 + r * 8.333_452e-3) * z
        + (1.398_199_9e-3 + r * 1.987_569_1e-4) * (z * z);
    let e = p * z + r + 1.0;
    // 2^k = 2^k1·2^k2 with k1 = ⌊k/2⌋: both factors normal for k ∈ [−150, 128].
    let ki = t
        .to_array()
        .map(|t| t.to_bits() as i32 - SHIFTER.to_bits() as i32);
    let k1 = ki.map(|k| k >> 1);
    let pow2 = |k: [i32; 4]| Vec4::from_array(k.map(|k| f32::from_bits(((k + 127) << 23) as u32)));
    let k2 = [0, 1, 2, 3].map(|i| ki[i] - k1[i]);
    let v = e * pow2(k1) * pow2(k2);
    let v = Vec4::select(low, Vec4::ZERO, v);
    let v = Vec4::select(high, Vec4::INFINITY, v);
    Vec4::select(y.is_nan_mask(), Vec4::NAN, v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    /// Distance in ulps between `got` and the `f64` `want` rounded to `f32` (the ulp of the
    /// rounded value; `f32` bit patterns are ordered like the values for positive floats).
    fn ulps(got: f32, want: f64) -> f64 {
        let w = want as f32;
        let ulp = (f32::from_bits(w.abs().to_bits() + 1) - w.abs()) as f64;
        (got as f64 - want).abs() / ulp
    }

    /// `ln_x4` against the `f64` `ln` on every 61st `f32` bit pattern from the smallest
    /// subnormal to the largest finite value, in every lane, plus the values next to 1:
    /// within 1 ulp everywhere (the measured worst case is printed).
    #[test]
    fn ln_x4_within_one_ulp() {
        let mut worst = 0.0f64;
        let mut b = 1u32;
        while b < f32::MAX.to_bits() {
            let xs = [b, b + 17, b + 29, b + 43].map(|b| f32::from_bits(b.min(0x7f7f_ffff)));
            let got = ln_x4(Vec4::from_array(xs)).to_array();
            for (x, g) in xs.iter().zip(got) {
                let want = (*x as f64).ln();
                if want != 0.0 {
                    worst = worst.max(ulps(g, want));
                } else {
                    assert_eq!(g, 0.0);
                }
            }
            b += 61;
        }
        // Around 1, where the result is tiny and only an exact f keeps it accurate.
        let mut x = 1.0f32;
        for _ in 0..100_000 {
            for y in [x, 2.0 - x] {
                let g = ln_x4(Vec4::splat(y)).x;
                let want = (y as f64).ln();
                if want != 0.0 {
                    worst = worst.max(ulps(g, want));
                }
            }
            x = f32::from_bits(x.to_bits() + 3);
        }
        std::println!("ln_x4: worst {worst:.3} ulp");
        assert!(worst <= 1.0, "{worst}");
    }

    /// The special values: `ln 0 = −∞` (both zeros), `ln ∞ = ∞`, `ln 1 = 0`, NaN for NaN
    /// and negative lanes, each in every lane position.
    #[test]
    fn ln_x4_special_values() {
        let cases = [
            (0.0f32, f32::NEG_INFINITY),
            (-0.0, f32::NEG_INFINITY),
            (f32::INFINITY, f32::INFINITY),
            (1.0, 0.0),
        ];
        for lane in 0..4 {
            for (x, want) in cases {
                let mut v = [2.0f32; 4];
                v[lane] = x;
                let got = ln_x4(Vec4::from_array(v)).to_array();
                assert_eq!(got[lane], want, "{x} at lane {lane}");
                assert_eq!(got[(lane + 1) % 4], core::f32::consts::LN_2);
            }
            for x in [f32::NAN, -1.0, -f32::MIN_POSITIVE, f32::NEG_INFINITY] {
                let mut v = [2.0f32; 4];
                v[lane] = x;
                assert!(ln_x4(Vec4::from_array(v)).to_array()[lane].is_nan(), "{x}");
            }
        }
    }

    /// `exp_x4` against the `f64` `exp` on a fine grid over `[−105, 90]` in every lane:
    /// within 1 ulp where the result is a normal `f32`, within one subnormal step below
    /// (the measured worst case is printed); the cut-offs where `e^y` rounds to 0 and ∞.
    #[test]
    fn exp_x4_within_one_ulp() {
        let mut worst = 0.0f64;
        let mut y = -105.0f32;
        while y < 90.0 {
            let ys = [y, y + 1.0 / 3.0, y * 0.999, -y * 0.5];
            let got = exp_x4(Vec4::from_array(ys)).to_array();
            for (y, g) in ys.iter().zip(got) {
                let want = (*y as f64).exp();
                let w = want as f32;
                if w.is_infinite() {
                    assert!(
                        g.is_infinite() || (g as f64 - want).abs() <= want * 1.2e-7,
                        "{y}"
                    );
                } else if w == 0.0 {
                    assert!(g as f64 <= 1.5e-45, "{y}: {g}");
                } else if w < f32::MIN_POSITIVE {
                    assert!((g as f64 - want).abs() <= 1.5e-45, "{y}: {g} vs {want}");
                } else {
                    worst = worst.max(ulps(g, want));
                }
            }
            y += 1.0 / 4099.0;
        }
        std::println!("exp_x4: worst {worst:.3} ulp");
        assert!(worst <= 1.0, "{worst}");
        let special = exp_x4(Vec4::new(0.0, f32::NEG_INFINITY, f32::INFINITY, f32::NAN));
        assert_eq!(special.x, 1.0);
        assert_eq!(special.y, 0.0);
        assert_eq!(special.z, f32::INFINITY);
        assert!(special.w.is_nan());
        let cut = exp_x4(Vec4::new(-104.5, 88.75, -103.9, 88.72)).to_array();
        assert_eq!((cut[0], cut[1]), (0.0, f32::INFINITY));
        assert!(cut[2] > 0.0 && cut[3].is_finite());
    }
}
