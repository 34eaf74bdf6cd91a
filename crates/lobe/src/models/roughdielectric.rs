//! Rough dielectric: frosted glass, a microfacet interface that reflects
//! and refracts (Walter et al. 2007; Mitsuba 3's `roughdielectric`).
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `distribution` | `ggx`, `beckmann` | `beckmann` | the NDF `D` (Mitsuba's default) |
//! | `alpha` | [1e-4, 2] | 0.1 | width of `D` |
//! | `alpha_u` | [1e-4, 2] | `alpha` | width along the tangent; with `alpha_v`, instead of `alpha` (anisotropic) |
//! | `alpha_v` | [1e-4, 2] | `alpha` | width along the bitangent |
//! | `int_ior` | > 0, or a name (`bk7`, `water`, `air`, ...: the list ends `lobe eval --help`) | `bk7` | index of refraction inside (below the surface); `bk7` is 1.5046 |
//! | `ext_ior` | > 0, or a name (`bk7`, `water`, `air`, ...: the list ends `lobe eval --help`) | `air` | index of refraction outside (above the surface); `air` is 1.000277 |
//! | `specular_reflectance` | RGB in [0, 1] | 1 | multiplies the reflected part (not physical; Mitsuba's) |
//! | `specular_transmittance` | RGB in [0, 1] | 1 | multiplies the transmitted part (not physical; Mitsuba's) |
//! | `sample_visible` | bool | true | Mitsuba's switch; lobe takes the strategy from each call instead, so only `true` is accepted |
//! | `mode` | `radiance`, `importance` | `radiance` | what is carried: radiance scales refraction by `(η_i/η_t)²`, importance does not (not a Mitsuba key: its context says) |
//! | `multiscatter` | `none`, `kulla-conty`, `turquin` | `none` | energy compensation for the light that bounces between microfacets ([`crate::energy::compensation`]; GGX or Beckmann with a Smith term; not a Mitsuba key, and `none` is Mitsuba's lobe) |
//!
//! (This table is [`PARAMS`]; a test checks that they agree.)
//!
//! With `η` the relative index of the other side over the side of `wo`
//! (`int_ior/ext_ior` from outside, its inverse from inside), the
//! generalized half vector is `h = ±(wo + η wi)` for a refraction and
//! `±(wo + wi)` for a reflection, turned to `+z`. With Smith's separable
//! `G = G1(wo) G1(wi)` (Mitsuba's), `F` the exact Fresnel reflectance at
//! `wo·h`:
//!
//! * reflection: `f = ks F D G / (4 |cos θo cos θi|)`;
//! * refraction: `f = kt (1 − F) D G |wo·h| |wi·h| / (|cos θo cos θi| (wo·h + η wi·h)²)`
//!   in radiance mode (times `η²` in importance mode).
//!
//! So `f(wo, wi)/η_o² = f(wi, wo)/η_i²` (generalized reciprocity). The
//! samplers draw a microfacet normal `m` for `wo` (turned to the upper
//! side), then reflect with probability `F(wo·m)` or refract otherwise
//! (`uc`): the density is `p(m) F / (4 |wi·m|)` or
//! `p(m) (1 − F) η² |wi·m| / (wo·m + η wi·m)²`. Strategies: `brdf`
//! (`p(m) = D(m) cos θm`), `vndf` (visible normals; GGX, Beckmann) and
//! `spherical-caps` (GGX); bounded VNDF bounds reflections only.
//!
//! `int_ior = ext_ior` (index-matched) makes every microfacet pass light
//! straight through: the lobe is then a delta, `wi = −wo`, weight `kt`.

use super::cook_torrance::{ALPHA, ALPHA_U, ALPHA_V};
use super::dielectric::{check_eta, refraction_scale};
#[cfg(feature = "desc")]
use super::keys;
use super::keys::{EXT_IOR, INT_IOR, MODE, SPECULAR_REFLECTANCE, SPECULAR_TRANSMITTANCE};
use super::{Bxdf, ModelInfo, Param, Range, Value};
use crate::energy::compensation::{
    self, Compensation, DielectricKullaConty, DielectricMultiscatter, DielectricTurquin,
};
use crate::fresnel::{fresnel_dielectric, refract_about};
use crate::math::Rgb;
use crate::microfacet::{Microfacet, Ndf};
use crate::sample::{Delta, Deltas, LobeSample, Reach, Scattering};
use crate::{BsdfStrategy, TransportMode};
use glam::{DVec2, DVec3};

pub const DISTRIBUTION: Param = Param {
    name: "distribution",
    range: Range::Names("ggx, beckmann"),
    note: "",
    default: Value::Name("beckmann"),
    meaning: "the NDF `D` (Mitsuba's default)",
};
pub const MITSUBA_ALPHA: Param = Param {
    range: Range::Number {
        min: crate::microfacet::MIN_ALPHA,
        max: crate::microfacet::MAX_ALPHA,
    },
    note: "",
    default: Value::Number(0.1),
    ..ALPHA
};
pub const MITSUBA_ALPHA_U: Param = Param {
    range: MITSUBA_ALPHA.range,
    note: "",
    ..ALPHA_U
};
pub const MITSUBA_ALPHA_V: Param = Param {
    range: MITSUBA_ALPHA.range,
    note: "",
    ..ALPHA_V
};
pub const SAMPLE_VISIBLE: Param = Param {
    name: "sample_visible",
    range: Range::Bool,
    note: "",
    default: Value::Bool(true),
    meaning: "Mitsuba's switch; lobe takes the strategy from each call instead, so only `true` is accepted",
};

/// The keys of a rough dielectric.
pub const PARAMS: &[Param] = &[
    DISTRIBUTION,
    MITSUBA_ALPHA,
    MITSUBA_ALPHA_U,
    MITSUBA_ALPHA_V,
    INT_IOR,
    EXT_IOR,
    SPECULAR_REFLECTANCE,
    SPECULAR_TRANSMITTANCE,
    SAMPLE_VISIBLE,
    MODE,
    super::keys::MULTISCATTER,
];

pub const INFO: ModelInfo = ModelInfo {
    name: "roughdielectric",
    params: PARAMS,
    #[cfg(feature = "desc")]
    from_desc,
};

#[cfg(feature = "desc")]
fn from_desc(d: &crate::desc::MaterialDesc) -> crate::error::Result<super::Lobes> {
    let lobe = RoughDielectric::new(
        mitsuba_microfacet(d, DISTRIBUTION, MITSUBA_ALPHA)?,
        keys::relative_ior(d, INT_IOR, EXT_IOR)?,
        keys::checked_colour(d.specular_reflectance, SPECULAR_REFLECTANCE)?,
        keys::checked_colour(d.specular_transmittance, SPECULAR_TRANSMITTANCE)?,
        keys::mode(d)?,
    )?
    .with_multiscatter(keys::multiscatter(d)?)?;
    Ok(super::Lobes::only(super::Glossy::RoughDielectric(lobe)))
}

/// The microfacet distribution of a Mitsuba-named model: `distribution`
/// (GGX or Beckmann), `alpha` or `alpha_u`/`alpha_v`, `sample_visible`
/// (only `true`: the strategy is an argument of each call in lobe).
#[cfg(feature = "desc")]
pub(crate) fn mitsuba_microfacet(
    d: &crate::desc::MaterialDesc,
    distribution: Param,
    alpha: Param,
) -> crate::error::Result<Microfacet> {
    use crate::Error;
    let name = d.distribution.as_deref().unwrap_or(distribution.default.name());
    let ndf = match name {
        "ggx" => Ndf::Ggx,
        "beckmann" => Ndf::Beckmann,
        other => {
            return Err(Error::UnknownName {
                field: distribution.name.into(),
                value: other.into(),
                expected: "ggx, beckmann".into(),
            });
        }
    };
    if d.sample_visible == Some(false) {
        return Err(Error::param(
            "sample_visible",
            "false is not a material parameter in lobe: the strategy is chosen per call (brdf draws D cos θm, vndf the visible normals)",
        ));
    }
    if d.roughness.is_some() {
        return Err(Error::param(
            "roughness",
            "does not apply to a Mitsuba-named model: give alpha (Mitsuba's key)",
        ));
    }
    let (ax, ay) = match (d.alpha, d.alpha_u, d.alpha_v) {
        (Some(_), Some(_), _) | (Some(_), _, Some(_)) => {
            return Err(Error::param("alpha", "give only one of alpha, alpha_u/alpha_v"));
        }
        (Some(a), None, None) => (a, a),
        (None, Some(u), Some(v)) => (u, v),
        (None, None, None) => (alpha.default.number(), alpha.default.number()),
        (None, None, Some(_)) => return Err(Error::param("alpha_u", "missing: alpha_v needs alpha_u")),
        (None, Some(_), None) => return Err(Error::param("alpha_v", "missing: alpha_u needs alpha_v")),
    };
    Microfacet::new(ndf, ax, ay).map_err(|e| match e {
        Error::Param { message, .. } if d.alpha.is_some() => Error::Param {
            field: alpha.name.into(),
            message,
        },
        e => e,
    })
}

/// A rough dielectric interface of relative index `eta = η_inside /
/// η_outside`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoughDielectric {
    pub microfacet: Microfacet,
    pub eta: f64,
    pub specular_reflectance: Rgb,
    pub specular_transmittance: Rgb,
    pub mode: TransportMode,
    /// Energy compensation (`multiscatter`); none from [`RoughDielectric::new`].
    pub multiscatter: DielectricMultiscatter,
}

