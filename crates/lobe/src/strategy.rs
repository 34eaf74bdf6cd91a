//! Sampling strategies, selected by name.

use crate::Error;

/// How a direction `wi` is drawn for a given `wo`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Strategy {
    /// Uniform over the upper hemisphere, `1/(2π)`: the lecture's baseline.
    Uniform,
    /// Cosine-weighted hemisphere, `cos θ/π`.
    Cosine,
    /// The lecture's classic importance sampling: Phong's lobe around the
    /// mirror direction, Blinn-Phong's half vector, Cook-Torrance's
    /// `D(h) cos θh`; a diffuse term is cosine sampled.
    Brdf,
    /// Visible normals (Heitz 2018; GGX and Beckmann).
    Vndf,
    /// Visible normals by spherical caps (Dupuy and Benyoub 2023; GGX).
    SphericalCaps,
    /// Bounded VNDF (Eto and Tokuyoshi 2023; GGX reflection).
    BoundedVndf,
}

impl Strategy {
    pub const ALL: [Strategy; 6] = [
        Strategy::Uniform,
        Strategy::Cosine,
        Strategy::Brdf,
        Strategy::Vndf,
        Strategy::SphericalCaps,
        Strategy::BoundedVndf,
    ];

    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Uniform => "uniform",
            Strategy::Cosine => "cosine",
            Strategy::Brdf => "brdf",
            Strategy::Vndf => "vndf",
            Strategy::SphericalCaps => "spherical-caps",
            Strategy::BoundedVndf => "bounded-vndf",
        }
    }

    /// All names, comma separated, for error messages and help.
    #[must_use]
    pub fn names() -> String {
        Strategy::ALL
            .iter()
            .map(|s| s.name())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

impl std::fmt::Display for Strategy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Strategy {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        Strategy::ALL
            .into_iter()
            .find(|x| x.name() == s)
            .ok_or_else(|| Error::UnknownName {
                field: "strategy".into(),
                value: s.into(),
                expected: Strategy::names(),
            })
    }
}
