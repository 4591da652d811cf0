//! Image errors against the path-traced reference, with the measures of the three papers.
//!
//! Pixels are classified by probing the scene at the pixel centre and near its four
//! corners: a pixel whose five probes meet different objects (or some escape) is a
//! *silhouette* pixel, where a pixel-centre method and the box-filtered reference
//! legitimately differ; its errors are reported apart. *Shaded* pixels are the
//! non-silhouette pixels whose centre meets a surface (not a light, not the environment).
//!
//! - `mean_abs_over_max` (cosine-lobe paper, Figure 15): the mean over shaded pixels and
//!   channels of `|method − reference|`, over the largest reference value of a shaded
//!   pixel (`max_radiance`);
//! - `rel_l2` (rotatable-square-lights paper): `‖method − reference‖₂ / ‖reference‖₂` over
//!   shaded pixels;
//! - `rmse`, `psnr_db` (HVL paper): over the whole image, on tone-mapped values in
//!   `[0, 1]` (`srgb(v·2^exposure)`), PSNR `= −20·log10(rmse)`; `rmse_shaded` the same
//!   over shaded pixels only (silhouettes apart, as for the other measures);
//! - `ssim`: over the whole 8-bit tone-mapped image, by `image-compare`'s SSIM (8 × 8
//!   windows, the smallest of the three channels' means);
//! - `rel_l2_noise_corrected`: `rel_l2` with the reference's noise taken out. For an image
//!   independent of the reference's samples, `E[(m − r)²] = (m − t)² + σ²` and
//!   `E[r²] = t² + σ²` (`t` the noise-free value, `σ` the reference's standard error), so
//!   `√((Σ(m − r)² − Σσ²)⁺ / (Σr² − Σσ²))` estimates the error against the noise-free
//!   image; without a standard error it equals `rel_l2`;
//! - `reference_noise_over_max`: the mean over shaded pixels of the reference's standard
//!   error over `max_radiance`, so an error can be judged against the reference's noise.

use serde::Serialize;

use super::image::Image;
use super::{Kind, Scene};

/// What a probe of a pixel met.
fn probe(scene: &Scene, i: u32, j: u32, x: f64, y: f64) -> Option<usize> {
    let ray = scene.camera.ray(i, j, x, y);
    scene.intersect(&ray, 0.0, f64::INFINITY).map(|h| h.object)
}

/// Per pixel: `Some(true)` shaded, `Some(false)` light or environment, `None` silhouette.
pub fn classify(scene: &Scene) -> Vec<Option<bool>> {
    let cam = scene.camera;
    let mut out = Vec::with_capacity(cam.pixels());
    for j in 0..cam.height {
        for i in 0..cam.width {
            let c = probe(scene, i, j, 0.5, 0.5);
            let same = [(0.02, 0.02), (0.98, 0.02), (0.02, 0.98), (0.98, 0.98)]
                .iter()
                .all(|&(x, y)| probe(scene, i, j, x, y) == c);
            out.push(if !same {
                None
            } else {
                Some(c.is_some_and(|o| matches!(scene.objects[o].kind, Kind::Surface(_))))
            });
        }
    }
    out
}

/// The errors of an image against the reference (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Metrics {
    /// Mean `|difference|` over shaded pixels, over `max_radiance`.
    pub mean_abs_over_max: f64,
    /// Largest `|difference|` over shaded pixels, over `max_radiance`.
    pub max_abs_over_max: f64,
    /// Relative L2 over shaded pixels.
    pub rel_l2: f64,
    /// Relative L2 over shaded pixels with the reference's variance subtracted (module
    /// docs).
    pub rel_l2_noise_corrected: f64,
    /// RMSE of the tone-mapped images, whole image.
    pub rmse: f64,
    /// RMSE of the tone-mapped images over shaded pixels.
    pub rmse_shaded: f64,
    /// PSNR in dB of the tone-mapped images.
    pub psnr_db: f64,
    /// SSIM of the 8-bit tone-mapped images.
    pub ssim: f64,
    /// Largest reference value over shaded pixels.
    pub max_radiance: f64,
    /// Mean reference standard error over shaded pixels, over `max_radiance` (0 without
    /// one).
    pub reference_noise_over_max: f64,
    /// Shaded pixels.
    pub shaded_pixels: usize,
    /// Silhouette pixels.
    pub silhouette_pixels: usize,
    /// Mean `|difference|` over silhouette pixels, over `max_radiance`.
    pub silhouette_mean_abs_over_max: f64,
    /// Exposure of the tone mapping.
    pub exposure: f64,
}

