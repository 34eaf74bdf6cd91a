//! Incident lighting at one shading point, in the local frame.
//!
//! | light | radiance `L(wi)` |
//! |---|---|
//! | `Constant(c)` | `c` everywhere: the furnace; the estimate is the directional albedo times `c` |
//! | `Lobe { dir, exponent, radiance }` | `radiance · max(0, wi·dir)^exponent`: a smooth analytic light toward `dir` |

use crate::math::Rgb;
use glam::DVec3;

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Light {
    Constant(Rgb),
    Lobe {
        dir: DVec3,
        exponent: f64,
        radiance: Rgb,
    },
}

impl Light {
    /// Incident radiance from direction `wi` (local frame, unit).
    #[inline]
    #[must_use]
    pub fn radiance(&self, wi: DVec3) -> Rgb {
        match *self {
            Light::Constant(c) => c,
            Light::Lobe {
                dir,
                exponent,
                radiance,
            } => radiance * wi.dot(dir).max(0.0).powf(exponent),
        }
    }
}
