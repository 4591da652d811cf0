//! Visibility maps from sphere occluders (rotatable-square-lights paper, sections 4.3 and 5):
//! the directions of the upper hemisphere of a shading point that are blocked by a set of
//! spheres, rasterised onto an `n × n` grid over the parametrisation square of the
//! equal-area map ([`crate::rsl::hemisphere`]) with **coverage**: texel `(i, j)` holds the
//! fraction of its area that is visible.
//!
//! A sphere seen from the point is a [`SphericalCap`] of directions (`sin α = radius /
//! distance`, [`local_cap`] puts it in the point's local frame); the occluded set is the
//! union of the caps, and a direction is visible when no cap contains it. In the
//! parametrisation square a cap becomes an oval (the equal-area map does not keep circles),
//! bounded by the zero set of the smooth function
//!
//! ```text
//! f(p) = (1 − cos α) − ½·|a − unmap(p)|²        (> 0 inside the cap)
//! ```
//!
//! whose gradient is at most 2 in magnitude (the equal-area map stretches by at most 2, at
//! the horizon; outside the disk `unmap` clamps radially, which keeps the bound).
//!
//! ## Coverage (correct at texel edges)
//!
//! The map is walked block by block from the whole square: a block of texels that the
//! bound below classifies as wholly visible, occluded or outside the disk is filled after
//! one test, and a mixed block is split in four down to single texels (bit-identical to
//! integrating every texel alone, tested). Each texel is integrated adaptively: a square
//! is classified as wholly inside or outside the disk and each cap by the bound `|f(x) − f(c)| ≤ 2·|x − c|` (`1` for the disk's exact
//! signed distance `1 − |p|`); a square that no boundary crosses contributes its whole area
//! or nothing; a crossed one is split in four, down to [`LEAF_DEPTH`] levels (leaves of
//! `1/32` texel side). At a leaf crossed by one boundary the boundary is replaced by its
//! tangent line (from the value and a central-difference gradient) and the leaf's fraction on
//! the visible side is the exact straight-edge area ([`crate::grid::square_halfplane_fraction`]);
//! a leaf crossed by two or more boundaries (where caps overlap or meet the horizon) is
//! point-sampled 4 × 4. The error per texel is of the order of the boundary's curvature times
//! the cube of the leaf size; the harness tests the total visible solid angle of one sphere
//! against the exact area of the cap clipped to the hemisphere (within `2·10⁻⁵` relative at
//! `n = 64`) and per-texel coverage against dense `f64` sampling.
//!
//! ## Texels outside the unit disk
//!
//! The corners of the square are not directions. [`Outside`] says what they count as, the
//! same for every texel: [`Outside::Visible`] (the default) makes an unoccluded point fully
//! visible in every texel, so every query square of an unshadowed point returns 1 exactly and
//! the horizon adds no boundary to the distance table; [`Outside::Occluded`] counts only real
//! directions, so `Σ coverage · 8/n²` is the visible solid angle ([`visible_solid_angle`]).
//!
//! **Bad input** (never panics): [`coverage_into`] rejects `n = 0`, `n > 2²⁴` and an output
//! of the wrong length; the caps are already validated [`SphericalCap`]s.

use crate::frame::Frame;
use crate::grid::square_halfplane_fraction;
use crate::grid::{check_len, check_side, checked_product};
use crate::lobe::cap::SphericalCap;
use crate::math;
use crate::rsl::hemisphere;
use crate::{Error, Vec2, Vec3};

/// Subdivision levels below a texel (leaves of `2⁻⁵` texel side).
pub const LEAF_DEPTH: u32 = 5;

/// Per depth of [`coverage_into_depth`] (index `0..=LEAF_DEPTH`): the worst coverage
/// error of one boundary texel and the relative error of the visible solid angle, as the
/// harness asserts them against dense `f64` sampling and a polar integral for three caps
/// (radii 0.05–0.5 rad, one crossing the horizon) at `n = 32`. Leaves crossed by two
/// boundaries (here the horizon and a cap) are point-sampled 4 × 4, so depths 0–1 err by
/// up to about a sixteenth there. Bounds for boundaries of that curvature, not for every
/// configuration.
pub const DEPTH_BOUNDS: [(f32, f32); LEAF_DEPTH as usize + 1] = [
    (0.12, 3e-3),
    (0.08, 8e-4),
    (0.02, 2.5e-4),
    (4e-3, 6e-5),
    (1e-3, 1.2e-5),
    (3e-4, 4e-6),
];

