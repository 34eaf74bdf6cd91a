//! The convergence plot: RMSE against the number of samples on log-log
//! axes, one panel per sample sequence, one colour per strategy.

use crate::draw::strategy_color;
use crate::draw::{
    DIM_TEXT, DResult, Figure, GRID, LIGHT_GRID, TEXT, fit_size, font, power_label, put_text,
    save_figure,
};
use anyhow::Result;
use plotters::coord::Shift;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use std::path::Path;

/// One curve of a convergence plot.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// The strategy: it chooses the colour, the same in every panel.
    pub strategy: String,
    /// The sample sequence: it chooses the panel, the line style and the
    /// marker.
    pub sequence: String,
    /// `(N, RMSE)` pairs. Points with `N ≤ 0` or `RMSE ≤ 0` (or not finite)
    /// cannot go on log axes and are left out.
    pub points: Vec<(f64, f64)>,
    /// Fitted slope of `log RMSE` against `log N` (−1/2 for a Monte Carlo
    /// estimator with finite variance), shown in the legend when given.
    pub slope: Option<f64>,
}

/// Draws RMSE against the number of samples on log-log axes (`log₂ N` on x,
/// `log₁₀ RMSE` on y) as small multiples: one panel per sample sequence
/// (up to three side by side, on shared axes), one colour per strategy (the
/// same strategy has the same colour in every panel and every figure), one
/// line style and marker per sequence, a dashed grey line of slope −1/2 in
/// each panel, and under each panel, outside its plotting area, a legend of
/// its curves with their fitted slopes. The image grows with the number of
/// panels and of curves per panel, so that every label fits.
///
/// Writes an SVG if `path` ends in `.svg`, a PNG if it ends in `.png`.
/// Series without any plottable point (e.g. RMSE = 0 everywhere, as for a
/// zero-variance estimator) are listed in the legend as not shown.
///
/// # Errors
///
/// An unknown extension, or the file cannot be written.
pub fn convergence_plot(path: &Path, title: &str, series: &[Series]) -> Result<()> {
    save_figure(path, &Convergence { title, series })
}

/// A linear f64 axis whose tick marks (bold) and minor grid lines (light)
/// are given, in the coordinates of the axis.
struct TickedAxis {
    range: std::ops::Range<f64>,
    bold: Vec<f64>,
    light: Vec<f64>,
}

impl Ranged for TickedAxis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let t = (value - self.range.start) / (self.range.end - self.range.start);
        limit.0 + (t * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.light.clone()
        } else {
            self.bold.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.range.clone()
    }
}

struct Convergence<'a> {
    title: &'a str,
    series: &'a [Series],
}

/// Plot area of one panel of a convergence figure (axes included).
const PANEL_W: i32 = 430;

/// Plot area of a convergence figure with one panel.
const SINGLE_PANEL_W: i32 = 700;

const PANEL_H: i32 = 380;

/// Height of one legend entry.
const ENTRY_H: i32 = 21;

/// Height of the title and the key line under it.
const CONVERGENCE_HEADER_H: i32 = 66;

/// Panels side by side at most.
const PANELS_PER_ROW: usize = 3;

/// The panels (sequences, in order of first appearance) and the series of
/// each (indices into the series).
fn panels(series: &[Series]) -> Vec<(String, Vec<usize>)> {
    let mut out: Vec<(String, Vec<usize>)> = Vec::new();
    for (k, s) in series.iter().enumerate() {
        match out.iter_mut().find(|(q, _)| *q == s.sequence) {
            Some((_, v)) => v.push(k),
            None => out.push((s.sequence.clone(), vec![k])),
        }
    }
    out
}

/// The outline, in pixel offsets, of marker shape `k % 4`: a disk (a
/// 12-gon), a triangle, a square, a diamond.
fn marker_shape(k: usize) -> Vec<(i32, i32)> {
    match k % 4 {
        0 => (0..12)
            .map(|i| {
                let a = std::f64::consts::TAU * f64::from(i) / 12.0;
                (
                    (4.5 * a.cos()).round() as i32,
                    (4.5 * a.sin()).round() as i32,
                )
            })
            .collect(),
        1 => vec![(0, -6), (5, 3), (-5, 3)],
        2 => vec![(-4, -4), (4, -4), (4, 4), (-4, 4)],
        _ => vec![(0, -6), (5, 0), (0, 6), (-5, 0)],
    }
}

/// The dash length and gap of the line of panel (sequence) `k`: solid,
/// dashed, dotted, dash-dot-like.
fn dash(k: usize) -> Option<(u32, u32)> {
    match k % 4 {
        0 => None,
        1 => Some((9, 5)),
        2 => Some((2, 4)),
        _ => Some((14, 4)),
    }
}

