//! Writing images: linear OpenEXR (RGB, 32-bit float) and a tone-mapped,
//! sRGB-encoded PNG.
//!
//! The PNG's tone curve: exposure 1 (the linear value as is), then
//! Reinhard's `x / (1 + x)` on each channel, then the sRGB transfer
//! function, rounded to 8 bits. A radiance of 1 shows as 0.5 before the
//! sRGB encoding (188 of 255).

use crate::render::Image;
use std::path::{Path, PathBuf};

/// An image that could not be written.
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot write the image: {message}", path.display())]
pub struct OutputError {
    pub path: PathBuf,
    pub message: String,
}

/// Reinhard's curve `x / (1 + x)`, with NaN and negative values as 0.
#[inline]
#[must_use]
pub fn reinhard(x: f64) -> f64 {
    if x > 0.0 {
        if x.is_finite() { x / (1.0 + x) } else { 1.0 }
    } else {
        0.0
    }
}

/// The sRGB transfer function of a linear value in [0, 1].
#[inline]
#[must_use]
pub fn srgb_encode(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// One linear channel value to an 8-bit tone-mapped sRGB value.
#[inline]
#[must_use]
pub fn tonemap_channel(x: f64) -> u8 {
    (srgb_encode(reinhard(x)) * 255.0).round() as u8
}

impl Image {
    /// The tone-mapped sRGB bytes, `RGB RGB ...`, row 0 at the top.
    #[must_use]
    pub fn to_srgb8(&self) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|p| p.to_array().map(tonemap_channel))
            .collect()
    }

    /// The linear values as f32, `RGB RGB ...`; non-finite values as 0.
    #[must_use]
    pub fn to_rgb32f(&self) -> Vec<f32> {
        self.pixels
            .iter()
            .flat_map(|p| {
                p.to_array()
                    .map(|c| if c.is_finite() { c as f32 } else { 0.0 })
            })
            .collect()
    }

    /// Write the linear image as OpenEXR (RGB, 32-bit float).
    pub fn write_exr(&self, path: &Path) -> Result<(), OutputError> {
        let err = |message: String| OutputError {
            path: path.to_path_buf(),
            message,
        };
        let img =
            image::Rgb32FImage::from_raw(self.width as u32, self.height as u32, self.to_rgb32f())
                .ok_or_else(|| err("the pixel buffer does not match the size".into()))?;
        image::DynamicImage::ImageRgb32F(img)
            .save_with_format(path, image::ImageFormat::OpenExr)
            .map_err(|e| err(e.to_string()))
    }

    /// Write the tone-mapped image as an 8-bit sRGB PNG.
    pub fn write_png(&self, path: &Path) -> Result<(), OutputError> {
        let err = |message: String| OutputError {
            path: path.to_path_buf(),
            message,
        };
        let img = image::RgbImage::from_raw(self.width as u32, self.height as u32, self.to_srgb8())
            .ok_or_else(|| err("the pixel buffer does not match the size".into()))?;
        img.save_with_format(path, image::ImageFormat::Png)
            .map_err(|e| err(e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tone_curve() {
        assert_eq!(tonemap_channel(0.0), 0);
        assert_eq!(tonemap_channel(f64::NAN), 0);
        assert_eq!(tonemap_channel(f64::INFINITY), 255);
        assert_eq!(tonemap_channel(1.0), 188);
        assert!(tonemap_channel(1e9) == 255);
    }
}
