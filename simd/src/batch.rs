//! Structure-of-arrays batches of [`LANES`] = 8 lanes.
//!
//! A batch holds one [`f32x8`] per component: [`Vec3x8`] is eight directions, [`Vec2x8`]
//! eight disk points, [`LobeX8`] eight cosine lobes. Batches are built
//!
//! - from slices of the scalar types (`&[Vec3]`, `&[Vec2]`, `&[CosineLobe]`): the first
//!   eight elements, and a slice shorter than eight is **padded** with a documented value
//!   ([`PAD_VEC3`], [`PAD_VEC2`], [`LobeX8::PAD_AXIS`]/`PAD_SCALE`/`PAD_EXPONENT`) chosen so
//!   every kernel gives a finite, quiet result on the padding lanes;
//! - from structure-of-arrays columns at an offset: [`Vec3x8::load`] reads lanes
//!   `offset .. offset + 8` of each column (and panics if a column is shorter), the
//!   `load_padded` variants read what is there and pad the rest with the same values.
//!
//! Stores mirror the loads: `store` writes eight lanes, `store_partial` writes only the
//! lanes that fit in the columns (the tail of a slice), `write_to_slice` writes the first
//! `min(8, len)` elements of a scalar slice.

use glam::{Vec2, Vec3};
use steradian_core::lobe::CosineLobe;
use wide::f32x8;

/// Lanes per batch.
pub const LANES: usize = 8;

/// Padding of a [`Vec3x8`] built from a short slice or column tail: the pole `(0, 0, 1)`.
pub const PAD_VEC3: Vec3 = Vec3::Z;
/// Padding of a [`Vec2x8`] built from a short slice or column tail: the disk centre `0`.
pub const PAD_VEC2: Vec2 = Vec2::ZERO;
/// Padding of a single `f32` column tail (lobe scale and exponent, cap half-angle): `0`.
pub const PAD_F32: f32 = 0.0;

/// Eight lanes of column `s` starting at `offset`. Panics if `s.len() < offset + 8`.
#[inline(always)]
pub(crate) fn load8(s: &[f32], offset: usize) -> f32x8 {
    let a: [f32; LANES] = s[offset..offset + LANES].try_into().unwrap();
    f32x8::new(a)
}

/// The lanes of column `s` from `offset` that exist, the rest `pad`.
#[inline]
pub(crate) fn load8_padded(s: &[f32], offset: usize, pad: f32) -> f32x8 {
    let mut a = [pad; LANES];
    let end = s.len().min(offset.saturating_add(LANES));
    if offset < end {
        a[..end - offset].copy_from_slice(&s[offset..end]);
    }
    f32x8::new(a)
}

/// Writes eight lanes to `s[offset..offset + 8]`. Panics if `s` is too short.
#[inline(always)]
pub(crate) fn store8(v: f32x8, s: &mut [f32], offset: usize) {
    s[offset..offset + LANES].copy_from_slice(v.as_array());
}

/// Writes the lanes that fit in `s` from `offset` on.
#[inline]
pub(crate) fn store8_partial(v: f32x8, s: &mut [f32], offset: usize) {
    let end = s.len().min(offset.saturating_add(LANES));
    if offset < end {
        s[offset..end].copy_from_slice(&v.as_array()[..end - offset]);
    }
}

/// Eight 3-vectors, one [`f32x8`] per component.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vec3x8 {
    /// x components.
    pub x: f32x8,
    /// y components.
    pub y: f32x8,
    /// z components.
    pub z: f32x8,
}

impl Vec3x8 {
    /// A batch from its component vectors.
    #[inline]
    pub fn new(x: f32x8, y: f32x8, z: f32x8) -> Self {
        Vec3x8 { x, y, z }
    }

    /// The same vector in every lane.
    #[inline]
    pub fn splat(v: Vec3) -> Self {
        Vec3x8::new(f32x8::splat(v.x), f32x8::splat(v.y), f32x8::splat(v.z))
    }

