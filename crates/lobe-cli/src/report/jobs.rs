//! The work of the report and its results: the comparison tables one at a
//! time (so that their times are undisturbed), then the convergence curves,
//! polar plots, warp tests, weight maps, lost-sample fractions and (for
//! Cook-Torrance) the white furnace in parallel, with a progress bar.

use super::catalogue::{Model, THETAS, build, figure_point, plain_point, view};
use super::format::strip_tags;
use crate::common::progress;
use crate::converge;
use crate::figures::{self, PolarScale};
use anyhow::{Context, Result, anyhow};
use lobe::estimator::Strategy;
use lobe::experiment::converge::{Curve, CurveSettings, curves};
use lobe::experiment::furnace::{FurnaceSettings, furnace};
use lobe::experiment::histogram::lost_fraction;
use lobe::experiment::polar;
use lobe::experiment::table::{Table, TableSettings, run_table};
use lobe::experiment::warp_test::{WarpTest, chi2_config, warp_test};
use lobe::math::luminance;
use lobe::progress::SystemClock;
use lobe::sequence::{Sequence, hash64};
use lobe::stats::chi2::Chi2Settings;
use lobe::{BsdfStrategy, Light, Material, Rgb};
use rayon::prelude::*;
use std::path::Path;

/// How much work the report does.
#[derive(Debug, Clone, Copy)]
pub(super) struct ReportSettings {
    /// Samples per estimate in the tables.
    pub(super) samples: usize,
    /// Runs and largest exponent of the convergence plots.
    pub(super) runs: usize,
    pub(super) max_exp: u32,
    /// Samples, histogram resolution and chi-square bins of the warp tests.
    pub(super) warp_samples: usize,
    pub(super) warp_res: usize,
    pub(super) chi2_nz: usize,
    pub(super) chi2_nphi: usize,
    /// Resolution of the weight maps.
    pub(super) heat_res: usize,
    /// Samples for the fraction of lost samples.
    pub(super) lost_samples: usize,
    /// The white furnace: its θo step in degrees, its α values and walks.
    pub(super) furnace_step: f64,
    pub(super) furnace_alphas: &'static [f64],
    pub(super) furnace_walks: u64,
}

impl ReportSettings {
    pub(super) fn new(quick: bool) -> Self {
        if quick {
            ReportSettings {
                samples: 4096,
                runs: 4,
                max_exp: 8,
                warp_samples: 20_000,
                warp_res: 24,
                chi2_nz: 16,
                chi2_nphi: 16,
                heat_res: 48,
                lost_samples: 4096,
                furnace_step: 20.0,
                furnace_alphas: &[0.1, 0.5, 1.0],
                furnace_walks: 2000,
            }
        } else {
            ReportSettings {
                samples: 1 << 16,
                runs: 32,
                max_exp: 14,
                warp_samples: 400_000,
                warp_res: 48,
                chi2_nz: 40,
                chi2_nphi: 40,
                heat_res: 128,
                lost_samples: 1 << 14,
                furnace_step: 5.0,
                furnace_alphas: &[0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.85, 1.0],
                furnace_walks: 20_000,
            }
        }
    }
}

/// One shading point of a model: its table and lost-sample fractions.
pub(super) struct Point {
    pub(super) value: f64,
    pub(super) theta: f64,
    pub(super) table: Table,
    /// Fraction of failed samples per strategy, in the table's order.
    pub(super) lost: Vec<f64>,
}

/// A figure written beside the page.
pub(super) struct Figure {
    pub(super) file: String,
    pub(super) alt: String,
}

/// A warp test: the figure and its chi-square p-value.
pub(super) struct Warp {
    pub(super) strategy: BsdfStrategy,
    pub(super) figure: Figure,
    pub(super) p_value: f64,
    pub(super) dof: usize,
    /// Fraction of the samples lost below the horizon, and the pdf's
    /// integral over the sphere (the same number, one minus it).
    pub(super) lost: f64,
    pub(super) pdf_integral: f64,
}

/// Everything the page shows about one model.
pub(super) struct ModelResult {
    pub(super) points: Vec<Point>,
    pub(super) curves: Vec<Curve>,
    pub(super) convergence: Figure,
    pub(super) polar: Figure,
    pub(super) warps: Vec<Warp>,
    pub(super) heat: Vec<(BsdfStrategy, Figure)>,
    /// The white furnace of a Cook-Torrance section.
    pub(super) furnace: Option<Figure>,
}

