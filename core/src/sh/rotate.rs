//! Rotation of SH coefficient vectors, every band (the HVL paper rotates its zonal cap
//! coefficients, eq. 15; a renderer rotates whole environments and BRDF lobes).
//!
//! ## Convention
//!
//! Rotating by the matrix `R` maps the value a function has at `d` to `R·d`:
//! `g(ω) = f(Rᵀω)`. The operator of a product is the product of the operators,
//! `M(R₁R₂) = M(R₁)·M(R₂)`, and each band `l` is rotated by its own orthogonal
//! `(2l+1)×(2l+1)` block, so every band's norm is preserved.
//!
//! ## Input: a validated rotation
//!
//! [`Rotation::new`] takes the matrix by rows and accepts it when `max |RᵀR − I| ≤ 1e-5`
//! and `det R > 0`; anything else (a reflection, a scaling, a shear, NaN) is an error. The
//! accepted matrix is replaced by its nearest rotation (the orthogonal polar factor, by
//! three Newton steps `X ← ½(X + X⁻ᵀ)` in `f64`, which converge quadratically from `1e-5` to
//! below `f64` rounding) and everything after works on that exact rotation.
//!
//! ## The built operator (many vectors, one rotation): Ivanic–Ruedenberg
//!
//! Band 1 of the real SH without the Condon–Shortley phase is `(y, z, x)` up to one
//! constant, so its block is `R` with rows and columns permuted to `(y, z, x)`; band `l` is
//! built from band `l − 1` and band 1 by the recurrence of Ivanic and Ruedenberg (with the
//! published erratum's sign of the `m < 0` term of `V`):
//! `R^l_{mn} = u·U + v·V + w·W`, each of `U, V, W` one or two products of a band-1 entry and
//! a band-`(l−1)` entry, `u, v, w` square roots of small rationals in `l, m, n`. The phase
//! `(−1)^m` of this crate's basis ([`crate::sh`]) conjugates each block by
//! `diag((−1)^m)`, i.e. flips the sign of entry `(m, n)` when `m + n` is odd. The recurrence
//! runs in `f64` (O(l²) per band, two bands of scratch) and the blocks are stored in `f32`
//! ([`operator_into`], [`apply_operator`]; [`Operator`] owns one with `alloc`).
//!
//! ## The fast path (one vector): ZXZXZ
//!
//! `R = Rz(α)·Ry(β)·Rz(γ)` and `Ry(β) = Rx(−90°)·Rz(β)·Rx(90°)` (conjugating a rotation
//! about `z` by `Rx(90°)`, which takes `y` to `z`, turns it into one about `y`), so
//! `M(R) = Z(α)·Jᵀ·Z(β)·J·Z(γ)` with `J = M(Rx(90°))` — one fixed table for every rotation,
//! built once by the recurrence above from the exact matrix of `Rx(90°)` ([`x90_into`];
//! [`Rotator`] owns one) — and `Z(θ)` the rotation about `z`, which only mixes the pair
//! `(m, −m)`: `f(φ − θ)` has `c′_m = c_m·cos mθ − c_{−m}·sin mθ`,
//! `c′_{−m} = c_m·sin mθ + c_{−m}·cos mθ`. Two dense products per band instead of building
//! the block. `cos mθ, sin mθ` come from powers of `e^{iθ}` in `f64`.
//!
//! **Euler angles without singularities.** From the entries of `R`,
//! `R₀₀ + R₁₁ = (1 + cos β)·cos(α+γ)`, `R₁₀ − R₀₁ = (1 + cos β)·sin(α+γ)`,
//! `R₀₀ − R₁₁ = −(1 − cos β)·cos(α−γ)`, `R₁₀ + R₀₁ = −(1 − cos β)·sin(α−γ)`, so `α ± γ`
//! come from two `atan2`s, each well conditioned where it matters (`α − γ` is undetermined
//! exactly when `β = 0`, where it does not matter, and its error is multiplied by `β`).
//! Then `sin β = cos α·R₀₂ + sin α·R₁₂` is signed consistently with the chosen `α` (the pair
//! `(α + π, γ + π)` is the same rotation with `−β`). A rotation about `z` (`R₀₂ = R₁₂ = R₂₀ =
//! R₂₁ = 0`, `R₂₂ = 1`) is applied as `Z(α + γ)` alone and a half-turn about a horizontal
//! axis (`R₂₂ = −1`) as `Z(α − γ)` times the exact sign flips of `Ry(π)`
//! (`(−1)^l`, and `−1` more for `m < 0`), with `cos, sin` read from the matrix's first
//! column: no table, no trigonometry.
//!
//! ## Accuracy (tests below, against `steradian-reference`'s rotation by exact quadrature)
//!
//! Both paths: `‖M·c − c_exact‖ ≤ rotate_rel_error(n)·‖c‖` (Euclidean norms) for `n` bands,
//! [`rotate_rel_error`]`(n) = 1e-7 + 1e-8·n`, so `4e-7` at 30 bands (measured there: `1.2e-7`
//! for the operator, which sums in `f32`, and `4.7e-8` for ZXZXZ, which sums in `f64`; the
//! `f32` rounding of the output alone is `3e-8`). Each band's norm is preserved to the same
//! relative bound, the two paths agree to `1.2e-6` through 100 bands, and the exact cases
//! (identity bit for bit, about `z`, `β = π` as exact sign flips, angles of `1e-6` and
//! `β = 1e-12`) are tested by name.
//!
//! # References
//!
//! - J. Ivanic, K. Ruedenberg, "Rotation Matrices for Real Spherical Harmonics. Direct
//!   Determination by Recursion", *J. Phys. Chem.* 100(15), 6342–6347, 1996.
//!   DOI: 10.1021/jp953350u; erratum *J. Phys. Chem. A* 102(45), 9099–9100, 1998.
//!   DOI: 10.1021/jp9833350.
//! - P.-P. Sloan, "Stupid Spherical Harmonics (SH) Tricks", GDC 2008 (the ZXZXZ
//!   decomposition with the fixed 90° blocks).

