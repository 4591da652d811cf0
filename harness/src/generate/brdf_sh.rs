//! BRDF SH tables (`steradian_core::sh::brdf`): the coefficients `F` and `F′` of an
//! isotropic BRDF per view `θₒ`, by quadrature of the `f64` textbook model
//! (`steradian_reference::lobe::brdf::Model`).
//!
//! **Quadrature.** Over the upper hemisphere of light directions: Gauss–Legendre (8 nodes)
//! on panels of `θᵢ` at most half the model's feature angle wide (graded down to a
//! sixteenth of that toward the horizon, where a lobe seen at grazing angles is squeezed
//! against `θᵢ = π/2`), times the midpoint rule in `φᵢ` with a node every quarter feature
//! angle (at least 64), refined by `1/(2 cos θₒ)` for grazing views (where the half vector
//! of a light near the mirror direction swings that much faster with `φᵢ`: without it GGX
//! at `θₒ = 86°` is 1.6 % off). The basis is separable, so each `θ` node sums Fourier
//! moments in `φ` and then feeds every band. Convergence (the same coefficients with twice
//! the nodes in both directions) is tested to `1e-6` of the largest coefficient.
//!
//! **Choices from a target error.** With `‖F‖²` from the same quadrature, Parseval gives
//! the truncation error of `n` bands without reconstructing anything:
//! `e(n)² = (‖F‖² − Σ_{l<n} Σ_m F_l^m²)/‖F‖²`, and for a window `w_l`,
//! `e_w(n)² = (‖F‖² − Σ_l (2w_l − w_l²) Σ_m F_l^m²)/‖F‖²`. [`choose_bands`] takes the
//! fewest bands (3..=16) with `e(n) ≤ target` at `θₒ = 45°`, and [`choose_table`] the
//! fewest views (from 16, 23, 30, 45, 90, 180) whose linear interpolation misses the
//! coefficients at the midpoints by at most `target/10` of their norm, testing the
//! midpoints from the grazing end and stopping at the first miss, and encodes the table
//! from the views it projected on the way.

use rayon::prelude::*;
use steradian_core::sh::brdf::{self, BrdfSh, Part, TABLE_NAME, stored};
use steradian_core::sh::window::Window;
use steradian_core::table::{HEADER_LEN, Spec, encode_into};
use steradian_reference::lobe::brdf::Model;
use steradian_reference::sh as shref;

/// Largest band count a table is projected to (for the error estimates).
pub const MAX_BANDS: usize = 16;

/// The quadrature in `θᵢ` and the basis's `θ` factors there; the `φ` rule is chosen per view.
pub struct Nodes {
    /// `(θ, weight sin θ·dθ)`.
    pub theta: Vec<(f64, f64)>,
    /// `p[k·stored(bands) + j]`: the `θ` factor of stored function `j` (`l, m ≥ 0`) at
    /// `θ` node `k`, `√2^[m>0]·K_l^m·P_l^m(cos θ)` (so `Y_l^m = p·cos mφ`).
    pub p: Vec<f64>,
    /// Bands of `p`.
    pub bands: usize,
    /// Azimuths of the rule at a view near the normal.
    pub nphi: usize,
}

impl Nodes {
    /// Nodes resolving features of `feature` radians (`refine` multiplies the density).
    pub fn new(feature: f64, bands: usize, refine: usize) -> Nodes {
        let half_pi = std::f64::consts::FRAC_PI_2;
        let nphi = (((8.0 * std::f64::consts::PI / feature).ceil() as usize).max(64)) * refine;
        let (gx, gw) = steradian_reference::quad::gauss_legendre(8);
        // Panel edges in θ: width ≤ feature/2, graded down to 1/16 of that toward the
        // horizon, where a lobe seen at grazing angles is squeezed against θ = π/2.
        let mut edges = vec![0.0f64];
        while *edges.last().unwrap() < half_pi {
            let t = *edges.last().unwrap();
            let grade = (4.0 * t.cos()).clamp(1.0 / 16.0, 1.0);
            let w = (0.5 * feature).min(0.4) * grade / refine as f64;
            edges.push((t + w).min(half_pi));
        }
        let mut theta = Vec::new();
        for p in edges.windows(2) {
            let (a, b) = (p[0], p[1]);
            for (x, w) in gx.iter().zip(&gw) {
                let t = a + (0.5 + 0.5 * x) * (b - a);
                theta.push((t, w * 0.5 * (b - a) * t.sin()));
            }
        }
        let mut p = Vec::with_capacity(theta.len() * stored(bands));
        for &(t, _) in &theta {
            let z = t.cos();
            for l in 0..bands {
                for m in 0..=l {
                    let k = if m > 0 { std::f64::consts::SQRT_2 } else { 1.0 };
                    p.push(k * shref::normalisation(l, m) * shref::legendre(l, m, z));
                }
            }
        }
        Nodes {
            theta,
            p,
            bands,
            nphi,
        }
    }

