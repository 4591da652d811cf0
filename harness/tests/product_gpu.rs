//! The WGSL lobe product (`steradian_core::wgsl::LOBE_PRODUCT`) against the scalar kernel
//! `product::product_with(ExactIntegral)`, lane by lane, within `wgsl::LOBE_PRODUCT_TOL`
//! (naga validation is in `wgsl_validate.rs`). The GPU tests skip with a message when no
//! adapter is available unless `STERADIAN_REQUIRE_GPU=1`.

use steradian_core::lobe::CosineLobe;
use steradian_core::lobe::product::{self, ProductFit, ProductTable};
use steradian_core::{Vec3, wgsl};
use steradian_harness::backend::gpu::Gpu;
use steradian_harness::backend::gpu_product::{
    ProductGpuTable, run_lobe_product_columns, run_lobe_product_gpu,
};
use steradian_harness::kernels::Columns;

use crate::common::gpu as gpu_common;
use gpu_common::{gpu, say};

/// The harness's deterministic generator, with the f32 helpers these tests want.
struct Rng(steradian_harness::rng::Rng);

impl Rng {
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        self.0.range(lo as f64, hi as f64) as f32
    }
    fn dir(&mut self) -> Vec3 {
        Vec3::from(self.0.sphere().map(|x| x as f32)).normalize()
    }
    fn exponent(&mut self) -> f32 {
        if self.0.next_u64().is_multiple_of(10) {
            0.0
        } else {
            self.0.log_range(1e-3, 1e5) as f32
        }
    }
    /// A pair of lobes `α` apart, `α` uniform in `[0, π)`.
    fn pair(&mut self) -> (CosineLobe, CosineLobe) {
        let a1 = self.dir();
        let t = a1.any_orthonormal_vector();
        let alpha = self.range(0.0, std::f32::consts::PI);
        let a2 = (a1 * alpha.cos() + t * alpha.sin()).normalize();
        let (s1, s2) = (self.range(0.1, 4.0), self.range(-2.0, 2.0));
        (
            CosineLobe::new(a1, s1, self.exponent()).unwrap(),
            CosineLobe::new(a2, s2, self.exponent()).unwrap(),
        )
    }
}

/// The differences of one lane divided by their bound's shape: `[axis, scale, exponent,
/// integral]` (see `wgsl::LOBE_PRODUCT_TOL`).
fn diff(a: &CosineLobe, b: &CosineLobe, got: &CosineLobe) -> [f64; 4] {
    let want = product::product_with(&ProductTable::builtin(), ProductFit::ExactIntegral, a, b);
    let axis = (got.axis() - want.axis()).abs().max_element() as f64;
    let c = a.axis().dot(b.axis()).clamp(-1.0, 1.0);
    let s = (b.axis() - a.axis() * c).length().min(1.0);
    let ln_p = product::baseline(a.exponent(), b.exponent(), c, s).ln_peak as f64;
    let ln_p = if ln_p.is_finite() { ln_p } else { 0.0 };
    let (ws, we) = (want.scale() as f64, want.exponent() as f64);
    let (gs, ge) = (got.scale() as f64, got.exponent() as f64);
    let ln_i = ln_p + (std::f64::consts::TAU / (1.0 + we)).ln();
    let l = 1.0 + ln_p.abs() + ln_i.abs();
    let s12 = (a.scale() * b.scale()) as f64;
    // Values below |s1·s2|·2⁻¹²⁶ may be flushed to zero.
    let flush = s12.abs() * f32::MIN_POSITIVE as f64;
    let rel = |d: f64, w: f64| {
        if d <= flush { 0.0 } else { d / (l * w.abs()) }
    };
    let scale = rel((gs - ws).abs(), ws);
    let exponent = (ge - we).abs() / (l * (1.0 + we));
    let (gi, wi) = (gs / (1.0 + ge), ws / (1.0 + we));
    let integral = rel((gi - wi).abs(), wi);
    [axis, scale, exponent, integral]
}

