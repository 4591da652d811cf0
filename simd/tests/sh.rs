//! The SH batch kernel lane by lane against `steradian_core::sh::eval_into`: bit-identical
//! for random directions, the named special values in every component and lane position
//! (NaN, ±∞, ±0, subnormals, huge and tiny), the poles and the equator, every slice length
//! around the batch size and band counts from 0 to `MAX_BANDS`.

use glam::Vec3;
use steradian_core::sh::{self, MAX_BANDS};
use steradian_simd::sh::{SLICE_LANES, eval_slices, eval_x4, eval_x8};

use crate::common::lanes::{LENGTHS, in_every_lane, same};
use crate::common::rng::Rng;
use crate::common::specials::{SPECIALS, in_each_component};

fn scalar(d: Vec3, bands: usize) -> Vec<f32> {
    let mut out = vec![0.0; bands * bands];
    sh::eval_into(d, bands, &mut out).expect("valid band count");
    out
}

/// `eval_slices` on `rows` against the scalar kernel, every coefficient of every row.
fn check(rows: &[Vec3], bands: usize) {
    let n = rows.len();
    let col = |f: fn(&Vec3) -> f32| rows.iter().map(f).collect::<Vec<f32>>();
    let (x, y, z) = (col(|d| d.x), col(|d| d.y), col(|d| d.z));
    let mut out = vec![0.0; bands * bands * n];
    eval_slices(&x, &y, &z, bands, &mut out).expect("valid shapes");
    for (i, d) in rows.iter().enumerate() {
        let want = scalar(*d, bands);
        for (k, w) in want.iter().enumerate() {
            let got = out[k * n + i];
            assert!(
                same(got, *w),
                "{d} bands {bands} coefficient {k}: {got} vs {w}"
            );
        }
    }
}

#[test]
fn random_directions_every_length_and_band_count() {
    let mut rng = Rng(0x5eed_0005);
    // Lengths of exactly one pass (4 and 8 lanes) take their own store path in the loop's
    // band counts (11 and up).
    for bands in [0usize, 1, 2, 3, 4, 5, 9, 10, 11, 17, 30] {
        for len in LENGTHS.into_iter().chain([4, SLICE_LANES]) {
            let rows: Vec<Vec3> = (0..len)
                .map(|_| rng.dir() * rng.log_range(1e-3, 1e3))
                .collect();
            check(&rows, bands);
        }
    }
}

#[test]
fn special_values_in_every_component_and_lane() {
    let rows: Vec<Vec3> = in_each_component()
        .into_iter()
        .chain([
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.6, 0.8, 0.0),
            Vec3::ZERO,
        ])
        .collect();
    in_every_lane(&rows, Vec3::new(0.2, -0.3, 0.9), |r| {
        check(r, 6);
        // The loop's band counts, and each row in every lane of one exact pass.
        check(r, 12);
        for pass in r.chunks(SLICE_LANES) {
            check(pass, 12);
        }
    });
}

#[test]
fn many_bands_and_the_x4_entry_point() {
    let mut rng = Rng(7);
    let dirs: [Vec3; 4] = core::array::from_fn(|_| rng.dir());
    // Every band count with generated straight-line code (2–10), its neighbours, and the
    // loop beyond.
    for bands in (1usize..=11).chain([MAX_BANDS]) {
        let mut out = vec![[0.0f32; 4]; bands * bands];
        eval_x4(dirs, bands, &mut out).expect("valid band count");
        for (lane, d) in dirs.iter().enumerate() {
            let want = scalar(*d, bands);
            for (k, w) in want.iter().enumerate() {
                assert!(same(out[k][lane], *w), "bands {bands} lane {lane} k {k}");
            }
        }
    }
}

#[test]
fn the_x8_entry_point_every_lane_with_special_values() {
    let mut rng = Rng(8);
    let mut dirs: [Vec3; 8] = core::array::from_fn(|_| rng.dir());
    // Special directions in some lanes: the poles, the zero vector, NaN and a subnormal.
    dirs[1] = Vec3::Z;
    dirs[3] = Vec3::ZERO;
    dirs[5] = Vec3::new(f32::NAN, 0.0, 1.0);
    dirs[6] = Vec3::new(1e-45, 0.0, -1e-45);
    dirs[7] = -Vec3::Z;
    for bands in (1usize..=11).chain([30, MAX_BANDS]) {
        let mut out = vec![[0.0f32; 8]; bands * bands];
        eval_x8(dirs, bands, &mut out).expect("valid band count");
        for (lane, d) in dirs.iter().enumerate() {
            let want = scalar(*d, bands);
            for (k, w) in want.iter().enumerate() {
                assert!(same(out[k][lane], *w), "bands {bands} lane {lane} k {k}");
            }
        }
    }
    let mut short = vec![[0.0f32; 8]; 3];
    assert!(eval_x8([Vec3::Z; 8], 2, &mut short).is_err());
}

