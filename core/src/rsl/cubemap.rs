//! Cube maps with exact texel solid angles.
//!
//! Face `f` of `6` has outward axis `n_f` and in-face axes `u_f`, `v_f` with
//! `u_f × v_f = n_f` (table [`FACES`], order +X, −X, +Y, −Y, +Z, −Z). A point `(a, b)` of
//! `[-1, 1]²` on face `f` is the direction `n_f + a·u_f + b·v_f`; texel `(i, j)` of an
//! `n × n` face covers `a ∈ [−1 + 2i/n, −1 + 2(i+1)/n]`, `b` likewise with `j`; its flat
//! index is `(f·n + j)·n + i`.
//!
//! The solid angle of a texel is exact: the solid angle subtended by the rectangle
//! `[0, a] × [0, b]` of the plane at unit distance is `F(a, b) = atan2(a·b, sqrt(a² + b² + 1))`,
//! and a texel's is `F(a1, b1) − F(a0, b1) − F(a1, b0) + F(a0, b0)` (f64). The 6·n² texels sum
//! to `4π` to rounding.
//!
//! Values are radiance, RGB `f32`; integrals are accumulated in `f64`.

use alloc::format;
use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;
use core::fmt;

use glam::DVec3;

use crate::math;

/// What was wrong with an environment or with a decomposition request.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvError {
    /// The data was not a valid environment (size, non-finite values, …), or the request
    /// cannot be met.
    Invalid(String),
}

