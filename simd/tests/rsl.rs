//! The rotatable-square-lights batch kernels lane by lane against their scalar kernels in
//! `steradian-core`: SAT box and square queries and VDT queries bit-identical, the eq. 5
//! shading and moments kernels within `shade::REL_TOL` / `shade::MOMENTS_REL_TOL` of the
//! largest channel. Inputs: random tables and queries at every slice length, the named
//! special values in every field and lane position, and the bad lanes (NaN views, views
//! below the horizon, grazing views, tables of different sizes).

use glam::{Vec2, Vec3};
use steradian_core::frame::Frame;
use steradian_core::lobe::brdf::{Brdf, Lambert, Phong};
use steradian_core::rsl::Rsl;
use steradian_core::rsl::brdf_sat::{BrdfSat, Resolution};
use steradian_core::rsl::sat::{Sat, SatView};
use steradian_core::rsl::shade::{self as core_shade, ShadeLight, VdtQuery, VdtVisibility};
use steradian_core::rsl::vdt::{FIT_WIDE_R, R_MAX, R_MIN, Vdt, VdtView};
use steradian_core::rsl::vis_moments::VisMoments;
use steradian_simd::rsl::shade::{
    IsoBrdfTables, MOMENTS_REL_TOL, MomentsInput, REL_TOL, ShadeInput, shade_moments_pair_x8,
    shade_moments_x8, shade_x8,
};
use steradian_simd::rsl::{sat, vdt};

use crate::common::lanes::{LENGTHS, in_every_lane, same};
use crate::common::rng::Rng;
use crate::common::specials::SPECIALS;

/// Table sizes: single texels, single rows and columns, odd and even squares.
const SIZES: [(usize, usize); 6] = [(1, 1), (1, 9), (9, 1), (17, 13), (64, 64), (300, 7)];

fn special(rng: &mut Rng) -> f32 {
    SPECIALS[(rng.next_u64() % SPECIALS.len() as u64) as usize]
}

/// A coordinate over `[−2, n + 2)`, a special value one time in eight.
fn coord(rng: &mut Rng, n: usize) -> f32 {
    if rng.next_u64().is_multiple_of(8) {
        special(rng)
    } else {
        rng.range(-2.0, n as f32 + 2.0)
    }
}

// ---- SAT ------------------------------------------------------------------------------

fn random_sat(w: usize, h: usize, rng: &mut Rng) -> Sat {
    let t: Vec<f32> = (0..w * h).map(|_| rng.range(-1.0, 1.0)).collect();
    Sat::build(w, h, &t).expect("finite texels")
}

/// Columns of `rows`.
fn cols<const N: usize>(rows: &[[f32; N]]) -> [Vec<f32>; N] {
    core::array::from_fn(|c| rows.iter().map(|r| r[c]).collect())
}

/// `box_sum_slices` and `square_slices` (centre `(q0, q1)`, half-diagonal `q2`) against
/// `SatView::box_sum` and `SatView::square`, bit for bit.
fn check_sat(v: &SatView<'_>, rows: &[[f32; 4]]) {
    let [u0, v0, u1, v1] = cols(rows);
    let mut out = vec![0.0; rows.len()];
    sat::box_sum_slices(v, &u0, &v0, &u1, &v1, &mut out);
    for (k, q) in rows.iter().enumerate() {
        let want = v.box_sum(q[0], q[1], q[2], q[3]);
        assert!(
            same(out[k], want),
            "box lane {k} {q:?}: {} vs {want}",
            out[k]
        );
    }
    sat::square_slices(v, &u0, &v0, &u1, &mut out);
    for (k, q) in rows.iter().enumerate() {
        let want = v.square(Vec2::new(q[0], q[1]), q[2]);
        assert!(
            same(out[k], want),
            "square lane {k} {q:?}: {} vs {want}",
            out[k]
        );
    }
}

#[test]
fn sat_random_queries_at_every_length() {
    let mut rng = Rng(77);
    for (w, h) in SIZES {
        let s = random_sat(w, h, &mut rng);
        for len in LENGTHS {
            let rows: Vec<[f32; 4]> = (0..len)
                .map(|_| {
                    [
                        coord(&mut rng, w),
                        coord(&mut rng, h),
                        coord(&mut rng, w),
                        coord(&mut rng, h),
                    ]
                })
                .collect();
            check_sat(&s.view(), &rows);
        }
    }
}

