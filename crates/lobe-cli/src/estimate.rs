//! `lobe estimate`: estimate the reflected radiance at one shading point with
//! each strategy and measure its noise against a quadrature reference.

use crate::common::{Bar, LightArgs, ViewArgs};
use anyhow::Result;
use clap::Args;
use glam::DVec3;
use lobe::estimator::Strategy;
use lobe::experiment::estimate::{EstimateTableSettings, MAX_MIS_SAMPLES, Setting, estimate_table};
use lobe::experiment::table::{StderrMethod, Table};
use lobe::progress::SystemClock;
use lobe::sequence::Sequence;
use lobe::{BsdfStrategy, Material};

#[derive(Args, Debug)]
#[command(
    about = "Estimate reflected radiance with each strategy and measure its noise",
    long_about = "Estimate L_o(wo) = ∫ f_r(wo, wi) L_i(wi) cos θi dωi at one shading point with each \
                  sampling strategy, and compare with a reference computed by deterministic adaptive \
                  quadrature in f64 (relative tolerance 1e-9; never a long Monte Carlo run).\n\n\
                  Columns: the estimate and its standard error (RGB), the relative error of the \
                  estimate's luminance against the reference, the per-sample variance of the luminance \
                  of f·L·cos/p, the variance reduction against `uniform` (the exact variance of uniform \
                  sampling, 2π ∫ lum(f L cos)² dω − μ² by quadrature, over this one's), the wall time, \
                  and the efficiency 1/(variance × time).\n\n\
                  Standard errors: on the independent sequence, the sample standard deviation over √N. \
                  Under stratified and Sobol points, whose samples are not independent, the N samples are \
                  cut into R (--replicas, default 16) independently randomized replicas of N/R points; the \
                  estimate is the mean of the replica means and its standard error their standard \
                  deviation over √R. The table and the JSON (`stderr_method`, `replicas`) say which.",
    after_help = "Examples:\n  \
                  lobe estimate --material '{\"type\":\"phong\",\"exponent\":100}' --theta 30 --samples 65536\n  \
                  lobe estimate --material @examples/ggx.toml --theta 70 --light beam:16:1,1,0 --strategy brdf,vndf --json\n  \
                  lobe estimate --material '{\"type\":\"lambert\"}' --wo 0.3,0,1 --sequence sobol"
)]
pub struct EstimateArgs {
    /// Material: JSON text, @file.json or @file.toml (`lobe eval --help` lists the keys)
    #[arg(long, short = 'm', value_name = "JSON|@FILE")]
    pub material: String,
    #[command(flatten)]
    pub view: ViewArgs,
    #[command(flatten)]
    pub light: LightArgs,
    /// Samples per strategy: a whole number such as 65536, 1e6 or 2^20
    #[arg(long, short = 'n', default_value_t = 65536, value_parser = crate::common::samples_usize)]
    pub samples: usize,
    #[arg(long, default_value = "all", help = strategy_help())]
    pub strategy: String,
    /// Independently randomized replicas whose spread gives the standard
    /// error under stratified and Sobol points (N/R points each; not used
    /// on the independent sequence)
    #[arg(long, short = 'r', default_value_t = lobe::experiment::table::REPLICAS)]
    pub replicas: usize,
    /// Seed of the sample sequence
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Sample sequence: independent, stratified or sobol
    #[arg(long, default_value = "independent")]
    pub sequence: String,
    /// The BSDF strategy that MIS combines with light sampling (default: vndf
    /// where the material has it, else brdf)
    #[arg(long)]
    pub mis_bsdf: Option<String>,
    /// Samples per technique for MIS: BSDF,LIGHT (multi-sample: an estimate
    /// uses both; one-sample: the chance of each)
    #[arg(long, default_value = "1,1")]
    pub mis_samples: String,
    /// Print JSON instead of a table
    #[arg(long)]
    pub json: bool,
    /// No progress bars
    #[arg(long, short)]
    pub quiet: bool,
}

/// The help of `--strategy`: every accepted name.
#[must_use]
pub fn strategy_help() -> String {
    format!(
        "`all` or a comma-separated list of strategies (all: {}). {}",
        lobe::strategy::ALL_MEANS,
        crate::common::strategy_help()
    )
}

