//! Maps over the projected hemisphere (the unit disk of `wi`'s `(x, y)`,
//! `x` to the right, `y` up): the warp-test histogram (observed against
//! expected sample counts) and the sample-weight heat map.

use crate::draw::{
    DIM_TEXT, DResult, Figure, OUTLINE, Orientation, TEXT, colorbar_extent, draw_colorbar,
    draw_title, fit_size, fmt_num, fmt_p, linear_ticks, log_ticks, put_text, save_figure,
    text_width, viridis,
};
use anyhow::{Result, bail};
use glam::{DVec2, DVec3};
use lobe::BsdfSampler;
use lobe::experiment::histogram::{WeightPixel, weight_pixels};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use std::path::Path;

/// Size in pixels of a warp-test histogram (two maps side by side; two rows
/// of them over the sphere).
const HISTOGRAM_SIZE: (u32, u32) = (800, 400);
const HISTOGRAM_SPHERE_SIZE: (u32, u32) = (800, 740);

/// Size in pixels of a sample-weight heat map (one disk; two side by side
/// over the sphere).
const WEIGHTS_SIZE: (u32, u32) = (640, 600);
const WEIGHTS_SPHERE_SIZE: (u32, u32) = (1000, 560);

/// The names of the disks of a map over the sphere.
const HEMISPHERES: [&str; 2] = ["above the surface", "below the surface"];

/// How many disks (1, or 2 over the sphere) `len` values of `res²` make.
fn disks(len: usize, res: usize) -> Option<usize> {
    [1, 2].into_iter().find(|d| len == d * res * res)
}

/// Significance level of the pass/fail word of [`warp_histogram`]: the test
/// passes when `p_value > PASS_LEVEL` (Nori's warp test uses 1 %).
pub const PASS_LEVEL: f64 = 0.01;

/// Draws Nori's warp-test picture: the observed and the expected sample
/// counts over the projected hemisphere as two square heat maps side by
/// side, on the same linear colour scale (with a colour bar), and the
/// chi-square `p_value` with the word PASS or FAIL (`p > PASS_LEVEL`)
/// appended to `title`.
///
/// `observed` and `expected` are `res × res` grids laid out as
/// [`lobe::experiment::histogram::projected_histograms`] returns them, or
/// two each over the sphere (drawn as a second row, below the surface).
///
/// Writes an SVG if `path` ends in `.svg`, a PNG (800×400) if `.png`.
///
/// # Errors
///
/// `res == 0`, grids whose length is not `res²`, an unknown extension, or
/// the file cannot be written.
pub fn warp_histogram(
    path: &Path,
    title: &str,
    observed: &[f64],
    expected: &[f64],
    res: usize,
    p_value: f64,
) -> Result<()> {
    if res == 0 || disks(observed.len(), res).is_none() || observed.len() != expected.len() {
        bail!(
            "warp_histogram: the grids must hold res² = {}² values, or twice that over the sphere (got {} and {})",
            res,
            observed.len(),
            expected.len()
        );
    }
    save_figure(
        path,
        &WarpHistogram {
            title,
            observed,
            expected,
            res,
            p_value,
        },
    )
}

/// Draws a heat map over the projected hemisphere of the sample weight
/// `f·cos θi / pdf` (luminance of `f`) that `strategy` gives the direction at
/// the centre of each of `res × res` pixels, on a log colour scale with a
/// colour bar. This shows where a strategy's weights blow up (uniform
/// sampling of a sharp lobe, `D cos θh` sampling at grazing views).
///
/// Pixels where `pdf = 0` but `f > 0` (directions the strategy never
/// samples, a bias) are drawn red; pixels where `f = 0` grey; both are
/// noted in the legend. A white `+` marks the mirror direction of `wo`.
/// The scale spans at most 8 decades below the largest weight.
///
/// Writes an SVG if `path` ends in `.svg`, a PNG (640×600) if `.png`.
///
/// # Errors
///
/// `res == 0`, an unknown extension, or the file cannot be written.
pub fn weight_heatmap(
    path: &Path,
    title: &str,
    sampler: &BsdfSampler<'_>,
    wo: DVec3,
    res: usize,
) -> Result<()> {
    if res == 0 {
        bail!("weight_heatmap: res must be at least 1");
    }
    let pixels = weight_pixels(sampler, wo, res);
    save_figure(
        path,
        &WeightMap {
            title,
            pixels: &pixels,
            res,
            mirror: DVec2::new(-wo.x, -wo.y),
            mirror_below: wo.z < 0.0,
        },
    )
}

