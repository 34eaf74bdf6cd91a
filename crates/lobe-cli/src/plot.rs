//! `lobe plot`: pictures of a material and a sampling strategy.
//!
//! * `polar`: in the plane of incidence at the chosen view, the integrand
//!   `f·cos θi / albedo` (cosine included; the pdf of a zero-variance
//!   sampler) and the pdf of the chosen strategy (or of every strategy) on
//!   the same axes, linear or log radius
//!   ([`lobe::experiment::polar`] computes the curves).
//! * `histogram`: Nori's warp test, observed against expected sample counts
//!   over the projected hemisphere, with the p-value of the chi-square test
//!   of `lobe::stats::chi2`.
//! * `weights`: the sample weight `f·cos/pdf` over the projected hemisphere.
//!
//! Where the material transmits (or is seen from below) the figures cover
//! the whole sphere: the polar plot goes round the full circle, the maps
//! are two disks, above and below the surface.
//!
//! The figures themselves are drawn by [`crate::figures`].

use crate::common::load_material;
use crate::common::{Bar, ViewArgs};
use crate::figures;
use anyhow::{Context, Result, anyhow, bail};
use clap::Args;
use glam::DVec3;
use lobe::experiment::warp_test::{WarpTest, chi2_config, warp_test};
use lobe::stats::chi2::Chi2Settings;
use lobe::{BsdfStrategy, Material};
use std::path::{Path, PathBuf};

/// Largest accepted `--res`.
const MAX_RES: usize = 1024;

/// The arguments of `lobe plot`.
#[derive(Args, Debug)]
#[command(
    about = "Draw figures of a material and a sampling strategy (PNG)",
    long_about = "Draw figures of a material and a sampling strategy as PNG files in --out:\n  \
        polar      in the plane of incidence at --theta/--wo: f·cos θi / albedo (the ideal\n             \
        pdf) against the pdf of --strategy (without it, of every strategy) on the\n             \
        same axes; --scale linear or log radius               -> polar.png\n             \
        with --fit (a measured material) or --against M: the material against\n             \
        its Cook-Torrance fit, or M, at θo = 0°, 30°, 60°, 75° -> polar-fit.png\n  \
        histogram  the warp test: observed against expected sample counts over the\n             \
        projected hemisphere, with the chi-square p-value     -> histogram-<STRATEGY>.png\n  \
        weights    the sample weight f·cos θi/pdf over the projected hemisphere,\n             \
        directions never sampled in red                       -> weights-<STRATEGY>.png\n  \
        all        the three\n\
        Glass and other materials that transmit (and two-sided ones seen from below, --theta\n\
        above 90): the polar plot goes round the full circle, the maps cover both hemispheres.\n\
        Delta lobes (smooth glass, mirrors, plastic's coating) have no density and are not drawn.\n\
        Prints the paths it wrote, one per line; the chi-square result goes to stderr.",
    after_help = "Examples:\n  \
        lobe plot --material '{\"type\":\"cook-torrance\",\"alpha\":0.3}' --theta 60 --strategy vndf --out figs\n  \
        lobe plot --material '{\"type\":\"phong\",\"exponent\":50}' --strategy uniform --kind weights --out figs\n  \
        lobe plot --material @examples/gold.toml --wo 0.5,0.2,0.8 --strategy brdf --kind histogram --samples 100000 --out figs"
)]
pub struct PlotArgs {
    /// Material: JSON text, @FILE.json or @FILE.toml (keys: see `lobe eval --help`)
    #[arg(long, short)]
    pub material: String,
    #[command(flatten)]
    pub view: ViewArgs,
    /// Sampling strategy: uniform, cosine, brdf, vndf, spherical-caps, bounded-vndf (polar: the pdf drawn against f·cos; all of them when not given)
    #[arg(long, short)]
    pub strategy: Option<String>,
    /// What to draw: polar, histogram, weights or all
    #[arg(long, short, default_value = "all")]
    pub kind: String,
    /// Directory to write the PNG files to (created if missing)
    #[arg(long, short)]
    pub out: PathBuf,
    /// Samples drawn for the histogram and the chi-square test: a whole
    /// number such as 100000, 1e6 or 2^20
    #[arg(long, short = 'n', default_value_t = 1_000_000, value_parser = crate::common::samples_usize)]
    pub samples: usize,
    /// Seed of the random stream of the histogram and the chi-square test
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Pixels per side of the histogram and weight maps, 1 to 1024
    #[arg(long, default_value_t = 64)]
    pub res: usize,
    /// No progress bars
    #[arg(long, short)]
    pub quiet: bool,
    /// Radius of the polar plot: linear, or log (four decades below the
    /// largest value), one scale for every curve
    #[arg(long, default_value = "linear")]
    pub scale: String,
    /// Polar: also fit Cook-Torrance (GGX or Beckmann, as `lobe fit` does,
    /// Schlick Fresnel) to the material (a measured one, in practice) and
    /// draw the fit against the data, f·cos θi in the plane of incidence
    /// at θo = 0°, 30°, 60° and 75°                   -> polar-fit.png
    #[arg(long, value_name = "ggx|beckmann", num_args = 0..=1, default_missing_value = "ggx",
          value_parser = ["ggx", "beckmann"])]
    pub fit: Option<String>,
    /// Polar: draw this material (JSON, @FILE; e.g. the one `lobe fit`
    /// printed) against --material, as --fit does, without fitting
    #[arg(long, value_name = "JSON|@FILE", conflicts_with = "fit")]
    pub against: Option<String>,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Polar,
    Histogram,
    Weights,
}

