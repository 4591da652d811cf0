//! Summed-area tables: `steradian_core::rsl::sat` against the f64 brute-force sum (property tests
//! with a fixed seed, the stated bound `2⁻²⁴·|I| + 2⁻¹⁵⁰ + 2⁻⁴⁶·A + n·2⁻⁵⁹·T`), named hard cases,
//! the WGSL kernel on a real adapter (within
//! `wgsl::SAT_BOX_REL_TOL`; naga validation is in `wgsl_validate.rs`), and
//! `steradian eval sat-box`. The SIMD kernel is checked lane by lane, bit for bit, in
//! `steradian-simd`'s `rsl` tests.

use proptest::prelude::*;
use proptest::test_runner::Config;

use crate::common::proptest_config;
use serde_json::{Value, json};
use steradian_core::Vec2;
use steradian_core::rsl::sat::{Sat, SatView};
use steradian_core::wgsl;
use steradian_harness::eval;
use steradian_harness::kernels::Columns;
use steradian_harness::report::sat::{random_boxes, uniform_grid};
use steradian_harness::rng::Rng;
use steradian_harness::sat::options::PlainF32;
use steradian_harness::sat::{Grid, error_bound, gpu_box_sums, gpu_table, ulp};

use crate::common::gpu as gpu_common;
use gpu_common::{gpu, say};

fn config(cases: u32) -> Config {
    proptest_config::config(cases, 0x5a7_ad1a)
}

fn build(g: &Grid) -> Sat {
    Sat::build(g.width, g.height, &g.texels).expect("valid grid")
}

/// Checks one box against the brute force and the stated bound; and `box_sum_f64`, the
/// same query before its rounding to `f32`, against the bound without the rounding terms
/// (`2⁻⁴⁶·A + n·2⁻⁵⁹·T`, its doc comment).
fn check(g: &Grid, sat: &Sat, t: f64, b: [f32; 4]) -> Result<(), String> {
    let r = g.reference(b[0], b[1], b[2], b[3]);
    let got = sat.box_sum(b[0], b[1], b[2], b[3]) as f64;
    // The brute force itself sums ≤ n terms in f64: allow its own rounding too.
    let slack = r.abs_read * r.n_read as f64 * 2f64.powi(-52);
    let bound = error_bound(&r, t) + slack;
    let fail = |what: &str, got: f64, bound: f64| {
        Err(format!(
            "{}×{} box {b:?}: {what} {got:e}, exact {:e}, error {:e} > bound {bound:e}",
            g.width,
            g.height,
            r.value,
            (got - r.value).abs()
        ))
    };
    if (got - r.value).abs() > bound {
        return fail("got", got, bound);
    }
    let got64 = sat.view().box_sum_f64(b[0], b[1], b[2], b[3]);
    let bound64 = r.abs_read * 2f64.powi(-46) + r.n_read as f64 * 2f64.powi(-59) * t + slack;
    if (got64 - r.value).abs() > bound64 {
        return fail("box_sum_f64", got64, bound64);
    }
    Ok(())
}

/// A `w × h` grid of texels drawn from a random [`texel_gen`] distribution per texel.
fn random_grid(w: usize, h: usize, rng: &mut Rng) -> Grid {
    let texels = (0..w * h)
        .map(|_| texel_gen(rng.next_u64() as u8, rng))
        .collect();
    Grid::new(w, h, texels).unwrap()
}

/// Texel distributions: uniform [0, 1), signed, log-uniform magnitudes over 60 decades
/// with random signs (huge/tiny dynamic range), constant, sparse spikes.
fn texel_gen(kind: u8, rng: &mut Rng) -> f32 {
    match kind % 5 {
        0 => rng.unit() as f32,
        1 => rng.range(-1.0, 1.0) as f32,
        2 => {
            let m = rng.log_range(1e-30, 1e30);
            (if rng.unit() < 0.5 { -m } else { m }) as f32
        }
        3 => 0.7,
        _ => {
            if rng.unit() < 0.02 {
                1e20
            } else {
                rng.unit() as f32 * 1e-3
            }
        }
    }
}

fn grid_strategy() -> impl Strategy<Value = Grid> {
    (1usize..40, 1usize..40, any::<u8>(), any::<u64>()).prop_map(|(w, h, kind, seed)| {
        let mut rng = Rng::new(seed);
        let texels = (0..w * h).map(|_| texel_gen(kind, &mut rng)).collect();
        Grid::new(w, h, texels).expect("shape")
    })
}

