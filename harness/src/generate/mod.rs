//! Table generators. Each built-in table of `steradian-core` is produced here in f64 from
//! its exact definition, encoded with `steradian_core::table`, and committed beside the
//! module that reads it (`core/src/lobe/tables/`, `core/src/sh/tables/`); so is the
//! straight-line SH code of `core/src/sh/fixed.rs` and `simd/src/sh/fixed.rs`. `steradian tables` rewrites them; `steradian tables --check`
//! regenerates in memory and fails if a committed file differs.

pub mod brdf_sh;
pub mod cap_exponent;
pub mod lobe_product;
pub mod mask_weights;
pub mod sh_fixed;

use std::path::{Path, PathBuf};

/// A built-in table: its path under `core/src/` and its generator.
pub struct TableDef {
    /// Path from the repository root, e.g. `core/src/lobe/tables/cap_exponent.bin`.
    pub file: &'static str,
    /// What the table holds.
    pub about: &'static str,
    /// Produces the complete file bytes (header + payload).
    pub generate: fn() -> Vec<u8>,
}

/// Every built-in table.
pub const TABLES: &[TableDef] = &[
    TableDef {
        file: "core/src/lobe/tables/cap_exponent.bin",
        about: "h(α) = e*(α)·α², L2-optimal cap exponent, uniform over [0, π/2]",
        generate: cap_exponent::generate,
    },
    TableDef {
        file: "core/src/lobe/tables/lobe_product.bin",
        about: "g = ln I − ln B, the lobe-product integral's correction to its closed-form baseline",
        generate: lobe_product::generate,
    },
    TableDef {
        file: "core/src/lobe/tables/mask_weights.bin",
        about: "w(dist, depth), the quadtree mask's leaf weights, least squares against exact visibility",
        generate: mask_weights::generate,
    },
    TableDef {
        file: "core/src/sh/tables/brdf_lambert.bin",
        about: "SH of Lambert (albedo 1) with and without the cosine, per view",
        generate: brdf_sh::generate_lambert,
    },
    TableDef {
        file: "core/src/sh/tables/brdf_phong30.bin",
        about: "SH of modified Phong (specular 1, exponent 30), per view",
        generate: brdf_sh::generate_phong,
    },
    TableDef {
        file: "core/src/sh/tables/brdf_lafortune.bin",
        about: "SH of a two-lobe Lafortune BRDF, per view",
        generate: brdf_sh::generate_lafortune,
    },
    TableDef {
        file: "core/src/sh/tables/brdf_ggx.bin",
        about: "SH of GGX (F0 0.04, alpha 0.3) with Schlick Fresnel, per view",
        generate: brdf_sh::generate_ggx,
    },
    TableDef {
        file: "core/src/sh/fixed.rs",
        about: "straight-line SH evaluation for 2–10 bands: the recurrence unrolled, its coefficients as literals",
        generate: sh_fixed::generate,
    },
    TableDef {
        file: "simd/src/sh/fixed.rs",
        about: "the same straight-line evaluation on f64 lanes, for the SIMD twin",
        generate: sh_fixed::generate_lanes,
    },
];

/// The root of this source tree (the table paths are relative to it).
pub fn default_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
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
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent)?;
            }
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
