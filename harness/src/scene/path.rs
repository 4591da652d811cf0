//! The reference: a path tracer for the same scene, in f64.
//!
//! Estimator (Veach 1997, ch. 9): at every surface vertex, next-event estimation toward
//! each spherical light by sampling its subtended cone uniformly (density
//! `1/(2π(1 − cos α))`) and toward the environment by its texel distribution, each
//! combined by the power heuristic `w_a = p_a²/(p_a² + p_b²)` with the material's own
//! sampling, whose ray also collects the light or environment it hits with the
//! complementary weight. A path has at most `bounces + 1` surface vertices: `bounces = 0`
//! is direct lighting. Camera rays are uniform over the pixel footprint (a box filter), so
//! a pixel is the mean over its area; the per-pixel standard error of that mean is
//! returned beside the image.
//!
//! Every sample uses its own SplitMix64 stream seeded from the pixel and the sample index,
//! so an image is the same whatever the thread count.

use glam::DVec3;
use indicatif::ProgressBar;
use rayon::prelude::*;

use super::image::Image;
use super::light::Cone;
use super::{Kind, Ray, Rgb, Scene};
use crate::rng::Rng;

/// Settings of a path-traced render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Samples per pixel.
    pub spp: u32,
    /// Indirect bounces (0: direct lighting only).
    pub bounces: u32,
    /// Seed of the sample streams.
    pub seed: u64,
}

/// The image and its per-pixel standard error.
#[derive(Clone, Debug)]
pub struct Output {
    /// Mean radiance per pixel.
    pub image: Image,
    /// Standard error of that mean, per channel.
    pub stderr: Image,
}

fn mis(a: f64, b: f64) -> f64 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 == 0.0 { 0.0 } else { a2 / (a2 + b2) }
}

fn add(l: &mut Rgb, beta: Rgb, v: Rgb, k: f64) {
    for c in 0..3 {
        l[c] += beta[c] * v[c] * k;
    }
}

/// The origin of rays leaving the surface point `x` on the side of `n`: offset by
/// `1e-7·(1 + |x|∞)`, far above the rounding of the hit point, far below any feature size.
pub fn offset(x: DVec3, n: DVec3) -> DVec3 {
    x + n * (1e-7 * (1.0 + x.abs().max_element()))
}