    /// Azimuths for the view `θₒ`: near grazing views the half vector of a light near the
    /// mirror direction swings `1/(2 cos θₒ)` times faster with `φᵢ`, so the rule is refined
    /// by that factor (a power of two, at most 64).
    pub fn nphi_at(&self, theta_o: f64) -> usize {
        let f = (0.5 / theta_o.cos().max(1e-3)).ceil().max(1.0) as usize;
        self.nphi * f.next_power_of_two().min(64)
    }
}

/// The view direction of `θₒ` in the view frame.
pub fn view(theta_o: f64) -> [f64; 3] {
    [theta_o.sin(), 0.0, theta_o.cos()]
}

/// `(F, F′, ‖F‖², ‖F′‖²)` at `θₒ`: the stored coefficients of both parts and the squared
/// norms of the functions themselves. The basis is separable, `Y_l^m = p_l^m(θ)·cos mφ`, so
/// each `θ` node first sums the Fourier moments `g_m = ∫ f·cos mφ dφ` and then feeds every
/// `l`: O(nodes·n) rather than O(nodes·n²).
pub fn project(model: &Model, nodes: &Nodes, theta_o: f64) -> (Vec<f64>, Vec<f64>, f64, f64) {
    let n = nodes.bands;
    let ns = stored(n);
    let wo = view(theta_o);
    let nphi = nodes.nphi_at(theta_o);
    let dphi = 2.0 * std::f64::consts::PI / nphi as f64;
    let (mut f, mut fp) = (vec![0.0; ns], vec![0.0; ns]);
    let (mut nf, mut nfp) = (0.0, 0.0);
    let (mut g, mut gp) = (vec![0.0; n], vec![0.0; n]);
    // The azimuths' (sin, cos, weight), the same at every `θ` node. The view is in the
    // xz-plane, so the BRDF is even in `φ` (`ρ(φ) = ρ(−φ)`, as is `cos mφ`): the midpoint
    // nodes `φ` and `2π − φ` pair up as one node of weight 2 (`φ = π`, the middle node of
    // an odd count, is its own partner: weight 1). Half the BRDF evaluations.
    let phis: Vec<(f64, f64, f64)> = (0..nphi.div_ceil(2))
        .map(|j| {
            let (sp, cp) = ((j as f64 + 0.5) * dphi).sin_cos();
            let w = if 2 * j + 1 == nphi { 1.0 } else { 2.0 };
            (sp, cp, w)
        })
        .collect();
    for (k, &(t, wt)) in nodes.theta.iter().enumerate() {
        let (s, c) = t.sin_cos();
        g.fill(0.0);
        gp.fill(0.0);
        let (mut sq, mut sqp) = (0.0, 0.0);
        for &(sp, cp, w) in &phis {
            let rho = model.rho([s * cp, s * sp, c], wo);
            if rho == 0.0 {
                continue;
            }
            let (a, b) = (rho * c, rho);
            sq += w * (a * a);
            sqp += w * (b * b);
            let (a, b) = (w * a, w * b);
            // cos mφ by the Chebyshev recurrence.
            let (mut c0, mut c1) = (1.0f64, cp);
            for m in 0..n {
                let cm = if m == 0 { 1.0 } else { c1 };
                g[m] += a * cm;
                gp[m] += b * cm;
                if m >= 1 {
                    (c0, c1) = (c1, 2.0 * cp * c1 - c0);
                }
            }
        }
        nf += wt * dphi * sq;
        nfp += wt * dphi * sqp;
        let p = &nodes.p[k * ns..(k + 1) * ns];
        for l in 0..n {
            for m in 0..=l {
                let j = stored(l) + m;
                f[j] += wt * dphi * p[j] * g[m];
                fp[j] += wt * dphi * p[j] * gp[m];
            }
        }
    }
    (f, fp, nf, nfp)
}

