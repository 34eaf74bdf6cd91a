//! The white-furnace figure (`lobe furnace --out`): the directional albedo
//! against θo, one panel per α, without compensation, with Kulla-Conty's
//! and Turquin's, and the random walk's with its error bars.

use crate::draw::paint_png;
use anyhow::{Context, Result, anyhow};
use lobe::energy::Compensation;
use lobe::experiment::furnace::Furnace;
use lobe::math::luminance;
use plotters::prelude::*;
use std::path::Path;

/// Colours and widths of the curves: none, turquin (wide, under),
/// kulla-conty (thin, over it: where the two agree both show), Okabe-Ito;
/// the random walk in black.
const CURVES: [(Compensation, RGBColor, u32); 3] = [
    (Compensation::None, RGBColor(150, 150, 150), 2),
    (Compensation::Turquin, RGBColor(213, 94, 0), 5),
    (Compensation::KullaConty, RGBColor(0, 114, 178), 2),
];

/// One panel per α (four per row), luminance of the albedo against θo.
pub fn furnace_plot(path: &Path, title: &str, f: &Furnace) -> Result<()> {
    let mut alphas: Vec<f64> = Vec::new();
    for r in &f.rows {
        if !alphas.contains(&r.alpha) {
            alphas.push(r.alpha);
        }
    }
    let cols = alphas.len().min(4);
    let rows = alphas.len().div_ceil(4);
    let size = (300 * cols as u32 + 40, 300 * rows as u32 + 90);
    let ymax = f
        .rows
        .iter()
        .flat_map(|r| {
            let w = r.walk.map_or(0.0, |w| luminance(w.mean));
            [luminance(r.kulla_conty), luminance(r.turquin), w]
        })
        .fold(1.0f64, f64::max)
        * 1.05;
    let e = |x: &dyn std::fmt::Display| anyhow!("{x}");
    paint_png(path, Vec::new(), size, |root| {
        root.fill(&WHITE).map_err(|x| e(&x))?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(|x| e(&x))?;
        let (legend, body) = root.split_vertically(34);
        let mut x = 20;
        for (kind, colour, width) in CURVES {
            legend
                .draw(&PathElement::new(
                    [(x, 14), (x + 28, 14)],
                    colour.stroke_width(width),
                ))
                .map_err(|x| e(&x))?;
            let label = format!("multiscatter {kind}");
            legend
                .draw(&Text::new(label.clone(), (x + 34, 6), ("sans-serif", 15)))
                .map_err(|x| e(&x))?;
            x += 44 + crate::draw::text_width(&label, 15.0);
        }
        legend
            .draw(&Circle::new((x + 10, 14), 4, BLACK.filled()))
            .map_err(|x| e(&x))?;
        legend
            .draw(&Text::new(
                "random walk (± 2 s.e.)",
                (x + 20, 6),
                ("sans-serif", 15),
            ))
            .map_err(|x| e(&x))?;
        let panels = body.split_evenly((rows, cols));
        for (panel, &alpha) in panels.iter().zip(&alphas) {
            let cells: Vec<_> = f.rows.iter().filter(|r| r.alpha == alpha).collect();
            let mut chart = ChartBuilder::on(panel)
                .caption(format!("α = {alpha}"), ("sans-serif", 16))
                .margin(8)
                .x_label_area_size(32)
                .y_label_area_size(44)
                .build_cartesian_2d(0f64..90f64, 0f64..ymax)
                .map_err(|x| e(&x))?;
            chart
                .configure_mesh()
                .x_desc("θo (°)")
                .y_desc("albedo (lum)")
                .x_labels(7)
                .label_style(("sans-serif", 12))
                .draw()
                .map_err(|x| e(&x))?;
            for (kind, colour, width) in CURVES {
                chart
                    .draw_series(LineSeries::new(
                        cells.iter().map(|r| (r.theta, luminance(r.albedo(kind)))),
                        colour.stroke_width(width),
                    ))
                    .map_err(|x| e(&x))?;
            }
            for r in &cells {
                if let Some(w) = r.walk {
                    let (m, s) = (luminance(w.mean), luminance(w.std_error));
                    chart
                        .draw_series([
                            PathElement::new(
                                [(r.theta, m - 2.0 * s), (r.theta, m + 2.0 * s)],
                                BLACK.stroke_width(1),
                            )
                            .into_dyn(),
                            Circle::new((r.theta, m), 3, BLACK.filled()).into_dyn(),
                        ])
                        .map_err(|x| e(&x))?;
                }
            }
        }
        Ok(())
    })
    .with_context(|| format!("--out {}", path.display()))
}
