//! Sphere-set visibility as a quadtree mask and weighted leaf lobes (cosine-lobe paper,
//! section 5.3, Figures 9–10, eq. 39–41).
//!
//! One lobe per occluder (`V = 1 − Σ c_k`) subtracts the overlap of two occluders twice.
//! The paper instead splats the occluders into a quadtree over a square that surrounds the
//! light's cone and turns each *shadow leaf* into one lobe, weighted by `w(dist, depth)`:
//! `V = 1 − Σ_i w(dist, d_i)·c_i`.
//!
//! **The square.** Seen from the shading point (the origin), the light's cap has axis `h`
//! and half-angle `α`. The paper's unit square `S_unit` is placed across `h` at the
//! distance `dist` where it circumscribes the cone's cross-section: half-side `½ =
//! dist·tan α`, so `dist = 1/(2 tan α)` (a scale-free stand-in for `α`; the square lies
//! behind the light when `dist` exceeds the light's distance, as the paper notes). Here it
//! is used at unit distance: gnomonic coordinates `(p, q) ∈ [−tan α, tan α]²`, direction
//! `normalize(h + p·t + q·b)`.
//!
//! **The quadtree** (Figure 9). A cell is *covered* when one occluder cap holds its four
//! corner directions (the cap's central projection is convex, so it holds the whole
//! cell): it becomes a shadow leaf and is not subdivided. A cell that no occluder can
//! touch (`angle(a_j, centre) > β_j + γ`, `γ` the cell's angular radius) or that lies
//! wholly outside the light's cap is not considered. Any other cell is subdivided, down to
//! `max_depth`, where a partially covered cell is dropped ([`Leaves::Aggressive`]), kept
//! ([`Leaves::Conservative`]) — the paper's two choices —, kept when its centre is
//! covered ([`Leaves::Centre`], the midpoint rule), or kept scaled by the covered share of
//! the directions of a 4 × 4 grid over it that lie in the light's cap
//! ([`Leaves::Fraction`], this crate's default: the midpoint rule two levels finer,
//! without the leaves two more levels would emit; the leaf's lobe product with the light
//! stands for the light it covers, of which `f` is the occluded share).
//!
//! **Leaf lobes.** A leaf of half-side `s` centred at `c` (on the unit-distance plane) is
//! bounded by the sphere of centre `c` and radius `√2·s`; its lobe is that sphere's cap
//! as a lobe, like a light's (eq. 31–32), with scale `−w·f`, `f` its covered fraction (1
//! but for [`Leaves::Fraction`]'s partial leaves).
//!
//! **Weights.** The paper tuned `w` by hand per `dist` and depth (a first-level weight for
//! a dark umbra, then each level against the previous). Here they are fitted once in the
//! harness (`generate::mask_weights`) by least squares against exact visibility — the
//! unoccluded fraction of the light's cap — over random occluder configurations, one set
//! per deepest level (a mask cut at depth 2 has partial leaves at depth 2 that a deeper
//! one subdivides), and committed as the table [`WEIGHT_TABLE_BYTES`]
//! (`steradian tables --check`), read with linear interpolation in `ln dist`
//! ([`weight`]).

use crate::Vec3;
use crate::lobe::cap::SphericalCap;
use crate::math;
use crate::table::{Header, decode_const};

/// Deepest level a mask subdivides to (the paper: "practically limited to 4 or 5").
pub const MAX_DEPTH: u32 = 5;
/// Depth levels in the weight table (`0..=MAX_DEPTH`).
pub const WEIGHT_DEPTHS: usize = MAX_DEPTH as usize + 1;
/// `dist` samples of the weight table, uniform in `ln dist` over [`WEIGHT_DIST_RANGE`].
pub const WEIGHT_DISTS: usize = 12;
/// The range of `dist` in the weight table (`α` from 82.9° to 0.9°); clamped outside.
pub const WEIGHT_DIST_RANGE: (f32, f32) = (0.0625, 32.0);
/// Number of weights: value `i + WEIGHT_DISTS·(depth + WEIGHT_DEPTHS·(max_depth − 1))` is
/// the weight of a leaf at `depth` of a mask cut at `max_depth` (1 ..= [`MAX_DEPTH`]) at
/// the `i`-th `dist`.
pub const WEIGHT_LEN: usize = WEIGHT_DISTS * WEIGHT_DEPTHS * MAX_DEPTH as usize;
/// The covered fraction of a [`Leaves::Fraction`] leaf is taken over `FRACTION_GRID²`
/// directions.
pub const FRACTION_GRID: usize = 4;
/// Name of the weight table.
pub const WEIGHT_TABLE_NAME: &str = "mask-weights";
/// The committed weight table.
pub static WEIGHT_TABLE_BYTES: &[u8] = include_bytes!("tables/mask_weights.bin");
const DECODED: (Header, [f32; WEIGHT_LEN]) =
    decode_const(include_bytes!("tables/mask_weights.bin"), WEIGHT_TABLE_NAME);