/// A corner coordinate: mostly inside (fractional or integer), sometimes outside.
fn coord(n: usize) -> impl Strategy<Value = f32> {
    let n = n as f32;
    prop_oneof![
        4 => (0.0f32..=1.0).prop_map(move |x| x * n),
        2 => (0..=(n as u32)).prop_map(|i| i as f32),
        1 => (-2.0f32..2.0).prop_map(move |x| x * n),
    ]
}

proptest! {
    #![proptest_config(config(600))]

    #[test]
    fn box_sums_within_the_stated_bound(
        (g, boxes) in grid_strategy().prop_flat_map(|g| {
            let (w, h) = (g.width, g.height);
            (Just(g), prop::collection::vec((coord(w), coord(h), coord(w), coord(h)), 1..20))
        })
    ) {
        let sat = build(&g);
        let t = g.abs_sum();
        for (u0, v0, u1, v1) in boxes {
            let r = check(&g, &sat, t, [u0, v0, u1, v1]);
            prop_assert!(r.is_ok(), "{}", r.unwrap_err());
        }
    }

    #[test]
    fn square_is_the_box_of_half_side_r_over_sqrt2(
        (g, cx, cy, r) in grid_strategy().prop_flat_map(|g| {
            let (w, h) = (g.width, g.height);
            (Just(g), coord(w), coord(h), -1.0f32..30.0)
        })
    ) {
        let sat = build(&g);
        let h = r.max(0.0) * std::f32::consts::FRAC_1_SQRT_2;
        let got = sat.square(Vec2::new(cx, cy), r);
        let want = sat.box_sum(cx - h, cy - h, cx + h, cy + h);
        prop_assert_eq!(got.to_bits(), want.to_bits());
    }
}

/// The issue's measurement at 1024²: texels in [0, 1), random fractional boxes and the
/// 16×16 box at the far corner. Every box within one f32 ulp of its exact value (the
/// bound gives ≤ 2⁻²⁴·|I| plus ~1e-10), where the plain f32 table is off by ~1.
#[test]
fn within_one_ulp_at_1024() {
    let n = 1024;
    let g = uniform_grid(n, 11);
    let sat = build(&g);
    let plain = PlainF32::build(&g);
    let t = g.abs_sum();
    let mut worst: f64 = 0.0;
    for b in random_boxes(n, 3000, 12) {
        check(&g, &sat, t, b).unwrap();
        let r = g.reference(b[0], b[1], b[2], b[3]).value;
        let got = sat.box_sum(b[0], b[1], b[2], b[3]) as f64;
        worst = worst.max((got - r).abs() / ulp(r));
    }
    say(&format!("sat 1024²: worst error {worst:.3} ulps"));
    assert!(worst <= 1.0, "{worst} ulps");
    // The far 16×16 box: ours within an ulp, plain f32 far off (the issue's figure).
    let f = (n - 17) as f32;
    let r = g.reference(f, f, f + 16.0, f + 16.0).value;
    let ours = sat.box_sum(f, f, f + 16.0, f + 16.0) as f64;
    let theirs = plain.box_sum_int(n - 17, n - 17, n - 1, n - 1) as f64;
    say(&format!(
        "far 16×16 box: exact {r}, ours off by {:e}, plain f32 off by {:e}",
        (ours - r).abs(),
        (theirs - r).abs()
    ));
    assert!((ours - r).abs() <= ulp(r));
    assert!((theirs - r).abs() > 1000.0 * ulp(r));
}

/// 2048², uniform and constant grids: within the bound, and within one ulp.
#[test]
fn within_one_ulp_at_2048_uniform_and_constant() {
    let n = 2048;
    for g in [
        uniform_grid(n, 21),
        Grid::new(n, n, vec![0.7; n * n]).unwrap(),
    ] {
        let sat = build(&g);
        let t = g.abs_sum();
        let mut boxes = random_boxes(n, 600, 22);
        boxes.push([0.0, 0.0, n as f32, n as f32]);
        boxes.push([0.5, 0.25, n as f32 - 0.75, n as f32 - 0.125]);
        for b in boxes {
            check(&g, &sat, t, b).unwrap();
            let r = g.reference(b[0], b[1], b[2], b[3]).value;
            let got = sat.box_sum(b[0], b[1], b[2], b[3]) as f64;
            assert!((got - r).abs() <= ulp(r), "{b:?}: {got} vs {r}");
        }
    }
}

