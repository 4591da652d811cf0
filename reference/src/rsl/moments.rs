//! The coverage integral and first moments of a query square over a piecewise-constant
//! coverage map, texel by texel in `f64`: the reference of `steradian_core::rsl::vis_moments`.

/// `(f, m_u, m_v)` of the square with centre `c` and half-diagonal `r` (disk units, the map
/// spanning `[−1, 1]²` over `n × n` texels): `f` the mean coverage over the square, `m` the
/// coverage-weighted mean offset from the centre (disk units). Each texel contributes its
/// exact overlap area with the square, its moment taken at the overlap's centroid (exact for
/// a constant texel); outside the table counts as visible (coverage 1).
pub fn square_moments(n: usize, cov: &[f32], c: [f32; 2], r: f32) -> (f64, f64, f64) {
    let hn = 0.5 * n as f64;
    let h = f64::from(r) * core::f64::consts::FRAC_1_SQRT_2 * hn;
    let (cu, cv) = ((f64::from(c[0]) + 1.0) * hn, (f64::from(c[1]) + 1.0) * hn);
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
            let vis = if inside {
                f64::from(cov[j as usize * n + i as usize])
            } else {
                1.0
            };
            let (px, py) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
            s += a * vis;
            mx += a * vis * (px - cu);
            my += a * vis * (py - cv);
        }
    }
    let area = 4.0 * h * h;
    (s / area, mx / (area * hn), my / (area * hn))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_map_has_its_coverage_and_no_moment() {
        let cov = vec![0.25f32; 64];
        let (f, mx, my) = square_moments(8, &cov, [0.0, 0.0], 0.5);
        assert!((f - 0.25).abs() < 1e-15 && mx.abs() < 1e-15 && my.abs() < 1e-15);
    }

    #[test]
    fn half_plane_moment_is_a_quarter_of_the_half_side() {
        // Left half occluded: the visible half has its centroid at +s/2 (s the half-side),
        // weight ½, so m_u = s/4 with s = r/√2.
        let n = 16;
        let cov: Vec<f32> = (0..n * n)
            .map(|k| if k % n < n / 2 { 0.0 } else { 1.0 })
            .collect();
        let r = 0.5f32;
        let (f, mx, my) = square_moments(n, &cov, [0.0, 0.0], r);
        let s = r as f64 * core::f64::consts::FRAC_1_SQRT_2;
        assert!((f - 0.5).abs() < 1e-12, "{f}");
        assert!(
            (mx - 0.25 * s).abs() < 1e-12 && my.abs() < 1e-12,
            "{mx} {my}"
        );
    }
}
