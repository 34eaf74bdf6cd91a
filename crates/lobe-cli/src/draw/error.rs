//! The errors of plotters' drawing calls, as they are and as
//! [`anyhow::Error`].

use plotters::prelude::{DrawingAreaErrorKind, DrawingBackend};

/// The result of a drawing call on a plotters backend `DB`.
pub type DResult<DB, T = ()> =
    std::result::Result<T, DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// A plotters error as an [`anyhow::Error`] (its own message).
pub fn drawing_error(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!("{e}")
}
