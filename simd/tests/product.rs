//! The lobe product of `steradian_simd::lobe::product` against the scalar kernel
//! `steradian_core::lobe::product::product_with`, lane by lane: the axis bit-identical, the scale,
//! exponent and integral within the bounds of the module docs, non-finite and extreme
//! lanes (recomputed by the scalar kernel) bit-identical. Inputs: deterministic
//! pseudo-random lobes over the whole domain, named hard cases in every lane position,
//! arbitrary bit patterns, and slice lengths around the vector sizes.

use glam::Vec3;
use steradian_core::lobe::CosineLobe;
use steradian_core::lobe::product::{self as core_product, ProductFit, ProductTable};
use steradian_simd::lobe::product::{
    EXPONENT_REL_TOL, INTEGRAL_REL_TOL, MAX_WIDE_EXPONENT, SCALE_REL_TOL, UNDERFLOW_ABS,
    product_slices, product_x8,
};
use steradian_simd::{LobeX8, Vec3x8, f32x8};

use crate::common::rng;
use rng::Rng;

const FITS: [ProductFit; 3] = [
    ProductFit::ExactIntegral,
    ProductFit::ExactIntegralCurvature,
    ProductFit::SphericalGaussian,
];

/// One lobe's raw fields `[ax, ay, az, s, e]` (what a `LobeX8` lane holds).
type Raw = [f32; 5];

/// The scalar kernel's lobe for a lane: `LobeX8::to_array`'s rule.
fn lobe(r: &Raw) -> CosineLobe {
    CosineLobe::saturating(Vec3::new(r[0], r[1], r[2]), r[3], r[4])
}

fn batch(r: &[Raw; 8]) -> LobeX8 {
    let col = |c: usize| f32x8::new(core::array::from_fn(|k| r[k][c]));
    LobeX8::new(Vec3x8::new(col(0), col(1), col(2)), col(3), col(4))
}

use crate::common::lanes::same;

/// The differences of one lane, each divided by its bound's shape (so each must be ≤ its
/// tolerance constant): `[scale, exponent, integral]`, plus whether the lane was exact.
#[derive(Clone, Copy, Debug, Default)]
struct Diff {
    scale: f64,
    exponent: f64,
    integral: f64,
    /// `|ΔI|/|I|` itself (not divided by `1 + L`), where `|ln I| < 20`.
    integral_raw: f64,
}

/// `ln p` of the scalar kernel (the peak value of the product of the unit lobes), from the
/// core's closed-form `baseline`.
fn ln_peak(a: &CosineLobe, b: &CosineLobe) -> f64 {
    let c = a.axis().dot(b.axis()).clamp(-1.0, 1.0);
    let s = (b.axis() - a.axis() * c).length().min(1.0);
    let ln_p = core_product::baseline(a.exponent(), b.exponent(), c, s).ln_peak as f64;
    if ln_p.is_finite() { ln_p } else { 0.0 }
}

