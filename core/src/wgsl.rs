//! WGSL sources of the GPU kernels, mirroring the scalar ones, as `pub const &str` so a
//! renderer can embed them. Each source is one compute entry point `main` with
//! `@workgroup_size(64)` reading storage buffers; see each constant for its bindings. The
//! batch layout below is written once, in `wgsl/batch.wgsl`, and prepended to every source,
//! so each constant is a complete shader.
//!
//! ## Bindings (identical for every kernel)
//!
//! ```wgsl
//! struct Params { n: u32, row_stride: u32, _pad0: u32, _pad1: u32 }
//! @group(0) @binding(0) var<storage, read> input: array<f32>;        // column-major
//! @group(0) @binding(1) var<storage, read_write> output: array<f32>; // column-major
//! @group(0) @binding(2) var<uniform> params: Params;
//! @group(0) @binding(3) var<storage, read> table: array<f32>;        // cap-exponent only
//! ```
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

/// Equal-area hemisphere map, direction → disk point (`hemisphere::map`).
/// Input columns `[x, y, z]`, output `[u, v]`.
///
/// Unlike the scalar kernel the input is scaled by the power of two `2^-exp(m)`
/// (`m` the largest component) rather than `1/m`, which is subnormal — and may be flushed
/// to zero on a GPU — for `m > 2¹²⁶`; the two differ by a common factor the normalisation
/// removes. Tolerance: [`HEMISPHERE_MAP_ABS_TOL`].
pub const HEMISPHERE_MAP: &str = concat!(
    include_str!("wgsl/batch.wgsl"),
    include_str!("wgsl/hemisphere_map.wgsl")
);
/// Inverse hemisphere map, disk point → unit direction (`hemisphere::unmap`).
/// Input columns `[u, v]`, output `[x, y, z]`. Points with `|p|² > 1` are clamped onto
/// the unit circle; `|p|` must stay below `1.8e19` so that `|p|²` is finite.
/// Tolerance: [`HEMISPHERE_UNMAP_ABS_TOL`].
pub const HEMISPHERE_UNMAP: &str = concat!(
    include_str!("wgsl/batch.wgsl"),
    include_str!("wgsl/hemisphere_unmap.wgsl")
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
    include_str!("wgsl/batch.wgsl"),
    include_str!("wgsl/lobe_eval.wgsl")
);
/// Exact lobe integral `2π·s/(e + 1)` (`lobe::integral`). Input columns `[e, s]`, output
/// `[integral]`; `|2π·s|` and `e + 1` must stay below `2¹²⁶`.
/// Tolerance: [`LOBE_INTEGRAL_ULP_TOL`].
pub const LOBE_INTEGRAL: &str = concat!(
    include_str!("wgsl/batch.wgsl"),
    include_str!("wgsl/lobe_integral.wgsl")
);
/// Cap → lobe L2 exponent looked up in the table of `h(α) = e*(α)·α²` (`cap::lookup`).
/// Input column `[half_angle]`, output `[exponent]`; the table (`cap::TABLE`, or any table
/// on the same grid) is the extra binding 3, its length read with `arrayLength`.
/// The constants `2/π` and the two-part `π/2` are the f32 values the scalar kernel uses.
/// Tolerance: [`CAP_EXPONENT_REL_TOL`] and [`CAP_EXPONENT_ABS_TOL`].
pub const CAP_EXPONENT: &str = concat!(
    include_str!("wgsl/batch.wgsl"),
    include_str!("wgsl/cap_exponent.wgsl")
);

/// Every kernel as `(name, source)`, the name as in the harness (`hemisphere-map`, …).
pub const ALL: [(&str, &str); 5] = [
    ("hemisphere-map", HEMISPHERE_MAP),
    ("hemisphere-unmap", HEMISPHERE_UNMAP),
    ("lobe-eval", LOBE_EVAL),
    ("lobe-integral", LOBE_INTEGRAL),
    ("cap-exponent", CAP_EXPONENT),
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
