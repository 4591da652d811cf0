//! The SH batch kernel lane by lane against `steradian_core::sh::eval_into`: bit-identical
//! for random directions, the named special values in every component and lane position
//! (NaN, ±∞, ±0, subnormals, huge and tiny), the poles and the equator, every slice length
//! around the batch size and band counts from 0 to `MAX_BANDS`.

use glam::Vec3;
use steradian_core::sh::{self, MAX_BANDS};
use steradian_simd::sh::{eval_slices, eval_x4};

use crate::common::lanes::{LENGTHS, in_every_lane, same};
use crate::common::rng::Rng;
use crate::common::specials::SPECIALS;

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
    for bands in [0usize, 1, 2, 3, 4, 5, 9, 10, 17, 30] {
        for len in LENGTHS {
            let rows: Vec<Vec3> = (0..len)
                .map(|_| rng.dir() * rng.log_range(1e-3, 1e3))
                .collect();
            check(&rows, bands);
        }
    }
}

#[test]
fn special_values_in_every_component_and_lane() {
    let rows: Vec<Vec3> = SPECIALS
        .iter()
        .flat_map(|&s| {
            [
                Vec3::new(s, 0.3, 0.4),
                Vec3::new(0.3, s, 0.4),
                Vec3::new(0.3, 0.4, s),
            ]
        })
        .chain([
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.6, 0.8, 0.0),
            Vec3::ZERO,
        ])
        .collect();
    in_every_lane(&rows, Vec3::new(0.2, -0.3, 0.9), |r| check(r, 6));
}

#[test]
fn many_bands_and_the_x4_entry_point() {
    let mut rng = Rng(7);
    let dirs: [Vec3; 4] = core::array::from_fn(|_| rng.dir());
    for bands in [1usize, 8, MAX_BANDS] {
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
fn bad_shapes_are_errors() {
    let mut out = vec![0.0; 8];
    assert!(eval_slices(&[0.0; 2], &[0.0; 2], &[1.0; 2], 2, &mut out).is_ok());
    assert!(eval_slices(&[0.0; 2], &[0.0; 3], &[1.0; 2], 2, &mut out).is_err());
    assert!(eval_slices(&[0.0; 2], &[0.0; 2], &[1.0; 2], 3, &mut out).is_err());
    assert!(eval_slices(&[], &[], &[], MAX_BANDS + 1, &mut []).is_err());
    let mut short = vec![[0.0f32; 4]; 3];
    assert!(eval_x4([Vec3::Z; 4], 2, &mut short).is_err());
}
