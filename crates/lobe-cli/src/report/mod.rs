//! `lobe report`: one self-contained HTML page, with PNG figures beside it,
//! that compares the sampling strategies of the lecture's reflection models
//! (Phong, Blinn-Phong, Cook-Torrance with GGX and Beckmann) at several
//! exponents or roughnesses and view angles, written for a graphics student.
//!
//! The work runs in two phases. First the comparison tables, one shading
//! point after the other, each estimate on every thread
//! ([`lobe::experiment::table::run_table`]): nothing else runs meanwhile, so the
//! measured times (and the efficiencies) are not disturbed. Then everything
//! else in parallel: convergence curves, polar plots, warp tests and weight
//! maps. All numbers except the times depend only on the seed.
//!
//! The page has no external CSS, script or font; a small inline script
//! checks, once the page has loaded, that every image loaded, and writes the
//! outcome into `<pre id="image-check">` (`ok 23/23 images loaded`), which
//! the tests read from headless Chromium.

mod args;
mod catalogue;
mod findings;
mod format;
mod html;
mod jobs;

pub use args::ReportArgs;

use anyhow::{Context, Result};
use catalogue::{given_models, models};
use html::page;
use jobs::{ReportSettings, run_all};
use std::time::Instant;

pub fn run(args: &ReportArgs) -> Result<()> {
    let start = Instant::now();
    let settings = ReportSettings::new(args.quick);
    let dir = &args.out;
    crate::common::prepare_output_dir("--out", dir)?;
    let models = if args.materials.is_empty() {
        models()
    } else {
        given_models(&args.materials)?
    };
    let results = run_all(&models, &settings, args.seed, dir, args.quiet)?;

    let elapsed = start.elapsed().as_secs_f64();
    let html = page(&models, &results, &settings, args, elapsed);
    let index = dir.join("index.html");
    std::fs::write(&index, html).with_context(|| format!("cannot write {}", index.display()))?;
    if !args.quiet {
        eprintln!("lobe report: done in {elapsed:.1} s");
    }
    let shown = index.canonicalize().unwrap_or(index);
    println!("{}", shown.display());
    Ok(())
}
