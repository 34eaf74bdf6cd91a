//! Writing images: linear OpenEXR (RGB, 32-bit float) and a tone-mapped,
//! sRGB-encoded PNG.
//!
//! The PNG's tone curve ([`ToneMap`]): the linear value times `2^exposure`
//! (exposure in stops, 0 by default), then a filmic curve on the pixel's
//! **luminance** (Narkowicz's fit of the ACES reference curve,
//! `x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)`), the colour scaled by the
//! ratio of the mapped to the linear luminance so that hue and saturation
//! stay as rendered, each channel clipped to [0, 1], then the sRGB transfer
//! function, rounded to 8 bits. A grey radiance of 1 shows as 0.80 before
//! the sRGB encoding (232 of 255), 0.18 (middle grey) as 0.27.

use crate::integrator::Image;
use std::path::{Path, PathBuf};

/// An image that could not be written.
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot write the image: {message}", path.display())]
pub struct OutputError {
    pub path: PathBuf,
    pub message: String,
}

/// Narkowicz's fit of the ACES filmic curve, from linear `[0, ∞)` to
/// `[0, 1]`; NaN and negative values as 0, infinity as 1.
#[inline]
#[must_use]
pub fn filmic(x: f64) -> f64 {
    if x > 0.0 {
        if x.is_finite() {
            (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).min(1.0)
        } else {
            1.0
        }
    } else {
        0.0
    }
}

/// How linear radiance becomes display values in a PNG.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToneMap {
    /// Exposure in stops: the linear value is scaled by `2^exposure`.
    pub exposure: f64,
}

impl Default for ToneMap {
    fn default() -> Self {
        ToneMap { exposure: 0.0 }
    }
}

impl ToneMap {
    /// The display values in [0, 1] (before the sRGB encoding) of a linear
    /// RGB value: the filmic curve on luminance, the colour scaled along.
    #[must_use]
    pub fn display(&self, rgb: [f64; 3]) -> [f64; 3] {
        Self::display_scaled(self.exposure.exp2(), rgb)
    }

    /// [`ToneMap::display`] with the exposure's factor `k = 2^exposure`.
    #[inline]
    fn display_scaled(k: f64, rgb: [f64; 3]) -> [f64; 3] {
        // NaN and negative values as 0; infinity as a radiance far past white.
        let c = rgb.map(|v| {
            if v == f64::INFINITY {
                1e30
            } else if v > 0.0 {
                (v * k).min(1e30)
            } else {
                0.0
            }
        });
        let lum = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
        if lum.is_nan() || lum <= 0.0 {
            return [0.0; 3];
        }
        let ratio = filmic(lum) / lum;
        c.map(|v| (v * ratio).clamp(0.0, 1.0))
    }

    /// The 8-bit sRGB values of a linear RGB value.
    #[must_use]
    pub fn srgb8(&self, rgb: [f64; 3]) -> [u8; 3] {
        Self::srgb8_scaled(self.exposure.exp2(), rgb)
    }

    /// [`ToneMap::srgb8`] with the exposure's factor `k = 2^exposure`: the
    /// display values' codes ([`srgb8_of`]) by [`Srgb8Steps`].
    #[inline]
    fn srgb8_scaled(k: f64, rgb: [f64; 3]) -> [u8; 3] {
        let steps = Srgb8Steps::get();
        Self::display_scaled(k, rgb).map(|v| steps.code(v))
    }
}

/// The 8-bit code of a display value: `srgb_encode(v) · 255`, rounded.
#[inline]
fn srgb8_of(v: f64) -> u8 {
    (srgb_encode(v) * 255.0).round() as u8
}

/// The display values where [`srgb8_of`] steps up: `steps[n − 1]` is the
/// least `f64` whose code is `n` or more. A value's code is then the count
/// of steps at or below it (eight comparisons instead of a `powf`; the
/// same byte, the code being non-decreasing in the value).
struct Srgb8Steps([f64; 255]);

