//! `lobe tabulate`: write a material as a MERL `.binary` table or an RGL
//! `.bsdf` file ([`lobe::tabulate`]).

use anyhow::{Context, Result};
use clap::Args;
use lobe::tabulate::{self, Format, RglResolution};

#[derive(Args, Debug)]
#[command(
    about = "Write a material as a measured BRDF file (MERL .binary or RGL .bsdf)",
    long_about = "Write any material as a measured BRDF file, so that it can be read back by \
                  `{\"type\":\"measured\",\"path\":FILE}` or carried to other renderers \
                  (Mitsuba 3's `measured` plugin reads the RGL files).\n\n\
                  merl: 90×90×180 (θh, θd, φd) RGB doubles with MERL's scales, f at each \
                  entry's centre; entries whose centre is below the horizon are written as \
                  missing (−1). 35 MB.\n\
                  rgl: an isotropic RGB tensor file: f·cos θi on the sample grid of a \
                  visible-normal warp built from the material (jacobian 0), --views view \
                  elevations uniform in [0°, 89°], a --grid × --grid grid.",
    after_help = "Examples:\n  \
                  lobe tabulate --material '{\"type\":\"cook-torrance\",\"alpha\":0.2}' --format rgl --out ggx.bsdf\n  \
                  lobe tabulate --material @examples/gold.toml --format merl --out gold.binary"
)]
pub struct TabulateArgs {
    /// The material (JSON, @FILE.json or @FILE.toml).
    #[arg(long, short = 'm', value_name = "JSON|@FILE")]
    material: String,
    /// `merl` or `rgl`.
    #[arg(long, value_parser = ["merl", "rgl"])]
    format: String,
    /// The file to write.
    #[arg(long, short = 'o', value_name = "FILE")]
    out: std::path::PathBuf,
    /// RGL: the number of view elevations.
    #[arg(long, default_value_t = RglResolution::default().n_theta as u16, value_parser = clap::value_parser!(u16).range(2..=512))]
    views: u16,
    /// RGL: the sample grid is N × N.
    #[arg(long, default_value_t = RglResolution::default().n as u16, value_parser = clap::value_parser!(u16).range(2..=1024))]
    grid: u16,
}

pub fn run(args: &TabulateArgs) -> Result<()> {
    crate::common::prepare_output_files("--out", std::slice::from_ref(&args.out))?;
    let m = crate::common::load_material(&args.material)?;
    crate::common::refuse_transmission(&m, "tabulate (a table of reflection)")?;
    let format = match args.format.as_str() {
        "merl" => Format::Merl,
        _ => Format::Rgl(RglResolution {
            n_theta: usize::from(args.views),
            n: usize::from(args.grid),
        }),
    };
    let t0 = std::time::Instant::now();
    let bytes = tabulate::write(&m, format, &args.out).context("--out")?;
    eprintln!(
        "wrote {} ({} bytes, {} table of a {} material) in {:.2} s",
        args.out.display(),
        bytes,
        args.format,
        m.model_name(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}
