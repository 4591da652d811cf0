//! Per-kernel error metrics against the f64 references, and their summary statistics.

use serde::Serialize;

use crate::kernels::{Columns, Kernel};
use crate::reference;

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

/// The lobe-eval metric `|c − c*| / (|c*|·κ)` with
/// `κ = 1 + |ln(c*/s)| + (EVAL_DOT_ERROR/EVAL_REL_ERROR)·e/(a·v)`, so that the documented
/// bound of `steradian_core::lobe` reads `metric ≤ EVAL_REL_ERROR`. Where `c*` is below
/// `1e-30·|s|` (f32 cannot hold it relative to `s`) it is the absolute error over `|s|`.
pub fn lobe_eval_error(axis: [f32; 3], s: f32, e: f32, v: [f32; 3], got: f64) -> f64 {
    use steradian_core::lobe::{EVAL_DOT_ERROR, EVAL_REL_ERROR};
    let want = reference::lobe_eval(axis, s, e, v);
    let s = s as f64;
    if want.abs() < 1e-30 * s.abs() || want == 0.0 {
        return (got - want).abs() / s.abs().max(f64::MIN_POSITIVE);
    }
    let (Some(a), Some(v)) = (reference::normalize(axis), reference::normalize(v)) else {
        return f64::INFINITY;
    };
    let d = a[0] * v[0] + a[1] * v[1] + a[2] * v[2];
    let e = (e as f64).max(0.0);
    let kappa = 1.0 + (want / s).ln().abs() + (EVAL_DOT_ERROR / EVAL_REL_ERROR) as f64 * e / d;
    (got - want).abs() / (want.abs() * kappa)
}

/// Reference data for the first `rows` rows of a batch (computed once, compared against
/// every backend).
pub struct Reference {
    kernel: Kernel,
    /// Per row: the exact outputs (for the cap exponent: `[e*, J(e*)]`).
    values: Vec<Vec<f64>>,
}

/// Computes the reference for the first `rows` rows of `input`.
pub fn reference(kernel: Kernel, input: &Columns, rows: usize) -> Reference {
    let rows = rows.min(input.n);
    let values = (0..rows)
        .map(|i| {
            let r = input.row(i);
            match kernel {
                Kernel::HemisphereMap => reference::hemisphere_map([r[0], r[1], r[2]]).to_vec(),
                Kernel::HemisphereUnmap => reference::hemisphere_unmap([r[0], r[1]]).to_vec(),
                Kernel::LobeEval => vec![reference::lobe_eval(
                    [r[0], r[1], r[2]],
                    r[3],
                    r[4],
                    [r[5], r[6], r[7]],
                )],
                Kernel::LobeIntegral => vec![reference::lobe_integral(r[0], r[1])],
                Kernel::CapExponent => {
                    let a = r[0] as f64;
                    let e = reference::cap::optimal_exponent(a);
                    vec![e, reference::cap::objective(e, a)]
                }
            }
        })
        .collect();
    Reference { kernel, values }
}

/// The error of row `i` of `out` in the kernel's metric (`+∞` for a non-finite output where
/// the reference is finite).
pub fn row_error(r: &Reference, input: &Columns, out: &Columns, i: usize) -> f64 {
    let got: Vec<f64> = out.row(i).into_iter().map(f64::from).collect();
    let want = &r.values[i];
    let err = match r.kernel {
        Kernel::HemisphereMap | Kernel::HemisphereUnmap => got
            .iter()
            .zip(want)
            .map(|(g, w)| (g - w).abs())
            .fold(0.0, f64::max),
        Kernel::LobeEval => {
            let r = input.row(i);
            lobe_eval_error([r[0], r[1], r[2]], r[3], r[4], [r[5], r[6], r[7]], got[0])
        }
        Kernel::LobeIntegral => {
            let (g, w) = (got[0], want[0]);
            if w == 0.0 {
                g.abs()
            } else {
                ((g - w) / w).abs()
            }
        }
        Kernel::CapExponent => {
            let a = input.row(i)[0] as f64;
            let best = want[1];
            let j = reference::cap::objective(got[0], a);
            if best > 0.0 {
                (j / best - 1.0).max(0.0)
            } else {
                j / reference::cap_solid_angle(a)
            }
        }
    };
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