/// The work of the second phase.
pub(super) enum Job {
    Convergence(usize),
    Polar(usize),
    Warp(usize, BsdfStrategy),
    Heat(usize, BsdfStrategy),
    Lost(usize),
    Furnace(usize),
}

pub(super) enum Done {
    Convergence(Vec<Curve>, Figure),
    Polar(Figure),
    Warp(Warp),
    Heat(BsdfStrategy, Figure),
    Lost(Vec<Vec<f64>>),
    Furnace(Figure),
}

/// Runs every job of the report's `models` with the sizes of `settings` and the
/// `seed`, writing the figures into `dir`, with a progress bar unless
/// `quiet`: first the tables, one at a time, then the rest in parallel.
pub(super) fn run_all(
    models: &[Model],
    settings: &ReportSettings,
    seed: u64,
    dir: &Path,
    quiet: bool,
) -> Result<Vec<ModelResult>> {
    let light = Light::Constant(Rgb::ONE);

    // Every material, built once (and checked before any work).
    let mut materials: Vec<Vec<Material>> = Vec::new();
    for model in models {
        materials.push(
            model
                .values
                .iter()
                .map(|&v| build(model, v))
                .collect::<Result<_>>()?,
        );
    }

    let mut jobs: Vec<Job> = Vec::new();
    for (i, model) in models.iter().enumerate() {
        jobs.push(Job::Convergence(i));
        jobs.push(Job::Polar(i));
        jobs.push(Job::Warp(i, BsdfStrategy::Brdf));
        for &s in &model.warp_extra {
            jobs.push(Job::Warp(i, s));
        }
        for &s in [BsdfStrategy::Uniform, BsdfStrategy::Brdf]
            .iter()
            .chain(&model.heat_extra)
        {
            jobs.push(Job::Heat(i, s));
        }
        jobs.push(Job::Lost(i));
        if furnace_desc(model).is_some() {
            jobs.push(Job::Furnace(i));
        }
    }
    let tables: usize = models.iter().map(|m| m.values.len() * THETAS.len()).sum();
    let pb = progress((tables + jobs.len()) as u64, "report", quiet);

    // Phase 1: the tables, one at a time, so that the times are undisturbed.
    pb.set_message("tables");
    let mut tables_of: Vec<Vec<(f64, f64, Table)>> = Vec::new();
    for (model, mats) in models.iter().zip(&materials) {
        let mut v = Vec::new();
        for (&value, m) in model.values.iter().zip(mats) {
            let strategies: Vec<Strategy> =
                m.strategies().into_iter().map(Strategy::from).collect();
            for &theta in &THETAS {
                let t = run_table(
                    m,
                    &lobe::estimator::ShadingPoint::local(view(theta)),
                    &light,
                    &strategies,
                    TableSettings {
                        sequence: Sequence::Independent,
                        samples: settings.samples,
                        seed,
                        replicas: lobe::experiment::table::REPLICAS,
                    },
                    &(),
                    &SystemClock::new(),
                )?;
                v.push((value, theta, t));
                pb.inc(1);
            }
        }
        tables_of.push(v);
    }

    // Phase 2: the figures and the rest, in parallel.
    pb.set_message("figures");
    let done: Vec<Done> = jobs
        .par_iter()
        .map(|job| {
            let r = run_job(job, models, &materials, &tables_of, settings, seed, dir);
            pb.inc(1);
            r
        })
        .collect::<Result<_>>()?;
    pb.finish_and_clear();

    // Gather per model.
    let mut results: Vec<ModelResult> = Vec::new();
    let mut done = done.into_iter();
    for (i, model) in models.iter().enumerate() {
        let Some(Done::Convergence(curves, convergence)) = done.next() else {
            unreachable!("jobs come in order")
        };
        let Some(Done::Polar(polar)) = done.next() else {
            unreachable!("jobs come in order")
        };
        let mut warps = Vec::new();
        for _ in 0..1 + model.warp_extra.len() {
            let Some(Done::Warp(w)) = done.next() else {
                unreachable!("jobs come in order")
            };
            warps.push(w);
        }
        let mut heat = Vec::new();
        for _ in 0..2 + model.heat_extra.len() {
            let Some(Done::Heat(s, f)) = done.next() else {
                unreachable!("jobs come in order")
            };
            heat.push((s, f));
        }
        let Some(Done::Lost(lost)) = done.next() else {
            unreachable!("jobs come in order")
        };
        let furnace = if furnace_desc(model).is_some() {
            let Some(Done::Furnace(f)) = done.next() else {
                unreachable!("jobs come in order")
            };
            Some(f)
        } else {
            None
        };
        let points = std::mem::take(&mut tables_of[i])
            .into_iter()
            .zip(lost)
            .map(|((value, theta, table), lost)| Point {
                value,
                theta,
                table,
                lost,
            })
            .collect();
        results.push(ModelResult {
            points,
            curves,
            convergence,
            polar,
            warps,
            heat,
            furnace,
        });
    }
    Ok(results)
}