impl RoughDielectric {
    /// The distribution must be GGX or Beckmann.
    pub fn new(
        microfacet: Microfacet,
        eta: f64,
        specular_reflectance: Rgb,
        specular_transmittance: Rgb,
        mode: TransportMode,
    ) -> crate::error::Result<Self> {
        if microfacet.ndf() == Ndf::BlinnPhong {
            return Err(crate::Error::param(
                "distribution",
                "a rough dielectric needs ggx or beckmann",
            ));
        }
        Ok(RoughDielectric {
            microfacet,
            eta: check_eta(eta)?,
            specular_reflectance: SPECULAR_REFLECTANCE.check_colour(specular_reflectance, None)?,
            specular_transmittance: SPECULAR_TRANSMITTANCE
                .check_colour(specular_transmittance, None)?,
            mode,
            multiscatter: DielectricMultiscatter::None,
        })
    }

    /// The same interface with energy compensation `kind` from lobe's
    /// built-in tables: `turquin` divides the lobe by its `R + T`;
    /// `kulla-conty` adds a reflection and a transmission lobe on each side
    /// ([`DielectricKullaConty`]).
    pub fn with_multiscatter(self, kind: Compensation) -> crate::error::Result<Self> {
        let (ax, ay) = self.microfacet.alpha();
        let (ndf, alpha) = (self.microfacet.ndf(), (ax * ay).sqrt());
        let multiscatter = match kind {
            Compensation::None => DielectricMultiscatter::None,
            Compensation::Turquin => {
                DielectricMultiscatter::Turquin(DielectricTurquin::builtin(ndf, alpha, self.eta)?)
            }
            Compensation::KullaConty => DielectricMultiscatter::KullaConty(
                DielectricKullaConty::builtin(ndf, alpha, self.eta)?,
            ),
        };
        Ok(RoughDielectric {
            multiscatter,
            ..self
        })
    }

