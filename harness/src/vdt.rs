//! Visibility distance tables in the harness: brute-force and exact-coverage references in
//! `f64`, the test families of the accuracy study (straight edges of every orientation,
//! corners, the discs cast by sphere occluders), their error distributions for eq. 9, the
//! straight-edge (gradient) variant and the summed-area table of the binary map, and the
//! `steradian eval vdt-box` handler.
//!
//! Units: texel units throughout, texel `(i, j)` covering `[i, i+1]×[j, j+1]`, row `j`
//! along `v`; a query is a square with centre `(u, v)` and half-diagonal `r` (half-side
//! `r/√2`).

use serde_json::{Map, Value, json};
use steradian_core::lobe::cap::SphericalCap;
use steradian_core::rsl::sat::Sat;
use steradian_core::rsl::vdt::Vdt;
use steradian_core::rsl::visibility::{self, Outside};
use steradian_core::{Vec2, Vec3};

use crate::json::{num, parse_f32};
use crate::rng::Rng;
use steradian_reference::rsl::vdt as vdt_ref;

/// [`steradian_reference::rsl::vdt::brute_force_edges`] rounded to `f32`, `±NO_BOUNDARY`
/// without a boundary (the core table's convention).
pub fn brute_force_edges(w: usize, h: usize, mask: &[bool]) -> Vec<f32> {
    to_table(vdt_ref::brute_force_edges(w, h, mask))
}

/// [`steradian_reference::rsl::vdt::brute_force_squares`] rounded to `f32` as
/// [`brute_force_edges`].
pub fn brute_force_squares(w: usize, h: usize, mask: &[bool]) -> Vec<f32> {
    to_table(vdt_ref::brute_force_squares(w, h, mask))
}

fn to_table(d: Vec<f64>) -> Vec<f32> {
    d.into_iter()
        .map(|x| {
            if x.is_finite() {
                x as f32
            } else {
                steradian_core::rsl::vdt::NO_BOUNDARY.copysign(x as f32)
            }
        })
        .collect()
}