#[test]
fn sat_special_corners_in_every_lane() {
    let mut rng = Rng(78);
    let s = random_sat(17, 13, &mut rng);
    let rows: Vec<[f32; 4]> = SPECIALS
        .iter()
        .flat_map(|&x| {
            [
                [x, 1.0, 2.5, 3.0],
                [0.5, x, 2.0, 3.0],
                [0.5, 0.5, x, 2.0],
                [0.5, 0.5, 2.0, x],
            ]
        })
        .collect();
    in_every_lane(&rows, [0.5, 0.5, 1.5, 1.5], |r| check_sat(&s.view(), r));
}

/// Batches of 8 integer corners (the SIMD kernel's all-integer path: inside, on and past
/// the far edges, `usize::MAX`), then the same batches with one lane NaN or fractional (the
/// general path).
#[test]
fn sat_integer_corner_path_and_spoiled_lanes() {
    let mut rng = Rng(0x1c0);
    for (w, h) in SIZES {
        let s = random_sat(w, h, &mut rng);
        let mut c = |n: usize| -> f32 {
            (match rng.next_u64() % 16 {
                0 => n,
                1 => n + 1 + (rng.next_u64() % 5) as usize,
                2 => usize::MAX,
                3 => 0,
                _ => (rng.next_u64() % (n as u64 + 1)) as usize,
            }) as f32
        };
        let rows: Vec<[f32; 4]> = (0..2000).map(|_| [c(w), c(h), c(w), c(h)]).collect();
        for spoil in [None, Some(f32::NAN), Some(0.5f32)] {
            let fq: Vec<[f32; 4]> = rows
                .iter()
                .enumerate()
                .map(|(k, &q)| {
                    let mut f = q;
                    if let Some(x) = spoil.filter(|_| k % 8 == 3) {
                        f[1] = if x.is_nan() { x } else { f[1] + x };
                    }
                    f
                })
                .collect();
            check_sat(&s.view(), &fq);
        }
    }
}

// ---- VDT ------------------------------------------------------------------------------

/// Table sizes of the VDT tests: those of the SAT tests and the small ones whose
/// straight-edge stencils are clamped everywhere (1 × N, N × 1, 2 × 2, 3 × 5, 8 × 8).
const VDT_SIZES: [(usize, usize); 11] = [
    (1, 1),
    (1, 2),
    (2, 1),
    (2, 2),
    (1, 9),
    (9, 1),
    (3, 5),
    (8, 8),
    (17, 13),
    (64, 64),
    (300, 7),
];

/// Half-diagonals the VDT tests name: point queries (`r ≤ 0`), the clamps to
/// `[R_MIN, R_MAX]`, and the switch to the wide stencil at `FIT_WIDE_R` with its neighbours.
const NAMED_RADII: [f32; 12] = [
    0.0,
    -0.0,
    -1.0,
    R_MIN,
    0.5 * R_MIN,
    R_MAX,
    2.0 * R_MAX,
    FIT_WIDE_R,
    FIT_WIDE_R.next_down(),
    FIT_WIDE_R.next_up(),
    4.0,
    5.0,
];

/// A half-diagonal: a special value or a named one one time in eight each, else uniform
/// over `[0, 12)` (both stencils).
fn radius(rng: &mut Rng) -> f32 {
    match rng.next_u64() % 8 {
        0 => special(rng),
        1 => NAMED_RADII[(rng.next_u64() % NAMED_RADII.len() as u64) as usize],
        _ => rng.range(0.0, 12.0),
    }
}

/// The table of a mask, `visible(x, y)` at the texel centres.
fn mask_vdt(w: usize, h: usize, visible: impl Fn(f32, f32) -> bool) -> Vdt {
    let mask: Vec<bool> = (0..w * h)
        .map(|k| visible((k % w) as f32 + 0.5, (k / w) as f32 + 0.5))
        .collect();
    Vdt::build(w, h, &mask).expect("valid shape")
}

