//! A material: a Lambertian term plus at most one other lobe (its
//! *glossy* lobe: any model but Lambert's, glass and plastic included),
//! seen from the front or from both sides, with evaluation, and a sampler
//! for each strategy that applies to it ([`Material::sampler`], resolved
//! once) that draws directions and gives the matching pdf.
//!
//! An opaque material scatters into the hemisphere of `wo`: from below the
//! surface it is black, unless it is two-sided (Mitsuba's `twosided`: `wo`
//! and `wi` mirrored through the surface before the lobes see them). A
//! material whose lobe transmits ([`Reach::transmits`]: glass) scatters
//! over the whole sphere and is seen from either side.
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
use crate::sample::{BsdfSample, Component, Deltas, Reach, Scattering};
use crate::{BsdfStrategy, Error, warp};
use glam::{DVec2, DVec3};

/// A material: `f = diffuse.albedo/π + glossy`. Cloning it is cheap: a
/// measured table is shared, not copied.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    pub diffuse: Lambert,
    pub glossy: Glossy,
    /// Seen from below the surface as from above (`wo` and `wi` mirrored
    /// through it); only for an opaque material.
    pub two_sided: bool,
}

/// `w` mirrored through the surface (its `z` negated).
#[inline]
fn mirrored(w: DVec3) -> DVec3 {
    DVec3::new(w.x, w.y, -w.z)
}

