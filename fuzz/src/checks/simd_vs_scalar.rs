//! SIMD vs scalar on arbitrary f32 bit patterns: bit-identical (NaN-ness equal) for the
//! hemisphere map, unmap, lobe integral and cap lookup; within the documented tolerance for
//! lobe evaluation. Never a panic.

use steradian_core::{Vec2, Vec3, lobe, lobe::cap, rsl::hemisphere};
use steradian_simd::f32x8;

fn same(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

fn lanes(data: &[u8], k: usize) -> [f32; 8] {
    let mut out = [0f32; 8];
    for (l, o) in out.iter_mut().enumerate() {
        let at = (k * 8 + l) * 4;
        let b = data.get(at..at + 4).unwrap_or(&[0, 0, 0, 0]);
        *o = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    }
    out
}

/// The target's checks on one input.
pub fn check(data: &[u8]) {
    let c: Vec<[f32; 8]> = (0..8).map(|k| lanes(data, k)).collect();
    let v = |k: usize| f32x8::from(c[k]);

    let p = steradian_simd::rsl::hemisphere::map(steradian_simd::Vec3x8::new(v(0), v(1), v(2)));
    let (pu, pv) = (p.x.to_array(), p.y.to_array());
    let d = steradian_simd::rsl::hemisphere::unmap(steradian_simd::Vec2x8::new(v(0), v(1)));
    let (dx, dy, dz) = (d.x.to_array(), d.y.to_array(), d.z.to_array());
    let integ = steradian_simd::lobe::integral(v(3), v(4)).to_array();
    let ex = steradian_simd::lobe::cap::exponent_l2(v(5)).to_array();
    for l in 0..8 {
        let s = hemisphere::map(Vec3::new(c[0][l], c[1][l], c[2][l]));
        assert!(same(s.x, pu[l]) && same(s.y, pv[l]), "map lane {l}");
        let s = hemisphere::unmap(Vec2::new(c[0][l], c[1][l]));
        assert!(
            same(s.x, dx[l]) && same(s.y, dy[l]) && same(s.z, dz[l]),
            "unmap lane {l}"
        );
        assert!(
            same(lobe::integral(c[3][l], c[4][l]), integ[l]),
            "integral lane {l}"
        );
        let e = cap::exponent_l2(c[5][l]);
        assert!(same(e, ex[l]), "cap lane {l}");
        assert!(
            e.is_nan() || (e >= 0.0 && e.is_finite()),
            "cap exponent {e}"
        );
    }

    // Lobe evaluation on unit axes and directions made from the fuzz data.
    let unit = |x: f32, y: f32, z: f32| {
        let u = steradian_core::frame::normalize_or_zero(Vec3::new(x, y, z));
        if u.is_finite() && u != Vec3::ZERO {
            u
        } else {
            Vec3::Z
        }
    };
    let axes: Vec<Vec3> = (0..8).map(|l| unit(c[0][l], c[1][l], c[2][l])).collect();
    let dirs: Vec<Vec3> = (0..8).map(|l| unit(c[5][l], c[6][l], c[7][l])).collect();
    let scale: Vec<f32> = (0..8)
        .map(|l| if c[3][l].is_finite() { c[3][l] } else { 1.0 })
        .collect();
    let expo: Vec<f32> = (0..8)
        .map(|l| c[4][l].abs().min(1e6))
        .map(|e| if e.is_nan() { 0.0 } else { e })
        .collect();
    let col = |f: &dyn Fn(usize) -> f32| f32x8::from(core::array::from_fn::<f32, 8, _>(f));
    let ax = steradian_simd::Vec3x8::new(
        col(&|l| axes[l].x),
        col(&|l| axes[l].y),
        col(&|l| axes[l].z),
    );
    let dv = steradian_simd::Vec3x8::new(
        col(&|l| dirs[l].x),
        col(&|l| dirs[l].y),
        col(&|l| dirs[l].z),
    );
    let got =
        steradian_simd::lobe::eval_parts(ax, col(&|l| scale[l]), col(&|l| expo[l]), dv).to_array();
    for l in 0..8 {
        let want = lobe::eval(axes[l], scale[l], expo[l], dirs[l]);
        let g = got[l];
        if want == 0.0 {
            assert!(g == 0.0, "eval lane {l}: scalar 0, simd {g}");
            continue;
        }
        let tol = steradian_simd::lobe::EVAL_REL_TOL
            * (1.0 + (want / scale[l]).abs().ln().abs())
            * want.abs()
            + steradian_simd::lobe::EVAL_UNDERFLOW_ABS * (1.0 + scale[l].abs());
        assert!(
            (g - want).abs() <= tol || (g.is_infinite() && g == want),
            "eval lane {l}: scalar {want} simd {g} (axis {:?} s {} e {} v {:?})",
            axes[l],
            scale[l],
            expo[l],
            dirs[l]
        );
    }
}
