//! Control-point fitting by least squares (Chatelier and Malgouyres, GRAPP 2007, eq. 3): the
//! normal equations that `steradian_core::cp::fit::Design` assembles, factored by
//! `nalgebra-sparse`'s sparse Cholesky, and the dense `f64` reference it is tested against.
//!
//! **Ordering.** The factorisation does no fill-in reduction of its own, so the unknowns are
//! ordered by the vertices' `z`: the area of the sphere is uniform in `z` (Archimedes), so a
//! slice of the height `h` of one edge holds about `V·h/2` vertices, and every non-zero of
//! `AᵀA` (vertices sharing a triangle) lies within that band of the diagonal. The factor
//! stays inside the band's profile (measured by `steradian report`, section
//! `control-points`).
//!
//! **Singular systems.** A vertex that no sample touches, or a triangle with fewer samples
//! than the freedom they constrain, makes `AᵀA` singular. A ridge `λ = RIDGE·max diag(AᵀA)`
//! makes it definite; two steps of iterative refinement on the unregularised system then
//! remove the ridge's bias from every component the samples determine. Every step stays in
//! the range of `AᵀA` (the ridge shares its eigenvectors), so the components in the null
//! space of `A` stay zero: the fit is the minimum-norm minimiser, as the SVD's. The residual equals the exact minimiser's within
//! `RESIDUAL_REL_ERROR` (asserted against the dense SVD minimiser by `tests/cp.rs`).

use nalgebra::{DMatrix, DVector};
use nalgebra_sparse::factorization::CscCholesky;
use nalgebra_sparse::{CooMatrix, CscMatrix};
use steradian_core::Vec3;
use steradian_core::cp::{Design, Icosphere};

/// The ridge, relative to the largest diagonal entry of `AᵀA`.
pub const RIDGE: f64 = 1e-10;

/// Bound on `(‖A v − f‖ − ‖A v* − f‖) / ‖f‖` of the fit `v` against an exact minimiser
/// `v*` (the dense SVD pseudo-inverse), asserted by `tests/cp.rs` on full, sparse and
/// under-determined sample sets (the SVD minimiser itself is exact only to about 1e-12, its
/// singular-value cut-off).
pub const RESIDUAL_REL_ERROR: f64 = 1e-12;

/// A least-squares fit for fixed sample directions: the design located and `AᵀA + λI`
/// factored once; each set of sample values then costs `Aᵀf` and three triangular solve
/// pairs (one plus two refinement steps).
pub struct LeastSquares {
    design: Design,
    /// Vertex → its row in the factored (z-ordered) matrix.
    rank: Vec<usize>,
    /// `AᵀA` (no ridge) in the factored order, as `(row, column, value)`.
    gram: Vec<(usize, usize, f64)>,
    factor: CscCholesky<f64>,
}

impl LeastSquares {
    /// Locates `dirs` on `mesh` and factors the normal equations. Errors: a zero or
    /// non-finite direction.
    pub fn new(mesh: &Icosphere, dirs: &[Vec3]) -> Result<Self, String> {
        let design = Design::new(mesh, dirs).map_err(|e| e.to_string())?;
        let nv = design.vertex_count();
        let mut order: Vec<usize> = (0..nv).collect();
        let z = |k: usize| mesh.vertices()[k].z;
        order.sort_by(|a, b| z(*a).total_cmp(&z(*b)).then(a.cmp(b)));
        let mut rank = vec![0usize; nv];
        for (r, v) in order.iter().enumerate() {
            rank[*v] = r;
        }
        let entries = design.gram();
        let max_diag = entries
            .iter()
            .filter(|e| e.0 == e.1)
            .map(|e| e.2)
            .fold(0.0f64, f64::max);
        let ridge = if max_diag > 0.0 {
            RIDGE * max_diag
        } else {
            1.0
        };
        let gram: Vec<(usize, usize, f64)> = entries
            .iter()
            .map(|(r, c, v)| (rank[*r as usize], rank[*c as usize], *v))
            .collect();
        let mut coo = CooMatrix::new(nv, nv);
        for (r, c, v) in &gram {
            coo.push(*r, *c, *v);
        }
        for k in 0..nv {
            coo.push(k, k, ridge);
        }
        let factor = CscCholesky::factor(&CscMatrix::from(&coo))
            .map_err(|e| format!("normal equations not definite: {e}"))?;
        Ok(Self {
            design,
            rank,
            gram,
            factor,
        })
    }

    /// The design (the located sample directions).
    pub fn design(&self) -> &Design {
        &self.design
    }