#[test]
fn bad_shapes_are_errors() {
    let mut out = vec![0.0; 8];
    assert!(eval_slices(&[0.0; 2], &[0.0; 2], &[1.0; 2], 2, &mut out).is_ok());
    assert!(eval_slices(&[0.0; 2], &[0.0; 3], &[1.0; 2], 2, &mut out).is_err());
    assert!(eval_slices(&[0.0; 2], &[0.0; 2], &[1.0; 2], 3, &mut out).is_err());
    assert!(eval_slices(&[], &[], &[], MAX_BANDS + 1, &mut []).is_err());
    let mut short = vec![[0.0f32; 4]; 3];
    assert!(eval_x4([Vec3::Z; 4], 2, &mut short).is_err());
}

/// `apply_operator_slices` on `vectors` (each `bands²` long, one after another) against the
/// scalar `apply_operator`, bit for bit, every coefficient of every vector.
fn check_rotation(op: &[f32], bands: usize, vectors: &[Vec<f32>]) {
    let nn = bands * bands;
    let input: Vec<f32> = vectors.concat();
    let mut out = vec![0.0f32; input.len()];
    steradian_simd::sh::rotate::apply_operator_slices(op, bands, &input, &mut out)
        .expect("valid shapes");
    let mut want = vec![0.0f32; nn];
    for (v, x) in vectors.iter().enumerate() {
        sh::rotate::apply_operator(op, bands, x, &mut want).expect("valid shapes");
        for (k, w) in want.iter().enumerate() {
            let got = out[v * nn + k];
            assert!(
                same(got, *w),
                "bands {bands} vector {v} coefficient {k}: {got} vs {w}"
            );
        }
    }
}

#[test]
fn rotation_operator_lanes_equal_the_scalar_kernel() {
    let mut rng = Rng(0x0707);
    let rot = sh::rotate::Rotation::from_axis_angle(Vec3::new(0.3, -0.5, 0.8), 1.1).unwrap();
    for bands in [0usize, 1, 2, 5, 12, 30] {
        let op = sh::rotate::Operator::new(&rot, bands).unwrap();
        let nn = bands * bands;
        for &len in &LENGTHS {
            let vectors: Vec<Vec<f32>> = (0..len.min(40))
                .map(|_| (0..nn).map(|_| rng.range(-2.0, 2.0)).collect())
                .collect();
            check_rotation(op.blocks(), bands, &vectors);
        }
        // Special values in one coefficient of one vector, in every lane position: the
        // other lanes are untouched and the lane itself matches the scalar kernel.
        if nn > 0 {
            let base: Vec<f32> = (0..nn).map(|k| (k as f32 * 0.37).sin()).collect();
            for &sp in SPECIALS.iter() {
                let mut odd = base.clone();
                odd[nn / 2] = sp;
                // The odd vector in every lane position (0..8 ordinary ones in front).
                for shift in 0..8 {
                    let mut rows = vec![base.clone(); shift];
                    rows.push(odd.clone());
                    check_rotation(op.blocks(), bands, &rows);
                }
            }
        }
    }
    // Shapes: not a whole number of vectors, out of another length, a short operator.
    let op = sh::rotate::Operator::new(&rot, 3).unwrap();
    let mut out = vec![0.0f32; 18];
    assert!(
        steradian_simd::sh::rotate::apply_operator_slices(
            op.blocks(),
            3,
            &[0.0; 17],
            &mut out[..17]
        )
        .is_err()
    );
    assert!(
        steradian_simd::sh::rotate::apply_operator_slices(
            op.blocks(),
            3,
            &[0.0; 18],
            &mut out[..9]
        )
        .is_err()
    );
    assert!(
        steradian_simd::sh::rotate::apply_operator_slices(
            &op.blocks()[..10],
            3,
            &[0.0; 18],
            &mut out
        )
        .is_err()
    );
}