/// The decoded weight table.
pub static WEIGHTS: [f32; WEIGHT_LEN] = DECODED.1;

/// What a partially covered cell at the deepest level becomes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Leaves {
    /// Dropped (lit): the paper's aggressive variant.
    Aggressive,
    /// Kept (shadow): the paper's conservative variant.
    Conservative,
    /// Kept when its centre direction is covered: the midpoint rule.
    Centre,
    /// Kept, its lobe scaled by the share of those of [`FRACTION_GRID`]² directions over it
    /// (the centres of its sub-cells) within the light's cap that an occluder covers;
    /// dropped where none is.
    #[default]
    Fraction,
}

/// `dist = 1/(2 tan α)` of a light cap of half-angle `α` (see the module docs).
pub fn dist_of(half_angle: f32) -> f32 {
    math::cosf(half_angle) / (2.0 * math::sinf(half_angle))
}

/// The fitted weight of a leaf at `depth` of a mask cut at `max_depth`, at `dist`,
/// interpolated linearly in `ln dist` (clamped to the table's range; `max_depth` is clamped
/// to `1 ..= MAX_DEPTH` and `depth` to `max_depth`).
pub fn weight(table: &[f32], dist: f32, depth: u32, max_depth: u32) -> f32 {
    let (lo, hi) = WEIGHT_DIST_RANGE;
    let u = (math::logf(dist.clamp(lo, hi)) - math::logf(lo)) / (math::logf(hi) - math::logf(lo));
    let x = u * (WEIGHT_DISTS - 1) as f32;
    let i = (math::floorf(x) as usize).min(WEIGHT_DISTS - 2);
    let f = x - i as f32;
    let max_depth = max_depth.clamp(1, MAX_DEPTH);
    let row =
        WEIGHT_DISTS * (depth.min(max_depth) as usize + WEIGHT_DEPTHS * (max_depth as usize - 1));
    let (a, b) = (table[row + i], table[row + i + 1]);
    a + f * (b - a)
}

/// Occluder caps as the mask tests them.
#[derive(Clone, Copy, Debug)]
struct Occ {
    axis: Vec3,
    cos_b: f32,
    sin_b: f32,
}

impl Occ {
    /// Whether the unit direction `d` lies in the cap.
    fn holds(&self, d: Vec3) -> bool {
        d.dot(self.axis) >= self.cos_b
    }
}

/// The square's frame and extent for one light.
#[derive(Clone, Copy, Debug)]
struct Square {
    h: Vec3,
    t: Vec3,
    b: Vec3,
    cos_a: f32,
    sin_a: f32,
}

impl Square {
    fn dir(&self, p: f32, q: f32) -> Vec3 {
        (self.h + self.t * p + self.b * q).normalize()
    }
}

/// Calls `leaf(cap, depth, fraction)` for every shadow leaf of the mask of `occluders` over
/// `light` (see the module docs; `fraction` is 1 but for [`Leaves::Fraction`]'s partial
/// leaves); returns the number of leaves. Occluder caps are given as seen
/// from the shading point (the same origin as `light`); any subset may miss the light.
pub fn shadow_leaves(
    light: &SphericalCap,
    occluders: &[SphericalCap],
    max_depth: u32,
    leaves: Leaves,
    mut leaf: impl FnMut(SphericalCap, u32, f32),
) -> usize {
    let max_depth = max_depth.min(MAX_DEPTH);
    let h = light.axis();
    let sign = if h.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + h.z);
    let bb = h.x * h.y * a;
    let sq = Square {
        h,
        t: Vec3::new(1.0 + sign * h.x * h.x * a, sign * bb, -sign * h.x),
        b: Vec3::new(bb, sign + h.y * h.y * a, -h.y),
        cos_a: math::cosf(light.half_angle()),
        sin_a: math::sinf(light.half_angle()),
    };
    // Beyond 80° the square's corners are near the horizon of the point: clamp.
    let tan_a = (sq.sin_a / sq.cos_a.max(0.17)).min(5.7);
    let mut occ = [Occ {
        axis: Vec3::Z,
        cos_b: 1.0,
        sin_b: 0.0,
    }; 64];
    let mut n = 0;
    for o in occluders {
        if n == occ.len() {
            break;
        }
        occ[n] = Occ {
            axis: o.axis(),
            cos_b: math::cosf(o.half_angle()),
            sin_b: math::sinf(o.half_angle()),
        };
        n += 1;
    }
    let mut count = 0;
    visit(
        &sq,
        &occ[..n],
        (0.0, 0.0, tan_a),
        0,
        max_depth,
        leaves,
        &mut |c, d, f| {
            count += 1;
            leaf(c, d, f)
        },
    );
    count
}

