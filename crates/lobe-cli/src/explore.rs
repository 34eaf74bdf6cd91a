//! `lobe explore`: the BRDF and sampler explorer in the browser
//! ([`lobe_explore`]; docs/explore.md).

use anyhow::{Context, Result, anyhow};
use clap::Args;
use std::io::Write;

#[derive(Args, Debug)]
#[command(
    about = "Explore materials and their samplers in the browser (a local web server)",
    long_about = "Start a local web server and print its address as the first line on \
                  standard output; the page it serves shows, for materials edited with \
                  sliders, the polar plot of f·cos, the 3D lobe, the albedo against the view \
                  angle, a lit sphere rendered by lobe's renderer, a sampler's warp test \
                  (histogram against pdf, chi-square p-value, weight map) and each strategy's \
                  variance and efficiency. Only files under --data are read; nothing is \
                  written. Runs until interrupted (Ctrl-C). See docs/explore.md.",
    after_help = "Examples:\n  \
                  lobe explore\n  \
                  lobe explore --material '{\"type\":\"roughconductor\",\"alpha\":0.1,\"material\":\"Au\"}' --material @examples/gold.toml\n  \
                  lobe explore --data ~/brdfs --port 8000"
)]
pub struct ExploreArgs {
    /// A material the page opens with (JSON or @FILE.json / @FILE.toml);
    /// repeat for more. Default: a rough gold conductor and a rough plastic.
    #[arg(long)]
    material: Vec<String>,
    /// The directory of measured tables (MERL .binary, RGL .bsdf) and HDR
    /// environment maps (.hdr, .exr) the page may open: the only files read.
    #[arg(long)]
    data: Option<std::path::PathBuf>,
    /// The port (0: a free one).
    #[arg(long, default_value_t = 0)]
    port: u16,
    /// The address to listen on (127.0.0.1: this machine only).
    #[arg(long, default_value = "127.0.0.1")]
    host: std::net::IpAddr,
    /// No line on standard error for each request (method, path, status,
    /// milliseconds).
    #[arg(long)]
    quiet: bool,
}

pub fn run(args: &ExploreArgs) -> Result<()> {
    let mut materials = Vec::new();
    for (i, m) in args.material.iter().enumerate() {
        let (desc, _) =
            lobe::desc::parse_material_arg(m).with_context(|| format!("--material #{}", i + 1))?;
        materials.push(
            serde_json::from_str(&desc.to_json())
                .map_err(|e| anyhow!("--material #{}: {e}", i + 1))?,
        );
    }
    let server = lobe_explore::Server::bind(&lobe_explore::Config {
        host: args.host,
        port: args.port,
        data: args.data.clone(),
        materials,
        log: !args.quiet,
    })
    .map_err(|e| anyhow!(e))?;
    let mut out = std::io::stdout().lock();
    writeln!(out, "{}", server.url())?;
    out.flush()?;
    drop(out);
    eprintln!(
        "lobe explore: open {} in a browser; Ctrl-C stops the server",
        server.url()
    );
    server.run().map_err(|e| anyhow!(e))
}
