//! Orthonormal shading frames: tangent `t`, bitangent `b`, normal `n` (right-handed,
//! `t × b = n`), and conversion between world and local coordinates.

use crate::math;
use crate::{Error, Vec3};

/// A right-handed orthonormal frame `(t, b, n)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    t: Vec3,
    b: Vec3,
    n: Vec3,
}

pub(crate) fn check_dir(v: Vec3, what: &'static str) -> Result<Vec3, Error> {
    if !v.is_finite() {
        return Err(Error::NonFinite { what });
    }
    let n = normalize_or_zero(v);
    if n == Vec3::ZERO {
        return Err(Error::ZeroVector { what });
    }
    Ok(n)
}

/// Normalises `v` without overflow or underflow (scales by the largest component first);
/// returns zero for the zero vector and NaN components for non-finite input.
#[inline]
pub fn normalize_or_zero(v: Vec3) -> Vec3 {
    let m = v.x.abs().max(v.y.abs()).max(v.z.abs());
    if m == 0.0 {
        return Vec3::ZERO;
    }
    // 1/m overflows for subnormal m; any large common factor keeps the direction.
    let s = v * (1.0 / m).min(f32::MAX);
    s * (1.0 / math::sqrtf(s.dot(s)))
}

impl Frame {
    /// A frame around `normal` with a tangent chosen by the branchless construction of
    /// Duff et al. (2017), continuous except across `n.z = 0` sign changes.
    pub fn from_normal(normal: Vec3) -> Result<Frame, Error> {
        let n = check_dir(normal, "normal")?;
        Ok(Self::from_unit_normal(n))
    }

    /// A frame around `normal` with `tangent` made orthogonal to it (Gram–Schmidt).
    pub fn from_normal_tangent(normal: Vec3, tangent: Vec3) -> Result<Frame, Error> {
        let n = check_dir(normal, "normal")?;
        let t0 = check_dir(tangent, "tangent")?;
        let t = normalize_or_zero(t0 - n * n.dot(t0));
        if t == Vec3::ZERO || !t.is_finite() {
            return Err(Error::ZeroVector {
                what: "tangent orthogonal to the normal",
            });
        }
        Ok(Frame {
            t,
            b: n.cross(t),
            n,
        })
    }

    pub(crate) fn from_unit_normal(n: Vec3) -> Frame {
        let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let t = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let bt = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { t, b: bt, n }
    }

    /// The tangent (local +x).
    pub fn tangent(&self) -> Vec3 {
        self.t
    }
    /// The bitangent (local +y).
    pub fn bitangent(&self) -> Vec3 {
        self.b
    }
    /// The normal (local +z).
    pub fn normal(&self) -> Vec3 {
        self.n
    }
    /// World → local coordinates.
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }
    /// Local → world coordinates.
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.t * v.x + self.b * v.y + self.n * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orthonormal_everywhere() {
        for n in [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(1.0, 2.0, -3.0),
            Vec3::new(1e-30, 0.0, -1e-30),
            Vec3::new(3e38, 3e38, 1.0),
        ] {
            let f = Frame::from_normal(n).unwrap();
            assert!((f.t.length() - 1.0).abs() < 1e-6);
            assert!((f.b.length() - 1.0).abs() < 1e-6);
            assert!(f.t.dot(f.n).abs() < 1e-6 && f.b.dot(f.n).abs() < 1e-6);
            assert!(
                (f.t.cross(f.b) - f.n).length() < 1e-6,
                "right-handed for {n}"
            );
        }
    }

    #[test]
    fn rejects_bad_input() {
        assert!(Frame::from_normal(Vec3::ZERO).is_err());
        assert!(Frame::from_normal(Vec3::new(f32::NAN, 0.0, 1.0)).is_err());
        assert!(Frame::from_normal_tangent(Vec3::Z, Vec3::Z * 2.0).is_err());
        let f = Frame::from_normal_tangent(Vec3::Z, Vec3::new(1.0, 0.0, 0.5)).unwrap();
        assert!((f.tangent() - Vec3::X).length() < 1e-6);
        assert!((f.bitangent() - Vec3::Y).length() < 1e-6);
    }
}
