//! Blinn-Phong reflection, the lecture's form and an exactly normalized one.
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `ks` | RGB in [0, 1] (any ≥ 0 when not normalized) | 1 | specular colour |
//! | `kd` | RGB in [0, 1] | 0 | diffuse colour, added as `kd/π` |
//! | `exponent` | [0, 1e7] | 32 | shininess `n` |
//! | `normalized` | bool | true | use the exactly normalized form |
//!
//! (This table is [`PARAMS`]; a test checks that they agree.)
//!
//! With `h = (wo + wi)/‖wo + wi‖` and `θh` its angle to the normal:
//!
//! * lecture form (`normalized = false`): `f = ks · max(cos θh, 0)ⁿ`.
//! * normalized form: `f = ks · K · cosⁿθh` with
//!   `K = (n+2)(n+4) / (8π (2^(−n/2) + n))`, which makes the albedo at normal
//!   incidence exactly `ks` (at `wo = n`, `θh = θi/2`; integrating
//!   `cosⁿ(θi/2) cos θi` over the hemisphere gives `1/K`). The common
//!   approximation `(n+8)/(8π)` is up to 7.5% too high (near `n = 9`) and
//!   tends to it only for large `n`.
//!
//! `brdf` sampling draws the *half vector* with density
//! `p_h(h) = (n+1)/(2π) cosⁿθh` and reflects `wo` about it. The density of
//! `wi` is then `p(wi) = p_h(h) / (4 wo·h)`: the reflection doubles angles,
//! and `|dωh/dωi| = 1/(4 wo·h)` is the Jacobian of that change of variables
//! (Walter et al. 2007, eq. 14). The lecture gives `p_h` alone; used as if it
//! were the density of `wi`, it makes the estimator biased.

use super::{Bxdf, ModelInfo, Param, Value};
use crate::math::{Rgb, luminance, reflect};
use crate::sample::Scattering;
use crate::{BsdfStrategy, warp};
use glam::{DVec2, DVec3};

pub const KS: Param = super::phong::KS;
pub const EXPONENT: Param = Param {
    meaning: "shininess `n`",
    ..super::phong::EXPONENT
};
pub const NORMALIZED: Param = Param {
    meaning: "use the exactly normalized form",
    default: Value::Bool(true),
    ..super::phong::NORMALIZED
};

/// The keys of a Blinn-Phong material.
pub const PARAMS: &[Param] = &[KS, super::KD, EXPONENT, NORMALIZED];

pub const INFO: ModelInfo = ModelInfo {
    name: "blinn-phong",
    params: PARAMS,
    #[cfg(feature = "desc")]
    from_desc,
};

#[cfg(feature = "desc")]
fn from_desc(d: &crate::desc::MaterialDesc) -> crate::error::Result<super::Lobes> {
    let (ks, kd, exponent, normalized) = super::lecture_keys(d, KS, EXPONENT, NORMALIZED);
    let lobe = BlinnPhong::new(ks, exponent, normalized)?;
    super::Lobes::with_diffuse(kd, super::Glossy::BlinnPhong(lobe))
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlinnPhong {
    pub ks: Rgb,
    pub exponent: f64,
    pub normalized: bool,
}

/// The exact normalization `K(n) = (n+2)(n+4) / (8π (2^(−n/2) + n))`.
#[must_use]
pub fn normalization(n: f64) -> f64 {
    (n + 2.0) * (n + 4.0) / (8.0 * std::f64::consts::PI * ((-0.5 * n).exp2() + n))
}

impl BlinnPhong {
    pub fn new(ks: Rgb, exponent: f64, normalized: bool) -> crate::error::Result<Self> {
        let ks = KS.check_colour(ks, (!normalized).then_some(f64::MAX))?;
        Ok(BlinnPhong {
            ks,
            exponent: EXPONENT.check_number(exponent, "the exponent")?,
            normalized,
        })
    }

    #[inline]
    fn norm(&self) -> f64 {
        if self.normalized {
            normalization(self.exponent)
        } else {
            1.0
        }
    }
}

/// Blinn-Phong's one sampler: the half vector by `cosⁿθh`, reflected (its
/// `brdf`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HalfVectorSampler;

impl Bxdf for BlinnPhong {
    type Sampler = HalfVectorSampler;

    /// | strategy | sampler |
    /// |---|---|
    /// | `brdf` | [`HalfVectorSampler`] |
    fn sampler(&self, strategy: BsdfStrategy) -> Result<HalfVectorSampler, String> {
        match strategy {
            BsdfStrategy::Brdf => Ok(HalfVectorSampler),
            _ => Err("Blinn-Phong here is the lecture's model, not a microfacet one; use uniform, cosine or brdf, or cook-torrance with distribution blinn-phong".into()),
        }
    }

    fn scattering(&self) -> Scattering {
        Scattering::GlossyReflection
    }

    #[inline]
    fn eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
        let Some(h) = (wo + wi).try_normalize() else {
            return Rgb::ZERO;
        };
        self.ks * (self.norm() * h.z.max(0.0).powf(self.exponent))
    }

    #[inline]
    fn sample(&self, _: HalfVectorSampler, wo: DVec3, _uc: f64, u: DVec2) -> Option<DVec3> {
        let h = warp::square_to_cos_power(u, self.exponent);
        let wi = reflect(wo, h);
        (wi.z > 0.0 && wo.dot(h) > 0.0).then(|| wi.normalize())
    }

    #[inline]
    fn pdf(&self, _: HalfVectorSampler, wo: DVec3, wi: DVec3) -> f64 {
        let Some(h) = (wo + wi).try_normalize() else {
            return 0.0;
        };
        let cos_oh = wo.dot(h);
        if cos_oh <= 0.0 || h.z <= 0.0 {
            return 0.0;
        }
        warp::square_to_cos_power_pdf(h, self.exponent) / (4.0 * cos_oh)
    }

    fn albedo_hint(&self, _wo: DVec3) -> f64 {
        let a = luminance(self.ks);
        if self.normalized {
            a
        } else {
            a / normalization(self.exponent)
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn normalization_limits_and_the_common_approximation() {
        use std::f64::consts::PI;
        // n = 0 is Lambertian: K = 1/π.
        assert!((super::normalization(0.0) - 1.0 / PI).abs() < 1e-15);
        // The (n+8)/(8π) approximation is at worst 7.5% off, near n = 9.
        let worst = (0..100_000)
            .map(|i| {
                let n = i as f64 * 1e-3;
                ((n + 8.0) / (8.0 * PI) / super::normalization(n) - 1.0).abs()
            })
            .fold(0.0, f64::max);
        assert!(
            (worst - 0.075).abs() < 0.005,
            "worst relative error {worst}"
        );
    }
}
