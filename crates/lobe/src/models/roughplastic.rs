//! Rough plastic: a rough dielectric coating over a Lambertian base
//! (Mitsuba 3's `roughplastic`).
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `diffuse_reflectance` | RGB in [0, 1] | 0.5 | albedo of the base under the coating |
//! | `specular_reflectance` | RGB in [0, 1] | 1 | multiplies the reflected part (not physical; Mitsuba's) |
//! | `distribution` | `ggx`, `beckmann` | `beckmann` | the NDF `D` (Mitsuba's default) |
//! | `alpha` | [1e-4, 2] | 0.1 | width of `D` |
//! | `int_ior` | > 0, or a name (`bk7`, `water`, `air`, ...: the list ends `lobe eval --help`) | `polypropylene` | index of refraction of the coating; `polypropylene` is 1.49 |
//! | `ext_ior` | > 0, or a name (`bk7`, `water`, `air`, ...: the list ends `lobe eval --help`) | `air` | index of refraction outside (above the surface); `air` is 1.000277 |
//! | `nonlinear` | bool | false | account for the base's colour in the light it sends back through the coating (its albedo in the internal-reflection series) |
//! | `sample_visible` | bool | true | Mitsuba's switch; lobe takes the strategy from each call instead, so only `true` is accepted |
//! | `multiscatter` | `none`, `kulla-conty`, `turquin` | `none` | energy compensation for the light that bounces between microfacets ([`crate::energy::compensation`]; GGX or Beckmann with a Smith term; not a Mitsuba key, and `none` is Mitsuba's lobe) |
//!
//! (This table is [`PARAMS`]; a test checks that they agree.)
//!
//! Two parts, both with a density. The coating is a microfacet reflection
//! with the dielectric's Fresnel term, `ks F D G1(wo) G1(wi) / (4 cos θo cos θi)`.
//! The base gives `f = ρ' T(θo) T(θi) / (π η²)`, `T(θ)` the fraction of the
//! light from `θ` that the rough coating lets through (single scattering,
//! averaged over its visible normals), `ρ' = ρ / (1 − R_int)` (or
//! `ρ / (1 − ρ R_int)` when `nonlinear`) and `R_int` the coating's mean
//! reflectance from inside. `T` is a table of 64 cosines and `R_int` a
//! number, both computed when the material is made, by Gauss-Legendre
//! quadrature over the visible normals as Mitsuba 3 does it (its
//! definitions: 32 × 32 nodes from the denser side, 128 × 128 from the
//! other, `R_int = 2 Σ R(μⱼ) μⱼ / 64`). Isotropic only (Mitsuba's).
//!
//! With `multiscatter = turquin` the coating is the compensated rough
//! interface of [`super::roughdielectric`]: its reflection and its
//! transmittance are divided by `E(μ, α, η)`, the single-scattering
//! interface's `R + T` (lobe's tables), so that what it reflects and what it
//! lets through add up to 1; `R_int` then follows from the compensated
//! transmittance by reciprocity, `1 − R_int = 2 ∫ T(μ) μ dμ / η²`
//! (exact for the piecewise-linear `T`), which is what makes a white base
//! under a clear coating send back all the light it receives, as a smooth
//! coating does. With `kulla-conty` the coating gets the compensated
//! interface's added reflection (on its side of the surface,
//! [`crate::energy::compensation::DielectricKullaConty`]) and `T` its
//! added transmission, `τ_out (1 − E(μ))`; `R_int` follows as above. Both
//! need `int_ior ≥ ext_ior` (under a rarer coating the compensated
//! transmittance breaks that reciprocity; refused).
//!
//! `uc` chooses the coating with probability `(1 − T) w / ((1 − T) w + T (1 − w))`,
//! `w = s̄/(s̄ + ρ̄)`; the pdf is that mixture of the coating's density (by
//! the strategy: `brdf`, `vndf`, `spherical-caps`, `bounded-vndf`) and the
//! base's `cos θi / π`.

use super::cook_torrance::CookTorrance;
use super::keys;
use super::keys::{EXT_IOR, SPECULAR_REFLECTANCE};
use super::plastic::{Base, DIFFUSE_REFLECTANCE, NONLINEAR, PLASTIC_INT_IOR};
use super::roughdielectric::{DISTRIBUTION, MITSUBA_ALPHA, SAMPLE_VISIBLE};
use super::{Bxdf, ModelInfo, Param};
use crate::energy::compensation::{
    Compensation, DielectricKullaConty, DielectricMultiscatter, DielectricTurquin,
};
use crate::fresnel::fresnel_dielectric;
use crate::math::Rgb;
use crate::microfacet::{Microfacet, Shadowing};
use crate::sample::{LobeSample, Reach, Scattering};
use crate::{BsdfStrategy, Fresnel, warp};
use glam::{DVec2, DVec3};
use std::sync::Arc;