/// Largest grid side.
pub const MAX_SIDE: usize = 1 << 24;

/// Bound on `|∇f|` of a cap's function in disk coordinates.
const LIP_CAP: f32 = 2.0;
/// Allowance for the `f32` rounding of `f` in the classification.
const MARGIN: f32 = 2.0e-6;

/// What the texels (or parts of texels) outside the unit disk count as.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Outside {
    /// Visible: an unoccluded point is visible in every texel (module docs).
    #[default]
    Visible,
    /// Occluded: only directions count; coverage sums to the visible solid angle.
    Occluded,
}

impl Outside {
    fn value(self) -> f32 {
        match self {
            Outside::Visible => 1.0,
            Outside::Occluded => 0.0,
        }
    }
}

/// The cap of directions blocked by the sphere `(centre, radius)` seen from `point`, in the
/// local frame `frame` (z = normal). Errors as [`SphericalCap::from_sphere`].
pub fn local_cap(
    point: Vec3,
    frame: &Frame,
    centre: Vec3,
    radius: f32,
) -> Result<SphericalCap, Error> {
    if !point.is_finite() {
        return Err(Error::NonFinite { what: "point" });
    }
    if !centre.is_finite() {
        return Err(Error::NonFinite {
            what: "sphere centre",
        });
    }
    let v = centre - point;
    if !v.is_finite() {
        return Err(Error::NonFinite {
            what: "centre − point",
        });
    }
    SphericalCap::from_sphere(Vec3::ZERO, frame.to_local(v), radius)
}

/// `f(p)` of a cap (module docs): positive inside.
#[inline]
fn cap_fn(cap: &SphericalCap, p: Vec2) -> f32 {
    cap_fn_at(cap, hemisphere::unmap(p))
}

/// `f` of a cap at the direction `w = unmap(p)` (one `unmap` serves every cap).
#[inline]
fn cap_fn_at(cap: &SphericalCap, w: Vec3) -> f32 {
    let d = cap.axis() - w;
    cap.one_minus_cos() - 0.5 * d.dot(d)
}

/// A bound on `|f(x) − f(c)|` for a cap's `f` over the points `x` within `h` of `c` (disk
/// coordinates), `w = unmap(c)`: `f = a·ω − cos α` for unit `ω` (`½|a − ω|² = 1 − a·ω`), and
/// along a segment of length `h` the direction moves by an arc of at most `LIP_CAP·h` (the
/// map's largest stretch), so the angle `θ` to the axis moves by at most that and
/// `|cos θ_x − cos θ_c| ≤ LIP_CAP·h·max |sin θ| ≤ LIP_CAP·h·min(1, sin θ_c + LIP_CAP·h)`
/// (`|sin|` is 1-Lipschitz), with `sin θ_c = |a × ω|`. For a small cap near its boundary this
/// is about `sin α` times the plain `LIP_CAP·h`, so far fewer squares near it are split.
#[inline]
fn cap_bound(cap: &SphericalCap, w: Vec3, h: f32) -> f32 {
    let reach = LIP_CAP * h;
    reach * (cap.axis().cross(w).length() + reach).min(1.0)
}