    /// A batch from eight vectors.
    #[inline]
    pub fn from_array(a: [Vec3; LANES]) -> Self {
        Vec3x8::new(
            f32x8::new(a.map(|v| v.x)),
            f32x8::new(a.map(|v| v.y)),
            f32x8::new(a.map(|v| v.z)),
        )
    }

    /// The first eight vectors of `s`; a shorter slice is padded with [`PAD_VEC3`].
    #[inline]
    pub fn from_slice(s: &[Vec3]) -> Self {
        let mut a = [PAD_VEC3; LANES];
        let k = s.len().min(LANES);
        a[..k].copy_from_slice(&s[..k]);
        Vec3x8::from_array(a)
    }

    /// The eight vectors.
    #[inline]
    pub fn to_array(self) -> [Vec3; LANES] {
        let (x, y, z) = (self.x.to_array(), self.y.to_array(), self.z.to_array());
        core::array::from_fn(|k| Vec3::new(x[k], y[k], z[k]))
    }

    /// Writes the first `min(8, out.len())` lanes to `out`.
    #[inline]
    pub fn write_to_slice(self, out: &mut [Vec3]) {
        let a = self.to_array();
        let k = out.len().min(LANES);
        out[..k].copy_from_slice(&a[..k]);
    }

    /// Lane `k` (`k < 8`; panics otherwise).
    #[inline]
    pub fn lane(self, k: usize) -> Vec3 {
        Vec3::new(
            self.x.as_array()[k],
            self.y.as_array()[k],
            self.z.as_array()[k],
        )
    }

    /// Lanes `offset .. offset + 8` of the columns `x`, `y`, `z`.
    ///
    /// # Panics
    /// If a column is shorter than `offset + 8`.
    #[inline(always)]
    pub fn load(x: &[f32], y: &[f32], z: &[f32], offset: usize) -> Self {
        Vec3x8::new(load8(x, offset), load8(y, offset), load8(z, offset))
    }

    /// Like [`Vec3x8::load`], but lanes past the end of a column are padded with
    /// [`PAD_VEC3`]'s component. Never panics.
    #[inline]
    pub fn load_padded(x: &[f32], y: &[f32], z: &[f32], offset: usize) -> Self {
        Vec3x8::new(
            load8_padded(x, offset, PAD_VEC3.x),
            load8_padded(y, offset, PAD_VEC3.y),
            load8_padded(z, offset, PAD_VEC3.z),
        )
    }

    /// Writes the eight lanes to `offset .. offset + 8` of the columns.
    ///
    /// # Panics
    /// If a column is shorter than `offset + 8`.
    #[inline(always)]
    pub fn store(self, x: &mut [f32], y: &mut [f32], z: &mut [f32], offset: usize) {
        store8(self.x, x, offset);
        store8(self.y, y, offset);
        store8(self.z, z, offset);
    }

    /// Writes the lanes that fit in each column from `offset` on (the tail of a slice).
    /// Never panics.
    #[inline]
    pub fn store_partial(self, x: &mut [f32], y: &mut [f32], z: &mut [f32], offset: usize) {
        store8_partial(self.x, x, offset);
        store8_partial(self.y, y, offset);
        store8_partial(self.z, z, offset);
    }
}

impl From<[Vec3; LANES]> for Vec3x8 {
    #[inline]
    fn from(a: [Vec3; LANES]) -> Self {
        Vec3x8::from_array(a)
    }
}

impl From<Vec3x8> for [Vec3; LANES] {
    #[inline]
    fn from(v: Vec3x8) -> Self {
        v.to_array()
    }
}

/// Eight 2-vectors (disk points), one [`f32x8`] per component.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vec2x8 {
    /// x (u) components.
    pub x: f32x8,
    /// y (v) components.
    pub y: f32x8,
}

impl Vec2x8 {
    /// A batch from its component vectors.
    #[inline]
    pub fn new(x: f32x8, y: f32x8) -> Self {
        Vec2x8 { x, y }
    }

