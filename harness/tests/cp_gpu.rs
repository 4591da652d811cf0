//! The control-point query kernel (`wgsl::CP_QUERY`) on a real adapter against the scalar
//! query within `wgsl::CP_QUERY_TOL`·max|v| at every level, for both weight kinds: random
//! directions of many lengths, and the hard ones (poles, axes, vertices, edge midpoints,
//! huge and tiny lengths) with gnomonic weights (on an edge the kernel may pick the other
//! triangle, where only the gnomonic weights are continuous); zero and non-finite
//! directions give NaN (naga validation is in `wgsl_validate.rs`).
//!
//! Without an adapter the GPU test prints `GPU tests skipped: <reason>` and passes, unless
//! `STERADIAN_REQUIRE_GPU=1`, in which case it fails.

use steradian_core::cp::{Icosphere, Weights};
use steradian_core::{Vec3, wgsl};
use steradian_harness::backend::gpu::Custom;
use steradian_harness::kernels::Columns;
use steradian_harness::rng::Rng;

use crate::common::gpu as gpu_common;
use gpu_common::{gpu, say};

#[test]
fn cp_query_gpu_matches_scalar() {
    let Some(mut g) = gpu() else { return };
    let mut rng = Rng::new(0x0c9_6a0);
    let mut worst = Vec::new();
    for level in 0..=4u32 {
        let mesh = Icosphere::new(level).unwrap();
        let values: Vec<f32> = (0..mesh.vertices().len())
            .map(|_| rng.range(-2.0, 3.0) as f32)
            .collect();
        let random: Vec<[f32; 3]> = (0..2000)
            .map(|_| {
                let len = rng.log_range(1e-20, 1e20);
                rng.sphere().map(|c| (c * len) as f32)
            })
            .collect();
        let mut hard: Vec<[f32; 3]> = vec![
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [-0.0, 0.0, 1.0],
            [3e30, -2e30, 1e30],
            [1e-38, 2e-38, -1e-38],
        ];
        for t in mesh.triangles().iter().step_by(5) {
            let v = t.map(|k| mesh.vertices()[k as usize]);
            hard.push(v[0].into());
            hard.push(((v[0] + v[1]) * 0.5).into());
            hard.push(((v[0] + v[1] + v[2]) * 7.0).into());
        }
        let bad: Vec<[f32; 3]> = vec![
            [0.0, 0.0, 0.0],
            [f32::NAN, 0.0, 1.0],
            [f32::INFINITY, 0.0, 0.0],
        ];
        for w in [Weights::Area, Weights::Gnomonic] {
            let mut rows = random.clone();
            if w == Weights::Gnomonic {
                rows.extend(&hard);
            }
            rows.extend(&bad);
            let input = Columns::from_rows(&rows);
            let mut out = Columns::zeros(1, rows.len());
            let table = mesh.gpu_table(&values, w).unwrap();
            let custom = Custom {
                label: "cp-query",
                source: wgsl::CP_QUERY,
                table: Some(&table),
            };
            g.run_custom(&custom, &input, &mut out)
                .expect("cp kernel runs");
            let mut level_worst = 0.0f32;
            for (k, r) in rows.iter().enumerate() {
                let got = out.data[k];
                match mesh.locate(Vec3::from(*r), w) {
                    Err(_) => assert!(got.is_nan(), "level {level} {w:?} {r:?}: gpu {got}"),
                    Ok(l) => {
                        let want = l.interpolate(&values);
                        let m = l
                            .vertices
                            .iter()
                            .map(|v| values[*v as usize].abs())
                            .fold(0.0f32, f32::max);
                        let e = (got - want).abs() / m.max(f32::MIN_POSITIVE);
                        level_worst = level_worst.max(e);
                        assert!(
                            e <= wgsl::CP_QUERY_TOL,
                            "level {level} {w:?} {r:?}: gpu {got} vs scalar {want}"
                        );
                    }
                }
            }
            worst.push((level, w, level_worst));
        }
    }
    say(&format!(
        "cp-query on the GPU against the scalar kernel (|Δ|/max|v|): {worst:?}"
    ));
}
