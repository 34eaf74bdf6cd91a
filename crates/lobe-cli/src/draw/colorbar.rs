//! The colour bar of every heat map and error map: a viridis strip, its
//! frame, and its tick labels; vertical beside a map (with a rotated name)
//! or horizontal in a box.

use super::error::DResult;
use super::palette::{OUTLINE, TEXT, viridis};
use super::text::{font, put_text, text_width};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Size of the tick labels.
const TICK_SIZE: f64 = 12.0;

/// Which way a colour bar runs: from the bottom up, ticks to its right and
/// its `name` along its right side, rotated to read upwards; or from the
/// left, ticks below it (its name is the caller's to place).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Orientation<'a> {
    Vertical { name: &'a str },
    Horizontal,
}

/// Width in pixels that [`draw_colorbar`] takes with a vertical bar `width`
/// wide: the bar, its tick labels and its rotated name.
pub fn colorbar_extent(width: i32, ticks: &[(f64, String)]) -> i32 {
    width + 12 + widest(ticks) + 22
}

/// The widest tick label.
fn widest(ticks: &[(f64, String)]) -> i32 {
    ticks
        .iter()
        .map(|(_, s)| text_width(s, TICK_SIZE))
        .max()
        .unwrap_or(0)
}

/// Draws a viridis colour bar filling the `w × h` rectangle at `(x, y)`,
/// the low end (t = 0) at the bottom or the left, framed, with its `ticks`
/// (position in [0, 1] along the bar, label) outside: to the right of a
/// vertical bar (then its name past them, all in the width
/// [`colorbar_extent`] gives), below a horizontal one.
pub fn draw_colorbar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x, y): (i32, i32),
    (w, h): (i32, i32),
    orientation: Orientation,
    ticks: &[(f64, String)],
) -> DResult<DB> {
    let (w, h) = (w.max(1), h.max(1));
    let (right, bottom) = (x + w, y + h);
    match orientation {
        Orientation::Vertical { .. } => {
            for k in 0..h {
                let t = 1.0 - (f64::from(k) + 0.5) / f64::from(h);
                area.draw(&Rectangle::new(
                    [(x, y + k), (right, y + k + 1)],
                    viridis(t).filled(),
                ))?;
            }
        }
        Orientation::Horizontal => {
            for k in 0..w {
                let t = (f64::from(k) + 0.5) / f64::from(w);
                area.draw(&Rectangle::new(
                    [(x + k, y), (x + k + 1, bottom)],
                    viridis(t).filled(),
                ))?;
            }
        }
    }
    area.draw(&Rectangle::new(
        [(x, y), (right, bottom)],
        OUTLINE.stroke_width(1),
    ))?;
    for (t, s) in ticks {
        let (tick, at, anchor) = match orientation {
            Orientation::Vertical { .. } => {
                let ty = bottom - (t * f64::from(h)).round() as i32;
                (
                    [(right, ty), (right + 4, ty)],
                    (right + 6, ty),
                    (HPos::Left, VPos::Center),
                )
            }
            Orientation::Horizontal => {
                let tx = x + (t * f64::from(w)).round() as i32;
                (
                    [(tx, bottom), (tx, bottom + 4)],
                    (tx, bottom + 6),
                    (HPos::Center, VPos::Top),
                )
            }
        };
        area.draw(&PathElement::new(tick.to_vec(), BLACK.stroke_width(1)))?;
        put_text(area, s, at, TICK_SIZE, TEXT, anchor)?;
    }
    if let Orientation::Vertical { name } = orientation {
        // Rotated to read upwards; VPos::Top puts the text to the right of
        // the anchor.
        let style = font(13.0)
            .transform(FontTransform::Rotate270)
            .color(&TEXT)
            .pos(Pos::new(HPos::Center, VPos::Top));
        area.draw_text(name, &style, (right + 12 + widest(ticks), (y + bottom) / 2))?;
    }
    Ok(())
}