/// `rotate_zxzxz_slices` on `vectors` with their rotations against the scalar
/// `rotate_zxzxz`, bit for bit, every coefficient of every vector.
fn check_zxzxz(x90: &[f32], rots: &[sh::rotate::Rotation], bands: usize, vectors: &[Vec<f32>]) {
    let nn = bands * bands;
    let input: Vec<f32> = vectors.concat();
    let mut out = vec![0.0f32; input.len()];
    steradian_simd::sh::rotate::rotate_zxzxz_slices(x90, rots, bands, &input, &mut out)
        .expect("valid shapes");
    let mut want = vec![0.0f32; nn];
    for (v, x) in vectors.iter().enumerate() {
        sh::rotate::rotate_zxzxz(x90, &rots[v], bands, x, &mut want).expect("valid shapes");
        for (k, w) in want.iter().enumerate() {
            let got = out[v * nn + k];
            assert!(
                same(got, *w),
                "bands {bands} vector {v} coefficient {k}: {got} vs {w}"
            );
        }
    }
}

/// Rotations of every path of the scalar kernel: general ones, about `z` (the identity
/// included), half-turns about horizontal axes, and the near-singular Euler angles; each
/// path is present (asserted).
fn every_kind_of_rotation(rng: &mut Rng) -> Vec<sh::rotate::Rotation> {
    use sh::rotate::{Euler, Rotation};
    let axis_angle = |a: Vec3, t: f32| Rotation::from_axis_angle(a, t).unwrap();
    let mut rots = vec![
        Rotation::identity(),
        axis_angle(Vec3::Z, 0.7),
        axis_angle(-Vec3::Z, 3.0),
        // Half-turns about horizontal axes, exactly (an f32 angle of π is not one): x, and
        // the diagonal of the xy-plane.
        Rotation::new([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]).unwrap(),
        Rotation::new([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]]).unwrap(),
        axis_angle(Vec3::X, 1e-6),
        axis_angle(Vec3::new(0.0, 1.0, 1e-6), 2.0),
        axis_angle(Vec3::Y, core::f32::consts::PI - 1e-6),
    ];
    for _ in 0..16 {
        rots.push(axis_angle(rng.dir(), rng.range(-3.2, 3.2)));
    }
    let path = |k: usize| match rots[k].euler() {
        Euler::AboutZ(_) => 0,
        Euler::HalfTurn(_) => 1,
        Euler::General { .. } => 2,
    };
    assert_eq!(
        (0..rots.len()).map(path).collect::<Vec<_>>()[..9],
        [0, 0, 0, 1, 1, 2, 2, 2, 2]
    );
    rots
}

#[test]
fn zxzxz_lanes_equal_the_scalar_kernel() {
    let mut rng = Rng(0x2a2a);
    let kinds = every_kind_of_rotation(&mut rng);
    // 40 bands: beyond the 32 whose blocks the batch widens to f64, the f32 block is read.
    for bands in [0usize, 1, 2, 3, 5, 10, 12, 30, 40] {
        let nn = bands * bands;
        let mut x90_table = vec![0.0f32; sh::rotate::operator_len(bands)];
        let mut scratch = vec![0.0f64; sh::rotate::scratch_len(bands)];
        sh::rotate::x90_into(bands, &mut x90_table, &mut scratch).unwrap();
        for &len in &LENGTHS {
            let len = len.min(60);
            let vectors: Vec<Vec<f32>> = (0..len)
                .map(|_| (0..nn).map(|_| rng.range(-2.0, 2.0)).collect())
                .collect();
            // Rotations of every kind in every lane position, mixed within a pass.
            let rots: Vec<_> = (0..len)
                .map(|v| kinds[(v * 7 + len) % kinds.len()])
                .collect();
            check_zxzxz(&x90_table, &rots, bands, &vectors);
            // All lanes of one kind: the passes that skip a path.
            for kind in [0usize, 3, 8] {
                check_zxzxz(&x90_table, &vec![kinds[kind]; len], bands, &vectors);
            }
        }
        // Special values in one coefficient of one vector, in every lane position, under a
        // general rotation and an exact one: the lane matches the scalar kernel and the
        // others are untouched.
        if nn > 0 {
            let base: Vec<f32> = (0..nn).map(|k| (k as f32 * 0.37).sin()).collect();
            for &sp in SPECIALS.iter() {
                let mut odd = base.clone();
                odd[nn / 2] = sp;
                for shift in 0..4 {
                    let mut rows = vec![base.clone(); shift];
                    rows.push(odd.clone());
                    rows.push(base.clone());
                    for rot in [kinds[9], kinds[3]] {
                        check_zxzxz(&x90_table, &vec![rot; rows.len()], bands, &rows);
                    }
                }
            }
        }
    }
}

