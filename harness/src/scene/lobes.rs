//! The `lobes` method (cosine-lobe paper, sections 5–5.4): direct lighting from spherical
//! lights as `∫ f_r·L·V·cos` with every factor a cosine lobe, evaluated by
//! [`steradian_core::lobe::sum::triple`] (its table-parameterised `triple_with`) with the
//! product table of [`Options::table`].
//!
//! Per shading point `x` with normal `n`, view `ωo`, and per spherical light:
//! - the light is the cap it subtends, as one lobe ([`SphericalCap::lobe`], eq. 31–32),
//!   multiplied by the cosine first ([`Cosine::WithLight`]): energy-preserving in the
//!   diffuse chain, the visible fraction the mask's weights were fitted for
//!   ([`Options::fit`]), and by default the cap's solid angle and mean cosine in the glossy
//!   chains, whose highlight it keeps sharp ([`Options::glossy_fit`]);
//! - the reflectance is the material's constant diffuse term `albedo/π` and one unit lobe
//!   per glossy lobe (modified Phong: about the mirror direction, `(n+2)/(2π)` carried in
//!   RGB; Lafortune: about `M·ωo`), each chained separately so that every colour channel
//!   is an exact scale of the same scalar integral;
//! - visibility is `1 − Σ_k w_k·c_k` (eq. 39–41): by default over the shadow leaves of the
//!   quadtree mask of section 5.3 with the fitted weights ([`Visibility::Mask`]), or one
//!   lobe of weight 1 per occluder ([`Visibility::PerOccluder`]);
//! - the diffuse term, by default ([`Options::exact_diffuse`]), is the exact unshadowed
//!   integral ([`SphericalCap::clipped_cosine`]) less the exact part the occluders hide
//!   ([`SphericalCap::overlap_moment`]) where the light's cap is above the horizon and the
//!   occluders' caps are pairwise disjoint, else times the visible fraction the chain gives.
//!
//! Occluders are the spheres of the scene (surfaces and other lights) whose centre is
//! nearer than the light's and whose cap overlaps the light's cap (`angle(a_l, a_o) <
//! α_l + α_o`, exact for caps: a sphere whose cap misses the light's hides none of it).
//! A light whose centre is on the other side of a plane than `x` is hidden; planes are
//! otherwise not occluders (the cosine already removes what lies below the tangent
//! plane). An environment does not light this method (the `rsl` method does); it is seen
//! by camera rays that escape.
//!
//! Pruning (section 4.3): each chain's threshold is `threshold × |its unshadowed value|`,
//! so the bound of [`steradian_core::lobe::sum`] holds relative to the unshadowed radiance.
//!
//! [`shade`] is the scalar path; [`shade_x8`] (the default of `steradian render`, through
//! [`render_simd`]) takes eight points at once through the SIMD product kernel for each
//! light's lobe times the cosine and runs the rest of [`shade`] lane by lane. A light
//! without occluders at a point skips the quadtree mask on both paths.

use glam::{DVec3, Vec3};
use indicatif::ProgressBar;
use steradian_core::lobe::CosineLobe;
use steradian_core::lobe::cap::{CapFit, MOMENTS_MAX_X, SphericalCap};
use steradian_core::lobe::mask::{self, Leaves};
use steradian_core::lobe::product::{ProductFit, ProductTable, product_with};
use steradian_core::lobe::sum::{
    Cosine, LobeSum, LobeTerms, LobeVec, ProductCounts, light_with_cosine_with, triple_with,
};

use super::image::Image;
use super::{Kind, Rgb, Scene, ShadingPoint, Shape, footprint, render_centres, render_centres_x8};

/// How visibility becomes lobes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visibility {
    /// One lobe per overlapping occluder sphere, weight 1: overlapping occluders are
    /// subtracted twice.
    PerOccluder,
    /// The quadtree mask of section 5.3 ([`steradian_core::lobe::mask`]): one lobe per
    /// shadow leaf, weighted by the fitted table.
    Mask {
        /// Deepest level (1–5).
        depth: u32,
        /// What a partially covered deepest cell becomes.
        leaves: Leaves,
    },
}

/// Settings of the `lobes` method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// How caps become lobes: energy-preserving by default, which the harness test
    /// `lobes_method_against_the_path_tracer_on_small_builtin_scenes` asserts more accurate
    /// than the L2 fit of eq. 32 against the path tracer on both `lobes` and `cluster` (the
    /// L2 lobe is wider than the cap and integrates to more than its solid angle).
    pub fit: CapFit,
    /// How the light's cap becomes its lobe in the glossy chains: [`CapFit::Moments`] by
    /// default, the cap's solid angle and mean cosine, whose product with a glossy lobe of
    /// exponent `n` is exact to second order in `x = n(1 − cos α)`; where the receiver's
    /// sharpest lobe has `x` above [`MOMENTS_MAX_X`], [`Options::fit`] instead (the better
    /// one there on the axis, core test `moments_fit_against_energy_preserving_on_the_axis`).
    /// The energy-preserving lobe is wider than the cap (angular variance `α²/0.96`
    /// against `α²/2`) and blurs a sphere light's highlight: on `lobes` its relative L2
    /// against path-traced pixel centres is over 5× the moments lobe's (harness test
    /// `moments_light_lobe_keeps_the_highlights`).
    pub glossy_fit: CapFit,
    /// Pruning threshold relative to each chain's unshadowed value.
    pub threshold: f32,
    /// The footprint threshold of [`footprint::refine`], relative to the image's largest
    /// surface value: pixels whose centre alone is estimated to miss the pixel's mean by
    /// that much are re-shaded at their 2×2 Gauss–Legendre points, on every path. 0 (the
    /// default) shades pixel centres only; `steradian render` plans it from the target
    /// error.
    pub footprint: f64,
    /// The visibility model.
    pub visibility: Visibility,
    /// The unshadowed diffuse term in closed form ([`SphericalCap::clipped_cosine`], the
    /// sphere's exact cosine-weighted solid angle above the horizon) times the visible
    /// fraction the lobes give, in place of the lobe product of the cap's lobe with the
    /// cosine (the paper); where the light's cap is wholly above the horizon and the
    /// occluders' caps are pairwise disjoint, what they hide of it is exact too
    /// ([`SphericalCap::overlap_moment`]) and the mask serves the glossy chains only. The
    /// harness tests `lobes_method_against_the_path_tracer_on_small_builtin_scenes` and
    /// `exact_diffuse_term_against_a_converged_reference` assert it more accurate against
    /// the path tracer on `lobes` and `cluster` (at most 0.7× the paper's error against a
    /// 4096-sample reference).
    pub exact_diffuse: bool,
    /// The lobe-product table every product reads ([`TableSize`]): the built-in one by
    /// default; `steradian render` plans the coarsest that its probes allow.
    pub table: TableSize,
}