use crate::math;
use crate::sh::check_shape;
use crate::{Error, Vec3};
use glam::{DMat3, DVec3};

/// Largest accepted `max |RᵀR − I|` of a rotation given to [`Rotation::new`].
pub const ORTHOGONALITY_TOLERANCE: f64 = 1e-5;

/// Error of both rotation paths for `bands` bands, relative to the input's norm:
/// `‖M·c − c_exact‖ ≤ rotate_rel_error(bands)·‖c‖` (module docs; tests below).
pub fn rotate_rel_error(bands: usize) -> f32 {
    1.0e-7 + 1.0e-8 * bands as f32
}

/// What the fast path does for a rotation (module docs, "Euler angles"): read by the SIMD
/// twin through [`Rotation::euler`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Euler {
    /// `Z(θ)` alone: a rotation about `z` (`(cos θ, sin θ)`).
    AboutZ([f64; 2]),
    /// `Z(θ)·M(Ry(π))`: a half-turn about a horizontal axis.
    HalfTurn([f64; 2]),
    /// `Z(α)·Jᵀ·Z(β)·J·Z(γ)`.
    General {
        /// `(cos α, sin α)`.
        alpha: [f64; 2],
        /// `(cos β, sin β)`.
        beta: [f64; 2],
        /// `(cos γ, sin γ)`.
        gamma: [f64; 2],
    },
}

/// A proper rotation, validated and made exactly orthogonal in `f64` (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rotation {
    m: DMat3,
    euler: Euler,
}

fn cis(t: f64) -> [f64; 2] {
    [math::cos64(t), math::sin64(t)]
}

impl Rotation {
    /// The rotation with the given rows `r[i][j] = R_ij`.
    ///
    /// Errors: a non-finite entry, `max |RᵀR − I| > 1e-5` or `det R ≤ 0`
    /// ([`Error::NotRotation`]).
    pub fn new(rows: [[f32; 3]; 3]) -> Result<Self, Error> {
        if rows.iter().flatten().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite { what: "rotation" });
        }
        let r = |i: usize| DVec3::new(rows[0][i].into(), rows[1][i].into(), rows[2][i].into());
        Self::from_dmat3(DMat3::from_cols(r(0), r(1), r(2)))
    }

    /// As [`Rotation::new`], from an `f64` matrix (columns as in glam).
    pub fn from_dmat3(m: DMat3) -> Result<Self, Error> {
        if !m.is_finite() {
            return Err(Error::NonFinite { what: "rotation" });
        }
        let g = m.transpose() * m - DMat3::IDENTITY;
        let dev = [g.x_axis, g.y_axis, g.z_axis]
            .iter()
            .map(|c| c.abs().max_element())
            .fold(0.0f64, f64::max);
        let det = m.determinant();
        if dev > ORTHOGONALITY_TOLERANCE || det <= 0.0 {
            return Err(Error::NotRotation {
                orthogonality: dev as f32,
                determinant: det as f32,
            });
        }
        // Nearest rotation: Newton's iteration for the polar factor.
        let mut x = m;
        for _ in 0..3 {
            x = (x + x.inverse().transpose()) * 0.5;
        }
        Ok(Rotation {
            m: x,
            euler: euler(&x),
        })
    }

    /// The identity.
    pub fn identity() -> Self {
        Self::from_dmat3(DMat3::IDENTITY).unwrap_or(Rotation {
            m: DMat3::IDENTITY,
            euler: Euler::AboutZ([1.0, 0.0]),
        })
    }

    /// The rotation by `angle` (radians, right-handed) about the axis `axis` (any non-zero
    /// length). Errors: a zero or non-finite axis, a non-finite angle.
    pub fn from_axis_angle(axis: Vec3, angle: f32) -> Result<Self, Error> {
        if !axis.is_finite() || !angle.is_finite() {
            return Err(Error::NonFinite {
                what: "rotation axis",
            });
        }
        let a = axis.as_dvec3();
        let len = a.length();
        if len == 0.0 || !len.is_finite() {
            return Err(Error::ZeroVector {
                what: "rotation axis",
            });
        }
        Self::from_dmat3(DMat3::from_axis_angle(a / len, angle.into()))
    }

    /// The Euler decomposition [`rotate_zxzxz`] applies (module docs), with its exact cases.
    pub fn euler(&self) -> Euler {
        self.euler
    }

    /// The exact (orthogonalised) matrix.
    pub fn matrix(&self) -> DMat3 {
        self.m
    }

    /// `R·d`, the image of a direction.
    pub fn apply_to(&self, d: Vec3) -> Vec3 {
        (self.m * d.as_dvec3()).as_vec3()
    }

    /// What [`rotate_zxzxz`] does for this rotation, as the seven `f32` values of a row of
    /// the WGSL twin (`wgsl::SH_ROTATE_ZXZXZ`): `[mode, cos α, sin α, cos β, sin β, cos γ,
    /// sin γ]`, mode 0 for a rotation about `z` (`Z(α)` alone), 1 for a half-turn about a
    /// horizontal axis (`Z(α)·M(Ry(π))`), 2 for `Z(α)·Jᵀ·Z(β)·J·Z(γ)`; the unused angles
    /// are 0 (`(1, 0)`). The exact cases stay exact on the GPU: no `J` block is applied.
    pub fn gpu_row(&self) -> [f32; 7] {
        let f = |c: [f64; 2]| [c[0] as f32, c[1] as f32];
        let (mode, a, b, g) = match self.euler {
            Euler::AboutZ(t) => (0.0, f(t), [1.0, 0.0], [1.0, 0.0]),
            Euler::HalfTurn(t) => (1.0, f(t), [1.0, 0.0], [1.0, 0.0]),
            Euler::General { alpha, beta, gamma } => (2.0, f(alpha), f(beta), f(gamma)),
        };
        [mode, a[0], a[1], b[0], b[1], g[0], g[1]]
    }
}

