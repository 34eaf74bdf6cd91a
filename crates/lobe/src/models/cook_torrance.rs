//! Cook-Torrance microfacet reflection.
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `ks` | RGB in [0, 1] | 1 | specular tint, multiplies `F` |
//! | `kd` | RGB in [0, 1] | 0 | diffuse colour, added as `kd/π` |
//! | `distribution` | `ggx`, `beckmann`, `blinn-phong` | `ggx` | the NDF `D` |
//! | `alpha` | [1e-4, 2] (`blinn-phong`: ≤ 1) | 0.3 | width of `D` |
//! | `alpha_u` | [1e-4, 2] (`blinn-phong`: ≤ 1) | `alpha` | width along the tangent; with `alpha_v`, instead of `alpha` (anisotropic) |
//! | `alpha_v` | [1e-4, 2] (`blinn-phong`: ≤ 1) | `alpha` | width along the bitangent |
//! | `roughness` | ≥ 0 | — | instead of `alpha`: `alpha = roughness²` |
//! | `shadowing` | `smith-separable`, `smith-correlated`, `v-cavity` | `smith-correlated` | the term `G` |
//! | `fresnel` | `none`, `schlick`, `dielectric`, `conductor` | `none` | the term `F`: an object with that `type` and its keys |
//! | `multiscatter` | `none`, `kulla-conty`, `turquin` | `none` | energy compensation for the light that bounces between microfacets ([`crate::energy::compensation`]; GGX or Beckmann with a Smith term; not a Mitsuba key, and `none` is Mitsuba's lobe) |
//!
//! (This table is [`PARAMS`]; a test checks that they agree. The Fresnel
//! terms and their keys are in [`crate::Fresnel`].)
//!
//! `f = ks · D(h) G(wo, wi, h) F(wo·h) / (4 cos θo cos θi)`, `h` the half
//! vector. With `F = 1` and a Smith term the directional albedo is at most 1
//! (energy is lost, not created, because single scattering ignores the light
//! that bounces between microfacets).
//!
//! Strategies, each turned from a density over `h` into one over `wi` by the
//! Jacobian `1/(4 wo·h)`:
//! * `brdf`: `p(h) = D(h) cos θh`, the lecture's sampler;
//! * `vndf`: visible normals, `p(h) = G1(wo) max(0, wo·h) D(h) / cos θo`
//!   (GGX, Beckmann), so that `p(wi) = G1(wo) D(h) / (4 cos θo)`;
//! * `spherical-caps`: the same density by a cheaper construction (GGX);
//! * `bounded-vndf`: Eto and Tokuyoshi's bounded VNDF with its own density (GGX).
//!
//! The sampling densities use Smith's `G1` whatever `G` term `eval` uses.

use super::{Bxdf, ModelInfo, Param, Range, Value};
use crate::energy::compensation::{self, Compensation, KullaConty, KullaContyAt, Multiscatter};
use crate::math::{INV_PI, Rgb, luminance, reflect};
use crate::sample::{LobeSample, Scattering};
use crate::microfacet::{MAX_ALPHA, MIN_ALPHA, Microfacet, Ndf, Shadowing};
use crate::{Fresnel, BsdfStrategy};
use glam::{DVec2, DVec3};

pub const KS: Param = Param {
    name: "ks",
    range: Range::Colour { max: 1.0 },
    note: "",
    default: Value::Number(1.0),
    meaning: "specular tint, multiplies `F`",
};
pub const DISTRIBUTION: Param = Param {
    name: "distribution",
    range: Range::Names(Ndf::NAMES),
    note: "",
    default: Value::Name("ggx"),
    meaning: "the NDF `D`",
};
pub const ALPHA: Param = Param {
    name: "alpha",
    range: Range::Number {
        min: MIN_ALPHA,
        max: MAX_ALPHA,
    },
    note: "(`blinn-phong`: ≤ 1)",
    default: Value::Number(0.3),
    meaning: "width of `D`",
};
pub const ALPHA_U: Param = Param {
    name: "alpha_u",
    default: Value::Text("`alpha`"),
    meaning: "width along the tangent; with `alpha_v`, instead of `alpha` (anisotropic)",
    ..ALPHA
};
pub const ALPHA_V: Param = Param {
    name: "alpha_v",
    meaning: "width along the bitangent",
    ..ALPHA_U
};
pub const ROUGHNESS: Param = Param {
    name: "roughness",
    range: Range::Number {
        min: 0.0,
        max: f64::INFINITY,
    },
    note: "",
    default: Value::Text("—"),
    meaning: "instead of `alpha`: `alpha = roughness²`",
};
pub const SHADOWING: Param = Param {
    name: "shadowing",
    range: Range::Names(Shadowing::NAMES),
    note: "",
    default: Value::Name("smith-correlated"),
    meaning: "the term `G`",
};
pub const FRESNEL: Param = Param {
    name: "fresnel",
    range: Range::Names("none, schlick, dielectric, conductor"),
    note: "",
    default: Value::Name("none"),
    meaning: "the term `F`: an object with that `type` and its keys",
};