/// Draws `pts` (in chart coordinates) as a line in the style of sequence `k`.
fn styled_line<DB: DrawingBackend, X: Ranged<ValueType = f64>, Y: Ranged<ValueType = f64>>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    pts: &[(f64, f64)],
    color: RGBColor,
    k: usize,
) -> DResult<DB> {
    match dash(k) {
        None => {
            chart.draw_series(LineSeries::new(pts.iter().copied(), color.stroke_width(2)))?;
        }
        Some((size, gap)) => {
            chart.draw_series(DashedLineSeries::new(
                pts.iter().copied(),
                size,
                gap,
                color.stroke_width(2),
            ))?;
        }
    }
    Ok(())
}

impl Convergence<'_> {
    /// Columns and rows of panels, the width of a panel and the height of a
    /// panel's legend.
    fn grid(&self) -> (usize, usize, i32, i32) {
        let panels = panels(self.series);
        let n = panels.len().max(1);
        let cols = n.min(PANELS_PER_ROW);
        let rows = n.div_ceil(PANELS_PER_ROW);
        let w = if n == 1 { SINGLE_PANEL_W } else { PANEL_W };
        let entries = panels.iter().map(|(_, v)| v.len()).max().unwrap_or(0) as i32;
        (cols, rows, w, entries * ENTRY_H + 14)
    }
}

/// The x and y ranges (log₂ N, log₁₀ RMSE), rounded out to whole units,
/// over every plotted point.
fn log_ranges(logged: &[Vec<(f64, f64)>]) -> ((f64, f64), (f64, f64)) {
    let all: Vec<(f64, f64)> = logged.iter().flatten().copied().collect();
    let (mut x0, mut x1, mut y0, mut y1) = (0.0f64, 20.0f64, -6.0f64, 0.0f64);
    if !all.is_empty() {
        x0 = all.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
        x1 = all.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
        y0 = all.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
        y1 = all.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    }
    let (xa, mut xb) = (x0.floor(), x1.ceil());
    if xb < xa + 1.0 {
        xb = xa + 1.0;
    }
    let (ya, mut yb) = (y0.floor(), y1.ceil());
    if yb < ya + 1.0 {
        yb = ya + 1.0;
    }
    ((xa, xb), (ya, yb))
}

