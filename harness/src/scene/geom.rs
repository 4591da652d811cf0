//! Rays, shapes and the pinhole camera (f64).

use glam::DVec3;

/// A ray `o + t·d` with unit `d`.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Origin.
    pub o: DVec3,
    /// Unit direction.
    pub d: DVec3,
}

/// The closest hit: distance and object index.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray.
    pub t: f64,
    /// Index into [`super::Scene::objects`].
    pub object: usize,
}

/// A sphere or an infinite plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// Centre and radius.
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius `> 0`.
        radius: f64,
    },
    /// A point and the unit normal.
    Plane {
        /// A point of the plane.
        point: DVec3,
        /// Unit normal.
        normal: DVec3,
    },
}

impl Shape {
    /// The smallest `t` in `(t_min, t_max)` where the ray meets the shape.
    ///
    /// Sphere: `|o + t·d − c|² = r²` with `b = (o − c)·d`; the discriminant is formed as
    /// `r² − |h|²`, `h = (o − c) − b·d` the offset of the closest approach, which keeps its
    /// precision for small or distant spheres, and the near root as `c/q` (no cancellation).
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<f64> {
        match *self {
            Shape::Sphere { center, radius } => {
                let oc = ray.o - center;
                let b = oc.dot(ray.d);
                let h = oc - b * ray.d;
                let disc = radius * radius - h.length_squared();
                if disc < 0.0 {
                    return None;
                }
                let c = oc.length_squared() - radius * radius;
                let q = -b - b.signum() * disc.sqrt();
                let (t0, t1) = if q == 0.0 {
                    (0.0, 0.0)
                } else {
                    let (a, z) = (c / q, q);
                    (a.min(z), a.max(z))
                };
                [t0, t1].into_iter().find(|&t| t > t_min && t < t_max)
            }
            Shape::Plane { point, normal } => {
                let den = normal.dot(ray.d);
                if den == 0.0 {
                    return None;
                }
                let t = normal.dot(point - ray.o) / den;
                (t > t_min && t < t_max).then_some(t)
            }
        }
    }

    /// The outward (sphere) or stored (plane) unit normal at a point `x` of the shape.
    pub fn normal(&self, x: DVec3) -> DVec3 {
        match *self {
            Shape::Sphere { center, .. } => (x - center).normalize(),
            Shape::Plane { normal, .. } => normal,
        }
    }
}

/// The pinhole camera of the scene-file contract (see the module docs of [`super`]).
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    /// Eye position.
    pub eye: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    tan_half: f64,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

impl Camera {
    /// A camera; the error says what is degenerate.
    pub fn new(
        eye: DVec3,
        target: DVec3,
        up: DVec3,
        fov_y_deg: f64,
        width: u32,
        height: u32,
    ) -> Result<Camera, String> {
        let f = target - eye;
        if f.length() <= 1e-12 * eye.length().max(1.0) {
            return Err("target: must differ from eye".into());
        }
        let f = f.normalize();
        let r = f.cross(up.normalize());
        if r.length() < 1e-6 {
            return Err("up: must not be parallel to target − eye".into());
        }
        let r = r.normalize();
        Ok(Camera {
            eye,
            forward: f,
            right: r,
            up: r.cross(f),
            tan_half: (fov_y_deg.to_radians() / 2.0).tan(),
            width,
            height,
        })
    }

    /// The same camera at `width` columns, the height following the aspect ratio.
    pub fn resized(&self, width: u32) -> Result<Camera, String> {
        if !(1..=16384).contains(&width) {
            return Err(format!("must be in 1..=16384 (got {width})"));
        }
        let h = ((self.height as f64 * width as f64 / self.width as f64).round() as u32).max(1);
        Ok(Camera {
            width,
            height: h,
            ..*self
        })
    }

    /// The ray through pixel `(i, j)` at offset `(x, y) ∈ [0, 1)²` inside it.
    pub fn ray(&self, i: u32, j: u32, x: f64, y: f64) -> Ray {
        let (w, h) = (self.width as f64, self.height as f64);
        let px = (2.0 * (i as f64 + x) / w - 1.0) * self.tan_half * w / h;
        let py = (1.0 - 2.0 * (j as f64 + y) / h) * self.tan_half;
        Ray {
            o: self.eye,
            d: (self.forward + px * self.right + py * self.up).normalize(),
        }
    }

    /// The ray through the pixel centre.
    pub fn centre_ray(&self, i: u32, j: u32) -> Ray {
        self.ray(i, j, 0.5, 0.5)
    }

    /// Pixel count.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }
}
