//! The weights `w(dist, depth)` of the quadtree visibility mask
//! (`steradian_core::lobe::mask`), fitted by least squares against exact visibility.
//!
//! For each deepest level `m` (1 ..= `MAX_DEPTH`), each `dist` sample (light half-angle
//! `α = atan(1/(2·dist))`, axis `+z`) and [`CONFIGS`] seeded configurations of 1–4
//! occluder caps that overlap the light (radii `0.15α … 2α`, at most 1.5 rad): the mask is
//! built down to depth `m` with [`LEAVES`]; `S_d` is the sum over its depth-`d` leaves of
//! `f·∫ L·c_leaf / ∫ L` (`f` the leaf's covered fraction; the light lobe `L` and the leaf
//! lobes energy-preserving, as the `lobes` method uses them; products by the built-in
//! kernel); the exact occluded fraction `o*` of the light's cap comes from a 64 × 128
//! equal-solid-angle midpoint grid over it. The model's occluded fraction is
//! `Σ_d w_d·S_d`, linear in the weights, so `min Σ_k (Σ_d w_d S_dk − o*_k)² + λ·Σ_d
//! (w_d − 1)²` over `d ≤ m` is one normal-equation solve per `m` and `dist` (`nalgebra`'s
//! Cholesky; the small ridge `λ` = [`RIDGE`]·configs pulls a depth that no configuration
//! reaches toward 1); the rows of depths below `m` hold 1, unread.

use std::f64::consts::TAU;

use nalgebra::{DMatrix, DVector};
use steradian_core::Vec3;
use steradian_core::lobe::cap::{CapFit, SphericalCap};
use steradian_core::lobe::mask::{
    Leaves, MAX_DEPTH, WEIGHT_DEPTHS, WEIGHT_DIST_RANGE, WEIGHT_DISTS, WEIGHT_LEN,
    WEIGHT_TABLE_NAME, shadow_leaves,
};
use steradian_core::lobe::product;
use steradian_core::table::{HEADER_LEN, Spec, encode_into};

use crate::rng::Rng;

/// Configurations per `dist` sample.
pub const CONFIGS: usize = 300;
/// The leaf rule the weights are fitted for (the `lobes` method's default).
pub const LEAVES: Leaves = Leaves::Fraction;
/// Ridge toward `w = 1`, per configuration.
pub const RIDGE: f64 = 1e-4;

/// `dist` of the `i`-th sample.
pub fn dist_sample(i: usize) -> f64 {
    let (lo, hi) = (WEIGHT_DIST_RANGE.0 as f64, WEIGHT_DIST_RANGE.1 as f64);
    (lo.ln() + (hi.ln() - lo.ln()) * i as f64 / (WEIGHT_DISTS - 1) as f64).exp()
}

/// A unit vector at polar angle `th`, azimuth `ph` about `+z`.
fn polar(th: f64, ph: f64) -> glam::DVec3 {
    glam::DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos())
}

/// One configuration: occluder caps overlapping a light of half-angle `alpha` about `+z`.
pub fn configuration(alpha: f64, rng: &mut Rng) -> Vec<(glam::DVec3, f64)> {
    let m = 1 + (rng.next_u64() % 4) as usize;
    (0..m)
        .map(|_| {
            let beta = (alpha * rng.log_range(0.15, 2.0)).min(1.5);
            let th = rng.range(0.0, alpha + beta);
            (polar(th, rng.range(0.0, TAU)), beta)
        })
        .collect()
}

/// The exact occluded fraction of the light's cap (midpoint grid, equal solid angles).
pub fn occluded_fraction(alpha: f64, occ: &[(glam::DVec3, f64)]) -> f64 {
    let (nr, np) = (64, 128);
    let omc = 1.0 - alpha.cos();
    let cos_b: Vec<f64> = occ.iter().map(|o| o.1.cos()).collect();
    let mut hit = 0usize;
    for i in 0..nr {
        let c = 1.0 - (i as f64 + 0.5) / nr as f64 * omc;
        let th = c.clamp(-1.0, 1.0).acos();
        for j in 0..np {
            let d = polar(th, (j as f64 + 0.5) / np as f64 * TAU);
            if occ.iter().zip(&cos_b).any(|(o, cb)| d.dot(o.0) >= *cb) {
                hit += 1;
            }
        }
    }
    hit as f64 / (nr * np) as f64
}

