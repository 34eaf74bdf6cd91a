//! The BSDF sampling strategies, selected by name: how a material draws
//! `wi` for a given `wo`. Which of them a material has is the models'
//! business ([`crate::models::Bxdf::sampler`]); how they combine with light
//! sampling is [`crate::strategy`]'s.

use crate::Error;

/// How a direction `wi` is drawn for a given `wo`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BsdfStrategy {
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

impl BsdfStrategy {
    pub const ALL: [BsdfStrategy; 6] = [
        BsdfStrategy::Uniform,
        BsdfStrategy::Cosine,
        BsdfStrategy::Brdf,
        BsdfStrategy::Vndf,
        BsdfStrategy::SphericalCaps,
        BsdfStrategy::BoundedVndf,
    ];

    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            BsdfStrategy::Uniform => "uniform",
            BsdfStrategy::Cosine => "cosine",
            BsdfStrategy::Brdf => "brdf",
            BsdfStrategy::Vndf => "vndf",
            BsdfStrategy::SphericalCaps => "spherical-caps",
            BsdfStrategy::BoundedVndf => "bounded-vndf",
        }
    }

    /// All names, comma separated, for error messages and help.
    #[must_use]
    pub fn names() -> String {
        BsdfStrategy::ALL
            .iter()
            .map(|s| s.name())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

impl std::fmt::Display for BsdfStrategy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for BsdfStrategy {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        BsdfStrategy::ALL
            .into_iter()
            .find(|x| x.name() == s)
            .ok_or_else(|| Error::UnknownName {
                field: "strategy".into(),
                value: s.into(),
                expected: BsdfStrategy::names(),
            })
    }
}
