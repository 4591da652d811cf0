//! The SH evaluation kernel (`wgsl::SH_EVAL`, `f32`, up to 16 bands) on a real adapter
//! against the scalar kernel within `wgsl::SH_EVAL_TOL` (naga validation is in
//! `wgsl_validate.rs`).
//!
//! Without an adapter the GPU test prints `GPU tests skipped: <reason>` and passes, unless
//! `STERADIAN_REQUIRE_GPU=1`, in which case it fails.

use steradian_core::{Vec3, sh, wgsl};
use steradian_harness::backend::gpu::Custom;
use steradian_harness::kernels::Columns;
use steradian_harness::rng::Rng;

use crate::common::gpu as gpu_common;
use gpu_common::{gpu, say};

#[test]
fn sh_eval_gpu_matches_scalar() {
    let Some(mut g) = gpu() else { return };
    let mut rng = Rng::new(0x5a_9a0);
    let mut rows: Vec<[f32; 3]> = (0..3000).map(|_| rng.sphere().map(|c| c as f32)).collect();
    // Poles, the equator, 1e-7 from a pole, non-unit lengths, the zero vector.
    rows.extend([
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.3, -0.4, 0.0],
        [1e-7, 0.0, 1.0],
        [3e4, -2e4, 1e4],
        [1e-30, 2e-30, -1e-30],
        [0.0, 0.0, 0.0],
    ]);
    let input = Columns::from_rows(&rows);
    let mut worst_by_bands = Vec::new();
    for bands in [1usize, 2, 3, 5, 9, 16] {
        let nn = bands * bands;
        let mut out = Columns::zeros(nn, rows.len());
        let table = [bands as f32];
        let custom = Custom {
            label: "sh-eval",
            source: wgsl::SH_EVAL,
            table: Some(&table),
        };
        g.run_custom(&custom, &input, &mut out)
            .expect("SH kernel runs");
        let n = rows.len();
        let mut y = vec![0.0f32; nn];
        let mut worst = 0.0f32;
        for (k, r) in rows.iter().enumerate() {
            sh::eval_into(Vec3::from(*r), bands, &mut y).unwrap();
            for (c, want) in y.iter().enumerate() {
                let got = out.data[c * n + k];
                let err = (got - want).abs();
                worst = worst.max(err);
                assert!(
                    err <= wgsl::SH_EVAL_TOL,
                    "{bands} bands, {r:?}, coefficient {c}: gpu {got} vs scalar {want}"
                );
            }
        }
        worst_by_bands.push((bands, worst));
    }
    say(&format!(
        "sh-eval on the GPU against the scalar kernel: {worst_by_bands:?}"
    ));
}
