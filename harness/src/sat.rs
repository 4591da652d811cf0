//! Summed-area tables in the harness: the f64 brute-force reference, the GPU query through
//! [`Gpu::run_custom`], the `steradian eval sat-box` handler, and the alternative storage
//! options the report measures against the one `steradian_core::rsl::sat` chose.

use serde_json::{Map, Value, json};
use steradian_core::rsl::sat::{Sat, SatView};
use steradian_core::wgsl;
use steradian_reference::rsl::sat::box_integral;

use crate::backend::BackendError;
use crate::backend::gpu::{Custom, Gpu};
use crate::json::{element_f32 as finite, num};
use crate::kernels::Columns;

/// A grid of texels, row-major (`texels[j·width + i]` is texel `(i, j)` covering
/// `[i, i+1]×[j, j+1]`).
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Texels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// `width·height` texels.
    pub texels: Vec<f32>,
}

/// Reference values of one box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxRef {
    /// `∫_B t`, summed in f64 over the texels the box overlaps (weights exact in f64).
    pub value: f64,
    /// `Σ|t|` over the texels the query reads (`I0 ≤ i ≤ I1`, `J0 ≤ j ≤ J1` of the core
    /// kernel): the `A` of the error bound.
    pub abs_read: f64,
    /// Number of texels the query reads: the `n` of the error bound.
    pub n_read: usize,
}

impl Grid {
    /// A grid; `Err` if `texels.len() ≠ width·height`.
    pub fn new(width: usize, height: usize, texels: Vec<f32>) -> Result<Grid, String> {
        if width.checked_mul(height) != Some(texels.len()) {
            return Err(format!(
                "{} texels for a {width}×{height} grid",
                texels.len()
            ));
        }
        Ok(Grid {
            width,
            height,
            texels,
        })
    }

    /// Texel `(i, j)`.
    pub fn at(&self, i: usize, j: usize) -> f32 {
        self.texels[j * self.width + i]
    }

    /// `Σ|t|` over the whole grid: the `T` of the error bound.
    pub fn abs_sum(&self) -> f64 {
        self.texels.iter().map(|t| (*t as f64).abs()).sum()
    }

    /// The exact box integral (the f64 brute force of `steradian-reference`) and the `A`,
    /// `n` of the bound.
    /// NaN corners give a NaN value.
    pub fn reference(&self, u0: f32, v0: f32, u1: f32, v1: f32) -> BoxRef {
        if [u0, v0, u1, v1].iter().any(|c| c.is_nan()) {
            return BoxRef {
                value: f64::NAN,
                abs_read: 0.0,
                n_read: 0,
            };
        }
        let value = box_integral(self.width, self.height, &self.texels, u0, v0, u1, v1);
        // The texels the core kernel reads: its (I0, I1) × (J0, J1).
        let (i0, _, i1, _) = steradian_core::rsl::sat::axis(u0, u1, self.width);
        let (j0, _, j1, _) = steradian_core::rsl::sat::axis(v0, v1, self.height);
        let mut abs_read = 0.0;
        for j in j0..=j1 {
            for i in i0..=i1 {
                abs_read += (self.at(i, j) as f64).abs();
            }
        }
        BoxRef {
            value,
            abs_read,
            n_read: (i1 - i0 + 1) * (j1 - j0 + 1),
        }
    }
}

/// The error bound of `steradian_core::rsl::sat` (module docs):
/// `2⁻²⁴·|I| + 2⁻¹⁵⁰ + 2⁻⁴⁶·A + n·2⁻⁵⁹·T`.
pub fn error_bound(r: &BoxRef, abs_sum: f64) -> f64 {
    r.value.abs() * 2f64.powi(-24)
        + 2f64.powi(-150)
        + r.abs_read * 2f64.powi(-46)
        + r.n_read as f64 * 2f64.powi(-59) * abs_sum
}

