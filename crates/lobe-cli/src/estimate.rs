//! `lobe estimate` (being written).

use anyhow::Result;
use clap::Args;

#[derive(Args, Debug)]
pub struct EstimateArgs {
    /// No progress bars
    #[arg(long, short)]
    pub quiet: bool,
}

pub fn run(args: &EstimateArgs) -> Result<()> {
    let _ = args;
    anyhow::bail!("lobe estimate is not written yet")
}
