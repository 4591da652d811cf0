//! Exact unshadowed environment integrals, for the `rsl` method's shadow ratio
//! ([`super::rsl::Options::exact_unshadowed`], an addition to the paper's pipeline).
//!
//! The `rsl` kernel estimates a BRDF part's reflected light `∫ L·V·φ` over `K` uniform
//! squares. Most of its error on the built-in `environment` scene is the light's variation
//! inside each square, seen sharply through a glossy lobe, and it is there with or
//! without occluders. The ratio form keeps the squares only for the fraction that the
//! spheres remove, with `V = V_P·V_S` split into the point's planes and its spheres:
//!
//! ```text
//!   ∫ L·V·φ ≈ X · S/U,    X = ∫ L·V_P·φ (these tables),    S = RSL(L, V, φ),    U = RSL(L, V_P, φ)
//! ```
//!
//! A plane hides exactly the directions that head toward it, so `V_P` is the indicator
//! of the half-spaces `v·ω > 0` its planes leave open, the same for every point on the
//! same sides of them: one set of tables per such signature. The form is exact wherever
//! only planes occlude (`S = U`), up to the tables' error, and otherwise as good as the
//! squares' estimate of the fraction the spheres remove. This is the ratio estimator of
//! Heitz, Hill and McGuire, "Combining analytic direct illumination and stochastic
//! shadows" (I3D 2018), with the squares in place of the stochastic shadows.
//!
//! The tables hold, per environment (times its scale) and signature:
//! - the diffuse part `φ = cos⁺/π`: `X(n) = (1/π)∫ L(ω)·max(n·ω, 0) dω`, a function of
//!   the normal alone, on a [`SphereTable`] of [`DIFFUSE_NODES`];
//! - a lobe `φ = max(a·ω, 0)^e·max(n·ω, 0)`: wherever the lobe's support lies above the
//!   horizon, `max(n·ω, 0) = n·ω` under it and `n` leaves the integral:
//!   `X(a, n) = n·M_e(a)` with `M_e(a) = ∫ L(ω)·max(a·ω, 0)^e·ω dω`, a vector per colour
//!   channel and a function of the axis alone (the support is where `(a·ω)^e ≥`
//!   [`LOBE_CUT`]). Where the lobe reaches below the horizon, [`EnvTables::lobe`] adds
//!   back what `n·ω < 0` subtracts there, from the lobe's Gaussian profile and
//!   `P_e(a) = ∫ L·max(a·ω, 0)^e dω` (tabulated beside `M_e`), down to an axis one lobe
//!   width below the horizon; it blends to `None` at two (the caller then keeps the
//!   squares' estimate).
//!
//! Both are integrals of the environment (cut by the half-spaces) box-averaged to a grid
//! of cells finer than the integrand's features ([`LOBE_NODES_PER_WIDTH`] and
//! [`LOBE_CELLS_PER_WIDTH`] to the lobe's width `1/√e`), taken at the table's nodes and
//! interpolated bilinearly.
//! The harness test `env_tables_match_a_brute_force_integral` asserts the error bounds
//! [`DIFFUSE_REL_TOL`], [`LOBE_REL_TOL`] (lobe clear of the horizon) and
//! [`LOBE_HORIZON_REL_TOL`] (across it) against an `f64` integral of the bilinear
//! environment the path tracer sees (measured at most 3.1e-4, 1.7e-3 and 7.8e-3 of the
//! largest value), at 120 directions, on the whole environment and cut by the horizon and
//! by a tilted plane (hard cases: the poles, the sun, axes from one lobe width below the
//! horizon up).

use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};

use super::Rgb;
use super::light::Environment;

/// Nodes `(columns, rows)` of the diffuse table: `X(n)` is a cosine convolution, smooth
/// at this spacing (3.75°).
pub const DIFFUSE_NODES: (usize, usize) = (96, 49);

/// Rows of quadrature cells of the diffuse table, at least (where the environment has
/// them): 2.8° cells.
pub const DIFFUSE_CELL_ROWS: usize = 64;

/// Where a lobe's support ends: `(a·ω)^e` below it is left out of `M_e`.
pub const LOBE_CUT: f64 = 1e-4;