/// Pixels where `f > 0` but `pdf = 0`.
const UNSAMPLED: RGBColor = RGBColor(228, 26, 28);

/// Pixels where `f = 0`.
const ZERO_F: RGBColor = RGBColor(190, 190, 190);

/// Where a disk map goes: a `size`-pixel square at `(x0, y0)` of the area.
#[derive(Clone, Copy)]
struct MapBox {
    x0: i32,
    y0: i32,
    size: i32,
}

impl MapBox {
    /// Pixel of disk coordinates `(x, y)` (y up).
    fn to_px(self, x: f64, y: f64) -> (i32, i32) {
        let s = f64::from(self.size);
        (
            self.x0 + ((x + 1.0) * 0.5 * s).round() as i32,
            self.y0 + ((1.0 - y) * 0.5 * s).round() as i32,
        )
    }
}

/// Draws `colors` (a `res × res` grid, row 0 at the bottom, `None` left
/// blank) in `b`, the unit circle, ticks at −1, 0, 1 and the axis names.
fn draw_disk_map<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    b: MapBox,
    res: usize,
    colors: &[Option<RGBColor>],
) -> DResult<DB> {
    let edge = |k: usize| (k as i64 * i64::from(b.size) / res as i64) as i32;
    for j in 0..res {
        let top = b.y0 + b.size - edge(j + 1);
        let bottom = (b.y0 + b.size - edge(j)).max(top + 1);
        for i in 0..res {
            if let Some(c) = colors[j * res + i] {
                let left = b.x0 + edge(i);
                let right = (b.x0 + edge(i + 1)).max(left + 1);
                area.draw(&Rectangle::new([(left, top), (right, bottom)], c.filled()))?;
            }
        }
    }
    area.draw(&Rectangle::new(
        [(b.x0, b.y0), (b.x0 + b.size, b.y0 + b.size)],
        OUTLINE.mix(0.5).stroke_width(1),
    ))?;
    let circle: Vec<(i32, i32)> = (0..=256)
        .map(|k| {
            let a = std::f64::consts::TAU * f64::from(k) / 256.0;
            b.to_px(a.cos(), a.sin())
        })
        .collect();
    area.draw(&PathElement::new(circle, OUTLINE.stroke_width(1)))?;
    for v in [-1.0, 0.0, 1.0] {
        let (x, _) = b.to_px(v, 0.0);
        let (_, y) = b.to_px(0.0, v);
        let bottom = b.y0 + b.size;
        area.draw(&PathElement::new(
            vec![(x, bottom), (x, bottom + 4)],
            OUTLINE.stroke_width(1),
        ))?;
        area.draw(&PathElement::new(
            vec![(b.x0 - 4, y), (b.x0, y)],
            OUTLINE.stroke_width(1),
        ))?;
        let label = fmt_num(v);
        put_text(
            area,
            &label,
            (x, bottom + 6),
            12.0,
            DIM_TEXT,
            (HPos::Center, VPos::Top),
        )?;
        put_text(
            area,
            &label,
            (b.x0 - 6, y),
            12.0,
            DIM_TEXT,
            (HPos::Right, VPos::Center),
        )?;
    }
    let (xm, _) = b.to_px(0.5, 0.0);
    put_text(
        area,
        "x",
        (xm, b.y0 + b.size + 6),
        13.0,
        TEXT,
        (HPos::Center, VPos::Top),
    )?;
    let (_, ym) = b.to_px(0.0, 0.5);
    put_text(
        area,
        "y",
        (b.x0 - 6, ym),
        13.0,
        TEXT,
        (HPos::Right, VPos::Center),
    )?;
    Ok(())
}

struct WarpHistogram<'a> {
    title: &'a str,
    observed: &'a [f64],
    expected: &'a [f64],
    res: usize,
    p_value: f64,
}

