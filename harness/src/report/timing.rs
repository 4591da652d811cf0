//! The report's timing helpers: every throughput figure of the report is the median of
//! timed runs after an untimed warm-up (caches, page faults, GPU pipelines, the core's
//! clock), measured here. A leaf module.

use std::time::{Duration, Instant};

/// Runs `f` once and returns its result with the wall time it took (for one-off work such
/// as building a table, which is reported as it happened rather than as a median).
pub fn timed<T>(f: impl FnOnce() -> T) -> (T, Duration) {
    let start = Instant::now();
    let out = f();
    (out, start.elapsed())
}

/// The median of `times` (the upper one of an even count); zero when empty.
pub fn median(mut times: Vec<Duration>) -> Duration {
    times.sort();
    times.get(times.len() / 2).copied().unwrap_or_default()
}

/// The shortest warm-up. A process's first milliseconds run slower (caches, page faults,
/// the core's clock leaving idle): a measurement of a few µs taken first fell inside them,
/// read slow, and gave its contestants a wrong ratio (the SH section's 3-band evaluation,
/// the first it times; `steradian report --section sh` shows it without the warm-up).
pub const WARM_UP: Duration = Duration::from_millis(30);

/// Runs `f` at least once and until it has run for [`WARM_UP`].
pub fn warm_up(mut f: impl FnMut()) {
    let start = Instant::now();
    f();
    while start.elapsed() < WARM_UP {
        f();
    }
}

/// Median wall time of `f` over `repeats` timed runs (at least one) after the warm-up.
pub fn median_time(repeats: usize, mut f: impl FnMut()) -> Duration {
    warm_up(&mut f);
    median((0..repeats.max(1)).map(|_| timed(&mut f).1).collect())
}

/// Median wall time of `f` after the warm-up, over timed runs repeated until they fill
/// `min_total` together: at least `repeats` and 3 runs, at most 50 (or `repeats`, if more).
pub fn median_time_for(repeats: usize, min_total: Duration, mut f: impl FnMut()) -> Duration {
    let (least, most) = (repeats.max(3), repeats.max(50));
    warm_up(&mut f);
    let start = Instant::now();
    let mut times = Vec::new();
    while times.len() < least || (start.elapsed() < min_total && times.len() < most) {
        times.push(timed(&mut f).1);
    }
    median(times)
}

/// Median wall time of each of `count` contestants, `run(i)` running the `i`-th: warm-up
/// rounds (each contestant once per round, for [`WARM_UP`] together), then `repeats` timed
/// rounds (at least one) in which the contestants take turns, so that a noisy machine slows
/// them alike and the ratios between them stay meaningful.
pub fn median_times_in_turns(
    repeats: usize,
    count: usize,
    mut run: impl FnMut(usize),
) -> Vec<Duration> {
    warm_up(|| (0..count).for_each(&mut run));
    let mut times = vec![Vec::new(); count];
    for _ in 0..repeats.max(1) {
        for (i, t) in times.iter_mut().enumerate() {
            t.push(timed(|| run(i)).1);
        }
    }
    times.into_iter().map(median).collect()
}

/// Items per second of `items` processed in `d`.
pub fn per_second(items: usize, d: Duration) -> f64 {
    items as f64 / d.as_secs_f64().max(1e-12)
}

/// Nanoseconds per item of `items` processed in `d`.
pub fn ns_per(items: usize, d: Duration) -> f64 {
    d.as_secs_f64() * 1e9 / items as f64
}
