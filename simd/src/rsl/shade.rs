//! RSL shading, 8 shading points at a time (mirrors `steradian_core::rsl::shade::shade` with an
//! isotropic BRDF SAT and a VDT per point).
//!
//! Each lane is one shading point; the loop runs over the lights. Per light and lane: the
//! rotation of the light's centre into the lane's frame, the extended equal-area map, the
//! horizon cull, the two view-interpolated BRDF SAT square queries and the VDT query, all
//! lane-wise; only the table reads are scalar (`wide` has no gather). The VDT query is
//! `VdtVisibility::fraction` operation for operation (the square in texel units, then eq. 9
//! of the bilinear `D`, or for `VdtQuery::Gradient` the straight-edge fraction of the
//! fitted 4 × 4 stencil, [`crate::rsl::vdt`]'s lane code): bit-identical to the scalar
//! query of the same square, each lane reading its own table. The two BRDF tables
//! between which a point's view is interpolated are read at the **same** indices (the square
//! is the same), so the corner arithmetic is done once for both (the scalar kernel repeats
//! it per table). Exact integer arithmetic of the SAT (`i64x8`) and the `f64x8` combination
//! follow `steradian_core::rsl::sat` operation for operation.
//!
//! **Accuracy against the scalar kernel.** Not bit-identical: the map is computed without
//! the scalar kernel's overflow-safe rescaling (the light centres and frames are unit, so
//! nothing overflows). The view's table interpolation constants are the scalar kernel's
//! operations on the same `s_max` (pass `BrdfSat::s_max`, not a value recomputed from
//! `θ_max`). Per light the factor `ρ̄·V̄` agrees with the scalar one to a few `f32` ulps of
//! the square's coordinates, which moves a VDT query near a steep edge by up to
//! `~1e-6/r` relative; the harness test `simd_matches_scalar_lane_by_lane` (which owns the
//! BRDF SATs and VDTs) checks [`REL_TOL`] per channel (relative to the point's largest
//! channel).
//!
//! **Bad input.** Never panics for validated tables; NaN in the frames or views gives NaN
//! in that lane.

use glam::Vec3;
use steradian_core::frame::Frame;
use steradian_core::rsl::sat::SatView;
use steradian_core::rsl::shade::{ShadeLight, VdtQuery};
use steradian_core::rsl::vdt::{R_MAX, R_MIN, VdtView};
use steradian_core::rsl::vis_moments::{AxisKnots, VisMomentsView, axis_knots};
use wide::{f32x8, f64x8, i64x8};

use crate::lanes::{to_f64, widen};

/// Relative difference allowed between [`shade_batch`] and the scalar kernel, per channel,
/// relative to the point's largest channel (see the module docs).
pub const REL_TOL: f32 = 2.0e-5;

/// Relative difference allowed between [`shade_moments_batch`] and the scalar moments
/// kernel, per channel, relative to the point's largest channel (measured by the harness
/// test `simd_moments_matches_scalar_lane_by_lane`).
pub const MOMENTS_REL_TOL: f32 = 1.0e-5;

/// An isotropic BRDF SAT as the SIMD kernel reads it: the tables of the polar view nodes
/// `k = 0..m` (`BrdfSat::table(k, 0)`), all of the same size, and `s_max`, the equal-area
/// radius of the last node (`BrdfSat::s_max`).
#[derive(Clone, Copy, Debug)]
pub struct IsoBrdfTables<'a> {
    /// The tables, one per polar node (at least 2).
    pub tables: &'a [SatView<'a>],
    /// Equal-area radius of the last node (`BrdfSat::s_max`).
    pub s_max: f32,
}

/// One shading point.
#[derive(Clone, Copy, Debug)]
pub struct ShadeInput<'a> {
    /// The local frame.
    pub frame: Frame,
    /// Unit view direction (world).
    pub wo: Vec3,
    /// The point's VDT (square).
    pub vdt: VdtView<'a>,
}

/// Per-lane view constants: table index, interpolation weight, view rotation.
#[derive(Clone, Copy)]
struct ViewLane {
    k0: usize,
    t: f32,
    c: f32,
    s: f32,
    front: bool,
}

fn view_lane(tables: &IsoBrdfTables<'_>, wo: Vec3) -> ViewLane {
    let m = tables.tables.len();
    let p = steradian_core::rsl::hemisphere::map(wo);
    let s = steradian_core::math::sqrtf(p.x * p.x + p.y * p.y);
    let x = (s / tables.s_max * (m - 1) as f32).clamp(0.0, (m - 1) as f32);
    let k0 = (x as usize).min(m - 2);
    let (c, sn) = if s > 0.0 {
        (p.x / s, p.y / s)
    } else {
        (1.0, 0.0)
    };
    ViewLane {
        k0,
        t: x - k0 as f32,
        c,
        s: sn,
        front: wo.z > 0.0,
    }
}

#[inline(always)]
fn sel(m: f32x8, t: f32x8, f: f32x8) -> f32x8 {
    m.select(t, f)
}

/// `steradian_core::rsl::sat::axis` lane-wise: `(I0, a0, I1, a1)` for `lo ≤ hi` (no NaN).
#[inline(always)]
fn sat_axis(lo: f32x8, hi: f32x8, n: usize) -> (f32x8, f32x8, f32x8, f32x8) {
    let nf = f32x8::splat(n as f32);
    let zero = f32x8::ZERO;
    let clip = |x: f32x8| {
        let x = sel(x.simd_gt(nf), nf, x);
        sel(x.simd_lt(zero), zero, x)
    };
    let (lo, hi) = (clip(lo), clip(hi));
    let last = f32x8::splat((n - 1) as f32);
    let fm = |x: f32x8| {
        let f = x.floor();
        sel(f.simd_gt(last), last, f)
    };
    let (i0, i1) = (fm(lo), fm(hi));
    (i0, lo - i0, i1, hi - i1)
}

#[inline(always)]
fn idx(x: f32x8) -> [usize; 8] {
    x.trunc_int().to_array().map(|i| i.max(0) as usize)
}

