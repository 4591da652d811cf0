//! Least-squares fitting of control-point values to samples (the paper's eq. 3): the design
//! matrix and its normal equations, sparse, accumulated in `f64`.
//!
//! Each sample `(d_s, f_s)` is one row of the design matrix `A`: the three area weights of
//! `d_s` at its triangle's vertices, zero elsewhere, so that `(A v)_s` is the query of `v` at
//! `d_s`. The values minimising `‖A v − f‖²` solve `AᵀA v = Aᵀf`; `AᵀA` couples only
//! vertices that share a triangle (at most 7 non-zeros per row). Core assembles both sides;
//! the factorisation is a linear-algebra crate's (the harness's `cp::LeastSquares`, a sparse
//! Cholesky), so that core stays `no_std`. When the directions are fixed the matrix is
//! factored once and each new set of sample values costs one [`Design::project`] and one
//! solve.

use alloc::vec;
use alloc::vec::Vec;

use super::mesh::{Icosphere, Location, Weights};
use crate::Error;
use crate::Vec3;

/// The design matrix of a set of sample directions on one mesh: one located row per sample.
#[derive(Clone, Debug)]
pub struct Design {
    vertex_count: usize,
    rows: Vec<Location>,
}

impl Design {
    /// Locates every direction (area weights, the paper's eq. 2–4). Errors: a zero or
    /// non-finite direction (the first one met).
    pub fn new(mesh: &Icosphere, dirs: &[Vec3]) -> Result<Self, Error> {
        let rows = dirs
            .iter()
            .map(|d| mesh.locate(*d, Weights::Area))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            vertex_count: mesh.vertices().len(),
            rows,
        })
    }

    /// The number of unknowns (the mesh's vertices).
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// The located rows, one per sample direction.
    pub fn rows(&self) -> &[Location] {
        &self.rows
    }

    /// `AᵀA` as triplets `(row, column, value)`, both triangles, one per distinct entry,
    /// sorted by column then row (compressed-column order). Every vertex that no sample
    /// touches has no entry: its column of `A` is zero.
    pub fn gram(&self) -> Vec<(u32, u32, f64)> {
        let mut t: Vec<(u32, u32, f64)> = Vec::with_capacity(self.rows.len() * 9);
        for r in &self.rows {
            for (a, wa) in r.vertices.iter().zip(r.weights) {
                for (b, wb) in r.vertices.iter().zip(r.weights) {
                    t.push((*b, *a, f64::from(wa) * f64::from(wb)));
                }
            }
        }
        t.sort_unstable_by_key(|e| (e.1, e.0));
        let mut out: Vec<(u32, u32, f64)> = Vec::with_capacity(t.len() / 4 + 1);
        for e in t {
            match out.last_mut() {
                Some(l) if l.0 == e.0 && l.1 == e.1 => l.2 += e.2,
                _ => out.push(e),
            }
        }
        out
    }

    /// `Aᵀf` for one value per sample. Errors: a wrong number of values.
    pub fn project(&self, values: &[f64]) -> Result<Vec<f64>, Error> {
        if values.len() != self.rows.len() {
            return Err(Error::OutOfRange {
                what: "number of sample values",
                value: values.len() as f32,
                min: self.rows.len() as f32,
                max: self.rows.len() as f32,
            });
        }
        let mut out = vec![0.0f64; self.vertex_count];
        for (r, f) in self.rows.iter().zip(values) {
            for (v, w) in r.vertices.iter().zip(r.weights) {
                out[*v as usize] += f64::from(w) * f;
            }
        }
        Ok(out)
    }

    /// `A v` in `f64`: the query of `v` (one value per vertex) at every sample direction.
    /// Errors: a wrong number of values.
    pub fn apply(&self, v: &[f64]) -> Result<Vec<f64>, Error> {
        if v.len() != self.vertex_count {
            return Err(Error::OutOfRange {
                what: "number of values",
                value: v.len() as f32,
                min: self.vertex_count as f32,
                max: self.vertex_count as f32,
            });
        }
        Ok(self
            .rows
            .iter()
            .map(|r| {
                r.vertices
                    .iter()
                    .zip(r.weights)
                    .map(|(k, w)| f64::from(w) * v[*k as usize])
                    .sum()
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{cos64, cosf, sin64, sinf, sqrtf};

    fn dirs(n: usize) -> Vec<Vec3> {
        // A deterministic spiral over the sphere.
        (0..n)
            .map(|k| {
                let z = 1.0 - 2.0 * (k as f32 + 0.5) / n as f32;
                let r = sqrtf((1.0 - z * z).max(0.0));
                let p = k as f32 * 2.399_963;
                Vec3::new(r * cosf(p), r * sinf(p), z)
            })
            .collect()
    }

    #[test]
    fn gram_is_the_product_of_the_design_with_itself() {
        // (AᵀA)_{ab} = Σ_s A_sa A_sb, checked entry by entry against A applied to unit
        // vectors.
        let m = Icosphere::new(1).unwrap();
        let d = Design::new(&m, &dirs(300)).unwrap();
        let nv = d.vertex_count();
        let cols: Vec<Vec<f64>> = (0..nv)
            .map(|a| {
                let mut e = vec![0.0; nv];
                e[a] = 1.0;
                d.apply(&e).unwrap()
            })
            .collect();
        let g = d.gram();
        let mut dense = vec![0.0f64; nv * nv];
        for (r, c, v) in &g {
            dense[*r as usize * nv + *c as usize] = *v;
        }
        for a in 0..nv {
            for b in 0..nv {
                let want: f64 = cols[a].iter().zip(&cols[b]).map(|(x, y)| x * y).sum();
                assert!((dense[a * nv + b] - want).abs() < 1e-12, "{a},{b}");
            }
        }
        // Compressed-column order, no duplicates.
        assert!(g.windows(2).all(|w| (w[0].1, w[0].0) < (w[1].1, w[1].0)));
    }

    #[test]
    fn project_is_the_transpose_of_apply() {
        // ⟨A v, f⟩ = ⟨v, Aᵀ f⟩ for arbitrary v and f.
        let m = Icosphere::new(2).unwrap();
        let d = Design::new(&m, &dirs(500)).unwrap();
        let v: Vec<f64> = (0..d.vertex_count())
            .map(|k| sin64(k as f64 * 0.37))
            .collect();
        let f: Vec<f64> = (0..500).map(|k| cos64(k as f64 * 0.11)).collect();
        let av = d.apply(&v).unwrap();
        let atf = d.project(&f).unwrap();
        let lhs: f64 = av.iter().zip(&f).map(|(a, b)| a * b).sum();
        let rhs: f64 = v.iter().zip(&atf).map(|(a, b)| a * b).sum();
        assert!((lhs - rhs).abs() < 1e-9 * lhs.abs().max(1.0), "{lhs} {rhs}");
    }

    #[test]
    fn bad_directions_and_lengths_are_errors() {
        let m = Icosphere::new(0).unwrap();
        assert!(Design::new(&m, &[Vec3::X, Vec3::ZERO]).is_err());
        assert!(Design::new(&m, &[Vec3::new(f32::NAN, 0.0, 1.0)]).is_err());
        let d = Design::new(&m, &[Vec3::X]).unwrap();
        assert!(d.project(&[1.0, 2.0]).is_err());
        assert!(d.apply(&[0.0; 11]).is_err());
        assert!(Design::new(&m, &[]).unwrap().gram().is_empty());
    }
}
