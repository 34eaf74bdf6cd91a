//! `lobe fit`: fit an analytic material to a measured one ([`lobe::fit`]).

use anyhow::{Context, Result, bail};
use clap::Args;
use lobe::Ndf;
use lobe::models::measured::Measured;

#[derive(Args, Debug)]
#[command(
    about = "Fit Cook-Torrance + Lambert to a measured BRDF file (MERL or RGL)",
    long_about = "Fit Cook-Torrance (GGX or Beckmann, Smith height-correlated shadowing, \
                  Schlick Fresnel with an RGB f0, or with --fresnel conductor a conductor's \
                  RGB eta and k; one alpha, or with --anisotropic alpha_u and alpha_v) plus a \
                  Lambertian kd to a measured BRDF \
                  file, minimising the cosine-weighted log-space L2 error over the table's \
                  entries\n\n  \
                  E = Σ cos θi Σ_c [ln(1 + f̂_c cos θi) − ln(1 + f_c cos θi)]² / (3 Σ cos θi)\n\n\
                  at the centres of a subset of MERL's (θh, θd, φd) entries (every θh, every \
                  6th θd, every 12th φd), by Nelder-Mead. Prints the fitted material as \
                  --material accepts it and the error E (with --json: one JSON object).",
    after_help = "Examples (the tabulate lines write the measured files the fits read):\n  \
                  lobe tabulate --material @examples/gold.toml --format merl --out gold.binary\n  \
                  lobe fit gold.binary --model cook-torrance\n  \
                  lobe fit gold.binary --fresnel conductor --anisotropic\n  \
                  lobe tabulate --material '{\"type\":\"cook-torrance\",\"distribution\":\"beckmann\",\"alpha\":0.3,\"kd\":0.2,\"ks\":0.8}' --format rgl --out paint.bsdf\n  \
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
    /// The Fresnel term: `schlick` (an RGB f0) or `conductor` (an RGB eta and k).
    #[arg(long, default_value = "schlick", value_parser = ["schlick", "conductor"])]
    fresnel: String,
    /// Fit alpha_u and alpha_v (the pairs are turned about the normal to
    /// cover every azimuth; MERL and RGL tables are isotropic, so their
    /// two alphas come out nearly equal).
    #[arg(long)]
    anisotropic: bool,
    /// Print one JSON object: {"material": ..., "error": E, ...}.
    #[arg(long)]
    json: bool,
    /// Also draw the fit against the data (f·cos θi in the plane of
    /// incidence at θo = 0°, 30°, 60°, 75°) to this PNG file.
    #[arg(long, value_name = "FILE.png")]
    plot: Option<std::path::PathBuf>,
}

pub fn run(args: &FitArgs) -> Result<()> {
    if args.model != "cook-torrance" {
        bail!("--model: only cook-torrance can be fitted");
    }
    if let Some(p) = &args.plot {
        crate::common::prepare_output_files("--plot", std::slice::from_ref(p))?;
    }
    let lobe = Measured::load(&args.file, None).context("FILE")?;
    eprintln!("{}", lobe.summary());
    let m = lobe::Material::with_diffuse(lobe::Rgb::ZERO, lobe::Glossy::Measured(lobe))?;
    let ndf = if args.distribution == "beckmann" {
        Ndf::Beckmann
    } else {
        Ndf::Ggx
    };
    let options = lobe::fit::FitSettings {
        distribution: ndf,
        fresnel: args.fresnel.parse()?,
        anisotropic: args.anisotropic,
    };
    let t0 = std::time::Instant::now();
    let pb = spinner("fitting");
    let fit = lobe::fit::fit(&m, options);
    pb.finish_and_clear();
    let fit = fit?;
    let seconds = t0.elapsed().as_secs_f64();
    if args.json {
        println!("{}", fit.report_json(Some(seconds)));
    } else {
        println!("{}", fit.to_json());
        println!(
            "error E = {:.4e} (cosine-weighted log-space L2 over {} entries; {} evaluations, {seconds:.1} s)",
            fit.error, fit.pairs, fit.evaluations
        );
    }
    if let Some(path) = &args.plot {
        let fitted = fit.material()?;
        let title = format!(
            "{} against its fit ({}; E = {:.2e})",
            args.file.file_name().map_or_else(
                || args.file.display().to_string(),
                |n| n.to_string_lossy().into_owned()
            ),
            fit_label(&fit),
            fit.error
        );
        crate::figures::fit_curves_plot(path, &title, &m, &fitted)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// A spinner on stderr while a fit runs (hidden when stderr is not a
/// terminal, as indicatif does).
pub fn spinner(message: &str) -> indicatif::ProgressBar {
    let pb = indicatif::ProgressBar::new_spinner();
    pb.set_message(message.to_string());
    pb.enable_steady_tick(std::time::Duration::from_millis(120));
    pb
}

/// `ggx, α 0.123, schlick` (or `α 0.1/0.3` and `conductor`).
pub fn fit_label(fit: &lobe::fit::Fit) -> String {
    let alpha = if fit.settings.anisotropic {
        format!("α {:.3}/{:.3}", fit.alpha_u, fit.alpha_v)
    } else {
        format!("α {:.3}", fit.alpha_u)
    };
    format!(
        "{}, {alpha}, {}",
        fit.settings.distribution.name(),
        fit.settings.fresnel.name()
    )
}