    /// Index-matched: no interface, light passes straight through.
    #[inline]
    fn index_matched(&self) -> bool {
        self.eta == 1.0
    }

    /// `η` of the other side over the side of `w`.
    #[inline]
    fn eta_beyond(&self, w: DVec3) -> f64 {
        if w.z > 0.0 { self.eta } else { 1.0 / self.eta }
    }

    /// The microfacet normal (turned to `+z`) that takes `wo` to `wi`, and
    /// whether that is a reflection; `None` where no microfacet does (a
    /// backfacing one, or no half vector).
    #[inline]
    fn half_vector(&self, wo: DVec3, wi: DVec3) -> Option<(DVec3, bool)> {
        if wo.z == 0.0 || wi.z == 0.0 {
            return None;
        }
        let reflect = wo.z * wi.z > 0.0;
        let h = if reflect {
            wo + wi
        } else {
            wo + wi * self.eta_beyond(wo)
        };
        let m = h.try_normalize()?;
        let m = if m.z < 0.0 { -m } else { m };
        // Each direction on the side of the microfacet it is on of the surface.
        if wo.dot(m) * wo.z <= 0.0 || wi.dot(m) * wi.z <= 0.0 {
            return None;
        }
        Some((m, reflect))
    }

    /// Density of the microfacet normal `m` drawn by `sampler` for `wo`
    /// (seen from its side: `wo` turned to `+z` by negation).
    #[inline]
    fn pdf_m(&self, sampler: RoughSampler, wo: DVec3, m: DVec3) -> f64 {
        let mf = &self.microfacet;
        match sampler {
            RoughSampler::DCos => mf.pdf_wm(m),
            RoughSampler::Visible | RoughSampler::SphericalCaps => {
                let up = if wo.z < 0.0 { -wo } else { wo };
                mf.pdf_visible(up, m)
            }
        }
    }