/// Two box sums per lane over the same boxes in tables `k0` and `k0 + 1` of each lane.
#[inline(always)]
fn box_pair(
    tables: &[SatView<'_>],
    views: &[ViewLane; 8],
    corners: (f32x8, f32x8, f32x8, f32x8),
    width: usize,
    height: usize,
) -> (f32x8, f32x8) {
    let (a, b) = box_pair_f64(tables, views, corners, width, height);
    let f = |v: f64x8| f32x8::new(v.to_array().map(|v| v as f32));
    (f(a), f(b))
}

/// [`box_pair`] before the rounding to `f32` (`SatView::box_sum_f64` per lane).
#[inline(always)]
fn box_pair_f64(
    tables: &[SatView<'_>],
    views: &[ViewLane; 8],
    (u0, v0, u1, v1): (f32x8, f32x8, f32x8, f32x8),
    width: usize,
    height: usize,
) -> (f64x8, f64x8) {
    let (i0, a0, i1, a1) = sat_axis(u0, u1, width);
    let (j0, b0, j1, b1) = sat_axis(v0, v1, height);
    let (i0, i1, j0, j1) = (idx(i0), idx(i1), idx(j0), idx(j1));
    let w1 = width + 1;
    // g[t][row*4 + col][lane]: rows J0, J0+1, J1, J1+1; columns I0, I0+1, I1, I1+1.
    let mut g = [[[0i64; 8]; 16]; 2];
    let mut quanta = [[0.0f64; 8]; 2];
    for k in 0..8 {
        let kk = views[k].k0;
        for (tt, gt) in g.iter_mut().enumerate() {
            let Some(tab) = tables.get(kk + tt) else {
                continue;
            };
            quanta[tt][k] = tab.quantum();
            let sums = tab.sums();
            for (r, l) in [j0[k], j0[k] + 1, j1[k], j1[k] + 1].into_iter().enumerate() {
                for (c, i) in [i0[k], i1[k]].into_iter().enumerate() {
                    let at = l * w1 + i;
                    let [x, y] = match sums.get(at..at + 2) {
                        Some(&[x, y]) => [x, y],
                        _ => [0, 0],
                    };
                    gt[4 * r + 2 * c][k] = x;
                    gt[4 * r + 2 * c + 1][k] = y;
                }
            }
        }
    }
    let f = [a0, a1, b0, b1].map(widen);
    let one = |gt: &[[i64; 8]; 16], q: [f64; 8]| -> f64x8 {
        let row = |r: usize| -> [i64x8; 4] { core::array::from_fn(|c| i64x8::new(gt[4 * r + c])) };
        combine_lanes([row(0), row(1), row(2), row(3)], f, q)
    };
    (one(&g[0], quanta[0]), one(&g[1], quanta[1]))
}

/// `BoxTerms::combine` times the quantum, lane-wise: the staged corner rows
/// `[J0, J0+1, J1, J1+1]` (each `[S(I0), S(I0+1), S(I1), S(I1+1)]`) and the fractions
/// `[a0, a1, b0, b1]` of one box in each lane.
#[inline(always)]
fn combine_lanes(rows: [[i64x8; 4]; 4], [a0, a1, b0, b1]: [f64x8; 4], q: [f64; 8]) -> f64x8 {
    let [r0, r0p, r1, r1p] = rows;
    let x = |l: [i64x8; 4], m: [i64x8; 4]| -> f64x8 {
        let p = (m[2] - m[0]) - (l[2] - l[0]);
        let e1 = (m[3] - m[2]) - (l[3] - l[2]);
        let e0 = (m[1] - m[0]) - (l[1] - l[0]);
        (to_f64(p) + a1 * to_f64(e1)) - a0 * to_f64(e0)
    };
    let (xb, xt, xd) = (x(r0, r1), x(r1, r1p), x(r0, r0p));
    ((xb + b1 * xt) - b0 * xd) * f64x8::new(q)
}

/// The three boxes of the BRDF gradient, `[whole, right, top]` = `[x0, x1] × [y0, y1]`,
/// `[xc, x1] × [y0, y1]`, `[x0, x1] × [yc, y1]` (each lane ordered `x0 ≤ xc ≤ x1`,
/// `y0 ≤ yc ≤ y1`), for both polar tables of each lane: [`box_pair_f64`] on each box, the
/// same bits, with the entries the boxes share staged once (`SatView::box3_f64` lane-wise:
/// 18 entry pairs per table instead of 24).
#[inline(always)]
fn box3_pair_f64(
    tables: &[SatView<'_>],
    views: &[ViewLane; 8],
    [x0, xc, x1]: [f32x8; 3],
    [y0, yc, y1]: [f32x8; 3],
    width: usize,
    height: usize,
) -> [(f64x8, f64x8); 3] {
    let corner = |x: f32x8, n: usize| {
        let (i, a, _, _) = sat_axis(x, x, n);
        (idx(i), widen(a))
    };
    let ((i0, a0), (ic, ac), (i1, a1)) = (corner(x0, width), corner(xc, width), corner(x1, width));
    let ((j0, b0), (jc, bc), (j1, b1)) =
        (corner(y0, height), corner(yc, height), corner(y1, height));
    let w1 = width + 1;
    // g[t][row*6 + col][lane]: rows J0, J0+1, Jc, Jc+1, J1, J1+1; columns I0, I0+1, Ic,
    // Ic+1, I1, I1+1.
    let mut g = [[[0i64; 8]; 36]; 2];
    let mut quanta = [[0.0f64; 8]; 2];
    for k in 0..8 {
        let kk = views[k].k0;
        for (tt, gt) in g.iter_mut().enumerate() {
            let Some(tab) = tables.get(kk + tt) else {
                continue;
            };
            quanta[tt][k] = tab.quantum();
            let sums = tab.sums();
            let rows = [j0[k], j0[k] + 1, jc[k], jc[k] + 1, j1[k], j1[k] + 1];
            for (r, l) in rows.into_iter().enumerate() {
                for (c, i) in [i0[k], ic[k], i1[k]].into_iter().enumerate() {
                    let at = l * w1 + i;
                    let [x, y] = match sums.get(at..at + 2) {
                        Some(&[x, y]) => [x, y],
                        _ => [0, 0],
                    };
                    gt[6 * r + 2 * c][k] = x;
                    gt[6 * r + 2 * c + 1][k] = y;
                }
            }
        }
    }
    // One box of one table: rows (first pair, last pair) and columns (lo, hi) of the
    // staging grid, with the fractions of its low corners.
    let one = |gt: &[[i64; 8]; 36],
               q: [f64; 8],
               (rl, rh): (usize, usize),
               (cl, ch): (usize, usize),
               (fa0, fb0): (f64x8, f64x8)|
     -> f64x8 {
        let row = |r: usize| -> [i64x8; 4] {
            [cl, cl + 1, ch, ch + 1].map(|c| i64x8::new(gt[6 * r + c]))
        };
        combine_lanes(
            [row(rl), row(rl + 1), row(rh), row(rh + 1)],
            [fa0, a1, fb0, b1],
            q,
        )
    };
    let both = |rows, cols, f| {
        (
            one(&g[0], quanta[0], rows, cols, f),
            one(&g[1], quanta[1], rows, cols, f),
        )
    };
    [
        both((0, 4), (0, 4), (a0, b0)),
        both((0, 4), (2, 4), (ac, b0)),
        both((2, 4), (0, 4), (a0, bc)),
    ]
}

/// VDT visible fractions per lane for squares `(u, v, r)` in texel units (lane `k` reads
/// `vdts[k]`, all `n × n`): eq. 9 of the bilinear `D`, or the straight-edge fraction of the
/// fitted line, [`crate::rsl::vdt`]'s lane code (bit-identical to `VdtView::gradient`).
#[inline(always)]
fn vdt_lanes(
    vdts: &[VdtView<'_>; 8],
    n: usize,
    u: f32x8,
    v: f32x8,
    r: f32x8,
    query: VdtQuery,
) -> f32x8 {
    if query == VdtQuery::Gradient {
        return crate::rsl::vdt::gradient_lanes(|k| vdts[k].samples(), n, n, [u, v, r]);
    }
    let hi_index = f32x8::splat(if n >= 2 { (n - 2) as f32 } else { 0.0 });
    let hi_frac = f32x8::splat(if n >= 2 { 1.0 } else { 0.0 });
    let zero = f32x8::ZERO;
    let ax = |x: f32x8| {
        let c = x - f32x8::splat(0.5);
        let f = c.floor();
        let i0 = sel(f.simd_gt(hi_index), hi_index, sel(f.simd_lt(zero), zero, f));
        let fr = c - i0;
        let fr = sel(
            fr.simd_gt(hi_frac),
            hi_frac,
            sel(fr.simd_lt(zero), zero, fr),
        );
        (i0, fr)
    };
    let (i0, fx) = ax(u);
    let (j0, fy) = ax(v);
    let (i0, j0) = (idx(i0), idx(j0));
    let mut d = [[0.0f32; 8]; 4];
    for k in 0..8 {
        let s = vdts[k].samples();
        let i1 = (i0[k] + 1).min(n - 1);
        let j1 = (j0[k] + 1).min(n - 1);
        let at = |i: usize, j: usize| s.get(j * n + i).copied().unwrap_or(0.0);
        d[0][k] = at(i0[k], j0[k]);
        d[1][k] = at(i1, j0[k]);
        d[2][k] = at(i0[k], j1);
        d[3][k] = at(i1, j1);
    }
    let [d00, d10, d01, d11] = d.map(f32x8::new);
    let one = f32x8::ONE;
    let lerp = |a: f32x8, b: f32x8, t: f32x8| (one - t) * a + t * b;
    let d0 = lerp(d00, d10, fx);
    let d1 = lerp(d01, d11, fx);
    let dd = lerp(d0, d1, fy);
    let (rmin, rmax) = (f32x8::splat(R_MIN), f32x8::splat(R_MAX));
    let rr = sel(r.simd_lt(rmin), rmin, sel(r.simd_gt(rmax), rmax, r));
    crate::rsl::vdt::eq9_lanes(dd, rr)
}

/// `VdtVisibility::fraction` lane-wise for the disk-unit squares `(px, py, r)`: the square
/// in texel units (`(p + 1)·n/2`, `r·n/2`, the scalar operations), then [`vdt_lanes`].
#[inline(always)]
fn vdt_fraction(
    vdts: &[VdtView<'_>; 8],
    n: usize,
    (px, py, r): (f32x8, f32x8, f32x8),
    query: VdtQuery,
) -> f32x8 {
    let half_n = f32x8::splat(0.5 * n as f32);
    let one = f32x8::ONE;
    vdt_lanes(
        vdts,
        n,
        (px + one) * half_n,
        (py + one) * half_n,
        r * half_n,
        query,
    )
}

/// The per-lane state both kernels share: the frames as rows, the view's table constants,
/// the front-facing mask and the NaN poison of each lane.
struct PointLanes {
    views: [ViewLane; 8],
    /// `fr[a][c]`: component `c` of frame axis `a` (tangent, bitangent, normal).
    fr: [[f32x8; 3]; 3],
    rot_c: f32x8,
    rot_s: f32x8,
    tw: f32x8,
    front: f32x8,
    nan: f32x8,
}

impl PointLanes {
    fn new(frames: [Frame; 8], wos: [Vec3; 8], brdf: &IsoBrdfTables<'_>) -> PointLanes {
        let views: [ViewLane; 8] =
            core::array::from_fn(|k| view_lane(brdf, frames[k].to_local(wos[k])));
        let lane = |f: &dyn Fn(usize) -> f32| f32x8::new(core::array::from_fn(f));
        let axes: [Vec3; 3] = [Vec3::X, Vec3::Y, Vec3::Z];
        // Frame rows: local = (c·t, c·b, c·n).
        let row = |k: usize, a: usize| -> Vec3 {
            let f = &frames[k];
            [f.tangent(), f.bitangent(), f.normal()][a]
        };
        PointLanes {
            views,
            fr: core::array::from_fn(|a| {
                core::array::from_fn(|c| lane(&|k| row(k, a).dot(axes[c])))
            }),
            rot_c: lane(&|k| views[k].c),
            rot_s: lane(&|k| views[k].s),
            tw: lane(&|k| views[k].t),
            front: lane(&|k| if views[k].front { 1.0 } else { 0.0 }).simd_gt(f32x8::ZERO),
            // NaN frames or views poison their lane.
            nan: lane(&|k| {
                let w = frames[k].to_local(wos[k]);
                if w.is_nan() { f32::NAN } else { 0.0 }
            }),
        }
    }

    /// The centre `(px, py)` of the light's square in each lane's parametrisation (the
    /// extended equal-area map of the centre turned into the lane's frame) and the mask of
    /// lanes where it is not wholly below the horizon and the view is in front.
    #[inline(always)]
    fn square(&self, c: Vec3, r: f32x8) -> (f32x8, f32x8, f32x8) {
        let (fr, one) = (&self.fr, f32x8::ONE);
        let x = fr[0][0] * c.x + fr[0][1] * c.y + fr[0][2] * c.z;
        let y = fr[1][0] * c.x + fr[1][1] * c.y + fr[1][2] * c.z;
        let z = fr[2][0] * c.x + fr[2][1] * c.y + fr[2][2] * c.z;
        let inv = one / (x * x + y * y + z * z).sqrt();
        let (x, y, z) = (x * inv, y * inv, z * inv);
        // Extended equal-area map: (x, y)/sqrt(1 + z) above, (x, y)·sqrt(1 − z)/|xy| below.
        let s2 = x * x + y * y;
        let up = z.simd_ge(f32x8::ZERO);
        let k_up = one / (one + z.abs()).sqrt();
        let k_dn = sel(
            s2.simd_gt(f32x8::ZERO),
            (one - z).sqrt() / s2.sqrt(),
            f32x8::ZERO,
        );
        let k = sel(up, k_up, k_dn);
        let px = sel(
            up | s2.simd_gt(f32x8::ZERO),
            x * k,
            f32x8::splat(core::f32::consts::SQRT_2),
        );
        let py = y * k;
        let live = ((px * px + py * py).sqrt() - r).simd_lt(one) & self.front;
        (px, py, live)
    }

    /// The square's centre in the BRDF tables' texels (turned by each lane's view azimuth).
    #[inline(always)]
    fn brdf_centre(&self, px: f32x8, py: f32x8, half_b: f32x8) -> (f32x8, f32x8) {
        let one = f32x8::ONE;
        let qx = px * self.rot_c + py * self.rot_s;
        let qy = py * self.rot_c - px * self.rot_s;
        ((qx + one) * half_b, (qy + one) * half_b)
    }

    /// The accumulated RGB per lane, zero where the view is behind, NaN where poisoned.
    fn finish(&self, acc: [f32x8; 3]) -> [[f32; 3]; 8] {
        let acc = acc.map(|a| sel(self.front, a, f32x8::ZERO) + self.nan);
        let arr = acc.map(|a| a.to_array());
        core::array::from_fn(|k| [arr[0][k], arr[1][k], arr[2][k]])
    }
}

/// The BRDF tables' common size, `None` for fewer than 2 tables or tables of different sizes.
fn brdf_size(brdf: &IsoBrdfTables<'_>) -> Option<(usize, usize)> {
    let tabs = brdf.tables;
    let first = tabs.first()?;
    let (bw, bh) = (first.width(), first.height());
    if tabs.len() < 2 || tabs.iter().any(|t| t.width() != bw || t.height() != bh) {
        return None;
    }
    Some((bw, bh))
}

/// Shades 8 points (lane `k` = `points[k]`), RGB per lane. All VDTs must have the same
/// square size `n` and the BRDF tables the same size; otherwise (or with fewer than 2
/// tables) returns `None`.
pub fn shade_x8(
    points: &[ShadeInput<'_>; 8],
    brdf: &IsoBrdfTables<'_>,
    query: VdtQuery,
    lights: &[ShadeLight],
) -> Option<[[f32; 3]; 8]> {
    let tabs = brdf.tables;
    let (bw, bh) = brdf_size(brdf)?;
    let n = points[0].vdt.width();
    if points
        .iter()
        .any(|p| p.vdt.width() != n || p.vdt.height() != n)
    {
        return None;
    }
    let lanes = PointLanes::new(points.map(|p| p.frame), points.map(|p| p.wo), brdf);
    let vdts: [VdtView<'_>; 8] = core::array::from_fn(|k| points[k].vdt);
    let half_b = f32x8::splat(0.5 * bw as f32);
    let mut acc = [f32x8::ZERO; 3];
    for l in lights {
        let r = f32x8::splat(l.half_diagonal());
        let (px, py, live) = lanes.square(l.centre(), r);
        if !live.any() {
            continue;
        }
        // BRDF: centre rotated by −φₒ, square in table texels.
        let (tcx, tcy) = lanes.brdf_centre(px, py, half_b);
        let h = r * half_b * f32x8::splat(core::f32::consts::FRAC_1_SQRT_2);
        let (v0, v1) = box_pair(
            tabs,
            &lanes.views,
            (tcx - h, tcy - h, tcx + h, tcy + h),
            bw,
            bh,
        );
        let rho = (v0 + lanes.tw * (v1 - v0)) * f32x8::splat(l.inv_solid_angle());
        let vis = vdt_fraction(&vdts, n, (px, py, r), query);
        let f = sel(live, rho * vis, f32x8::ZERO) + lanes.nan;
        for (a, e) in acc.iter_mut().zip(l.energy()) {
            *a += f32x8::splat(e) * f;
        }
    }
    Some(lanes.finish(acc))
}

/// One shading point of the moments kernel.
#[derive(Clone, Copy, Debug)]
pub struct MomentsInput<'a> {
    /// The local frame.
    pub frame: Frame,
    /// Unit view direction (world).
    pub wo: Vec3,
    /// The point's visibility moment tables.
    pub vis: VisMomentsView<'a>,
}

/// `x` clamped to `[0, hi]` lane-wise; NaN stays NaN (the scalar kernel's clamp).
#[inline(always)]
fn clamp_keep_nan(x: f32x8, hi: f32x8) -> f32x8 {
    sel(
        x.simd_lt(f32x8::ZERO),
        f32x8::ZERO,
        sel(x.simd_gt(hi), hi, x),
    )
}

/// `x` clamped to `[lo, hi]` lane-wise in `f64` (`f64::clamp` for non-NaN input).
#[inline(always)]
fn clamp64(x: f64x8, lo: f64, hi: f64) -> f64x8 {
    let (lo, hi) = (f64x8::splat(lo), f64x8::splat(hi));
    let x = x.simd_lt(lo).select(lo, x);
    x.simd_gt(hi).select(hi, x)
}

/// `BrdfSat::integral_gradient` (isotropic) lane-wise: the integral and the gradient of its
/// density over the square with half-side `h` (texels) around `(tcx, tcy)`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn brdf_gradient(
    lanes: &PointLanes,
    tabs: &[SatView<'_>],
    (tcx, tcy): (f32x8, f32x8),
    h: f32,
    half_b: f32,
    bw: usize,
    bh: usize,
) -> (f32x8, [f32x8; 2]) {
    let hh = f32x8::splat(h);
    let [whole, right, top] = box3_pair_f64(
        tabs,
        &lanes.views,
        [tcx - hh, tcx, tcx + hh],
        [tcy - hh, tcy, tcy + hh],
        bw,
        bh,
    );
    let two = f64x8::splat(2.0);
    let parts = |w: f64x8, r: f64x8, t: f64x8| [w, two * r - w, two * t - w];
    let (p0, p1) = (
        parts(whole.0, right.0, top.0),
        parts(whole.1, right.1, top.1),
    );
    let t = widen(lanes.tw);
    let sums: [f64x8; 3] = core::array::from_fn(|i| p0[i] + t * (p1[i] - p0[i]));
    let to32 = |v: f64x8| f32x8::new(v.to_array().map(|v| v as f32));
    let hd = f64::from(h) / f64::from(half_b);
    if hd <= 0.0 {
        return (to32(sums[0]), [f32x8::ZERO; 2]);
    }
    let k = f64x8::splat(1.0 / (2.0 * hd * hd * hd));
    let (gx, gy) = (sums[1] * k, sums[2] * k);
    let (c, sn) = (widen(lanes.rot_c), widen(lanes.rot_s));
    (
        to32(sums[0]),
        [to32(c * gx - sn * gy), to32(sn * gx + c * gy)],
    )
}

/// `VisMomentsView::moments` lane-wise (each lane its own tables, all of side `n`), for the
/// square of half-diagonal `r` (disk units, the same in every lane) centred at `(px, py)`:
/// `(f, m)`. The knots of each lane are `vis_moments::axis_knots`; the 32 table entries a
/// lane needs are read per lane, the rest is the scalar query's `f64` arithmetic lane-wise.
#[inline(always)]
fn vis_moments_lanes(
    vis: &[VisMomentsView<'_>; 8],
    n: usize,
    px: f32x8,
    py: f32x8,
    r: f32,
) -> (f32x8, [f32x8; 2]) {
    let hn = 0.5 * n as f64;
    let h = f64::from(steradian_core::rsl::sat::square_half_side(r)) * hn;
    if h <= 0.0 {
        return (f32x8::ONE, [f32x8::ZERO; 2]);
    }
    let (one, half) = (f64x8::splat(1.0), f64x8::splat(0.5));
    let hn8 = f64x8::splat(hn);
    let cu = (widen(px) + one) * hn8;
    let cv = (widen(py) + one) * hn8;
    let nf = n as f64;
    let h8 = f64x8::splat(h);
    let (a0, a1) = (clamp64(cu - h8, 0.0, nf), clamp64(cu + h8, 0.0, nf));
    let (b0, b1) = (clamp64(cv - h8, 0.0, nf), clamp64(cv + h8, 0.0, nf));
    let (a0a, a1a, b0a, b1a) = (a0.to_array(), a1.to_array(), b0.to_array(), b1.to_array());
    let kx: [AxisKnots; 8] = core::array::from_fn(|k| axis_knots(a0a[k], a1a[k], n));
    let ky: [AxisKnots; 8] = core::array::from_fn(|k| axis_knots(b0a[k], b1a[k], n));
    // Reads: V at the 4×4 knots, u·V at x-knots 1, 2, v·V at y-knots 1, 2.
    let mut sv = [[[0i64; 8]; 4]; 4];
    let mut sx = [[[0i64; 8]; 4]; 2];
    let mut sy = [[[0i64; 8]; 2]; 4];
    let mut q = [[0.0f64; 8]; 3];
    let w1 = n + 1;
    for k in 0..8 {
        let [tv, tx, ty] = vis[k].tables();
        let at =
            |t: &SatView<'_>, i: usize, j: usize| t.sums().get(j * w1 + i).copied().unwrap_or(0);
        let (x, y) = (kx[k].knots, ky[k].knots);
        for (i, &xi) in x.iter().enumerate() {
            for (j, &yj) in y.iter().enumerate() {
                sv[i][j][k] = at(&tv, xi, yj);
            }
        }
        for a in 0..2 {
            for (j, &yj) in y.iter().enumerate() {
                sx[a][j][k] = at(&tx, x[a + 1], yj);
            }
            for (i, &xi) in x.iter().enumerate() {
                sy[i][a][k] = at(&ty, xi, y[a + 1]);
            }
        }
        q[0][k] = tv.quantum();
        q[1][k] = tx.quantum();
        q[2][k] = ty.quantum();
    }
    // The integer box between knots [i0, i1] × [j0, j1] of a 2-D grid of reads
    // (`SatView::integer_box`'s operations), scaled by the quantum.
    let boxq = |s11: [i64; 8], s01: [i64; 8], s10: [i64; 8], s00: [i64; 8], q: [f64; 8]| {
        let [s11, s01, s10, s00] = [s11, s01, s10, s00].map(i64x8::new);
        to_f64((s11 - s01) - (s10 - s00)) * f64x8::new(q)
    };
    let bv: [[f64x8; 3]; 3] = core::array::from_fn(|i| {
        core::array::from_fn(|j| boxq(sv[i + 1][j + 1], sv[i][j + 1], sv[i + 1][j], sv[i][j], q[0]))
    });
    let bx: [f64x8; 3] =
        core::array::from_fn(|j| boxq(sx[1][j + 1], sx[0][j + 1], sx[1][j], sx[0][j], q[1]));
    let by: [f64x8; 3] =
        core::array::from_fn(|i| boxq(sy[i + 1][1], sy[i][1], sy[i + 1][0], sy[i][0], q[2]));
    let lanes = |ks: &[AxisKnots; 8], f: fn(&AxisKnots) -> f64| {
        f64x8::new(core::array::from_fn(|k| f(&ks[k])))
    };
    let (wfx, wlx) = (lanes(&kx, |a| a.w_first), lanes(&kx, |a| a.w_last));
    let (mfx, mlx) = (lanes(&kx, |a| a.mid_first), lanes(&kx, |a| a.mid_last));
    let (wfy, wly) = (lanes(&ky, |a| a.w_first), lanes(&ky, |a| a.w_last));
    let (mfy, mly) = (lanes(&ky, |a| a.mid_first), lanes(&ky, |a| a.mid_last));
    let (wx, wy) = ([wfx, one, wlx], [wfy, one, wly]);
    let (ou, ov) = (cu - hn8, cv - hn8);
    // `vis_moments::combine_blocks`, lane-wise.
    let (mut s, mut mx, mut my) = (f64x8::ZERO, f64x8::ZERO, f64x8::ZERO);
    for j in 0..3 {
        for i in 0..3 {
            s += wx[i] * wy[j] * bv[i][j];
        }
        mx += wy[j]
            * ((wfx * bv[0][j] * (mfx - cu) + (bx[j] - ou * bv[1][j]))
                + wlx * bv[2][j] * (mlx - cu));
    }
    for i in 0..3 {
        my += wx[i]
            * ((wfy * bv[i][0] * (mfy - cv) + (by[i] - ov * bv[i][1]))
                + wly * bv[i][2] * (mly - cv));
    }
    // `VisMomentsView::moments` after `inside`.
    let area = f64x8::splat(4.0 * h * h);
    let area_in = (a1 - a0) * (b1 - b0);
    let mx_out = -area_in * (half * (a0 + a1) - cu);
    let my_out = -area_in * (half * (b0 + b1) - cv);
    let f = clamp64((s + (area - area_in)) / area, 0.0, 1.0);
    let to_disk = one / (area * hn8);
    let to32 = |v: f64x8| f32x8::new(v.to_array().map(|v| v as f32));
    (
        to32(f),
        [to32((mx + mx_out) * to_disk), to32((my + my_out) * to_disk)],
    )
}

/// The moments kernel (`steradian_core::rsl::shade::shade_moments` with an isotropic BRDF SAT and
/// visibility moment tables per point) for 8 points, RGB per lane. All moment tables must
/// have the same side and the BRDF tables the same size; otherwise (or with fewer than 2
/// BRDF tables) returns `None`.
pub fn shade_moments_x8(
    points: &[MomentsInput<'_>; 8],
    brdf: &IsoBrdfTables<'_>,
    lights: &[ShadeLight],
) -> Option<[[f32; 3]; 8]> {
    moments_x8::<false>(points, brdf, lights, None).map(|(s, _)| s)
}

/// RGB of eight lanes: the shadowed `S` and the unshadowed `U` of [`shade_moments_pair_x8`].
pub type PairX8 = ([[f32; 3]; 8], [[f32; 3]; 8]);

/// [`shade_moments_x8`] under two visibilities from one BRDF lookup per light
/// (`steradian_core::rsl::shade::shade_moments_pair`): `(S, U)` per lane, `S` under each
/// point's tables and `U` under `base` (per lane, the same side as the points' tables) or,
/// without it, with nothing occluded. `None` as [`shade_moments_x8`], or for a `base`
/// table of another side.
pub fn shade_moments_pair_x8(
    points: &[MomentsInput<'_>; 8],
    brdf: &IsoBrdfTables<'_>,
    lights: &[ShadeLight],
    base: Option<&[VisMomentsView<'_>; 8]>,
) -> Option<PairX8> {
    moments_x8::<true>(points, brdf, lights, base)
}

/// One light's contribution per lane from the BRDF's `(I, g)` and the visibility's
/// `(f, m)` (`steradian_core::rsl::shade::light_moments`, lane-wise).
#[inline(always)]
fn moments_contribution_x8(
    lanes: &PointLanes,
    l: &ShadeLight,
    (px, py, r): (f32x8, f32x8, f32),
    (i, g): (f32x8, [f32x8; 2]),
    (f, m): (f32x8, [f32x8; 2]),
) -> [f32x8; 3] {
    let area = 2.0 * r * r;
    let joint = i * f + f32x8::splat(area) * (g[0] * m[0] + g[1] * m[1]);
    let joint = clamp_keep_nan(joint, i) * f32x8::splat(l.inv_solid_angle());
    let e = l.energy();
    let mut out: [f32x8; 3] = core::array::from_fn(|c| f32x8::splat(e[c]) * joint);
    let grad = l.gradient();
    if grad != [Vec3::ZERO; 3] {
        let cf =
            f32x8::splat(area) * f * f32x8::splat(r) * f32x8::splat(r) * f32x8::splat(1.0 / 6.0);
        let w = [i * m[0] + cf * g[0], i * m[1] + cf * g[1]];
        // `hemisphere::unmap_jacobian`, lane-wise.
        let r2 = px * px + py * py;
        let lim = f32x8::splat(2.0 - 1.0 / 4096.0);
        let r2 = sel(r2.simd_gt(lim), lim, r2);
        let sq = (f32x8::splat(2.0) - r2).sqrt();
        let inv = f32x8::ONE / sq;
        let uv = px * py * inv;
        let two = f32x8::splat(2.0);
        let ju = [sq - px * px * inv, -uv, -(two * px)];
        let jv = [-uv, sq - py * py * inv, -(two * py)];
        let loc: [f32x8; 3] = core::array::from_fn(|a| ju[a] * w[0] + jv[a] * w[1]);
        // Frame::to_world: t·x + b·y + n·z.
        let fr = &lanes.fr;
        let u: [f32x8; 3] =
            core::array::from_fn(|c| fr[0][c] * loc[0] + fr[1][c] * loc[1] + fr[2][c] * loc[2]);
        for (o, gc) in out.iter_mut().zip(&grad) {
            let d =
                f32x8::splat(gc.x) * u[0] + f32x8::splat(gc.y) * u[1] + f32x8::splat(gc.z) * u[2];
            *o = clamp_keep_nan(*o + d, f32x8::splat(f32::INFINITY));
        }
    }
    out
}

/// The moments kernel for 8 points; with `PAIR`, also the same under `base` (or with
/// nothing occluded, `f = 1`, `m = 0`; without `PAIR` the second result is zeros).
#[inline(always)]
fn moments_x8<const PAIR: bool>(
    points: &[MomentsInput<'_>; 8],
    brdf: &IsoBrdfTables<'_>,
    lights: &[ShadeLight],
    base: Option<&[VisMomentsView<'_>; 8]>,
) -> Option<PairX8> {
    let tabs = brdf.tables;
    let (bw, bh) = brdf_size(brdf)?;
    let n = points[0].vis.side();
    let other_side = |v: &VisMomentsView<'_>| v.side() != n;
    if points.iter().any(|p| other_side(&p.vis)) || base.is_some_and(|b| b.iter().any(other_side)) {
        return None;
    }
    let lanes = PointLanes::new(points.map(|p| p.frame), points.map(|p| p.wo), brdf);
    let vis: [VisMomentsView<'_>; 8] = points.map(|p| p.vis);
    let half_b = 0.5 * bw as f32;
    let mut acc = [f32x8::ZERO; 3];
    let mut acc_free = [f32x8::ZERO; 3];
    for l in lights {
        let r = l.half_diagonal();
        let (px, py, live) = lanes.square(l.centre(), f32x8::splat(r));
        if !live.any() {
            continue;
        }
        let centre = lanes.brdf_centre(px, py, f32x8::splat(half_b));
        let h = steradian_core::rsl::sat::square_half_side(r) * half_b;
        let (i, g) = brdf_gradient(&lanes, tabs, centre, h, half_b, bw, bh);
        let fm = vis_moments_lanes(&vis, n, px, py, r);
        let out = moments_contribution_x8(&lanes, l, (px, py, r), (i, g), fm);
        for (a, o) in acc.iter_mut().zip(out) {
            *a += sel(live, o, f32x8::ZERO) + lanes.nan;
        }
        if PAIR {
            let fm = match base {
                Some(b) => vis_moments_lanes(b, n, px, py, r),
                None => (f32x8::ONE, [f32x8::ZERO; 2]),
            };
            let out = moments_contribution_x8(&lanes, l, (px, py, r), (i, g), fm);
            for (a, o) in acc_free.iter_mut().zip(out) {
                *a += sel(live, o, f32x8::ZERO) + lanes.nan;
            }
        }
    }
    let free = if PAIR {
        lanes.finish(acc_free)
    } else {
        [[0.0; 3]; 8]
    };
    Some((lanes.finish(acc), free))
}

/// Shades every point with [`shade_moments_x8`] (`out[i]` for `points[i]`), 8 at a time;
/// the tail is padded with the last point. Returns `false` if the lengths differ (`out`
/// untouched) or a group's tables do not fit [`shade_moments_x8`]'s requirements (the
/// groups before it written).
pub fn shade_moments_batch(
    points: &[MomentsInput<'_>],
    brdf: &IsoBrdfTables<'_>,
    lights: &[ShadeLight],
    out: &mut [[f32; 3]],
) -> bool {
    by_eight(points, out, |g| shade_moments_x8(g, brdf, lights))
}

/// [`shade_moments_batch`] with [`shade_moments_pair_x8`]: `out[i]` and `free[i]` for
/// `points[i]`, `free[i]` under `base[i]` (nothing occluded without `base`); `false` as
/// [`shade_moments_batch`] (or when a length differs, or a `base` table's side does).
pub fn shade_moments_pair_batch(
    points: &[MomentsInput<'_>],
    brdf: &IsoBrdfTables<'_>,
    lights: &[ShadeLight],
    base: Option<&[VisMomentsView<'_>]>,
    out: &mut [[f32; 3]],
    free: &mut [[f32; 3]],
) -> bool {
    if free.len() != points.len()
        || out.len() != points.len()
        || base.is_some_and(|b| b.len() != points.len())
    {
        return false;
    }
    groups_of_eight(points.len(), |start, idx| {
        let g = idx.map(|i| points[i]);
        let b = base.map(|b| idx.map(|i| b[i]));
        let Some((s, f)) = shade_moments_pair_x8(&g, brdf, lights, b.as_ref()) else {
            return false;
        };
        let n = (points.len() - start).min(8);
        out[start..start + n].copy_from_slice(&s[..n]);
        free[start..start + n].copy_from_slice(&f[..n]);
        true
    })
}

/// Calls `x8(start, indices)` on each group of eight of `0..len` (the tail padded with
/// `len − 1`, so a padded lane repeats the last point), stopping at the first `false`;
/// `true` when every group (or none) ran.
fn groups_of_eight(len: usize, mut x8: impl FnMut(usize, [usize; 8]) -> bool) -> bool {
    (0..len)
        .step_by(8)
        .all(|start| x8(start, core::array::from_fn(|j| (start + j).min(len - 1))))
}

/// `out[i]` = lane `i mod 8` of `x8` on the group of eight points holding `points[i]` (the
/// tail padded with the last point); `false` when the lengths differ (`out` untouched) or
/// `x8` refuses a group (the groups before it written).
fn by_eight<P: Copy>(
    points: &[P],
    out: &mut [[f32; 3]],
    mut x8: impl FnMut(&[P; 8]) -> Option<[[f32; 3]; 8]>,
) -> bool {
    if points.len() != out.len() {
        return false;
    }
    groups_of_eight(points.len(), |start, idx| {
        let Some(r) = x8(&idx.map(|i| points[i])) else {
            return false;
        };
        let n = (points.len() - start).min(8);
        out[start..start + n].copy_from_slice(&r[..n]);
        true
    })
}

/// Shades every point (`out[i]` for `points[i]`), 8 at a time; the tail is padded with the
/// last point. Returns `false` if the lengths differ (`out` untouched) or a group's tables
/// or VDTs do not fit [`shade_x8`]'s requirements (the groups before it written).
pub fn shade_batch(
    points: &[ShadeInput<'_>],
    brdf: &IsoBrdfTables<'_>,
    query: VdtQuery,
    lights: &[ShadeLight],
    out: &mut [[f32; 3]],
) -> bool {
    by_eight(points, out, |g| shade_x8(g, brdf, query, lights))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::tests::same;
    use glam::Vec2;
    use steradian_core::rsl::shade::{SquareVisibility, VdtVisibility};
    use steradian_core::rsl::vdt::{FIT_WIDE_R, scratch_len, signed_distance_into};

    /// `box3_pair_f64` is `box_pair_f64` on each of its three boxes, bit for bit, in every
    /// lane: random centres over and beyond the tables (integer ones included), half-sides
    /// from 0, each lane on its own pair of polar tables (the last lane past the end).
    #[test]
    fn box3_pair_is_three_box_pairs_bit_for_bit() {
        use steradian_core::rsl::sat::Sat;
        let (w, h) = (9usize, 7usize);
        let sats: Vec<Sat> = (0..4)
            .map(|t| {
                let tex: Vec<f32> = (0..w * h)
                    .map(|k| ((k * 7 + t * 13) as f32 * 0.37).sin() + 1.2)
                    .collect();
                Sat::build(w, h, &tex).unwrap()
            })
            .collect();
        let views: Vec<SatView<'_>> = sats.iter().map(|s| s.view()).collect();
        let mut next = crate::lanes::tests::uniform(0xb0c5_u64);
        for round in 0..500 {
            let lanes: [ViewLane; 8] = core::array::from_fn(|k| ViewLane {
                k0: (k + round) % 4,
                t: 0.5,
                c: 1.0,
                s: 0.0,
                front: true,
            });
            let draw = |next: &mut dyn FnMut() -> f32, lo: f32, hi: f32| {
                f32x8::new(core::array::from_fn(|k| {
                    let x = lo + (hi - lo) * next();
                    if k % 3 == 0 { x.floor() } else { x }
                }))
            };
            let (cx, cy) = (
                draw(&mut next, -2.0, w as f32 + 2.0),
                draw(&mut next, -2.0, h as f32 + 2.0),
            );
            let hh = draw(&mut next, 0.0, 4.0);
            let got = box3_pair_f64(
                &views,
                &lanes,
                [cx - hh, cx, cx + hh],
                [cy - hh, cy, cy + hh],
                w,
                h,
            );
            let want = [
                box_pair_f64(&views, &lanes, (cx - hh, cy - hh, cx + hh, cy + hh), w, h),
                box_pair_f64(&views, &lanes, (cx, cy - hh, cx + hh, cy + hh), w, h),
                box_pair_f64(&views, &lanes, (cx - hh, cy, cx + hh, cy + hh), w, h),
            ];
            for b in 0..3 {
                for (g, e) in [(got[b].0, want[b].0), (got[b].1, want[b].1)] {
                    let (g, e) = (g.to_array(), e.to_array());
                    for k in 0..8 {
                        assert_eq!(
                            g[k].to_bits(),
                            e[k].to_bits(),
                            "round {round} box {b} lane {k}"
                        );
                    }
                }
            }
        }
    }

    /// The exact table of an `n × n` mask.
    fn table(n: usize, mask: &[bool]) -> Vec<f32> {
        let mut d = vec![0.0; n * n];
        let mut s = vec![0.0; scratch_len(n, n)];
        signed_distance_into(n, n, mask, &mut d, &mut s).unwrap();
        d
    }

    /// `vdt_fraction` (the VDT step of `shade_x8`) against `VdtVisibility::fraction` (the
    /// scalar shading kernel's), both queries, bit for bit: eight different tables per size
    /// (random, half-planes axis-aligned and oblique, a disc, no boundary either way), random
    /// squares over and beyond the parametrisation square, and special values in `p` and `r`
    /// (NaN, ±∞, zeros, huge, the half-diagonals around `FIT_WIDE_R`) in every lane.
    #[test]
    fn vdt_fraction_matches_vdt_visibility_bit_for_bit() {
        let mut next = crate::lanes::tests::uniform(0x5eed_u64);
        let specials = [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            0.0,
            -0.0,
            1e-40,
            -1.0,
            1.0,
            -1e30,
            1e30,
            0.999_999_9,
        ];
        for n in [1usize, 2, 3, 4, 8, 13] {
            let half_n = 0.5 * n as f32;
            let masks: Vec<Vec<bool>> = (0..8)
                .map(|t| {
                    (0..n * n)
                        .map(|k| {
                            let (x, y) = ((k % n) as f32 + 0.5, (k / n) as f32 + 0.5);
                            let c = 0.5 * n as f32;
                            match t {
                                0 => true,
                                1 => false,
                                2 => x < c,
                                3 => y >= 0.3 * n as f32,
                                4 => 0.6 * x - 0.8 * y + 0.2 * c > 0.0,
                                5 => (x - c) * (x - c) + (y - 0.4 * c) * (y - 0.4 * c) > c,
                                _ => next() < 0.5,
                            }
                        })
                        .collect()
                })
                .collect();
            let tables: Vec<Vec<f32>> = masks.iter().map(|m| table(n, m)).collect();
            let views: [VdtView<'_>; 8] =
                core::array::from_fn(|k| VdtView::new(n, n, &tables[k]).unwrap());
            // Disk-unit half-diagonals whose texel half-diagonal is FIT_WIDE_R and its
            // neighbours (exact for power-of-two sides).
            let wide = FIT_WIDE_R / half_n;
            let radii = [
                wide,
                wide.next_down(),
                wide.next_up(),
                0.0,
                -1.0,
                1e-14,
                1e30,
            ];
            let mut rows: Vec<[f32; 3]> = Vec::new();
            for _ in 0..400 {
                let r = if next() < 0.3 {
                    radii[(next() * radii.len() as f32) as usize % radii.len()]
                } else {
                    (next() * 1.5).powi(2)
                };
                rows.push([next() * 2.8 - 1.4, next() * 2.8 - 1.4, r]);
            }
            for &x in specials.iter().chain(&radii) {
                rows.extend([[x, 0.1, 0.3], [-0.2, x, 0.3], [0.1, -0.3, x]]);
            }
            // Every row in every lane position: shift by 0..8 filler rows.
            for shift in 0..8 {
                let mut r = vec![[0.25f32, -0.5, 0.2]; shift];
                r.extend_from_slice(&rows);
                for chunk in r.chunks(8) {
                    let lane = |c: usize| {
                        f32x8::new(core::array::from_fn(|k| {
                            chunk.get(k).map_or(0.5, |row| row[c])
                        }))
                    };
                    let (px, py, rr) = (lane(0), lane(1), lane(2));
                    for query in [VdtQuery::Eq9, VdtQuery::Gradient] {
                        let got = vdt_fraction(&views, n, (px, py, rr), query).to_array();
                        for k in 0..8 {
                            let (x, y, rk) = (px.as_array()[k], py.as_array()[k], rr.as_array()[k]);
                            let vis = VdtVisibility::new(views[k], query).unwrap();
                            let want = vis.fraction(Vec2::new(x, y), rk);
                            assert!(
                                same(got[k], want),
                                "n {n} {query:?} lane {k} ({x}, {y}, {rk}): {} vs {want}",
                                got[k]
                            );
                        }
                    }
                }
            }
        }
    }
}