/// Resolutions of the lobe-product table (`exponents × exponents × angles`, core's
/// [`steradian_core::lobe::product`] format): three generated at run time by the harness's
/// generator (`generate::lobe_product::encode`, once per process each) and the committed
/// one. The report section `lobe-product` measures each one's integral error against the
/// exact product and prints its generation time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum TableSize {
    /// 12 × 12 × 16 (5.0 KB).
    E12,
    /// 24 × 24 × 32 (38 KB).
    E24,
    /// 40 × 40 × 64 (210 KB).
    E40,
    /// The committed 64 × 64 × 128 table (1.06 MB).
    BuiltIn,
}

impl std::fmt::Display for TableSize {
    /// `12×12×16`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (e, a) = self.dims();
        write!(f, "{e}×{e}×{a}")
    }
}

impl TableSize {
    /// Every size, coarsest first.
    pub const ALL: [TableSize; 4] = [
        TableSize::E12,
        TableSize::E24,
        TableSize::E40,
        TableSize::BuiltIn,
    ];

    /// `(exponent samples, angle samples)`.
    pub fn dims(self) -> (usize, usize) {
        use steradian_core::lobe::product::{TABLE_ANGLES, TABLE_EXPONENTS};
        match self {
            TableSize::E12 => (12, 16),
            TableSize::E24 => (24, 32),
            TableSize::E40 => (40, 64),
            TableSize::BuiltIn => (TABLE_EXPONENTS, TABLE_ANGLES),
        }
    }

    /// Its name in plans and reports with its origin and size, e.g.
    /// `12×12×16 (generated, 4992 bytes)`.
    pub fn describe(self) -> String {
        let origin = match self {
            TableSize::BuiltIn => "built in",
            _ => "generated",
        };
        format!("{self} ({origin}, {} bytes)", self.table().bytes())
    }

