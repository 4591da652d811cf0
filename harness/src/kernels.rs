//! The kernels every backend runs, and their batch layout.
//!
//! A batch is structure-of-arrays: [`Columns`] holds `arity` columns of `n` `f32` each,
//! column `c` at `data[c·n .. (c+1)·n]`. The same layout is uploaded to the GPU.

use std::fmt;

/// A kernel of the library, as named in `steradian eval` and `report.json`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Kernel {
    /// Equal-area hemisphere map: `[x, y, z] → [u, v]`.
    HemisphereMap,
    /// Its inverse: `[u, v] → [x, y, z]`.
    HemisphereUnmap,
    /// Cosine lobe evaluation: `[ax, ay, az, s, e, vx, vy, vz] → [value]`.
    LobeEval,
    /// Exact lobe integral: `[e, s] → [integral]`.
    LobeIntegral,
    /// Cap → lobe L2 exponent from the table: `[half_angle] → [exponent]`.
    CapExponent,
}

impl Kernel {
    /// Every kernel, in report order.
    pub const ALL: [Kernel; 5] = [
        Kernel::HemisphereMap,
        Kernel::HemisphereUnmap,
        Kernel::LobeEval,
        Kernel::LobeIntegral,
        Kernel::CapExponent,
    ];

    /// The kernel's name (`hemisphere-map`, …).
    pub const fn name(self) -> &'static str {
        match self {
            Kernel::HemisphereMap => "hemisphere-map",
            Kernel::HemisphereUnmap => "hemisphere-unmap",
            Kernel::LobeEval => "lobe-eval",
            Kernel::LobeIntegral => "lobe-integral",
            Kernel::CapExponent => "cap-exponent",
        }
    }

    /// Looks a kernel up by name.
    pub fn from_name(name: &str) -> Option<Kernel> {
        Kernel::ALL.into_iter().find(|k| k.name() == name)
    }

    /// Number of input columns.
    pub fn input_arity(self) -> usize {
        match self {
            Kernel::HemisphereMap => 3,
            Kernel::HemisphereUnmap => 2,
            Kernel::LobeEval => 8,
            Kernel::LobeIntegral => 2,
            Kernel::CapExponent => 1,
        }
    }

    /// Number of output columns.
    pub fn output_arity(self) -> usize {
        match self {
            Kernel::HemisphereMap => 2,
            Kernel::HemisphereUnmap => 3,
            _ => 1,
        }
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
