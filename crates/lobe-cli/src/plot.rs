//! `lobe plot` (being written).

use anyhow::Result;
use clap::Args;

#[derive(Args, Debug)]
pub struct PlotArgs {
    /// No progress bars
    #[arg(long, short)]
    pub quiet: bool,
}

pub fn run(args: &PlotArgs) -> Result<()> {
    let _ = args;
    anyhow::bail!("lobe plot is not written yet")
}
