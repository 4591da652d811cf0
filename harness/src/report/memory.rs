//! The memory hierarchy of the machine the report runs on, measured in the same run as the
//! kernels it is compared with: the latency of one load (a dependent chase through a random
//! cyclic permutation of cache lines, so that neither the prefetchers nor out-of-order
//! execution can overlap two loads) and the read bandwidth (a streaming sum with independent
//! accumulators), at working sets that sit in L1, in L2 and in DRAM. The table-lookup
//! sections (SAT, VDT) put their kernels beside these and beside a load-only floor of their
//! own access pattern (the same addresses, no arithmetic): that floor is the memory limit a
//! kernel of that layout cannot beat. A leaf module.

use std::hint::black_box;

use super::timing::median_time;
use crate::rng::Rng;

/// Bytes of a cache line (x86-64).
pub const LINE: usize = 64;

/// One level of the hierarchy as measured.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Level {
    /// `L1`, `L2` or `DRAM`: where a working set of `bytes` sits on current x86-64 cores
    /// (L1d 32–48 KiB, L2 0.5–2 MiB, L3 tens of MiB).
    pub name: &'static str,
    /// Working set.
    pub bytes: usize,
    /// Nanoseconds per dependent load.
    pub latency_ns: f64,
    /// Read bandwidth, bytes per nanosecond (GB/s).
    pub bandwidth_bytes_per_ns: f64,
}

/// The working sets measured: 16 KiB, 256 KiB and 256 MiB.
pub const SETS: [(&str, usize); 3] = [("L1", 16 << 10), ("L2", 256 << 10), ("DRAM", 256 << 20)];

/// Nanoseconds per load of a dependent chase through `bytes` (one `u32` link per cache
/// line, a random single cycle through all lines), `steps` loads per timed run.
pub fn latency_ns(bytes: usize, steps: usize, repeats: usize, seed: u64) -> f64 {
    let lines = (bytes / LINE).max(2);
    let per = LINE / 4;
    // Sattolo's algorithm: a uniformly random single cycle.
    let mut order: Vec<u32> = (0..lines as u32).collect();
    let mut rng = Rng::new(seed);
    for i in (1..lines).rev() {
        let j = (rng.next_u64() % i as u64) as usize;
        order.swap(i, j);
    }
    let mut next = vec![0u32; lines * per];
    for (i, &o) in order.iter().enumerate() {
        next[i * per] = o * per as u32;
    }
    let mut at = 0u32;
    let t = median_time(repeats, || {
        let mut p = at;
        for _ in 0..steps {
            p = next[p as usize];
        }
        at = black_box(p);
    });
    t.as_secs_f64() * 1e9 / steps as f64
}

/// Read bandwidth over `bytes` in bytes per nanosecond: the sum of every `u64`, eight
/// independent accumulators (vectorised), `passes` passes per timed run.
pub fn bandwidth(bytes: usize, passes: usize, repeats: usize) -> f64 {
    let words: Vec<u64> = (0..bytes / 8).map(|k| k as u64).collect();
    let t = median_time(repeats, || {
        for _ in 0..passes {
            let acc = black_box(&words)
                .chunks_exact(8)
                .fold([0u64; 8], |mut acc, c| {
                    for i in 0..8 {
                        acc[i] = acc[i].wrapping_add(c[i]);
                    }
                    acc
                });
            black_box(acc);
        }
    });
    (bytes * passes) as f64 / (t.as_secs_f64() * 1e9)
}

/// Every level of [`SETS`], `scale` (≤ 1) shortening the runs of a quick report.
pub fn measure(repeats: usize, scale: f64) -> Vec<Level> {
    let s = |n: usize| ((n as f64 * scale) as usize).max(1);
    SETS.iter()
        .enumerate()
        .map(|(k, &(name, bytes))| {
            let big = bytes > (8 << 20);
            Level {
                name,
                bytes,
                latency_ns: latency_ns(
                    bytes,
                    s(if big { 200_000 } else { 1_000_000 }),
                    repeats,
                    k as u64 + 1,
                ),
                bandwidth_bytes_per_ns: bandwidth(
                    bytes,
                    s(if big { 1 } else { (64 << 20) / bytes }),
                    repeats,
                ),
            }
        })
        .collect()
}

/// One line: latency and bandwidth per level.
pub fn summary(levels: &[Level]) -> String {
    let parts: Vec<String> = levels
        .iter()
        .map(|l| {
            format!(
                "{} ({} KiB): {:.1} ns/load dependent, {:.1} GB/s streaming",
                l.name,
                l.bytes >> 10,
                l.latency_ns,
                l.bandwidth_bytes_per_ns
            )
        })
        .collect();
    format!("memory, same run: {}", parts.join("; "))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The measurements are positive and finite, and DRAM is slower than L1 on both counts
    /// (on any machine the report runs on).
    #[test]
    fn levels_are_ordered() {
        let l1 = latency_ns(16 << 10, 100_000, 3, 1);
        let dram = latency_ns(64 << 20, 20_000, 3, 2);
        assert!(l1 > 0.0 && l1.is_finite() && dram > l1, "{l1} {dram}");
        let b1 = bandwidth(16 << 10, 200, 3);
        let bd = bandwidth(64 << 20, 1, 3);
        assert!(b1 > 0.0 && b1.is_finite() && b1 > bd, "{b1} {bd}");
    }
}
