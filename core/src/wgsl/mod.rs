//! WGSL sources of the GPU kernels, mirroring the scalar ones, as `pub const &str` so a
//! renderer can embed them. Each source is one compute entry point `main` with
//! `@workgroup_size(64)` reading storage buffers; see each constant for its bindings. The
//! batch layout below is written once, in `wgsl/batch.wgsl`, and prepended to every source,
//! so each constant is a complete shader. Functions that several kernels use are written
//! once too and concatenated into each of them: `wgsl/log1p.wgsl` (`log` without WGSL's
//! `log`), `wgsl/atan2.wgsl` (`atan2` with full relative precision), `rsl/sat_lib.wgsl` (SAT box sums) and `rsl/vdt_lib.wgsl` (VDT queries).
//!
//! ## Bindings (identical for every kernel)
//!
//! ```wgsl
//! struct Params { n: u32, row_stride: u32, _pad0: u32, _pad1: u32 }
//! @group(0) @binding(0) var<storage, read> input: array<f32>;        // column-major
//! @group(0) @binding(1) var<storage, read_write> output: array<f32>; // column-major
//! @group(0) @binding(2) var<uniform> params: Params;
//! @group(0) @binding(3) var<storage, read> table: array<f32>;        // or array<u32>
//! ```
//!
//! Binding 3 is the kernel's table: the cap-exponent table in [`CAP_EXPONENT`], a
//! caller-supplied table for the kernels of [`CUSTOM`] (its element type listed there, its
//! layout documented at each constant and packed in core beside the table it holds);
//! the other kernels of [`ALL`] declare none.
//!
//! A batch of `n` rows is structure-of-arrays: input column `c` of row `i` is
//! `input[c·n + i]`, output column `c` is `output[c·n + i]`. Thread `gid` handles row
//! `i = gid.x + gid.y·row_stride` (`row_stride` = threads per row of the dispatch grid, i.e.
//! `64 ×` the workgroups dispatched along x), so more than `65535 × 64` rows fit in one
//! dispatch by folding the workgroups into a 2-D grid; threads with `i ≥ n` return at
//! once. The input and output arities are those of the scalar kernels (see each constant).
//!
//! ## Input contract: finite inputs
//!
//! WGSL gives no guarantee for NaN and infinities (comparisons, `min`/`max`/`clamp` with a
//! NaN operand are implementation-defined, and a compiler may assume no value is NaN or
//! infinite), and f32 subnormals may be flushed to zero. So the GPU kernels are specified
//! for **finite, normal (or zero) inputs whose intermediate values do not overflow** only;
//! for those they follow the scalar kernels formula for formula (same order of operations,
//! clamps and fallbacks: zero vector → pole, lower hemisphere mirrored `z → |z|`, points
//! outside the disk clamped onto the circle, a negative exponent clamped to 0, the cap
//! half-angle clamped to `[MIN_HALF_ANGLE, π/2]`), with two deliberate exceptions, both
//! explained at their constant: [`HEMISPHERE_MAP`] normalises by a power of two instead of
//! `1/m`, and [`LOBE_EVAL`] computes `log1p` without `log`. What the scalar kernels do with NaN
//! (NaN out) is not promised on the GPU. Results that are subnormal on the CPU may be 0.
//!
//! ## Accuracy against the scalar kernels
//!
//! WGSL's `sqrt`, `inverseSqrt`, division, `exp` and `log` are not correctly rounded (the
//! spec allows 2.5 ULP for division, `3 + 2|x|` ULP for `exp`, 3 ULP or `2⁻²¹` absolute
//! for `log`, and a compiler may fuse `a·b + c`), so a GPU result is not bit-identical to
//! the CPU one. Each kernel states a tolerance against its scalar kernel below, as a
//! constant; the harness test `tests/gpu.rs` checks it on every adapter it runs on, with
//! random and hand-picked finite inputs. The values were measured on lavapipe (Mesa
//! llvmpipe, Vulkan) with some margin; a driver with worse transcendental functions may
//! need more.

/// The types a renderer uploads (`CosineLobe`, `SphericalCap`, `Rsl`, `ShadeLight`) as WGSL
/// structs with the byte layout of the `#[repr(C)]` Rust types (each type's `LAYOUT`, a
/// [`Layout`]); no entry point, for a renderer to prepend to its own shaders.
pub const TYPES: &str = include_str!("types.wgsl");

/// The byte layout of a `#[repr(C)]` type that has a WGSL twin in [`TYPES`]: its size and
/// each field's offset, from `size_of` and `offset_of!` (the harness compares them with
/// naga's layout of the WGSL struct).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// The struct's name, in Rust and in [`TYPES`].
    pub name: &'static str,
    /// `size_of`, bytes.
    pub size: usize,
    /// `(field, offset in bytes)`, in declaration order.
    pub fields: &'static [(&'static str, usize)],
}

