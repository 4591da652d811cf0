//! BRDF summed-area tables (rotatable-square-lights paper, section 4.2, eq. 6 and 8).
//!
//! For a view direction `wₒ`, the table holds the texel integrals
//! `t(i, j) = ∫_texel ρ(wᵢ, wₒ)·cos θᵢ dωᵢ` over the equal-area parametrisation square of
//! incident directions ([`crate::rsl::hemisphere`]: disk point `p ∈ [−1, 1]²`, texel `(i, j)` of an
//! `n × n` grid covers `p ∈ [−1 + 2i/n, −1 + 2(i+1)/n] × …`, `dω = 2·du·dv`, zero outside the
//! unit disk), summed into a [`Sat`]. The integral of the cosine-weighted BRDF over a square
//! of the parametrisation plane — the paper's BRDF integral over an RSL, with the cosine
//! folded in — is then four lookups (the [`Sat`] query with fractional corners, exact for
//! the piecewise-constant texels).
//!
//! **View sampling.** Views are sampled at the polar nodes `s_k = s_max·k/(m − 1)`,
//! `k = 0..m−1`, of the equal-area radius `s = |map(wₒ)| = √(1 − cos θₒ)` (uniform in `s` is
//! close to uniform in `θₒ`: `s = √2·sin(θₒ/2)`), with `s_max = √(1 − cos θ_max)`;
//! views beyond `θ_max` use the last node (constant extension).
//! - An **isotropic** BRDF has one table per polar node, at azimuth `φₒ = 0`
//!   (`wₒ = (sin θₒ, 0, cos θₒ)`), a 3D dataset as in the paper. A query with another
//!   azimuth uses `ρ(wᵢ, wₒ) = ρ(R₋φ wᵢ, R₋φ wₒ)` and the fact that the map commutes with
//!   rotations about the normal: the query square's **centre** is rotated by `−φₒ` about the
//!   origin and the square stays axis-aligned. That is exact for the square rotated by `φₒ`
//!   about its own centre: [`BrdfSat::integral`] integrates over the square with centre `c`
//!   and half-diagonal `r` **turned by the view azimuth `φₒ`** about `c`. The paper does the
//!   same when it rotates the RSL into the local frame (section 3): an RSL stands for every
//!   rotation of its square (its fit averages over the rotation angle, section 4.1.1), so
//!   the orientation of the square is free, and the one that makes the lookup exact is used.
//! - An **anisotropic** BRDF has one table per view node `(s_k, φ_l)`, `φ_l = 2πl/a`, a 4D
//!   dataset; squares are axis-aligned in the local frame (tangent = `u`, bitangent = `v`).
//!
//! Between view nodes the integrals are interpolated linearly in `s` (and periodically in
//! `φ`), as the paper interpolates "for intermediate view directions".
//!
//! **Texel integrals.** Each texel is integrated with a 3×3 Gauss–Legendre rule on `k × k`
//! sub-cells (`f32` BRDF values, `f64` accumulation): `k = 2` for texels that cross the
//! horizon circle, and near the specular peak (the mirror direction) the sub-cells are made
//! smaller than half the BRDF's [`Brdf::feature_angle`], so sharp lobes (Phong `e = 10⁴`,
//! GGX `α = 0.01`) are integrated rather than point-sampled. Table sums are therefore
//! integrals, not sample sums.
//!
//! **Resolution for a target error** ("model only what a scene needs"):
//! [`BrdfSat::for_target`] / [`BrdfSat::fit`] build tables of increasing grid size `n` and
//! view count until the error against a reference integral (adaptive Gauss–Legendre
//! quadrature of the same BRDF, `f64` accumulation, to 1 % of the target) on a test set of
//! queries meets the target, or a cap is reached. The test set has, for views on the nodes
//! (up to 6), between them (up to 7 midpoints, including the first and last intervals) and
//! at random (4): squares centred on the specular peak, squares with an edge through or
//! next to the peak (offset by up to half the peak's travel between view nodes, where
//! interpolating two shifted lobes errs most), and 6 random squares, with half-diagonals
//! log-spaced in `[r_min, r_max]` (the RSL sizes the scene needs). The error of one query
//! is **relative with an albedo floor**:
//!
//! `err = |T − R| / max(R, A(wₒ)·4r²/(2π))`
//!
//! where `T` is the table's value, `R` the reference, `A(wₒ)` the directional albedo and
//! `4r²` the square's solid angle: relative where the square holds a fair share of the
//! reflected energy, and relative to a uniform BRDF of the same albedo in the dark parts of
//! the hemisphere (where an absolute error that small is invisible next to the other RSLs).
//! The fit grows `n` when the error at the view nodes (grid error) exceeds half the target,
//! and the view count when the extra error between nodes (interpolation error) does.
//! [`Fit`] reports the resolution chosen and the error achieved (maximum and RMS over the
//! test set); `harness/tests/brdf.rs` checks fresh queries against an independent `f64`
//! reference: when the target is met, fresh queries stay within 1.5× the reported maximum.
//! The reported maximum is a sample maximum, not a bound: when the caps stop the fit far
//! above the target (sharp lobes: Phong `e = 1000` at 16 MiB), fresh queries can exceed it
//! (the report shows both).
//!
//! **Cost.** A query is one `map` (a square root), a rotation and two [`Sat::square`]
//! lookups (isotropic) or an `atan2` and four lookups (anisotropic); memory is
//! `8·(n+1)²` bytes per view node ([`Resolution::bytes`]). Sharp lobes need both a fine
//! grid (the square's edges cut the lobe inside a texel) and many view nodes (the lobe
//! moves by twice the view step, and linear interpolation of two shifted lobes is not a
//! shifted lobe).
//!
//! **Bad input** (never panics): builders validate and return [`Error`];
//! [`BrdfSat::integral`] returns NaN for NaN in any input, 0 for a view on or below the
//! horizon, and follows [`Sat::square`] for the square (negative `r` → empty, clipped to the
//! parametrisation square).

