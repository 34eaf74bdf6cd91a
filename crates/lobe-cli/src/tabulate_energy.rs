//! `lobe tabulate-energy`: compute the albedo tables of energy compensation
//! ([`lobe::energy::tabulate`]) and write them in lobe's table format.

use anyhow::{Context, Result};
use clap::Args;
use lobe::energy::tabulate::{Shape, TABLES, TabulateSettings, tabulate_all};

const B: TabulateSettings = TabulateSettings::BUILTIN;

#[derive(Args, Debug)]
#[command(
    about = "Compute the albedo tables E(μ, α) (and η for glass) that energy compensation (multiscatter) uses",
    long_about = "Compute the directional albedo E(μ, α) of the single-scattering microfacet lobe \
                  with F = 1, for GGX and Beckmann with Smith's separable and height-correlated \
                  terms, and R + T of rough glass against η as well, by lobe's own estimator \
                  (visible-normal samples, an independent random stream per node), and write the tables with each node's standard error. The \
                  defaults are the settings of the tables built into lobe \
                  (crates/lobe/data/energy.txt); the same settings give the same file for any \
                  thread count: `lobe tabulate-energy --out energy.txt` remakes the built-in \
                  file in about 5 minutes on 2 cores.",
    after_help = "Examples:\n  \
                  lobe tabulate-energy --mu 16 --alpha 16 --samples 1024 --out small.txt"
)]
pub struct TabulateEnergyArgs {
    /// The file to write.
    #[arg(long, short = 'o', value_name = "FILE")]
    out: std::path::PathBuf,
    /// Nodes along μ = cos θo.
    #[arg(long, default_value_t = B.conductor.n_mu as u16, value_parser = clap::value_parser!(u16).range(4..=1024))]
    mu: u16,
    /// Nodes along α (conductors; dielectrics have half as many).
    #[arg(long, default_value_t = B.conductor.n_alpha as u16, value_parser = clap::value_parser!(u16).range(4..=1024))]
    alpha: u16,
    /// Nodes along η (dielectrics).
    #[arg(long, default_value_t = B.dielectric.n_eta as u16, value_parser = clap::value_parser!(u16).range(2..=1024))]
    eta: u16,
    /// Samples per node (conductors; dielectrics have 1/16 of it).
    #[arg(long, default_value_t = B.conductor.samples, value_parser = |s: &str| crate::common::parse_count(s, 256, 1 << 30, "samples"))]
    samples: u64,
    /// Seed of the random streams.
    #[arg(long, default_value_t = B.seed)]
    seed: u64,
    /// No progress bar.
    #[arg(long, short = 'q')]
    quiet: bool,
}

pub fn run(args: &TabulateEnergyArgs) -> Result<()> {
    crate::common::prepare_output_files("--out", std::slice::from_ref(&args.out))?;
    let (mu, alpha) = (usize::from(args.mu), usize::from(args.alpha));
    let s = TabulateSettings {
        conductor: Shape {
            n_mu: mu,
            n_alpha: alpha,
            n_eta: 1,
            samples: args.samples,
        },
        dielectric: Shape {
            n_mu: mu,
            n_alpha: alpha / 2,
            n_eta: usize::from(args.eta),
            samples: args.samples / 16,
        },
        seed: args.seed,
    };
    let t0 = std::time::Instant::now();
    let bar = crate::common::Bar::new(args.quiet);
    let tables = tabulate_all(&s, &bar);
    bar.finish();
    let comment = format!(
        "Directional albedo E(mu, alpha) of single-scattering microfacet lobes: conductors with F = 1,\n\
         dielectrics R + T with exact Fresnel (importance mode) against eta as well.\n\
         Made by: lobe tabulate-energy --mu {} --alpha {} --eta {} --samples {} --seed {}\n\
         Nodes: mu = (i/(N_MU-1))^2 (node 0 at 1e-4), alpha = 2 (j/(N_ALPHA-1))^2 (node 0 at 1e-4),\n\
         eta = 3^(2k/(N_ETA-1) - 1). Each table: N_ETA x N_ALPHA rows of E (one per alpha node,\n\
         eta node by eta node), then as many rows of standard errors.",
        args.mu, args.alpha, args.eta, args.samples, args.seed
    );
    std::fs::write(&args.out, tables.to_text(&comment))
        .with_context(|| format!("--out {}", args.out.display()))?;
    let worst = tables
        .tables
        .iter()
        .flat_map(|t| t.std_errors.iter().copied())
        .fold(0.0, f64::max);
    eprintln!(
        "wrote {} ({} tables; conductors {} × {} nodes of {} samples, dielectrics {} × {} × {} of {}; largest s.e. of a node {:.1e}) in {:.1} s",
        args.out.display(),
        TABLES.len(),
        s.conductor.n_mu,
        s.conductor.n_alpha,
        s.conductor.samples,
        s.dielectric.n_eta,
        s.dielectric.n_alpha,
        s.dielectric.n_mu,
        s.dielectric.samples,
        worst,
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}
