//! The SH evaluation kernel (`wgsl::SH_EVAL`, `f32`, up to 32 bands) on a real adapter
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

/// On lavapipe (the CI's adapter), the worst error per band count is within the figures the
/// `wgsl` docs quote: `(bands, bound)` pairs, each applying from that band count on.
fn assert_lavapipe_figures(
    g: &steradian_harness::backend::gpu::Gpu,
    what: &str,
    worst: &[(usize, f32)],
    figures: &[(usize, f32)],
) {
    if !g.adapter_info().contains("llvmpipe") {
        return;
    }
    for &(bands, w) in worst {
        // The figure of the smallest quoted band count at or above `bands`.
        if let Some(&(_, bound)) = figures.iter().find(|(b, _)| bands <= *b) {
            assert!(
                w <= bound,
                "{what}, {bands} bands: {w:e} > the quoted {bound:e}"
            );
        }
    }
}

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
    // Within 0.1 rad of either pole, where the plain recurrence's f32 error grows like l²
    // (4.8e-5 at band 29).
    rows.extend((0..400).map(|k| {
        let theta = rng.range(0.0, 0.1);
        let phi = rng.range(0.0, std::f64::consts::TAU);
        let z = if k % 2 == 0 {
            theta.cos()
        } else {
            -theta.cos()
        };
        [
            (theta.sin() * phi.cos()) as f32,
            (theta.sin() * phi.sin()) as f32,
            z as f32,
        ]
    }));
    let input = Columns::from_rows(&rows);
    let mut worst_by_bands = Vec::new();
    for bands in [1usize, 2, 3, 5, 9, 16, 20, 30, 32] {
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
    assert_lavapipe_figures(
        &g,
        "sh-eval",
        &worst_by_bands,
        &[(9, 1e-6), (16, 2e-6), (32, 4e-6)],
    );
}

/// Axes of the GPU tests: random, the poles, the equator, non-unit, zero.
fn axes(rng: &mut Rng, count: usize) -> Vec<[f32; 3]> {
    let mut rows: Vec<[f32; 3]> = (0..count).map(|_| rng.sphere().map(|c| c as f32)).collect();
    rows.extend([
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.3, -0.4, 0.0],
        [3e4, -2e4, 1e4],
        [0.0, 0.0, 0.0],
    ]);
    rows
}

#[test]
fn sh_cap_gpu_matches_scalar() {
    let Some(mut g) = gpu() else { return };
    let mut rng = Rng::new(0xca9);
    // Half-angles from 1e-4 rad to π, the hemisphere; then bad ones (NaN on the GPU).
    let angles = [
        1e-4f32,
        1e-3,
        0.05,
        0.5,
        core::f32::consts::FRAC_PI_2,
        2.2,
        core::f32::consts::PI,
    ];
    let mut rows: Vec<[f32; 4]> = axes(&mut rng, 1500)
        .into_iter()
        .enumerate()
        .map(|(k, d)| [d[0], d[1], d[2], angles[k % angles.len()]])
        .collect();
    let bad = [f32::NAN, -0.1, 3.2];
    rows.extend(bad.map(|a| [0.0, 0.0, 1.0, a]));
    let input = Columns::from_rows(&rows);
    let mut worst_by_bands = Vec::new();
    for bands in [1usize, 2, 3, 5, 9, 16, 20, 30, 32] {
        let nn = bands * bands;
        let mut out = Columns::zeros(nn, rows.len());
        let table = [bands as f32];
        let custom = Custom {
            label: "sh-cap",
            source: wgsl::SH_CAP,
            table: Some(&table),
        };
        g.run_custom(&custom, &input, &mut out)
            .expect("SH cap kernel runs");
        let n = rows.len();
        let mut want = vec![0.0f32; nn];
        let mut worst = 0.0f32;
        for (k, r) in rows.iter().enumerate() {
            let axis = Vec3::new(r[0], r[1], r[2]);
            if sh::cap::coefficients_into(axis, r[3], bands, &mut want).is_err() {
                for c in 0..nn {
                    assert!(out.data[c * n + k].is_nan(), "bad half-angle {}", r[3]);
                }
                continue;
            }
            let omega = 4.0 * core::f32::consts::PI * (0.5 * r[3]).sin().powi(2);
            for (c, w) in want.iter().enumerate() {
                let got = out.data[c * n + k];
                let err = (got - w).abs() / omega;
                worst = worst.max(err);
                assert!(
                    err <= wgsl::SH_CAP_TOL,
                    "{bands} bands, {r:?}, coefficient {c}: gpu {got} vs scalar {w} ({err:e} of the solid angle)"
                );
            }
        }
        worst_by_bands.push((bands, worst));
    }
    say(&format!(
        "sh-cap on the GPU against the scalar kernel (per unit of the cap's solid angle): {worst_by_bands:?}"
    ));
    assert_lavapipe_figures(
        &g,
        "sh-cap",
        &worst_by_bands,
        &[(9, 1e-6), (16, 2e-6), (32, 4e-6)],
    );
}

