//! The adapter helper of the GPU test files (`gpu.rs`, `product_gpu.rs`, `vdt_gpu.rs`,
//! `sat.rs`, `shade.rs`), included by each with `#[path = "common/gpu.rs"] mod gpu_common;`.
//!
//! Without an adapter a GPU test prints `GPU tests skipped: <reason>` and passes, unless
//! `STERADIAN_REQUIRE_GPU=1`, in which case it fails.

use std::io::Write;

use steradian_harness::backend::gpu::{Gpu, gpu_required, try_gpu};

/// Writes straight to stderr: the test harness captures `eprintln!` of passing tests, and
/// which adapter ran (or why none did) must show in every test run.
pub fn say(line: &str) {
    let _ = writeln!(std::io::stderr(), "{line}");
}

/// The GPU backend, after saying which adapter it runs on; `None` after saying why there is
/// none, or a panic when `STERADIAN_REQUIRE_GPU=1`.
pub fn gpu() -> Option<Gpu> {
    match try_gpu() {
        Ok(g) => {
            say(&format!("GPU tests ran on adapter: {}", g.adapter_info()));
            Some(g)
        }
        Err(reason) => {
            if gpu_required() {
                panic!("STERADIAN_REQUIRE_GPU=1 but no GPU backend: {reason}");
            }
            say(&format!("GPU tests skipped: {reason}"));
            None
        }
    }
}
