//! Summed-area table queries against the brute-force sum on random small grids (up to 9×9,
//! texels from small integers, quarter fractions, or raw `f32` bits) and random boxes (any
//! corners: fractional, outside the table, inverted, raw `f32` bits including NaN and ±∞):
//! within the documented bound `2⁻²⁴·|I| + 2⁻¹⁵⁰ + 2⁻⁴⁶·A + n·2⁻⁵⁹·T`, NaN exactly when a corner
//! is NaN, the same for every order of the corners, and the SIMD kernel bit-identical.
//! Integer corners through `box_sum_cells` likewise (exact up to the far edges).
//! Non-finite texels must be rejected by the builder; nothing may panic.

use steradian_core::rsl::sat::{SatView, axis};
use steradian_reference::rsl::sat::overlap;
use steradian_simd::f32x8;

fn f32_at(d: &[u8], at: usize) -> f32 {
    let b: [u8; 4] = core::array::from_fn(|k| d.get(at + k).copied().unwrap_or(0));
    f32::from_le_bytes(b)
}

/// The target's checks on one input.
pub fn check(data: &[u8]) {
    if data.len() < 3 {
        return;
    }
    let w = 1 + (data[0] % 9) as usize;
    let h = 1 + (data[1] % 9) as usize;
    let mode = data[2] % 4;
    let rest = &data[3..];
    let texels: Vec<f32> = (0..w * h)
        .map(|k| match mode {
            0 => rest.get(k).map_or(0.0, |&b| b as i8 as f32),
            1 => rest.get(k).map_or(0.0, |&b| b as i8 as f32 * 0.25),
            _ => f32_at(rest, 4 * k),
        })
        .collect();
    let used = if mode < 2 { w * h } else { 4 * w * h };
    let boxes = rest.get(used..).unwrap_or(&[]);

    let mut sums = vec![0i64; (w + 1) * (h + 1)];
    let sat = match SatView::build_into(w, h, &texels, &mut sums) {
        Ok(s) => s,
        Err(_) => {
            assert!(
                texels.iter().any(|t| !t.is_finite()),
                "finite texels rejected: {texels:?}"
            );
            return;
        }
    };
    assert!(texels.iter().all(|t| t.is_finite()));
    let total: f64 = texels.iter().map(|t| (*t as f64).abs()).sum();

    // Each box: 4 corners of 4 bytes; bytes < 0x80 in the last byte of a corner read as a
    // small quarter-texel coordinate (often in or near the table), others as raw f32 bits.
    let mut qs = Vec::new();
    for chunk in boxes.chunks_exact(16).take(16) {
        let c: [f32; 4] = core::array::from_fn(|k| {
            let raw = f32_at(chunk, 4 * k);
            if chunk[4 * k + 3] < 0x80 {
                (chunk[4 * k] as i8 as f32) * 0.25
            } else {
                raw
            }
        });
        qs.push(c);
    }
    for &[u0, v0, u1, v1] in &qs {
        let got = sat.box_sum(u0, v0, u1, v1);
        let any_nan = [u0, v0, u1, v1].iter().any(|c| c.is_nan());
        assert_eq!(got.is_nan(), any_nan, "{u0} {v0} {u1} {v1} → {got}");
        if any_nan {
            continue;
        }
        // Order of the corners does not matter, bit for bit.
        for other in [
            sat.box_sum(u1, v1, u0, v0),
            sat.box_sum(u1, v0, u0, v1),
            sat.box_sum(u0, v1, u1, v0),
        ] {
            assert_eq!(other.to_bits(), got.to_bits());
        }
        // Brute force and the bound.
        let mut exact = 0.0f64;
        for j in 0..h {
            for i in 0..w {
                exact += texels[j * w + i] as f64 * overlap(u0, u1, w, i) * overlap(v0, v1, h, j);
            }
        }
        let (i0, _, i1, _) = axis(u0, u1, w);
        let (j0, _, j1, _) = axis(v0, v1, h);
        let mut abs_read = 0.0f64;
        for j in j0..=j1 {
            for i in i0..=i1 {
                abs_read += (texels[j * w + i] as f64).abs();
            }
        }
        let n = ((i1 - i0 + 1) * (j1 - j0 + 1)) as f64;
        let bound = exact.abs() * 2f64.powi(-24)
            + 2f64.powi(-150)
            + abs_read * 2f64.powi(-46)
            + n * 2f64.powi(-59) * total
            + abs_read * 81.0 * 2f64.powi(-52);
        if exact.abs() <= f32::MAX as f64 * 0.99 {
            assert!(
                ((got as f64) - exact).abs() <= bound,
                "{w}×{h} box ({u0}, {v0}, {u1}, {v1}): got {got}, exact {exact}, bound {bound}"
            );
        }
    }
    // Integer corners (`box_sum_cells`, any order, up to two past the far edge): the
    // brute-force sum within the bound, order-independent, and `box_sum`'s bits while
    // both corners lie before the last column and row.
    for chunk in boxes.chunks_exact(16).take(16) {
        let q: [usize; 4] =
            core::array::from_fn(|k| chunk[4 * k] as usize % (if k % 2 == 0 { w } else { h } + 3));
        let got = sat.box_sum_cells(q[0], q[1], q[2], q[3]);
        for other in [
            sat.box_sum_cells(q[2], q[3], q[0], q[1]),
            sat.box_sum_cells(q[2], q[1], q[0], q[3]),
            sat.box_sum_cells(q[0], q[3], q[2], q[1]),
        ] {
            assert_eq!(other.to_bits(), got.to_bits(), "cells {q:?}");
        }
        let f = q.map(|c| c as f32);
        if q[0].max(q[2]) < w && q[1].max(q[3]) < h {
            let want = sat.box_sum(f[0], f[1], f[2], f[3]);
            assert_eq!(
                got.to_bits(),
                want.to_bits(),
                "cells {q:?}: {got} vs {want}"
            );
        }
        let (x0, x1) = (q[0].min(q[2]).min(w), q[0].max(q[2]).min(w));
        let (y0, y1) = (q[1].min(q[3]).min(h), q[1].max(q[3]).min(h));
        let (mut exact, mut abs_read) = (0.0f64, 0.0f64);
        for j in y0..y1 {
            for i in x0..x1 {
                exact += texels[j * w + i] as f64;
                abs_read += (texels[j * w + i] as f64).abs();
            }
        }
        let n = ((x1 - x0) * (y1 - y0)) as f64;
        let bound = exact.abs() * 2f64.powi(-24)
            + 2f64.powi(-150)
            + n * 2f64.powi(-59) * total
            + abs_read * 81.0 * 2f64.powi(-52);
        if exact.abs() <= f32::MAX as f64 * 0.99 {
            assert!(
                ((got as f64) - exact).abs() <= bound,
                "{w}×{h} cells {q:?}: got {got}, exact {exact}, bound {bound}"
            );
        }
    }
    // SIMD, lane by lane.
    for lanes in qs.chunks(8) {
        let col =
            |c: usize| f32x8::new(core::array::from_fn(|k| lanes.get(k).map_or(0.0, |q| q[c])));
        let r = steradian_simd::rsl::sat::box_sum(&sat, col(0), col(1), col(2), col(3));
        for (k, q) in lanes.iter().enumerate() {
            let want = sat.box_sum(q[0], q[1], q[2], q[3]);
            let got = r.as_array()[k];
            assert!(
                got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                "SIMD lane {k}: {got} vs {want}"
            );
        }
    }
}