/// One `f32` ulp at the magnitude of `x` (`2^(⌊log2|x|⌋ − 23)`; the smallest subnormal
/// for 0).
pub fn ulp(x: f64) -> f64 {
    let x = (x as f32).abs();
    if x == 0.0 || !x.is_finite() {
        return f32::from_bits(1) as f64;
    }
    let next = f32::from_bits(x.to_bits() + 1);
    (next as f64 - x as f64).max(f32::from_bits(1) as f64)
}

/// The table [`SatView::gpu_words`] as the `f32` bit patterns `Custom::table` takes.
pub fn gpu_table(sat: &SatView<'_>) -> Vec<f32> {
    sat.gpu_words().map(f32::from_bits).collect()
}

/// Box sums on the GPU (`wgsl::SAT_BOX`): `queries` has the columns `[u0, v0, u1, v1]`,
/// `out` one column. `table` is [`gpu_table`] of the SAT (uploaded on every call).
pub fn gpu_box_sums(
    gpu: &mut Gpu,
    table: &[f32],
    queries: &Columns,
    out: &mut Columns,
) -> Result<(), BackendError> {
    let custom = Custom {
        label: "sat-box",
        source: wgsl::SAT_BOX,
        table: Some(table),
    };
    gpu.run_custom(&custom, queries, out)
}

/// The grid of a `sat-box` line: an array of equally long, non-empty rows of finite
/// numbers.
pub fn parse_grid(v: &Value) -> Result<Grid, String> {
    let rows = v
        .as_array()
        .ok_or("field \"grid\" must be an array of rows")?;
    if rows.is_empty() {
        return Err("field \"grid\" has no rows".into());
    }
    let mut width = None;
    let mut texels = Vec::new();
    for (j, row) in rows.iter().enumerate() {
        let row = row
            .as_array()
            .ok_or_else(|| format!("grid row {j} must be an array of numbers"))?;
        match width {
            None if row.is_empty() => return Err("grid row 0 is empty".into()),
            None => width = Some(row.len()),
            Some(w) if w != row.len() => {
                return Err(format!(
                    "grid is ragged: row {j} has {} values, row 0 has {w}",
                    row.len()
                ));
            }
            Some(_) => {}
        }
        for (i, x) in row.iter().enumerate() {
            texels.push(finite(x, &format!("grid[{j}][{i}]"))?);
        }
    }
    Grid::new(width.unwrap_or(0), rows.len(), texels)
}

/// `steradian eval sat-box`: `{"grid": [[…], …], "queries": [[u0, v0, u1, v1], …]}` →
/// `{"values": […]}`, the integrals over each box (texel units, corners in any order,
/// clipped to the grid; see `steradian_core::rsl::sat`).
pub fn eval_sat_box(obj: &Map<String, Value>) -> Result<Value, String> {
    let grid = parse_grid(obj.get("grid").ok_or("missing field \"grid\"")?)?;
    let queries = obj
        .get("queries")
        .ok_or("missing field \"queries\"")?
        .as_array()
        .ok_or("field \"queries\" must be an array of [u0, v0, u1, v1]")?;
    let sat = Sat::build(grid.width, grid.height, &grid.texels).map_err(|e| e.to_string())?;
    let mut values = Vec::with_capacity(queries.len());
    for (k, q) in queries.iter().enumerate() {
        let q = q
            .as_array()
            .filter(|a| a.len() == 4)
            .ok_or_else(|| format!("queries[{k}] must be [u0, v0, u1, v1]"))?;
        let c: Vec<f32> = q
            .iter()
            .enumerate()
            .map(|(i, x)| finite(x, &format!("queries[{k}][{i}]")))
            .collect::<Result<_, _>>()?;
        let v = sat.box_sum(c[0], c[1], c[2], c[3]);
        if !v.is_finite() {
            return Err(format!("queries[{k}]: the integral overflows f32"));
        }
        values.push(num(v));
    }
    Ok(json!({ "values": values }))
}

/// Alternative SAT storage options, measured by the report against the core's choice.
/// Each answers the same fractional-corner box query its own natural way.
pub mod options {
    use super::Grid;

