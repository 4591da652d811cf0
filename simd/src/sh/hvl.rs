//! HVL contributions, four HVLs to one receiver per pass (mirrors
//! `steradian_core::sh::hvl::contribution`): each HVL's geometry by the scalar kernel's own
//! `prepare` (lane by lane), the emission basis and the cap coefficients of the four on
//! `f64` lanes (the twins of `sh::eval_into` and `sh::cap::coefficients_into`,
//! bit-identical), the two dot products on `wide::f32x4` lanes in index order from `+0`,
//! and `P·e·G·s` left to right, so every lane is **bit-identical** to the scalar kernel.
//! The use: a shading point summing hundreds of HVLs (the paper's Table 1).
//!
//! [`contributions_zonal`] (eight HVLs to one zonal receiver per pass, the Lambertian
//! receivers of the `hvl` render) runs every step on lanes instead, the geometry's two
//! arcsines included, and is within [`ZONAL_TOL`] of `contribution_zonal`: 7–10 times the
//! speed of the scalar kernel at 3–9 bands (`steradian report --section sh`, `hvl_ns[]`),
//! where the geometry done lane by lane leaves [`contributions`] 1.2–1.7 times faster.

use steradian_core::grid::check_len;
use steradian_core::sh::hvl::{
    Horizon, Hvl, Prepared, Receiver, ZonalReceiver, contribution_zonal, prepare,
};
use steradian_core::sh::{bands_of, check_shape};
use steradian_core::{Error, Vec3};
use wide::{f32x4, f32x8, f64x8};

use crate::lanes::{narrow, widen};

/// The contributions of four HVLs to the receiver `rx`, lane-wise
/// `steradian_core::sh::hvl::contribution` with the same `emission` (the HVLs' material's
/// `F′`, shared) and `horizon`; `scratch` at least `max(n², n_e²)` entries.
///
/// Errors: coefficient counts that are not squares, a short `scratch`.
pub fn contributions_x4(
    hvls: [&Hvl; 4],
    emission: &[f32],
    rx: &Receiver<'_>,
    horizon: Horizon,
    scratch: &mut [[f32; 4]],
) -> Result<[f32; 4], Error> {
    let n = bands_of(rx.coeffs.len())?;
    let ne = bands_of(emission.len())?;
    check_shape(n.max(ne), scratch.len())?;
    // Each lane's geometry; settled lanes keep their value and run the SH part on a harmless
    // stand-in (+z, a zero cap, zero power), whose result is not used.
    let mut value: [Option<f32>; 4] = [None; 4];
    let (mut emit, mut axis) = ([Vec3::Z; 4], [Vec3::Z; 4]);
    let (mut angle, mut power, mut g) = ([0.0f32; 4], [0.0f32; 4], [0.0f32; 4]);
    for (k, h) in hvls.iter().enumerate() {
        match prepare(h, rx.point, &rx.frame, horizon) {
            Prepared::Value(v) => value[k] = Some(v),
            Prepared::Lit {
                emit_dir,
                cap_axis,
                half_angle,
                power: p,
                g: gk,
            } => {
                (emit[k], axis[k], angle[k], power[k], g[k]) =
                    (emit_dir, cap_axis, half_angle, p, gk);
            }
        }
    }
    if value.iter().all(Option::is_some) {
        return Ok(value.map(|v| v.unwrap_or(0.0)));
    }
    super::eval_x4(emit, ne, scratch)?;
    let mut e = f32x4::ZERO;
    for (a, y) in emission.iter().zip(scratch.iter()) {
        e += f32x4::splat(*a) * f32x4::new(*y);
    }
    super::cap::coefficients_x4(axis, angle, n, scratch)?;
    let mut s = f32x4::ZERO;
    for (f, c) in rx.coeffs.iter().zip(scratch.iter()) {
        s += f32x4::splat(*f) * f32x4::new(*c);
    }
    let r = (f32x4::new(power) * e * f32x4::new(g) * s).to_array();
    Ok(core::array::from_fn(|k| value[k].unwrap_or(r[k])))
}