#[test]
fn sh_irradiance_gpu_matches_scalar() {
    let Some(mut g) = gpu() else { return };
    let mut rng = Rng::new(0x1aad);
    let rows = axes(&mut rng, 2000);
    let input = Columns::from_rows(&rows);
    let mut worst_by_bands = Vec::new();
    for bands in [1usize, 2, 3, 5, 9, 16, 20, 30, 32] {
        let nn = bands * bands;
        let radiance: Vec<f32> = (0..nn).map(|_| rng.range(-1.0, 2.0) as f32).collect();
        let mut table = vec![bands as f32];
        table.extend((0..bands).map(|l| sh::irradiance::clamped_cosine(l) as f32));
        table.extend(&radiance);
        let scale: f32 = (0..bands)
            .map(|l| {
                let a = sh::irradiance::clamped_cosine(l).abs() as f32;
                a * radiance[l * l..(l + 1) * (l + 1)]
                    .iter()
                    .map(|v| v.abs())
                    .sum::<f32>()
            })
            .sum();
        let mut out = Columns::zeros(1, rows.len());
        let custom = Custom {
            label: "sh-irradiance",
            source: wgsl::SH_IRRADIANCE,
            table: Some(&table),
        };
        g.run_custom(&custom, &input, &mut out)
            .expect("SH irradiance kernel runs");
        let mut basis = vec![0.0f32; nn];
        let mut worst = 0.0f32;
        for (k, r) in rows.iter().enumerate() {
            let want = sh::irradiance::irradiance(&radiance, Vec3::from(*r), &mut basis).unwrap();
            let err = (out.data[k] - want).abs() / scale;
            worst = worst.max(err);
            assert!(
                err <= wgsl::SH_IRRADIANCE_TOL,
                "{bands} bands, {r:?}: gpu {} vs scalar {want} ({err:e} of Σ|A||L|)",
                out.data[k]
            );
        }
        worst_by_bands.push((bands, worst));
    }
    say(&format!(
        "sh-irradiance on the GPU against the scalar kernel (per unit of Σ|A_l||L_lm|): {worst_by_bands:?}"
    ));
    assert_lavapipe_figures(&g, "sh-irradiance", &worst_by_bands, &[(32, 1e-7)]);
}

/// `n²`-long coefficient vectors as the first `n²` columns of a batch, with `extra` more
/// columns (zeros) after them.
fn vector_columns(vectors: &[Vec<f32>], nn: usize, extra: usize) -> Columns {
    let count = vectors.len();
    let mut input = Columns::zeros(nn + extra, count);
    for (i, v) in vectors.iter().enumerate() {
        for (k, x) in v.iter().enumerate() {
            input.data[k * count + i] = *x;
        }
    }
    input
}