#[allow(clippy::too_many_arguments)]
pub(super) fn run_job(
    job: &Job,
    models: &[Model],
    materials: &[Vec<Material>],
    tables: &[Vec<(f64, f64, Table)>],
    st: &ReportSettings,
    seed: u64,
    dir: &Path,
) -> Result<Done> {
    let light = Light::Constant(Rgb::ONE);
    let caption = |model: &Model| {
        format!(
            "{}, θo = {}°",
            plain_point(model, model.values[model.figure_value]),
            model.figure_theta
        )
    };
    match *job {
        Job::Convergence(i) => {
            let model = &models[i];
            let (k, wo) = figure_point(model);
            let m = &materials[i][k];
            // The table of this point holds the reference.
            let target = tables[i]
                .iter()
                .find(|(v, t, _)| *v == model.values[k] && *t == model.figure_theta)
                .map(|(_, _, t)| luminance(Rgb::from_array(t.reference)))
                .ok_or_else(|| anyhow!("no table for the figure's configuration"))?;
            let series = convergence_series(m);
            let mut curves = curves(
                m,
                &lobe::estimator::ShadingPoint::local(wo),
                &light,
                target,
                &series,
                CurveSettings {
                    runs: st.runs,
                    max_exp: st.max_exp,
                    seed,
                },
                &(),
            )?;
            converge::zero_exact_curves(&mut curves, target);
            let file = format!("{}-convergence.png", model.id);
            let title = format!(
                "{}, light: white furnace: RMSE of {} runs",
                caption(model),
                st.runs
            );
            figures::convergence_plot(&dir.join(&file), &title, &converge::plot_series(&curves))
                .with_context(|| format!("cannot write {file}"))?;
            Ok(Done::Convergence(
                curves,
                Figure {
                    file,
                    alt: format!("Convergence plot: {title}"),
                },
            ))
        }
        Job::Polar(i) => {
            let model = &models[i];
            let (k, wo) = figure_point(model);
            let m = &materials[i][k];
            let file = format!("{}-polar.png", model.id);
            let title = format!("{}: integrand and sampling densities", caption(model));
            let curves = polar::curves(m, wo, &polar::default_strategies(m), polar::DEFAULT_STEPS)?;
            figures::polar_plot(&dir.join(&file), &title, &curves, PolarScale::Log)
                .with_context(|| format!("cannot write {file}"))?;
            Ok(Done::Polar(Figure {
                file,
                alt: format!("Polar plot: {title}"),
            }))
        }
        Job::Warp(i, s) => {
            let model = &models[i];
            let (k, _) = figure_point(model);
            let wo = view(model.warp_theta);
            let m = &materials[i][k];
            let wseed = hash64(seed ^ 0x7761_7270);
            let cfg = Chi2Settings {
                n_z: st.chi2_nz,
                n_phi: st.chi2_nphi,
                samples: st.warp_samples,
                seed: wseed,
                ..chi2_config(m)
            };
            let WarpTest {
                histograms: h,
                chi2,
                ..
            } = warp_test(&m.sampler(s)?, wo, cfg, st.warp_res, &());
            let file = format!("{}-warp-{}.png", model.id, s.name());
            let title = format!(
                "{}, θo = {}°: {} sampler",
                plain_point(model, model.values[k]),
                model.warp_theta,
                s.name()
            );
            figures::warp_histogram(
                &dir.join(&file),
                &title,
                &h.observed,
                &h.expected,
                st.warp_res,
                chi2.p_value,
            )
            .with_context(|| format!("cannot write {file}"))?;
            Ok(Done::Warp(Warp {
                strategy: s,
                figure: Figure {
                    file,
                    alt: format!("Warp test: {title}"),
                },
                p_value: chi2.p_value,
                dof: chi2.dof,
                lost: chi2.lost_observed / st.warp_samples as f64,
                pdf_integral: chi2.pdf_integral,
            }))
        }
        Job::Heat(i, s) => {
            let model = &models[i];
            let (k, wo) = figure_point(model);
            let m = &materials[i][k];
            let file = format!("{}-weights-{}.png", model.id, s.name());
            let title = format!("{}: weights of {}", caption(model), s.name());
            figures::weight_heatmap(&dir.join(&file), &title, &m.sampler(s)?, wo, st.heat_res)
                .with_context(|| format!("cannot write {file}"))?;
            Ok(Done::Heat(
                s,
                Figure {
                    file,
                    alt: format!("Weight map: {title}"),
                },
            ))
        }
        Job::Furnace(i) => {
            let model = &models[i];
            let desc = furnace_desc(model).expect("only Cook-Torrance sections have the job");
            let mut thetas: Vec<f64> = (0..)
                .map(|k| f64::from(k) * st.furnace_step)
                .take_while(|t| *t < 89.0)
                .collect();
            thetas.push(89.0);
            let s = FurnaceSettings {
                thetas,
                alphas: st.furnace_alphas.to_vec(),
                walks: st.furnace_walks,
                seed,
            };
            let f = furnace(&desc, &s, &())?;
            let file = format!("{}-furnace.png", model.id);
            let title = format!(
                "{}: white furnace, with and without energy compensation",
                model.title
            );
            figures::furnace_plot(&dir.join(&file), &strip_tags(&title), &f)
                .with_context(|| format!("cannot write {file}"))?;
            Ok(Done::Furnace(Figure {
                file,
                alt: format!("Furnace: {}", strip_tags(&title)),
            }))
        }
        Job::Lost(i) => {
            let model = &models[i];
            let lost = tables[i]
                .iter()
                .map(|(value, theta, table)| {
                    let k = model.values.iter().position(|v| v == value).unwrap_or(0);
                    let m = &materials[i][k];
                    table
                        .strategies
                        .iter()
                        .map(|row| {
                            row.name
                                .parse::<BsdfStrategy>()
                                .ok()
                                .and_then(|s| {
                                    lost_fraction(m, s, view(*theta), st.lost_samples, seed).ok()
                                })
                                .unwrap_or(f64::NAN)
                        })
                        .collect()
                })
                .collect();
            Ok(Done::Lost(lost))
        }
    }
}

