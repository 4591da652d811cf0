//! Control points on arbitrary bits: at every level, point location of any direction (NaN,
//! ±∞, subnormal, huge components included) either fails (zero or non-finite direction) or
//! returns a triangle of the mesh holding three of its vertices, with weights all ≥ −1e-6
//! summing to 1 within 1e-6, for both weight kinds; the SIMD query equals the scalar one (bit
//! for bit with gnomonic weights, within `AREA_TOL·max|v_i|` with area weights; NaN where the
//! scalar query fails); and the least-squares fit of arbitrary finite samples is finite.

use steradian_core::Vec3;
use steradian_core::cp::{Icosphere, Weights};
use steradian_simd::cp::{AREA_TOL, query_slices};

fn f32_at(d: &[u8], at: usize) -> f32 {
    let b: [u8; 4] = core::array::from_fn(|k| d.get(at + k).copied().unwrap_or(0));
    f32::from_le_bytes(b)
}

/// The target's checks on one input.
pub fn check(data: &[u8]) {
    let Some((&head, rest)) = data.split_first() else {
        return;
    };
    let level = u32::from(head % 5);
    let mesh = Icosphere::new(level).expect("level 0–4");
    let nv = mesh.vertices().len();
    let dirs: Vec<Vec3> = (0..(rest.len() / 12).clamp(1, 16))
        .map(|k| {
            Vec3::new(
                f32_at(rest, 12 * k),
                f32_at(rest, 12 * k + 4),
                f32_at(rest, 12 * k + 8),
            )
        })
        .collect();
    // Finite values in [−8, 8), one per vertex, from the input's bytes.
    let values: Vec<f32> = (0..nv)
        .map(|k| {
            let b = rest.get(k % rest.len().max(1)).copied().unwrap_or(0);
            (f32::from(b) - 128.0) / 16.0 + (k % 7) as f32 * 1e-3
        })
        .collect();
    for d in &dirs {
        for w in [Weights::Area, Weights::Gnomonic] {
            match mesh.locate(*d, w) {
                Err(_) => assert!(!d.is_finite() || *d == Vec3::ZERO, "{d:?}: located nothing"),
                Ok(l) => {
                    assert!(d.is_finite() && *d != Vec3::ZERO, "{d:?}: located");
                    let tri = mesh.triangles()[l.triangle as usize];
                    assert_eq!(tri, l.vertices, "{d:?}: vertices of its triangle");
                    let s: f32 = l.weights.iter().sum();
                    assert!(
                        l.weights.iter().all(|x| *x >= -1e-6) && (s - 1.0).abs() <= 1e-6,
                        "{d:?} {w:?}: weights {:?}",
                        l.weights
                    );
                }
            }
        }
    }
    let (x, y, z): (Vec<f32>, Vec<f32>, Vec<f32>) = (
        dirs.iter().map(|d| d.x).collect(),
        dirs.iter().map(|d| d.y).collect(),
        dirs.iter().map(|d| d.z).collect(),
    );
    let mut out = vec![0.0f32; dirs.len()];
    for w in [Weights::Area, Weights::Gnomonic] {
        query_slices(&mesh, &values, w, &x, &y, &z, &mut out).expect("shapes");
        for (d, got) in dirs.iter().zip(&out) {
            match mesh.locate(*d, w) {
                Err(_) => assert!(got.is_nan(), "{d:?}: SIMD {got} where scalar fails"),
                Ok(l) => {
                    let want = l.interpolate(&values);
                    let m = l
                        .vertices
                        .iter()
                        .map(|k| values[*k as usize].abs())
                        .fold(0.0f32, f32::max);
                    let ok = match w {
                        Weights::Gnomonic => got.to_bits() == want.to_bits(),
                        Weights::Area => (got - want).abs() <= AREA_TOL * m,
                    };
                    assert!(ok, "{d:?} {w:?}: SIMD {got}, scalar {want}");
                }
            }
        }
    }
    // The fit at levels 0–2 of the finite, non-zero samples (directions and values from the
    // same bits).
    let fit_mesh = Icosphere::new(level.min(2)).expect("level");
    let samples: Vec<[f32; 4]> = dirs
        .iter()
        .zip(&values)
        .filter(|(d, _)| d.is_finite() && **d != Vec3::ZERO)
        .map(|(d, v)| [d.x, d.y, d.z, *v])
        .collect();
    let v = steradian_harness::cp::fit(&fit_mesh, &samples).expect("finite samples fit");
    assert_eq!(v.len(), fit_mesh.vertices().len());
    assert!(
        v.iter().all(|x| x.is_finite()),
        "fit not finite: {samples:?}"
    );
}