/// The keys of a Cook-Torrance material.
pub const PARAMS: &[Param] = &[
    KS,
    super::KD,
    DISTRIBUTION,
    ALPHA,
    ALPHA_U,
    ALPHA_V,
    ROUGHNESS,
    SHADOWING,
    FRESNEL,
    super::keys::MULTISCATTER,
];

pub const DEFAULT_ALPHA: f64 = ALPHA.default.number();

pub const INFO: ModelInfo = ModelInfo {
    name: "cook-torrance",
    params: PARAMS,
    #[cfg(feature = "desc")]
    from_desc,
};

#[cfg(feature = "desc")]
fn from_desc(d: &crate::desc::MaterialDesc) -> crate::error::Result<super::Lobes> {
    use crate::Error;
    let ndf: Ndf = d
        .distribution
        .as_deref()
        .unwrap_or(DISTRIBUTION.default.name())
        .parse()?;
    let (ax, ay) = alphas(d)?;
    let mf = Microfacet::new(ndf, ax, ay).map_err(|e| match e {
        // Name the key the user wrote.
        Error::Param { message, .. } if d.alpha.is_some() => Error::Param {
            field: ALPHA.name.into(),
            message,
        },
        Error::Param { message, .. } if d.roughness.is_some() => Error::Param {
            field: ROUGHNESS.name.into(),
            message: format!("gives {message} (alpha = roughness²)"),
        },
        e => e,
    })?;
    let shadowing: Shadowing = d
        .shadowing
        .as_deref()
        .unwrap_or(SHADOWING.default.name())
        .parse()?;
    let fresnel = d
        .fresnel
        .as_ref()
        .map_or(Ok(Fresnel::None), crate::desc::FresnelDesc::build)?;
    let lobe = CookTorrance::new(super::colour(d.ks, KS), mf, shadowing, fresnel)?
        .with_multiscatter(super::keys::multiscatter(d)?)?;
    super::Lobes::with_diffuse(super::colour(d.kd, super::KD), super::Glossy::CookTorrance(lobe))
}