/// The four-lane entry point (which reads the f32 block directly) lane by lane against the
/// scalar kernel, every kind of rotation in every lane, special values in one lane.
#[test]
fn zxzxz_x4_lanes_equal_the_scalar_kernel() {
    use steradian_simd::sh::rotate::rotate_zxzxz_x4;
    let mut rng = Rng(0x2b2b);
    let kinds = every_kind_of_rotation(&mut rng);
    for bands in [1usize, 2, 3, 7, 10, 33] {
        let nn = bands * bands;
        let mut x90 = vec![0.0f32; sh::rotate::operator_len(bands)];
        let mut scratch = vec![0.0f64; sh::rotate::scratch_len(bands)];
        sh::rotate::x90_into(bands, &mut x90, &mut scratch).unwrap();
        for (pass, sp) in [0.0f32]
            .iter()
            .chain(SPECIALS.iter().step_by(5))
            .enumerate()
        {
            let rots: [&sh::rotate::Rotation; 4] =
                core::array::from_fn(|j| &kinds[(pass * 4 + j * 3) % kinds.len()]);
            let mut vectors: Vec<Vec<f32>> = (0..4)
                .map(|_| (0..nn).map(|_| rng.range(-2.0, 2.0)).collect())
                .collect();
            if pass > 0 {
                vectors[pass % 4][nn / 2] = *sp;
            }
            let input: Vec<[f32; 4]> = (0..nn)
                .map(|k| core::array::from_fn(|j| vectors[j][k]))
                .collect();
            let mut out = vec![[0.0f32; 4]; nn];
            rotate_zxzxz_x4(&x90, rots, bands, &input, &mut out).expect("valid shapes");
            let mut want = vec![0.0f32; nn];
            for (j, v) in vectors.iter().enumerate() {
                sh::rotate::rotate_zxzxz(&x90, rots[j], bands, v, &mut want).unwrap();
                for (k, w) in want.iter().enumerate() {
                    assert!(
                        same(out[k][j], *w),
                        "bands {bands} pass {pass} lane {j} k {k}: {} vs {w}",
                        out[k][j]
                    );
                }
            }
        }
    }
}

#[test]
fn zxzxz_shapes_are_errors() {
    use sh::rotate::Rotation;
    use steradian_simd::sh::rotate::{rotate_zxzxz_slices, rotate_zxzxz_x4};
    let mut x90 = vec![0.0f32; sh::rotate::operator_len(3)];
    let mut scratch = vec![0.0f64; sh::rotate::scratch_len(3)];
    sh::rotate::x90_into(3, &mut x90, &mut scratch).unwrap();
    let general = Rotation::from_axis_angle(Vec3::new(0.3, -0.5, 0.8), 1.1).unwrap();
    let about_z = Rotation::from_axis_angle(Vec3::Z, 1.1).unwrap();
    let mut out = vec![0.0f32; 18];
    // Not a whole number of vectors; out of another length; a rotation short.
    assert!(rotate_zxzxz_slices(&x90, &[general; 2], 3, &[0.0; 17], &mut out[..17]).is_err());
    assert!(rotate_zxzxz_slices(&x90, &[general; 2], 3, &[0.0; 18], &mut out[..9]).is_err());
    assert!(rotate_zxzxz_slices(&x90, &[general; 1], 3, &[0.0; 18], &mut out).is_err());
    // A short table is an error only where a rotation needs it, as in the scalar kernel.
    assert!(rotate_zxzxz_slices(&x90[..10], &[general; 2], 3, &[0.0; 18], &mut out).is_err());
    assert!(rotate_zxzxz_slices(&x90[..10], &[about_z; 2], 3, &[0.0; 18], &mut out).is_ok());
    assert!(rotate_zxzxz_slices(&x90, &[general; 1], MAX_BANDS + 1, &[], &mut []).is_err());
    let mut short = vec![[0.0f32; 4]; 8];
    assert!(rotate_zxzxz_x4(&x90, [&general; 4], 3, &[[0.0; 4]; 9], &mut short).is_err());
    let mut lanes = vec![[0.0f32; 4]; 9];
    assert!(rotate_zxzxz_x4(&x90[..10], [&general; 4], 3, &[[0.0; 4]; 9], &mut lanes).is_err());
    assert!(rotate_zxzxz_x4(&x90[..10], [&about_z; 4], 3, &[[0.0; 4]; 9], &mut lanes).is_ok());
}

