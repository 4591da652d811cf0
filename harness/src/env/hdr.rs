//! Equirectangular (latitude–longitude) environment images: Radiance `.hdr` and OpenEXR
//! through the `image` crate, and their resampling to a [`CubeMap`].
//!
//! Convention (world `+z` up, as the local frames of `steradian-core`): pixel `(x, y)` of a
//! `W × H` image has its centre at polar angle `θ = π·(y + ½)/H` from `+z` (row 0 is the
//! zenith) and azimuth `φ = 2π·(x + ½)/W`, direction `(sinθ·cosφ, sinθ·sinφ, cosθ)`; its
//! solid angle is `(2π/W)·(cos θ0 − cos θ1)` exactly.

use std::f64::consts::PI;
use std::path::Path;

use glam::DVec3;

use super::EnvError;
use super::cubemap::CubeMap;

/// An equirectangular RGB radiance image.
#[derive(Clone, Debug)]
pub struct Equirect {
    width: usize,
    height: usize,
    data: Vec<[f32; 3]>,
}

impl Equirect {
    /// An image from row-major RGB pixels. Rejects a wrong length, a size of zero, and
    /// non-finite values; negative values (some EXR files have tiny ones) become 0.
    pub fn new(width: usize, height: usize, mut data: Vec<[f32; 3]>) -> Result<Equirect, EnvError> {
        if width == 0 || height == 0 || data.len() != width * height {
            return Err(EnvError::invalid(format!(
                "{} pixels for a {width} × {height} image",
                data.len()
            )));
        }
        for (k, p) in data.iter_mut().enumerate() {
            if p.iter().any(|c| !c.is_finite()) {
                return Err(EnvError::invalid(format!(
                    "pixel ({}, {}) is {p:?}: radiance must be finite",
                    k % width,
                    k / width
                )));
            }
            for c in p.iter_mut() {
                *c = c.max(0.0);
            }
        }
        Ok(Equirect {
            width,
            height,
            data,
        })
    }

    /// Reads a Radiance `.hdr` or OpenEXR file (any format `image` decodes) as linear RGB.
    /// The image must be equirectangular, `width = 2·height`.
    pub fn load(path: &Path) -> Result<Equirect, EnvError> {
        let img = image::open(path)
            .map_err(|e| EnvError::Io(format!("{}: {e}", path.display())))?
            .into_rgb32f();
        let (w, h) = (img.width() as usize, img.height() as usize);
        if w != 2 * h {
            return Err(EnvError::invalid(format!(
                "{}: {w} × {h} is not an equirectangular (2:1) image",
                path.display()
            )));
        }
        let data = img.pixels().map(|p| p.0).collect();
        Equirect::new(w, h, data)
    }

    /// Width (azimuth samples).
    pub fn width(&self) -> usize {
        self.width
    }
    /// Height (polar samples).
    pub fn height(&self) -> usize {
        self.height
    }
    /// Row-major RGB pixels.
    pub fn data(&self) -> &[[f32; 3]] {
        &self.data
    }

    /// Exact solid angle of a pixel of row `y`.
    pub fn pixel_solid_angle(&self, y: usize) -> f64 {
        let h = self.height as f64;
        let (t0, t1) = (PI * y as f64 / h, PI * (y + 1) as f64 / h);
        2.0 * PI / self.width as f64 * (t0.cos() - t1.cos())
    }

    /// `∫ L dω` of the piecewise-constant image, RGB, f64.
    pub fn integral(&self) -> [f64; 3] {
        let mut acc = [0.0f64; 3];
        for y in 0..self.height {
            let w = self.pixel_solid_angle(y);
            for p in &self.data[y * self.width..(y + 1) * self.width] {
                for c in 0..3 {
                    acc[c] += p[c] as f64 * w;
                }
            }
        }
        acc
    }

    /// Bilinear interpolation between pixel centres at direction `d` (wraps in azimuth,
    /// clamps at the poles).
    pub fn sample_bilinear(&self, d: DVec3) -> [f64; 3] {
        let d = d.normalize_or(DVec3::Z);
        let theta = d.z.clamp(-1.0, 1.0).acos();
        let mut phi = d.y.atan2(d.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let (w, h) = (self.width, self.height);
        let x = phi / (2.0 * PI) * w as f64 - 0.5;
        let y = (theta / PI * h as f64 - 0.5).clamp(0.0, (h - 1) as f64);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let xi0 = (x0 as i64).rem_euclid(w as i64) as usize;
        let xi1 = (xi0 + 1) % w;
        let yi0 = y0 as usize;
        let yi1 = (yi0 + 1).min(h - 1);
        let p = |xi: usize, yi: usize| self.data[yi * w + xi];
        let mut out = [0.0; 3];
        for (c, o) in out.iter_mut().enumerate() {
            let top = p(xi0, yi0)[c] as f64 * (1.0 - fx) + p(xi1, yi0)[c] as f64 * fx;
            let bot = p(xi0, yi1)[c] as f64 * (1.0 - fx) + p(xi1, yi1)[c] as f64 * fx;
            *o = top * (1.0 - fy) + bot * fy;
        }
        out
    }

    /// Resamples to a cube map of face size `n`: each cube texel is the average over its
    /// solid angle of the bilinear reconstruction of the image, by the midpoint rule on
    /// sub-texels no wider than half a source pixel (weights: exact sub-texel solid angles).
    /// Constants are reproduced exactly; the total integral matches
    /// [`Equirect::integral`] to the accuracy of the bilinear reconstruction (the test
    /// `loads_the_real_exr_and_a_hdr_written_from_it` states the measured bound).
    pub fn to_cubemap(&self, n: usize) -> Result<CubeMap, EnvError> {
        let n = n.max(1);
        // Cube texels are at most (π/2)/n wide (face centre); source pixels π/H tall.
        let src = PI / self.height as f64;
        let cube = 0.5 * PI / n as f64;
        let sub = ((2.0 * cube / src).ceil() as usize).clamp(1, 32);
        CubeMap::from_fn(n, sub, |d| self.sample_bilinear(d)).map_err(EnvError::from)
    }
}