/// The keys of a rough plastic.
pub const PARAMS: &[Param] = &[
    DIFFUSE_REFLECTANCE,
    SPECULAR_REFLECTANCE,
    DISTRIBUTION,
    MITSUBA_ALPHA,
    PLASTIC_INT_IOR,
    EXT_IOR,
    NONLINEAR,
    SAMPLE_VISIBLE,
    keys::MULTISCATTER,
];

pub const INFO: ModelInfo = ModelInfo {
    name: "roughplastic",
    params: PARAMS,
    #[cfg(feature = "desc")]
    from_desc,
};

#[cfg(feature = "desc")]
fn from_desc(d: &crate::desc::MaterialDesc) -> crate::error::Result<super::Lobes> {
    if d.alpha_u.is_some() || d.alpha_v.is_some() {
        return Err(crate::Error::param(
            if d.alpha_u.is_some() { "alpha_u" } else { "alpha_v" },
            "rough plastic is isotropic (as Mitsuba's): give alpha",
        ));
    }
    let mf = super::roughdielectric::mitsuba_microfacet(d, DISTRIBUTION, MITSUBA_ALPHA)?;
    let lobe = RoughPlastic::new(
        mf,
        keys::checked_colour(d.diffuse_reflectance, DIFFUSE_REFLECTANCE)?,
        keys::checked_colour(d.specular_reflectance, SPECULAR_REFLECTANCE)?,
        keys::relative_ior(d, PLASTIC_INT_IOR, EXT_IOR)?,
        d.nonlinear.unwrap_or(NONLINEAR.default.flag()),
    )?
    .with_multiscatter(keys::multiscatter(d)?)?;
    Ok(super::Lobes::only(super::Glossy::RoughPlastic(lobe)))
}

/// Number of cosines in the transmittance table (Mitsuba's).
pub const TABLE_SIZE: usize = 64;

/// What the coating lets through: `T(μⱼ)` at `μⱼ = max(1e-6, j/63)` and
/// `R_int`.
#[derive(Debug, Clone, PartialEq)]
struct Transmission {
    table: Arc<[f64]>,
    internal_reflectance: f64,
}

/// A rough dielectric coating over a Lambertian base.
#[derive(Debug, Clone, PartialEq)]
pub struct RoughPlastic {
    pub diffuse_reflectance: Rgb,
    pub eta: f64,
    pub nonlinear: bool,
    /// The coating: Cook-Torrance with the dielectric's Fresnel term and
    /// Smith's separable `G` (Mitsuba's).
    pub coating: CookTorrance,
    /// Energy compensation of the coating (`multiscatter`); none from
    /// [`RoughPlastic::new`].
    pub multiscatter: DielectricMultiscatter,
    base: Base,
    /// The single-scattering coating's (Mitsuba's).
    single: Transmission,
    /// What the base sees: `single`, or the compensated coating's.
    through: Transmission,
}

impl RoughPlastic {
    /// `microfacet` must be isotropic, GGX or Beckmann.
    pub fn new(
        microfacet: Microfacet,
        diffuse_reflectance: Rgb,
        specular_reflectance: Rgb,
        eta: f64,
        nonlinear: bool,
    ) -> crate::error::Result<Self> {
        use crate::Error;
        if !microfacet.is_isotropic() {
            return Err(Error::param("alpha_u", "rough plastic is isotropic (as Mitsuba's)"));
        }
        if microfacet.ndf() == crate::Ndf::BlinnPhong {
            return Err(Error::param("distribution", "rough plastic needs ggx or beckmann"));
        }
        let rho = DIFFUSE_REFLECTANCE.check_colour(diffuse_reflectance, None)?;
        let eta = super::dielectric::check_eta(eta)?;
        let coating = CookTorrance::new(
            specular_reflectance,
            microfacet,
            Shadowing::SmithSeparable,
            Fresnel::Dielectric { eta: Rgb::splat(eta) },
        )?;
        let (table, r_int) = coating_tables(&microfacet, eta);
        let single = Transmission {
            table: table.into(),
            internal_reflectance: r_int,
        };
        Ok(RoughPlastic {
            diffuse_reflectance: rho,
            eta,
            nonlinear,
            base: Base::new(rho, coating.ks, eta, r_int, nonlinear),
            coating,
            multiscatter: DielectricMultiscatter::None,
            through: single.clone(),
            single,
        })
    }

