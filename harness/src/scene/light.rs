//! Spherical lights (sampled by the cone they subtend) and environments (sampled by a
//! piecewise-constant distribution over the image's texels).

use std::f64::consts::{PI, TAU};
use std::path::Path;

use glam::DVec3;

use super::Rgb;
use super::material::basis;
use crate::env::{Equirect, Sky};

/// A sphere emitting `radiance` uniformly from its surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereLight {
    /// Centre.
    pub center: DVec3,
    /// Radius.
    pub radius: f64,
    /// RGB radiance.
    pub radiance: Rgb,
}

/// The cone a sphere subtends from a point outside it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Unit axis toward the centre.
    pub axis: DVec3,
    /// Distance to the centre.
    pub dist: f64,
    /// `cos α`.
    pub cos_a: f64,
    /// `1 − cos α`, formed without cancellation: `sin²α/(1 + cos α)`, `sin α = r/d`.
    pub one_minus_cos: f64,
}

impl Cone {
    /// The cone of the sphere `(center, radius)` from `x`; `None` when `x` is inside.
    pub fn of_sphere(x: DVec3, center: DVec3, radius: f64) -> Option<Cone> {
        let v = center - x;
        let dist = v.length();
        if dist <= radius {
            return None;
        }
        let sin2 = (radius / dist).powi(2);
        let cos_a = (1.0 - sin2).sqrt();
        Some(Cone {
            axis: v / dist,
            dist,
            cos_a,
            one_minus_cos: sin2 / (1.0 + cos_a),
        })
    }

    /// Solid angle `2π(1 − cos α)`.
    pub fn solid_angle(&self) -> f64 {
        TAU * self.one_minus_cos
    }

    /// A direction uniform in the cone: `cos θ = 1 − u₁(1 − cos α)`.
    pub fn sample(&self, u1: f64, u2: f64) -> DVec3 {
        let omc = u1 * self.one_minus_cos;
        let cos_t = 1.0 - omc;
        let sin_t = (omc * (2.0 - omc)).max(0.0).sqrt();
        let (t, b) = basis(self.axis);
        let phi = TAU * u2;
        (sin_t * phi.cos() * t + sin_t * phi.sin() * b + cos_t * self.axis).normalize()
    }

    /// Whether unit `d` lies in the cone.
    pub fn contains(&self, d: DVec3) -> bool {
        d.dot(self.axis) >= self.cos_a
    }
}

/// An environment: an equirectangular image times a scale, with a sampling distribution.
#[derive(Clone, Debug)]
pub struct Environment {
    /// The image.
    pub image: Equirect,
    /// Factor on every texel.
    pub scale: f64,
    /// Where the image came from (`builtin:sky` or the path given).
    pub source: String,
    /// Cumulative row weights (length `h + 1`, last = 1).
    row_cdf: Vec<f64>,
    /// Per row, cumulative column weights (length `w + 1` each, last = 1).
    col_cdf: Vec<Vec<f64>>,
    /// Probability of each texel (row-major).
    texel_p: Vec<f64>,
}

/// Columns and rows of the built-in sky's image: 0.35° texels, so the sun (angular radius
/// about `1/√λ` = 1.05°) spans three of them.
pub const SKY_SIZE: (usize, usize) = (1024, 512);

fn lum(c: [f32; 3]) -> f64 {
    0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64
}

impl Environment {
    /// `builtin:sky` (the procedural [`Sky`] sampled at texel centres, [`SKY_SIZE`]) or an
    /// `.exr`/`.hdr` file, relative to `dir` unless absolute.
    pub fn load(spec: &str, dir: &Path, scale: f64) -> Result<Environment, String> {
        let image = if spec == "builtin:sky" {
            let sky = Sky::default();
            let (w, h) = SKY_SIZE;
            let mut data = Vec::with_capacity(w * h);
            for y in 0..h {
                let th = (y as f64 + 0.5) / h as f64 * PI;
                for x in 0..w {
                    let ph = (x as f64 + 0.5) / w as f64 * TAU;
                    let d = DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                    data.push(sky.radiance(d).map(|v| v as f32));
                }
            }
            Equirect::new(w, h, data).map_err(|e| e.to_string())?
        } else if spec.starts_with("builtin:") {
            return Err(format!(
                "unknown built-in environment {spec:?} (known: builtin:sky)"
            ));
        } else {
            let p = dir.join(spec);
            Equirect::load(&p).map_err(|e| format!("{}: {e}", p.display()))?
        };
        Ok(Environment::new(image, scale, spec.to_string()))
    }

