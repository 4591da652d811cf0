//! Fuzz target `cap_integrals`: the checks of `steradian_fuzz::checks::cap_integrals`
//! (replayed from the committed corpus by the harness test `fuzz_replay`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| steradian_fuzz::checks::cap_integrals::check(data));