    /// Bilinear interpolation of a `(w+1)×(h+1)` table at `(u, v)` (clipped), in f64.
    fn bilinear(s: &impl Fn(usize, usize) -> f64, w: usize, h: usize, u: f64, v: f64) -> f64 {
        let u = u.clamp(0.0, w as f64);
        let v = v.clamp(0.0, h as f64);
        let i = (u.floor() as usize).min(w - 1);
        let j = (v.floor() as usize).min(h - 1);
        let (a, b) = (u - i as f64, v - j as f64);
        let s00 = s(i, j);
        let s10 = s(i + 1, j);
        let s01 = s(i, j + 1);
        let s11 = s(i + 1, j + 1);
        (1.0 - b) * ((1.0 - a) * s00 + a * s10) + b * ((1.0 - a) * s01 + a * s11)
    }

    fn order(c0: f32, c1: f32) -> (f32, f32) {
        if c1 < c0 { (c1, c0) } else { (c0, c1) }
    }

    /// The box query of the f64-cornered options: the corners ordered, four bilinear
    /// corners of the table `s` in f64, combined as `(S11 − S01) − (S10 − S00)`, rounded
    /// to f32.
    fn box_f64(
        s: impl Fn(usize, usize) -> f64,
        w: usize,
        h: usize,
        [u0, v0, u1, v1]: [f32; 4],
    ) -> f64 {
        let (u0, u1) = order(u0, u1);
        let (v0, v1) = order(v0, v1);
        let c = |u: f32, v: f32| bilinear(&s, w, h, u as f64, v as f64);
        ((c(u1, v1) - c(u0, v1)) - (c(u1, v0) - c(u0, v0))) as f32 as f64
    }

    /// Bilinear interpolation in `f32` of a `(w+1)×(h+1)` `f32` table at `(u, v)`
    /// (clipped), as a texture unit would.
    fn corner_f32(s: &[f32], w: usize, h: usize, u: f32, v: f32) -> f32 {
        let u = u.clamp(0.0, w as f32);
        let v = v.clamp(0.0, h as f32);
        let i = (u.floor() as usize).min(w - 1);
        let j = (v.floor() as usize).min(h - 1);
        let (a, b) = (u - i as f32, v - j as f32);
        let w1 = w + 1;
        let s00 = s[j * w1 + i];
        let s10 = s[j * w1 + i + 1];
        let s01 = s[(j + 1) * w1 + i];
        let s11 = s[(j + 1) * w1 + i + 1];
        (1.0 - b) * ((1.0 - a) * s00 + a * s10) + b * ((1.0 - a) * s01 + a * s11)
    }

    /// The f64 SAT of `f(t)` over the texels (f64 accumulation), entries at `l·(w+1) + k`.
    fn prefix_f64(g: &Grid, f: impl Fn(f32) -> f64) -> Vec<f64> {
        let w1 = g.width + 1;
        let mut s = vec![0.0f64; w1 * (g.height + 1)];
        for j in 0..g.height {
            let mut acc = 0.0;
            for i in 0..g.width {
                acc += f(g.at(i, j));
                s[(j + 1) * w1 + i + 1] = s[j * w1 + i + 1] + acc;
            }
        }
        s
    }

    /// The f64 SAT of the texels (f64 accumulation), entries at `l·(w+1) + k`.
    pub fn sat_f64(g: &Grid) -> Vec<f64> {
        prefix_f64(g, f64::from)
    }

    /// A storage option.
    pub trait Storage {
        /// Short name for the report.
        fn name(&self) -> &'static str;
        /// Bytes of the table.
        fn bytes(&self) -> usize;
        /// The box integral.
        fn box_sum(&self, u0: f32, v0: f32, u1: f32, v1: f32) -> f64;
    }

    /// Plain `f32` SAT (f32 accumulation, like the `summed-area` crate or a GPU prefix
    /// sum); query: four bilinear corners in `f32`, as a texture unit would.
    pub struct PlainF32 {
        w: usize,
        h: usize,
        s: Vec<f32>,
    }

