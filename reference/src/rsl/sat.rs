//! Box integrals of a piecewise-constant texel grid, by brute force in `f64`: the reference
//! of `steradian_core::rsl::sat` (texel `(i, j)` covers `[i, i+1]×[j, j+1]`, row-major).

/// `f64` length of `[lo, hi] ∩ [i, i + 1]` with the interval first clipped to `[0, n]`
/// (corners in either order).
pub fn overlap(c0: f32, c1: f32, n: usize, i: usize) -> f64 {
    let (lo, hi) = (c0.min(c1) as f64, c0.max(c1) as f64);
    let (lo, hi) = (lo.clamp(0.0, n as f64), hi.clamp(0.0, n as f64));
    (hi.min(i as f64 + 1.0) - lo.max(i as f64)).max(0.0)
}

/// `∫_B t = Σ t(i,j)·overlap_u(i)·overlap_v(j)` over the box with corners `(u0, v0)`,
/// `(u1, v1)` (either order; clipped to the table; NaN for a NaN corner). `O(w·h)`.
#[allow(clippy::too_many_arguments)]
pub fn box_integral(w: usize, h: usize, t: &[f32], u0: f32, v0: f32, u1: f32, v1: f32) -> f64 {
    if [u0, v0, u1, v1].iter().any(|c| c.is_nan()) {
        return f64::NAN;
    }
    let mut s = 0.0;
    for j in 0..h {
        let wy = overlap(v0, v1, h, j);
        if wy == 0.0 {
            continue;
        }
        let mut row = 0.0;
        for i in 0..w {
            let wx = overlap(u0, u1, w, i);
            if wx != 0.0 {
                row += t[j * w + i] as f64 * wx;
            }
        }
        s += row * wy;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_table_is_the_sum_and_half_a_texel_is_half() {
        let t = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        assert_eq!(box_integral(3, 2, &t, 0.0, 0.0, 3.0, 2.0), 21.0);
        assert_eq!(box_integral(3, 2, &t, 3.0, 2.0, 0.0, 0.0), 21.0);
        assert_eq!(box_integral(3, 2, &t, 0.5, 0.0, 1.0, 1.0), 0.5);
        assert_eq!(box_integral(3, 2, &t, -9.0, -9.0, 0.0, 9.0), 0.0);
        assert!(box_integral(3, 2, &t, f32::NAN, 0.0, 1.0, 1.0).is_nan());
    }
}
