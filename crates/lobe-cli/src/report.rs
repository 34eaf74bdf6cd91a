//! `lobe report` (being written).

use anyhow::Result;
use clap::Args;

#[derive(Args, Debug)]
pub struct ReportArgs {
    /// No progress bars
    #[arg(long, short)]
    pub quiet: bool,
}

pub fn run(args: &ReportArgs) -> Result<()> {
    let _ = args;
    anyhow::bail!("lobe report is not written yet")
}