/// Equal-area hemisphere map, direction → disk point (`hemisphere::map`).
/// Input columns `[x, y, z]`, output `[u, v]`.
///
/// Unlike the scalar kernel the input is scaled by the power of two `2^-exp(m)`
/// (`m` the largest component) rather than `1/m`, which is subnormal — and may be flushed
/// to zero on a GPU — for `m > 2¹²⁶`; the two differ by a common factor the normalisation
/// removes. Tolerance: [`HEMISPHERE_MAP_ABS_TOL`].
pub const HEMISPHERE_MAP: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../rsl/hemisphere_map.wgsl")
);
/// Inverse hemisphere map, disk point → unit direction (`hemisphere::unmap`).
/// Input columns `[u, v]`, output `[x, y, z]`. Points with `|p|² > 1` are clamped onto
/// the unit circle; `|p|` must stay below `1.8e19` so that `|p|²` is finite.
/// Tolerance: [`HEMISPHERE_UNMAP_ABS_TOL`].
pub const HEMISPHERE_UNMAP: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../rsl/hemisphere_unmap.wgsl")
);
/// Cosine lobe `s·max(a·v, 0)^e` as `s·exp(e·log1p(−|a − v|²/2))`, 0 where
/// `|a − v|²/2 ≥ 1` (`lobe::eval`). Input columns `[ax, ay, az, s, e, vx, vy, vz]`, output
/// `[value]`.
///
/// WGSL has no `log1p`, and the textbook substitute `u = 1 + x; log(u)·x/(u − 1)` fails on
/// real drivers: Mesa was seen to fold `(1 + x) − 1` into `x`, undoing the correction
/// (WGSL lets compilers reassociate), and WGSL's `log`
/// only promises `2⁻²¹` *absolute* error near 1 (lavapipe's is off by up to `1.6e-7`), so
/// `log1p(−5e-7)` came out 6 % wrong and `e = 1e5` lobes 0.3 % wrong. The kernel uses no
/// `log`: `log1p(x) = 2·atanh(x/(2 + x))` by its odd series (six terms) for
/// `1 + x ∈ [√½, √2)`, and `k·ln 2 + 2·atanh((m − 1)/(m + 1))` with `1 + x = 2^k·m`
/// (`frexp`) elsewhere; it is within 2 ULP of the exact `log1p` on lavapipe.
///
/// A driver that fuses the `|a − v|²` sum into `fma`s computes a slightly different `t`;
/// within a few ULP of the lobe's horizon (`t → 1`), where `(1 − t)^e` is steepest, and for
/// `e = 0` exactly at `t = 1` (value `s` or 0), its results may then differ from the scalar
/// kernel by more than the tolerance. Lavapipe does not fuse them.
/// Tolerance: [`LOBE_EVAL_REL_TOL`].
pub const LOBE_EVAL: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("log1p.wgsl"),
    include_str!("../lobe/lobe_eval.wgsl")
);
/// Exact lobe integral `2π·s/(e + 1)` (`lobe::integral`). Input columns `[e, s]`, output
/// `[integral]`; `|2π·s|` and `e + 1` must stay below `2¹²⁶`.
/// Tolerance: [`LOBE_INTEGRAL_ULP_TOL`].
pub const LOBE_INTEGRAL: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../lobe/lobe_integral.wgsl")
);
/// Cap → lobe L2 exponent looked up in the table of `h(α) = e*(α)·α²` (`cap::lookup`).
/// Input column `[half_angle]`, output `[exponent]`; the table (`cap::TABLE`, or any table
/// on the same grid) is the extra binding 3, its length read with `arrayLength`.
/// The constants `2/π` and the two-part `π/2` are the f32 values the scalar kernel uses.
/// Tolerance: [`CAP_EXPONENT_REL_TOL`] and [`CAP_EXPONENT_ABS_TOL`].
pub const CAP_EXPONENT: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../lobe/cap_exponent.wgsl")
);

/// Summed-area table box query (`sat::SatView::box_sum`). Input columns `[u0, v0, u1, v1]`,
/// output `[value]`. Binding 3 is the table as **`array<u32>`** in the layout of
/// `sat::SatView::gpu_words` (header `[width, height, exponent, 0]`, then each `i64` entry
/// as its low and high words); a caller with an `f32` binding passes the same bits
/// (`f32::from_bits`). Not in [`ALL`] (no built-in table): run it with the harness's custom
/// kernels. Same algorithm as the scalar kernel: the nine sub-box sums are exact 64-bit
/// integer differences (`u32` pairs with borrow), converted to `f32` by magnitude and
/// combined in `f32` (not `f64`), then scaled by `2^e` with two `ldexp` steps.
/// Tolerance: [`SAT_BOX_REL_TOL`].
pub const SAT_BOX: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../rsl/sat_lib.wgsl"),
    include_str!("../rsl/sat.wgsl")
);
/// Difference allowed between [`SAT_BOX`] and `sat::SatView::box_sum`, relative to
/// `A = Σ|t|` over the texels the query reads (`sat` module docs): nine conversions and
/// seven operations in `f32`, each within about one ulp of a term bounded by `A`.
/// Lavapipe: `2.4e-7·A` (about 4 ulps of `A`) on grids from 1×1 to 1024², magnitudes
/// `1e-30` to `1e12`, mixed signs (the harness test `tests/sat.rs` prints it). For texels of
/// one sign `A` exceeds the box integral only by the partly covered edge texels, so the GPU
/// result is within a few ulps of the box's own magnitude there too.
pub const SAT_BOX_REL_TOL: f32 = 1.0e-6;