pub use steradian_reference::rsl::vdt::{clip, polygon_area};

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> [[f64; 2]; 4] {
    [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
}

/// The binary visibility map (coverage ≥ ½) of three sphere occluders on an `n × n` grid:
/// the map of the report's and the bench's timings.
pub fn spheres_mask(n: usize) -> Vec<bool> {
    let caps = [
        SphericalCap::new(Vec3::new(0.3, 0.2, 0.9), 0.4).expect("cap"),
        SphericalCap::new(Vec3::new(-0.7, 0.1, 0.3), 0.5).expect("cap"),
        SphericalCap::new(Vec3::new(0.1, -0.8, 0.5), 0.3).expect("cap"),
    ];
    let mut cov = vec![0.0f32; n * n];
    visibility::coverage_into(&caps, n, Outside::Visible, &mut cov).expect("grid");
    let mut mask = vec![false; n * n];
    visibility::binary_into(&cov, &mut mask);
    mask
}

/// A visibility pattern in the plane of the map (texel units), with its exact coverage.
#[derive(Clone, Debug)]
pub enum Shape {
    /// Visible where `n·x ≥ c` (`n` unit).
    Edge {
        /// Unit normal, pointing into the visible side.
        n: [f64; 2],
        /// Offset.
        c: f64,
    },
    /// A corner: the intersection of two half-planes `nk·x ≥ ck`, visible inside (or, with
    /// `invert`, outside).
    Corner {
        /// The two half-planes.
        planes: [([f64; 2], f64); 2],
        /// Visible outside the wedge instead.
        invert: bool,
    },
    /// Sphere occluders seen through the equal-area map on a `size × size` grid
    /// ([`Outside::Visible`]).
    Caps {
        /// The caps in the local frame.
        caps: Vec<SphericalCap>,
        /// Grid side (texels).
        size: usize,
    },
}

/// Stratified samples per texel side of the reference of [`Shape::Caps`].
pub const CAP_REF_SAMPLES: usize = 16;

fn cap_visible_f64(caps: &[SphericalCap], size: usize, u: f64, v: f64) -> bool {
    let p = [2.0 * u / size as f64 - 1.0, 2.0 * v / size as f64 - 1.0];
    let r2 = p[0] * p[0] + p[1] * p[1];
    if r2 > 1.0 {
        return true;
    }
    let s = (2.0 - r2).sqrt();
    let d = [p[0] * s, p[1] * s, 1.0 - r2];
    caps.iter().all(|c| {
        let a = c.axis();
        let e = [a.x as f64 - d[0], a.y as f64 - d[1], a.z as f64 - d[2]];
        0.5 * (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) > c.one_minus_cos() as f64
    })
}

/// Visible area of the box `[x0, x1]×[y0, y1]` (texel units of a `size × size` map) for
/// the caps, by midpoint sampling at `k × k` samples per texel ([`Outside::Visible`]).
pub fn caps_visible_area(caps: &[SphericalCap], size: usize, b: [f64; 4], k: usize) -> f64 {
    let [x0, y0, x1, y1] = b;
    let k = k as f64;
    let (nx, ny) = (
        ((x1 - x0) * k).ceil().max(1.0) as usize,
        ((y1 - y0) * k).ceil().max(1.0) as usize,
    );
    let (dx, dy) = ((x1 - x0) / nx as f64, (y1 - y0) / ny as f64);
    let mut hit = 0usize;
    for b in 0..ny {
        for a in 0..nx {
            let u = x0 + (a as f64 + 0.5) * dx;
            let v = y0 + (b as f64 + 0.5) * dy;
            hit += cap_visible_f64(caps, size, u, v) as usize;
        }
    }
    hit as f64 * dx * dy
}

impl Shape {
    /// The visible area of the box `[x0, x1]×[y0, y1]`: exact for edges and corners
    /// (polygon clipping), midpoint-sampled at [`CAP_REF_SAMPLES`]² per texel for caps.
    pub fn visible_area(&self, x0: f64, y0: f64, x1: f64, y1: f64) -> f64 {
        let r = rect(x0, y0, x1, y1);
        match self {
            Shape::Edge { n, c } => polygon_area(&clip(&r, *n, *c)),
            Shape::Corner { planes, invert } => {
                let p = clip(
                    &clip(&r, planes[0].0, planes[0].1),
                    planes[1].0,
                    planes[1].1,
                );
                let inside = polygon_area(&p);
                if *invert {
                    (x1 - x0) * (y1 - y0) - inside
                } else {
                    inside
                }
            }
            Shape::Caps { caps, size } => {
                caps_visible_area(caps, *size, [x0, y0, x1, y1], CAP_REF_SAMPLES)
            }
        }
    }

    /// Rasterises the shape on a `w × h` grid: per-texel coverage (exact for edges and
    /// corners; [`visibility::coverage_into`] for caps) and the binary map (coverage ≥ ½).
    pub fn rasterize(&self, w: usize, h: usize) -> (Vec<f32>, Vec<bool>) {
        let cov: Vec<f32> = match self {
            Shape::Caps { caps, size } => {
                let mut c = vec![0.0f32; size * size];
                visibility::coverage_into(caps, *size, Outside::Visible, &mut c)
                    .expect("valid grid");
                c
            }
            _ => (0..w * h)
                .map(|k| {
                    let (i, j) = ((k % w) as f64, (k / w) as f64);
                    self.visible_area(i, j, i + 1.0, j + 1.0) as f32
                })
                .collect(),
        };
        let mut mask = vec![false; cov.len()];
        visibility::binary_into(&cov, &mut mask);
        (cov, mask)
    }
}

/// Exact visible fraction of the box `[x0, x1]×[y0, y1]` of a binary map (piecewise
/// constant texels, the box clipped to the grid; `f64` prefix sums).
pub struct MaskSums {
    w: usize,
    h: usize,
    s: Vec<f64>,
}

impl MaskSums {
    /// Prefix sums of a binary map.
    pub fn new(w: usize, h: usize, mask: &[bool]) -> Self {
        let mut s = vec![0.0; (w + 1) * (h + 1)];
        for j in 0..h {
            for i in 0..w {
                s[(j + 1) * (w + 1) + i + 1] = s[j * (w + 1) + i + 1] + s[(j + 1) * (w + 1) + i]
                    - s[j * (w + 1) + i]
                    + mask[j * w + i] as u8 as f64;
            }
        }
        MaskSums { w, h, s }
    }
    /// `∫` over `[0, x]×[0, y]` (bilinear in the prefix sums: exact for piecewise-constant
    /// texels).
    fn at(&self, x: f64, y: f64) -> f64 {
        let x = x.clamp(0.0, self.w as f64);
        let y = y.clamp(0.0, self.h as f64);
        let (i, j) = (
            (x.floor() as usize).min(self.w - 1),
            (y.floor() as usize).min(self.h - 1),
        );
        let (a, b) = (x - i as f64, y - j as f64);
        let w1 = self.w + 1;
        let s = |i: usize, j: usize| self.s[j * w1 + i];
        let s0 = s(i, j) + a * (s(i + 1, j) - s(i, j));
        let s1 = s(i, j + 1) + a * (s(i + 1, j + 1) - s(i, j + 1));
        s0 + b * (s1 - s0)
    }
    /// Visible area of the box (clipped to the grid).
    pub fn area(&self, x0: f64, y0: f64, x1: f64, y1: f64) -> f64 {
        self.at(x1, y1) - self.at(x0, y1) - self.at(x1, y0) + self.at(x0, y0)
    }
}

/// The three estimates of one query and its two references.
#[derive(Clone, Copy, Debug)]
pub struct QueryResult {
    /// Centre and half-diagonal.
    pub q: [f32; 3],
    /// Eq. 9.
    pub eq9: f32,
    /// Straight-edge (gradient) variant.
    pub gradient: f32,
    /// Summed-area table of the binary map (4 lookups; `steradian_core::rsl::sat`).
    pub sat: f32,
    /// Exact visible fraction of the binary map.
    pub mask: f64,
    /// Exact visible fraction of the true shape (edges, corners) or its dense-sampled
    /// reference (caps).
    pub truth: f64,
}

/// A test family of the accuracy study.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// Straight edges, uniform orientation in `[0, π)`.
    Edges,
    /// Corners (wedges of opening 30°–150°, visible inside or outside).
    Corners,
    /// One to three sphere occluders seen through the equal-area map.
    SphereDiscs,
}

