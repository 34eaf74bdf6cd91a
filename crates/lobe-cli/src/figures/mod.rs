//! Figures drawn with plotters: convergence plots, polar plots of a BRDF,
//! warp-test histograms, sample-weight heat maps, a material against
//! its fit, and the white furnace.
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

mod convergence;
mod fit;
mod furnace;
mod maps;
mod polar;

pub use convergence::{Series, convergence_plot};
pub use fit::{fit_curves_plot, fit_polar_plot};
pub use furnace::furnace_plot;
pub use maps::{PASS_LEVEL, warp_histogram, weight_heatmap};
pub use polar::{PolarScale, polar_plot};

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
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