/// [`contributions_x4`] over a slice of HVLs: `out[j]` is HVL `j`'s contribution to `rx`.
/// Any length (the tail repeats the last HVL and is not written).
///
/// Errors: as [`contributions_x4`]; `out` of another length than `hvls`.
pub fn contributions(
    hvls: &[Hvl],
    emission: &[f32],
    rx: &Receiver<'_>,
    horizon: Horizon,
    scratch: &mut [[f32; 4]],
    out: &mut [f32],
) -> Result<(), Error> {
    check_len("HVL output length", out.len(), hvls.len())?;
    for (group, out) in hvls.chunks(4).zip(out.chunks_mut(4)) {
        let four: [&Hvl; 4] = core::array::from_fn(|k| &group[k.min(group.len() - 1)]);
        let c = contributions_x4(four, emission, rx, horizon, scratch)?;
        out.copy_from_slice(&c[..out.len()]);
    }
    Ok(())
}

/// The bound of [`contributions_zonal`] against the scalar
/// `steradian_core::sh::hvl::contribution_zonal`: `|Δ| ≤ ZONAL_TOL·P·Ē·(G/H)·S̄`, the
/// contribution without its horizon factor `H`, with every SH value and band scale at its
/// largest magnitude: `Ē = Σ_k |F′_k|·y_l(k)`, `S̄ = Σ_l |F_l|·y_l·(1 + l²)·k̄`, where
/// `y_l = √((2l + 1)/4π) ≥ |Y_l^m|` and `k̄ = 4π·max(sin²(a/2), sin²a) ≥ |k_l|`
/// ([`zonal_bound`]). Relative to the terms' scale, not to the value: a basis value's
/// rounding is absolute on its scale (it vanishes at the roots of `P_l`, the magic angle of
/// `l = 2` included), a receiver's `F_l·C_l⁰` may cancel, and at a cap straddling the
/// horizon the smoothstep's argument `t = (a + asin cos θ)/2a` cancels, where an ulp of
/// either arcsine moves `H` by up to `1.5·ulp(π/2)/2a`. The `(1 + l²)` covers the scalar
/// kernel's own rounding of `a` to `f32`: near `a = π/2` (a receiver within an HVL's
/// radius) it moves `cos a` by up to `ulp(π/2)` and `k_l` (which vanishes for even `l ≥ 2`
/// at `π/2` exactly) by up to about `l²·ulp(π/2)·k̄/16`, where this twin, from `sin a`
/// itself, is exact. Plus `(2n + 2)·2⁻¹⁴⁹·(1 + P·Ē·G/H)` where `s` is subnormal (its
/// roundings are then absolute). Measured by the lane tests of `simd/tests/sh.rs`; the `sh`
/// fuzz target checks it on arbitrary positions, radii and coefficients.
pub const ZONAL_TOL: f32 = 2e-6;

/// The bound of [`contributions_zonal`] for one HVL: `ZONAL_TOL·P·Ē·(G/H)·S̄` ([`ZONAL_TOL`])
/// from the scalar kernel's geometry (`steradian_core::sh::hvl::prepare`, `cap_trig`), in
/// `f64`: `Some(bound)` where `prepare` lights the HVL with the smoothstep horizon, `None`
/// where it settles it (both kernels then give the same bits). What the lane tests and the
/// `sh` fuzz target check each lane against.
///
/// Errors: an emission count that is not a square.
pub fn zonal_bound(
    hvl: &Hvl,
    emission: &[f32],
    rx: &ZonalReceiver<'_>,
) -> Result<Option<f64>, Error> {
    use steradian_core::sh::hvl::horizon_smoothstep;
    let Prepared::Lit {
        cap_axis,
        half_angle,
        power,
        g,
        ..
    } = prepare(hvl, rx.point, &rx.frame, Horizon::Smoothstep)
    else {
        return Ok(None);
    };
    // Each basis value at its largest, `|Y_l^m| ≤ √((2l + 1)/4π)` (its rounding is absolute
    // on that scale, not relative to the value, which vanishes at the roots of `P_l`), and
    // each band scale at its largest, `k̄ ≥ |k_l|`.
    let y_max =
        |l: usize| steradian_core::math::sqrt64((2 * l + 1) as f64 / (4.0 * core::f64::consts::PI));
    let ne = steradian_core::sh::bands_of(emission.len())?;
    let e_abs: f64 = (0..ne)
        .map(|l| {
            let band = &emission[l * l..(l + 1) * (l + 1)];
            band.iter().map(|f| f64::from(*f).abs()).sum::<f64>() * y_max(l)
        })
        .sum();
    let n = rx.coeffs.len();
    let [h2, s2, _] = steradian_core::sh::cap::cap_trig(half_angle);
    let k_max = 4.0 * core::f64::consts::PI * h2.max(s2);
    let s_abs: f64 = (0..n)
        .map(|l| {
            let l2 = (l * l) as f64;
            f64::from(rx.coeffs[l]).abs() * y_max(l) * (1.0 + l2) * k_max
        })
        .sum();
    let h = f64::from(horizon_smoothstep(cap_axis.z, half_angle));
    let peg = f64::from(power).abs() * e_abs * (f64::from(g) / h);
    // Where `s` is subnormal its roundings are absolute (at most `2⁻¹⁵⁰` each, two per band),
    // and `P·e·G` scales them.
    let underflow = (2 * n + 2) as f64 * f64::from(f32::from_bits(1)) * (1.0 + peg);
    Ok(Some(f64::from(ZONAL_TOL) * peg * s_abs + underflow))
}

