//! Rotation of many coefficient vectors at once; lane `k` is vector `k`, and every lane is
//! **bit-identical** to the scalar kernel it mirrors, NaN included (a lane's special values
//! never reach another lane).
//!
//! - The built operator (one rotation for all vectors), eight vectors per pass, mirrors
//!   `steradian_core::sh::rotate::apply_operator`: every block entry is broadcast and
//!   multiplied into all eight, and each output sums its row left to right from `+0` like the
//!   scalar kernel.
//! - The ZXZXZ path (each vector its own rotation), four vectors per pass on `f64x4`, mirrors
//!   `steradian_core::sh::rotate::rotate_zxzxz`: the `J` entries are broadcast, the per-lane
//!   `(cos mθ, sin mθ)` chains and sums run with the scalar kernel's operations in its
//!   order. A lane whose rotation is about `z` or a half-turn takes the scalar kernel's exact
//!   path (sign flips and one `Z`), chosen per lane; the `J` products run only when some lane
//!   needs them.

use steradian_core::Error;
use steradian_core::sh::check_shape;
use steradian_core::sh::rotate::{Euler, Rotation, check_operator, operator_len};
use wide::{f32x8, f64x4};

/// `out[k][lane] = (M·input_lane)_k` over `bands` bands for the blocks `op` of
/// `steradian_core::sh::rotate::operator_into`: coefficient `k` of vector `lane` is
/// `input[k][lane]`.
///
/// Errors: `bands > MAX_BANDS`; `op`, `input` or `out` too short.
pub fn apply_operator_x8(
    op: &[f32],
    bands: usize,
    input: &[[f32; 8]],
    out: &mut [[f32; 8]],
) -> Result<(), Error> {
    check_shape(bands, input.len())?;
    check_shape(bands, out.len())?;
    check_operator(op, bands)?;
    for l in 0..bands {
        let w = 2 * l + 1;
        let block = &op[operator_len(l)..operator_len(l + 1)];
        band_x8(
            block,
            w,
            &input[l * l..l * l + w],
            &mut out[l * l..l * l + w],
        );
    }
    Ok(())
}

/// One band's block on eight vectors: `out[i] = Σ_j block[i·w + j]·x[j]`, left to right from
/// `+0` on every lane.
#[inline(always)]
fn band_x8(block: &[f32], w: usize, x: &[[f32; 8]], out: &mut [[f32; 8]]) {
    for (i, o) in out[..w].iter_mut().enumerate() {
        let mut acc = f32x8::splat(0.0);
        for (&a, xv) in block[i * w..i * w + w].iter().zip(&x[..w]) {
            acc += f32x8::splat(a) * f32x8::from(*xv);
        }
        *o = acc.to_array();
    }
}

/// [`apply_operator_x8`] over any number of vectors stored one after another
/// (`input[v·n² + k]` is coefficient `k` of vector `v`, `n² = bands²`), into `out` in the same
/// layout: eight vectors per pass, the tail padded with zeros and not written.
///
/// Errors: `input` or `out` not a whole number of vectors, lengths that differ, or the
/// shape errors of [`apply_operator_x8`].
pub fn apply_operator_slices(
    op: &[f32],
    bands: usize,
    input: &[f32],
    out: &mut [f32],
) -> Result<(), Error> {
    let vectors = batch_len(bands, input, out)?;
    if vectors == 0 {
        return Ok(());
    }
    check_operator(op, bands)?;
    let nn = bands * bands;
    // One band of eight vectors at a time, on the stack (at most 2·MAX_BANDS − 1 lanes).
    let mut lanes = [[0.0f32; 8]; 2 * steradian_core::sh::MAX_BANDS - 1];
    let mut res = [[0.0f32; 8]; 2 * steradian_core::sh::MAX_BANDS - 1];
    let mut v = 0;
    while v < vectors {
        let live = (vectors - v).min(8);
        for l in 0..bands {
            let w = 2 * l + 1;
            gather(input, nn, v, live, l, &mut lanes[..w]);
            band_x8(
                &op[operator_len(l)..operator_len(l + 1)],
                w,
                &lanes,
                &mut res,
            );
            scatter(&res[..w], nn, v, live, l, out);
        }
        v += 8;
    }
    Ok(())
}