/// The table of a disc of occluded texels (centre `(cx, cy)`, radius `rad`, texel units).
fn disc_vdt(w: usize, h: usize, cx: f32, cy: f32, rad: f32) -> Vdt {
    mask_vdt(w, h, |x, y| {
        let (x, y) = (x - cx, y - cy);
        x * x + y * y > rad * rad
    })
}

/// The tables of the VDT tests on a `w × h` grid: a disc, no boundary (all visible, all
/// occluded), axis-aligned half-planes along each axis (slope exactly 0 along the other),
/// an oblique one, random texels.
fn vdt_tables(w: usize, h: usize, rng: &mut Rng) -> Vec<Vdt> {
    let (wf, hf) = (w as f32, h as f32);
    let bits: Vec<bool> = (0..w * h)
        .map(|_| rng.next_u64().is_multiple_of(2))
        .collect();
    vec![
        disc_vdt(w, h, 0.4 * wf, 0.6 * hf, 0.3 * wf.min(hf) + 0.5),
        mask_vdt(w, h, |_, _| true),
        mask_vdt(w, h, |_, _| false),
        mask_vdt(w, h, |x, _| x > 0.5 * wf),
        mask_vdt(w, h, |_, y| y < 0.4 * hf),
        mask_vdt(w, h, |x, y| {
            0.8 * (x - 0.5 * wf) + 0.6 * (y - 0.3 * hf) > 0.0
        }),
        Vdt::build(w, h, &bits).expect("valid shape"),
    ]
}

/// `query_slices` against `VdtView::query`, both estimates bit for bit.
fn check_vdt(v: &VdtView<'_>, rows: &[[f32; 3]]) {
    let [u, w, r] = cols(rows);
    let (mut e9, mut g) = (vec![0.0; rows.len()], vec![0.0; rows.len()]);
    vdt::query_slices(v, &u, &w, &r, &mut e9, &mut g);
    for (k, q) in rows.iter().enumerate() {
        let (we, wg) = v.query(q[0], q[1], q[2]);
        assert!(same(e9[k], we), "eq9 lane {k} {q:?}: {} vs {we}", e9[k]);
        assert!(same(g[k], wg), "gradient lane {k} {q:?}: {} vs {wg}", g[k]);
    }
}

#[test]
fn vdt_random_queries_at_every_length() {
    let mut rng = Rng(91);
    for (w, h) in VDT_SIZES {
        for t in vdt_tables(w, h, &mut rng) {
            for len in LENGTHS {
                let rows: Vec<[f32; 3]> = (0..len)
                    .map(|_| {
                        let r = radius(&mut rng);
                        [coord(&mut rng, w), coord(&mut rng, h), r]
                    })
                    .collect();
                check_vdt(&t.view(), &rows);
            }
        }
    }
}

/// A grid of centres over and beyond the table (every quarter texel on small tables: on
/// the texel centres and edges where the cell and the stencil change, and past both ends
/// where they clamp), each with half-diagonals of both stencils and around the switch.
#[test]
fn vdt_grid_over_and_beyond_the_edges() {
    let mut rng = Rng(92);
    let radii = [
        0.0,
        0.3,
        1.0,
        3.0,
        FIT_WIDE_R.next_down(),
        FIT_WIDE_R,
        9.0,
        40.0,
    ];
    let steps = |n: usize| -> Vec<f32> {
        let step = (0.25f32).max(((n + 4) as f32 / 48.0).ceil() * 0.25);
        let k = ((n as f32 + 4.0) / step) as usize;
        (0..=k).map(|i| -2.0 + i as f32 * step).collect()
    };
    for (w, h) in VDT_SIZES {
        let (us, vs) = (steps(w), steps(h));
        let mut rows = Vec::new();
        for &u in &us {
            for &v in &vs {
                rows.extend(radii.map(|r| [u, v, r]));
            }
        }
        for t in vdt_tables(w, h, &mut rng) {
            check_vdt(&t.view(), &rows);
        }
    }
}

