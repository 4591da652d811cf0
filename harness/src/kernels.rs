//! The batch kernels every backend runs ([`Batch`], [`Kernel`]), and their batch layout.
//!
//! A batch is structure-of-arrays: [`Columns`] holds `arity` columns of `n` `f32` each,
//! column `c` at `data[c·n .. (c+1)·n]`. The same layout is uploaded to the GPU.

use std::fmt;

use crate::rng::Rng;

/// Everything the backends, the workload and the accuracy check need of one batch kernel
/// (the kernels every backend runs over [`Columns`]). One per kernel, written beside its
/// paper's other batch kernels (`batch/lobe.rs`, `batch/rsl.rs`) and registered once in
/// [`crate::registry::KERNELS`]; nothing else matches on a kernel.
pub struct Batch {
    /// Name in `steradian eval` and `report.json`.
    pub name: &'static str,
    /// Input columns.
    pub inputs: usize,
    /// Output columns.
    pub outputs: usize,
    /// Salt of the workload's generator (kept per kernel so each kernel's default workload
    /// is the same bytes from run to run and release to release).
    pub seed: u64,
    /// The scalar kernel over columns; `opaque` routes every value through
    /// [`std::hint::black_box`] (the `cpu-scalar` backend: one call per row, no
    /// auto-vectorisation), otherwise the compiler may vectorise the loop
    /// (`cpu-scalar-loop`).
    pub scalar: fn(&Columns, &mut Columns, bool),
    /// The SIMD slice kernel of `steradian-simd` over columns.
    pub simd: fn(&Columns, &mut Columns),
    /// Whether the WGSL kernel (the registry entry's `wgsl`) reads the built-in cap-exponent
    /// table at binding 3.
    pub cap_table: bool,
    /// Named hard cases, one row each.
    pub hard_cases: fn() -> Vec<(&'static str, Vec<f32>)>,
    /// One pseudo-random row over the kernel's whole domain.
    pub random_row: fn(&mut Rng) -> Vec<f32>,
    /// The f64 reference of one input row (the values [`Batch::error`] compares with).
    pub reference: fn(&[f32]) -> Vec<f64>,
    /// The error of one output row in the kernel's metric, from the input row, the output
    /// (widened) and the reference values.
    pub error: fn(&[f32], &[f64], &[f64]) -> f64,
}

/// `x`, through [`std::hint::black_box`] when `opaque` (see [`Batch::scalar`]).
#[inline(always)]
pub fn bb<T>(x: T, opaque: bool) -> T {
    if opaque { std::hint::black_box(x) } else { x }
}

/// A batch kernel of the library: a handle to its [`Batch`], compared by name.
#[derive(Clone, Copy)]
pub struct Kernel(pub &'static Batch);

impl Kernel {
    /// The kernel's name (`hemisphere-map`, …).
    pub const fn name(self) -> &'static str {
        self.0.name
    }

    /// The kernel's description.
    pub const fn spec(self) -> &'static Batch {
        self.0
    }

    /// Number of input columns.
    pub fn input_arity(self) -> usize {
        self.0.inputs
    }

    /// Number of output columns.
    pub fn output_arity(self) -> usize {
        self.0.outputs
    }
}

impl PartialEq for Kernel {
    fn eq(&self, other: &Kernel) -> bool {
        self.name() == other.name()
    }
}
impl Eq for Kernel {}

impl std::hash::Hash for Kernel {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        self.name().hash(h);
    }
}

impl fmt::Debug for Kernel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Kernel({})", self.name())
    }
}

impl fmt::Display for Kernel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// `arity` columns of `n` values each, column-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Columns {
    /// Values per column.
    pub n: usize,
    /// Number of columns.
    pub arity: usize,
    /// `arity · n` values, column `c` at `c·n .. (c+1)·n`.
    pub data: Vec<f32>,
}

impl Columns {
    /// Zero-filled columns.
    pub fn zeros(arity: usize, n: usize) -> Self {
        Columns {
            n,
            arity,
            data: vec![0.0; arity * n],
        }
    }

    /// Builds columns from rows of length `arity`.
    pub fn from_rows<const A: usize>(rows: &[[f32; A]]) -> Self {
        let n = rows.len();
        let mut c = Columns::zeros(A, n);
        for (i, r) in rows.iter().enumerate() {
            for (k, v) in r.iter().enumerate() {
                c.data[k * n + i] = *v;
            }
        }
        c
    }

    /// Column `c`.
    pub fn col(&self, c: usize) -> &[f32] {
        &self.data[c * self.n..(c + 1) * self.n]
    }

    /// Column `c`, mutable.
    pub fn col_mut(&mut self, c: usize) -> &mut [f32] {
        &mut self.data[c * self.n..(c + 1) * self.n]
    }

    /// Row `i` as a vector.
    pub fn row(&self, i: usize) -> Vec<f32> {
        (0..self.arity).map(|c| self.data[c * self.n + i]).collect()
    }
}