/// Per band limit `n = 1..=bands`, the relative L2 truncation error of `F` (module docs)
/// with the window weights `w(l, n)`.
pub fn truncation_errors(
    f: &[f64],
    norm2: f64,
    bands: usize,
    w: impl Fn(usize, usize) -> f64,
) -> Vec<f64> {
    (1..=bands)
        .map(|n| {
            let mut kept = 0.0;
            for l in 0..n {
                let wl = w(l, n);
                // m > 0 coefficients stand for cos mφ; the stored value is the coefficient
                // itself (the sin mφ partner is 0), so each counts once.
                let band: f64 = (0..=l).map(|m| f[stored(l) + m].powi(2)).sum();
                kept += (2.0 * wl - wl * wl) * band;
            }
            ((norm2 - kept).max(0.0) / norm2).sqrt()
        })
        .collect()
}

/// The fewest bands (3..=16) with truncation error at most `target` at `θₒ = 45°`.
pub fn choose_bands(model: &Model, target: f64) -> usize {
    let nodes = Nodes::new(model.feature_angle(), MAX_BANDS, 1);
    let (f, _, n2, _) = project(model, &nodes, std::f64::consts::FRAC_PI_4);
    let e = truncation_errors(&f, n2, MAX_BANDS, |_, _| 1.0);
    (3..=MAX_BANDS)
        .find(|&n| e[n - 1] <= target)
        .unwrap_or(MAX_BANDS)
}

/// `θ_k` of `T` samples.
pub fn theta(k: usize, samples: usize) -> f64 {
    (k as f64 + 0.5) * std::f64::consts::FRAC_PI_2 / samples as f64
}

/// View counts [`choose_table`] tries, in order (180 where none is enough).
pub const SAMPLE_COUNTS: [usize; 5] = [16, 23, 30, 45, 90];

/// `(F, F′)` of one view.
type View = (Vec<f64>, Vec<f64>);

/// Whether `t` views interpolate within `target/10` at every midpoint (module docs), and
/// the views computed on the way: all `t` of them where it does.
///
/// The midpoints are tested from the grazing end, a few at a time (in parallel), and the
/// test stops at the first chunk with a miss: the decision is the same as testing them all,
/// and a count that fails usually fails near grazing, where `F` changes fastest, after a
/// handful of projections instead of `2t − 1`.
fn interpolates(model: &Model, nodes: &Nodes, t: usize, target: f64) -> (bool, Vec<Option<View>>) {
    let mut views: Vec<Option<View>> = vec![None; t];
    let chunk = 2 * rayon::current_num_threads().max(1);
    let mids: Vec<usize> = (0..t - 1).rev().collect();
    for ks in mids.chunks(chunk) {
        // The views these midpoints need, then the midpoints themselves.
        let need: Vec<usize> = (ks[ks.len() - 1]..=ks[0] + 1)
            .filter(|&k| views[k].is_none())
            .collect();
        let got: Vec<(usize, View)> = need
            .into_par_iter()
            .map(|k| {
                let (f, fp, _, _) = project(model, nodes, theta(k, t));
                (k, (f, fp))
            })
            .collect();
        for (k, v) in got {
            views[k] = Some(v);
        }
        let seen = &views;
        let worst = ks
            .par_iter()
            .map(|&k| {
                let mid = project(model, nodes, 0.5 * (theta(k, t) + theta(k + 1, t))).0;
                let (Some(a), Some(b)) = (&seen[k], &seen[k + 1]) else {
                    return f64::INFINITY;
                };
                let err: f64 = mid
                    .iter()
                    .zip(a.0.iter().zip(&b.0))
                    .map(|(m, (a, b))| (m - 0.5 * (a + b)).powi(2))
                    .sum();
                let norm: f64 = mid.iter().map(|m| m * m).sum();
                (err / norm.max(1e-300)).sqrt()
            })
            .reduce(|| 0.0, f64::max);
        if worst > target / 10.0 {
            return (false, views);
        }
    }
    (true, views)
}