impl Srgb8Steps {
    /// The table, made on first use (by bisection over the `f64`s around
    /// each step's value by the inverse transfer function: a few thousand
    /// calls of [`srgb8_of`]).
    fn get() -> &'static Self {
        static STEPS: std::sync::OnceLock<Srgb8Steps> = std::sync::OnceLock::new();
        STEPS.get_or_init(|| {
            // The inverse of `srgb_encode`, for a first guess.
            let decode = |y: f64| {
                if y <= 0.04045 {
                    y / 12.92
                } else {
                    ((y + 0.055) / 1.055).powf(2.4)
                }
            };
            Srgb8Steps(std::array::from_fn(|k| {
                let n = k as u8 + 1;
                let guess = decode((f64::from(n) - 0.5) / 255.0).to_bits();
                // A bracket `lo < step ≤ hi` in the bits of positive f64s
                // (ordered as the values), widened until it holds.
                let mut d = 64u64;
                let (mut lo, mut hi) = loop {
                    let (lo, hi) = (guess.saturating_sub(d), guess + d);
                    if srgb8_of(f64::from_bits(lo)) < n && srgb8_of(f64::from_bits(hi)) >= n {
                        break (lo, hi);
                    }
                    d *= 16;
                };
                while hi - lo > 1 {
                    let mid = lo + (hi - lo) / 2;
                    if srgb8_of(f64::from_bits(mid)) >= n {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                f64::from_bits(hi)
            }))
        })
    }

    /// [`srgb8_of`]`(v)` for a display value (in [0, 1], or NaN: 0).
    #[inline]
    fn code(&self, v: f64) -> u8 {
        self.0.partition_point(|&t| t <= v) as u8
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

impl Image {
    /// The sRGB bytes tone-mapped by `tone`, `RGB RGB ...`, row 0 at the top
    /// (the pixels mapped on rayon's threads, each on its own).
    #[must_use]
    pub fn to_srgb8(&self, tone: &ToneMap) -> Vec<u8> {
        use rayon::prelude::*;
        let k = tone.exposure.exp2();
        self.pixels
            .par_iter()
            .map(|p| ToneMap::srgb8_scaled(k, p.to_array()))
            .collect::<Vec<[u8; 3]>>()
            .into_flattened()
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

    /// Write the linear image as OpenEXR (RGB, 32-bit float, scan lines
    /// without compression: a render's noisy floats hardly compress, by
    /// `exr`'s run-length default 5%, which took half again as long to
    /// write), on the calling thread (a thread pool per file would cost
    /// more than it saves).
    ///
    /// The header holds what the image is the mean of, from
    /// [`Image::stats`] when it counts camera rays: `spp` (a 64-bit float
    /// attribute: the camera rays per pixel, the mean where the variance
    /// allocation gave pixels different counts) and `passes` (a 64-bit
    /// float: whole passes, [`crate::integrator::RenderStats::passes`]).
    pub fn write_exr(&self, path: &Path) -> Result<(), OutputError> {
        self.write_exr_noted(path, None)
    }

    /// [`Image::write_exr`] with `note`, when given, in the header's
    /// standard `comments` attribute (`software` names lobe either way) (Latin-1 text: other characters are
    /// an error).
    pub fn write_exr_noted(&self, path: &Path, note: Option<&str>) -> Result<(), OutputError> {
        use exr::meta::attribute::{AttributeValue, Text};
        use exr::prelude::{Image as ExrImage, SpecificChannels, WritableImage};
        let err = |message: String| OutputError {
            path: path.to_path_buf(),
            message,
        };
        let rgb = self.to_rgb32f();
        if rgb.len() != 3 * self.width * self.height {
            return Err(err("the pixel buffer does not match the size".into()));
        }
        let note = match note {
            Some(n) => Some(Text::new_or_none(n).ok_or_else(|| {
                err(format!(
                    "the note {n:?} has characters an EXR text cannot hold"
                ))
            })?),
            None => None,
        };
        let w = self.width;
        let pixels = (self.width * self.height) as f64;
        write_replacing(path, |out| {
            let mut image = ExrImage::from_encoded_channels(
                (self.width, self.height),
                exr::prelude::Encoding::UNCOMPRESSED,
                SpecificChannels::rgb(|p: exr::math::Vec2<usize>| {
                    let k = 3 * (p.y() * w + p.x());
                    (rgb[k], rgb[k + 1], rgb[k + 2])
                }),
            );
            let layer = &mut image.layer_data.attributes;
            // (One custom attribute per map: `exr` writes a map in its
            // hash order, which differs from run to run, and the same
            // image must give the same bytes.)
            if self.stats.camera_rays > 0 && pixels > 0.0 {
                let spp = self.stats.camera_rays as f64 / pixels;
                let passes = self.stats.passes.max(1) as f64;
                let image = &mut image.attributes.other;
                image.insert(Text::from("spp"), AttributeValue::F64(spp));
                layer
                    .other
                    .insert(Text::from("passes"), AttributeValue::F64(passes));
            }
            layer.comments = note;
            layer.software_name = Some(Text::from(concat!("lobe ", env!("CARGO_PKG_VERSION"))));
            image.write().non_parallel().to_buffered(out)
        })
    }

    /// The samples per pixel of a variance-allocated render
    /// ([`Image::spp`]) as an 8-bit sRGB picture, `RGB RGB ...`: black for
    /// the fewest, through purple and orange to pale yellow for the most,
    /// on a logarithmic scale; `None` for a render that gave every pixel
    /// the same count.
    #[must_use]
    pub fn spp_srgb8(&self) -> Option<Vec<u8>> {
        let counts = self.spp.as_ref()?;
        let lo = (*counts.iter().min()? as f64).max(1.0).ln();
        let hi = (*counts.iter().max()? as f64).max(1.0).ln();
        // (A colour ramp like matplotlib's "magma", by a few stops.)
        const STOPS: [[f64; 3]; 5] = [
            [0.0, 0.0, 0.02],
            [0.32, 0.07, 0.48],
            [0.72, 0.21, 0.47],
            [0.98, 0.53, 0.38],
            [0.99, 0.99, 0.75],
        ];
        let colour = |n: u64| {
            let t = if hi > lo {
                ((n as f64).max(1.0).ln() - lo) / (hi - lo)
            } else {
                1.0
            };
            let x = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
            let k = (x as usize).min(STOPS.len() - 2);
            let f = x - k as f64;
            let (a, b) = (STOPS[k], STOPS[k + 1]);
            [0, 1, 2].map(|c| ((a[c] + (b[c] - a[c]) * f) * 255.0).round() as u8)
        };
        // (Neighbours mostly share a count: its colour is kept.)
        let mut bytes = Vec::with_capacity(3 * counts.len());
        let mut last = None;
        for &n in counts {
            let c = match last {
                Some((m, c)) if m == n => c,
                _ => colour(n),
            };
            last = Some((n, c));
            bytes.extend_from_slice(&c);
        }
        Some(bytes)
    }

    /// Write [`Image::spp_srgb8`] as a PNG; `Ok(false)` (nothing written)
    /// for a render without per-pixel counts.
    pub fn write_spp_png(&self, path: &Path) -> Result<bool, OutputError> {
        let Some(bytes) = self.spp_srgb8() else {
            return Ok(false);
        };
        self.write_srgb8_png(path, bytes, "count")?;
        Ok(true)
    }

    /// Write the image tone-mapped by `tone` as an 8-bit sRGB PNG.
    pub fn write_png(&self, path: &Path, tone: &ToneMap) -> Result<(), OutputError> {
        self.write_srgb8_png(path, self.to_srgb8(tone), "pixel")
    }

    /// Write `bytes` (8-bit sRGB, `RGB RGB ...`, the image's size) as a PNG;
    /// `what` names the buffer in the error if its size is wrong.
    fn write_srgb8_png(&self, path: &Path, bytes: Vec<u8>, what: &str) -> Result<(), OutputError> {
        let err = |message: String| OutputError {
            path: path.to_path_buf(),
            message,
        };
        use image::ImageEncoder;
        if bytes.len() != 3 * self.width * self.height {
            return Err(err(format!("the {what} buffer does not match the size")));
        }
        write_replacing(path, |out| {
            image::codecs::png::PngEncoder::new(out).write_image(
                &bytes,
                self.width as u32,
                self.height as u32,
                image::ExtendedColorType::Rgb8,
            )
        })
    }
}

/// Write the file at `path` by `write` into a buffer over
/// [`create_replacing`]'s file, flushed at the end; any error as an
/// [`OutputError`] naming the path.
fn write_replacing<E: std::fmt::Display>(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> Result<(), E>,
) -> Result<(), OutputError> {
    let err = |message: String| OutputError {
        path: path.to_path_buf(),
        message,
    };
    let mut out = std::io::BufWriter::new(create_replacing(path).map_err(|e| err(e.to_string()))?);
    write(&mut out).map_err(|e| err(e.to_string()))?;
    std::io::Write::flush(&mut out).map_err(|e| err(e.to_string()))
}

/// A new, empty file at `path` to write. A regular file already there, the
/// only link to its data and writable, is removed first instead of being
/// truncated: on Linux's ext4, truncating a file that was written moments
/// ago (the previous render's output) waits until the kernel has written
/// its old data to the disk (half a millisecond to several), while the
/// blocks of a removed file are freed in the background. Anything else (a
/// symbolic link, a file with other hard links, a file this process cannot
/// write) is opened as [`std::fs::File::create`] opens it, and fails or
/// not as it does.
fn create_replacing(path: &Path) -> std::io::Result<std::fs::File> {
    if let Ok(m) = std::fs::symlink_metadata(path)
        && m.file_type().is_file()
        && only_link(&m)
        && std::fs::OpenOptions::new().write(true).open(path).is_ok()
    {
        // (Another process may remove it first: create below either way.)
        let _ = std::fs::remove_file(path);
    }
    std::fs::File::create(path)
}

/// Whether `m`'s file has a single hard link (always so where links cannot
/// be counted).
fn only_link(m: &std::fs::Metadata) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        m.nlink() == 1
    }
    #[cfg(not(unix))]
    {
        let _ = m;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A render written over an earlier file, over a symbolic link and over
    /// a file with a second hard link: the file gets the new bytes, the
    /// link is written through (and stays a link), the other hard link sees
    /// the new bytes too (its data was rewritten in place).
    #[test]
    fn outputs_replace_files_and_write_through_links() {
        let d = std::env::temp_dir().join(format!("lobe-output-test-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let mut img = Image::new(4, 3);
        img.pixels[5] = lobe::Rgb::new(0.5, 1.0, 2.0);
        let fresh = d.join("fresh.png");
        img.write_png(&fresh, &ToneMap::default()).unwrap();
        let want = std::fs::read(&fresh).unwrap();
        // Over a longer file.
        let old = d.join("old.png");
        std::fs::write(&old, vec![7u8; 10 * want.len()]).unwrap();
        img.write_png(&old, &ToneMap::default()).unwrap();
        assert_eq!(std::fs::read(&old).unwrap(), want);
        #[cfg(unix)]
        {
            let target = d.join("target.png");
            std::fs::write(&target, b"old").unwrap();
            let link = d.join("link.png");
            let _ = std::fs::remove_file(&link);
            std::os::unix::fs::symlink(&target, &link).unwrap();
            img.write_png(&link, &ToneMap::default()).unwrap();
            assert!(
                std::fs::symlink_metadata(&link)
                    .unwrap()
                    .file_type()
                    .is_symlink()
            );
            assert_eq!(std::fs::read(&target).unwrap(), want);
            let other = d.join("other.png");
            let _ = std::fs::remove_file(&other);
            std::fs::hard_link(&old, &other).unwrap();
            std::fs::write(&old, b"x").unwrap();
            img.write_png(&old, &ToneMap::default()).unwrap();
            assert_eq!(std::fs::read(&other).unwrap(), want);
        }
        // The EXR: over an earlier file, read back.
        let exr = d.join("img.exr");
        std::fs::write(&exr, vec![1u8; 100_000]).unwrap();
        img.write_exr(&exr).unwrap();
        let back = crate::load_envmap(&exr, 1.0, 0.0).unwrap().0;
        assert_eq!(back.texel(1, 1), lobe::Rgb::new(0.5, 1.0, 2.0));
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// The header of a render's EXR: its camera rays per pixel (`spp`),
    /// its passes, and a note in `comments`; none of them for an image
    /// that counts no camera rays.
    #[test]
    fn the_exr_header_says_the_samples_per_pixel() {
        use exr::meta::attribute::{AttributeValue, Text};
        let d = std::env::temp_dir().join(format!("lobe-exr-meta-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let read = |p: &Path| {
            let meta = exr::meta::MetaData::read_from_file(p, false).unwrap();
            let h = &meta.headers[0];
            // (One layer: the reader puts every custom attribute in it.)
            let mut attrs = h.shared_attributes.other.clone();
            attrs.extend(h.own_attributes.other.clone());
            if let Some(c) = &h.own_attributes.comments {
                attrs.insert(Text::from("comments"), AttributeValue::Text(c.clone()));
            }
            attrs
        };
        let mut img = Image::new(4, 3);
        let plain = d.join("plain.exr");
        img.write_exr(&plain).unwrap();
        let attrs = read(&plain);
        assert!(!attrs.contains_key(&Text::from("spp")), "{attrs:?}");
        img.stats.camera_rays = 12 * 24;
        img.stats.passes = 3;
        let noted = d.join("noted.exr");
        img.write_exr_noted(&noted, Some("interrupted after 3 passes"))
            .unwrap();
        let attrs = read(&noted);
        assert_eq!(attrs[&Text::from("spp")], AttributeValue::F64(24.0));
        assert_eq!(attrs[&Text::from("passes")], AttributeValue::F64(3.0));
        assert_eq!(
            attrs[&Text::from("comments")],
            AttributeValue::Text(Text::from("interrupted after 3 passes"))
        );
        // The same bytes every time (the header's maps in a fixed order).
        let bytes = std::fs::read(&noted).unwrap();
        for _ in 0..8 {
            img.write_exr_noted(&noted, Some("interrupted after 3 passes"))
                .unwrap();
            assert_eq!(std::fs::read(&noted).unwrap(), bytes);
        }
        let e = img.write_exr_noted(&noted, Some("3 ≥ 2")).unwrap_err();
        assert!(e.to_string().contains("cannot hold"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn tone_curve() {
        let t = ToneMap::default();
        assert_eq!(t.srgb8([0.0; 3]), [0; 3]);
        assert_eq!(t.srgb8([f64::NAN; 3]), [0; 3]);
        assert_eq!(t.srgb8([f64::INFINITY; 3]), [255; 3]);
        assert_eq!(t.srgb8([-1.0; 3]), [0; 3]);
        assert_eq!(t.srgb8([1.0; 3]), [232; 3]);
        assert!((t.display([0.18; 3])[0] - 0.2669).abs() < 1e-3);
        assert_eq!(t.srgb8([1e9; 3]), [255; 3]);
        // Monotone in luminance.
        let mut last = 0.0;
        for i in 1..1000 {
            let v = t.display([f64::from(i) * 0.01; 3])[0];
            assert!(v >= last - 1e-12, "{i}: {v} < {last}");
            last = v;
        }
    }

    /// The table of steps gives the code the transfer function gives: at
    /// and around every step (a thousand `f64`s either side), and at a
    /// million values spread over [0, 1] (and 0, 1, NaN).
    #[test]
    fn srgb8_steps_give_the_transfer_functions_codes() {
        let steps = Srgb8Steps::get();
        let check = |v: f64| assert_eq!(steps.code(v), srgb8_of(v), "{v:e}");
        for &t in &steps.0 {
            let b = t.to_bits();
            for d in 0..=1000 {
                check(f64::from_bits(b - d));
                check(f64::from_bits(b + d));
            }
        }
        let mut x = 0x9e37_79b9_7f4a_7c15_u64;
        for i in 0..1_000_000u32 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = (x >> 11) as f64 / (1u64 << 53) as f64;
            // (Half of them squared: more of the small values.)
            check(if i % 2 == 0 { v } else { v * v });
        }
        for v in [0.0, -0.0, 1.0, f64::NAN, 0.003_130_8] {
            check(v);
        }
        // Every code is some value's: the steps rise.
        assert!(steps.0.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(srgb8_of(steps.0[254]), 255);
    }

    #[test]
    fn the_curve_keeps_the_hue_and_exposure_scales() {
        let t = ToneMap::default();
        let d = t.display([0.2, 0.1, 0.05]);
        // The channel ratios are kept (per-channel curves would change them).
        assert!((d[0] / d[1] - 2.0).abs() < 1e-12 && (d[1] / d[2] - 2.0).abs() < 1e-12);
        // One stop up is the same as twice the radiance.
        let up = ToneMap { exposure: 1.0 }.display([0.2, 0.1, 0.05]);
        assert_eq!(up, t.display([0.4, 0.2, 0.1]));
    }
}
