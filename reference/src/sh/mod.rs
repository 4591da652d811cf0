//! References for the spherical-harmonics kernels (`steradian_core::sh`), in `f64` and by a
//! different route than the kernels: spherical angles from `atan2`/`acos`, the unnormalised
//! associated Legendre recurrence with the Condon–Shortley phase, normalisation by
//! factorials (as log-sums), `cos(mφ)` and `sin(mφ)` from `libm`.
//!
//! Valid while `(2m − 1)!!` fits in an `f64` (through about 150 bands).
//!
//! # References
//!
//! Those of `steradian_core::sh` (the HVL paper, eq. 7–8).

pub mod hvl;

use std::f64::consts::PI;

/// `ln k!`.
fn ln_factorial(k: usize) -> f64 {
    (2..=k).map(|i| (i as f64).ln()).sum()
}

/// The unnormalised `P_l^m(z)` with the Condon–Shortley phase, `m ≤ l`.
pub fn legendre(l: usize, m: usize, z: f64) -> f64 {
    let s = (1.0 - z * z).max(0.0).sqrt();
    // P_m^m = (−1)^m (2m−1)!! s^m
    let mut pmm = 1.0;
    for k in 1..=m {
        pmm *= -((2 * k - 1) as f64) * s;
    }
    if l == m {
        return pmm;
    }
    let mut p1 = (2 * m + 1) as f64 * z * pmm;
    if l == m + 1 {
        return p1;
    }
    let mut p2 = pmm;
    for ll in m + 2..=l {
        let p = ((2 * ll - 1) as f64 * z * p1 - (ll + m - 1) as f64 * p2) / (ll - m) as f64;
        (p2, p1) = (p1, p);
    }
    p1
}

/// `K_l^m = √((2l+1)/(4π)·(l−m)!/(l+m)!)`.
pub fn normalisation(l: usize, m: usize) -> f64 {
    ((2 * l + 1) as f64 / (4.0 * PI)).sqrt()
        * (0.5 * (ln_factorial(l - m) - ln_factorial(l + m))).exp()
}

/// All `bands²` real SH at the direction `d` (normalised here), index `l² + l + m`.
pub fn eval(d: [f64; 3], bands: usize) -> Vec<f64> {
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let (x, y, z) = (d[0] / n, d[1] / n, d[2] / n);
    let phi = libm::atan2(y, x);
    let z = z.clamp(-1.0, 1.0);
    let mut out = vec![0.0; bands * bands];
    for l in 0..bands {
        for m in 0..=l {
            let v = normalisation(l, m) * legendre(l, m, z);
            let c = l * l + l;
            if m == 0 {
                out[c] = v;
            } else {
                let r = std::f64::consts::SQRT_2 * v;
                out[c + m] = r * libm::cos(m as f64 * phi);
                out[c - m] = r * libm::sin(m as f64 * phi);
            }
        }
    }
    out
}

/// The zonal coefficients `∫_cap Y_l^0 dω`, `l < bands`, of the cap of half-angle `a`
/// around `+z`, by Gauss–Kronrod quadrature of `2π·K_l^0·∫_0^a P_l(cos θ)·sin θ dθ` over
/// panels a quarter of an oscillation wide (not the closed form the kernel uses).
pub fn cap_zonal(a: f64, bands: usize) -> Vec<f64> {
    let panels = (((bands + 1) as f64 * a / PI * 4.0).ceil() as usize).max(1);
    (0..bands)
        .map(|l| {
            let mut f = |t: f64| legendre(l, 0, t.cos()) * t.sin();
            let w = a / panels as f64;
            let i: f64 = (0..panels)
                .map(|k| crate::quad::gk15(&mut f, k as f64 * w, (k + 1) as f64 * w).0)
                .sum();
            2.0 * PI * normalisation(l, 0) * i
        })
        .collect()
}

/// `A_l = 2π·∫_0^1 t·P_l(t) dt` by Gauss–Kronrod quadrature (panels of width 1/(l + 1)).
pub fn clamped_cosine(l: usize) -> f64 {
    let panels = l + 1;
    let w = 1.0 / panels as f64;
    let mut f = |t: f64| t * legendre(l, 0, t);
    2.0 * PI
        * (0..panels)
            .map(|k| crate::quad::gk15(&mut f, k as f64 * w, (k + 1) as f64 * w).0)
            .sum::<f64>()
}

/// `∫ L(ω)·max(n·ω, 0) dω` for the radiance with SH coefficients `coeffs` (`bands²`), by
/// quadrature in the frame of `n`: Gauss–Kronrod in `t = n·ω` over 8 panels of `[0, 1]`
/// and the midpoint rule over 128 azimuths (exact for band-limited radiance below 60 bands).
pub fn irradiance(coeffs: &[f64], n: [f64; 3]) -> f64 {
    let bands = (coeffs.len() as f64).sqrt().round() as usize;
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let nz = [n[0] / len, n[1] / len, n[2] / len];
    let (t1, t2) = crate::perpendiculars(nz);
    let nphi = 128;
    let mut ring = |t: f64| {
        let s = (1.0 - t * t).max(0.0).sqrt();
        let mut acc = 0.0;
        for j in 0..nphi {
            let p = (j as f64 + 0.5) * 2.0 * PI / nphi as f64;
            let (c, sn) = (p.cos(), p.sin());
            let d: [f64; 3] = std::array::from_fn(|i| s * (c * t1[i] + sn * t2[i]) + t * nz[i]);
            let y = eval(d, bands);
            acc += y.iter().zip(coeffs).map(|(y, c)| y * c).sum::<f64>();
        }
        t * acc * 2.0 * PI / nphi as f64
    };
    let panels = 8;
    let w = 1.0 / panels as f64;
    (0..panels)
        .map(|k| crate::quad::gk15(&mut ring, k as f64 * w, (k + 1) as f64 * w).0)
        .sum()
}

