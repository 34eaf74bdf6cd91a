//! lobe's integration tests, in one test binary: each file is a module, so
//! the binary links lobe and its dependencies once instead of seven times
//! (CI's budget is mostly compile and link time). `cargo test -p lobe
//! --test integration chi2::` runs one module.

// Each module uses a part of the shared helpers.
#[allow(dead_code)]
mod common;

mod adaptive_mis;
mod checklist;
mod chi2;
mod energy;
mod estimator;
mod glass;
mod lights;
mod measured;
mod measured_fuzz;
mod properties;