use alloc::vec::Vec;

use crate::lobe::brdf::Brdf;
use crate::math;
use crate::rsl::hemisphere;
use crate::rsl::sat::Sat;
use crate::{Error, TWO_PI, Vec2, Vec3};

/// Grid size and view sampling of a [`BrdfSat`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Resolution {
    /// Texels per side of each table (`n`).
    pub grid: usize,
    /// Polar view nodes (`m ≥ 2`).
    pub polar: usize,
    /// Azimuthal view nodes (`1` for isotropic BRDFs).
    pub azimuth: usize,
}

impl Resolution {
    /// Number of tables.
    pub fn views(&self) -> usize {
        self.polar * self.azimuth
    }
    /// Bytes of the summed-area tables (8 bytes per `(n + 1)²` entry per table).
    pub fn bytes(&self) -> usize {
        (self.grid + 1) * (self.grid + 1) * 8 * self.views()
    }
}

/// What [`BrdfSat::fit`] chose and achieved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// The requested error.
    pub target: f32,
    /// Largest query error over the test set (see the module docs for the metric).
    pub max_error: f32,
    /// Root-mean-square query error over the test set.
    pub rms_error: f32,
    /// Largest error at the view nodes (the grid's share).
    pub node_error: f32,
    /// Whether `max_error ≤ target`.
    pub met: bool,
    /// Tables built (refinement steps).
    pub steps: usize,
    /// Queries in the test set of the final step.
    pub queries: usize,
    /// The worst query of the final step: view, square centre and half-diagonal.
    pub worst: (Vec3, Vec2, f32),
}

/// The scene's needs and the caps for [`BrdfSat::fit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitOptions {
    /// Target error (module docs), `> 0`.
    pub target: f32,
    /// Smallest square half-diagonal the scene queries (parametrisation units, disk radius 1).
    pub r_min: f32,
    /// Largest square half-diagonal.
    pub r_max: f32,
    /// Largest view polar angle tabulated (radians, `≤ π/2`); beyond it the last node is used.
    pub theta_max: f32,
    /// Grid cap.
    pub max_grid: usize,
    /// Polar node cap.
    pub max_polar: usize,
    /// Azimuthal node cap (anisotropic BRDFs).
    pub max_azimuth: usize,
    /// Cap on [`Resolution::bytes`].
    pub max_bytes: usize,
    /// Seed of the random part of the test set.
    pub seed: u64,
}

impl FitOptions {
    /// Defaults for `target`: squares of half-diagonal `0.03..0.5` (RSLs of 10–100 lights
    /// over a 6×32² cube map, down to a single cube texel), views up to 89°, grid ≤ 512,
    /// ≤ 129 polar and ≤ 64 azimuthal nodes, ≤ 64 MiB.
    pub fn new(target: f32) -> Self {
        FitOptions {
            target,
            r_min: 0.03,
            r_max: 0.5,
            theta_max: 89.0_f32.to_radians(),
            max_grid: 512,
            max_polar: 129,
            max_azimuth: 64,
            max_bytes: 64 << 20,
            seed: 0x0b3d_f5a7,
        }
    }

    fn validate(&self) -> Result<(), Error> {
        let pos = |what, v: f32, max: f32| {
            if !v.is_finite() {
                Err(Error::NonFinite { what })
            } else if !(v > 0.0 && v <= max) {
                Err(Error::OutOfRange {
                    what,
                    value: v,
                    min: 0.0,
                    max,
                })
            } else {
                Ok(())
            }
        };
        pos("target error", self.target, f32::MAX)?;
        pos("r_min", self.r_min, 2.0)?;
        pos("r_max", self.r_max, 2.0)?;
        pos("theta_max", self.theta_max, core::f32::consts::FRAC_PI_2)?;
        if self.r_min > self.r_max {
            return Err(Error::OutOfRange {
                what: "r_min",
                value: self.r_min,
                min: 0.0,
                max: self.r_max,
            });
        }
        Ok(())
    }
}

/// A view and a square's centre located among the tables ([`BrdfSat::locate`]).
struct Located {
    /// Lower polar view node and the fraction towards the next.
    k0: usize,
    t: f32,
    /// Texels per disk unit (half the grid side).
    half_n: f32,
    /// The square's centre in texel units, in the table frame.
    tc: Vec2,
    /// `(cos φ, sin φ)` by which an isotropic table's frame is turned (`(1, 0)` otherwise).
    turn: (f32, f32),
    /// Anisotropic tables: the azimuth nodes and the fraction between them.
    azimuth: Option<(usize, usize, f32)>,
}

