//! A material: a Lambertian term plus at most one glossy lobe, with
//! evaluation, sampling by any strategy, and the matching pdf.
//!
//! With two lobes, `sample` chooses the glossy lobe with probability
//! `P = a_g / (a_g + a_d)` from the lobes' albedo estimates
//! ([`crate::models::Bxdf::albedo_hint`]) and the diffuse lobe otherwise,
//! and `pdf` is the mixture `P p_g + (1 − P) p_d` (one-sample MIS with the
//! balance heuristic), so `pdf` is always the density that `sample` draws from.

use crate::math::Rgb;
pub use crate::models::Glossy;
use crate::models::{Bxdf, Lambert};
use crate::sample::{BsdfSample, Component};
use crate::{BsdfStrategy, Error, warp};
use glam::{DVec2, DVec3};

/// A material: `f = diffuse.albedo/π + glossy`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    pub diffuse: Lambert,
    pub glossy: Glossy,
}

impl Material {
    /// A Lambertian material.
    pub fn lambert(albedo: Rgb) -> crate::error::Result<Self> {
        Ok(Material {
            diffuse: Lambert::new(albedo)?,
            glossy: Glossy::None,
        })
    }

    /// A glossy lobe plus a diffuse term `kd/π`.
    pub fn with_diffuse(kd: Rgb, glossy: Glossy) -> crate::error::Result<Self> {
        let diffuse = Lambert::new(kd).map_err(|_| {
            Error::param(
                "kd",
                format!("{kd} is out of range: each channel must be in [0, 1]"),
            )
        })?;
        Ok(Material { diffuse, glossy })
    }

    /// Build a material from a command-line style argument: JSON text, or
    /// `@FILE` naming a `.toml` file (TOML) or any other file (JSON). Every
    /// error starts with `material` (or `material (file FILE)`) and names
    /// the field at fault.
    #[cfg(feature = "desc")]
    pub fn load(arg: &str) -> crate::error::Result<Self> {
        let (desc, origin) = crate::desc::parse_material_arg(arg)?;
        desc.build()
            .map_err(|e| Error::Parse(format!("{origin}: {e}")))
    }

    /// The measured table of this material, if its glossy lobe is one.
    #[must_use]
    pub fn measured(&self) -> Option<&crate::models::measured::Measured> {
        match &self.glossy {
            Glossy::Measured(t) => Some(t),
            _ => None,
        }
    }

