//! The polar plot: the integrand and the sampling densities in the plane
//! of incidence, on one radial scale.

use crate::draw::strategy_color;
use crate::draw::{
    DIM_TEXT, DResult, Figure, GRID, LIGHT_GRID, TEXT, draw_title, fit_size, fmt_num, put_text,
    save_figure, text_style,
};
use anyhow::Result;
use lobe::experiment::polar::{CurveKind, PolarCurves};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use std::path::Path;

/// Size in pixels of a polar plot.
const POLAR_SIZE: (u32, u32) = (800, 500);

/// Size of a polar plot round the full circle (a material that transmits).
const POLAR_FULL_SIZE: (u32, u32) = (800, 820);

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
        if self.curves.full_circle {
            POLAR_FULL_SIZE
        } else {
            POLAR_SIZE
        }
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
        // the legend, centred ([−1.1, 1.1] in y round the full circle).
        let full = self.curves.full_circle;
        let (y_min, y_span) = if full { (-1.1, 2.2) } else { (-0.12, 1.22) };
        let legend_rows = curves.len().div_ceil(POLAR_LEGEND_COLS) as i32;
        let legend_h = legend_rows * POLAR_LEGEND_ROW_H + 8;
        let area = root.margin(title_h + legend_h, 30, 6, 6);
        let (aw, ah) = area.dim_in_pixel();
        let s = (f64::from(aw) / 2.28).min(f64::from(ah) / y_span);
        let half_w = f64::from(aw) / (2.0 * s);
        let y_lo = y_min - 0.5 * (f64::from(ah) / s - y_span);
        let y_hi = y_lo + f64::from(ah) / s;
        let mut chart = ChartBuilder::on(&area).build_cartesian_2d(-half_w..half_w, y_lo..y_hi)?;
        let limit = if full {
            std::f64::consts::PI
        } else {
            FRAC_PI_2
        };

        let polar = lobe::experiment::polar::figure_xy;
        // Rings, rays and their labels.
        for (i, r) in [0.25, 0.5, 0.75, 1.0].into_iter().enumerate() {
            let ring: Vec<(f64, f64)> = (0..=360)
                .map(|k| polar(-limit + 2.0 * limit * f64::from(k) / 360.0, r))
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
        let max_deg = if full { 165 } else { 75 };
        for deg in (-max_deg..=max_deg).step_by(15) {
            let t = f64::from(deg).to_radians();
            let color = if deg % 30 == 0 { GRID } else { LIGHT_GRID };
            chart.draw_series(LineSeries::new(
                [(0.0, 0.0), polar(t, 1.0)],
                color.stroke_width(1),
            ))?;
        }
        let label_deg: i32 = if full { 180 } else { 90 };
        for deg in (-label_deg..=label_deg).step_by(30) {
            if full && deg == -180 {
                continue;
            }
            let t = f64::from(deg).to_radians();
            let label = format!("{deg}°").replace('-', "−");
            let (pos, anchor) = match deg {
                -90 => ((-1.03, 0.015), (HPos::Right, VPos::Bottom)),
                90 => ((1.03, 0.015), (HPos::Left, VPos::Bottom)),
                0 => (polar(t, 1.05), (HPos::Center, VPos::Bottom)),
                180 => (polar(t, 1.05), (HPos::Center, VPos::Top)),
                d if d.abs() > 90 && d < 0 => (polar(t, 1.04), (HPos::Right, VPos::Top)),
                d if d.abs() > 90 => (polar(t, 1.04), (HPos::Left, VPos::Top)),
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
        let sides = if full {
            [
                ("mirror side (θi < 0)", (-0.62, 0.075), VPos::Bottom),
                ("viewer's side (θi > 0)", (0.62, 0.075), VPos::Bottom),
                ("below the surface", (-0.62, -0.03), VPos::Top),
            ]
        } else {
            [
                ("mirror side (θi < 0)", (-0.55, -0.03), VPos::Top),
                ("viewer's side (θi > 0)", (0.55, -0.03), VPos::Top),
                ("", (0.0, 0.0), VPos::Top),
            ]
        };
        chart.draw_series(
            sides
                .into_iter()
                .filter(|(t, _, _)| !t.is_empty())
                .map(|(t, pos, v)| Text::new(t, pos, text_style(13.0, DIM_TEXT, HPos::Center, v))),
        )?;
        // The ray toward the viewer (on the viewer's side, above or below).
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
                .map(|&(t, v)| polar(t.clamp(-limit, limit), radius(v)))
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