fn run_and_check(g: &mut Gpu, pairs: &[(CosineLobe, CosineLobe)], what: &str) -> [f64; 4] {
    let (a, b): (Vec<_>, Vec<_>) = pairs.iter().copied().unzip();
    let got = run_lobe_product_gpu(g, &a, &b).expect("lobe product runs");
    let tol = wgsl::LOBE_PRODUCT_TOL as f64;
    let mut worst = [0.0f64; 4];
    for (i, ((x, y), r)) in pairs.iter().zip(&got).enumerate() {
        let d = diff(x, y, r);
        assert!(
            d.iter().all(|&v| v <= tol),
            "{what} row {i}: {d:?} over {tol:e}: a={x:?} b={y:?} gpu={r:?} cpu={:?}",
            product::product(x, y)
        );
        for (w, v) in worst.iter_mut().zip(d) {
            *w = w.max(v);
        }
    }
    worst
}

/// Random pairs over the whole domain (exponents `{0} ∪ [1e-3, 1e5]`, `α ∈ [0, π)`),
/// lane by lane within `LOBE_PRODUCT_TOL`; prints the measured maxima.
#[test]
fn lobe_product_matches_scalar() {
    let Some(mut g) = gpu() else { return };
    let mut rng = Rng(steradian_harness::rng::Rng::new(0x9e0d_0001));
    let pairs: Vec<_> = (0..100_000).map(|_| rng.pair()).collect();
    let w = run_and_check(&mut g, &pairs, "random");
    say(&format!(
        "lobe-product GPU vs scalar: axis {:.2e} abs, scale {:.2e}, exponent {:.2e}, integral {:.2e} per unit of 1 + L",
        w[0], w[1], w[2], w[3]
    ));
}

/// Named hard cases: exponents 0, 1 and 1e5 in every combination at angles from 0 to just
/// below π; coincident and exactly opposite axes (zero scale); e1 = e2 = 1e5 at α = 0.01;
/// the paper's worst region (exponents below 1, α near π/2).
#[test]
fn lobe_product_hard_cases() {
    let Some(mut g) = gpu() else { return };
    let mut pairs = vec![];
    let lobe = |a: Vec3, s: f32, e: f32| CosineLobe::new(a, s, e).unwrap();
    let at = |alpha: f32| Vec3::new(alpha.sin(), 0.0, alpha.cos());
    for e1 in [0.0, 1.0, 1e5] {
        for e2 in [0.0, 1.0, 1e5] {
            let pi = std::f32::consts::PI;
            for alpha in [
                0.0f32,
                1e-4,
                0.01,
                0.5,
                pi / 2.0,
                2.5,
                pi - 1.6e-3,
                pi - 1e-4,
            ] {
                pairs.push((lobe(Vec3::Z, 1.0, e1), lobe(at(alpha), 1.0, e2)));
            }
            pairs.push((lobe(Vec3::Z, 2.0, e1), lobe(-Vec3::Z, 1.0, e2)));
            pairs.push((lobe(Vec3::X, 2.0, e1), lobe(Vec3::X, 0.5, e2)));
        }
    }
    pairs.push((lobe(Vec3::Z, 1.0, 1e5), lobe(at(0.01), 1.0, 1e5)));
    let mut rng = Rng(steradian_harness::rng::Rng::new(7));
    for _ in 0..1000 {
        let (e1, e2, al) = (
            rng.range(0.0, 1.0),
            rng.range(0.0, 1.0),
            rng.range(1.4, 1.75),
        );
        pairs.push((lobe(Vec3::Z, 1.0, e1), lobe(at(al), 1.0, e2)));
    }
    run_and_check(&mut g, &pairs, "hard cases");
    // Exactly opposite axes give a zero-scale lobe, as on the CPU.
    let got = run_lobe_product_gpu(
        &mut g,
        &[lobe(Vec3::Z, 2.0, 3.0)],
        &[lobe(-Vec3::Z, 1.0, 5.0)],
    )
    .unwrap();
    assert_eq!(got[0].scale(), 0.0);
}