    /// Draw a microfacet normal by `sampler` for `wo` (seen from its side).
    #[inline]
    fn sample_m(&self, sampler: RoughSampler, wo: DVec3, u: DVec2) -> Option<DVec3> {
        let mf = &self.microfacet;
        let up = if wo.z < 0.0 { -wo } else { wo };
        match sampler {
            RoughSampler::DCos => Some(mf.sample_wm(u)),
            RoughSampler::Visible => mf.sample_visible(up, u),
            RoughSampler::SphericalCaps => Some(mf.sample_visible_caps(up, u)),
        }
    }

    /// `(f, pdf)` at `wi` by `sampler`, or `None` where both are zero:
    /// the single-scattering lobe's, with Kulla-Conty's lobes added and
    /// their mixture density where they are on.
    #[inline]
    fn eval_pdf_at(&self, sampler: RoughSampler, wo: DVec3, wi: DVec3) -> Option<(Rgb, f64)> {
        if self.index_matched() {
            return None;
        }
        let DielectricMultiscatter::KullaConty(kc) = &self.multiscatter else {
            return self.single_eval_pdf_at(sampler, wo, wi);
        };
        let (f, p) = self
            .single_eval_pdf_at(sampler, wo, wi)
            .unwrap_or((Rgb::ZERO, 0.0));
        let q = Self::added_probability(kc, wo);
        let f = f + self.added_eval(kc, wo, wi);
        let pdf = (1.0 - q) * p + q * kc.pdf(wo, wi);
        let ok = |x: f64| x.is_finite() && x >= 0.0;
        (ok(pdf) && f.to_array().into_iter().all(ok) && (pdf > 0.0 || f != Rgb::ZERO))
            .then_some((f, pdf))
    }

    /// The probability of drawing Kulla-Conty's added lobes at `wo`: their
    /// share of a clear interface's energy, `1 − E(μo)`, at most 0.9.
    #[inline]
    fn added_probability(kc: &DielectricKullaConty, wo: DVec3) -> f64 {
        kc.albedo(wo).min(0.9)
    }

    /// Kulla-Conty's added lobes toward `wi`, tinted, and a transmission
    /// scaled for radiance as the single-scattering one is.
    #[inline]
    fn added_eval(&self, kc: &DielectricKullaConty, wo: DVec3, wi: DVec3) -> Rgb {
        let v = kc.eval(wo, wi);
        if wo.z * wi.z > 0.0 {
            self.specular_reflectance * v
        } else {
            let eta = self.eta_beyond(wo);
            let v = if self.mode == TransportMode::Importance {
                v
            } else {
                v / (eta * eta)
            };
            self.specular_transmittance * v
        }
    }

    /// The single-scattering lobe's `(f, pdf)` (Turquin's scaling applied),
    /// or `None` where both are zero.
    #[inline]
    fn single_eval_pdf_at(&self, sampler: RoughSampler, wo: DVec3, wi: DVec3) -> Option<(Rgb, f64)> {
        let (m, reflect) = self.half_vector(wo, wi)?;
        let mf = &self.microfacet;
        let (cos_om, cos_im) = (wo.dot(m), wi.dot(m));
        let d = mf.d(m);
        let g = mf.g1(wo) * mf.g1(wi);
        let fr = fresnel_dielectric(cos_om, self.eta).r;
        let cos_oi = (wo.z * wi.z).abs();
        let pm = self.pdf_m(sampler, wo, m);
        let (f, pdf) = if reflect {
            let f = self.specular_reflectance * (fr * d * g / (4.0 * cos_oi));
            (f, pm * fr / (4.0 * cos_im.abs()))
        } else {
            let eta = self.eta_beyond(wo);
            let denom = cos_om + eta * cos_im;
            let denom2 = denom * denom;
            let t = 1.0 - fr;
            let mut f = t * d * g * (cos_om * cos_im).abs() / (cos_oi * denom2);
            if self.mode == TransportMode::Importance {
                f *= eta * eta;
            }
            let pdf = pm * t * eta * eta * cos_im.abs() / denom2;
            (self.specular_transmittance * f, pdf)
        };
        let f = match &self.multiscatter {
            DielectricMultiscatter::Turquin(t) => f * t.scale(wo.z.abs(), self.eta_beyond(wo)),
            DielectricMultiscatter::None | DielectricMultiscatter::KullaConty(_) => f,
        };
        let ok = |x: f64| x.is_finite() && x >= 0.0;
        if !(ok(pdf) && f.to_array().into_iter().all(ok)) {
            return None;
        }
        Some((f, pdf))
    }
}

