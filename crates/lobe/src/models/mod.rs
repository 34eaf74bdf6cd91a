//! The reflection models, one file each. Each is a *lobe*: a material
//! ([`crate::Material`]) is a Lambertian term plus at most one glossy lobe.

use crate::Strategy;
use crate::math::Rgb;
use glam::{DVec2, DVec3};

pub mod blinn_phong;
pub mod cook_torrance;
pub mod lambert;
pub mod phong;

pub use blinn_phong::BlinnPhong;
pub use cook_torrance::CookTorrance;
pub use lambert::Lambert;
pub use phong::Phong;

/// One lobe of a material, evaluated and sampled by its own strategy
/// (`Strategy::Brdf` and the microfacet strategies). `uniform` and `cosine`
/// are handled by [`crate::Material`] for every model.
///
/// The caller guarantees `wo.z > 0` (and `wi.z > 0` for `eval` and `pdf`).
pub trait Lobe {
    /// `f_r(wo, wi)` of this lobe, without the cosine.
    fn eval(&self, wo: DVec3, wi: DVec3) -> Rgb;
    /// Draw `wi` by the lobe's sampler for `strategy`; `None` for a failed
    /// sample (below the horizon).
    fn sample(&self, strategy: Strategy, wo: DVec3, u: DVec2) -> Option<DVec3>;
    /// Density in solid angle of what `sample` returns.
    fn pdf(&self, strategy: Strategy, wo: DVec3, wi: DVec3) -> f64;
    /// `sample`, and `eval` and `pdf` at the sampled direction, sharing what
    /// they have in common (a model may override it for speed).
    #[inline]
    fn sample_eval(&self, strategy: Strategy, wo: DVec3, u: DVec2) -> Option<(DVec3, Rgb, f64)> {
        let wi = self.sample(strategy, wo, u)?;
        Some((wi, self.eval(wo, wi), self.pdf(strategy, wo, wi)))
    }
    /// `(eval, pdf)` at one `wi`, sharing what they have in common (a model
    /// may override it for speed; the numbers must be the same as the two
    /// calls).
    #[inline]
    fn eval_pdf(&self, strategy: Strategy, wo: DVec3, wi: DVec3) -> (Rgb, f64) {
        (self.eval(wo, wi), self.pdf(strategy, wo, wi))
    }
    /// An estimate of the lobe's directional albedo (luminance), used to
    /// choose between lobes.
    fn albedo_hint(&self, wo: DVec3) -> f64;
    /// `Ok` when the lobe has its own sampler for `strategy`; otherwise why not.
    fn supports(&self, strategy: Strategy) -> Result<(), String>;
}

/// Check an RGB parameter: every channel finite and in `[0, max]`.
pub(crate) fn check_rgb(field: &str, c: Rgb, max: f64) -> crate::error::Result<Rgb> {
    for v in c.to_array() {
        if !v.is_finite() || v < 0.0 || v > max {
            return Err(crate::Error::param(
                field,
                format!("{v} is out of range: each channel must be a number in [0, {max}]"),
            ));
        }
    }
    Ok(c)
}

/// Largest accepted Phong and Blinn-Phong exponent.
pub const MAX_EXPONENT: f64 = 1e7;

pub(crate) fn check_exponent(n: f64) -> crate::error::Result<f64> {
    if !n.is_finite() || !(0.0..=MAX_EXPONENT).contains(&n) {
        return Err(crate::Error::param(
            "exponent",
            format!("{n} is out of range: the exponent must be a number in [0, {MAX_EXPONENT}]"),
        ));
    }
    Ok(n)
}