/// Visibility distance table query (`vdt::VdtView::query`): input columns `[u, v, r]`
/// (centre and half-diagonal in texel units), output `[eq9, gradient]`. Binding 3 is the
/// table `[w, h, D…]` of `vdt::Vdt::gpu_table` (`w`, `h` as `f32`, samples row-major). Not
/// in [`ALL`] (no built-in table): run it with the harness's custom kernels. Eq. 9 of the
/// bilinear `D` (`(1 − t)·a + t·b`), and the straight-edge variant: the 4 × 4 stencil
/// (narrow below `vdt::FIT_WIDE_R`, wide from it, indices clamped in `f32` before they
/// become `u32`), the least-squares plane through the raw samples, the zero-level
/// correction, the plane through the corrected samples and the exact fraction of the square
/// on the visible side of that line (`vdt::VdtView::gradient`). The same operations in the
/// same order as the scalar kernel (`sum4`'s pairing, `select` for its branches), in
/// `rsl/vdt_lib.wgsl`, which [`SHADE`] shares. Tolerance: [`VDT_QUERY_TOL`].
pub const VDT_QUERY: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../rsl/vdt_lib.wgsl"),
    include_str!("../rsl/vdt.wgsl")
);
/// Difference allowed between [`VDT_QUERY`] and `vdt::VdtView::query` per output: eq. 9 in
/// units of `1 + |t|` with `t = D·√2/r` the bilinear `D` in half-sides, the straight-edge
/// fraction in units of `1 + |t| + s` with `t` the fitted line's distance in half-sides and
/// `s = S·√2/r`, `S` the largest `|D|` among the stencil's 16 samples (the fitted distance
/// rounds at the samples' magnitude, which the fraction divides by the half-side; WGSL
/// division is 2.5 ulp and a compiler may fuse `a·b + c` or reassociate sums). Lavapipe:
/// eq. 9 bit-identical; the straight-edge fraction differs in up to 8 % of the queries on
/// maps with a boundary (the driver reassociates or contracts the fit's sums: the mean of
/// the 16 samples, for one, comes out as the sum of the row sums, not of the column sums),
/// by at most `9.5e-8` in these units, about one ulp of the fraction (harness test
/// `tests/vdt_gpu.rs`, which prints both figures, over 16 maps from 1 × 1 to 64 × 64 with
/// queries along the edges and `r` on both sides of `vdt::FIT_WIDE_R`). Set at 20 times
/// that figure, the headroom the eq. 9 kernel has always had: WGSL division may be 2.5 ulp
/// off, and lavapipe's own code generation follows the host CPU's vector extensions.
pub const VDT_QUERY_TOL: f32 = 2.0e-6;

/// Control-point query (`cp::Icosphere::query`): input columns `[x, y, z]` (any non-zero
/// length), output `[value]`, NaN for a zero or non-finite direction. Binding 3 is the table
/// of `cp::Icosphere::gpu_table` (mesh, weight kind and the values). Not in [`ALL`]: run it
/// with the harness's custom kernels. Same operations as the scalar kernel; WGSL's `atan2`
/// and division are not the standard library's, and on an edge the kernel may pick the other
/// triangle, where the area weights differ by their documented discontinuity (≤ 3.3e-4 of
/// the value difference at level 2, measured by the report): [`CP_QUERY_TOL`] holds off the
/// edges, and everywhere with gnomonic weights.
pub const CP_QUERY: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../cp/cp_query.wgsl")
);
/// Difference allowed between [`CP_QUERY`] and `cp::Icosphere::query`, in units of the
/// largest `|value|` of the triangle's three vertices. Lavapipe: gnomonic weights
/// bit-identical; area weights `7.0e-6` at level 0 (its `atan2` on the largest triangles),
/// `2.1e-7` from level 2 (harness test `tests/cp_gpu.rs`, which prints them).
pub const CP_QUERY_TOL: f32 = 1.0e-5;

/// All `bands²` real SH at a direction (`sh::eval_into`) in `f32`, for `bands ≤ 32`
/// ([`SH_EVAL_MAX_BANDS`]). Input columns `[x, y, z]`, output columns `l² + l + m`. Binding 3
/// is one `f32`: the band count. Not in [`ALL`]: run it with the harness's custom kernels.
/// WGSL has no `f64`, and the scalar kernel's recurrence in `f32` loses accuracy like `l²`
/// near the poles (a double characteristic root at `|cos θ| = 1`), so the GPU runs the same
/// Legendre recurrence per order on the ratios `P̃_l^m(t)/P̃_l^m(1)` (`P̃ = P/sin^m θ`) and
/// their differences, with `1 − |cos θ|` formed without cancellation (derived in
/// `sh_basis.wgsl`): its errors add instead. Its coefficients come from `sqrt` of the same
/// rationals on the GPU. Tolerance: [`SH_EVAL_TOL`].
pub const SH_EVAL: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../sh/sh_cap_factors.wgsl"),
    include_str!("../sh/sh_basis.wgsl"),
    include_str!("../sh/sh_eval.wgsl")
);
/// Largest band count of [`SH_EVAL`], [`SH_CAP`] and [`SH_IRRADIANCE`]; more bands are
/// clamped to it ([`SH_HVL`] clamps at 16).
pub const SH_EVAL_MAX_BANDS: usize = 32;
/// Absolute difference allowed between [`SH_EVAL`] and `sh::eval_into` per value, for up
/// to [`SH_EVAL_MAX_BANDS`] bands (the values are at most `√((2l+1)/(2π))` ≈ 3.2 in size).
/// Lavapipe: within `1e-6` through 9 bands, `2e-6` through 16, `4e-6` through 32 (asserted
/// there by the harness test `tests/sh_gpu.rs`, which prints the measured values).
pub const SH_EVAL_TOL: f32 = 1.0e-5;

