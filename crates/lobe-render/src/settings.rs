//! What to render with: samples per pixel, the strategy, the seed, the
//! sample sequence, the path
//! depth and the thread count. A scene file's `[render]` table sets them
//! ([`crate::scene`]); the renderer ([`crate::render()`]) reads them.

use lobe::estimator::Strategy;
use lobe::sequence::Sequence;

/// Render settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderSettings {
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
    /// Threads to render on: rayon's current pool when it has that many,
    /// else a local pool of that many; `None` runs on rayon's current pool.
    pub threads: Option<usize>,
    /// The batch loop (the default) or the scalar one, its reference.
    pub render_loop: RenderLoop,
    /// How the samples are shared out among the pixels: as a pilot's
    /// estimate of each pixel's noise says ([`SppAllocation::Variance`], the
    /// default) or `spp` each (uniform).
    pub spp_allocation: SppAllocation,
}

/// How a render shares its `width × height × spp` samples out among the
/// pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum SppAllocation {
    /// `spp` samples in every pixel.
    Uniform,
    /// In proportion to each pixel's standard deviation as a pilot
    /// estimates it (extra samples of their own randomization, not in the
    /// image), with a floor of `spp / 16` (at least 1) per pixel: the
    /// allocation that minimizes the image's mean squared error for a
    /// given number of samples when each pixel's error is `σ / √n`. The
    /// same total (`width × height × spp`) as `Uniform`; unbiased, since
    /// the image's samples do not decide their own counts
    /// ([`crate::integrator::spp_counts`]). The default.
    #[default]
    Variance,
}

impl SppAllocation {
    pub const ALL: [SppAllocation; 2] = [SppAllocation::Uniform, SppAllocation::Variance];

    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            SppAllocation::Uniform => "uniform",
            SppAllocation::Variance => "variance",
        }
    }
}

impl std::fmt::Display for SppAllocation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for SppAllocation {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        SppAllocation::ALL
            .into_iter()
            .find(|a| a.name() == s)
            .ok_or_else(|| {
                format!("unknown spp allocation `{s}`, expected one of: uniform, variance")
            })
    }
}

/// Which loop renders: the batch (wavefront) loop on `lobe::batch`'s f32
/// SIMD kernels where it covers the scene and the strategy
/// ([`crate::integrator::batch_refusal`] says why not; the scalar loop
/// renders it then), or the scalar f64 loop, the reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum RenderLoop {
    #[default]
    Batch,
    Scalar,
}

impl RenderLoop {
    pub const ALL: [RenderLoop; 2] = [RenderLoop::Batch, RenderLoop::Scalar];

    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            RenderLoop::Batch => "batch",
            RenderLoop::Scalar => "scalar",
        }
    }
}

impl std::fmt::Display for RenderLoop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for RenderLoop {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        RenderLoop::ALL
            .into_iter()
            .find(|l| l.name() == s)
            .ok_or_else(|| format!("unknown loop `{s}`, expected one of: batch, scalar"))
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            spp: 64,
            strategy: Strategy::MIS,
            seed: 1,
            sequence: Sequence::Sobol,
            max_depth: 1,
            threads: None,
            render_loop: RenderLoop::Batch,
            spp_allocation: SppAllocation::Variance,
        }
    }
}