/// The fewest views of [`SAMPLE_COUNTS`] with interpolation error at most `target/10`
/// (module docs), 180 where none is enough, and the [`table`] of that many views (file
/// bytes), from the views the choice projected already: the same bytes as `table(model,
/// bands, views)` (the same projections, each computed once).
pub fn choose_table(model: &Model, bands: usize, target: f64) -> (usize, Vec<u8>) {
    let nodes = Nodes::new(model.feature_angle(), bands, 1);
    for t in SAMPLE_COUNTS {
        let (ok, views) = interpolates(model, &nodes, t, target);
        if ok {
            let views: Vec<View> = views.into_iter().flatten().collect();
            return (t, encode_views(bands, &views));
        }
    }
    (180, table(model, bands, 180))
}

/// The table of `model` with `bands` bands and `samples` views (file bytes).
pub fn table(model: &Model, bands: usize, samples: usize) -> Vec<u8> {
    let nodes = Nodes::new(model.feature_angle(), bands, 1);
    let views: Vec<View> = (0..samples)
        .into_par_iter()
        .map(|k| {
            let (f, fp, _, _) = project(model, &nodes, theta(k, samples));
            (f, fp)
        })
        .collect();
    encode_views(bands, &views)
}

/// The table file of the views `(F, F′)` at `θ_k` ([`theta`]), `k = 0..views.len()`.
fn encode_views(bands: usize, views: &[View]) -> Vec<u8> {
    let ns = stored(bands);
    let samples = views.len();
    let mut values = Vec::with_capacity(samples * 2 * ns);
    for (f, fp) in views {
        values.extend(f.iter().map(|&v| v as f32));
        values.extend(fp.iter().map(|&v| v as f32));
    }
    let spec = Spec {
        name: TABLE_NAME,
        rank: 2,
        channels: ns as u32,
        dims: [samples as u32, 2, 1, 1],
        lo: [0.0; 4],
        hi: [std::f64::consts::FRAC_PI_2, 2.0, 1.0, 1.0],
    };
    let mut out = vec![0u8; HEADER_LEN + 4 * values.len()];
    encode_into(&spec, &values, &mut out).expect("sizes agree by construction");
    out
}

/// The relative L2 errors against `F` at `θₒ` of what the table `t` gives there, one per
/// window: its own band count, interpolated between its views (`BrdfSh::lookup_into`), each
/// band `l` weighted by the window's `w(l, n)`. The stored basis is orthonormal (module
/// docs), so by Parseval `‖F − T‖² = ‖F‖² − 2⟨f, t⟩ + ‖t‖²` with `f` the exact coefficients
/// through [`MAX_BANDS`] and `‖F‖²` by quadrature: truncation, interpolation, the window and
/// the `f32` storage together.
pub fn table_errors(model: &Model, t: &BrdfSh<'_>, theta_o: f64, windows: &[Window]) -> Vec<f64> {
    let nodes = Nodes::new(model.feature_angle(), MAX_BANDS, 1);
    let (f, _, norm2, _) = project(model, &nodes, theta_o);
    let n = t.bands();
    let mut got = vec![0.0f32; n * n];
    t.lookup_into(Part::WithCosine, theta_o as f32, n, &mut got)
        .expect("the table's own band count");
    windows
        .iter()
        .map(|w| {
            let (mut cross, mut tt) = (0.0, 0.0);
            for l in 0..n {
                let wl = w.weight(l, n);
                for m in 0..=l {
                    let tv = wl * f64::from(got[l * l + l + m]);
                    cross += f[stored(l) + m] * tv;
                    tt += tv * tv;
                }
            }
            ((norm2 - 2.0 * cross + tt).max(0.0) / norm2).sqrt()
        })
        .collect()
}