/// The Euler decomposition `R = Rz(α)·Ry(β)·Rz(γ)` (module docs), with the exact cases.
fn euler(r: &DMat3) -> Euler {
    // r.col(j)[i] = R_ij.
    let e = |i: usize, j: usize| r.col(j)[i];
    let (r00, r01, r10, r11) = (e(0, 0), e(0, 1), e(1, 0), e(1, 1));
    if e(0, 2) == 0.0 && e(1, 2) == 0.0 && e(2, 0) == 0.0 && e(2, 1) == 0.0 {
        // The entries are the cosine and sine themselves: `Rz(θ)` has first column
        // `(cos θ, sin θ, 0)`, `Rz(θ)·Ry(π)` has `(−cos θ, −sin θ, 0)`.
        return if e(2, 2) > 0.0 {
            Euler::AboutZ([r00, r10])
        } else {
            Euler::HalfTurn([-r00, -r10])
        };
    }
    let sum = math::atan2_64(r10 - r01, r00 + r11);
    let diff = math::atan2_64(-(r10 + r01), -(r00 - r11));
    let (alpha, gamma) = (0.5 * (sum + diff), 0.5 * (sum - diff));
    let (ca, cg) = (cis(alpha), cis(gamma));
    // sin β signed consistently with α and γ (both estimates, averaged).
    let sb = 0.5 * (ca[0] * e(0, 2) + ca[1] * e(1, 2) - cg[0] * e(2, 0) + cg[1] * e(2, 1));
    let beta = math::atan2_64(sb, e(2, 2));
    Euler::General {
        alpha: ca,
        beta: cis(beta),
        gamma: cg,
    }
}

// ---- The built operator -------------------------------------------------------------------

/// Number of `f32` entries of the per-band blocks of `bands` bands:
/// `Σ_{l<bands} (2l+1)² = bands·(4·bands² − 1)/3`.
pub const fn operator_len(bands: usize) -> usize {
    if bands == 0 {
        0
    } else {
        bands * (4 * bands * bands - 1) / 3
    }
}

/// Number of `f64` scratch entries [`operator_into`] needs: two blocks of the last band.
pub const fn scratch_len(bands: usize) -> usize {
    if bands == 0 {
        0
    } else {
        2 * (2 * bands - 1) * (2 * bands - 1)
    }
}

/// The Ivanic–Ruedenberg blocks of `rot` for `bands` bands into `out[..operator_len(bands)]`
/// (band `l` at offset `operator_len(l)`, row-major, row = output `m + l`, column = input
/// `n + l`), computed in `f64` in `scratch[..scratch_len(bands)]` (module docs).
///
/// Errors: `bands > MAX_BANDS`, a short `out` or `scratch`.
pub fn operator_into(
    rot: &Rotation,
    bands: usize,
    out: &mut [f32],
    scratch: &mut [f64],
) -> Result<(), Error> {
    check_shape(bands, usize::MAX)?;
    check_len("rotation operator", out.len(), operator_len(bands))?;
    check_len("rotation scratch", scratch.len(), scratch_len(bands))?;
    if bands == 0 {
        return Ok(());
    }
    out[0] = 1.0;
    if bands == 1 {
        return Ok(());
    }
    // Band 1 without the phase: R permuted to (y, z, x); r1[(m+1)*3 + (n+1)].
    let p = [1usize, 2, 0];
    let e = |i: usize, j: usize| rot.m.col(j)[i];
    let mut r1 = [0.0f64; 9];
    for (a, &pa) in p.iter().enumerate() {
        for (b, &pb) in p.iter().enumerate() {
            r1[a * 3 + b] = e(pa, pb);
        }
    }
    let half = scratch_len(bands) / 2;
    let (prev, cur) = scratch[..2 * half].split_at_mut(half);
    prev[..9].copy_from_slice(&r1);
    store(1, &prev[..9], &mut out[operator_len(1)..operator_len(2)]);
    for l in 2..bands {
        let w_prev = 2 * l - 1;
        let w = 2 * l + 1;
        band_block(l, &r1, &prev[..w_prev * w_prev], &mut cur[..w * w]);
        store(
            l,
            &cur[..w * w],
            &mut out[operator_len(l)..operator_len(l + 1)],
        );
        prev[..w * w].copy_from_slice(&cur[..w * w]);
    }
    Ok(())
}

/// `Err` unless `op` holds the blocks of [`operator_into`] for `bands` bands (at least
/// [`operator_len`]`(bands)` values): the check every application of an operator makes.
pub fn check_operator(op: &[f32], bands: usize) -> Result<(), Error> {
    check_len("rotation operator", op.len(), operator_len(bands))
}

fn check_len(what: &'static str, len: usize, need: usize) -> Result<(), Error> {
    if len < need {
        return Err(Error::OutOfRange {
            what,
            value: len as f32,
            min: need as f32,
            max: f32::INFINITY,
        });
    }
    Ok(())
}

