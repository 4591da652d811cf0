//! Texel-grid helpers shared by the grid-based kernels of the rotatable-square-lights paper
//! (`rsl::sat`, `rsl::vdt`, `rsl::visibility`): the shape checks of their constructors and
//! the exact coverage of a square by a straight edge.

use crate::Error;
use crate::math;

/// `Err` unless `1 ≤ n ≤ max`: a grid side.
pub(crate) fn check_side(what: &'static str, n: usize, max: usize) -> Result<(), Error> {
    if n == 0 || n > max {
        return Err(Error::OutOfRange {
            what,
            value: n as f32,
            min: 1.0,
            max: max as f32,
        });
    }
    Ok(())
}

/// `Err` unless a slice length `got` is exactly `want` (`what` names the slice); the one
/// length check of the kernels, their SIMD twins included.
pub fn check_len(what: &'static str, got: usize, want: usize) -> Result<(), Error> {
    if got != want {
        return Err(Error::OutOfRange {
            what,
            value: got as f32,
            min: want as f32,
            max: want as f32,
        });
    }
    Ok(())
}

/// `a·b`, or `Err` where it overflows `usize` (sides of up to `2²⁴` can only overflow a
/// `usize` narrower than 64 bits).
pub(crate) fn checked_product(what: &'static str, a: usize, b: usize) -> Result<usize, Error> {
    a.checked_mul(b).ok_or(Error::OutOfRange {
        what,
        value: f32::INFINITY,
        min: 1.0,
        max: usize::MAX as f32,
    })
}

/// Below this, the smaller normal component `q` of the straight-edge fraction is treated as
/// this in the divisions of the two corner pieces (whose numerators are then at most `4q²`,
/// so the result is the exact limit `q → 0` to within `q/2`).
pub const Q_MIN: f32 = 1.0e-20;

/// The exact fraction of the square `[−1, 1]²` on the side `x·nx + y·ny ≥ −t` of a straight
/// line, for a normal `(nx, ny)` (any length, not both zero: it is normalised here; a zero
/// normal falls back to `(1, 0)`) and `t` the signed distance of the line from the centre in
/// units of the half-side (`t > 0`: the centre is on the visible side).
///
/// With `q = min(|nx|, |ny|)/max(|nx|, |ny|)` and `T = t·√(1 + q²)` clamped to `±(1 + q)`
/// (`X = x + q·y` has a trapezoidal density on `[−1−q, 1+q]`):
///
/// ```text
/// T ≤ q − 1:  (T + 1 + q)²/(8q)
/// T ≥ 1 − q:  1 − (1 + q − T)²/(8q)
/// otherwise:  (T + 1)/2
/// ```
///
/// the divisions by `max(q, `[`Q_MIN`]`)`. Within a few `f32` ulps of the exact fraction
/// (harness test against `f64` polygon clipping). NaN `t` gives NaN; `±∞` gives 1 or 0.
#[inline(always)]
pub fn square_halfplane_fraction(t: f32, nx: f32, ny: f32) -> f32 {
    let (ax, ay) = (nx.abs(), ny.abs());
    let m = ax.max(ay);
    let q = if m > 0.0 { ax.min(ay) / m } else { 0.0 };
    edge_fraction(t, q)
}

/// [`square_halfplane_fraction`] after the normal has been reduced to `q ∈ [0, 1]`.
#[inline(always)]
fn edge_fraction(t: f32, q: f32) -> f32 {
    let len = math::sqrtf(1.0 + q * q);
    let hi = 1.0 + q;
    let tt = (t * len).clamp(-hi, hi);
    let den = 8.0 * q.max(Q_MIN);
    // All three pieces, then a choice (compiled to selects, not branches: random queries
    // fall on all three).
    let lo_e = tt + hi;
    let lo_v = lo_e * lo_e / den;
    let hi_e = hi - tt;
    let hi_v = 1.0 - hi_e * hi_e / den;
    let mid = (tt + 1.0) * 0.5;
    let r = if tt >= 1.0 - q { hi_v } else { mid };
    if tt <= q - 1.0 { lo_v } else { r }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f32::consts::SQRT_2;

    #[test]
    fn halfplane_fraction_limits() {
        assert_eq!(square_halfplane_fraction(0.0, 0.3, -0.7), 0.5);
        assert_eq!(square_halfplane_fraction(10.0, 1.0, 1.0), 1.0);
        assert_eq!(square_halfplane_fraction(-10.0, 1.0, 1.0), 0.0);
        assert_eq!(square_halfplane_fraction(0.5, 0.0, 0.0), 0.75);
        // Diagonal: the corner triangle beyond distance t = 1/√2·(…): at t = 0 on the
        // diagonal, ½; at the corner (t = −√2) 0.
        assert_eq!(square_halfplane_fraction(-1.5, 1.0, 1.0), 0.0);
        assert!(square_halfplane_fraction(-SQRT_2, 1.0, 1.0) < 1e-6);
        assert!(square_halfplane_fraction(f32::NAN, 1.0, 0.0).is_nan());
        assert_eq!(square_halfplane_fraction(f32::INFINITY, 1.0, 0.2), 1.0);
    }
}
