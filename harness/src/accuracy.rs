//! Per-kernel error metrics against the f64 references, and their summary statistics.

use serde::Serialize;

use crate::kernels::{Columns, Kernel};

/// Name of the error metric of a kernel (as in `report.json`; from the registry).
pub fn metric(kernel: Kernel) -> &'static str {
    match crate::registry::of(kernel).bound {
        crate::registry::Piece::At(b) => b.metric,
        crate::registry::Piece::Without(_) => "none",
    }
}

/// The documented bound of a kernel in its metric (from the registry).
pub fn bound(kernel: Kernel) -> f64 {
    crate::registry::of(kernel)
        .bound
        .get()
        .and_then(|b| b.value)
        .unwrap_or(f64::NAN)
}

pub use crate::batch::lobe::lobe_eval_error;

/// Reference data for the first `rows` rows of a batch (computed once, compared against
/// every backend).
pub struct Reference {
    kernel: Kernel,
    /// Per row: the kernel's reference values (`Batch::reference`).
    values: Vec<Vec<f64>>,
}

/// Computes the reference for the first `rows` rows of `input`.
pub fn reference(kernel: Kernel, input: &Columns, rows: usize) -> Reference {
    let rows = rows.min(input.n);
    let values = (0..rows)
        .map(|i| (kernel.spec().reference)(&input.row(i)))
        .collect();
    Reference { kernel, values }
}

/// The error of row `i` of `out` in the kernel's metric (`+∞` for a non-finite output where
/// the reference is finite).
pub fn row_error(r: &Reference, input: &Columns, out: &Columns, i: usize) -> f64 {
    let got: Vec<f64> = out.row(i).into_iter().map(f64::from).collect();
    let want = &r.values[i];
    let err = (r.kernel.spec().error)(&input.row(i), &got, want);
    if err.is_nan() { f64::INFINITY } else { err }
}

/// Summary of a kernel's errors over a batch.
#[derive(Clone, Debug, Serialize)]
pub struct ErrorStats {
    /// Metric name ([`metric`]).
    pub metric: &'static str,
    /// Largest error.
    pub max: f64,
    /// Mean error.
    pub mean: f64,
    /// 99th percentile.
    pub p99: f64,
    /// Rows compared.
    pub n: usize,
    /// Row index of the largest error.
    pub argmax: usize,
}

/// Errors of `out` against `r` over its rows.
pub fn stats(r: &Reference, input: &Columns, out: &Columns) -> ErrorStats {
    let mut errs: Vec<f64> = (0..r.values.len())
        .map(|i| row_error(r, input, out, i))
        .collect();
    let (argmax, max) =
        errs.iter().copied().enumerate().fold(
            (0, 0.0),
            |(bi, b), (i, e)| if e > b { (i, e) } else { (bi, b) },
        );
    let mean = errs.iter().sum::<f64>() / errs.len().max(1) as f64;
    errs.sort_by(f64::total_cmp);
    let p99 = errs
        .get(((errs.len() as f64) * 0.99) as usize)
        .copied()
        .unwrap_or(0.0);
    ErrorStats {
        metric: metric(r.kernel),
        max,
        mean,
        p99,
        n: errs.len(),
        argmax,
    }
}
