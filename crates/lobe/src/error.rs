//! The one error type of the core library.

/// What can go wrong when a material or a strategy is set up.
///
/// Every variant names the field (or the input) at fault so that the command
/// line can print a one-line message.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A parameter is out of its range or not a finite number.
    #[error("field `{field}`: {message}")]
    Param { field: String, message: String },
    /// A name (strategy, distribution, ...) that lobe does not know.
    #[error("field `{field}`: unknown value `{value}`, expected one of: {expected}")]
    UnknownName {
        field: String,
        value: String,
        expected: String,
    },
    /// A strategy name (a BSDF strategy, `light` or a form of MIS) that lobe
    /// does not know.
    #[error("unknown strategy `{value}`, expected one of: {expected}")]
    UnknownStrategy { value: String, expected: String },
    /// A strategy that does not apply to the material.
    #[error("strategy `{strategy}` does not apply to this material ({reason})")]
    Unsupported { strategy: String, reason: String },
    /// A material description that cannot be parsed.
    #[error("{0}")]
    Parse(String),
}

impl Error {
    pub(crate) fn param(field: &str, message: impl Into<String>) -> Self {
        Error::Param {
            field: field.to_string(),
            message: message.into(),
        }
    }
}

pub type Result<T> = std::result::Result<T, Error>;
