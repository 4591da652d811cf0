//! The VDT query kernel (`wgsl::VDT_QUERY`) on a real adapter against the scalar kernel
//! within `wgsl::VDT_QUERY_TOL` (naga validation is in `wgsl_validate.rs`): random and
//! structured maps from 1 × 1 up, queries over and just outside the table, along its edges
//! and corners, and half-diagonals on both sides of `vdt::FIT_WIDE_R` (where the
//! straight-edge variant switches stencils).
//!
//! Without an adapter the GPU test prints `GPU tests skipped: <reason>` and passes, unless
//! `STERADIAN_REQUIRE_GPU=1`, in which case it fails.

use std::f64::consts::SQRT_2;

use steradian_core::rsl::vdt::{FIT_WIDE_R, R_MAX, R_MIN, Vdt};
use steradian_core::wgsl;
use steradian_harness::backend::gpu::Custom;
use steradian_harness::kernels::Columns;
use steradian_harness::rng::Rng;

use crate::common::gpu as gpu_common;
use gpu_common::{gpu, say};

/// The test maps: `(label, w, h, mask)`.
fn maps(rng: &mut Rng) -> Vec<(String, usize, usize, Vec<bool>)> {
    let mut out = Vec::new();
    let random = |w: usize, h: usize, density: f64, rng: &mut Rng| {
        let m: Vec<bool> = (0..w * h).map(|_| rng.unit() < density).collect();
        (format!("{w}×{h} random {density}"), w, h, m)
    };
    for (w, h, density) in [
        (37usize, 29usize, 0.6f64),
        (1, 9, 0.5),
        (13, 1, 0.5),
        (3, 40, 0.5),
        (64, 64, 1.0),
        (8, 8, 0.0),
        (1, 1, 1.0),
        (1, 1, 0.0),
    ] {
        out.push(random(w, h, density, rng));
    }
    let fixed: [(&str, usize, usize, &[bool]); 4] = [
        ("2×2 one occluded", 2, 2, &[true, false, true, true]),
        ("2×2 diagonal", 2, 2, &[true, false, false, true]),
        ("2×1", 2, 1, &[false, true]),
        ("1×2", 1, 2, &[true, false]),
    ];
    for (label, w, h, m) in fixed {
        out.push((label.to_string(), w, h, m.to_vec()));
    }
    // Oblique straight edges (the far zero-level correction) and a disc (curvature).
    let (w, h) = (40usize, 33usize);
    for (nx, ny, c) in [(0.6f64, 0.8, 17.3), (-0.93, 0.37, -12.1), (1.0, 0.0, 20.0)] {
        let m = (0..w * h)
            .map(|k| {
                let (i, j) = ((k % w) as f64 + 0.5, (k / w) as f64 + 0.5);
                nx * i + ny * j >= c
            })
            .collect();
        out.push((format!("{w}×{h} edge ({nx}, {ny})"), w, h, m));
    }
    let m = (0..w * h)
        .map(|k| {
            let (i, j) = ((k % w) as f64 + 0.5, (k / w) as f64 + 0.5);
            (i - 19.2).hypot(j - 15.7) > 9.4
        })
        .collect();
    out.push((format!("{w}×{h} disc"), w, h, m));
    out
}

/// Half-diagonals around [`FIT_WIDE_R`]: both neighbouring floats, itself, and nearby.
fn around_wide_r() -> [f32; 7] {
    let r = FIT_WIDE_R;
    [
        r.next_down(),
        r,
        r.next_up(),
        r - 0.01,
        r + 0.01,
        r * 0.9,
        r * 1.1,
    ]
}

/// The queries for a `w × h` table: random over the table and 2 texels beyond, along the
/// edges and corners (coordinates at and next to 0, ½, 1, …, the far edge), and the
/// hand-picked ones of the original test.
fn queries(w: usize, h: usize, rng: &mut Rng) -> Vec<[f32; 3]> {
    let (wf, hf) = (w as f64, h as f64);
    let random_r = |rng: &mut Rng| -> f32 {
        match rng.next_u64() % 3 {
            0 => around_wide_r()[(rng.next_u64() % 7) as usize],
            _ => rng.log_range(1e-3, 40.0) as f32,
        }
    };
    let mut rows: Vec<[f32; 3]> = (0..4000)
        .map(|_| {
            [
                rng.range(-2.0, wf + 2.0) as f32,
                rng.range(-2.0, hf + 2.0) as f32,
                random_r(rng),
            ]
        })
        .collect();
    // Near the edges: one coordinate at an edge landmark (± a little), the other random.
    let marks = |len: f64| {
        [
            -0.5,
            0.0,
            0.25,
            0.5,
            1.0,
            1.5,
            2.0,
            len - 2.0,
            len - 1.5,
            len - 1.0,
            len - 0.5,
            len,
            len + 0.5,
        ]
    };
    let (mu, mv) = (marks(wf), marks(hf));
    for k in 0..2000 {
        let jitter = |rng: &mut Rng| match rng.next_u64() % 3 {
            0 => 0.0,
            1 => rng.range(-1e-3, 1e-3),
            _ => rng.range(-0.2, 0.2),
        };
        let (u, v) = if k % 3 == 0 {
            // A corner region.
            let u = mu[(rng.next_u64() % 13) as usize] + jitter(rng);
            let v = mv[(rng.next_u64() % 13) as usize] + jitter(rng);
            (u, v)
        } else if k % 3 == 1 {
            (
                mu[(rng.next_u64() % 13) as usize] + jitter(rng),
                rng.range(-1.0, hf + 1.0),
            )
        } else {
            (
                rng.range(-1.0, wf + 1.0),
                mv[(rng.next_u64() % 13) as usize] + jitter(rng),
            )
        };
        rows.push([u as f32, v as f32, random_r(rng)]);
    }
    // Hand-picked: texel centres, edges, the corners, r = 0 and huge, both sides of
    // FIT_WIDE_R at the corners.
    rows.extend([
        [0.5, 0.5, 1.0],
        [w as f32 - 0.5, h as f32 - 0.5, 2.0],
        [0.0, 0.0, 0.0],
        [w as f32, h as f32, 1e30],
        [1.0, 0.5, 1e-20],
    ]);
    for r in around_wide_r() {
        for (u, v) in [
            (0.0, 0.0),
            (w as f32, 0.0),
            (0.0, h as f32),
            (w as f32, h as f32),
        ] {
            rows.push([u, v, r]);
        }
    }
    rows
}

