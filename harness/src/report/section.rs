//! One section of the report: what each subsystem's producer returns. A leaf module, so
//! that the sections (`product`, `sat`, …) and the list of them (`sections`) import it
//! without importing each other.

use serde::Serialize;

use super::Options;

/// One section of the report.
#[derive(Clone, Debug, Serialize)]
pub struct Section {
    /// HTML anchor and key in `report.json`.
    pub id: &'static str,
    /// Heading.
    pub title: String,
    /// Plain text for the summary printed on stdout.
    pub summary: String,
    /// HTML body (tables, inline SVG, links to `files`).
    #[serde(skip)]
    pub html: String,
    /// Machine-readable measurements.
    pub data: serde_json::Value,
    /// Extra files written beside `index.html`: (file name, bytes).
    #[serde(skip)]
    pub files: Vec<(String, Vec<u8>)>,
}

/// A section producer: runs its measurements under `opts` (use `opts.gpu` to decide whether
/// to try `backend::gpu::try_gpu()`), or says why it could not.
pub type Producer = fn(&Options) -> Result<Section, Box<dyn std::error::Error>>;
