//! # steradian-simd
//!
//! 8-lane structure-of-arrays versions of the scalar kernels of `steradian-core`, built on
//! [`wide::f32x8`]. Each module mirrors the core module of the same path:
//!
//! | module | batch kernels | slice function | against the scalar kernel |
//! |---|---|---|---|
//! | [`rsl::hemisphere`] | [`rsl::hemisphere::map`], [`rsl::hemisphere::unmap`] | `map_slices`, `unmap_slices` | bit-identical |
//! | [`lobe`] | [`lobe::integral`] | `integral_slices` | bit-identical |
//! | [`lobe`] | [`lobe::eval`], [`lobe::eval_parts`] | `eval_slices` | within [`lobe::EVAL_REL_TOL`] |
//! | [`lobe::cap`] | [`lobe::cap::exponent_l2`], [`lobe::cap::lookup`] | `exponent_l2_slices`, `lookup_slices` | bit-identical |
//! | [`lobe::product`] | [`lobe::product::product_x8`] | `product_slices` | axis bit-identical; scale, exponent within [`lobe::product::SCALE_REL_TOL`] etc. |
//! | [`rsl::sat`] | [`rsl::sat::box_sum`], [`rsl::sat::square`] | `box_sum_slices`, `square_slices` | bit-identical |
//! | [`rsl::vdt`] | [`rsl::vdt::query`] | `query_slices` | bit-identical |
//! | [`sh`] | [`sh::eval_x4`], [`sh::eval_x8`] (four or eight directions, `f64` lanes as the scalar kernel) | `eval_slices` (eight lanes with AVX-512F, four otherwise) | bit-identical |
//! | [`sh::cap`] | [`sh::cap::coefficients_x4`] (four caps, `f64` lanes) | `coefficients_slices` | bit-identical |
//! | [`sh::hvl`] | [`sh::hvl::contributions_x4`] (four HVLs, one receiver) | `contributions` | bit-identical |
//! | [`sh::irradiance`] | [`sh::irradiance::irradiance_x4`] (one radiance vector, four normals) | `irradiance_slices` | bit-identical |
//! | [`cp`] | (one function at many directions) | [`cp::query_slices`] | bit-identical (gnomonic weights), within [`cp::AREA_TOL`] (area weights) |
//! | [`rsl::shade`] | [`rsl::shade::shade_x8`], [`rsl::shade::shade_moments_x8`], [`rsl::shade::shade_moments_pair_x8`] | `shade_batch`, `shade_moments_batch`, `shade_moments_pair_batch` | within [`rsl::shade::REL_TOL`], [`rsl::shade::MOMENTS_REL_TOL`] |
//!
//! The folders are those of `steradian-core`, one per paper (`lobe/`, `rsl/`, `sh/`, `cp`).
//!
//! [`batch`] holds the lane types ([`Vec3x8`], [`Vec2x8`], [`LobeX8`]), their conversions
//! from and to slices of the scalar types (a short slice is padded with a documented value),
//! and loads and stores at an offset of structure-of-arrays columns.
//!
//! The slice functions take structure-of-arrays columns of any length (the batch layout of
//! `steradian-harness`: one `&[f32]` per component) and write the output columns in place:
//! whole vectors, then one padded vector for the tail. They run on the widest vector of the
//! build, [`slice_lanes`] lanes: 16 (`wide::f32x16`, one 512-bit register) where AVX-512F is
//! enabled, as wide as the compiler's own auto-vectorised loops there, and 8 otherwise. The
//! lane kernels are written once, generic over the width, so both widths compute the same
//! operations and give the same results.
//!
//! ## The contract: one truth per kernel
//!
//! The scalar kernels of `steradian-core` are the single source of truth. Lane `k` of a
//! batch kernel equals the scalar kernel applied to lane `k` of the input:
//!
//! - **Bit-identical** where the batch kernel performs the same IEEE operations in the same
//!   order (hemisphere map and unmap, lobe integral, cap lookup), for *every* input: NaN,
//!   ±∞, ±0, subnormals, huge and tiny values. NaN-ness matches; a NaN's payload may differ.
//!   This holds because the batch kernels use only correctly rounded operations
//!   (`+ − × ÷ √ ceil`, comparisons, selects), never fuse a multiply and an add the scalar
//!   keeps separate, never use approximate reciprocals, and replicate the NaN rules of
//!   `f32::max`/`min` (NaN-ignoring) and `f32::clamp` (NaN-keeping) with explicit masks
//!   rather than relying on what a SIMD `max` instruction does with NaN.
//! - **Within a stated tolerance** where the operations differ: [`lobe::eval`] uses wide's
//!   polynomial `ln_1p`/`exp` instead of the standard library's; its error against the
//!   scalar kernel's value `c` is at most [`lobe::EVAL_REL_TOL`]`·(1 + |ln(c/s)|)·|c|` (plus
//!   two subnormal units where `exp` underflows), it is `0·s` exactly where the scalar kernel
//!   takes its horizon branch, exactly `s` when `e = 0`, and NaN exactly where the scalar
//!   kernel is NaN.
//!
//! The tests (one binary, `tests/main.rs`: `contract` for the lobe and hemisphere kernels,
//! `product`, `rsl` for SAT, VDT and shading) check the contract lane by lane on pseudo-random inputs,
//! arbitrary bit patterns, named special values in every lane position, and slice lengths
//! around the vector sizes (0, 1, 7, 8, 9, 1000); the cap lookup also on every `f32`
//! (`cargo test --release -p steradian-simd -- --ignored`).
//!
//! ## Getting the wide paths
//!
//! `wide` chooses its instruction set **at compile time** from the enabled target features;
//! there is no runtime dispatch. On x86-64 the default target is baseline x86-64, so an
//! `f32x8` is two SSE2 `f32x4` halves. To get 256-bit AVX (AVX2/FMA), or 512-bit AVX-512 in
//! the slice functions, build the crate that embeds this one for a higher target CPU, for
//! instance in its `.cargo/config.toml`:
//!
//! ```toml
//! [build]
//! rustflags = ["-C", "target-cpu=x86-64-v3"]   # AVX2 + FMA; "x86-64-v4" adds AVX-512; "native"
//! ```
//!
//! or with `RUSTFLAGS="-C target-cpu=native" cargo build --release`. The steradian workspace
//! itself builds with `target-cpu=native`. [`isa`] and [`slice_lanes`] report what the build
//! uses. On AArch64 NEON is always on; on wasm32 enable `simd128`. The results are the same
//! on every instruction set (the bit-identical kernels use only correctly rounded
//! operations); only the speed differs.
//!
//! ## `unsafe` in one place
//!
//! The crate denies `unsafe` but for two functions of [`rsl::sat`]: its table reads use
//! the hardware gathers (`vpgatherqq`), 8-lane with AVX-512F and 4-lane with AVX2, where
//! the build enables them on x86-64. `wide` has no gather, and from the plain lane loop
//! LLVM forms only 4-lane gathers with AVX-512 (its preferred vector width on current
//! Intel cores is 256 bits) and none for AVX2 alone. The gathers read the same entries
//! with far fewer instructions (the report's `sat` section puts the query beside its
//! load-only floor). Every index is clipped into the table just before the gather, in
//! the same function (its `SAFETY` comment); the plain loop, used on every other target,
//! is kept, and a test checks that the gathers read what it reads.
//!
//! ## Speed
//!
//! `cargo run --release -p steradian-simd --example speed` prints ns per element for the
//! scalar kernel called per input behind `black_box`, a plain loop over the scalar kernel
//! (which LLVM auto-vectorises where it can), and the slice functions.
#![cfg_attr(not(test), no_std)]
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod batch;
#[cfg(feature = "alloc")]
pub mod cp;
pub mod lobe;
pub mod rsl;
pub mod sh;

