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
//! - **Spherical harmonics** ([`sh`]): real SH of the HVL paper eq. 7–8 with the
//!   Condon–Shortley phase, order `l = 0..n-1`, `m = −l..l`, flat index `l² + l + m`.
//! - **Precision.** `f32` in kernels; `f64` only in references and table generators, and
//!   inside a kernel only where `f32` arithmetic cannot meet its stated bound (the SH
//!   recurrence, [`sh`]; inputs and outputs stay `f32`).
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
//! ## Example: one point lit by a spherical light through a Phong material
//!
//! The cosine-lobe paper's pipeline for one shading point: the light's cap becomes a lobe
//! (the L2 fit of [`lobe::cap`]), the BRDF a sum of lobes with the cosine folded into the
//! light, and the reflected radiance the integral of their products ([`lobe::sum`]).
//!
//! ```
//! use steradian_core::Vec3;
//! use steradian_core::lobe::Phong;
//! use steradian_core::lobe::cap::{CapFit, SphericalCap};
//! use steradian_core::lobe::sum::{Cosine, LobeSum, ProductCounts, light_with_cosine,
//!     phong_reflectance, triple};
//!
//! let (point, normal) = (Vec3::ZERO, Vec3::Z);
//! let view = Vec3::new(0.6, 0.0, 0.8); // towards the eye
//! // A sphere of radius 0.5 at distance 4, emitting radiance 10.
//! let cap = SphericalCap::from_sphere(point, Vec3::new(-2.0, 0.5, 3.4), 0.5)?;
//! let mut light = LobeSum::<1>::new();
//! light.push_cap(&cap, 10.0, CapFit::L2);
//! let mut counts = ProductCounts::default();
//! let light = light_with_cosine(&light, normal, Cosine::WithLight, &mut counts);
//! // Modified Phong: diffuse 0.5, specular 0.3, exponent 50.
//! let brdf = Phong::modified(0.5, 0.3, 50.0)?;
//! let reflectance = phong_reflectance(&brdf, normal, view, Cosine::WithLight, &mut counts);
//! let radiance = triple(&reflectance, &light, &LobeSum::<0>::unoccluded(), 0.0, &mut counts);
//! // Seen as a point light of solid angle Ω in direction l, the point would reflect
//! // f(l)·10·Ω·(n·l), with f = 0.5/π + 0.3·52/(2π)·(r·l)^50 and r the mirrored view; the
//! // light's extent (0.13 rad, about the lobe's width) lowers the specular peak a little.
//! let l = cap.axis();
//! let r = steradian_core::lobe::reflect(view, normal);
//! let f = 0.5 / steradian_core::PI + 0.3 * 52.0 / steradian_core::TWO_PI * r.dot(l).powi(50);
//! let point_light = f * 10.0 * cap.solid_angle() * normal.dot(l);
//! assert!((radiance / point_light - 1.0).abs() < 0.2, "{radiance} vs {point_light}");
//! # Ok::<(), steradian_core::Error>(())
//! ```
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

#[cfg(feature = "alloc")]
pub mod cp;
pub mod frame;
pub mod grid;
pub mod lobe;
pub mod rsl;
pub mod sh;
pub mod table;
pub mod wgsl;

pub use error::Error;
pub use glam::{Vec2, Vec3};

/// The constant π as `f32`.
pub const PI: f32 = core::f32::consts::PI;
/// The constant 2π as `f32`.
pub const TWO_PI: f32 = core::f32::consts::TAU;