/// Parse `all` or a list of strategy names: the BSDF strategies
/// (uniform, cosine, brdf, vndf, spherical-caps, bounded-vndf), `light`,
/// and MIS: `mis` (adaptive), `mis-balance` and `mis-power`, multi-sample,
/// or `mis-one` and `mis-power-one`, one-sample. Each is checked against the
/// material.
pub fn parse_strategies(
    spec: &str,
    m: &Material,
    mis_bsdf: BsdfStrategy,
    n_bsdf: u32,
    n_light: u32,
) -> Result<Vec<Strategy>> {
    Strategy::parse_list(spec.split(','), m, mis_bsdf, n_bsdf, n_light)
        .map_err(|e| anyhow::anyhow!("--strategy: {e}"))
}

/// `B,L`: samples of BSDF and light sampling per MIS estimate (their
/// range is checked with the other settings, [`EstimateTableSettings::check`]).
pub fn parse_mis_samples(spec: &str) -> Result<(u32, u32)> {
    let bad = || {
        anyhow::anyhow!(
            "--mis-samples {spec}: expected two counts BSDF,LIGHT, each 1 to {MAX_MIS_SAMPLES}"
        )
    };
    let (a, b) = spec.split_once(',').ok_or_else(bad)?;
    Ok((
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    ))
}

pub fn parse_sequence(spec: &str) -> Result<Sequence> {
    spec.parse().map_err(|_| {
        anyhow::anyhow!(
            "--sequence: unknown sequence `{spec}`, expected independent, stratified or sobol"
        )
    })
}

pub fn run(args: &EstimateArgs) -> Result<()> {
    let m = crate::common::load_material(&args.material)?;
    let wo = args.view.wo(&m)?;
    let light = args.light.light()?;
    let mis_samples = parse_mis_samples(&args.mis_samples)?;
    let settings = EstimateTableSettings {
        strategies: args.strategy.split(',').map(str::to_string).collect(),
        mis_bsdf: args.mis_bsdf.clone(),
        mis_samples,
        samples: args.samples,
        sequence: args.sequence.clone(),
        seed: args.seed,
        replicas: args.replicas,
    };
    let flag = |s: Setting| match s {
        Setting::Strategies => "--strategy",
        Setting::MisBsdf => "--mis-bsdf",
        Setting::MisSamples => "--mis-samples",
        Setting::Samples => "--samples",
        Setting::Sequence => "--sequence",
        Setting::Replicas => "--replicas",
    };
    // Checked before the progress bar starts.
    let checked = settings
        .check(&m)
        .map_err(|e| anyhow::anyhow!(e.named(flag)))?;
    let bar = Bar::new(args.quiet);
    let sp = args.light.shading_point(&light, wo)?;
    let mut table = estimate_table(&m, &sp, &light, &checked, &bar, &SystemClock::new())
        .map_err(|e| anyhow::anyhow!(e.named(flag)))?;
    bar.finish();
    crate::common::zero_exact_rows(&mut table);
    if args.json {
        println!("{}", serde_json::to_string(&table)?);
    } else {
        print_table(&table, m.model_name(), wo);
    }
    Ok(())
}

fn rgb(c: [f64; 3]) -> String {
    if c[0] == c[1] && c[1] == c[2] {
        format!("{:.6}", c[0])
    } else {
        format!("{:.5},{:.5},{:.5}", c[0], c[1], c[2])
    }
}