    /// The same vector in every lane.
    #[inline]
    pub fn splat(v: Vec2) -> Self {
        Vec2x8::new(f32x8::splat(v.x), f32x8::splat(v.y))
    }

    /// A batch from eight vectors.
    #[inline]
    pub fn from_array(a: [Vec2; LANES]) -> Self {
        Vec2x8::new(f32x8::new(a.map(|v| v.x)), f32x8::new(a.map(|v| v.y)))
    }

    /// The first eight vectors of `s`; a shorter slice is padded with [`PAD_VEC2`].
    #[inline]
    pub fn from_slice(s: &[Vec2]) -> Self {
        let mut a = [PAD_VEC2; LANES];
        let k = s.len().min(LANES);
        a[..k].copy_from_slice(&s[..k]);
        Vec2x8::from_array(a)
    }

    /// The eight vectors.
    #[inline]
    pub fn to_array(self) -> [Vec2; LANES] {
        let (x, y) = (self.x.to_array(), self.y.to_array());
        core::array::from_fn(|k| Vec2::new(x[k], y[k]))
    }

    /// Writes the first `min(8, out.len())` lanes to `out`.
    #[inline]
    pub fn write_to_slice(self, out: &mut [Vec2]) {
        let a = self.to_array();
        let k = out.len().min(LANES);
        out[..k].copy_from_slice(&a[..k]);
    }

    /// Lane `k` (`k < 8`; panics otherwise).
    #[inline]
    pub fn lane(self, k: usize) -> Vec2 {
        Vec2::new(self.x.as_array()[k], self.y.as_array()[k])
    }

    /// Lanes `offset .. offset + 8` of the columns `x`, `y`.
    ///
    /// # Panics
    /// If a column is shorter than `offset + 8`.
    #[inline(always)]
    pub fn load(x: &[f32], y: &[f32], offset: usize) -> Self {
        Vec2x8::new(load8(x, offset), load8(y, offset))
    }

    /// Like [`Vec2x8::load`], but lanes past the end of a column are padded with
    /// [`PAD_VEC2`]'s component. Never panics.
    #[inline]
    pub fn load_padded(x: &[f32], y: &[f32], offset: usize) -> Self {
        Vec2x8::new(
            load8_padded(x, offset, PAD_VEC2.x),
            load8_padded(y, offset, PAD_VEC2.y),
        )
    }

    /// Writes the eight lanes to `offset .. offset + 8` of the columns.
    ///
    /// # Panics
    /// If a column is shorter than `offset + 8`.
    #[inline(always)]
    pub fn store(self, x: &mut [f32], y: &mut [f32], offset: usize) {
        store8(self.x, x, offset);
        store8(self.y, y, offset);
    }

    /// Writes the lanes that fit in each column from `offset` on. Never panics.
    #[inline]
    pub fn store_partial(self, x: &mut [f32], y: &mut [f32], offset: usize) {
        store8_partial(self.x, x, offset);
        store8_partial(self.y, y, offset);
    }
}

impl From<[Vec2; LANES]> for Vec2x8 {
    #[inline]
    fn from(a: [Vec2; LANES]) -> Self {
        Vec2x8::from_array(a)
    }
}

impl From<Vec2x8> for [Vec2; LANES] {
    #[inline]
    fn from(v: Vec2x8) -> Self {
        v.to_array()
    }
}

/// Eight cosine lobes `s·max(a·v, 0)^e` (see `steradian_core::lobe`).
///
/// Built from [`CosineLobe`]s the fields are validated (unit axis, finite scale, exponent
/// `≥ 0`); built from raw columns they are taken as given and the kernels saturate the way
/// the scalar `lobe::eval` does (negative exponent → 0, NaN → NaN).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LobeX8 {
    /// Unit axes `a`.
    pub axis: Vec3x8,
    /// Scales `s`.
    pub scale: f32x8,
    /// Exponents `e`.
    pub exponent: f32x8,
}