impl Material {
    /// A Lambertian material.
    pub fn lambert(albedo: Rgb) -> crate::error::Result<Self> {
        Ok(Material {
            diffuse: Lambert::new(albedo)?,
            glossy: Glossy::None,
            two_sided: false,
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

    /// Whether it transmits, has a delta part, chooses between parts: its
    /// glossy lobe's ([`crate::models::Bxdf::reach`]).
    #[inline]
    #[must_use]
    pub fn reach(&self) -> Reach {
        self.glossy.reach()
    }

    /// The same material carrying importance ([`crate::TransportMode`]):
    /// its refraction without radiance's `(η_i/η_t)²`, so that what it
    /// scatters is a fraction of the flux it receives (an energy check's
    /// view; radiance into a less dense medium legitimately grows).
    #[must_use]
    pub fn carrying_importance(&self) -> Material {
        let mut m = self.clone();
        match &mut m.glossy {
            Glossy::Dielectric(d) => d.mode = crate::TransportMode::Importance,
            Glossy::RoughDielectric(d) => d.mode = crate::TransportMode::Importance,
            _ => {}
        }
        m
    }

    /// This material seen from both sides (Mitsuba's `twosided`); an error
    /// for one that transmits (it has two sides already).
    pub fn two_sided(mut self) -> crate::error::Result<Self> {
        if self.reach().transmits {
            return Err(Error::param(
                "bsdf",
                format!(
                    "twosided needs an opaque material; {} transmits and is seen from both sides already",
                    self.model_name()
                ),
            ));
        }
        self.two_sided = true;
        Ok(self)
    }

    /// `(wo, wi)` as the lobes see them, or `None` where the material does
    /// not scatter: for an opaque material both above the surface (mirrored
    /// first if it is two-sided and `wo` is below); for one that transmits,
    /// `wo` off the horizon.
    #[inline]
    fn local(&self, wo: DVec3, wi: DVec3) -> Option<(DVec3, DVec3)> {
        if self.reach().transmits {
            return (wo.z != 0.0).then_some((wo, wi));
        }
        let (wo, wi) = if self.two_sided && wo.z < 0.0 {
            (mirrored(wo), mirrored(wi))
        } else {
            (wo, wi)
        };
        (wo.z > 0.0 && wi.z > 0.0).then_some((wo, wi))
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

    /// The view direction `wo` at `theta_deg` from the normal and azimuth
    /// `phi_deg`: θ in `[0, 90)`, or in `(90, 180]` (from below) for a
    /// material that transmits or is two-sided; φ any finite number. The
    /// error says which angle and why (front ends name their field with
    /// [`ViewError::named`]).
    pub fn view_direction(&self, theta_deg: f64, phi_deg: f64) -> Result<DVec3, ViewError> {
        if !phi_deg.is_finite() {
            return Err(ViewError::Phi(format!(
                "{phi_deg}: the azimuth must be a finite number of degrees"
            )));
        }
        let below = self.reach().transmits || self.two_sided;
        let ok = theta_deg.is_finite()
            && ((0.0..90.0).contains(&theta_deg)
                || (below && theta_deg > 90.0 && theta_deg <= 180.0));
        if !ok {
            return Err(ViewError::Theta(if below {
                format!(
                    "{theta_deg}: the view angle must be in [0, 90) or (90, 180] degrees (from below) for this material"
                )
            } else {
                format!(
                    "{theta_deg}: the view angle must be in [0, 90) degrees (this material neither transmits nor is two-sided)"
                )
            }));
        }
        Ok(crate::frame::wo_from_theta(theta_deg, phi_deg))
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

    /// `f(wo, wi)` without the cosine (delta parts left out); zero where
    /// the material does not scatter (an opaque one: unless both directions
    /// are above the horizon, or both below for a two-sided one).
    #[inline]
    #[must_use]
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
        debug_assert!(
            crate::math::is_unit(wo) && crate::math::is_unit(wi),
            "wo {wo} or wi {wi} not unit"
        );
        let Some((wo, wi)) = self.local(wo, wi) else {
            return Rgb::ZERO;
        };
        self.eval_local(wo, wi)
    }

    /// The delta parts at `wo` (a mirror's, glass's reflection and
    /// refraction, a coating's): each direction and `∫ f |cos θi| dωi` over
    /// it, what [`Material::eval`] leaves out. None where the material does
    /// not scatter.
    #[must_use]
    pub fn deltas(&self, wo: DVec3) -> Deltas {
        let transmits = self.reach().transmits;
        if wo.z == 0.0 || (wo.z < 0.0 && !transmits && !self.two_sided) {
            return Deltas::NONE;
        }
        if wo.z < 0.0 && !transmits {
            return self.glossy.deltas(mirrored(wo)).map_wi(mirrored);
        }
        self.glossy.deltas(wo)
    }

    /// [`Material::eval`] of directions already as the lobes see them.
    #[inline]
    fn eval_local(&self, wo: DVec3, wi: DVec3) -> Rgb {
        let g = self.glossy.eval(wo, wi);
        if wo.z > 0.0 && wi.z > 0.0 {
            g + self.diffuse.eval(wo, wi)
        } else {
            g
        }
    }

    /// What the material's samples do when a strategy ignores its lobes:
    /// the glossy lobe's kind (diffuse for none), reflected or transmitted
    /// as `wi` is on the side of `wo` or not.
    fn hemisphere_scattering(&self, wo: DVec3, wi: DVec3) -> Scattering {
        let kind = self
            .glossy
            .scattering()
            .unwrap_or(Scattering::DiffuseReflection);
        if wo.z * wi.z >= 0.0 {
            return kind;
        }
        match kind {
            Scattering::DiffuseReflection => Scattering::DiffuseTransmission,
            Scattering::SpecularReflection => Scattering::SpecularTransmission,
            Scattering::GlossyReflection => Scattering::GlossyTransmission,
            other => other,
        }
    }

    /// How `strategy` draws for this material: the one place a strategy is
    /// turned into samplers (`uniform` and `cosine` here, the others by the
    /// lobes' own tables, [`Bxdf::sampler`]).
    fn draw(&self, strategy: BsdfStrategy) -> Result<Draw<'_>, String> {
        let reach = self.reach();
        match strategy {
            BsdfStrategy::Uniform | BsdfStrategy::Cosine if reach.delta => Err(format!(
                "{} has a delta part (a mirror or a smooth interface) that {strategy} sampling never hits: only the model's own sampler (brdf) reaches it",
                self.model_name()
            )),
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
            two_sided: l.two_sided,
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
    /// Uniform over the hemisphere of `wo` (over the sphere for a material
    /// that transmits), whatever the lobes.
    Uniform,
    /// Cosine-weighted over the hemisphere of `wo` (`|cos θ|/(2π)` over the
    /// sphere for a material that transmits), whatever the lobes.
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

    /// Whether `sample` uses `uc` to choose a lobe or a part of one: the
    /// material has a diffuse term and a glossy lobe, or a lobe with parts
    /// (glass: reflection or refraction; plastic: coating or base), and the
    /// strategy samples them (not `uniform` or `cosine`).
    #[inline]
    #[must_use]
    pub fn chooses_lobe(&self) -> bool {
        let m = self.material;
        matches!(self.draw, Draw::Lobes(..))
            && !matches!(m.glossy, Glossy::None)
            && (m.has_diffuse() || m.reach().chooses)
    }

    /// Density of `uniform` or `cosine` at `wi` (directions as the lobes
    /// see them, where the material scatters).
    #[inline]
    fn hemisphere_pdf(&self, wi: DVec3) -> f64 {
        let sphere = self.material.reach().transmits;
        match (self.draw, sphere) {
            (Draw::Cosine, false) => warp::square_to_cosine_hemisphere_pdf(wi),
            (Draw::Cosine, true) => 0.5 * warp::square_to_cosine_hemisphere_pdf(abs_z(wi)),
            (_, false) => warp::square_to_uniform_hemisphere_pdf(wi),
            (_, true) => warp::square_to_uniform_sphere_pdf(wi),
        }
    }

    /// Density in solid angle with which `sample(wo, ..)` returns `wi`
    /// (delta parts left out); zero where the material does not scatter.
    #[inline]
    #[must_use]
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        let Some((wo, wi)) = self.material.local(wo, wi) else {
            return 0.0;
        };
        self.pdf_local(wo, wi)
    }

    /// `(f, pdf)` at `wi` in one call: the lobe-choice probability (which
    /// evaluates Fresnel) and each lobe's shared terms are computed once.
    /// `f` is without the cosine; the pdf is in solid angle. Bit for bit
    /// the numbers of [`Material::eval`] and [`BsdfSampler::pdf`].
    #[inline]
    #[must_use]
    pub fn eval_pdf(&self, wo: DVec3, wi: DVec3) -> (Rgb, f64) {
        let m = self.material;
        let Some((wo, wi)) = m.local(wo, wi) else {
            return (Rgb::ZERO, 0.0);
        };
        match self.draw {
            Draw::Uniform | Draw::Cosine => (m.eval_local(wo, wi), self.hemisphere_pdf(wi)),
            Draw::Lobes(glossy, diffuse) => {
                let p = m.glossy_probability(wo);
                let (fg, pg) = if p > 0.0 {
                    glossy.eval_pdf(wo, wi)
                } else {
                    (m.glossy.eval(wo, wi), 0.0)
                };
                if !(wo.z > 0.0 && wi.z > 0.0) {
                    return (fg, p * pg);
                }
                let fd = m.diffuse.eval(wo, wi);
                let pd = if p < 1.0 {
                    m.diffuse.pdf(diffuse, wo, wi)
                } else {
                    0.0
                };
                (fg + fd, p * pg + (1.0 - p) * pd)
            }
        }
    }

    /// Draw `wi` for `wo`: `uc` chooses the lobe (or a part of it), `u` the
    /// direction. `None` is a failed sample (below the horizon, or `wo`
    /// where the material does not scatter), which an estimator counts with
    /// weight zero. The weight includes the cosine.
    #[inline]
    #[must_use]
    pub fn sample(&self, wo: DVec3, uc: f64, u: DVec2) -> Option<BsdfSample> {
        let m = self.material;
        let reach = m.reach();
        let flip = m.two_sided && wo.z < 0.0 && !reach.transmits;
        let wo = if flip { mirrored(wo) } else { wo };
        if wo.z == 0.0 || (wo.z < 0.0 && !reach.transmits) {
            return None;
        }
        let s = self.sample_local(wo, uc, u)?;
        Some(if flip {
            BsdfSample {
                wi: mirrored(s.wi),
                ..s
            }
        } else {
            s
        })
    }

    /// [`BsdfSampler::sample`] for `wo` as the lobes see it.
    #[inline]
    fn sample_local(&self, wo: DVec3, uc: f64, u: DVec2) -> Option<BsdfSample> {
        let m = self.material;
        let (wi, component) = match self.draw {
            Draw::Uniform | Draw::Cosine => {
                let sphere = m.reach().transmits;
                // Over the sphere, `u.x` chooses the side first (half each).
                let (u, below) = if sphere && u.x >= 0.5 {
                    (DVec2::new(2.0 * u.x - 1.0, u.y), true)
                } else if sphere {
                    (DVec2::new(2.0 * u.x, u.y), false)
                } else {
                    (u, false)
                };
                let w = if matches!(self.draw, Draw::Cosine) {
                    warp::square_to_cosine_hemisphere(u)
                } else {
                    warp::square_to_uniform_hemisphere(u)
                };
                (if below { mirrored(w) } else { w }, Component::Hemisphere)
            }
            Draw::Lobes(glossy, diffuse) => {
                let p = m.glossy_probability(wo);
                if p >= 1.0 {
                    // One lobe: its own f and pdf (and its delta parts),
                    // computed with the sample.
                    let s = glossy.sample_eval(wo, uc, u)?;
                    return finish(wo, s.wi, s.f, s.pdf, Component::Glossy, s.scattering);
                }
                // Two lobes (a diffuse term beside an opaque lobe with a
                // density: `Lobes::with_diffuse`); `uc` rescaled so that the
                // lobe sees a uniform number of its own.
                if uc < p {
                    (glossy.sample(wo, uc / p, u)?, Component::Glossy)
                } else {
                    (m.diffuse.sample(diffuse, wo, 0.0, u)?, Component::Diffuse)
                }
            }
        };
        if wi.z == 0.0 || (wi.z < 0.0 && !m.reach().transmits) {
            return None;
        }
        let scattering = match component {
            Component::Diffuse => m.diffuse.scattering(),
            _ => m.hemisphere_scattering(wo, wi),
        };
        finish(
            wo,
            wi,
            m.eval_local(wo, wi),
            self.pdf_local(wo, wi),
            component,
            scattering,
        )
    }

    /// [`BsdfSampler::pdf`] for directions as the lobes see them.
    #[inline]
    fn pdf_local(&self, wo: DVec3, wi: DVec3) -> f64 {
        let m = self.material;
        match self.draw {
            Draw::Uniform | Draw::Cosine => self.hemisphere_pdf(wi),
            Draw::Lobes(glossy, diffuse) => {
                let p = m.glossy_probability(wo);
                let pg = if p > 0.0 { glossy.pdf(wo, wi) } else { 0.0 };
                let pd = if p < 1.0 && wo.z > 0.0 && wi.z > 0.0 {
                    m.diffuse.pdf(diffuse, wo, wi)
                } else {
                    0.0
                };
                p * pg + (1.0 - p) * pd
            }
        }
    }
}

/// `w` with `|z|`.
#[inline]
fn abs_z(w: DVec3) -> DVec3 {
    DVec3::new(w.x, w.y, w.z.abs())
}

/// The sample record, or `None` for a sample with no weight to give (a
/// zero or non-finite pdf, `wi` on the horizon or on the side its
/// scattering does not go to).
#[inline]
fn finish(
    wo: DVec3,
    wi: DVec3,
    f: Rgb,
    pdf: f64,
    component: Component,
    scattering: Scattering,
) -> Option<BsdfSample> {
    let same_side = wo.z * wi.z > 0.0;
    if !(pdf > 0.0 && pdf.is_finite() && wi.z != 0.0 && same_side == scattering.is_reflection()) {
        return None;
    }
    Some(BsdfSample {
        wi,
        f,
        pdf,
        weight: f * (wi.z.abs() / pdf),
        component,
        scattering,
    })
}

/// Which angle [`Material::view_direction`] refused, with the value and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ViewError {
    Theta(String),
    Phi(String),
}

impl ViewError {
    /// The message with the angle named as the front end spells it.
    #[must_use]
    pub fn named(&self, theta: &str, phi: &str) -> String {
        match self {
            ViewError::Theta(m) => format!("{theta} {m}"),
            ViewError::Phi(m) => format!("{phi} {m}"),
        }
    }
}