/// `coefficients_slices` on caps `(axis, half-angle)` against the scalar
/// `coefficients_into`, bit for bit, every coefficient of every cap.
fn check_caps(caps: &[(Vec3, f32)], bands: usize) {
    let n = caps.len();
    let col = |f: &dyn Fn(&(Vec3, f32)) -> f32| caps.iter().map(f).collect::<Vec<f32>>();
    let (x, y, z, a) = (
        col(&|c| c.0.x),
        col(&|c| c.0.y),
        col(&|c| c.0.z),
        col(&|c| c.1),
    );
    let mut out = vec![0.0; bands * bands * n];
    steradian_simd::sh::cap::coefficients_slices(&x, &y, &z, &a, bands, &mut out)
        .expect("valid caps");
    let mut want = vec![0.0; bands * bands];
    for (i, (axis, half)) in caps.iter().enumerate() {
        sh::cap::coefficients_into(*axis, *half, bands, &mut want).expect("valid cap");
        for (k, w) in want.iter().enumerate() {
            let got = out[k * n + i];
            assert!(
                same(got, *w),
                "{axis} {half} bands {bands} k {k}: {got} vs {w}"
            );
        }
    }
}

#[test]
fn cap_lanes_equal_the_scalar_kernel() {
    let mut rng = Rng(0x0c0a);
    // Half-angles from 1e-4 rad (the small-cap case) to π (the whole sphere), the hemisphere.
    let angles = [
        0.0f32,
        1e-4,
        1e-3,
        0.3,
        core::f32::consts::FRAC_PI_2,
        2.5,
        core::f32::consts::PI,
    ];
    for bands in [0usize, 1, 3, 5, 10, 30] {
        for len in LENGTHS {
            let caps: Vec<(Vec3, f32)> = (0..len)
                .map(|i| {
                    (
                        rng.dir() * rng.log_range(1e-3, 1e3),
                        angles[i % angles.len()],
                    )
                })
                .collect();
            check_caps(&caps, bands);
        }
    }
    // Special values in the axis, every component and lane position; the poles, zero axis.
    let rows: Vec<(Vec3, f32)> = in_each_component()
        .into_iter()
        .chain([Vec3::Z, -Vec3::Z, Vec3::ZERO])
        .map(|d| (d, 0.7))
        .collect();
    in_every_lane(&rows, (Vec3::new(0.2, -0.3, 0.9), 0.2), |r| {
        check_caps(r, 6)
    });
    // A bad half-angle in any lane is an error, as the scalar kernel's for that cap.
    for bad in [f32::NAN, -0.1, 3.2, f32::INFINITY] {
        let mut out = vec![0.0; 9 * 5];
        let a = [0.5, 0.5, bad, 0.5, 0.5];
        assert!(
            steradian_simd::sh::cap::coefficients_slices(
                &[0.0; 5], &[0.0; 5], &[1.0; 5], &a, 3, &mut out
            )
            .is_err(),
            "{bad}"
        );
        assert!(sh::cap::coefficients_into(Vec3::Z, bad, 3, &mut [0.0; 9]).is_err());
    }
    let mut out = vec![0.0; 9 * 2];
    assert!(
        steradian_simd::sh::cap::coefficients_slices(
            &[0.0; 2],
            &[0.0; 2],
            &[1.0; 2],
            &[0.5],
            3,
            &mut out
        )
        .is_err()
    );
    let mut short = vec![[0.0f32; 4]; 8];
    assert!(
        steradian_simd::sh::cap::coefficients_x4([Vec3::Z; 4], [0.5; 4], 3, &mut short).is_err()
    );
}

/// `irradiance_slices` at `normals` against the scalar `irradiance`, bit for bit.
fn check_irradiance(radiance: &[f32], normals: &[Vec3]) {
    let n = normals.len();
    let bands = sh::bands_of(radiance.len()).expect("square");
    let col = |f: fn(&Vec3) -> f32| normals.iter().map(f).collect::<Vec<f32>>();
    let (x, y, z) = (col(|d| d.x), col(|d| d.y), col(|d| d.z));
    let mut scratch = vec![[0.0f32; 4]; bands * bands];
    let mut out = vec![0.0; n];
    steradian_simd::sh::irradiance::irradiance_slices(radiance, &x, &y, &z, &mut scratch, &mut out)
        .expect("valid shapes");
    let mut basis = vec![0.0; bands * bands];
    for (i, d) in normals.iter().enumerate() {
        let want = sh::irradiance::irradiance(radiance, *d, &mut basis).expect("valid");
        assert!(
            same(out[i], want),
            "{d} bands {bands}: {} vs {want}",
            out[i]
        );
    }
}