impl Family {
    /// All families, in report order.
    pub const ALL: [Family; 3] = [Family::Edges, Family::Corners, Family::SphereDiscs];
    /// Name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Family::Edges => "straight edges",
            Family::Corners => "corners",
            Family::SphereDiscs => "sphere discs",
        }
    }
}

/// Side of the maps of the study.
pub const STUDY_SIZE: usize = 64;

fn random_shape(family: Family, rng: &mut Rng) -> Shape {
    let size = STUDY_SIZE as f64;
    match family {
        Family::Edges => {
            let th = rng.range(0.0, std::f64::consts::PI);
            let n = [th.cos(), th.sin()];
            let p = [rng.range(0.3, 0.7) * size, rng.range(0.3, 0.7) * size];
            Shape::Edge {
                n,
                c: n[0] * p[0] + n[1] * p[1],
            }
        }
        Family::Corners => {
            let apex = [rng.range(0.35, 0.65) * size, rng.range(0.35, 0.65) * size];
            let dir = rng.range(0.0, std::f64::consts::TAU);
            let open = rng.range(30f64, 150.0).to_radians();
            // Half-plane normals pointing into the wedge around direction `dir`.
            let a1 = dir - 0.5 * open + std::f64::consts::FRAC_PI_2;
            let a2 = dir + 0.5 * open - std::f64::consts::FRAC_PI_2;
            let pl = |a: f64| {
                let n = [a.cos(), a.sin()];
                (n, n[0] * apex[0] + n[1] * apex[1])
            };
            Shape::Corner {
                planes: [pl(a1), pl(a2)],
                invert: rng.next_u64() & 1 == 1,
            }
        }
        Family::SphereDiscs => {
            let k = 1 + (rng.next_u64() % 3) as usize;
            let caps = (0..k)
                .map(|_| {
                    let z = rng.range(0.15, 1.0);
                    let phi = rng.range(0.0, std::f64::consts::TAU);
                    let s = (1.0 - z * z).sqrt();
                    let axis = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32);
                    SphericalCap::new(axis, rng.range(0.15, 0.6) as f32).expect("valid cap")
                })
                .collect();
            Shape::Caps {
                caps,
                size: STUDY_SIZE,
            }
        }
    }
}