/// `(alpha_u, alpha_v)` from `alpha`, `alpha_u`/`alpha_v` or `roughness`.
#[cfg(feature = "desc")]
fn alphas(d: &crate::desc::MaterialDesc) -> crate::error::Result<(f64, f64)> {
    use crate::Error;
    let given = [
        d.alpha.is_some(),
        d.alpha_u.is_some() || d.alpha_v.is_some(),
        d.roughness.is_some(),
    ];
    if given.iter().filter(|&&g| g).count() > 1 {
        return Err(Error::param(
            "alpha",
            "give only one of alpha, alpha_u/alpha_v, roughness",
        ));
    }
    if let Some(r) = d.roughness {
        if !r.is_finite() || r < 0.0 {
            return Err(Error::param(
                "roughness",
                format!("{r} is out of range: roughness must be a number >= 0"),
            ));
        }
        return Ok((r * r, r * r));
    }
    if let Some(a) = d.alpha {
        return Ok((a, a));
    }
    match (d.alpha_u, d.alpha_v) {
        (Some(u), Some(v)) => Ok((u, v)),
        (None, None) => Ok((DEFAULT_ALPHA, DEFAULT_ALPHA)),
        (None, _) => Err(Error::param("alpha_u", "missing: alpha_v needs alpha_u")),
        (_, None) => Err(Error::param("alpha_v", "missing: alpha_u needs alpha_v")),
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CookTorrance {
    pub ks: Rgb,
    pub microfacet: Microfacet,
    pub shadowing: Shadowing,
    pub fresnel: Fresnel,
    /// Energy compensation (`multiscatter`); [`Multiscatter::None`] from
    /// [`CookTorrance::new`].
    pub multiscatter: Multiscatter,
}

impl CookTorrance {
    pub fn new(
        ks: Rgb,
        microfacet: Microfacet,
        shadowing: Shadowing,
        fresnel: Fresnel,
    ) -> crate::error::Result<Self> {
        Ok(CookTorrance {
            ks: KS.check_colour(ks, None)?,
            microfacet,
            shadowing,
            fresnel,
            multiscatter: Multiscatter::None,
        })
    }

    /// The same lobe with energy compensation `kind`, from lobe's built-in
    /// albedo tables; the error (naming `multiscatter`) says why the lobe
    /// cannot have it (a distribution or shadowing term without a table).
    pub fn with_multiscatter(self, kind: Compensation) -> crate::error::Result<Self> {
        if kind == Compensation::None {
            return Ok(CookTorrance {
                multiscatter: Multiscatter::None,
                ..self
            });
        }
        let ndf = self.microfacet.ndf();
        let table = crate::energy::AlbedoTables::builtin()
            .get(ndf, crate::energy::table::Surface::Conductor(self.shadowing))
            .ok_or_else(|| {
                crate::Error::param(
                    "multiscatter",
                    format!(
                        "{kind} needs a table of the lobe's albedo, and lobe has them for \
                         distribution ggx or beckmann with shadowing smith-separable or \
                         smith-correlated, not {} with {}",
                        ndf.name(),
                        self.shadowing.name()
                    ),
                )
            })?;
        let (ax, ay) = self.microfacet.alpha();
        let (ks, fresnel) = (self.ks, self.fresnel);
        Ok(CookTorrance {
            multiscatter: Multiscatter::new(kind, table, (ax * ay).sqrt(), |mu| {
                ks * fresnel.eval(mu)
            }),
            ..self
        })
    }

    /// With Kulla-Conty compensation, the probability that a sample is
    /// drawn from the added lobe (by cosine sampling) at `wo`; else 0.
    #[inline]
    fn cosine_probability(&self, wo: DVec3) -> f64 {
        match &self.multiscatter {
            Multiscatter::KullaConty(kc) => self.kulla_conty_at(kc, wo).q,
            _ => 0.0,
        }
    }

    /// Kulla-Conty's lobe at `wo` (one table lookup).
    #[inline]
    fn kulla_conty_at(&self, kc: &KullaConty, wo: DVec3) -> KullaContyAt {
        kc.at(wo, self.ks * self.fresnel.eval(wo.z))
    }

    /// Kulla-Conty's `sample_eval`: the single-scattering lobe's own
    /// `sample_eval` where the microfacet sampler draws (its `D`, `Λ(wo)`
    /// and half vector shared), its `eval_pdf` where the cosine draws, the
    /// added lobe and the mixture density from one lookup of `E(μo)`.
    #[inline]
    fn kulla_conty_sample_eval(
        &self,
        kc: &KullaConty,
        sampler: MicrofacetSampler,
        wo: DVec3,
        u: DVec2,
    ) -> Option<LobeSample> {
        let at = self.kulla_conty_at(kc, wo);
        let drawn = |u| {
            self.single_sample_eval(sampler, wo, u)
                .map(|s| (s.wi, s.f, s.pdf))
        };
        let (wi, f, p) = if at.q > 0.0 {
            match compensation::choose(u, at.q) {
                Ok(u) => {
                    let wi = crate::warp::square_to_cosine_hemisphere(u);
                    if wi.z <= 0.0 {
                        return None;
                    }
                    let (f, p) = self.single_eval_pdf(sampler, wo, wi);
                    (wi, f, p)
                }
                Err(u) => drawn(u)?,
            }
        } else {
            drawn(u)?
        };
        let pdf = Self::mixed_pdf(p, at.q, wi);
        (pdf > 0.0).then_some(LobeSample {
            wi,
            f: f + kc.eval_at(&at, wi),
            pdf,
            scattering: Scattering::GlossyReflection,
        })
    }

    /// The single-scattering lobe's `f` with the compensation added or
    /// applied; `f` itself without compensation (the same bits).
    #[inline]
    fn compensated(&self, f: Rgb, wo: DVec3, wi: DVec3) -> Rgb {
        match &self.multiscatter {
            Multiscatter::None => f,
            Multiscatter::KullaConty(kc) => f + kc.eval(wo, wi),
            Multiscatter::Turquin(t) => f * t.scale(wo),
        }
    }

    /// The mixture density of Kulla-Conty sampling: `p` the microfacet
    /// sampler's, `q` the cosine's share.
    #[inline]
    fn mixed_pdf(p: f64, q: f64, wi: DVec3) -> f64 {
        if q > 0.0 {
            (1.0 - q) * p + q * wi.z.max(0.0) * INV_PI
        } else {
            p
        }
    }
}

/// Cook-Torrance's samplers: how the microfacet normal `wm` is drawn
/// before `wo` is reflected about it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MicrofacetSampler {
    /// `p(wm) = D(wm) cos θm`, the lecture's (`brdf`).
    DCos,
    /// Visible normals, Heitz 2018 (`vndf`).
    Visible,
    /// Visible normals by spherical caps, Dupuy and Benyoub 2023
    /// (`spherical-caps`): the density of `Visible`.
    SphericalCaps,
    /// Bounded VNDF, Eto and Tokuyoshi 2023 (`bounded-vndf`).
    BoundedVisible,
}

impl CookTorrance {
    /// Draw the microfacet normal by `sampler` and reflect: `(wi, wm)`.
    #[inline]
    fn sample_wm(&self, sampler: MicrofacetSampler, wo: DVec3, u: DVec2) -> Option<(DVec3, DVec3)> {
        let mf = &self.microfacet;
        let wm = match sampler {
            MicrofacetSampler::Visible => mf.sample_visible(wo, u)?,
            MicrofacetSampler::SphericalCaps => mf.sample_visible_caps(wo, u),
            MicrofacetSampler::BoundedVisible => mf.sample_visible_bounded(wo, u),
            MicrofacetSampler::DCos => mf.sample_wm(u),
        };
        if wo.dot(wm) <= 0.0 {
            return None;
        }
        // Reflecting a unit vector about a unit vector keeps it unit to an ulp or two.
        let wi = reflect(wo, wm);
        (wi.z > 0.0).then_some((wi, wm))
    }

    /// The pdf of the reflected direction by `sampler` from the terms it
    /// shares with `f`: `h` the half vector, `cos_oh = wo·h > 0`,
    /// `d = D(h)`, `lo` gives `Λ(wo)` (computed only where needed).
    #[inline]
    fn pdf_of(
        &self,
        sampler: MicrofacetSampler,
        wo: DVec3,
        h: DVec3,
        cos_oh: f64,
        d: f64,
        lo: impl FnOnce() -> f64,
    ) -> f64 {
        let mf = &self.microfacet;
        match sampler {
            MicrofacetSampler::BoundedVisible => mf.pdf_reflect_bounded_d(d, wo),
            MicrofacetSampler::Visible | MicrofacetSampler::SphericalCaps => {
                Microfacet::pdf_visible_reflect(d, lo(), wo)
            }
            MicrofacetSampler::DCos => mf.pdf_wm(h) / (4.0 * cos_oh),
        }
    }
}

/// The single-scattering lobe (without compensation), which the
/// [`Bxdf`] methods compensate.
impl CookTorrance {
    #[inline]
    /// `f` of the single-scattering lobe.
    #[must_use]
    pub fn single_eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
        let Some(h) = (wo + wi).try_normalize() else {
            return Rgb::ZERO;
        };
        let cos_oh = wo.dot(h);
        if cos_oh <= 0.0 {
            return Rgb::ZERO;
        }
        let mf = &self.microfacet;
        let dg = mf.d(h) * mf.g(self.shadowing, wo, wi, h) / (4.0 * wo.z * wi.z);
        if !(dg.is_finite()) {
            return Rgb::ZERO;
        }
        self.ks * self.fresnel.eval(cos_oh) * dg
    }

    /// The sampled `wm` is the half vector of `wo` and the reflected `wi`,
    /// so `D(wm)` and `Λ(wo)` serve `f` and the pdf at once.
    #[inline]
    fn single_sample_eval(
        &self,
        sampler: MicrofacetSampler,
        wo: DVec3,
        u: DVec2,
    ) -> Option<LobeSample> {
        let (wi, wm) = self.sample_wm(sampler, wo, u)?;
        let mf = &self.microfacet;
        let cos_oh = wo.dot(wm);
        let d = mf.d(wm);
        let lo = mf.lambda(wo);
        let g = mf.g_with_lambda_o(self.shadowing, lo, wo, wi, wm);
        let inv4o = 0.25 / wo.z;
        let dg = d * g * inv4o / wi.z;
        let pdf = match sampler {
            MicrofacetSampler::Visible | MicrofacetSampler::SphericalCaps => {
                Microfacet::pdf_visible_reflect(d, lo, wo)
            }
            MicrofacetSampler::BoundedVisible => mf.pdf_reflect_bounded(wo, wi),
            MicrofacetSampler::DCos => mf.pdf_wm(wm) * 0.25 / cos_oh,
        };
        if !(dg.is_finite() && pdf.is_finite()) {
            return None;
        }
        Some(LobeSample {
            wi,
            f: self.ks * self.fresnel.eval(cos_oh) * dg,
            pdf,
            scattering: Scattering::GlossyReflection,
        })
    }

    #[inline]
    fn single_pdf(&self, sampler: MicrofacetSampler, wo: DVec3, wi: DVec3) -> f64 {
        let mf = &self.microfacet;
        // Every sampler draws `wi` by reflecting `wo` about a normal `wm`
        // with `wo·wm > 0`, so no sampler's density reaches a pair whose
        // half vector faces away from `wo` (for unit vectors only
        // `wi = −wo`; for vectors rounded to f32, pairs near it).
        let Some(h) = (wo + wi).try_normalize() else {
            return 0.0;
        };
        let cos_oh = wo.dot(h);
        if cos_oh <= 0.0 {
            return 0.0;
        }
        let p = self.pdf_of(sampler, wo, h, cos_oh, mf.d(h), || mf.lambda(wo));
        if p.is_finite() { p } else { 0.0 }
    }

    /// `eval` and `pdf` sharing the half vector, `D(h)` and `Λ(wo)`; the
    /// same numbers as the two calls.
    #[inline]
    fn single_eval_pdf(&self, sampler: MicrofacetSampler, wo: DVec3, wi: DVec3) -> (Rgb, f64) {
        let mf = &self.microfacet;
        // As `pdf`: no sampler reaches a pair with `wo·h <= 0`.
        let Some(h) = (wo + wi).try_normalize() else {
            return (Rgb::ZERO, 0.0);
        };
        let cos_oh = wo.dot(h);
        if cos_oh <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let d = mf.d(h);
        let lo = mf.lambda(wo);
        let dg = d * mf.g_with_lambda_o(self.shadowing, lo, wo, wi, h) / (4.0 * wo.z * wi.z);
        let f = if dg.is_finite() {
            self.ks * self.fresnel.eval(cos_oh) * dg
        } else {
            Rgb::ZERO
        };
        let p = self.pdf_of(sampler, wo, h, cos_oh, d, || lo);
        (f, if p.is_finite() { p } else { 0.0 })
    }

}

