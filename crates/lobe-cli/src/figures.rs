//! Figures drawn with plotters: convergence plots, polar plots of a BRDF,
//! warp-test histograms and sample-weight heat maps.
//!
//! Every function writes one file and chooses the format from its extension:
//! `.png` (a bitmap at a size meant to be read on screen) or `.svg`. The text
//! is drawn with DejaVu Sans, embedded in the binary, so no font has to be
//! installed where the figures are made.
//!
//! Heat maps are drawn over the *projected hemisphere*: the unit disk of the
//! `(x, y)` coordinates of `wi` in the local frame (`+z` is the normal), `x`
//! to the right and `y` up. With `wo = (sin θo, 0, cos θo)` the viewer is on
//! the right and the mirror direction on the left.

use crate::draw::{
    DIM_TEXT, DResult, Figure, GRID, LIGHT_GRID, OUTLINE, Orientation, TEXT, colorbar_extent,
    draw_colorbar, draw_title, fit_size, fmt_num, fmt_p, font, linear_ticks, log_ticks,
    power_label, put_text, save_figure, text_style, text_width, viridis,
};
use anyhow::{Result, bail};
use glam::{DVec2, DVec3};
use lobe::BsdfSampler;
use lobe::experiment::histogram::{WeightPixel, weight_pixels};
use lobe::experiment::polar::{CurveKind, PolarCurves};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use std::path::Path;

/// Size in pixels of a polar plot.
pub const POLAR_SIZE: (u32, u32) = (800, 500);
/// Size in pixels of a warp-test histogram (two maps side by side).
pub const HISTOGRAM_SIZE: (u32, u32) = (800, 400);
/// Size in pixels of a sample-weight heat map.
pub const WEIGHTS_SIZE: (u32, u32) = (640, 600);

/// Significance level of the pass/fail word of [`warp_histogram`]: the test
/// passes when `p_value > PASS_LEVEL` (Nori's warp test uses 1 %).
pub const PASS_LEVEL: f64 = 0.01;

// ---------------------------------------------------------------------------
// Public API
// ---------------------------------------------------------------------------

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

/// Draws curves in the plane of incidence on one polar plot: the upper half
/// disk, the angle θi measured from the normal (straight up), negative
/// angles on the mirror side (left), positive on the viewer's side (right),
/// with a ray toward the viewer at θi = +θo: each direction on the side of
/// its own `x`, as in the warp-test histogram and the weight heat map
/// ([`lobe::experiment::polar::figure_xy`]). Every curve is drawn on the
/// same radial scale (`scale`), so that a pdf can be read against the
/// integrand `f·cos θi / albedo` (cosine included): where the pdf lies
/// inside the integrand, samples are rare and their weights large. The
/// integrand is drawn thick and dark, each pdf in its strategy's colour;
/// the legend (beside the plot) gives each curve's maximum in 1/sr.
/// Negative or non-finite values are drawn as zero.
///
/// Writes an SVG if `path` ends in `.svg`, a PNG (800×500) if `.png`.
///
/// # Errors
///
/// An unknown extension, or the file cannot be written.
pub fn polar_plot(path: &Path, title: &str, curves: &PolarCurves, scale: PolarScale) -> Result<()> {
    save_figure(
        path,
        &Polar {
            title,
            curves,
            scale,
        },
    )
}

/// How [`polar_plot`] turns values (1/sr) into radii; one scale serves
/// every curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PolarScale {
    /// The radius is the value over the maximum of all curves.
    Linear,
    /// The radius is `1 + log₁₀(value / maximum) / POLAR_DECADES`: the
    /// outer ring is the maximum of all curves, the centre
    /// [`POLAR_DECADES`] decades below it. Shows a diffuse term or a
    /// pdf's tail next to a sharp peak.
    Log,
}

/// Decades shown by [`PolarScale::Log`].
pub const POLAR_DECADES: f64 = 4.0;

impl std::str::FromStr for PolarScale {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "linear" => Ok(PolarScale::Linear),
            "log" => Ok(PolarScale::Log),
            _ => Err(format!("unknown scale '{s}', expected linear or log")),
        }
    }
}

