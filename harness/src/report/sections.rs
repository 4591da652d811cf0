//! Report sections contributed by the subsystems (lobe products, summed-area and visibility
//! distance tables, RSL shading, …), registered in one list. Each one measures itself, may
//! write files (SVG, PNG) beside `index.html`, and adds text to the summary and HTML to the
//! page; each imports only [`super::section`], never this list.

use super::Options;
pub use super::section::{Producer, Section};

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