/// Summed-area tables of a BRDF over the parametrisation square, one per view node.
#[derive(Clone, Debug, PartialEq)]
pub struct BrdfSat {
    res: Resolution,
    s_max: f32,
    sats: Vec<Sat>,
    fit: Option<Fit>,
}

/// Largest grid side accepted by [`BrdfSat::build`].
pub const MAX_GRID: usize = 4096;
/// Largest number of polar or azimuthal view nodes accepted by [`BrdfSat::build`].
pub const MAX_VIEW_NODES: usize = 1024;

/// 3-point Gauss–Legendre nodes and weights on `[0, 1]`.
const GL_X: [f64; 3] = [
    0.5 - 0.387_298_334_620_741_7,
    0.5,
    0.5 + 0.387_298_334_620_741_7,
];
const GL_W: [f64; 3] = [5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0];

/// `2·ρcos` at disk point `(u, v)` (the `dω = 2 du dv` factor included), 0 outside the disk.
#[inline]
fn integrand<B: Brdf + ?Sized>(brdf: &B, wo: Vec3, u: f64, v: f64) -> f64 {
    if u * u + v * v >= 1.0 {
        return 0.0;
    }
    let wi = hemisphere::unmap(Vec2::new(u as f32, v as f32));
    2.0 * f64::from(brdf.eval(wi, wo))
}

/// 3×3 Gauss–Legendre estimate over `[x0, x1]×[y0, y1]`.
#[inline]
fn gl3<B: Brdf + ?Sized>(brdf: &B, wo: Vec3, x0: f64, y0: f64, x1: f64, y1: f64) -> f64 {
    let (dx, dy) = (x1 - x0, y1 - y0);
    let mut s = 0.0;
    for (yj, wj) in GL_X.iter().zip(GL_W) {
        let v = y0 + dy * yj;
        let mut row = 0.0;
        for (xi, wi) in GL_X.iter().zip(GL_W) {
            row += wi * integrand(brdf, wo, x0 + dx * xi, v);
        }
        s += wj * row;
    }
    s * dx * dy
}

/// Distance from point `q` to the rectangle (0 inside).
fn rect_dist(q: (f64, f64), x0: f64, y0: f64, x1: f64, y1: f64) -> f64 {
    let dx = (x0 - q.0).max(q.0 - x1).max(0.0);
    let dy = (y0 - q.1).max(q.1 - y1).max(0.0);
    math::sqrt64(dx * dx + dy * dy)
}

/// Where the quadrature must resolve the BRDF: the specular peak (the mirror direction of
/// `wₒ` in disk coordinates) and the feature size there, in disk units.
#[derive(Clone, Copy)]
struct Feature {
    peak: (f64, f64),
    size: f64,
}

impl Feature {
    fn of<B: Brdf + ?Sized>(brdf: &B, wo: Vec3) -> Feature {
        let p = hemisphere::map(wo);
        // dp/dθ ≥ 1/2 and |p|dφ ≥ sinθ·dφ/√2 on the hemisphere: half the angle is safe.
        let size = 0.5 * f64::from(brdf.feature_angle().clamp(1e-4, 1.0));
        Feature {
            peak: (-f64::from(p.x), -f64::from(p.y)),
            size,
        }
    }
}

/// Texel integral over `[x0, x1]×[y0, y1]` (disk units): 3×3 Gauss–Legendre on sub-cells.
fn texel_integral<B: Brdf + ?Sized>(
    brdf: &B,
    wo: Vec3,
    f: Feature,
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
) -> f64 {
    // Nearest point of the texel to the origin: outside the disk → 0.
    let near = rect_dist((0.0, 0.0), x0, y0, x1, y1);
    if near >= 1.0 {
        return 0.0;
    }
    let h = x1 - x0;
    let (fx, fy) = (x0.abs().max(x1.abs()), y0.abs().max(y1.abs()));
    let far = math::sqrt64(fx * fx + fy * fy);
    let mut k: usize = if far > 1.0 { 2 } else { 1 };
    if rect_dist(f.peak, x0, y0, x1, y1) < 8.0 * f.size {
        // ⌈h/size⌉ sub-cells, at most 64 (no f64 `ceil` without std)
        let want = (h / f.size).min(64.0);
        let mut kk = want as usize;
        if (kk as f64) < want {
            kk += 1;
        }
        k = k.max(kk);
    }
    let d = h / k as f64;
    let mut s = 0.0;
    for b in 0..k {
        for a in 0..k {
            let u0 = x0 + d * a as f64;
            let v0 = y0 + d * b as f64;
            s += gl3(brdf, wo, u0, v0, u0 + d, v0 + d);
        }
    }
    s
}

