//! Spherical harmonics on arbitrary bits: the SIMD evaluation equals the scalar one bit for
//! bit for any direction (NaN, ±∞, subnormal components included) at 1–32 bands (the
//! straight-line code and the loop, in a padded pass and in whole ones); every value is finite for every finite non-zero
//! direction; the cap coefficients are finite for any finite direction and any half-angle
//! in `[0, π]` (an error outside, never a panic); the irradiance at a finite normal is
//! finite for coefficients below `1e30` in magnitude, the SH of a direction or arbitrary
//! bits; a rotation that passes validation (nine arbitrary entries, or an arbitrary axis and
//! angle) preserves every band's norm on both paths (ZXZXZ and the built operator), which
//! agree, for the SH of a direction and for arbitrary coefficients. The SIMD twins of
//! the cap coefficients, of the irradiance and of the ZXZXZ rotation equal their scalar
//! kernels bit for bit on the same arbitrary bits; the zonal HVL twin is within its
//! `zonal_bound` of the scalar kernel for HVLs at arbitrary positions and radii.

use steradian_core::sh::rotate::{Operator, Rotation, Rotator, rotate_rel_error};
use steradian_core::{Vec3, sh};

/// Both rotation paths on `c` (`bands` bands): finite, every band's norm kept, and equal.
fn check_rotation(rot: &Rotation, c: &[f32], bands: usize) {
    let n = bands * bands;
    let (mut a, mut b) = (vec![0.0f32; n], vec![0.0f32; n]);
    let rotator = Rotator::new(bands).expect("bands");
    rotator.rotate(rot, c, &mut a).expect("shape");
    // The SIMD twin of ZXZXZ, with the vector in a pass of its own and beside an
    // identity-rotated copy: bit for bit the scalar path.
    let two: Vec<f32> = c.iter().chain(c).copied().collect();
    let mut simd = vec![0.0f32; 2 * n];
    steradian_simd::sh::rotate::rotate_zxzxz_slices(
        rotator.table(),
        &[Rotation::identity(), *rot],
        bands,
        &two,
        &mut simd,
    )
    .expect("shape");
    for (k, (&s, &w)) in simd[n..].iter().zip(&a).enumerate() {
        assert!(same_bits(s, w), "SIMD ZXZXZ coefficient {k}: {s} vs {w}");
    }
    Operator::new(rot, bands)
        .expect("bands")
        .apply(c, &mut b)
        .expect("shape");
    let tol = 4.0 * f64::from(rotate_rel_error(bands));
    let norm = |v: &[f32]| v.iter().map(|&x| f64::from(x).powi(2)).sum::<f64>().sqrt();
    let total = norm(c);
    for l in 0..bands {
        let r = l * l..(l + 1) * (l + 1);
        let (n0, na, nb) = (norm(&c[r.clone()]), norm(&a[r.clone()]), norm(&b[r]));
        assert!(
            (na - n0).abs() <= tol * n0 + 1e-30 && (nb - n0).abs() <= tol * n0 + 1e-30,
            "band {l}: {n0} → {na} / {nb}"
        );
    }
    let diff: f64 = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (f64::from(*x) - f64::from(*y)).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(
        diff <= 2.0 * tol * total + 1e-30,
        "paths differ by {diff} of {total}"
    );
}

