//! `lobe compare`: render one scene under several strategies, at equal
//! samples and at equal time, next to a high-spp reference, and draw one
//! grid of the renders with their per-pixel error maps and RMSE.
//!
//! The renders and the numbers come from [`lobe_render::compare`]; this
//! module parses the arguments, shows progress, draws the grid
//! ([`write_grid`]) and writes NAME.json ([`summary`]). `lobe demo` draws
//! its showcase with the same pieces.

use crate::common::Bar;
use crate::compare_figure::{FigureInfo, FigureSpec, sections, write_grid};
use crate::draw::{fmt_time, sig3};
use anyhow::{Result, anyhow, bail};
use clap::Args;
use lobe::estimator::Strategy;
use lobe::progress::SystemClock;
use lobe_render::compare::{
    CompareSettings, Comparison, Shot, default_reference_spp, default_strategies, run_comparison,
};
use lobe_render::{fallbacks, load_scene};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The arguments of `lobe compare`.
#[derive(Args, Debug)]
#[command(
    about = "Compare strategies on a scene at equal samples and equal time, with error maps",
    long_about = "Render a scene file (the format of `lobe render --help`) with each strategy twice: at \
                  equal samples (every strategy at --spp) and at equal time (every strategy with the \
                  samples per pixel that make its render take the time mis took at max(--spp, 32) spp (more when that is under 50 ms), \
                  or the slowest strategy when mis is not compared, within 3%: each is rendered again, \
                  up to 4 times, with the spp its earlier renders' times point to). Times are of the \
                  render alone: every strategy is first rendered once untimed (the start-up: threads, \
                  tables, memory), and a render under 0.1 s is timed as the fastest of 3 runs. The \
                  budget is at least 32 spp because whole samples per pixel cannot make small budgets \
                  equal (at 4 spp one sample is 25%). A reference is rendered with mis-balance at \
                  --reference-spp, from an independent seed.\n\n\
                  The RMSE of BSDF sampling (brdf, vndf) under the built-in sky is a few fireflies': \
                  a rare sample that finds the small, bright sun puts most of the squared error into \
                  one pixel (the `worst px` column), so its RMSE changes several-fold with --seed (on \
                  examples/scene.toml at 4 spp, seeds 1 to 8: brdf 1.2 to 28, vndf 1.2 to 26, the \
                  same mean); the table says when this is so.\n\n\
                  Writes NAME.png, one figure: the reference, and for each strategy and each row (equal \
                  samples, equal time) the render (tone-mapped as `lobe render`'s PNG) with its per-pixel \
                  error map: the relative error of luminance |Y - Y_ref| / (Y_ref + eps), eps = 1% of the \
                  reference's mean luminance, on one logarithmic colour scale shared by every map. Each \
                  caption gives the strategy, spp, wall time and RMSE (over all pixels and the three \
                  channels of linear RGB, against the reference). NAME.json holds the numbers: \
                  {\"reference\":{\"spp\",\"time_s\",..},\"equal_samples\":[{\"strategy\",\"spp\",\"time_s\",\
                  \"rmse\"}],\"equal_time\":[..],..}.\n\n\
                  The renders are the same for a given seed and spp on any thread count; the equal-time \
                  spp depend on the measured times.",
    after_help = "Examples:\n  \
                  lobe compare examples/scene.toml --spp 16 --out cmp\n  \
                  lobe compare examples/scene.toml --strategy brdf,light,mis,mis-one --spp 4 --reference-spp 256 --threads 2"
)]
pub struct CompareArgs {
    /// The scene file (TOML; `lobe render --help` shows the format)
    pub scene: PathBuf,
    /// Samples per pixel of the equal-samples row (default: the scene's
    /// render.spp): a whole number such as 64, 1e3 or 2^8
    #[arg(long, value_parser = crate::common::spp_u32)]
    pub spp: Option<u32>,
    /// Seed of the random streams (default: the scene's render.seed)
    #[arg(long)]
    pub seed: Option<u64>,
    /// Sample pattern of every render: sobol, stratified or independent
    /// (default: the scene's render.sequence, itself sobol by default)
    #[arg(long)]
    pub sequence: Option<String>,
    /// Worker threads (default: one per core)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
    /// Output name: writes NAME.png and NAME.json (default: the scene file's
    /// stem followed by -compare, in the current directory)
    #[arg(long, value_name = "NAME")]
    pub out: Option<PathBuf>,
    /// Samples per pixel of the mis reference (default: 16 × spp, at least 1024)
    #[arg(long, value_name = "R", value_parser = crate::common::spp_u32)]
    pub reference_spp: Option<u32>,
    #[arg(long = "strategy", alias = "strategies", value_name = "LIST", help = strategy_help())]
    pub strategies: Option<String>,
    /// No progress bars and no notes
    #[arg(long, short)]
    pub quiet: bool,
}