/// Adaptive 3×3 Gauss–Legendre over a rectangle, cells near the peak refined to the
/// feature size; `whole` is the parent's estimate.
#[allow(clippy::too_many_arguments)]
fn adaptive<B: Brdf + ?Sized>(
    brdf: &B,
    wo: Vec3,
    f: Feature,
    rect: [f64; 4],
    whole: f64,
    tol: f64,
    depth: u32,
) -> f64 {
    let [x0, y0, x1, y1] = rect;
    let (xm, ym) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let kids = [
        [x0, y0, xm, ym],
        [xm, y0, x1, ym],
        [x0, ym, xm, y1],
        [xm, ym, x1, y1],
    ];
    let est = kids.map(|[a, b, c, d]| gl3(brdf, wo, a, b, c, d));
    let sum: f64 = est.iter().sum();
    let size = (x1 - x0).max(y1 - y0);
    let forced = size > f.size && rect_dist(f.peak, x0, y0, x1, y1) < 6.0 * f.size;
    if depth >= 18 || (!forced && (sum - whole).abs() <= tol) {
        return sum;
    }
    kids.iter()
        .zip(est)
        .map(|(k, e)| adaptive(brdf, wo, f, *k, e, 0.5 * tol, depth + 1))
        .sum()
}

/// Reference integral of `ρcos` over the axis-aligned rectangle `[x0, x1]×[y0, y1]` of the
/// parametrisation (disk units), to an absolute tolerance `tol` (adaptive, `f64` sums).
fn reference_rect<B: Brdf + ?Sized>(brdf: &B, wo: Vec3, rect: [f64; 4], tol: f64) -> f64 {
    let f = Feature::of(brdf, wo);
    let [x0, y0, x1, y1] = [
        rect[0].max(-1.0),
        rect[1].max(-1.0),
        rect[2].min(1.0),
        rect[3].min(1.0),
    ];
    if !(x1 > x0 && y1 > y0) {
        return 0.0;
    }
    // Start from a 4×4 split so no lobe hides between the first nodes.
    let (dx, dy) = ((x1 - x0) / 4.0, (y1 - y0) / 4.0);
    let mut s = 0.0;
    for b in 0..4 {
        for a in 0..4 {
            let r = [
                x0 + dx * a as f64,
                y0 + dy * b as f64,
                x0 + dx * (a + 1) as f64,
                y0 + dy * (b + 1) as f64,
            ];
            let e = gl3(brdf, wo, r[0], r[1], r[2], r[3]);
            s += adaptive(brdf, wo, f, r, e, tol / 16.0, 0);
        }
    }
    s
}

/// Equal-area radius of polar view node `k` (fractional between nodes) of `m` nodes up to
/// `s_max`: `s_max·k/(m − 1)`.
fn polar_node(s_max: f32, k: f32, m: usize) -> f32 {
    s_max * k / (m - 1) as f32
}

/// View direction of polar node value `s` (equal-area radius) and azimuth `(cos φ, sin φ)`.
fn view_dir(s: f32, cs: (f32, f32)) -> Vec3 {
    hemisphere::unmap(Vec2::new(s * cs.0, s * cs.1))
}

fn azimuth_cs(l: usize, a: usize) -> (f32, f32) {
    if a <= 1 {
        return (1.0, 0.0);
    }
    let phi = TWO_PI * l as f32 / a as f32;
    (math::cosf(phi), math::sinf(phi))
}

/// The `(n × n)` texel integrals of `ρcos` for view `wₒ` (row-major, rows in `v`).
pub fn texel_integrals<B: Brdf + ?Sized>(brdf: &B, wo: Vec3, n: usize) -> Vec<f64> {
    let f = Feature::of(brdf, wo);
    let h = 2.0 / n as f64;
    let mut out = Vec::with_capacity(n * n);
    for j in 0..n {
        let y0 = -1.0 + h * j as f64;
        for i in 0..n {
            let x0 = -1.0 + h * i as f64;
            out.push(texel_integral(brdf, wo, f, x0, y0, x0 + h, y0 + h));
        }
    }
    out
}

impl BrdfSat {
    /// Tables for `brdf` at resolution `res`, views tabulated up to `theta_max` (radians).
    ///
    /// Errors: `grid` outside `[2, MAX_GRID]`, `polar` outside `[2, MAX_VIEW_NODES]`,
    /// `azimuth` not 1 for an isotropic BRDF or outside `[4, MAX_VIEW_NODES]` for an
    /// anisotropic one, `theta_max` outside `(0, π/2]`, or a table the [`Sat`] rejects.
    pub fn build<B: Brdf + ?Sized>(
        brdf: &B,
        res: Resolution,
        theta_max: f32,
    ) -> Result<BrdfSat, Error> {
        let range = |what, v: usize, min: usize, max: usize| {
            if (min..=max).contains(&v) {
                Ok(())
            } else {
                Err(Error::OutOfRange {
                    what,
                    value: v as f32,
                    min: min as f32,
                    max: max as f32,
                })
            }
        };
        range("grid", res.grid, 2, MAX_GRID)?;
        range("polar view nodes", res.polar, 2, MAX_VIEW_NODES)?;
        if brdf.is_isotropic() {
            range("azimuthal view nodes (isotropic BRDF)", res.azimuth, 1, 1)?;
        } else {
            range("azimuthal view nodes", res.azimuth, 4, MAX_VIEW_NODES)?;
        }
        if !theta_max.is_finite() {
            return Err(Error::NonFinite { what: "theta_max" });
        }
        if !(theta_max > 0.0 && theta_max <= core::f32::consts::FRAC_PI_2) {
            return Err(Error::OutOfRange {
                what: "theta_max",
                value: theta_max,
                min: 0.0,
                max: core::f32::consts::FRAC_PI_2,
            });
        }
        let s_max = math::sqrtf(1.0 - math::cosf(theta_max));
        let mut sats = Vec::with_capacity(res.views());
        for k in 0..res.polar {
            let s = polar_node(s_max, k as f32, res.polar);
            for l in 0..res.azimuth {
                let wo = view_dir(s, azimuth_cs(l, res.azimuth));
                let t = texel_integrals(brdf, wo, res.grid);
                sats.push(Sat::build_f64(res.grid, res.grid, &t)?);
            }
        }
        Ok(BrdfSat {
            res,
            s_max,
            sats,
            fit: None,
        })
    }

