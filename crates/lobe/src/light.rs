//! Incident lighting at one shading point, in the local frame, with light
//! sampling.
//!
//! | light | radiance `L(wi)` | light sampling |
//! |---|---|---|
//! | `Constant(c)` | `c` everywhere: the furnace; the estimate is the directional albedo times `c` | uniform sphere, `1/(4π)` |
//! | `Lobe { dir, exponent, radiance }` | `radiance · max(0, wi·dir)^exponent`: a smooth analytic light toward `dir` | `(k+1)/(2π) max(0, cos)^k` around `dir` |
//! | `Env { map, frame }` | the environment map seen through the shading frame | ∝ the map's luminance ([`EnvMap::sample`]) |
//!
//! Light samples below the horizon are failed samples (they count, with value 0).

use crate::envmap::EnvMap;
use crate::math::Rgb;
use crate::{Frame, warp};
use glam::{DVec2, DVec3};
use std::sync::Arc;

#[derive(Debug, Clone, PartialEq)]
pub enum Light {
    Constant(Rgb),
    Lobe {
        dir: DVec3,
        exponent: f64,
        radiance: Rgb,
    },
    /// An environment map; `frame` is the shading frame (local ↔ world).
    Env {
        map: Arc<EnvMap>,
        frame: Frame,
    },
}

impl Light {
    /// Incident radiance from direction `wi` (local frame, unit).
    #[inline]
    #[must_use]
    pub fn radiance(&self, wi: DVec3) -> Rgb {
        match self {
            Light::Constant(c) => *c,
            Light::Lobe {
                dir,
                exponent,
                radiance,
            } => *radiance * wi.dot(*dir).max(0.0).powf(*exponent),
            Light::Env { map, frame } => map.eval(frame.to_world(wi)),
        }
    }

    /// Draw a direction (local frame) by light sampling: `(wi, pdf)`.
    /// `None` when the light cannot be sampled (a black map).
    #[inline]
    #[must_use]
    pub fn sample(&self, u: DVec2) -> Option<(DVec3, f64)> {
        match self {
            Light::Constant(_) => Some((
                warp::square_to_uniform_sphere(u),
                warp::square_to_uniform_sphere_pdf(DVec3::Z),
            )),
            Light::Lobe { dir, exponent, .. } => {
                let w = Frame::from_normal(*dir).to_world(warp::square_to_cos_power(u, *exponent));
                let p = self.pdf(w);
                (p > 0.0).then_some((w, p))
            }
            Light::Env { map, frame } => map.sample(u).map(|(d, p)| (frame.to_local(d), p)),
        }
    }

    /// The light sampler MIS uses: for an environment map, MIS compensation
    /// ([`EnvMap::sample_compensated`]); otherwise [`Light::sample`].
    #[inline]
    #[must_use]
    pub fn sample_mis(&self, u: DVec2) -> Option<(DVec3, f64)> {
        match self {
            Light::Env { map, frame } => map
                .sample_compensated(u)
                .map(|(d, p)| (frame.to_local(d), p)),
            _ => self.sample(u),
        }
    }

    /// Density of [`Light::sample_mis`] at `wi` (local frame).
    #[inline]
    #[must_use]
    pub fn pdf_mis(&self, wi: DVec3) -> f64 {
        match self {
            Light::Env { map, frame } => map.pdf_compensated(frame.to_world(wi)),
            _ => self.pdf(wi),
        }
    }

    /// Density in solid angle of [`Light::sample`] at `wi` (local frame).
    #[inline]
    #[must_use]
    pub fn pdf(&self, wi: DVec3) -> f64 {
        match self {
            Light::Constant(_) => warp::square_to_uniform_sphere_pdf(wi),
            Light::Lobe { dir, exponent, .. } => warp::cos_power_pdf(wi.dot(*dir), *exponent),
            Light::Env { map, frame } => map.pdf(frame.to_world(wi)),
        }
    }
}
