//! `lobe fit`: fit an analytic material to a measured one ([`lobe::fit`]).

use anyhow::{Context, Result, bail};
use clap::Args;
use lobe::Ndf;
use lobe::models::measured::Measured;

#[derive(Args, Debug)]
#[command(
    about = "Fit Cook-Torrance + Lambert to a measured BRDF file (MERL or RGL)",
    long_about = "Fit Cook-Torrance (GGX or Beckmann, Smith height-correlated shadowing, \
                  Schlick Fresnel with an RGB f0) plus a Lambertian kd to a measured BRDF \
                  file, minimising the cosine-weighted log-space L2 error over the table's \
                  entries\n\n  \
                  E = Σ cos θi Σ_c [ln(1 + f̂_c cos θi) − ln(1 + f_c cos θi)]² / (3 Σ cos θi)\n\n\
                  at the centres of a subset of MERL's (θh, θd, φd) entries (every θh, every \
                  6th θd, every 12th φd), by Nelder-Mead. Prints the fitted material as \
                  --material accepts it and the error E (with --json: one JSON object).",
    after_help = "Examples:\n  \
                  lobe fit gold.binary --model cook-torrance\n  \
                  lobe fit paint.bsdf --model cook-torrance --distribution beckmann --json"
)]
pub struct FitArgs {
    /// The measured file (MERL .binary or RGL .bsdf, recognised by content).
    file: std::path::PathBuf,
    /// The model to fit (only `cook-torrance`).
    #[arg(long, default_value = "cook-torrance", value_parser = ["cook-torrance"])]
    model: String,
    /// The normal distribution.
    #[arg(long, default_value = "ggx", value_parser = ["ggx", "beckmann"])]
    distribution: String,
    /// Print one JSON object: {"material": ..., "error": E, ...}.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &FitArgs) -> Result<()> {
    if args.model != "cook-torrance" {
        bail!("--model: only cook-torrance can be fitted");
    }
    let lobe = Measured::load(&args.file, None).context("FILE")?;
    let m = lobe::Material::with_diffuse(lobe::Rgb::ZERO, lobe::Glossy::Measured(lobe))?;
    let ndf = if args.distribution == "beckmann" { Ndf::Beckmann } else { Ndf::Ggx };
    let t0 = std::time::Instant::now();
    let fit = lobe::fit::fit_cook_torrance(&m, ndf)?;
    let seconds = t0.elapsed().as_secs_f64();
    if args.json {
        println!(
            r#"{{"material":{},"error":{:e},"pairs":{},"evaluations":{},"seconds":{seconds:.3}}}"#,
            fit.to_json(),
            fit.error,
            fit.pairs,
            fit.evaluations
        );
    } else {
        println!("{}", fit.to_json());
        println!(
            "error E = {:.4e} (cosine-weighted log-space L2 over {} entries; {} evaluations, {seconds:.1} s)",
            fit.error, fit.pairs, fit.evaluations
        );
    }
    Ok(())
}