/// Run `lobe plot`.
pub fn run(args: &PlotArgs) -> Result<()> {
    let kinds: Vec<Kind> = match args.kind.as_str() {
        "polar" => vec![Kind::Polar],
        "histogram" => vec![Kind::Histogram],
        "weights" => vec![Kind::Weights],
        "all" => vec![Kind::Polar, Kind::Histogram, Kind::Weights],
        k => bail!("--kind {k}: unknown kind, expected polar, histogram, weights or all"),
    };
    let scale: figures::PolarScale = args
        .scale
        .parse()
        .map_err(|e| anyhow!("--scale {}: {e}", args.scale))?;
    let material = load_material(&args.material)?;
    // Over the whole sphere where the material transmits or is seen from
    // below (two-sided): the polar plot round the full circle, the maps
    // as two disks, one per hemisphere.
    let wo = args.view.wo(&material)?;
    if (args.fit.is_some() || args.against.is_some()) && !kinds.contains(&Kind::Polar) {
        bail!("--fit and --against draw polar figures: use --kind polar or all");
    }
    if args.fit.is_some() || args.against.is_some() {
        crate::common::refuse_transmission(&material, "plot --fit or --against")?;
    }
    crate::common::refuse_all_delta(&material, wo)?;
    let needs_strategy = kinds.iter().any(|&k| k != Kind::Polar);
    let strategy = match (&args.strategy, needs_strategy) {
        (Some(s), _) => {
            let s: BsdfStrategy = s.parse().map_err(|_| {
                anyhow!(
                    "--strategy {s}: unknown strategy, expected one of: {}",
                    BsdfStrategy::names()
                )
            })?;
            material
                .check(s)
                .map_err(|e| anyhow!("--strategy {s}: {e}"))?;
            Some(s)
        }
        (None, true) => bail!(
            "--strategy is needed for --kind {}: one of {}",
            args.kind,
            BsdfStrategy::names()
        ),
        (None, false) => None,
    };
    if needs_strategy {
        if args.samples == 0 && kinds.contains(&Kind::Histogram) {
            bail!("--samples 0: the histogram needs at least one sample");
        }
        if args.res == 0 || args.res > MAX_RES {
            bail!("--res {}: must be between 1 and {MAX_RES}", args.res);
        }
    }
    crate::common::prepare_output_dir("--out", &args.out)?;

    let label = material_label(&args.material, &material);
    let view = view_label(args, wo);
    for kind in kinds {
        match kind {
            Kind::Polar => {
                let path = args.out.join("polar.png");
                let strategies = strategy.map_or_else(
                    || lobe::experiment::polar::default_strategies(&material),
                    |s| vec![s],
                );
                let curves = lobe::experiment::polar::curves(
                    &material,
                    wo,
                    &strategies,
                    lobe::experiment::polar::DEFAULT_STEPS,
                )?;
                let what = match strategy {
                    Some(s) => format!("the pdf of {s}"),
                    None => "each strategy's pdf".to_string(),
                };
                let title = format!("{label}, {view}: f·cos θi ÷ albedo against {what}");
                figures::polar_plot(&path, &title, &curves, scale)?;
                println!("{}", path.display());
                if let Some((other, what)) = comparison(args, &material)? {
                    let path = args.out.join("polar-fit.png");
                    let title = format!("{label} (black) against {what} (red): f·cos θi");
                    let legend = if args.fit.is_some() {
                        ["data", "fit"]
                    } else {
                        ["--material", "--against"]
                    };
                    figures::fit_polar_plot(&path, &title, &material, &other, legend, scale)?;
                    println!("{}", path.display());
                }
            }
            Kind::Histogram => {
                let s = strategy.expect("checked above");
                let path = args.out.join(format!("histogram-{s}.png"));
                histogram(
                    args,
                    &material,
                    s,
                    wo,
                    &format!("{label}, {s}, {view}"),
                    &path,
                )?;
                println!("{}", path.display());
            }
            Kind::Weights => {
                let s = strategy.expect("checked above");
                let path = args.out.join(format!("weights-{s}.png"));
                let title = format!("{label}, {s}, {view}: sample weight f·|cos θi| / pdf");
                figures::weight_heatmap(&path, &title, &material.sampler(s)?, wo, args.res)?;
                println!("{}", path.display());
            }
        }
    }
    Ok(())
}