    /// The same plastic with energy compensation `kind` of its coating from
    /// lobe's built-in tables (see the module documentation).
    pub fn with_multiscatter(self, kind: Compensation) -> crate::error::Result<Self> {
        // Isotropic (checked in `new`).
        let (ndf, (alpha, _)) = (self.coating.microfacet.ndf(), self.coating.microfacet.alpha());
        let (multiscatter, through) = match kind {
            Compensation::None => (DielectricMultiscatter::None, self.single.clone()),
            _ if self.eta < 1.0 => {
                return Err(crate::Error::param(
                    "multiscatter",
                    format!(
                        "{kind} needs int_ior ≥ ext_ior (a coating denser than the outside, as a \
                         plastic's is; here int_ior/ext_ior is {}): under a rarer coating the \
                         compensated transmittance breaks reciprocity, and a white base would \
                         send back more light than it receives",
                        self.eta
                    ),
                ));
            }
            Compensation::Turquin => {
                let turquin = DielectricTurquin::builtin(ndf, alpha, self.eta)?;
                let table = self.compensated_transmittance(|mu, t| {
                    t * turquin.scale(mu, self.eta)
                });
                (DielectricMultiscatter::Turquin(turquin), table)
            }
            Compensation::KullaConty => {
                let kc = DielectricKullaConty::builtin(ndf, alpha, self.eta)?;
                // The added transmission into the base: τ_out (1 − E(μ)).
                let table = self.compensated_transmittance(|mu, t| {
                    let w = DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
                    t + kc.tau(w) * kc.albedo(w)
                });
                (DielectricMultiscatter::KullaConty(kc), table)
            }
        };
        let base = Base::new(
            self.diffuse_reflectance,
            self.coating.ks,
            self.eta,
            through.internal_reflectance,
            self.nonlinear,
        );
        Ok(RoughPlastic {
            multiscatter,
            base,
            through,
            ..self
        })
    }

    /// The compensated coating's transmittance table, `through(μⱼ, T(μⱼ))`
    /// at each cosine (at most 1), and `R_int` from it by reciprocity:
    /// `1 − R_int = 2 ∫ T(μ) μ dμ / η²`, exact for the piecewise-linear `T`.
    fn compensated_transmittance(&self, through: impl Fn(f64, f64) -> f64) -> Transmission {
        let n = TABLE_SIZE - 1;
        let table: Vec<f64> = (0..TABLE_SIZE)
            .map(|j| {
                let mu = (j as f64 / n as f64).max(1e-6);
                through(mu, self.single.table[j]).min(1.0)
            })
            .collect();
        // 2 ∫ T(μ) μ dμ of the piecewise-linear T, segment by segment.
        let mean: f64 = table
            .windows(2)
            .enumerate()
            .map(|(j, t)| {
                let (a, b) = (j as f64 / n as f64, (j + 1) as f64 / n as f64);
                (b - a) / 6.0 * (t[0] * (2.0 * a + b) + t[1] * (a + 2.0 * b))
            })
            .sum::<f64>()
            * 2.0;
        Transmission {
            table: table.into(),
            internal_reflectance: (1.0 - mean / (self.eta * self.eta)).max(0.0),
        }
    }

    /// The coating's part of `f` (compensated where asked).
    #[inline]
    fn coating_eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
        self.compensated(self.coating.eval(wo, wi), wo, wi)
    }

    /// The single-scattering coating's `f` compensated: scaled by
    /// `1/E(μo, α, η)` (Turquin) or with Kulla-Conty's added reflection
    /// (tinted as the coating); `f` itself without compensation.
    #[inline]
    fn compensated(&self, f: Rgb, wo: DVec3, wi: DVec3) -> Rgb {
        match &self.multiscatter {
            DielectricMultiscatter::None => f,
            DielectricMultiscatter::Turquin(t) => f * t.scale(wo.z.max(0.0), self.eta),
            DielectricMultiscatter::KullaConty(kc) => f + self.coating.ks * kc.eval(wo, wi),
        }
    }

    /// `T(cos θ)`, linear between the table's cosines (the compensated
    /// coating's with `multiscatter`).
    #[inline]
    #[must_use]
    pub fn transmittance(&self, cos_theta: f64) -> f64 {
        let x = cos_theta.clamp(0.0, 1.0) * (TABLE_SIZE - 1) as f64;
        let i = (x as usize).min(TABLE_SIZE - 2);
        let t = &self.through.table;
        t[i] + (t[i + 1] - t[i]) * (x - i as f64)
    }

    /// The base under the coating: the scale of its `f` and the coating's
    /// weight in the lobe choice.
    #[must_use]
    pub fn base(&self) -> &Base {
        &self.base
    }

    /// `R_int`, the coating's mean reflectance from inside (the
    /// compensated coating's with `multiscatter`).
    #[must_use]
    pub fn internal_reflectance(&self) -> f64 {
        self.through.internal_reflectance
    }

    /// Probability of sampling the coating for `wo`.
    #[inline]
    fn coating_probability(&self, wo: DVec3) -> f64 {
        self.base.coating_probability(self.transmittance(wo.z))
    }

    /// The base's part of `f`.
    #[inline]
    fn base_eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
        self.base.scale * (self.transmittance(wo.z) * self.transmittance(wi.z))
    }
}

