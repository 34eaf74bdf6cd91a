//! Writing figures to files: a bitmap drawn with plotters to a PNG, a
//! [`Figure`] to PNG or SVG by the file's extension, and a caption strip
//! added under a PNG.

use super::error::DResult;
use super::palette::TEXT;
use super::text::{fit_size, put_text, register_fonts};
use anyhow::{Result, anyhow, bail};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use std::path::Path;

/// A figure that can draw itself on any plotters backend.
pub trait Figure {
    fn size(&self) -> (u32, u32);
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DResult<DB>;
}

/// Writes RGB8 pixels (`size.0 × size.1`, row-major) as a PNG file.
fn write_png(path: &Path, rgb: &[u8], size: (u32, u32)) -> Result<()> {
    image::save_buffer_with_format(
        path,
        rgb,
        size.0,
        size.1,
        image::ExtendedColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .map_err(|e| anyhow!("cannot write {}: {e}", path.display()))
}

/// Draws with `draw` on a `size` bitmap that starts as `pixels` (RGB8,
/// row-major; black where the figure paints nothing) and writes it to
/// `path` as a PNG. The embedded font is registered first.
///
/// # Errors
///
/// `draw`'s, or the file cannot be written.
pub fn paint_png(
    path: &Path,
    mut pixels: Vec<u8>,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> Result<()>,
) -> Result<()> {
    register_fonts()?;
    pixels.resize(size.0 as usize * size.1 as usize * 3, 0);
    {
        let root = BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area();
        draw(&root)?;
        root.present()
            .map_err(|e| anyhow!("drawing {}: {e}", path.display()))?;
    }
    write_png(path, &pixels, size)
}

/// Writes `fig` to `path`: an SVG if it ends in `.svg`, a PNG if `.png`.
///
/// # Errors
///
/// Another extension, or the file cannot be written.
pub fn save_figure(path: &Path, fig: &impl Figure) -> Result<()> {
    register_fonts()?;
    let shown = path.display();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => paint_png(path, Vec::new(), fig.size(), |root| {
            fig.draw(root).map_err(|e| anyhow!("drawing {shown}: {e}"))
        })?,
        Some("svg") => {
            let root = SVGBackend::new(path, fig.size()).into_drawing_area();
            fig.draw(&root)
                .map_err(|e| anyhow!("drawing {shown}: {e}"))?;
            root.present()
                .map_err(|e| anyhow!("cannot write {shown}: {e}"))?;
        }
        _ => bail!("{shown}: a figure file name must end in .png or .svg"),
    }
    Ok(())
}

/// Adds a white strip under the PNG at `path` holding `lines` of caption
/// text (left-aligned, each shrunk to fit the width), rewrites the file and
/// returns the new size.
///
/// # Errors
///
/// The file cannot be read, decoded or written.
pub fn append_caption(path: &Path, lines: &[String]) -> Result<(u32, u32)> {
    let img = image::open(path)
        .map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?
        .to_rgb8();
    let (w, h) = img.dimensions();
    let line_h = 22;
    let strip = line_h * lines.len() as u32 + 14;
    let size = (w, h + strip);
    let mut pixels = img.into_raw();
    pixels.resize(w as usize * size.1 as usize * 3, 255);
    paint_png(path, pixels, size, |root| {
        for (k, line) in lines.iter().enumerate() {
            let fs = fit_size(line, 16.0, w as i32 - 32);
            put_text(
                root,
                line,
                (16, (h + 6 + line_h * k as u32) as i32),
                fs,
                TEXT,
                (HPos::Left, VPos::Top),
            )
            .map_err(|e| anyhow!("drawing {}: {e}", path.display()))?;
        }
        Ok(())
    })?;
    Ok(size)
}