/// The differences of both outputs, each in the unit of `wgsl::VDT_QUERY_TOL`: eq. 9 per
/// `1 + |t|` (`t = D·√2/r`, the bilinear `D` in half-sides), the straight-edge fraction per
/// `1 + |t| + s` (`t` from the fitted line's distance, `s = S·√2/r` with `S` the largest
/// `|D|` among the stencil's 16 samples: the fit rounds at the samples' magnitude, and a
/// compiler may reassociate its sums).
#[test]
fn vdt_query_gpu_matches_scalar() {
    let Some(mut g) = gpu() else { return };
    let mut rng = Rng::new(0x0bd7);
    let (mut worst_eq9, mut worst_edge) = (0.0f64, 0.0f64);
    for (label, w, h, mask) in maps(&mut rng) {
        let vdt = Vdt::build(w, h, &mask).unwrap();
        let view = vdt.view();
        let single_class = mask.iter().all(|&b| b == mask[0]);
        let table = vdt.gpu_table();
        let rows = queries(w, h, &mut rng);
        let input = Columns::from_rows(&rows);
        let mut out = Columns::zeros(2, rows.len());
        let custom = Custom {
            label: "vdt-query",
            source: wgsl::VDT_QUERY,
            table: Some(&table),
        };
        g.run_custom(&custom, &input, &mut out)
            .expect("VDT kernel runs");
        let n = rows.len();
        let (mut w9, mut we, mut differ) = (0.0f64, 0.0f64, 0usize);
        for (k, q) in rows.iter().enumerate() {
            let (u, v, r) = (q[0], q[1], q[2]);
            let rr = r.clamp(R_MIN, R_MAX) as f64;
            let (e9, gr) = vdt.query(u, v, r);
            let (g9, ge) = (out.data[k], out.data[n + k]);
            differ += usize::from(g9 != e9) + usize::from(ge != gr);
            if single_class {
                // No boundary: zero slopes and saturation, exactly.
                let want = if mask[0] { 1.0 } else { 0.0 };
                assert!(
                    (g9, ge) == (want, want),
                    "{label} at {q:?}: gpu ({g9}, {ge}), want {want}"
                );
            }
            let t9 = (view.distance(u, v) as f64 * SQRT_2 / rr).abs();
            let err9 = (g9 as f64 - e9 as f64).abs() / (1.0 + t9);
            let line = view.line(u, v, r);
            let st = view.stencil(u, v, r >= FIT_WIDE_R);
            let s_max = st.d.iter().flatten().fold(0.0f32, |m, x| m.max(x.abs())) as f64;
            let te = (line.d as f64 * SQRT_2 / rr).abs();
            let erre = (ge as f64 - gr as f64).abs() / (1.0 + te + s_max * SQRT_2 / rr);
            w9 = w9.max(err9);
            we = we.max(erre);
            assert!(
                err9 <= wgsl::VDT_QUERY_TOL as f64,
                "{label} eq9 at {q:?}: gpu {g9} vs scalar {e9}"
            );
            assert!(
                erre <= wgsl::VDT_QUERY_TOL as f64,
                "{label} gradient at {q:?}: gpu {ge} vs scalar {gr} (line {line:?})"
            );
        }
        say(&format!(
            "VDT query {label}: {n} queries, {differ} outputs differ; worst eq. 9 {w9:.2e} \
             per 1 + |t|, straight-edge {we:.2e} per 1 + |t| + s"
        ));
        worst_eq9 = worst_eq9.max(w9);
        worst_edge = worst_edge.max(we);
    }
    say(&format!(
        "VDT query: worst GPU difference eq. 9 {worst_eq9:.2e}, straight-edge {worst_edge:.2e} \
         (tolerance {:.1e})",
        wgsl::VDT_QUERY_TOL
    ));
}