/// A short name of the material for titles: the file name, the JSON text
/// in one line, or the model name when that is too long.
fn material_label(arg: &str, m: &Material) -> String {
    if let Some(path) = arg.strip_prefix('@') {
        return Path::new(path)
            .file_name()
            .map_or_else(|| path.to_string(), |f| f.to_string_lossy().into_owned());
    }
    let compact = minify(arg);
    if compact.chars().count() <= 60 {
        compact
    } else {
        m.model_name().to_string()
    }
}

/// JSON text on one line without the blanks outside strings, keys in the
/// user's order.
fn minify(json: &str) -> String {
    let mut out = String::with_capacity(json.len());
    let (mut in_string, mut escaped) = (false, false);
    for c in json.trim().chars() {
        if in_string {
            out.push(c);
            if escaped {
                escaped = false;
            } else if c == '\\' {
                escaped = true;
            } else if c == '"' {
                in_string = false;
            }
        } else if c == '"' {
            in_string = true;
            out.push(c);
        } else if !c.is_whitespace() {
            out.push(c);
        }
    }
    out
}

/// `θo = 60°` or `wo = (x, y, z)`.
fn view_label(args: &PlotArgs, wo: DVec3) -> String {
    if args.view.wo.is_some() {
        format!("wo = ({:.3}, {:.3}, {:.3})", wo.x, wo.y, wo.z)
    } else {
        format!("θo = {}°", args.view.theta.unwrap_or(30.0))
    }
}

/// The warp-test figure: histograms, the chi-square test, its summary on
/// stderr.
fn histogram(
    args: &PlotArgs,
    m: &Material,
    s: BsdfStrategy,
    wo: DVec3,
    title: &str,
    path: &Path,
) -> Result<()> {
    let sampler = m.sampler(s)?;
    let config = Chi2Settings {
        samples: args.samples,
        seed: args.seed,
        ..chi2_config(m)
    };
    let bar = Bar::new(args.quiet);
    let WarpTest {
        histograms: h,
        chi2: result,
        config: cfg,
    } = warp_test(&sampler, wo, config, args.res, &bar);
    bar.finish();
    let verdict = if result.p_value > figures::PASS_LEVEL {
        "pass"
    } else {
        "FAIL"
    };
    eprintln!(
        "chi-square ({} × {} bins over the sphere, {} samples): statistic {:.1}, {} dof, p = {:.4e}: {verdict} at {}%{}",
        cfg.n_z,
        cfg.n_phi,
        cfg.samples,
        result.statistic,
        result.dof,
        result.p_value,
        figures::PASS_LEVEL * 100.0,
        result
            .message
            .as_deref()
            .map(|m| format!(" ({m})"))
            .unwrap_or_default()
    );
    figures::warp_histogram(path, title, &h.observed, &h.expected, h.res, result.p_value)
}

/// The material `--fit` fits or `--against` names, and how to call it.
fn comparison(args: &PlotArgs, data: &Material) -> Result<Option<(Material, String)>> {
    if let Some(spec) = &args.against {
        let m = load_material(spec).context("--against")?;
        crate::common::refuse_transmission(&m, "plot").context("--against")?;
        let label = material_label(spec, &m);
        return Ok(Some((m, label)));
    }
    let Some(dist) = &args.fit else {
        return Ok(None);
    };
    let options = lobe::fit::FitSettings {
        distribution: if dist == "beckmann" {
            lobe::Ndf::Beckmann
        } else {
            lobe::Ndf::Ggx
        },
        ..lobe::fit::FitSettings::default()
    };
    let pb = if args.quiet {
        indicatif::ProgressBar::hidden()
    } else {
        crate::fit::spinner("fitting")
    };
    let fit = lobe::fit::fit(data, options);
    pb.finish_and_clear();
    let fit = fit.context("--fit")?;
    eprintln!("fit: {} (error E = {:.3e})", fit.to_json(), fit.error);
    Ok(Some((
        fit.material()?,
        format!(
            "its fit ({}; E = {:.2e})",
            crate::fit::fit_label(&fit),
            fit.error
        ),
    )))
}