/// Up to `per_map` boundary-crossing query squares on the [`STUDY_SIZE`]² map of `shape`
/// (half-diagonal log-uniform in `[1, 8]` texels, inside the grid, the binary map's
/// coverage strictly between 0 and 1), each with its estimates and references.
fn map_queries(shape: &Shape, rng: &mut Rng, per_map: usize, out: &mut Vec<QueryResult>) {
    let n = STUDY_SIZE;
    let (_, mask) = shape.rasterize(n, n);
    let vdt = Vdt::build(n, n, &mask).expect("valid map");
    let view = vdt.view();
    let texels: Vec<f32> = mask.iter().map(|&b| b as u8 as f32).collect();
    let sat = Sat::build(n, n, &texels).expect("valid map");
    let sums = MaskSums::new(n, n, &mask);
    let mut got = 0;
    let mut tries = 0;
    while got < per_map && tries < per_map * 200 {
        tries += 1;
        let r = rng.log_range(1.0, 8.0);
        let hs = r / std::f64::consts::SQRT_2;
        let (u, v) = (rng.range(hs, n as f64 - hs), rng.range(hs, n as f64 - hs));
        let (uf, vf, rf) = (u as f32, v as f32, r as f32);
        // The box of the f32 query, as the kernels see it.
        let hsf = steradian_core::rsl::sat::square_half_side(rf) as f64;
        let (x0, y0, x1, y1) = (
            uf as f64 - hsf,
            vf as f64 - hsf,
            uf as f64 + hsf,
            vf as f64 + hsf,
        );
        let a = (x1 - x0) * (y1 - y0);
        let mask_frac = sums.area(x0, y0, x1, y1) / a;
        if !(mask_frac > 0.0 && mask_frac < 1.0) {
            continue;
        }
        let truth = shape.visible_area(x0, y0, x1, y1) / a;
        let (eq9, gradient) = view.query(uf, vf, rf);
        let sat_frac = (sat.square(Vec2::new(uf, vf), rf) as f64 / a) as f32;
        out.push(QueryResult {
            q: [uf, vf, rf],
            eq9,
            gradient,
            sat: sat_frac,
            mask: mask_frac,
            truth,
        });
        got += 1;
    }
}

/// Mean errors on oblique straight edges (`|sin 2θ| ≥ ½`, half-diagonals log-uniform in
/// `[4, 12]` texels, squares the edge crosses): `(gradient variant, eq. 9 on the exact
/// distance)`, both against the exact coverage of the square (the edge's half-plane), over
/// `maps` edges with `per_map` queries each. Eq. 9 is fed the exact signed distance from the
/// square's centre to the edge line, so the comparison isolates what the straight-edge
/// variant adds over the best any `D`-only ramp can do.
pub fn oblique_edges(seed: u64, maps: usize, per_map: usize) -> (f64, f64) {
    let n = STUDY_SIZE;
    let mut rng = Rng::new(seed);
    let (mut eg, mut e9, mut count) = (0.0, 0.0, 0usize);
    let mut made = 0;
    while made < maps {
        let th = rng.range(0.0, std::f64::consts::PI);
        if (2.0 * th).sin().abs() < 0.5 {
            continue;
        }
        made += 1;
        let nrm = [th.cos(), th.sin()];
        let p = [
            rng.range(0.35, 0.65) * n as f64,
            rng.range(0.35, 0.65) * n as f64,
        ];
        let shape = Shape::Edge {
            n: nrm,
            c: nrm[0] * p[0] + nrm[1] * p[1],
        };
        let (_, mask) = shape.rasterize(n, n);
        let vdt = Vdt::build(n, n, &mask).expect("valid map");
        let mut got = 0;
        let mut tries = 0;
        while got < per_map && tries < per_map * 200 {
            tries += 1;
            let r = rng.log_range(4.0, 12.0);
            let hs = r / std::f64::consts::SQRT_2;
            let (u, v) = (rng.range(hs, n as f64 - hs), rng.range(hs, n as f64 - hs));
            let (uf, vf, rf) = (u as f32, v as f32, r as f32);
            let hsf = steradian_core::rsl::sat::square_half_side(rf) as f64;
            let (uc, vc) = (uf as f64, vf as f64);
            let a = 4.0 * hsf * hsf;
            let truth = shape.visible_area(uc - hsf, vc - hsf, uc + hsf, vc + hsf) / a;
            if !(truth > 1e-9 && truth < 1.0 - 1e-9) {
                continue;
            }
            let Shape::Edge { n: nn, c } = shape else {
                unreachable!("an edge")
            };
            let d_exact = nn[0] * uc + nn[1] * vc - c;
            let e9_exact = steradian_core::rsl::vdt::eq9_from(d_exact as f32, rf) as f64;
            let (_, g) = vdt.query(uf, vf, rf);
            eg += (g as f64 - truth).abs();
            e9 += (e9_exact - truth).abs();
            count += 1;
            got += 1;
        }
    }
    let k = count.max(1) as f64;
    (eg / k, e9 / k)
}

