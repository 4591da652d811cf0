//! Equal-area hemisphere map, 8 lanes at a time (mirrors `steradian_core::rsl::hemisphere`).
//!
//! [`map`] and [`unmap`] perform exactly the scalar kernels' IEEE operations in the same
//! order, so every lane is **bit-identical** to `steradian_core::rsl::hemisphere::map`/`unmap` of
//! that lane, for every input (NaN-ness matches, payloads may differ). That includes the
//! scalar kernels' saturation: the zero vector maps to the pole, the reciprocal `1/m` of the
//! largest component is clamped to the normal range, `z → |z|`, points outside the disk are
//! scaled by their larger component and clamped onto the circle, and the NaN-ignoring
//! `f32::max` of the normalisation (so `(NaN, 0, 0)` maps to `0`, as in the scalar kernel).
//!
//! [`map_slices`] and [`unmap_slices`] run over structure-of-arrays columns of any length.

use crate::batch::{PAD_VEC2, PAD_VEC3, Vec2x8, Vec3x8};
use crate::lanes::{ColumnKernel, Lanes, SliceVec, clamp, drive, max_num};

/// Direction → point on the unit disk, lane-wise `steradian_core::rsl::hemisphere::map`:
/// `p = (x, y)/sqrt(1 + |z|)` of the normalised input, the zero vector → `0`.
#[inline]
pub fn map(dir: Vec3x8) -> Vec2x8 {
    let [u, v] = map_lanes([dir.x, dir.y, dir.z]);
    Vec2x8::new(u, v)
}

/// Point on the disk → unit direction in the upper hemisphere, lane-wise
/// `steradian_core::rsl::hemisphere::unmap`: `z = 1 − |p|²`, `(x, y) = p·sqrt(2 − |p|²)`, points
/// outside the disk clamped radially onto the circle.
#[inline]
pub fn unmap(p: Vec2x8) -> Vec3x8 {
    let [x, y, z] = unmap_lanes([p.x, p.y]);
    Vec3x8::new(x, y, z)
}

/// The scalar `map`, operation for operation.
#[inline(always)]
fn map_lanes<W: Lanes>([dx, dy, dz]: [W; 3]) -> [W; 2] {
    let (one, zero) = (W::splat(1.0), W::splat(0.0));
    // Scalar: dir.x.abs().max(dir.y.abs()).max(dir.z.abs()), NaN-ignoring max.
    let m = max_num(max_num(dx.abs(), dy.abs()), dz.abs());
    // Scalar: `(1.0 / m).clamp(f32::MIN_POSITIVE, f32::MAX)` (NaN stays NaN).
    let r = clamp(one / m, W::splat(f32::MIN_POSITIVE), W::splat(f32::MAX));
    let (x, y, z) = (dx * r, dy * r, dz * r);
    let inv_len = one / (x * x + y * y + z * z).sqrt();
    let zn = z.abs() * inv_len;
    let s = inv_len / (one + zn).sqrt();
    // Scalar: the zero vector → `(x + y + z)·0` (the pole, or NaN for a NaN component).
    let is_zero = m.eq(zero);
    let z0 = (dx + dy + dz) * zero;
    [is_zero.select(z0, x * s), is_zero.select(z0, y * s)]
}

/// The scalar `unmap`, operation for operation.
#[inline(always)]
fn unmap_lanes<W: Lanes>([px, py]: [W; 2]) -> [W; 3] {
    let one = W::splat(1.0);
    let r2 = px * px + py * py;
    let outside = r2.gt(one);
    // The scalar kernel only divides for points outside the disk; skipping the division
    // when no lane is outside changes nothing in the result.
    let (px, py, r2) = if outside.any() {
        // Scalar (outside lanes): scale by the larger component first (NaN-ignoring max),
        // `q = p/m`, `k = 1/sqrt(|q|²)`, `(q·k, 1)`.
        let m = max_num(px.abs(), py.abs());
        let (qx, qy) = (px / m, py / m);
        let k = one / (qx * qx + qy * qy).sqrt();
        (
            outside.select(qx * k, px),
            outside.select(qy * k, py),
            outside.select(one, r2),
        )
    } else {
        (px, py, r2)
    };
    let s = (W::splat(2.0) - r2).sqrt();
    [px * s, py * s, one - r2]
}

struct MapK;
impl ColumnKernel<3, 2> for MapK {
    const PADS: [f32; 3] = [PAD_VEC3.x, PAD_VEC3.y, PAD_VEC3.z];
    #[inline(always)]
    fn apply<W: Lanes>(&self, v: [W; 3]) -> ([W; 2], W) {
        (map_lanes(v), W::splat(0.0))
    }
}

struct UnmapK;
impl ColumnKernel<2, 3> for UnmapK {
    const PADS: [f32; 2] = [PAD_VEC2.x, PAD_VEC2.y];
    #[inline(always)]
    fn apply<W: Lanes>(&self, v: [W; 2]) -> ([W; 3], W) {
        (unmap_lanes(v), W::splat(0.0))
    }
}

/// [`map`] over structure-of-arrays columns: `(u[i], v[i]) = map((x[i], y[i], z[i]))` for
/// every `i`. Any length; the tail goes through one padded vector (padding [`PAD_VEC3`]).
/// Runs on the build's widest vector (16 lanes with AVX-512F, else 8), same results.
///
/// # Panics
/// If the five columns do not all have the same length.
pub fn map_slices(x: &[f32], y: &[f32], z: &[f32], u: &mut [f32], v: &mut [f32]) {
    drive::<SliceVec, _, 3, 2>("hemisphere::map_slices", &MapK, [x, y, z], [u, v]);
}

/// [`unmap`] over structure-of-arrays columns: `(x[i], y[i], z[i]) = unmap((u[i], v[i]))`
/// for every `i`. Any length; the tail goes through one padded vector (padding
/// [`PAD_VEC2`]). Runs on the build's widest vector (16 lanes with AVX-512F, else 8), same
/// results.
///
/// # Panics
/// If the five columns do not all have the same length.
pub fn unmap_slices(u: &[f32], v: &[f32], x: &mut [f32], y: &mut [f32], z: &mut [f32]) {
    drive::<SliceVec, _, 2, 3>("hemisphere::unmap_slices", &UnmapK, [u, v], [x, y, z]);
}