    /// [`BrdfSat::fit`] with [`FitOptions::new`]`(target)`.
    pub fn for_target<B: Brdf + ?Sized>(brdf: &B, target: f32) -> Result<BrdfSat, Error> {
        Self::fit(brdf, &FitOptions::new(target))
    }

    /// Builds tables of growing resolution until the test-set error (module docs) is at most
    /// `opts.target` or a cap is reached; [`BrdfSat::fit_report`] says what was achieved.
    pub fn fit<B: Brdf + ?Sized>(brdf: &B, opts: &FitOptions) -> Result<BrdfSat, Error> {
        opts.validate()?;
        let iso = brdf.is_isotropic();
        let mut res = Resolution {
            grid: 16,
            polar: 5,
            azimuth: if iso { 1 } else { 8 },
        };
        let mut steps = 0;
        loop {
            steps += 1;
            let mut t = BrdfSat::build(brdf, res, opts.theta_max)?;
            let (node, all, rms, queries, worst) = t.test_error(brdf, opts);
            let met = all <= f64::from(opts.target);
            let fit = Fit {
                target: opts.target,
                max_error: all as f32,
                rms_error: rms as f32,
                node_error: node as f32,
                met,
                steps,
                queries,
                worst,
            };
            let tgt = f64::from(opts.target);
            let mut next = res;
            if !met {
                if node > 0.5 * tgt && res.grid < opts.max_grid {
                    next.grid = (res.grid * 2).min(opts.max_grid);
                }
                if all - node > 0.5 * tgt || (next == res && node <= 0.5 * tgt) {
                    if res.polar < opts.max_polar {
                        next.polar = (2 * res.polar - 1).min(opts.max_polar);
                    }
                    if !iso && res.azimuth < opts.max_azimuth {
                        next.azimuth = (res.azimuth * 2).min(opts.max_azimuth);
                    }
                }
            }
            if met || next == res || next.bytes() > opts.max_bytes {
                t.fit = Some(fit);
                return Ok(t);
            }
            res = next;
        }
    }

