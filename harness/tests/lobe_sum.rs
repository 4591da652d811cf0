//! The lobe-sum chain `∫ R·L·V` (steradian_core::lobe::sum) against f64 quadrature of the
//! exact integrand (reference::triple), on named hard cases and fixed-seed random scenes;
//! threshold pruning (section 4.3) and its counters.
//!
//! Two references (see reference::triple): the *lobe model* (light and visibility as the
//! same cap lobes the chain uses, BRDF lobes with the exact cosine) isolates the chain's own
//! error — products and pruning — and is what [`CHAIN_BOUND`] bounds; the *physical* one
//! (cap indicator light, exact occluders) adds the caps-as-lobes representation error, which
//! is printed (`--nocapture`) and only sanity-checked.
//!
//! Errors are relative to the unshadowed size `S = ∫|R|·|L|` (the scale of the pixel; in
//! umbra the result itself is ~0), floored at `1e-3·Φ·sup R` (a thousandth of the brightest
//! this light could make the surface), so lights behind the surface do not divide by ~0.

use glam::Vec3;
use steradian_core::frame::Frame;
use steradian_core::lobe::cap::{CapFit, SphericalCap};
use steradian_core::lobe::sum::{
    self as lobe_sum, Cosine, LobeSum, LobeTerms, ProductCounts, lafortune_reflectance,
    phong_reflectance, triple,
};
use steradian_core::lobe::{CosineLobe, Lafortune, LafortuneLobe, Phong};
use steradian_harness::reference as adapt;
use steradian_harness::reference::triple::{self as reference, Scene, Term, Visibility};
use steradian_harness::rng::Rng;

/// Bound on `|chain(t = 0) − lobe-model reference| / S` with the cosine on the light
/// (`Cosine::WithLight`, the default), over the hard cases and random scenes below, with
/// `product::product` as it stands (the (e1, e2, α) table). Measured worst: 3.2e-2 (e = 0
/// lobes: a lune-shaped product of broad lobes is far from one lobe), 3.1e-2 (light partly
/// below the horizon), 2.6e-2 (grazing light); random scenes mean 1.2e-3, max 2.1e-2.
const CHAIN_BOUND: f64 = 0.05;
/// The same with the cosine multiplied into the BRDF lobes first (`Cosine::WithBrdf`).
/// Measured worst: 0.28 (grazing light: the glossy×cosine lobe's tail toward the horizon is
/// what a grazing light sees), 6.9e-2 below the horizon, random max 6.0e-2.
const CHAIN_BOUND_WITH_BRDF: f64 = 0.4;
/// Quadrature tolerance of the references (relative to `S`).
const REF_TOL: f64 = 1e-8;

