//! `lobe furnace`: the white furnace of a microfacet material, with and
//! without energy compensation, against the random walk
//! ([`lobe::experiment::furnace`]).

use anyhow::{Context, Result};
use clap::Args;
use lobe::energy::Compensation;
use lobe::experiment::furnace::{FurnaceSettings, furnace};
use lobe::math::luminance;
use std::fmt::Write as _;

/// The material when none is given: a white GGX conductor, Mitsuba's keys.
const DEFAULT_MATERIAL: &str = r#"{"type":"roughconductor","distribution":"ggx"}"#;

#[derive(Args, Debug)]
#[command(
    about = "The white furnace: albedo against θo and α, with and without energy compensation, against the random walk",
    long_about = "The directional albedo ∫ f |cos θi| dωi of a microfacet material (cook-torrance, \
                  roughconductor, roughdielectric: R + T in importance mode, or roughplastic: \
                  the coating and what the base sends back) in a white furnace, against θo and α: without compensation \
                  (multiscatter none, what Mitsuba 3 and pbrt-v4 render), with Kulla and Conty's \
                  and with Turquin's, by quadrature, and Heitz et al.'s random walk on the \
                  microsurface (every bounce, conductors and dielectrics; mean ± standard \
                  error of --walks walks). The material's alpha and multiscatter are replaced by each cell's. Prints \
                  luminance per α; --json writes every RGB number.",
    after_help = "Examples:\n  \
                  lobe furnace --alpha 0.2,1 --out furnace.png\n  \
                  lobe furnace --material '{\"type\":\"cook-torrance\",\"fresnel\":{\"type\":\"conductor\"}}' --alpha 0.5,1 --theta 0,30,60,80,89 --out gold.png\n  \
                  lobe furnace --theta 0,45,80 --alpha 0.5,1 --walks 0 --json\n  \
                  lobe furnace -m '{\"type\":\"roughplastic\",\"distribution\":\"ggx\",\"diffuse_reflectance\":1}' --theta 0,60,85 --alpha 0.1,0.5,1"
)]
pub struct FurnaceArgs {
    /// The material (JSON, @FILE.json or @FILE.toml).
    #[arg(long, short = 'm', value_name = "JSON|@FILE", default_value = DEFAULT_MATERIAL)]
    material: String,
    /// θo in degrees, comma separated (default 0 to 85 by 5, and 89).
    #[arg(long, value_delimiter = ',', value_name = "DEG,...")]
    theta: Option<Vec<f64>>,
    /// α values, comma separated (default 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.85, 1).
    #[arg(long, value_delimiter = ',', value_name = "A,...")]
    alpha: Option<Vec<f64>>,
    /// Walks of the random walk per cell (0: no random walk).
    #[arg(long, default_value_t = FurnaceSettings::standard().walks)]
    walks: u64,
    /// Seed of the random walk.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Write the figure (PNG): one panel per α, albedo against θo.
    #[arg(long, short = 'o', value_name = "FILE.png")]
    out: Option<std::path::PathBuf>,
    /// Print JSON instead of the tables.
    #[arg(long)]
    json: bool,
    /// No progress bar.
    #[arg(long, short = 'q')]
    quiet: bool,
}

pub fn run(args: &FurnaceArgs) -> Result<()> {
    if let Some(p) = &args.out {
        crate::common::prepare_output_files("--out", std::slice::from_ref(p))?;
    }
    let (desc, origin) = lobe::desc::parse_material_arg(&args.material)?;
    let standard = FurnaceSettings::standard();
    let s = FurnaceSettings {
        thetas: args.theta.clone().unwrap_or(standard.thetas),
        alphas: args.alpha.clone().unwrap_or(standard.alphas),
        walks: args.walks,
        seed: args.seed,
    };
    let bar = crate::common::Bar::new(args.quiet);
    let f = furnace(&desc, &s, &bar).with_context(|| origin.clone())?;
    bar.finish();
    if args.json {
        println!("{}", f.to_json());
    } else {
        let mut out = String::new();
        let mut last = f64::NAN;
        for r in &f.rows {
            if r.alpha != last {
                last = r.alpha;
                let _ = writeln!(
                    out,
                    "\n{} α = {}: albedo (luminance) in a white furnace\n{:>6} {:>9} {:>12} {:>9} {:>18}",
                    f.model, r.alpha, "θo", "none", "kulla-conty", "turquin", "random walk ± s.e."
                );
            }
            let walk = r.walk.map_or("—".to_string(), |w| {
                format!("{:.4} ± {:.4}", luminance(w.mean), luminance(w.std_error))
            });
            let lum = |kind| format!("{:.4}", luminance(r.albedo(kind)));
            let _ = writeln!(
                out,
                "{:>6} {:>9} {:>12} {:>9} {:>18}",
                r.theta,
                lum(Compensation::None),
                lum(Compensation::KullaConty),
                lum(Compensation::Turquin),
                walk
            );
        }
        print!("{}", out.trim_start());
    }
    if let Some(p) = &args.out {
        let what = if args.material.len() <= 90 && !args.material.starts_with('@') {
            args.material.clone()
        } else {
            origin.clone()
        };
        let title = format!("White furnace (light 1 from every direction): {what}");
        crate::figures::furnace_plot(p, &title, &f)?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}