impl LobeX8 {
    /// Axis of a padding lane: `+z`.
    pub const PAD_AXIS: Vec3 = Vec3::Z;
    /// Scale of a padding lane: `0` (so a padding lane evaluates and integrates to `0`).
    pub const PAD_SCALE: f32 = 0.0;
    /// Exponent of a padding lane: `0`.
    pub const PAD_EXPONENT: f32 = 0.0;

    /// A batch from its fields.
    #[inline]
    pub fn new(axis: Vec3x8, scale: f32x8, exponent: f32x8) -> Self {
        LobeX8 {
            axis,
            scale,
            exponent,
        }
    }

    /// The same lobe in every lane.
    #[inline]
    pub fn splat(l: CosineLobe) -> Self {
        LobeX8::new(
            Vec3x8::splat(l.axis()),
            f32x8::splat(l.scale()),
            f32x8::splat(l.exponent()),
        )
    }

    /// A batch from eight lobes.
    #[inline]
    pub fn from_array(a: [CosineLobe; LANES]) -> Self {
        LobeX8::new(
            Vec3x8::from_array(a.map(|l| l.axis())),
            f32x8::new(a.map(|l| l.scale())),
            f32x8::new(a.map(|l| l.exponent())),
        )
    }

    /// The first eight lobes of `s`; a shorter slice is padded with lobes of axis
    /// [`PAD_AXIS`](Self::PAD_AXIS), scale [`PAD_SCALE`](Self::PAD_SCALE) and exponent
    /// [`PAD_EXPONENT`](Self::PAD_EXPONENT).
    #[inline]
    pub fn from_slice(s: &[CosineLobe]) -> Self {
        let mut axis = [Self::PAD_AXIS; LANES];
        let mut scale = [Self::PAD_SCALE; LANES];
        let mut exponent = [Self::PAD_EXPONENT; LANES];
        for (k, l) in s.iter().take(LANES).enumerate() {
            axis[k] = l.axis();
            scale[k] = l.scale();
            exponent[k] = l.exponent();
        }
        LobeX8::new(
            Vec3x8::from_array(axis),
            f32x8::new(scale),
            f32x8::new(exponent),
        )
    }

    /// The eight lobes, rebuilt with [`CosineLobe::saturating`] (which normalises the axis,
    /// clamps a negative exponent to 0 and keeps NaN). The scale and a non-negative exponent
    /// come back as they went in; an axis, even one `saturating` already normalised, may
    /// move by an ulp (normalising a unit `f32` vector again is not always exact), so a
    /// lane-by-lane comparison feeds the scalar kernel these lobes, not the ones the batch
    /// was built from.
    #[inline]
    pub fn to_array(self) -> [CosineLobe; LANES] {
        let a = self.axis.to_array();
        let (s, e) = (self.scale.to_array(), self.exponent.to_array());
        core::array::from_fn(|k| CosineLobe::saturating(a[k], s[k], e[k]))
    }

    /// Writes the first `min(8, out.len())` lanes to `out` (see [`LobeX8::to_array`]).
    #[inline]
    pub fn write_to_slice(self, out: &mut [CosineLobe]) {
        let a = self.to_array();
        let k = out.len().min(LANES);
        out[..k].copy_from_slice(&a[..k]);
    }

    /// Lanes `offset .. offset + 8` of the columns `[ax, ay, az, s, e]` (the lobe part of
    /// the `lobe-eval` batch layout).
    ///
    /// # Panics
    /// If a column is shorter than `offset + 8`.
    #[inline(always)]
    pub fn load(axis: [&[f32]; 3], scale: &[f32], exponent: &[f32], offset: usize) -> Self {
        LobeX8::new(
            Vec3x8::load(axis[0], axis[1], axis[2], offset),
            load8(scale, offset),
            load8(exponent, offset),
        )
    }