    /// Non-zeros of the Cholesky factor (the fill the z-ordering leaves).
    pub fn factor_nonzeros(&self) -> usize {
        self.factor.l().nnz()
    }

    /// The values (one per vertex) minimising `‖A v − f‖²` for one value per sample.
    /// Errors: a wrong number of values, or a non-finite result (values near `f64::MAX`).
    pub fn fit(&self, values: &[f64]) -> Result<Vec<f64>, String> {
        let atf = self.design.project(values).map_err(|e| e.to_string())?;
        let nv = atf.len();
        let mut b = vec![0.0f64; nv];
        for (v, x) in atf.iter().enumerate() {
            b[self.rank[v]] = *x;
        }
        let mut x = vec![0.0f64; nv];
        let mut r = DMatrix::from_column_slice(nv, 1, &b);
        for step in 0..3 {
            let dx = self.factor.solve(&r);
            for (k, xk) in x.iter_mut().enumerate() {
                *xk += dx[(k, 0)];
            }
            if step < 2 {
                // r = b − AᵀA x, on the unregularised matrix.
                let mut res = b.clone();
                for (row, col, v) in &self.gram {
                    res[*row] -= v * x[*col];
                }
                r = DMatrix::from_column_slice(nv, 1, &res);
            }
        }
        let out: Vec<f64> = (0..nv).map(|v| x[self.rank[v]]).collect();
        if out.iter().all(|v| v.is_finite()) {
            Ok(out)
        } else {
            Err("the fit is not finite (sample values too large)".into())
        }
    }
}

/// The least-squares fit of `samples` (`[x, y, z, value]`) on `mesh`: [`LeastSquares`] for
/// one set of values.
pub fn fit(mesh: &Icosphere, samples: &[[f32; 4]]) -> Result<Vec<f64>, String> {
    let dirs: Vec<Vec3> = samples
        .iter()
        .map(|s| Vec3::new(s[0], s[1], s[2]))
        .collect();
    let values: Vec<f64> = samples.iter().map(|s| f64::from(s[3])).collect();
    LeastSquares::new(mesh, &dirs)?.fit(&values)
}

/// The error the L∞ fit minimises over the samples (the paper's eq. 5–7), each sample's
/// residual divided by its scale `s_i`: 1, `|f_i|` or `√|f_i|`. The relative scales are
/// floored at `1e-6·max|f|`, so that a zero sample is not an equality constraint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Linf {
    /// Eq. 5: `max |A v − f|`.
    Absolute,
    /// Eq. 6: `max |A v − f| / |f|`.
    Relative,
    /// Eq. 7: `max |A v − f| / √|f|` (the paper's compromise).
    SqrtRelative,
}

impl Linf {
    /// All three, in the paper's order.
    pub const ALL: [Linf; 3] = [Linf::Absolute, Linf::Relative, Linf::SqrtRelative];

    /// Its name in the report.
    pub fn name(self) -> &'static str {
        match self {
            Linf::Absolute => "L∞ absolute (eq. 5)",
            Linf::Relative => "L∞ relative (eq. 6)",
            Linf::SqrtRelative => "L∞ sqrt-relative (eq. 7)",
        }
    }
}

/// The L∞ fit of eq. 5–7 by linear programming (`microlp`): minimise `h` subject to
/// `−h·s_i ≤ (A v − f)_i ≤ h·s_i` for every sample. Vertices no sample touches are 0.
/// Returns the values and the optimal `h`. Errors: a wrong number of values, or the
/// solver's failure (reported, not hidden).
pub fn fit_linf(design: &Design, values: &[f64], scale: Linf) -> Result<(Vec<f64>, f64), String> {
    use microlp::{ComparisonOp, OptimizationDirection, Problem};
    let rows = design.rows();
    if values.len() != rows.len() {
        return Err(format!(
            "{} sample values for {} samples",
            values.len(),
            rows.len()
        ));
    }
    let nv = design.vertex_count();
    let mut touched = vec![false; nv];
    for r in rows {
        for (v, w) in r.vertices.iter().zip(r.weights) {
            if w != 0.0 {
                touched[*v as usize] = true;
            }
        }
    }
    let mut p = Problem::new(OptimizationDirection::Minimize);
    let x: Vec<_> = touched
        .iter()
        .map(|t| {
            let b = if *t { f64::INFINITY } else { 0.0 };
            p.add_var(0.0, (-b, b))
        })
        .collect();
    let h = p.add_var(1.0, (0.0, f64::INFINITY));
    let floor = 1e-6 * values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (r, f) in rows.iter().zip(values) {
        let s = match scale {
            Linf::Absolute => 1.0,
            Linf::Relative => f.abs().max(floor),
            Linf::SqrtRelative => f.abs().max(floor).sqrt(),
        };
        let mut e: Vec<(microlp::Variable, f64)> = r
            .vertices
            .iter()
            .zip(r.weights)
            .filter(|(_, w)| *w != 0.0)
            .map(|(v, w)| (x[*v as usize], f64::from(w)))
            .collect();
        e.push((h, -s));
        p.add_constraint(e.as_slice(), ComparisonOp::Le, *f);
        if let Some(last) = e.last_mut() {
            last.1 = s;
        }
        p.add_constraint(e.as_slice(), ComparisonOp::Ge, *f);
    }
    let sol = p
        .solve()
        .map_err(|e| format!("linear program: {e}"))?
        .into_solution()
        .map_err(|e| format!("linear program interrupted: {e:?}"))?;
    Ok((
        x.iter().map(|v| sol.var_value(*v)).collect(),
        sol.var_value(h),
    ))
}

