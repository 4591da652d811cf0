//! Decomposition of an environment map into `K` rotatable square lights (rotatable square
//! lights paper, section 4.1: the fit of 4.1.1 with the area penalty of eq. 7, the
//! bottom-up merging of 4.1.2 / Figure 5).
//!
//! ## The RSL fit of a region (section 4.1.1, eq. 7)
//!
//! A region `S` (a set of cube-map texels, luminance `L`) is fitted by a square of uniform
//! radiance `I` centred on `c` with half-diagonal `ρ`, rotated by `θ` about `c`. We work in
//! the Lambert azimuthal equal-area plane around `c`, `q = (x, y)·sqrt(2/(1 + z))` in a frame
//! with `z = c` (area in `q` = solid angle, so no distortion of areas at any distance from
//! `c`); the square has area `A = 2ρ²` sr. With `T = L` on `S` and `F = I` on the square,
//!
//! ```text
//!   η²(θ) = ∫ (T − F)² = Q − 2·I·G(θ) + I²·A,     Q = ∫_S L²,  G(θ) = ∫_{S ∩ square(θ)} L,
//!   I = E/A  (E = ∫_S L: energy preserved, as the paper sets I),
//!   objective (eq. 7) = |S| · mean over θ ∈ {0, π/8, π/4, 3π/8} of η²(θ).
//! ```
//!
//! `c` is the better of the luminance-weighted and the solid-angle-weighted mean direction
//! of the region; `ρ` is optimised exactly for the model below (the paper optimises `c`
//! and `r`; it does not say how). The coverage of texel `k` (solid angle `w_k`, Lambert
//! position `q_k`) by the rotated square is modelled as a linear ramp in the square's
//! half-side across the texel's width `sqrt(w_k)`, around the texel's Chebyshev distance
//! from `c` in the rotated frame. `G(ρ)` and the covered area `C(ρ)` are then piecewise
//! linear in `ρ`, and the objective is minimised exactly over the breakpoints, the
//! stationary point within each segment, and the points where `C = A`. Where the model
//! claims more covered area than the square has (`C > A`, squares of texel size) `G` is
//! scaled by `A/C`; `ρ` is kept at least one texel (`A ≥ min w_k`) and at most `4π` sr.
//!
//! ## Merging (section 4.1.2, Figure 5)
//!
//! Every texel starts as a region; at each step the pair of adjacent regions with the least
//! merge key is merged, until `K` regions remain. Figure 5 rescans every region and its
//! neighbours at each step (kept here as [`decompose_rescan`], the reference and the timing
//! baseline); [`decompose`] keeps every candidate pair in a binary heap and invalidates
//! lazily: a merge creates a region with a new id, only pairs with the new region are
//! fitted and pushed, and popped pairs whose regions no longer exist are skipped. A pair's
//! key depends only on its two (immutable) regions, so both select the same pair at each
//! step (same key, same ties: `(key, smallest texel of each region)`) and give the same
//! partition. One run yields every requested `K` (the partitions are nested). Measured on
//! the 2-core dev machine (report section `rsl`): 6 × 32 × 32 down to `K = 10` in
//! 0.3–0.9 s (the paper: about 2 minutes); on 6 × 8 × 8 the rescan is about 15× slower than
//! the heap, and the gap grows with the square of the texel count.
//!
//! ## Merge objectives ([`Options::objective`])
//!
//! - [`Objective::Paper`]: the key is the merged region's eq. 7 objective `|S|·mean_θ η²`
//!   (the paper: "the merged subregion has the least RSL fitting error").
//! - [`Objective::Bound`] (default): the key is the *increase* of the summed eq. 13 bound,
//!   `B(a ∪ b) − B(a) − B(b)`, with
//!
//!   ```text
//!   B(S) = E·σ̂_V·σ̂_ρ + w_L·sqrt(|S|·η̄²)·(σ̂_V + σ̂_ρ + σ̂_V·σ̂_ρ),
//!   σ̂_V = ½·(|S|/1 sr)^¼,  σ̂_ρ = (|S|/1 sr)^½,  w_L = 30   ([`bound_cost`]).
//!   ```
//!
//!   Why: the shading error of region `S` is the multi-product error of eq. 5, bounded by
//!   eq. 13, `|S|·(u_L·σ_V·σ_ρ + u_V·σ_ρ·σ_L + u_ρ·σ_L·σ_V + m_L·m_V·m_ρ)`, plus the
//!   error of replacing the region by its square (eq. 6). With `u_V, u_ρ` normalised to 1
//!   and `σ_V, σ_ρ` replaced by the paper's own scaling laws (section 4.1.1 and 6.1:
//!   `E(σ_V²) ∝ sqrt|S|`, and a smooth `ρ·cos` varying linearly across the region), the
//!   first term is `E·σ̂_V·σ̂_ρ` — energy × angular extent — which eq. 7 ignores: eq. 7 is
//!   `|S|²σ_L²` plus the square mismatch, zero for any uniform region however large, so the
//!   paper's merge builds big uniform sky regions that straddle contact shadows and whose
//!   `ρ` varies across them. The light terms use the RSL fit in place of `|S|·σ_L`
//!   (`sqrt(|S|·η̄²) ≥ |S|·σ_L`, and it includes the square mismatch of eq. 6); the third
//!   moments are modelled by the second (`m ≈ σ`). The bound is summed over regions, so the
//!   greedy step takes the merge that raises the sum least (the merged value as key would
//!   favour merging small dark regions with anything). `w_L` and the exponents are a
//!   model, not a theorem: the report section `shade` measures both objectives per `K`
//!   against the exact integral, with the true eq. 13 bound beside them.
//!
//! **Deviation, optional:** the paper merges only regions on the same cube face "for
//! simplicity"; our fit works on the sphere, so merging across face edges is the default
//! ([`Options::cross_face`]); with `false` the paper's rule holds (then `K ≥ 6`).
//!
//! ## Radiance gradient (an extension)
//!
//! The paper's light is uniform over its square. Each region also gets a radiance gradient
//! per channel for the linear model `L(ω) = E/Ω + G·(ω − c)` over the square
//! ([`crate::rsl::Rsl::gradient`], read only by the moments kernel,
//! [`crate::rsl::shade::light_moments`]). `G` is not a least-squares fit over the
//! region: the square is centred where the fit put it (often the region's luminance
//! centroid) and has the square's extent, not the region's, so a least-squares gradient
//! moves the light's energy centroid a second time and overshoots across narrow regions
//! (measured: it made the `K = 30` default-sky error worse, 0.51 % → 0.73 % for the exact
//! integral over the squares). Instead `G` matches the first moment of radiance about `c`:
//! the square's `∫(E/Ω + G·q)·q dω = G·Ω²/12` (side `√Ω` on the tangent plane) equals the
//! region's `Σ_k L_k·w_k·q_k` with `q = ω − (ω·c)·c`, so `G = 12·Σ_k L_k w_k q_k/Ω²`
//! ([`moment_gradient`]). It costs nothing in the decomposition and keeps the first-order
//! light–BRDF covariance that a uniform square drops; the harness measures it (report
//! section `shade`, variant `SquareLinear`).
//!
//! ## Fit error
//!
//! Two measures, both luminance, relative L2 over the sphere (solid-angle weighted):
//! [`Decomposition::piecewise_rel_l2`], the environment against its piecewise-constant
//! average per region, `sqrt(Σ_k w_k (L_k − E_r/|S_r|)² / Σ_k w_k L_k²)` (non-increasing in
//! `K` for nested partitions), and [`Decomposition::rsl_rel_l2`], the paper's RSL fitting
//! error, `sqrt(Σ_r mean_θ η_r²(θ) / Σ_k w_k L_k²)` (the environment against the squares
//! themselves). With a sun both L2 measures are dominated by the few texels around it;
//! [`Decomposition::piecewise_rel_l1`] (relative L1 against the per-region average) shows
//! the rest of the sky.

