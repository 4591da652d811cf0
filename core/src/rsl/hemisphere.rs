//! Equal-area hemisphere map (rotatable-square-lights paper, section 5).
//!
//! `p = (x, y)/sqrt(1 + z)` maps the unit upper hemisphere onto the unit disk; it is the
//! paper's `p = sinθ/sqrt(1 + cosθ)·(cos φ, sin φ)` written without trigonometry (our frame
//! has `x = sinθ·cosφ`; the paper's `(sin φ, cos φ)` only swaps the axes). The inverse is
//! `z = 1 − |p|²`, `(x, y) = p·sqrt(2 − |p|²)`, and the map is equal-area: `dω = 2·du·dv`,
//! so the disk's area π carries the hemisphere's 2π sr.
//!
//! The disk is inscribed in the texture square as the paper does: `uv = (p + 1)/2`, texel
//! `(i, j)` of an `n × n` grid covers `[i, i+1]/n × [j, j+1]/n` and has solid angle `8/n²`
//! where it lies inside the disk (texels straddling the circle cover the horizon partly).
//!
//! **Error bounds** (checked against an f64 reference by the harness property tests):
//! [`map`] is within [`MAP_ABS_ERROR`] per component of the exact map of the normalised
//! input; [`unmap`] within [`UNMAP_ABS_ERROR`] per component for `|p| ≤ 1`.
//!
//! **Bad input** (never panics): the input of [`map`] need not be unit (it is normalised
//! without overflow for any finite vector); the zero vector maps to the pole `p = 0`; a
//! direction below the horizon is mirrored through the tangent plane (`z → |z|`), so the map
//! is total and continuous, and callers that need zero below the horizon test `z`
//! themselves; NaN or infinite components give NaN. [`unmap`] clamps points outside the unit
//! disk radially onto the circle (the horizon); NaN or infinite input gives NaN.

use crate::math;
use crate::{Vec2, Vec3};

/// Per-component absolute error bound of [`map`] against the exact map of the normalised
/// input, for any finite non-zero input.
pub const MAP_ABS_ERROR: f32 = 3.0e-7;
/// Per-component absolute error bound of [`unmap`] against the exact inverse, `|p| ≤ 1`.
pub const UNMAP_ABS_ERROR: f32 = 3.0e-7;

/// Direction → point on the unit disk: `p = (x, y)/sqrt(1 + |z|)` of the normalised input.
///
/// Branch-free apart from the zero-vector fallback; LLVM vectorises a loop over it.
#[inline]
pub fn map(dir: Vec3) -> Vec2 {
    let m = dir.x.abs().max(dir.y.abs()).max(dir.z.abs());
    // Any common factor keeps the direction: clamping 1/m to the normal range avoids its
    // overflow for subnormal m and its subnormal (flushed under FTZ) value for m > 2¹²⁶.
    let r = (1.0 / m).clamp(f32::MIN_POSITIVE, f32::MAX);
    let (x, y, z) = (dir.x * r, dir.y * r, dir.z * r);
    let inv_len = 1.0 / math::sqrtf(x * x + y * y + z * z);
    let zn = z.abs() * inv_len;
    let s = inv_len / math::sqrtf(1.0 + zn);
    if m == 0.0 {
        // The zero vector → the pole; `m` ignores NaN, so keep a NaN component visible.
        let z0 = (dir.x + dir.y + dir.z) * 0.0;
        Vec2::new(z0, z0)
    } else {
        Vec2::new(x * s, y * s)
    }
}

/// Point on the disk → unit direction in the upper hemisphere:
/// `z = 1 − |p|²`, `(x, y) = p·sqrt(2 − |p|²)`. Points outside the disk are clamped radially
/// onto the unit circle.
#[inline]
pub fn unmap(p: Vec2) -> Vec3 {
    let r2 = p.x * p.x + p.y * p.y;
    let (px, py, r2) = if r2 > 1.0 {
        // Scale by the larger component first so |p| beyond 1.8e19 does not overflow.
        let m = p.x.abs().max(p.y.abs());
        let (qx, qy) = (p.x / m, p.y / m);
        let k = 1.0 / math::sqrtf(qx * qx + qy * qy);
        (qx * k, qy * k, 1.0)
    } else {
        (p.x, p.y, r2)
    };
    let s = math::sqrtf(2.0 - r2);
    Vec3::new(px * s, py * s, 1.0 - r2)
}