/// A band's block (no phase, `f64`) into this crate's phase (`(−1)^(m+n)`) as `f32`.
fn store(l: usize, block: &[f64], out: &mut [f32]) {
    let w = 2 * l + 1;
    for i in 0..w {
        for j in 0..w {
            let v = block[i * w + j];
            // m + n = i + j − 2l has the parity of i + j.
            out[i * w + j] = if (i + j) % 2 == 1 { -v } else { v } as f32;
        }
    }
}

/// One band of the Ivanic–Ruedenberg recurrence: `cur = R^l` from `prev = R^{l−1}` and the
/// band-1 block `r1` (all without the phase, row-major, centred indices).
fn band_block(l: usize, r1: &[f64; 9], prev: &[f64], cur: &mut [f64]) {
    let li = l as isize;
    let wp = 2 * li - 1;
    let r1e = |i: isize, j: isize| r1[((i + 1) * 3 + (j + 1)) as usize];
    let pe = |a: isize, b: isize| prev[((a + li - 1) * wp + (b + li - 1)) as usize];
    // P(i, a, b) of the recurrence.
    let pf = |i: isize, a: isize, b: isize| -> f64 {
        if b == li {
            r1e(i, 1) * pe(a, li - 1) - r1e(i, -1) * pe(a, -li + 1)
        } else if b == -li {
            r1e(i, 1) * pe(a, -li + 1) + r1e(i, -1) * pe(a, li - 1)
        } else {
            r1e(i, 0) * pe(a, b)
        }
    };
    let w = 2 * li + 1;
    let lf = l as f64;
    for m in -li..=li {
        let am = m.unsigned_abs() as f64;
        let d0 = if m == 0 { 1.0 } else { 0.0 };
        for n in -li..=li {
            let denom = if n.abs() == li {
                2.0 * lf * (2.0 * lf - 1.0)
            } else {
                (lf + n as f64) * (lf - n as f64)
            };
            let mf = m as f64;
            let u = math::sqrt64((lf + mf) * (lf - mf) / denom);
            let v = 0.5
                * math::sqrt64((1.0 + d0) * (lf + am - 1.0) * (lf + am) / denom)
                * (1.0 - 2.0 * d0);
            let wc =
                -0.5 * math::sqrt64(((lf - am - 1.0) * (lf - am)).max(0.0) / denom) * (1.0 - d0);
            let mut val = 0.0;
            if u != 0.0 {
                val += u * pf(0, m, n);
            }
            if v != 0.0 {
                let vv = if m == 0 {
                    pf(1, 1, n) + pf(-1, -1, n)
                } else if m > 0 {
                    let d1 = if m == 1 { 1.0 } else { 0.0 };
                    pf(1, m - 1, n) * math::sqrt64(1.0 + d1) - pf(-1, -m + 1, n) * (1.0 - d1)
                } else {
                    let d1 = if m == -1 { 1.0 } else { 0.0 };
                    pf(1, m + 1, n) * (1.0 - d1) + pf(-1, -m - 1, n) * math::sqrt64(1.0 + d1)
                };
                val += v * vv;
            }
            if wc != 0.0 {
                let ww = if m > 0 {
                    pf(1, m + 1, n) + pf(-1, -m - 1, n)
                } else {
                    pf(1, m - 1, n) - pf(-1, -m + 1, n)
                };
                val += wc * ww;
            }
            cur[((m + li) * w + (n + li)) as usize] = val;
        }
    }
}

/// `out = M·input` for the blocks `op` of [`operator_into`] over `bands` bands (`f32`).
///
/// Errors: `bands > MAX_BANDS`; `op`, `input` or `out` too short.
pub fn apply_operator(
    op: &[f32],
    bands: usize,
    input: &[f32],
    out: &mut [f32],
) -> Result<(), Error> {
    check_shape(bands, input.len())?;
    check_shape(bands, out.len())?;
    check_operator(op, bands)?;
    for l in 0..bands {
        let w = 2 * l + 1;
        let block = &op[operator_len(l)..operator_len(l + 1)];
        let x = &input[l * l..l * l + w];
        for (i, o) in out[l * l..l * l + w].iter_mut().enumerate() {
            // Left to right from +0: the order the SIMD twin repeats on each lane.
            let mut acc = 0.0f32;
            for (a, b) in block[i * w..i * w + w].iter().zip(x) {
                acc += a * b;
            }
            *o = acc;
        }
    }
    Ok(())
}

// ---- The fast path -------------------------------------------------------------------------

/// The blocks of `J = M(Rx(90°))` for `bands` bands (layout of [`operator_into`]), the one
/// table of the ZXZXZ path, built from the exact matrix.
pub fn x90_into(bands: usize, out: &mut [f32], scratch: &mut [f64]) -> Result<(), Error> {
    let rx90 = DMat3::from_cols(DVec3::X, DVec3::Z, -DVec3::Y);
    let rot = Rotation {
        m: rx90,
        euler: euler(&rx90),
    };
    operator_into(&rot, bands, out, scratch)
}

/// `Z(θ)` on one band in place (module docs): pair `(m, −m)` at `l + m`, `l − m`.
fn rotate_z(l: usize, cs: [f64; 2], band: &mut [f64]) {
    let (mut c, mut s) = (1.0f64, 0.0f64);
    for m in 1..=l {
        (c, s) = (c * cs[0] - s * cs[1], c * cs[1] + s * cs[0]);
        let (p, q) = (band[l + m], band[l - m]);
        band[l + m] = p * c - q * s;
        band[l - m] = p * s + q * c;
    }
}