    /// A short name of the model, for tables.
    #[must_use]
    pub fn model_name(&self) -> &'static str {
        self.glossy.model_name()
    }

    pub(crate) fn has_diffuse(&self) -> bool {
        self.diffuse.albedo != Rgb::ZERO
    }

    /// `Ok` when `strategy` applies to this material, otherwise an error
    /// that says why.
    pub fn check(&self, strategy: BsdfStrategy) -> crate::error::Result<()> {
        let r = match self.glossy {
            Glossy::None => self.diffuse.supports(strategy),
            g => g.supports(strategy),
        };
        r.map_err(|reason| Error::Unsupported {
            strategy: strategy.name().into(),
            reason,
        })
    }

    /// The strategies that apply to this material, in [`BsdfStrategy::ALL`] order.
    #[must_use]
    pub fn strategies(&self) -> Vec<BsdfStrategy> {
        BsdfStrategy::ALL
            .into_iter()
            .filter(|&s| self.check(s).is_ok())
            .collect()
    }

    /// The BSDF strategy to pair with light sampling in MIS: visible normals
    /// where the material has them, else the lecture's `brdf`.
    #[must_use]
    pub fn best_bsdf_strategy(&self) -> BsdfStrategy {
        if self.check(BsdfStrategy::Vndf).is_ok() {
            BsdfStrategy::Vndf
        } else {
            BsdfStrategy::Brdf
        }
    }

    /// Whether `sample(strategy, ..)` uses `uc` to choose between two lobes:
    /// the material has a diffuse term and a glossy lobe, and the strategy
    /// samples them (not `uniform` or `cosine`). Where it does not, `uc` does
    /// not change the sample.
    #[must_use]
    pub fn chooses_lobe(&self, strategy: BsdfStrategy) -> bool {
        !matches!(strategy, BsdfStrategy::Uniform | BsdfStrategy::Cosine)
            && !matches!(self.glossy, Glossy::None)
            && self.has_diffuse()
    }

    /// Probability of choosing the glossy lobe for `wo`.
    #[inline]
    #[must_use]
    pub fn glossy_probability(&self, wo: DVec3) -> f64 {
        if matches!(self.glossy, Glossy::None) {
            return 0.0;
        }
        if !self.has_diffuse() {
            return 1.0;
        }
        let g = self.glossy.albedo_hint(wo);
        let d = self.diffuse.albedo_hint(wo);
        if g + d > 0.0 { g / (g + d) } else { 0.5 }
    }

    /// `f_r(wo, wi)` without the cosine; zero unless both directions are
    /// above the horizon.
    #[inline]
    #[must_use]
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
        debug_assert!(
            crate::math::is_unit(wo) && crate::math::is_unit(wi),
            "wo {wo} or wi {wi} not unit"
        );
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let g = self.glossy.eval(wo, wi);
        g + self.diffuse.eval(wo, wi)
    }

    /// Validate `strategy` for this material once, into a handle that
    /// samples and gives pdfs by it: the error says why a strategy does not
    /// apply (see [`Material::check`]).
    pub fn sampler(&self, strategy: BsdfStrategy) -> crate::error::Result<BsdfSampler<'_>> {
        self.check(strategy)?;
        Ok(BsdfSampler {
            material: self,
            strategy,
        })
    }

    /// Density in solid angle with which `sample(strategy, wo, ..)` returns
    /// `wi`; zero below the horizon. `strategy` must apply to the material
    /// (checked in debug builds); [`Material::sampler`] validates it once.
    #[inline]
    #[must_use]
    pub fn pdf(&self, strategy: BsdfStrategy, wo: DVec3, wi: DVec3) -> f64 {
        debug_assert!(self.check(strategy).is_ok(), "{strategy} does not apply");
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        match strategy {
            BsdfStrategy::Uniform => warp::square_to_uniform_hemisphere_pdf(wi),
            BsdfStrategy::Cosine => warp::square_to_cosine_hemisphere_pdf(wi),
            _ => {
                let p = self.glossy_probability(wo);
                let pg = if p > 0.0 {
                    self.glossy.pdf(strategy, wo, wi)
                } else {
                    0.0
                };
                let pd = if p < 1.0 {
                    self.diffuse.pdf(strategy, wo, wi)
                } else {
                    0.0
                };
                p * pg + (1.0 - p) * pd
            }
        }
    }

    /// `(eval(wo, wi), pdf(strategy, wo, wi))` in one call: the lobe-choice
    /// probability (which evaluates Fresnel) and each lobe's shared terms
    /// are computed once. `f` is without the cosine; the pdf is in solid
    /// angle. Bit for bit the same numbers as the two calls.
    #[inline]
    #[must_use]
    pub fn eval_pdf(&self, strategy: BsdfStrategy, wo: DVec3, wi: DVec3) -> (Rgb, f64) {
        debug_assert!(self.check(strategy).is_ok(), "{strategy} does not apply");
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let fd = self.diffuse.eval(wo, wi);
        match strategy {
            BsdfStrategy::Uniform | BsdfStrategy::Cosine => {
                let f = self.glossy.eval(wo, wi) + fd;
                let pdf = if strategy == BsdfStrategy::Uniform {
                    warp::square_to_uniform_hemisphere_pdf(wi)
                } else {
                    warp::square_to_cosine_hemisphere_pdf(wi)
                };
                (f, pdf)
            }
            _ => {
                let p = self.glossy_probability(wo);
                let (fg, pg) = if p > 0.0 {
                    self.glossy.eval_pdf(strategy, wo, wi)
                } else {
                    (self.glossy.eval(wo, wi), 0.0)
                };
                let pd = if p < 1.0 {
                    self.diffuse.pdf(strategy, wo, wi)
                } else {
                    0.0
                };
                (fg + fd, p * pg + (1.0 - p) * pd)
            }
        }
    }

    /// Draw `wi` for `wo` with `strategy`. `uc` chooses the lobe, `u` the
    /// direction. `None` is a failed sample (below the horizon, or `wo`
    /// below it), which an estimator counts with weight zero. `strategy`
    /// must apply to the material (checked in debug builds);
    /// [`Material::sampler`] validates it once.
    #[inline]
    #[must_use]
    pub fn sample(
        &self,
        strategy: BsdfStrategy,
        wo: DVec3,
        uc: f64,
        u: DVec2,
    ) -> Option<BsdfSample> {
        debug_assert!(self.check(strategy).is_ok(), "{strategy} does not apply");
        if wo.z <= 0.0 {
            return None;
        }
        let (wi, lobe) = match strategy {
            BsdfStrategy::Uniform => (warp::square_to_uniform_hemisphere(u), Component::Hemisphere),
            BsdfStrategy::Cosine => (warp::square_to_cosine_hemisphere(u), Component::Hemisphere),
            _ => {
                let p = self.glossy_probability(wo);
                if p >= 1.0 {
                    // One lobe: its own f and pdf, computed with the sample.
                    let (wi, f, pdf) = self.glossy.sample_eval(strategy, wo, u)?;
                    return Self::finish(wi, f, pdf, Component::Glossy);
                }
                if uc < p {
                    (self.glossy.sample(strategy, wo, u)?, Component::Glossy)
                } else {
                    (self.diffuse.sample(strategy, wo, u)?, Component::Diffuse)
                }
            }
        };
        if wi.z <= 0.0 {
            return None;
        }
        Self::finish(wi, self.eval(wo, wi), self.pdf(strategy, wo, wi), lobe)
    }

    #[inline]
    fn finish(wi: DVec3, f: Rgb, pdf: f64, component: Component) -> Option<BsdfSample> {
        if !(pdf > 0.0 && pdf.is_finite() && wi.z > 0.0) {
            return None;
        }
        Some(BsdfSample {
            wi,
            f,
            pdf,
            weight: f * (wi.z / pdf),
            component,
        })
    }
}

