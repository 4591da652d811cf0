//! The f64 references of the `steradian-reference` crate under their harness paths, and the
//! adapters from core's `f32` types to the references' `f64` ones (kept here so that the
//! reference crate does not depend on the code it checks).

pub use steradian_reference::lobe::{
    brdf, cap, cap_solid_angle, lobe_eval, lobe_integral, normalize, product, triple,
};
pub use steradian_reference::quad;
pub use steradian_reference::rsl::{hemisphere_map, hemisphere_unmap};

use steradian_core::lobe::CosineLobe;
use steradian_core::lobe::brdf as core_brdf;
use steradian_core::lobe::cap::SphericalCap;
use steradian_core::lobe::sum::LobeTerms;

/// The f32 lobe, widened (axis renormalised in f64).
pub fn lobe_of(l: &CosineLobe) -> triple::Lobe {
    let a = l.axis();
    triple::Lobe::new(
        [a.x as f64, a.y as f64, a.z as f64],
        l.scale() as f64,
        l.exponent() as f64,
    )
}

/// The f32 cap, widened.
pub fn cap_of(c: &SphericalCap) -> triple::Cap {
    let a = c.axis();
    triple::Cap::new([a.x as f64, a.y as f64, a.z as f64], c.half_angle() as f64)
}

/// The terms of a core lobe sum (`k + Σ lobes`).
pub fn terms_of(s: &impl LobeTerms) -> Vec<triple::Term> {
    let mut t: Vec<triple::Term> = s
        .lobes()
        .iter()
        .map(|l| triple::Term::Lobe(lobe_of(l)))
        .collect();
    if s.constant() != 0.0 {
        t.insert(0, triple::Term::Constant(s.constant() as f64));
    }
    t
}

/// A core BRDF model's parameters, widened to the reference [`brdf::Model`].
pub trait AsModel {
    /// The reference model with the same parameters.
    fn model(&self) -> brdf::Model;
}

impl AsModel for core_brdf::Lambert {
    fn model(&self) -> brdf::Model {
        brdf::Model::Lambert {
            a: self.albedo() as f64,
        }
    }
}
impl AsModel for core_brdf::Phong {
    fn model(&self) -> brdf::Model {
        let (kd, ks, e) = self.params();
        brdf::Model::Phong {
            kd: kd as f64,
            ks: ks as f64,
            e: e as f64,
        }
    }
}
impl AsModel for core_brdf::BlinnPhong {
    fn model(&self) -> brdf::Model {
        let (kd, ks, e) = self.params();
        brdf::Model::BlinnPhong {
            kd: kd as f64,
            ks: ks as f64,
            e: e as f64,
        }
    }
}
impl AsModel for core_brdf::Ward {
    fn model(&self) -> brdf::Model {
        let (rd, rs, ax, ay) = self.params();
        brdf::Model::Ward {
            rd: rd as f64,
            rs: rs as f64,
            ax: ax as f64,
            ay: ay as f64,
        }
    }
}
impl AsModel for core_brdf::Ggx {
    fn model(&self) -> brdf::Model {
        let (kd, f0, alpha) = self.params();
        brdf::Model::Ggx {
            kd: kd as f64,
            f0: f0 as f64,
            alpha: alpha as f64,
        }
    }
}

impl AsModel for steradian_core::lobe::Lafortune<2> {
    fn model(&self) -> brdf::Model {
        let l = self.lobe_params();
        let p = |k: usize| {
            [
                l[k].c.x as f64,
                l[k].c.y as f64,
                l[k].c.z as f64,
                l[k].exponent as f64,
                l[k].rho as f64,
            ]
        };
        brdf::Model::Lafortune {
            lobes: [p(0), p(1)],
        }
    }
}

/// `ρ cos θᵢ` of a core model through its `Brdf` impl, for directions given in `f64`.
pub fn core_eval<B: core_brdf::Brdf + ?Sized>(b: &B, wi: [f64; 3], wo: [f64; 3]) -> f32 {
    let v = |d: [f64; 3]| steradian_core::Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
    b.eval(v(wi), v(wo))
}