/// The help of `--strategy`: every accepted name.
fn strategy_help() -> String {
    format!(
        "Comma-separated strategies (default: {}). {}",
        lobe_render::compare::DEFAULT_STRATEGIES,
        crate::common::strategy_help()
    )
}

/// Parse `--strategy`: a comma-separated list of strategy names, each once.
pub fn parse_strategies_list(spec: &str) -> Result<Vec<Strategy>> {
    let mut v = Vec::new();
    for name in spec.split(',').map(str::trim) {
        if name.is_empty() {
            bail!(
                "--strategy {spec}: an empty name; expected a comma-separated list of: {}",
                Strategy::names()
            );
        }
        let m: Strategy = name.parse().map_err(|e| anyhow!("--strategy: {e}"))?;
        if !v.contains(&m) {
            v.push(m);
        }
    }
    Ok(v)
}

/// Warn on stderr of every render whose path samples were not all finite
/// (an equal-time shot that is its pilot was not rendered again).
pub fn warn_nonfinite(cmp: &Comparison) {
    let spp = cmp.equal_samples.first().map_or(0, |s| s.spp);
    let rendered = cmp
        .equal_samples
        .iter()
        .chain(
            cmp.equal_time
                .iter()
                .flat_map(|e| e.shots.iter().filter(|s| s.spp != spp)),
        )
        .chain(std::iter::once(&cmp.reference));
    for s in rendered {
        if s.image.stats.nonfinite > 0 {
            eprintln!(
                "lobe: warning: {} at {} spp: {} path samples were not finite numbers and counted as 0",
                s.strategy, s.spp, s.image.stats.nonfinite
            );
        }
    }
}

/// [`run_comparison`] with a progress bar (hidden when `quiet`) and the
/// system clock, then the warnings of [`warn_nonfinite`].
#[must_use]
pub fn run_with_progress(
    scene: &lobe_render::Scene,
    settings: &CompareSettings,
    quiet: bool,
) -> Comparison {
    let bar = Bar::new(quiet);
    let cmp = run_comparison(scene, settings, &bar, &SystemClock::new());
    bar.finish();
    warn_nonfinite(&cmp);
    cmp
}

// ---------------------------------------------------------------------------
// The numbers
// ---------------------------------------------------------------------------

#[derive(Debug, Clone, Serialize)]
pub struct ShotJson {
    pub strategy: String,
    pub spp: u32,
    pub time_s: f64,
    pub rmse: f64,
    /// The share of the squared error (RMSE²) in the worst pixel
    /// ([`worst_pixel_share`]).
    pub worst_pixel_share: f64,
}

#[derive(Debug, Clone, Serialize)]
pub struct ReferenceJson {
    pub strategy: String,
    pub spp: u32,
    pub time_s: f64,
    pub seed: u64,
}