/// The partial derivatives `(∂ω/∂u, ∂ω/∂v)` of the inverse map `ω(p) = (p·sqrt(2 − |p|²),
/// 1 − |p|²)` at `p`: with `s = sqrt(2 − |p|²)`,
///
/// ```text
///   ∂ω/∂u = (s − u²/s, −u·v/s, −2u),   ∂ω/∂v = (−u·v/s, s − v²/s, −2v),
/// ```
///
/// and `|∂ω/∂u × ∂ω/∂v| = 2` (the map is equal-area). The formula is that of the whole-sphere
/// map ([`crate::rsl::map_extended`]), so it holds beyond the unit disk up to `|p| = √2`
/// (the antipode), where `s → 0`; `|p|²` is clamped to `2 − 2⁻¹²` there so the result
/// stays finite (near the antipode a first-order model of the map is meaningless anyway).
/// Used by the moments kernel to carry a light's radiance gradient into the parametrisation
/// ([`crate::rsl::shade::light_moments`]). NaN in gives NaN.
#[inline]
pub fn unmap_jacobian(p: Vec2) -> (Vec3, Vec3) {
    let r2 = (p.x * p.x + p.y * p.y).min(2.0 - 1.0 / 4096.0);
    let s = math::sqrtf(2.0 - r2);
    let inv = 1.0 / s;
    let uv = p.x * p.y * inv;
    (
        Vec3::new(s - p.x * p.x * inv, -uv, -2.0 * p.x),
        Vec3::new(-uv, s - p.y * p.y * inv, -2.0 * p.y),
    )
}

/// Disk point → texture coordinates in `[0, 1]²` (the disk inscribed in the square).
#[inline]
pub fn disk_to_uv(p: Vec2) -> Vec2 {
    (p + Vec2::ONE) * 0.5
}

/// Texture coordinates → disk point (`2·uv − 1`; points outside the disk are below the
/// horizon and [`unmap`] clamps them).
#[inline]
pub fn uv_to_disk(uv: Vec2) -> Vec2 {
    uv * 2.0 - Vec2::ONE
}

/// Direction → texture coordinates: [`disk_to_uv`]∘[`map`].
#[inline]
pub fn dir_to_uv(dir: Vec3) -> Vec2 {
    disk_to_uv(map(dir))
}

/// Unit direction through the centre of texel `(i, j)` of an `n × n` grid (`i` along u,
/// `j` along v). Centres outside the disk are clamped to the horizon. `n = 0` gives NaN.
#[inline]
pub fn texel_center_dir(i: u32, j: u32, n: u32) -> Vec3 {
    let inv = 1.0 / n as f32;
    let uv = Vec2::new((i as f32 + 0.5) * inv, (j as f32 + 0.5) * inv);
    unmap(uv_to_disk(uv))
}

/// Texel `(i, j)` of an `n × n` grid containing a direction (clamped to the grid).
#[inline]
pub fn dir_to_texel(dir: Vec3, n: u32) -> (u32, u32) {
    let uv = dir_to_uv(dir);
    let f = n as f32;
    let last = n.saturating_sub(1);
    // `as u32` saturates and maps NaN to 0.
    let i = ((uv.x * f) as u32).min(last);
    let j = ((uv.y * f) as u32).min(last);
    (i, j)
}

