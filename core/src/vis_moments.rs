//! Visibility moment tables: the visible fraction **and the first moment of the visible
//! part** of any square, from three exact summed-area tables of a binary visibility map.
//! An extension of the rotatable-square-lights shading (section 3, eq. 5), not in the
//! paper; [`crate::shade::shade_moments`] uses it.
//!
//! ## Why
//!
//! Eq. 5 replaces `∫_R ρ·V` over a light's square `R` by `ρ̄·V̄·|R|`. The error is the
//! covariance of `ρ` and `V` over `R` (eq. 13's `u_L·σ_V·σ_ρ` term): large for the big,
//! partly shadowed squares of a sky, where the cosine-weighted BRDF changes by a factor of
//! two across the square. With `ρ` linear over the square, `φ(x) ≈ φ̄ + g·(x − c)` (a
//! density per unit parametrisation area, [`crate::shade::BrdfIntegral::integral_gradient`]),
//!
//! ```text
//!   ∫_R φ·V dA ≈ φ̄·∫_R V dA + g·∫_R (x − c)·V dA = I·f + g·|R|·m,
//!   f = (1/|R|)∫_R V dA,   m = (1/|R|)∫_R (x − c)·V dA,
//! ```
//!
//! exact for a linear `φ` and any visibility. `f` and `m` are box sums of `V`, `u·V` and
//! `v·V`: three summed-area tables ([`crate::sat`], exact `i64` fixed point), twelve
//! lookups for integer corners and up to 48 for fractional ones.
//!
//! ## Grid, units, accuracy
//!
//! The map is `n × n` over the parametrisation square `[−1, 1]²` (texel `(i, j)` covers
//! `[i, i+1]×[j, j+1]` in texel units, as [`crate::vdt`] and [`crate::visibility`]),
//! `true` = visible. The moment tables hold `(i + ½ − n/2)·V` and `(j + ½ − n/2)·V`: each
//! texel's moment is taken at its centre, so a fractionally covered texel's moment is off
//! by at most half a texel times its covered area (the only approximation beyond the
//! map's rasterisation; the box sums themselves are exact to `f64` rounding,
//! [`crate::sat::SatView::box_sum_f64`]). Outside the table counts as visible (as
//! [`crate::visibility::Outside::Visible`]: it is below the horizon, where the
//! cosine-weighted BRDF is 0). Queries take the centre and half-diagonal in disk units, as
//! [`crate::shade::SquareVisibility`]; `m` is returned in disk units.
//!
//! **Cost:** three tables of `(n + 1)²` `i64` entries, 1.6 MB at `n = 256` (the VDT: 256 KB).
//!
//! **Bad input.** Construction validates the size; NaN in a query gives NaN; a zero or
//! negative half-diagonal (an empty square) gives `f = 1`, `m = 0`. Nothing panics.

use alloc::vec::Vec;

use crate::sat::Sat;
use crate::{Error, Vec2};

/// Three exact summed-area tables of a visibility map: `V`, `u·V`, `v·V` (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct VisMoments {
    n: usize,
    v: Sat,
    xv: Sat,
    yv: Sat,
}

impl VisMoments {
    /// The tables of an `n × n` map, row-major (`mask[j·n + i]`, `true` = visible).
    /// Errors: `n` outside the SAT's range or `mask.len() ≠ n²`.
    pub fn build(n: usize, mask: &[bool]) -> Result<VisMoments, Error> {
        let len = n.checked_mul(n).ok_or(Error::OutOfRange {
            what: "visibility map side",
            value: n as f32,
            min: 1.0,
            max: crate::sat::MAX_SIDE as f32,
        })?;
        crate::sat::check_len("visibility map length", mask.len(), len)?;
        let half = 0.5 * n as f32;
        let mut v = Vec::with_capacity(len);
        let mut xv = Vec::with_capacity(len);
        let mut yv = Vec::with_capacity(len);
        for (j, row) in mask.chunks(n.max(1)).enumerate() {
            for (i, &m) in row.iter().enumerate() {
                let w = if m { 1.0f32 } else { 0.0 };
                v.push(w);
                // Exact in f32: n ≤ 2^24 and the offsets are multiples of ½.
                xv.push(w * (i as f32 + 0.5 - half));
                yv.push(w * (j as f32 + 0.5 - half));
            }
        }
        Ok(VisMoments {
            n,
            v: Sat::build(n, n, &v)?,
            xv: Sat::build(n, n, &xv)?,
            yv: Sat::build(n, n, &yv)?,
        })
    }

