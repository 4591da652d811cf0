//! The coverage test (as libm's `check_coverage`): every registered kernel has each of its
//! pieces — scalar kernel, SIMD twin, WGSL twin, f64 reference, eval handler, error bound —
//! or says why it deliberately has none, and every item the registry names exists in the
//! sources. A missing piece fails the test with the list of what is missing.

use std::path::Path;

use steradian_harness::registry::{self, KERNELS, Piece};

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

#[test]
fn every_registered_kernel_has_every_piece() {
    let missing = registry::missing_pieces(KERNELS, root());
    let list: Vec<String> = missing
        .iter()
        .map(|(k, what)| format!("  {k}: {what}"))
        .collect();
    assert!(
        missing.is_empty(),
        "{} missing piece(s):\n{}",
        missing.len(),
        list.join("\n")
    );
}

#[test]
fn the_check_notices_a_removed_piece() {
    // A kernel whose SIMD twin is gone, whose reference names nothing, and which gives no
    // reason for lacking a GPU twin: each is reported.
    let mut k = *registry::find("lobe-eval").unwrap();
    k.simd = Piece::At("steradian_simd::lobe::no_such_function");
    k.reference = Piece::At("steradian_harness::reference::nothing_here");
    k.wgsl = Piece::Without("");
    let missing = registry::missing_pieces(&[k], root());
    let text: Vec<&str> = missing.iter().map(|(_, w)| w.as_str()).collect();
    assert!(text.iter().any(|w| w.starts_with("SIMD twin")), "{text:?}");
    assert!(text.iter().any(|w| w.starts_with("reference")), "{text:?}");
    assert!(
        text.iter().any(|w| w.starts_with("no WGSL twin")),
        "{text:?}"
    );
}

#[test]
fn eval_accepts_exactly_the_registered_handlers() {
    for k in KERNELS {
        assert_eq!(
            steradian_harness::eval::accepts(k.name),
            k.eval.get().is_some(),
            "{}",
            k.name
        );
    }
    assert!(!steradian_harness::eval::accepts("no-such-kernel"));
}