/// The series of a report's convergence plot: every strategy but cosine and
/// spherical caps (the same density as VNDF) with independent samples, and
/// the best samplers with stratified and Sobol points.
/// The description a Cook-Torrance section's furnace starts from (its α is
/// replaced by the furnace's); `None` for other sections and for a given
/// material (whose description the report does not keep).
fn furnace_desc(model: &Model) -> Option<lobe::MaterialDesc> {
    let super::catalogue::Source::Lecture(json) = &model.source else {
        return None;
    };
    lobe::MaterialDesc::from_json(&json(model.values[model.figure_value]))
        .ok()
        .filter(|d| d.kind == "cook-torrance")
}

pub(super) fn convergence_series(m: &Material) -> Vec<(Strategy, Sequence)> {
    let has = |s| m.check(s).is_ok();
    let mut v = vec![
        (BsdfStrategy::Uniform.into(), Sequence::Independent),
        (BsdfStrategy::Brdf.into(), Sequence::Independent),
        (BsdfStrategy::Brdf.into(), Sequence::Stratified),
        (BsdfStrategy::Brdf.into(), Sequence::Sobol),
    ];
    if has(BsdfStrategy::Vndf) {
        v.push((BsdfStrategy::Vndf.into(), Sequence::Independent));
        v.push((BsdfStrategy::Vndf.into(), Sequence::Sobol));
    }
    if has(BsdfStrategy::BoundedVndf) {
        v.push((BsdfStrategy::BoundedVndf.into(), Sequence::Independent));
    }
    v
}