/// The dense `f64` reference: the minimum-norm least-squares solution `A⁺f` by the SVD of
/// the design matrix (singular values below `1e-12·σ_max` treated as zero). O(S·V²): for
/// tests and the report at levels ≤ 2.
pub fn fit_dense_reference(design: &Design, values: &[f64]) -> Vec<f64> {
    let nv = design.vertex_count();
    let rows = design.rows();
    let mut a = DMatrix::<f64>::zeros(rows.len().max(1), nv);
    for (s, r) in rows.iter().enumerate() {
        for (v, w) in r.vertices.iter().zip(r.weights) {
            a[(s, *v as usize)] += f64::from(w);
        }
    }
    let mut f = DVector::<f64>::zeros(rows.len().max(1));
    for (s, v) in values.iter().enumerate() {
        f[s] = *v;
    }
    let svd = a.svd(true, true);
    let eps = 1e-12 * svd.singular_values.max();
    let x = svd.solve(&f, eps).expect("u and v were computed");
    x.iter().copied().collect()
}

/// `‖A v − f‖` in `f64`.
pub fn residual(design: &Design, v: &[f64], values: &[f64]) -> f64 {
    design
        .apply(v)
        .map(|av| {
            av.iter()
                .zip(values)
                .map(|(a, f)| (a - f) * (a - f))
                .sum::<f64>()
                .sqrt()
        })
        .unwrap_or(f64::NAN)
}

/// The brute-force query, the baseline of the O(1) location's speed: every triangle's three
/// edge planes (precomputed in `f32`), the triangle whose nearest edge plane is farthest (a
/// full scan of `20·4^L` triangles), then the area weights by the plain Van Oosterom–Strackee
/// form.
pub struct BruteForce<'a> {
    mesh: &'a Icosphere,
    planes: Vec<[Vec3; 3]>,
}

impl<'a> BruteForce<'a> {
    /// The edge planes of every triangle of `mesh`.
    pub fn new(mesh: &'a Icosphere) -> Self {
        let v = mesh.vertices();
        let planes = mesh
            .triangles()
            .iter()
            .map(|t| {
                let p = t.map(|k| v[k as usize]);
                [
                    p[1].cross(p[2]).normalize(),
                    p[2].cross(p[0]).normalize(),
                    p[0].cross(p[1]).normalize(),
                ]
            })
            .collect();
        Self { mesh, planes }
    }

    /// The function of `values` at `d` (non-zero, finite), by the scan.
    pub fn query(&self, values: &[f32], d: Vec3) -> f32 {
        let u = d.normalize();
        let mut best = (f32::NEG_INFINITY, 0);
        for (t, p) in self.planes.iter().enumerate() {
            let m = u.dot(p[0]).min(u.dot(p[1])).min(u.dot(p[2]));
            if m > best.0 {
                best = (m, t);
            }
        }
        let tri = self.mesh.triangles()[best.1];
        let v = tri.map(|k| self.mesh.vertices()[k as usize]);
        let area = |a: Vec3, b: Vec3, c: Vec3| {
            2.0 * a
                .dot(b.cross(c))
                .abs()
                .atan2(1.0 + a.dot(b) + b.dot(c) + c.dot(a))
        };
        let w = [
            area(u, v[1], v[2]),
            area(v[0], u, v[2]),
            area(v[0], v[1], u),
        ];
        let s = w[0] + w[1] + w[2];
        (0..3).map(|k| w[k] / s * values[tri[k] as usize]).sum()
    }
}