use alloc::collections::{BTreeSet, BinaryHeap};
use alloc::format;
use alloc::vec;
use alloc::vec::Vec;
use core::cmp::Ordering;
use core::f64::consts::{PI, SQRT_2};

use glam::DVec3;

use crate::math;
use crate::rsl::Rsl;
use crate::rsl::cubemap::{CubeMap, EnvError};

/// What a caller of [`decompose_observed`] sees of a run: a clock for
/// [`Decomposition::seconds`] and the progress of the merging (core has neither a clock nor
/// a terminal; the harness's observer is `std::time::Instant` and a progress bar).
pub trait Observer {
    /// Seconds since the run started (`0` without a clock).
    fn seconds(&mut self) -> f64 {
        0.0
    }
    /// The run will make `total` merges.
    fn start(&mut self, _total: u64) {}
    /// One more merge done.
    fn merged(&mut self) {}
}

/// No clock, no progress.
impl Observer for () {}

/// The square's rotations over which the fit error is averaged (the paper's).
pub const ROTATIONS: [f64; 4] = [0.0, PI / 8.0, PI / 4.0, 3.0 * PI / 8.0];

/// The numbers of lights the paper reports.
pub const PAPER_KS: [usize; 4] = [10, 30, 60, 100];

/// What to decompose into.
#[derive(Clone, Debug)]
pub struct Options {
    /// Numbers of lights wanted (any order; one partition is returned per entry).
    pub ks: Vec<usize>,
    /// Merge across cube-face edges (default), or only within a face as the paper does.
    pub cross_face: bool,
    /// Whether the caller's observer should show progress (the harness: a progress bar
    /// when the run takes more than a second). Core itself prints nothing.
    pub progress: bool,
    /// The merge objective (default [`Objective::Bound`]).
    pub objective: Objective,
}

/// Which cost the merging minimises (module docs, "Merge objectives").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Objective {
    /// The paper's eq. 7: `|S|·mean_θ η²(θ)` ([`Fit::objective`]).
    Paper,
    /// The eq. 13 bound with modelled BRDF and visibility deviations ([`Fit::bound`]).
    #[default]
    Bound,
}