// ---- The ZXZXZ path --------------------------------------------------------------------------

/// One band's `Z(θ)` on four lanes in place: the scalar `rotate_z` with each lane's own
/// `(cos θ, sin θ)`, the same products in the same order.
#[inline(always)]
fn rotate_z_x4(l: usize, cs: [f64x4; 2], band: &mut [f64x4]) {
    let (mut c, mut s) = (f64x4::ONE, f64x4::ZERO);
    for m in 1..=l {
        (c, s) = (c * cs[0] - s * cs[1], c * cs[1] + s * cs[0]);
        let (p, q) = (band[l + m], band[l - m]);
        band[l + m] = p * c - q * s;
        band[l - m] = p * s + q * c;
    }
}

/// `y = J·x` or `Jᵀ·x` for one band on four lanes: the scalar `apply_block`'s sums, each
/// from `+0` in input order, unfused. Outputs are formed in tiles of 8, 4, 2, 1 held in
/// registers while the inputs stream past; no output's order of summation changes.
#[inline(always)]
fn apply_block_x4<E: Copy + Into<f64>>(
    block: &[E],
    w: usize,
    transpose: bool,
    x: &[f64x4],
    y: &mut [f64x4],
) {
    let mut o = 0;
    while o < w {
        let left = w - o;
        o += if left >= 8 {
            block_tile_x4::<8, E>(block, w, transpose, o, x, y)
        } else if left >= 4 {
            block_tile_x4::<4, E>(block, w, transpose, o, x, y)
        } else if left >= 2 {
            block_tile_x4::<2, E>(block, w, transpose, o, x, y)
        } else {
            block_tile_x4::<1, E>(block, w, transpose, o, x, y)
        };
    }
}

/// Outputs `o..o + T` of [`apply_block_x4`]; returns `T`.
#[inline(always)]
fn block_tile_x4<const T: usize, E: Copy + Into<f64>>(
    block: &[E],
    w: usize,
    transpose: bool,
    o: usize,
    x: &[f64x4],
    y: &mut [f64x4],
) -> usize {
    let mut acc = [f64x4::ZERO; T];
    for (k, &xk) in x[..w].iter().enumerate() {
        for (r, a) in acc.iter_mut().enumerate() {
            // Entry (o + r, k) of J, or of Jᵀ (entry (k, o + r) of J).
            let e = if transpose {
                block[k * w + o + r]
            } else {
                block[(o + r) * w + k]
            };
            *a += f64x4::splat(e.into()) * xk;
        }
    }
    y[o..o + T].copy_from_slice(&acc);
    T
}

/// The four lanes' rotations split by path: the general lanes' `(cos, sin)` of `α, β, γ`
/// (`(1, 0)` elsewhere), the exact lanes' angle and half-turn flag, and which lanes are
/// general.
struct Lanes4 {
    alpha: [f64x4; 2],
    beta: [f64x4; 2],
    gamma: [f64x4; 2],
    exact: [f64x4; 2],
    half_turn: [bool; 4],
    general: [bool; 4],
}

impl Lanes4 {
    fn new(rots: [&Rotation; 4]) -> Self {
        let (mut g, mut exact) = ([[[1.0, 0.0]; 4]; 3], [[1.0, 0.0]; 4]);
        let (mut half_turn, mut general) = ([false; 4], [false; 4]);
        for (j, r) in rots.iter().enumerate() {
            match r.euler() {
                Euler::General { alpha, beta, gamma } => {
                    (g[0][j], g[1][j], g[2][j]) = (alpha, beta, gamma);
                    general[j] = true;
                }
                Euler::AboutZ(t) => exact[j] = t,
                Euler::HalfTurn(t) => (exact[j], half_turn[j]) = (t, true),
            }
        }
        let lanes = |v: [[f64; 2]; 4]| [f64x4::new(v.map(|c| c[0])), f64x4::new(v.map(|c| c[1]))];
        Lanes4 {
            alpha: lanes(g[0]),
            beta: lanes(g[1]),
            gamma: lanes(g[2]),
            exact: lanes(exact),
            half_turn,
            general,
        }
    }
}

