//! The straight-line SH evaluation of `steradian_core::sh` for 2–10 bands
//! (`core/src/sh/fixed.rs`): the recurrence of `sh::fill` written out for each band count,
//! its coefficients `A`, `AB`, `DIAG`, `SUB` as literals (Rust's shortest round-trip
//! decimal of each `f64`, so the same bits), no loop, no index arithmetic, no bounds check
//! but one per function. Every value is computed by the operations `sh::fill` performs for
//! it, in the same order (the homogeneous recurrence with `r²`, each value times `r^−l`;
//! on a normalised point, `r² = r^−l = 1`, the products by 1 fold away), so the output is
//! bit-identical to the loop's (tested in core).

use std::fmt::Write as _;

use steradian_core::sh::{A, AB, DIAG, SUB, tri};

/// The band counts written out.
pub const BANDS: std::ops::RangeInclusive<usize> = 2..=10;

/// An `f64` literal with the value's exact bits.
fn lit(v: f64) -> String {
    let s = format!("{v:?}");
    debug_assert_eq!(s.parse::<f64>().map(f64::to_bits), Ok(v.to_bits()));
    s
}

/// The function for `n` bands: scalar (`core`'s `fill` into `out`) or on `f64` lanes
/// (`simd`'s `fill`, generic over its lane type, each value handed to `put`).
fn function(n: usize, lanes: bool, out: &mut String) {
    let nn = n * n;
    let w = |out: &mut String, line: String| {
        out.push_str("    ");
        out.push_str(&line);
        out.push('\n');
    };
    // A literal, splatted on lanes.
    let k = |v: f64| {
        if lanes {
            format!("sp({})", lit(v))
        } else {
            lit(v)
        }
    };
    let put = |out: &mut String, at: usize, v: String| {
        if lanes {
            w(out, format!("put({at}, {v});"));
        } else if v.contains(' ') {
            w(out, format!("out[{at}] = ({v}) as f32;"));
        } else {
            w(out, format!("out[{at}] = {v} as f32;"));
        }
    };
    writeln!(out, "/// `fill` for {n} bands, straight-line.").unwrap();
    writeln!(out, "#[inline(always)]").unwrap();
    if lanes {
        writeln!(
            out,
            "pub(super) fn fill_{n}<F: F64Lanes>(u: [F; 5], put: &mut impl FnMut(usize, F)) {{"
        )
        .unwrap();
        // r² enters only the steps from band 2 on (n ≥ 3).
        let r2 = if n >= 3 { "r2" } else { "_" };
        w(out, format!("let [x, y, z, {r2}, inv] = u;"));
        w(out, "let sp = F::splat;".into());
    } else {
        writeln!(out, "pub(super) fn fill_{n}(pt: Point, out: &mut [f32]) {{").unwrap();
        w(
            out,
            format!("let Some(out) = out.first_chunk_mut::<{nn}>() else {{"),
        );
        w(out, "    return;".into());
        w(out, "};".into());
        if n >= 3 {
            w(
                out,
                "let (x, y, z, r2, inv) = (pt.p.x, pt.p.y, pt.p.z, pt.r2, pt.inv);".into(),
            );
        } else {
            w(
                out,
                "let (x, y, z, inv) = (pt.p.x, pt.p.y, pt.p.z, pt.inv);".into(),
            );
        }
        // `+ 0·z`: NaN for a NaN direction, exactly `Y00` otherwise (`fill`'s last write).
        w(out, "out[0] = (Y00_F64 + 0.0 * z) as f32;".into());
    }
    // r^−l, l ≥ 1, as `fill`'s `il[l] = il[l−1]·inv` (il[1] = 1·inv = inv exactly).
    for l in 1..n {
        if l == 1 {
            w(out, "let i1 = inv;".into());
        } else {
            w(out, format!("let i{l} = i{} * inv;", l - 1));
        }
    }
    // One value: the chain's next q (from the order's first value, the one-step start or
    // the two-term recurrence) and its outputs.
    let value = |out: &mut String, l: usize, m: usize| {
        if l == m {
            // The order's angular factors and the chain's first value (`fill`'s first
            // loop; `Π_m^m` does not depend on the direction: a scalar constant).
            if m == 0 {
                let y00 = if lanes { "sp(Y00_F64)" } else { "Y00_F64" };
                w(out, format!("let q0_0 = {y00};"));
            } else {
                let prev = if m == 1 {
                    "Y00_F64".to_string()
                } else {
                    format!("p{}", m - 1)
                };
                let (c, s) = if m == 1 {
                    (k(1.0), k(0.0))
                } else {
                    (format!("c{}", m - 1), format!("s{}", m - 1))
                };
                w(out, format!("let p{m} = {prev} * {};", lit(DIAG[m])));
                w(
                    out,
                    format!("let (c{m}, s{m}) = (x * {c} - y * {s}, x * {s} + y * {c});"),
                );
                let q = format!("core::f64::consts::SQRT_2 * p{m}");
                let q = if lanes { format!("sp({q})") } else { q };
                w(out, format!("let q{m}_{m} = {q};"));
            }
        } else if l == m + 1 {
            w(out, format!("let q{l}_{m} = {} * z * q{m}_{m};", k(SUB[m])));
        } else {
            let t = tri(l, m);
            w(
                out,
                format!(
                    "let q{l}_{m} = {} * z * q{}_{m} - {} * r2 * q{}_{m};",
                    k(A[t]),
                    l - 1,
                    k(AB[t]),
                    l - 2
                ),
            );
        }
        // The value goes out as q·S_m, then q·C_m; for m = 0 (C = 1, S = 0) that is q
        // itself (q·1 = q exactly), and coefficient 0 is written once, last.
        // Each value q·S (q·C) times r^−l last (`fill`'s order: only that product waits
        // for the normalisation).
        let at = l * l + l;
        if m == 0 {
            if l > 0 {
                put(out, at, format!("q{l}_0 * i{l}"));
            }
        } else {
            put(out, at - m, format!("q{l}_{m} * s{m} * i{l}"));
            put(out, at + m, format!("q{l}_{m} * c{m} * i{l}"));
        }
    };
    // Every value's operations are those of `fill`, whatever the order of the statements:
    // order by order on lanes; band by band in the scalar code, whose stores then come in
    // the order of the output (the statement order is what LLVM's SLP vectorizer packs
    // neighbouring stores from).
    if lanes {
        for m in 0..n {
            for l in m..n {
                value(out, l, m);
            }
        }
    } else {
        for l in 0..n {
            for m in 0..=l {
                value(out, l, m);
            }
        }
    }
    if lanes {
        w(out, "put(0, sp(Y00_F64) + sp(0.0) * z);".into());
    }
    out.push_str("}\n");
}