/// A GPU rotation's output columns against the scalar kernel's `want(i, vector, out)` for
/// every vector, each coefficient of the first `max_bands` bands within `tol` of its input
/// band's norm, every coefficient beyond NaN; the largest difference in those units.
fn rotation_error(
    what: &str,
    vectors: &[Vec<f32>],
    (bands, max_bands): (usize, usize),
    out: &Columns,
    tol: f32,
    mut want: impl FnMut(usize, &[f32], &mut [f32]),
) -> f32 {
    let (count, nn) = (vectors.len(), bands * bands);
    let mut w = vec![0.0f32; nn];
    let mut worst = 0.0f32;
    for (i, v) in vectors.iter().enumerate() {
        want(i, v, &mut w);
        for k in (max_bands.min(bands) * max_bands.min(bands))..nn {
            let got = out.data[k * count + i];
            assert!(
                got.is_nan(),
                "{what}, {bands} bands, vector {i}, coefficient {k}: {got}"
            );
        }
        for l in 0..bands.min(max_bands) {
            let band = l * l..(l + 1) * (l + 1);
            let norm = v[band.clone()].iter().map(|x| x * x).sum::<f32>().sqrt();
            for k in band {
                let got = out.data[k * count + i];
                let err = (got - w[k]).abs() / norm.max(f32::MIN_POSITIVE);
                worst = worst.max(err);
                assert!(
                    err <= tol,
                    "{what}, {bands} bands, vector {i}, coefficient {k}: gpu {got} vs scalar {} ({err:e} of the band's norm)",
                    w[k]
                );
            }
        }
    }
    worst
}

#[test]
fn sh_rotate_gpu_matches_scalar() {
    let Some(mut g) = gpu() else { return };
    let mut rng = Rng::new(0x707);
    let rot = sh::rotate::Rotation::from_axis_angle(Vec3::new(0.3, -0.5, 0.8), 1.1).unwrap();
    let mut worst_by_bands = Vec::new();
    for bands in [1usize, 2, 3, 5, 10, 30, 32, 40] {
        let nn = bands * bands;
        let op = sh::rotate::Operator::new(&rot, bands).unwrap();
        let count = 300;
        let vectors: Vec<Vec<f32>> = (0..count)
            .map(|_| (0..nn).map(|_| rng.range(-2.0, 2.0) as f32).collect())
            .collect();
        let input = vector_columns(&vectors, nn, 0);
        let mut table = vec![bands as f32];
        table.extend_from_slice(op.blocks());
        let mut out = Columns::zeros(nn, count);
        let custom = Custom {
            label: "sh-rotate",
            source: wgsl::SH_ROTATE,
            table: Some(&table),
        };
        g.run_custom(&custom, &input, &mut out)
            .expect("SH rotation kernel runs");
        let worst = rotation_error(
            "operator",
            &vectors,
            (bands, wgsl::SH_ROTATE_MAX_BANDS),
            &out,
            wgsl::SH_ROTATE_TOL,
            |_, v, w| op.apply(v, w).unwrap(),
        );
        worst_by_bands.push((bands, worst));
    }
    say(&format!(
        "sh-rotate (built operator) on the GPU against the scalar kernel (per unit of the band's norm): {worst_by_bands:?}"
    ));
}