    /// Like [`LobeX8::load`], but lanes past the end of a column are padded with the
    /// padding lobe's fields. Never panics.
    #[inline]
    pub fn load_padded(axis: [&[f32]; 3], scale: &[f32], exponent: &[f32], offset: usize) -> Self {
        LobeX8::new(
            Vec3x8::new(
                load8_padded(axis[0], offset, Self::PAD_AXIS.x),
                load8_padded(axis[1], offset, Self::PAD_AXIS.y),
                load8_padded(axis[2], offset, Self::PAD_AXIS.z),
            ),
            load8_padded(scale, offset, Self::PAD_SCALE),
            load8_padded(exponent, offset, Self::PAD_EXPONENT),
        )
    }
}

impl From<[CosineLobe; LANES]> for LobeX8 {
    #[inline]
    fn from(a: [CosineLobe; LANES]) -> Self {
        LobeX8::from_array(a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices_round_trip_and_pad() {
        let v: Vec<Vec3> = (0..11)
            .map(|i| Vec3::new(i as f32, -(i as f32), 0.5))
            .collect();
        let b = Vec3x8::from_slice(&v[..3]);
        let a = b.to_array();
        assert_eq!(&a[..3], &v[..3]);
        assert!(a[3..].iter().all(|&p| p == PAD_VEC3));
        let mut out = [Vec3::NAN; 5];
        Vec3x8::from_slice(&v).write_to_slice(&mut out);
        assert_eq!(&out[..], &v[..5]);
        assert_eq!(Vec3x8::from_slice(&v).lane(7), v[7]);

        let p: Vec<Vec2> = (0..9).map(|i| Vec2::new(i as f32, 1.0)).collect();
        let b = Vec2x8::from_slice(&p[..1]).to_array();
        assert_eq!(b[0], p[0]);
        assert!(b[1..].iter().all(|&q| q == PAD_VEC2));
        assert_eq!(<[Vec2; 8]>::from(Vec2x8::from_slice(&p)), p[..8]);

        let l = CosineLobe::new(Vec3::X, 2.0, 3.0).unwrap();
        let b = LobeX8::from_slice(&[l, l]).to_array();
        assert_eq!(&b[..2], &[l, l]);
        let pad = CosineLobe::saturating(LobeX8::PAD_AXIS, LobeX8::PAD_SCALE, LobeX8::PAD_EXPONENT);
        assert!(b[2..].iter().all(|&q| q == pad));
        assert_eq!(LobeX8::from([l; 8]), LobeX8::splat(l));
    }

    #[test]
    fn column_loads_and_stores() {
        let x: Vec<f32> = (0..11).map(|i| i as f32).collect();
        let y: Vec<f32> = x.iter().map(|v| v + 100.0).collect();
        let z: Vec<f32> = x.iter().map(|v| v + 200.0).collect();
        let b = Vec3x8::load(&x, &y, &z, 2);
        assert_eq!(b.lane(0), Vec3::new(2.0, 102.0, 202.0));
        let t = Vec3x8::load_padded(&x, &y, &z, 8);
        assert_eq!(t.lane(2), Vec3::new(10.0, 110.0, 210.0));
        assert_eq!(t.lane(3), PAD_VEC3);
        assert!(
            Vec3x8::load_padded(&x, &y, &z, 100)
                .to_array()
                .iter()
                .all(|&p| p == PAD_VEC3)
        );
        let (mut a, mut c, mut d) = (vec![0.0; 11], vec![0.0; 11], vec![0.0; 11]);
        b.store(&mut a, &mut c, &mut d, 3);
        assert_eq!(a[3..11], x[2..10]);
        t.store_partial(&mut a, &mut c, &mut d, 9);
        assert_eq!((a[9], a[10]), (8.0, 9.0));
        assert_eq!((c[10], d[10]), (109.0, 209.0));
        let mut e: Vec<f32> = vec![];
        Vec2x8::splat(Vec2::ONE).store_partial(&mut e, &mut [], 0);
        assert_eq!(Vec2x8::load_padded(&x, &y, 10).lane(1), PAD_VEC2);
    }
}