    impl PlainF32 {
        /// Builds it.
        pub fn build(g: &Grid) -> Self {
            let w1 = g.width + 1;
            let mut s = vec![0.0f32; w1 * (g.height + 1)];
            for j in 0..g.height {
                let mut acc = 0.0f32;
                for i in 0..g.width {
                    acc += g.at(i, j);
                    s[(j + 1) * w1 + i + 1] = s[j * w1 + i + 1] + acc;
                }
            }
            PlainF32 {
                w: g.width,
                h: g.height,
                s,
            }
        }

        /// Bilinear corner value in f32.
        #[inline]
        fn corner(&self, u: f32, v: f32) -> f32 {
            corner_f32(&self.s, self.w, self.h, u, v)
        }

        /// Integer-corner box sum, four lookups in f32 (the peers' query).
        #[inline]
        pub fn box_sum_int(&self, x0: usize, y0: usize, x1: usize, y1: usize) -> f32 {
            let w1 = self.w + 1;
            let s = &self.s;
            s[y1 * w1 + x1] - s[y0 * w1 + x1] - s[y1 * w1 + x0] + s[y0 * w1 + x0]
        }

        /// The fractional box query in f32.
        #[inline]
        pub fn box_sum_f32(&self, u0: f32, v0: f32, u1: f32, v1: f32) -> f32 {
            let (u0, u1) = order(u0, u1);
            let (v0, v1) = order(v0, v1);
            self.corner(u1, v1) - self.corner(u0, v1) - self.corner(u1, v0) + self.corner(u0, v0)
        }
    }