    /// Side of the map.
    pub fn side(&self) -> usize {
        self.n
    }

    /// Bytes of the three tables.
    pub fn bytes(&self) -> usize {
        self.v.bytes() + self.xv.bytes() + self.yv.bytes()
    }

    /// `(f, m)` of the square with centre `centre` and half-diagonal `half_diagonal` (disk
    /// units): the visible fraction and the mean of `(x − c)·V` over the square (module
    /// docs), `f ∈ [0, 1]`, `|m| ≤ half-side`.
    pub fn moments(&self, centre: Vec2, half_diagonal: f32) -> (f32, Vec2) {
        if centre.is_nan() || half_diagonal.is_nan() {
            return (f32::NAN, Vec2::NAN);
        }
        let hn = 0.5 * self.n as f64;
        let h = f64::from(crate::sat::square_half_side(half_diagonal)) * hn;
        if h <= 0.0 {
            return (1.0, Vec2::ZERO);
        }
        let cu = (f64::from(centre.x) + 1.0) * hn;
        let cv = (f64::from(centre.y) + 1.0) * hn;
        let (u0, u1, v0, v1) = (cu - h, cu + h, cv - h, cv + h);
        let (v, xv, yv) = (self.v.view(), self.xv.view(), self.yv.view());
        let q =
            |t: &crate::sat::SatView<'_>| t.box_sum_f64(u0 as f32, v0 as f32, u1 as f32, v1 as f32);
        let (sv, sx, sy) = (q(&v), q(&xv), q(&yv));
        // The part of the square inside the table, and its centroid.
        let n = self.n as f64;
        let (a0, a1) = (u0.clamp(0.0, n), u1.clamp(0.0, n));
        let (b0, b1) = (v0.clamp(0.0, n), v1.clamp(0.0, n));
        let area = 4.0 * h * h;
        let area_in = (a1 - a0) * (b1 - b0);
        // ∫_in (x − c)·V: the tables measure x from the table centre hn.
        let mx_in = sx - (cu - hn) * sv;
        let my_in = sy - (cv - hn) * sv;
        // Outside is visible: ∫_out (x − c) = −∫_in (x − c) (the whole square's is 0).
        let mx_out = -area_in * (0.5 * (a0 + a1) - cu);
        let my_out = -area_in * (0.5 * (b0 + b1) - cv);
        let f = ((sv + (area - area_in)) / area).clamp(0.0, 1.0);
        let to_disk = 1.0 / (area * hn);
        let m = Vec2::new(
            ((mx_in + mx_out) * to_disk) as f32,
            ((my_in + my_out) * to_disk) as f32,
        );
        (f as f32, m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Texel by texel: the exact overlap of each texel with the square, its moment at the
    /// texel centre inside the table and at the overlap's centroid outside (the
    /// definitions of the module docs), in f64.
    fn brute(n: usize, mask: &[bool], c: Vec2, r: f32) -> (f64, f64, f64) {
        let hn = 0.5 * n as f64;
        let h = f64::from(r) * core::f64::consts::FRAC_1_SQRT_2 * hn;
        let (cu, cv) = ((f64::from(c.x) + 1.0) * hn, (f64::from(c.y) + 1.0) * hn);
        let (mut s, mut mx, mut my) = (0.0, 0.0, 0.0);
        let lo = |x: f64| x.floor() as i64;
        for j in lo(cv - h)..=lo(cv + h) {
            for i in lo(cu - h)..=lo(cu + h) {
                let (x0, x1) = ((i as f64).max(cu - h), ((i + 1) as f64).min(cu + h));
                let (y0, y1) = ((j as f64).max(cv - h), ((j + 1) as f64).min(cv + h));
                if x1 <= x0 || y1 <= y0 {
                    continue;
                }
                let a = (x1 - x0) * (y1 - y0);
                let inside = i >= 0 && j >= 0 && (i as usize) < n && (j as usize) < n;
                let (vis, px, py) = if inside {
                    (
                        mask[j as usize * n + i as usize],
                        i as f64 + 0.5,
                        j as f64 + 0.5,
                    )
                } else {
                    (true, 0.5 * (x0 + x1), 0.5 * (y0 + y1))
                };
                if vis {
                    s += a;
                    mx += a * (px - cu);
                    my += a * (py - cv);
                }
            }
        }
        let area = 4.0 * h * h;
        (s / area, mx / (area * hn), my / (area * hn))
    }

    #[test]
    fn matches_brute_force_on_a_disc_and_a_half_plane() {
        let n = 32;
        let mask: Vec<bool> = (0..n * n)
            .map(|k| {
                let (i, j) = ((k % n) as f64 + 0.5, (k / n) as f64 + 0.5);
                let disc = (i - 12.0).powi(2) + (j - 18.0).powi(2) < 49.0;
                let half = i + 0.4 * j > 26.0;
                !(disc || half)
            })
            .collect();
        let t = VisMoments::build(n, &mask).unwrap();
        assert_eq!(t.bytes(), 3 * 33 * 33 * 8);
        // centres include the pole, the table edge (horizon) and beyond it
        for (c, r) in [
            (Vec2::new(0.0, 0.0), 0.3),
            (Vec2::new(-0.2, 0.15), 0.55),
            (Vec2::new(0.31, -0.4), 0.05),
            (Vec2::new(0.9, 0.95), 0.4),
            (Vec2::new(-1.1, 0.2), 0.3),
            (Vec2::new(0.0, 0.0), 3.0),
        ] {
            let (f, m) = t.moments(c, r);
            let (bf, bx, by) = brute(n, &mask, c, r);
            let h = f64::from(r) * core::f64::consts::FRAC_1_SQRT_2;
            // f32 corners and results: a few f32 ulps of 1 and of the half-side
            assert!((f64::from(f) - bf).abs() < 1e-6, "{c} {r}: f {f} vs {bf}");
            assert!(
                (f64::from(m.x) - bx).abs() < 1e-6 * h,
                "{c} {r}: mx {} vs {bx}",
                m.x
            );
            assert!(
                (f64::from(m.y) - by).abs() < 1e-6 * h,
                "{c} {r}: my {} vs {by}",
                m.y
            );
        }
    }

    #[test]
    fn all_visible_has_no_moment_and_bad_input_is_nan() {
        let t = VisMoments::build(8, &[true; 64]).unwrap();
        // a square on texel edges (half-side 0.5 = two texels): no centre-moment error
        let (f, m) = t.moments(Vec2::new(0.25, -0.5), 0.5 * core::f32::consts::SQRT_2);
        assert!((f - 1.0).abs() < 1e-6 && m.length() < 1e-6, "{f} {m}");
        // partly outside the table (below the horizon), which counts as visible
        let (f, m) = t.moments(Vec2::new(0.9, -0.95), 0.4);
        assert!((f - 1.0).abs() < 1e-6 && m.length() < 0.02, "{f} {m}");
        let (f, m) = t.moments(Vec2::new(f32::NAN, 0.0), 0.1);
        assert!(f.is_nan() && m.is_nan());
        assert_eq!(t.moments(Vec2::ZERO, -1.0), (1.0, Vec2::ZERO));
        assert!(VisMoments::build(8, &[true; 63]).is_err());
        // all occluded, square inside the table: f = 0, m = 0
        let t = VisMoments::build(8, &[false; 64]).unwrap();
        let (f, m) = t.moments(Vec2::new(0.1, 0.1), 0.4);
        assert!(f.abs() < 1e-6 && m.length() < 1e-6, "{f} {m}");
    }
}