/// `asinf` on eight lanes by musl's (and the `libm` crate's) algorithm: `x + x·R(x²)` below
/// `|x| = ½` (`x` itself below `2⁻¹²`), `π/2 − 2(s + s·R(z))` with `z = (1 − |x|)/2`,
/// `s = √z` in `f64` above, `R` the same rational fit; NaN outside `[−1, 1]`. Within an ulp
/// of the arcsine, as the scalar function it mirrors (the standard library's `asin`, which
/// the scalar kernel uses with `std`, may differ from it by an ulp).
#[inline(always)]
#[allow(clippy::excessive_precision)] // musl's coefficients as its source writes them
fn asin_x8(x: f32x8) -> f32x8 {
    const PIO2: f64 = core::f64::consts::FRAC_PI_2;
    let r = |z: f32x8| {
        let p = z
            * (f32x8::splat(1.666_658_669_7e-1)
                + z * (f32x8::splat(-4.274_342_209_1e-2) + z * f32x8::splat(-8.656_363_003_0e-3)));
        let q = f32x8::ONE + z * f32x8::splat(-7.066_296_339_0e-1);
        p / q
    };
    let ax = x.abs();
    let small = ax
        .simd_lt(f32x8::splat(f32::from_bits(0x3980_0000)))
        .select(x, x + x * r(x * x));
    let z = (f32x8::ONE - ax) * f32x8::splat(0.5);
    let s = widen(z).sqrt();
    let big = narrow(f64x8::splat(PIO2) - f64x8::splat(2.0) * (s + s * widen(r(z))));
    let big = x.simd_lt(f32x8::ZERO).select(-big, big);
    let y = ax.simd_lt(f32x8::splat(0.5)).select(small, big);
    ax.simd_gt(f32x8::ONE).select(f32x8::splat(f32::NAN), y)
}