impl Figure for WarpHistogram<'_> {
    fn size(&self) -> (u32, u32) {
        if self.observed.len() > self.res * self.res {
            HISTOGRAM_SPHERE_SIZE
        } else {
            HISTOGRAM_SIZE
        }
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DResult<DB> {
        root.fill(&WHITE)?;
        let verdict = if self.p_value > PASS_LEVEL {
            "PASS"
        } else {
            "FAIL"
        };
        let title = format!(
            "{}: χ² p = {} → {verdict} (at {} %)",
            self.title,
            fmt_p(self.p_value),
            PASS_LEVEL * 100.0
        );
        let title_h = draw_title(root, &title, 19.0)?;
        let res = self.res;
        let vmax = self
            .observed
            .iter()
            .chain(self.expected)
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        let vmax = if vmax > 0.0 { vmax } else { 1.0 };
        // Pixels whose centre is in the disk, or that hold any count.
        let rows = self.observed.len() / (res * res);
        let colors = |grid: &[f64], other: &[f64]| -> Vec<Option<RGBColor>> {
            (0..res * res)
                .map(|k| {
                    let (i, j) = (k % res, k / res);
                    let x = -1.0 + (i as f64 + 0.5) * 2.0 / res as f64;
                    let y = -1.0 + (j as f64 + 0.5) * 2.0 / res as f64;
                    (x * x + y * y < 1.0 || grid[k] > 0.0 || other[k] > 0.0)
                        .then(|| viridis(grid[k] / vmax))
                })
                .collect()
        };
        let (_, h) = root.dim_in_pixel();
        let label_h = 22;
        let (w, _) = root.dim_in_pixel();
        // Room for the tick labels at the left, the gap, and the colour bar.
        let ticks = linear_ticks(vmax);
        let bar_w = colorbar_extent(16, &ticks);
        // Room for the tick labels at the left, the gap, and the colour bar.
        let rows_i = rows as i32;
        let size = ((h as i32 - title_h - rows_i * (label_h + 34)) / rows_i)
            .min((w as i32 - 44 - 50 - 24 - bar_w - 8) / 2);
        let top = title_h + label_h;
        let n = res * res;
        for (row, hemisphere) in HEMISPHERES.iter().enumerate().take(rows) {
            let y0 = top + row as i32 * (size + label_h + 34);
            let left = MapBox { x0: 44, y0, size };
            let right = MapBox {
                x0: left.x0 + size + 50,
                y0,
                size,
            };
            let (obs, exp) = (
                &self.observed[row * n..(row + 1) * n],
                &self.expected[row * n..(row + 1) * n],
            );
            let side = if rows > 1 {
                format!(", {hemisphere}")
            } else {
                String::new()
            };
            for (b, name, grid, other) in [
                (left, format!("observed samples{side}"), obs, exp),
                (
                    right,
                    format!("expected (samples × ∫ pdf dω){side}"),
                    exp,
                    obs,
                ),
            ] {
                put_text(
                    root,
                    &name,
                    (b.x0 + size / 2, y0 - 4),
                    fit_size(&name, 15.0, size + 40),
                    TEXT,
                    (HPos::Center, VPos::Bottom),
                )?;
                draw_disk_map(root, b, res, &colors(grid, other))?;
            }
        }
        let right_x0 = 44 + size + 50;
        draw_colorbar(
            root,
            (right_x0 + size + 24, top),
            (16, size),
            Orientation::Vertical {
                name: &format!("samples per pixel ({res}×{res} pixels)"),
            },
            &ticks,
        )?;
        Ok(())
    }
}

struct WeightMap<'a> {
    title: &'a str,
    pixels: &'a [WeightPixel],
    res: usize,
    mirror: DVec2,
    /// `wo` is below the surface (its mirror direction too).
    mirror_below: bool,
}

