//! Lambertian (ideal diffuse) reflection.
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `albedo` | RGB in [0, 1] | 0.8 | fraction of light reflected, from every direction |
//!
//! (This table is [`PARAMS`]; a test checks that they agree.)
//!
//! `f_r = albedo / π`. Its `brdf` sampler is the cosine-weighted hemisphere,
//! density `cos θi / π`, so the weight `f cos/pdf = albedo` is constant: a
//! zero-variance estimator under constant light (the furnace test).

use super::{Bxdf, ModelInfo, Param, Range, Value};
use crate::math::{INV_PI, Rgb};
use crate::sample::Scattering;
use crate::{BsdfStrategy, warp};
use glam::{DVec2, DVec3};

pub const ALBEDO: Param = Param {
    name: "albedo",
    range: Range::Colour { max: 1.0 },
    note: "",
    default: Value::Number(0.8),
    meaning: "fraction of light reflected, from every direction",
};

/// The keys of a Lambertian material.
pub const PARAMS: &[Param] = &[ALBEDO];

pub const DEFAULT_ALBEDO: f64 = ALBEDO.default.number();

pub const INFO: ModelInfo = ModelInfo {
    name: "lambert",
    params: PARAMS,
    #[cfg(feature = "desc")]
    from_desc,
};

#[cfg(feature = "desc")]
fn from_desc(d: &crate::desc::MaterialDesc) -> crate::error::Result<super::Lobes> {
    Ok(super::Lobes {
        diffuse: Lambert::new(
            d.albedo
                .map_or(Rgb::splat(DEFAULT_ALBEDO), crate::desc::Color::rgb),
        )?,
        glossy: super::Glossy::None,
        two_sided: false,
    })
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lambert {
    pub albedo: Rgb,
}

impl Lambert {
    pub fn new(albedo: Rgb) -> crate::error::Result<Self> {
        Ok(Lambert {
            albedo: ALBEDO.check_colour(albedo, None)?,
        })
    }
}

/// Lambert's one sampler: the cosine-weighted hemisphere (its `brdf`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CosineSampler;

impl Bxdf for Lambert {
    type Sampler = CosineSampler;

    /// | strategy | sampler |
    /// |---|---|
    /// | `brdf` | [`CosineSampler`] |
    fn sampler(&self, strategy: BsdfStrategy) -> Result<CosineSampler, String> {
        match strategy {
            BsdfStrategy::Brdf => Ok(CosineSampler),
            _ => Err("a Lambertian term has no microfacets; use uniform, cosine or brdf".into()),
        }
    }

    fn scattering(&self) -> Scattering {
        Scattering::DiffuseReflection
    }

    #[inline]
    fn eval(&self, _wo: DVec3, _wi: DVec3) -> Rgb {
        self.albedo * INV_PI
    }

    #[inline]
    fn sample(&self, _: CosineSampler, _wo: DVec3, _uc: f64, u: DVec2) -> Option<DVec3> {
        let wi = warp::square_to_cosine_hemisphere(u);
        (wi.z > 0.0).then_some(wi)
    }

    #[inline]
    fn pdf(&self, _: CosineSampler, _wo: DVec3, wi: DVec3) -> f64 {
        warp::square_to_cosine_hemisphere_pdf(wi)
    }

    fn albedo_hint(&self, _wo: DVec3) -> f64 {
        crate::math::luminance(self.albedo)
    }
}
