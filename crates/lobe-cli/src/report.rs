//! `lobe report`: one self-contained HTML page, with PNG figures beside it,
//! that compares the sampling strategies of the lecture's reflection models
//! (Phong, Blinn-Phong, Cook-Torrance with GGX and Beckmann) at several
//! exponents or roughnesses and view angles, written for a graphics student.
//!
//! The work runs in two phases. First the comparison tables, one shading
//! point after the other, each estimate on every thread
//! ([`lobe::experiment::table::run_table`]): nothing else runs meanwhile, so the
//! measured times (and the efficiencies) are not disturbed. Then everything
//! else in parallel: convergence curves, polar plots, warp tests and weight
//! maps. All numbers except the times depend only on the seed.
//!
//! The page has no external CSS, script or font; a small inline script
//! checks, once the page has loaded, that every image loaded, and writes the
//! outcome into `<pre id="image-check">` (`ok 23/23 images loaded`), which
//! the tests read from headless Chromium.

use crate::common::progress;
use crate::converge;
use crate::figures::{self, PolarScale};
use anyhow::{Context, Result, anyhow};
use clap::Args;
use glam::DVec3;
use lobe::estimator::Strategy;
use lobe::experiment::converge::{Curve, CurveSettings, curves};
use lobe::experiment::histogram::lost_fraction;
use lobe::experiment::polar;
use lobe::experiment::table::{Row, Table, TableSettings, run_table};
use lobe::experiment::warp_test::{WarpTest, chi2_config, warp_test};
use lobe::math::luminance;
use lobe::progress::SystemClock;
use lobe::sequence::{Sequence, hash64};
use lobe::stats::chi2::Chi2Settings;
use lobe::{BsdfStrategy, Light, Material, MaterialDesc, Rgb};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The arguments of `lobe report`.
#[derive(Args, Debug)]
#[command(
    about = "Write an HTML report comparing the sampling strategies of every model",
    long_about = "Write DIR/index.html, a self-contained page (no external CSS, script or font) with \
                  PNG figures beside it, that compares the sampling strategies of the lecture's models: \
                  Phong and Blinn-Phong (n = 10, 100, 1000) and Cook-Torrance with GGX and Beckmann \
                  (alpha = 0.05, 0.2, 0.5), at view angles 0, 45 and 75 degrees, under a white furnace \
                  (L_i = 1, so the exact answer is the directional albedo).\n\n\
                  For each model: a table of strategies (estimate, standard error, quadrature reference, \
                  relative error, variance, variance reduction against uniform, time, efficiency), a \
                  convergence plot, a polar plot of the integrand and the sampling densities, the warp \
                  test of the brdf sampler (and of VNDF for GGX) with its chi-square p-value, and maps \
                  of the sample weights, each with a short explanation.\n\n\
                  With --material M (repeatable; JSON, TOML, @FILE or a measured table, as the other \
                  commands take it) the page is about the given materials instead: one section each, \
                  with the same tables and figures at the same three views.\n\n\
                  The default settings take some seconds to a minute on two cores; --quick takes fewer \
                  samples (for checking the page, not the numbers).",
    after_help = "Examples:\n  \
                  lobe report --out report && xdg-open report/index.html\n  \
                  lobe report --out /tmp/r --quick --quiet"
)]
pub struct ReportArgs {
    /// Output directory (created if missing): index.html and the PNG figures
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Fewer samples and runs: checks the page quickly, numbers are rougher
    #[arg(long)]
    pub quick: bool,
    /// Seed of every random sequence in the report
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Report on this material instead of the lecture's models, as
    /// `--material` of the other commands (JSON, TOML, @FILE, or
    /// {"type": "measured", "path": ...}); repeat it for several, each gets
    /// its own section
    #[arg(long = "material", value_name = "M")]
    pub materials: Vec<String>,
    /// No progress bar
    #[arg(long, short)]
    pub quiet: bool,
}

/// How much work the report does.
#[derive(Debug, Clone, Copy)]
struct ReportSettings {
    /// Samples per estimate in the tables.
    samples: usize,
    /// Runs and largest exponent of the convergence plots.
    runs: usize,
    max_exp: u32,
    /// Samples, histogram resolution and chi-square bins of the warp tests.
    warp_samples: usize,
    warp_res: usize,
    chi2_nz: usize,
    chi2_nphi: usize,
    /// Resolution of the weight maps.
    heat_res: usize,
    /// Samples for the fraction of lost samples.
    lost_samples: usize,
}

impl ReportSettings {
    fn new(quick: bool) -> Self {
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
            }
        }
    }
}

/// The view angles of the tables, in degrees.
const THETAS: [f64; 3] = [0.0, 45.0, 75.0];

/// One section of the page: a reflection model of the lecture and its
/// parameter values, or a material given with `--material`.
struct Model {
    /// File-name stem and HTML anchor.
    id: String,
    /// Section title.
    title: String,
    /// The parameter's name in HTML (`n`, `α`); empty for a given material.
    param: &'static str,
    /// The parameter values (one, `0`, for a given material).
    values: Vec<f64>,
    /// The configuration of the figures: index into `values`, and θo.
    figure_value: usize,
    figure_theta: f64,
    /// The view angle of the warp tests: less grazing than the other
    /// figures, where a grazing lobe would fill a pixel or two at the rim of
    /// the projected hemisphere.
    warp_theta: f64,
    /// Extra strategies whose sampler is warp-tested (brdf always is).
    warp_extra: Vec<BsdfStrategy>,
    /// Extra strategies whose weights are mapped (uniform and brdf always are).
    heat_extra: Vec<BsdfStrategy>,
    /// Where the materials come from.
    source: Source,
    /// What the model is and how its brdf sampler works (HTML).
    intro: String,
    /// Which notes of the figures apply: `phong`, `blinn-phong`, `ggx`,
    /// `beckmann`, `measured` or `other`.
    family: &'static str,
}

/// The materials of a section.
enum Source {
    /// The material description for a parameter value.
    Lecture(fn(f64) -> String),
    /// A material of `--material` (loaded once).
    Given(Material),
}