/// `T(μⱼ)` for the table's cosines and `R_int`, as Mitsuba 3 defines them:
/// the single-scattering transmittance into the coating and its
/// reflectance from inside, each the mean over visible normals of
/// `G1(w') (1 − F)` (or `G1(w') F`), by Gauss-Legendre quadrature over the
/// visible-normal sampler's square (`n × n` nodes, `n` 32 from the side of
/// the larger index, 128 from the other, where total internal reflection
/// cuts the integrand).
fn coating_tables(mf: &Microfacet, eta: f64) -> (Vec<f64>, f64) {
    // Recently built coatings, by their microfacets and index: a front end
    // that builds the same material for each of its views (`lobe explore`)
    // computes the 1.1 million integrand values once. At most 16 kept.
    type Cache = std::sync::Mutex<Vec<(String, (Vec<f64>, f64))>>;
    static CACHE: std::sync::OnceLock<Cache> = std::sync::OnceLock::new();
    let key = format!("{mf:?} {eta:?}");
    let cache = CACHE.get_or_init(Default::default);
    if let Some(hit) = cache
        .lock()
        .ok()
        .and_then(|c| c.iter().find(|e| e.0 == key).map(|e| e.1.clone()))
    {
        return hit;
    }
    let tables = compute_coating_tables(mf, eta);
    if let Ok(mut c) = cache.lock() {
        if c.len() >= 16 {
            c.remove(0);
        }
        c.push((key, tables.clone()));
    }
    tables
}

/// [`coating_tables`] computed (the cosines in parallel, summed in order:
/// the same numbers for any thread count).
fn compute_coating_tables(mf: &Microfacet, eta: f64) -> (Vec<f64>, f64) {
    let mu = |j: usize| (j as f64 / (TABLE_SIZE - 1) as f64).max(1e-6);
    // The two rules, computed once for the 128 integrals.
    let rules = [32, 128].map(crate::stats::quadrature::gauss_legendre);
    let quad = |n: usize, f: &dyn Fn(DVec2) -> f64| -> f64 {
        let rule = &rules[usize::from(n == 128)];
        let mut s = 0.0;
        for &(xa, wa) in rule {
            for &(xb, wb) in rule {
                s += 0.25 * wa * wb * f(DVec2::new(0.5 * xa + 0.5, 0.5 * xb + 0.5));
            }
        }
        s
    };
    let nodes = |e: f64| if e > 1.0 { 32 } else { 128 };
    let g1 = |w: DVec3, m: DVec3| {
        if w.dot(m) * w.z <= 0.0 { 0.0 } else { mf.g1(w) }
    };
    let transmittance = |wi: DVec3, e: f64| {
        quad(nodes(e), &|u| {
            let Some(m) = mf.sample_visible(wi, u) else { return 0.0 };
            let fr = fresnel_dielectric(wi.dot(m), e);
            let wt = m * (wi.dot(m) * fr.eta_ti + fr.cos_theta_t) - wi * fr.eta_ti;
            if wt.z * wi.z >= 0.0 { 0.0 } else { g1(wt, m) * (1.0 - fr.r) }
        })
    };
    let reflectance = |wi: DVec3, e: f64| {
        quad(nodes(e), &|u| {
            let Some(m) = mf.sample_visible(wi, u) else { return 0.0 };
            let c = wi.dot(m);
            let f = fresnel_dielectric(c, e).r;
            let wr = 2.0 * c * m - wi;
            if wr.z <= 0.0 { 0.0 } else { g1(wr, m) * f }
        })
    };
    let dir = |m: f64| DVec3::new((1.0 - m * m).max(0.0).sqrt(), 0.0, m);
    let table = crate::parallel::map_indices(TABLE_SIZE, |j| transmittance(dir(mu(j)), eta));
    let r_int = 2.0
        * crate::parallel::map_indices(TABLE_SIZE, |j| reflectance(dir(mu(j)), 1.0 / eta) * mu(j))
            .into_iter()
            .sum::<f64>()
        / TABLE_SIZE as f64;
    (table, r_int)
}

