//! The lobe product on the GPU: [`steradian_core::wgsl::LOBE_PRODUCT`] (the scalar
//! `product::product_with` with `ProductFit::ExactIntegral`) run through [`Gpu::run_custom`]
//! with the product table at binding 3 as `[exponents, angles, g…]` in `f32`.
//!
//! The table layout is core's (`ProductTable::gpu_table`).
//!
//! [`run_lobe_product_gpu`] is the convenience the report and the tests time: lobes in,
//! lobes out, one full round trip (upload of the batch and of the table, dispatch,
//! read-back). [`ProductGpuTable`] decodes a table once for repeated runs.

use steradian_core::lobe::CosineLobe;
use steradian_core::lobe::product::{self, ProductTable};
use steradian_core::{Vec3, wgsl};

use super::BackendError;
use super::gpu::{Custom, Gpu};
use crate::kernels::Columns;

/// A product table decoded for the GPU kernel: `[exponents, angles, g…]`.
#[derive(Clone, Debug)]
pub struct ProductGpuTable(Vec<f32>);

impl ProductGpuTable {
    /// The built-in table (`product::TABLE_BYTES`).
    pub fn builtin() -> Result<Self, BackendError> {
        Self::from_bytes(product::TABLE_BYTES)
    }

    /// A product table file (`steradian_core::table` format, as
    /// `ProductTable::from_bytes` accepts), validated and decoded.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, BackendError> {
        let bad = |e: &dyn std::fmt::Debug| BackendError(format!("lobe-product table: {e:?}"));
        let t = ProductTable::from_bytes(bytes).map_err(|e| bad(&e))?;
        let data = t.gpu_table();
        Ok(ProductGpuTable(data))
    }

    /// The values bound at binding 3.
    pub fn as_slice(&self) -> &[f32] {
        &self.0
    }
}

/// The 10 input columns `[a1x, a1y, a1z, s1, e1, a2x, a2y, a2z, s2, e2]` of
/// [`wgsl::LOBE_PRODUCT`] for the pairs `(a, b)`, one row per pair.
pub fn lobe_product_input<'a>(
    pairs: impl IntoIterator<Item = (&'a CosineLobe, &'a CosineLobe)>,
) -> Columns {
    let rows: Vec<[f32; 10]> = pairs
        .into_iter()
        .map(|(x, y)| {
            let (p, q) = (x.axis(), y.axis());
            [
                p.x,
                p.y,
                p.z,
                x.scale(),
                x.exponent(),
                q.x,
                q.y,
                q.z,
                y.scale(),
                y.exponent(),
            ]
        })
        .collect();
    Columns::from_rows(&rows)
}

/// Runs [`wgsl::LOBE_PRODUCT`] on `input` (the 10 columns
/// `[a1x, a1y, a1z, s1, e1, a2x, a2y, a2z, s2, e2]`) into `out` (5 columns
/// `[ax, ay, az, scale, exponent]`, same length).
pub fn run_lobe_product_columns(
    gpu: &mut Gpu,
    table: &ProductGpuTable,
    input: &Columns,
    out: &mut Columns,
) -> Result<(), BackendError> {
    if input.arity != 10 || out.arity != 5 {
        return Err(BackendError(format!(
            "lobe-product: expected 10 input and 5 output columns, got {} and {}",
            input.arity, out.arity
        )));
    }
    let custom = Custom {
        label: "lobe-product",
        source: wgsl::LOBE_PRODUCT,
        table: Some(table.as_slice()),
    };
    gpu.run_custom(&custom, input, out)
}

/// The product `a[i]·b[i]` of each pair on the GPU with the built-in table (`a` and `b` of
/// one length). Finite lobes only (see [`wgsl::LOBE_PRODUCT`]); the result lobes are
/// rebuilt with `CosineLobe::saturating`.
pub fn run_lobe_product_gpu(
    gpu: &mut Gpu,
    a: &[CosineLobe],
    b: &[CosineLobe],
) -> Result<Vec<CosineLobe>, BackendError> {
    if a.len() != b.len() {
        return Err(BackendError(format!(
            "lobe-product: {} lobes against {}",
            a.len(),
            b.len()
        )));
    }
    let table = ProductGpuTable::builtin()?;
    let input = lobe_product_input(a.iter().zip(b));
    let n = input.n;
    let mut out = Columns::zeros(5, n);
    run_lobe_product_columns(gpu, &table, &input, &mut out)?;
    let col = |c: usize, i: usize| out.data[c * n + i];
    Ok((0..n)
        .map(|i| {
            CosineLobe::saturating(
                Vec3::new(col(0, i), col(1, i), col(2, i)),
                col(3, i),
                col(4, i),
            )
        })
        .collect())
}