/// A product quadrature on the sphere exact for every product of two functions of
/// `bands` bands: Gauss–Legendre in `z` with `bands` nodes (degree `2·bands − 1`) times
/// `2·bands` equispaced azimuths (trigonometric degree `< 2·bands`). `(direction, weight)`.
pub fn exact_grid(bands: usize) -> Vec<([f64; 3], f64)> {
    let (zs, ws) = crate::quad::gauss_legendre(bands.max(1));
    let nphi = 2 * bands.max(1);
    let mut out = Vec::with_capacity(zs.len() * nphi);
    for (z, w) in zs.iter().zip(&ws) {
        let s = (1.0 - z * z).max(0.0).sqrt();
        for j in 0..nphi {
            let p = (j as f64 + 0.5) * 2.0 * PI / nphi as f64;
            out.push(([s * p.cos(), s * p.sin(), *z], w * 2.0 * PI / nphi as f64));
        }
    }
    out
}

/// The coefficients of `g(ω) = f(Rᵀω)` for `f` with coefficients `coeffs` (`bands²`) and the
/// rotation `r` (rows, `r[i][j] = R_ij`), by projecting `g` onto the basis with
/// [`exact_grid`]: no rotation formula, only evaluation at the rotated directions.
pub fn rotate(coeffs: &[f64], r: [[f64; 3]; 3]) -> Vec<f64> {
    let bands = (coeffs.len() as f64).sqrt().round() as usize;
    let mut out = vec![0.0; bands * bands];
    for (d, w) in exact_grid(bands) {
        // Rᵀd: (Rᵀd)_j = Σ_i R_ij d_i.
        let rd: [f64; 3] = std::array::from_fn(|j| (0..3).map(|i| r[i][j] * d[i]).sum());
        let f: f64 = eval(rd, bands).iter().zip(coeffs).map(|(y, c)| y * c).sum();
        for (o, y) in out.iter_mut().zip(eval(d, bands)) {
            *o += w * f * y;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotating_a_band_one_function_rotates_its_vector() {
        // f(ω) = a·ω has coefficients ∝ (−a_y, a_z, −a_x) in band 1; g = f∘Rᵀ = (R a)·ω.
        let k = (4.0 * PI / 3.0).sqrt();
        let a = [0.3, -0.5, 0.8];
        let c = [0.0, -k * a[1], k * a[2], -k * a[0]];
        let (s, co) = (0.6f64, 0.8f64);
        let r = [[co, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, co]];
        let ra: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| r[i][j] * a[j]).sum());
        let want = [0.0, -k * ra[1], k * ra[2], -k * ra[0]];
        for (g, w) in rotate(&c, r).iter().zip(want) {
            assert!((g - w).abs() < 1e-13, "{g} vs {w}");
        }
    }

    /// Orthonormality by quadrature: Gauss–Kronrod in `z` (exact for these polynomials of
    /// degree ≤ 8) and the midpoint rule in `φ` (exact for trigonometric degree < 64).
    #[test]
    fn orthonormal_by_quadrature() {
        use std::collections::HashMap;
        let n = 5;
        let nphi = 64;
        // ∫ y_a·y_b dφ at one z, for every pair, cached per node.
        let mut cache: HashMap<u64, Vec<f64>> = HashMap::new();
        let mut ring = |z: f64| -> Vec<f64> {
            cache
                .entry(z.to_bits())
                .or_insert_with(|| {
                    let s = (1.0 - z * z).max(0.0).sqrt();
                    let mut g = vec![0.0; n * n * n * n];
                    for j in 0..nphi {
                        let p = (j as f64 + 0.5) * 2.0 * PI / nphi as f64;
                        let y = eval([s * p.cos(), s * p.sin(), z], n);
                        for a in 0..n * n {
                            for b in 0..n * n {
                                g[a * n * n + b] += 2.0 * PI / nphi as f64 * y[a] * y[b];
                            }
                        }
                    }
                    g
                })
                .clone()
        };
        for a in 0..n * n {
            for b in 0..n * n {
                let (v, _) = crate::quad::gk15(&mut |z: f64| ring(z)[a * n * n + b], -1.0, 1.0);
                let want = if a == b { 1.0 } else { 0.0 };
                assert!((v - want).abs() < 1e-12, "{a} {b}: {v}");
            }
        }
    }

    #[test]
    fn band_one_is_minus_y_z_minus_x() {
        let k = (3.0 / (4.0 * PI)).sqrt();
        let y = eval([0.48, -0.6, 0.64], 2);
        let want = [0.5 / PI.sqrt(), -k * -0.6, k * 0.64, -k * 0.48];
        for (g, w) in y.iter().zip(want) {
            assert!((g - w).abs() < 1e-14);
        }
    }
}