/// Draws Nori's warp-test picture: the observed and the expected sample
/// counts over the projected hemisphere as two square heat maps side by
/// side, on the same linear colour scale (with a colour bar), and the
/// chi-square `p_value` with the word PASS or FAIL (`p > PASS_LEVEL`)
/// appended to `title`.
///
/// `observed` and `expected` are `res × res` grids laid out as
/// [`lobe::experiment::histogram::projected_histograms`] returns them.
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
    if res == 0 || observed.len() != res * res || expected.len() != res * res {
        bail!(
            "warp_histogram: the grids must hold res² = {}² values (got {} and {})",
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
        },
    )
}

/// Pixels where `f > 0` but `pdf = 0`.
const UNSAMPLED: RGBColor = RGBColor(228, 26, 28);
/// Pixels where `f = 0`.
const ZERO_F: RGBColor = RGBColor(190, 190, 190);

// ---------------------------------------------------------------------------
// Convergence plot
// ---------------------------------------------------------------------------

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

/// The names whose colour is fixed, so that a strategy has the same colour
/// in every figure: every strategy lobe knows, in [`lobe::Strategy::all`] order.
fn strategy_order() -> Vec<String> {
    lobe::Strategy::all().iter().map(|s| s.name()).collect()
}

/// Twelve colours that stay apart: Okabe–Ito's seven (yellow left out),
/// then purple, brown, crimson, olive and indigo.
const STRATEGY_PALETTE: [RGBColor; 12] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(117, 60, 160),
    RGBColor(140, 86, 40),
    RGBColor(170, 30, 60),
    RGBColor(110, 130, 0),
    RGBColor(50, 50, 140),
];

/// The colour of the strategy `names[k]`: fixed for the known names, else
/// the next colour after them in order of first appearance.
fn strategy_color(names: &[&str], k: usize) -> RGBColor {
    let name = names[k];
    let order = strategy_order();
    if let Some(i) = order.iter().position(|n| n == name) {
        return STRATEGY_PALETTE[i];
    }
    let mut unknown: Vec<&str> = Vec::new();
    for n in names {
        if !order.iter().any(|o| o == n) && !unknown.contains(n) {
            unknown.push(n);
        }
    }
    let i = unknown.iter().position(|n| *n == name).unwrap_or(0);
    STRATEGY_PALETTE[(order.len() + i) % STRATEGY_PALETTE.len()]
}

// ---------------------------------------------------------------------------
// Polar plot
// ---------------------------------------------------------------------------

struct Polar<'a> {
    title: &'a str,
    curves: &'a PolarCurves,
    scale: PolarScale,
}

/// Columns of the legend above a polar plot, and the height of a row.
const POLAR_LEGEND_COLS: usize = 3;
const POLAR_LEGEND_ROW_H: i32 = 22;