/// Runs one family: `maps` random shapes, `per_map` boundary-crossing query squares each
/// (half-diagonal log-uniform in `[1, 8]` texels, inside the grid, the binary map's
/// coverage strictly between 0 and 1). Returns every query's estimates and references.
pub fn study(family: Family, seed: u64, maps: usize, per_map: usize) -> Vec<QueryResult> {
    let mut rng = Rng::new(seed ^ (family as u64 + 1).wrapping_mul(0x9e37_79b9));
    let mut out = Vec::with_capacity(maps * per_map);
    for _ in 0..maps {
        let shape = random_shape(family, &mut rng);
        map_queries(&shape, &mut rng, per_map, &mut out);
    }
    out
}

/// Mean, 99th percentile and maximum of absolute errors.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct Dist {
    /// Mean absolute error.
    pub mean: f64,
    /// 99th percentile.
    pub p99: f64,
    /// Maximum.
    pub max: f64,
}

impl Dist {
    /// The distribution of `|e|` over `errs`.
    pub fn of(errs: impl IntoIterator<Item = f64>) -> Dist {
        let mut v: Vec<f64> = errs.into_iter().map(f64::abs).collect();
        if v.is_empty() {
            return Dist::default();
        }
        v.sort_by(f64::total_cmp);
        let k = ((v.len() as f64 * 0.99).ceil() as usize).clamp(1, v.len()) - 1;
        Dist {
            mean: v.iter().sum::<f64>() / v.len() as f64,
            p99: v[k],
            max: v[v.len() - 1],
        }
    }
}

/// Error distributions of one family: each estimate against the true shape, and eq. 9 and
/// the gradient variant against the binary map (where the SAT is exact).
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct FamilyErrors {
    /// Queries.
    pub n: usize,
    /// Eq. 9 vs the true shape.
    pub eq9: Dist,
    /// Gradient variant vs the true shape.
    pub gradient: Dist,
    /// SAT of the binary map vs the true shape.
    pub sat: Dist,
    /// Eq. 9 vs the binary map.
    pub eq9_mask: Dist,
    /// Gradient variant vs the binary map.
    pub gradient_mask: Dist,
    /// SAT vs the binary map (its own rounding only).
    pub sat_mask: Dist,
}

/// Summarises a study.
pub fn errors(rs: &[QueryResult]) -> FamilyErrors {
    FamilyErrors {
        n: rs.len(),
        eq9: Dist::of(rs.iter().map(|r| r.eq9 as f64 - r.truth)),
        gradient: Dist::of(rs.iter().map(|r| r.gradient as f64 - r.truth)),
        sat: Dist::of(rs.iter().map(|r| r.sat as f64 - r.truth)),
        eq9_mask: Dist::of(rs.iter().map(|r| r.eq9 as f64 - r.mask)),
        gradient_mask: Dist::of(rs.iter().map(|r| r.gradient as f64 - r.mask)),
        sat_mask: Dist::of(rs.iter().map(|r| r.sat as f64 - r.mask)),
    }
}