mod lanes;

pub use batch::{LANES, LobeX8, Vec2x8, Vec3x8};
pub use wide::f32x8;

/// The instruction set this build's [`f32x8`] runs on, decided at compile time from the
/// enabled target features (the way `wide` decides):
///
/// - `"avx512f"`: 256-bit AVX operations, compiled with AVX-512 enabled (EVEX encodings and
///   mask registers are available to the compiler);
/// - `"avx2+fma"`, `"avx2"`, `"avx"`: one 256-bit register per `f32x8`;
/// - `"sse4.1"`, `"sse2"`: two 128-bit halves (the x86-64 default is `"sse2"`);
/// - `"neon"` (AArch64), `"simd128"` (wasm32): two 128-bit halves;
/// - `"scalar"`: plain arrays, no SIMD.
pub fn isa() -> &'static str {
    if cfg!(target_feature = "avx512f") {
        "avx512f"
    } else if cfg!(all(target_feature = "avx2", target_feature = "fma")) {
        "avx2+fma"
    } else if cfg!(target_feature = "avx2") {
        "avx2"
    } else if cfg!(target_feature = "avx") {
        "avx"
    } else if cfg!(target_feature = "sse4.1") {
        "sse4.1"
    } else if cfg!(target_feature = "sse2") {
        "sse2"
    } else if cfg!(all(target_arch = "aarch64", target_feature = "neon")) {
        "neon"
    } else if cfg!(target_feature = "simd128") {
        "simd128"
    } else {
        "scalar"
    }
}

/// Lanes per vector in the slice functions (`map_slices`, `eval_slices`, …): 16 where the
/// build enables AVX-512F (one `wide::f32x16` per 512-bit register, as wide as the
/// compiler's own auto-vectorised loops there), 8 otherwise. The batch types are always 8
/// lanes; results are the same either way.
pub fn slice_lanes() -> usize {
    <lanes::SliceVec as lanes::Lanes>::N
}