/// A strategy validated for one material ([`Material::sampler`]): it can
/// only be asked for what that strategy has, so there is no meaningless pdf.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSampler<'m> {
    material: &'m Material,
    strategy: BsdfStrategy,
}

impl<'m> BsdfSampler<'m> {
    /// The strategy this handle samples by.
    #[inline]
    #[must_use]
    pub fn strategy(&self) -> BsdfStrategy {
        self.strategy
    }

    /// The material it samples.
    #[inline]
    #[must_use]
    pub fn material(&self) -> &'m Material {
        self.material
    }

    /// [`Material::sample`]: `uc` chooses the lobe, `u` the direction;
    /// `None` is a failed sample. The weight includes the cosine.
    #[inline]
    #[must_use]
    pub fn sample(&self, wo: DVec3, uc: f64, u: DVec2) -> Option<BsdfSample> {
        self.material.sample(self.strategy, wo, uc, u)
    }

    /// [`Material::pdf`]: the solid-angle density of `sample` at `wi`.
    #[inline]
    #[must_use]
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        self.material.pdf(self.strategy, wo, wi)
    }

    /// [`Material::eval_pdf`]: `f` (no cosine) and the pdf at `wi`.
    #[inline]
    #[must_use]
    pub fn eval_pdf(&self, wo: DVec3, wi: DVec3) -> (Rgb, f64) {
        self.material.eval_pdf(self.strategy, wo, wi)
    }
}
