//! The command line of `lobe report`.

use clap::Args;
use std::path::PathBuf;

/// The arguments of `lobe report`.
#[derive(Args, Debug)]
#[command(
    about = "Write an HTML report comparing the sampling strategies of every model",
    long_about = "Write DIR/index.html, a self-contained page (no external CSS, script or font) with \
                  PNG figures beside it, that compares the sampling strategies of the lecture's models: \
                  Phong and Blinn-Phong (n = 10, 100, 1000) and Cook-Torrance with GGX and Beckmann \
                  (alpha = 0.05, 0.2, 0.5), at view angles 0, 45 and 75 degrees, under a white furnace \
                  (L_i = 1, so the exact answer is the directional albedo).\n\n\
                  For each model: a table of strategies (estimate, standard error, quadrature reference, \
                  relative error, variance, variance reduction against uniform, time, efficiency), a \
                  convergence plot, a polar plot of the integrand and the sampling densities, the warp \
                  test of the brdf sampler (and of VNDF for GGX) with its chi-square p-value, and maps \
                  of the sample weights, each with a short explanation.\n\n\
                  With --material M (repeatable; JSON, TOML, @FILE or a measured table, as the other \
                  commands take it) the page is about the given materials instead: one section each, \
                  with the same tables and figures at the same three views.\n\n\
                  The default settings take some seconds to a minute on two cores; --quick takes fewer \
                  samples (for checking the page, not the numbers).",
    after_help = "Examples:\n  \
                  lobe report --out report && xdg-open report/index.html\n  \
                  lobe report --out /tmp/r --quick --quiet"
)]
pub struct ReportArgs {
    /// Output directory (created if missing): index.html and the PNG figures
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Fewer samples and runs: checks the page quickly, numbers are rougher
    #[arg(long)]
    pub quick: bool,
    /// Seed of every random sequence in the report
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Report on this material instead of the lecture's models, as
    /// `--material` of the other commands (JSON, TOML, @FILE, or
    /// {"type": "measured", "path": ...}); repeat it for several, each gets
    /// its own section
    #[arg(long = "material", value_name = "M")]
    pub materials: Vec<String>,
    /// No progress bar
    #[arg(long, short)]
    pub quiet: bool,
}