fn print_table(t: &Table, model: &str, wo: DVec3) {
    let n = t.strategies.first().map_or(0, |r| r.samples);
    println!(
        "{model} at wo = ({:.4}, {:.4}, {:.4}) (θo = {:.1}°), {n} samples per strategy, {} sequence",
        wo.x,
        wo.y,
        wo.z,
        wo.z.acos().to_degrees(),
        t.sequence
    );
    println!("reference {} by {}", rgb(t.reference), t.reference_method);
    match (t.stderr_method, t.replicas) {
        (StderrMethod::Replicas, Some(r)) => println!(
            "std. error: the spread of {r} independently randomized replicas of {} points (std. dev. of the replica means / √{r}); estimate: their mean",
            replica_size(n, r)
        ),
        _ => println!("std. error: independent samples (sample std. dev. / √N)"),
    }
    let u = &t.uniform_variance;
    if u.reliable {
        println!(
            "vs uniform: against uniform's exact variance {:.4e} ({})\n",
            u.variance, u.method
        );
    } else if u.variance.is_infinite() {
        println!("vs uniform: {}\n", u.method);
    } else {
        println!(
            "vs uniform: unreliable (the quadrature of uniform's variance did not converge)\n"
        );
    }
    println!(
        "{:<15} {:>26} {:>26} {:>10} {:>11} {:>10} {:>9} {:>11}",
        "strategy",
        "estimate",
        "std. error",
        "rel. err",
        "variance",
        "vs uniform",
        "time",
        "efficiency"
    );
    let mut unreliable = false;
    let mut exact = false;
    for r in &t.strategies {
        let red = if !r.variance_reliable {
            unreliable = true;
            "unreliable".to_string()
        } else if r.variance <= 0.0 {
            exact = true;
            "exact".to_string()
        } else if let Some(x) = r.variance_reduction {
            format_ratio(x)
        } else {
            unreliable = true;
            "unreliable".to_string()
        };
        // `!`: the sample's own tail says the standard error is too small.
        let se = if r.stderr_reliable {
            rgb(r.stderr)
        } else {
            format!("{}!", rgb(r.stderr))
        };
        let eff = r
            .efficiency
            .map_or("inf".to_string(), |x| format!("{x:.3e}"));
        let variance = if r.variance <= 0.0 {
            "0".to_string()
        } else {
            format!("{:.4e}", r.variance)
        };
        println!(
            "{:<15} {:>26} {:>26} {:>10.2e} {:>11} {:>10} {:>8.3}s {:>11}",
            r.name,
            rgb(r.mean),
            se,
            r.relative_error,
            variance,
            red,
            r.time_s,
            eff
        );
    }
    if let Some(worst) = t
        .strategies
        .iter()
        .filter(|r| !r.stderr_reliable)
        .map(|r| r.variance_rel_stderr)
        .max_by(f64::total_cmp)
    {
        if worst.is_nan() {
            println!(
                "\n!: fewer than 4 samples: the sample cannot tell whether its std. error is to be trusted (docs/statistics.md)"
            );
        } else {
            println!(
                "\n!: heavy-tailed weights: by the sample's kurtosis the variance's own relative std. error is {worst:.2} (above {}), so the std. error is likely too small and not to be trusted (docs/statistics.md)",
                lobe::experiment::table::VARIANCE_REL_STDERR_MAX
            );
        }
    }
    println!("\n{}", legend(unreliable, exact));
}

/// The notes under the table: always what the columns are; what
/// `unreliable` and `exact` mean only when a row says so.
fn legend(unreliable: bool, exact: bool) -> String {
    let mut s = String::from(
        "variance: per sample, of the luminance of f·L·cos/p; vs uniform: uniform's exact variance / this one; efficiency: 1/(variance × time)",
    );
    if exact {
        s.push_str(&format!(
            "\nexact: zero variance up to rounding (per-sample std. dev. below {:e} of the mean): every sample gives the integral",
            crate::common::EXACT_RELATIVE_SD
        ));
    }
    if unreliable {
        s.push_str("\nunreliable: the estimate is more than 6 std. errors from the reference (or uniform's exact variance did not converge), so the ratio is not to be trusted");
    }
    s
}

/// `N/R` as printed: one number when the replicas are equal, else a range.
fn replica_size(n: usize, r: usize) -> String {
    if n.is_multiple_of(r) {
        (n / r).to_string()
    } else {
        format!("{}–{}", n / r, n / r + 1)
    }
}

/// A variance ratio: `12.3x`, or in scientific notation past 10⁶ and
/// below 0.1 (`1.83e31x`, `2.50e-3x`).
#[must_use]
pub fn format_ratio(x: f64) -> String {
    if (0.1..1e6).contains(&x) {
        format!("{x:.1}x")
    } else {
        format!("{x:.2e}x")
    }
}