/// Shape errors are reported, not panics; a table from other bytes is rejected.
#[test]
fn lobe_product_bad_shapes() {
    assert!(ProductGpuTable::from_bytes(&[1, 2, 3]).is_err());
    let Some(mut g) = gpu() else { return };
    let t = ProductGpuTable::builtin().unwrap();
    let input = Columns::zeros(9, 4);
    let mut out = Columns::zeros(5, 4);
    assert!(run_lobe_product_columns(&mut g, &t, &input, &mut out).is_err());
    let l = CosineLobe::new(Vec3::Z, 1.0, 1.0).unwrap();
    assert!(run_lobe_product_gpu(&mut g, &[l, l], &[l]).is_err());
}

/// `wgsl::LOBE_CHAIN` row by row against its scalar twin (the `lobes` method's chain:
/// `LobeSum::push_times_cosine_with` on the light's lobe, then `sum::triple_with`
/// unshadowed and shadowed), with the built-in product table, its rows laid out by
/// `lobes::chain_row` as the method lays them out: random normals, cap lobes of 1e-4 to 1.5
/// rad (energy-preserving and moments fits), diffuse and glossy reflectances (exponents 0
/// to 1e5), 0 to 6 visibility lobes, thresholds 0 and 1e-4, plus the named hard cases (no
/// visibility lobe, the light straight below the normal, a glossy lobe of exponent 0 and of
/// 1e5). Each value within `LOBE_CHAIN_REL_TOL` of the chain's scale `|u|·(1 + Σ|w_k|)`
/// plus, with a threshold, `(k + 1)·t·|u|` (a term at the threshold may be kept on one side
/// only), the scale taken per unit of `1 + ln(1 + e_max)` (`e_max` the chain's largest
/// exponent) as `LOBE_PRODUCT_TOL` is per unit of its logarithms (and `1e-30` absolutely,
/// where `f32` results may be flushed); the products computed equal where the threshold is
/// 0. The test prints the worst (lavapipe: 4.3e-6 without pruning).
#[test]
fn lobe_chain_matches_the_scalar_chain_row_by_row() {
    use steradian_core::lobe::cap::{CapFit, SphericalCap};
    use steradian_core::lobe::sum::{LobeSum, LobeTerms, LobeVec, ProductCounts, triple_with};
    use steradian_harness::backend::gpu::Custom;
    use steradian_harness::scene::lobes;
    let Some(mut g) = gpu() else {
        return;
    };
    let table = ProductTable::builtin();
    let kernel = |a: &CosineLobe, b: &CosineLobe| {
        product::product_with(&table, ProductFit::ExactIntegral, a, b)
    };
    let mut rng = Rng(steradian_harness::rng::Rng::new(41));
    // (normal, light lobe, reflectance, visibility lobes, threshold)
    type Case = (Vec3, CosineLobe, LobeSum<1>, Vec<CosineLobe>, f32);
    let diffuse = LobeSum::<1>::with_constant(1.0 / std::f32::consts::PI);
    let glossy =
        |axis: Vec3, e: f32| LobeSum::<1>::from_lobes(0.0, &[CosineLobe::saturating(axis, 1.0, e)]);
    let mut cases: Vec<Case> = Vec::new();
    for k in 0..2000 {
        let n = rng.dir();
        let cap = SphericalCap::new(rng.dir(), rng.0.log_range(1e-4, 1.5) as f32).unwrap();
        // The diffuse chain's lobe and the glossy chains' (the `lobes` method's defaults).
        let light = cap.lobe(
            1.0,
            if k % 4 < 2 {
                CapFit::EnergyPreserving
            } else {
                CapFit::Moments
            },
        );
        let r = if k % 2 == 0 {
            diffuse
        } else {
            glossy(rng.dir(), rng.exponent())
        };
        let nv = (rng.0.next_u64() % 7) as usize;
        let vis = (0..nv)
            .map(|_| CosineLobe::saturating(rng.dir(), -rng.range(0.0, 1.0), rng.exponent()))
            .collect();
        cases.push((n, light, r, vis, if k % 3 == 0 { 1e-4 } else { 0.0 }));
    }
    let light = SphericalCap::new(Vec3::Z, 0.2)
        .unwrap()
        .lobe(1.0, CapFit::EnergyPreserving);
    let occ = SphericalCap::new(Vec3::new(0.1, 0.0, 1.0).normalize(), 0.1)
        .unwrap()
        .lobe(-0.8, CapFit::EnergyPreserving);
    // The named hard cases: no visibility lobe, the light straight below the normal, a
    // glossy lobe of exponent 0 and of 1e5.
    cases.extend([
        (Vec3::Z, light, diffuse, vec![], 0.0),
        (-Vec3::Z, light, diffuse, vec![occ], 0.0),
        (Vec3::Z, light, glossy(Vec3::Z, 0.0), vec![occ], 0.0),
        (Vec3::Z, light, glossy(Vec3::Z, 1e5), vec![occ], 0.0),
    ]);
    // The scalar chain and the kernel's rows.
    let mut data = table.gpu_table();
    let mut rows = Vec::new();
    let mut want = Vec::new();
    for (n, light, r, vis, t) in &cases {
        let mut counts = ProductCounts::default();
        let mut l = LobeSum::<1>::new();
        l.push_times_cosine_with(&kernel, light, *n, &mut counts);
        let before = counts.computed;
        let u = triple_with(
            &kernel,
            r,
            &l,
            &LobeSum::<1>::unoccluded(),
            0.0,
            &mut counts,
        );
        let visv = LobeVec {
            constant: 1.0,
            lobes: vis.clone(),
        };
        let v = if vis.is_empty() {
            u
        } else {
            triple_with(&kernel, r, &l, &visv, t * u.abs(), &mut counts)
        };
        let e_max = vis
            .iter()
            .chain(r.lobes())
            .chain([light])
            .map(|z| z.exponent())
            .fold(1.0f32, f32::max);
        let scale = u.abs()
            * (1.0 + vis.iter().map(|z| z.scale().abs()).sum::<f32>())
            * (1.0 + (1.0 + e_max).ln());
        want.push((u, v, counts.computed - before, scale, *t, vis.len()));
        let off = data.len() as u32;
        for z in vis {
            let a = z.axis();
            data.extend([a.x, a.y, a.z, z.scale(), z.exponent()]);
        }
        rows.push(lobes::chain_row(*n, light, r, (off, vis.len() as u32), *t));
    }
    let input = Columns::from_rows(&rows);
    let mut out = Columns::zeros(3, rows.len());
    let custom = Custom {
        label: "lobe-chain",
        source: wgsl::LOBE_CHAIN,
        table: Some(&data),
    };
    g.run_custom(&custom, &input, &mut out).unwrap();
    let m = rows.len();
    let mut worst = 0.0f64;
    for (i, (u, v, computed, scale, t, nv)) in want.iter().enumerate() {
        let (gu, gv, gc) = (out.data[i], out.data[m + i], out.data[2 * m + i]);
        let allow = wgsl::LOBE_CHAIN_REL_TOL * scale + (*nv as f32 + 1.0) * t * u.abs();
        for (got, exp) in [(gu, *u), (gv, *v)] {
            assert!(got.is_finite(), "row {i}: {got}");
            let d = (got - exp).abs();
            assert!(
                d <= allow + 1e-30,
                "row {i}: {got} vs {exp} (scale {scale}) {:?}",
                cases[i]
            );
            if *scale > 1e-20 && *t == 0.0 {
                worst = worst.max(f64::from(d / scale));
            }
        }
        if *t == 0.0 {
            assert_eq!(gc as u64, *computed, "row {i}");
        }
    }
    say(&format!(
        "lobe-chain GPU vs scalar over {m} rows: worst {worst:.2e} of the chain's scale (per unit of its logarithms) without pruning"
    ));
}
