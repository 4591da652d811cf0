//! The environment decomposition (RSL paper section 4.1) lives in core
//! (`steradian_core::rsl::decompose`), so a renderer gets its lights from `steradian-core`
//! alone. The harness adds the clock and the progress bar: [`decompose`] and
//! [`decompose_rescan`] here time each partition with `std::time::Instant` and, with
//! `Options::progress`, show a progress bar once a run takes more than a second.

use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use steradian_core::rsl::decompose as core_decompose;
pub use steradian_core::rsl::decompose::{
    Decomposition, Fit, Objective, Observer, Options, PAPER_KS, ROTATIONS, Region, basis,
    bound_cost, fit_region, moment_gradient,
};

use super::{CubeMap, EnvError};

/// The harness's observer: a wall clock and an optional progress bar.
struct Clock {
    start: Instant,
    bar: ProgressBar,
    want: bool,
    shown: bool,
}

impl Clock {
    fn new(want: bool) -> Clock {
        let bar = if want {
            let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
            bar.set_style(
                ProgressStyle::with_template(
                    "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            bar.set_message("merging environment regions");
            bar
        } else {
            ProgressBar::hidden()
        };
        Clock {
            start: Instant::now(),
            bar,
            want,
            shown: false,
        }
    }
}

impl Observer for Clock {
    fn seconds(&mut self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    fn start(&mut self, total: u64) {
        self.bar.set_length(total);
    }

    fn merged(&mut self) {
        self.bar.inc(1);
        if !self.shown && self.want && self.start.elapsed().as_secs_f64() > 1.0 {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
            self.shown = true;
        }
    }
}

/// `steradian_core::rsl::decompose::decompose`, timed, with a progress bar when
/// `opts.progress` and the run takes more than a second.
pub fn decompose(cube: &CubeMap, opts: &Options) -> Result<Vec<Decomposition>, EnvError> {
    let mut clock = Clock::new(opts.progress);
    let out = core_decompose::decompose_observed(cube, opts, &mut clock);
    clock.bar.finish_and_clear();
    Ok(out?)
}

/// `steradian_core::rsl::decompose::decompose_rescan`, timed.
pub fn decompose_rescan(
    cube: &CubeMap,
    k: usize,
    cross_face: bool,
    objective: Objective,
) -> Result<Decomposition, EnvError> {
    let mut clock = Clock::new(false);
    Ok(core_decompose::decompose_rescan_observed(
        cube, k, cross_face, objective, &mut clock,
    )?)
}