/// NAME.json.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    pub scene: String,
    pub width: usize,
    pub height: usize,
    pub seed: u64,
    pub sequence: &'static str,
    pub max_depth: u32,
    pub reference: ReferenceJson,
    pub equal_samples: Vec<ShotJson>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub equal_time: Option<Vec<ShotJson>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_budget_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_budget_from: Option<String>,
    pub rmse: &'static str,
    pub error_map: &'static str,
    pub figure: FigureInfo,
}

fn shots_json(shots: &[Shot], reference: &Shot) -> Vec<ShotJson> {
    shots
        .iter()
        .map(|s| ShotJson {
            strategy: s.strategy.name().to_string(),
            spp: s.spp,
            time_s: s.time_s,
            rmse: s.rmse,
            worst_pixel_share: worst_pixel_share(s, reference),
        })
        .collect()
}

/// The share of a render's squared error against the reference (the sum
/// over pixels of |render − reference|², RMSE² up to a constant) that is in
/// its worst pixel: near 1, the RMSE is one firefly's (0 for no error).
#[must_use]
pub fn worst_pixel_share(s: &Shot, reference: &Shot) -> f64 {
    let (mut sum, mut worst) = (0.0f64, 0.0f64);
    for (p, r) in s.image.pixels.iter().zip(&reference.image.pixels) {
        let e = (*p - *r).length_squared();
        sum += e;
        worst = worst.max(e);
    }
    if sum > 0.0 { worst / sum } else { 0.0 }
}

/// Above this [`worst_pixel_share`], a render's RMSE is called a firefly's
/// in the printed table.
pub const FIREFLY_SHARE: f64 = 0.25;

/// The numbers of a comparison, for NAME.json.
#[must_use]
pub fn summary(scene: &str, s: &CompareSettings, cmp: &Comparison, figure: FigureInfo) -> Summary {
    let r = &cmp.reference;
    Summary {
        scene: scene.to_string(),
        width: r.image.width,
        height: r.image.height,
        seed: s.seed,
        sequence: s.sequence.name(),
        max_depth: s.max_depth,
        reference: ReferenceJson {
            strategy: r.strategy.name().to_string(),
            spp: r.spp,
            time_s: r.time_s,
            seed: cmp.reference_seed,
        },
        equal_samples: shots_json(&cmp.equal_samples, &cmp.reference),
        equal_time: cmp
            .equal_time
            .as_ref()
            .map(|e| shots_json(&e.shots, &cmp.reference)),
        time_budget_s: cmp.equal_time.as_ref().map(|e| e.budget_s),
        time_budget_from: cmp.equal_time.as_ref().map(|e| e.budget_from.clone()),
        rmse: "root mean square over all pixels and the three channels of (render - reference), linear RGB",
        error_map: "per pixel |Y - Y_ref| / (Y_ref + eps) of luminance, eps = 1% of the reference's mean luminance",
        figure,
    }
}

/// Write `summary` as pretty JSON to `path`.
pub fn write_json(path: &Path, summary: &Summary) -> Result<()> {
    let text = serde_json::to_string_pretty(summary)?;
    std::fs::write(path, text + "\n").map_err(|e| anyhow!("{}: cannot write: {e}", path.display()))
}

/// The table of a comparison, for stdout.
pub fn print_table(cmp: &Comparison) {
    let r = &cmp.reference;
    println!(
        "reference: {} at {} spp, {}",
        r.strategy,
        r.spp,
        fmt_time(r.time_s)
    );
    let mut fireflies: Vec<String> = Vec::new();
    for (heading, shots) in sections(cmp) {
        println!("{heading}");
        println!(
            "  {:<15} {:>8} {:>10} {:>12} {:>10}",
            "strategy", "spp", "time", "RMSE", "worst px"
        );
        for s in shots {
            let share = worst_pixel_share(s, r);
            if share > FIREFLY_SHARE && !fireflies.contains(&s.strategy.name()) {
                fireflies.push(s.strategy.name());
            }
            println!(
                "  {:<15} {:>8} {:>10} {:>12} {:>9.0}%",
                s.strategy.name(),
                s.spp,
                fmt_time(s.time_s),
                sig3(s.rmse),
                100.0 * share
            );
        }
    }
    println!(
        "time: of the render alone, after an untimed warm-up (the fastest of {} runs below {}); worst px: the share of the squared error in the worst pixel",
        lobe_render::compare::SHORT_RENDER_RUNS,
        fmt_time(lobe_render::compare::SHORT_RENDER_S)
    );
    if !fireflies.is_empty() {
        println!(
            "{}: one pixel holds more than {:.0}% of the squared error: a firefly, a rare sample of a large weight (BSDF sampling that found the small, bright sun; light sampling that found a sharp highlight). Such an RMSE changes several-fold with --seed; do not rank these strategies by one seed",
            fireflies.join(", "),
            100.0 * FIREFLY_SHARE
        );
    }
}

