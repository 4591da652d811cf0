//! Environment maps and their decomposition into rotatable square lights (rotatable square
//! lights paper, section 4.1).
//!
//! - [`cubemap`]: cube maps with exact texel solid angles (the decomposition's domain,
//!   6 × 32 × 32 by default as in the paper);
//! - [`hdr`]: Radiance `.hdr` / OpenEXR equirectangular images and their resampling;
//! - [`sky`]: the embedded default, a procedural sky with a sun and a known integral;
//! - [`decompose`](mod@decompose): bottom-up merging (Figure 5) with the RSL fit of
//!   section 4.1.1 and the area penalty of eq. 7, driven by a priority queue.

pub mod cubemap;
pub mod decompose;
pub mod hdr;
pub mod sh;
pub mod sky;

use std::fmt;
use std::path::{Path, PathBuf};

pub use cubemap::CubeMap;
pub use decompose::{Decomposition, Region, decompose};
pub use hdr::Equirect;
pub use sky::Sky;

/// The real environment used by the tests and the report, relative to the harness crate
/// (see `harness/data/PROVENANCE.md`).
pub const REAL_ENV: &str = "data/sky.exr";

/// Path of [`REAL_ENV`] from this crate's manifest directory.
pub fn real_env_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(REAL_ENV)
}

/// What went wrong reading or building an environment: the file, or the data (the
/// error core's cube map and decomposition give).
#[derive(Clone, Debug, PartialEq)]
pub enum EnvError {
    /// The file could not be read or decoded.
    Io(String),
    /// The data was not a valid environment (size, non-finite values, …).
    Invalid(steradian_core::rsl::cubemap::EnvError),
}

impl EnvError {
    /// An invalid-environment error with this message.
    pub fn invalid(msg: String) -> Self {
        EnvError::Invalid(steradian_core::rsl::cubemap::EnvError::Invalid(msg))
    }
}

impl fmt::Display for EnvError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EnvError::Io(s) => write!(f, "reading environment: {s}"),
            EnvError::Invalid(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for EnvError {}

impl From<steradian_core::rsl::cubemap::EnvError> for EnvError {
    fn from(e: steradian_core::rsl::cubemap::EnvError) -> Self {
        EnvError::Invalid(e)
    }
}

/// The default environment: [`Sky::default`] as a cube map of face size `n`.
pub fn default_sky(n: usize) -> Result<CubeMap, EnvError> {
    Sky::default().cubemap(n)
}

/// Loads an equirectangular `.hdr`/`.exr` file as a cube map of face size `n`.
pub fn load_cubemap(path: &Path, n: usize) -> Result<CubeMap, EnvError> {
    Equirect::load(path)?.to_cubemap(n)
}