// ---- Named hard cases -------------------------------------------------------------------

fn small() -> (Grid, Sat) {
    let g = Grid::new(
        4,
        3,
        vec![
            1.0, 2.0, 3.0, 4.0, //
            5.0, 6.0, 7.0, 8.0, //
            9.0, 10.0, 11.0, 12.0,
        ],
    )
    .unwrap();
    let s = build(&g);
    (g, s)
}

#[test]
fn zero_area_box_is_zero() {
    let (_, s) = small();
    for b in [
        [1.5, 1.0, 1.5, 2.5],
        [0.0, 2.0, 4.0, 2.0],
        [2.0, 2.0, 2.0, 2.0],
        [4.0, 3.0, 4.0, 3.0],
    ] {
        assert_eq!(s.box_sum(b[0], b[1], b[2], b[3]), 0.0, "{b:?}");
    }
}

#[test]
fn box_outside_the_table_is_zero_and_partly_outside_is_clipped() {
    let (_, s) = small();
    assert_eq!(s.box_sum(-5.0, -5.0, -1.0, -1.0), 0.0);
    assert_eq!(s.box_sum(5.0, 0.0, 9.0, 3.0), 0.0);
    assert_eq!(s.box_sum(0.0, 3.5, 4.0, 10.0), 0.0);
    // [−10, 1]×[−10, 1] clips to texel (0, 0).
    assert_eq!(s.box_sum(-10.0, -10.0, 1.0, 1.0), 1.0);
    assert_eq!(s.box_sum(3.0, 2.0, 100.0, 100.0), 12.0);
}

#[test]
fn inverted_corners_give_the_same_unsigned_box() {
    let (g, s) = small();
    let want = g.reference(0.5, 0.25, 3.5, 2.75).value as f32;
    for b in [
        [0.5, 0.25, 3.5, 2.75],
        [3.5, 2.75, 0.5, 0.25],
        [3.5, 0.25, 0.5, 2.75],
        [0.5, 2.75, 3.5, 0.25],
    ] {
        assert_eq!(s.box_sum(b[0], b[1], b[2], b[3]), want, "{b:?}");
    }
}

#[test]
fn box_equal_to_the_whole_table() {
    let (_, s) = small();
    assert_eq!(s.box_sum(0.0, 0.0, 4.0, 3.0), 78.0);
    assert_eq!(s.box_sum(-1.0, -1.0, 9.0, 9.0), 78.0);
}

#[test]
fn one_by_one_table() {
    let s = Sat::build(1, 1, &[2.5]).unwrap();
    assert_eq!(s.box_sum(0.0, 0.0, 1.0, 1.0), 2.5);
    assert_eq!(s.box_sum(0.25, 0.5, 0.75, 1.0), 2.5 * 0.5 * 0.5);
    assert_eq!(s.box_sum(-3.0, -3.0, 3.0, 3.0), 2.5);
    // Half-diagonal 1: half-side 0.707, clipped to the texel.
    assert_eq!(s.square(Vec2::new(0.5, 0.5), 1.0), 2.5);
    // Half-diagonal 0.5: a square of side 1/√2, area 1/2.
    assert!((s.square(Vec2::new(0.5, 0.5), 0.5) - 1.25).abs() < 1e-6);
}

#[test]
fn one_by_n_and_n_by_one_tables() {
    let t: Vec<f32> = (1..=7).map(|k| k as f32).collect();
    let row = Sat::build(7, 1, &t).unwrap();
    let col = Sat::build(1, 7, &t).unwrap();
    assert_eq!(row.box_sum(1.0, 0.0, 4.0, 1.0), 2.0 + 3.0 + 4.0);
    assert_eq!(col.box_sum(0.0, 1.0, 1.0, 4.0), 2.0 + 3.0 + 4.0);
    assert_eq!(row.box_sum(1.5, 0.0, 2.5, 1.0), 0.5 * 2.0 + 0.5 * 3.0);
    assert_eq!(col.box_sum(0.0, 6.5, 1.0, 7.0), 3.5);
    assert_eq!(row.box_sum(0.0, 0.5, 7.0, 0.5), 0.0);
}