fn models() -> Vec<Model> {
    vec![
        Model {
            id: "phong".into(),
            title: "Phong".into(),
            param: "n",
            values: vec![10.0, 100.0, 1000.0],
            figure_value: 1,
            figure_theta: 45.0,
            warp_theta: 45.0,
            warp_extra: vec![],
            heat_extra: vec![],
            source: Source::Lecture(|n| format!(r#"{{"type":"phong","exponent":{n}}}"#)),
            intro: PHONG_INTRO.into(),
            family: "phong",
        },
        Model {
            id: "blinn-phong".into(),
            title: "Blinn-Phong".into(),
            param: "n",
            values: vec![10.0, 100.0, 1000.0],
            figure_value: 1,
            figure_theta: 45.0,
            warp_theta: 45.0,
            warp_extra: vec![],
            heat_extra: vec![],
            source: Source::Lecture(|n| format!(r#"{{"type":"blinn-phong","exponent":{n}}}"#)),
            intro: BLINN_INTRO.into(),
            family: "blinn-phong",
        },
        Model {
            id: "ggx".into(),
            title: "Cook-Torrance with GGX".into(),
            param: "α",
            values: vec![0.05, 0.2, 0.5],
            figure_value: 1,
            figure_theta: 75.0,
            warp_theta: 45.0,
            warp_extra: vec![BsdfStrategy::Vndf],
            heat_extra: vec![BsdfStrategy::Vndf],
            source: Source::Lecture(|a| {
                format!(r#"{{"type":"cook-torrance","distribution":"ggx","alpha":{a}}}"#)
            }),
            intro: GGX_INTRO.into(),
            family: "ggx",
        },
        Model {
            id: "beckmann".into(),
            title: "Cook-Torrance with Beckmann".into(),
            param: "α",
            values: vec![0.05, 0.2, 0.5],
            figure_value: 1,
            figure_theta: 75.0,
            warp_theta: 45.0,
            warp_extra: vec![],
            heat_extra: vec![BsdfStrategy::Vndf],
            source: Source::Lecture(|a| {
                format!(r#"{{"type":"cook-torrance","distribution":"beckmann","alpha":{a}}}"#)
            }),
            intro: BECKMANN_INTRO.into(),
            family: "beckmann",
        },
    ]
}

/// The sections of the materials given with `--material`, one each,
/// every material loaded (and checked) before any work.
fn given_models(specs: &[String]) -> Result<Vec<Model>> {
    specs
        .iter()
        .enumerate()
        .map(|(i, spec)| {
            let m =
                crate::common::load_material(spec).with_context(|| format!("--material {spec}"))?;
            let vndf = if m.check(BsdfStrategy::Vndf).is_ok() {
                vec![BsdfStrategy::Vndf]
            } else {
                vec![]
            };
            let name = m.model_name();
            let label = match m.measured() {
                Some(t) => format!(
                    "{name} ({})",
                    t.data.path.file_name().map_or_else(
                        || t.data.path.display().to_string(),
                        |f| f.to_string_lossy().into_owned()
                    )
                ),
                None => name.to_string(),
            };
            let family = match (&m.glossy, m.measured()) {
                (_, Some(_)) => "measured",
                (lobe::Glossy::Phong(_), _) => "phong",
                (lobe::Glossy::BlinnPhong(_), _) => "blinn-phong",
                (lobe::Glossy::CookTorrance(ct), _) => match ct.microfacet.ndf() {
                    lobe::Ndf::Ggx => "ggx",
                    lobe::Ndf::Beckmann => "beckmann",
                    lobe::Ndf::BlinnPhong => "microfacet",
                },
                _ => "other",
            };
            let mut intro = format!(
                "<p>The material given with <code>--material {}</code>: <code>{}</code>, under the \
                 same white furnace and at the same three views as the lecture's models. Its \
                 strategies: {}.</p>\n",
                esc(spec),
                esc(name),
                m.strategies()
                    .iter()
                    .map(|s| format!("<code>{s}</code>"))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            if let Some(t) = m.measured() {
                let _ = writeln!(
                    intro,
                    "<p>A measured table ({}). Its <code>brdf</code> sampler draws from a \
                     tabulated distribution built from the data (per bin of θ<sub>o</sub>, a \
                     piecewise-constant density over the half vector weighted by luminance × \
                     cos&thinsp;θ<sub>i</sub> × the half-vector Jacobian, mixed with a small share \
                     of cosine sampling), with an exact pdf: the warp test below checks it.</p>",
                    esc(&t.summary())
                );
            }
            Ok(Model {
                id: format!("material-{}", i + 1),
                title: format!("Material {}: {}", i + 1, label),
                param: "",
                values: vec![0.0],
                figure_value: 0,
                figure_theta: if vndf.is_empty() { 45.0 } else { 75.0 },
                warp_theta: 45.0,
                warp_extra: vndf.clone(),
                heat_extra: vndf,
                source: Source::Given(m),
                intro,
                family,
            })
        })
        .collect()
}

fn build(model: &Model, value: f64) -> Result<Material> {
    match &model.source {
        Source::Lecture(json) => {
            let json = json(value);
            MaterialDesc::from_json(&json)
                .and_then(|d| d.build())
                .map_err(|e| anyhow!("report material {json}: {e}"))
        }
        Source::Given(m) => Ok(m.clone()),
    }
}

fn view(theta: f64) -> DVec3 {
    let t = theta.to_radians();
    DVec3::new(t.sin(), 0.0, t.cos())
}

/// One shading point of a model: its table and lost-sample fractions.
struct Point {
    value: f64,
    theta: f64,
    table: Table,
    /// Fraction of failed samples per strategy, in the table's order.
    lost: Vec<f64>,
}

/// A figure written beside the page.
struct Figure {
    file: String,
    alt: String,
}

/// A warp test: the figure and its chi-square p-value.
struct Warp {
    strategy: BsdfStrategy,
    figure: Figure,
    p_value: f64,
    dof: usize,
    /// Fraction of the samples lost below the horizon, and the pdf's
    /// integral over the sphere (the same number, one minus it).
    lost: f64,
    pdf_integral: f64,
}

/// Everything the page shows about one model.
struct ModelResult {
    points: Vec<Point>,
    curves: Vec<Curve>,
    convergence: Figure,
    polar: Figure,
    warps: Vec<Warp>,
    heat: Vec<(BsdfStrategy, Figure)>,
}

/// The work of the second phase.
enum Job {
    Convergence(usize),
    Polar(usize),
    Warp(usize, BsdfStrategy),
    Heat(usize, BsdfStrategy),
    Lost(usize),
}

enum Done {
    Convergence(Vec<Curve>, Figure),
    Polar(Figure),
    Warp(Warp),
    Heat(BsdfStrategy, Figure),
    Lost(Vec<Vec<f64>>),
}

pub fn run(args: &ReportArgs) -> Result<()> {
    let start = Instant::now();
    let settings = ReportSettings::new(args.quick);
    let dir = &args.out;
    crate::common::prepare_output_dir("--out", dir)?;
    let models = if args.materials.is_empty() {
        models()
    } else {
        given_models(&args.materials)?
    };
    let light = Light::Constant(Rgb::ONE);

    // Every material, built once (and checked before any work).
    let mut materials: Vec<Vec<Material>> = Vec::new();
    for model in &models {
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
    }
    let tables: usize = models.iter().map(|m| m.values.len() * THETAS.len()).sum();
    let pb = progress((tables + jobs.len()) as u64, "report", args.quiet);

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
                        seed: args.seed,
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
            let r = run_job(
                job, &models, &materials, &tables_of, &settings, args.seed, dir,
            );
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
        });
    }

    let elapsed = start.elapsed().as_secs_f64();
    let html = page(&models, &results, &settings, args, elapsed);
    let index = dir.join("index.html");
    std::fs::write(&index, html).with_context(|| format!("cannot write {}", index.display()))?;
    if !args.quiet {
        eprintln!("lobe report: done in {elapsed:.1} s");
    }
    let shown = index.canonicalize().unwrap_or(index);
    println!("{}", shown.display());
    Ok(())
}

/// The estimates at the figure's configuration use this view.
fn figure_point(model: &Model) -> (usize, DVec3) {
    (model.figure_value, view(model.figure_theta))
}

#[allow(clippy::too_many_arguments)]
fn run_job(
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
fn convergence_series(m: &Material) -> Vec<(Strategy, Sequence)> {
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

// ---------------------------------------------------------------------------
// The page
// ---------------------------------------------------------------------------

/// Escape text for HTML.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The text of an HTML fragment without its tags.
fn strip_tags(s: &str) -> String {
    let mut out = String::new();
    let mut inside = false;
    for c in s.chars() {
        match c {
            '<' => inside = true,
            '>' => inside = false,
            _ if !inside => out.push(c),
            _ => {}
        }
    }
    out
}

/// `1.23×10<sup>−5</sup>`, with `digits` decimals.
fn sci(x: f64, digits: usize) -> String {
    let s = format!("{x:.digits$e}");
    let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
    format!(
        "{}×10<sup>{}</sup>",
        m.replace('-', "−"),
        e.replace('-', "−")
    )
}

/// A number with about four significant digits, scientific when far from 1.
fn num(x: f64) -> String {
    if !x.is_finite() {
        return "—".into();
    }
    if x == 0.0 {
        return "0".into();
    }
    // Round to four significant digits first, so that 0.99999 reads 1.000.
    let a: f64 = format!("{:.3e}", x.abs()).parse().unwrap_or(x.abs());
    if (1e-3..1e5).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        format!("{x:.decimals$}").replace('-', "−")
    } else {
        sci(x, 3)
    }
}

/// A factor such as a variance reduction: `12.3×`, `4.1×10³ ×`.
fn factor(x: f64) -> String {
    if !x.is_finite() {
        return "—".into();
    }
    if x >= 1e4 {
        format!("{}&thinsp;×", sci(x, 1))
    } else if x >= 100.0 {
        format!("{x:.0}×")
    } else if x >= 10.0 {
        format!("{x:.1}×")
    } else {
        format!("{x:.2}×")
    }
}

fn percent(x: f64) -> String {
    if !x.is_finite() {
        "—".into()
    } else if x == 0.0 {
        "0".into()
    } else if x < 0.001 {
        "&lt;0.1%".into()
    } else {
        format!("{:.1}%", 100.0 * x)
    }
}

fn lum(c: [f64; 3]) -> f64 {
    luminance(Rgb::from_array(c))
}

/// The value of a parameter: `n = 100`, `α = 0.2` (HTML); a given
/// material's name.
fn param_value(model: &Model, v: f64) -> String {
    match &model.source {
        Source::Lecture(_) => format!("<i>{}</i>&nbsp;=&nbsp;{v}", model.param),
        Source::Given(..) => esc(&model.title),
    }
}

/// The section's title and the parameter value, as plain text for figure
/// titles: `Phong, n = 100`.
fn plain_point(model: &Model, v: f64) -> String {
    match &model.source {
        Source::Lecture(_) => format!("{}, {} = {v}", model.title, strip_tags(model.param)),
        Source::Given(..) => model.title.clone(),
    }
}

fn strategy_cell(name: &str) -> String {
    format!("<td class=\"s\"><code>{}</code></td>", esc(name))
}

/// Whether a row's variance is zero up to rounding (relative to its mean²).
fn exact(row: &Row) -> bool {
    crate::common::row_is_exact(row)
}

/// Uniform's variance over this row's; `None` for a zero variance.
fn reduction(row: &Row) -> Option<f64> {
    if exact(row) {
        None
    } else {
        row.variance_reduction
    }
}

/// `1/(variance × time)`; `None` for a zero variance.
fn efficiency(row: &Row) -> Option<f64> {
    if exact(row) { None } else { row.efficiency }
}

fn uniform_row(t: &Table) -> Option<&Row> {
    t.row(BsdfStrategy::Uniform.into())
}

/// The full table of one shading point.
fn point_table(h: &mut String, model: &Model, p: &Point) {
    let reference = lum(p.table.reference);
    let uniform_eff = uniform_row(&p.table).and_then(efficiency);
    let best = p
        .table
        .strategies
        .iter()
        .map(|r| efficiency(r).unwrap_or(f64::INFINITY))
        .fold(0.0, f64::max);
    let _ = writeln!(
        h,
        "<table class=\"data\"><caption>{}, θ<sub>o</sub>&nbsp;=&nbsp;{}°: reference {} \
         (quadrature), {} samples per estimate</caption>",
        param_value(model, p.value),
        p.theta,
        num(reference),
        p.table.strategies.first().map_or(0, |r| r.samples)
    );
    h.push_str(
        "<thead><tr><th>strategy</th><th>estimate</th><th>std.&nbsp;error</th><th>reference</th>\
         <th>rel.&nbsp;error</th><th>variance</th><th>variance reduction</th><th>lost</th>\
         <th>time (ns/sample)</th><th>efficiency</th><th>efficiency vs uniform</th></tr></thead><tbody>\n",
    );
    for (row, lost) in p.table.strategies.iter().zip(&p.lost) {
        let est = lum(row.mean);
        let se = (row.variance / row.samples as f64).sqrt();
        let red = reduction(row).map_or("exact".to_string(), factor);
        let eff = efficiency(row).map_or("∞".to_string(), num);
        let vs = match (efficiency(row), uniform_eff) {
            (Some(e), Some(u)) if u > 0.0 => factor(e / u),
            (None, _) => "∞".into(),
            _ => "—".into(),
        };
        let class = if efficiency(row).unwrap_or(f64::INFINITY) == best {
            " class=\"best\""
        } else {
            ""
        };
        let _ = writeln!(
            h,
            "<tr{class}>{}<td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{red}</td>\
             <td>{}</td><td>{:.0}</td><td>{eff}</td><td>{vs}</td></tr>",
            strategy_cell(&row.name),
            num(est),
            num(se),
            num(reference),
            num(row.relative_error),
            num(row.variance),
            percent(*lost),
            row.time_s / row.samples as f64 * 1e9,
        );
    }
    h.push_str("</tbody></table>\n");
}

/// The variance reductions of every shading point of a model.
fn summary_table(h: &mut String, model: &Model, r: &ModelResult) {
    let names: Vec<String> = r
        .points
        .first()
        .map(|p| p.table.strategies.iter().map(|r| r.name.clone()).collect())
        .unwrap_or_default();
    let lecture = matches!(model.source, Source::Lecture(_));
    let _ = write!(
        h,
        "<p class=\"tcap\">Variance reduction against uniform sampling (uniform's variance \
         divided by each strategy's; higher is better, the best of each row in bold)</p>\
         <table class=\"data summary\"><thead><tr>{}<th>θ<sub>o</sub></th>\
         <th>reference</th>",
        if lecture {
            format!("<th><i>{}</i></th>", model.param)
        } else {
            String::new()
        }
    );
    for n in &names {
        let _ = write!(h, "<th><code>{}</code></th>", esc(n));
    }
    h.push_str("</tr></thead><tbody>\n");
    for p in &r.points {
        let best = p
            .table
            .strategies
            .iter()
            .map(|r| reduction(r).unwrap_or(f64::INFINITY))
            .fold(0.0, f64::max);
        let _ = write!(
            h,
            "<tr>{}<td>{}°</td><td>{}</td>",
            if lecture {
                format!("<td>{}</td>", p.value)
            } else {
                String::new()
            },
            p.theta,
            num(lum(p.table.reference))
        );
        for row in &p.table.strategies {
            let v = reduction(row).unwrap_or(f64::INFINITY);
            let text = reduction(row).map_or("exact".to_string(), factor);
            if v == best {
                let _ = write!(h, "<td><b>{text}</b></td>");
            } else {
                let _ = write!(h, "<td>{text}</td>");
            }
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</tbody></table>\n");
}

fn figure(h: &mut String, f: &Figure, caption: &str) {
    let _ = writeln!(
        h,
        "<figure><a href=\"{0}\" title=\"open the full-size image\"><img src=\"{0}\" alt=\"{1}\"></a>\
         <figcaption>{caption}</figcaption></figure>",
        esc(&f.file),
        esc(&f.alt)
    );
}

fn find_point(r: &ModelResult, value: f64, theta: f64) -> Option<&Point> {
    r.points
        .iter()
        .find(|p| p.value == value && p.theta == theta)
}

fn variance_of(p: &Point, s: BsdfStrategy) -> Option<f64> {
    p.table
        .row(s.into())
        .map(|r| if exact(r) { 0.0 } else { r.variance })
}

fn lost_of(p: &Point, s: BsdfStrategy) -> Option<f64> {
    p.table
        .position(s.into())
        .and_then(|i| p.lost.get(i).copied())
}

/// A sentence or two drawn from the numbers of a model.
fn findings(model: &Model, r: &ModelResult) -> String {
    let mut out = String::new();
    // brdf against uniform: smallest and largest gain.
    let gains: Vec<(&Point, f64)> = r
        .points
        .iter()
        .filter_map(|p| {
            let u = variance_of(p, BsdfStrategy::Uniform)?;
            let b = variance_of(p, BsdfStrategy::Brdf)?;
            Some((p, if b > 0.0 { u / b } else { f64::INFINITY }))
        })
        .collect();
    if let (Some(lo), Some(hi)) = (
        gains.iter().min_by(|a, b| a.1.total_cmp(&b.1)),
        gains.iter().max_by(|a, b| a.1.total_cmp(&b.1)),
    ) {
        let most = if hi.1.is_finite() {
            format!("by {}", factor(hi.1))
        } else {
            "to zero (up to rounding)".into()
        };
        let at = |p: &Point| {
            format!(
                "{}, θ<sub>o</sub>&nbsp;=&nbsp;{}°",
                param_value(model, p.value),
                p.theta
            )
        };
        let _ = write!(
            out,
            "The {} <code>brdf</code> sampler cuts the variance of uniform sampling {most} \
             at {}: the sharper the lobe, the more a blind (uniform) sampler misses it, and the \
             more importance sampling gains. ",
            if matches!(model.source, Source::Lecture(_)) {
                "lecture's"
            } else {
                "material's"
            },
            at(hi.0)
        );
        if lo.1 >= 1.0 {
            let _ = write!(
                out,
                "Its smallest gain is {} at {}. ",
                factor(lo.1),
                at(lo.0)
            );
        } else {
            let _ = write!(
                out,
                "But at {} it has {} <i>more</i> variance than uniform sampling: a sampler that \
                 puts its samples in the wrong places is worse than none. ",
                at(lo.0),
                factor(1.0 / lo.1)
            );
        }
    }
    // VNDF against brdf at the most grazing view.
    let theta = THETAS[THETAS.len() - 1];
    let mut all_better = true;
    let vs: Vec<String> = model
        .values
        .iter()
        .filter_map(|&v| {
            let p = find_point(r, v, theta)?;
            let b = variance_of(p, BsdfStrategy::Brdf)?;
            let n = variance_of(p, BsdfStrategy::Vndf)?;
            all_better &= b > n;
            let lost = lost_of(p, BsdfStrategy::Brdf).unwrap_or(f64::NAN);
            let name = if matches!(model.source, Source::Lecture(_)) {
                format!("{}: ", param_value(model, v))
            } else {
                String::new()
            };
            Some(format!(
                "{name}{} (<code>brdf</code> loses {} of its samples below the horizon)",
                if n > 0.0 { factor(b / n) } else { "∞".into() },
                percent(lost)
            ))
        })
        .collect();
    if !vs.is_empty() {
        // A measured table's brdf sampler follows the data, not D·cos.
        let brdf = if model.family == "measured" {
            "<code>brdf</code> (tabulated)"
        } else {
            "<code>brdf</code> (D·cos)"
        };
        if all_better {
            let _ = write!(
                out,
                "At the grazing view θ<sub>o</sub>&nbsp;=&nbsp;{theta}°, VNDF sampling has less \
                 variance than {brdf} sampling by {}.",
                vs.join("; ")
            );
        } else {
            let _ = write!(
                out,
                "At the grazing view θ<sub>o</sub>&nbsp;=&nbsp;{theta}°, VNDF sampling does not \
                 always beat {brdf} sampling here: the variance of {brdf} over VNDF's is {}.",
                vs.join("; ")
            );
        }
    }
    out
}

fn slope_text(c: &Curve) -> String {
    match c.slope {
        Some(s) => format!("{s:.2}").replace('-', "−"),
        None => "—".into(),
    }
}

fn section(h: &mut String, model: &Model, r: &ModelResult, st: &ReportSettings) {
    let fig_value = model.values[model.figure_value];
    let _ = writeln!(h, "<section id=\"{}\"><h2>{}</h2>", model.id, model.title);
    h.push_str(&model.intro);
    let _ = writeln!(h, "<p class=\"finding\">{}</p>", findings(model, r));

    let _ = writeln!(
        h,
        "<h3>Strategies compared</h3>\
         <p>Every strategy at {} view angles, with {} samples each. The best \
         strategy of each row is in bold. The full tables, with estimates, errors, lost samples, \
         times and efficiencies, follow.</p>",
        match (&model.source, model.param) {
            (Source::Given(..), _) => "three",
            (_, "n") => "three exponents and three",
            _ => "three roughnesses and three",
        },
        st.samples
    );
    summary_table(h, model, r);
    if let Some(p) = find_point(r, fig_value, model.figure_theta) {
        let _ = writeln!(
            h,
            "<p>The shading point of the figures below, in full (the most efficient strategy \
             highlighted):</p>"
        );
        point_table(h, model, p);
    }
    let _ = writeln!(
        h,
        "<details><summary>All {} shading points in full</summary>",
        r.points.len()
    );
    for p in &r.points {
        point_table(h, model, p);
    }
    h.push_str("</details>\n");
    let _ = writeln!(
        h,
        "<p class=\"explain\"><b>What to look for.</b> The estimates of all strategies agree with \
         the reference within a few standard errors: every strategy is unbiased, they differ only \
         in noise. The variance column is the noise of one sample; the standard error of the \
         estimate is √(variance/N). A variance reduction of 100× means uniform sampling needs 100 \
         times more samples for the same noise. Efficiency also charges for time: a sampler that \
         costs twice as much per sample must cut the variance by more than 2× to pay off.</p>"
    );

    // Figures, all at one shading point.
    let _ = writeln!(
        h,
        "<h3>Figures at {}, θ<sub>o</sub>&nbsp;=&nbsp;{}°</h3>\
         <p class=\"note\">Click a figure to open it at full size.</p>",
        param_value(model, fig_value),
        model.figure_theta
    );
    let slopes: Vec<String> = r
        .curves
        .iter()
        .map(|c| {
            format!(
                "<code>{}</code>&nbsp;/&nbsp;{}&nbsp;{}",
                c.strategy,
                c.sequence,
                slope_text(c)
            )
        })
        .collect();
    figure(
        h,
        &r.convergence,
        &format!(
            "<b>Convergence.</b> RMSE of {} independent estimates against the reference, for \
             N&nbsp;=&nbsp;1&nbsp;…&nbsp;2<sup>{}</sup> samples, on log-log axes. With independent \
             samples every strategy falls along a line of slope −1/2 (RMSE&nbsp;∝&nbsp;1/√N, the \
             dashed line): importance sampling does not change the rate, it moves the whole line \
             down, and a line 10× lower means 100× fewer samples for the same error. Stratified \
             and Sobol points change the rate itself where the weight f·cos/p is a smooth function \
             of the random numbers. The stratified curve zigzags: when N is a square \
             (N&nbsp;=&nbsp;4,&nbsp;16,&nbsp;64,&nbsp;…) its points form a √N×√N jittered grid; \
             otherwise they fall back to Latin hypercube sampling, which stratifies each \
             coordinate only on its own. Slopes fitted by least squares over the upper half of the range \
             (N&nbsp;≥&nbsp;2<sup>{}</sup>): {}.",
            st.runs,
            st.max_exp,
            lobe::experiment::converge::fit_start(st.max_exp),
            slopes.join(", ")
        ),
    );
    figure(
        h,
        &r.polar,
        "<b>Shapes in the plane of incidence.</b> The integrand f<sub>r</sub>·cos&thinsp;θ<sub>i</sub> \
         divided by its integral (the ideal density, which would give zero variance) and the density \
         of each strategy, all in 1/sr on one logarithmic radial scale (four decades below the largest \
         value; the legend gives each curve's peak), so that the curves compare directly. The \
         viewer is on the right, the mirror direction on the left, as in the histograms and weight maps. A good sampler has the shape of \
         the integrand: where its density is much lower than the integrand, the rare samples that \
         land there carry huge weights — the fireflies of a render. Uniform and cosine sampling \
         spread their samples over the whole hemisphere while the integrand lives in a narrow lobe.",
    );
    for w in &r.warps {
        let verdict = if w.p_value > figures::PASS_LEVEL {
            "passes"
        } else {
            "fails"
        };
        figure(
            h,
            &w.figure,
            &format!(
                "<b>Warp test of the <code>{}</code> sampler</b> at θ<sub>o</sub>&nbsp;=&nbsp;{}° \
                 (a less grazing view than the other figures, so that the lobe is not squeezed \
                 against the rim of the disk). Left: where {} sampled directions \
                 landed, seen from above (the disk is the hemisphere projected onto the surface). \
                 Right: where the sampler's own pdf says they should land. They must match: \
                 an estimator divides by the pdf, so a sampler whose samples do not follow its pdf \
                 gives a <i>biased</i> answer, however many samples it takes. A chi-square test over \
                 {}×{} bins of the sphere (after pooling sparse bins: {} degrees of freedom) gives \
                 p&nbsp;=&nbsp;{}; the test {verdict} at the 1% level (p&nbsp;>&nbsp;0.01 means no \
                 evidence of a mismatch). {}{}",
                w.strategy,
                model.warp_theta,
                st.warp_samples,
                st.chi2_nz,
                st.chi2_nphi,
                w.dof,
                num(w.p_value),
                lost_note(w),
                warp_note(model, w.strategy)
            ),
        );
    }
    h.push_str("<div class=\"row\">\n");
    for (s, f) in &r.heat {
        figure(h, f, &format!("<code>{s}</code>"));
    }
    h.push_str("</div>\n");
    let _ = writeln!(
        h,
        "<p class=\"explain\"><b>Sample weights.</b> Each pixel is a direction ω<sub>i</sub> seen \
         from above, coloured by the weight f<sub>r</sub>·cos&thinsp;θ<sub>i</sub>/p that a sample \
         there would carry (log colour scale; the white + is the mirror direction; grey: f<sub>r</sub> \
         = 0). The estimate is the average of these weights over the samples, so its noise is the \
         spread of the weights <i>where samples land</i>. With uniform sampling the weights span \
         many decades: huge in the small lobe, tiny everywhere else, and most samples land where \
         they are worthless. With p&nbsp;∝&nbsp;f<sub>r</sub>·cos&thinsp;θ<sub>i</sub> the weight \
         would be the same constant everywhere; a good sampler's map is nearly flat where it puts \
         its samples.{}</p>",
        heat_note(model)
    );
    h.push_str("</section>\n");
}

fn lost_note(w: &Warp) -> String {
    if w.lost > 0.0 {
        format!(
            "{} of the samples were lost below the horizon: they fall in no pixel, and the pdf \
             integrates to {:.5} over the sphere, short of one by the same amount.",
            percent(w.lost),
            w.pdf_integral
        )
    } else {
        "No sample was lost below the horizon.".into()
    }
}

fn warp_note(model: &Model, s: BsdfStrategy) -> &'static str {
    match (model.family, s) {
        ("blinn-phong", BsdfStrategy::Brdf) => {
            " This sampler draws the half vector h, not ω<sub>i</sub>; its pdf includes the \
             Jacobian 1/(4&thinsp;ω<sub>o</sub>·h) of the reflection. Without it the right map \
             would not match the left one."
        }
        ("ggx" | "beckmann", BsdfStrategy::Vndf) => {
            " VNDF draws only normals that face the viewer, so fewer of its samples are lost \
             than with <code>brdf</code> (the tables give the lost fraction at every view)."
        }
        _ => "",
    }
}

fn heat_note(model: &Model) -> &'static str {
    match model.family {
        "measured" => {
            " For a measured table the <code>brdf</code> sampler follows the tabulated data \
             (luminance × cos&thinsp;θ<sub>i</sub>), so its weight is nearly flat where the \
             data are smooth, and stays bounded where the cosine share of the mixture covers \
             what the table misses."
        }
        "other" => "",
        "phong" => {
            " For Phong the <code>brdf</code> weight is k<sub>s</sub>(n+2)/(n+1)·cos&thinsp;θ<sub>i</sub>: \
             it varies only with cos&thinsp;θ<sub>i</sub> across the lobe."
        }
        "blinn-phong" => {
            " For Blinn-Phong the <code>brdf</code> weight varies a little more, through the \
             Jacobian 4&thinsp;ω<sub>o</sub>·h and cos&thinsp;θ<sub>i</sub>, but it stays within a \
             small range where samples land."
        }
        _ => {
            " For microfacets the <code>brdf</code> (D·cos) weight is G·(ω<sub>o</sub>·h)/(cos&thinsp;θ<sub>o</sub> \
             cos&thinsp;θ<sub>h</sub>): at a grazing view cos&thinsp;θ<sub>o</sub> is small and the \
             weight grows large. The <code>vndf</code> weight is G<sub>2</sub>/G<sub>1</sub> ≤ 1 \
             everywhere: its map is flat and bounded."
        }
    }
}

fn page(
    models: &[Model],
    results: &[ModelResult],
    st: &ReportSettings,
    args: &ReportArgs,
    elapsed: f64,
) -> String {
    let images: usize = results
        .iter()
        .map(|r| 2 + r.warps.len() + r.heat.len())
        .sum();
    let mut h = String::with_capacity(1 << 18);
    h.push_str(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>Importance sampling in BRDF evaluation — lobe report</title>\n<style>\n",
    );
    h.push_str(CSS);
    h.push_str("</style>\n</head>\n<body>\n<main>\n");
    let _ = writeln!(
        h,
        "<header><h1>Importance sampling in BRDF evaluation</h1>\
         <p class=\"sub\">{}: how the choice of sampling density changes the noise of a Monte \
         Carlo estimate.</p></header>",
        if args.materials.is_empty() {
            "Phong, Blinn-Phong and Cook-Torrance (GGX and Beckmann)".to_string()
        } else {
            models
                .iter()
                .map(|m| esc(&m.title))
                .collect::<Vec<_>>()
                .join("; ")
        }
    );
    h.push_str("<nav><b>Contents:</b> <a href=\"#background\">Background</a>");
    for m in models {
        let _ = write!(h, " · <a href=\"#{}\">{}</a>", m.id, m.title);
    }
    h.push_str(" · <a href=\"#about\">About this page</a></nav>\n");
    h.push_str(BACKGROUND);
    for (m, r) in models.iter().zip(results) {
        section(&mut h, m, r, st);
    }
    let _ = writeln!(
        h,
        "<section id=\"about\"><h2>About this page</h2><p>Generated by <code>lobe report{}{}{}</code> \
         in {elapsed:.1}&nbsp;s. Tables: {} samples per estimate (independent samples, seed {}). \
         Convergence: {} runs per N, N up to 2<sup>{}</sup>; each estimate uses its own sequence of \
         exactly N samples. Warp tests: {} samples, chi-square over {}×{} bins of the sphere. \
         References: {}. \
         Times are wall-clock on every thread of this machine and vary from run to run; all other \
         numbers depend only on the seed. {}</p>",
        if args.quick { " --quick" } else { "" },
        args.materials
            .iter()
            .map(|m| format!(" --material {}", esc(&shell_quote(m))))
            .collect::<String>(),
        if args.seed != 1 {
            format!(" --seed {}", args.seed)
        } else {
            String::new()
        },
        st.samples,
        args.seed,
        reference_methods(results),
        st.runs,
        st.max_exp,
        st.warp_samples,
        st.chi2_nz,
        st.chi2_nphi,
        if args.quick {
            "<b>Quick mode:</b> few samples; the numbers are rough."
        } else {
            ""
        }
    );
    let _ = writeln!(
        h,
        "<p>Page check: <span id=\"image-check\">{images} images; waiting for the page to load…</span></p>\
         </section>"
    );
    h.push_str("</main>\n<script>\n");
    h.push_str(IMAGE_CHECK);
    h.push_str("</script>\n</body>\n</html>\n");
    h
}

/// The distinct ways the tables' references were computed, joined.
fn reference_methods(results: &[ModelResult]) -> String {
    let mut v: Vec<&str> = Vec::new();
    for p in results.iter().flat_map(|r| &r.points) {
        if !v.contains(&p.table.reference_method.as_str()) {
            v.push(&p.table.reference_method);
        }
    }
    esc(&v.join("; "))
}

/// `s` as a shell word: bare when it is plain, else in single quotes.
fn shell_quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "@%+=:,./_-".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// Writes `ok N/N images loaded`, or the images that did not load, into
/// `#image-check` once the page has loaded.
const IMAGE_CHECK: &str = r#"window.addEventListener('load', function () {
  var imgs = Array.prototype.slice.call(document.images);
  var bad = imgs.filter(function (i) { return !(i.complete && i.naturalWidth > 0); });
  var out = document.getElementById('image-check');
  if (bad.length === 0) {
    out.textContent = 'ok ' + imgs.length + '/' + imgs.length + ' images loaded';
  } else {
    out.textContent = 'FAILED ' + (imgs.length - bad.length) + '/' + imgs.length +
      ' images loaded; missing: ' + bad.map(function (i) { return i.getAttribute('src'); }).join(' ');
  }
});
"#;

const CSS: &str = r#"
:root { --ink: #1d2330; --muted: #5a6375; --line: #d9dde5; --soft: #f4f6f9; --accent: #0b6bcb; --best: #e6f4ea; }
* { box-sizing: border-box; }
body { margin: 0; color: var(--ink); background: #fff; font: 16px/1.55 system-ui, -apple-system, "Segoe UI", Roboto, "Helvetica Neue", Arial, sans-serif; }
main { max-width: 1100px; margin: 0 auto; padding: 24px 28px 64px; }
header h1 { font-size: 2rem; margin: 0.4em 0 0.1em; }
.sub { color: var(--muted); margin-top: 0; font-size: 1.08rem; }
nav { background: var(--soft); border: 1px solid var(--line); border-radius: 8px; padding: 8px 14px; margin: 16px 0 8px; }
a { color: var(--accent); text-decoration: none; }
a:hover { text-decoration: underline; }
h2 { font-size: 1.55rem; margin: 2.2em 0 0.4em; padding-bottom: 0.2em; border-bottom: 2px solid var(--line); }
h3 { font-size: 1.15rem; margin: 1.6em 0 0.4em; }
code { font: 0.92em/1 ui-monospace, "SFMono-Regular", Menlo, Consolas, "DejaVu Sans Mono", monospace; background: var(--soft); padding: 1px 4px; border-radius: 4px; }
.formula { text-align: center; font-size: 1.1rem; margin: 0.8em 0; font-family: "Cambria Math", "STIX Two Math", "Latin Modern Math", Georgia, serif; }
.finding { background: #eef5fd; border-left: 4px solid var(--accent); padding: 10px 14px; border-radius: 0 6px 6px 0; }
.explain { background: #fbf7ec; border-left: 4px solid #d9a400; padding: 10px 14px; border-radius: 0 6px 6px 0; }
dl.defs { display: grid; grid-template-columns: max-content 1fr; gap: 4px 14px; }
dl.defs dt { font-weight: 600; }
dl.defs dd { margin: 0; }
table.data { border-collapse: collapse; margin: 12px 0 18px; font-size: 0.86rem; font-variant-numeric: tabular-nums; width: 100%; }
table.data caption { caption-side: top; text-align: left; font-weight: 600; padding: 4px 0 6px; color: var(--ink); }
table.data th, table.data td { border-bottom: 1px solid var(--line); padding: 4px 7px; text-align: right; white-space: nowrap; }
table.data th { background: var(--soft); font-weight: 600; vertical-align: bottom; white-space: normal; }
table.data td.s, table.data th:first-child { text-align: left; }
table.data tbody tr:nth-child(even) { background: #fafbfc; }
table.data tr.best { background: var(--best) !important; }
table.summary { width: auto; margin-top: 0; }
p.note { color: var(--muted); font-size: 0.9rem; margin-top: 0; }
p.tcap { font-weight: 600; font-size: 0.86rem; margin: 12px 0 6px; }
table.summary td:first-child, table.summary th:first-child { text-align: left; }
details { margin: 8px 0 16px; }
details > summary { cursor: pointer; color: var(--accent); font-weight: 600; }
figure { margin: 20px 0; }
figure img { display: block; max-width: 100%; height: auto; margin: 0 auto; border: 1px solid var(--line); border-radius: 6px; }
figcaption { color: #343b49; font-size: 0.93rem; margin-top: 8px; }
.row { display: flex; gap: 12px; flex-wrap: wrap; }
.row figure { flex: 1 1 0; min-width: 300px; margin: 12px 0 4px; }
.row figcaption { text-align: center; }
#image-check { font-family: ui-monospace, "DejaVu Sans Mono", monospace; }
"#;

const BACKGROUND: &str = r#"<section id="background"><h2>Background</h2>
<p>A renderer computes the light that leaves a surface point toward the viewer by integrating the
light that arrives from every direction of the hemisphere above it:</p>
<p class="formula">L<sub>o</sub>(ω<sub>o</sub>) = ∫<sub>Ω</sub> f<sub>r</sub>(ω<sub>o</sub>, ω<sub>i</sub>) L<sub>i</sub>(ω<sub>i</sub>) cos θ<sub>i</sub> dω<sub>i</sub></p>
<p>where f<sub>r</sub> is the BRDF (the reflection model), ω<sub>o</sub> points toward the viewer,
ω<sub>i</sub> toward the light and θ<sub>i</sub> is the angle between ω<sub>i</sub> and the normal.
A Monte Carlo estimator draws N random directions ω<sub>1</sub> … ω<sub>N</sub> from a
density p and averages the <i>sample weights</i>:</p>
<p class="formula">L̂ = (1/N) Σ<sub>k</sub> f<sub>r</sub>(ω<sub>o</sub>, ω<sub>k</sub>) L<sub>i</sub>(ω<sub>k</sub>) cos θ<sub>k</sub> / p(ω<sub>k</sub>)</p>
<p>This is right on average for <i>any</i> density p that is positive wherever the integrand is:
the choice of p changes only the noise. The variance of L̂ is the variance of one weight divided
by N. <b>Why importance sampling reduces noise:</b> if p is proportional to
f<sub>r</sub>·cos θ<sub>i</sub>, every weight f<sub>r</sub> cos θ<sub>i</sub>/p is the same
number (the integral itself), and the variance is zero. A real sampler cannot do that exactly,
but the closer p follows f<sub>r</sub>·cos θ<sub>i</sub>, the flatter the weights and the lower
the noise. Uniform sampling ignores the BRDF: for a sharp highlight it rarely hits the lobe, and
the few samples that do carry enormous weights.</p>
<p><b>The test scene.</b> All numbers use a <i>white furnace</i>: L<sub>i</sub> = 1 from every
direction. The exact answer is then the directional albedo ∫ f<sub>r</sub> cos θ<sub>i</sub>
dω<sub>i</sub>, and all the noise comes from the mismatch between p and
f<sub>r</sub>·cos θ<sub>i</sub>. The reference is computed by deterministic adaptive quadrature,
not by a long Monte Carlo run. The view direction is ω<sub>o</sub> = (sin θ<sub>o</sub>, 0,
cos θ<sub>o</sub>) with the normal along +z: θ<sub>o</sub> = 0° looks straight down,
75° is a grazing view. A sample that a sampler sends below the horizon is a <i>failed</i> (lost)
sample: it adds zero but still counts in N.</p>
<h3>The strategies</h3>
<dl class="defs">
<dt><code>uniform</code></dt><dd>p = 1/(2π) over the hemisphere: the baseline, which knows nothing about the BRDF.</dd>
<dt><code>cosine</code></dt><dd>p = cos θ<sub>i</sub>/π: follows the cosine factor only; perfect for a matte (Lambertian) surface.</dd>
<dt><code>brdf</code></dt><dd>The lecture's samplers. Phong: directions around the mirror direction with p ∝ cos<sup>n</sup> α. Blinn-Phong: the half vector with p<sub>h</sub> ∝ cos<sup>n</sup> θ<sub>h</sub>, then ω<sub>i</sub> by reflecting ω<sub>o</sub>. Cook-Torrance: the half vector from D(h) cos θ<sub>h</sub>, then the same reflection.</dd>
<dt><code>vndf</code></dt><dd>Microfacets only: draws only the normals visible from ω<sub>o</sub> (Heitz 2018).</dd>
<dt><code>spherical-caps</code></dt><dd>The same density as <code>vndf</code>, drawn by a simpler construction (Dupuy and Benyoub 2023; GGX).</dd>
<dt><code>bounded-vndf</code></dt><dd>A VNDF variant that avoids most normals whose reflection would go below the horizon (Eto and Tokuyoshi 2023; GGX).</dd>
</dl>
<h3>The columns of the tables</h3>
<dl class="defs">
<dt>estimate</dt><dd>The Monte Carlo estimate of L<sub>o</sub> (luminance).</dd>
<dt>std. error</dt><dd>Its standard error, √(variance/N): the typical distance from the truth.</dd>
<dt>reference</dt><dd>The exact value, by quadrature.</dd>
<dt>rel. error</dt><dd>|estimate − reference| / reference: the error of this one estimate.</dd>
<dt>variance</dt><dd>The variance of one sample weight f<sub>r</sub> cos θ<sub>i</sub>/p. This is what a strategy controls.</dd>
<dt>variance reduction</dt><dd>Uniform's variance divided by this one: how many times fewer samples give the same noise. <i>exact</i>: zero variance.</dd>
<dt>lost</dt><dd>The fraction of samples sent below the horizon (wasted).</dd>
<dt>time</dt><dd>Measured wall time per sample.</dd>
<dt>efficiency</dt><dd>1/(variance × time), here with the time of the whole estimate: how much noise is removed per second. <i>vs uniform</i> is the ratio to uniform's; the most efficient row is highlighted.</dd>
</dl>
</section>
"#;

const PHONG_INTRO: &str = r#"<p>The (energy-normalized) Phong model is
f<sub>r</sub> = k<sub>s</sub> (n+2)/(2π) cos<sup>n</sup> α, where α is the angle between
ω<sub>i</sub> and the mirror direction of ω<sub>o</sub>. The highlight is a cone around the
mirror direction whose width shrinks like 1/√n. The lecture's <code>brdf</code> sampler draws α
with density (n+1)/(2π) cos<sup>n</sup> α around the mirror direction (cos α = u<sup>1/(n+1)</sup>),
so f<sub>r</sub>/p is the constant k<sub>s</sub>(n+2)/(n+1): the weight varies only through
cos θ<sub>i</sub>. At grazing views part of the cone lies below the horizon, and those samples
are lost.</p>
"#;

const BLINN_INTRO: &str = r#"<p>Blinn-Phong uses the half vector
h = (ω<sub>o</sub> + ω<sub>i</sub>)/|ω<sub>o</sub> + ω<sub>i</sub>|:
f<sub>r</sub> = k<sub>s</sub> K cos<sup>n</sup> θ<sub>h</sub>, with K chosen so that the albedo at
normal incidence is k<sub>s</sub>. The <code>brdf</code> sampler draws the half vector with density
p<sub>h</sub>(h) = (n+1)/(2π) cos<sup>n</sup> θ<sub>h</sub> and reflects ω<sub>o</sub> about it.
But the estimator needs the density of ω<sub>i</sub>, not of h. <b>The half-vector Jacobian:</b>
reflecting about h doubles angles, so a small patch of half vectors dω<sub>h</sub> becomes a
patch of directions dω<sub>i</sub> = 4 (ω<sub>o</sub>·h) dω<sub>h</sub>, and</p>
<p class="formula">p(ω<sub>i</sub>) = p<sub>h</sub>(h) / (4 ω<sub>o</sub>·h).</p>
<p>Forgetting the factor, i.e. dividing by p<sub>h</sub>, does not just add noise: it makes the
estimate wrong on average (biased). The warp test below checks that the samples really follow
the corrected density.</p>
"#;

const GGX_INTRO: &str = r#"<p>Cook-Torrance models a surface as tiny mirrors (microfacets):
f<sub>r</sub> = D(h) G(ω<sub>o</sub>, ω<sub>i</sub>) F / (4 cos θ<sub>o</sub> cos θ<sub>i</sub>),
here with F = 1 and Smith's height-correlated G. D is the distribution of microfacet normals,
of width α; GGX has long tails (a soft glow around the highlight). The lecture's
<code>brdf</code> sampler draws h from D(h) cos θ<sub>h</sub> and reflects ω<sub>o</sub> about
it, with the same Jacobian 1/(4 ω<sub>o</sub>·h) as Blinn-Phong. Its weight is
G (ω<sub>o</sub>·h) / (cos θ<sub>o</sub> cos θ<sub>h</sub>).</p>
<p><b>Why VNDF beats D·cos at grazing angles.</b> D·cos draws normals as the surface holds them,
ignoring where the viewer is. At a grazing view many of those normals face away from the viewer
or reflect ω<sub>o</sub> below the horizon (lost samples), and the weight above grows like
1/cos θ<sub>o</sub>. VNDF sampling draws only the normals the viewer can see, in proportion to
their visible area, p(h) = G<sub>1</sub>(ω<sub>o</sub>) max(0, ω<sub>o</sub>·h) D(h) / cos θ<sub>o</sub>.
Its weight is G<sub>2</sub>/G<sub>1</sub> ≤ 1 at every angle. Looking straight down both
densities are almost the same; the gap opens as θ<sub>o</sub> grows.</p>
"#;

const BECKMANN_INTRO: &str = r#"<p>The same Cook-Torrance model with the Beckmann distribution
of normals, a Gaussian-like D with shorter tails than GGX (a crisper highlight edge). The
samplers are the same: <code>brdf</code> draws h from D(h) cos θ<sub>h</sub>; <code>vndf</code>
draws only visible normals (for Beckmann this needs a numerical inversion, which makes it
slower per sample: compare the time and efficiency columns). The same reasoning holds: at grazing
views the D·cos weights G (ω<sub>o</sub>·h)/(cos θ<sub>o</sub> cos θ<sub>h</sub>) grow, and VNDF's
stay bounded by one.</p>
"#;
