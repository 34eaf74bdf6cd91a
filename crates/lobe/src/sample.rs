//! The result of sampling a material or one of its lobes.

use crate::math::Rgb;
use glam::DVec3;

/// Which part of the material drew the direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Component {
    /// The Lambertian term, by cosine sampling.
    Diffuse,
    /// The glossy (specular) lobe, by the strategy's own sampler.
    Glossy,
    /// A strategy that ignores the material (`uniform`, `cosine`).
    Hemisphere,
}

/// What a sampled direction does, after pbrt-v4's `BxDFFlags` (one value
/// instead of bits): reflection or transmission, and whether the lobe it
/// belongs to is diffuse, glossy or specular (a delta: its pdf is not a
/// density, and only the sampler reaches it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Scattering {
    DiffuseReflection,
    GlossyReflection,
    SpecularReflection,
    DiffuseTransmission,
    GlossyTransmission,
    SpecularTransmission,
}

impl Scattering {
    /// `wi` on the side of `wo`.
    #[must_use]
    pub fn is_reflection(self) -> bool {
        matches!(
            self,
            Scattering::DiffuseReflection
                | Scattering::GlossyReflection
                | Scattering::SpecularReflection
        )
    }

    /// `wi` on the other side of the surface.
    #[must_use]
    pub fn is_transmission(self) -> bool {
        !self.is_reflection()
    }

    /// A delta lobe: a mirror or a smooth interface.
    #[must_use]
    pub fn is_specular(self) -> bool {
        matches!(
            self,
            Scattering::SpecularReflection | Scattering::SpecularTransmission
        )
    }

    #[must_use]
    pub fn is_glossy(self) -> bool {
        matches!(
            self,
            Scattering::GlossyReflection | Scattering::GlossyTransmission
        )
    }

    #[must_use]
    pub fn is_diffuse(self) -> bool {
        matches!(
            self,
            Scattering::DiffuseReflection | Scattering::DiffuseTransmission
        )
    }
}

/// One direction drawn by a lobe, with `f` and the pdf there
/// ([`crate::models::Bxdf::sample_eval`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobeSample {
    /// The sampled direction toward the light, unit.
    pub wi: DVec3,
    /// The lobe's `f_r(wo, wi)`, without the cosine.
    pub f: Rgb,
    /// The lobe sampler's density of `wi`, in solid angle.
    pub pdf: f64,
}

/// One sampled direction, after pbrt-v4's `BSDFSample`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    /// The sampled direction toward the light, unit, `z > 0`.
    pub wi: DVec3,
    /// `f_r(wo, wi)`, without the cosine.
    pub f: Rgb,
    /// Density of `wi` in solid angle: equal to [`crate::BsdfSampler::pdf`]
    /// (for a mixture, the mixture density).
    pub pdf: f64,
    /// `f · cos θi / pdf`, the Monte Carlo weight (cosine included).
    pub weight: Rgb,
    /// The lobe that was chosen.
    pub component: Component,
    /// What the direction does: the chosen lobe's [`Scattering`] (for
    /// `uniform` and `cosine`, which ignore the lobes, the glossy lobe's if
    /// the material has one, else diffuse reflection).
    pub scattering: Scattering,
}
