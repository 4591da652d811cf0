//! Rotation of control-point functions (section 3.4): the rotated function
//! `g(ω) = f(Rᵀω)` (the value at `d` moves to `R·d`, as `sh::rotate`) as a sparse operator
//! on the values, precomputed once per rotation and applied in `O(V)`.
//!
//! The control points cannot move (the location needs the fixed mesh), so the values are
//! re-assigned. Three ways, each an [`Operator`]:
//! - [`Operator::permutation`] (section 3.4.1): each rotated point `R·v_j` hands its value
//!   to one real point, a bijection. The first match is the best one over all points (`C`);
//!   the others follow in order of their distance to `C`, each taking the nearest real point
//!   still free, so that no point is left isolated among taken neighbours (the paper's
//!   Figure 11: matching best-first over the whole sphere ends with catastrophic matches).
//!   Measured: below half an edge the permutation is the identity (the paper's stated
//!   drawback), and the ordering does not rule out a catastrophic match either (at level 2,
//!   0.5 rad, one rotated point ends 2.8 rad from its match; the report prints the worst).
//! - [`Operator::continuous`] (section 3.4.2): each rotated point is a sample interpolated
//!   by the three real points of its triangle with weights `ω`; a real point's new value is
//!   the `ω`-weighted mean of the values of the rotated points it takes part in,
//!   `g_k = Σ_j ω_kj f_j / Σ_j ω_kj` (a real point in no rotated point's triangle, which
//!   the spacing of the mesh makes rare, takes the resampled value below).
//! - [`Operator::resample`]: the interpolant resampled at the real points, `g_k = f(Rᵀv_k)`
//!   by the query (three weights per row): not in the paper, measured beside it.
//!
//! Their errors after 1, 10 and 100 successive rotations, against the function resampled
//! exactly, are in `steradian report`, section `control-points`.

use alloc::vec;
use alloc::vec::Vec;

use glam::DVec3;

use super::mesh::{Icosphere, Weights};
use crate::Error;
use crate::Vec3;
use crate::sh::rotate::Rotation;

/// A rotation of control-point values: `out[k] = Σ weight·values[index]` over row `k`.
#[derive(Clone, Debug)]
pub struct Operator {
    start: Vec<u32>,
    index: Vec<u32>,
    weight: Vec<f32>,
}

fn rotated(mesh: &Icosphere, m: glam::DMat3) -> Vec<Vec3> {
    mesh.vertices()
        .iter()
        .map(|v| {
            let r: DVec3 = m * v.as_dvec3();
            r.as_vec3()
        })
        .collect()
}

impl Operator {
    fn from_rows(rows: impl Iterator<Item = Vec<(u32, f32)>>) -> Self {
        let (mut start, mut index, mut weight) = (vec![0u32], Vec::new(), Vec::new());
        for r in rows {
            for (i, w) in r {
                index.push(i);
                weight.push(w);
            }
            start.push(index.len() as u32);
        }
        Self {
            start,
            index,
            weight,
        }
    }

    /// The resampling `g_k = f(Rᵀv_k)`: each row the query weights of `Rᵀv_k`.
    pub fn resample(mesh: &Icosphere, rot: &Rotation) -> Result<Self, Error> {
        let back = rotated(mesh, rot.matrix().transpose());
        let rows = back
            .iter()
            .map(|d| {
                mesh.locate(*d, Weights::Area)
                    .map(|l| l.vertices.into_iter().zip(l.weights).collect())
            })
            .collect::<Result<Vec<Vec<(u32, f32)>>, Error>>()?;
        Ok(Self::from_rows(rows.into_iter()))
    }

    /// The paper's continuous re-weighting (module docs).
    pub fn continuous(mesh: &Icosphere, rot: &Rotation) -> Result<Self, Error> {
        let nv = mesh.vertices().len();
        let fwd = rotated(mesh, rot.matrix());
        let mut rows: Vec<Vec<(u32, f32)>> = vec![Vec::new(); nv];
        for (j, d) in fwd.iter().enumerate() {
            let l = mesh.locate(*d, Weights::Area)?;
            for (k, w) in l.vertices.iter().zip(l.weights) {
                if w > 0.0 {
                    rows[*k as usize].push((j as u32, w));
                }
            }
        }
        let fallback = Self::resample(mesh, rot)?;
        for (k, row) in rows.iter_mut().enumerate() {
            let s: f32 = row.iter().map(|e| e.1).sum();
            if s > 0.0 {
                for e in row.iter_mut() {
                    e.1 /= s;
                }
            } else {
                *row = fallback.row(k).collect();
            }
        }
        Ok(Self::from_rows(rows.into_iter()))
    }

    /// The paper's permutation, best match first and then nearest to it (module docs). Also
    /// returns the largest angle (radians) between a rotated point and its match.
    pub fn permutation(mesh: &Icosphere, rot: &Rotation) -> Result<(Self, f32), Error> {
        let v = mesh.vertices();
        let nv = v.len();
        let fwd = rotated(mesh, rot.matrix());
        // The nearest free real point: a scan of all of them (O(V²) per rotation, once).
        let nearest = |p: Vec3, free: &[bool]| -> Option<(u32, f32)> {
            let mut best: Option<(u32, f32)> = None;
            for (k, q) in v.iter().enumerate() {
                if free[k] {
                    let c = p.dot(*q);
                    if best.is_none_or(|b| c > b.1) {
                        best = Some((k as u32, c));
                    }
                }
            }
            best
        };
        let all = vec![true; nv];
        // C: the best match over all rotated points.
        let mut first = (0usize, 0u32, f32::NEG_INFINITY);
        for (j, p) in fwd.iter().enumerate() {
            if let Some((k, c)) = nearest(*p, &all)
                && c > first.2
            {
                first = (j, k, c);
            }
        }
        let centre = v[first.1 as usize];
        let mut order: Vec<usize> = (0..nv).filter(|j| *j != first.0).collect();
        order.sort_by(|a, b| {
            centre
                .dot(fwd[*b])
                .total_cmp(&centre.dot(fwd[*a]))
                .then(a.cmp(b))
        });
        let mut free = vec![true; nv];
        let mut source = vec![0u32; nv];
        free[first.1 as usize] = false;
        source[first.1 as usize] = first.0 as u32;
        let mut worst = first.2;
        for j in order {
            let (k, c) = nearest(fwd[j], &free).unwrap_or((0, -1.0));
            free[k as usize] = false;
            source[k as usize] = j as u32;
            worst = worst.min(c);
        }
        let op = Self::from_rows(source.iter().map(|j| vec![(*j, 1.0)]));
        Ok((op, crate::math::acosf(worst.clamp(-1.0, 1.0))))
    }