/// The contributions of eight HVLs to one zonal receiver, lane-wise
/// `steradian_core::sh::hvl::contribution_zonal` with the smoothstep horizon, every step on
/// lanes: the geometry of `prepare` in `f32` (the same operations, with [`asin_x8`] for the
/// two arcsines), the band scales `k_l` of `steradian_core::sh::cap::band_scales` in `f64`
/// from `sin a = min(r/d, 1)` itself (`cos a = √((1 − s)(1 + s))`,
/// `sin²(a/2) = s²/(2(1 + cos a))`: exact for `a ≤ π/2`, where the scalar kernel goes through
/// the `f32` angle and a sine and cosine of its half), the zonal basis `Y_l⁰` by the Legendre
/// recurrence in `f64` at the cap axis's normalised `z`, each rounded to `f32` before its
/// product with `k_l` as the scalar kernel does, and `P·e·G·s` left to right. Within
/// [`ZONAL_TOL`] of the scalar kernel (tested); `Value` lanes
/// (NaN distance, coincident, infinitely far, facing away, below the horizon) exactly.
/// An emission of more than one band is evaluated lane by lane by the scalar SH kernel.
fn contributions_zonal_x8(
    hvls: [&Hvl; 8],
    emission: &[f32],
    rx: &ZonalReceiver<'_>,
    scratch: &mut [f32],
) -> Result<[f32; 8], Error> {
    let lane = |f: &dyn Fn(&Hvl) -> f32| f32x8::new(hvls.map(f));
    let (px, py, pz) = (
        lane(&|h| h.position().x),
        lane(&|h| h.position().y),
        lane(&|h| h.position().z),
    );
    let (nx, ny, nz) = (
        lane(&|h| h.frame().normal().x),
        lane(&|h| h.frame().normal().y),
        lane(&|h| h.frame().normal().z),
    );
    let (radius, power) = (lane(&|h| h.radius()), lane(&|h| h.power()));
    let splat = f32x8::splat;
    let (vx, vy, vz) = (
        px - splat(rx.point.x),
        py - splat(rx.point.y),
        pz - splat(rx.point.z),
    );
    let d = (vx * vx + vy * vy + vz * vz).sqrt();
    let (wx, wy, wz) = (vx / d, vy / d, vz / d);
    let cos_j = -(wx * nx + wy * ny + wz * nz);
    let sin_a = (radius / d).min(f32x8::ONE);
    let a = asin_x8(sin_a);
    let fnorm = rx.frame.normal();
    let cos_x = wx * splat(fnorm.x) + wy * splat(fnorm.y) + wz * splat(fnorm.z);
    // `horizon_smoothstep(cos_x, a)`: `a > 0` on these lanes (the others are settled).
    let c = cos_x.max(splat(-1.0)).min(f32x8::ONE);
    let t = ((a + asin_x8(c)) / (splat(2.0) * a))
        .max(f32x8::ZERO)
        .min(f32x8::ONE);
    let a_zero = a.simd_le(f32x8::ZERO);
    let h = a_zero.select(
        c.simd_gt(f32x8::ZERO).select(f32x8::ONE, f32x8::ZERO),
        t * t * (splat(3.0) - splat(2.0) * t),
    );
    // The lanes `prepare` settles, in its order.
    let nan = d.is_nan();
    let gone = d.simd_le(f32x8::ZERO) | d.simd_ge(splat(f32::INFINITY));
    let away = cos_j.simd_le(f32x8::ZERO);
    let below = h.simd_eq(f32x8::ZERO);
    let settled = nan | gone | away | below;
    let g = cos_j * h / (splat(core::f32::consts::PI) * radius * radius);
    // `e = Σ F′_k·Y_k(−ω_j)` in the HVL's frame.
    let ne = steradian_core::sh::bands_of(emission.len())?;
    let e = if ne == 1 {
        splat(emission[0] * steradian_core::sh::Y00)
    } else {
        let (w, settled) = ([wx, wy, wz].map(f32x8::to_array), settled.to_array());
        let mut e = [0.0f32; 8];
        for (k, h) in hvls.iter().enumerate() {
            if settled[k] != 0.0 {
                continue;
            }
            let emit = h.frame().to_local(-Vec3::new(w[0][k], w[1][k], w[2][k]));
            steradian_core::sh::eval_into(emit, ne, scratch)?;
            for (f, y) in emission.iter().zip(scratch.iter()) {
                e[k] += f * y;
            }
        }
        f32x8::new(e)
    };
    // The cap's zonal coefficients `C_l⁰ = k_l·Y_l⁰(ω_j)`, dotted with `F_l`.
    let (tx, ty) = (rx.frame.tangent(), rx.frame.bitangent());
    let ax = wx * splat(tx.x) + wy * splat(tx.y) + wz * splat(tx.z);
    let ay = wx * splat(ty.x) + wy * splat(ty.y) + wz * splat(ty.z);
    let (ax, ay, az) = (widen(ax), widen(ay), widen(cos_x));
    let z = az / (ax * ax + ay * ay + az * az).sqrt();
    let s = widen(sin_a);
    let one = f64x8::ONE;
    let ca = ((one - s) * (one + s)).sqrt();
    let s2 = s * s;
    let h2 = s2 / (f64x8::splat(2.0) * (one + ca));
    let pi = core::f64::consts::PI;
    let y00 = f64x8::splat(steradian_core::sh::Y00_F64);
    // Band 0 (`band_scales`' `k_0 = 4π·sin²(a/2)`; `eval_zonal_into`'s `Y00 + 0·z`).
    let mut sum = match rx.coeffs.first() {
        Some(f0) => {
            splat(*f0)
                * narrow(widen(narrow(y00 + f64x8::ZERO * z)) * (f64x8::splat(4.0 * pi) * h2))
        }
        None => f32x8::ZERO,
    };
    // Band scales (`band_scales`) and Legendre polynomials `P_l(z)` side by side.
    let (mut p_prev, mut p) = (one, ca);
    let (mut dp_prev, mut dp) = (f64x8::ZERO, one);
    let (mut q_prev, mut q) = (one, z);
    for (l, f) in rx.coeffs.iter().enumerate().skip(1) {
        let lf = l as f64;
        let k = f64x8::splat(2.0 * pi) * s2 * dp / f64x8::splat(lf * (lf + 1.0));
        let y = q * f64x8::splat(steradian_core::math::sqrt64((2.0 * lf + 1.0) / (4.0 * pi)));
        sum += splat(*f) * narrow(widen(narrow(y)) * k);
        let p_next = (f64x8::splat(2.0 * lf + 1.0) * ca * p - f64x8::splat(lf) * p_prev)
            / f64x8::splat(lf + 1.0);
        let dp_next = dp_prev + f64x8::splat(2.0 * lf + 1.0) * p;
        (p_prev, p) = (p, p_next);
        (dp_prev, dp) = (dp, dp_next);
        let q_next = (f64x8::splat(2.0 * lf + 1.0) * z * q - f64x8::splat(lf) * q_prev)
            / f64x8::splat(lf + 1.0);
        (q_prev, q) = (q, q_next);
    }
    let lit = power * e * g * sum;
    let value = nan.select(splat(f32::NAN), f32x8::ZERO);
    Ok(settled.select(value, lit).to_array())
}

