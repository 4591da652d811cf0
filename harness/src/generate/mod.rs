//! Table generators. Each built-in table of `steradian-core` is produced here in f64 from
//! its exact definition, encoded with `steradian_core::table`, and committed under
//! `core/src/lobe/tables/`. `steradian tables` rewrites them; `steradian tables --check`
//! regenerates in memory and fails if a committed file differs.

pub mod cap_exponent;
pub mod lobe_product;

use std::path::{Path, PathBuf};

/// A built-in table: its file name under `core/src/lobe/tables/` and its generator.
pub struct TableDef {
    /// File name, e.g. `cap_exponent.bin`.
    pub file: &'static str,
    /// What the table holds.
    pub about: &'static str,
    /// Produces the complete file bytes (header + payload).
    pub generate: fn() -> Vec<u8>,
}

/// Every built-in table.
pub const TABLES: &[TableDef] = &[
    TableDef {
        file: "cap_exponent.bin",
        about: "h(α) = e*(α)·α², L2-optimal cap exponent, uniform over [0, π/2]",
        generate: cap_exponent::generate,
    },
    TableDef {
        file: "lobe_product.bin",
        about: "g = ln I − ln B, the lobe-product integral's correction to its closed-form baseline",
        generate: lobe_product::generate,
    },
];

/// `core/src/lobe/tables` of this source tree.
pub fn default_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../core/src/lobe/tables")
}

/// Outcome of writing or checking one table.
#[derive(Debug)]
pub struct Outcome {
    /// File name.
    pub file: &'static str,
    /// Size in bytes.
    pub bytes: usize,
    /// For `check`: whether the committed bytes equal a fresh generation.
    pub matches: bool,
}

/// Regenerates every table; writes them into `dir` unless `check_only`, in which case the
/// committed files are compared byte for byte.
pub fn run(dir: &Path, check_only: bool) -> std::io::Result<Vec<Outcome>> {
    let mut out = Vec::new();
    for t in TABLES {
        let fresh = (t.generate)();
        let path = dir.join(t.file);
        let matches = if check_only {
            match std::fs::read(&path) {
                Ok(old) => old == fresh,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => false,
                Err(e) => return Err(e),
            }
        } else {
            std::fs::write(&path, &fresh)?;
            true
        };
        out.push(Outcome {
            file: t.file,
            bytes: fresh.len(),
            matches,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn committed_tables_match_generators() {
        let r = run(&default_dir(), true).unwrap();
        for o in r {
            assert!(
                o.matches,
                "{} differs from a fresh generation: run `steradian tables`",
                o.file
            );
        }
    }
}
