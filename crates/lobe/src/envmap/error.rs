//! The error of building a map ([`EnvMapError`]).

/// What went wrong building a map.
#[derive(Debug, Clone, PartialEq)]
pub enum EnvMapError {
    Empty {
        width: usize,
        height: usize,
    },
    Size {
        width: usize,
        height: usize,
        got: usize,
    },
    Scale(f64),
    Rotation(f64),
}

impl std::fmt::Display for EnvMapError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            EnvMapError::Empty { width, height } => {
                write!(f, "the map is empty ({width}×{height})")
            }
            EnvMapError::Size { width, height, got } => write!(
                f,
                "the map has {got} texels, expected {width}×{height} = {}",
                width * height
            ),
            EnvMapError::Scale(v) => write!(f, "scale {v} must be a finite number >= 0"),
            EnvMapError::Rotation(v) => write!(f, "rotation_y {v} must be a finite number"),
        }
    }
}

impl std::error::Error for EnvMapError {}