/// `out[k][lane] = (M(rots[lane])·input_lane)_k` over `bands` bands by ZXZXZ with the table
/// `x90` of `steradian_core::sh::rotate::x90_into`, lane-wise
/// `steradian_core::sh::rotate::rotate_zxzxz`, bit-identical: coefficient `k` of vector
/// `lane` is `input[k][lane]`.
///
/// Errors: `bands > MAX_BANDS`; `input` or `out` too short; `x90` too short when some lane's
/// rotation needs it (as the scalar kernel).
pub fn rotate_zxzxz_x4(
    x90: &[f32],
    rots: [&Rotation; 4],
    bands: usize,
    input: &[[f32; 4]],
    out: &mut [[f32; 4]],
) -> Result<(), Error> {
    check_shape(bands, input.len())?;
    check_shape(bands, out.len())?;
    let lanes = Lanes4::new(rots);
    if lanes.general.contains(&true) {
        check_operator(x90, bands)?;
    }
    const W: usize = 2 * steradian_core::sh::MAX_BANDS - 1;
    let mut bufs = [[f64x4::ZERO; W]; 3];
    for l in 0..bands {
        zxzxz_band_x4(
            x90,
            &lanes,
            l,
            &input[l * l..],
            &mut out[l * l..],
            &mut bufs,
            None,
        );
    }
    Ok(())
}

/// One band of [`rotate_zxzxz_x4`]: `input[..2l+1]` to `out[..2l+1]`.
#[inline(always)]
fn zxzxz_band_x4(
    x90: &[f32],
    lanes: &Lanes4,
    l: usize,
    input: &[[f32; 4]],
    out: &mut [[f32; 4]],
    [a, b, e]: &mut [[f64x4; 2 * steradian_core::sh::MAX_BANDS - 1]; 3],
    widened: Option<&mut [f64]>,
) {
    let w = 2 * l + 1;
    for (t, v) in a[..w].iter_mut().zip(&input[..w]) {
        *t = f64x4::new(v.map(f64::from));
    }
    let any_exact = lanes.general.contains(&false);
    if any_exact {
        // M(Ry(π)): (−1)^l, and −1 more for m < 0, on the half-turn lanes; ×1 (exact) on
        // the others.
        let sl = if l % 2 == 1 { -1.0 } else { 1.0 };
        let flip = |below: bool| {
            let s = if below { -sl } else { sl };
            f64x4::new(lanes.half_turn.map(|h| if h { s } else { 1.0 }))
        };
        let (low, high) = (flip(true), flip(false));
        for (i, (t, &v)) in e[..w].iter_mut().zip(&a[..w]).enumerate() {
            *t = v * if i < l { low } else { high };
        }
        rotate_z_x4(l, lanes.exact, e);
    }
    if lanes.general.contains(&true) {
        let block = &x90[operator_len(l)..operator_len(l + 1)];
        rotate_z_x4(l, lanes.gamma, a);
        if let Some(widened) = widened.filter(|b| b.len() >= w * w) {
            // The block widened to f64 once for both products: the same values, and each
            // entry's broadcast is then a plain load.
            for (d, &s) in widened.iter_mut().zip(block) {
                *d = f64::from(s);
            }
            apply_block_x4(&widened[..w * w], w, false, a, b);
            rotate_z_x4(l, lanes.beta, b);
            apply_block_x4(&widened[..w * w], w, true, b, a);
        } else {
            apply_block_x4(block, w, false, a, b);
            rotate_z_x4(l, lanes.beta, b);
            apply_block_x4(block, w, true, b, a);
        }
        rotate_z_x4(l, lanes.alpha, a);
    }
    for (k, o) in out[..w].iter_mut().enumerate() {
        let (g, x) = (a[k].to_array(), e[k].to_array());
        *o = core::array::from_fn(|j| (if lanes.general[j] { g[j] } else { x[j] }) as f32);
    }
}