/// A rough dielectric's samplers: how the microfacet normal is drawn before
/// `wo` is reflected or refracted about it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RoughSampler {
    /// `p(m) = D(m) cos θm` (`brdf`).
    DCos,
    /// Visible normals of `wo`'s side (`vndf`).
    Visible,
    /// Visible normals by spherical caps (`spherical-caps`, GGX).
    SphericalCaps,
}

impl Bxdf for RoughDielectric {
    type Sampler = RoughSampler;

    /// | strategy | sampler | needs |
    /// |---|---|---|
    /// | `brdf` | [`RoughSampler::DCos`] | |
    /// | `vndf` | [`RoughSampler::Visible`] | |
    /// | `spherical-caps` | [`RoughSampler::SphericalCaps`] | GGX |
    fn sampler(&self, strategy: BsdfStrategy) -> Result<RoughSampler, String> {
        match (strategy, self.microfacet.ndf()) {
            (BsdfStrategy::Brdf, _) => Ok(RoughSampler::DCos),
            (BsdfStrategy::Vndf, _) => Ok(RoughSampler::Visible),
            (BsdfStrategy::SphericalCaps, Ndf::Ggx) => Ok(RoughSampler::SphericalCaps),
            (BsdfStrategy::SphericalCaps, _) => Err("spherical-caps needs distribution ggx".into()),
            (BsdfStrategy::BoundedVndf, _) => Err(
                "bounded VNDF bounds reflections only (its cap leaves out normals a refraction needs)"
                    .into(),
            ),
            (BsdfStrategy::Uniform | BsdfStrategy::Cosine, _) => {
                Err(format!("{strategy} is drawn by the material, not the lobe"))
            }
        }
    }

    fn scattering(&self) -> Scattering {
        Scattering::GlossyReflection
    }

    fn reach(&self) -> Reach {
        Reach {
            transmits: true,
            delta: self.index_matched(),
            chooses: true,
        }
    }

