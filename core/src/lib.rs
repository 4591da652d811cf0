//! # steradian-core
//!
//! Scalar kernels and precomputed tables for fast, accurate approximations of spherical
//! lighting integrals: the equal-area hemisphere map, cosine lobes and the BRDFs built from
//! them, and the cap → lobe fit for spherical lights. Every kernel states its error bound
//! against the exact quantity; the bounds are checked against f64 references by the property
//! tests in `steradian-harness`.
//!
//! The crate is `#![no_std]`, never allocates on a hot path and never panics on any input.
//!
//! ## Conventions (every kernel follows them)
//!
//! - **Frame.** Right-handed local frame, `z` = surface normal or lobe axis;
//!   `x = sinθ·cosφ`, `y = sinθ·sinφ`, `z = cosθ`. Angles in radians.
//! - **Cosine lobe.** `c(v) = s·max(a·v, 0)^e` with `e ≥ 0`; `e = 0` is the indicator of the
//!   open hemisphere around `a` (a lobe is `0` on its own horizon, `a·v = 0`, for every `e`).
//! - **Equal-area hemisphere map.** `p = (x, y)/sqrt(1 + z)`, inverse `z = 1 − |p|²`,
//!   `(x, y) = p·sqrt(2 − |p|²)`; `dω = 2·du·dv`. The disk is inscribed in the texture
//!   square: `uv = (p + 1)/2`.
//! - **Spherical harmonics** (later kernels): real SH of the HVL paper eq. 7–8 with the
//!   Condon–Shortley phase, order `l = 0..n-1`, `m = −l..l`, flat index `l² + l + m`.
//! - **Precision.** `f32` in kernels; `f64` only in references and table generators.
//!
//! ## Bad input
//!
//! Constructors that take user data validate it and return [`Result`] with an [`Error`]
//! saying what was wrong. Hot-path kernels take validated types or saturate in a documented
//! way: NaN in → NaN out, a negative exponent is clamped to 0, a zero vector falls back to a
//! documented direction. Nothing panics.
//!
//! ## Features
//!
//! - `std` (default): float functions from the standard library.
//! - `libm`: float functions from the pure-Rust `libm` crate (the no_std backend).
//!   Build for a renderer without std with `default-features = false, features = ["libm"]`.
//! - `alloc`: owned copies of tables loaded from user bytes.
//!
//! One of `std` or `libm` must be enabled; with both, `std` is used.
//!
//! ## GPU
//!
//! The WGSL sources of the kernels are in [`wgsl`] as `pub const &str`, so a renderer can
//! embed them without the rest of this project.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

#[cfg(not(any(feature = "std", feature = "libm")))]
compile_error!(
    "steradian-core needs a math backend: enable the `std` feature (default) or the `libm` feature"
);

#[cfg(feature = "std")]
extern crate std;

#[cfg(feature = "alloc")]
extern crate alloc;

mod error;
pub mod math;

pub mod frame;
pub mod grid;
pub mod lobe;
pub mod rsl;
pub mod table;
pub mod wgsl;

pub use error::Error;
pub use glam::{Vec2, Vec3};

/// The constant π as `f32`.
pub const PI: f32 = core::f32::consts::PI;
/// The constant 2π as `f32`.
pub const TWO_PI: f32 = core::f32::consts::TAU;
