//! The result of sampling a material.

use crate::math::Rgb;
use glam::DVec3;

/// Which part of the material drew the direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Component {
    /// The Lambertian term, by cosine sampling.
    Diffuse,
    /// The glossy (specular) lobe, by the strategy's own sampler.
    Glossy,
    /// A strategy that ignores the material (`uniform`, `cosine`).
    Hemisphere,
}

/// One sampled direction, after pbrt-v4's `BSDFSample`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    /// The sampled direction toward the light, unit, `z > 0`.
    pub wi: DVec3,
    /// `f_r(wo, wi)`, without the cosine.
    pub f: Rgb,
    /// Density of `wi` in solid angle: equal to `Material::pdf` for the same
    /// strategy (for a mixture, the mixture density).
    pub pdf: f64,
    /// `f · cos θi / pdf`, the Monte Carlo weight (cosine included).
    pub weight: Rgb,
    /// The lobe that was chosen.
    pub component: Component,
}