/// The contributions of a slice of HVLs to one zonal receiver, eight HVLs per pass with
/// every step on lanes (module docs): `out[j]` is HVL `j`'s contribution to `rx`, lane-wise
/// `steradian_core::sh::hvl::contribution_zonal` within [`ZONAL_TOL`] of it
/// ([`zonal_bound`]); with [`Horizon::Exact`] the scalar kernel itself, lane by lane. Any
/// length. `scratch` at least `max(n, n_e²)` values.
///
/// Errors: those of the scalar kernel (an emission count that is not a square, more than
/// `MAX_BANDS` bands, a short `scratch`); `out` of another length than `hvls`.
pub fn contributions_zonal(
    hvls: &[Hvl],
    emission: &[f32],
    rx: &ZonalReceiver<'_>,
    horizon: Horizon,
    scratch: &mut [f32],
    out: &mut [f32],
) -> Result<(), Error> {
    check_len("HVL output length", out.len(), hvls.len())?;
    let Some(first) = hvls.first() else {
        return Ok(());
    };
    // The scalar kernel's checks, once (they do not depend on the HVL).
    contribution_zonal(first, emission, rx, horizon, scratch)?;
    if horizon == Horizon::Exact {
        for (o, h) in out.iter_mut().zip(hvls) {
            *o = contribution_zonal(h, emission, rx, horizon, scratch)?;
        }
        return Ok(());
    }
    for (group, out) in hvls.chunks(8).zip(out.chunks_mut(8)) {
        let eight: [&Hvl; 8] = core::array::from_fn(|k| &group[k.min(group.len() - 1)]);
        let c = contributions_zonal_x8(eight, emission, rx, scratch)?;
        out.copy_from_slice(&c[..out.len()]);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `asin_x8` within an ulp of the `f64` arcsine rounded to `f32` over `[−1, 1]`: a dense
    /// sweep of the bit patterns of `[0, 1]` (both signs), the branch points (`2⁻¹²`, `½`),
    /// `±0`, subnormals and `±1`; NaN for NaN, infinities and `|x| > 1`.
    #[test]
    fn asin_lanes_are_within_an_ulp() {
        let mut xs: Vec<f32> = (0..=0x3f80_0000u32)
            .step_by(997)
            .map(f32::from_bits)
            .collect();
        for b in [0x3980_0000u32, 0x3f00_0000] {
            xs.extend((b - 8..b + 8).map(f32::from_bits));
        }
        xs.extend([0.0, 1e-45, 1.17e-38, 1.0, 0.999_999_94, 0.5, 0.499_999_97]);
        let negated: Vec<f32> = xs.iter().map(|x| -x).collect();
        xs.extend(negated);
        let ulp = |y: f32| f32::from_bits(y.abs().to_bits() + 1) - y.abs();
        for chunk in xs.chunks(8) {
            let lanes: [f32; 8] = core::array::from_fn(|k| chunk[k % chunk.len()]);
            let got = asin_x8(f32x8::new(lanes)).to_array();
            for (x, y) in lanes.iter().zip(got) {
                let want = f64::from(*x).asin();
                let err = (f64::from(y) - want).abs();
                assert!(
                    err <= f64::from(ulp(want as f32)),
                    "asin({x:e}) = {y:e}, want {want:e}"
                );
                assert_eq!(y.is_sign_negative(), x.is_sign_negative(), "{x:e}");
            }
        }
        let specials = [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            1.000_000_1,
            -1.5,
            2.0,
            -1e30,
            3.0,
        ];
        for y in asin_x8(f32x8::new(specials)).to_array() {
            assert!(y.is_nan(), "{y}");
        }
    }
}