#[test]
fn fractional_corners_inside_one_texel() {
    let (g, s) = small();
    // Inside texel (2, 1) (value 7): area 0.3 × 0.4.
    let got = s.box_sum(2.1, 1.3, 2.4, 1.7);
    let want = g.reference(2.1, 1.3, 2.4, 1.7).value;
    assert!((got as f64 - want).abs() <= ulp(want), "{got} vs {want}");
    let area = (2.4f32 as f64 - 2.1f32 as f64) * (1.7f32 as f64 - 1.3f32 as f64);
    assert!((want - 7.0 * area).abs() < 1e-12);
    // Inside the last texel, touching the far edges.
    let got = s.box_sum(3.75, 2.5, 4.0, 3.0);
    assert_eq!(got, 12.0 * 0.25 * 0.5);
}

#[test]
fn nan_and_infinite_corners() {
    let (_, s) = small();
    let nan = f32::NAN;
    let inf = f32::INFINITY;
    for b in [
        [nan, 0.0, 1.0, 1.0],
        [0.0, nan, 1.0, 1.0],
        [0.0, 0.0, nan, 1.0],
        [0.0, 0.0, 1.0, nan],
    ] {
        assert!(s.box_sum(b[0], b[1], b[2], b[3]).is_nan(), "{b:?}");
    }
    assert!(s.square(Vec2::new(nan, 1.0), 1.0).is_nan());
    assert!(s.square(Vec2::new(1.0, 1.0), nan).is_nan());
    // Infinities are clipped like any other corner.
    assert_eq!(s.box_sum(-inf, -inf, inf, inf), 78.0);
    assert_eq!(s.box_sum(inf, 0.0, inf, 3.0), 0.0);
    assert_eq!(s.box_sum(-inf, 0.0, 1.0, 1.0), 1.0);
    // An infinite square: centre ± ∞ spans the table.
    assert_eq!(s.square(Vec2::new(1.0, 1.0), inf), 78.0);
    assert_eq!(s.square(Vec2::new(1.0, 1.0), -1.0), 0.0);
}

#[test]
fn non_finite_texels_are_rejected_by_build() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let e = Sat::build(2, 2, &[1.0, bad, 0.0, 0.0]).unwrap_err();
        assert!(e.to_string().contains("texel"), "{e}");
    }
    assert!(Sat::build_f64(1, 2, &[1.0, f64::NAN]).is_err());
    assert!(Sat::build_f64(1, 1, &[1e39]).is_err());
    assert!(Sat::build(0, 3, &[]).is_err());
    assert!(Sat::build(3, 0, &[]).is_err());
    assert!(Sat::build(2, 2, &[1.0; 5]).is_err());
}

#[test]
fn extreme_texels_do_not_overflow_the_table() {
    // f32::MAX texels: the sum overflows f32 (→ ∞) but a single texel does not.
    let s = Sat::build(2, 2, &[f32::MAX; 4]).unwrap();
    assert_eq!(s.box_sum(0.0, 0.0, 1.0, 1.0), f32::MAX);
    assert_eq!(s.box_sum(0.0, 0.0, 2.0, 2.0), f32::INFINITY);
    // Subnormal texels survive (quanta reach 2⁻²⁰⁹).
    let tiny = f32::from_bits(3);
    let s = Sat::build(2, 1, &[tiny, tiny]).unwrap();
    assert_eq!(s.box_sum(0.0, 0.0, 2.0, 1.0), f32::from_bits(6));
    // Mixed signs that cancel.
    let s = Sat::build(2, 1, &[1e30, -1e30]).unwrap();
    assert_eq!(s.box_sum(0.0, 0.0, 2.0, 1.0), 0.0);
}

/// Found by the fuzzer: a result in the subnormal range is rounded to the subnormal grid
/// (spacing 2⁻¹⁴⁹), so the relative term of the bound alone does not cover it; the bound's
/// `2⁻¹⁵⁰` does.
#[test]
fn subnormal_result_within_half_a_subnormal_spacing() {
    let t = f32::from_bits(0x2b) / 16.0 * 16.0; // 43 subnormal units
    let g = Grid::new(1, 1, vec![t]).unwrap();
    let s = build(&g);
    let b = [0.25, 0.25, -32.0, 0.0];
    let r = g.reference(b[0], b[1], b[2], b[3]);
    let got = s.box_sum(b[0], b[1], b[2], b[3]) as f64;
    assert!(
        (got - r.value).abs() <= 2f64.powi(-150),
        "{got:e} vs {:e}",
        r.value
    );
    check(&g, &s, g.abs_sum(), b).unwrap();
}