#[test]
fn irradiance_lanes_equal_the_scalar_kernel() {
    let mut rng = Rng(0x1aad);
    for bands in [1usize, 2, 3, 5, 9, 30] {
        let radiance: Vec<f32> = (0..bands * bands).map(|_| rng.range(-1.0, 2.0)).collect();
        for len in LENGTHS {
            let normals: Vec<Vec3> = (0..len)
                .map(|_| rng.dir() * rng.log_range(1e-3, 1e3))
                .collect();
            check_irradiance(&radiance, &normals);
        }
    }
    let radiance: Vec<f32> = (0..16).map(|k| (k as f32 * 0.61).cos()).collect();
    let rows: Vec<Vec3> = in_each_component()
        .into_iter()
        .chain([Vec3::Z, -Vec3::Z, Vec3::X, Vec3::ZERO])
        .collect();
    in_every_lane(&rows, Vec3::new(0.2, -0.3, 0.9), |r| {
        check_irradiance(&radiance, r)
    });
    // A special value in the radiance reaches every normal as it does in the scalar kernel.
    for &sp in SPECIALS.iter() {
        let mut odd = radiance.clone();
        odd[5] = sp;
        check_irradiance(&odd, &rows);
    }
    // Shapes: not a square, a short scratch, columns of different lengths.
    let mut scratch = vec![[0.0f32; 4]; 16];
    let mut out = vec![0.0; 3];
    let irr = steradian_simd::sh::irradiance::irradiance_slices;
    assert!(
        irr(
            &[0.0; 15],
            &[0.0; 3],
            &[0.0; 3],
            &[1.0; 3],
            &mut scratch,
            &mut out
        )
        .is_err()
    );
    assert!(
        irr(
            &[0.0; 25],
            &[0.0; 3],
            &[0.0; 3],
            &[1.0; 3],
            &mut scratch,
            &mut out
        )
        .is_err()
    );
    assert!(
        irr(
            &[0.0; 16],
            &[0.0; 3],
            &[0.0; 2],
            &[1.0; 3],
            &mut scratch,
            &mut out
        )
        .is_err()
    );
    assert!(
        irr(
            &[0.0; 16],
            &[0.0; 3],
            &[0.0; 3],
            &[1.0; 3],
            &mut scratch,
            &mut out
        )
        .is_ok()
    );
}

/// `contributions` of `hvls` to one receiver against the scalar `contribution`, bit for bit.
fn check_hvls(hvls: &[sh::hvl::Hvl], emission: &[f32], rx: &sh::hvl::Receiver<'_>) {
    let bands = sh::bands_of(rx.coeffs.len())
        .expect("square")
        .max(sh::bands_of(emission.len()).expect("square"));
    let mut scratch4 = vec![[0.0f32; 4]; bands * bands];
    let mut scratch = vec![0.0f32; bands * bands];
    for horizon in [sh::hvl::Horizon::Smoothstep, sh::hvl::Horizon::Exact] {
        let mut out = vec![0.0f32; hvls.len()];
        steradian_simd::sh::hvl::contributions(
            hvls,
            emission,
            rx,
            horizon,
            &mut scratch4,
            &mut out,
        )
        .expect("valid shapes");
        for (j, h) in hvls.iter().enumerate() {
            let want =
                sh::hvl::contribution(h, emission, rx, horizon, &mut scratch).expect("valid");
            assert!(
                same(out[j], want),
                "HVL {j} {horizon:?}: {} vs {want}",
                out[j]
            );
        }
    }
}

#[test]
fn hvl_lanes_equal_the_scalar_kernel() {
    let mut rng = Rng(0x4f1);
    for (n, ne) in [(1usize, 1usize), (3, 1), (5, 3), (9, 1), (14, 5)] {
        let coeffs: Vec<f32> = (0..n * n).map(|_| rng.range(-0.5, 1.0)).collect();
        let emission: Vec<f32> = (0..ne * ne).map(|_| rng.range(0.0, 0.5)).collect();
        let normal = rng.dir();
        let rx = sh::hvl::Receiver {
            point: Vec3::new(0.1, -0.2, 0.3),
            frame: sh::brdf::view_frame(normal, (normal + rng.dir() * 0.5).normalize())
                .expect("frame"),
            coeffs: &coeffs,
        };
        for len in LENGTHS {
            // Around the receiver at distances 0.05–20, every orientation: some face away,
            // some lie below its horizon, some are larger than their distance.
            let hvls: Vec<sh::hvl::Hvl> = (0..len.min(200))
                .map(|_| {
                    let p = rx.point + rng.dir() * rng.log_range(0.05, 20.0);
                    sh::hvl::Hvl::new(
                        p,
                        rng.dir(),
                        rng.dir(),
                        rng.log_range(0.01, 2.0),
                        rng.range(0.0, 5.0),
                    )
                    .expect("valid HVL")
                })
                .collect();
            check_hvls(&hvls, &emission, &rx);
        }
        // The HVL at the receiver itself, and one lit lane among settled ones in every position.
        let at_point = sh::hvl::Hvl::new(rx.point, Vec3::Z, Vec3::Z, 0.1, 1.0).expect("valid");
        let facing =
            sh::hvl::Hvl::new(rx.point + normal, -normal, Vec3::Z, 0.3, 2.0).expect("valid");
        for k in 0..5 {
            let mut row = vec![at_point; 5];
            row[k] = facing;
            check_hvls(&row, &emission, &rx);
        }
    }
    // Shapes: coefficient counts that are not squares, a short scratch, a short output.
    let coeffs = [0.0f32; 9];
    let rx = sh::hvl::Receiver {
        point: Vec3::ZERO,
        frame: sh::brdf::view_frame(Vec3::Z, Vec3::Z).expect("frame"),
        coeffs: &coeffs,
    };
    let h = sh::hvl::Hvl::new(Vec3::Z, -Vec3::Z, Vec3::Z, 0.1, 1.0).expect("valid");
    let hz = sh::hvl::Horizon::Smoothstep;
    let mut s4 = vec![[0.0f32; 4]; 9];
    let f = steradian_simd::sh::hvl::contributions;
    assert!(f(&[h; 2], &[0.0; 2], &rx, hz, &mut s4, &mut [0.0; 2]).is_err());
    assert!(f(&[h; 2], &[0.0; 1], &rx, hz, &mut s4[..4], &mut [0.0; 2]).is_err());
    assert!(f(&[h; 2], &[0.0; 1], &rx, hz, &mut s4, &mut [0.0; 1]).is_err());
    assert!(f(&[h; 2], &[0.0; 1], &rx, hz, &mut s4, &mut [0.0; 2]).is_ok());
}

