//! A material against another (a measured one against its Cook-Torrance
//! fit, in practice) in the plane of incidence at θo = 0°, 30°, 60° and
//! 75°: as polar curves of f·cos θi (`lobe plot --fit` / `--against`), or
//! as lum(f·cos θi) over the signed θi (`lobe fit --plot`).

use super::polar::{POLAR_DECADES, PolarScale};
use crate::draw::paint_png;
use anyhow::{Context, Result, anyhow};
use lobe::Material;
use plotters::prelude::*;
use std::path::Path;

/// Four polar panels (θo = 0°, 30°, 60°, 75°): `lum(f·cos θi)` of `data`
/// (black) and `other` (red) in the plane of incidence, `wi` at its angle
/// from the normal (up), the view in blue; one radius scale per panel
/// (linear, or `--scale log`: four decades); `legend` names the two curves.
pub fn fit_polar_plot(
    path: &Path,
    title: &str,
    data: &Material,
    other: &Material,
    legend: [&str; 2],
    scale: PolarScale,
) -> Result<()> {
    let e = |e: &dyn std::fmt::Display| anyhow!("{path:?}: {e}");
    paint_png(path, Vec::new(), (1200, 760), |root| {
        root.fill(&WHITE).map_err(|x| e(&x))?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(|x| e(&x))?;
        for (panel, theta) in root
            .split_evenly((2, 2))
            .iter()
            .zip([0.0, 30.0, 60.0, 75.0])
        {
            let d = lobe::fit::incidence_plane(data, theta, 720);
            let f = lobe::fit::incidence_plane(other, theta, 720);
            let vmax = d
                .iter()
                .chain(&f)
                .map(|p| p.1)
                .fold(0.0f64, f64::max)
                .max(1e-12);
            let radius = |v: f64| match scale {
                PolarScale::Linear => (v / vmax).max(0.0),
                PolarScale::Log => {
                    if v > 0.0 {
                        (1.0 + (v / vmax).log10() / POLAR_DECADES).max(0.0)
                    } else {
                        0.0
                    }
                }
            };
            let to_xy = |pts: &[(f64, f64)]| -> Vec<(f64, f64)> {
                pts.iter()
                    .map(|&(a, v)| {
                        let (s, c) = a.to_radians().sin_cos();
                        let r = radius(v);
                        (r * s, r * c)
                    })
                    .collect()
            };
            let mut chart = ChartBuilder::on(panel)
                .caption(
                    format!(
                        "θo = {theta}° (max {vmax:.3}{})",
                        if scale == PolarScale::Log {
                            ", log radius"
                        } else {
                            ""
                        }
                    ),
                    ("sans-serif", 17),
                )
                .margin(8)
                .build_cartesian_2d(-1.35f64..1.35f64, -0.04f64..1.08f64)
                .map_err(|x| e(&x))?;
            let grey = RGBColor(200, 200, 200);
            for ring in [0.25, 0.5, 0.75, 1.0] {
                let arc: Vec<(f64, f64)> = (0..=90)
                    .map(|i| {
                        let a = std::f64::consts::PI * f64::from(i) / 90.0;
                        (ring * a.cos(), ring * a.sin())
                    })
                    .collect();
                chart
                    .draw_series(LineSeries::new(arc, grey))
                    .map_err(|x| e(&x))?;
            }
            for deg in [-60.0f64, -30.0, 0.0, 30.0, 60.0] {
                let (s, c) = deg.to_radians().sin_cos();
                chart
                    .draw_series(LineSeries::new([(0.0, 0.0), (s, c)], grey))
                    .map_err(|x| e(&x))?;
            }
            chart
                .draw_series(LineSeries::new([(-1.05, 0.0), (1.05, 0.0)], BLACK))
                .map_err(|x| e(&x))?;
            let (s, c) = theta.to_radians().sin_cos();
            let blue = RGBColor(40, 90, 200);
            chart
                .draw_series(LineSeries::new(
                    [(0.0, 0.0), (1.05 * s, 1.05 * c)],
                    blue.stroke_width(2),
                ))
                .map_err(|x| e(&x))?
                .label("view wo")
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 20, y)], blue.stroke_width(2))
                });
            chart
                .draw_series(LineSeries::new(to_xy(&d), BLACK.stroke_width(3)))
                .map_err(|x| e(&x))?
                .label(legend[0])
                .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.stroke_width(3)));
            let red = RGBColor(220, 50, 30);
            chart
                .draw_series(LineSeries::new(to_xy(&f), red.stroke_width(2)))
                .map_err(|x| e(&x))?
                .label(legend[1])
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], red.stroke_width(2)));
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperLeft)
                .border_style(BLACK)
                .background_style(WHITE)
                .label_font(("sans-serif", 14))
                .draw()
                .map_err(|x| e(&x))?;
        }
        Ok(())
    })
}

/// Four panels, one per view: the data and the fit, `lum(f cos θi)` over
/// the signed `θi` of the plane of incidence.
pub fn fit_curves_plot(path: &Path, title: &str, data: &Material, fit: &Material) -> Result<()> {
    paint_png(path, Vec::new(), (1200, 900), |root| {
        root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
        let root = root
            .titled(title, ("sans-serif", 24))
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        let panels = root.split_evenly((2, 2));
        for (panel, theta) in panels.iter().zip([0.0, 30.0, 60.0, 75.0]) {
            let d = lobe::fit::incidence_plane(data, theta, 360);
            let f = lobe::fit::incidence_plane(fit, theta, 360);
            let ymax = d
                .iter()
                .chain(&f)
                .map(|p| p.1)
                .fold(0.0f64, f64::max)
                .max(1e-9)
                * 1.08;
            let mut chart = ChartBuilder::on(panel)
                .caption(format!("θo = {theta}°"), ("sans-serif", 20))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .build_cartesian_2d(-90f64..90f64, 0f64..ymax)
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            chart
                .configure_mesh()
                .x_desc("θi in the plane of incidence (°; negative: the mirror side)")
                .y_desc("lum(f · cos θi)")
                .label_style(("sans-serif", 14))
                .draw()
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            chart
                .draw_series(LineSeries::new(d, BLACK.stroke_width(3)))
                .map_err(|e| anyhow::anyhow!("{e}"))?
                .label("data")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.stroke_width(3)));
            chart
                .draw_series(LineSeries::new(f, RGBColor(220, 50, 30).stroke_width(2)))
                .map_err(|e| anyhow::anyhow!("{e}"))?
                .label("fit")
                .legend(|(x, y)| {
                    PathElement::new([(x, y), (x + 20, y)], RGBColor(220, 50, 30).stroke_width(2))
                });
            chart
                .configure_series_labels()
                .border_style(BLACK)
                .background_style(WHITE)
                .label_font(("sans-serif", 16))
                .draw()
                .map_err(|e| anyhow::anyhow!("{e}"))?;
        }
        Ok(())
    })
    .with_context(|| format!("--plot {}", path.display()))
}