/// The committed table of `materials()[k]` (core's built-in, the same order).
pub fn committed(k: usize) -> BrdfSh<'static> {
    [brdf::lambert, brdf::phong, brdf::lafortune, brdf::ggx][k]()
}

/// Target truncation error of the built-in tables (relative L2 at `θₒ = 45°`).
pub const TARGET: f64 = 0.05;

/// A built-in material.
pub struct Material {
    /// Short name.
    pub name: &'static str,
    /// The model.
    pub model: Model,
}

/// The built-in materials, in `steradian_core::sh::brdf`'s order.
pub fn materials() -> [Material; 4] {
    let pi = std::f64::consts::PI;
    [
        Material {
            name: "lambert",
            model: Model::Lambert { a: 1.0 },
        },
        Material {
            name: "phong30",
            model: Model::Phong {
                kd: 0.0,
                ks: 1.0,
                e: 30.0,
            },
        },
        Material {
            name: "lafortune",
            model: Model::Lafortune {
                lobes: [
                    [0.0, 0.0, 1.0, 0.0, 0.3 / pi],
                    [-0.9, -0.9, 1.0, 20.0, 0.5 * 22.0 / (2.0 * pi)],
                ],
            },
        },
        Material {
            name: "ggx",
            model: Model::Ggx {
                kd: 0.0,
                f0: 0.04,
                alpha: 0.3,
            },
        },
    ]
}

fn builtin(k: usize) -> Vec<u8> {
    let m = &materials()[k];
    let bands = choose_bands(&m.model, TARGET).max(3);
    choose_table(&m.model, bands, TARGET).1
}

