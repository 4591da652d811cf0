//! The report's timing helpers: every throughput figure of the report is the median of
//! timed runs after one untimed warm-up run (caches, page faults, GPU pipelines), measured
//! here. A leaf module.

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

/// Median wall time of `f` over `repeats` timed runs (at least one) after one warm-up run.
pub fn median_time(repeats: usize, mut f: impl FnMut()) -> Duration {
    f();
    median((0..repeats.max(1)).map(|_| timed(&mut f).1).collect())
}

/// Median wall time of `f` after one warm-up run, over timed runs repeated until they fill
/// `min_total` together: at least `repeats` and 3 runs, at most 50 (or `repeats`, if more).
pub fn median_time_for(repeats: usize, min_total: Duration, mut f: impl FnMut()) -> Duration {
    let (least, most) = (repeats.max(3), repeats.max(50));
    f();
    let start = Instant::now();
    let mut times = Vec::new();
    while times.len() < least || (start.elapsed() < min_total && times.len() < most) {
        times.push(timed(&mut f).1);
    }
    median(times)
}

/// Median wall time of each of `count` contestants, `run(i)` running the `i`-th: one warm-up
/// round, then `repeats` timed rounds (at least one) in which the contestants take turns, so
/// that a noisy machine slows them alike and the ratios between them stay meaningful.
pub fn median_times_in_turns(
    repeats: usize,
    count: usize,
    mut run: impl FnMut(usize),
) -> Vec<Duration> {
    let mut times = vec![Vec::new(); count];
    for round in 0..=repeats.max(1) {
        for (i, t) in times.iter_mut().enumerate() {
            let (_, d) = timed(|| run(i));
            if round > 0 {
                t.push(d);
            }
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
