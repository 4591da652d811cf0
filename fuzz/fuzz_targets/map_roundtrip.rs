//! Hemisphere map and unmap: `unmap(map(d))` is the normalised `d` (mirrored into the upper
//! hemisphere) for every finite non-zero `d`, `map(unmap(p)) = p` inside the disk, outputs
//! stay on the disk and the unit sphere, and nothing panics on any bit pattern.
#![no_main]

use libfuzzer_sys::fuzz_target;
use steradian_core::{Vec2, Vec3, frame::normalize_or_zero, rsl::hemisphere};

fuzz_target!(|data: [u32; 5]| {
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
});
