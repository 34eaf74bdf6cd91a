//! Monte Carlo estimation of reflected radiance
//! `L_o(wo) = ∫ f_r(wo, wi) L_i(wi) cos θi dωi` with a chosen strategy, and
//! its deterministic quadrature reference.
//!
//! The `N` samples are cut into chunks of [`CHUNK`] samples; chunk `k` draws
//! its random numbers from its own stream, so the result depends only on the
//! seed, never on how many threads ran the chunks, as long as chunks are
//! merged in order ([`Accumulator::merge`]).

use crate::light::Light;
use crate::math::{Rgb, luminance};
use crate::sequence::{self, Sequence};
use crate::stats::quadrature::{Tolerance, integrate_hemisphere};
use crate::stats::ttest::Moments;
use crate::{Material, Strategy};
use glam::{DVec2, DVec3};
use rand_pcg::Pcg64;

/// Samples per chunk: the unit of work and of random streams.
pub const CHUNK: usize = 4096;

/// Running sums of the sample values `f L cos / p` (zero for a failed sample).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Accumulator {
    /// Sum of the RGB sample values.
    pub sum: Rgb,
    /// Sum of squares per channel (for per-channel standard errors).
    pub sum_sq: Rgb,
    /// Moments of the luminance of the sample values.
    pub lum: Moments,
}

impl Accumulator {
    #[inline]
    pub fn push(&mut self, v: Rgb) {
        self.sum += v;
        self.sum_sq += v * v;
        self.lum.push(luminance(v));
    }

    pub fn merge(&mut self, o: &Accumulator) {
        self.sum += o.sum;
        self.sum_sq += o.sum_sq;
        self.lum.merge(&o.lum);
    }

    #[must_use]
    pub fn count(&self) -> usize {
        self.lum.count()
    }

    #[must_use]
    pub fn mean(&self) -> Rgb {
        self.sum / self.count().max(1) as f64
    }

    /// Standard error of the mean, per channel.
    #[must_use]
    pub fn std_error(&self) -> Rgb {
        let n = self.count() as f64;
        if n < 2.0 {
            return Rgb::ZERO;
        }
        let m = self.mean();
        let var = ((self.sum_sq - n * m * m) / (n - 1.0)).max(Rgb::ZERO);
        (var / n).powf(0.5)
    }
}

/// The random stream of chunk `chunk` for `seed`.
#[must_use]
pub fn chunk_rng(seed: u64, chunk: usize) -> Pcg64 {
    // Distinct PCG streams per chunk (the increment selects the stream).
    Pcg64::new(
        0xcafe_f00d_d15e_a5e5u128 ^ (u128::from(seed) << 64),
        0x0a02_bdbf_7bb3_c0a7_ac28_fa16_a64a_bf96u128 ^ (chunk as u128),
    )
}

/// One sample value `f(wo, wi) L(wi) cos θi / p(wi)`, zero for a failed sample.
#[inline]
#[must_use]
pub fn sample_value(m: &Material, s: Strategy, wo: DVec3, light: &Light, uc: f64, u: DVec2) -> Rgb {
    match m.sample(s, wo, uc, u) {
        Some(x) => x.weight * light.radiance(x.wi),
        None => Rgb::ZERO,
    }
}

/// What one estimate is: a strategy, a sequence, a sample count and a seed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plan {
    pub strategy: Strategy,
    pub sequence: Sequence,
    pub samples: usize,
    pub seed: u64,
}

impl Plan {
    /// `samples` independent samples with `seed`.
    #[must_use]
    pub fn independent(strategy: Strategy, samples: usize, seed: u64) -> Self {
        Plan {
            strategy,
            sequence: Sequence::Independent,
            samples,
            seed,
        }
    }

    /// Number of chunks of [`CHUNK`] samples.
    #[must_use]
    pub fn chunks(&self) -> usize {
        self.samples.div_ceil(CHUNK)
    }
}

/// Estimate chunk by chunk, in order, on this thread. A caller with threads
/// runs [`estimate_chunk`] for every chunk and merges them in chunk order,
/// which gives the same numbers.
#[must_use]
pub fn estimate(m: &Material, wo: DVec3, light: &Light, plan: &Plan) -> Accumulator {
    let mut acc = Accumulator::default();
    for chunk in 0..plan.chunks() {
        acc.merge(&estimate_chunk(m, wo, light, plan, chunk));
    }
    acc
}

/// The samples of chunk `chunk` of an estimate.
#[must_use]
pub fn estimate_chunk(
    m: &Material,
    wo: DVec3,
    light: &Light,
    plan: &Plan,
    chunk: usize,
) -> Accumulator {
    let first = chunk * CHUNK;
    let len = CHUNK.min(plan.samples.saturating_sub(first));
    let mut points = [[0.0; 3]; CHUNK];
    let points = &mut points[..len];
    sequence::fill(plan.sequence, plan.seed, plan.samples, chunk, first, points);
    let mut acc = Accumulator::default();
    for p in points.iter() {
        acc.push(sample_value(
            m,
            plan.strategy,
            wo,
            light,
            p[0],
            DVec2::new(p[1], p[2]),
        ));
    }
    acc
}

/// The reflected radiance by deterministic adaptive quadrature (f64), to
/// about `rel` relative accuracy, per channel.
#[must_use]
pub fn reference(m: &Material, wo: DVec3, light: &Light, rel: f64) -> Rgb {
    let channel = |c: usize| {
        integrate_hemisphere(
            |wi| (m.eval(wo, wi) * light.radiance(wi))[c] * wi.z,
            Tolerance::relative(rel),
        )
        .value
    };
    Rgb::new(channel(0), channel(1), channel(2))
}