/// Special values in each of `u`, `v` and `r` (and the named half-diagonals, at the centre
/// and on the edges of the table) in every lane position, on tables of every shape.
#[test]
fn vdt_special_values_in_every_lane() {
    let mut rng = Rng(93);
    let mut tables = vec![disc_vdt(32, 32, 14.0, 17.0, 7.0)];
    for (w, h) in [(1, 1), (2, 2), (1, 9), (9, 1), (5, 5)] {
        tables.extend(vdt_tables(w, h, &mut rng));
    }
    for t in &tables {
        let (w, h) = (t.width() as f32, t.height() as f32);
        let (cu, cv) = (0.5 * w, 0.5 * h);
        let mut rows: Vec<[f32; 3]> = SPECIALS
            .iter()
            .flat_map(|&x| [[x, cv, 3.0], [cu, x, 3.0], [cu, cv, x], [x, x, 6.0]])
            .collect();
        for r in NAMED_RADII {
            for (u, v) in [(cu, cv), (0.0, 0.0), (w, h), (-0.5, cv), (cu, h + 0.5)] {
                rows.push([u, v, r]);
            }
        }
        in_every_lane(&rows, [cu, cv, 2.0], |r| check_vdt(&t.view(), r));
    }
}

// ---- Shading (eq. 5 and the moments kernel) ---------------------------------------------

struct Setup {
    sat: BrdfSat,
    lights: Vec<ShadeLight>,
    uniform: Vec<ShadeLight>,
    vdts: Vec<Vdt>,
    moments: Vec<VisMoments>,
}

const SIDE: usize = 32;

fn setup(glossy: bool) -> Setup {
    let mut rng = Rng(if glossy { 5 } else { 6 });
    let brdf: Box<dyn Brdf> = if glossy {
        Box::new(Phong::new(0.3, 0.5, 30.0).expect("valid"))
    } else {
        Box::new(Lambert::new(0.8).expect("valid"))
    };
    let res = Resolution {
        grid: 32,
        polar: 8,
        azimuth: 1,
    };
    let sat = BrdfSat::build(brdf.as_ref(), res, core::f32::consts::FRAC_PI_2).expect("valid");
    let (mut lights, mut uniform) = (Vec::new(), Vec::new());
    while lights.len() < 12 {
        let energy = [
            rng.range(0.1, 2.0),
            rng.range(0.1, 2.0),
            rng.range(0.1, 2.0),
        ];
        let Ok(l) = Rsl::new(rng.dir(), rng.dir(), rng.log_range(1e-3, 0.6), energy) else {
            continue;
        };
        let g = [rng.dir() * 0.3, rng.dir() * 0.2, rng.dir() * 0.1];
        uniform.push(ShadeLight::from(&l));
        lights.push(ShadeLight::from(
            &l.with_gradient(g).expect("finite gradient"),
        ));
    }
    let (mut vdts, mut moments) = (Vec::new(), Vec::new());
    for _ in 0..8 {
        let (cx, cy, rad) = (
            rng.range(0.0, SIDE as f32),
            rng.range(0.0, SIDE as f32),
            rng.range(1.0, 12.0),
        );
        let mask: Vec<bool> = (0..SIDE * SIDE)
            .map(|k| {
                let (x, y) = ((k % SIDE) as f32 + 0.5 - cx, (k / SIDE) as f32 + 0.5 - cy);
                x * x + y * y > rad * rad
            })
            .collect();
        vdts.push(Vdt::build(SIDE, SIDE, &mask).expect("valid"));
        moments.push(VisMoments::build(SIDE, &mask).expect("valid"));
    }
    Setup {
        sat,
        lights,
        uniform,
        vdts,
        moments,
    }
}

fn views(sat: &BrdfSat) -> Vec<SatView<'_>> {
    (0..sat.resolution().polar)
        .map(|k| sat.table(k, 0).expect("isotropic table").view())
        .collect()
}