/// Mean absolute error against the true shape per edge orientation, for the straight-edge
/// family: `bins` bins of the edge normal's angle folded into `[0°, 90°)`;
/// `(bin centre in degrees, [eq9, gradient, sat])`.
pub fn edge_error_by_angle(
    seed: u64,
    maps: usize,
    per_map: usize,
    bins: usize,
) -> Vec<(f64, [f64; 3])> {
    let mut rng = Rng::new(seed);
    let mut acc = vec![([0.0f64; 3], 0usize); bins];
    let mut rs = Vec::with_capacity(per_map);
    for _ in 0..maps {
        let shape = random_shape(Family::Edges, &mut rng);
        let Shape::Edge { n: nrm, .. } = shape else {
            unreachable!()
        };
        let ang = nrm[1].atan2(nrm[0]).to_degrees().rem_euclid(90.0);
        let bin = ((ang / 90.0 * bins as f64) as usize).min(bins - 1);
        rs.clear();
        map_queries(&shape, &mut rng, per_map, &mut rs);
        let e = &mut acc[bin];
        for q in &rs {
            for (s, x) in e.0.iter_mut().zip([q.eq9, q.gradient, q.sat]) {
                *s += (x as f64 - q.truth).abs();
            }
        }
        e.1 += rs.len();
    }
    acc.iter()
        .enumerate()
        .filter(|(_, (_, c))| *c > 0)
        .map(|(k, (s, c))| {
            let m = *c as f64;
            (
                (k as f64 + 0.5) * 90.0 / bins as f64,
                [s[0] / m, s[1] / m, s[2] / m],
            )
        })
        .collect()
}

/// Exact area of a cap of half-angle `alpha` whose axis makes the angle `gamma` with the
/// normal, clipped to the upper hemisphere (`f64`): the intersection of two caps
/// (half-angles `alpha` and `π/2`), in steradians.
pub fn cap_area_in_hemisphere(alpha: f64, gamma: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI, TAU};
    let full = TAU * (1.0 - alpha.cos());
    if gamma + alpha <= FRAC_PI_2 {
        return full; // wholly above the horizon
    }
    if gamma - alpha >= FRAC_PI_2 {
        return 0.0; // wholly below
    }
    if alpha - gamma >= FRAC_PI_2 {
        return TAU; // contains the whole hemisphere
    }
    // Two circles that cross: A = 2[π − acos(cos γ/ sin α) − cos α·acos(−cot γ·cot α)].
    let (ca, sa, cg, sg) = (alpha.cos(), alpha.sin(), gamma.cos(), gamma.sin());
    let t1 = (cg / sa).clamp(-1.0, 1.0).acos();
    let t2 = (-(cg * ca) / (sg * sa)).clamp(-1.0, 1.0).acos();
    2.0 * (PI - t1 - ca * t2)
}