/// [`rotate_zxzxz_x4`] over any number of vectors stored one after another
/// (`input[v·n² + k]` is coefficient `k` of vector `v`, `n² = bands²`), vector `v` rotated
/// by `rots[v]`, into `out` in the same layout: four vectors per pass, the tail padded with
/// zero vectors and the identity and not written.
///
/// Errors: `input` not a whole number of vectors, `out` of another length, `rots` not one
/// per vector, or the errors of [`rotate_zxzxz_x4`].
pub fn rotate_zxzxz_slices(
    x90: &[f32],
    rots: &[Rotation],
    bands: usize,
    input: &[f32],
    out: &mut [f32],
) -> Result<(), Error> {
    let vectors = batch_len(bands, input, out)?;
    if vectors == 0 {
        return Ok(());
    }
    if rots.len() != vectors {
        return Err(Error::OutOfRange {
            what: "rotations of a batch (one per vector)",
            value: rots.len() as f32,
            min: vectors as f32,
            max: vectors as f32,
        });
    }
    let nn = bands * bands;
    if rots
        .iter()
        .any(|r| matches!(r.euler(), Euler::General { .. }))
    {
        check_operator(x90, bands)?;
    }
    const W: usize = 2 * steradian_core::sh::MAX_BANDS - 1;
    let mut bufs = [[f64x4::ZERO; W]; 3];
    let mut lanes_in = [[0.0f32; 4]; W];
    let mut lanes_out = [[0.0f32; 4]; W];
    let identity = Rotation::identity();
    // Room for one band's block widened to f64 (up to 32 bands, w ≤ 63), rewritten by each
    // pass for both of its products; beyond, the f32 block is read directly.
    let mut widened = [0.0f64; 63 * 63];
    let mut v = 0;
    while v < vectors {
        let live = (vectors - v).min(4);
        let lanes = Lanes4::new(core::array::from_fn(|j| {
            if j < live { &rots[v + j] } else { &identity }
        }));
        for l in 0..bands {
            let w = 2 * l + 1;
            gather(input, nn, v, live, l, &mut lanes_in[..w]);
            zxzxz_band_x4(
                x90,
                &lanes,
                l,
                &lanes_in,
                &mut lanes_out,
                &mut bufs,
                Some(&mut widened),
            );
            scatter(&lanes_out[..w], nn, v, live, l, out);
        }
        v += 4;
    }
    Ok(())
}

// ---- Batches of vectors ----------------------------------------------------------------------

/// The number of `bands²`-long vectors in `input`, checked: `bands ≤ MAX_BANDS`, `input` a
/// whole number of vectors and `out` as long (0 for 0 bands).
fn batch_len(bands: usize, input: &[f32], out: &[f32]) -> Result<usize, Error> {
    check_shape(bands, usize::MAX)?;
    let nn = bands * bands;
    if nn == 0 {
        return Ok(0);
    }
    if !input.len().is_multiple_of(nn) || out.len() != input.len() {
        return Err(Error::OutOfRange {
            what: "rotation batch length (a whole number of n² vectors, out as long as in)",
            value: input.len() as f32,
            min: 0.0,
            max: f32::INFINITY,
        });
    }
    Ok(input.len() / nn)
}

/// Band `l` of vectors `v .. v + live` (each `nn` long, one after another in `input`) into
/// lanes: `lanes[k][j]` is coefficient `l² + k` of vector `v + j`, zero beyond `live`.
#[inline(always)]
fn gather<const N: usize>(
    input: &[f32],
    nn: usize,
    v: usize,
    live: usize,
    l: usize,
    lanes: &mut [[f32; N]],
) {
    for (k, lane) in lanes.iter_mut().enumerate() {
        *lane = core::array::from_fn(|j| {
            if j < live {
                input[(v + j) * nn + l * l + k]
            } else {
                0.0
            }
        });
    }
}

/// The inverse of [`gather`] for the `live` lanes: `lanes[k][j]` to coefficient `l² + k` of
/// vector `v + j` in `out`.
#[inline(always)]
fn scatter<const N: usize>(
    lanes: &[[f32; N]],
    nn: usize,
    v: usize,
    live: usize,
    l: usize,
    out: &mut [f32],
) {
    for (k, r) in lanes.iter().enumerate() {
        for (j, &value) in r.iter().enumerate().take(live) {
            out[(v + j) * nn + l * l + k] = value;
        }
    }
}