/// The SH coefficients of spherical caps (`sh::cap::coefficients_into`) in `f32`, for
/// `bands ≤ 32`: the basis of [`SH_EVAL`] at the axis times each band's factor
/// `2π·sin²a·P_l′(cos a)/(l(l+1))` (the scalar kernel's `band_scales`, in `f32`, `P_l` by
/// its recurrence on differences so that small caps keep their accuracy). Input
/// columns `[x, y, z, a]`, output columns `l² + l + m`; binding 3 is one `f32`, the band
/// count. A half-angle outside `[0, π]` or NaN gives NaN (the scalar kernel's error). Not in
/// [`ALL`]. Tolerance: [`SH_CAP_TOL`].
pub const SH_CAP: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../sh/sh_cap_factors.wgsl"),
    include_str!("../sh/sh_basis.wgsl"),
    include_str!("../sh/sh_cap.wgsl")
);
/// Absolute difference allowed between [`SH_CAP`] and `sh::cap::coefficients_into` per
/// coefficient, in units of the cap's solid angle `4π·sin²(a/2)` (every coefficient of band
/// `l` is at most `√((2l+1)/4π)` of it), for half-angles from `1e-4` to `π`. Lavapipe:
/// within `1e-6` through 9 bands, `2e-6` through 16, `4e-6` through 32, the basis's error
/// (asserted there by the harness test `tests/sh_gpu.rs`, which prints the measured values).
pub const SH_CAP_TOL: f32 = 1.0e-5;

/// The built SH rotation operator (`sh::rotate::apply_operator`, the many-vectors path of
/// `sh-rotate`) applied to one coefficient vector per invocation, in `f32` as on the CPU.
/// Input and output: `bands²` columns; binding 3 is `[bands, blocks…]` (the blocks of
/// `sh::rotate::Operator::blocks`); bands from [`SH_ROTATE_MAX_BANDS`] on come out NaN. Not
/// in [`ALL`]. Tolerance: [`SH_ROTATE_TOL`].
pub const SH_ROTATE: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../sh/sh_rotate.wgsl")
);
/// Most bands of [`SH_ROTATE`]: lavapipe ends a shader's loops after about 65 000
/// iterations in all, which the sums of 36 bands pass (harness test `tests/sh_gpu.rs`
/// checks 32 bands and NaN from there on).
pub const SH_ROTATE_MAX_BANDS: usize = 32;
/// Absolute difference allowed between [`SH_ROTATE`] and `sh::rotate::apply_operator` per
/// coefficient, in units of the norm of the input's band (a GPU may fuse the sums'
/// multiply-adds). Lavapipe: bit-identical through 30 bands (harness test
/// `tests/sh_gpu.rs`, which prints the largest difference).
pub const SH_ROTATE_TOL: f32 = 1.0e-6;

/// The ZXZXZ fast path of `sh-rotate` (`sh::rotate::rotate_zxzxz`) in `f32`, one
/// coefficient vector and one rotation per invocation, up to [`SH_ROTATE_ZXZXZ_MAX_BANDS`]
/// bands. Input: `bands²` coefficient columns, then the seven columns of
/// `sh::rotate::Rotation::gpu_row`; output `bands²` columns; binding 3 is `[bands, blocks…]`
/// (the blocks of `sh::rotate::x90_into`). Not in [`ALL`]. Tolerance:
/// [`SH_ROTATE_ZXZXZ_TOL`].
pub const SH_ROTATE_ZXZXZ: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../sh/sh_rotate_zxzxz.wgsl")
);
/// Most bands of [`SH_ROTATE_ZXZXZ`] (its per-band scratch arrays hold 64 values); bands
/// from there on come out NaN.
pub const SH_ROTATE_ZXZXZ_MAX_BANDS: usize = 32;
/// Absolute difference allowed between [`SH_ROTATE_ZXZXZ`] and `sh::rotate::rotate_zxzxz`
/// per coefficient, in units of the norm of the input's band: `f32` sums of up to 63 terms
/// through two `J` blocks and `cos mθ`, `sin mθ` by angle addition. Lavapipe, over 49
/// rotations (random, about `z`, half-turns, `β` within `1e-6` of 0 and π): `2.7e-7` at 10
/// bands, `6.6e-7` at 30, `5.6e-7` at 32, and exact (asserted) for rotations about `z` at
/// `m = 0` (harness test `tests/sh_gpu.rs`, which prints the largest difference per band
/// count).
pub const SH_ROTATE_ZXZXZ_TOL: f32 = 5.0e-6;