    /// The table: the committed one, or generated on first use in this process (the bytes
    /// and the parsed view kept for the process's life, so every product reads it without
    /// a lock).
    pub fn table(self) -> &'static ProductTable<'static> {
        use std::sync::OnceLock;
        static BUILT_IN: OnceLock<ProductTable<'static>> = OnceLock::new();
        static BYTES: [OnceLock<Vec<u8>>; 3] = [OnceLock::new(), OnceLock::new(), OnceLock::new()];
        static TABLES: [OnceLock<ProductTable<'static>>; 3] =
            [OnceLock::new(), OnceLock::new(), OnceLock::new()];
        let k = match self {
            TableSize::BuiltIn => return BUILT_IN.get_or_init(ProductTable::builtin),
            TableSize::E12 => 0,
            TableSize::E24 => 1,
            TableSize::E40 => 2,
        };
        TABLES[k].get_or_init(|| {
            let (e, a) = self.dims();
            let bytes = BYTES[k].get_or_init(|| crate::generate::lobe_product::encode(e, a));
            ProductTable::from_bytes(bytes).expect("the generator writes valid tables")
        })
    }
}

impl Default for Options {
    fn default() -> Self {
        Options {
            fit: CapFit::EnergyPreserving,
            glossy_fit: CapFit::Moments,
            threshold: 1e-4,
            footprint: 0.0,
            visibility: Visibility::Mask {
                depth: mask::MAX_DEPTH,
                leaves: Leaves::Fraction,
            },
            exact_diffuse: true,
            table: TableSize::BuiltIn,
        }
    }
}

fn f32v(v: DVec3) -> Vec3 {
    v.as_vec3()
}

/// The reflected radiance at a shading point.
pub fn shade(scene: &Scene, p: &ShadingPoint, o: &Options, counts: &mut ProductCounts) -> Rgb {
    let rx = Receiver::of(scene, p);
    let mut out = [0.0; 3];
    for li in 0..scene.lights.len() {
        let Some(cap) = light_cap(scene, p, li) else {
            continue;
        };
        let occ = occluders(scene, p, li);
        // The light's lobe times the cosine is formed by the first chain that uses it.
        let lit = Lit {
            cap: &cap,
            l: [None, None],
            occluders: &occ,
            hidden: diffuse_hidden(&cap, &occ, rx.normal, o),
        };
        shade_light(scene, &rx, li, &lit, o, counts, &mut out);
    }
    out
}

/// The light's cap as one lobe (`fit`) times the cosine about `normal`, by `kernel` (the
/// product on `o.table`).
fn light_lobe<K>(
    kernel: &K,
    cap: &SphericalCap,
    normal: Vec3,
    fit: CapFit,
    counts: &mut ProductCounts,
) -> LobeSum<1>
where
    K: Fn(&CosineLobe, &CosineLobe) -> CosineLobe,
{
    let mut l = LobeSum::<1>::new();
    l.push_cap(cap, 1.0, fit);
    light_with_cosine_with(kernel, &l, normal, Cosine::WithLight, counts)
}

/// [`shade`] of up to eight points at once (`out[k]` for `points[k]`), the product of each
/// light's lobe with the cosine by the SIMD kernel
/// ([`steradian_simd::lobe::product::product_x8`], eight points per product) and the rest
/// lane by lane as [`shade`] does it. Each radiance is within the SIMD product's bounds of
/// [`shade`]'s (its axis is the scalar kernel's bit for bit; its scale and exponent are within
/// a few `f32` ulps per unit of their logarithms), which the harness test
/// `lobes_simd_render_matches_the_scalar_one` measures on the built-in scenes.
///
/// # Panics
/// If `points` and `out` differ in length or hold more than eight.
pub fn shade_x8(
    scene: &Scene,
    points: &[ShadingPoint],
    o: &Options,
    counts: &mut ProductCounts,
    out: &mut [Rgb],
) {
    use steradian_simd::batch::LobeX8;
    use steradian_simd::lobe::product::product_x8;
    assert!(points.len() == out.len() && points.len() <= 8);
    let rxs: Vec<Receiver> = points.iter().map(|p| Receiver::of(scene, p)).collect();
    out.fill([0.0; 3]);
    let table = o.table.table();
    for li in 0..scene.lights.len() {
        // Per lane (fixed arrays: no allocation but the occluder lists that are not empty).
        let n = points.len();
        let caps: [Option<SphericalCap>; 8] =
            core::array::from_fn(|k| points.get(k).and_then(|p| light_cap(scene, p, li)));
        let occ: [Vec<SphericalCap>; 8] = core::array::from_fn(|k| match caps[k] {
            Some(_) => occluders(scene, &points[k], li),
            None => Vec::new(),
        });
        let hidden: [Option<f64>; 8] = core::array::from_fn(|k| {
            caps[k].and_then(|c| diffuse_hidden(&c, &occ[k], rxs[k].normal, o))
        });
        // The light's lobe times the cosine each lane's chains will use ([`chain_fits`]).
        let fits: [[Option<CapFit>; 2]; 8] = core::array::from_fn(|k| match caps[k] {
            Some(c) => chain_fits(&c, &rxs[k], &occ[k], hidden[k], o),
            None => [None, None],
        });
        let caps = &caps[..n];
        // `lobe_product` for the batches where some lane uses it: the unit product of the
        // light's unit lobe (a pad where a lane has no light) and the cosine, scaled by the
        // light lobe's scale (the cosine's is 1).
        let batch = |which: usize| {
            fits.iter().any(|f| f[which].is_some()).then(|| {
                let pad = CosineLobe::saturating(Vec3::Z, 0.0, 0.0);
                let lobes: [CosineLobe; 8] = core::array::from_fn(|k| {
                    match (caps.get(k).copied().flatten(), fits[k][which]) {
                        (Some(c), Some(fit)) => c.lobe(1.0, fit),
                        _ => pad,
                    }
                });
                let units: [CosineLobe; 8] = core::array::from_fn(|k| {
                    CosineLobe::saturating(lobes[k].axis(), 1.0, lobes[k].exponent())
                });
                let cosines: [CosineLobe; 8] = core::array::from_fn(|k| {
                    rxs.get(k)
                        .map_or(pad, |rx| CosineLobe::saturating(rx.normal, 1.0, 1.0))
                });
                let (a, b) = (
                    LobeX8::from_slice(&units[..n]),
                    LobeX8::from_slice(&cosines[..n]),
                );
                let q = product_x8(table, ProductFit::ExactIntegral, &a, &b).to_array();
                core::array::from_fn::<_, 8, _>(|k| {
                    CosineLobe::saturating(
                        q[k].axis(),
                        q[k].scale() * lobes[k].scale(),
                        q[k].exponent(),
                    )
                })
            })
        };
        let products = [batch(0), batch(1)];
        for (k, cap) in caps.iter().enumerate() {
            let Some(cap) = cap else { continue };
            // Each product a chain uses, counted as `push_times_cosine` counts it; a chain
            // that finds none formed forms its own, as in [`shade`].
            let l: [Option<LobeSum<1>>; 2] = core::array::from_fn(|w| {
                let lp = products[w].filter(|_| fits[k][w].is_some())?;
                counts.computed += 1;
                Some(LobeSum::<1>::from_lobes(0.0, &[lp[k]]))
            });
            let lit = Lit {
                cap,
                l: [l[0].as_ref(), l[1].as_ref()],
                occluders: &occ[k],
                hidden: hidden[k],
            };
            shade_light(scene, &rxs[k], li, &lit, o, counts, &mut out[k]);
        }
    }
}

/// What [`shade`] needs of a point for every light: its material's diffuse RGB and glossy
/// lobes at its view, and its normal in `f32`.
struct Receiver {
    diffuse: Rgb,
    glossy: super::material::ViewLobes,
    normal: Vec3,
}

impl Receiver {
    fn of(scene: &Scene, p: &ShadingPoint) -> Receiver {
        let mat = &scene.materials[p.material];
        Receiver {
            diffuse: mat.diffuse(),
            glossy: mat.lobes(p.n, p.wo),
            normal: f32v(p.n),
        }
    }
}

/// The cap light `li` subtends at `p`, or `None` where it lights nothing there: hidden by a
/// plane (its centre on the other side of a plane than `p`, `p` not on that plane), or no
/// cap (`p` inside the light).
fn light_cap(scene: &Scene, p: &ShadingPoint, li: usize) -> Option<SphericalCap> {
    let (x, light) = (p.x, &scene.lights[li]);
    for obj in &scene.objects {
        if let Shape::Plane { point, normal } = obj.shape {
            let sx = normal.dot(x - point);
            let sl = normal.dot(light.center - point);
            if sx.abs() > 1e-9 * (1.0 + x.abs().max_element()) && sx * sl < 0.0 {
                return None;
            }
        }
    }
    SphericalCap::from_sphere(Vec3::ZERO, f32v(light.center - x), light.radius as f32).ok()
}

/// The caps of the spheres that can hide part of light `li` from `p` (module docs): nearer
/// than the light's centre, their cap overlapping the light's.
fn occluders(scene: &Scene, p: &ShadingPoint, li: usize) -> Vec<SphericalCap> {
    let (self_id, x, light) = (p.object, p.x, &scene.lights[li]);
    let rel = light.center - x;
    let d_light = rel.length();
    let (s_light, a_light) = ((light.radius / d_light).min(1.0), rel / d_light);
    let c_light = (1.0 - s_light * s_light).max(0.0).sqrt();
    let mut occluders = Vec::new();
    for (id, obj) in scene.objects.iter().enumerate() {
        if id == self_id || obj.kind == Kind::Light(li) {
            continue;
        }
        let Shape::Sphere { center, radius } = obj.shape else {
            continue;
        };
        let rc = center - x;
        let d2 = rc.length_squared();
        if d2 >= d_light * d_light {
            continue;
        }
        // The caps overlap iff the angle θ between their axes is below α_l + α_o:
        // cos θ > cos α_l·cos α_o − sin α_l·sin α_o (both angles in [0, π/2],
        // sin α_o = r/d), times d: rc·a_l > cos α_l·√(d² − r²) − sin α_l·r. Outside the
        // sphere the cull `A = rc·a_l + sin α_l·r ≤ cos α_l·√(d² − r²)` is tested squared
        // where `A > 0` (no root, no inverse trigonometry); inside it `√(d²)` is `r_in`.
        let culled = if d2 > radius * radius {
            let a = rc.dot(a_light) + s_light * radius;
            a <= 0.0 || a * a <= c_light * c_light * (d2 - radius * radius)
        } else {
            rc.dot(a_light) <= -s_light * d2.sqrt()
        };
        if culled {
            continue;
        }
        let Ok(oc) = SphericalCap::from_sphere(Vec3::ZERO, f32v(rc), radius as f32) else {
            continue;
        };
        occluders.push(oc);
    }
    occluders
}

/// The cosine-weighted solid angle the occluders hide of the light's cap at a receiver
/// with normal `n`, exactly: `Σᵢ n·overlap_moment(cap, occluderᵢ)`
/// ([`SphericalCap::overlap_moment`]), which is exact where the light's cap lies wholly
/// above the horizon (so every hidden direction has `n·ω > 0`) and the occluders' caps are
/// pairwise disjoint (so no direction is hidden twice). `None` elsewhere (the lobe chain's
/// visible fraction is used), or without [`Options::exact_diffuse`].
fn diffuse_hidden(
    cap: &SphericalCap,
    occluders: &[SphericalCap],
    n: Vec3,
    o: &Options,
) -> Option<f64> {
    if !o.exact_diffuse {
        return None;
    }
    // `(sin α, cos α)` from `1 − cos α`, as `SphericalCap::clipped_cosine` forms them.
    let sc = |c: &SphericalCap| {
        let k = f64::from(c.one_minus_cos());
        ((k * (2.0 - k)).sqrt(), 1.0 - k)
    };
    if f64::from(n.dot(cap.axis())) < sc(cap).0 {
        return None;
    }
    // Disjoint: the angle between the axes is at least `α_a + α_b`, i.e. (both at most
    // π/2, caps of spheres) `cos d ≤ cos α_a·cos α_b − sin α_a·sin α_b`.
    for (i, a) in occluders.iter().enumerate() {
        let (sa, ca) = sc(a);
        for b in &occluders[i + 1..] {
            let (sb, cb) = sc(b);
            if f64::from(a.axis().dot(b.axis())) > ca * cb - sa * sb {
                return None;
            }
        }
    }
    let n = n.as_dvec3();
    Some(
        occluders
            .iter()
            .map(|oc| n.dot(cap.overlap_moment(oc).as_dvec3()))
            .sum(),
    )
}

/// The fit of the light's lobe in the glossy chains at a receiver ([`Options::glossy_fit`]):
/// [`Options::fit`] where the moments lobe is asked for but the receiver's sharpest lobe has
/// `n(1 − cos α)` above [`MOMENTS_MAX_X`].
fn glossy_fit(cap: &SphericalCap, rx: &Receiver, o: &Options) -> CapFit {
    let n = rx.glossy.iter().map(|g| g.exponent).fold(0.0, f64::max);
    if o.glossy_fit == CapFit::Moments
        && n * f64::from(cap.one_minus_cos()) > f64::from(MOMENTS_MAX_X)
    {
        o.fit
    } else {
        o.glossy_fit
    }
}

/// The light's lobes times the cosine a receiver's chains will use, so that [`shade_x8`]
/// forms them in batches: `[diffuse, glossy]`, the diffuse one ([`Options::fit`]) for a
/// shadow chain the diffuse term cannot do without ([`diffuse_hidden`] is `None` with
/// occluders) or the paper's diffuse chain, the glossy one ([`glossy_fit`]) for glossy
/// chains unless it is the diffuse one's fit, which they then share.
fn chain_fits(
    cap: &SphericalCap,
    rx: &Receiver,
    occluders: &[SphericalCap],
    hidden: Option<f64>,
    o: &Options,
) -> [Option<CapFit>; 2] {
    let diffuse = !o.exact_diffuse || (!occluders.is_empty() && hidden.is_none());
    fits_with(diffuse, cap, rx, o)
}

/// [`chain_fits`] where whether the diffuse chain runs is known (`diffuse`).
fn fits_with(diffuse: bool, cap: &SphericalCap, rx: &Receiver, o: &Options) -> [Option<CapFit>; 2] {
    let diffuse = diffuse.then_some(o.fit);
    let glossy = rx
        .glossy
        .iter()
        .next()
        .map(|_| glossy_fit(cap, rx, o))
        .filter(|g| diffuse != Some(*g));
    [diffuse, glossy]
}

/// One light at one receiver: its cap, its lobes times the cosine for the diffuse and the
/// glossy chains when formed ahead ([`chain_fits`]; `None`: the first chain that uses one
/// forms it), the caps of its occluders and what they hide of the diffuse term when that is
/// exact ([`diffuse_hidden`]).
struct Lit<'a> {
    cap: &'a SphericalCap,
    l: [Option<&'a LobeSum<1>>; 2],
    occluders: &'a [SphericalCap],
    hidden: Option<f64>,
}

/// The visibility of one light at a receiver as `1 + Σ` lobes (module docs): none where the
/// light has no occluder, nor where only an exact diffuse term would use them.
fn visibility(rx: &Receiver, lit: &Lit<'_>, o: &Options) -> LobeVec {
    let mut vis = LobeVec {
        constant: 1.0,
        lobes: Vec::new(),
    };
    match o.visibility {
        Visibility::PerOccluder => {
            vis.lobes
                .extend(lit.occluders.iter().map(|oc| oc.lobe(-1.0, o.fit)));
        }
        // No occluder, no shadow leaf: the mask is not walked; nor where only the diffuse
        // term would use it and that is exact.
        Visibility::Mask { .. }
            if lit.occluders.is_empty()
                || (lit.hidden.is_some() && rx.glossy.iter().next().is_none()) => {}
        Visibility::Mask { depth, leaves } => {
            let dist = mask::dist_of(lit.cap.half_angle());
            mask::shadow_leaves(lit.cap, lit.occluders, depth, leaves, |leaf, d, f| {
                let w = mask::weight(&mask::WEIGHTS, dist, d, depth);
                vis.lobes.push(leaf.lobe(-w * f, o.fit));
            });
        }
    }
    vis
}

/// Whether the diffuse term needs its chain: not where it is exact ([`diffuse_hidden`]),
/// nor where the exact unshadowed value meets no shadow lobe.
fn diffuse_needs_chain(hidden: Option<f64>, vis: &LobeVec, o: &Options) -> bool {
    hidden.is_none() && (!o.exact_diffuse || !vis.lobes.is_empty())
}

/// The constant diffuse reflectance `1/π` of a chain (the albedo is carried in RGB).
fn diffuse_reflectance() -> LobeSum<1> {
    LobeSum::with_constant(1.0 / std::f32::consts::PI)
}

/// A glossy lobe's reflectance of a chain: the unit lobe (its RGB scale carried apart).
fn glossy_reflectance(g: &super::material::ViewLobe) -> LobeSum<1> {
    let lobe = CosineLobe::saturating(f32v(g.axis), 1.0, g.exponent as f32);
    LobeSum::<1>::from_lobes(0.0, &[lobe])
}

/// Light `li`'s radiance at a receiver `rx` added to `out` (module docs).
fn shade_light(
    scene: &Scene,
    rx: &Receiver,
    li: usize,
    lit: &Lit<'_>,
    o: &Options,
    counts: &mut ProductCounts,
    out: &mut Rgb,
) {
    let vis = visibility(rx, lit, o);
    let unoccluded = LobeSum::<1>::unoccluded();
    let table = o.table.table();
    let kernel =
        |a: &CosineLobe, b: &CosineLobe| product_with(table, ProductFit::ExactIntegral, a, b);
    // A chain's unshadowed and shadowed values under the light's lobe times the cosine `l`.
    let run = |l: &LobeSum<1>, r: &LobeSum<1>, counts: &mut ProductCounts| -> (f64, f64) {
        let u = triple_with(&kernel, r, l, &unoccluded, 0.0, counts);
        if vis.lobes.is_empty() {
            return (u as f64, u as f64);
        }
        let v = triple_with(&kernel, r, l, &vis, o.threshold * u.abs(), counts);
        (u as f64, v as f64)
    };
    // The lobes times the cosine where not formed ahead, by the first chain that uses each;
    // the glossy chains share the diffuse chain's where their fits agree.
    let (fd, fg) = (o.fit, glossy_fit(lit.cap, rx, o));
    let mut ld = lit.l[0].cloned();
    let d = diffuse_needs_chain(lit.hidden, &vis, o).then(|| {
        let l = ld.get_or_insert_with(|| light_lobe(&kernel, lit.cap, rx.normal, fd, counts));
        let l = *l;
        run(&l, &diffuse_reflectance(), counts)
    });
    let mut lg = lit.l[1].cloned().or(ld.filter(|_| fg == fd));
    let mut glossy = Vec::with_capacity(rx.glossy.len());
    for g in rx.glossy.iter() {
        let l = *lg.get_or_insert_with(|| light_lobe(&kernel, lit.cap, rx.normal, fg, counts));
        glossy.push(run(&l, &glossy_reflectance(g), counts).1);
    }
    let glossy = glossy.into_iter();
    add_light(&scene.lights[li], rx, lit, o, d, glossy, out);
}

/// The light's radiance from its chains' values, added to `out`: `d` the diffuse chain's
/// `(unshadowed, shadowed)` where [`diffuse_needs_chain`], `glossy` the shadowed value of
/// each of the receiver's glossy lobes in order. The diffuse term is exact where
/// [`diffuse_hidden`] is, else (with [`Options::exact_diffuse`]) the exact unshadowed value
/// times the chain's visible fraction (all of it without a chain, or where the chain leaves
/// nothing to divide), else the chain's shadowed value.
fn add_light(
    light: &super::SphereLight,
    rx: &Receiver,
    lit: &Lit<'_>,
    o: &Options,
    d: Option<(f64, f64)>,
    glossy: impl Iterator<Item = f64>,
    out: &mut Rgb,
) {
    let exact = || f64::from(lit.cap.clipped_cosine(rx.normal));
    let i_d = if let Some(hidden) = lit.hidden {
        // Exact: the unshadowed value less what the occluders hide of it.
        (exact() - hidden).max(0.0) / std::f64::consts::PI
    } else if o.exact_diffuse {
        let visible = match d {
            Some((u_d, v_d)) if u_d > 0.0 => (v_d / u_d).clamp(0.0, 1.0),
            _ => 1.0,
        };
        exact() / std::f64::consts::PI * visible
    } else {
        d.map_or(0.0, |c| c.1)
    };
    let mut acc = rx.diffuse.map(|d| d * i_d);
    for (g, i_g) in rx.glossy.iter().zip(glossy) {
        for (a, s) in acc.iter_mut().zip(g.scale) {
            *a += s * i_g;
        }
    }
    for c in 0..3 {
        out[c] += light.radiance[c] * acc[c].max(0.0);
    }
}

/// Shading points per dispatch of [`render_gpu`].
pub const GPU_BATCH: usize = 2048;

/// One light at one receiver as [`render_gpu`] prepares it on the CPU: its cap, what its
/// occluders hide of the diffuse term where that is exact, its visibility lobes and
/// whether the diffuse term needs a chain.
struct LightPrep {
    li: usize,
    cap: SphericalCap,
    hidden: Option<f64>,
    vis: LobeVec,
    diffuse_chain: bool,
}

/// A receiver and its lit lights, prepared as [`shade`] prepares them.
fn prepare(scene: &Scene, p: &ShadingPoint, o: &Options) -> (Receiver, Vec<LightPrep>) {
    let rx = Receiver::of(scene, p);
    let mut lights = Vec::new();
    for li in 0..scene.lights.len() {
        let Some(cap) = light_cap(scene, p, li) else {
            continue;
        };
        let occ = occluders(scene, p, li);
        let hidden = diffuse_hidden(&cap, &occ, rx.normal, o);
        let lit = Lit {
            cap: &cap,
            l: [None, None],
            occluders: &occ,
            hidden,
        };
        let vis = visibility(&rx, &lit, o);
        let diffuse_chain = diffuse_needs_chain(hidden, &vis, o);
        lights.push(LightPrep {
            li,
            cap,
            hidden,
            vis,
            diffuse_chain,
        });
    }
    (rx, lights)
}

/// The input row of `steradian_core::wgsl::LOBE_CHAIN` for reflectance `r` (a constant and
/// at most one lobe) at normal `n` under the light lobe `l`, its visibility lobes at `vis`
/// (offset and count, in lobes of five floats, in the table after the product table),
/// pruning threshold `t`.
pub fn chain_row(n: Vec3, l: &CosineLobe, r: &LobeSum<1>, vis: (u32, u32), t: f32) -> [f32; 18] {
    let (la, rl) = (l.axis(), r.lobes().first());
    let (ra, rs, re) = rl.map_or((Vec3::Z, 0.0, 0.0), |g| (g.axis(), g.scale(), g.exponent()));
    [
        n.x,
        n.y,
        n.z,
        la.x,
        la.y,
        la.z,
        l.scale(),
        l.exponent(),
        r.constant(),
        r.lobes().len() as f32,
        ra.x,
        ra.y,
        ra.z,
        rs,
        re,
        f32::from_bits(vis.0),
        f32::from_bits(vis.1),
        t,
    ]
}

/// [`render`] on the wgpu backend: [`GPU_BATCH`] points at a time, each point's lights
/// prepared on the CPU's thread pool as [`shade`] prepares them (caps, occluders, the
/// quadtree mask's visibility lobes, the exact diffuse term), every chain evaluated by
/// `steradian_core::wgsl::LOBE_CHAIN` (one row per chain, the light's lobe times the cosine
/// formed in each), and the chains combined on the CPU as [`shade`] combines them. Each
/// pixel is within the chains' tolerance of [`render`]'s (harness test
/// `lobes_gpu_path_matches_the_scalar_path`); pixels are then refined at `o.footprint` as
/// on the CPU paths. The counts are the products computed, the light's lobe times the
/// cosine counted once per fit its chains use, as [`shade`] counts it; the other counts
/// stay 0.
pub fn render_gpu(
    scene: &Scene,
    o: &Options,
    gpu: &mut crate::backend::gpu::Gpu,
    bar: &ProgressBar,
) -> Result<(Image, ProductCounts), String> {
    let (mut img, queue) = super::centre_queue(scene);
    let pixels = img.data.len();
    bar.set_length(pixels as u64);
    bar.inc((pixels - queue.len()) as u64);
    let mut counts = ProductCounts::default();
    let points: Vec<ShadingPoint> = queue.iter().map(|(_, p)| *p).collect();
    let shaded = shade_points_gpu(scene, o, gpu, &points, &mut counts, bar)?;
    for ((px, _), v) in queue.iter().zip(shaded) {
        img.data[*px] = v;
    }
    let objects = super::queue_objects(pixels, &queue);
    footprint::refine(scene, &mut img, &objects, o.footprint, |points| {
        shade_points_gpu(scene, o, gpu, points, &mut counts, &ProgressBar::hidden())
    })?;
    Ok((img, counts))
}

/// The radiance of each point by the wgpu path of [`render_gpu`], [`GPU_BATCH`] points per
/// dispatch; the products computed are added to `counts`, and `bar` advanced per point.
fn shade_points_gpu(
    scene: &Scene,
    o: &Options,
    gpu: &mut crate::backend::gpu::Gpu,
    points: &[ShadingPoint],
    counts: &mut ProductCounts,
    bar: &ProgressBar,
) -> Result<Vec<Rgb>, String> {
    use crate::backend::gpu::Custom;
    use crate::kernels::Columns;
    use rayon::prelude::*;

    let product_table = o.table.table().gpu_table();
    let mut shaded = Vec::with_capacity(points.len());
    for chunk in points.chunks(GPU_BATCH) {
        let preps: Vec<(Receiver, Vec<LightPrep>)> =
            chunk.par_iter().map(|p| prepare(scene, p, o)).collect();
        let mut table = product_table.clone();
        let mut rows: Vec<[f32; 18]> = Vec::new();
        for (rx, lights) in &preps {
            for lp in lights {
                let chains = usize::from(lp.diffuse_chain) + rx.glossy.len();
                if chains == 0 {
                    continue;
                }
                // The light's lobe times the cosine, counted once per fit the chains use,
                // as [`shade`] forms them.
                let fits = fits_with(lp.diffuse_chain, &lp.cap, rx, o);
                counts.computed += fits.iter().flatten().count() as u64;
                let off = u32::try_from(table.len())
                    .map_err(|_| "lobes --gpu: table beyond u32 indices".to_string())?;
                for v in &lp.vis.lobes {
                    let a = v.axis();
                    table.extend([a.x, a.y, a.z, v.scale(), v.exponent()]);
                }
                let vis = (off, lp.vis.lobes.len() as u32);
                if lp.diffuse_chain {
                    rows.push(chain_row(
                        rx.normal,
                        &lp.cap.lobe(1.0, o.fit),
                        &diffuse_reflectance(),
                        vis,
                        o.threshold,
                    ));
                }
                let l = lp.cap.lobe(1.0, glossy_fit(&lp.cap, rx, o));
                for g in rx.glossy.iter() {
                    rows.push(chain_row(
                        rx.normal,
                        &l,
                        &glossy_reflectance(g),
                        vis,
                        o.threshold,
                    ));
                }
            }
        }
        let mut out = Columns::zeros(3, rows.len());
        if !rows.is_empty() {
            let custom = Custom {
                label: "lobe-chain",
                source: steradian_core::wgsl::LOBE_CHAIN,
                table: Some(&table),
            };
            gpu.run_custom(&custom, &Columns::from_rows(&rows), &mut out)
                .map_err(|e| format!("lobe-chain kernel: {e}"))?;
        }
        let n = rows.len();
        let value = |c: usize, r: usize| f64::from(out.data[c * n + r]);
        let mut r = 0;
        for (rx, lights) in &preps {
            let mut acc = [0.0; 3];
            for lp in lights {
                let d = lp.diffuse_chain.then(|| {
                    r += 1;
                    (value(0, r - 1), value(1, r - 1))
                });
                let glossy: Vec<f64> = (0..rx.glossy.len()).map(|k| value(1, r + k)).collect();
                r += glossy.len();
                let lit = Lit {
                    cap: &lp.cap,
                    l: [None, None],
                    occluders: &[],
                    hidden: lp.hidden,
                };
                add_light(
                    &scene.lights[lp.li],
                    rx,
                    &lit,
                    o,
                    d,
                    glossy.into_iter(),
                    &mut acc,
                );
            }
            shaded.push(acc);
        }
        counts.computed += (0..n).map(|r| value(2, r) as u64).sum::<u64>();
        bar.inc(chunk.len() as u64);
    }
    Ok(shaded)
}

/// What [`choose_depth`] chose and what it measured.
#[derive(Clone, Debug)]
pub struct DepthChoice {
    /// The chosen deepest level of the quadtree mask.
    pub depth: u32,
    /// `(depth, estimate)`: the probes' mean |difference| from the deepest mask over its
    /// largest value ([`super::probe_estimates`]).
    pub estimates: Vec<(u32, f64)>,
}

/// The shallowest quadtree mask (levels `1 ..= mask::MAX_DEPTH`) that keeps the shaded
/// probes within [`super::PLAN_SHARE`] of `target` (mean |difference| over the maximum
/// radiance, the render's measure) of the deepest mask's: the probes are the
/// [`super::probe_points`] grid, shaded with `o` but for the depth, so the difference is
/// the depth's alone. The deepest level when `o` does not use the mask or none is within.
pub fn choose_depth(scene: &Scene, o: &Options, target: f64) -> DepthChoice {
    let Visibility::Mask { leaves, .. } = o.visibility else {
        return DepthChoice {
            depth: mask::MAX_DEPTH,
            estimates: Vec::new(),
        };
    };
    let probes = super::probe_points(scene);
    let mut counts = ProductCounts::default();
    let depths: Vec<u32> = (1..=mask::MAX_DEPTH).collect();
    let images: Vec<Vec<Rgb>> = depths
        .iter()
        .map(|&depth| {
            let od = Options {
                visibility: Visibility::Mask { depth, leaves },
                ..*o
            };
            probes
                .iter()
                .map(|p| shade(scene, p, &od, &mut counts))
                .collect()
        })
        .collect();
    let (depth, estimates) =
        super::plan_choice(&depths, &images, target).unwrap_or((mask::MAX_DEPTH, Vec::new()));
    DepthChoice { depth, estimates }
}

/// The product table the plan chose, with the estimates of the sizes it tried.
pub struct TableChoice {
    /// The chosen size.
    pub size: TableSize,
    /// `(size, estimate)` per size tried against the built-in table
    /// ([`super::probe_estimates`]).
    pub estimates: Vec<(TableSize, f64)>,
}

/// The coarsest product table of [`TableSize::ALL`] whose probe pixels
/// ([`super::probe_points`], shaded by [`shade`] with `o`) stay within
/// [`super::PLAN_SHARE`] of `target` of the built-in table's. The sizes are tried coarsest
/// first and the search stops at the first that passes, so a size is generated only when
/// it is tried (the built-in table's probes are shaded first, as the reference).
pub fn choose_table(scene: &Scene, o: &Options, target: f64) -> TableChoice {
    let probes = super::probe_points(scene);
    let mut counts = ProductCounts::default();
    let mut shaded = |table: TableSize| -> Vec<Rgb> {
        let ot = Options { table, ..*o };
        probes
            .iter()
            .map(|p| shade(scene, p, &ot, &mut counts))
            .collect()
    };
    let reference = shaded(TableSize::BuiltIn);
    let mut estimates = Vec::new();
    for size in TableSize::ALL {
        if size == TableSize::BuiltIn {
            break;
        }
        let img = shaded(size);
        let e = super::probe_estimates(&[img, reference.clone()])[0];
        estimates.push((size, e));
        if e <= super::PLAN_SHARE * target {
            return TableChoice { size, estimates };
        }
    }
    estimates.push((TableSize::BuiltIn, 0.0));
    TableChoice {
        size: TableSize::BuiltIn,
        estimates,
    }
}

/// One pixel-centre sample per pixel ([`super::render_centres`]), surfaces shaded by
/// [`shade`]; the product counts of the whole image.
pub fn render(scene: &Scene, o: &Options, bar: &ProgressBar) -> (Image, ProductCounts) {
    let (mut img, rows, objects) =
        render_centres(scene, bar, ProductCounts::default, |counts, p| {
            shade(scene, p, o, counts)
        });
    let mut total = sum_counts(rows);
    total += refine_image(scene, &mut img, &objects, o, false);
    (img, total)
}

/// The footprint refinement of a `lobes` image `img` (its centre pass's `objects`) at
/// `o.footprint`, the points shaded by [`shade_x8`], or by [`shade`] one at a time without
/// `simd`; the products computed for it.
pub fn refine_image(
    scene: &Scene,
    img: &mut Image,
    objects: &[Option<usize>],
    o: &Options,
    simd: bool,
) -> ProductCounts {
    let mut total = ProductCounts::default();
    if simd {
        refine(scene, img, objects, o, &mut total, |points, counts, out| {
            shade_x8(scene, points, o, counts, out)
        });
    } else {
        refine(scene, img, objects, o, &mut total, |points, counts, out| {
            for (p, v) in points.iter().zip(out.iter_mut()) {
                *v = shade(scene, p, o, counts);
            }
        });
    }
    total
}

fn sum_counts(rows: impl IntoIterator<Item = ProductCounts>) -> ProductCounts {
    let mut total = ProductCounts::default();
    for c in rows {
        total += c;
    }
    total
}

/// [`footprint::refine`] at `o.footprint` (nothing where it is 0), the points shaded
/// `shade(points, counts, out)` up to eight at a time on the thread pool and their product
/// counts added to `total`. Errors cannot occur: every point given is shaded.
fn refine(
    scene: &Scene,
    img: &mut Image,
    objects: &[Option<usize>],
    o: &Options,
    total: &mut ProductCounts,
    shade: impl Fn(&[ShadingPoint], &mut ProductCounts, &mut [Rgb]) + Sync,
) {
    use rayon::prelude::*;
    let refined = footprint::refine(scene, img, objects, o.footprint, |points| {
        let parts: Vec<(Vec<Rgb>, ProductCounts)> = points
            .par_chunks(8)
            .map(|ps| {
                let (mut out, mut c) = (vec![[0.0; 3]; ps.len()], ProductCounts::default());
                shade(ps, &mut c, &mut out);
                (out, c)
            })
            .collect();
        let mut all = Vec::with_capacity(points.len());
        for (v, c) in parts {
            all.extend(v);
            *total += c;
        }
        Ok(all)
    });
    debug_assert!(refined.is_ok(), "every point given is shaded");
}

/// [`render`] with the points of each row shaded eight at a time by [`shade_x8`].
pub fn render_simd(scene: &Scene, o: &Options, bar: &ProgressBar) -> (Image, ProductCounts) {
    let (mut img, rows, objects) =
        render_centres_x8(scene, bar, ProductCounts::default, |counts, ps, out| {
            shade_x8(scene, ps, o, counts, out)
        });
    let mut total = sum_counts(rows);
    total += refine_image(scene, &mut img, &objects, o, true);
    (img, total)
}
