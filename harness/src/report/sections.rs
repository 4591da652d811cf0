//! Report sections contributed by the subsystems (lobe products, summed-area and visibility
//! distance tables, RSL shading, …). Each one measures itself, may write files (SVG, PNG)
//! beside `index.html`, and adds text to the summary and HTML to the page.

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

/// Every section, in report order.
pub const PRODUCERS: &[Producer] = &[
    super::product::section,
    super::sat::section,
    super::brdf::section,
    super::lobe_sum::section,
    super::vdt::section,
    super::rsl::section,
    super::shade::section,
];

/// Runs every section producer.
pub fn run_all(opts: &Options) -> Result<Vec<Section>, Box<dyn std::error::Error>> {
    PRODUCERS.iter().map(|p| p(opts)).collect()
}