/// `contributions_zonal` against the scalar `contribution_zonal`: within `zonal_bound`
/// (`ZONAL_TOL·P·Ē·(G/H)·S̄`, the scalar kernel's terms in absolute value, without the
/// horizon factor); settled lanes and the exact horizon bit for bit. Returns the worst error
/// over that scale and the worst relative error where `H > 0.05` and no sum cancels by more
/// than half.
fn check_zonal(
    hvls: &[sh::hvl::Hvl],
    emission: &[f32],
    rx: &sh::hvl::ZonalReceiver<'_>,
) -> (f64, f64) {
    use steradian_simd::sh::hvl::{ZONAL_TOL, zonal_bound};
    let ne = sh::bands_of(emission.len()).expect("square");
    let n = rx.coeffs.len();
    let mut scratch = vec![0.0f32; n.max(ne * ne)];
    let (mut worst_scale, mut worst_rel) = (0.0f64, 0.0f64);
    for horizon in [sh::hvl::Horizon::Smoothstep, sh::hvl::Horizon::Exact] {
        let mut out = vec![0.0f32; hvls.len()];
        steradian_simd::sh::hvl::contributions_zonal(
            hvls,
            emission,
            rx,
            horizon,
            &mut scratch,
            &mut out,
        )
        .expect("valid shapes");
        for (j, h) in hvls.iter().enumerate() {
            let want =
                sh::hvl::contribution_zonal(h, emission, rx, horizon, &mut scratch).expect("valid");
            let got = out[j];
            let bound = zonal_bound(h, emission, rx).expect("valid shapes");
            let (Some(bound), sh::hvl::Horizon::Smoothstep) = (bound, horizon) else {
                assert!(same(got, want), "HVL {j} {horizon:?}: {got} vs {want}");
                continue;
            };
            let err = (f64::from(got) - f64::from(want)).abs();
            assert!(err <= bound, "HVL {j}: {got} vs {want} (bound {bound:e})");
            let scale = bound / f64::from(ZONAL_TOL);
            if scale > 0.0 {
                worst_scale = worst_scale.max(err / scale);
            }
            // Where no sum cancels by half and the horizon factor is not small.
            let sh::hvl::Prepared::Lit {
                cap_axis,
                half_angle,
                ..
            } = sh::hvl::prepare(h, rx.point, &rx.frame, horizon)
            else {
                continue;
            };
            let hs = sh::hvl::horizon_smoothstep(cap_axis.z, half_angle);
            if hs > 0.05 && 2.0 * f64::from(want).abs() > scale * f64::from(hs) {
                worst_rel = worst_rel.max(err / f64::from(want).abs());
            }
        }
    }
    (worst_scale, worst_rel)
}

