//! The command-line tests, in one test binary: each file is a module, so
//! the binary links lobe, lobe-render and their dependencies once instead
//! of thirteen times (CI's budget is mostly compile and link time).

mod common;

mod bench;
mod compare;
mod converge;
mod demo;
mod estimate;
mod eval;
mod eval_batch;
mod explore;
mod help_examples;
mod measured;
mod plot;
mod render;
mod report;
mod vocabulary;