/// One HVL's contribution to one receiver per invocation (`sh::hvl::contribution` with
/// `Horizon::Smoothstep`) in `f32`, for `n, n_e ≤ 16` bands: the geometry of
/// `sh::hvl::prepare`, the emission and cap through the basis and cap factors of
/// [`SH_CAP`] (`sh_basis.wgsl`). Input columns `[px, py, pz, tx, ty, tz, bx, by, bz, nx, ny,
/// nz, r, P]` per HVL (its frame's tangent, bitangent, normal); output one column; binding 3 is
/// `[n, n_e, x, y, z, t, b, n (receiver frame, 9 values), F (n²), F′ (n_e²)]`. Neither in
/// [`ALL`] nor in [`CUSTOM`]: one HVL's contribution is not a registered kernel (no `eval`
/// contract); wgpu validates it when the harness test `tests/sh_gpu.rs` and the report's SH
/// section build it (both pack it with `steradian_harness::sh::hvl_gpu_rows` and
/// `hvl_gpu_table`). Tolerance: [`SH_HVL_TOL`].
pub const SH_HVL: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("atan2.wgsl"),
    include_str!("../sh/sh_cap_factors.wgsl"),
    include_str!("../sh/sh_basis.wgsl"),
    "const HVL_EXACT_HORIZON: bool = false;\n",
    include_str!("../sh/sh_hvl.wgsl")
);
/// [`SH_HVL`] with `Horizon::Exact`: the exact fraction of the cap above the receiver's
/// horizon instead of the smoothstep `H` (`sh::hvl::horizon_exact`, in the
/// cancellation-free form of its docs, with `sin a = r/d` and full-relative-precision
/// `atan2`, so caps of `1e-4` rad keep their fraction). Same bindings. Tolerance:
/// [`SH_HVL_TOL`].
pub const SH_HVL_EXACT: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("atan2.wgsl"),
    include_str!("../sh/sh_cap_factors.wgsl"),
    include_str!("../sh/sh_basis.wgsl"),
    "const HVL_EXACT_HORIZON: bool = true;\n",
    include_str!("../sh/sh_hvl.wgsl")
);
/// Absolute difference allowed between [`SH_HVL`] (and [`SH_HVL_EXACT`]) and
/// `sh::hvl::contribution`, per unit of
/// the largest `|contribution|` among the HVLs lighting the receiver (the horizon term's
/// slope carries the GPU's trigonometry into the smallest contributions). The kernel's
/// `asin` goes through `atan2` with `√((1 − x)(1 + x))`: lavapipe's own `asin` misses this
/// tolerance near `|x| = 1`. Lavapipe: `7.3e-6` over 2000 random
/// HVLs at 1–14 bands, for both horizons, and `4.3e-5` of their own value for 200 caps of
/// `1e-4`–`1e-2` rad straddling the horizon (harness test `tests/sh_gpu.rs`, which prints
/// them and asserts `2e-4` for those).
pub const SH_HVL_TOL: f32 = 2.0e-5;

/// The diffuse light a set of Lambertian HVLs sends to receivers, one receiver per row
/// (`sh::hvl::contribution_zonal` with the smoothstep horizon and `lambert_emission(1)`,
/// each contribution clamped at 0, summed with each HVL's RGB weight), with an optional
/// shadow ray per HVL–receiver pair against sphere and plane occluders: the `hvl` scene
/// method's wgpu path. Input columns `[x, y, z, n (3), origin (3), F_0 … F_{n−1}]` (the
/// receiver, its normal, the shadow rays' origin, its zonal `F`), output three columns;
/// binding 3 holds the HVLs and occluders (layout in `sh_hvl_sum.wgsl`), `n ≤ 16` bands
/// (checked at the committed Lambert table's 5). Not a registered kernel (no `eval`
/// contract); the harness tests `tests/wgsl_validate.rs` (naga) and `tests/scene.rs`
/// (`hvl_gpu_path_matches_the_cpu_path`, on an adapter) build it. Tolerance:
/// [`SH_HVL_SUM_TOL`].
pub const SH_HVL_SUM: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../sh/sh_cap_factors.wgsl"),
    include_str!("../sh/sh_hvl_sum.wgsl")
);
/// Difference allowed between [`SH_HVL_SUM`] and the CPU sum per receiver, relative to the
/// largest RGB component of that receiver's sum, where no shadow ray changes its answer
/// between `f32` and `f64` (each term within [`SH_HVL_TOL`] of its largest).
pub const SH_HVL_SUM_TOL: f32 = 1.0e-4;