/// One radiance sample along a camera ray.
pub fn radiance(scene: &Scene, ray: Ray, bounces: u32, rng: &mut Rng) -> Rgb {
    let mut l = [0.0; 3];
    let mut beta = [1.0; 3];
    let mut ray = ray;
    // (pdf of the material sample that made `ray`, its origin); None for the camera ray.
    let mut prev: Option<(f64, DVec3)> = None;
    let mut vertices = 0;
    loop {
        let Some(hit) = scene.intersect(&ray, 0.0, f64::INFINITY) else {
            if let Some(env) = &scene.environment {
                let w = prev.map_or(1.0, |(pb, _)| mis(pb, env.pdf(ray.d)));
                add(&mut l, beta, env.radiance(ray.d), w);
            }
            break;
        };
        let obj = scene.objects[hit.object];
        let x = ray.o + hit.t * ray.d;
        let mi = match obj.kind {
            Kind::Light(li) => {
                let light = &scene.lights[li];
                let w = match prev {
                    None => 1.0,
                    Some((pb, px)) => Cone::of_sphere(px, light.center, light.radius)
                        .map_or(1.0, |c| mis(pb, 1.0 / c.solid_angle())),
                };
                add(&mut l, beta, light.radiance, w);
                break;
            }
            Kind::Surface(mi) => mi,
        };
        if vertices > bounces {
            break;
        }
        vertices += 1;
        let mat = &scene.materials[mi];
        let wo = -ray.d;
        let mut n = obj.shape.normal(x);
        if n.dot(wo) < 0.0 {
            n = -n;
        }
        let origin = offset(x, n);
        for light in &scene.lights {
            let (u1, u2) = (rng.unit(), rng.unit());
            let Some(cone) = Cone::of_sphere(origin, light.center, light.radius) else {
                continue;
            };
            let wi = cone.sample(u1, u2);
            let cos = n.dot(wi);
            if cos <= 0.0 {
                continue;
            }
            let shadow = Ray { o: origin, d: wi };
            let shape = super::Shape::Sphere {
                center: light.center,
                radius: light.radius,
            };
            // A direction at the cone's rim may miss the sphere by rounding: take the
            // closest approach then.
            let t_light = shape
                .intersect(&shadow, 0.0, f64::INFINITY)
                .unwrap_or_else(|| (light.center - origin).dot(wi));
            if scene.occluded(&shadow, 0.0, t_light * (1.0 - 1e-9)) {
                continue;
            }
            let f = mat.eval(n, wo, wi);
            let pl = 1.0 / cone.solid_angle();
            let w = mis(pl, mat.pdf(n, wo, wi));
            let k = cos / pl * w;
            for c in 0..3 {
                l[c] += beta[c] * f[c] * light.radiance[c] * k;
            }
        }
        if let Some(env) = &scene.environment {
            let (wi, pe) = env.sample(rng.unit(), rng.unit(), rng.unit(), rng.unit());
            let cos = n.dot(wi);
            if cos > 0.0 && pe > 0.0 {
                let shadow = Ray { o: origin, d: wi };
                if !scene.occluded(&shadow, 0.0, f64::INFINITY) {
                    let f = mat.eval(n, wo, wi);
                    let le = env.radiance(wi);
                    let w = mis(pe, mat.pdf(n, wo, wi));
                    let k = cos / pe * w;
                    for c in 0..3 {
                        l[c] += beta[c] * f[c] * le[c] * k;
                    }
                }
            }
        }
        let Some((wi, pb)) = mat.sample(n, wo, [rng.unit(), rng.unit(), rng.unit()]) else {
            break;
        };
        let cos = n.dot(wi);
        if cos <= 0.0 {
            break;
        }
        let f = mat.eval(n, wo, wi);
        for c in 0..3 {
            beta[c] *= f[c] * cos / pb;
        }
        if beta.iter().all(|&b| b == 0.0) {
            break;
        }
        prev = Some((pb, origin));
        ray = Ray { o: origin, d: wi };
    }
    l
}

/// Seed of the stream for one pixel.
fn pixel_seed(seed: u64, pixel: u64) -> u64 {
    Rng::new(seed ^ pixel.wrapping_mul(0x9e37_79b9_7f4a_7c15)).next_u64()
}

/// Renders the scene: `spp` samples uniform over each pixel, rows in parallel.
pub fn render(scene: &Scene, s: &Settings, bar: &ProgressBar) -> Output {
    let cam = scene.camera;
    let (w, h) = (cam.width as usize, cam.height as usize);
    let spp = s.spp.max(1);
    let rows: Vec<(Vec<Rgb>, Vec<Rgb>)> = (0..h)
        .into_par_iter()
        .map(|j| {
            let mut mean_row = Vec::with_capacity(w);
            let mut se_row = Vec::with_capacity(w);
            for i in 0..w {
                let mut rng = Rng::new(pixel_seed(s.seed, (j * w + i) as u64));
                let (mut m, mut m2) = ([0.0; 3], [0.0; 3]);
                for _ in 0..spp {
                    let ray = cam.ray(i as u32, j as u32, rng.unit(), rng.unit());
                    let v = radiance(scene, ray, s.bounces, &mut rng);
                    for c in 0..3 {
                        m[c] += v[c];
                        m2[c] += v[c] * v[c];
                    }
                }
                let n = spp as f64;
                let mean = m.map(|x| x / n);
                let mut se = [0.0; 3];
                for c in 0..3 {
                    let var = if spp > 1 {
                        ((m2[c] - n * mean[c] * mean[c]) / (n - 1.0)).max(0.0)
                    } else {
                        0.0
                    };
                    se[c] = (var / n).sqrt();
                }
                mean_row.push(mean);
                se_row.push(se);
            }
            bar.inc(1);
            (mean_row, se_row)
        })
        .collect();
    let mut image = Image::new(w, h);
    let mut stderr = Image::new(w, h);
    for (j, (m, e)) in rows.into_iter().enumerate() {
        image.data[j * w..(j + 1) * w].copy_from_slice(&m);
        stderr.data[j * w..(j + 1) * w].copy_from_slice(&e);
    }
    Output { image, stderr }
}
