//! Incident lighting as a function of **world** direction, with light
//! sampling. A light knows nothing of shading frames: the shading-point
//! estimator ([`crate::estimator::ShadingPoint`]) takes directions between
//! its local frame and the world, so the same light serves one shading point
//! (`lobe estimate`) and every hit of the renderer.
//!
//! | light | radiance `L(d)` | light sampling |
//! |---|---|---|
//! | `Constant(c)` | `c` everywhere: the furnace; the estimate is the directional albedo times `c` | uniform sphere, `1/(4π)` |
//! | `Beam { dir, exponent, radiance }` | `radiance · max(0, d·dir)^exponent`: a smooth analytic light toward `dir` | `(k+1)/(2π) max(0, cos)^k` around `dir` |
//! | `Env(map)` | the environment map | ∝ the map's luminance ([`EnvMap::sample`]), or MIS-compensated ([`EnvMap::sample_compensated`]) |
//!
//! Which of a light's two distributions a technique draws from is decided in
//! one place, [`crate::estimator::Strategy::light_distribution`]. Light
//! samples below a shading point's horizon are failed samples (they count,
//! with value 0).

use crate::envmap::EnvMap;
use crate::math::Rgb;
use crate::{Frame, warp};
use glam::{DVec2, DVec3};
use std::sync::Arc;

/// An incident light, in world coordinates.
#[derive(Debug, Clone, PartialEq)]
pub enum Light {
    /// The same radiance from every direction (the furnace).
    Constant(Rgb),
    /// `radiance · max(0, d·dir)^exponent` toward the unit world direction `dir`.
    Beam {
        dir: DVec3,
        exponent: f64,
        radiance: Rgb,
    },
    /// An environment map (world +Y up, Mitsuba's convention).
    Env(Arc<EnvMap>),
}

/// Which density light sampling draws from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LightDistribution {
    /// The light's own density (∝ luminance for a map): for light sampling alone.
    Plain,
    /// For MIS: an environment map's compensated density, ∝
    /// `max(0, lum − mean lum)` (Karlík et al. 2019), which leaves the dim
    /// part to BSDF sampling; the plain density for the other lights.
    Compensated,
}

/// A light sample: a world direction and its solid-angle density.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// Unit world direction toward the light.
    pub dir: DVec3,
    /// Density of `dir` in solid angle.
    pub pdf: f64,
}

impl Light {
    /// Incident radiance from world direction `d` (unit).
    #[inline]
    #[must_use]
    pub fn radiance(&self, d: DVec3) -> Rgb {
        match self {
            Light::Constant(c) => *c,
            Light::Beam {
                dir,
                exponent,
                radiance,
            } => *radiance * d.dot(*dir).max(0.0).powf(*exponent),
            Light::Env(map) => map.eval(d),
        }
    }

    /// Draw a world direction from `dist`. `None` when the light cannot be
    /// sampled (a black map).
    #[inline]
    #[must_use]
    pub fn sample(&self, dist: LightDistribution, u: DVec2) -> Option<LightSample> {
        let (dir, pdf) = match self {
            Light::Constant(_) => (
                warp::square_to_uniform_sphere(u),
                warp::square_to_uniform_sphere_pdf(DVec3::Z),
            ),
            Light::Beam { dir, exponent, .. } => {
                let w = Frame::from_normal(*dir).to_world(warp::square_to_cos_power(u, *exponent));
                let p = self.pdf(dist, w);
                if p <= 0.0 {
                    return None;
                }
                (w, p)
            }
            Light::Env(map) => match dist {
                LightDistribution::Plain => map.sample(u)?,
                LightDistribution::Compensated => map.sample_compensated(u)?,
            },
        };
        Some(LightSample { dir, pdf })
    }

    /// Density in solid angle of [`Light::sample`] from `dist` at world
    /// direction `d`.
    #[inline]
    #[must_use]
    pub fn pdf(&self, dist: LightDistribution, d: DVec3) -> f64 {
        match self {
            Light::Constant(_) => warp::square_to_uniform_sphere_pdf(d),
            Light::Beam { dir, exponent, .. } => warp::cos_power_pdf(d.dot(*dir), *exponent),
            Light::Env(map) => match dist {
                LightDistribution::Plain => map.pdf(d),
                LightDistribution::Compensated => map.pdf_compensated(d),
            },
        }
    }
}