/// `y = J·x` (`transpose = false`) or `Jᵀ·x` for one band's block. Each output sums its
/// products in input order from `+0`, unfused: the order the SIMD twin repeats per lane.
fn apply_block(block: &[f32], w: usize, transpose: bool, x: &[f64], y: &mut [f64]) {
    if transpose {
        y[..w].fill(0.0);
        for (i, &xi) in x[..w].iter().enumerate() {
            for (yj, &a) in y[..w].iter_mut().zip(&block[i * w..i * w + w]) {
                *yj += f64::from(a) * xi;
            }
        }
    } else {
        for (i, yi) in y[..w].iter_mut().enumerate() {
            let mut acc = 0.0f64;
            for (&a, &b) in block[i * w..i * w + w].iter().zip(&x[..w]) {
                acc += f64::from(a) * b;
            }
            *yi = acc;
        }
    }
}

/// `out = M(rot)·input` over `bands` bands by ZXZXZ (module docs) with the table `x90` of
/// [`x90_into`] (at least `bands` bands of it). Sums in `f64`, one rounding per output.
///
/// Errors: `bands > MAX_BANDS`; `x90`, `input` or `out` too short.
pub fn rotate_zxzxz(
    x90: &[f32],
    rot: &Rotation,
    bands: usize,
    input: &[f32],
    out: &mut [f32],
) -> Result<(), Error> {
    check_shape(bands, input.len())?;
    check_shape(bands, out.len())?;
    if let Euler::General { .. } = rot.euler {
        check_len("x90 table", x90.len(), operator_len(bands))?;
    }
    let mut a = [0.0f64; 2 * crate::sh::MAX_BANDS - 1];
    let mut b = [0.0f64; 2 * crate::sh::MAX_BANDS - 1];
    for l in 0..bands {
        let w = 2 * l + 1;
        for (t, &v) in a[..w].iter_mut().zip(&input[l * l..l * l + w]) {
            *t = f64::from(v);
        }
        match rot.euler {
            Euler::AboutZ(t) => rotate_z(l, t, &mut a),
            Euler::HalfTurn(t) => {
                // M(Ry(π)): (−1)^l, and −1 more for m < 0.
                let sl = if l % 2 == 1 { -1.0 } else { 1.0 };
                for (i, v) in a[..w].iter_mut().enumerate() {
                    *v *= if i < l { -sl } else { sl };
                }
                rotate_z(l, t, &mut a);
            }
            Euler::General { alpha, beta, gamma } => {
                let block = &x90[operator_len(l)..operator_len(l + 1)];
                rotate_z(l, gamma, &mut a);
                apply_block(block, w, false, &a, &mut b);
                rotate_z(l, beta, &mut b);
                apply_block(block, w, true, &b, &mut a);
                rotate_z(l, alpha, &mut a);
            }
        }
        for (o, &v) in out[l * l..l * l + w].iter_mut().zip(&a[..w]) {
            *o = v as f32;
        }
    }
    Ok(())
}

// ---- Owned conveniences --------------------------------------------------------------------

/// The built per-band operator of one rotation (module docs), for many vectors.
#[cfg(feature = "alloc")]
#[derive(Clone, Debug, PartialEq)]
pub struct Operator {
    bands: usize,
    blocks: alloc::vec::Vec<f32>,
}

#[cfg(feature = "alloc")]
impl Operator {
    /// The operator of `rot` over `bands` bands. Errors: `bands > MAX_BANDS`.
    pub fn new(rot: &Rotation, bands: usize) -> Result<Self, Error> {
        check_shape(bands, usize::MAX)?;
        let mut blocks = alloc::vec![0.0; operator_len(bands)];
        let mut scratch = alloc::vec![0.0; scratch_len(bands)];
        operator_into(rot, bands, &mut blocks, &mut scratch)?;
        Ok(Operator { bands, blocks })
    }

    /// The band count.
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// The blocks (layout of [`operator_into`]).
    pub fn blocks(&self) -> &[f32] {
        &self.blocks
    }

    /// `out = M·input` over the operator's bands. Errors: a short slice.
    pub fn apply(&self, input: &[f32], out: &mut [f32]) -> Result<(), Error> {
        apply_operator(&self.blocks, self.bands, input, out)
    }
}

/// The ZXZXZ fast path with its `J` table for up to `bands` bands (module docs): build once,
/// rotate any vector by any rotation.
#[cfg(feature = "alloc")]
#[derive(Clone, Debug, PartialEq)]
pub struct Rotator {
    bands: usize,
    x90: alloc::vec::Vec<f32>,
}

#[cfg(feature = "alloc")]
impl Rotator {
    /// The table for up to `bands` bands. Errors: `bands > MAX_BANDS`.
    pub fn new(bands: usize) -> Result<Self, Error> {
        check_shape(bands, usize::MAX)?;
        let mut x90 = alloc::vec![0.0; operator_len(bands)];
        let mut scratch = alloc::vec![0.0; scratch_len(bands)];
        x90_into(bands, &mut x90, &mut scratch)?;
        Ok(Rotator { bands, x90 })
    }

    /// The largest band count the table covers.
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// The `J` table (layout of [`operator_into`]), for the SIMD twin.
    pub fn table(&self) -> &[f32] {
        &self.x90
    }

    /// `out = M(rot)·input` for the `n` bands of `input` (`n² = input.len()`, `n` at most
    /// the table's). Errors: a length that is not a square, more bands than the table, a
    /// short `out`.
    pub fn rotate(&self, rot: &Rotation, input: &[f32], out: &mut [f32]) -> Result<(), Error> {
        let n = crate::sh::bands_of(input.len())?;
        if n > self.bands {
            return Err(Error::OutOfRange {
                what: "SH bands of the rotated vector",
                value: n as f32,
                min: 0.0,
                max: self.bands as f32,
            });
        }
        rotate_zxzxz(&self.x90, rot, n, input, out)
    }
}

