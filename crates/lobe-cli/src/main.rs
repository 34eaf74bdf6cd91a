//! `lobe`: BRDF importance sampling on the command line.
//!
//! A thin dispatcher: one module per command. Every error ends as one line
//! `lobe: error: <message>` on stderr and exit code 1 (clap's own usage
//! errors exit 2).

mod alloc;
mod bench;
mod bench_all;
mod common;
mod compare;
mod compare_figure;
mod converge;
mod demo;
mod draw;
mod estimate;
mod eval;
mod eval_batch;
mod eval_line;
mod explore;
mod figures;
mod fit;
mod furnace;
mod plot;
mod render;
mod report;
mod sweep;
mod tabulate;
mod tabulate_energy;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[global_allocator]
static ALLOCATOR: alloc::Allocator = alloc::Allocator::new();

#[derive(Parser, Debug)]
#[command(
    name = "lobe",
    version,
    about = "BRDFs and their importance samplers: evaluate, sample, compare",
    after_help = "Examples:\n  \
                  lobe demo\n  \
                  echo '{\"wo\":[0.6,0,0.8],\"wi\":[0,0,1]}' | lobe eval --material '{\"type\":\"lambert\"}'\n\n\
                  `lobe <COMMAND> --help` shows each command's input, output and examples."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    Demo(demo::DemoArgs),
    Eval(eval::EvalArgs),
    Estimate(estimate::EstimateArgs),
    Converge(converge::ConvergeArgs),
    Plot(plot::PlotArgs),
    Report(report::ReportArgs),
    Render(render::RenderArgs),
    Compare(compare::CompareArgs),
    Bench(bench::BenchArgs),
    Tabulate(tabulate::TabulateArgs),
    TabulateEnergy(tabulate_energy::TabulateEnergyArgs),
    Fit(fit::FitArgs),
    Explore(explore::ExploreArgs),
    Furnace(furnace::FurnaceArgs),
    Sweep(sweep::SweepArgs),
}

fn main() -> ExitCode {
    // Huge pages for `render`'s large blocks only (see `alloc`), decided
    // before any large block exists.
    ALLOCATOR.use_huge_pages(std::env::args_os().nth(1).is_some_and(|a| a == "render"));
    let cli = Cli::parse();
    let result = common::check_simd_env().and_then(|()| match cli.command {
        Command::Demo(args) => demo::run(&args),
        Command::Eval(args) => eval::run(&args),
        Command::Estimate(args) => estimate::run(&args),
        Command::Converge(args) => converge::run(&args),
        Command::Plot(args) => plot::run(&args),
        Command::Report(args) => report::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Compare(args) => compare::run(&args),
        Command::Bench(args) => bench::run(&args),
        Command::Tabulate(args) => tabulate::run(&args),
        Command::TabulateEnergy(args) => tabulate_energy::run(&args),
        Command::Fit(args) => fit::run(&args),
        Command::Explore(args) => explore::run(&args),
        Command::Furnace(args) => furnace::run(&args),
        Command::Sweep(args) => sweep::run(&args),
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(ref e) if let Some(s) = e.downcast_ref::<common::ExitStatus>() => ExitCode::from(s.0),
        Err(e) => {
            // One line, whatever the message holds.
            let message = format!("{e:#}");
            let message: Vec<&str> = message
                .lines()
                .map(str::trim)
                .filter(|l| !l.is_empty())
                .collect();
            eprintln!("lobe: error: {}", message.join("; "));
            ExitCode::FAILURE
        }
    }
}