/// Compares lane output `got` with the scalar kernel on inputs `a`, `b`; panics with the
/// inputs on a violation. Returns the normalised differences.
fn check(fit: ProductFit, a: &Raw, b: &Raw, got: [f32; 5], what: &str) -> Diff {
    let (la, lb) = (lobe(a), lobe(b));
    let want = core_product::product_with(&ProductTable::builtin(), fit, &la, &lb);
    let wa = want.axis();
    let ctx = || format!("{what}: {fit:?} a={a:?} b={b:?} got={got:?} want={want:?}");
    for (g, w) in got[..3].iter().zip([wa.x, wa.y, wa.z]) {
        assert!(same(*g, w), "axis not bit-identical: {}", ctx());
    }
    let (gs, ge) = (got[3], got[4]);
    let (ws, we) = (want.scale(), want.exponent());
    let s12 = (la.scale() as f64) * (lb.scale() as f64);
    // ln p and ln I of the scalar result (unit lobes), the logarithms the outputs are the
    // exponentials of.
    let (ws64, we64) = (ws as f64, we as f64);
    let ln_p = ln_peak(&la, &lb);
    // ln I of the unit lobes: the result's integral, `ln(p·2π/(1 + e_r))` for the fits
    // whose scale is the peak value.
    let ln_scale = if ws != 0.0 && s12 != 0.0 && ws.is_finite() && s12.is_finite() {
        (ws64 / s12).abs().ln()
    } else {
        ln_p
    };
    let ln_i = if we.is_finite() {
        ln_scale + (std::f64::consts::TAU / (1.0 + we64)).ln()
    } else {
        ln_scale
    };
    let l = 1.0 + ln_p.abs() + ln_i.abs();
    // The curvature fit's scale is `exp(ln I)·(1 + e_r)/(2π)`: its `exp` may be subnormal
    // where the scale is not.
    let sub = UNDERFLOW_ABS as f64
        * (1.0 + s12.abs().min(f32::MAX as f64))
        * if fit == ProductFit::ExactIntegralCurvature && we.is_finite() {
            ((1.0 + we64) / std::f64::consts::TAU).max(1.0)
        } else {
            1.0
        };
    // Both finite, or the same special value, or one overflowed where the other is within
    // the tolerance of `f32::MAX`.
    let finite_pair = |g: f32, w: f32, tol: f32| {
        if g.is_finite() && w.is_finite() {
            return true;
        }
        let (inf, fin) = if g.is_finite() { (w, g) } else { (g, w) };
        assert!(
            same(g, w)
                || (inf.is_infinite()
                    && fin.is_finite()
                    && fin.signum() == inf.signum()
                    && fin.abs() as f64 >= f32::MAX as f64 * (1.0 - 2.0 * tol as f64 * l)),
            "non-finite mismatch: {}",
            ctx()
        );
        false
    };
    let (scale_ok, exp_ok) = (
        finite_pair(gs, ws, SCALE_REL_TOL),
        finite_pair(ge, we, EXPONENT_REL_TOL),
    );
    assert!(ge.is_nan() || ge >= 0.0, "negative exponent: {}", ctx());
    let ds = ((gs as f64 - ws64).abs() - sub).max(0.0);
    let scale = if !scale_ok || ds == 0.0 {
        0.0
    } else {
        ds / (l * ws64.abs())
    };
    let exponent = if exp_ok {
        (ge as f64 - we64).abs() / (l * (1.0 + we64))
    } else {
        0.0
    };
    let gi = gs as f64 / (1.0 + ge as f64);
    let wi = ws64 / (1.0 + we64);
    let di = ((gi - wi).abs() - sub / (1.0 + we64)).max(0.0);
    let integral = if !(scale_ok && exp_ok) || di == 0.0 {
        0.0
    } else {
        di / (l * wi.abs())
    };
    let d = Diff {
        scale,
        exponent,
        integral,
        integral_raw: if ln_i.abs() < 20.0 && integral > 0.0 {
            di / wi.abs()
        } else {
            0.0
        },
    };
    assert!(
        d.scale <= SCALE_REL_TOL as f64
            && d.exponent <= EXPONENT_REL_TOL as f64
            && d.integral <= INTEGRAL_REL_TOL as f64,
        "{d:?} over the tolerance: {}",
        ctx()
    );
    d
}

/// Runs 8 lanes through `product_x8` and checks each.
fn check8(fit: ProductFit, a: &[Raw; 8], b: &[Raw; 8], what: &str) -> [Diff; 8] {
    let t = ProductTable::builtin();
    let r = product_x8(&t, fit, &batch(a), &batch(b));
    core::array::from_fn(|k| {
        let ax = r.axis.lane(k);
        let got = [
            ax.x,
            ax.y,
            ax.z,
            r.scale.as_array()[k],
            r.exponent.as_array()[k],
        ];
        check(fit, &a[k], &b[k], got, what)
    })
}

impl Rng {
    /// `{0}` one time in ten, else log-uniform in `[1e-3, 1e5]`.
    fn exponent(&mut self) -> f32 {
        if self.next_u64().is_multiple_of(10) {
            0.0
        } else {
            self.log_range(1e-3, 1e5)
        }
    }
    /// A pair of unit lobes `α` apart, `α` uniform in `[0, π)` (or random axes one time in
    /// four), scales in `[0.1, 10]` (negative one time in eight).
    fn pair(&mut self) -> (Raw, Raw) {
        let a1 = self.dir();
        let a2 = if self.next_u64().is_multiple_of(4) {
            self.dir()
        } else {
            let alpha = self.range(0.0, std::f32::consts::PI);
            let t = a1.any_orthonormal_vector();
            let t = (t + 0.3 * a1.cross(t)).normalize();
            (a1 * alpha.cos() + t * alpha.sin()).normalize()
        };
        let mut s = || {
            let v = self.log_range(0.1, 10.0);
            if self.next_u64().is_multiple_of(8) {
                -v
            } else {
                v
            }
        };
        let (s1, s2) = (s(), s());
        (
            [a1.x, a1.y, a1.z, s1, self.exponent()],
            [a2.x, a2.y, a2.z, s2, self.exponent()],
        )
    }
}