/// `θ > α + γ` for `θ = ∠(u, v)` (unit vectors), given `cos α`, `sin α`, `cos γ`, `sin γ` of
/// two angles in `[0, π]`: where `α + γ < π` (`cos γ > −cos α`) it is
/// `u·v < cos(α + γ) = cos α·cos γ − sin α·sin γ` (cosine falls on `[0, π]`), and false
/// otherwise (no angle exceeds `π`). Trigonometry-free, where the cell tests of [`visit`]
/// took one `acos` per comparison.
#[inline]
fn beyond(uv: f32, (cos_a, sin_a): (f32, f32), (cos_g, sin_g): (f32, f32)) -> bool {
    cos_g > -cos_a && uv.clamp(-1.0, 1.0) < cos_a * cos_g - sin_a * sin_g
}

fn visit(
    sq: &Square,
    occ: &[Occ],
    (p, q, s): (f32, f32, f32),
    depth: u32,
    max_depth: u32,
    leaves: Leaves,
    leaf: &mut impl FnMut(SphericalCap, u32, f32),
) {
    let centre = sq.dir(p, q);
    let corners = [
        sq.dir(p - s, q - s),
        sq.dir(p + s, q - s),
        sq.dir(p - s, q + s),
        sq.dir(p + s, q + s),
    ];
    // γ, the cell's angular radius about its centre: the largest corner angle, i.e. the
    // smallest cosine.
    let cos_g = corners
        .iter()
        .map(|c| c.dot(centre).clamp(-1.0, 1.0))
        .fold(1.0f32, f32::min);
    let g = (cos_g, math::sqrtf((1.0 - cos_g * cos_g).max(0.0)));
    // Wholly outside the light's cap (∠(centre, h) > α + γ): not considered.
    if beyond(centre.dot(sq.h), (sq.cos_a, sq.sin_a), g) {
        return;
    }
    let mut touched = false;
    for o in occ {
        if corners.iter().all(|&c| o.holds(c)) {
            emit(sq, (p, q, s), depth, 1.0, leaf);
            return;
        }
        // Within reach of the occluder's cap: ∠(axis, centre) ≤ β + γ.
        if !beyond(o.axis.dot(centre), (o.cos_b, o.sin_b), g) {
            touched = true;
        }
    }
    if !touched {
        return;
    }
    if depth >= max_depth {
        let fraction = match leaves {
            Leaves::Aggressive => 0.0,
            Leaves::Conservative => 1.0,
            Leaves::Centre => {
                if occ.iter().any(|o| o.holds(centre)) {
                    1.0
                } else {
                    0.0
                }
            }
            Leaves::Fraction => {
                const N: usize = FRACTION_GRID;
                let (mut lit, mut hit) = (0, 0);
                for a in 0..N {
                    for b in 0..N {
                        let u = p + s * ((2 * a + 1) as f32 / N as f32 - 1.0);
                        let v = q + s * ((2 * b + 1) as f32 / N as f32 - 1.0);
                        let d = sq.dir(u, v);
                        if d.dot(sq.h) < sq.cos_a {
                            continue;
                        }
                        lit += 1;
                        if occ.iter().any(|o| o.holds(d)) {
                            hit += 1;
                        }
                    }
                }
                if lit == 0 {
                    0.0
                } else {
                    hit as f32 / lit as f32
                }
            }
        };
        if fraction > 0.0 {
            emit(sq, (p, q, s), depth, fraction, leaf);
        }
        return;
    }
    let h = s / 2.0;
    for (dp, dq) in [(-h, -h), (h, -h), (-h, h), (h, h)] {
        visit(
            sq,
            occ,
            (p + dp, q + dq, h),
            depth + 1,
            max_depth,
            leaves,
            leaf,
        );
    }
}

