//! Every input the fuzzers ever kept, replayed through the same invariant checks on stable:
//! the fuzz targets' checks (`fuzz/src/checks/`) on every file of the committed corpora
//! (`fuzz/corpus/<target>/`), in seconds, as part of `cargo test --workspace`.

#[path = "../../fuzz/src/checks/mod.rs"]
#[allow(dead_code)]
mod checks;

use std::path::Path;

#[test]
fn every_corpus_input_passes_its_target_checks() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/corpus");
    let mut total = 0;
    for (name, check) in checks::TARGETS {
        let dir = root.join(name);
        let entries = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e} (a committed corpus per target)", dir.display()));
        let mut n = 0;
        for e in entries {
            let path = e.expect("readable corpus entry").path();
            let data = std::fs::read(&path).expect("readable corpus file");
            let r = std::panic::catch_unwind(|| check(&data));
            assert!(r.is_ok(), "{name}: {} fails its checks", path.display());
            n += 1;
        }
        assert!(n > 0, "{name}: empty corpus");
        eprintln!("{name}: {n} inputs");
        total += n;
    }
    assert!(total > 0);
}