/// The complete scalar file (`core/src/sh/fixed.rs`).
pub fn code() -> String {
    let mut out = String::from(
        "//! Straight-line SH evaluation for 2–10 bands: `sh::fill`'s recurrence written out per\n\
         //! band count, bit-identical to it (tested in `sh`). Generated by\n\
         //! `steradian-harness` (`generate::sh_fixed`); `steradian tables --check` proves this\n\
         //! file matches its generator. Do not edit.\n\n\
         use super::{Point, Y00_F64};\n",
    );
    for n in BANDS {
        out.push('\n');
        function(n, false, &mut out);
    }
    out
}

/// The complete lanes file (`simd/src/sh/fixed.rs`).
pub fn code_lanes() -> String {
    let mut out = String::from(
        "//! Straight-line SH evaluation for 2–10 bands on `f64` lanes: `fill`'s recurrence\n\
         //! written out per band count, bit-identical lane by lane to the scalar kernel (tested\n\
         //! in `sh`). Generated by `steradian-harness` (`generate::sh_fixed`);\n\
         //! `steradian tables --check` proves this file matches its generator. Do not edit.\n\n\
         use steradian_core::sh::Y00_F64;\n\n\
         use super::F64Lanes;\n",
    );
    for n in BANDS {
        out.push('\n');
        function(n, true, &mut out);
    }
    out
}

/// [`code`] as the bytes of the committed file.
pub fn generate() -> Vec<u8> {
    code().into_bytes()
}

/// [`code_lanes`] as the bytes of the committed file.
pub fn generate_lanes() -> Vec<u8> {
    code_lanes().into_bytes()
}