/// `σ̂_V(|S|) = ½·(|S|/1 sr)^¼`: modelled standard deviation of visibility over a region
/// (Agarwal et al.: `E(σ_V²) ∝ sqrt|S|`, saturating at ½ for a half-shadowed steradian).
const SIGMA_V_SCALE: f64 = 0.5;
/// `σ̂_ρ(|S|) = (|S|/1 sr)^½`: modelled relative standard deviation of `ρ·cos θ` over a
/// region (a smooth BRDF varies linearly across it; not capped, so that a region of a
/// hemisphere, which no square represents, is expensive).
const SIGMA_RHO_SCALE: f64 = 1.0;
/// Weight of the light-variance terms of eq. 13 against `u_L·σ_V·σ_ρ` (chosen by the
/// measurement in the report section `shade`: the weights 10, 30 and 100 gave K = 30
/// kernel errors of 1.03 / 0.73 / 0.85 % on the default sky, 0.68 / 0.59 / 0.55 % on
/// `sky.exr`).
const LIGHT_WEIGHT: f64 = 30.0;

/// The eq. 13 merge cost of a region (module docs, "Merge objectives"):
/// `E·σ̂_V·σ̂_ρ + w_L·sqrt(|S|·η̄²)·(σ̂_V + σ̂_ρ + σ̂_V·σ̂_ρ)` with `E = ∫_S L` (luminance),
/// `η̄²` the rotation-averaged RSL fitting error ([`Fit::eta2`]) and `σ̂_V`, `σ̂_ρ` the
/// modelled deviations of visibility and BRDF at solid angle `|S|` sr. Non-negative;
/// non-finite or negative inputs are clamped to 0.
pub fn bound_cost(solid_angle: f64, energy: f64, eta2: f64) -> f64 {
    let pos = |x: f64| if x > 0.0 && x.is_finite() { x } else { 0.0 };
    let s = pos(solid_angle);
    let sv = SIGMA_V_SCALE * math::sqrt64(math::sqrt64(s));
    let sr = SIGMA_RHO_SCALE * math::sqrt64(s);
    let sl = math::sqrt64(s * pos(eta2));
    pos(energy) * sv * sr + LIGHT_WEIGHT * sl * (sv + sr + sv * sr)
}

impl Default for Options {
    fn default() -> Self {
        Options {
            ks: PAPER_KS.to_vec(),
            cross_face: true,
            progress: true,
            objective: Objective::Bound,
        }
    }
}

impl Options {
    /// The defaults for the numbers of lights `ks`, without a progress bar (tests, benches
    /// and report sections, which show their own).
    pub fn quiet(ks: &[usize]) -> Options {
        Options {
            ks: ks.to_vec(),
            progress: false,
            ..Options::default()
        }
    }
}

/// The RSL fitted to a region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// Unit centre direction `c`.
    pub centre: DVec3,
    /// Unit tangent at `c` of the best-fitting rotation among [`ROTATIONS`].
    pub tangent: DVec3,
    /// The best-fitting rotation (radians, from the frame of `c` built by [`basis`]).
    pub rotation: f64,
    /// Solid angle of the square, `2ρ²` sr.
    pub solid_angle: f64,
    /// Rotation-averaged fitting error `mean_θ η²(θ)` (luminance² · sr).
    pub eta2: f64,
    /// The merge objective of eq. 7, `|S| · eta2`.
    pub objective: f64,
    /// The eq. 13 merge objective ([`bound_cost`]).
    pub bound: f64,
}

/// One region of a decomposition and its RSL.
#[derive(Clone, Debug)]
pub struct Region {
    /// Flat cube-map indices of its texels, ascending (for exact reference integration).
    pub texels: Vec<u32>,
    /// `∫_S L dω`, RGB (the RSL's `I_i`).
    pub energy: [f64; 3],
    /// Solid angle of the region itself, `|S|`.
    pub solid_angle: f64,
    /// `∫_S L dω` of the luminance.
    pub luminance_energy: f64,
    /// `∫_S L² dω` of the luminance.
    pub luminance_sq: f64,
    /// The fitted square.
    pub fit: Fit,
    /// Radiance gradient per channel ([`moment_gradient`], module docs "Radiance gradient").
    pub gradient: [DVec3; 3],
}

impl Region {
    /// The region as an [`Rsl`] (f32): centre, tangent, square solid angle, energy and
    /// radiance gradient.
    pub fn rsl(&self) -> Result<Rsl, crate::Error> {
        let f = &self.fit;
        Rsl::new(
            f.centre.as_vec3(),
            f.tangent.as_vec3(),
            (f.solid_angle as f32).clamp(f32::MIN_POSITIVE, crate::rsl::MAX_SOLID_ANGLE),
            self.energy.map(|e| e as f32),
        )?
        .with_gradient(self.gradient.map(|g| g.as_vec3()))
    }
}