fn v3(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

fn dir(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// A shading configuration: BRDF, lights (cap + radiance), occluders (cap + weight).
#[derive(Clone, Debug)]
enum Brdf {
    Phong(Phong),
    Lafortune(Lafortune<2>),
}

#[derive(Clone, Debug)]
struct Config {
    brdf: Brdf,
    normal: Vec3,
    wo: Vec3,
    cosine: Cosine,
    lights: Vec<(SphericalCap, f32)>,
    occluders: Vec<(SphericalCap, f32)>,
    fit: CapFit,
}

struct Built {
    r: LobeSum<2>,
    /// The light with the cosine multiplied in (for `Cosine::WithLight`).
    l: LobeSum<4>,
    /// The light lobes as fitted to the caps.
    l_raw: LobeSum<4>,
    v: LobeSum<64>,
}

impl Config {
    fn build(&self) -> Built {
        let mut setup = ProductCounts::default();
        let r = match &self.brdf {
            Brdf::Phong(p) => phong_reflectance(p, self.normal, self.wo, self.cosine, &mut setup),
            Brdf::Lafortune(l) => {
                let f = Frame::from_normal(self.normal).unwrap();
                lafortune_reflectance(l, &f, self.wo, self.cosine, &mut setup)
            }
        };
        let mut l_raw = LobeSum::new();
        for (c, rad) in &self.lights {
            assert!(l_raw.push_cap(c, *rad, self.fit));
        }
        let l = lobe_sum::light_with_cosine(&l_raw, self.normal, self.cosine, &mut setup);
        let mut v = LobeSum::unoccluded();
        for (c, w) in &self.occluders {
            assert!(v.push_occluder(c, *w, self.fit));
        }
        Built { r, l, l_raw, v }
    }

    /// The exact reflectance terms: BRDF lobes times the exact cosine.
    fn reflectance_terms(&self) -> Vec<Term> {
        let n = v3(self.normal);
        let exact = |l: &CosineLobe, times_cos: bool| {
            if times_cos {
                Term::LobeTimesCosine(adapt::lobe_of(l), n)
            } else {
                Term::Lobe(adapt::lobe_of(l))
            }
        };
        let with_cos = self.cosine != Cosine::AsGiven;
        match &self.brdf {
            Brdf::Phong(p) => {
                let [d, s] = p.lobes(self.normal, self.wo);
                vec![exact(&d, false), exact(&s, with_cos)]
            }
            Brdf::Lafortune(b) => {
                let f = Frame::from_normal(self.normal).unwrap();
                b.lobes(&f, self.wo)
                    .iter()
                    .map(|l| exact(l, with_cos))
                    .collect()
            }
        }
    }

    /// Lobe-model reference: lights and visibility as the chain's lobes, exact cosine.
    fn lobe_model(&self, b: &Built) -> Scene {
        Scene {
            reflectance: self.reflectance_terms(),
            light: adapt::terms_of(&b.l_raw),
            visibility: Visibility::Lobes(adapt::terms_of(&b.v)),
        }
    }

    /// Physical reference: cap indicator lights, exact occluders (weights ignored).
    fn physical(&self) -> Scene {
        Scene {
            reflectance: self.reflectance_terms(),
            light: self
                .lights
                .iter()
                .map(|(c, rad)| Term::Cap(adapt::cap_of(c), *rad as f64))
                .collect(),
            visibility: Visibility::Occluders(
                self.occluders
                    .iter()
                    .map(|(c, _)| adapt::cap_of(c))
                    .collect(),
            ),
        }
    }
}

struct Measured {
    chain: f64,
    lobe_ref: reference::Estimate,
    phys_ref: reference::Estimate,
    counts: ProductCounts,
    /// `1e-3·Φ·sup R`: a thousandth of the brightest this light could make the surface
    /// (light lobe integral times the reflectance's peak), the floor of the error scale.
    floor: f64,
}

impl Measured {
    fn chain_error(&self) -> f64 {
        (self.chain - self.lobe_ref.value).abs() / self.lobe_ref.scale.max(self.floor)
    }
    fn model_error(&self) -> f64 {
        (self.chain - self.phys_ref.value).abs() / self.phys_ref.scale.max(self.floor)
    }
}

fn measure(cfg: &Config, t: f32) -> Measured {
    let b = cfg.build();
    let mut counts = ProductCounts::default();
    let chain = triple(&b.r, &b.l, &b.v, t, &mut counts) as f64;
    let lobe_ref = reference::triple(&cfg.lobe_model(&b), REF_TOL);
    let phys_ref = reference::triple(&cfg.physical(), REF_TOL);
    assert!(
        lobe_ref.error <= 100.0 * REF_TOL * lobe_ref.scale,
        "reference did not converge: {lobe_ref:?}"
    );
    let floor = 1e-3 * b.l_raw.integral().abs() as f64 * b.r.abs_bound() as f64;
    Measured {
        chain,
        lobe_ref,
        phys_ref,
        counts,
        floor,
    }
}

/// Measures `cfg` with its cosine order and with the other one (printed), asserts the
/// chain bound of each order, returns the measurement of `cfg` as given.
fn check(name: &str, cfg: &Config) -> Measured {
    let mut out = None;
    let orders: &[Cosine] = match cfg.cosine {
        Cosine::AsGiven => &[Cosine::AsGiven],
        c => &[c, other(c)],
    };
    for &order in orders {
        let cfg = Config {
            cosine: order,
            ..cfg.clone()
        };
        let m = measure(&cfg, 0.0);
        println!(
            "{name} [{order:?}]: chain {:.6e}, lobe model {:.6e} (S = {:.3e}), physical {:.6e}; \
             chain error {:.2e}·S, model error {:.2e}·S, {} products",
            m.chain,
            m.lobe_ref.value,
            m.lobe_ref.scale,
            m.phys_ref.value,
            m.chain_error(),
            m.model_error(),
            m.counts.computed
        );
        assert!(
            m.chain.is_finite() && m.phys_ref.value.is_finite(),
            "{name}: {}",
            m.chain
        );
        let bound = bound_of(order);
        assert!(
            m.chain_error() <= bound,
            "{name} [{order:?}]: chain error {:.3e}·S exceeds {bound}",
            m.chain_error()
        );
        out.get_or_insert(m);
    }
    out.unwrap()
}

fn other(c: Cosine) -> Cosine {
    match c {
        Cosine::WithLight => Cosine::WithBrdf,
        _ => Cosine::WithLight,
    }
}

fn bound_of(c: Cosine) -> f64 {
    match c {
        Cosine::WithBrdf => CHAIN_BOUND_WITH_BRDF,
        _ => CHAIN_BOUND,
    }
}

fn phong(e: f32) -> Brdf {
    Brdf::Phong(Phong::modified(0.4, 0.6, e).unwrap())
}

fn cap(axis: Vec3, a: f32) -> SphericalCap {
    SphericalCap::new(axis, a).unwrap()
}

fn base(brdf: Brdf, wo: Vec3, lights: Vec<(SphericalCap, f32)>) -> Config {
    Config {
        brdf,
        normal: Vec3::Z,
        wo: wo.normalize(),
        cosine: Cosine::WithLight,
        lights,
        occluders: vec![],
        fit: CapFit::L2,
    }
}

#[test]
fn grazing_light() {
    let l = cap(dir(1.48, 0.0), 0.08);
    let mut c = base(phong(50.0), dir(1.3, std::f32::consts::PI), vec![(l, 5.0)]);
    check("grazing light", &c);
    c.occluders.push((cap(dir(1.46, 0.02), 0.03), 1.0));
    check("grazing light, occluded", &c);
}

#[test]
fn light_partly_below_the_horizon() {
    let l = cap(dir(1.75, 0.3), 0.35);
    let c = base(
        phong(20.0),
        dir(0.8, 0.3 + std::f32::consts::PI),
        vec![(l, 2.0)],
    );
    check("light partly below the horizon", &c);
    let mut c2 = c.clone();
    c2.cosine = Cosine::AsGiven;
    check("light partly below the horizon, cosine as given", &c2);
}

#[test]
fn thin_occluder_across_a_specular_highlight() {
    // Light at the mirror direction of the view; a thin occluder across the highlight.
    let wo = dir(0.5, 0.0);
    let mirror = dir(0.5, std::f32::consts::PI);
    let l = cap(mirror, 0.06);
    let mut c = base(phong(800.0), wo, vec![(l, 10.0)]);
    check("highlight, unoccluded", &c);
    c.occluders
        .push((cap(dir(0.5 + 0.015, std::f32::consts::PI), 0.025), 1.0));
    let m = check("thin occluder across a specular highlight", &c);
    // The occluder must visibly darken the highlight.
    let open = measure(
        &Config {
            occluders: vec![],
            ..c.clone()
        },
        0.0,
    );
    assert!(m.lobe_ref.value < 0.9 * open.lobe_ref.value);
    assert!(m.chain < 0.9 * open.chain);
}

#[test]
fn e0_lobes() {
    // A Lafortune BRDF with a hemisphere (e = 0) lobe, lit by a hemisphere light (e = 0
    // L2 fit), shadowed by a large occluder whose fit is nearly a hemisphere too.
    let brdf = Lafortune::new([
        LafortuneLobe {
            c: Vec3::new(0.0, 0.0, 1.0),
            exponent: 0.0,
            rho: 0.3,
        },
        LafortuneLobe {
            c: Vec3::new(-1.0, -1.0, 1.0),
            exponent: 10.0,
            rho: 1.0,
        },
    ])
    .unwrap();
    let l = cap(dir(1.0, 0.5), std::f32::consts::FRAC_PI_2);
    assert_eq!(l.exponent_l2(), 0.0);
    let mut c = base(Brdf::Lafortune(brdf), dir(0.7, 2.0), vec![(l, 1.0)]);
    check("e = 0 lobes", &c);
    c.occluders.push((cap(dir(0.9, 1.5), 1.4), 1.0));
    check("e = 0 lobes, occluded", &c);
}

#[test]
fn coincident_and_nearly_opposite_axes() {
    let wo = dir(0.4, 0.0);
    let mirror = dir(0.4, std::f32::consts::PI);
    // Light exactly at the mirror direction, occluder coaxial with the light.
    let mut c = base(phong(100.0), wo, vec![(cap(mirror, 0.1), 3.0)]);
    c.occluders.push((cap(mirror, 0.03), 1.0));
    check("coincident axes", &c);
    // An occluder nearly opposite the light (behind the point): its products vanish.
    let mut c = base(phong(100.0), wo, vec![(cap(mirror, 0.1), 3.0)]);
    c.occluders
        .push((cap(-mirror + Vec3::new(1e-3, 0.0, 0.0), 0.2), 1.0));
    let m = check("nearly opposite axes", &c);
    let open = measure(
        &Config {
            occluders: vec![],
            ..c.clone()
        },
        0.0,
    );
    assert!((m.chain - open.chain).abs() <= 1e-3 * m.lobe_ref.scale);
    // Normal incidence: view along the normal, mirror = normal = light axis.
    let c = base(phong(100.0), Vec3::Z, vec![(cap(Vec3::Z, 0.2), 1.0)]);
    check("everything coaxial", &c);
}

fn random_config(rng: &mut Rng) -> Config {
    let e = rng.log_range(1.0, 1e4) as f32;
    let brdf = if rng.unit() < 0.75 {
        Brdf::Phong(
            Phong::modified(rng.range(0.0, 0.5) as f32, rng.range(0.2, 0.5) as f32, e).unwrap(),
        )
    } else {
        Brdf::Lafortune(
            Lafortune::new([
                LafortuneLobe {
                    c: Vec3::new(0.0, 0.0, 1.0),
                    exponent: rng.range(0.0, 2.0) as f32,
                    rho: 0.2,
                },
                LafortuneLobe {
                    c: Vec3::new(-rng.range(0.6, 1.0) as f32, -1.0, 1.0),
                    exponent: e,
                    rho: 0.5,
                },
            ])
            .unwrap(),
        )
    };
    let wo = dir(
        rng.range(0.0, 1.4) as f32,
        rng.range(0.0, std::f64::consts::TAU) as f32,
    );
    // Lights near the mirror direction half of the time (highlights), else anywhere above
    // or straddling the horizon.
    let mirror = lobe_sum_mirror(wo);
    let mut lights = vec![];
    for _ in 0..(1 + (rng.unit() < 0.3) as usize) {
        let axis = if rng.unit() < 0.5 {
            (mirror + 0.2 * Vec3::from(rng.sphere().map(|x| x as f32))).normalize()
        } else {
            dir(
                rng.range(0.0, 1.75) as f32,
                rng.range(0.0, std::f64::consts::TAU) as f32,
            )
        };
        lights.push((
            cap(axis, rng.log_range(0.01, 0.5) as f32),
            rng.range(0.5, 5.0) as f32,
        ));
    }
    // Occluders around the first light, not overlapping each other (weights 1).
    let mut occluders: Vec<(SphericalCap, f32)> = vec![];
    let (la, lr) = (lights[0].0.axis(), lights[0].0.half_angle());
    for _ in 0..rng.range(0.0, 8.0) as usize {
        let r = (rng.log_range(0.005, 0.2) as f32).min(lr * 2.0);
        let axis = (la + 1.5 * lr * Vec3::from(rng.sphere().map(|x| x as f32))).normalize();
        let c = cap(axis, r);
        let overlaps = occluders
            .iter()
            .any(|(o, _)| o.axis().dot(axis).clamp(-1.0, 1.0).acos() < o.half_angle() + r);
        if !overlaps {
            occluders.push((c, 1.0));
        }
    }
    Config {
        brdf,
        normal: Vec3::Z,
        wo,
        cosine: Cosine::WithLight,
        lights,
        occluders,
        fit: if rng.unit() < 0.5 {
            CapFit::L2
        } else {
            CapFit::EnergyPreserving
        },
    }
}

fn lobe_sum_mirror(wo: Vec3) -> Vec3 {
    steradian_core::lobe::reflect(wo, Vec3::Z)
}

#[test]
fn random_scenes_against_quadrature() {
    let mut rng = Rng::new(0x0b5e_55ed);
    let (mut worst, mut worst_model, mut sum) = (0.0f64, 0.0f64, 0.0);
    let n = 40;
    for i in 0..n {
        let cfg = random_config(&mut rng);
        let m = check(&format!("random #{i}"), &cfg);
        worst = worst.max(m.chain_error());
        worst_model = worst_model.max(m.model_error());
        sum += m.chain_error();
    }
    println!(
        "{n} random scenes: chain error mean {:.2e}·S, max {worst:.2e}·S; model error max {worst_model:.2e}·S",
        sum / n as f64
    );
}

/// Pruning with `t = 0` keeps every term and equals the full expansion computed by hand in
/// the same order (bit for bit), and the counters add up.
#[test]
fn zero_threshold_is_no_pruning() {
    let mut rng = Rng::new(7);
    for _ in 0..20 {
        let cfg = random_config(&mut rng);
        let b = cfg.build();
        let mut c = ProductCounts::default();
        let got = triple(&b.r, &b.l, &b.v, 0.0, &mut c);
        // Terms in expansion order (constant first), multiplied by hand.
        let terms = |s: &dyn LobeTerms| -> Vec<Option<CosineLobe>> {
            (s.constant() != 0.0)
                .then_some(None)
                .into_iter()
                .chain(s.lobes().iter().map(|l| Some(*l)))
                .collect()
        };
        let (kr, kl, kv) = (b.r.constant(), b.l.constant(), b.v.constant());
        let mut products = 0;
        // (constant, lobe) × (constant, lobe) → (constant or lobe).
        let mut mul = |x: (f32, Option<CosineLobe>), y: (f32, Option<CosineLobe>)| match (x, y) {
            ((a, None), (b, None)) => (a * b, None),
            ((k, None), (_, Some(l))) | ((_, Some(l)), (k, None)) => (
                0.0,
                Some(CosineLobe::saturating(
                    l.axis(),
                    k * l.scale(),
                    l.exponent(),
                )),
            ),
            ((_, Some(a)), (_, Some(b))) => {
                products += 1;
                (0.0, Some(lobe_sum::lobe_product(&a, &b)))
            }
        };
        let mut want = 0.0f32;
        for x in terms(&b.r) {
            for y in terms(&b.l) {
                let p = mul((kr, x), (kl, y));
                for z in terms(&b.v) {
                    let q = mul(p, (kv, z));
                    want += match q {
                        (k, None) => 4.0 * std::f32::consts::PI * k,
                        (_, Some(l)) => l.integral(),
                    };
                }
            }
        }
        assert_eq!(got.to_bits(), want.to_bits(), "{got} vs {want}");
        assert_eq!(c.computed, products);
        assert_eq!(c.dropped(), 0);
        assert_eq!(c.overflowed, 0);
        let rl = (b.r.terms() * b.l.terms()) as u64;
        assert_eq!(c.considered(), rl + rl * b.v.terms() as u64);
    }
}

/// Raising the threshold never computes more products, the counters add up at every
/// threshold, and the pruned result stays within the exact pruning bound of the module docs.
#[test]
fn pruning_error_and_counts() {
    let mut rng = Rng::new(11);
    for _ in 0..20 {
        let cfg = random_config(&mut rng);
        let b = cfg.build();
        let mut c0 = ProductCounts::default();
        let full = triple(&b.r, &b.l, &b.v, 0.0, &mut c0);
        let size = lobe_sum::triple(
            &b.r,
            &b.l,
            &LobeSum::<0>::with_constant(1.0),
            0.0,
            &mut ProductCounts::default(),
        )
        .abs();
        let rl = (b.r.terms() * b.l.terms()) as u64;
        let mut prev = c0.computed;
        for k in [1e-6f32, 1e-4, 1e-3, 1e-2, 0.1, 1.0] {
            let t = k * size;
            let mut c = ProductCounts::default();
            let got = triple(&b.r, &b.l, &b.v, t, &mut c);
            assert_eq!(c.considered(), rl + rl * b.v.terms() as u64);
            assert_eq!(c.kept() + c.pruned, c.computed + c.scaled);
            assert!(c.computed <= prev, "t = {t}: {} > {prev}", c.computed);
            prev = c.computed;
            // Terms of R·L dropped: each chain skips V's terms.
            let n1 = c.skipped_chain / b.v.terms() as u64;
            let n2 = c.pruned + c.skipped_bound - n1;
            // The bound of the module docs, with the kernel's integral error ε (≤ 0.5
            // assumed here) on the dropped terms.
            let eps = 1.5;
            let bound = t * (n1 as f32 * eps * eps * b.v.abs_bound() + n2 as f32 * eps);
            let slack = 1e-5 * (size + full.abs());
            assert!(
                (got - full).abs() <= bound + slack,
                "t = {t}: |{got} − {full}| > {bound} (n1 {n1}, n2 {n2})"
            );
        }
    }
}

/// `product_into` twice (storing R·L, then (R·L)·V) gives the streamed triple.
#[test]
fn stored_products_match_the_stream() {
    let mut rng = Rng::new(3);
    for _ in 0..10 {
        let cfg = random_config(&mut rng);
        let b = cfg.build();
        for t in [0.0f32, 1e-3] {
            let mut c1 = ProductCounts::default();
            let s = triple(&b.r, &b.l, &b.v, t, &mut c1);
            let mut c2 = ProductCounts::default();
            let mut rl = LobeSum::<8>::new();
            b.r.product_into(&b.l, t, &mut rl, &mut c2);
            let mut rlv = LobeSum::<600>::new();
            rl.product_into(&b.v, t, &mut rlv, &mut c2);
            let i = rlv.integral();
            assert!((s - i).abs() <= 1e-5 * (s.abs() + 1e-3), "{s} vs {i}");
            assert_eq!(c2.overflowed, 0);
            assert_eq!(c1.computed, c2.computed);
        }
    }
}

/// The report section on its own (prints its summary; the report runs it anyway).
/// `cargo test --release -p steradian-harness --test lobe_sum report_section -- --ignored --nocapture`
#[test]
#[ignore = "runs the report section (~seconds); the report covers it"]
fn report_section() {
    let t = std::time::Instant::now();
    let s = steradian_harness::report::lobe_sum::section(&Default::default()).unwrap();
    println!("{}\n{}", s.title, s.summary);
    println!("section took {:.1} s", t.elapsed().as_secs_f64());
    std::fs::write("/tmp/lobe_sum.svg", &s.files[0].1).unwrap();
}