impl fmt::Display for EnvError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EnvError::Invalid(s) => write!(f, "invalid environment: {s}"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for EnvError {}

/// `(n, u, v)` of each face, `u × v = n`: +X, −X, +Y, −Y, +Z, −Z.
pub const FACES: [(DVec3, DVec3, DVec3); 6] = [
    (DVec3::X, DVec3::Y, DVec3::Z),
    (DVec3::NEG_X, DVec3::Z, DVec3::Y),
    (DVec3::Y, DVec3::Z, DVec3::X),
    (DVec3::NEG_Y, DVec3::X, DVec3::Z),
    (DVec3::Z, DVec3::X, DVec3::Y),
    (DVec3::NEG_Z, DVec3::Y, DVec3::X),
];

/// Default face resolution (the paper's 6 × 32 × 32).
pub const DEFAULT_N: usize = 32;

/// Solid angle of `[0, a] × [0, b]` on the plane at unit distance (signed).
#[inline]
fn corner_solid_angle(a: f64, b: f64) -> f64 {
    math::atan2_64(a * b, math::sqrt64(a * a + b * b + 1.0))
}

/// Exact solid angle of the face rectangle `[a0, a1] × [b0, b1]`.
#[inline]
pub fn rect_solid_angle(a0: f64, a1: f64, b0: f64, b1: f64) -> f64 {
    corner_solid_angle(a1, b1) - corner_solid_angle(a0, b1) - corner_solid_angle(a1, b0)
        + corner_solid_angle(a0, b0)
}

/// Unit direction of the face point `(a, b)` of face `f`.
#[inline]
pub fn face_dir(f: usize, a: f64, b: f64) -> DVec3 {
    let (n, u, v) = FACES[f];
    (n + u * a + v * b).normalize()
}

/// Face and face coordinates `(a, b) ∈ [-1, 1]²` of a direction (need not be unit; the
/// zero vector and NaN give face +X at its centre). Ties between axes go to x, then y.
#[inline]
pub fn dir_to_face(d: DVec3) -> (usize, f64, f64) {
    let (ax, ay, az) = (d.x.abs(), d.y.abs(), d.z.abs());
    let f = if ax >= ay && ax >= az {
        if d.x >= 0.0 { 0 } else { 1 }
    } else if ay >= az {
        if d.y >= 0.0 { 2 } else { 3 }
    } else if d.z >= 0.0 {
        4
    } else {
        5
    };
    let m = ax.max(ay).max(az);
    if !m.is_finite() || m <= 0.0 {
        return (0, 0.0, 0.0);
    }
    let (_, u, v) = FACES[f];
    (f, d.dot(u) / m, d.dot(v) / m)
}

/// Visits the `sub × sub` sub-texels of every texel of a `6 × n × n` cube map, in flat
/// texel order and row-major within a texel: `visit(texel, dir, solid_angle)` with the unit
/// direction through the sub-texel's centre and its exact solid angle. The one place that
/// splits texels (box filtering in [`CubeMap::from_fn`], the shading reference's samples).
pub fn for_each_sub_texel(n: usize, sub: usize, mut visit: impl FnMut(usize, DVec3, f64)) {
    let sub = sub.max(1);
    let h = 2.0 / n.max(1) as f64;
    let hs = h / sub as f64;
    for f in 0..6 {
        for j in 0..n {
            for i in 0..n {
                let k = (f * n + j) * n + i;
                for sj in 0..sub {
                    let b0 = -1.0 + h * j as f64 + hs * sj as f64;
                    for si in 0..sub {
                        let a0 = -1.0 + h * i as f64 + hs * si as f64;
                        visit(
                            k,
                            face_dir(f, a0 + 0.5 * hs, b0 + 0.5 * hs),
                            rect_solid_angle(a0, a0 + hs, b0, b0 + hs),
                        );
                    }
                }
            }
        }
    }
}

/// A cube map of RGB radiance.
#[derive(Clone, Debug)]
pub struct CubeMap {
    n: usize,
    texels: Vec<[f32; 3]>,
    solid_angles: Vec<f64>,
    dirs: Vec<DVec3>,
}

impl CubeMap {
    /// A cube map from `6·n²` RGB texels in flat-index order. Rejects `n = 0`, a wrong
    /// length, and non-finite or negative values.
    pub fn new(n: usize, texels: Vec<[f32; 3]>) -> Result<CubeMap, EnvError> {
        if n == 0 || n > 4096 {
            return Err(EnvError::Invalid(format!(
                "cube face size {n} outside 1..=4096"
            )));
        }
        if texels.len() != 6 * n * n {
            return Err(EnvError::Invalid(format!(
                "{} texels given for a 6 × {n} × {n} cube map",
                texels.len()
            )));
        }
        for (k, t) in texels.iter().enumerate() {
            if t.iter().any(|c| !c.is_finite() || *c < 0.0) {
                return Err(EnvError::Invalid(format!(
                    "texel {k} is {t:?}: radiance must be finite and non-negative"
                )));
            }
        }
        let mut solid_angles = Vec::with_capacity(6 * n * n);
        let mut dirs = Vec::with_capacity(6 * n * n);
        let h = 2.0 / n as f64;
        for f in 0..6 {
            for j in 0..n {
                let (b0, b1) = (-1.0 + h * j as f64, -1.0 + h * (j + 1) as f64);
                for i in 0..n {
                    let (a0, a1) = (-1.0 + h * i as f64, -1.0 + h * (i + 1) as f64);
                    solid_angles.push(rect_solid_angle(a0, a1, b0, b1));
                    dirs.push(face_dir(f, 0.5 * (a0 + a1), 0.5 * (b0 + b1)));
                }
            }
        }
        Ok(CubeMap {
            n,
            texels,
            solid_angles,
            dirs,
        })
    }

    /// The box-filtered cube map of a function of direction: each texel is the average of
    /// `f` over its solid angle, by the midpoint rule on `sub × sub` sub-texels weighted by
    /// their exact solid angles (so a constant is reproduced exactly). Negative or
    /// non-finite values of `f` are an error.
    pub fn from_fn(
        n: usize,
        sub: usize,
        f: impl Fn(DVec3) -> [f64; 3],
    ) -> Result<CubeMap, EnvError> {
        let mut acc = vec![([0.0f64; 3], 0.0f64); 6 * n * n];
        for_each_sub_texel(n, sub, |k, d, om| {
            let v = f(d);
            let (sum, w) = &mut acc[k];
            for c in 0..3 {
                sum[c] += v[c] * om;
            }
            *w += om;
        });
        CubeMap::new(
            n,
            acc.iter().map(|(s, w)| s.map(|a| (a / w) as f32)).collect(),
        )
    }

    /// Face size `n`.
    pub fn n(&self) -> usize {
        self.n
    }
    /// Number of texels, `6·n²`.
    pub fn len(&self) -> usize {
        self.texels.len()
    }
    /// Never true (a cube map has at least 6 texels); for clippy.
    pub fn is_empty(&self) -> bool {
        self.texels.is_empty()
    }
    /// RGB radiance of every texel, flat-index order.
    pub fn texels(&self) -> &[[f32; 3]] {
        &self.texels
    }
    /// Exact solid angle of every texel (f64, flat-index order).
    pub fn solid_angles(&self) -> &[f64] {
        &self.solid_angles
    }
    /// Unit direction through the centre of every texel (f64, flat-index order).
    pub fn dirs(&self) -> &[DVec3] {
        &self.dirs
    }
    /// Luminance of texel `k` (Rec. 709 weights), f64.
    pub fn luminance(&self, k: usize) -> f64 {
        let t = self.texels[k];
        crate::rsl::LUMINANCE
            .iter()
            .zip(t)
            .map(|(w, c)| *w as f64 * c as f64)
            .sum()
    }
    /// `(face, i, j)` of flat index `k`.
    pub fn unflatten(&self, k: usize) -> (usize, usize, usize) {
        let n = self.n;
        (k / (n * n), k % n, (k / n) % n)
    }
    /// Flat index of the texel containing direction `d`.
    pub fn dir_to_texel(&self, d: DVec3) -> usize {
        let (f, a, b) = dir_to_face(d);
        let n = self.n;
        let to = |x: f64| (math::floor64((x + 1.0) * 0.5 * n as f64).max(0.0) as usize).min(n - 1);
        (f * n + to(b)) * n + to(a)
    }
    /// The four edge neighbours of texel `k` (−a, +a, −b, +b), across cube edges where
    /// the texel is on one.
    pub fn neighbours(&self, k: usize) -> [usize; 4] {
        let (f, i, j) = self.unflatten(k);
        let n = self.n;
        let h = 2.0 / n as f64;
        let (ac, bc) = (-1.0 + h * (i as f64 + 0.5), -1.0 + h * (j as f64 + 0.5));
        let step = |da: f64, db: f64| -> usize {
            let (a, b) = (ac + da * h, bc + db * h);
            if (-1.0..=1.0).contains(&a) && (-1.0..=1.0).contains(&b) {
                let to = |x: f64| (math::floor64((x + 1.0) / h) as usize).min(n - 1);
                (f * n + to(b)) * n + to(a)
            } else {
                // Beyond the face edge: the point on the face's plane, seen from the centre,
                // lies on the neighbouring face.
                let (nf, u, v) = FACES[f];
                self.dir_to_texel(nf + u * a + v * b)
            }
        };
        [
            step(-1.0, 0.0),
            step(1.0, 0.0),
            step(0.0, -1.0),
            step(0.0, 1.0),
        ]
    }
    /// `∫ L dω` over the sphere, RGB, f64.
    pub fn integral(&self) -> [f64; 3] {
        let mut acc = [0.0f64; 3];
        for (t, w) in self.texels.iter().zip(&self.solid_angles) {
            for c in 0..3 {
                acc[c] += t[c] as f64 * w;
            }
        }
        acc
    }
    /// Radiance at direction `d` (nearest texel).
    pub fn sample(&self, d: DVec3) -> [f32; 3] {
        self.texels[self.dir_to_texel(d)]
    }
}
