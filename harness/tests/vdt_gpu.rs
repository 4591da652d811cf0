//! The VDT query kernel (`wgsl::VDT_QUERY`) on a real adapter against the scalar kernel
//! within `wgsl::VDT_QUERY_TOL` (naga validation is in `wgsl_validate.rs`).
//!
//! Without an adapter the GPU test prints `GPU tests skipped: <reason>` and passes, unless
//! `STERADIAN_REQUIRE_GPU=1`, in which case it fails.

use steradian_core::rsl::vdt::Vdt;
use steradian_core::wgsl;
use steradian_harness::backend::gpu::Custom;
use steradian_harness::kernels::Columns;
use steradian_harness::rng::Rng;

use crate::common::gpu as gpu_common;
use gpu_common::{gpu, say};

#[test]
fn vdt_query_gpu_matches_scalar() {
    let Some(mut g) = gpu() else { return };
    let mut rng = Rng::new(0x0bd7);
    for (w, h, density) in [
        (37usize, 29usize, 0.6f64),
        (1, 9, 0.5),
        (64, 64, 1.0),
        (8, 8, 0.0),
    ] {
        let mask: Vec<bool> = (0..w * h).map(|_| rng.unit() < density).collect();
        let vdt = Vdt::build(w, h, &mask).unwrap();
        let table = vdt.gpu_table();
        let mut rows: Vec<[f32; 3]> = (0..5000)
            .map(|_| {
                [
                    rng.range(-2.0, w as f64 + 2.0) as f32,
                    rng.range(-2.0, h as f64 + 2.0) as f32,
                    rng.log_range(1e-3, 40.0) as f32,
                ]
            })
            .collect();
        // Hand-picked: texel centres, edges, the corners, r = 0 and huge.
        rows.extend([
            [0.5, 0.5, 1.0],
            [w as f32 - 0.5, h as f32 - 0.5, 2.0],
            [0.0, 0.0, 0.0],
            [w as f32, h as f32, 1e30],
            [1.0, 0.5, 1e-20],
        ]);
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
        let mut worst = 0.0f64;
        for (k, r) in rows.iter().enumerate() {
            let s = vdt.view().sample(r[0], r[1]);
            let (e9, gr) = vdt.query(r[0], r[1], r[2]);
            let rr = r[2].clamp(
                steradian_core::rsl::vdt::R_MIN,
                steradian_core::rsl::vdt::R_MAX,
            );
            let t = (s.d as f64 * std::f64::consts::SQRT_2 / rr as f64).abs();
            for (got, want, what) in [(out.data[k], e9, "eq9"), (out.data[n + k], gr, "gradient")] {
                let err = (got as f64 - want as f64).abs() / (1.0 + t);
                worst = worst.max(err);
                assert!(
                    err <= wgsl::VDT_QUERY_TOL as f64,
                    "{w}×{h} {what} at {r:?}: gpu {got} vs scalar {want}"
                );
            }
        }
        say(&format!(
            "VDT query {w}×{h}: worst GPU difference {worst:.2e} per unit of 1 + |t|"
        ));
    }
}