/// The largest lobe exponent tabulated: its table has 165 × 328 nodes
/// ([`LOBE_NODES_PER_WIDTH`]); a sharper lobe keeps the squares' estimate.
pub const MAX_EXPONENT: f64 = 300.0;

/// Asserted bound on the diffuse table's error relative to the largest value of `X`
/// over the sphere (harness test `env_tables_match_a_brute_force_integral`).
pub const DIFFUSE_REL_TOL: f64 = 5e-4;

/// Asserted bound on a lobe's error relative to the largest value over the sphere, with
/// the lobe clear of the horizon (its axis three lobe widths above it or more).
pub const LOBE_REL_TOL: f64 = 3e-3;

/// Asserted bound on a lobe's error relative to the largest value over the sphere, with
/// the lobe across the horizon (its axis from one width below to three above it: the
/// horizon term's Gaussian model).
pub const LOBE_HORIZON_REL_TOL: f64 = 1.2e-2;

/// A function on the unit sphere at nodes `θ_j = π·j/(rows − 1)`, `φ_i = 2π·i/columns`,
/// bilinear between them (wrapping in `φ`).
#[derive(Clone, Debug)]
pub struct SphereTable<T> {
    cols: usize,
    rows: usize,
    values: Vec<T>,
}

/// The unit direction of polar angle `theta` and azimuth `phi` (`+z` up, `φ` from `+x`
/// toward `+y`, the environment's convention).
fn direction(theta: f64, phi: f64) -> DVec3 {
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

impl<T: Copy + Send> SphereTable<T> {
    /// `f` at every node (in parallel).
    fn build(cols: usize, rows: usize, f: impl Fn(DVec3, f64, f64) -> T + Sync) -> Self {
        let values = (0..cols * rows)
            .into_par_iter()
            .map(|q| {
                let (i, j) = (q % cols, q / cols);
                let theta = PI * j as f64 / (rows - 1) as f64;
                let phi = TAU * i as f64 / cols as f64;
                f(direction(theta, phi), theta, phi)
            })
            .collect();
        SphereTable { cols, rows, values }
    }

    /// The four nodes around unit `d` with their bilinear weights.
    fn corners(&self, d: DVec3) -> [(T, f64); 4] {
        let theta = d.z.clamp(-1.0, 1.0).acos();
        let phi = d.y.atan2(d.x).rem_euclid(TAU);
        let y = (theta / PI * (self.rows - 1) as f64).clamp(0.0, (self.rows - 1) as f64);
        let x = phi / TAU * self.cols as f64;
        let j0 = (y.floor() as usize).min(self.rows - 2);
        let fy = y - j0 as f64;
        let x0 = x.floor();
        let fx = x - x0;
        let i0 = (x0 as usize) % self.cols;
        let i1 = (i0 + 1) % self.cols;
        let v = |i: usize, j: usize| self.values[j * self.cols + i];
        [
            (v(i0, j0), (1.0 - fx) * (1.0 - fy)),
            (v(i1, j0), fx * (1.0 - fy)),
            (v(i0, j0 + 1), (1.0 - fx) * fy),
            (v(i1, j0 + 1), fx * fy),
        ]
    }
}

/// The environment box-averaged to cells: `(direction, solid angle, mean radiance)` of
/// each, at least `min_rows` rows where the image has them (each cell a block of `f × f`
/// texels, the last ones clipped). A cell's direction is its luminance-weighted centroid
/// (renormalised), so that a bright spot smaller than a cell (the sun) keeps its place:
/// a smooth integrand then sees the cell's error at second order only.
fn cells(
    env: &Environment,
    visible: &[DVec3],
    min_rows: usize,
) -> (usize, Vec<(DVec3, f64, [f64; 3])>) {
    let img = &env.image;
    let (w, h) = (img.width(), img.height());
    // A texel's share inside every half-space `v·ω > 0`: 1 or 0 away from the planes'
    // great circles, else the share of 4 × 4 points spread over it. `reach` bounds the
    // sine of the angle from a texel's centre to its corners.
    let reach = 1.5 * PI / h as f64;
    let share = |theta: f64, phi: f64| -> f64 {
        let d = direction(theta, phi);
        let m = visible
            .iter()
            .map(|v| v.dot(d))
            .fold(f64::INFINITY, f64::min);
        if m >= reach {
            return 1.0;
        }
        if m <= -reach {
            return 0.0;
        }
        let (dt, dp) = (PI / h as f64, TAU / w as f64);
        let mut inside = 0;
        for a in 0..4 {
            for b in 0..4 {
                let q = direction(
                    theta + dt * ((a as f64 + 0.5) / 4.0 - 0.5),
                    phi + dp * ((b as f64 + 0.5) / 4.0 - 0.5),
                );
                if visible.iter().all(|v| v.dot(q) > 0.0) {
                    inside += 1;
                }
            }
        }
        f64::from(inside) / 16.0
    };
    let f = (h / min_rows.max(1)).max(1);
    let (cw, ch) = (w.div_ceil(f), h.div_ceil(f));
    let data = img.data();
    let mut out = Vec::with_capacity(cw * ch);
    for cy in 0..ch {
        let (y0, y1) = (cy * f, ((cy + 1) * f).min(h));
        for cx in 0..cw {
            let (x0, x1) = (cx * f, ((cx + 1) * f).min(w));
            let (mut area, mut sum, mut centroid) = (0.0, [0.0f64; 3], DVec3::ZERO);
            for y in y0..y1 {
                let a = img.pixel_solid_angle(y);
                let theta = PI * (y as f64 + 0.5) / h as f64;
                for (x, p) in (x0..x1).zip(&data[y * w + x0..y * w + x1]) {
                    let phi = TAU * (x as f64 + 0.5) / w as f64;
                    let a = if visible.is_empty() {
                        a
                    } else {
                        a * share(theta, phi)
                    };
                    for c in 0..3 {
                        sum[c] += p[c] as f64 * a;
                    }
                    let lum = 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64;
                    centroid += direction(theta, phi) * (lum.max(0.0) * a);
                }
                area += img.pixel_solid_angle(y) * (x1 - x0) as f64;
            }
            let centre = direction(
                PI * (y0 + y1) as f64 / (2 * h) as f64,
                TAU * (x0 + x1) as f64 / (2 * w) as f64,
            );
            let d = centroid.try_normalize().unwrap_or(centre);
            let l = sum.map(|s| s / area * env.scale);
            out.push((d, area, l));
        }
    }
    (cw, out)
}

/// A lobe's table: `M_e(a)` and `P_e(a) = ∫ L·max(a·ω, 0)^e dω` per colour channel.
#[derive(Clone, Debug)]
struct LobeTable {
    exponent: f64,
    table: SphereTable<([DVec3; 3], [f64; 3])>,
}

/// The exact unshadowed integrals of an environment (module docs).
#[derive(Clone, Debug)]
pub struct EnvTables {
    diffuse: SphereTable<[f64; 3]>,
    lobes: Vec<LobeTable>,
}

impl EnvTables {
    /// The diffuse table and one lobe table per distinct exponent of `exponents` up to
    /// [`MAX_EXPONENT`] (others are left out: [`EnvTables::lobe`] answers `None`), of the
    /// environment seen through the half-spaces `v·ω > 0` of `visible` (unit `v`; the
    /// directions planes leave open, [`super::rsl`]; none for the whole environment).
    pub fn build(env: &Environment, visible: &[DVec3], exponents: &[f64]) -> EnvTables {
        let (_, quad) = cells(env, visible, DIFFUSE_CELL_ROWS);
        let diffuse = SphereTable::build(DIFFUSE_NODES.0, DIFFUSE_NODES.1, |n, _, _| {
            let mut e = [0.0f64; 3];
            for (d, a, l) in &quad {
                let c = n.dot(*d);
                if c > 0.0 {
                    for k in 0..3 {
                        e[k] += a * l[k] * c;
                    }
                }
            }
            e.map(|v| v / PI)
        });
        let mut lobes: Vec<LobeTable> = Vec::new();
        for &e in exponents {
            if !(e > 0.0 && e <= MAX_EXPONENT) || lobes.iter().any(|l| l.exponent == e) {
                continue;
            }
            lobes.push(lobe_table(env, visible, e));
        }
        EnvTables { diffuse, lobes }
    }

    /// `(1/π)∫ L·max(n·ω, 0) dω` at unit `n`.
    pub fn diffuse(&self, n: DVec3) -> Rgb {
        let mut out = [0.0; 3];
        for (v, w) in self.diffuse.corners(n) {
            for k in 0..3 {
                out[k] += w * v[k];
            }
        }
        out
    }

    /// `∫ L·max(a·ω, 0)^e·max(n·ω, 0) dω` at unit axis `a` and normal `n`, with its
    /// weight: `(value, weight)`, `None` for an exponent without a table or an axis more
    /// than two lobe widths below the horizon.
    ///
    /// The value is `n·M_e(a)` (exact while the lobe clears the horizon) plus the part of
    /// the lobe below the horizon that `n·ω < 0` subtracts there. Near the axis the lobe
    /// `(a·ω)^e ≈ exp(−θ²/2σ²)`, `σ = 1/√e`, so across the horizon the light it weights is
    /// taken as a Gaussian of width `σ` in the height `h = n·ω`, centred on its mean height
    /// `t = n·M_e/P_e` (per channel; `(e+1)/(e+2)·n·a` for a uniform environment). The
    /// clipped integral is `P_e·E[h₊] = P_e·E[h] + P_e·E[(−h)₊]`, and `P_e·E[h] = n·M_e`,
    /// so the missing part is `P_e·E[(−h)₊] = P_e·(σ·φ(t/σ) − t·Q(t/σ))` (φ the normal
    /// density, `Q` its upper tail): exact for a uniform environment as `σ → 0`, tested
    /// against brute force on one (`horizon_term_is_exact_for_a_uniform_environment`).
    /// The term is below 4e-4 of `P_e·σ` for `t ≥ 3σ`. The weight uses the axis's own
    /// height `asin(n·a)`: 1 down to one lobe width below the horizon, falling linearly
    /// to 0 at two, where the caller keeps the squares' estimate.
    pub fn lobe(&self, e: f64, a: DVec3, n: DVec3) -> Option<(Rgb, f64)> {
        let l = self.lobes.iter().find(|l| l.exponent == e)?;
        let sigma = 1.0 / e.sqrt();
        let t = n.dot(a).clamp(-1.0, 1.0).asin();
        let k = t / sigma;
        let weight = (k + 2.0).clamp(0.0, 1.0);
        if weight <= 0.0 || weight.is_nan() {
            return None;
        }
        let (mut m, mut p) = ([0.0; 3], [0.0; 3]);
        for ((mv, pv), w) in l.table.corners(a) {
            for c in 0..3 {
                m[c] += w * n.dot(mv[c]);
                p[c] += w * pv[c];
            }
        }
        let mut out = [0.0; 3];
        for c in 0..3 {
            // The Gaussian about the lobe's own mean height `n·M/P` above the horizon.
            let te = if p[c] > 0.0 { m[c] / p[c] } else { t };
            let k = te / sigma;
            let phi = (-0.5 * k * k).exp() / (2.0 * PI).sqrt();
            let q = 0.5 * libm::erfc(k / std::f64::consts::SQRT_2);
            out[c] = m[c] + p[c] * (sigma * phi - te * q);
        }
        Some((out.map(|v| v.max(0.0)), weight))
    }
}

/// Nodes of a lobe's table per lobe width `1/√e`.
pub const LOBE_NODES_PER_WIDTH: f64 = 3.0;

/// Quadrature cells of a lobe's table per lobe width `1/√e` (at most the environment's
/// own texels).
pub const LOBE_CELLS_PER_WIDTH: f64 = 4.0;

/// `M_e` on nodes [`LOBE_NODES_PER_WIDTH`] to the lobe's width `1/√e`, from cells
/// [`LOBE_CELLS_PER_WIDTH`] to it.
fn lobe_table(env: &Environment, visible: &[DVec3], e: f64) -> LobeTable {
    let width = 1.0 / e.sqrt();
    let rows = (LOBE_NODES_PER_WIDTH * PI / width).ceil() as usize + 1;
    let cells_rows = (LOBE_CELLS_PER_WIDTH * PI / width).ceil() as usize;
    let (cw, quad) = cells(env, visible, cells_rows);
    let cos_support = LOBE_CUT.powf(1.0 / e);
    let support = cos_support.acos();
    // The cells by row (`cw` per row), so that each node visits only the rows within β
    // of its axis and, in each, the columns within reach (a cell's centroid lies inside
    // it, and the last, clipped cell shifts the others by less than one: two cells of
    // margin each way).
    let band_rows = quad.len() / cw;
    let table = SphereTable::build(2 * (rows - 1), rows, |axis, theta, phi| {
        let mut m = [DVec3::ZERO; 3];
        let mut p0 = [0.0f64; 3];
        let row_of = |t: f64| ((t / PI * band_rows as f64) as usize).min(band_rows - 1);
        let (r0, r1) = (row_of((theta - support).max(0.0)), row_of(theta + support));
        for r in r0.saturating_sub(1)..=(r1 + 1).min(band_rows - 1) {
            let band = &quad[r * cw..(r + 1) * cw];
            // Columns within β of the axis: `cos Δφ ≥ (cos β − cos θ cos θₐ)/(sin θ sin θₐ)`
            // at the row's nearest polar angle; all of them near a pole.
            let (t0, t1) = (
                PI * r as f64 / band_rows as f64,
                PI * (r + 1) as f64 / band_rows as f64,
            );
            let t = theta.clamp(t0, t1);
            let den = t.sin() * theta.sin();
            let q = if den > 1e-9 {
                (cos_support - t.cos() * theta.cos()) / den
            } else {
                -2.0
            };
            let span = if q <= -1.0 { PI } else { q.min(1.0).acos() };
            let lo = ((phi - span) / TAU * cw as f64).floor() as i64 - 2;
            let hi = ((phi + span) / TAU * cw as f64).ceil() as i64 + 2;
            let cols: Box<dyn Iterator<Item = usize>> = if hi - lo + 1 >= cw as i64 {
                Box::new(0..cw)
            } else {
                Box::new((lo..=hi).map(move |i| i.rem_euclid(cw as i64) as usize))
            };
            for i in cols {
                let (d, a, l) = &band[i];
                let c = axis.dot(*d);
                if c > cos_support {
                    // In f32 (six digits, well inside the table's error), twice as fast.
                    let f = a * f64::from((c as f32).powf(e as f32));
                    for k in 0..3 {
                        m[k] += *d * (f * l[k]);
                        p0[k] += f * l[k];
                    }
                }
            }
        }
        (m, p0)
    });
    LobeTable { exponent: e, table }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::scene::Scene;
    use std::f64::consts::FRAC_PI_2;

    /// `(direction, solid angle, radiance)` of the bilinear environment the path tracer
    /// sees through the half-spaces of `visible`, sampled 2 × 2 per texel (8 × 8 where a
    /// sample's cell meets a half-space's boundary): the reference integrals' quadrature.
    fn fine(env: &Environment, visible: &[DVec3]) -> Vec<(DVec3, f64, Rgb)> {
        let (w, h) = (2 * env.image.width(), 2 * env.image.height());
        let open = |d: DVec3| visible.iter().all(|v| v.dot(d) > 0.0);
        let near = |d: DVec3| visible.iter().any(|v| v.dot(d).abs() < 2.0 * PI / h as f64);
        let mut out = Vec::with_capacity(w * h);
        for y in 0..h {
            let (t0, t1) = (PI * y as f64 / h as f64, PI * (y + 1) as f64 / h as f64);
            let a = TAU / w as f64 * (t0.cos() - t1.cos());
            for x in 0..w {
                let d = direction(0.5 * (t0 + t1), TAU * (x as f64 + 0.5) / w as f64);
                if !near(d) {
                    if open(d) {
                        out.push((d, a, env.radiance(d)));
                    }
                    continue;
                }
                for i in 0..4 {
                    let (s0, s1) = (
                        t0 + (t1 - t0) * i as f64 / 4.0,
                        t0 + (t1 - t0) * (i + 1) as f64 / 4.0,
                    );
                    let sa = TAU / (4 * w) as f64 * (s0.cos() - s1.cos());
                    for j in 0..4 {
                        let q = direction(
                            0.5 * (s0 + s1),
                            TAU * (x as f64 + (j as f64 + 0.5) / 4.0) / w as f64,
                        );
                        if open(q) {
                            out.push((q, sa, env.radiance(q)));
                        }
                    }
                }
            }
        }
        out
    }

    /// The unit directions tested: random ones, the poles, toward the brightest texel
    /// (the sun) and just off it.
    fn directions(env: &Environment, fine: &[(DVec3, f64, Rgb)], count: usize) -> Vec<DVec3> {
        let mut rng = Rng::new(11);
        let mut out = vec![DVec3::Z, -DVec3::Z];
        let sun = fine
            .iter()
            .max_by(|a, b| a.2[1].total_cmp(&b.2[1]))
            .map(|c| c.0)
            .unwrap();
        let _ = env;
        out.push(sun);
        out.push((sun + DVec3::new(0.01, -0.02, 0.015)).normalize());
        while out.len() < count {
            let z = 2.0 * rng.unit() - 1.0;
            let phi = TAU * rng.unit();
            let s = (1.0 - z * z).max(0.0).sqrt();
            out.push(DVec3::new(s * phi.cos(), s * phi.sin(), z));
        }
        out
    }

    /// The case the tables' formulas are exact in: a uniform environment `L ≡ 1`. The
    /// diffuse table is `(1/π)∫cos⁺ = 1` (within [`DIFFUSE_REL_TOL`], the cells' error); a lobe clear of the horizon is
    /// `n·M_e = n·a·∫(a·ω)₊^(e+1) dω = n·a·2π/(e+2)`; across the horizon the Gaussian
    /// term's error against a brute-force integral (midpoint rule, 2048 × 1024 directions)
    /// falls about as `1/e` (relative to `P_e·σ`, the term's scale, `σ = 1/√e`): measured
    /// 7.9e-3 at `e` = 60 and 1.5e-3 at 300; asserted below 1e-2 and falling at least
    /// fourfold.
    #[test]
    fn horizon_term_is_exact_for_a_uniform_environment() {
        // The size of the built-in `city.exr`, so the cells are those of the scene test.
        let img = crate::env::Equirect::new(512, 256, vec![[1.0; 3]; 512 * 256]).unwrap();
        let env = Environment::new(img, 1.0, "uniform".into());
        let t = EnvTables::build(&env, &[], &[60.0, 300.0]);
        for n in [DVec3::Z, DVec3::X, DVec3::new(0.3, -0.5, 0.8).normalize()] {
            let d = t.diffuse(n);
            assert!(
                d.iter().all(|v| (v - 1.0).abs() <= DIFFUSE_REL_TOL),
                "{d:?}"
            );
        }
        let (qw, qh) = (2048usize, 1024usize);
        let mut worst_of = Vec::new();
        for e in [60.0f64, 300.0] {
            let sigma = 1.0 / e.sqrt();
            let p = TAU / (e + 1.0);
            let a = DVec3::new(0.2, 0.4, 0.6).normalize();
            let (u, v) = crate::scene::material::basis(a);
            let mut worst = 0.0f64;
            for i in 0..=20 {
                // The axis from one lobe width below the horizon to four above it.
                let h = sigma * (-1.0 + 0.25 * i as f64);
                let n = h.sin() * a + h.cos() * (0.6 * u + 0.8 * v);
                let mut exact = 0.0;
                for j in 0..qh {
                    let (t0, t1) = (PI * j as f64 / qh as f64, PI * (j + 1) as f64 / qh as f64);
                    let w = TAU / qw as f64 * (t0.cos() - t1.cos());
                    for k in 0..qw {
                        let d = direction(0.5 * (t0 + t1), TAU * (k as f64 + 0.5) / qw as f64);
                        let (c, cn) = (a.dot(d), n.dot(d));
                        if c > 0.0 && cn > 0.0 {
                            exact += w * c.powf(e) * cn;
                        }
                    }
                }
                let (got, weight) = t.lobe(e, a, n).unwrap();
                assert!((weight - 1.0).abs() < 1e-9, "{weight}");
                worst = worst.max((got[0] - exact).abs() / (p * sigma));
                if h >= 3.0 * sigma {
                    // Clear of the horizon: the closed form.
                    let closed = n.dot(a) * TAU / (e + 2.0);
                    assert!(
                        (got[0] - closed).abs() <= 2e-3 * closed,
                        "{e} {h}: {got:?} {closed}"
                    );
                }
            }
            eprintln!("e = {e}: worst error across the horizon {worst:.3e} of P·σ");
            worst_of.push(worst);
        }
        assert!(worst_of[0] < 1e-2, "{worst_of:?}");
        assert!(4.0 * worst_of[1] <= worst_of[0], "{worst_of:?}");
    }

    /// The diffuse table and a lobe's `n·M_e(a)` against `f64` integrals of the bilinear
    /// environment at four times its texels, on `city.exr` (a sun, a bright sky, a dark
    /// street), whole and seen through one and two planes' half-spaces (the horizon, and
    /// the horizon with a tilted plane): within [`DIFFUSE_REL_TOL`] and [`LOBE_REL_TOL`] of
    /// the largest value, at the poles, the sun, random directions and, for the lobe,
    /// normals down to `n·a = sin β_e` (grazing).
    #[test]
    fn env_tables_match_a_brute_force_integral() {
        let scene = Scene::load("builtin:environment").unwrap();
        let env = scene.environment.as_ref().unwrap();
        let tilted = DVec3::new(0.6, 0.0, 0.8);
        for visible in [vec![], vec![DVec3::Z], vec![DVec3::Z, tilted]] {
            eprintln!("visible half-spaces {visible:?}");
            tables_match(env, &visible);
        }
    }

    fn tables_match(env: &Environment, visible: &[DVec3]) {
        let e = 60.0;
        let t = EnvTables::build(env, visible, &[e, 1e4]);
        let fine = fine(env, visible);
        let dirs = directions(env, &fine, 120);
        // Diffuse: the error over the largest value seen.
        let (mut worst, mut top) = (0.0f64, 0.0f64);
        for &n in &dirs {
            let mut exact = [0.0; 3];
            for (d, a, l) in &fine {
                let c = n.dot(*d).max(0.0);
                for k in 0..3 {
                    exact[k] += a * l[k] * c / PI;
                }
            }
            let got = t.diffuse(n);
            for k in 0..3 {
                worst = worst.max((got[k] - exact[k]).abs());
                top = top.max(exact[k]);
            }
        }
        eprintln!("diffuse: worst {:.3e} of the largest", worst / top);
        assert!(worst / top <= DIFFUSE_REL_TOL, "{}", worst / top);
        // A lobe, at normals from the axis to one lobe width below the horizon (the
        // horizon term's range), half of them within three widths of it.
        let sigma = 1.0 / e.sqrt();
        let mut rng = Rng::new(5);
        // The worst error with the lobe clear of the horizon (axis three widths above it)
        // and crossing it, and the largest value.
        let (mut clear, mut crossing, mut top) = (0.0f64, 0.0f64, 0.0f64);
        for (i, &a) in dirs.iter().enumerate() {
            let (u, v) = crate::scene::material::basis(a);
            let above = if i % 2 == 0 {
                -sigma + 4.0 * sigma * rng.unit()
            } else {
                -sigma + (FRAC_PI_2 + sigma) * rng.unit()
            };
            let s = above.sin();
            let phi = TAU * rng.unit();
            let n = s * a + (1.0 - s * s).sqrt() * (phi.cos() * u + phi.sin() * v);
            let mut exact = [0.0; 3];
            for (d, w, li) in &fine {
                let c = a.dot(*d);
                let cn = n.dot(*d);
                if c > 0.0 && cn > 0.0 {
                    for k in 0..3 {
                        exact[k] += w * li[k] * c.powf(e) * cn;
                    }
                }
            }
            let (got, weight) = t.lobe(e, a, n).unwrap();
            assert_eq!(weight, 1.0);
            for k in 0..3 {
                let err = (got[k] - exact[k]).abs();
                if above >= 3.0 * sigma {
                    clear = clear.max(err);
                } else {
                    crossing = crossing.max(err);
                }
                top = top.max(exact[k]);
            }
        }
        let (clear, crossing) = (clear / top, crossing / top);
        eprintln!(
            "lobe e = {e}: worst {clear:.3e} clear of the horizon, {crossing:.3e} across it, of the largest"
        );
        assert!(clear <= LOBE_REL_TOL, "{clear}");
        assert!(crossing <= LOBE_HORIZON_REL_TOL, "{crossing}");
        // Past the table's exponent and two widths below the horizon: no value.
        assert!(t.lobe(1e4, DVec3::Z, DVec3::Z).is_none());
        assert!(
            t.lobe(e, DVec3::new(1.0, 0.0, -0.3).normalize(), DVec3::Z)
                .is_none()
        );
        let mid = t.lobe(e, DVec3::new(0.0, 0.0, 1.0), DVec3::Z).unwrap();
        assert_eq!(mid.1, 1.0);
    }
}
