//! `lobe sweep`: a sweep described in a TOML file, run by the Python
//! package on Dask (`lobe.sweeps`, the optional extra `lobe[dask]`). This
//! command only finds Python and hands it the arguments.

use anyhow::{Context, Result, bail};
use clap::Args;

#[derive(Args, Debug)]
#[command(
    about = "Run a sweep (a grid of estimates, chi-square tests, fits or furnace cells) on Dask",
    long_about = "Run the sweep a TOML file describes on a Dask cluster (a local one of --workers \
                  processes unless --scheduler names one), writing each finished row to a \
                  Parquet dataset (--out) that a rerun resumes from; prints a summary and the \
                  table. The work is the Python package's lobe.sweeps (pip install 'lobe[dask]', \
                  then this command runs `python3 -m lobe.sweeps`; $LOBE_PYTHON names another \
                  interpreter). The file: task = \"estimate\" | \"chi2\" | \"fit\" | \"albedo\", \
                  a [grid] table of lists (their product) or [[tasks]] tables, and optionally \
                  out, workers, scheduler (docs/sweeps.md).",
    after_help = "Example (needs the Python package with its dask extra):\n  \
                  lobe sweep examples/sweep_lecture.toml --out runs/lecture.parquet --workers 2"
)]
pub struct SweepArgs {
    /// The sweep (TOML).
    spec: std::path::PathBuf,
    /// Parquet dataset to write and resume from (overrides the file's `out`).
    #[arg(long, value_name = "DIR")]
    out: Option<std::path::PathBuf>,
    /// Local worker processes (overrides the file's `workers`).
    #[arg(long, value_name = "N")]
    workers: Option<u32>,
    /// A Dask scheduler's address (tcp://HOST:PORT) instead of a local cluster.
    #[arg(long, value_name = "ADDRESS")]
    scheduler: Option<String>,
    /// Also write the table as CSV.
    #[arg(long, value_name = "FILE.csv")]
    csv: Option<std::path::PathBuf>,
    /// No progress bar.
    #[arg(long, short = 'q')]
    quiet: bool,
}

pub fn run(args: &SweepArgs) -> Result<()> {
    if !args.spec.is_file() {
        bail!("{}: no such file", args.spec.display());
    }
    let python = std::env::var_os("LOBE_PYTHON").unwrap_or_else(|| "python3".into());
    let mut cmd = std::process::Command::new(&python);
    cmd.args(["-m", "lobe.sweeps"]).arg(&args.spec);
    if let Some(o) = &args.out {
        cmd.arg("--out").arg(o);
    }
    if let Some(w) = args.workers {
        cmd.arg("--workers").arg(w.to_string());
    }
    if let Some(s) = &args.scheduler {
        cmd.args(["--scheduler", s]);
    }
    if let Some(c) = &args.csv {
        cmd.arg("--csv").arg(c);
    }
    if args.quiet {
        cmd.arg("--quiet");
    }
    let status = cmd.status().with_context(|| {
        format!(
            "cannot run {} (set LOBE_PYTHON to the Python that has lobe installed with its dask extra)",
            python.to_string_lossy()
        )
    })?;
    match status.code() {
        Some(0) => Ok(()),
        Some(code) => Err(crate::common::ExitStatus(u8::try_from(code).unwrap_or(1)).into()),
        None => bail!("python was stopped by a signal"),
    }
}