#[cfg(all(test, feature = "alloc"))]
mod tests {
    use super::*;
    use crate::sh::bands_of;
    use alloc::vec;
    use alloc::vec::Vec;
    extern crate std;
    use std::println;
    use steradian_reference::sh as reference;

    use crate::sh::test_rng as rng;

    fn random_vector(bands: usize, seed: u64) -> Vec<f32> {
        let mut r = rng(seed);
        (0..bands * bands).map(|_| r()).collect()
    }

    fn rows(r: &Rotation) -> [[f64; 3]; 3] {
        let m = r.matrix();
        core::array::from_fn(|i| core::array::from_fn(|j| m.col(j)[i]))
    }

    fn norm(v: &[f32]) -> f64 {
        v.iter().map(|&x| f64::from(x).powi(2)).sum::<f64>().sqrt()
    }

    /// `|got − want| / |input|` (Euclidean norms).
    fn rel_error(got: &[f32], want: &[f64], input: &[f32]) -> f64 {
        let e = got
            .iter()
            .zip(want)
            .map(|(&g, w)| (f64::from(g) - w).powi(2))
            .sum::<f64>()
            .sqrt();
        e / norm(input)
    }

    /// Both paths of `rot` on `input` against the reference; returns the two errors.
    fn both_paths(rot: &Rotation, input: &[f32]) -> (f64, f64) {
        let n = bands_of(input.len()).unwrap();
        let want = reference::rotate(
            &input.iter().map(|&x| f64::from(x)).collect::<Vec<_>>(),
            rows(rot),
        );
        let op = Operator::new(rot, n).unwrap();
        let mut a = vec![0.0; n * n];
        op.apply(input, &mut a).unwrap();
        let mut b = vec![0.0; n * n];
        Rotator::new(n).unwrap().rotate(rot, input, &mut b).unwrap();
        (rel_error(&a, &want, input), rel_error(&b, &want, input))
    }

    fn random_rotations() -> Vec<Rotation> {
        let mut r = rng(0x0707);
        (0..4)
            .map(|_| {
                let axis = Vec3::new(r(), r(), r());
                Rotation::from_axis_angle(axis, 3.0 * r()).unwrap()
            })
            .collect()
    }

    #[test]
    fn gpu_row_names_the_path_and_its_angles() {
        // About z: mode 0 with (cos, sin) of the angle, the others (1, 0).
        let r = Rotation::from_axis_angle(Vec3::Z, 0.5).unwrap().gpu_row();
        assert_eq!(r[0], 0.0);
        assert!((r[1] - 0.5f32.cos()).abs() < 1e-7 && (r[2] - 0.5f32.sin()).abs() < 1e-7);
        assert_eq!(&r[3..], &[1.0, 0.0, 1.0, 0.0]);
        // A half-turn about a horizontal axis (entries exactly 0 and −1): mode 1.
        let h = Rotation::new([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]).unwrap();
        assert_eq!(h.gpu_row()[0], 1.0);
        // A general rotation: mode 2, three unit (cos, sin) pairs, and Z(α)·Ry(β)·Z(γ)
        // rebuilds the matrix.
        let g = Rotation::from_axis_angle(Vec3::new(0.3, -0.5, 0.8), 1.1).unwrap();
        let r = g.gpu_row();
        assert_eq!(r[0], 2.0);
        for k in [1, 3, 5] {
            assert!((r[k] * r[k] + r[k + 1] * r[k + 1] - 1.0).abs() < 1e-6);
        }
        let rz = |c: f32, s: f32| {
            DMat3::from_cols(
                DVec3::new(c.into(), s.into(), 0.0),
                DVec3::new((-s).into(), c.into(), 0.0),
                DVec3::Z,
            )
        };
        let ry = DMat3::from_cols(
            DVec3::new(r[3].into(), 0.0, (-r[4]).into()),
            DVec3::Y,
            DVec3::new(r[4].into(), 0.0, r[3].into()),
        );
        let m = rz(r[1], r[2]) * ry * rz(r[5], r[6]);
        let d = m - g.matrix();
        let worst = [d.x_axis, d.y_axis, d.z_axis]
            .iter()
            .map(|c| c.abs().max_element())
            .fold(0.0, f64::max);
        assert!(worst < 1e-6, "{worst}");
    }

    #[test]
    fn both_paths_match_the_quadrature_reference_through_30_bands() {
        for bands in [1usize, 2, 3, 5, 10, 30] {
            let mut worst = (0.0f64, 0.0f64);
            for (k, rot) in random_rotations().iter().enumerate() {
                let input = random_vector(bands, 11 + k as u64);
                let (a, b) = both_paths(rot, &input);
                worst = (worst.0.max(a), worst.1.max(b));
            }
            println!(
                "bands {bands:2}: operator {:.2e}, zxzxz {:.2e}",
                worst.0, worst.1
            );
            let bound = f64::from(rotate_rel_error(bands));
            assert!(
                worst.0 <= bound && worst.1 <= bound,
                "{bands}: {worst:?} > {bound}"
            );
            if bands == 30 {
                // The figures the module docs and the README quote.
                assert!(worst.0 <= 1.3e-7 && worst.1 <= 5e-8, "{worst:?}");
            }
        }
    }

