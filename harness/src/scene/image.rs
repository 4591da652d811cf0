//! Linear RGB images: OpenEXR out and in (f32), tone-mapped sRGB PNG out.

use std::path::Path;

use super::Rgb;

/// A linear RGB image, row-major from the top-left pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width·height` pixels.
    pub data: Vec<Rgb>,
}

/// The sRGB transfer function of IEC 61966-2-1 on a linear value in `[0, 1]`.
pub fn srgb_encode(v: f64) -> f64 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

impl Image {
    /// A black image.
    pub fn new(width: usize, height: usize) -> Image {
        Image {
            width,
            height,
            data: vec![[0.0; 3]; width * height],
        }
    }

    /// Pixel `(i, j)`.
    pub fn get(&self, i: usize, j: usize) -> Rgb {
        self.data[j * self.width + i]
    }

    /// The tone-mapped value of every channel: `srgb(v·2^exposure)` in `[0, 1]`.
    pub fn tone_mapped(&self, exposure: f64) -> Vec<[f64; 3]> {
        let k = exposure.exp2();
        self.data
            .iter()
            .map(|p| p.map(|v| srgb_encode(if v.is_finite() { v * k } else { 0.0 })))
            .collect()
    }

    /// Writes linear f32 RGB OpenEXR.
    pub fn write_exr(&self, path: &Path) -> Result<(), String> {
        let mut buf = image::Rgb32FImage::new(self.width as u32, self.height as u32);
        for (p, q) in buf.pixels_mut().zip(&self.data) {
            *p = image::Rgb(q.map(|v| v as f32));
        }
        buf.save_with_format(path, image::ImageFormat::OpenExr)
            .map_err(|e| format!("writing {}: {e}", path.display()))
    }

    /// Reads an OpenEXR (or any format the `image` crate reads) as linear RGB.
    pub fn read(path: &Path) -> Result<Image, String> {
        let img = image::open(path)
            .map_err(|e| format!("reading {}: {e}", path.display()))?
            .into_rgb32f();
        Ok(Image {
            width: img.width() as usize,
            height: img.height() as usize,
            data: img.pixels().map(|p| p.0.map(|v| v as f64)).collect(),
        })
    }

    /// The 8-bit sRGB image after `2^exposure`.
    pub fn to_rgb8(&self, exposure: f64) -> image::RgbImage {
        let mut out = image::RgbImage::new(self.width as u32, self.height as u32);
        for (p, q) in out.pixels_mut().zip(self.tone_mapped(exposure)) {
            *p = image::Rgb(q.map(|v| (v * 255.0).round() as u8));
        }
        out
    }

    /// Writes the tone-mapped sRGB PNG.
    pub fn write_png(&self, path: &Path, exposure: f64) -> Result<(), String> {
        self.to_rgb8(exposure)
            .save_with_format(path, image::ImageFormat::Png)
            .map_err(|e| format!("writing {}: {e}", path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_round_trips_f32_values() {
        let mut img = Image::new(3, 2);
        for (k, p) in img.data.iter_mut().enumerate() {
            *p = [k as f64 * 0.25, 1e-3 * k as f64, 1e3 + k as f64];
        }
        let dir = std::env::temp_dir().join(format!("steradian-img-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("t.exr");
        img.write_exr(&p).unwrap();
        let back = Image::read(&p).unwrap();
        assert_eq!((back.width, back.height), (3, 2));
        for (a, b) in img.data.iter().zip(&back.data) {
            for c in 0..3 {
                assert_eq!(a[c] as f32 as f64, b[c]);
            }
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn srgb_is_continuous_and_monotone() {
        let lo = srgb_encode(0.003_130_8 - 1e-12);
        let hi = srgb_encode(0.003_130_8 + 1e-12);
        assert!((lo - hi).abs() < 1e-6);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-15);
        assert_eq!(srgb_encode(-1.0), 0.0);
    }
}