#[test]
fn build_into_and_view_match_the_owned_table() {
    let g = uniform_grid(33, 5);
    let s = build(&g);
    let mut sums = vec![0i64; 34 * 34];
    let v = SatView::build_into(33, 33, &g.texels, &mut sums).unwrap();
    assert_eq!(v, s.view());
    let again = SatView::new(33, 33, s.exponent(), s.sums()).unwrap();
    assert_eq!(
        again.box_sum(1.5, 2.0, 30.25, 17.0),
        s.box_sum(1.5, 2.0, 30.25, 17.0)
    );
    assert_eq!(v.gpu_len(), s.gpu_table().len());
    let mut short = vec![0i64; 10];
    assert!(SatView::build_into(33, 33, &g.texels, &mut short).is_err());
}

// ---- Integer fast paths ------------------------------------------------------------------

fn same(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

/// Integer corners (the fast paths: the scalar four-lookup path and `box_sum_cells`; the
/// SIMD kernel's all-lanes-integer path is in `steradian-simd`'s `rsl` tests): inside, on
/// the far edges, outside, inverted. `box_sum_cells` gives `box_sum`'s bits while
/// both corners lie before the last column and row; at and past the far edges it reads the
/// exact integer box (where `box_sum` takes its general path), so there it is held to its
/// own bound against the brute force, and to the same bits as its ordered, clipped box.
#[test]
fn integer_corner_fast_paths_match_the_general_query_bit_for_bit() {
    let mut rng = Rng::new(0x1c0);
    for (w, h) in [(1, 1), (1, 9), (9, 1), (17, 13), (64, 64), (300, 7)] {
        let g = random_grid(w, h, &mut rng);
        let s = build(&g);
        let v = s.view();
        let t = g.abs_sum();
        let mut c = |n: usize| -> usize {
            match rng.next_u64() % 16 {
                0 => n,
                1 => n + 1 + (rng.next_u64() % 5) as usize,
                2 => usize::MAX,
                3 => 0,
                _ => (rng.next_u64() % (n as u64 + 1)) as usize,
            }
        };
        let qs: Vec<[usize; 4]> = (0..2000).map(|_| [c(w), c(h), c(w), c(h)]).collect();
        for q in &qs {
            let f = q.map(|x| x as f32);
            let got = v.box_sum_cells(q[0], q[1], q[2], q[3]);
            if q[0].max(q[2]) < w && q[1].max(q[3]) < h {
                let want = v.box_sum(f[0], f[1], f[2], f[3]);
                assert!(same(got, want), "{w}×{h} cells {q:?}: {got} vs {want}");
            } else {
                let (x0, x1) = (q[0].min(q[2]).min(w), q[0].max(q[2]).min(w));
                let (y0, y1) = (q[1].min(q[3]).min(h), q[1].max(q[3]).min(h));
                let clipped = v.box_sum_cells(x0, y0, x1, y1);
                assert!(
                    same(got, clipped),
                    "{w}×{h} cells {q:?}: {got} vs {clipped}"
                );
                let r = g.reference(x0 as f32, y0 as f32, x1 as f32, y1 as f32);
                let slack = r.abs_read * r.n_read as f64 * 2f64.powi(-52);
                let bound = r.value.abs() * 2f64.powi(-24)
                    + 2f64.powi(-150)
                    + r.n_read as f64 * 2f64.powi(-59) * t
                    + slack;
                let err = (got as f64 - r.value).abs();
                assert!(
                    err <= bound,
                    "{w}×{h} cells {q:?}: error {err:e} > {bound:e}"
                );
            }
            check(&g, &s, t, f).unwrap();
        }
    }
}

/// Integer texels with integer corners: the fixed-point sum is exact, so the query is the
/// correctly rounded exact sum (what the f32 tables of the other crates miss, bench
/// `sat`), through the scalar and the integer-coordinate query (the SIMD query equals the
/// scalar one bit for bit: `steradian-simd`'s `rsl` tests).
#[test]
fn integer_boxes_of_integer_texels_are_correctly_rounded() {
    let n = 512;
    let mut rng = Rng::new(0xb17e);
    let bytes: Vec<u64> = (0..n * n).map(|_| rng.next_u64() % 256).collect();
    let texels: Vec<f32> = bytes.iter().map(|&b| b as f32).collect();
    let s = Sat::build(n, n, &texels).unwrap();
    let v = s.view();
    let mut rows = vec![0u64; (n + 1) * (n + 1)];
    for j in 0..n {
        for i in 0..n {
            rows[(j + 1) * (n + 1) + i + 1] =
                bytes[j * n + i] + rows[j * (n + 1) + i + 1] + rows[(j + 1) * (n + 1) + i]
                    - rows[j * (n + 1) + i];
        }
    }
    let exact = |x0: usize, y0: usize, x1: usize, y1: usize| {
        let at = |x: usize, y: usize| rows[y * (n + 1) + x];
        (at(x1, y1) + at(x0, y0) - at(x0, y1) - at(x1, y0)) as f32
    };
    let qs: Vec<[usize; 4]> = (0..4000)
        .map(|_| {
            let mut a = |m: u64| (rng.next_u64() % m) as usize;
            let (x0, y0) = (a(n as u64), a(n as u64));
            let (x1, y1) = ((x0 + 1 + a(300)).min(n), (y0 + 1 + a(300)).min(n));
            [x0, y0, x1, y1]
        })
        .collect();
    for q in &qs {
        let want = exact(q[0], q[1], q[2], q[3]);
        let f = q.map(|x| x as f32);
        assert_eq!(v.box_sum(f[0], f[1], f[2], f[3]), want, "{q:?}");
        assert_eq!(v.box_sum_cells(q[0], q[1], q[2], q[3]), want, "{q:?}");
    }
}

// ---- WGSL --------------------------------------------------------------------------------

/// The WGSL kernel against the scalar kernel lane by lane, on finite corners:
/// `|gpu − cpu| ≤ SAT_BOX_REL_TOL·A` (A = Σ|t| over the texels the query reads).
#[test]
fn gpu_matches_scalar_within_tolerance() {
    let Some(mut gpu) = gpu() else { return };
    let mut rng = Rng::new(404);
    let mut worst: f64 = 0.0;
    let grids = [
        uniform_grid(1024, 3),
        Grid::new(37, 5, (0..37 * 5).map(|_| texel_gen(1, &mut rng)).collect()).unwrap(),
        Grid::new(1, 1, vec![3.0]).unwrap(),
        Grid::new(
            50,
            50,
            (0..2500)
                .map(|_| {
                    let m = rng.log_range(1e-12, 1e12);
                    (if rng.unit() < 0.5 { -m } else { m }) as f32
                })
                .collect(),
        )
        .unwrap(),
        Grid::new(64, 64, vec![1e-30; 64 * 64]).unwrap(),
    ];
    for g in &grids {
        let s = build(g);
        let v = s.view();
        let table = gpu_table(&v);
        let (w, h) = (g.width as f64, g.height as f64);
        let mut qs: Vec<[f32; 4]> = (0..5000)
            .map(|_| {
                [
                    rng.range(-1.0, w + 1.0) as f32,
                    rng.range(-1.0, h + 1.0) as f32,
                    rng.range(-1.0, w + 1.0) as f32,
                    rng.range(-1.0, h + 1.0) as f32,
                ]
            })
            .collect();
        qs.extend(random_boxes(g.width.min(g.height), 2000, 9));
        qs.push([0.0, 0.0, w as f32, h as f32]);
        qs.push([1e30, -1e30, -1e30, 1e30]);
        let input = Columns::from_rows(&qs);
        let mut out = Columns::zeros(1, qs.len());
        gpu_box_sums(&mut gpu, &table, &input, &mut out).expect("GPU run");
        for (k, q) in qs.iter().enumerate() {
            let cpu = v.box_sum(q[0], q[1], q[2], q[3]) as f64;
            let a = g.reference(q[0], q[1], q[2], q[3]).abs_read;
            let d = (out.data[k] as f64 - cpu).abs();
            let rel = if a > 0.0 { d / a } else { d };
            worst = worst.max(rel);
            assert!(
                d <= wgsl::SAT_BOX_REL_TOL as f64 * a,
                "{}×{} {q:?}: gpu {} cpu {cpu} A {a}",
                g.width,
                g.height,
                out.data[k]
            );
        }
    }
    say(&format!(
        "sat-box GPU vs scalar: worst |Δ|/A = {worst:.3e} (tolerance {:e})",
        wgsl::SAT_BOX_REL_TOL
    ));
}

// ---- eval --------------------------------------------------------------------------------

fn eval_one(line: &str) -> Value {
    let mut out = Vec::new();
    eval::run("sat-box", line.as_bytes(), &mut out).unwrap();
    serde_json::from_slice(&out).unwrap()
}

#[test]
fn eval_sat_box_answers_boxes() {
    let v = eval_one(
        r#"{"grid": [[1, 2, 3], [4, 5, 6]], "queries": [[0, 0, 3, 2], [1, 0, 2, 1], [0, 1, 1, 2], [0.5, 0.5, 1.5, 1.5], [3, 2, 0, 0], [9, 9, 10, 10]]}"#,
    );
    assert_eq!(v, json!({"values": [21.0, 2.0, 4.0, 3.0, 21.0, 0.0]}));
}

#[test]
fn eval_sat_box_on_grids_it_did_not_see() {
    let mut rng = Rng::new(2024);
    for _ in 0..20 {
        let w = 1 + (rng.next_u64() % 30) as usize;
        let h = 1 + (rng.next_u64() % 30) as usize;
        let rows: Vec<Vec<f32>> = (0..h)
            .map(|_| (0..w).map(|_| rng.range(-10.0, 10.0) as f32).collect())
            .collect();
        let g = Grid::new(w, h, rows.concat()).unwrap();
        let qs: Vec<[f32; 4]> = (0..10)
            .map(|_| {
                [
                    rng.range(-3.0, w as f64 + 3.0) as f32,
                    rng.range(-3.0, h as f64 + 3.0) as f32,
                    rng.range(-3.0, w as f64 + 3.0) as f32,
                    rng.range(-3.0, h as f64 + 3.0) as f32,
                ]
            })
            .collect();
        let line = json!({"grid": rows, "queries": qs}).to_string();
        let v = eval_one(&line);
        let vals = v["values"].as_array().expect("values");
        let t = g.abs_sum();
        for (q, got) in qs.iter().zip(vals) {
            let r = g.reference(q[0], q[1], q[2], q[3]);
            // The shortest decimal that reads back to the same f32.
            let got = got.as_f64().unwrap() as f32 as f64;
            assert!(
                (got - r.value).abs() <= error_bound(&r, t) + 1e-12,
                "{q:?}: {got} vs {}",
                r.value
            );
        }
    }
}

#[test]
fn eval_sat_box_rejects_bad_lines_and_goes_on() {
    let lines = [
        r#"{"grid": [[1, 2], [3]], "queries": [[0, 0, 1, 1]]}"#,
        r#"{"grid": [[1, 2], [3, 1e39]], "queries": [[0, 0, 1, 1]]}"#,
        r#"{"grid": [[1, "x"]], "queries": []}"#,
        r#"{"grid": [], "queries": []}"#,
        r#"{"grid": [[]], "queries": []}"#,
        r#"{"grid": [[1]], "queries": [[0, 0, 1]]}"#,
        r#"{"grid": [[1]], "queries": [[0, 0, 1, 1e40]]}"#,
        r#"{"grid": [[1]], "queries": [[0, 0, 1, null]]}"#,
        r#"{"grid": [[1]]}"#,
        r#"{"queries": []}"#,
        r#"{"grid": [[3e38, 3e38]], "queries": [[0, 0, 2, 1]]}"#,
        r#"{"grid": [[2]], "queries": [[0, 0, 1, 1]]}"#,
    ];
    let mut out = Vec::new();
    let errors = eval::run("sat-box", lines.join("\n").as_bytes(), &mut out).unwrap();
    assert_eq!(errors, lines.len() - 1);
    let outs: Vec<Value> = String::from_utf8(out)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(outs.len(), lines.len());
    for (o, l) in outs.iter().zip(&lines).take(lines.len() - 1) {
        assert!(o["error"].is_string(), "{l} → {o}");
    }
    assert!(outs[0]["error"].as_str().unwrap().contains("ragged"));
    assert_eq!(outs[lines.len() - 1], json!({"values": [2.0]}));
}

/// The report section alone, with its run time (`cargo test --release -p steradian-harness
/// --test sat -- --ignored --nocapture report_section`): it must stay well under 20 s.
#[test]
#[ignore = "timing; run by hand"]
fn report_section_alone() {
    let t = std::time::Instant::now();
    let opts = steradian_harness::report::Options::default();
    let s = steradian_harness::report::sat::section(&opts).expect("section");
    say(&s.summary);
    say(&format!(
        "SAT section took {:.1} s",
        t.elapsed().as_secs_f64()
    ));
}