/// Whether the disk point `p` (any point of the square `[−1, 1]²`) is visible.
#[inline]
pub fn is_visible(caps: &[SphericalCap], p: Vec2, outside: Outside) -> bool {
    if p.dot(p) > 1.0 {
        return outside == Outside::Visible;
    }
    let w = hemisphere::unmap(p);
    caps.iter().all(|c| cap_fn_at(c, w) <= 0.0)
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum St {
    In,
    Out,
    Cross,
}

fn classify(v: f32, bound: f32) -> St {
    if v > bound + MARGIN {
        St::In
    } else if v < -(bound + MARGIN) {
        St::Out
    } else {
        St::Cross
    }
}

/// The visible fraction of the axis-aligned square with centre `c` and half-side `hs` in
/// disk coordinates, integrated adaptively `depth` levels deep (module docs).
pub fn square_coverage(
    caps: &[SphericalCap],
    c: Vec2,
    hs: f32,
    outside: Outside,
    depth: u32,
) -> f32 {
    if !(c.is_finite() && hs.is_finite()) {
        return f32::NAN;
    }
    area(caps, c, hs.abs(), outside, depth)
}

fn area(caps: &[SphericalCap], c: Vec2, hs: f32, outside: Outside, depth: u32) -> f32 {
    let ov = outside.value();
    let h = hs * core::f32::consts::SQRT_2;
    let rc = math::sqrtf(c.dot(c));
    let disk = classify(1.0 - rc, h);
    if disk == St::Out {
        return ov;
    }
    let mut any_in = false;
    let mut crossing = 0usize;
    let mut which = 0usize;
    let w = hemisphere::unmap(c);
    for (k, cap) in caps.iter().enumerate() {
        match classify(cap_fn_at(cap, w), cap_bound(cap, w, h)) {
            St::In => {
                any_in = true;
                break;
            }
            St::Cross => {
                crossing += 1;
                which = k;
            }
            St::Out => {}
        }
    }
    if any_in {
        // Every direction of the square is occluded: only its part outside the disk may be
        // visible.
        if disk == St::In || ov == 0.0 {
            return 0.0;
        }
        crossing = 0;
    } else if crossing == 0 && (disk == St::In || ov == 1.0) {
        return 1.0;
    }
    let disk_cross = disk == St::Cross;
    if depth > 0 {
        let q = 0.5 * hs;
        let mut s = 0.0;
        for (dx, dy) in [(-q, -q), (q, -q), (-q, q), (q, q)] {
            s += area(caps, c + Vec2::new(dx, dy), q, outside, depth - 1);
        }
        return 0.25 * s;
    }
    // A leaf.
    if disk_cross && crossing == 0 {
        // Only the horizon crosses: 1 − |p| is an exact signed distance with gradient −p/|p|.
        let inside = if rc > 0.0 {
            square_halfplane_fraction((1.0 - rc) / hs, -c.x, -c.y)
        } else {
            1.0
        };
        let outside_part = ov * (1.0 - inside);
        return if any_in {
            outside_part
        } else {
            inside + outside_part
        };
    }
    if !disk_cross && crossing == 1 {
        let cap = &caps[which];
        let f0 = cap_fn_at(cap, w);
        let gx = cap_fn(cap, c + Vec2::new(hs, 0.0)) - cap_fn(cap, c - Vec2::new(hs, 0.0));
        let gy = cap_fn(cap, c + Vec2::new(0.0, hs)) - cap_fn(cap, c - Vec2::new(0.0, hs));
        // Gradient of −f (towards the visible side) per unit half-side: −(gx, gy)/2.
        let g = 0.5 * math::sqrtf(gx * gx + gy * gy);
        if g > 0.0 {
            return square_halfplane_fraction(-f0 / g, -gx, -gy);
        }
    }
    // Two or more boundaries (or a flat one): 4 × 4 point samples.
    let mut n = 0u32;
    for a in 0..4 {
        for b in 0..4 {
            let p = c + Vec2::new(hs * (a as f32 * 0.5 - 0.75), hs * (b as f32 * 0.5 - 0.75));
            n += is_visible(caps, p, outside) as u32;
        }
    }
    n as f32 / 16.0
}

/// The coverage map of the caps on an `n × n` grid over the parametrisation square
/// (`out[j·n + i]`, texel `(i, j)` covering `[i, i+1]/n × [j, j+1]/n` in `uv`, i.e.
/// disk coordinates `2·uv − 1`): the visible fraction of each texel (module docs). No
/// allocation.
pub fn coverage_into(
    caps: &[SphericalCap],
    n: usize,
    outside: Outside,
    out: &mut [f32],
) -> Result<(), Error> {
    coverage_into_depth(caps, n, outside, LEAF_DEPTH, out)
}

/// [`coverage_into`] with `depth` subdivision levels below a texel instead of
/// [`LEAF_DEPTH`] (at most [`LEAF_DEPTH`]; leaves of `2^−depth` texel side). A boundary
/// crossing a leaf is still its tangent line, so each leaf errs by its curvature times the
/// cube of its side and a boundary texel, crossed by about `2^depth` leaves, by the
/// square; [`DEPTH_BOUNDS`] holds the asserted figures. `depth = 0` tests each texel once.
/// Errors as [`coverage_into`], and a `depth` above [`LEAF_DEPTH`].
pub fn coverage_into_depth(
    caps: &[SphericalCap],
    n: usize,
    outside: Outside,
    depth: u32,
    out: &mut [f32],
) -> Result<(), Error> {
    if depth > LEAF_DEPTH {
        return Err(Error::OutOfRange {
            what: "coverage subdivision depth",
            value: depth as f32,
            min: 0.0,
            max: LEAF_DEPTH as f32,
        });
    }
    check_side("visibility map side", n, MAX_SIDE)?;
    let texels = checked_product("visibility map texel count", n, n)?;
    check_len("visibility map length", out.len(), texels)?;
    block(caps, n, outside, depth, [0, n, 0, n], out);
    Ok(())
}

/// Fills the texels `[i0, i1) × [j0, j1)` of an `n × n` map: a block that the bound of
/// [`area`] classifies as wholly visible, wholly occluded or wholly outside the disk is
/// filled at once; a mixed one is split in four down to single texels, which [`area`]
/// integrates. Each texel gets what [`area`] gives it alone (a block's bound holds for
/// every square inside it), at the cost of one test per uniform block.
fn block(
    caps: &[SphericalCap],
    n: usize,
    outside: Outside,
    depth: u32,
    [i0, i1, j0, j1]: [usize; 4],
    out: &mut [f32],
) {
    let inv = 1.0 / n as f32;
    if i1 - i0 == 1 && j1 - j0 == 1 {
        let c = Vec2::new(
            (2 * i0 + 1) as f32 * inv - 1.0,
            (2 * j0 + 1) as f32 * inv - 1.0,
        );
        out[j0 * n + i0] = area(caps, c, inv, outside, depth);
        return;
    }
    let c = Vec2::new((i0 + i1) as f32 * inv - 1.0, (j0 + j1) as f32 * inv - 1.0);
    let hb = (i1 - i0).max(j1 - j0) as f32 * inv;
    let fill = |v: f32, out: &mut [f32]| {
        for j in j0..j1 {
            out[j * n + i0..j * n + i1].fill(v);
        }
    };
    let ov = outside.value();
    let h = hb * core::f32::consts::SQRT_2;
    let disk = classify(1.0 - math::sqrtf(c.dot(c)), h);
    if disk == St::Out {
        return fill(ov, out);
    }
    let w = hemisphere::unmap(c);
    let (mut any_in, mut crossing) = (false, false);
    for cap in caps {
        match classify(cap_fn_at(cap, w), cap_bound(cap, w, h)) {
            St::In => {
                any_in = true;
                break;
            }
            St::Cross => crossing = true,
            St::Out => {}
        }
    }
    if any_in && (disk == St::In || ov == 0.0) {
        return fill(0.0, out);
    }
    if !any_in && !crossing && (disk == St::In || ov == 1.0) {
        return fill(1.0, out);
    }
    let (im, jm) = ((i0 + i1).div_ceil(2), (j0 + j1).div_ceil(2));
    for [a, b] in [[i0, im], [im, i1]] {
        for [c, d] in [[j0, jm], [jm, j1]] {
            if a < b && c < d {
                block(caps, n, outside, depth, [a, b, c, d], out);
            }
        }
    }
}

/// `Σ coverage · 8/n²` (in `f64`): the visible solid angle of a map built with
/// [`Outside::Occluded`] (each texel inside the disk carries `8/n²` sr).
pub fn visible_solid_angle(coverage: &[f32], n: usize) -> f64 {
    let s: f64 = coverage.iter().map(|&c| c as f64).sum();
    s * 8.0 / (n as f64 * n as f64)
}

/// The binary map of a coverage map: visible where the coverage is at least ½.
pub fn binary_into(coverage: &[f32], out: &mut [bool]) {
    for (o, &c) in out.iter_mut().zip(coverage) {
        *o = c >= 0.5;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_caps_is_all_visible_and_disk_area_is_pi() {
        let n = 16;
        let mut out = [0.0f32; 256];
        coverage_into(&[], n, Outside::Visible, &mut out).unwrap();
        assert!(out.iter().all(|&c| c == 1.0));
        coverage_into(&[], n, Outside::Occluded, &mut out).unwrap();
        // The disk carries 2π sr.
        let sa = visible_solid_angle(&out, n);
        assert!((sa - core::f64::consts::TAU).abs() < 1e-4, "{sa}");
        assert!(coverage_into(&[], 0, Outside::Visible, &mut out[..0]).is_err());
        assert!(coverage_into(&[], 4, Outside::Visible, &mut out[..15]).is_err());
    }

    /// Uniform `[0, 1)` values from a xorshift stream seeded with `seed`.
    fn uniform(mut seed: u64) -> impl FnMut() -> f32 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// `cap_bound` bounds the change of a cap's `f` over a square: for caps from 1e-3 rad to
    /// a hemisphere, square centres over the whole parametrisation square (outside the disk
    /// too), half-diagonals from a leaf's to a whole-map block's, and points across the
    /// square, `|f(x) − f(c)| ≤ cap_bound + MARGIN`; and the bound is tighter than the plain
    /// `LIP_CAP·h` near a small cap.
    #[test]
    fn cap_bound_bounds_the_cap_function_over_a_square() {
        let mut r = uniform(0x9e37_79b9_7f4a_7c15);
        let mut tighter = 0;
        for trial in 0..4000 {
            let a = Vec3::new(2.0 * r() - 1.0, 2.0 * r() - 1.0, 2.0 * r() - 0.5);
            let alpha = [1e-3, 0.05, 0.3, 1.0, core::f32::consts::FRAC_PI_2][trial % 5];
            let cap = SphericalCap::new(a, alpha).unwrap();
            let c = Vec2::new(2.4 * r() - 1.2, 2.4 * r() - 1.2);
            let hs = [1.0 / 64.0, 1.0 / 16.0, 0.25, 1.0][(trial / 5) % 4];
            let h = hs * core::f32::consts::SQRT_2;
            let w = hemisphere::unmap(c);
            let bound = cap_bound(&cap, w, h);
            tighter += usize::from(bound < LIP_CAP * h);
            let f0 = cap_fn_at(&cap, w);
            for _ in 0..16 {
                let x = c + Vec2::new(hs * (2.0 * r() - 1.0), hs * (2.0 * r() - 1.0));
                let d = (cap_fn(&cap, x) - f0).abs();
                assert!(
                    d <= bound + MARGIN,
                    "cap {alpha} at {c}, hs {hs}: {d} > {bound}"
                );
            }
        }
        assert!(tighter > 1000, "{tighter}");
    }

    /// The block walk gives each texel what `area` gives it alone.
    #[test]
    fn block_walk_matches_texel_by_texel() {
        let mut r = uniform(0x2545_f491_4f6c_dd1d);
        let mut worst = 0.0f32;
        for trial in 0..60 {
            let caps: [SphericalCap; 4] = core::array::from_fn(|_| {
                let a = Vec3::new(2.0 * r() - 1.0, 2.0 * r() - 1.0, 1.5 * r() - 0.5);
                SphericalCap::new(a, 0.02 + 0.8 * r()).unwrap()
            });
            let k = 1 + trial % 4;
            let n = [1usize, 5, 16, 32, 33][trial % 5];
            for outside in [Outside::Visible, Outside::Occluded] {
                for depth in [0, 2, LEAF_DEPTH] {
                    let mut out = [0.0f32; 33 * 33];
                    coverage_into_depth(&caps[..k], n, outside, depth, &mut out[..n * n]).unwrap();
                    let hs = 1.0 / n as f32;
                    for (t, &o) in out[..n * n].iter().enumerate() {
                        let (i, j) = (t % n, t / n);
                        let c =
                            Vec2::new((2 * i + 1) as f32 * hs - 1.0, (2 * j + 1) as f32 * hs - 1.0);
                        let want = area(&caps[..k], c, hs, outside, depth);
                        worst = worst.max((o - want).abs());
                    }
                }
            }
        }
        assert!(worst == 0.0, "{worst}");
    }

    #[test]
    fn overhead_cap_blocks_the_centre() {
        let cap = SphericalCap::new(Vec3::Z, 0.5).unwrap();
        assert!(!is_visible(&[cap], Vec2::ZERO, Outside::Visible));
        assert!(is_visible(&[cap], Vec2::new(0.9, 0.0), Outside::Visible));
        assert!(is_visible(&[cap], Vec2::new(0.9, 0.9), Outside::Visible));
        assert!(!is_visible(&[cap], Vec2::new(0.9, 0.9), Outside::Occluded));
        assert!(square_coverage(&[cap], Vec2::ZERO, f32::NAN, Outside::Visible, 3).is_nan());
    }
}
