//! What a path carries: radiance from the lights toward the camera (what
//! an estimate or a path tracer computes, the default) or importance from
//! the camera toward the lights (light tracing, bidirectional methods).
//! Refraction is the one place the two differ: radiance crossing from
//! index `η_t` into `η_i` is scaled by `(η_i/η_t)²` (the solid angle is
//! compressed or expanded), importance is not (Veach 1997, §5.2).

use crate::Error;

/// Which quantity a BSDF's values are for ([`TransportMode::Radiance`] by
/// default).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum TransportMode {
    /// Light toward the camera: refraction scales by `(η_i/η_t)²`.
    #[default]
    Radiance,
    /// The camera's importance toward the lights: no scaling.
    Importance,
}

impl TransportMode {
    pub const NAMES: &'static str = "radiance, importance";

    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            TransportMode::Radiance => "radiance",
            TransportMode::Importance => "importance",
        }
    }
}

impl std::str::FromStr for TransportMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        match s {
            "radiance" => Ok(TransportMode::Radiance),
            "importance" => Ok(TransportMode::Importance),
            _ => Err(Error::UnknownName {
                field: "mode".into(),
                value: s.into(),
                expected: Self::NAMES.into(),
            }),
        }
    }
}
