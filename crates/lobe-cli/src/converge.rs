//! `lobe converge`: how fast the error of each strategy and sample sequence
//! falls with the number of samples. The curves and slopes come from
//! [`lobe::experiment::converge`]; this module parses the arguments, writes
//! the CSV and the plots, and prints the slopes.

use crate::common::with_ext;
use crate::common::{Bar, LightArgs, ViewArgs};
use crate::figures::{self, Series};
use anyhow::{Context, Result, bail};
use clap::Args;
use lobe::estimator::{Strategy, reference};
use lobe::experiment::converge::{
    Curve, CurveSettings, REFERENCE_TOLERANCE, curves, fit_start, product,
};
use lobe::math::luminance;
use lobe::sequence::Sequence;
use std::fmt::Write as _;
use std::path::PathBuf;
/// Largest accepted `--max-exp`: `N` up to 2^20 samples.
pub const MAX_EXP: u32 = 20;

/// The arguments of `lobe converge`.
#[derive(Args, Debug)]
#[command(
    about = "Plot the RMSE of each strategy and sequence against the number of samples",
    long_about = "For each strategy × sample sequence, estimate the luminance of the reflected \
                  radiance L_o(wo) = ∫ f_r L_i cos θi dωi with N = 1, 2, 4, ..., 2^K samples, R times \
                  with independent seeds, and measure the root mean square error against a \
                  deterministic quadrature reference (relative tolerance 1e-9).\n\n\
                  The slope of log RMSE against log N is fitted by least squares over the upper half \
                  of the log N range (N = 2^ceil(K/2) .. 2^K). Plain Monte Carlo converges as N^-1/2 \
                  (slope -0.5) whatever the strategy: importance sampling lowers the constant, not \
                  the rate. Stratified and Sobol points can do better on smooth integrands (Sobol: \
                  up to about -1.5).\n\n\
                  Each estimate uses exactly N samples from its own sequence (a Sobol sequence of \
                  length N, as a renderer would use), and run r at N = 2^k has the seed \
                  hash(S, r, k), so that the estimates at different N are independent. The numbers \
                  do not depend on the thread count (RAYON_NUM_THREADS).\n\n\
                  Writes PREFIX.csv (strategy,sequence,n,rmse,slope; slope is empty when it cannot \
                  be fitted, e.g. for an exact zero-variance estimator), PREFIX.svg and PREFIX.png, \
                  and prints the slopes.",
    after_help = "Examples:\n  \
                  lobe converge --material '{\"type\":\"phong\",\"exponent\":10}' --theta 30 --light beam:8 \\\n      \
                  --strategy cosine,brdf --max-exp 12 --out conv/phong\n  \
                  lobe converge --material @examples/ggx.toml --theta 75 --sequence independent,sobol --runs 16 --max-exp 12 --out ggx75"
)]
pub struct ConvergeArgs {
    /// Material: JSON text, @file.json or @file.toml (`lobe eval --help` lists the keys)
    #[arg(long, short = 'm', value_name = "JSON|@FILE")]
    pub material: String,
    #[command(flatten)]
    pub view: ViewArgs,
    #[command(flatten)]
    pub light: LightArgs,
    #[arg(long, default_value = "all", help = crate::estimate::strategy_help())]
    pub strategy: String,
    /// Comma-separated list of sample sequences: independent, stratified, sobol
    #[arg(long, default_value = "independent,stratified,sobol")]
    pub sequence: String,
    /// Independent estimates per N (the RMSE is over these)
    #[arg(long, default_value_t = 32)]
    pub runs: usize,
    /// Largest exponent K: N = 2^0, 2^1, ..., 2^K (K in 2..=20)
    #[arg(long, default_value_t = 16)]
    pub max_exp: u32,
    /// Seed S: run r at N = 2^k uses the seed hash(S, r, k)
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output prefix: writes PREFIX.csv, PREFIX.svg and PREFIX.png
    #[arg(long, value_name = "PREFIX")]
    pub out: PathBuf,
    /// No progress bar
    #[arg(long, short)]
    pub quiet: bool,
}

/// What to run: the series and the sample counts.
#[derive(Debug, Clone)]
pub struct Setup {
    pub strategies: Vec<Strategy>,
    pub sequences: Vec<Sequence>,
    pub runs: usize,
    pub max_exp: u32,
    pub seed: u64,
}

impl Setup {
    /// Every strategy × sequence, strategy-major.
    #[must_use]
    pub fn series(&self) -> Vec<(Strategy, Sequence)> {
        product(&self.strategies, &self.sequences)
    }
}

/// Parse a comma-separated list of sequences.
pub fn parse_sequences(spec: &str) -> Result<Vec<Sequence>> {
    let mut v = Vec::new();
    for name in spec.split(',').map(str::trim) {
        let q = crate::estimate::parse_sequence(name)?;
        if !v.contains(&q) {
            v.push(q);
        }
    }
    Ok(v)
}

/// The label of a curve in plots and tables.
#[must_use]
pub fn label(c: &Curve) -> String {
    format!("{} / {}", c.strategy, c.sequence)
}

/// The curves as plot series.
#[must_use]
pub fn plot_series(curves: &[Curve]) -> Vec<Series> {
    curves
        .iter()
        .map(|c| Series {
            strategy: c.strategy.name(),
            sequence: c.sequence.name().to_string(),
            points: c.points.iter().map(|&(n, e)| (n as f64, e)).collect(),
            slope: c.slope,
        })
        .collect()
}