/// The visible solid angle of the upper hemisphere with the caps removed, by integration
/// over the polar angle of the exact union of the arcs each cap cuts from each circle of
/// latitude (`f64`, `steps` midpoint steps in `cos θ`).
pub fn visible_solid_angle_polar(caps: &[SphericalCap], steps: usize) -> f64 {
    use std::f64::consts::TAU;
    let mut total = 0.0;
    for s in 0..steps {
        // Midpoint in z = cos θ (dω = dz dφ).
        let z = (s as f64 + 0.5) / steps as f64;
        let st = (1.0 - z * z).sqrt();
        let mut arcs: Vec<(f64, f64)> = Vec::new();
        let mut full = false;
        for c in caps {
            let a = c.axis();
            let (ax, ay, az) = (a.x as f64, a.y as f64, a.z as f64);
            let at = (ax * ax + ay * ay).sqrt();
            let cos_alpha = 1.0 - c.one_minus_cos() as f64;
            // a·d = st·at·cos(φ − φa) + z·az ≥ cos α.
            if at * st == 0.0 {
                if z * az >= cos_alpha {
                    full = true;
                }
                continue;
            }
            let cb = (cos_alpha - z * az) / (st * at);
            if cb <= -1.0 {
                full = true;
            } else if cb < 1.0 {
                let b = cb.acos();
                let phi = ay.atan2(ax);
                arcs.push((phi - b, phi + b));
            }
        }
        let blocked = if full {
            TAU
        } else {
            // Union length of arcs on the circle: unroll each to [0, 2π) pieces.
            let mut iv: Vec<(f64, f64)> = Vec::new();
            for (lo, hi) in arcs {
                let lo2 = lo.rem_euclid(TAU);
                let hi2 = lo2 + (hi - lo);
                if hi2 > TAU {
                    iv.push((lo2, TAU));
                    iv.push((0.0, hi2 - TAU));
                } else {
                    iv.push((lo2, hi2));
                }
            }
            iv.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut len = 0.0;
            let mut cur: Option<(f64, f64)> = None;
            for (lo, hi) in iv {
                match cur {
                    Some((a, b)) if lo <= b => cur = Some((a, b.max(hi))),
                    Some((a, b)) => {
                        len += b - a;
                        cur = Some((lo, hi));
                    }
                    None => cur = Some((lo, hi)),
                }
            }
            if let Some((a, b)) = cur {
                len += b - a;
            }
            len
        };
        total += (TAU - blocked) / steps as f64;
    }
    total
}

/// `steradian eval vdt-box`: `{"mask": ["0110…", …], "queries": [[u, v, r], …]}` (rows of
/// `'0'`/`'1'`, row `j` along `v`, `'1'` visible; centre and half-diagonal in texel units)
/// → `{"values": [eq. 9 per query], "values_gradient": [straight-edge variant per query]}`.
pub fn eval_vdt_box(obj: &Map<String, Value>) -> Result<Value, String> {
    let rows = obj
        .get("mask")
        .ok_or("missing field \"mask\"")?
        .as_array()
        .ok_or("field \"mask\" must be an array of strings")?;
    if rows.is_empty() {
        return Err("field \"mask\" must have at least one row".into());
    }
    let mut w = 0usize;
    let mut mask = Vec::new();
    for (j, r) in rows.iter().enumerate() {
        let s = r
            .as_str()
            .ok_or_else(|| format!("mask row {j} must be a string of '0' and '1'"))?;
        if j == 0 {
            w = s.chars().count();
            if w == 0 {
                return Err("mask rows must not be empty".into());
            }
        } else if s.chars().count() != w {
            return Err(format!(
                "mask row {j} has {} characters, row 0 has {w} (ragged mask)",
                s.chars().count()
            ));
        }
        for (i, ch) in s.chars().enumerate() {
            match ch {
                '0' => mask.push(false),
                '1' => mask.push(true),
                other => {
                    return Err(format!(
                        "mask row {j}, column {i}: {other:?} is not '0' or '1'"
                    ));
                }
            }
        }
    }
    let h = rows.len();
    let vdt = Vdt::build(w, h, &mask).map_err(|e| e.to_string())?;
    let qs = obj
        .get("queries")
        .ok_or("missing field \"queries\"")?
        .as_array()
        .ok_or("field \"queries\" must be an array of [u, v, r]")?;
    let mut values = Vec::with_capacity(qs.len());
    let mut values_gradient = Vec::with_capacity(qs.len());
    for (k, q) in qs.iter().enumerate() {
        let a = q
            .as_array()
            .filter(|a| a.len() == 3)
            .ok_or_else(|| format!("query {k} must be [u, v, r]"))?;
        let mut x = [0f32; 3];
        for (o, val) in x.iter_mut().zip(a) {
            *o = parse_f32(
                val,
                || format!("query {k}: components must be numbers"),
                |f| format!("query {k}: {f} is not a finite f32"),
            )?;
        }
        if x[2] < 0.0 {
            return Err(format!("query {k}: half-diagonal r = {} must be ≥ 0", x[2]));
        }
        let (e9, g) = vdt.query(x[0], x[1], x[2]);
        values.push(num(e9));
        values_gradient.push(num(g));
    }
    Ok(json!({ "values": values, "values_gradient": values_gradient }))
}