    /// The test-set errors `(max at nodes, max overall, rms overall, query count)`.
    #[allow(clippy::type_complexity)]
    fn test_error<B: Brdf + ?Sized>(
        &self,
        brdf: &B,
        opts: &FitOptions,
    ) -> (f64, f64, f64, usize, (Vec3, Vec2, f32)) {
        let mut rng = SplitMix(opts.seed);
        let (m, a) = (self.res.polar, self.res.azimuth);
        // (s, φ index or value, on-node?)
        let mut views: Vec<(f32, f32, bool)> = Vec::new();
        let picks = |count: usize, want: usize| -> Vec<usize> {
            let want = want.min(count);
            (0..want)
                .map(|q| {
                    if want == 1 {
                        0
                    } else {
                        q * (count - 1) / (want - 1)
                    }
                })
                .collect()
        };
        let node_s = |k: f32| polar_node(self.s_max, k, m);
        let phi_of = |l: f32| if a <= 1 { 0.0 } else { TWO_PI * l / a as f32 };
        for (q, k) in picks(m, 6).into_iter().enumerate() {
            views.push((node_s(k as f32), phi_of((q % a) as f32), true));
        }
        for (q, k) in picks(m - 1, 7).into_iter().enumerate() {
            let l = (q % a) as f32 + if a > 1 { 0.5 } else { 0.0 };
            views.push((node_s(k as f32 + 0.5), phi_of(l), false));
        }
        for _ in 0..4 {
            let s = self.s_max * rng.unit() as f32;
            let phi = if a > 1 {
                TWO_PI * rng.unit() as f32
            } else {
                0.0
            };
            views.push((s, phi, false));
        }
        // log-spaced half-diagonals: r_min·(r_max/r_min)^t
        let ratio = opts.r_max / opts.r_min;
        let log_r = |t: f32| f64::from(opts.r_min * math::powf(ratio, t));
        let radii: [f64; 4] = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0].map(log_r);
        let tol_rel = 0.01 * f64::from(opts.target);
        let (mut node_max, mut all_max, mut sq, mut count) = (0.0f64, 0.0f64, 0.0f64, 0usize);
        let mut worst = (Vec3::Z, Vec2::ZERO, 0.0);
        for &(s, phi, on) in &views {
            let wo = view_dir(s, (math::cosf(phi), math::sinf(phi)));
            if wo.z.is_nan() || wo.z <= 0.0 {
                continue;
            }
            // The albedo only sets the error floor: 0.1 % is plenty (a tighter tolerance
            // spends its time on the kink of the integrand at the horizon circle).
            let rough = texel_integrals(brdf, wo, 32).iter().sum::<f64>();
            let albedo = reference_rect(brdf, wo, [-1.0, -1.0, 1.0, 1.0], 1e-3 * rough).max(1e-30);
            let peak = {
                let p = hemisphere::map(wo);
                (-f64::from(p.x), -f64::from(p.y))
            };
            let mut queries: Vec<((f64, f64), f64)> = Vec::new();
            // Edges near the peak at offsets of up to half the peak's travel between view
            // nodes (where interpolating two shifted lobes errs most).
            let travel = f64::from(self.s_max) / (m - 1) as f64;
            for (q, &r) in radii.iter().enumerate() {
                let h = r * core::f64::consts::FRAC_1_SQRT_2;
                let d = travel * [0.0, 0.5, -0.25, 0.25][q % 4];
                queries.push((peak, r));
                queries.push(((peak.0 + h + d, peak.1 + 0.37 * h), r));
                queries.push(((peak.0 + 0.29 * h, peak.1 - h - d), r));
                queries.push(((peak.0 - h + 0.5 * d, peak.1 - 0.2 * h), r));
            }
            for _ in 0..6 {
                let (rr, t) = (math::sqrt64(rng.unit()), TWO_PI * rng.unit() as f32);
                let c = (rr * f64::from(math::cosf(t)), rr * f64::from(math::sinf(t)));
                let r = log_r(rng.unit() as f32);
                queries.push((c, r));
            }
            for (c, r) in queries {
                let h = r * core::f64::consts::FRAC_1_SQRT_2;
                let floor = albedo * 4.0 * r * r / core::f64::consts::TAU;
                let rect = [c.0 - h, c.1 - h, c.0 + h, c.1 + h];
                let exact = reference_rect(brdf, wo, rect, tol_rel * floor);
                let got = f64::from(self.integral(wo, Vec2::new(c.0 as f32, c.1 as f32), r as f32));
                let err = (got - exact).abs() / exact.max(floor);
                if on {
                    node_max = node_max.max(err);
                }
                if err > all_max {
                    all_max = err;
                    worst = (wo, Vec2::new(c.0 as f32, c.1 as f32), r as f32);
                }
                sq += err * err;
                count += 1;
            }
        }
        let rms = if count > 0 {
            math::sqrt64(sq / count as f64)
        } else {
            0.0
        };
        (node_max, all_max, rms, count, worst)
    }

    /// Where a view and a square's centre fall among the tables (shared by
    /// [`BrdfSat::integral`] and [`BrdfSat::integral_gradient`]; the view must be finite
    /// and above the horizon).
    #[inline(always)]
    fn locate(&self, wo_local: Vec3, centre: Vec2) -> Located {
        let p = hemisphere::map(wo_local);
        let s = math::sqrtf(p.x * p.x + p.y * p.y);
        let m = self.res.polar;
        let x = (s / self.s_max * (m - 1) as f32).clamp(0.0, (m - 1) as f32);
        let k0 = (x as usize).min(m - 2);
        let t = x - k0 as f32;
        let half_n = 0.5 * self.res.grid as f32;
        let a = self.res.azimuth;
        if a == 1 {
            let (c, sn) = if s > 0.0 {
                (p.x / s, p.y / s)
            } else {
                (1.0, 0.0)
            };
            let q = Vec2::new(centre.x * c + centre.y * sn, centre.y * c - centre.x * sn);
            let tc = (q + Vec2::ONE) * half_n;
            Located {
                k0,
                t,
                half_n,
                tc,
                turn: (c, sn),
                azimuth: None,
            }
        } else {
            let tc = (centre + Vec2::ONE) * half_n;
            let phi = math::atan2f(p.y, p.x);
            let y = phi / TWO_PI * a as f32;
            let y = y - math::floorf(y / a as f32) * a as f32; // [0, a]
            let l0f = math::floorf(y);
            let u = y - l0f;
            let l0 = (l0f as usize) % a;
            let l1 = (l0 + 1) % a;
            Located {
                k0,
                t,
                half_n,
                tc,
                turn: (1.0, 0.0),
                azimuth: Some((l0, l1, u)),
            }
        }
    }

    /// `∫ ρ(wᵢ, wₒ)·cos θᵢ dωᵢ` over the square of the parametrisation plane with centre
    /// `centre` (disk units, the point [`hemisphere::map`] gives) and half-diagonal
    /// `half_diagonal`, for the local view direction `wo_local` (unit, `z` = normal).
    ///
    /// Isotropic BRDFs: the square is turned by the view azimuth `φₒ` about its centre
    /// (module docs); anisotropic: axis-aligned. Linear interpolation between view nodes.
    #[inline]
    pub fn integral(&self, wo_local: Vec3, centre: Vec2, half_diagonal: f32) -> f32 {
        if wo_local.is_nan() || centre.is_nan() || half_diagonal.is_nan() {
            return f32::NAN;
        }
        if wo_local.z <= 0.0 {
            return 0.0;
        }
        let n = self.locate(wo_local, centre);
        let (k0, t, tc) = (n.k0, n.t, n.tc);
        let r = half_diagonal * n.half_n;
        match n.azimuth {
            None => {
                let v0 = self.sats[k0].square(tc, r);
                let v1 = self.sats[k0 + 1].square(tc, r);
                v0 + t * (v1 - v0)
            }
            Some((l0, l1, u)) => {
                let a = self.res.azimuth;
                let at = |k: usize, l: usize| self.sats[k * a + l].square(tc, r);
                let lo = at(k0, l0) + u * (at(k0, l1) - at(k0, l0));
                let hi = at(k0 + 1, l0) + u * (at(k0 + 1, l1) - at(k0 + 1, l0));
                lo + t * (hi - lo)
            }
        }
    }

    /// [`BrdfSat::integral`] and the gradient `g` of the integrand's density per unit
    /// parametrisation area, `φ = 2·ρ·cos θᵢ` (disk units), fitted as a plane over the
    /// square: `g = (I_right − I_left, I_top − I_bottom)/(2h³)` with `h` the half-side, exact
    /// for a linear `φ` (for the shading with visibility moments,
    /// [`crate::rsl::shade::shade_moments`]). Three box queries per table instead of one. The
    /// integral is [`BrdfSat::integral`]'s up to `f32` rounding (it is recombined from the
    /// same tables in `f64`). NaN input gives NaN; a view on or below the horizon gives 0.
    pub fn integral_gradient(
        &self,
        wo_local: Vec3,
        centre: Vec2,
        half_diagonal: f32,
    ) -> (f32, Vec2) {
        if wo_local.is_nan() || centre.is_nan() || half_diagonal.is_nan() {
            return (f32::NAN, Vec2::NAN);
        }
        if wo_local.z <= 0.0 {
            return (0.0, Vec2::ZERO);
        }
        let n = self.locate(wo_local, centre);
        let (k0, t, tc) = (n.k0, f64::from(n.t), n.tc);
        let h = crate::rsl::sat::square_half_side(half_diagonal) * n.half_n;
        // [whole, right − left, top − bottom] of one table around `tc` (texel units).
        let parts = |k: usize| -> [f64; 3] {
            let [whole, right, top] = self.sats[k]
                .view()
                .box3_f64([tc.x - h, tc.x, tc.x + h], [tc.y - h, tc.y, tc.y + h]);
            [whole, 2.0 * right - whole, 2.0 * top - whole]
        };
        let lerp = |a: [f64; 3], b: [f64; 3], u: f64| -> [f64; 3] {
            core::array::from_fn(|i| a[i] + u * (b[i] - a[i]))
        };
        let sums = match n.azimuth {
            None => lerp(parts(k0), parts(k0 + 1), t),
            Some((l0, l1, u)) => {
                let (a, u) = (self.res.azimuth, f64::from(u));
                let at = |k: usize, l: usize| parts(k * a + l);
                let lo = lerp(at(k0, l0), at(k0, l1), u);
                let hi = lerp(at(k0 + 1, l0), at(k0 + 1, l1), u);
                lerp(lo, hi, t)
            }
        };
        let hd = f64::from(h) / f64::from(n.half_n);
        if hd <= 0.0 {
            return (sums[0] as f32, Vec2::ZERO);
        }
        let k = 1.0 / (2.0 * hd * hd * hd);
        // Gradient in the (possibly azimuth-turned) table frame, turned back.
        let (gx, gy) = (sums[1] * k, sums[2] * k);
        let (c, sn) = (f64::from(n.turn.0), f64::from(n.turn.1));
        let g = Vec2::new((c * gx - sn * gy) as f32, (sn * gx + c * gy) as f32);
        (sums[0] as f32, g)
    }

    /// The resolution.
    pub fn resolution(&self) -> Resolution {
        self.res
    }

    /// Equal-area radius `s_max = √(1 − cos θ_max)` of the last polar view node: the value
    /// [`BrdfSat::integral`] divides by to find a view's nodes. Kernels that read the
    /// tables directly (the SIMD and WGSL shading) take this value rather than recomputing
    /// it from [`BrdfSat::theta_max`], which need not round-trip bit for bit.
    #[inline]
    pub fn s_max(&self) -> f32 {
        self.s_max
    }

    /// Largest tabulated view polar angle (radians).
    pub fn theta_max(&self) -> f32 {
        let s2 = self.s_max * self.s_max;
        math::atan2f(self.s_max * math::sqrtf(2.0 - s2), 1.0 - s2)
    }

    /// Bytes of the tables.
    pub fn bytes(&self) -> usize {
        self.sats.iter().map(Sat::bytes).sum()
    }

    /// What [`BrdfSat::fit`] chose and achieved (`None` for [`BrdfSat::build`]).
    pub fn fit_report(&self) -> Option<Fit> {
        self.fit
    }

    /// The table of view node `(k, l)` (polar, azimuthal), if it exists.
    pub fn table(&self, k: usize, l: usize) -> Option<&Sat> {
        if l >= self.res.azimuth {
            return None;
        }
        self.sats.get(k * self.res.azimuth + l)
    }

    /// Direction of view node `(k, l)`.
    pub fn view_node(&self, k: usize, l: usize) -> Vec3 {
        let s = polar_node(self.s_max, k as f32, self.res.polar);
        view_dir(s, azimuth_cs(l, self.res.azimuth))
    }
}

