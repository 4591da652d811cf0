//! The cap → lobe fit (cosine-lobe paper eq. 32–34) in f64.
//!
//! For a cap of half-angle `α ≤ π/2` and the unit lobe `max(a·v, 0)^e` the L2 distance
//! has the closed form
//! `J(e) = 2π(1 − c) − 4π(1 − c^(e+1))/(e + 1) + 2π/(2e + 1)`, `c = cos α`
//! (for `α ≥ π/2`, `c` is replaced by 0: the lobe lies inside the cap). Its derivative,
//! scaled by `(e+1)²/4π`, is
//! `g(e) = (1 − q) + q·ln c·(e + 1) − ((e + 1)/(2e + 1))²` with `q = c^(e+1)`,
//! negative at `e = 0` and `3/4` at `e → ∞`; the optimum is its root, found by bisection
//! on `ln e` to full f64 precision. For `α → 0`, `e*·α²/2 → k*` with `e^(−k*)(1 + k*) = 3/4`.

use std::f64::consts::{FRAC_PI_2, PI};

/// `(1 − cos α, ln cos α)` without cancellation; `ln cos α = −∞` for `α ≥ π/2`.
fn cap_terms(a: f64) -> (f64, f64) {
    if a >= FRAC_PI_2 {
        return (1.0, f64::NEG_INFINITY);
    }
    let s = libm::sin(0.5 * a);
    let omc = 2.0 * s * s;
    let ln_c = if omc < 0.5 {
        libm::log1p(-omc)
    } else {
        libm::log(libm::cos(a))
    };
    (omc, ln_c)
}

/// `(1 − c^(e+1), c^(e+1))` accurately.
fn powers(e: f64, ln_c: f64) -> (f64, f64) {
    if ln_c == f64::NEG_INFINITY {
        return (1.0, 0.0);
    }
    let x = (e + 1.0) * ln_c;
    (-libm::expm1(x), libm::exp(x))
}

/// The exact objective `J(e)` for half-angle `α` (any `α ≥ 0`, `e ≥ 0`).
pub fn objective(e: f64, a: f64) -> f64 {
    let (omc, ln_c) = cap_terms(a);
    let (one_minus_q, _) = powers(e, ln_c);
    2.0 * PI * omc - 4.0 * PI * one_minus_q / (e + 1.0) + 2.0 * PI / (2.0 * e + 1.0)
}

fn slope(e: f64, ln_c: f64) -> f64 {
    let (one_minus_q, q) = powers(e, ln_c);
    let r = (e + 1.0) / (2.0 * e + 1.0);
    let ql = if q == 0.0 { 0.0 } else { q * ln_c * (e + 1.0) };
    one_minus_q + ql - r * r
}

/// `k*`, the root of `e^(−k)(1 + k) = 3/4` (Newton from 1).
pub fn k_star() -> f64 {
    let mut k: f64 = 1.0;
    for _ in 0..60 {
        let f = libm::exp(-k) * (1.0 + k) - 0.75;
        let df = -libm::exp(-k) * k;
        k -= f / df;
    }
    k
}

/// The L2-optimal exponent `e*(α)`: 0 for `α ≥ π/2`, `+∞` for `α = 0`.
pub fn optimal_exponent(a: f64) -> f64 {
    if a >= FRAC_PI_2 {
        return 0.0;
    }
    if a <= 0.0 {
        return f64::INFINITY;
    }
    let (_, ln_c) = cap_terms(a);
    // Bracket in ln e around the small-cap asymptote e ≈ 2k*/α².
    let mut lo = -80.0f64; // e = 1.8e-35
    let mut hi = (2.0 * k_star() / (a * a)).ln() + 5.0;
    if slope(libm::exp(lo), ln_c) >= 0.0 {
        return 0.0;
    }
    while slope(libm::exp(hi), ln_c) <= 0.0 {
        hi += 5.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if slope(libm::exp(mid), ln_c) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    libm::exp(0.5 * (lo + hi))
}

/// `h(α) = e*(α)·α²`, the smooth quantity the table stores (`2k*` at `α = 0`).
pub fn h(a: f64) -> f64 {
    if a <= 0.0 {
        2.0 * k_star()
    } else {
        optimal_exponent(a) * a * a
    }
}

/// Relative excess objective `J(e)/J(e*) − 1` of exponent `e` for half-angle `α`.
pub fn excess(e: f64, a: f64) -> f64 {
    let best = objective(optimal_exponent(a), a);
    let got = objective(e, a);
    if best == 0.0 {
        // α = π/2: J(0) = 0; measure absolutely against the cap's solid angle.
        return got / super::cap_solid_angle(a);
    }
    got / best - 1.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn k_star_value() {
        let k = k_star();
        assert!((libm::exp(-k) * (1.0 + k) - 0.75).abs() < 1e-15);
        assert!((k - 0.961_279).abs() < 1e-5, "{k}");
    }

    #[test]
    fn optimum_is_a_minimum_of_the_objective() {
        for a in [1e-6, 1e-4, 0.01, 0.3, 1.0, 1.4, 1.57] {
            let e = optimal_exponent(a);
            let j = objective(e, a);
            for f in [0.999, 1.001, 0.9, 1.1] {
                assert!(objective(e * f, a) >= j, "α={a} e={e} f={f}");
            }
        }
    }

    #[test]
    fn objective_matches_quadrature() {
        // ∫ (f_cap − c)² over the sphere, by midpoint rule in θ (zonal).
        for (a, e) in [(0.3f64, 20.0f64), (1.0, 2.0), (1.5, 0.1)] {
            let n = 200_000;
            let mut s = 0.0;
            for i in 0..n {
                let t = (i as f64 + 0.5) * PI / n as f64;
                let cap = if t < a { 1.0 } else { 0.0 };
                let lobe = libm::cos(t).max(0.0).powf(e);
                s += (cap - lobe).powi(2) * libm::sin(t);
            }
            let q = 2.0 * PI * s * PI / n as f64;
            assert!((q / objective(e, a) - 1.0).abs() < 1e-4, "α={a} e={e}: {q}");
        }
    }

    #[test]
    fn small_cap_asymptote() {
        let a = 1e-6;
        assert!((h(a) / h(0.0) - 1.0).abs() < 1e-9);
    }
}
