//! Smooth dielectric: the interface between two media of different
//! indices, glass or water (Mitsuba 3's `dielectric`).
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `int_ior` | > 0, or a name (`bk7`, `water`, `air`, ...: the list ends `lobe eval --help`) | `bk7` | index of refraction inside (below the surface); `bk7` is 1.5046 |
//! | `ext_ior` | > 0, or a name (`bk7`, `water`, `air`, ...: the list ends `lobe eval --help`) | `air` | index of refraction outside (above the surface); `air` is 1.000277 |
//! | `specular_reflectance` | RGB in [0, 1] | 1 | multiplies the reflected part (not physical; Mitsuba's) |
//! | `specular_transmittance` | RGB in [0, 1] | 1 | multiplies the transmitted part (not physical; Mitsuba's) |
//! | `mode` | `radiance`, `importance` | `radiance` | what is carried: radiance scales refraction by `(η_i/η_t)²`, importance does not (not a Mitsuba key: its context says) |
//!
//! (This table is [`PARAMS`]; a test checks that they agree.)
//!
//! Two delta parts: the mirror direction with probability `F` (the exact
//! unpolarized Fresnel reflectance at `θo`) and the refracted direction
//! (Snell's law) with `1 − F`, chosen by `uc`, so every sample has weight
//! `specular_reflectance`, or `specular_transmittance · (η_o/η_i)²` in
//! radiance mode (`η_o` the index on the side of `wo`). `wo` below the
//! surface sees the interface from inside (relative index `1/η`); past the
//! critical angle everything is reflected. With `int_ior = ext_ior` the
//! interface is index-matched: everything passes straight through
//! (`wi = −wo`). `eval` and `pdf` are zero (deltas have no density).

use super::conductor::{DeltaSampler, delta_sampler, mirror};
#[cfg(feature = "desc")]
use super::keys;
use super::keys::{EXT_IOR, INT_IOR, MODE, SPECULAR_REFLECTANCE, SPECULAR_TRANSMITTANCE};
use super::{Bxdf, ModelInfo, Param};
use crate::fresnel::{fresnel_dielectric, refract};
use crate::math::Rgb;
use crate::sample::{Delta, Deltas, LobeSample, Reach, Scattering};
use crate::{BsdfStrategy, TransportMode};
use glam::{DVec2, DVec3};

/// The keys of a smooth dielectric.
pub const PARAMS: &[Param] = &[INT_IOR, EXT_IOR, SPECULAR_REFLECTANCE, SPECULAR_TRANSMITTANCE, MODE];

pub const INFO: ModelInfo = ModelInfo {
    name: "dielectric",
    params: PARAMS,
    #[cfg(feature = "desc")]
    from_desc,
};

#[cfg(feature = "desc")]
fn from_desc(d: &crate::desc::MaterialDesc) -> crate::error::Result<super::Lobes> {
    let lobe = Dielectric::new(
        keys::relative_ior(d, INT_IOR, EXT_IOR)?,
        keys::checked_colour(d.specular_reflectance, SPECULAR_REFLECTANCE)?,
        keys::checked_colour(d.specular_transmittance, SPECULAR_TRANSMITTANCE)?,
        keys::mode(d)?,
    )?;
    Ok(super::Lobes::only(super::Glossy::Dielectric(lobe)))
}

/// Check a relative index of refraction: finite and `> 0`.
pub(crate) fn check_eta(eta: f64) -> crate::error::Result<f64> {
    if eta.is_finite() && eta > 0.0 {
        Ok(eta)
    } else {
        Err(crate::Error::param(
            "int_ior",
            format!("int_ior / ext_ior = {eta} is out of range: it must be a number > 0"),
        ))
    }
}

/// A smooth dielectric interface of relative index `eta = η_inside /
/// η_outside`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dielectric {
    pub eta: f64,
    pub specular_reflectance: Rgb,
    pub specular_transmittance: Rgb,
    pub mode: TransportMode,
}

impl Dielectric {
    pub fn new(
        eta: f64,
        specular_reflectance: Rgb,
        specular_transmittance: Rgb,
        mode: TransportMode,
    ) -> crate::error::Result<Self> {
        Ok(Dielectric {
            eta: check_eta(eta)?,
            specular_reflectance: SPECULAR_REFLECTANCE.check_colour(specular_reflectance, None)?,
            specular_transmittance: SPECULAR_TRANSMITTANCE
                .check_colour(specular_transmittance, None)?,
            mode,
        })
    }
}

/// The factor radiance takes on refraction from the side of `wo` into the
/// other: `eta_ti² = (η_o/η_i)²` in radiance mode, 1 in importance mode.
#[inline]
pub(crate) fn refraction_scale(mode: TransportMode, eta_ti: f64) -> f64 {
    match mode {
        TransportMode::Radiance => eta_ti * eta_ti,
        TransportMode::Importance => 1.0,
    }
}

impl Bxdf for Dielectric {
    type Sampler = DeltaSampler;

    /// | strategy | sampler |
    /// |---|---|
    /// | `brdf` | [`DeltaSampler`] |
    fn sampler(&self, strategy: BsdfStrategy) -> Result<DeltaSampler, String> {
        delta_sampler("a smooth dielectric", strategy)
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

    /// `uc < F`: the mirror direction, `pdf = F`; otherwise the refracted
    /// one, `pdf = 1 − F`; `f` is the weight times `pdf / |cos θi|`.
    #[inline]
    fn sample_eval(&self, _: DeltaSampler, wo: DVec3, uc: f64, _u: DVec2) -> Option<LobeSample> {
        let fr = fresnel_dielectric(wo.z, self.eta);
        if uc < fr.r {
            let wi = mirror(wo);
            return Some(LobeSample {
                wi,
                f: self.specular_reflectance * (fr.r / wi.z.abs()),
                pdf: fr.r,
                scattering: Scattering::SpecularReflection,
            });
        }
        let t = 1.0 - fr.r;
        let wi = refract(wo, fr.cos_theta_t, fr.eta_ti);
        let weight = self.specular_transmittance * refraction_scale(self.mode, fr.eta_ti);
        Some(LobeSample {
            wi,
            f: weight * (t / wi.z.abs()),
            pdf: t,
            scattering: Scattering::SpecularTransmission,
        })
    }

    fn deltas(&self, wo: DVec3) -> Deltas {
        let fr = fresnel_dielectric(wo.z, self.eta);
        let r = Delta {
            wi: mirror(wo),
            value: self.specular_reflectance * fr.r,
            scattering: Scattering::SpecularReflection,
        };
        let t = (fr.r < 1.0).then(|| Delta {
            wi: refract(wo, fr.cos_theta_t, fr.eta_ti),
            value: self.specular_transmittance
                * ((1.0 - fr.r) * refraction_scale(self.mode, fr.eta_ti)),
            scattering: Scattering::SpecularTransmission,
        });
        Deltas::new(Some(r), t)
    }

    fn albedo_hint(&self, _wo: DVec3) -> f64 {
        1.0
    }
}
