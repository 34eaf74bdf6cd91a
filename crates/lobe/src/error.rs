//! The one error type of the core library.

/// What can go wrong when a material or a strategy is set up.
///
/// Every variant names the field (or the input) at fault so that the command
/// line can print a one-line message.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// A parameter is out of its range or not a finite number.
    Param { field: String, message: String },
    /// A name (strategy, distribution, ...) that lobe does not know.
    UnknownName {
        field: String,
        value: String,
        expected: String,
    },
    /// A strategy name (a BSDF strategy, `light` or a form of MIS) that lobe
    /// does not know.
    UnknownStrategy { value: String, expected: String },
    /// A strategy that does not apply to the material: why, and the
    /// strategies the material has (their names, in the order of
    /// `BsdfStrategy::ALL`).
    Unsupported {
        strategy: String,
        reason: String,
        available: Vec<&'static str>,
    },
    /// A material description that cannot be parsed.
    Parse(String),
    /// A data file (a measured BRDF table) that cannot be read or is not
    /// valid: `path` names the file, `message` what is wrong.
    File { path: String, message: String },
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Error::Param { field, message } => write!(f, "field `{field}`: {message}"),
            Error::UnknownName {
                field,
                value,
                expected,
            } => write!(
                f,
                "field `{field}`: unknown value `{value}`, expected one of: {expected}"
            ),
            Error::UnknownStrategy { value, expected } => {
                write!(f, "unknown strategy `{value}`, expected one of: {expected}")
            }
            Error::Unsupported {
                strategy,
                reason,
                available,
            } => write!(
                f,
                "strategy `{strategy}` does not apply to this material ({reason}); it has: {}",
                available.join(", ")
            ),
            Error::Parse(message) => f.write_str(message),
            Error::File { path, message } => write!(f, "file {path}: {message}"),
        }
    }
}

impl std::error::Error for Error {}

impl Error {
    pub(crate) fn file(path: impl std::fmt::Display, message: impl Into<String>) -> Self {
        Error::File {
            path: path.to_string(),
            message: message.into(),
        }
    }

    pub(crate) fn param(field: &str, message: impl Into<String>) -> Self {
        Error::Param {
            field: field.to_string(),
            message: message.into(),
        }
    }
}

pub type Result<T> = std::result::Result<T, Error>;