    #[inline]
    fn eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
        // Any sampler: `f` does not depend on it.
        self.eval_pdf_at(RoughSampler::DCos, wo, wi)
            .map_or(Rgb::ZERO, |(f, _)| f)
    }

    #[inline]
    fn sample(&self, sampler: RoughSampler, wo: DVec3, uc: f64, u: DVec2) -> Option<DVec3> {
        if self.index_matched() {
            return Some(-wo);
        }
        // Kulla-Conty: u.x first chooses the added lobes (probability q),
        // whose own choice of side takes uc.
        let u = match &self.multiscatter {
            DielectricMultiscatter::KullaConty(kc) => {
                match compensation::choose(u, Self::added_probability(kc, wo)) {
                    Ok(u) => return kc.sample(wo, uc, u),
                    Err(u) => u,
                }
            }
            _ => u,
        };
        let m = self.sample_m(sampler, wo, u)?;
        let cos_om = wo.dot(m);
        // `brdf` draws normals that `wo` may see from behind.
        if cos_om * wo.z <= 0.0 {
            return None;
        }
        let fr = fresnel_dielectric(cos_om, self.eta).r;
        let wi = if uc < fr {
            let wi = 2.0 * cos_om * m - wo;
            (wi.z * wo.z > 0.0).then_some(wi)?
        } else {
            let wi = refract_about(wo, m, self.eta)?;
            (wi.z * wo.z < 0.0).then_some(wi)?
        };
        Some(wi.normalize())
    }

    #[inline]
    fn pdf(&self, sampler: RoughSampler, wo: DVec3, wi: DVec3) -> f64 {
        self.eval_pdf_at(sampler, wo, wi).map_or(0.0, |(_, p)| p)
    }

    #[inline]
    fn eval_pdf(&self, sampler: RoughSampler, wo: DVec3, wi: DVec3) -> (Rgb, f64) {
        self.eval_pdf_at(sampler, wo, wi).unwrap_or((Rgb::ZERO, 0.0))
    }

    #[inline]
    fn sample_eval(&self, sampler: RoughSampler, wo: DVec3, uc: f64, u: DVec2) -> Option<LobeSample> {
        if self.index_matched() {
            let c = wo.z.abs();
            return Some(LobeSample {
                wi: -wo,
                f: self.specular_transmittance * (refraction_scale(self.mode, 1.0) / c),
                pdf: 1.0,
                scattering: Scattering::SpecularTransmission,
            });
        }
        let wi = self.sample(sampler, wo, uc, u)?;
        let (f, pdf) = self.eval_pdf_at(sampler, wo, wi)?;
        let scattering = if wi.z * wo.z > 0.0 {
            Scattering::GlossyReflection
        } else {
            Scattering::GlossyTransmission
        };
        Some(LobeSample { wi, f, pdf, scattering })
    }

    /// Index-matched, the straight pass; otherwise none.
    fn deltas(&self, wo: DVec3) -> Deltas {
        if !self.index_matched() {
            return Deltas::NONE;
        }
        Deltas::new(
            Some(Delta {
                wi: -wo,
                value: self.specular_transmittance,
                scattering: Scattering::SpecularTransmission,
            }),
            None,
        )
    }

    fn albedo_hint(&self, _wo: DVec3) -> f64 {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::super::conductor::mirror;
    use super::*;

    fn glass(ndf: Ndf, alpha: f64, eta: f64) -> RoughDielectric {
        RoughDielectric::new(
            Microfacet::new(ndf, alpha, alpha).unwrap(),
            eta,
            Rgb::ONE,
            Rgb::ONE,
            TransportMode::Radiance,
        )
        .unwrap()
    }

    /// `f(wo, wi)/η_o² = f(wi, wo)/η_i²` for refraction, `f` symmetric for
    /// reflection.
    #[test]
    fn generalized_reciprocity() {
        let g = glass(Ndf::Ggx, 0.3, 1.5);
        let dirs = [
            DVec3::new(0.3, 0.1, 0.9).normalize(),
            DVec3::new(-0.5, 0.2, 0.4).normalize(),
            DVec3::new(0.1, -0.6, -0.7).normalize(),
            DVec3::new(-0.2, 0.3, -0.5).normalize(),
        ];
        for &a in &dirs {
            for &b in &dirs {
                let (fab, fba) = (g.eval(a, b).x, g.eval(b, a).x);
                let eta = |w: DVec3| if w.z > 0.0 { 1.0 } else { 1.5 };
                let (l, r) = (fab / (eta(a) * eta(a)), fba / (eta(b) * eta(b)));
                assert!((l - r).abs() <= 1e-12 * l.abs().max(1e-300), "{a} {b}: {l} vs {r}");
            }
        }
        let _ = mirror(DVec3::Z);
    }

    /// No NaN or infinity anywhere: `wi = −wo`, grazing, the smallest α,
    /// index-matched.
    #[test]
    fn finite_at_the_edges() {
        for (alpha, eta) in [(1e-4, 1.5), (0.5, 1.5), (0.5, 1.0), (0.3, 1.0 / 1.33)] {
            for ndf in [Ndf::Ggx, Ndf::Beckmann] {
                let g = glass(ndf, alpha, eta);
                for wo in [
                    DVec3::Z,
                    -DVec3::Z,
                    DVec3::new(1.0, 0.0, 1e-9).normalize(),
                    DVec3::new(0.6, 0.0, -0.8),
                ] {
                    for wi in [-wo, wo, mirror(wo), DVec3::new(0.0, 1.0, 1e-12).normalize()] {
                        for s in [RoughSampler::DCos, RoughSampler::Visible] {
                            let (f, p) = g.eval_pdf(s, wo, wi);
                            assert!(f.is_finite() && p.is_finite(), "{wo} {wi}: {f} {p}");
                        }
                    }
                    for uc in [0.0, 0.5, 0.999] {
                        if let Some(s) = g.sample_eval(RoughSampler::Visible, wo, uc, DVec2::new(0.3, 0.7)) {
                            assert!(s.f.is_finite() && s.pdf.is_finite() && s.pdf > 0.0, "{s:?}");
                        }
                    }
                }
            }
        }
    }
}