/// The radiance gradient of the linear light model `L(ω) = E/Ω + G·(ω − c)` over a square
/// of solid angle `omega` centred on `centre` that has the same first moment of radiance
/// about `c` as the region's texels (module docs, "Radiance gradient"):
/// `G = 12·Σ_k L_k·w_k·(d_k − (d_k·c)·c) / Ω²`, per channel.
pub fn moment_gradient(cube: &CubeMap, texels: &[u32], centre: DVec3, omega: f64) -> [DVec3; 3] {
    let mut m = [DVec3::ZERO; 3];
    for &t in texels {
        let d = cube.dirs()[t as usize];
        let q = (d - centre * d.dot(centre)) * cube.solid_angles()[t as usize];
        let rgb = cube.texels()[t as usize];
        for c in 0..3 {
            m[c] += q * f64::from(rgb[c]);
        }
    }
    let k = if omega > 0.0 {
        12.0 / (omega * omega)
    } else {
        0.0
    };
    m.map(|v| v * k)
}

/// A partition of the cube map into `k` regions.
#[derive(Clone, Debug)]
pub struct Decomposition {
    /// Number of regions.
    pub k: usize,
    /// The regions, ordered by their smallest texel index.
    pub regions: Vec<Region>,
    /// Region index of every texel.
    pub region_of: Vec<u32>,
    /// Seconds from the start of the decomposition until this partition was reached.
    pub seconds: f64,
    /// Whether merges crossed cube-face edges.
    pub cross_face: bool,
    /// The merge objective that produced it.
    pub merge: Objective,
}

impl Decomposition {
    /// The RSLs, in region order.
    pub fn rsls(&self) -> Result<Vec<Rsl>, crate::Error> {
        self.regions.iter().map(Region::rsl).collect()
    }

    /// `(Σ_k dev(w_k, L_k − E_r/|S_r|), Σ_k mag(w_k, L_k))` over the texels (luminance,
    /// solid angle `w_k`, `r` the texel's region).
    fn piecewise_sums(
        &self,
        cube: &CubeMap,
        dev: impl Fn(f64, f64) -> f64,
        mag: impl Fn(f64, f64) -> f64,
    ) -> (f64, f64) {
        let (mut num, mut den) = (0.0, 0.0);
        for (k, &r) in self.region_of.iter().enumerate() {
            let reg = &self.regions[r as usize];
            let mean = reg.luminance_energy / reg.solid_angle;
            let l = cube.luminance(k);
            let w = cube.solid_angles()[k];
            num += dev(w, l - mean);
            den += mag(w, l);
        }
        (num, den)
    }

    /// Relative L2 error of the luminance against its per-region average (module docs).
    pub fn piecewise_rel_l2(&self, cube: &CubeMap) -> f64 {
        let (num, den) = self.piecewise_sums(cube, |w, d| w * d * d, |w, l| w * l * l);
        if den > 0.0 {
            math::sqrt64(num / den)
        } else {
            0.0
        }
    }

    /// Relative L1 error of the luminance against its per-region average,
    /// `Σ_k w_k |L_k − E_r/|S_r|| / Σ_k w_k L_k` (less dominated by the brightest texels
    /// than the L2 measures).
    pub fn piecewise_rel_l1(&self, cube: &CubeMap) -> f64 {
        let (num, den) = self.piecewise_sums(cube, |w, d| w * d.abs(), |w, l| w * l);
        if den > 0.0 { num / den } else { 0.0 }
    }

    /// The paper's RSL fitting error, relative (module docs).
    pub fn rsl_rel_l2(&self) -> f64 {
        let num: f64 = self.regions.iter().map(|r| r.fit.eta2).sum();
        let den: f64 = self.regions.iter().map(|r| r.luminance_sq).sum();
        if den > 0.0 {
            math::sqrt64(num / den)
        } else {
            0.0
        }
    }

    /// Sum of the objectives of eq. 7 over the regions.
    pub fn objective(&self) -> f64 {
        self.regions.iter().map(|r| r.fit.objective).sum()
    }

    /// Sum of the modelled eq. 13 costs ([`bound_cost`]) over the regions.
    pub fn bound(&self) -> f64 {
        self.regions.iter().map(|r| r.fit.bound).sum()
    }
}

/// A right-handed orthonormal `(t, b)` around unit `c` (Duff et al. 2017, f64).
pub fn basis(c: DVec3) -> (DVec3, DVec3) {
    let sign = if c.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + c.z);
    let b = c.x * c.y * a;
    let t = DVec3::new(1.0 + sign * c.x * c.x * a, sign * b, -sign * c.x);
    let bt = DVec3::new(b, sign + c.y * c.y * a, -c.y);
    (t, bt)
}

/// Lambert azimuthal equal-area coordinates `q = (x, y)·sqrt(2/(1 + z))` of the unit
/// direction `d` in the frame `(t, b, c)` (module docs: area in `q` = solid angle).
#[inline]
fn lambert(d: DVec3, t: DVec3, bt: DVec3, c: DVec3) -> (f64, f64) {
    let (x, y, z) = (d.dot(t), d.dot(bt), d.dot(c));
    let s = math::sqrt64(2.0 / (1.0 + z).max(1e-12));
    (x * s, y * s)
}