/// Compares `img` with `reference` (and its standard error, when known), pixels classified
/// by [`classify`].
pub fn compare(
    class: &[Option<bool>],
    img: &Image,
    reference: &Image,
    stderr: Option<&Image>,
    exposure: f64,
) -> Result<Metrics, String> {
    if (img.width, img.height) != (reference.width, reference.height)
        || img.width * img.height != class.len()
    {
        return Err(format!(
            "image sizes differ: {}×{} vs reference {}×{} ({} classified pixels)",
            img.width,
            img.height,
            reference.width,
            reference.height,
            class.len()
        ));
    }
    let mut max_radiance: f64 = 0.0;
    for (k, c) in class.iter().enumerate() {
        if *c == Some(true) {
            max_radiance = max_radiance.max(reference.data[k].iter().cloned().fold(0.0, f64::max));
        }
    }
    let scale = if max_radiance > 0.0 {
        max_radiance
    } else {
        1.0
    };
    let (mut sum_abs, mut max_abs, mut n_shaded) = (0.0, 0.0f64, 0usize);
    let (mut d2, mut r2, mut noise, mut var) = (0.0, 0.0, 0.0, 0.0);
    let (mut sil_abs, mut n_sil) = (0.0, 0usize);
    for (k, c) in class.iter().enumerate() {
        let (a, b) = (img.data[k], reference.data[k]);
        let diff: f64 = (0..3).map(|ch| (a[ch] - b[ch]).abs()).sum::<f64>() / 3.0;
        match c {
            Some(true) => {
                n_shaded += 1;
                sum_abs += diff;
                for ch in 0..3 {
                    max_abs = max_abs.max((a[ch] - b[ch]).abs());
                    d2 += (a[ch] - b[ch]).powi(2);
                    r2 += b[ch] * b[ch];
                }
                if let Some(se) = stderr {
                    noise += se.data[k].iter().sum::<f64>() / 3.0;
                    var += se.data[k].iter().map(|e| e * e).sum::<f64>();
                }
            }
            None => {
                n_sil += 1;
                sil_abs += diff;
            }
            Some(false) => {}
        }
    }
    let ta = img.tone_mapped(exposure);
    let tb = reference.tone_mapped(exposure);
    let mse = ta
        .iter()
        .zip(&tb)
        .map(|(p, q)| (0..3).map(|c| (p[c] - q[c]).powi(2)).sum::<f64>())
        .sum::<f64>()
        / (3 * ta.len()).max(1) as f64;
    let rmse = mse.sqrt();
    let (mut se_shaded, mut n_se) = (0.0, 0usize);
    for ((p, q), c) in ta.iter().zip(&tb).zip(class) {
        if *c == Some(true) {
            se_shaded += (0..3).map(|ch| (p[ch] - q[ch]).powi(2)).sum::<f64>();
            n_se += 3;
        }
    }
    let rmse_shaded = if n_se == 0 {
        0.0
    } else {
        (se_shaded / n_se as f64).sqrt()
    };
    let ssim = if img.width >= 8 && img.height >= 8 {
        image_compare::rgb_similarity_structure(
            &image_compare::Algorithm::MSSIMSimple,
            &img.to_rgb8(exposure),
            &reference.to_rgb8(exposure),
        )
        .map_err(|e| format!("ssim: {e}"))?
        .score
    } else {
        f64::NAN
    };
    let per = |s: f64, n: usize| if n == 0 { 0.0 } else { s / n as f64 / scale };
    Ok(Metrics {
        mean_abs_over_max: per(sum_abs, n_shaded),
        max_abs_over_max: max_abs / scale,
        rel_l2: if r2 > 0.0 { (d2 / r2).sqrt() } else { 0.0 },
        rel_l2_noise_corrected: if r2 - var > 0.0 {
            ((d2 - var).max(0.0) / (r2 - var)).sqrt()
        } else {
            0.0
        },
        rmse,
        rmse_shaded,
        psnr_db: if rmse > 0.0 {
            -20.0 * rmse.log10()
        } else {
            f64::INFINITY
        },
        ssim,
        max_radiance,
        reference_noise_over_max: per(noise, n_shaded),
        shaded_pixels: n_shaded,
        silhouette_pixels: n_sil,
        silhouette_mean_abs_over_max: per(sil_abs, n_sil),
        exposure,
    })
}

/// A false-colour image of `method − reference` over shaded and silhouette pixels: red
/// where the method is brighter, blue where darker, full at `±range` (relative to the
/// reference's `max_radiance`), grey elsewhere.
pub fn difference_image(
    class: &[Option<bool>],
    img: &Image,
    reference: &Image,
    max_radiance: f64,
    range: f64,
) -> Image {
    let mut out = Image::new(img.width, img.height);
    let s = if max_radiance > 0.0 {
        max_radiance
    } else {
        1.0
    } * range;
    for (k, c) in class.iter().enumerate() {
        let d = (0..3)
            .map(|ch| img.data[k][ch] - reference.data[k][ch])
            .sum::<f64>()
            / 3.0;
        let t = (d / s).clamp(-1.0, 1.0);
        out.data[k] = match c {
            Some(false) => [0.05; 3],
            _ if t >= 0.0 => [1.0, 1.0 - t, 1.0 - t],
            _ => [1.0 + t, 1.0 + t, 1.0],
        };
    }
    out
}