/// `brdf_lambert.bin`.
pub fn generate_lambert() -> Vec<u8> {
    builtin(0)
}
/// `brdf_phong30.bin`.
pub fn generate_phong() -> Vec<u8> {
    builtin(1)
}
/// `brdf_lafortune.bin`.
pub fn generate_lafortune() -> Vec<u8> {
    builtin(2)
}
/// `brdf_ggx.bin`.
pub fn generate_ggx() -> Vec<u8> {
    builtin(3)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn at_a_stored_view_the_table_error_is_the_truncation_error() {
        // At a sample the interpolation weight is 0: what is left is the truncation to the
        // table's bands (and the f32 storage, far below the tolerance).
        for (k, m) in materials().iter().enumerate() {
            let t = committed(k);
            let th = f64::from(t.theta(t.samples() / 2));
            let nodes = Nodes::new(m.model.feature_angle(), MAX_BANDS, 1);
            let (f, _, n2, _) = project(&m.model, &nodes, th);
            let want = truncation_errors(&f, n2, MAX_BANDS, |_, _| 1.0)[t.bands() - 1];
            let got = table_errors(&m.model, &t, th, &[Window::None])[0];
            assert!((got - want).abs() < 1e-5, "{}: {got} vs {want}", m.name);
        }
    }

    /// The folded azimuth rule of [`project`] against the plain one it halves: every
    /// midpoint node `φ_j` on its own, `cos mφ` from `cos`, for every built-in material and
    /// a Phong lobe seen near grazing (where the rule is refined). Equal within round-off
    /// (1e-10 of the largest coefficient, far below the tables' `f32` storage; measured
    /// 2.3e-12 near grazing): the BRDF of a view in the xz-plane is even in `φ`.
    #[test]
    fn the_folded_azimuth_rule_is_the_full_one() {
        let pi = std::f64::consts::PI;
        let mut models: Vec<Model> = materials().iter().map(|m| m.model).collect();
        models.push(Model::Phong {
            kd: 0.2,
            ks: 0.8,
            e: 7.0,
        });
        for model in models {
            let nodes = Nodes::new(model.feature_angle(), 6, 1);
            for th in [0.3, 1.2, 1.55] {
                let (f, fp, nf, nfp) = project(&model, &nodes, th);
                let wo = view(th);
                let nphi = nodes.nphi_at(th);
                let dphi = 2.0 * pi / nphi as f64;
                let ns = stored(6);
                let (mut g, mut gp, mut n2, mut n2p) = (vec![0.0; ns], vec![0.0; ns], 0.0, 0.0);
                for (k, &(t, wt)) in nodes.theta.iter().enumerate() {
                    let (s, c) = t.sin_cos();
                    for j in 0..nphi {
                        let ph = (j as f64 + 0.5) * dphi;
                        let rho = model.rho([s * ph.cos(), s * ph.sin(), c], wo);
                        n2 += wt * dphi * (rho * c).powi(2);
                        n2p += wt * dphi * rho * rho;
                        for l in 0..6 {
                            for m in 0..=l {
                                let y = nodes.p[k * ns + stored(l) + m] * (m as f64 * ph).cos();
                                g[stored(l) + m] += wt * dphi * rho * c * y;
                                gp[stored(l) + m] += wt * dphi * rho * y;
                            }
                        }
                    }
                }
                let scale = f[0].abs().max(fp[0].abs());
                for (x, y) in f.iter().chain(&fp).zip(g.iter().chain(&gp)) {
                    assert!(
                        (x - y).abs() <= 1e-10 * scale,
                        "{model:?} θ {th}: {x} vs {y}"
                    );
                }
                assert!((nf - n2).abs() <= 1e-10 * n2 && (nfp - n2p).abs() <= 1e-10 * n2p);
            }
        }
    }

    /// [`choose_table`] makes the choice of the plain search (every view and every
    /// midpoint of each count of [`SAMPLE_COUNTS`], the first count whose largest
    /// interpolation error is within `target/10`) and encodes the same bytes as [`table`]
    /// at that count, for the Lambert model and a Phong lobe.
    #[test]
    fn choose_table_is_the_plain_search() {
        let models = [
            Model::Lambert { a: 1.0 },
            Model::Phong {
                kd: 0.0,
                ks: 1.0,
                e: 10.0,
            },
        ];
        for model in models {
            let bands = choose_bands(&model, TARGET);
            let nodes = Nodes::new(model.feature_angle(), bands, 1);
            let plain = SAMPLE_COUNTS
                .into_iter()
                .find(|&t| {
                    let at: Vec<Vec<f64>> = (0..t)
                        .map(|k| project(&model, &nodes, theta(k, t)).0)
                        .collect();
                    (0..t - 1).all(|k| {
                        let mid = project(&model, &nodes, 0.5 * (theta(k, t) + theta(k + 1, t))).0;
                        let err: f64 = mid
                            .iter()
                            .zip(at[k].iter().zip(&at[k + 1]))
                            .map(|(m, (a, b))| (m - 0.5 * (a + b)).powi(2))
                            .sum();
                        let norm: f64 = mid.iter().map(|m| m * m).sum();
                        (err / norm.max(1e-300)).sqrt() <= TARGET / 10.0
                    })
                })
                .unwrap_or(180);
            let (t, bytes) = choose_table(&model, bands, TARGET);
            assert_eq!(t, plain, "{model:?}");
            assert!(bytes == table(&model, bands, t), "{model:?}: bytes differ");
        }
    }

    #[test]
    fn the_quadrature_has_converged() {
        for m in materials() {
            let a = Nodes::new(m.model.feature_angle(), 8, 1);
            let b = Nodes::new(m.model.feature_angle(), 8, 2);
            for th in [0.1, 0.8, 1.5] {
                let (fa, fpa, _, _) = project(&m.model, &a, th);
                let (fb, fpb, _, _) = project(&m.model, &b, th);
                let scale = fb[0].abs().max(fpb[0].abs());
                for (x, y) in fa.iter().chain(&fpa).zip(fb.iter().chain(&fpb)) {
                    assert!(
                        (x - y).abs() < 1e-6 * scale,
                        "{} θ {th}: {x} vs {y}",
                        m.name
                    );
                }
            }
        }
    }
}
