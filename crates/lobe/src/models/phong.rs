//! Phong reflection, the lecture's form and the energy-normalized one.
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `ks` | RGB in [0, 1] (any ≥ 0 when not normalized) | 1 | specular colour |
//! | `kd` | RGB in [0, 1] | 0 | diffuse colour, added as `kd/π` |
//! | `exponent` | [0, 1e7] | 32 | shininess `n`: larger is a tighter highlight |
//! | `normalized` | bool | true | use the energy-normalized form |
//!
//! (This table is [`PARAMS`]; a test checks that they agree.)
//!
//! With `α` the angle between `wi` and the mirror direction of `wo` about the
//! normal (equivalently between `wo` and the mirror of `wi`: the model is
//! reciprocal):
//!
//! * lecture form (`normalized = false`): `f = ks · max(cos α, 0)ⁿ`. Its albedo
//!   at normal incidence is `ks · 2π/(n+2)`, above 1 for `n < 4.3` with
//!   `ks = 1`: this form does not conserve energy.
//! * modified Phong of Lafortune and Willems 1994 (`normalized = true`):
//!   `f = ks · (n+2)/(2π) · max(cos α, 0)ⁿ`, whose albedo at normal incidence
//!   is exactly `ks`, and lower at other angles (the lobe is cut by the
//!   horizon).
//!
//! A diffuse term `kd/π` is added by the material.
//!
//! `brdf` sampling draws `α` around the mirror direction with density
//! `(n+1)/(2π) cosⁿα` (`cos α = u₁^(1/(n+1))`, `φ = 2πu₂`), in a frame built
//! around the mirror direction. Directions below the horizon are failed
//! samples; the pdf is that density on the upper hemisphere and 0 below.

use super::{Bxdf, MAX_EXPONENT, ModelInfo, Param, Range, Value};
use crate::math::{INV_TWO_PI, Rgb, luminance, mirror_z};
use crate::sample::Scattering;
use crate::{Frame, BsdfStrategy, warp};
use glam::{DVec2, DVec3};

pub const KS: Param = Param {
    name: "ks",
    range: Range::Colour { max: 1.0 },
    note: "(any ≥ 0 when not normalized)",
    default: Value::Number(1.0),
    meaning: "specular colour",
};
pub const EXPONENT: Param = Param {
    name: "exponent",
    range: Range::Number {
        min: 0.0,
        max: MAX_EXPONENT,
    },
    note: "",
    default: Value::Number(32.0),
    meaning: "shininess `n`: larger is a tighter highlight",
};
pub const NORMALIZED: Param = Param {
    name: "normalized",
    range: Range::Bool,
    note: "",
    default: Value::Bool(true),
    meaning: "use the energy-normalized form",
};

/// The keys of a Phong material.
pub const PARAMS: &[Param] = &[KS, super::KD, EXPONENT, NORMALIZED];

pub const INFO: ModelInfo = ModelInfo {
    name: "phong",
    params: PARAMS,
    #[cfg(feature = "desc")]
    from_desc,
};

#[cfg(feature = "desc")]
fn from_desc(d: &crate::desc::MaterialDesc) -> crate::error::Result<super::Lobes> {
    let (ks, kd, exponent, normalized) = super::lecture_keys(d, KS, EXPONENT, NORMALIZED);
    let lobe = Phong::new(ks, exponent, normalized)?;
    super::Lobes::with_diffuse(kd, super::Glossy::Phong(lobe))
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Phong {
    pub ks: Rgb,
    pub exponent: f64,
    pub normalized: bool,
}

impl Phong {
    pub fn new(ks: Rgb, exponent: f64, normalized: bool) -> crate::error::Result<Self> {
        let ks = KS.check_colour(ks, (!normalized).then_some(f64::MAX))?;
        Ok(Phong {
            ks,
            exponent: EXPONENT.check_number(exponent, "the exponent")?,
            normalized,
        })
    }

    /// The factor in front of `cosⁿα`.
    #[inline]
    fn norm(&self) -> f64 {
        if self.normalized {
            (self.exponent + 2.0) * INV_TWO_PI
        } else {
            1.0
        }
    }

    #[inline]
    fn cos_alpha(wo: DVec3, wi: DVec3) -> f64 {
        mirror_z(wo).dot(wi).max(0.0)
    }
}

/// Phong's one sampler: `cosⁿα` around the mirror direction (its `brdf`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MirrorLobeSampler;

impl Bxdf for Phong {
    type Sampler = MirrorLobeSampler;

    /// | strategy | sampler |
    /// |---|---|
    /// | `brdf` | [`MirrorLobeSampler`] |
    fn sampler(&self, strategy: BsdfStrategy) -> Result<MirrorLobeSampler, String> {
        match strategy {
            BsdfStrategy::Brdf => Ok(MirrorLobeSampler),
            _ => Err("Phong has no microfacet distribution; use uniform, cosine or brdf".into()),
        }
    }

    fn scattering(&self) -> Scattering {
        Scattering::GlossyReflection
    }

    #[inline]
    fn eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
        self.ks * (self.norm() * Self::cos_alpha(wo, wi).powf(self.exponent))
    }

    #[inline]
    fn sample(&self, _: MirrorLobeSampler, wo: DVec3, _uc: f64, u: DVec2) -> Option<DVec3> {
        let local = warp::square_to_cos_power(u, self.exponent);
        let wi = Frame::from_normal(mirror_z(wo)).to_world(local);
        (wi.z > 0.0).then_some(wi)
    }

    #[inline]
    fn pdf(&self, _: MirrorLobeSampler, wo: DVec3, wi: DVec3) -> f64 {
        warp::cos_power_pdf(mirror_z(wo).dot(wi), self.exponent)
    }

    fn albedo_hint(&self, _wo: DVec3) -> f64 {
        let a = luminance(self.ks);
        if self.normalized {
            a
        } else {
            a * 2.0 / (self.exponent + 2.0) * std::f64::consts::PI
        }
    }
}
