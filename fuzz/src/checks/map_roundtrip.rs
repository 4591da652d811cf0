//! Hemisphere map and unmap: `unmap(map(d))` is the normalised `d` (mirrored into the upper
//! hemisphere) for every finite non-zero `d`, `map(unmap(p)) = p` inside the disk, outputs
//! stay on the disk and the unit sphere, and nothing panics on any bit pattern.

use steradian_core::{Vec2, Vec3, frame::normalize_or_zero, rsl::hemisphere};

/// The five `u32` of the input, little-endian, zero-padded (the decoding of the
/// `arbitrary` crate the target used, so earlier corpora keep their meaning).
fn words(bytes: &[u8]) -> [u32; 5] {
    core::array::from_fn(|k| {
        let mut w = [0u8; 4];
        for (i, b) in w.iter_mut().enumerate() {
            *b = bytes.get(4 * k + i).copied().unwrap_or(0);
        }
        u32::from_le_bytes(w)
    })
}

/// The target's checks on one input.
pub fn check(bytes: &[u8]) {
    let data = words(bytes);
    let [x, y, z, u, v] = data.map(f32::from_bits);
    let d = Vec3::new(x, y, z);
    let p = hemisphere::map(d);
    if d.is_finite() && d != Vec3::ZERO {
        assert!(p.is_finite() && p.length() <= 1.0 + 1e-6, "map({d}) = {p}");
        let n = normalize_or_zero(d);
        let back = hemisphere::unmap(p);
        let want = Vec3::new(n.x, n.y, n.z.abs());
        assert!(
            (back - want).abs().max_element() < 2e-6,
            "{d}: {back} vs {want}"
        );
    } else if !d.is_finite() {
        assert!(p.is_nan() || p.is_finite(), "never infinite");
    }
    let q = Vec2::new(u, v);
    let dir = hemisphere::unmap(q);
    if q.is_finite() {
        assert!(
            (dir.length() - 1.0).abs() < 1e-6 && dir.z >= 0.0,
            "unmap({q}) = {dir}"
        );
        if q.length_squared() <= 1.0 {
            let again = hemisphere::map(dir);
            assert!(
                (again - q).abs().max_element() < 2e-6,
                "{q} → {dir} → {again}"
            );
        }
    }
}