/// SplitMix64 (the test set's random part; same sequence on every machine).
struct SplitMix(u64);

impl SplitMix {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lobe::brdf::{Lambert, Phong};

    #[test]
    fn whole_hemisphere_is_the_albedo() {
        let res = Resolution {
            grid: 32,
            polar: 4,
            azimuth: 1,
        };
        let t = BrdfSat::build(&Lambert::new(0.8).unwrap(), res, 1.4).unwrap();
        for wo in [Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.3, 0.5, 0.4)] {
            let a = t.integral(wo.normalize(), Vec2::ZERO, 2.0);
            assert!((a - 0.8).abs() < 1e-4, "{a}");
        }
        // Phong at normal incidence: k_d + k_s, the lobe integrated by the texel quadrature
        let t = BrdfSat::build(&Phong::new(0.1, 0.8, 1e4).unwrap(), res, 1.4).unwrap();
        let a = t.integral(Vec3::Z, Vec2::ZERO, 2.0);
        assert!((a - 0.9).abs() < 1e-3, "{a}");
        assert_eq!(t.bytes(), res.bytes());
        assert!(t.fit_report().is_none());
    }

    /// Lambert: `φ = 2·(a/π)·cos θ = 2·(a/π)·(1 − |x|²)` per unit disk area, whose plane fit
    /// over a square (the half-box difference) is the gradient at the centre, `−4·(a/π)·c`,
    /// exactly. Views with an azimuth check that the gradient is turned back from the
    /// table's azimuth frame.
    #[test]
    fn integral_gradient_of_lambert_is_the_cosine_slope() {
        let res = Resolution {
            grid: 64,
            polar: 4,
            azimuth: 1,
        };
        let a = 0.8;
        let t = BrdfSat::build(&Lambert::new(a).unwrap(), res, 1.4).unwrap();
        let k = -4.0 * a / crate::PI;
        for wo in [
            Vec3::Z,
            Vec3::new(0.36, 0.48, 0.8),
            Vec3::new(-0.5, -0.2, 0.6),
        ] {
            let wo = wo.normalize();
            for (c, r) in [
                (Vec2::new(0.3, -0.2), 0.3),
                (Vec2::new(-0.5, 0.1), 0.2),
                (Vec2::new(0.05, 0.6), 0.1),
                (Vec2::ZERO, 0.5),
            ] {
                let (i, g) = t.integral_gradient(wo, c, r);
                let plain = t.integral(wo, c, r);
                assert!((i - plain).abs() <= 1e-6 * plain, "{i} vs {plain}");
                let want = c * k;
                // texel quadrature of a quadratic: within 2 % of |k| (|k| ≈ 1)
                assert!((g - want).length() < 0.02, "{wo} {c} {r}: {g} vs {want}");
            }
        }
        let (i, g) = t.integral_gradient(Vec3::new(0.0, 0.0, -1.0), Vec2::ZERO, 0.1);
        assert_eq!((i, g), (0.0, Vec2::ZERO));
        let (i, g) = t.integral_gradient(Vec3::Z, Vec2::new(f32::NAN, 0.0), 0.1);
        assert!(i.is_nan() && g.is_nan());
    }

    #[test]
    fn s_max_is_the_last_view_nodes_radius() {
        let res = Resolution {
            grid: 8,
            polar: 5,
            azimuth: 1,
        };
        for theta in [
            0.3f32,
            1.2,
            89f32.to_radians(),
            core::f32::consts::FRAC_PI_2,
        ] {
            let t = BrdfSat::build(&Lambert::new(0.5).unwrap(), res, theta).unwrap();
            let s = t.s_max();
            assert_eq!(s, math::sqrtf(1.0 - math::cosf(theta)));
            let last = hemisphere::map(t.view_node(res.polar - 1, 0)).length();
            assert!((last - s).abs() <= 1e-6 * s, "{theta}: {last} {s}");
            assert!((t.theta_max() - theta).abs() <= 1e-6, "{theta}");
            assert_eq!(t.view_node(0, 0), Vec3::Z);
        }
    }

    #[test]
    fn fit_options_validate() {
        let b = Lambert::new(0.5).unwrap();
        let bad = [
            FitOptions::new(-1.0),
            FitOptions {
                r_min: 0.6,
                r_max: 0.5,
                ..FitOptions::new(0.1)
            },
            FitOptions {
                theta_max: 2.0,
                ..FitOptions::new(0.1)
            },
        ];
        for o in bad {
            assert!(BrdfSat::fit(&b, &o).is_err());
        }
    }
}
