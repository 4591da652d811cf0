//! The built rotation operator applied to eight coefficient vectors at once (mirrors
//! `steradian_core::sh::rotate::apply_operator`): lane `k` is vector `k`, every block entry is
//! broadcast and multiplied into all eight, and each output sums its row left to right from
//! `+0` like the scalar kernel, so every lane is **bit-identical** to it, NaN included (a
//! lane's special values never reach another lane).

use steradian_core::Error;
use steradian_core::sh::check_shape;
use steradian_core::sh::rotate::{check_operator, operator_len};
use wide::f32x8;

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
    check_shape(bands, usize::MAX)?;
    let nn = bands * bands;
    if nn == 0 {
        return Ok(());
    }
    if !input.len().is_multiple_of(nn) || out.len() != input.len() {
        return Err(Error::OutOfRange {
            what: "rotation batch length (a whole number of n² vectors, out as long as in)",
            value: input.len() as f32,
            min: 0.0,
            max: f32::INFINITY,
        });
    }
    check_operator(op, bands)?;
    let vectors = input.len() / nn;
    // One band of eight vectors at a time, on the stack (at most 2·MAX_BANDS − 1 lanes).
    let mut lanes = [[0.0f32; 8]; 2 * steradian_core::sh::MAX_BANDS - 1];
    let mut res = [[0.0f32; 8]; 2 * steradian_core::sh::MAX_BANDS - 1];
    let mut v = 0;
    while v < vectors {
        let live = (vectors - v).min(8);
        for l in 0..bands {
            let w = 2 * l + 1;
            for (k, lane) in lanes[..w].iter_mut().enumerate() {
                *lane = core::array::from_fn(|j| {
                    if j < live {
                        input[(v + j) * nn + l * l + k]
                    } else {
                        0.0
                    }
                });
            }
            band_x8(
                &op[operator_len(l)..operator_len(l + 1)],
                w,
                &lanes,
                &mut res,
            );
            for (k, r) in res[..w].iter().enumerate() {
                for (j, &value) in r.iter().enumerate().take(live) {
                    out[(v + j) * nn + l * l + k] = value;
                }
            }
        }
        v += 8;
    }
    Ok(())
}