    impl Storage for PlainF32 {
        fn name(&self) -> &'static str {
            "f32"
        }
        fn bytes(&self) -> usize {
            self.s.len() * 4
        }
        fn box_sum(&self, u0: f32, v0: f32, u1: f32, v1: f32) -> f64 {
            self.box_sum_f32(u0, v0, u1, v1) as f64
        }
    }

    /// `f32` SAT of `t − mean` (summed in f64, stored in f32); query in f32 plus
    /// `mean·area`.
    pub struct MeanOffsetF32 {
        w: usize,
        h: usize,
        mean: f64,
        s: Vec<f32>,
    }

    impl MeanOffsetF32 {
        /// Builds it.
        pub fn build(g: &Grid) -> Self {
            let mean = g.texels.iter().map(|t| *t as f64).sum::<f64>() / g.texels.len() as f64;
            let s = prefix_f64(g, |t| t as f64 - mean);
            MeanOffsetF32 {
                w: g.width,
                h: g.height,
                mean,
                s: s.into_iter().map(|x| x as f32).collect(),
            }
        }
    }

    impl Storage for MeanOffsetF32 {
        fn name(&self) -> &'static str {
            "f32, mean subtracted"
        }
        fn bytes(&self) -> usize {
            self.s.len() * 4 + 8
        }
        fn box_sum(&self, u0: f32, v0: f32, u1: f32, v1: f32) -> f64 {
            let (u0, u1) = order(u0, u1);
            let (v0, v1) = order(v0, v1);
            let (w, h) = (self.w, self.h);
            let c = |u: f32, v: f32| corner_f32(&self.s, w, h, u, v);
            let d = c(u1, v1) - c(u0, v1) - c(u1, v0) + c(u0, v0);
            let cl = |x: f32, n: usize| (x as f64).clamp(0.0, n as f64);
            let area = (cl(u1, w) - cl(u0, w)) * (cl(v1, h) - cl(v0, h));
            (d as f64 + (self.mean * area) as f32 as f64) as f32 as f64
        }
    }

    /// Tiles of `T×T` entries with a local offset: each tile stores its origin entry in f64
    /// and the others as `f32` differences from it; query: four bilinear corners in f64.
    pub struct TiledF32 {
        w: usize,
        h: usize,
        tile: usize,
        tiles_x: usize,
        base: Vec<f64>,
        local: Vec<f32>,
    }

    impl TiledF32 {
        /// Builds it with tiles of `tile×tile` entries.
        pub fn build(g: &Grid, tile: usize) -> Self {
            let s = sat_f64(g);
            let w1 = g.width + 1;
            let h1 = g.height + 1;
            let tiles_x = w1.div_ceil(tile);
            let tiles_y = h1.div_ceil(tile);
            let mut base = vec![0.0; tiles_x * tiles_y];
            for ty in 0..tiles_y {
                for tx in 0..tiles_x {
                    base[ty * tiles_x + tx] = s[ty * tile * w1 + tx * tile];
                }
            }
            let local = (0..h1 * w1)
                .map(|at| {
                    let (k, l) = (at % w1, at / w1);
                    (s[at] - base[(l / tile) * tiles_x + k / tile]) as f32
                })
                .collect();
            TiledF32 {
                w: g.width,
                h: g.height,
                tile,
                tiles_x,
                base,
                local,
            }
        }
    }

    impl Storage for TiledF32 {
        fn name(&self) -> &'static str {
            "f32 + f64 offset per 16² tile"
        }
        fn bytes(&self) -> usize {
            self.local.len() * 4 + self.base.len() * 8
        }
        fn box_sum(&self, u0: f32, v0: f32, u1: f32, v1: f32) -> f64 {
            let w1 = self.w + 1;
            let s = |k: usize, l: usize| {
                self.base[(l / self.tile) * self.tiles_x + k / self.tile]
                    + self.local[l * w1 + k] as f64
            };
            box_f64(s, self.w, self.h, [u0, v0, u1, v1])
        }
    }

    /// hi/lo `f32` pairs of the f64 SAT (`hi = f32(S)`, `lo = f32(S − hi)`); query: the
    /// pairs summed exactly into f64, four bilinear corners in f64.
    pub struct HiLoF32 {
        w: usize,
        h: usize,
        hi: Vec<f32>,
        lo: Vec<f32>,
    }

    impl HiLoF32 {
        /// Builds it.
        pub fn build(g: &Grid) -> Self {
            let s = sat_f64(g);
            let hi: Vec<f32> = s.iter().map(|x| *x as f32).collect();
            let lo = s
                .iter()
                .zip(&hi)
                .map(|(x, h)| (x - *h as f64) as f32)
                .collect();
            HiLoF32 {
                w: g.width,
                h: g.height,
                hi,
                lo,
            }
        }
    }

    impl Storage for HiLoF32 {
        fn name(&self) -> &'static str {
            "hi/lo f32 pair"
        }
        fn bytes(&self) -> usize {
            self.hi.len() * 8
        }
        fn box_sum(&self, u0: f32, v0: f32, u1: f32, v1: f32) -> f64 {
            let w1 = self.w + 1;
            let s = |k: usize, l: usize| self.hi[l * w1 + k] as f64 + self.lo[l * w1 + k] as f64;
            box_f64(s, self.w, self.h, [u0, v0, u1, v1])
        }
    }

    /// The f64 SAT; query: four bilinear corners in f64.
    pub struct PlainF64 {
        w: usize,
        h: usize,
        s: Vec<f64>,
    }

    impl PlainF64 {
        /// Builds it.
        pub fn build(g: &Grid) -> Self {
            PlainF64 {
                w: g.width,
                h: g.height,
                s: sat_f64(g),
            }
        }
    }

    impl Storage for PlainF64 {
        fn name(&self) -> &'static str {
            "f64"
        }
        fn bytes(&self) -> usize {
            self.s.len() * 8
        }
        fn box_sum(&self, u0: f32, v0: f32, u1: f32, v1: f32) -> f64 {
            let w1 = self.w + 1;
            box_f64(|k, l| self.s[l * w1 + k], self.w, self.h, [u0, v0, u1, v1])
        }
    }

    /// The core's table (`i64` fixed point, nine exact sub-sums).
    pub struct Fixed(pub steradian_core::rsl::sat::Sat);

    impl Storage for Fixed {
        fn name(&self) -> &'static str {
            "i64 fixed point (steradian)"
        }
        fn bytes(&self) -> usize {
            self.0.bytes()
        }
        fn box_sum(&self, u0: f32, v0: f32, u1: f32, v1: f32) -> f64 {
            self.0.box_sum(u0, v0, u1, v1) as f64
        }
    }
}