/// Eight random shading points: a frame and a view above its horizon, with one lane's view
/// replaced by `special` when given (at lane `at`).
fn points(rng: &mut Rng, special: Option<(usize, Vec3)>) -> [(Frame, Vec3); 8] {
    core::array::from_fn(|k| {
        let frame = Frame::from_normal(rng.dir()).expect("unit normal");
        let mut d = rng.dir();
        d.z = d.z.abs().max(1e-3);
        let wo = match special {
            Some((at, s)) if at == k => s,
            _ => frame.to_world(d.normalize()),
        };
        (frame, wo)
    })
}

/// Lane `k` within `tol` of the largest channel of the scalar result, or NaN in every
/// channel of both.
fn close(got: [f32; 3], want: [f32; 3], tol: f32) -> bool {
    if want.iter().any(|x| x.is_nan()) {
        return got.iter().chain(&want).all(|x| x.is_nan());
    }
    let m = want.iter().fold(0.0f32, |m, x| m.max(x.abs()));
    (0..3).all(|c| (got[c] - want[c]).abs() <= tol * m.max(1e-30))
}

/// Views that are not ordinary: NaN, below the horizon (the negated normal is used when
/// `None`), grazing, infinite and zero.
fn special_views() -> Vec<Option<Vec3>> {
    vec![
        Some(Vec3::new(f32::NAN, 0.0, 1.0)),
        None,
        Some(Vec3::new(f32::INFINITY, 0.0, 0.0)),
        Some(Vec3::ZERO),
    ]
}

/// Checks every lane; returns how many lanes are lit (so a test can assert it shaded
/// something).
fn check_shade(s: &Setup, pts: &[(Frame, Vec3); 8], q: VdtQuery) -> usize {
    let views = views(&s.sat);
    let tables = IsoBrdfTables {
        tables: &views,
        s_max: s.sat.s_max(),
    };
    let input: [ShadeInput<'_>; 8] = core::array::from_fn(|k| ShadeInput {
        frame: pts[k].0,
        wo: pts[k].1,
        vdt: s.vdts[k].view(),
    });
    let out = shade_x8(&input, &tables, q, &s.lights).expect("same sizes");
    for (k, p) in input.iter().enumerate() {
        let vis = VdtVisibility::new(p.vdt, q).expect("square table");
        let want = core_shade::shade(&p.frame, p.wo, &s.sat, &vis, &s.lights);
        assert!(
            close(out[k], want, REL_TOL),
            "{q:?} lane {k}: {:?} vs {want:?}",
            out[k]
        );
    }
    out.iter().filter(|o| o[0] > 0.0).count()
}

fn check_moments(s: &Setup, pts: &[(Frame, Vec3); 8], lights: &[ShadeLight]) -> usize {
    let views = views(&s.sat);
    let tables = IsoBrdfTables {
        tables: &views,
        s_max: s.sat.s_max(),
    };
    let input: [MomentsInput<'_>; 8] = core::array::from_fn(|k| MomentsInput {
        frame: pts[k].0,
        wo: pts[k].1,
        vis: s.moments[k].view(),
    });
    let out = shade_moments_x8(&input, &tables, lights).expect("same sizes");
    // The pair kernel: its `S` is the kernel's bit for bit, its `U` the scalar pair's.
    let (s_pair, u_pair) =
        shade_moments_pair_x8(&input, &tables, lights, None).expect("same sizes");
    // With a base: the tables of the next lane (U under another point's visibility).
    let base: [_; 8] = core::array::from_fn(|k| s.moments[(k + 1) % 8].view());
    let (s_based, u_based) =
        shade_moments_pair_x8(&input, &tables, lights, Some(&base)).expect("same sizes");
    let bits = |v: [f32; 3]| v.map(f32::to_bits);
    for (k, p) in input.iter().enumerate() {
        let want = core_shade::shade_moments(&p.frame, p.wo, &s.sat, &p.vis, lights);
        assert!(
            close(out[k], want, MOMENTS_REL_TOL),
            "moments lane {k}: {:?} vs {want:?}",
            out[k]
        );
        assert_eq!(bits(s_pair[k]), bits(out[k]), "pair lane {k}");
        let (_, u) = core_shade::shade_moments_pair(
            &p.frame,
            p.wo,
            &s.sat,
            &p.vis,
            &core_shade::Unoccluded,
            lights,
        );
        assert!(
            close(u_pair[k], u, MOMENTS_REL_TOL),
            "pair lane {k}: {:?} vs {u:?}",
            u_pair[k]
        );
        assert_eq!(bits(s_based[k]), bits(out[k]), "based pair lane {k}");
        let (_, ub) =
            core_shade::shade_moments_pair(&p.frame, p.wo, &s.sat, &p.vis, &base[k], lights);
        assert!(
            close(u_based[k], ub, MOMENTS_REL_TOL),
            "based pair lane {k}: {:?} vs {ub:?}",
            u_based[k]
        );
    }
    out.iter().filter(|o| o[0] > 0.0).count()
}