/// Equal bits, or both NaN (a NaN's payload may differ between the twins).
fn same_bits(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

fn f32_at(d: &[u8], at: usize) -> f32 {
    let b: [u8; 4] = core::array::from_fn(|k| d.get(at + k).copied().unwrap_or(0));
    f32::from_le_bytes(b)
}

/// The target's checks on one input.
pub fn check(data: &[u8]) {
    if data.is_empty() {
        return;
    }
    let bands = 1 + (data[0] % 32) as usize;
    let rest = &data[1..];
    let dirs: Vec<Vec3> = (0..4)
        .map(|k| {
            Vec3::new(
                f32_at(rest, 12 * k),
                f32_at(rest, 12 * k + 4),
                f32_at(rest, 12 * k + 8),
            )
        })
        .collect();
    let x: Vec<f32> = dirs.iter().map(|d| d.x).collect();
    let y: Vec<f32> = dirs.iter().map(|d| d.y).collect();
    let z: Vec<f32> = dirs.iter().map(|d| d.z).collect();
    let n = bands * bands;
    let mut cols = vec![0.0f32; n * 4];
    steradian_simd::sh::eval_slices(&x, &y, &z, bands, &mut cols).expect("valid shapes");
    // The cap twin: four caps of the same arbitrary half-angle, bit for bit or an error
    // exactly where the scalar kernel errs.
    let a = f32_at(rest, 48);
    let angles = [a; 4];
    let simd_caps =
        steradian_simd::sh::cap::coefficients_slices(&x, &y, &z, &angles, bands, &mut cols);
    let mut c = vec![0.0f32; n];
    for (i, d) in dirs.iter().enumerate() {
        let scalar = sh::cap::coefficients_into(*d, a, bands, &mut c);
        assert_eq!(
            scalar.is_ok(),
            simd_caps.is_ok(),
            "cap {a}: the twins disagree on validity"
        );
        if scalar.is_ok() {
            for k in 0..n {
                let (s, v) = (cols[k * 4 + i], c[k]);
                assert!(same_bits(s, v), "cap {d} {a} k {k}: {s} vs {v}");
            }
        }
    }
    // The irradiance twin: arbitrary radiance bits at the four normals.
    let radiance: Vec<f32> = (0..n).map(|k| f32_at(rest, 4 * k)).collect();
    let mut scratch4 = vec![[0.0f32; 4]; n];
    let mut e4 = [0.0f32; 4];
    steradian_simd::sh::irradiance::irradiance_slices(
        &radiance,
        &x,
        &y,
        &z,
        &mut scratch4,
        &mut e4,
    )
    .expect("valid shapes");
    // Arbitrary coefficients of moderate size: finite irradiance at a finite normal.
    let moderate = radiance.iter().all(|v| v.abs() < 1e30);
    for (i, d) in dirs.iter().enumerate() {
        let e = sh::irradiance::irradiance(&radiance, *d, &mut c).expect("square length");
        assert!(same_bits(e, e4[i]), "irradiance {d}: {} vs {e}", e4[i]);
        if moderate && d.is_finite() {
            assert!(
                e.is_finite(),
                "irradiance of moderate coefficients at {d}: {e}"
            );
        }
    }
    steradian_simd::sh::eval_slices(&x, &y, &z, bands, &mut cols).expect("valid shapes");
    // The four directions twice: eight columns, one whole pass of eight lanes (AVX-512) or
    // two of four, where four alone are a padded tail.
    let twice = |v: &[f32]| -> Vec<f32> { v.iter().chain(v).copied().collect() };
    let mut cols8 = vec![0.0f32; n * 8];
    steradian_simd::sh::eval_slices(&twice(&x), &twice(&y), &twice(&z), bands, &mut cols8)
        .expect("valid shapes");
    let mut one = vec![0.0f32; n];
    for (i, d) in dirs.iter().enumerate() {
        sh::eval_into(*d, bands, &mut one).expect("valid band count");
        for k in 0..n {
            let (a, b) = (cols[k * 4 + i], one[k]);
            assert!(same_bits(a, b), "{d} k {k}: {a} vs {b}");
            for j in [i, i + 4] {
                let a = cols8[k * 8 + j];
                assert!(same_bits(a, b), "{d} of eight, lane {j} k {k}: {a} vs {b}");
            }
        }
        if d.is_finite() {
            assert!(one.iter().all(|v| v.is_finite()), "{d}: non-finite SH");
            let a = f32_at(rest, 48);
            let mut c = vec![0.0f32; n];
            match sh::cap::coefficients_into(*d, a, bands, &mut c) {
                Ok(()) => assert!(c.iter().all(|v| v.is_finite()), "cap {a}: non-finite"),
                Err(_) => assert!(!(0.0..=steradian_core::PI).contains(&a)),
            }
            if one.iter().all(|v| v.abs() < 1e30) {
                let mut scratch = vec![0.0f32; n];
                let e = sh::irradiance::irradiance(&one, *d, &mut scratch).expect("square length");
                assert!(e.is_finite(), "irradiance of finite coefficients: {e}");
            }
            if i == 0 {
                let rows: [[f32; 3]; 3] = core::array::from_fn(|r| {
                    core::array::from_fn(|c| f32_at(rest, 52 + 12 * r + 4 * c))
                });
                if let Ok(rot) = Rotation::new(rows) {
                    check_rotation(&rot, &one, bands);
                    if moderate {
                        check_rotation(&rot, &radiance, bands);
                    }
                }
                let axis = Vec3::new(f32_at(rest, 88), f32_at(rest, 92), f32_at(rest, 96));
                if let Ok(rot) = Rotation::from_axis_angle(axis, f32_at(rest, 100)) {
                    check_rotation(&rot, &one, bands);
                }
            }
        }
    }
    check_zonal_hvls(&dirs, f32_at(rest, 48), &radiance, bands);
}

/// The zonal HVL twin (`steradian_simd::sh::hvl::contributions_zonal`) against the scalar
/// `contribution_zonal` within its `zonal_bound`: HVLs at the four directions' bits taken as
/// positions (with the HVL set twice: one whole pass of eight), facing the receiver at the
/// origin, of radius `|a|` (clamped into `[1e-6, 1e6]`), and the receiver's `min(bands, 8)`
/// zonal coefficients from the radiance bits (non-finite or beyond `1e6` ones replaced).
fn check_zonal_hvls(dirs: &[Vec3], a: f32, radiance: &[f32], bands: usize) {
    use sh::hvl::{Horizon, Hvl, ZonalReceiver, contribution_zonal, lambert_emission};
    use steradian_simd::sh::hvl::{contributions_zonal, zonal_bound};
    let radius = if a.is_nan() {
        0.1
    } else {
        a.abs().clamp(1e-6, 1e6)
    };
    let hvls: Vec<Hvl> = dirs
        .iter()
        .chain(dirs)
        .filter_map(|&p| Hvl::new(p, -p, Vec3::Z, radius, 1.0).ok())
        .collect();
    let coeffs: Vec<f32> = radiance
        .iter()
        .take(bands.min(8))
        .map(|&v| {
            if v.is_finite() && v.abs() <= 1e6 {
                v
            } else {
                0.5
            }
        })
        .collect();
    let Ok(frame) = steradian_core::frame::Frame::from_normal(Vec3::Z) else {
        return;
    };
    let rx = ZonalReceiver {
        point: Vec3::ZERO,
        frame,
        coeffs: &coeffs,
    };
    let emission = lambert_emission(0.8);
    let mut scratch = vec![0.0f32; coeffs.len().max(1)];
    let mut out = vec![0.0f32; hvls.len()];
    contributions_zonal(
        &hvls,
        &emission,
        &rx,
        Horizon::Smoothstep,
        &mut scratch,
        &mut out,
    )
    .expect("valid shapes");
    for (h, got) in hvls.iter().zip(out) {
        let want = contribution_zonal(h, &emission, &rx, Horizon::Smoothstep, &mut scratch)
            .expect("valid shapes");
        match zonal_bound(h, &emission, &rx).expect("valid shapes") {
            None => assert!(
                same_bits(got, want),
                "settled HVL at {}: {got} vs {want}",
                h.position()
            ),
            Some(bound) => {
                let err = (f64::from(got) - f64::from(want)).abs();
                assert!(
                    err <= bound || (got.is_nan() && want.is_nan()),
                    "HVL at {} r {radius}: {got} vs {want}, bound {bound:e}",
                    h.position()
                );
            }
        }
    }
}
