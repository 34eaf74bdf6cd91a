//! What to render with: samples per pixel, the technique, the seed, the
//! sample sequence, the path
//! depth and the thread count. A scene file's `[render]` table sets them
//! ([`crate::scene`]); the renderer ([`crate::render()`]) reads them.

use lobe::estimator::Strategy;
use lobe::sequence::Sequence;

/// Render settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderOptions {
    /// Samples (camera rays) per pixel, at least 1.
    pub spp: u64,
    /// How each hit estimates its reflected light: a BSDF strategy (falling
    /// back to `brdf` on a material it does not apply to), `light`, or MIS
    /// on the material's best BSDF strategy.
    pub strategy: Strategy,
    pub seed: u64,
    /// How each pixel's samples are placed in every dimension the
    /// integrator draws ([`lobe::sequence::pair_point`]); Sobol by default.
    pub sequence: Sequence,
    /// 1 = direct lighting; more adds bounces. At least 1.
    pub max_depth: u32,
    /// Threads of a local pool; `None` runs on rayon's current pool.
    pub threads: Option<usize>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            spp: 64,
            strategy: Strategy::MIS,
            seed: 1,
            sequence: Sequence::Sobol,
            max_depth: 1,
            threads: None,
        }
    }
}