#[test]
fn shade_random_points_lane_by_lane() {
    for glossy in [false, true] {
        let s = setup(glossy);
        let mut rng = Rng(17);
        let mut lit = 0;
        for _ in 0..64 {
            let pts = points(&mut rng, None);
            lit += check_shade(&s, &pts, VdtQuery::Eq9);
            lit += check_shade(&s, &pts, VdtQuery::Gradient);
            lit += check_moments(&s, &pts, &s.lights);
            lit += check_moments(&s, &pts, &s.uniform);
        }
        // 12 lights over random hemispheres: nearly every point sees one.
        assert!(lit > 4 * 64 * 8 * 3 / 4, "only {lit} lit lanes");
    }
}

#[test]
fn shade_special_views_in_every_lane() {
    for glossy in [false, true] {
        let s = setup(glossy);
        let mut rng = Rng(18);
        for view in special_views() {
            for at in 0..8 {
                let mut pts = points(&mut rng, None);
                let wo = view.unwrap_or(-pts[at].0.normal());
                pts[at].1 = wo;
                check_shade(&s, &pts, VdtQuery::Gradient);
                check_moments(&s, &pts, &s.lights);
            }
        }
        // A grazing view, just above the horizon, in every lane.
        for at in 0..8 {
            let mut pts = points(&mut rng, None);
            let f = pts[at].0;
            pts[at].1 = (f.tangent() + 1e-6 * f.normal()).normalize();
            check_shade(&s, &pts, VdtQuery::Eq9);
            check_moments(&s, &pts, &s.lights);
        }
    }
}

/// The eq. 5 kernel with VDTs of 1 × 1, 2 × 2 and 5 × 5 texels (every straight-edge
/// stencil clamped), with and without a boundary, a different table in each lane, both
/// queries.
#[test]
fn shade_small_and_uniform_vdts() {
    let mut s = setup(true);
    let mut rng = Rng(20);
    for n in [1usize, 2, 5] {
        let tables = vdt_tables(n, n, &mut rng);
        s.vdts = (0..8).map(|k| tables[k % tables.len()].clone()).collect();
        let mut lit = 0;
        for _ in 0..16 {
            let pts = points(&mut rng, None);
            lit += check_shade(&s, &pts, VdtQuery::Eq9);
            lit += check_shade(&s, &pts, VdtQuery::Gradient);
        }
        assert!(lit > 0, "n {n}: nothing lit");
    }
}