/// `S_d`: per depth, the summed `f·∫ L·c_leaf / ∫ L` of the leaves of the mask cut at
/// `max_depth`.
pub fn leaf_sums(alpha: f64, occ: &[(glam::DVec3, f64)], max_depth: u32) -> [f64; WEIGHT_DEPTHS] {
    let light = SphericalCap::new(Vec3::Z, alpha as f32).expect("valid light");
    let l = light.lobe(1.0, CapFit::EnergyPreserving);
    let caps: Vec<SphericalCap> = occ
        .iter()
        .map(|(a, b)| SphericalCap::new(a.as_vec3(), *b as f32).expect("valid occluder"))
        .collect();
    let mut s = [0.0; WEIGHT_DEPTHS];
    let total = l.integral() as f64;
    shadow_leaves(&light, &caps, max_depth, LEAVES, |cap, d, f| {
        let c = cap.lobe(1.0, CapFit::EnergyPreserving);
        s[d as usize] += f64::from(f) * product::product(&l, &c).integral() as f64 / total;
    });
    s
}

/// The fitted weights, value `i + WEIGHT_DISTS·(depth + WEIGHT_DEPTHS·(max_depth − 1))`
/// (`steradian_core::lobe::mask::WEIGHT_LEN`).
pub fn fit() -> Vec<f32> {
    let mut out = vec![1.0f32; WEIGHT_LEN];
    for m in 1..=MAX_DEPTH {
        let (base, nd) = (
            WEIGHT_DISTS * WEIGHT_DEPTHS * (m as usize - 1),
            m as usize + 1,
        );
        for i in 0..WEIGHT_DISTS {
            let alpha = (1.0 / (2.0 * dist_sample(i))).atan();
            let mut rng = Rng::new(0x6d61_736b ^ ((i as u64) << 32));
            let mut a = DMatrix::<f64>::zeros(CONFIGS, nd);
            let mut y = DVector::<f64>::zeros(CONFIGS);
            for k in 0..CONFIGS {
                let occ = configuration(alpha, &mut rng);
                let s = leaf_sums(alpha, &occ, m);
                for d in 0..nd {
                    a[(k, d)] = s[d];
                }
                y[k] = occluded_fraction(alpha, &occ);
            }
            let lambda = RIDGE * CONFIGS as f64;
            let mut n = a.transpose() * &a;
            let mut rhs = a.transpose() * &y;
            for d in 0..nd {
                n[(d, d)] += lambda;
                rhs[d] += lambda;
            }
            let w = n
                .cholesky()
                .expect("the ridge makes the normal matrix positive definite")
                .solve(&rhs);
            for d in 0..nd {
                out[base + i + WEIGHT_DISTS * d] = w[d] as f32;
            }
        }
    }
    out
}

/// The complete table file.
pub fn generate() -> Vec<u8> {
    let values = fit();
    let spec = Spec {
        name: WEIGHT_TABLE_NAME,
        rank: 3,
        channels: 1,
        dims: [WEIGHT_DISTS as u32, WEIGHT_DEPTHS as u32, MAX_DEPTH, 1],
        lo: [(WEIGHT_DIST_RANGE.0 as f64).ln(), 0.0, 1.0, 0.0],
        hi: [
            (WEIGHT_DIST_RANGE.1 as f64).ln(),
            (WEIGHT_DEPTHS - 1) as f64,
            MAX_DEPTH as f64,
            1.0,
        ],
    };
    let mut out = vec![0u8; HEADER_LEN + 4 * values.len()];
    encode_into(&spec, &values, &mut out).expect("sizes agree by construction");
    out
}