    #[test]
    fn band_norms_are_preserved() {
        let bands = 30;
        let input = random_vector(bands, 5);
        let rz = Rotator::new(bands).unwrap();
        for rot in random_rotations() {
            let op = Operator::new(&rot, bands).unwrap();
            for path in 0..2 {
                let mut out = vec![0.0; bands * bands];
                if path == 0 {
                    op.apply(&input, &mut out).unwrap();
                } else {
                    rz.rotate(&rot, &input, &mut out).unwrap();
                }
                for l in 0..bands {
                    let r = l * l..(l + 1) * (l + 1);
                    let (a, b) = (norm(&input[r.clone()]), norm(&out[r]));
                    assert!(
                        (a - b).abs() <= f64::from(rotate_rel_error(bands)) * a,
                        "path {path} band {l}: {a} vs {b}"
                    );
                }
            }
        }
    }

    #[test]
    fn composition_is_the_product_of_operators() {
        let bands = 12;
        let rs = random_rotations();
        let input = random_vector(bands, 9);
        let rz = Rotator::new(bands).unwrap();
        let mut once = vec![0.0; bands * bands];
        let mut twice = vec![0.0; bands * bands];
        rz.rotate(&rs[1], &input, &mut once).unwrap();
        let tmp = once.clone();
        rz.rotate(&rs[0], &tmp, &mut twice).unwrap();
        let prod = Rotation::from_dmat3(rs[0].matrix() * rs[1].matrix()).unwrap();
        let mut direct = vec![0.0; bands * bands];
        rz.rotate(&prod, &input, &mut direct).unwrap();
        for (a, b) in twice.iter().zip(&direct) {
            assert!((a - b).abs() < 1e-5, "{a} vs {b}");
        }
    }

    #[test]
    fn the_rotated_function_is_the_function_at_the_rotated_direction() {
        // g(R·d) = f(d): evaluate both sides with the kernel's own SH.
        let bands = 8;
        let input = random_vector(bands, 3);
        let rot = &random_rotations()[2];
        let mut out = vec![0.0; bands * bands];
        Rotator::new(bands)
            .unwrap()
            .rotate(rot, &input, &mut out)
            .unwrap();
        let mut y = vec![0.0; bands * bands];
        let mut r = rng(77);
        for _ in 0..50 {
            let d = Vec3::new(r(), r(), r() + 0.01).normalize();
            crate::sh::eval_into(d, bands, &mut y).unwrap();
            let f: f32 = y.iter().zip(&input).map(|(a, b)| a * b).sum();
            crate::sh::eval_into(rot.apply_to(d), bands, &mut y).unwrap();
            let g: f32 = y.iter().zip(&out).map(|(a, b)| a * b).sum();
            assert!((f - g).abs() < 1e-4, "{f} vs {g}");
        }
    }

    #[test]
    fn identity_is_exact() {
        let bands = 30;
        let input = random_vector(bands, 1);
        let mut out = vec![0.0; bands * bands];
        let rot = Rotation::new([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]).unwrap();
        Rotator::new(bands)
            .unwrap()
            .rotate(&rot, &input, &mut out)
            .unwrap();
        assert_eq!(out, input);
        Operator::new(&rot, bands)
            .unwrap()
            .apply(&input, &mut out)
            .unwrap();
        assert_eq!(out, input);
    }

    #[test]
    fn rotation_about_z_touches_no_table() {
        let rot = Rotation::from_axis_angle(Vec3::Z, 0.7).unwrap();
        assert!(matches!(rot.euler, Euler::AboutZ(_)));
        // The fast path needs no x90 table for it.
        let input = random_vector(30, 2);
        let mut out = vec![0.0; 900];
        rotate_zxzxz(&[], &rot, 30, &input, &mut out).unwrap();
        let (a, b) = both_paths(&rot, &input);
        let want = reference::rotate(
            &input.iter().map(|&x| f64::from(x)).collect::<Vec<_>>(),
            rows(&rot),
        );
        let direct = rel_error(&out, &want, &input);
        println!("about z: operator {a:.2e}, zxzxz {b:.2e}, no table {direct:.2e}");
        assert!(a.max(b).max(direct) <= f64::from(rotate_rel_error(30)));
        // m = 0 coefficients do not move at all.
        for l in 0..30 {
            assert_eq!(out[l * l + l], input[l * l + l]);
        }
    }

