//! Python bindings of lobe (the `lobe` package, built by maturin from the
//! repository root: `pip install .`).
//!
//! The pure-Rust parts are modules of their own, tested by `cargo test`
//! without Python: the array [`engine`] (batch SIMD kernels with a scalar
//! fallback, rayon blocks), the [`estimate`] call, the explorer's
//! [`views`] and the [`chi2`] glue. The PyO3 glue (`py`) is built only
//! with the `python` feature, which maturin turns on
//! (`pyproject.toml`), so a plain `cargo build` or `cargo test` neither
//! needs nor links a Python interpreter.

pub mod chi2;
pub mod engine;
pub mod estimate;
pub mod pool;
#[cfg(feature = "python")]
mod py;
pub mod views;
