//! `lobe converge` (being written).

use anyhow::Result;
use clap::Args;

#[derive(Args, Debug)]
pub struct ConvergeArgs {
    /// No progress bars
    #[arg(long, short)]
    pub quiet: bool,
}

pub fn run(args: &ConvergeArgs) -> Result<()> {
    let _ = args;
    anyhow::bail!("lobe converge is not written yet")
}
