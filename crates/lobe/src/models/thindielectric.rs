//! Thin dielectric: a pane of glass of negligible thickness, a window
//! (Mitsuba 3's `thindielectric`).
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `int_ior` | > 0, or a name (`bk7`, `water`, `air`, ...: the list ends `lobe eval --help`) | `bk7` | index of refraction inside (below the surface); `bk7` is 1.5046 |
//! | `ext_ior` | > 0, or a name (`bk7`, `water`, `air`, ...: the list ends `lobe eval --help`) | `air` | index of refraction outside (above the surface); `air` is 1.000277 |
//! | `specular_reflectance` | RGB in [0, 1] | 1 | multiplies the reflected part (not physical; Mitsuba's) |
//! | `specular_transmittance` | RGB in [0, 1] | 1 | multiplies the transmitted part (not physical; Mitsuba's) |
//!
//! (This table is [`PARAMS`]; a test checks that they agree.)
//!
//! Light meets two parallel interfaces and bounces between them: with `R`
//! the Fresnel reflectance of one interface at `θo` and `T = 1 − R`, the
//! pane reflects `R' = R + T²R/(1 − R²)` (the geometric series of the
//! inter-reflections, absorption-free) and transmits `T' = 1 − R'`, straight
//! through: `wi = −wo` (refracted in, refracted back out, parallel). Two
//! delta parts chosen by `uc` with probabilities `R'` and `T'`, each with
//! weight its tint; the pane is the same from either side and the light
//! leaves in the medium it came from, so no `η²` factor.

use super::conductor::{DeltaSampler, delta_sampler, mirror};
use super::dielectric::check_eta;
#[cfg(feature = "desc")]
use super::keys;
use super::keys::{EXT_IOR, INT_IOR, SPECULAR_REFLECTANCE, SPECULAR_TRANSMITTANCE};
use super::{Bxdf, ModelInfo, Param};
use crate::fresnel::fresnel_dielectric;
use crate::math::Rgb;
use crate::sample::{Delta, Deltas, LobeSample, Reach, Scattering};
use crate::BsdfStrategy;
use glam::{DVec2, DVec3};

/// The keys of a thin dielectric.
pub const PARAMS: &[Param] = &[INT_IOR, EXT_IOR, SPECULAR_REFLECTANCE, SPECULAR_TRANSMITTANCE];

pub const INFO: ModelInfo = ModelInfo {
    name: "thindielectric",
    params: PARAMS,
    #[cfg(feature = "desc")]
    from_desc,
};

#[cfg(feature = "desc")]
fn from_desc(d: &crate::desc::MaterialDesc) -> crate::error::Result<super::Lobes> {
    let lobe = ThinDielectric::new(
        keys::relative_ior(d, INT_IOR, EXT_IOR)?,
        keys::checked_colour(d.specular_reflectance, SPECULAR_REFLECTANCE)?,
        keys::checked_colour(d.specular_transmittance, SPECULAR_TRANSMITTANCE)?,
    )?;
    Ok(super::Lobes::only(super::Glossy::ThinDielectric(lobe)))
}

/// A thin pane of relative index `eta`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThinDielectric {
    pub eta: f64,
    pub specular_reflectance: Rgb,
    pub specular_transmittance: Rgb,
}

impl ThinDielectric {
    pub fn new(
        eta: f64,
        specular_reflectance: Rgb,
        specular_transmittance: Rgb,
    ) -> crate::error::Result<Self> {
        Ok(ThinDielectric {
            eta: check_eta(eta)?,
            specular_reflectance: SPECULAR_REFLECTANCE.check_colour(specular_reflectance, None)?,
            specular_transmittance: SPECULAR_TRANSMITTANCE
                .check_colour(specular_transmittance, None)?,
        })
    }

    /// The pane's reflectance `R'` at `cos θ` (either side), inter-reflections summed.
    #[must_use]
    pub fn reflectance(&self, cos_theta: f64) -> f64 {
        let r = fresnel_dielectric(cos_theta.abs(), self.eta).r;
        if r < 1.0 {
            let t = 1.0 - r;
            r + t * t * r / (1.0 - r * r)
        } else {
            r
        }
    }
}

impl Bxdf for ThinDielectric {
    type Sampler = DeltaSampler;

    /// | strategy | sampler |
    /// |---|---|
    /// | `brdf` | [`DeltaSampler`] |
    fn sampler(&self, strategy: BsdfStrategy) -> Result<DeltaSampler, String> {
        delta_sampler("a thin dielectric", strategy)
    }

    fn scattering(&self) -> Scattering {
        Scattering::SpecularReflection
    }

    fn reach(&self) -> Reach {
        Reach {
            transmits: true,
            delta: true,
            chooses: true,
        }
    }

    #[inline]
    fn eval(&self, _wo: DVec3, _wi: DVec3) -> Rgb {
        Rgb::ZERO
    }

    #[inline]
    fn sample(&self, s: DeltaSampler, wo: DVec3, uc: f64, u: DVec2) -> Option<DVec3> {
        self.sample_eval(s, wo, uc, u).map(|x| x.wi)
    }

    #[inline]
    fn pdf(&self, _: DeltaSampler, _wo: DVec3, _wi: DVec3) -> f64 {
        0.0
    }

    #[inline]
    fn sample_eval(&self, _: DeltaSampler, wo: DVec3, uc: f64, _u: DVec2) -> Option<LobeSample> {
        let r = self.reflectance(wo.z);
        let c = wo.z.abs();
        if uc < r {
            return Some(LobeSample {
                wi: mirror(wo),
                f: self.specular_reflectance * (r / c),
                pdf: r,
                scattering: Scattering::SpecularReflection,
            });
        }
        let t = 1.0 - r;
        Some(LobeSample {
            wi: -wo,
            f: self.specular_transmittance * (t / c),
            pdf: t,
            scattering: Scattering::SpecularTransmission,
        })
    }

    fn deltas(&self, wo: DVec3) -> Deltas {
        let r = self.reflectance(wo.z);
        Deltas::new(
            Some(Delta {
                wi: mirror(wo),
                value: self.specular_reflectance * r,
                scattering: Scattering::SpecularReflection,
            }),
            Some(Delta {
                wi: -wo,
                value: self.specular_transmittance * (1.0 - r),
                scattering: Scattering::SpecularTransmission,
            }),
        )
    }

    fn albedo_hint(&self, _wo: DVec3) -> f64 {
        1.0
    }
}