#[test]
fn sh_rotate_zxzxz_gpu_matches_scalar() {
    use sh::rotate::{Rotation, rotate_zxzxz, x90_into};
    let Some(mut g) = gpu() else { return };
    let mut rng = Rng::new(0x2a2);
    // General rotations, then the exact cases and the Euler singularities: about z, a
    // half-turn about a horizontal axis, β = 0 and β = π up to 1e-6, tiny angles.
    let mut rots: Vec<Rotation> = (0..40)
        .map(|_| {
            let a = rng.sphere();
            let axis = Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32);
            Rotation::from_axis_angle(axis, rng.range(-3.1, 3.1) as f32).unwrap()
        })
        .collect();
    for (axis, angle) in [
        (Vec3::Z, 0.7f32),
        (Vec3::Z, -2.9),
        (Vec3::X, std::f32::consts::PI),
        (Vec3::new(0.6, 0.8, 0.0), std::f32::consts::PI),
        (Vec3::X, 1e-6),
        (Vec3::new(1.0, 1.0, 0.0), std::f32::consts::PI - 1e-6),
        (Vec3::new(0.2, -0.3, 0.9), 1e-6),
    ] {
        rots.push(Rotation::from_axis_angle(axis, angle).unwrap());
    }
    // Exact half-turns about horizontal axes (the scalar kernel's sign-flip path).
    rots.push(Rotation::new([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]).unwrap());
    rots.push(Rotation::new([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]]).unwrap());
    assert!(rots.iter().any(|r| r.gpu_row()[0] == 1.0));
    let mut worst_by_bands = Vec::new();
    for bands in [1usize, 2, 3, 5, 10, 16, 29, 30, 32, 34] {
        let nn = bands * bands;
        let count = rots.len() * 8;
        let vectors: Vec<Vec<f32>> = (0..count)
            .map(|_| (0..nn).map(|_| rng.range(-2.0, 2.0) as f32).collect())
            .collect();
        let mut input = vector_columns(&vectors, nn, 7);
        for i in 0..count {
            for (k, x) in rots[i % rots.len()].gpu_row().iter().enumerate() {
                input.data[(nn + k) * count + i] = *x;
            }
        }
        let mut blocks = vec![0.0f32; sh::rotate::operator_len(bands)];
        let mut scratch = vec![0.0f64; sh::rotate::scratch_len(bands)];
        x90_into(bands, &mut blocks, &mut scratch).unwrap();
        let mut table = vec![bands as f32];
        table.extend_from_slice(&blocks);
        let mut out = Columns::zeros(nn, count);
        let custom = Custom {
            label: "sh-rotate-zxzxz",
            source: wgsl::SH_ROTATE_ZXZXZ,
            table: Some(&table),
        };
        g.run_custom(&custom, &input, &mut out)
            .expect("SH ZXZXZ rotation kernel runs");
        let worst = rotation_error(
            "ZXZXZ",
            &vectors,
            (bands, wgsl::SH_ROTATE_ZXZXZ_MAX_BANDS),
            &out,
            wgsl::SH_ROTATE_ZXZXZ_TOL,
            |i, v, w| rotate_zxzxz(&blocks, &rots[i % rots.len()], bands, v, w).unwrap(),
        );
        // The exact cases stay exact in structure: about z, every m = 0 coefficient is
        // unchanged (bit for bit, no J block is applied).
        for (i, v) in vectors.iter().enumerate() {
            if rots[i % rots.len()].gpu_row()[0] == 0.0 {
                for l in 0..bands.min(wgsl::SH_ROTATE_ZXZXZ_MAX_BANDS) {
                    let k = l * l + l;
                    assert_eq!(out.data[k * count + i], v[k], "about z, m = 0 of band {l}");
                }
            }
        }
        worst_by_bands.push((bands, worst));
    }
    say(&format!(
        "sh-rotate (ZXZXZ) on the GPU against the scalar kernel (per unit of the band's norm): {worst_by_bands:?}"
    ));
}

#[test]
fn sh_hvl_gpu_matches_scalar() {
    use sh::hvl::Horizon;
    let Some(mut g) = gpu() else { return };
    for (horizon, source, name) in [
        (Horizon::Smoothstep, wgsl::SH_HVL, "sh-hvl"),
        (Horizon::Exact, wgsl::SH_HVL_EXACT, "sh-hvl-exact"),
    ] {
        hvl_case(&mut g, horizon, source, name);
    }
}