impl Figure for Polar<'_> {
    fn size(&self) -> (u32, u32) {
        POLAR_SIZE
    }

    #[allow(clippy::too_many_lines)]
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DResult<DB> {
        use std::f64::consts::FRAC_PI_2;
        root.fill(&WHITE)?;
        let curves = self.curves.all();
        let max = curves.iter().map(|c| c.max()).fold(0.0, f64::max);
        let radius = |v: f64| -> f64 {
            if !(v.is_finite() && v > 0.0 && max > 0.0) {
                return 0.0;
            }
            match self.scale {
                PolarScale::Linear => v / max,
                PolarScale::Log => (1.0 + (v / max).log10() / POLAR_DECADES).max(0.0),
            }
        };
        // The value on ring r.
        let ring_value = |r: f64| match self.scale {
            PolarScale::Linear => r * max,
            PolarScale::Log => max * 10f64.powf((r - 1.0) * POLAR_DECADES),
        };

        let title_h = draw_title(root, self.title, 20.0)?;
        let (w, h) = root.dim_in_pixel();
        let caption = match self.scale {
            PolarScale::Linear => format!(
                "radius ∝ value in 1/sr, one scale for all curves (outer ring {}); albedo {}",
                fmt_num(max),
                fmt_num(self.curves.albedo)
            ),
            PolarScale::Log => format!(
                "radius = log of the value in 1/sr, one scale for all curves: {} decades, outer ring {}; albedo {}",
                POLAR_DECADES,
                fmt_num(max),
                fmt_num(self.curves.albedo)
            ),
        };
        let csize = fit_size(&caption, 14.0, w as i32 - 30);
        put_text(
            root,
            &caption,
            (w as i32 / 2, h as i32 - 8),
            csize,
            DIM_TEXT,
            (HPos::Center, VPos::Bottom),
        )?;

        // Equal scale in x and y: fit [−1.14, 1.14] × [−0.12, 1.1] under
        // the legend, centred.
        let legend_rows = curves.len().div_ceil(POLAR_LEGEND_COLS) as i32;
        let legend_h = legend_rows * POLAR_LEGEND_ROW_H + 8;
        let area = root.margin(title_h + legend_h, 30, 6, 6);
        let (aw, ah) = area.dim_in_pixel();
        let s = (f64::from(aw) / 2.28).min(f64::from(ah) / 1.22);
        let half_w = f64::from(aw) / (2.0 * s);
        let y_lo = -0.12 - 0.5 * (f64::from(ah) / s - 1.22);
        let y_hi = y_lo + f64::from(ah) / s;
        let mut chart = ChartBuilder::on(&area).build_cartesian_2d(-half_w..half_w, y_lo..y_hi)?;

        let polar = lobe::experiment::polar::figure_xy;
        // Rings, rays and their labels.
        for (i, r) in [0.25, 0.5, 0.75, 1.0].into_iter().enumerate() {
            let ring: Vec<(f64, f64)> = (0..=180)
                .map(|k| polar(-FRAC_PI_2 + std::f64::consts::PI * f64::from(k) / 180.0, r))
                .collect();
            let color = if i == 3 {
                RGBColor(150, 150, 150)
            } else {
                GRID
            };
            chart.draw_series(LineSeries::new(ring, color.stroke_width(1)))?;
            if max > 0.0 {
                chart.draw_series(std::iter::once(Text::new(
                    fmt_num(ring_value(r)),
                    (-r + 0.012, 0.012),
                    text_style(11.0, DIM_TEXT, HPos::Left, VPos::Bottom),
                )))?;
            }
        }
        for deg in (-75..=75).step_by(15) {
            let t = f64::from(deg).to_radians();
            let color = if deg % 30 == 0 { GRID } else { LIGHT_GRID };
            chart.draw_series(LineSeries::new(
                [(0.0, 0.0), polar(t, 1.0)],
                color.stroke_width(1),
            ))?;
        }
        for deg in (-90i32..=90).step_by(30) {
            let t = f64::from(deg).to_radians();
            let label = format!("{deg}°").replace('-', "−");
            let (pos, anchor) = match deg {
                -90 => ((-1.03, 0.015), (HPos::Right, VPos::Bottom)),
                90 => ((1.03, 0.015), (HPos::Left, VPos::Bottom)),
                0 => (polar(t, 1.05), (HPos::Center, VPos::Bottom)),
                d if d < 0 => (polar(t, 1.04), (HPos::Right, VPos::Bottom)),
                _ => (polar(t, 1.04), (HPos::Left, VPos::Bottom)),
            };
            let (h, v) = anchor;
            chart.draw_series(std::iter::once(Text::new(
                label,
                pos,
                text_style(13.0, DIM_TEXT, h, v),
            )))?;
        }
        // The surface, and which side is which.
        chart.draw_series(LineSeries::new(
            [(-1.12, 0.0), (1.12, 0.0)],
            BLACK.stroke_width(2),
        ))?;
        chart.draw_series([
            Text::new(
                "mirror side (θi < 0)",
                (-0.55, -0.03),
                text_style(13.0, DIM_TEXT, HPos::Center, VPos::Top),
            ),
            Text::new(
                "viewer's side (θi > 0)",
                (0.55, -0.03),
                text_style(13.0, DIM_TEXT, HPos::Center, VPos::Top),
            ),
        ])?;
        // The ray toward the viewer.
        let theta_o = self.curves.wo.z.clamp(-1.0, 1.0).acos();
        let view = polar(theta_o, 1.0);
        chart.draw_series(DashedLineSeries::new(
            [(0.0, 0.0), view],
            6,
            4,
            RGBColor(90, 90, 90).stroke_width(1),
        ))?;
        let (vx, vy) = polar(theta_o, 0.62);
        chart.draw_series(std::iter::once(Text::new(
            "wo",
            (vx + 0.02, vy),
            text_style(13.0, DIM_TEXT, HPos::Left, VPos::Center),
        )))?;

        let names: Vec<String> = curves
            .iter()
            .map(|c| match c.kind {
                CurveKind::Integrand => String::new(),
                CurveKind::Pdf(s) => s.name().to_string(),
            })
            .collect();
        let name_refs: Vec<&str> = names.iter().map(String::as_str).collect();
        let style = |k: usize| -> (RGBColor, u32) {
            match curves[k].kind {
                CurveKind::Integrand => (RGBColor(40, 40, 40), 4),
                CurveKind::Pdf(_) => (strategy_color(&name_refs, k), 2),
            }
        };
        // The integrand first (underneath), its area lightly filled.
        for (k, c) in curves.iter().enumerate() {
            let (color, width) = style(k);
            let xy: Vec<(f64, f64)> = c
                .points
                .iter()
                .filter(|(t, _)| t.is_finite())
                .map(|&(t, v)| polar(t.clamp(-FRAC_PI_2, FRAC_PI_2), radius(v)))
                .collect();
            if c.kind == CurveKind::Integrand {
                chart.draw_series(std::iter::once(Polygon::new(
                    xy.clone(),
                    RGBColor(40, 40, 40).mix(0.08).filled(),
                )))?;
            }
            chart.draw_series(LineSeries::new(xy, color.stroke_width(width)))?;
        }

        // The legend, above the plot in columns.
        let col_w = (w as i32 - 24) / POLAR_LEGEND_COLS as i32;
        for (k, c) in curves.iter().enumerate() {
            let (color, width) = style(k);
            let lx = 12 + (k % POLAR_LEGEND_COLS) as i32 * col_w;
            let ly = title_h + 6 + (k / POLAR_LEGEND_COLS) as i32 * POLAR_LEGEND_ROW_H;
            root.draw(&PathElement::new(
                vec![(lx, ly), (lx + 26, ly)],
                color.stroke_width(width),
            ))?;
            let label = match c.kind {
                CurveKind::Integrand => "f·cos θi ÷ albedo".to_string(),
                CurveKind::Pdf(s) => format!("pdf {s}"),
            };
            let text = format!("{label} (max {})", fmt_num(c.max()));
            let size = fit_size(&text, 14.0, col_w - 40);
            put_text(
                root,
                &text,
                (lx + 34, ly),
                size,
                TEXT,
                (HPos::Left, VPos::Center),
            )?;
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------
// Heat maps over the projected hemisphere
// ---------------------------------------------------------------------------

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
        HISTOGRAM_SIZE
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
        let size =
            (h as i32 - title_h - label_h - 34).min((w as i32 - 44 - 50 - 24 - bar_w - 8) / 2);
        let top = title_h + label_h;
        let left = MapBox {
            x0: 44,
            y0: top,
            size,
        };
        let right = MapBox {
            x0: left.x0 + size + 50,
            y0: top,
            size,
        };
        for (b, name, grid, other) in [
            (left, "observed samples", self.observed, self.expected),
            (
                right,
                "expected (samples × ∫ pdf dω)",
                self.expected,
                self.observed,
            ),
        ] {
            put_text(
                root,
                name,
                (b.x0 + size / 2, top - 4),
                15.0,
                TEXT,
                (HPos::Center, VPos::Bottom),
            )?;
            draw_disk_map(root, b, res, &colors(grid, other))?;
        }
        draw_colorbar(
            root,
            (right.x0 + size + 24, top),
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
}

impl Figure for WeightMap<'_> {
    fn size(&self) -> (u32, u32) {
        WEIGHTS_SIZE
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
        let size = (h as i32 - title_h - legend_h - 30).min(w as i32 - 44 - 24 - bar_w - 8);
        let b = MapBox {
            x0: 44,
            y0: title_h + 4,
            size,
        };
        draw_disk_map(root, b, self.res, &colors)?;

        // The mirror direction of wo.
        let (mx, my) = b.to_px(self.mirror.x, self.mirror.y);
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
            (b.x0 + size + 24, b.y0),
            (16, size),
            Orientation::Vertical {
                name: "weight f·cos θi / pdf (log scale)",
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

#[cfg(test)]
mod tests {
    use super::*;
    use lobe::{BsdfStrategy, Material};

    /// Draws every figure as PNG and SVG (into `LOBE_FIGURES_DIR` when set,
    /// to look at them).
    #[test]
    fn every_figure_renders() {
        let dir = std::env::var_os("LOBE_FIGURES_DIR").map_or_else(
            || std::env::temp_dir().join(format!("lobe-figures-{}", std::process::id())),
            Into::into,
        );
        std::fs::create_dir_all(&dir).unwrap();
        let curve = |c: f64, slope: f64| -> Vec<(f64, f64)> {
            (4..=20)
                .step_by(2)
                .map(|k| {
                    let n = f64::from(1u32 << k);
                    (n, c * n.powf(slope) * (1.0 + 0.1 * f64::from(k).sin()))
                })
                .collect()
        };
        let series = vec![
            Series {
                strategy: "uniform".into(),
                sequence: "independent".into(),
                points: curve(3.0, -0.5),
                slope: Some(-0.49),
            },
            Series {
                strategy: "brdf".into(),
                sequence: "independent".into(),
                points: curve(0.4, -0.5),
                slope: Some(-0.51),
            },
            Series {
                strategy: "vndf".into(),
                sequence: "independent".into(),
                points: curve(0.2, -0.5),
                slope: Some(-0.50),
            },
            Series {
                strategy: "heavy tail".into(),
                sequence: "independent".into(),
                points: curve(1.0, -0.3),
                slope: Some(-0.31),
            },
            Series {
                strategy: "cosine".into(),
                sequence: "independent".into(),
                points: vec![(16.0, 0.0), (1024.0, 0.0)],
                slope: None,
            },
        ];
        let m = Material::lambert(lobe::Rgb::splat(0.8)).unwrap();
        let wo = DVec3::new(0.5, 0.0, 0.75f64.sqrt());
        let h = lobe::experiment::histogram::projected_histograms(
            &m.sampler(BsdfStrategy::Cosine).unwrap(),
            wo,
            10_000,
            3,
            16,
            &(),
        );
        let (o, e) = (h.observed, h.expected);
        let polar = lobe::experiment::polar::curves(
            &m,
            wo,
            &[BsdfStrategy::Cosine, BsdfStrategy::Uniform],
            90,
        )
        .unwrap();
        // Many curves: nine strategies × three sequences.
        let mut many = Vec::new();
        for (q, sequence) in ["independent", "stratified", "sobol"].iter().enumerate() {
            for (k, strategy) in [
                "uniform",
                "cosine",
                "brdf",
                "vndf",
                "spherical-caps",
                "bounded-vndf",
                "light",
                "mis",
                "mis-power",
            ]
            .iter()
            .enumerate()
            {
                many.push(Series {
                    strategy: (*strategy).into(),
                    sequence: (*sequence).into(),
                    points: curve(0.2 + 0.3 * k as f64, -0.5 - 0.25 * q as f64),
                    slope: Some(-0.5 - 0.25 * q as f64),
                });
            }
        }
        for ext in ["png", "svg"] {
            let p = |name: &str| dir.join(format!("{name}.{ext}"));
            convergence_plot(
                &p("convergence"),
                "RMSE of the furnace estimate, GGX α = 0.3, θo = 60°",
                &series,
            )
            .unwrap();
            convergence_plot(&p("convergence-empty"), "no data", &[]).unwrap();
            convergence_plot(&p("convergence-many"), "27 curves", &many).unwrap();
            polar_plot(&p("polar"), "polar", &polar, PolarScale::Linear).unwrap();
            polar_plot(&p("polar-log"), "polar, log", &polar, PolarScale::Log).unwrap();
            warp_histogram(&p("histogram"), "cosine", &o, &e, 16, 0.5).unwrap();
            weight_heatmap(
                &p("weights"),
                "weights",
                &m.sampler(BsdfStrategy::Uniform).unwrap(),
                wo,
                16,
            )
            .unwrap();
            for name in [
                "convergence",
                "convergence-empty",
                "convergence-many",
                "polar",
                "polar-log",
                "histogram",
                "weights",
            ] {
                assert!(
                    std::fs::metadata(p(name)).unwrap().len() > 1000,
                    "{name}.{ext}"
                );
            }
        }
        assert!(convergence_plot(&dir.join("x.jpg"), "t", &series).is_err());
        assert!(warp_histogram(&dir.join("h.png"), "t", &o, &e, 15, 0.5).is_err());
        if std::env::var_os("LOBE_FIGURES_DIR").is_none() {
            let _ = std::fs::remove_dir_all(&dir);
        }
    }
}