/// The irradiance of one radiance vector at many normals (`sh::irradiance::irradiance`) in
/// `f32`, for `bands ≤ 32`: the basis of [`SH_EVAL`] at the normal, dotted band by band
/// with the radiance and weighted by the clamped-cosine factors. Input columns `[x, y, z]`,
/// output one column; binding 3 is `[bands, A_0 … A_{bands−1}, L_0 … L_{bands²−1}]` (the
/// factors of `sh::irradiance::clamped_cosine` rounded to `f32`, then the radiance). Not in
/// [`ALL`]. Tolerance: [`SH_IRRADIANCE_TOL`].
pub const SH_IRRADIANCE: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../sh/sh_cap_factors.wgsl"),
    include_str!("../sh/sh_basis.wgsl"),
    include_str!("../sh/sh_irradiance.wgsl")
);
/// Absolute difference allowed between [`SH_IRRADIANCE`] and `sh::irradiance::irradiance`,
/// per unit of `Σ_l |A_l|·Σ_m |L_l^m|` (the basis's own tolerance [`SH_EVAL_TOL`] carried
/// through the sum). Lavapipe: within `1e-7` through 32 bands (asserted there by the harness
/// test `tests/sh_gpu.rs`, which prints the measured values).
pub const SH_IRRADIANCE_TOL: f32 = 1.0e-5;

/// RSL shading of one point per invocation (`shade::shade` with an isotropic BRDF SAT and
/// one VDT per point). Input columns `[tx, ty, tz, bx, by, bz, nx, ny, nz, wox, woy, woz,
/// vdt_index]` (frame axes, world view, which VDT), output `[r, g, b]`. Binding 3 is one
/// **`array<u32>`** table (a caller with an `f32` binding passes the same bits): header
/// `[lights, grid, polar, s_max (f32 bits), vdt_n, off_lights, off_brdf, off_vdt, query
/// (0 = eq. 9, 1 = gradient)]`, then per light 8 `f32` words `[cx, cy, cz, r, 1/Ω, E_r,
/// E_g, E_b]`, per BRDF table (polar node `k`) its exponent word and its `i64` entries as
/// in `sat::SatView::gpu_words`, and per point `vdt_n²` `f32` distances. The harness's
/// `shade::gpu_table` builds it. Same operations as the scalar kernel except the SAT
/// combination in `f32` (as [`SAT_BOX`]) and the map without the overflow-safe rescaling;
/// the visibility is [`VDT_QUERY`]'s eq. 9 or straight-edge query (the shared
/// `rsl/vdt_lib.wgsl`, `shade::VdtVisibility`). Tolerance: [`SHADE_REL_TOL`].
pub const SHADE: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../rsl/sat_lib.wgsl"),
    include_str!("../rsl/vdt_lib.wgsl"),
    include_str!("../rsl/shade_lib.wgsl"),
    include_str!("../rsl/shade.wgsl")
);
/// Difference allowed between [`SHADE`] and `shade::shade`, per channel, relative to the
/// point's largest channel (the `f32` SAT combination is within about `10⁻⁶` of the
/// table's local magnitude; a VDT query moves by ulps of the square's coordinates over its
/// half-side). Lavapipe: `2.0e-6` with eq. 9 (its VDT queries bit-identical: the SAT's
/// share) and `2.0e-6` with the straight-edge query, over Lambert and Phong (harness test
/// `tests/shade.rs`, `gpu_matches_scalar`, which prints them); set at 50 times that (the
/// bound it always had), for adapters other than lavapipe on this CPU.
pub const SHADE_REL_TOL: f32 = 1.0e-4;

/// RSL shading with visibility moments, one point per invocation
/// (`shade::shade_moments` with an isotropic BRDF SAT and one `vis_moments::VisMoments`
/// per point). Input columns `[tx, ty, tz, bx, by, bz, nx, ny, nz, wox, woy, woz,
/// point_index]` (frame axes, world view, which point's tables), output `[r, g, b]`.
/// Binding 3 is one **`array<u32>`** table (a caller with an `f32` binding passes the same
/// bits):
///
/// - header `[lights, grid, polar, s_max (f32 bits), vis_n, off_lights, off_brdf,
///   off_vis]`;
/// - per light 17 `f32` words `[cx, cy, cz, r, 1/Ω, E_r, E_g, E_b, G_r (3), G_g (3),
///   G_b (3)]` (`shade::ShadeLight`, the radiance gradients last);
/// - per BRDF table (polar node `k`) its exponent word and its `(grid + 1)²` `i64` entries
///   as `(low, high)` word pairs, as in `sat::SatView::gpu_words` (as [`SHADE`]);
/// - per point the three tables of `VisMoments::tables` (`V`, `u·V`, `v·V`, each `vis_n`
///   wide), each as its exponent word and its `(vis_n + 1)²` entries in the same pairs:
///   `3·(1 + 2·(vis_n + 1)²)` words per point, 1.6 MB at `vis_n = 256`.
///
/// The harness's `shade::gpu_moments_table` builds it (and splits large batches so that
/// each table stays within the device's storage-binding limit). Same formulas as the scalar
/// kernel; the visibility moments are exact for the piecewise-constant map as there (the
/// partly covered edge texels weighted at their covered centres), from exact 64-bit
/// integer box sums: the square's edges are placed relative to an integer texel near its
/// centre (so they keep the precision of the square's size, not of the table's), and a
/// run of whole texels takes its moment `M − (c − n/2)·V` — two terms that grow with the
/// distance from the table's centre — as the exact integer `M − s·(V ≫ k)` (`s` the
/// integer part of `c − n/2`, `2^k` the ratio of the two tables' quanta) plus `f32`
/// remainders below a quantum of `M` and `frac·V`. Sums are then combined in `f32`
/// (not `f64`), the BRDF box sums as in [`SAT_BOX`]. Tolerance: [`SHADE_MOMENTS_REL_TOL`].
pub const SHADE_MOMENTS: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("../rsl/sat_lib.wgsl"),
    include_str!("../rsl/shade_lib.wgsl"),
    include_str!("../rsl/shade_moments.wgsl")
);
/// Difference allowed between [`SHADE_MOMENTS`] and `shade::shade_moments`, per channel,
/// relative to the point's largest channel. Lavapipe (harness test
/// `tests/shade_moments_gpu.rs`, 111 points with 256² maps, K = 30 lights with radiance
/// gradients, grazing views and squares across the horizon): `2.2e-6` (Lambert) and
/// `1.1e-6` (Phong), about what [`SHADE`] measures, from the `f32` BRDF box sums and the
/// map's last ulps; the visibility moments alone differ by `1.2e-6` in `f` and `5.7e-7·h`
/// in `m` (`1.4e-6·h` when a run's moment is taken as the plain `f32` difference). Kept
/// tight on purpose: dropping the kernel's `g·m` term moves the result by only about
/// `1e-4` of it.
pub const SHADE_MOMENTS_REL_TOL: f32 = 1.0e-5;