    #[test]
    fn half_turns_beta_pi_are_exact_sign_flips() {
        // Exact half-turns about x, y and (1, −2, 0)/√5 (2uuᵀ − I) take the exact path.
        let exact = [
            [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]],
            [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]],
            [[-0.6, -0.8, 0.0], [-0.8, 0.6, 0.0], [0.0, 0.0, -1.0]],
        ];
        let input = random_vector(30, 4);
        for m in exact {
            let rot = Rotation::new(m).unwrap();
            assert!(matches!(rot.euler, Euler::HalfTurn(_)), "{m:?}");
            let (a, b) = both_paths(&rot, &input);
            assert!(
                a.max(b) <= f64::from(rotate_rel_error(30)),
                "{m:?}: {a} {b}"
            );
        }
        // The f32 π is 8.7e-8 short of a half-turn: the general path, as accurate.
        for axis in [Vec3::X, Vec3::Y, Vec3::new(1.0, -2.0, 0.0)] {
            let rot = Rotation::from_axis_angle(axis, core::f32::consts::PI).unwrap();
            assert!(matches!(rot.euler, Euler::General { .. }), "{axis}");
            let (a, b) = both_paths(&rot, &input);
            assert!(
                a.max(b) <= f64::from(rotate_rel_error(30)),
                "{axis}: {a} {b}"
            );
        }
        // About x by π: (x, y, z) → (x, −y, −z); the exact signs, bit for bit.
        let rot = Rotation::new([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]).unwrap();
        let input = random_vector(10, 6);
        let mut out = vec![0.0; 100];
        rotate_zxzxz(&[], &rot, 10, &input, &mut out).unwrap();
        for l in 0..10usize {
            for m in -(l as isize)..=l as isize {
                let i = crate::sh::index(l, m);
                let s = if (l + m.unsigned_abs()) % 2 == 1 {
                    -1.0
                } else {
                    1.0
                };
                let s = if m < 0 { -s } else { s };
                assert_eq!(out[i], s * input[i], "l {l} m {m}");
            }
        }
    }

    #[test]
    fn tiny_angles_and_near_singular_euler_angles() {
        let input = random_vector(30, 8);
        let cases = [
            Rotation::from_axis_angle(Vec3::X, 1e-6).unwrap(),
            Rotation::from_axis_angle(Vec3::new(0.3, -0.2, 0.9), 1e-6).unwrap(),
            // β = 1e-6 with large α, γ: Rz(2)·Ry(1e-6)·Rz(−1.3).
            Rotation::from_dmat3(
                DMat3::from_rotation_z(2.0)
                    * DMat3::from_rotation_y(1e-6)
                    * DMat3::from_rotation_z(-1.3),
            )
            .unwrap(),
            // β = π − 1e-6.
            Rotation::from_dmat3(
                DMat3::from_rotation_z(0.4)
                    * DMat3::from_rotation_y(core::f64::consts::PI - 1e-6)
                    * DMat3::from_rotation_z(2.9),
            )
            .unwrap(),
            // β = 1e-12, below where α − γ is determined at all.
            Rotation::from_dmat3(
                DMat3::from_rotation_z(1.0)
                    * DMat3::from_rotation_x(1e-12)
                    * DMat3::from_rotation_z(0.5),
            )
            .unwrap(),
        ];
        for (k, rot) in cases.iter().enumerate() {
            let (a, b) = both_paths(rot, &input);
            println!("case {k}: operator {a:.2e}, zxzxz {b:.2e}");
            assert!(
                a.max(b) <= f64::from(rotate_rel_error(30)),
                "case {k}: {a} {b}"
            );
        }
    }

    #[test]
    fn matrices_that_are_not_rotations_are_refused() {
        let bad = [
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]], // reflection
            [[1.001, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], // scaling
            [[1.0, 0.01, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], // shear
            [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]], // inversion
            [[0.0; 3]; 3],
        ];
        for m in bad {
            assert!(
                matches!(Rotation::new(m), Err(Error::NotRotation { .. })),
                "{m:?}"
            );
        }
        let nan = [[f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(matches!(Rotation::new(nan), Err(Error::NonFinite { .. })));
        // Within the tolerance: accepted and made orthogonal.
        let near = [[1.0, 4e-6, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0 + 4e-6]];
        let r = Rotation::new(near).unwrap().matrix();
        let g = r.transpose() * r - DMat3::IDENTITY;
        assert!(g.abs().to_cols_array().iter().all(|&e| e < 1e-15));
        assert!(Rotation::from_axis_angle(Vec3::ZERO, 1.0).is_err());
    }

    #[test]
    fn shapes_are_errors_not_panics() {
        let rot = Rotation::identity();
        let mut out = vec![0.0; 8];
        assert!(bands_of(8).is_err());
        assert!(
            Rotator::new(2)
                .unwrap()
                .rotate(&rot, &[0.0; 8], &mut out)
                .is_err()
        );
        assert!(
            Rotator::new(2)
                .unwrap()
                .rotate(&rot, &[0.0; 9], &mut out)
                .is_err()
        );
        assert!(
            Rotator::new(2)
                .unwrap()
                .rotate(&rot, &[0.0; 4], &mut out)
                .is_ok()
        );
        assert!(apply_operator(&[1.0; 5], 2, &[0.0; 4], &mut out).is_err());
        assert!(operator_into(&rot, 3, &mut [0.0; 35], &mut [0.0; 50]).is_ok());
        assert!(operator_into(&rot, 3, &mut [0.0; 34], &mut [0.0; 50]).is_err());
        assert!(operator_into(&rot, 3, &mut [0.0; 35], &mut [0.0; 49]).is_err());
        assert!(Operator::new(&rot, crate::sh::MAX_BANDS + 1).is_err());
    }

    #[test]
    fn finite_and_orthogonal_through_100_bands() {
        let bands = 100;
        let rot = &random_rotations()[3];
        let op = Operator::new(rot, bands).unwrap();
        assert!(op.blocks().iter().all(|v| v.is_finite()));
        // Each block orthogonal: rows of unit norm (checked on a few bands).
        for l in [50usize, 99] {
            let w = 2 * l + 1;
            let b = &op.blocks()[operator_len(l)..operator_len(l + 1)];
            for i in 0..w {
                let n: f64 = b[i * w..i * w + w]
                    .iter()
                    .map(|&x| f64::from(x).powi(2))
                    .sum();
                assert!((n - 1.0).abs() < 1e-5, "l {l} row {i}: {n}");
            }
        }
        let input = random_vector(bands, 12);
        let mut a = vec![0.0; bands * bands];
        let mut b = vec![0.0; bands * bands];
        op.apply(&input, &mut a).unwrap();
        Rotator::new(bands)
            .unwrap()
            .rotate(rot, &input, &mut b)
            .unwrap();
        let e = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f32, f32::max);
        println!("100 bands: operator vs zxzxz {e:.2e}");
        assert!(e < 1.3e-6, "{e}");
    }
}