impl Figure for Convergence<'_> {
    fn size(&self) -> (u32, u32) {
        let (cols, rows, w, legend_h) = self.grid();
        (
            (cols as i32 * w + 24) as u32,
            (CONVERGENCE_HEADER_H + rows as i32 * (PANEL_H + legend_h) + 8) as u32,
        )
    }

    #[allow(clippy::too_many_lines)]
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DResult<DB> {
        root.fill(&WHITE)?;
        let (width, _) = root.dim_in_pixel();
        let title_size = fit_size(self.title, 22.0, width as i32 - 30);
        put_text(
            root,
            self.title,
            (width as i32 / 2, 8),
            title_size,
            TEXT,
            (HPos::Center, VPos::Top),
        )?;
        let key = "one panel per sample sequence, one colour per strategy; \
                   grey dashes: slope −1/2 (RMSE ∝ 1/√N, plain Monte Carlo)";
        let key_size = fit_size(key, 15.0, width as i32 - 30);
        put_text(
            root,
            key,
            (width as i32 / 2, 40),
            key_size,
            DIM_TEXT,
            (HPos::Center, VPos::Top),
        )?;

        let logged: Vec<Vec<(f64, f64)>> = self
            .series
            .iter()
            .map(|s| {
                s.points
                    .iter()
                    .filter(|&&(n, e)| n.is_finite() && n > 0.0 && e.is_finite() && e > 0.0)
                    .map(|&(n, e)| (n.log2(), e.log10()))
                    .collect()
            })
            .collect();
        let ((xa, xb), (ya, yb)) = log_ranges(&logged);
        let y_pad = 0.04 * (yb - ya);
        let x_range = (xa - 0.3)..(xb + 0.3);
        let y_range = (ya - y_pad)..(yb + y_pad);
        let x_step = ((xb - xa) / 8.0).ceil().max(1.0);
        let x_ticks: Vec<f64> = (0..)
            .map(|k| (xa / x_step).ceil() * x_step + f64::from(k) * x_step)
            .take_while(|&x| x <= xb + 1e-9)
            .collect();
        let y_step = ((yb - ya) / 10.0).ceil().max(1.0);
        let y_ticks: Vec<f64> = (0..)
            .map(|k| (ya / y_step).ceil() * y_step + f64::from(k) * y_step)
            .take_while(|&y| y <= yb + 1e-9)
            .collect();
        let y_light: Vec<f64> = ((ya as i64)..(yb as i64))
            .flat_map(|d| (1..10).map(move |m| d as f64 + f64::log10(f64::from(m))))
            .collect();

        let (_, _, panel_w, legend_h) = self.grid();
        let mut panels = panels(self.series);
        if panels.is_empty() {
            panels.push((String::new(), Vec::new()));
        }
        let names: Vec<&str> = self.series.iter().map(|s| s.strategy.as_str()).collect();
        for (p, (sequence, members)) in panels.iter().enumerate() {
            let (col, row) = ((p % PANELS_PER_ROW) as i32, (p / PANELS_PER_ROW) as i32);
            let x0 = 12 + col * panel_w;
            let y0 = CONVERGENCE_HEADER_H + row * (PANEL_H + legend_h);
            let (fw, fh) = root.dim_in_pixel();
            let area = root.margin(y0, fh as i32 - y0 - PANEL_H, x0, fw as i32 - x0 - panel_w);
            let caption = if sequence.is_empty() {
                String::new()
            } else {
                format!("{sequence} samples")
            };
            let mut chart = ChartBuilder::on(&area)
                .caption(caption, font(17.0).color(&TEXT))
                .margin(6)
                .margin_right(16)
                .x_label_area_size(44)
                .y_label_area_size(62)
                .build_cartesian_2d(
                    TickedAxis {
                        range: x_range.clone(),
                        bold: x_ticks.clone(),
                        light: Vec::new(),
                    },
                    TickedAxis {
                        range: y_range.clone(),
                        bold: y_ticks.clone(),
                        light: y_light.clone(),
                    },
                )?;
            chart
                .configure_mesh()
                .x_desc("samples N")
                .y_desc("RMSE")
                .x_label_formatter(&|v| power_label(2, *v))
                .y_label_formatter(&|v| power_label(10, *v))
                .label_style(font(14.0).color(&TEXT))
                .axis_desc_style(font(15.0).color(&TEXT))
                .bold_line_style(GRID)
                .light_line_style(LIGHT_GRID)
                .draw()?;
            if members.is_empty() {
                let (pw, ph) = chart.plotting_area().dim_in_pixel();
                let base = chart.plotting_area().get_base_pixel();
                put_text(
                    root,
                    "no data",
                    (base.0 + pw as i32 / 2, base.1 + ph as i32 / 2),
                    18.0,
                    DIM_TEXT,
                    (HPos::Center, VPos::Center),
                )?;
                continue;
            }

            // Slope −1/2 through the first plotted point of the panel,
            // clipped to the plotting range.
            if let Some(&(ax, ay)) = members.iter().find_map(|&k| logged[k].first()) {
                let slope = -0.5 * std::f64::consts::LOG10_2;
                let x_at = |y: f64| ax + (y - ay) / slope;
                let lo = x_range.start.max(x_at(y_range.end));
                let hi = x_range.end.min(x_at(y_range.start));
                if lo < hi {
                    chart.draw_series(DashedLineSeries::new(
                        [(lo, ay + slope * (lo - ax)), (hi, ay + slope * (hi - ax))],
                        8,
                        6,
                        RGBColor(150, 150, 150).stroke_width(2),
                    ))?;
                }
            }
            for &k in members {
                let color = strategy_color(&names, k);
                styled_line(&mut chart, &logged[k], color, p)?;
                chart.draw_series(logged[k].iter().map(|&pt| {
                    EmptyElement::at(pt) + Polygon::new(marker_shape(p), color.filled())
                }))?;
            }

            // The legend under the panel, outside the plotting area.
            let base = chart.plotting_area().get_base_pixel();
            let lx = base.0 + 4;
            let mut ly = y0 + PANEL_H + 4;
            for &k in members {
                let s = &self.series[k];
                let color = strategy_color(&names, k);
                let cy = ly + ENTRY_H / 2;
                let seg = [(lx, cy), (lx + 30, cy)];
                match dash(p) {
                    None => root.draw(&PathElement::new(seg.to_vec(), color.stroke_width(2)))?,
                    Some((size, gap)) => {
                        let mut x = lx;
                        while x < lx + 30 {
                            let x1 = (x + size as i32).min(lx + 30);
                            root.draw(&PathElement::new(
                                vec![(x, cy), (x1, cy)],
                                color.stroke_width(2),
                            ))?;
                            x = x1 + gap as i32;
                        }
                    }
                }
                root.draw(
                    &(EmptyElement::at((lx + 15, cy))
                        + Polygon::new(marker_shape(p), color.filled())),
                )?;
                let text = match (logged[k].is_empty(), s.slope) {
                    (true, _) if s.points.iter().all(|p| p.1 == 0.0) => {
                        format!("{}: RMSE 0 (exact), not shown", s.strategy)
                    }
                    (true, _) => format!("{}: no point with RMSE > 0, not shown", s.strategy),
                    (false, Some(m)) if m.is_finite() => format!(
                        "{}   slope {}",
                        s.strategy,
                        format!("{m:+.2}").replace('-', "−")
                    ),
                    (false, _) => s.strategy.clone(),
                };
                put_text(
                    root,
                    &text,
                    (lx + 40, cy),
                    15.0,
                    TEXT,
                    (HPos::Left, VPos::Center),
                )?;
                ly += ENTRY_H;
            }
        }
        Ok(())
    }
}