    /// An environment from an image; builds the sampling distribution.
    ///
    /// A texel's weight is the largest luminance among it and its eight neighbours (the
    /// bilinear reconstruction inside a texel reaches toward its neighbours' values) times
    /// its solid angle, plus a floor of 1e-3 of the mean, so that every direction where
    /// the environment is non-zero has a non-zero density.
    pub fn new(image: Equirect, scale: f64, source: String) -> Environment {
        let (w, h) = (image.width(), image.height());
        let data = image.data();
        let mut weight = vec![0.0; w * h];
        for y in 0..h {
            for x in 0..w {
                let mut m: f64 = 0.0;
                for dy in [-1i64, 0, 1] {
                    let yy = (y as i64 + dy).clamp(0, h as i64 - 1) as usize;
                    for dx in [-1i64, 0, 1] {
                        let xx = (x as i64 + dx).rem_euclid(w as i64) as usize;
                        m = m.max(lum(data[yy * w + xx]));
                    }
                }
                weight[y * w + x] = m * image.pixel_solid_angle(y);
            }
        }
        let mean = weight.iter().sum::<f64>() / (w * h) as f64;
        let floor = if mean > 0.0 { 1e-3 * mean } else { 1.0 };
        for (y, row) in weight.chunks_mut(w).enumerate() {
            for v in row.iter_mut() {
                *v += floor * image.pixel_solid_angle(y) / (4.0 * PI / (w * h) as f64);
            }
        }
        let total: f64 = weight.iter().sum();
        let texel_p: Vec<f64> = weight.iter().map(|v| v / total).collect();
        let mut row_cdf = vec![0.0; h + 1];
        let mut col_cdf = Vec::with_capacity(h);
        for y in 0..h {
            let row = &texel_p[y * w..(y + 1) * w];
            let rs: f64 = row.iter().sum();
            row_cdf[y + 1] = row_cdf[y] + rs;
            let mut c = vec![0.0; w + 1];
            for x in 0..w {
                c[x + 1] = c[x] + row[x];
            }
            let last = c[w];
            for v in c.iter_mut() {
                *v /= last;
            }
            col_cdf.push(c);
        }
        let last = row_cdf[h];
        for v in row_cdf.iter_mut() {
            *v /= last;
        }
        Environment {
            image,
            scale,
            source,
            row_cdf,
            col_cdf,
            texel_p,
        }
    }

    /// Radiance toward unit `d`: bilinear, times the scale.
    pub fn radiance(&self, d: DVec3) -> Rgb {
        self.image.sample_bilinear(d).map(|v| v * self.scale)
    }

    fn texel_of(&self, d: DVec3) -> (usize, usize) {
        let (w, h) = (self.image.width(), self.image.height());
        let th = d.z.clamp(-1.0, 1.0).acos();
        let mut ph = d.y.atan2(d.x);
        if ph < 0.0 {
            ph += TAU;
        }
        let x = ((ph / TAU * w as f64) as usize).min(w - 1);
        let y = ((th / PI * h as f64) as usize).min(h - 1);
        (x, y)
    }

    /// Density (per steradian) of [`Environment::sample`] at unit `d`.
    pub fn pdf(&self, d: DVec3) -> f64 {
        let (x, y) = self.texel_of(d);
        self.texel_p[y * self.image.width() + x] / self.image.pixel_solid_angle(y)
    }

    /// A direction: a texel by the tabulated distribution, then uniform in solid angle
    /// inside it (uniform in `φ` and in `cos θ`). Returns the direction and its density.
    pub fn sample(&self, u1: f64, u2: f64, u3: f64, u4: f64) -> (DVec3, f64) {
        let (w, h) = (self.image.width(), self.image.height());
        let y = search(&self.row_cdf, u1).min(h - 1);
        let x = search(&self.col_cdf[y], u2).min(w - 1);
        let (c0, c1) = (
            (y as f64 / h as f64 * PI).cos(),
            ((y + 1) as f64 / h as f64 * PI).cos(),
        );
        let cos_t = c0 + (c1 - c0) * u3;
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let ph = (x as f64 + u4) / w as f64 * TAU;
        let d = DVec3::new(sin_t * ph.cos(), sin_t * ph.sin(), cos_t);
        (d, self.texel_p[y * w + x] / self.image.pixel_solid_angle(y))
    }
}

/// The index `i` with `cdf[i] ≤ u < cdf[i + 1]`, skipping empty intervals.
fn search(cdf: &[f64], u: f64) -> usize {
    let i = cdf.partition_point(|&c| c <= u);
    i.saturating_sub(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// `E[f/pdf]` of the environment sampler equals the image's integral
    /// ([`Equirect::integral`]) for a smooth `f` = the environment itself.
    #[test]
    fn environment_sampler_integrates_the_image() {
        let env = Environment::load("builtin:sky", Path::new("."), 1.0).unwrap();
        let mut rng = Rng::new(3);
        let n = 200_000;
        let mut s = 0.0;
        for _ in 0..n {
            let (d, p) = env.sample(rng.unit(), rng.unit(), rng.unit(), rng.unit());
            assert!((p - env.pdf(d)).abs() <= 1e-6 * p, "{p} vs {}", env.pdf(d));
            s += env.radiance(d)[1] / p;
        }
        let est = s / n as f64;
        let exact = env.image.integral()[1];
        assert!((est - exact).abs() < 0.01 * exact, "{est} vs {exact}");
    }

    #[test]
    fn cone_sampling_stays_in_the_cone_and_has_the_right_solid_angle() {
        let c = Cone::of_sphere(DVec3::ZERO, DVec3::new(1e3, 2.0, -3.0), 1e-2).unwrap();
        let exact = TAU * (1.0 - (1.0 - (1e-2f64 / c.dist).powi(2)).sqrt());
        assert!((c.solid_angle() - exact).abs() < 1e-6 * exact);
        let mut rng = Rng::new(1);
        for _ in 0..1000 {
            let d = c.sample(rng.unit(), rng.unit());
            assert!(d.dot(c.axis) >= c.cos_a - 1e-12);
        }
        assert!(Cone::of_sphere(DVec3::ZERO, DVec3::X, 2.0).is_none());
    }
}