/// A NaN view poisons only its lane (NaN, as the scalar kernel); a view below the horizon
/// gives 0; tables of different sizes, or fewer than two BRDF tables, are refused.
#[test]
fn shade_bad_lanes_and_mismatched_tables() {
    let s = setup(false);
    let mut rng = Rng(19);
    let mut pts = points(&mut rng, Some((3, Vec3::new(f32::NAN, 0.0, 1.0))));
    pts[5].1 = -pts[5].0.normal();
    let views = views(&s.sat);
    let tables = IsoBrdfTables {
        tables: &views,
        s_max: s.sat.s_max(),
    };
    let mut input: [MomentsInput<'_>; 8] = core::array::from_fn(|k| MomentsInput {
        frame: pts[k].0,
        wo: pts[k].1,
        vis: s.moments[k].view(),
    });
    let out = shade_moments_x8(&input, &tables, &s.lights).expect("same sizes");
    assert!(out[3].iter().all(|x| x.is_nan()), "{:?}", out[3]);
    assert_eq!(out[5], [0.0; 3]);
    assert!(
        out.iter()
            .enumerate()
            .all(|(k, o)| k == 3 || k == 5 || o[0] > 0.0)
    );
    let small = VisMoments::build(16, &vec![true; 256]).expect("valid");
    input[7].vis = small.view();
    assert!(shade_moments_x8(&input, &tables, &s.lights).is_none());

    let other = Vdt::build(16, 16, &vec![true; 256]).expect("valid");
    let mut input: [ShadeInput<'_>; 8] = core::array::from_fn(|k| ShadeInput {
        frame: pts[k].0,
        wo: pts[k].1,
        vdt: s.vdts[k].view(),
    });
    let out = shade_x8(&input, &tables, VdtQuery::Gradient, &s.lights).expect("same sizes");
    assert!(out[3].iter().all(|x| x.is_nan()));
    assert_eq!(out[5], [0.0; 3]);
    input[2].vdt = other.view();
    assert!(shade_x8(&input, &tables, VdtQuery::Gradient, &s.lights).is_none());
    input[2].vdt = s.vdts[2].view();
    let one = IsoBrdfTables {
        tables: &views[..1],
        s_max: s.sat.s_max(),
    };
    assert!(shade_x8(&input, &one, VdtQuery::Gradient, &s.lights).is_none());
}

/// The pair batch over 11 points (a full group and a padded tail), with and without base
/// tables: `S` is `shade_moments_batch`'s bit for bit and `U` the scalar pair's within
/// `MOMENTS_REL_TOL`; mismatched lengths are refused.
#[test]
fn moments_pair_batch_covers_the_tail() {
    use steradian_simd::rsl::shade::{shade_moments_batch, shade_moments_pair_batch};
    let s = setup(true);
    let mut rng = Rng(23);
    let (a, b) = (points(&mut rng, None), points(&mut rng, None));
    let pts: Vec<(Frame, Vec3)> = a.iter().chain(&b[..3]).copied().collect();
    let views = views(&s.sat);
    let tables = IsoBrdfTables {
        tables: &views,
        s_max: s.sat.s_max(),
    };
    let input: Vec<MomentsInput<'_>> = pts
        .iter()
        .enumerate()
        .map(|(k, p)| MomentsInput {
            frame: p.0,
            wo: p.1,
            vis: s.moments[k % 8].view(),
        })
        .collect();
    let base: Vec<_> = (0..pts.len())
        .map(|k| s.moments[(k + 3) % 8].view())
        .collect();
    let n = input.len();
    let mut single = vec![[0.0f32; 3]; n];
    assert!(shade_moments_batch(&input, &tables, &s.lights, &mut single));
    let bits = |v: [f32; 3]| v.map(f32::to_bits);
    for b in [None, Some(base.as_slice())] {
        let (mut out, mut free) = (vec![[0.0f32; 3]; n], vec![[0.0f32; 3]; n]);
        assert!(shade_moments_pair_batch(
            &input, &tables, &s.lights, b, &mut out, &mut free
        ));
        for k in 0..n {
            assert_eq!(bits(out[k]), bits(single[k]), "point {k}");
            let p = &input[k];
            let u = match b {
                None => core_shade::shade_moments_pair(
                    &p.frame,
                    p.wo,
                    &s.sat,
                    &p.vis,
                    &core_shade::Unoccluded,
                    &s.lights,
                ),
                Some(b) => {
                    core_shade::shade_moments_pair(&p.frame, p.wo, &s.sat, &p.vis, &b[k], &s.lights)
                }
            }
            .1;
            assert!(
                close(free[k], u, MOMENTS_REL_TOL),
                "point {k}: {:?} vs {u:?}",
                free[k]
            );
        }
    }
    let mut short = vec![[0.0f32; 3]; n - 1];
    let mut out = vec![[0.0f32; 3]; n];
    assert!(!shade_moments_pair_batch(
        &input, &tables, &s.lights, None, &mut out, &mut short
    ));
    assert!(!shade_moments_pair_batch(
        &input,
        &tables,
        &s.lights,
        Some(&base[..n - 1]),
        &mut out,
        &mut vec![[0.0f32; 3]; n]
    ));
}
