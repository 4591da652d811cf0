//! Report sections contributed by the subsystems (lobe products, summed-area and visibility
//! distance tables, RSL shading, …), registered in one list. Each one measures itself, may
//! write files (SVG, PNG) beside `index.html`, and adds text to the summary and HTML to the
//! page; each imports only [`super::section`], never this list.

use super::Options;
pub use super::section::{Producer, Section};

/// Every section with its id (its key in `report.json`), in report order.
pub const PRODUCERS: &[(&str, Producer)] = &[
    ("lobe-product", super::product::section),
    ("sat", super::sat::section),
    ("brdf_sat", super::brdf::section),
    ("lobe-sum", super::lobe_sum::section),
    ("vdt", super::vdt::section),
    ("rsl", super::rsl::section),
    ("shade", super::shade::section),
    ("sh", super::sh::section),
    ("control-points", super::cp::section),
    ("scenes", super::scenes::section),
];

/// Runs every section producer, or only the one `opts.only` names.
pub fn run_all(opts: &Options) -> Result<Vec<Section>, Box<dyn std::error::Error>> {
    if let Some(id) = &opts.only
        && !PRODUCERS.iter().any(|(p, _)| p == id)
    {
        let ids: Vec<&str> = PRODUCERS.iter().map(|(p, _)| *p).collect();
        return Err(format!("no report section {id:?}; the sections are {ids:?}").into());
    }
    PRODUCERS
        .iter()
        .filter(|(id, _)| opts.only.as_deref().is_none_or(|o| o == *id))
        .map(|(id, p)| {
            let s = p(opts)?;
            debug_assert_eq!(s.id, *id);
            Ok(s)
        })
        .collect()
}