fn hvl_case(
    g: &mut steradian_harness::backend::gpu::Gpu,
    horizon: sh::hvl::Horizon,
    source: &'static str,
    name: &'static str,
) {
    use sh::hvl::{Hvl, Receiver, contribution};
    let mut rng = Rng::new(0x4f1);
    let v = |a: [f64; 3]| Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32);
    let mut worst_by_bands = Vec::new();
    for (n, ne) in [(1usize, 1usize), (3, 1), (5, 3), (9, 1), (14, 5), (16, 9)] {
        let coeffs: Vec<f32> = (0..n * n).map(|_| rng.range(-0.5, 1.0) as f32).collect();
        let emission: Vec<f32> = (0..ne * ne).map(|_| rng.range(0.0, 0.5) as f32).collect();
        let normal = v(rng.sphere());
        let wo = (normal + v(rng.sphere()) * 0.5).normalize();
        let rx = Receiver {
            point: Vec3::new(0.1, -0.2, 0.3),
            frame: sh::brdf::view_frame(normal, wo).unwrap(),
            coeffs: &coeffs,
        };
        let mut hvls: Vec<Hvl> = (0..2000)
            .map(|_| {
                let d = rng.range(0.05f64.ln(), 20f64.ln()).exp() as f32;
                let p = rx.point + v(rng.sphere()) * d;
                let r = rng.range(0.01f64.ln(), 2f64.ln()).exp() as f32;
                Hvl::new(
                    p,
                    v(rng.sphere()),
                    v(rng.sphere()),
                    r,
                    rng.range(0.0, 5.0) as f32,
                )
                .unwrap()
            })
            .collect();
        // Small caps (1e-4 to 1e-2 rad) straddling the receiver's horizon, facing it.
        let t = rx.frame.normal().any_orthonormal_vector();
        for i in 0..200 {
            let a = 10f32.powf(-4.0 + 2.0 * (i % 10) as f32 / 9.0);
            let k = -1.2 + 2.4 * (i / 10) as f32 / 19.0;
            let th = std::f32::consts::FRAC_PI_2 + k * a;
            let dir = rx.frame.normal() * th.cos() + t * th.sin();
            let d = 3.0;
            hvls.push(Hvl::new(rx.point + dir * d, -dir, -dir, d * a.sin(), 1.0).unwrap());
        }
        let rows = steradian_harness::sh::hvl_gpu_rows(&hvls);
        let table = steradian_harness::sh::hvl_gpu_table(&rx, &emission);
        let input = Columns::from_rows(&rows);
        let mut out = Columns::zeros(1, rows.len());
        let custom = Custom {
            label: name,
            source,
            table: Some(&table),
        };
        g.run_custom(&custom, &input, &mut out)
            .expect("HVL kernel runs");
        let mut scratch = vec![0.0f32; n.max(ne) * n.max(ne)];
        let want: Vec<f32> = hvls
            .iter()
            .map(|h| contribution(h, &emission, &rx, horizon, &mut scratch).unwrap())
            .collect();
        let scale = want.iter().fold(0.0f32, |m, w| m.max(w.abs()));
        let mut worst = 0.0f32;
        for (k, w) in want.iter().enumerate() {
            let err = (out.data[k] - w).abs() / scale;
            worst = worst.max(err);
            assert!(
                err <= wgsl::SH_HVL_TOL,
                "{name}: {n}/{ne} bands, HVL {k}: gpu {} vs scalar {w} ({err:e} of the largest)",
                out.data[k]
            );
        }
        // The small caps near the horizon, each against its own value (the horizon term
        // decides it: a cancelling form would lose these entirely in f32).
        let mut worst_rel = 0.0f32;
        for (k, w) in want.iter().enumerate().skip(2000) {
            let err = (out.data[k] - w).abs() / (w.abs() + 1e-6 * scale);
            worst_rel = worst_rel.max(err);
            assert!(
                err <= 2e-4,
                "{name}: {n}/{ne} bands, small cap {k}: gpu {} vs scalar {w}",
                out.data[k]
            );
        }
        worst_by_bands.push((n, ne, worst));
        say(&format!(
            "{name}, {n}/{ne} bands: small caps at the horizon within {worst_rel:e} of their own value"
        ));
    }
    say(&format!(
        "{name} on the GPU against the scalar kernel (per unit of the largest contribution): {worst_by_bands:?}"
    ));
}