/// Chebyshev distance from the origin of `q` in the frame turned by `θ`, `(cs, sn) =
/// (cos θ, sin θ)`: the half-side of the smallest square of rotation `θ` containing `q`.
#[inline]
fn chebyshev((qx, qy): (f64, f64), (cs, sn): (f64, f64)) -> f64 {
    let xr = qx * cs + qy * sn;
    let yr = -qx * sn + qy * cs;
    xr.abs().max(yr.abs())
}

/// Per-texel data of the cube map, f64.
struct Texels {
    dir: Vec<DVec3>,
    w: Vec<f64>,
    lum: Vec<f64>,
}

impl Texels {
    fn new(cube: &CubeMap) -> Texels {
        Texels {
            dir: cube.dirs().to_vec(),
            w: cube.solid_angles().to_vec(),
            lum: (0..cube.len()).map(|k| cube.luminance(k)).collect(),
        }
    }
}

/// Two ascending index lists merged in ascending order (the canonical order of a union,
/// so that every sum over a region is evaluated in the same order whichever way it was
/// formed).
fn merged<'a>(a: &'a [u32], b: &'a [u32]) -> impl Iterator<Item = u32> + 'a {
    let (mut i, mut j) = (0, 0);
    core::iter::from_fn(move || match (a.get(i), b.get(j)) {
        (Some(&x), Some(&y)) => {
            if x <= y {
                i += 1;
                Some(x)
            } else {
                j += 1;
                Some(y)
            }
        }
        (Some(&x), None) => {
            i += 1;
            Some(x)
        }
        (None, Some(&y)) => {
            j += 1;
            Some(y)
        }
        (None, None) => None,
    })
}

/// Reusable scratch space for fits.
#[derive(Default)]
struct Fitter {
    events: Vec<(f64, f64, f64)>,
}

struct Sums {
    s: f64,
    e: f64,
    q: f64,
    w_min: f64,
    m_area: DVec3,
    m_lum: DVec3,
    first: DVec3,
}

impl Fitter {
    fn sums(td: &Texels, it: impl Iterator<Item = u32>) -> Sums {
        let mut s = Sums {
            s: 0.0,
            e: 0.0,
            q: 0.0,
            w_min: f64::INFINITY,
            m_area: DVec3::ZERO,
            m_lum: DVec3::ZERO,
            first: DVec3::ZERO,
        };
        for k in it {
            let k = k as usize;
            let (w, l, d) = (td.w[k], td.lum[k], td.dir[k]);
            if s.s == 0.0 {
                s.first = d;
            }
            s.s += w;
            s.e += l * w;
            s.q += l * l * w;
            s.w_min = s.w_min.min(w);
            s.m_area += d * w;
            s.m_lum += d * (l * w);
        }
        s
    }

    /// Fits the region `a ∪ b` (ascending lists). Rotation and tangent are left at the
    /// frame's (see [`Fitter::rotation`]).
    fn fit(&mut self, td: &Texels, a: &[u32], b: &[u32]) -> Fit {
        let sums = Self::sums(td, merged(a, b));
        let mut cands: [Option<DVec3>; 2] = [None, None];
        if sums.e > 0.0 && sums.m_lum.length() > 1e-9 * sums.e {
            cands[0] = Some(sums.m_lum.normalize());
        }
        if sums.m_area.length() > 1e-9 * sums.s {
            let c = sums.m_area.normalize();
            if cands[0].is_none_or(|c0| c0.dot(c) < 1.0 - 1e-15) {
                cands[1] = Some(c);
            }
        }
        if cands.iter().all(Option::is_none) {
            cands[0] = Some(sums.first);
        }
        let mut best: Option<(f64, f64, DVec3)> = None;
        for c in cands.into_iter().flatten() {
            let (f, rho) = self.fit_radius(td, a, b, c, &sums);
            if best.is_none_or(|(bf, _, _)| f < bf) {
                best = Some((f, rho, c));
            }
        }
        let (f, rho, c) = best.unwrap_or((0.0, math::sqrt64(sums.s * 0.5), sums.first));
        Fit {
            centre: c,
            tangent: basis(c).0,
            rotation: 0.0,
            solid_angle: 2.0 * rho * rho,
            eta2: f,
            objective: sums.s * f,
            bound: bound_cost(sums.s, sums.e, f),
        }
    }

    /// The objective's `mean_θ η²` at half-diagonal `rho` from the modelled `G`, `C`.
    #[inline]
    fn eval(rho: f64, g: f64, c: f64, sums: &Sums) -> f64 {
        let area = 2.0 * rho * rho;
        let g = if c > area { g * area / c } else { g };
        (sums.q - 2.0 * sums.e * g / area + sums.e * sums.e / area).max(0.0)
    }