/// The curves whose every RMSE is rounding (at most
/// [`crate::common::EXACT_RELATIVE_SD`] of the `target`) with their RMSE set
/// to 0 and no slope: an exact estimator, printed as `exact`, not as the
/// slope of its rounding (0.001).
pub fn zero_exact_curves(curves: &mut [Curve], target: f64) {
    for c in curves {
        if c.points
            .iter()
            .all(|p| p.1 <= crate::common::EXACT_RELATIVE_SD * target.abs())
        {
            for p in &mut c.points {
                p.1 = 0.0;
            }
            c.slope = None;
        }
    }
}

/// The CSV text: `strategy,sequence,n,rmse,slope`, one line per curve and N.
#[must_use]
pub fn csv(curves: &[Curve]) -> String {
    let mut s = String::from("strategy,sequence,n,rmse,slope\n");
    for c in curves {
        let slope = c.slope.map_or(String::new(), |x| x.to_string());
        for &(n, e) in &c.points {
            let _ = writeln!(s, "{},{},{n},{e},{slope}", c.strategy, c.sequence);
        }
    }
    s
}

/// The slopes as an aligned table: one row per strategy, one column per sequence.
#[must_use]
pub fn slope_table(curves: &[Curve], setup: &Setup) -> String {
    let width = setup
        .strategies
        .iter()
        .map(|s| s.name().len())
        .max()
        .unwrap_or(8)
        .max("strategy".len());
    let col = setup
        .sequences
        .iter()
        .map(|q| q.name().len())
        .max()
        .unwrap_or(5)
        .max(8);
    let mut out = format!("{:<width$}", "strategy");
    for q in &setup.sequences {
        let _ = write!(out, "  {:>col$}", q.name());
    }
    out.push('\n');
    for s in &setup.strategies {
        let _ = write!(out, "{:<width$}", s.name());
        for q in &setup.sequences {
            let cell = match curves.iter().find(|c| c.strategy == *s && c.sequence == *q) {
                Some(Curve { slope: Some(x), .. }) => format!("{x:.3}"),
                Some(c) if c.points.iter().all(|p| p.1 == 0.0) => "exact".to_string(),
                _ => "n/a".to_string(),
            };
            let _ = write!(out, "  {cell:>col$}");
        }
        out.push('\n');
    }
    out
}

pub fn run(args: &ConvergeArgs) -> Result<()> {
    if args.runs == 0 {
        bail!("--runs 0: the RMSE needs at least one run");
    }
    if !(2..=MAX_EXP).contains(&args.max_exp) {
        bail!(
            "--max-exp {}: must be between 2 and {MAX_EXP} (N = 2^0 .. 2^K samples)",
            args.max_exp
        );
    }
    let sequences = parse_sequences(&args.sequence)?;
    crate::common::prepare_output_files(
        "--out",
        &["csv", "svg", "png"].map(|e| with_ext(&args.out, e)),
    )?;
    let m = crate::common::load_material(&args.material)?;
    let wo = args.view.wo(&m)?;
    let light = args.light.light()?;
    let strategies =
        crate::estimate::parse_strategies(&args.strategy, &m, m.best_bsdf_strategy(), 1, 1)?;
    let setup = Setup {
        strategies,
        sequences,
        runs: args.runs,
        max_exp: args.max_exp,
        seed: args.seed,
    };

    let sp = args.light.shading_point(&light, wo)?;
    let target = luminance(reference(&m, &sp, &light, REFERENCE_TOLERANCE));
    if !target.is_finite() {
        bail!("the quadrature reference is not finite ({target})");
    }
    let series = setup.series();
    let bar = Bar::new(args.quiet);
    let mut curves = curves(
        &m,
        &sp,
        &light,
        target,
        &series,
        CurveSettings {
            runs: setup.runs,
            max_exp: setup.max_exp,
            seed: setup.seed,
        },
        &bar,
    )?;
    bar.finish();
    zero_exact_curves(&mut curves, target);
    if let Some(c) = curves
        .iter()
        .find(|c| c.points.iter().any(|p| !p.1.is_finite()))
    {
        bail!(
            "{}: an estimate is not a finite number (RMSE {:?})",
            label(c),
            c.points
        );
    }

    let csv_path = with_ext(&args.out, "csv");
    std::fs::write(&csv_path, csv(&curves))
        .with_context(|| format!("cannot write {}", csv_path.display()))?;
    let theta = wo.z.clamp(-1.0, 1.0).acos().to_degrees();
    let title = format!(
        "{}, θo = {theta:.0}°, light {}: RMSE of {} runs",
        m.model_name(),
        args.light.light,
        setup.runs
    );
    let plot = plot_series(&curves);
    for ext in ["svg", "png"] {
        let path = with_ext(&args.out, ext);
        figures::convergence_plot(&path, &title, &plot)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }

    let start = fit_start(setup.max_exp);
    println!(
        "{} at θo = {theta:.1}°, light {}: reference luminance {target:.6e}",
        m.model_name(),
        args.light.light
    );
    println!(
        "RMSE over {} runs for N = 2^0 .. 2^{}; slope of log RMSE vs log N, least squares over the upper half N = 2^{start} .. 2^{}",
        setup.runs, setup.max_exp, setup.max_exp
    );
    println!("(-0.5 is plain Monte Carlo; `exact` means a zero-variance estimator)\n");
    print!("{}", slope_table(&curves, &setup));
    println!(
        "\nwrote {}, {} and {}",
        csv_path.display(),
        with_ext(&args.out, "svg").display(),
        with_ext(&args.out, "png").display()
    );
    Ok(())
}
