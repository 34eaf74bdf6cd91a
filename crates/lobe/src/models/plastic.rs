//! Smooth plastic: a smooth dielectric coating over a Lambertian base
//! (Mitsuba 3's `plastic`).
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `diffuse_reflectance` | RGB in [0, 1] | 0.5 | albedo of the base under the coating |
//! | `specular_reflectance` | RGB in [0, 1] | 1 | multiplies the reflected part (not physical; Mitsuba's) |
//! | `int_ior` | > 0, or a name (`bk7`, `water`, `air`, ...: the list ends `lobe eval --help`) | `polypropylene` | index of refraction of the coating; `polypropylene` is 1.49 |
//! | `ext_ior` | > 0, or a name (`bk7`, `water`, `air`, ...: the list ends `lobe eval --help`) | `air` | index of refraction outside (above the surface); `air` is 1.000277 |
//! | `nonlinear` | bool | false | account for the base's colour in the light it sends back through the coating (its albedo in the internal-reflection series) |
//!
//! (This table is [`PARAMS`]; a test checks that they agree.)
//!
//! Two parts. The coating reflects the mirror direction with the Fresnel
//! reflectance `F(θo)` (a delta, weight `specular_reflectance · F`). Light
//! that enters, scatters off the base, and leaves gives the diffuse part
//!
//! `f = ρ' (1 − F(θo)) (1 − F(θi)) / (π η²)`, with `ρ' = ρ / (1 − F̄_int)`
//! (`ρ / (1 − ρ F̄_int)` when `nonlinear`),
//!
//! `F̄_int` the mean reflectance of the coating seen from inside under
//! diffuse light (Mitsuba's fit, [`crate::fresnel::diffuse_reflectance_fit`])
//! and `1/η²` the spreading of the light as it leaves. `uc` chooses the
//! coating with probability `F w / (F w + (1 − F)(1 − w))`, `w =
//! s̄/(s̄ + ρ̄)` from the channel means of the two tints (Mitsuba's), and
//! the base is cosine sampled otherwise. `eval` and `pdf` are the diffuse
//! part's (the coating is a delta): only `brdf` samples it all.

use super::conductor::{DeltaSampler, mirror};
#[cfg(feature = "desc")]
use super::keys;
use super::keys::{EXT_IOR, INT_IOR, SPECULAR_REFLECTANCE};
use super::{Bxdf, ModelInfo, Param, Range, Value};
use crate::fresnel::{diffuse_reflectance_fit, fresnel_dielectric};
use crate::math::{INV_PI, Rgb};
use crate::sample::{Delta, Deltas, LobeSample, Reach, Scattering};
use crate::{BsdfStrategy, warp};
use glam::{DVec2, DVec3};

pub const DIFFUSE_REFLECTANCE: Param = Param {
    name: "diffuse_reflectance",
    range: Range::Colour { max: 1.0 },
    note: "",
    default: Value::Number(0.5),
    meaning: "albedo of the base under the coating",
};
pub const PLASTIC_INT_IOR: Param = Param {
    default: Value::Name("polypropylene"),
    meaning: "index of refraction of the coating; `polypropylene` is 1.49",
    ..INT_IOR
};
pub const NONLINEAR: Param = Param {
    name: "nonlinear",
    range: Range::Bool,
    note: "",
    default: Value::Bool(false),
    meaning: "account for the base's colour in the light it sends back through the coating (its albedo in the internal-reflection series)",
};

/// The keys of a smooth plastic.
pub const PARAMS: &[Param] = &[
    DIFFUSE_REFLECTANCE,
    SPECULAR_REFLECTANCE,
    PLASTIC_INT_IOR,
    EXT_IOR,
    NONLINEAR,
];

pub const INFO: ModelInfo = ModelInfo {
    name: "plastic",
    params: PARAMS,
    #[cfg(feature = "desc")]
    from_desc,
};

#[cfg(feature = "desc")]
fn from_desc(d: &crate::desc::MaterialDesc) -> crate::error::Result<super::Lobes> {
    let lobe = Plastic::new(
        keys::checked_colour(d.diffuse_reflectance, DIFFUSE_REFLECTANCE)?,
        keys::checked_colour(d.specular_reflectance, SPECULAR_REFLECTANCE)?,
        keys::relative_ior(d, PLASTIC_INT_IOR, EXT_IOR)?,
        d.nonlinear.unwrap_or(NONLINEAR.default.flag()),
    )?;
    Ok(super::Lobes::only(super::Glossy::Plastic(lobe)))
}

/// The base under a dielectric coating, as plastic and rough plastic share
/// it: `ρ' = ρ / (1 − R_int)` (or `ρ / (1 − ρ R_int)`, nonlinear) over `π η²`,
/// and the probability weight of the coating, `w = s̄/(s̄ + ρ̄)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Base {
    /// `ρ' / (π η²)`: the diffuse part is this times the two
    /// transmittances through the coating.
    pub scale: Rgb,
    /// `w`: how much the coating's sampling weighs against the base's.
    pub specular_weight: f64,
}