impl Bxdf for CookTorrance {
    type Sampler = MicrofacetSampler;

    /// | strategy | sampler | needs |
    /// |---|---|---|
    /// | `brdf` | [`MicrofacetSampler::DCos`] | |
    /// | `vndf` | [`MicrofacetSampler::Visible`] | GGX or Beckmann |
    /// | `spherical-caps` | [`MicrofacetSampler::SphericalCaps`] | GGX |
    /// | `bounded-vndf` | [`MicrofacetSampler::BoundedVisible`] | GGX |
    fn sampler(&self, strategy: BsdfStrategy) -> Result<MicrofacetSampler, String> {
        let ndf = self.microfacet.ndf();
        match (strategy, ndf) {
            (BsdfStrategy::Brdf, _) => Ok(MicrofacetSampler::DCos),
            (BsdfStrategy::Vndf, Ndf::Ggx | Ndf::Beckmann) => Ok(MicrofacetSampler::Visible),
            (BsdfStrategy::Vndf, _) => {
                Err("visible-normal sampling needs distribution ggx or beckmann".into())
            }
            (BsdfStrategy::SphericalCaps, Ndf::Ggx) => Ok(MicrofacetSampler::SphericalCaps),
            (BsdfStrategy::BoundedVndf, Ndf::Ggx) => Ok(MicrofacetSampler::BoundedVisible),
            (BsdfStrategy::SphericalCaps | BsdfStrategy::BoundedVndf, _) => {
                Err(format!("{strategy} needs distribution ggx"))
            }
            (BsdfStrategy::Uniform | BsdfStrategy::Cosine, _) => {
                Err(format!("{strategy} is drawn by the material, not the lobe"))
            }
        }
    }

