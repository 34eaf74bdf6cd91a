//! Cook-Torrance microfacet reflection.
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `ks` | RGB in [0, 1] | 1 | specular tint, multiplies `F` |
//! | `distribution` | `ggx`, `beckmann`, `blinn-phong` | `ggx` | the NDF `D` |
//! | `alpha` or `alpha_u`, `alpha_v` | [1e-4, 2] (`blinn-phong`: [1e-4, 1]) | 0.3 | widths; `roughness` `r` gives `alpha = r²` |
//! | `shadowing` | `smith-separable`, `smith-correlated`, `v-cavity` | `smith-correlated` | the term `G` |
//! | `fresnel` | `none`, `schlick`, `dielectric`, `conductor` | `none` | the term `F`, see [`crate::Fresnel`] |
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

use super::Lobe;
use crate::math::{Rgb, luminance, reflect};
use crate::microfacet::{Microfacet, Ndf, Shadowing};
use crate::{Fresnel, Strategy};
use glam::{DVec2, DVec3};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CookTorrance {
    pub ks: Rgb,
    pub microfacet: Microfacet,
    pub shadowing: Shadowing,
    pub fresnel: Fresnel,
}

impl CookTorrance {
    pub fn new(
        ks: Rgb,
        microfacet: Microfacet,
        shadowing: Shadowing,
        fresnel: Fresnel,
    ) -> crate::error::Result<Self> {
        Ok(CookTorrance {
            ks: super::check_rgb("ks", ks, 1.0)?,
            microfacet,
            shadowing,
            fresnel,
        })
    }
}

impl CookTorrance {
    /// Draw the microfacet normal by `strategy` and reflect: `(wi, wm)`.
    #[inline]
    fn sample_wm(&self, strategy: Strategy, wo: DVec3, u: DVec2) -> Option<(DVec3, DVec3)> {
        let mf = &self.microfacet;
        let wm = match strategy {
            Strategy::Vndf => mf.sample_visible(wo, u)?,
            Strategy::SphericalCaps => mf.sample_visible_caps(wo, u),
            Strategy::BoundedVndf => mf.sample_visible_bounded(wo, u),
            _ => mf.sample_wm(u),
        };
        if wo.dot(wm) <= 0.0 {
            return None;
        }
        // Reflecting a unit vector about a unit vector keeps it unit to an ulp or two.
        let wi = reflect(wo, wm);
        (wi.z > 0.0).then_some((wi, wm))
    }
}

impl Lobe for CookTorrance {
    #[inline]
    fn eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
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

    #[inline]
    fn sample(&self, strategy: Strategy, wo: DVec3, u: DVec2) -> Option<DVec3> {
        self.sample_wm(strategy, wo, u).map(|(wi, _)| wi)
    }

    /// The sampled `wm` is the half vector of `wo` and the reflected `wi`,
    /// so `D(wm)` and `Λ(wo)` serve `f` and the pdf at once.
    #[inline]
    fn sample_eval(&self, strategy: Strategy, wo: DVec3, u: DVec2) -> Option<(DVec3, Rgb, f64)> {
        let (wi, wm) = self.sample_wm(strategy, wo, u)?;
        let mf = &self.microfacet;
        let cos_oh = wo.dot(wm);
        let d = mf.d(wm);
        let lo = mf.lambda(wo);
        let g = match self.shadowing {
            Shadowing::SmithCorrelated => 1.0 / (1.0 + lo + mf.lambda(wi)),
            Shadowing::SmithSeparable => mf.g1(wi) / (1.0 + lo),
            Shadowing::VCavity => mf.g(Shadowing::VCavity, wo, wi, wm),
        };
        let inv4o = 0.25 / wo.z;
        let dg = d * g * inv4o / wi.z;
        let pdf = match strategy {
            Strategy::Vndf | Strategy::SphericalCaps => d * inv4o / (1.0 + lo),
            Strategy::BoundedVndf => mf.pdf_reflect_bounded(wo, wi),
            _ => mf.pdf_wm(wm) * 0.25 / cos_oh,
        };
        if !(dg.is_finite() && pdf.is_finite()) {
            return None;
        }
        Some((wi, self.ks * self.fresnel.eval(cos_oh) * dg, pdf))
    }

    #[inline]
    fn pdf(&self, strategy: Strategy, wo: DVec3, wi: DVec3) -> f64 {
        let mf = &self.microfacet;
        if strategy == Strategy::BoundedVndf {
            return mf.pdf_reflect_bounded(wo, wi);
        }
        let Some(h) = (wo + wi).try_normalize() else {
            return 0.0;
        };
        let cos_oh = wo.dot(h);
        if cos_oh <= 0.0 {
            return 0.0;
        }
        let p = match strategy {
            // pdf_visible / (4 wo·h) simplifies to G1(wo) D(h) / (4 cos θo).
            Strategy::Vndf | Strategy::SphericalCaps => mf.g1(wo) * mf.d(h) / (4.0 * wo.z),
            _ => mf.pdf_wm(h) / (4.0 * cos_oh),
        };
        if p.is_finite() { p } else { 0.0 }
    }

    fn albedo_hint(&self, wo: DVec3) -> f64 {
        luminance(self.ks * self.fresnel.eval(wo.z))
    }

    fn supports(&self, strategy: Strategy) -> Result<(), String> {
        let ndf = self.microfacet.ndf();
        match strategy {
            Strategy::Uniform | Strategy::Cosine | Strategy::Brdf => Ok(()),
            Strategy::Vndf if ndf != Ndf::BlinnPhong => Ok(()),
            Strategy::Vndf => {
                Err("visible-normal sampling needs distribution ggx or beckmann".into())
            }
            Strategy::SphericalCaps | Strategy::BoundedVndf if ndf == Ndf::Ggx => Ok(()),
            _ => Err(format!("{strategy} needs distribution ggx")),
        }
    }
}
