//! The control-point query lane by lane against `Icosphere::query`: bit-identical with the
//! gnomonic weights and within `AREA_TOL·max|v_i|` with the area weights, for random
//! directions of every length, arbitrary bit patterns, the named special values in every
//! component and lane position, the vertices, edge midpoints and face centres of every
//! level, and every slice length around the batch size. A direction the scalar query
//! rejects (zero, non-finite) is NaN in its lane.

use glam::Vec3;
use steradian_core::cp::{Icosphere, MAX_LEVEL, Weights};
use steradian_simd::cp::{AREA_TOL, query_slices};

use crate::common::lanes::{LENGTHS, in_every_lane, same};
use crate::common::rng::Rng;
use crate::common::specials::{SPECIALS, in_each_component};

fn meshes() -> Vec<(Icosphere, Vec<f32>)> {
    let mut rng = Rng(0x5eed_0c90);
    (0..=MAX_LEVEL)
        .map(|l| {
            let m = Icosphere::new(l).expect("valid level");
            let v = (0..m.vertices().len())
                .map(|_| rng.range(-2.0, 3.0))
                .collect();
            (m, v)
        })
        .collect()
}

/// `query_slices` on `rows` against the scalar query, every row.
fn check(mesh: &Icosphere, values: &[f32], rows: &[Vec3], w: Weights) {
    let col = |f: fn(&Vec3) -> f32| rows.iter().map(f).collect::<Vec<f32>>();
    let (x, y, z) = (col(|d| d.x), col(|d| d.y), col(|d| d.z));
    let mut out = vec![0.0; rows.len()];
    query_slices(mesh, values, w, &x, &y, &z, &mut out).expect("valid shapes");
    for (d, got) in rows.iter().zip(&out) {
        match mesh.query(values, *d, w) {
            Err(_) => assert!(got.is_nan(), "{d:?}: {got} where the scalar query errs"),
            Ok(want) => match w {
                Weights::Gnomonic => assert!(same(*got, want), "{d:?}: {got} vs {want}"),
                Weights::Area => {
                    let l = mesh.locate(*d, w).expect("located");
                    let vmax = l
                        .vertices
                        .iter()
                        .map(|&k| values[k as usize].abs())
                        .fold(0.0f32, f32::max);
                    assert!(
                        (got - want).abs() <= AREA_TOL * vmax,
                        "{d:?} level {}: {got} vs {want}",
                        mesh.level()
                    );
                }
            },
        }
    }
}

const BOTH: [Weights; 2] = [Weights::Area, Weights::Gnomonic];

#[test]
fn random_directions_every_length_and_level() {
    let mut rng = Rng(0x5eed_0c91);
    for (m, v) in meshes() {
        for len in LENGTHS {
            let rows: Vec<Vec3> = (0..len)
                .map(|_| rng.dir() * rng.log_range(1e-30, 1e30))
                .collect();
            for w in BOTH {
                check(&m, &v, &rows, w);
            }
        }
    }
}

#[test]
fn arbitrary_bit_patterns() {
    let mut rng = Rng(0x5eed_0c92);
    let all = meshes();
    let rows: Vec<Vec3> = (0..4000)
        .map(|_| Vec3::new(rng.bits(), rng.bits(), rng.bits()))
        .collect();
    for (m, v) in &all {
        for w in BOTH {
            check(m, v, &rows, w);
        }
    }
}

#[test]
fn special_values_in_every_component_and_lane() {
    let mut rows = in_each_component();
    rows.extend(
        SPECIALS
            .iter()
            .flat_map(|&s| [Vec3::splat(s), Vec3::new(s, -s, 0.0)]),
    );
    for (m, v) in meshes() {
        for w in BOTH {
            in_every_lane(&rows, Vec3::X, |r| check(&m, &v, r, w));
        }
    }
}

#[test]
fn vertices_edge_midpoints_and_face_centres() {
    for (m, v) in meshes() {
        let p = m.vertices();
        let mut rows: Vec<Vec3> = p.to_vec();
        for t in m.triangles() {
            let [a, b, c] = t.map(|k| p[k as usize]);
            rows.extend([a + b, b + c, c + a, a + b + c]);
        }
        // Signed zeros on the octant planes and the axes.
        rows.extend([
            Vec3::X,
            -Vec3::Y,
            Vec3::new(-0.0, 0.0, 1.0),
            Vec3::new(0.0, -0.0, -1.0),
        ]);
        for w in BOTH {
            check(&m, &v, &rows, w);
        }
    }
}

#[test]
fn shape_errors() {
    let (m, v) = &meshes()[1];
    let col = [1.0f32; 3];
    let mut out = [0.0f32; 3];
    assert!(query_slices(m, &v[1..], Weights::Area, &col, &col, &col, &mut out).is_err());
    assert!(query_slices(m, v, Weights::Area, &col[..2], &col, &col, &mut out).is_err());
}
