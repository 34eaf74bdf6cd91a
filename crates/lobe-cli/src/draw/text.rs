//! Text: the embedded DejaVu Sans, measuring a string, shrinking it to a
//! width, and drawing it at an anchor.

use super::error::DResult;
use super::palette::TEXT;
use anyhow::{Result, anyhow};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::sync::OnceLock;

/// The font family every figure uses; DejaVu Sans is registered under it.
const FONT: &str = "sans-serif";
static FONT_BYTES: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// Registers the embedded DejaVu Sans once (as sans-serif, serif and
/// monospace); plotters' ab_glyph text needs it, and no font has to be
/// installed where the figures are made.
pub(super) fn register_fonts() -> Result<()> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        ["sans-serif", "serif", "monospace"].iter().all(|family| {
            plotters::style::register_font(family, FontStyle::Normal, FONT_BYTES).is_ok()
        })
    });
    if ok {
        Ok(())
    } else {
        Err(anyhow!("the embedded font could not be loaded"))
    }
}

/// The figures' font at `size` pixels.
pub fn font(size: f64) -> FontDesc<'static> {
    (FONT, size).into_font()
}

/// The font at `size` in `color`, anchored by `h` and `v`.
pub fn text_style(size: f64, color: RGBColor, h: HPos, v: VPos) -> TextStyle<'static> {
    font(size).color(&color).pos(Pos::new(h, v))
}

/// Width in pixels of `s` at `size` (0 when it cannot be measured).
pub fn text_width(s: &str, size: f64) -> i32 {
    font(size).box_size(s).map_or(0, |(w, _)| w as i32)
}

/// The largest size ≤ `size` (in steps of half a pixel, not below 9) at
/// which `s` fits in `width` pixels.
pub fn fit_size(s: &str, size: f64, width: i32) -> f64 {
    let mut size = size;
    while size > 9.0 && text_width(s, size) > width {
        size -= 0.5;
    }
    size
}

/// Draws `s` at pixel `pos` of `area`, anchored by `h` and `v`.
pub fn put_text<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    s: &str,
    pos: (i32, i32),
    size: f64,
    color: RGBColor,
    (h, v): (HPos, VPos),
) -> DResult<DB> {
    area.draw_text(s, &text_style(size, color, h, v), pos)
}

/// Draws a title centred at the top of `area` (shrunk to fit) and returns
/// the height it took.
pub fn draw_title<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    size: f64,
) -> DResult<DB, i32> {
    let (w, _) = area.dim_in_pixel();
    let size = fit_size(title, size, w as i32 - 40);
    put_text(
        area,
        title,
        (w as i32 / 2, 8),
        size,
        TEXT,
        (HPos::Center, VPos::Top),
    )?;
    Ok(size.round() as i32 + 16)
}
