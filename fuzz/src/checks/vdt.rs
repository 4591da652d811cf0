//! Visibility distance tables: on arbitrary small masks the exact signed distances are
//! symmetric under flips of either axis and the transpose, negate under inversion, are ±½
//! at every texel that touches the other class (so the interpolated D is zero at every
//! boundary-edge midpoint); arbitrary queries (any f32 bits) never panic, return a value in
//! [0, 1] (NaN only for NaN input), and the SIMD query equals the scalar one bit for bit.

use steradian_core::rsl::vdt::{VdtView, scratch_len, signed_distance_into};

fn edt(w: usize, h: usize, m: &[bool]) -> Vec<f32> {
    let mut d = vec![0.0; w * h];
    let mut s = vec![0.0; scratch_len(w, h)];
    signed_distance_into(w, h, m, &mut d, &mut s).expect("valid shape");
    d
}

/// The target's checks on one input.
pub fn check(data: &[u8]) {
    if data.len() < 2 {
        return;
    }
    let w = 1 + (data[0] % 24) as usize;
    let h = 1 + (data[1] % 24) as usize;
    let bits = &data[2..];
    let m: Vec<bool> = (0..w * h)
        .map(|k| bits.get(k / 8).is_some_and(|b| b >> (k % 8) & 1 == 1))
        .collect();
    let d = edt(w, h, &m);
    let flip_u: Vec<bool> = (0..w * h)
        .map(|k| m[(k / w) * w + (w - 1 - k % w)])
        .collect();
    let flip_v: Vec<bool> = (0..w * h).map(|k| m[(h - 1 - k / w) * w + k % w]).collect();
    let tr: Vec<bool> = (0..w * h).map(|k| m[(k % h) * w + k / h]).collect();
    let inv: Vec<bool> = m.iter().map(|b| !b).collect();
    let (du, dv, dt, di) = (
        edt(w, h, &flip_u),
        edt(w, h, &flip_v),
        edt(h, w, &tr),
        edt(w, h, &inv),
    );
    for j in 0..h {
        for i in 0..w {
            let x = d[j * w + i];
            assert!(x.is_finite() && (x > 0.0) == m[j * w + i]);
            assert_eq!(du[j * w + (w - 1 - i)], x);
            assert_eq!(dv[(h - 1 - j) * w + i], x);
            assert_eq!(dt[i * h + j], x);
            assert_eq!(di[j * w + i], -x);
            let touches = [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)]
                .iter()
                .any(|&(a, b)| {
                    let (x2, y2) = (i as i64 + a, j as i64 + b);
                    x2 >= 0
                        && y2 >= 0
                        && (x2 as usize) < w
                        && (y2 as usize) < h
                        && m[y2 as usize * w + x2 as usize] != m[j * w + i]
                });
            assert_eq!(touches, x.abs() == 0.5, "texel ({i}, {j}) D = {x}");
        }
    }
    let view = VdtView::new(w, h, &d).expect("valid table");
    for j in 0..h {
        for i in 1..w {
            if m[j * w + i - 1] != m[j * w + i] {
                assert_eq!(view.distance(i as f32, j as f32 + 0.5), 0.0);
            }
        }
    }
    // Queries from the tail: any f32 bits.
    let qb = &bits[(w * h).div_ceil(8).min(bits.len())..];
    let f = |k: usize| {
        qb.get(4 * k..4 * k + 4)
            .map_or(0.5, |b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let nq = qb.len() / 12;
    let (mut u, mut v, mut r) = (Vec::new(), Vec::new(), Vec::new());
    for q in 0..nq {
        u.push(f(3 * q));
        v.push(f(3 * q + 1));
        r.push(f(3 * q + 2));
    }
    let mut e9 = vec![0.0; nq];
    let mut gr = vec![0.0; nq];
    steradian_simd::rsl::vdt::query_slices(&view, &u, &v, &r, &mut e9, &mut gr);
    for q in 0..nq {
        let (a, b) = view.query(u[q], v[q], r[q]);
        let nan_in = u[q].is_nan() || v[q].is_nan() || r[q].is_nan();
        for x in [a, b] {
            if nan_in {
                assert!(x.is_nan() || (0.0..=1.0).contains(&x));
            } else {
                assert!(
                    (0.0..=1.0).contains(&x),
                    "query {:?} → {x}",
                    (u[q], v[q], r[q])
                );
            }
        }
        assert!(a.to_bits() == e9[q].to_bits() || (a.is_nan() && e9[q].is_nan()));
        assert!(b.to_bits() == gr[q].to_bits() || (b.is_nan() && gr[q].is_nan()));
    }
}
