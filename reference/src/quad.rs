//! One-dimensional quadrature shared by the references: the Gauss–Kronrod G7K15 rule
//! with QUADPACK's error estimate.

/// Kronrod 15-point nodes on `[−1, 1]` (QUADPACK `qk15`), positive half, centre last.
const XGK: [f64; 8] = [
    0.9914553711208126,
    0.9491079123427585,
    0.8648644233597691,
    0.7415311855993945,
    0.5860872354676911,
    0.4058451513773972,
    0.20778495500789848,
    0.0,
];
/// Kronrod 15-point weights for [`XGK`].
const WGK: [f64; 8] = [
    0.022935322010529224,
    0.06309209262997856,
    0.10479001032225019,
    0.14065325971552592,
    0.1690047266392679,
    0.19035057806478542,
    0.20443294007529889,
    0.20948214108472782,
];
/// Gauss 7-point weights for the nodes `XGK[1], XGK[3], XGK[5], XGK[7]`.
const WG: [f64; 4] = [
    0.1294849661688697,
    0.27970539148927664,
    0.3818300505051189,
    0.4179591836734694,
];

/// `(∫_a^b f, error estimate)` by G7K15 with QUADPACK's error estimate
/// `resasc·min(1, (200·|K − G|/resasc)^1.5)`, floored at `50ε·∫|f|`.
pub fn gk15<F: FnMut(f64) -> f64 + ?Sized>(f: &mut F, a: f64, b: f64) -> (f64, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let fc = f(c);
    let mut resk = WGK[7] * fc;
    let mut resg = WG[3] * fc;
    let mut resabs = (WGK[7] * fc).abs();
    let mut fv = [(0.0, 0.0); 7];
    for (j, slot) in fv.iter_mut().enumerate() {
        let dx = h * XGK[j];
        let (f1, f2) = (f(c - dx), f(c + dx));
        *slot = (f1, f2);
        resk += WGK[j] * (f1 + f2);
        resabs += WGK[j] * (f1.abs() + f2.abs());
        if j % 2 == 1 {
            resg += WG[j / 2] * (f1 + f2);
        }
    }
    let mean = 0.5 * resk;
    let mut resasc = WGK[7] * (fc - mean).abs();
    for (j, &(f1, f2)) in fv.iter().enumerate() {
        resasc += WGK[j] * ((f1 - mean).abs() + (f2 - mean).abs());
    }
    let ah = h.abs();
    let (resabs, resasc) = (resabs * ah, resasc * ah);
    let mut err = ((resk - resg) * h).abs();
    if resasc != 0.0 && err != 0.0 {
        err = resasc * libm::pow(200.0 * err / resasc, 1.5).min(1.0);
    }
    if resabs > f64::MIN_POSITIVE / (50.0 * f64::EPSILON) {
        err = err.max(50.0 * f64::EPSILON * resabs);
    }
    (resk * h, err)
}

/// The `n`-point Gauss–Legendre rule on `[−1, 1]`, `(nodes, weights)`: exact for
/// polynomials of degree `≤ 2n − 1`. Nodes by Newton's iteration on `P_n` from the
/// Chebyshev-like guesses `cos(π(i − ¼)/(n + ½))`, to full `f64` precision.
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(z) and P_n'(z) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0f64, z);
            for k in 2..=n {
                let kf = k as f64;
                (p0, p1) = (p1, ((2.0 * kf - 1.0) * z * p1 - (kf - 1.0) * p0) / kf);
            }
            if n == 1 {
                p0 = 1.0;
            }
            dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

#[cfg(test)]
mod tests {
    #[test]
    fn gauss_legendre_integrates_monomials_exactly() {
        for n in [1usize, 2, 5, 16, 31, 64] {
            let (x, w) = super::gauss_legendre(n);
            for k in 0..2 * n {
                let got: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k as i32)).sum();
                let want = if k % 2 == 1 {
                    0.0
                } else {
                    2.0 / (k as f64 + 1.0)
                };
                assert!((got - want).abs() < 1e-13, "n {n} k {k}: {got} vs {want}");
            }
        }
    }

    use super::*;

    #[test]
    fn gk15_is_exact_on_polynomials() {
        for deg in 0..=22 {
            let (v, _) = gk15(&mut |x: f64| libm::pow(x, deg as f64), 0.0, 1.0);
            assert!(
                (v - 1.0 / (deg as f64 + 1.0)).abs() < 1e-15,
                "deg {deg}: {v}"
            );
        }
        // The embedded Gauss rule alone is exact to degree 13 on [−1, 1].
        for deg in 0..=13 {
            let f = |x: f64| libm::pow(x, deg as f64);
            let mut g = WG[3] * f(0.0);
            for i in 0..3 {
                let x = XGK[2 * i + 1];
                g += WG[i] * (f(x) + f(-x));
            }
            let want = if deg % 2 == 0 {
                2.0 / (deg as f64 + 1.0)
            } else {
                0.0
            };
            assert!((g - want).abs() < 1e-15, "Gauss deg {deg}: {g}");
        }
    }
}