/// Product of two cosine lobes as one lobe (`product::product_with` with
/// `ProductFit::ExactIntegral`, the only fit on the GPU). Input columns
/// `[a1x, a1y, a1z, s1, e1, a2x, a2y, a2z, s2, e2]` (unit axes, as `CosineLobe` stores
/// them), output `[ax, ay, az, scale, exponent]`. Binding 3 is the table
/// `[exponents, angles, g…]`: the two sizes as `f32`, then the `g` values of
/// `product::ProductTable` in its packed layout, decoded to `f32` (the harness's
/// `backend::gpu_product` builds it from `product::TABLE_BYTES` or any table file). Not in
/// [`ALL`]: run it with the harness's custom kernels. Same formulas and order as the scalar
/// kernel (arc frame, closed-form peak, logit-Laplace baseline, trilinear correction);
/// its `log` and `log1p` are computed without WGSL's `log` (an `atanh` series after
/// `frexp`, as in [`LOBE_EVAL`]) and its `atan2` with Cephes' `atanf` polynomial (WGSL's
/// `atan2` promises only 4096 ulp, and lavapipe's lost relative precision for small angles:
/// `6e-6` per unit of `1 + L` in the exponent); `exp` and `sqrt` are WGSL's. Axes within
/// about `1e-18` of opposite, where the baseline's intermediates overflow, are outside the
/// finite-input contract. Tolerance: [`LOBE_PRODUCT_TOL`].
pub const LOBE_PRODUCT: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("log1p.wgsl"),
    include_str!("atan2.wgsl"),
    include_str!("../lobe/product_lib.wgsl"),
    include_str!("../lobe/product.wgsl")
);
/// Difference allowed between [`LOBE_PRODUCT`] and `product::product_with`
/// (`ExactIntegral`), per output: axis components absolutely; the scale relative per unit of
/// `1 + L`, the exponent relative to `1 + e_r` per unit of `1 + L`, and the integral
/// `2π·s/(e_r + 1)` relative per unit of `1 + L`, with `L = |ln p| + |ln I|` the size of
/// the logarithms the outputs are exponentials of (`p` the peak value, `I` the integral of
/// the product of the unit lobes; see `steradian_simd::lobe::product` for the same bound on the
/// CPU). Results below `|s1·s2|·2⁻¹²⁶` may be flushed to 0. Lavapipe, over 10⁵ random
/// pairs (harness test `tests/product_gpu.rs`, which prints them; its named hard cases are
/// checked against the same tolerance): axis `1.2e-7`, scale `2.3e-7`, exponent `5.9e-7`,
/// integral `6.6e-7`.
pub const LOBE_PRODUCT_TOL: f32 = 1.0e-5;

