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

/// What a lobe can do, beyond reflecting into the upper hemisphere with a
/// density ([`crate::models::Bxdf::reach`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reach {
    /// It sends light to the other side of the surface, and is seen from
    /// either side (`wo` below the surface means from inside).
    pub transmits: bool,
    /// It has a delta lobe (a mirror, a smooth interface) that only its own
    /// sampler reaches: `eval` and `pdf` leave it out.
    pub delta: bool,
    /// Its sampler uses `uc` to choose between its parts (reflection or
    /// refraction; the coating or the base).
    pub chooses: bool,
}

impl Reach {
    /// An opaque lobe with a density: the lecture's models.
    pub const REFLECTION: Reach = Reach {
        transmits: false,
        delta: false,
        chooses: false,
    };
}

/// One delta part of a lobe at one `wo` ([`crate::models::Bxdf::deltas`]):
/// the one direction it sends light from, and how much:
/// `∫ f |cos θi| dωi` over the delta (the sample's weight times the
/// probability of drawing it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Delta {
    pub wi: DVec3,
    pub value: Rgb,
    pub scattering: Scattering,
}

/// The delta parts of a lobe at one `wo`: at most two (a mirror direction
/// and a refracted or straight-through one).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Deltas {
    parts: [Option<Delta>; 2],
}

impl Deltas {
    /// No delta part.
    pub const NONE: Deltas = Deltas {
        parts: [None, None],
    };

    /// The parts given, those with a zero value left out.
    #[must_use]
    pub fn new(a: Option<Delta>, b: Option<Delta>) -> Self {
        let keep = |d: Option<Delta>| d.filter(|d| d.value != Rgb::ZERO);
        Deltas {
            parts: [keep(a), keep(b)],
        }
    }

    /// The parts, in order.
    pub fn iter(&self) -> impl Iterator<Item = &Delta> {
        self.parts.iter().flatten()
    }

    /// The same parts with each direction mapped by `f`.
    #[must_use]
    pub fn map_wi(self, f: impl Fn(DVec3) -> DVec3) -> Self {
        Deltas {
            parts: self.parts.map(|p| p.map(|d| Delta { wi: f(d.wi), ..d })),
        }
    }
}

/// One direction drawn by a lobe, with `f` and the pdf there
/// ([`crate::models::Bxdf::sample_eval`]).
///
/// For a delta part (`scattering.is_specular()`) `pdf` is the probability
/// with which the sampler chose that part, and `f` is the part's weight
/// over `|cos θi|`, so that `f |cos θi| / pdf` is the Monte Carlo weight as
/// for every other sample (pbrt-v4's convention).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobeSample {
    /// The sampled direction toward the light, unit.
    pub wi: DVec3,
    /// The lobe's `f(wo, wi)`, without the cosine.
    pub f: Rgb,
    /// The lobe sampler's density of `wi`, in solid angle (for a delta part:
    /// the probability of choosing it).
    pub pdf: f64,
    /// What the sampled part does.
    pub scattering: Scattering,
}

/// One sampled direction, after pbrt-v4's `BSDFSample`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    /// The sampled direction toward the light, unit: `z > 0` for a
    /// reflection, `z < 0` for a transmission (`wo` above the surface).
    pub wi: DVec3,
    /// `f(wo, wi)`, without the cosine.
    pub f: Rgb,
    /// Density of `wi` in solid angle: equal to [`crate::BsdfSampler::pdf`]
    /// (for a mixture, the mixture density). For a delta part
    /// (`scattering.is_specular()`): the probability of choosing it, with
    /// `f` its weight over `|cos θi|` ([`LobeSample`]).
    pub pdf: f64,
    /// `f · |cos θi| / pdf`, the Monte Carlo weight (cosine included).
    pub weight: Rgb,
    /// The lobe that was chosen.
    pub component: Component,
    /// What the direction does: the chosen lobe's [`Scattering`] (for
    /// `uniform` and `cosine`, which ignore the lobes, the glossy lobe's if
    /// the material has one, else diffuse reflection).
    pub scattering: Scattering,
}