/// Run `lobe compare`.
pub fn run(args: &CompareArgs) -> Result<()> {
    if args.spp == Some(0) {
        bail!("--spp 0: at least 1 sample per pixel");
    }
    if args.reference_spp == Some(0) {
        bail!("--reference-spp 0: at least 1 sample per pixel");
    }
    let strategies = args
        .strategies
        .as_deref()
        .map(parse_strategies_list)
        .transpose()?;
    let base = crate::common::output_base(
        args.out.as_deref(),
        &args.scene,
        &["png", "json"],
        "-compare",
    )?;
    crate::common::prepare_output_files(
        "--out",
        &["png", "json"].map(|e| crate::common::with_ext(&base, e)),
    )?;
    let scene = load_scene(&args.scene)?;
    crate::common::warn_scene_energy_gain(&scene, &args.scene);
    let strategies = strategies.unwrap_or_else(|| default_strategies(&scene));
    let spp = args
        .spp
        .unwrap_or(u32::try_from(scene.settings.spp).unwrap_or(u32::MAX))
        .max(1);
    let settings = CompareSettings {
        strategies,
        spp,
        reference_spp: args
            .reference_spp
            .unwrap_or_else(|| default_reference_spp(spp)),
        seed: args.seed.unwrap_or(scene.settings.seed),
        sequence: match &args.sequence {
            Some(s) => crate::estimate::parse_sequence(s)?,
            None => scene.settings.sequence,
        },
        max_depth: scene.settings.max_depth,
        threads: args.threads.map(|t| t as usize),
        equal_time: true,
    };
    for w in &scene.warnings {
        eprintln!("lobe: warning: {w}");
    }
    if let Some(n) = lobe_render::integrator::shallow_glass(&scene, settings.max_depth) {
        eprintln!("lobe: note: {n}");
    }
    if !args.quiet {
        for &m in &settings.strategies {
            for f in fallbacks(&scene, m) {
                eprintln!(
                    "lobe: note: object {} ({}): {} does not apply to its material, using {}",
                    f.object, f.model, f.requested, f.used
                );
            }
        }
        if settings.reference_spp <= spp {
            eprintln!(
                "lobe: note: the reference ({} spp) has no more samples than the compared renders ({spp} spp): its own noise will dominate the errors",
                settings.reference_spp
            );
        }
    }
    let cmp = run_with_progress(&scene, &settings, args.quiet);
    let png = crate::common::with_ext(&base, "png");
    let json = crate::common::with_ext(&base, "json");
    let (w, h) = (scene.camera.width, scene.camera.height);
    let name = args.scene.display().to_string();
    let figure = write_grid(
        &png,
        &FigureSpec {
            title: format!(
                "lobe compare: {name} · {w}×{h} · seed {} · max_depth {}",
                settings.seed, settings.max_depth
            ),
            cmp: &cmp,
            labels: Vec::new(),
        },
    )?;
    write_json(&json, &summary(&name, &settings, &cmp, figure))?;
    print_table(&cmp);
    println!("wrote {} and {}", png.display(), json.display());
    Ok(())
}