    fn scattering(&self) -> Scattering {
        Scattering::GlossyReflection
    }

    #[inline]
    fn eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
        self.compensated(self.single_eval(wo, wi), wo, wi)
    }

    /// With Kulla-Conty compensation, `u.x` first chooses between cosine
    /// sampling (the added lobe, probability `q(wo)`) and the sampler.
    #[inline]
    fn sample(&self, sampler: MicrofacetSampler, wo: DVec3, _uc: f64, u: DVec2) -> Option<DVec3> {
        let q = self.cosine_probability(wo);
        if q > 0.0 {
            return match compensation::choose(u, q) {
                Ok(u) => Some(crate::warp::square_to_cosine_hemisphere(u)).filter(|w| w.z > 0.0),
                Err(u) => self.sample_wm(sampler, wo, u).map(|(wi, _)| wi),
            };
        }
        self.sample_wm(sampler, wo, u).map(|(wi, _)| wi)
    }

    /// The sampled `wm` is the half vector of `wo` and the reflected `wi`,
    /// so `D(wm)` and `Λ(wo)` serve `f` and the pdf at once (without
    /// compensation; with it, `eval_pdf` at the sampled direction).
    #[inline]
    fn sample_eval(
        &self,
        sampler: MicrofacetSampler,
        wo: DVec3,
        _uc: f64,
        u: DVec2,
    ) -> Option<LobeSample> {
        match &self.multiscatter {
            Multiscatter::None => self.single_sample_eval(sampler, wo, u),
            Multiscatter::KullaConty(kc) => self.kulla_conty_sample_eval(kc, sampler, wo, u),
            Multiscatter::Turquin(t) => self.single_sample_eval(sampler, wo, u).map(|s| LobeSample {
                f: s.f * t.scale(wo),
                ..s
            }),
        }
    }

    #[inline]
    fn pdf(&self, sampler: MicrofacetSampler, wo: DVec3, wi: DVec3) -> f64 {
        Self::mixed_pdf(
            self.single_pdf(sampler, wo, wi),
            self.cosine_probability(wo),
            wi,
        )
    }

    /// `eval` and `pdf` sharing the half vector, `D(h)` and `Λ(wo)`; the
    /// same numbers as the two calls.
    #[inline]
    fn eval_pdf(&self, sampler: MicrofacetSampler, wo: DVec3, wi: DVec3) -> (Rgb, f64) {
        let (f, p) = self.single_eval_pdf(sampler, wo, wi);
        match &self.multiscatter {
            Multiscatter::KullaConty(kc) => {
                let at = self.kulla_conty_at(kc, wo);
                (f + kc.eval_at(&at, wi), Self::mixed_pdf(p, at.q, wi))
            }
            _ => (self.compensated(f, wo, wi), p),
        }
    }

    fn albedo_hint(&self, wo: DVec3) -> f64 {
        let single = luminance(self.ks * self.fresnel.eval(wo.z));
        match &self.multiscatter {
            Multiscatter::KullaConty(kc) => single + kc.albedo(wo),
            _ => single,
        }
    }
}