/// The leaf's bounding sphere (centre on the unit-distance plane, radius `√2·s`) as a cap;
/// a sphere that would hold the origin is shrunk to the largest that does not.
fn emit(
    sq: &Square,
    (p, q, s): (f32, f32, f32),
    depth: u32,
    fraction: f32,
    leaf: &mut impl FnMut(SphericalCap, u32, f32),
) {
    let c = sq.h + sq.t * p + sq.b * q;
    let d = c.length();
    let r = (core::f32::consts::SQRT_2 * s).min(0.999 * d);
    if let Ok(cap) = SphericalCap::from_sphere(Vec3::ZERO, c, r) {
        leaf(cap, depth, fraction);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `beyond` is the angle comparison `θ > α + γ` it replaces, on a grid of angles
    /// covering `[0, π]` each (sums past `π` included), wherever the two sides are more
    /// than `1e-5` rad apart (within that the `f32` roundings of either form decide).
    #[test]
    fn beyond_is_the_angle_comparison() {
        let steps = 60;
        let at = |i: usize| crate::PI * i as f32 / steps as f32;
        let mut decided = 0;
        for i in 0..=steps {
            for j in 0..=steps {
                for k in 0..=steps {
                    let (t, a, g) = (at(i), at(j), at(k));
                    if (f64::from(t) - f64::from(a) - f64::from(g)).abs() < 1e-5 {
                        continue;
                    }
                    let sc = |x: f32| (math::cosf(x), math::sinf(x));
                    assert_eq!(
                        beyond(math::cosf(t), sc(a), sc(g)),
                        t > a + g,
                        "θ {t} α {a} γ {g}"
                    );
                    decided += 1;
                }
            }
        }
        assert!(decided > 200_000, "{decided}");
    }

    #[test]
    fn dist_is_the_circumscribing_distance() {
        // Half-side ½ at distance dist subtends tan α = ½/dist.
        for a in [0.01f32, 0.3, 1.0] {
            let d = dist_of(a);
            assert!((0.5 / d - math::sinf(a) / math::cosf(a)).abs() < 1e-5 * (1.0 + 0.5 / d));
        }
    }

    /// Linear interpolation in `ln dist` is exact at the table's nodes, and clamps beyond
    /// its range; each deepest level reads its own rows, a depth beyond it its last.
    #[test]
    fn weight_reproduces_the_nodes_and_clamps() {
        let (lo, hi) = WEIGHT_DIST_RANGE;
        let table: [f32; WEIGHT_LEN] = core::array::from_fn(|k| k as f32);
        for m in 1..=MAX_DEPTH {
            let base = WEIGHT_DISTS * WEIGHT_DEPTHS * (m as usize - 1);
            for d in 0..=m as usize {
                for i in 0..WEIGHT_DISTS {
                    let u = i as f32 / (WEIGHT_DISTS - 1) as f32;
                    let dist = math::expf(math::logf(lo) + u * (math::logf(hi) - math::logf(lo)));
                    let want = (base + i + WEIGHT_DISTS * d) as f32;
                    let got = weight(&table, dist, d as u32, m);
                    assert!(
                        (got - want).abs() < 1e-3,
                        "node {i}, depth {d} of {m}: {got} vs {want}"
                    );
                }
                let row = (base + WEIGHT_DISTS * d) as f32;
                assert_eq!(weight(&table, lo / 10.0, d as u32, m), row);
                assert_eq!(
                    weight(&table, hi * 10.0, d as u32, m),
                    row + (WEIGHT_DISTS - 1) as f32
                );
            }
            assert_eq!(weight(&table, lo, m + 1, m), weight(&table, lo, m, m));
        }
        // A deepest level beyond the table reads the last one's rows, 0 the first's.
        assert_eq!(
            weight(&table, lo, 2, MAX_DEPTH + 3),
            weight(&table, lo, 2, MAX_DEPTH)
        );
        assert_eq!(weight(&table, lo, 0, 0), weight(&table, lo, 0, 1));
    }

    #[test]
    fn no_occluder_no_leaf_and_a_covering_occluder_one_leaf() {
        let light = SphericalCap::new(Vec3::Z, 0.1).unwrap();
        assert_eq!(
            shadow_leaves(&light, &[], 5, Leaves::Centre, |_, _, _| {}),
            0
        );
        let big = SphericalCap::new(Vec3::Z, 0.5).unwrap();
        let mut depths = [0u32; 8];
        let n = shadow_leaves(&light, &[big], 5, Leaves::Centre, |_, d, _| {
            depths[d as usize] += 1
        });
        assert_eq!((n, depths[0]), (1, 1));
        // An occluder beside the light touches no cell.
        let away = SphericalCap::new(Vec3::X, 0.2).unwrap();
        assert_eq!(
            shadow_leaves(&light, &[away], 5, Leaves::Centre, |_, _, _| {}),
            0
        );
    }

    /// Half the light covered by a large occluder whose rim runs through the light's
    /// axis: the leaves' solid angle (their bounding caps overlap, so it exceeds the
    /// area) is about half the square's, and aggressive ≤ centre ≤ conservative.
    #[test]
    fn a_half_covered_light() {
        let light = SphericalCap::new(Vec3::Z, 0.05).unwrap();
        let occ =
            SphericalCap::new(Vec3::new(1.0, 0.0, 0.0), core::f32::consts::FRAC_PI_2).unwrap();
        let count = |l| shadow_leaves(&light, &[occ], 5, l, |_, _, _| {});
        let (a, c, k) = (
            count(Leaves::Aggressive),
            count(Leaves::Centre),
            count(Leaves::Conservative),
        );
        assert!(a <= c && c <= k && a > 0, "{a} {c} {k}");
    }

    /// A light of half-angle `α = 0.1` about `+z`, and a hemisphere about `(1, 0, −k·tan α)`
    /// whose rim crosses the light's square along the line `p = k·tan α` (on the tangent
    /// plane `z = 1` it covers `x ≥ k·tan α`).
    fn rim_across_the_square(k: f32) -> (SphericalCap, SphericalCap) {
        let alpha = 0.1f32;
        let light = SphericalCap::new(Vec3::Z, alpha).unwrap();
        let x0 = k * math::sinf(alpha) / math::cosf(alpha);
        let occ = SphericalCap::new(
            Vec3::new(1.0, 0.0, -x0).normalize(),
            core::f32::consts::FRAC_PI_2,
        )
        .unwrap();
        (light, occ)
    }

    /// A hemisphere whose rim crosses the square along the line `p = 0.3·tan α` (about
    /// `+z` the square's axes are `x` and `y`; the light's cap is the disc of radius
    /// `tan α`), at depth 1: the two right cells are partial leaves. Of each one's 4 × 4
    /// grid, 13 directions lie in the light's cap, and 9 of those right of the rim
    /// (`f = 9/13 ≈ 0.69`, against the exact share `0.62` of the quarter disc), where the
    /// midpoint rule keeps them whole and the left cells are dropped.
    #[test]
    fn fraction_leaves_count_the_covered_share() {
        let (light, occ) = rim_across_the_square(0.3);
        let leaves = |l| {
            let mut got = [(0u32, 0.0f32); 8];
            let n = shadow_leaves(&light, &[occ], 1, l, |_, d, f| {
                if let Some(g) = got.iter_mut().find(|g| g.1 == 0.0) {
                    *g = (d, f);
                }
            });
            (n, got)
        };
        let (n, got) = leaves(Leaves::Fraction);
        assert_eq!(
            (n, &got[..3]),
            (2, &[(1, 9.0 / 13.0), (1, 9.0 / 13.0), (0, 0.0)][..])
        );
        let (n, got) = leaves(Leaves::Centre);
        assert_eq!((n, &got[..3]), (2, &[(1, 1.0), (1, 1.0), (0, 0.0)][..]));
        assert_eq!(leaves(Leaves::Aggressive).0, 0);
        assert_eq!(leaves(Leaves::Conservative).0, 2);
    }

    /// Where the grid is exact: at depth 2 the rim `p = tan α/4` runs along a boundary of
    /// the 4 × 4 grids of the cells `0 ≤ p ≤ tan α/2`, and the two of them with
    /// `|q| ≤ tan α/2` lie wholly in the light's cap (their far corner at `0.71·tan α`),
    /// so their `f` is their exact covered share, ½; the two beyond them count 7 of their
    /// 15 lit directions, and the cells right of them are covered whole (`f = 1`).
    #[test]
    fn fraction_leaves_are_exact_where_the_rim_follows_the_grid() {
        let (light, occ) = rim_across_the_square(0.25);
        let (mut half, mut sevenths, mut whole, mut other) = (0, 0, 0, 0);
        shadow_leaves(&light, &[occ], 2, Leaves::Fraction, |_, d, f| {
            assert_eq!(d, 2);
            if f == 0.5 {
                half += 1;
            } else if f == 7.0 / 15.0 {
                sevenths += 1;
            } else if f == 1.0 {
                whole += 1;
            } else {
                other += 1;
            }
        });
        assert_eq!((half, sevenths, other), (2, 2, 0));
        assert!(whole >= 4, "{whole}");
    }
}
