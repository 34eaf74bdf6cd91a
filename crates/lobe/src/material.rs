//! A material: a Lambertian term plus at most one glossy lobe, with
//! evaluation, and a sampler for each strategy that applies to it
//! ([`Material::sampler`], resolved once) that draws directions and gives
//! the matching pdf.
//!
//! With two lobes, `sample` chooses the glossy lobe with probability
//! `P = a_g / (a_g + a_d)` from the lobes' albedo estimates
//! ([`crate::models::Bxdf::albedo_hint`]) and the diffuse lobe otherwise,
//! and `pdf` is the mixture `P p_g + (1 − P) p_d` (one-sample MIS with the
//! balance heuristic), so `pdf` is always the density that `sample` draws from.

use crate::math::Rgb;
pub use crate::models::Glossy;
use crate::models::lambert::CosineSampler;
use crate::models::{Bxdf, GlossySampler, Lambert, Lobes};
use crate::sample::{BsdfSample, Component, Scattering};
use crate::{BsdfStrategy, Error, warp};
use glam::{DVec2, DVec3};

/// A material: `f = diffuse.albedo/π + glossy`. Cloning it is cheap: a
/// measured table is shared, not copied.
#[derive(Debug, Clone, PartialEq)]
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
        Lobes::with_diffuse(kd, glossy).map(Material::from)
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
    /// that says why and which strategies it has.
    pub fn check(&self, strategy: BsdfStrategy) -> crate::error::Result<()> {
        self.sampler(strategy).map(|_| ())
    }

    /// The strategies that apply to this material, in [`BsdfStrategy::ALL`] order.
    #[must_use]
    pub fn strategies(&self) -> Vec<BsdfStrategy> {
        BsdfStrategy::ALL
            .into_iter()
            .filter(|&s| self.draw(s).is_ok())
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

    /// Whether the sampler of `strategy` uses `uc` to choose between two
    /// lobes ([`BsdfSampler::chooses_lobe`]); false for a strategy the
    /// material does not have. Where it does not, `uc` does not change the
    /// sample.
    #[must_use]
    pub fn chooses_lobe(&self, strategy: BsdfStrategy) -> bool {
        self.sampler(strategy).is_ok_and(|s| s.chooses_lobe())
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

    /// What the material's samples do when a strategy ignores its lobes.
    fn hemisphere_scattering(&self) -> Scattering {
        self.glossy
            .scattering()
            .unwrap_or(Scattering::DiffuseReflection)
    }

    /// How `strategy` draws for this material: the one place a strategy is
    /// turned into samplers (`uniform` and `cosine` here, the others by the
    /// lobes' own tables, [`Bxdf::sampler`]).
    fn draw(&self, strategy: BsdfStrategy) -> Result<Draw<'_>, String> {
        match strategy {
            BsdfStrategy::Uniform => Ok(Draw::Uniform),
            BsdfStrategy::Cosine => Ok(Draw::Cosine),
            _ => match self.glossy {
                // A Lambertian material: its own `brdf` only.
                Glossy::None => {
                    self.diffuse.sampler(strategy)?;
                    Ok(Draw::Lobes(GlossySampler::None, CosineSampler))
                }
                // The glossy lobe's sampler; the diffuse term (if any) is
                // cosine sampled whatever the strategy.
                ref g => Ok(Draw::Lobes(g.sampler(strategy)?, CosineSampler)),
            },
        }
    }

    /// Resolve `strategy` for this material once, into a sampler that draws
    /// directions and gives pdfs by it; the error says why a strategy does
    /// not apply and which strategies the material has.
    pub fn sampler(&self, strategy: BsdfStrategy) -> crate::error::Result<BsdfSampler<'_>> {
        match self.draw(strategy) {
            Ok(draw) => Ok(BsdfSampler {
                material: self,
                strategy,
                draw,
            }),
            Err(reason) => Err(Error::Unsupported {
                strategy: strategy.name().into(),
                reason,
                available: self
                    .strategies()
                    .into_iter()
                    .map(BsdfStrategy::name)
                    .collect(),
            }),
        }
    }
}

impl From<Lobes> for Material {
    fn from(l: Lobes) -> Self {
        Material {
            diffuse: l.diffuse,
            glossy: l.glossy,
        }
    }
}

#[cfg(feature = "desc")]
impl crate::desc::MaterialDesc {
    /// Check every field and build the material: the model's own
    /// [`crate::models::ModelInfo::from_desc`], once every key given is
    /// known to belong to the model. (Here rather than beside
    /// `MaterialDesc`: the models read descriptions, so `desc` must not
    /// read the models.)
    pub fn build(&self) -> Result<Material, Error> {
        let kind = self.kind.as_str();
        let Some(model) = crate::models::find(kind) else {
            return Err(Error::UnknownName {
                field: "type".into(),
                value: self.kind.clone(),
                expected: crate::models::names(", "),
            });
        };
        for (name, present) in self.present_fields() {
            if present && !model.keys().any(|k| k == name) {
                return Err(Error::param(
                    name,
                    format!(
                        "does not apply to type {kind} (its keys: {})",
                        model.keys().collect::<Vec<_>>().join(", ")
                    ),
                ));
            }
        }
        (model.from_desc)(self).map(Material::from)
    }
}