    /// Exact minimiser over `ρ` of the modelled objective for centre `c`: `(η², ρ)`.
    fn fit_radius(
        &mut self,
        td: &Texels,
        a: &[u32],
        b: &[u32],
        c: DVec3,
        sums: &Sums,
    ) -> (f64, f64) {
        let (t, bt) = basis(c);
        let rho_min = math::sqrt64(sums.w_min * 0.5);
        let rho_max = math::sqrt64(2.0 * PI);
        let rho_s = math::sqrt64(sums.s * 0.5).clamp(rho_min, rho_max);
        if sums.e <= 0.0 {
            return (Self::eval(rho_s, 0.0, 0.0, sums), rho_s);
        }
        let rot: [(f64, f64); 4] = ROTATIONS.map(|r| (math::cos64(r), math::sin64(r)));
        let nr = ROTATIONS.len() as f64;
        let ev = &mut self.events;
        ev.clear();
        for k in merged(a, b) {
            let k = k as usize;
            let q = lambert(td.dir[k], t, bt, c);
            let h = 0.5 * math::sqrt64(td.w[k]);
            let wl = td.lum[k] * td.w[k] / nr;
            let wc = td.w[k] / nr;
            let inv = 1.0 / (2.0 * SQRT_2 * h);
            for &cs_sn in &rot {
                let dd = chebyshev(q, cs_sn);
                ev.push((SQRT_2 * (dd - h), wl * inv, wc * inv));
                ev.push((SQRT_2 * (dd + h), -wl * inv, -wc * inv));
            }
        }
        ev.push((rho_min, 0.0, 0.0));
        ev.push((rho_s, 0.0, 0.0));
        ev.sort_unstable_by(|p, q| p.0.total_cmp(&q.0));
        let (mut g, mut cc, mut sg, mut sc) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let mut rp = ev[0].0;
        // The markers at ρ_min and ρ_S are always considered, so `best` gets set.
        let mut best = (f64::INFINITY, rho_s);
        let mut consider = |rho: f64, g: f64, cc: f64| {
            if rho >= rho_min && rho <= rho_max {
                let f = Self::eval(rho, g, cc, sums);
                if f < best.0 || (f == best.0 && rho < best.1) {
                    best = (f, rho);
                }
            }
        };
        for &(r, dg, dc) in ev.iter() {
            if r > rp {
                // Interior stationary point of the uncapped objective, and where C = A.
                if sg > 0.0 {
                    let alpha = sums.e * sums.e - 2.0 * sums.e * (g - sg * rp);
                    if alpha > 0.0 {
                        let rs = alpha / (sums.e * sg);
                        if rs > rp && rs < r {
                            consider(rs, g + sg * (rs - rp), cc + sc * (rs - rp));
                        }
                    }
                }
                let disc = sc * sc + 8.0 * (cc - sc * rp);
                if disc >= 0.0 {
                    let rs = (sc + math::sqrt64(disc)) * 0.25;
                    if rs > rp && rs < r {
                        consider(rs, g + sg * (rs - rp), cc + sc * (rs - rp));
                    }
                }
                g += sg * (r - rp);
                cc += sc * (r - rp);
                rp = r;
            }
            sg += dg;
            sc += dc;
            consider(rp, g, cc);
        }
        best
    }

    /// The best of [`ROTATIONS`] for a fitted region (the fit averages over them; this
    /// only orients the square for display).
    fn rotation(td: &Texels, texels: &[u32], fit: &mut Fit, sums: &Sums) {
        let (t, bt) = basis(fit.centre);
        let c = fit.centre;
        let rho = math::sqrt64(0.5 * fit.solid_angle);
        let mut best = (f64::INFINITY, 0usize);
        for (i, r) in ROTATIONS.iter().enumerate() {
            let cs_sn = (math::cos64(*r), math::sin64(*r));
            let (mut g, mut cc) = (0.0, 0.0);
            for &k in texels {
                let k = k as usize;
                let dd = chebyshev(lambert(td.dir[k], t, bt, c), cs_sn);
                let h = 0.5 * math::sqrt64(td.w[k]);
                let cov = ((rho / SQRT_2 - (dd - h)) / (2.0 * h)).clamp(0.0, 1.0);
                g += cov * td.lum[k] * td.w[k];
                cc += cov * td.w[k];
            }
            let f = Self::eval(rho, g, cc, sums);
            if f < best.0 {
                best = (f, i);
            }
        }
        fit.rotation = ROTATIONS[best.1];
        let (cs, sn) = (math::cos64(fit.rotation), math::sin64(fit.rotation));
        fit.tangent = t * cs + bt * sn;
    }
}

/// Fits one region given by its texel indices (any order, no duplicates).
pub fn fit_region(cube: &CubeMap, texels: &[u32]) -> Fit {
    let td = Texels::new(cube);
    let mut sorted = texels.to_vec();
    sorted.sort_unstable();
    let mut fitter = Fitter::default();
    let mut fit = fitter.fit(&td, &sorted, &[]);
    let sums = Fitter::sums(&td, sorted.iter().copied());
    Fitter::rotation(&td, &sorted, &mut fit, &sums);
    fit
}