/// A rough plastic's samplers: its coating's (the microfacet strategies;
/// the base is cosine sampled whatever the strategy).
pub type RoughPlasticSampler = super::cook_torrance::MicrofacetSampler;

impl Bxdf for RoughPlastic {
    type Sampler = RoughPlasticSampler;

    /// The coating's table ([`CookTorrance`]'s): `brdf`, `vndf`,
    /// `spherical-caps`, `bounded-vndf`.
    fn sampler(&self, strategy: BsdfStrategy) -> Result<RoughPlasticSampler, String> {
        self.coating.sampler(strategy)
    }

    fn scattering(&self) -> Scattering {
        Scattering::GlossyReflection
    }

    fn reach(&self) -> Reach {
        Reach {
            transmits: false,
            delta: false,
            chooses: true,
        }
    }

    #[inline]
    fn eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
        self.coating_eval(wo, wi) + self.base_eval(wo, wi)
    }

    #[inline]
    fn sample(&self, s: RoughPlasticSampler, wo: DVec3, uc: f64, u: DVec2) -> Option<DVec3> {
        if uc < self.coating_probability(wo) {
            self.coating.sample(s, wo, 0.0, u)
        } else {
            let wi = warp::square_to_cosine_hemisphere(u);
            (wi.z > 0.0).then_some(wi)
        }
    }

    #[inline]
    fn pdf(&self, s: RoughPlasticSampler, wo: DVec3, wi: DVec3) -> f64 {
        let p = self.coating_probability(wo);
        p * self.coating.pdf(s, wo, wi) + (1.0 - p) * warp::square_to_cosine_hemisphere_pdf(wi)
    }

    #[inline]
    fn eval_pdf(&self, s: RoughPlasticSampler, wo: DVec3, wi: DVec3) -> (Rgb, f64) {
        let (fc, pc) = self.coating.eval_pdf(s, wo, wi);
        let p = self.coating_probability(wo);
        (
            self.compensated(fc, wo, wi) + self.base_eval(wo, wi),
            p * pc + (1.0 - p) * warp::square_to_cosine_hemisphere_pdf(wi),
        )
    }

    #[inline]
    fn sample_eval(&self, s: RoughPlasticSampler, wo: DVec3, uc: f64, u: DVec2) -> Option<LobeSample> {
        let coating = uc < self.coating_probability(wo);
        let wi = if coating {
            self.coating.sample(s, wo, 0.0, u)?
        } else {
            let wi = warp::square_to_cosine_hemisphere(u);
            (wi.z > 0.0).then_some(wi)?
        };
        let (f, pdf) = self.eval_pdf(s, wo, wi);
        Some(LobeSample {
            wi,
            f,
            pdf,
            scattering: if coating {
                Scattering::GlossyReflection
            } else {
                Scattering::DiffuseReflection
            },
        })
    }

    fn albedo_hint(&self, _wo: DVec3) -> f64 {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mitsuba 3.9.1's tables for its default index (1.49/1.000277),
    /// α = 0.1: `R_int` and `T` at the ends and the middle (read from
    /// Mitsuba, in the notes of issue 42).
    #[test]
    fn tables_match_mitsuba() {
        let eta = 1.49 / 1.000_277;
        for (ndf, r_int, t) in [
            (crate::Ndf::Beckmann, 0.574_663, [(0, 0.37013), (31, 0.90819), (63, 0.96132)]),
            (crate::Ndf::Ggx, 0.545_523, [(0, 0.57312), (31, 0.90573), (63, 0.96089)]),
        ] {
            let mf = Microfacet::new(ndf, 0.1, 0.1).unwrap();
            let (table, r) = coating_tables(&mf, eta);
            assert!((r - r_int).abs() < 2e-3, "{ndf:?}: R_int {r} vs Mitsuba's {r_int}");
            for (j, v) in t {
                assert!((table[j] - v).abs() < 2e-3, "{ndf:?}: T[{j}] {} vs Mitsuba's {v}", table[j]);
            }
        }
    }
}
