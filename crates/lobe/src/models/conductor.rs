//! Smooth conductor: a perfect mirror with a conductor's Fresnel term
//! (Mitsuba 3's `conductor`).
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `material` | `none` or a conductor's name (`Au`, `Ag`, `Cu`, `Al`, `Cr`, ...) | `none` | a named conductor's RGB `eta`, `k` (Mitsuba's data); `none` reflects everything (`F = 1`) |
//! | `eta` | RGB ≥ 0 | `material`'s, else 0 | real part of the conductor's index; with or without `k`, instead of `material` |
//! | `k` | RGB ≥ 0 | `material`'s, else 1 | imaginary part of the conductor's index (absorption) |
//! | `fresnel` | `none`, `schlick`, `dielectric`, `conductor` | `none` | lobe's Fresnel object (as for `cook-torrance`), instead of `material` or `eta`/`k` |
//! | `specular_reflectance` | RGB in [0, 1] | 1 | multiplies the reflected part (not physical; Mitsuba's) |
//!
//! (This table is [`PARAMS`]; a test checks that they agree.)
//!
//! A delta lobe: all light leaving toward `wo` comes from its mirror
//! direction `wi = (−wo.x, −wo.y, wo.z)`, with weight
//! `specular_reflectance · F(cos θo)`. `eval` and `pdf` are zero (a delta
//! has no density); only the `brdf` sampler reaches it, and `uniform` and
//! `cosine` are refused.

#[cfg(feature = "desc")]
use super::keys;
use super::keys::{ETA, K, MATERIAL, SPECULAR_REFLECTANCE};
use super::{Bxdf, ModelInfo, Param, Range, Value};
use crate::math::{Rgb, luminance};
use crate::sample::{Delta, Deltas, LobeSample, Reach, Scattering};
use crate::{BsdfStrategy, Fresnel};
use glam::{DVec2, DVec3};

pub const FRESNEL: Param = Param {
    name: "fresnel",
    range: Range::Names("none, schlick, dielectric, conductor"),
    note: "",
    default: Value::Name("none"),
    meaning: "lobe's Fresnel object (as for `cook-torrance`), instead of `material` or `eta`/`k`",
};

/// The keys of a smooth conductor.
pub const PARAMS: &[Param] = &[MATERIAL, ETA, K, FRESNEL, SPECULAR_REFLECTANCE];

pub const INFO: ModelInfo = ModelInfo {
    name: "conductor",
    params: PARAMS,
    #[cfg(feature = "desc")]
    from_desc,
};

#[cfg(feature = "desc")]
fn from_desc(d: &crate::desc::MaterialDesc) -> crate::error::Result<super::Lobes> {
    let lobe = Conductor::new(
        keys::conductor_fresnel(d)?,
        keys::checked_colour(d.specular_reflectance, SPECULAR_REFLECTANCE)?,
    );
    Ok(super::Lobes::only(super::Glossy::Conductor(lobe)))
}

/// A smooth conductor: a mirror with Fresnel term `fresnel`, tinted by
/// `specular_reflectance`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conductor {
    pub fresnel: Fresnel,
    pub specular_reflectance: Rgb,
}

impl Conductor {
    #[must_use]
    pub fn new(fresnel: Fresnel, specular_reflectance: Rgb) -> Self {
        Conductor {
            fresnel,
            specular_reflectance,
        }
    }
}

/// The sampler of a model made of delta parts only: it draws the mirror
/// (or refracted, or straight-through) direction exactly. Its `brdf`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DeltaSampler;

/// The table of strategies of a model made of delta parts: `brdf` only.
pub(crate) fn delta_sampler(model: &str, strategy: BsdfStrategy) -> Result<DeltaSampler, String> {
    match strategy {
        BsdfStrategy::Brdf => Ok(DeltaSampler),
        _ => Err(format!(
            "{model} is smooth (a delta: no microfacets, no density); its one sampler is brdf"
        )),
    }
}

/// `w` mirrored about the normal `+z`.
#[inline]
pub(crate) fn mirror(w: DVec3) -> DVec3 {
    DVec3::new(-w.x, -w.y, w.z)
}

impl Bxdf for Conductor {
    type Sampler = DeltaSampler;

    /// | strategy | sampler |
    /// |---|---|
    /// | `brdf` | [`DeltaSampler`] |
    fn sampler(&self, strategy: BsdfStrategy) -> Result<DeltaSampler, String> {
        delta_sampler("a smooth conductor", strategy)
    }

    fn scattering(&self) -> Scattering {
        Scattering::SpecularReflection
    }

    fn reach(&self) -> Reach {
        Reach {
            transmits: false,
            delta: true,
            chooses: false,
        }
    }

    #[inline]
    fn eval(&self, _wo: DVec3, _wi: DVec3) -> Rgb {
        Rgb::ZERO
    }

    #[inline]
    fn sample(&self, _: DeltaSampler, wo: DVec3, _uc: f64, _u: DVec2) -> Option<DVec3> {
        Some(mirror(wo))
    }

    #[inline]
    fn pdf(&self, _: DeltaSampler, _wo: DVec3, _wi: DVec3) -> f64 {
        0.0
    }

    #[inline]
    fn sample_eval(&self, _: DeltaSampler, wo: DVec3, _uc: f64, _u: DVec2) -> Option<LobeSample> {
        Some(LobeSample {
            wi: mirror(wo),
            f: self.specular_reflectance * self.fresnel.eval(wo.z) / wo.z,
            pdf: 1.0,
            scattering: Scattering::SpecularReflection,
        })
    }

    fn deltas(&self, wo: DVec3) -> Deltas {
        let mirror = Delta {
            wi: mirror(wo),
            value: self.specular_reflectance * self.fresnel.eval(wo.z),
            scattering: Scattering::SpecularReflection,
        };
        Deltas::new(Some(mirror), None)
    }

    fn albedo_hint(&self, wo: DVec3) -> f64 {
        luminance(self.specular_reflectance * self.fresnel.eval(wo.z))
    }
}