#[test]
fn hvl_zonal_lanes_are_within_their_bound_of_the_scalar_kernel() {
    let mut rng = Rng(0x5a7);
    let (mut rel, mut abs) = (0.0f64, 0.0f64);
    for (n, ne) in [(1usize, 1usize), (3, 1), (5, 1), (5, 3), (9, 1), (20, 2)] {
        let coeffs: Vec<f32> = (0..n).map(|_| rng.range(-0.5, 1.0)).collect();
        let emission: Vec<f32> = (0..ne * ne).map(|_| rng.range(0.0, 0.5)).collect();
        let normal = rng.dir();
        let rx = sh::hvl::ZonalReceiver {
            point: Vec3::new(0.1, -0.2, 0.3),
            frame: sh::brdf::view_frame(normal, (normal + rng.dir() * 0.5).normalize())
                .expect("frame"),
            coeffs: &coeffs,
        };
        for len in LENGTHS {
            // Distances 0.05–20 and radii 0.001–2: caps from 5e-5 rad to a half-space, some
            // facing away, some below the horizon, some across it.
            let hvls: Vec<sh::hvl::Hvl> = (0..len.min(400))
                .map(|_| {
                    let p = rx.point + rng.dir() * rng.log_range(0.05, 20.0);
                    sh::hvl::Hvl::new(
                        p,
                        rng.dir(),
                        rng.dir(),
                        rng.log_range(0.001, 2.0),
                        rng.range(0.0, 5.0),
                    )
                    .expect("valid HVL")
                })
                .collect();
            let (r, a) = check_zonal(&hvls, &emission, &rx);
            (rel, abs) = (rel.max(r), abs.max(a));
        }
        // Settled lanes among lit ones in every position: at the receiver, facing away,
        // infinitely far is not constructible (finite positions), wholly below the horizon.
        let at_point = sh::hvl::Hvl::new(rx.point, Vec3::Z, Vec3::Z, 0.1, 1.0).expect("valid");
        let facing =
            sh::hvl::Hvl::new(rx.point + normal, -normal, Vec3::Z, 0.3, 2.0).expect("valid");
        let away = sh::hvl::Hvl::new(rx.point + normal, normal, Vec3::Z, 0.3, 2.0).expect("valid");
        let below =
            sh::hvl::Hvl::new(rx.point - normal * 3.0, normal, Vec3::Z, 0.3, 2.0).expect("valid");
        for k in 0..9 {
            let mut row = vec![
                at_point, away, below, at_point, away, below, at_point, away, below,
            ];
            row[k] = facing;
            check_zonal(&row, &emission, &rx);
        }
        // Hard cases by name: the receiver within an HVL's radius (`sin a = 1`, a half-space
        // cap, where the scalar kernel's `f32` angle overshoots π/2), a cap of 5e-5 rad, and
        // caps straddling the horizon.
        let tilted = (normal + rx.frame.tangent()).normalize();
        let hvl =
            |p: Vec3, n: Vec3, r: f32| sh::hvl::Hvl::new(p, n, Vec3::Z, r, 1.0).expect("valid");
        let hard = [
            hvl(rx.point + normal * 0.5, -normal, 2.0),
            hvl(rx.point + normal * 20.0, -normal, 1e-3),
            hvl(rx.point + rx.frame.tangent(), -rx.frame.tangent(), 0.3),
            hvl(rx.point + tilted * 0.2, -tilted, 0.5),
        ];
        check_zonal(&hard, &emission, &rx);
    }
    println!(
        "zonal HVL lanes: worst error {rel:.2e} of the terms' scale, {abs:.2e} relative where H > 0.05 and the sums cancel by less than half"
    );
    // Shapes: a non-square emission, a short scratch, a short output, nothing at all.
    let coeffs = [0.5f32; 3];
    let rx = sh::hvl::ZonalReceiver {
        point: Vec3::ZERO,
        frame: sh::brdf::view_frame(Vec3::Z, Vec3::Z).expect("frame"),
        coeffs: &coeffs,
    };
    let h = sh::hvl::Hvl::new(Vec3::Z, -Vec3::Z, Vec3::Z, 0.1, 1.0).expect("valid");
    let hz = sh::hvl::Horizon::Smoothstep;
    let f = steradian_simd::sh::hvl::contributions_zonal;
    let mut s = vec![0.0f32; 3];
    assert!(f(&[h; 2], &[0.0; 2], &rx, hz, &mut s, &mut [0.0; 2]).is_err());
    assert!(f(&[h; 2], &[0.0; 1], &rx, hz, &mut s[..2], &mut [0.0; 2]).is_err());
    assert!(f(&[h; 2], &[0.0; 1], &rx, hz, &mut s, &mut [0.0; 1]).is_err());
    assert!(f(&[], &[0.0; 1], &rx, hz, &mut s, &mut []).is_ok());
    assert!(f(&[h; 2], &[0.0; 1], &rx, hz, &mut s, &mut [0.0; 2]).is_ok());
}