/// Solid angle of one texel of an `n × n` grid lying wholly inside the disk: `8/n²`
/// (the square `[-1, 1]²` has area 4 and `dω = 2·du·dv`).
#[inline]
pub fn texel_solid_angle(n: u32) -> f32 {
    let f = n as f32;
    8.0 / (f * f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unmap_jacobian_matches_central_differences_and_is_equal_area() {
        // f64 inverse map (the whole-sphere formula) for the differences.
        let w = |x: f64, y: f64| {
            let s = (2.0 - x * x - y * y).sqrt();
            [x * s, y * s, 1.0 - x * x - y * y]
        };
        // The pole, mid-disk, near the horizon, beyond it (the extended map) and near the
        // antipode.
        for (x, y) in [
            (0.0, 0.0),
            (0.3, -0.4),
            (-0.7, 0.69),
            (0.99, 0.05),
            (1.1, -0.3),
            (0.9, 1.0),
        ] {
            let (ju, jv) = unmap_jacobian(Vec2::new(x as f32, y as f32));
            let e = 1e-6;
            for (j, d) in [(ju, (e, 0.0)), (jv, (0.0, e))] {
                let (a, b) = (w(x + d.0, y + d.1), w(x - d.0, y - d.1));
                for k in 0..3 {
                    let fd = (a[k] - b[k]) / (2.0 * e);
                    assert!(
                        (f64::from(j[k]) - fd).abs() < 2e-5,
                        "({x}, {y}) {k}: {j} vs {fd}"
                    );
                }
            }
            let area = ju.cross(jv).length();
            assert!((area - 2.0).abs() < 1e-5, "({x}, {y}): area factor {area}");
        }
        // The antipode stays finite; NaN propagates.
        let (a, b) = unmap_jacobian(Vec2::new(core::f32::consts::SQRT_2, 0.0));
        assert!(a.is_finite() && b.is_finite());
        assert!(unmap_jacobian(Vec2::new(f32::NAN, 0.0)).0.is_nan());
    }

    #[test]
    fn pole_horizon_and_fallbacks() {
        assert_eq!(map(Vec3::Z), Vec2::ZERO);
        assert_eq!(map(Vec3::ZERO), Vec2::ZERO);
        let h = map(Vec3::X);
        assert!((h - Vec2::X).length() < 1e-7);
        // mirrored lower hemisphere
        let a = map(Vec3::new(0.3, -0.4, 0.5));
        let b = map(Vec3::new(0.3, -0.4, -0.5));
        assert_eq!(a, b);
        assert_eq!(map(-Vec3::Z), Vec2::ZERO);
        assert!(map(Vec3::new(f32::NAN, 0.0, 1.0)).x.is_nan());
        assert!(map(Vec3::new(f32::NAN, 0.0, 0.0)).is_nan());
        assert!(map(Vec3::new(0.0, 0.0, f32::NAN)).is_nan());
        assert!(map(Vec3::new(f32::INFINITY, 0.0, 1.0)).is_nan());
        // subnormal components: the reciprocal of the largest saturates, no NaN
        let s = map(Vec3::new(1e-45, 0.0, 1e-45));
        assert!((s - map(Vec3::new(1.0, 0.0, 1.0))).length() < 1e-6, "{s}");
        // unmap clamps outside the disk onto the horizon
        let d = unmap(Vec2::new(3.0, 4.0));
        assert!((d - Vec3::new(0.6, 0.8, 0.0)).length() < 1e-6);
        assert!(unmap(Vec2::new(f32::NAN, 0.0)).is_nan());
        let far = unmap(Vec2::new(3e30, -4e30));
        assert!((far - Vec3::new(0.6, -0.8, 0.0)).length() < 1e-6, "{far}");
        let big = map(Vec3::new(3e38, 1e38, 2e38));
        assert!(
            (big - map(Vec3::new(3.0, 1.0, 2.0))).length() < 1e-6,
            "{big}"
        );
        assert!(unmap(Vec2::new(f32::INFINITY, 0.0)).is_nan());
    }

    #[test]
    fn texel_helpers() {
        let n = 32;
        let mut inside = 0;
        for j in 0..n {
            for i in 0..n {
                let d = texel_center_dir(i, j, n);
                assert!((d.length() - 1.0).abs() < 1e-6 && d.z >= 0.0);
                let p = uv_to_disk(Vec2::new(
                    (i as f32 + 0.5) / n as f32,
                    (j as f32 + 0.5) / n as f32,
                ));
                if p.length() < 1.0 {
                    inside += 1;
                    assert_eq!(dir_to_texel(d, n), (i, j));
                }
            }
        }
        // texels with centres inside the disk carry about the hemisphere's 2π sr
        let total = inside as f32 * texel_solid_angle(n);
        assert!((total - crate::TWO_PI).abs() < 0.05 * crate::TWO_PI);
        assert_eq!(dir_to_texel(Vec3::new(f32::NAN, 0.0, 1.0), n), (0, 0));
    }
}