/// One chain of the harness's `lobes` method (`scene::lobes`): `∫ r·(L·cos)·V` for a
/// reflectance `r` of a constant and at most one lobe, a light of one lobe `L` (multiplied
/// by the cosine lobe of the normal first, `sum::light_with_cosine_with`) and a visibility
/// `V = 1 + Σ` lobes, by `sum::triple_with` twice: unshadowed (threshold 0) and shadowed
/// (threshold `t·|unshadowed|`), every product by [`LOBE_PRODUCT`]'s `lobe_product`.
/// Input columns `[nx, ny, nz, lx, ly, lz, ls, le, rk, r_lobes, rx, ry, rz, rs, re,
/// vis_offset, vis_count, t]` (`vis_offset` and `vis_count` as `u32` bits), output
/// `[unshadowed, shadowed, products]`. Binding 3 is [`LOBE_PRODUCT`]'s table followed by
/// the visibility lobes, five `f32` each (axis, scale, exponent), which `vis_offset`
/// indexes. Not a registered kernel (no `eval` contract; its scalar twin is the harness's
/// chain); the harness tests `tests/wgsl_validate.rs` (naga) and `tests/scene.rs`
/// (`lobes_gpu_path_matches_the_scalar_path`, on an adapter) build it. Tolerance:
/// [`LOBE_CHAIN_REL_TOL`].
pub const LOBE_CHAIN: &str = concat!(
    include_str!("batch.wgsl"),
    include_str!("log1p.wgsl"),
    include_str!("atan2.wgsl"),
    include_str!("../lobe/product_lib.wgsl"),
    include_str!("../lobe/lobe_chain.wgsl")
);
/// Difference allowed between a pixel of the `lobes` method rendered with [`LOBE_CHAIN`]
/// and with the scalar chains, per channel, relative to the image's largest value: each
/// product is within [`LOBE_PRODUCT_TOL`] and a chain sums a few dozen, shadows subtracted;
/// a term whose integral lies at the pruning threshold may be kept on one side and dropped
/// on the other. Lavapipe (harness test `lobes_gpu_path_matches_the_scalar_path`, `lobes`
/// and `cluster` at 48 columns, three visibility and diffuse variants): `3.6e-7`, with the
/// same products computed. Row by row (harness test
/// `lobe_chain_matches_the_scalar_chain_row_by_row`, 2004 random and hard-case chains)
/// each value is within this bound of the chain's scale `|u|·(1 + Σ|w_k|)` per unit of
/// `1 + ln(1 + e_max)`; lavapipe `4.3e-6`.
pub const LOBE_CHAIN_REL_TOL: f32 = 1.0e-5;

/// Every kernel as `(name, source)`, the name as in the harness (`hemisphere-map`, …).
pub const ALL: [(&str, &str); 5] = [
    ("hemisphere-map", HEMISPHERE_MAP),
    ("hemisphere-unmap", HEMISPHERE_UNMAP),
    ("lobe-eval", LOBE_EVAL),
    ("lobe-integral", LOBE_INTEGRAL),
    ("cap-exponent", CAP_EXPONENT),
];

/// The kernels outside [`ALL`], with a caller-supplied table at binding 3 (run them with
/// the harness's custom kernels), as `(name, source, element type of the table)`.
pub const CUSTOM: [(&str, &str, &str); 11] = [
    ("cp-query", CP_QUERY, "f32"),
    ("lobe-product", LOBE_PRODUCT, "f32"),
    ("sh-eval", SH_EVAL, "f32"),
    ("sh-cap", SH_CAP, "f32"),
    ("sh-irradiance", SH_IRRADIANCE, "f32"),
    ("sh-rotate", SH_ROTATE_ZXZXZ, "f32"),
    ("sh-rotate", SH_ROTATE, "f32"),
    ("sat-box", SAT_BOX, "u32"),
    ("vdt-box", VDT_QUERY, "f32"),
    ("shade", SHADE, "u32"),
    ("shade-moments", SHADE_MOMENTS, "u32"),
];

/// Per-component absolute difference allowed between [`HEMISPHERE_MAP`] and
/// `hemisphere::map` (the components lie in `[−1, 1]`). Lavapipe: `1.8e-7` (4 ULP), from
/// the power-of-two scaling.
pub const HEMISPHERE_MAP_ABS_TOL: f32 = 1.0e-6;
/// Per-component absolute difference allowed between [`HEMISPHERE_UNMAP`] and
/// `hemisphere::unmap` (the components lie in `[−1, 1]`). Lavapipe: bit-identical (its
/// `sqrt` and division are correctly rounded).
pub const HEMISPHERE_UNMAP_ABS_TOL: f32 = 1.0e-6;
/// Relative difference allowed between [`LOBE_EVAL`] and `lobe::eval`, per unit of
/// `1 + |ln(c/s)|` (`c` the scalar result): the error of `exp(y)` grows with `|y|`. Values
/// below `|s|·2⁻¹²⁶` (subnormal ones) may differ by up to that absolutely.
/// Lavapipe: `2.3e-7` per unit (about 2 ULP per unit; `1.1e-5` relative at `|ln(c/s)| ≈ 85`).
pub const LOBE_EVAL_REL_TOL: f32 = 1.0e-6;
/// Difference in units in the last place allowed between [`LOBE_INTEGRAL`] and
/// `lobe::integral` (for results of at least `2⁻¹²⁶`; smaller ones may be flushed to 0).
/// Lavapipe: bit-identical.
pub const LOBE_INTEGRAL_ULP_TOL: u32 = 4;
/// Relative difference allowed between [`CAP_EXPONENT`] and `cap::exponent_l2`, on top of
/// [`CAP_EXPONENT_ABS_TOL`]. Lavapipe: bit-identical.
pub const CAP_EXPONENT_REL_TOL: f32 = 1.0e-5;
/// Absolute difference allowed between [`CAP_EXPONENT`] and `cap::exponent_l2` on top of
/// the relative one: next to `α = π/2`, where the exponent goes to 0, the lookup depends on
/// `u = π/2 − α` to full relative precision (a two-part `π/2`), which a compiler that
/// reassociates or fuses the arithmetic degrades (lavapipe, before the kernel hid the low
/// part of `π/2` from constant folding, moved the exponent by `2.8e-7` there).
pub const CAP_EXPONENT_ABS_TOL: f32 = 1.0e-5;