fn survey(fit: ProductFit, n: usize, seed: u64) -> Diff {
    let mut rng = Rng(seed);
    let mut worst = Diff::default();
    for _ in 0..n / 8 {
        let mut a = [[0.0; 5]; 8];
        let mut b = [[0.0; 5]; 8];
        for k in 0..8 {
            (a[k], b[k]) = rng.pair();
        }
        for d in check8(fit, &a, &b, "survey") {
            worst.scale = worst.scale.max(d.scale);
            worst.exponent = worst.exponent.max(d.exponent);
            worst.integral = worst.integral.max(d.integral);
            worst.integral_raw = worst.integral_raw.max(d.integral_raw);
        }
    }
    worst
}

/// The largest measured difference per unit of the bound's shape that the module docs of
/// `steradian_simd::lobe::product` quote as "at most": a quarter of the tolerance constants
/// (`2e-6`). Measured on the development machine (2·10⁶ lanes per fit): scale 5.3e-7,
/// exponent 6.3e-7, integral 6.3e-7; the margin covers other machines' `exp`/`ln` rounding.
const SURVEY_MAX: f64 = 8.0e-7;

/// The survey of the module docs (2·10⁶ pseudo-random lanes per fit over the whole domain):
/// every maximum within [`SURVEY_MAX`], which the docs quote, and printed
/// (`cargo test --release -p steradian-simd --test main survey -- --nocapture`).
#[test]
fn survey_max_differences() {
    for (i, fit) in FITS.into_iter().enumerate() {
        let w = survey(fit, 2_000_000, 0x1_5eed_0000 + i as u64);
        println!(
            "{fit:?}: max scale {:.2e}/(1+L), exponent {:.2e}/((1+L)(1+e)), integral {:.2e}/(1+L) ({:.2e} relative where |ln I| < 20)",
            w.scale, w.exponent, w.integral, w.integral_raw
        );
        for (what, v) in [
            ("scale", w.scale),
            ("exponent", w.exponent),
            ("integral", w.integral),
        ] {
            assert!(
                v <= SURVEY_MAX,
                "{fit:?}: {what} {v:.2e} > {SURVEY_MAX:.1e}"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------
// Named cases

use crate::common::specials;
use specials::SPECIALS;

/// A batch of 8 ordinary pairs from `rng`.
fn ordinary(rng: &mut Rng) -> ([Raw; 8], [Raw; 8]) {
    let mut a = [[0.0; 5]; 8];
    let mut b = [[0.0; 5]; 8];
    for k in 0..8 {
        (a[k], b[k]) = rng.pair();
    }
    (a, b)
}

/// Every special value in every field of either lobe, in every lane position (the other
/// lanes ordinary): the result matches the scalar kernel (bit for bit where a field is
/// non-finite or the exponent is beyond `MAX_WIDE_EXPONENT`: the scalar kernel computes
/// those lanes), never panics.
#[test]
fn special_fields_in_every_lane() {
    let mut rng = Rng(0x5bec_1a15);
    for fit in FITS {
        for &v in &SPECIALS {
            for field in 0..10 {
                for lane in 0..8 {
                    let (mut a, mut b) = ordinary(&mut rng);
                    if field < 5 {
                        a[lane][field] = v;
                    } else {
                        b[lane][field - 5] = v;
                    }
                    check8(
                        fit,
                        &a,
                        &b,
                        &format!("special {v:e} in field {field} lane {lane}"),
                    );
                }
            }
        }
    }
}

/// Whole lobes made of special values (every field at once), paired with each other.
#[test]
fn special_lobes_paired() {
    for fit in FITS {
        for &x in &SPECIALS {
            for &y in &SPECIALS {
                let a: [Raw; 8] = core::array::from_fn(|k| match k {
                    0 => [x, x, x, x, x],
                    1 => [0.0, 0.0, 1.0, x, y],
                    2 => [x, 0.0, 1.0, 1.0, y],
                    3 => [0.0, y, x, 2.0, 1.0],
                    _ => [1.0, 0.0, 0.0, y, x],
                });
                let b: [Raw; 8] = core::array::from_fn(|k| match k {
                    0 => [y, y, y, y, y],
                    1 => [0.0, 0.0, -1.0, y, x],
                    2 => [y, 1.0, 0.0, x, 0.0],
                    3 => [1.0, 0.0, y, 0.5, x],
                    _ => [0.0, 1.0, 0.0, x, y],
                });
                check8(fit, &a, &b, &format!("special lobes {x:e}, {y:e}"));
            }
        }
    }
}

/// Exponents 0 (hemispheres: their product is a lune), 1 and 1e5 (the table's end) in
/// every combination, at angles from 0 to just below π.
#[test]
fn exponents_zero_one_and_1e5() {
    let es = [0.0, 1.0, 1e5];
    let pi = std::f32::consts::PI;
    let alphas: [f32; 8] = [0.0, 1e-4, 0.01, 0.5, pi / 2.0, 2.5, pi - 1.6e-3, pi - 1e-4];
    for fit in FITS {
        for &e1 in &es {
            for &e2 in &es {
                let a: [Raw; 8] = [[0.0, 0.0, 1.0, 1.0, e1]; 8];
                let b: [Raw; 8] =
                    core::array::from_fn(|k| [alphas[k].sin(), 0.0, alphas[k].cos(), 1.0, e2]);
                check8(fit, &a, &b, &format!("e1 {e1} e2 {e2}"));
            }
        }
    }
}

/// Axes exactly coincident, exactly opposite (the scalar kernel's `α = π` branch: zero
/// scale), an ulp apart, and within `1e-7` of opposite, along the coordinate axes and a
/// generic direction, in every lane.
#[test]
fn axes_coincident_and_opposite() {
    let g = Vec3::new(0.36, -0.48, 0.8);
    let near = |v: Vec3, d: Vec3| (v + d).normalize();
    let mut pairs = vec![];
    for v in [Vec3::Z, -Vec3::Z, Vec3::X, -Vec3::Y, g, -g] {
        pairs.push((v, v));
        pairs.push((v, -v));
        pairs.push((v, near(v, Vec3::splat(1e-7))));
        pairs.push((v, near(-v, Vec3::new(1e-7, -2e-7, 1e-7))));
        pairs.push((v, near(-v, Vec3::new(3e-4, 0.0, 0.0))));
    }
    for fit in FITS {
        for &(u, v) in &pairs {
            for (e1, e2) in [(0.0, 0.0), (1.0, 0.0), (1e5, 1e5), (3.0, 1e4), (1e-3, 0.5)] {
                for lane in 0..8 {
                    let mut rng = Rng(lane as u64);
                    let (mut a, mut b) = ordinary(&mut rng);
                    a[lane] = [u.x, u.y, u.z, 1.5, e1];
                    b[lane] = [v.x, v.y, v.z, 0.5, e2];
                    check8(fit, &a, &b, &format!("axes {u} {v} e {e1} {e2}"));
                }
            }
        }
    }
}

/// e1 = e2 = 1e5 at α = 0.01, and the paper's worst region (both exponents below 1, α near
/// π/2), named hard cases of the core kernel.
#[test]
fn hard_cases_of_the_core_kernel() {
    let mut rng = Rng(0x4a7d);
    for fit in FITS {
        let a: [Raw; 8] = [[0.0, 0.0, 1.0, 1.0, 1e5]; 8];
        let b: [Raw; 8] = [[0.01f32.sin(), 0.0, 0.01f32.cos(), 1.0, 1e5]; 8];
        check8(fit, &a, &b, "1e5 at 0.01");
        for _ in 0..100 {
            let a: [Raw; 8] = core::array::from_fn(|_| [0.0, 0.0, 1.0, 1.0, rng.range(0.0, 1.0)]);
            let b: [Raw; 8] = core::array::from_fn(|_| {
                let al = rng.range(1.4, 1.75);
                [al.sin(), 0.0, al.cos(), 1.0, rng.range(0.0, 1.0)]
            });
            check8(fit, &a, &b, "paper's worst region");
        }
    }
}

/// Arbitrary bit patterns in every field: matches the scalar kernel within the bounds (or
/// exactly), never panics.
#[test]
fn arbitrary_bits() {
    let mut rng = Rng(0xb175);
    for fit in FITS {
        for _ in 0..20_000 {
            let a: [Raw; 8] = core::array::from_fn(|_| core::array::from_fn(|_| rng.bits()));
            let b: [Raw; 8] = core::array::from_fn(|_| core::array::from_fn(|_| rng.bits()));
            check8(fit, &a, &b, "bits");
        }
    }
}

/// For finite inputs with scales `≥ 0` whose product is finite and exponents up to
/// `MAX_WIDE_EXPONENT` (ten times the table's range) the result's scale and exponent are
/// never negative, and NaN only where the scalar kernel's are (`check8`). The fits with the
/// product's peak as the scale (`ExactIntegral`, `SphericalGaussian`) give no NaN at all
/// here; `ExactIntegralCurvature` can (a scalar-kernel limitation, counted and printed:
/// an exponent below about `1e-12` whose lobe's axis is more than `π/2` from the other
/// gives an infinite curvature `e·sec²(α − t*)` with `α − t* = π/2`, so `e_r = ∞` and the
/// scale `0·∞`).
#[test]
fn finite_inputs_give_nonnegative_results() {
    let mut rng = Rng(0x9051);
    let t = ProductTable::builtin();
    for fit in FITS {
        let mut nans = 0;
        for _ in 0..20_000 {
            let f = |rng: &mut Rng| -> Raw {
                let d = rng.dir();
                let e = match rng.next_u64() % 4 {
                    0 => rng.log_range(1e-38, MAX_WIDE_EXPONENT),
                    1 => 0.0,
                    _ => rng.log_range(1e-3, 1e5),
                };
                [d.x, d.y, d.z, rng.log_range(1e-15, 1e15), e]
            };
            let a: [Raw; 8] = core::array::from_fn(|_| f(&mut rng));
            let b: [Raw; 8] = core::array::from_fn(|_| f(&mut rng));
            check8(fit, &a, &b, "finite");
            let r = product_x8(&t, fit, &batch(&a), &batch(&b));
            for k in 0..8 {
                let (s, e) = (r.scale.as_array()[k], r.exponent.as_array()[k]);
                assert!(
                    (s.is_nan() || s >= 0.0) && (e.is_nan() || e >= 0.0),
                    "{fit:?} a={:?} b={:?}: scale {s}, exponent {e}",
                    a[k],
                    b[k]
                );
                if s.is_nan() || e.is_nan() {
                    nans += 1;
                }
            }
        }
        println!("{fit:?}: {nans} NaN lanes of 160000 (as the scalar kernel)");
        if fit != ProductFit::ExactIntegralCurvature {
            assert_eq!(nans, 0, "{fit:?}");
        }
    }
}

/// Padding lanes of a short slice compute the product of two padding lobes (axis `+z`,
/// scale 0, exponent 0): a zero-scale lobe along `+z`, as the scalar kernel gives.
#[test]
fn padding_lanes() {
    let t = ProductTable::builtin();
    let l = CosineLobe::new(Vec3::new(0.0, 0.6, 0.8), 2.0, 30.0).unwrap();
    let m = CosineLobe::new(Vec3::X, 0.5, 3.0).unwrap();
    for fit in FITS {
        for n in 0..=8 {
            let a = LobeX8::from_slice(&vec![l; n]);
            let b = LobeX8::from_slice(&vec![m; n]);
            // The raw lanes (`to_array` would renormalise the result axes).
            let r = product_x8(&t, fit, &a, &b);
            let (rx, ry, rz) = (
                r.axis.x.to_array(),
                r.axis.y.to_array(),
                r.axis.z.to_array(),
            );
            let (rs, re) = (r.scale.to_array(), r.exponent.to_array());
            let (aa, bb) = (a.to_array(), b.to_array());
            for k in 0..8 {
                let want = core_product::product_with(&t, fit, &aa[k], &bb[k]);
                let to_raw = |x: &CosineLobe| -> Raw {
                    let v = x.axis();
                    [v.x, v.y, v.z, x.scale(), x.exponent()]
                };
                let g = [rx[k], ry[k], rz[k], rs[k], re[k]];
                check(fit, &to_raw(&aa[k]), &to_raw(&bb[k]), g, "padding");
                if k >= n {
                    assert_eq!(
                        Vec3::new(g[0], g[1], g[2]),
                        Vec3::Z,
                        "{fit:?} n={n} lane {k}"
                    );
                    assert_eq!(g[3], 0.0);
                    assert_eq!(want.scale(), 0.0);
                }
            }
        }
    }
}

/// `product_slices` at lengths around the vector sizes (8 and 16), lane by lane against the
/// scalar kernel, with ordinary and special lanes mixed.
#[test]
fn slices_of_every_length() {
    let t = ProductTable::builtin();
    let mut rng = Rng(0x511ce);
    for fit in FITS {
        for n in [0, 1, 7, 8, 9, 15, 16, 17, 31, 33, 1000] {
            let mut a: Vec<Raw> = vec![];
            let mut b: Vec<Raw> = vec![];
            for i in 0..n {
                let (mut x, y) = rng.pair();
                if i % 13 == 5 {
                    x[4] = SPECIALS[i % SPECIALS.len()];
                }
                a.push(x);
                b.push(y);
            }
            let col = |r: &[Raw], c: usize| -> Vec<f32> { r.iter().map(|l| l[c]).collect() };
            let (ac, bc): (Vec<Vec<f32>>, Vec<Vec<f32>>) = (
                (0..5).map(|c| col(&a, c)).collect(),
                (0..5).map(|c| col(&b, c)).collect(),
            );
            let mut o: [Vec<f32>; 5] = core::array::from_fn(|_| vec![f32::NAN; n]);
            let [ox, oy, oz, os, oe] = &mut o;
            product_slices(
                &t,
                fit,
                [&ac[0], &ac[1], &ac[2]],
                &ac[3],
                &ac[4],
                [&bc[0], &bc[1], &bc[2]],
                &bc[3],
                &bc[4],
                [ox, oy, oz],
                os,
                oe,
            );
            for i in 0..n {
                let got = core::array::from_fn(|c| o[c][i]);
                check(fit, &a[i], &b[i], got, &format!("slices n={n} i={i}"));
            }
        }
    }
}

/// Columns of different lengths are a caller bug: a panic naming the function.
#[test]
#[should_panic(expected = "product::product_slices")]
fn slices_of_different_lengths_panic() {
    let t = ProductTable::builtin();
    let (x, y) = (vec![0.0f32; 4], vec![0.0f32; 5]);
    let (mut o1, mut o2, mut o3, mut o4, mut o5) = (
        vec![0.0; 4],
        vec![0.0; 4],
        vec![0.0; 4],
        vec![0.0; 4],
        vec![0.0; 4],
    );
    product_slices(
        &t,
        ProductFit::ExactIntegral,
        [&x, &x, &x],
        &x,
        &x,
        [&x, &x, &x],
        &x,
        &y,
        [&mut o1, &mut o2, &mut o3],
        &mut o4,
        &mut o5,
    );
}

/// Axes `4e-18` from opposite with sharp lobes (found by the fuzz target): the scalar
/// kernel's baseline curvature `h` overflows, `ln I = −∞`, and the result is a zero-scale
/// lobe of exponent 0; the vector path must give the same, not `0·∞`.
#[test]
fn baseline_overflow_near_opposite_axes() {
    let a: Raw = [
        2.3509886e-38,
        8.5378e-41,
        -3.0801087e16,
        -3.0801087e16,
        24352.0,
    ];
    let b: Raw = [
        -2.277905e16,
        -3.0801087e16,
        8.877809e33,
        -3.0801087e16,
        24352.0,
    ];
    for fit in FITS {
        let d = check8(fit, &[a; 8], &[b; 8], "near-opposite overflow");
        assert_eq!(d[0].scale, 0.0);
        let r = product_x8(
            &ProductTable::builtin(),
            fit,
            &batch(&[a; 8]),
            &batch(&[b; 8]),
        );
        if fit != ProductFit::SphericalGaussian {
            assert_eq!(r.exponent.as_array()[0], 0.0, "{fit:?}");
        }
    }
}