/// A candidate merge in the heap: ordered so that the heap pops the least objective, ties
/// by the smallest texels of the two regions.
#[derive(Clone, Copy, Debug)]
struct Cand {
    cost: f64,
    key: (u32, u32),
    a: u32,
    b: u32,
}

impl PartialEq for Cand {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Cand {}
impl PartialOrd for Cand {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Cand {
    fn cmp(&self, o: &Self) -> Ordering {
        // Reversed: BinaryHeap is a max-heap.
        o.cost
            .total_cmp(&self.cost)
            .then_with(|| o.key.cmp(&self.key))
    }
}

/// The live state of a merge run.
struct State<'a> {
    td: Texels,
    cube: &'a CubeMap,
    texels: Vec<Vec<u32>>,
    adj: Vec<BTreeSet<u32>>,
    alive: Vec<bool>,
    n_alive: usize,
    fitter: Fitter,
    objective: Objective,
    /// Merge cost of every region alone (for the increase key).
    cost: Vec<f64>,
}

impl<'a> State<'a> {
    fn new(cube: &'a CubeMap, cross_face: bool, objective: Objective) -> State<'a> {
        let n = cube.len();
        let per_face = cube.n() * cube.n();
        let mut adj = vec![BTreeSet::new(); n];
        for (k, set) in adj.iter_mut().enumerate() {
            for nb in cube.neighbours(k) {
                if nb != k && (cross_face || nb / per_face == k / per_face) {
                    set.insert(nb as u32);
                }
            }
        }
        // Make adjacency symmetric (cube corners).
        for k in 0..n {
            let ns: Vec<u32> = adj[k].iter().copied().collect();
            for nb in ns {
                adj[nb as usize].insert(k as u32);
            }
        }
        let mut st = State {
            td: Texels::new(cube),
            cube,
            texels: (0..n as u32).map(|k| vec![k]).collect(),
            adj,
            alive: vec![true; n],
            n_alive: n,
            fitter: Fitter::default(),
            objective,
            cost: Vec::with_capacity(2 * n),
        };
        for k in 0..n as u32 {
            let fit = st.fitter.fit(&st.td, &[k], &[]);
            let c = st.cost_of(&fit);
            st.cost.push(c);
        }
        st
    }

    fn cost_of(&self, fit: &Fit) -> f64 {
        match self.objective {
            Objective::Paper => fit.objective,
            Objective::Bound => fit.bound,
        }
    }

    fn candidate(&mut self, a: u32, b: u32) -> Cand {
        let (ta, tb) = (&self.texels[a as usize], &self.texels[b as usize]);
        let fit = self.fitter.fit(&self.td, ta, tb);
        let (ka, kb) = (ta[0], tb[0]);
        let mut cost = self.cost_of(&fit);
        if self.objective == Objective::Bound {
            // The increase of the summed bound (module docs).
            cost -= self.cost[a as usize] + self.cost[b as usize];
        }
        Cand {
            cost,
            key: (ka.min(kb), ka.max(kb)),
            a,
            b,
        }
    }

    /// Merges `a` and `b` into a new region; returns its id.
    fn merge(&mut self, a: u32, b: u32) -> u32 {
        let m = self.texels.len() as u32;
        let t: Vec<u32> = merged(&self.texels[a as usize], &self.texels[b as usize]).collect();
        let mut nbrs: BTreeSet<u32> = &self.adj[a as usize] | &self.adj[b as usize];
        nbrs.remove(&a);
        nbrs.remove(&b);
        for &nb in &nbrs {
            let s = &mut self.adj[nb as usize];
            s.remove(&a);
            s.remove(&b);
            s.insert(m);
        }
        for id in [a, b] {
            self.alive[id as usize] = false;
            self.texels[id as usize] = Vec::new();
            self.adj[id as usize].clear();
        }
        let fit = self.fitter.fit(&self.td, &t, &[]);
        let c = self.cost_of(&fit);
        self.cost.push(c);
        self.texels.push(t);
        self.adj.push(nbrs);
        self.alive.push(true);
        self.n_alive -= 1;
        m
    }

    fn snapshot(&mut self, k: usize, seconds: f64, cross_face: bool) -> Decomposition {
        let mut ids: Vec<usize> = (0..self.texels.len()).filter(|&i| self.alive[i]).collect();
        ids.sort_by_key(|&i| self.texels[i][0]);
        let mut region_of = vec![0u32; self.cube.len()];
        let mut regions = Vec::with_capacity(ids.len());
        for (ri, &id) in ids.iter().enumerate() {
            let tex = &self.texels[id];
            let mut fit = self.fitter.fit(&self.td, tex, &[]);
            let sums = Fitter::sums(&self.td, tex.iter().copied());
            Fitter::rotation(&self.td, tex, &mut fit, &sums);
            let mut energy = [0.0f64; 3];
            for &t in tex {
                region_of[t as usize] = ri as u32;
                let w = self.td.w[t as usize];
                let rgb = self.cube.texels()[t as usize];
                for c in 0..3 {
                    energy[c] += rgb[c] as f64 * w;
                }
            }
            let gradient = moment_gradient(self.cube, tex, fit.centre, fit.solid_angle);
            regions.push(Region {
                texels: tex.clone(),
                energy,
                solid_angle: sums.s,
                luminance_energy: sums.e,
                luminance_sq: sums.q,
                fit,
                gradient,
            });
        }
        Decomposition {
            k,
            regions,
            region_of,
            seconds,
            cross_face,
            merge: self.objective,
        }
    }
}

fn check_ks(cube: &CubeMap, ks: &[usize], cross_face: bool) -> Result<Vec<usize>, EnvError> {
    let lo = if cross_face { 1 } else { 6 };
    if ks.is_empty() {
        return Err(EnvError::Invalid("no number of lights asked for".into()));
    }
    let mut v = ks.to_vec();
    for &k in &v {
        if k < lo || k > cube.len() {
            return Err(EnvError::Invalid(format!(
                "K = {k} outside {lo}..={} (6 faces{} of {} texels)",
                cube.len(),
                if cross_face { "" } else { " merged separately" },
                cube.len()
            )));
        }
    }
    v.sort_unstable_by(|a, b| b.cmp(a));
    v.dedup();
    Ok(v)
}

/// Decomposes `cube` into each requested number of RSLs (priority queue with lazy
/// invalidation; see the module docs). Returns one [`Decomposition`] per distinct `K`,
/// largest `K` first.
pub fn decompose(cube: &CubeMap, opts: &Options) -> Result<Vec<Decomposition>, EnvError> {
    decompose_observed(cube, opts, &mut ())
}

/// [`decompose`], reporting to `obs` (its clock times each [`Decomposition`]).
pub fn decompose_observed(
    cube: &CubeMap,
    opts: &Options,
    obs: &mut dyn Observer,
) -> Result<Vec<Decomposition>, EnvError> {
    let ks = check_ks(cube, &opts.ks, opts.cross_face)?;
    let mut st = State::new(cube, opts.cross_face, opts.objective);
    let k_min = *ks.last().unwrap_or(&1);
    obs.start((cube.len() - k_min) as u64);
    let mut heap = BinaryHeap::new();
    for a in 0..cube.len() as u32 {
        let ns: Vec<u32> = st.adj[a as usize]
            .iter()
            .copied()
            .filter(|&b| b > a)
            .collect();
        for b in ns {
            heap.push(st.candidate(a, b));
        }
    }
    let mut out = Vec::with_capacity(ks.len());
    let mut next = 0;
    if ks[next] == st.n_alive {
        out.push(st.snapshot(ks[next], obs.seconds(), opts.cross_face));
        next += 1;
    }
    while next < ks.len() {
        let Some(c) = heap.pop() else {
            return Err(EnvError::Invalid(format!(
                "cannot reach K = {}: {} regions are not connected",
                ks[next], st.n_alive
            )));
        };
        if !st.alive[c.a as usize] || !st.alive[c.b as usize] {
            continue;
        }
        let m = st.merge(c.a, c.b);
        let ns: Vec<u32> = st.adj[m as usize].iter().copied().collect();
        for nb in ns {
            heap.push(st.candidate(m, nb));
        }
        obs.merged();
        if st.n_alive == ks[next] {
            out.push(st.snapshot(ks[next], obs.seconds(), opts.cross_face));
            next += 1;
        }
    }
    Ok(out)
}

/// Figure 5 as written: at every step, fit every region merged with each of its
/// neighbours and merge the best pair. Same result as [`decompose`], quadratically slower;
/// kept as the reference for the priority queue and as the timing baseline.
pub fn decompose_rescan(
    cube: &CubeMap,
    k: usize,
    cross_face: bool,
    objective: Objective,
) -> Result<Decomposition, EnvError> {
    decompose_rescan_observed(cube, k, cross_face, objective, &mut ())
}

/// [`decompose_rescan`], timed by `obs`.
pub fn decompose_rescan_observed(
    cube: &CubeMap,
    k: usize,
    cross_face: bool,
    objective: Objective,
    obs: &mut dyn Observer,
) -> Result<Decomposition, EnvError> {
    let ks = check_ks(cube, &[k], cross_face)?;
    let mut st = State::new(cube, cross_face, objective);
    while st.n_alive > ks[0] {
        let mut best: Option<Cand> = None;
        for a in 0..st.texels.len() as u32 {
            if !st.alive[a as usize] {
                continue;
            }
            let ns: Vec<u32> = st.adj[a as usize]
                .iter()
                .copied()
                .filter(|&b| b > a)
                .collect();
            for b in ns {
                let c = st.candidate(a, b);
                // `Cand`'s order is reversed for the max-heap: "greater" is better.
                if best.is_none_or(|bc| c > bc) {
                    best = Some(c);
                }
            }
        }
        let Some(c) = best else {
            return Err(EnvError::Invalid(format!(
                "cannot reach K = {k}: {} regions are not connected",
                st.n_alive
            )));
        };
        st.merge(c.a, c.b);
    }
    Ok(st.snapshot(ks[0], obs.seconds(), cross_face))
}