/// How a [`BsdfSampler`] draws: resolved once from its strategy.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Draw<'m> {
    /// Uniform over the hemisphere, whatever the lobes.
    Uniform,
    /// Cosine-weighted, whatever the lobes.
    Cosine,
    /// The glossy lobe by its sampler, the diffuse term by cosine sampling,
    /// one of them chosen by `uc` with the lobes' albedo hints.
    Lobes(GlossySampler<'m>, CosineSampler),
}

/// A strategy resolved for one material ([`Material::sampler`]): it draws
/// directions and answers pdfs by that strategy, with no further check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSampler<'m> {
    material: &'m Material,
    strategy: BsdfStrategy,
    draw: Draw<'m>,
}

impl<'m> BsdfSampler<'m> {
    /// The strategy this sampler draws by.
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

    /// Whether `sample` uses `uc` to choose between two lobes: the material
    /// has a diffuse term and a glossy lobe, and the strategy samples them
    /// (not `uniform` or `cosine`).
    #[inline]
    #[must_use]
    pub fn chooses_lobe(&self) -> bool {
        let m = self.material;
        matches!(self.draw, Draw::Lobes(..)) && !matches!(m.glossy, Glossy::None) && m.has_diffuse()
    }

    /// Density in solid angle with which `sample(wo, ..)` returns `wi`;
    /// zero below the horizon.
    #[inline]
    #[must_use]
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        match self.draw {
            Draw::Uniform => warp::square_to_uniform_hemisphere_pdf(wi),
            Draw::Cosine => warp::square_to_cosine_hemisphere_pdf(wi),
            Draw::Lobes(glossy, diffuse) => {
                let m = self.material;
                let p = m.glossy_probability(wo);
                let pg = if p > 0.0 { glossy.pdf(wo, wi) } else { 0.0 };
                let pd = if p < 1.0 {
                    m.diffuse.pdf(diffuse, wo, wi)
                } else {
                    0.0
                };
                p * pg + (1.0 - p) * pd
            }
        }
    }

    /// `(f, pdf)` at `wi` in one call: the lobe-choice probability (which
    /// evaluates Fresnel) and each lobe's shared terms are computed once.
    /// `f` is without the cosine; the pdf is in solid angle. Bit for bit
    /// the numbers of [`Material::eval`] and [`BsdfSampler::pdf`].
    #[inline]
    #[must_use]
    pub fn eval_pdf(&self, wo: DVec3, wi: DVec3) -> (Rgb, f64) {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let m = self.material;
        let fd = m.diffuse.eval(wo, wi);
        match self.draw {
            Draw::Uniform => (
                m.glossy.eval(wo, wi) + fd,
                warp::square_to_uniform_hemisphere_pdf(wi),
            ),
            Draw::Cosine => (
                m.glossy.eval(wo, wi) + fd,
                warp::square_to_cosine_hemisphere_pdf(wi),
            ),
            Draw::Lobes(glossy, diffuse) => {
                let p = m.glossy_probability(wo);
                let (fg, pg) = if p > 0.0 {
                    glossy.eval_pdf(wo, wi)
                } else {
                    (m.glossy.eval(wo, wi), 0.0)
                };
                let pd = if p < 1.0 {
                    m.diffuse.pdf(diffuse, wo, wi)
                } else {
                    0.0
                };
                (fg + fd, p * pg + (1.0 - p) * pd)
            }
        }
    }

    /// Draw `wi` for `wo`: `uc` chooses the lobe, `u` the direction. `None`
    /// is a failed sample (below the horizon, or `wo` below it), which an
    /// estimator counts with weight zero. The weight includes the cosine.
    #[inline]
    #[must_use]
    pub fn sample(&self, wo: DVec3, uc: f64, u: DVec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let m = self.material;
        let (wi, component, scattering) = match self.draw {
            Draw::Uniform => (
                warp::square_to_uniform_hemisphere(u),
                Component::Hemisphere,
                m.hemisphere_scattering(),
            ),
            Draw::Cosine => (
                warp::square_to_cosine_hemisphere(u),
                Component::Hemisphere,
                m.hemisphere_scattering(),
            ),
            Draw::Lobes(glossy, diffuse) => {
                let p = m.glossy_probability(wo);
                let glossy_scattering = m.glossy.scattering();
                if p >= 1.0 {
                    // One lobe: its own f and pdf, computed with the sample.
                    let s = glossy.sample_eval(wo, u)?;
                    return finish(s.wi, s.f, s.pdf, Component::Glossy, glossy_scattering?);
                }
                if uc < p {
                    (glossy.sample(wo, u)?, Component::Glossy, glossy_scattering?)
                } else {
                    (
                        m.diffuse.sample(diffuse, wo, u)?,
                        Component::Diffuse,
                        m.diffuse.scattering(),
                    )
                }
            }
        };
        if wi.z <= 0.0 {
            return None;
        }
        finish(wi, m.eval(wo, wi), self.pdf(wo, wi), component, scattering)
    }
}

#[inline]
fn finish(
    wi: DVec3,
    f: Rgb,
    pdf: f64,
    component: Component,
    scattering: Scattering,
) -> Option<BsdfSample> {
    if !(pdf > 0.0 && pdf.is_finite() && wi.z > 0.0) {
        return None;
    }
    Some(BsdfSample {
        wi,
        f,
        pdf,
        weight: f * (wi.z / pdf),
        component,
        scattering,
    })
}