impl Figure for WeightMap<'_> {
    fn size(&self) -> (u32, u32) {
        if self.pixels.len() > self.res * self.res {
            WEIGHTS_SPHERE_SIZE
        } else {
            WEIGHTS_SIZE
        }
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DResult<DB> {
        root.fill(&WHITE)?;
        let title_h = draw_title(root, self.title, 18.0)?;
        let weights = || {
            self.pixels.iter().filter_map(|p| match p {
                WeightPixel::Weight(w) if w.is_finite() => Some(*w),
                _ => None,
            })
        };
        let (wmin, wmax) = weights().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), w| {
            (a.min(w), b.max(w))
        });
        let (mut lo, mut hi) = if wmin <= wmax {
            (wmin.log10(), wmax.log10())
        } else {
            (-1.0, 1.0)
        };
        let clipped = hi - lo > 8.0;
        if clipped {
            lo = (hi - 8.0).ceil();
        }
        if hi - lo < 0.2 {
            let c = 0.5 * (hi + lo);
            (lo, hi) = (c - 0.5, c + 0.5);
        }
        let colors: Vec<Option<RGBColor>> = self
            .pixels
            .iter()
            .map(|p| match *p {
                WeightPixel::Outside => None,
                WeightPixel::ZeroF => Some(ZERO_F),
                WeightPixel::Unsampled => Some(UNSAMPLED),
                WeightPixel::Weight(w) if w.is_finite() => {
                    Some(viridis((w.log10() - lo) / (hi - lo)))
                }
                WeightPixel::Weight(_) => Some(UNSAMPLED),
            })
            .collect();
        let mut ticks = log_ticks(lo, hi);
        if clipped {
            // The bottom colour also holds every smaller weight.
            match ticks.first_mut() {
                Some(first) if first.0 < 0.04 => first.1 = format!("≤ {}", first.1),
                _ => ticks.insert(0, (0.0, format!("≤ {}", fmt_num(10f64.powf(lo))))),
            }
        }
        let (w, h) = root.dim_in_pixel();
        let legend_h = 44;
        let bar_w = colorbar_extent(16, &ticks);
        let n = self.res * self.res;
        let cols = (self.pixels.len() / n) as i32;
        let label_h = if cols > 1 { 22 } else { 0 };
        let size = (h as i32 - title_h - label_h - legend_h - 30)
            .min((w as i32 - 44 - 24 - bar_w - 8 - (cols - 1) * 50) / cols);
        let boxes: Vec<MapBox> = (0..cols)
            .map(|c| MapBox {
                x0: 44 + c * (size + 50),
                y0: title_h + 4 + label_h,
                size,
            })
            .collect();
        for (c, b) in boxes.iter().enumerate() {
            draw_disk_map(root, *b, self.res, &colors[c * n..(c + 1) * n])?;
            if cols > 1 {
                put_text(
                    root,
                    HEMISPHERES[c],
                    (b.x0 + size / 2, b.y0 - 4),
                    15.0,
                    TEXT,
                    (HPos::Center, VPos::Bottom),
                )?;
            }
        }
        let b = boxes[0];
        let last = boxes[boxes.len() - 1];

        // The mirror direction of wo, on the side of wo.
        let mb = if self.mirror_below { last } else { b };
        let (mx, my) = mb.to_px(self.mirror.x, self.mirror.y);
        for (c, wd) in [(BLACK, 4), (WHITE, 2)] {
            root.draw(&PathElement::new(
                vec![(mx - 7, my), (mx + 7, my)],
                c.stroke_width(wd),
            ))?;
            root.draw(&PathElement::new(
                vec![(mx, my - 7), (mx, my + 7)],
                c.stroke_width(wd),
            ))?;
        }

        draw_colorbar(
            root,
            (last.x0 + size + 24, b.y0),
            (16, size),
            Orientation::Vertical {
                name: "weight f·|cos θi| / pdf (log scale)",
            },
            &ticks,
        )?;

        // Legend and range.
        let unsampled = self
            .pixels
            .iter()
            .filter(|p| **p == WeightPixel::Unsampled)
            .count();
        let zero_f = self
            .pixels
            .iter()
            .filter(|p| **p == WeightPixel::ZeroF)
            .count();
        let y1 = b.y0 + size + 30;
        let mut x = b.x0;
        let swatch = |x: i32, y: i32, c: RGBColor| -> DResult<DB> {
            root.draw(&Rectangle::new([(x, y - 6), (x + 12, y + 6)], c.filled()))?;
            root.draw(&Rectangle::new(
                [(x, y - 6), (x + 12, y + 6)],
                OUTLINE.stroke_width(1),
            ))
        };
        swatch(x, y1, UNSAMPLED)?;
        let s = if unsampled > 0 {
            format!("f > 0 but pdf = 0 (never sampled): {unsampled} px")
        } else {
            "f > 0 but pdf = 0 (never sampled): none".to_string()
        };
        put_text(
            root,
            &s,
            (x + 18, y1),
            13.0,
            TEXT,
            (HPos::Left, VPos::Center),
        )?;
        x += 18 + text_width(&s, 13.0) + 18;
        swatch(x, y1, ZERO_F)?;
        let s = format!("f = 0: {zero_f} px");
        put_text(
            root,
            &s,
            (x + 18, y1),
            13.0,
            TEXT,
            (HPos::Left, VPos::Center),
        )?;
        let y2 = y1 + 20;
        let range = if wmin <= wmax {
            format!(
                "+ mirror direction of wo;  weights from {} to {} at pixel centres",
                fmt_num(wmin),
                fmt_num(wmax)
            )
        } else {
            "+ mirror direction of wo;  no pixel with a finite weight".to_string()
        };
        put_text(
            root,
            &range,
            (b.x0, y2),
            13.0,
            TEXT,
            (HPos::Left, VPos::Center),
        )?;
        Ok(())
    }
}