impl Base {
    /// The base of albedo `rho` under a coating of relative index `eta`
    /// whose internal reflectance under diffuse light is `r_int`.
    #[must_use]
    pub fn new(rho: Rgb, specular: Rgb, eta: f64, r_int: f64, nonlinear: bool) -> Self {
        let denom = if nonlinear {
            Rgb::ONE - rho * r_int
        } else {
            Rgb::splat(1.0 - r_int)
        };
        let mean = |c: Rgb| (c.x + c.y + c.z) / 3.0;
        let (s, d) = (mean(specular), mean(rho));
        Base {
            scale: rho / denom * (INV_PI / (eta * eta)),
            specular_weight: if s + d > 0.0 { s / (s + d) } else { 0.5 },
        }
    }

    /// Probability of sampling the coating when a fraction `t` of the light
    /// from `wo` passes into the base (`1 − F` for the smooth coating).
    #[inline]
    #[must_use]
    pub fn coating_probability(&self, t: f64) -> f64 {
        let w = self.specular_weight;
        let (ps, pd) = ((1.0 - t) * w, t * (1.0 - w));
        if ps + pd > 0.0 { ps / (ps + pd) } else { 0.0 }
    }
}

/// A smooth dielectric coating of relative index `eta` over a Lambertian
/// base.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plastic {
    pub diffuse_reflectance: Rgb,
    pub specular_reflectance: Rgb,
    pub eta: f64,
    pub nonlinear: bool,
    base: Base,
}

impl Plastic {
    pub fn new(
        diffuse_reflectance: Rgb,
        specular_reflectance: Rgb,
        eta: f64,
        nonlinear: bool,
    ) -> crate::error::Result<Self> {
        let rho = DIFFUSE_REFLECTANCE.check_colour(diffuse_reflectance, None)?;
        let ks = SPECULAR_REFLECTANCE.check_colour(specular_reflectance, None)?;
        let eta = super::dielectric::check_eta(eta)?;
        Ok(Plastic {
            diffuse_reflectance: rho,
            specular_reflectance: ks,
            eta,
            nonlinear,
            base: Base::new(rho, ks, eta, diffuse_reflectance_fit(1.0 / eta), nonlinear),
        })
    }

    /// Probability of sampling the coating for `wo` and its Fresnel term.
    #[inline]
    /// The base under the coating: the scale of its `f` and the coating's
    /// weight in the lobe choice.
    #[must_use]
    pub fn base(&self) -> &Base {
        &self.base
    }

    fn coating(&self, wo: DVec3) -> (f64, f64) {
        let f = fresnel_dielectric(wo.z, self.eta).r;
        (self.base.coating_probability(1.0 - f), f)
    }
}

impl Bxdf for Plastic {
    type Sampler = DeltaSampler;

    /// | strategy | sampler |
    /// |---|---|
    /// | `brdf` | [`DeltaSampler`]: the coating's mirror direction or the base's cosine lobe |
    fn sampler(&self, strategy: BsdfStrategy) -> Result<DeltaSampler, String> {
        match strategy {
            BsdfStrategy::Brdf => Ok(DeltaSampler),
            _ => Err("smooth plastic has a delta coating and a Lambertian base; its one sampler is brdf".into()),
        }
    }

    fn scattering(&self) -> Scattering {
        Scattering::DiffuseReflection
    }

    fn reach(&self) -> Reach {
        Reach {
            transmits: false,
            delta: true,
            chooses: true,
        }
    }

    #[inline]
    fn eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
        let fo = fresnel_dielectric(wo.z, self.eta).r;
        let fi = fresnel_dielectric(wi.z, self.eta).r;
        self.base.scale * ((1.0 - fo) * (1.0 - fi))
    }

    #[inline]
    fn sample(&self, s: DeltaSampler, wo: DVec3, uc: f64, u: DVec2) -> Option<DVec3> {
        self.sample_eval(s, wo, uc, u).map(|x| x.wi)
    }

    #[inline]
    fn pdf(&self, _: DeltaSampler, wo: DVec3, wi: DVec3) -> f64 {
        let (p, _) = self.coating(wo);
        (1.0 - p) * warp::square_to_cosine_hemisphere_pdf(wi)
    }

    #[inline]
    fn sample_eval(&self, s: DeltaSampler, wo: DVec3, uc: f64, u: DVec2) -> Option<LobeSample> {
        let (p, f) = self.coating(wo);
        if uc < p {
            let wi = mirror(wo);
            return Some(LobeSample {
                wi,
                f: self.specular_reflectance * (f / wi.z),
                pdf: p,
                scattering: Scattering::SpecularReflection,
            });
        }
        let wi = warp::square_to_cosine_hemisphere(u);
        if wi.z <= 0.0 {
            return None;
        }
        Some(LobeSample {
            wi,
            f: self.eval(wo, wi),
            pdf: self.pdf(s, wo, wi),
            scattering: Scattering::DiffuseReflection,
        })
    }

    fn deltas(&self, wo: DVec3) -> Deltas {
        let f = fresnel_dielectric(wo.z, self.eta).r;
        Deltas::new(
            Some(Delta {
                wi: mirror(wo),
                value: self.specular_reflectance * f,
                scattering: Scattering::SpecularReflection,
            }),
            None,
        )
    }

    fn albedo_hint(&self, _wo: DVec3) -> f64 {
        1.0
    }
}