    fn row(&self, k: usize) -> impl Iterator<Item = (u32, f32)> + '_ {
        let (a, b) = (self.start[k] as usize, self.start[k + 1] as usize);
        self.index[a..b]
            .iter()
            .copied()
            .zip(self.weight[a..b].iter().copied())
    }

    /// The number of rows (the mesh's vertices).
    pub fn len(&self) -> usize {
        self.start.len() - 1
    }

    /// Whether the operator has no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Non-zero weights in all.
    pub fn nonzeros(&self) -> usize {
        self.index.len()
    }

    /// The rotated values. Errors: `values` or `out` of another length than the rows.
    pub fn apply(&self, values: &[f32], out: &mut [f32]) -> Result<(), Error> {
        let n = self.len();
        if values.len() != n || out.len() != n {
            return Err(Error::OutOfRange {
                what: "number of values",
                value: values.len().max(out.len()) as f32,
                min: n as f32,
                max: n as f32,
            });
        }
        for (k, o) in out.iter_mut().enumerate() {
            *o = self.row(k).map(|(i, w)| w * values[i as usize]).sum();
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(d: Vec3) -> f32 {
        let a = Vec3::new(0.3, 0.5, 0.81).normalize();
        crate::math::powf(d.dot(a).max(0.0), 4.0) + 0.2 * d.x
    }

    #[test]
    fn identity_is_exact_for_every_operator() {
        let m = Icosphere::new(2).unwrap();
        let values: Vec<f32> = m.vertices().iter().map(|v| f(*v)).collect();
        let id = Rotation::identity();
        let (perm, worst) = Operator::permutation(&m, &id).unwrap();
        assert!(worst < 1e-3, "{worst}");
        for op in [
            perm,
            Operator::continuous(&m, &id).unwrap(),
            Operator::resample(&m, &id).unwrap(),
        ] {
            let mut out = vec![0.0; values.len()];
            op.apply(&values, &mut out).unwrap();
            for (a, b) in out.iter().zip(&values) {
                assert!((a - b).abs() < 1e-5, "{a} vs {b}");
            }
        }
    }

    #[test]
    fn a_symmetry_of_the_icosahedron_is_an_exact_permutation() {
        // A rotation by 2π/5 about a base vertex maps the mesh onto itself: the permutation
        // matches every point exactly and moves the values as the function moves.
        let m = Icosphere::new(2).unwrap();
        let axis = m.vertices()[0];
        let rot = Rotation::from_axis_angle(axis, core::f32::consts::TAU / 5.0).unwrap();
        let (perm, worst) = Operator::permutation(&m, &rot).unwrap();
        assert!(worst < 2e-3, "worst match {worst}");
        let values: Vec<f32> = m.vertices().iter().map(|v| f(*v)).collect();
        let mut out = vec![0.0; values.len()];
        perm.apply(&values, &mut out).unwrap();
        let back = rot.matrix().transpose();
        for (k, v) in m.vertices().iter().enumerate() {
            let want = f((back * v.as_dvec3()).as_vec3());
            assert!((out[k] - want).abs() < 1e-3, "{k}: {} vs {want}", out[k]);
        }
        assert_eq!(perm.nonzeros(), values.len());
    }

    #[test]
    fn the_permutation_is_the_identity_below_half_an_edge_and_can_fail_above() {
        // The limits the module docs state, on the report's rotation axis at level 2.
        let m = Icosphere::new(2).unwrap();
        let axis = Vec3::new(1.0, -1.0, 0.2);
        let small = Rotation::from_axis_angle(axis, 0.1).unwrap();
        let (p, worst) = Operator::permutation(&m, &small).unwrap();
        assert!((0..p.len()).all(|k| p.row(k).eq([(k as u32, 1.0)])));
        assert!(worst <= 0.1 + 1e-4, "{worst}");
        let large = Rotation::from_axis_angle(axis, 0.5).unwrap();
        let (_, worst) = Operator::permutation(&m, &large).unwrap();
        assert!(worst > 2.5, "worst match {worst} rad");
    }

    #[test]
    fn continuous_rows_are_convex_and_bad_lengths_are_errors() {
        let m = Icosphere::new(1).unwrap();
        let rot = Rotation::from_axis_angle(Vec3::new(1.0, 2.0, 3.0), 0.3).unwrap();
        let op = Operator::continuous(&m, &rot).unwrap();
        for k in 0..op.len() {
            let s: f32 = op.row(k).map(|e| e.1).sum();
            assert!((s - 1.0).abs() < 1e-5 && op.row(k).all(|e| e.1 >= 0.0));
        }
        let mut out = vec![0.0; 42];
        assert!(op.apply(&[0.0; 41], &mut out).is_err());
        assert!(op.apply(&[0.0; 42], &mut out[..3]).is_err());
    }
}
