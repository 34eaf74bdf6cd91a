//! The integrator: direct lighting from the environment map by BSDF
//! sampling, light sampling or MIS, exactly as `lobe`'s estimator combines
//! them, and (with `max_depth > 1`) path tracing with next-event estimation.
//!
//! # One shading point
//!
//! At a camera ray's hit, with `wo` toward the camera in the shading frame
//! (`Frame::from_normal(n)`, `n` turned toward the ray), the reflected
//! radiance `L_o = ∫ f L cos dω` is estimated by one of:
//!
//! * **BSDF sampling** with a strategy `s`: draw `wi ~ p_s`, trace a ray;
//!   if it escapes, `f L cos / p_s`, else 0 (the environment is the only
//!   light). A failed sample (below the horizon) counts as 0.
//! * **Light sampling** ([`lobe::envmap::EnvMap::sample`]): draw a world direction with
//!   density ∝ the map's luminance, take it to the local frame; below the
//!   horizon it is a failed sample; otherwise a shadow ray, and
//!   `f L cos / p_light` when it escapes.
//! * **MIS** (Veach's multi-sample form with one sample per strategy):
//!   both of the above, each weighted by the balance heuristic
//!   `p_t / (p_b + p_l)` (`mis-balance`) or the power heuristic
//!   `p_t² / (p_b² + p_l²)` (`mis-power`), where the BSDF strategy is
//!   `vndf` when the material has it, else `brdf`, and the light strategy
//!   draws from the MIS-compensated distribution
//!   ([`lobe::envmap::EnvMap::sample_compensated`], density ∝ `max(0, lum − mean)`), as
//!   `lobe`'s estimator does ([`lobe::Light::sample`] with [`lobe::light::LightDistribution::Compensated`]).
//!
//! * **Adaptive MIS** (`mis`, the default): the same two draws per sample,
//!   given at the first bounce to BSDF sampling, the balance heuristic or
//!   light sampling as a pilot says is best for the pixel
//!   ([`lobe::estimator::Pilot`]): before pass 0, [`pilot_spp`] extra
//!   samples per pixel of their own randomization (not in the image) record
//!   the balance heuristic's draws; each pixel takes the allocation of
//!   least estimated variance over the pilots of the 7 × 7 pixels around it
//!   ([`PILOT_RADIUS`]). Every pass uses the same allocations. Deeper
//!   bounces use the balance heuristic.
//!
//! This is [`lobe::estimator::ShadingEstimator::estimate`] with shadow rays.
//!
//! **Strategy fallback:** a BSDF strategy that does not apply to an
//! object's material (`vndf` on a Phong sphere, `spherical-caps` on a
//! Lambertian plane, ...) is replaced by `brdf` for that object, which
//! applies to every material; [`fallbacks`] lists where this happens.
//!
//! # Paths (`max_depth > 1`)
//!
//! At every vertex, the same strategy: light sampling adds next-event
//! estimation (MIS-weighted under `mis`/`mis-power`, unweighted under
//! `light`), and the path goes on by BSDF sampling; a BSDF-sampled ray that
//! escapes adds the environment, MIS-weighted under `mis`, in full under a
//! BSDF strategy, and not at all under `light` (whose direct light comes
//! from the light samples alone). The continuation strategy is the
//! object's BSDF strategy (for `light`: `vndf` where the material has it,
//! else `brdf`). Russian roulette starts after the third bounce. With
//! `max_depth = 1` this is the single-bounce estimator above.
//!
//! # Samples and determinism
//!
//! Every number a sample uses comes from [`lobe::sequence::pair_point`] in
//! its own dimension pair ([`dims`]): the position in the pixel, then per
//! bounce the BSDF sample's direction and lobe choice, the light sample
//! (multi-sample MIS gives each strategy its own dimensions), the
//! continuation's direction and lobe choice, and Russian roulette. The
//! pattern ([`RenderSettings::sequence`]) is `sobol` (Owen-scrambled,
//! padded per pair) by default, or `stratified`, or `independent`. Pixel
//! `(x, y)` has its own randomization, seeded from `(seed, y · width + x)`,
//! so the image is the same bit for bit for any thread count and any order
//! of the rows.
//!
//! # Passes
//!
//! [`render_pass`] renders pass `p` of `spp` samples per pixel: Sobol and
//! independent samples `p·spp … (p+1)·spp − 1` of the pixel's sequence, a
//! fresh stratification for `stratified`. [`render_progressive`] averages
//! whole passes until a time budget is spent; its image depends only on the
//! number of passes.
//!
//! # Samples per pixel
//!
//! With [`SppAllocation::Uniform`] every pixel gets `spp` samples per pass.
//! With [`SppAllocation::Variance`] (the default) a pilot (before pass
//! 0: [`pilot_spp`] samples per pixel, at least 2, of their own
//! randomization, not in the image; adaptive MIS's pilot when the strategy
//! is `mis`) estimates
//! each pixel's variance, pooled over the 5 × 5 pixels around it, and
//! [`spp_counts`] shares the pass's `width × height × spp` samples out in
//! proportion to the standard deviations, at least `spp / 16` (and 1) per
//! pixel and at most [`MAX_SPP_FACTOR`] × `spp`. Pixel `(x, y)` then takes
//! samples `p·n … (p+1)·n − 1` of its sequence in pass `p`, `n` its count,
//! and its value is their mean: unbiased, because the counts come from
//! samples apart from the image's. Every pass uses the same counts.
//!
//! # Batch loop
//!
//! [`RenderSettings::render_loop`] is [`RenderLoop::Batch`] by default: for
//! direct lighting (`max_depth = 1`) with a BSDF strategy, `light`, or MIS
//! with one BSDF and one light draw (`mis`, `mis-balance`, `mis-power`),
//! each row is rendered in blocks of [`BLOCK`] samples (consecutive samples
//! of consecutive pixels), the whole row at the block's SIMD level: the
//! camera rays and their hits (f64 lanes, [`crate::ray_block`], testing only
//! the spheres whose film box ([`crate::camera::Camera::film_bounds`]) the
//! block's pixels overlap; the escaping rays' radiance from
//! [`lobe::envmap::EnvMap::eval_many`]), then every BSDF draw of the block in one
//! [`lobe::batch::BatchSampler::sample`] call per object and every light
//! draw's `f` and BSDF pdf in one [`lobe::batch::BatchSampler::eval_pdf`]
//! call per object (f32 lanes, structure of arrays, AVX-512 / AVX2 /
//! portable as [`lobe::batch::SimdLevel::from_env`] says), the light draws
//! from [`lobe::envmap::EnvMap::sample_lookup`] (guide-table CDF inversion,
//! a binary search only inside one interval of the guide, with the drawn
//! texel's radiance and pdfs), each BSDF
//! direction's radiance and pdfs from one [`lobe::envmap::EnvMap::lookup`],
//! then the block's shadow rays (f64 lanes). It draws the same numbers from the same
//! dimensions as the scalar loop and weights them the same way, so the two
//! loops estimate the same image and, for one seed, agree to f32 rounding
//! (the test `batch_loop_matches_the_scalar_loop`). Adaptive MIS's pilot
//! runs on the batch loop too (its draws recorded with
//! [`lobe::estimator::Pilot::record`]), except under `--loop scalar`. The
//! block's Sobol pairs come from [`lobe::sequence::sobol_pairs`] (SIMD
//! lanes, the camera pair for every sample, the others for the samples
//! that hit), its light draws from [`lobe::envmap::EnvMap::sample_lookup_many`]
//! and its BSDF directions' map lookups from
//! [`lobe::envmap::EnvMap::lookup_many`] (the reads of a block overlap).
//! Where the batch loop does not apply (bounces, one-sample MIS, a
//! material the batch kernels refuse: none today), the scalar loop renders
//! the whole image and [`batch_refusal`] says why
//! (`lobe render` prints it once);
//! [`RenderLoop::Scalar`] forces the scalar loop. Both give the same bits
//! for any thread count.

use crate::geometry::{Hit, spawn_ray};
use crate::scene::Scene;
pub use crate::settings::{RenderLoop, RenderSettings, SppAllocation};
use glam::{DVec2, DVec3};
use lobe::estimator::{
    Allocation, BsdfDraw, DrawnBsdf, Mis, MisForm, Pilot, ShadingEstimator, ShadingPoint, Strategy,
    Visibility,
};
use lobe::light::Light;
use lobe::math::{Rgb, luminance};
use lobe::sequence::{Sequence, hash64, pair_point};
use lobe::{BsdfSampler, BsdfStrategy, Frame, Material};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

mod wavefront;
pub use wavefront::{BLOCK, batch_refusal};

/// The dimension pairs of one sample ([`lobe::sequence::pair_point`]).
pub mod dims {
    /// The position in the pixel.
    pub const CAMERA: u32 = 0;
    /// Pairs per bounce.
    pub const PER_BOUNCE: u32 = 6;
    /// The BSDF sample's direction `u` at bounce `b` (from 0).
    #[must_use]
    pub const fn bsdf_u(b: u32) -> u32 {
        1 + PER_BOUNCE * b
    }
    /// The BSDF sample's lobe choice `uc` (first coordinate; the second is
    /// the light point's, used when adaptive MIS gives it to BSDF sampling).
    #[must_use]
    pub const fn bsdf_uc(b: u32) -> u32 {
        2 + PER_BOUNCE * b
    }
    /// The light sample.
    #[must_use]
    pub const fn light(b: u32) -> u32 {
        3 + PER_BOUNCE * b
    }
    /// The continuation's direction, when the estimate drew no BSDF sample.
    #[must_use]
    pub const fn next_u(b: u32) -> u32 {
        4 + PER_BOUNCE * b
    }
    /// The continuation's lobe choice (first coordinate).
    #[must_use]
    pub const fn next_uc(b: u32) -> u32 {
        5 + PER_BOUNCE * b
    }
    /// Russian roulette (first coordinate).
    #[must_use]
    pub const fn roulette(b: u32) -> u32 {
        6 + PER_BOUNCE * b
    }
}

/// The first bounce of a pixel's samples under adaptive MIS.
#[derive(Debug, Clone, Copy, PartialEq)]
enum FirstBounce {
    /// As the estimator is (every strategy but adaptive MIS; adaptive MIS
    /// at the balance heuristic).
    Plain,
    /// Adaptive MIS's pilot: the balance heuristic, recorded.
    Pilot,
    /// Adaptive MIS with the pixel's allocation.
    Allocated(Allocation),
}

/// One sample of one pixel: where its numbers come from.
#[derive(Debug, Clone, Copy)]
struct PixelSample {
    sequence: Sequence,
    seed: u64,
    n: u64,
    index: u64,
}

impl PixelSample {
    fn pair(&self, dim: u32) -> DVec2 {
        DVec2::from_array(pair_point(
            self.sequence,
            self.seed,
            self.n,
            self.index,
            dim,
        ))
    }

    fn one(&self, dim: u32) -> f64 {
        self.pair(dim).x
    }
}

/// Counters of one render.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RenderStats {
    /// Camera rays (= pixels × spp).
    pub camera_rays: u64,
    /// Every ray traced: camera, shadow and BSDF rays.
    pub rays: u64,
    /// Path samples whose value was not finite, counted as zero (should
    /// stay 0; a non-zero count is a bug worth reporting).
    pub nonfinite: u64,
    /// Whole passes of `spp` samples per pixel (1 for [`render`]).
    pub passes: u64,
}

/// A linear RGB image, row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    /// Row-major, `pixels[y * width + x]`.
    pub pixels: Vec<Rgb>,
    pub stats: RenderStats,
    /// Under [`SppAllocation::Variance`], each pixel's samples per pass
    /// (row-major; [`spp_counts`]); `None` when every pixel took `spp`.
    pub spp: Option<Vec<u64>>,
}

impl Image {
    /// A black image.
    #[must_use]
    pub fn new(width: usize, height: usize) -> Self {
        Image {
            width,
            height,
            pixels: vec![Rgb::ZERO; width * height],
            stats: RenderStats::default(),
            spp: None,
        }
    }

    /// The pixel at column `x`, row `y` (row 0 at the top).
    #[must_use]
    pub fn get(&self, x: usize, y: usize) -> Rgb {
        self.pixels[y * self.width + x]
    }
}

/// How one object is shaded: the strategy validated for its material, and
/// the BSDF sampler that continues its paths.
#[derive(Debug, Clone, Copy)]
struct ObjectShading<'m> {
    estimator: ShadingEstimator<'m>,
    /// The strategy's own BSDF sampler, or for `light` the material's best.
    continuation: BsdfSampler<'m>,
    /// The material transmits: its frame keeps the surface's own normal,
    /// and a view from below it is a view from inside.
    transmits: bool,
}

/// The strategy `strategy` becomes on material `m`: a BSDF strategy that
/// does not apply falls back to `brdf`, which applies to every material;
/// light sampling on a material with a delta part (a mirror, smooth glass,
/// plastic's coating), which light samples never hit, falls back to the
/// material's best BSDF strategy ([`Material::best_bsdf_strategy`]).
#[must_use]
pub fn strategy_for(strategy: Strategy, m: &Material) -> Strategy {
    match strategy {
        Strategy::Bsdf(s) if m.check(s).is_err() => Strategy::Bsdf(BsdfStrategy::Brdf),
        Strategy::Light if m.reach().delta => Strategy::Bsdf(m.best_bsdf_strategy()),
        t => t,
    }
}

fn object_shading(strategy: Strategy, m: &Material) -> ObjectShading<'_> {
    let estimator = ShadingEstimator::new(strategy_for(strategy, m), m)
        .or_else(|_| ShadingEstimator::new(Strategy::Bsdf(BsdfStrategy::Brdf), m))
        .expect("brdf applies to every material");
    let continuation = estimator.sampler().unwrap_or_else(|| {
        m.sampler(m.best_bsdf_strategy())
            .expect("the best BSDF strategy applies")
    });
    ObjectShading {
        estimator,
        continuation,
        transmits: m.reach().transmits,
    }
}

/// An object whose material does not take the requested strategy.
#[derive(Debug, Clone, PartialEq)]
pub struct Fallback {
    pub object: usize,
    pub model: &'static str,
    pub requested: Strategy,
    pub used: Strategy,
}

/// The objects on which `strategy` falls back to another
/// ([`strategy_for`]).
#[must_use]
pub fn fallbacks(scene: &Scene, strategy: Strategy) -> Vec<Fallback> {
    scene
        .objects
        .iter()
        .enumerate()
        .filter_map(|(i, o)| {
            let used = strategy_for(strategy, &o.material);
            (used != strategy).then(|| Fallback {
                object: i,
                model: o.material.model_name(),
                requested: strategy,
                used,
            })
        })
        .collect()
}

/// The depth below which a transmitting object shows little of what is
/// behind it: a ray goes in, out, and on to the next surface.
pub const SEE_THROUGH_DEPTH: u32 = 3;

/// A note when an object of `scene` transmits (glass) and `max_depth` is
/// below [`SEE_THROUGH_DEPTH`]: such a render is correct for its depth but
/// shows glass dark, and the user likely wants more bounces.
#[must_use]
pub fn shallow_glass(scene: &Scene, max_depth: u32) -> Option<String> {
    if max_depth >= SEE_THROUGH_DEPTH {
        return None;
    }
    let (i, o) = scene
        .objects
        .iter()
        .enumerate()
        .find(|(_, o)| o.material.reach().transmits)?;
    Some(format!(
        "object {i} ({}) transmits, and max_depth {max_depth} ends paths before light passes through it (in, out, on: {SEE_THROUGH_DEPTH} bounces), so it shows dark; give max_depth 8 or more to see through glass",
        o.material.model_name()
    ))
}

/// The largest spp × passes a Sobol render takes (its sample index is 32
/// bits).
pub const SOBOL_MAX_SAMPLES: u64 = 1 << 32;

/// Render `scene` with `opts` (pass 0 of [`render_pass`]). Rows are rendered in parallel (on a local
/// pool of `opts.threads` threads, else on rayon's current pool), each
/// written in place; `progress` is called with the number of samples
/// (camera rays) finished, every few thousand samples of a pixel and at its
/// end (they add up to `width × height × spp`).
#[must_use]
pub fn render(scene: &Scene, opts: &RenderSettings, progress: impl Fn(u64) + Sync) -> Image {
    render_pass(scene, opts, 0, progress)
}

/// Pass `pass` of a progressive render: `opts.spp` more samples per pixel
/// (see the module doc); the mean of passes `0..P` is the image of `P`
/// passes. Sobol takes `(pass + 1) · spp ≤ 2³²` ([`SOBOL_MAX_SAMPLES`]).
#[must_use]
pub fn render_pass(
    scene: &Scene,
    opts: &RenderSettings,
    pass: u64,
    progress: impl Fn(u64) + Sync,
) -> Image {
    on_pool(opts, || {
        if pass > 0 && needs_pilot(opts) {
            // The allocations of later passes come from pass 0's pilot.
            let prior = pilot_phase(scene, opts, &NEVER).expect(NOT_CANCELLED).0;
            render_on_pool(scene, opts, pass, &progress, Some(&prior), &NEVER)
        } else {
            render_on_pool(scene, opts, pass, &progress, None, &NEVER)
        }
        .expect(NOT_CANCELLED)
        .0
    })
}

/// The flag of the renders that cannot be cancelled.
static NEVER: AtomicBool = AtomicBool::new(false);
const NOT_CANCELLED: &str = "a render without a cancellation flag finishes";

/// Whether `s` is adaptive MIS, whose first bounce a per-pixel pilot tunes.
fn is_adaptive(s: Strategy) -> bool {
    matches!(s, Strategy::Mis(m) if m.form == MisForm::Adaptive)
}

/// Whether a render with `opts` starts with a pilot: adaptive MIS, or the
/// variance allocation of samples.
fn needs_pilot(opts: &RenderSettings) -> bool {
    is_adaptive(opts.strategy) || opts.spp_allocation == SppAllocation::Variance
}

/// The most samples per pass one pixel gets under
/// [`SppAllocation::Variance`], as a multiple of `spp`.
pub const MAX_SPP_FACTOR: u64 = 64;

/// The most samples per pass any pixel of a render with `opts` takes:
/// `spp`, or [`MAX_SPP_FACTOR`] × `spp` under the variance allocation (a
/// Sobol render needs it times the pass count ≤ [`SOBOL_MAX_SAMPLES`]).
#[must_use]
pub fn max_pixel_spp(opts: &RenderSettings) -> u64 {
    let spp = opts.spp.max(1);
    match opts.spp_allocation {
        SppAllocation::Uniform => spp,
        SppAllocation::Variance => spp.saturating_mul(MAX_SPP_FACTOR),
    }
}

/// Samples per pixel under [`SppAllocation::Variance`]: `variance[y · w + x]`
/// is an estimate of pixel `(x, y)`'s per-sample variance (negative or not
/// finite counts as 0); each pixel's standard deviation is taken from the
/// mean variance of the 5 × 5 pixels around it ([`VARIANCE_POOL_RADIUS`]),
/// and the `w · h · spp`
/// samples are shared out as `floor + spare · σᵢ / Σσ` (`floor = max(1,
/// spp / 16)` ([`SPP_FLOOR_DIVISOR`]), `spare` the samples above the
/// floors), at most
/// [`MAX_SPP_FACTOR`] × `spp` per pixel (what a capped pixel does not take
/// goes to the others), rounded so that the counts add up to exactly
/// `w · h · spp`. Where every σ is 0 (or their sum overflows), `spp` each.
///
/// # Panics
/// If `variance.len() != w * h`.
#[must_use]
pub fn spp_counts(variance: &[f64], w: usize, h: usize, spp: u64) -> Vec<u64> {
    assert_eq!(variance.len(), w * h, "spp_counts: one variance per pixel");
    let p = w * h;
    let spp = spp.max(1);
    let var = |i: usize| {
        let v = variance[i];
        if v.is_finite() && v > 0.0 { v } else { 0.0 }
    };
    // Pooled over the (2r + 1)² pixels around each one (fewer at the
    // edges): the variances' sum over their count.
    let r = VARIANCE_POOL_RADIUS;
    let span = |c: usize, n: usize| (c + r + 1).min(n) - c.saturating_sub(r);
    let sigma: Vec<f64> = box_pool(
        w,
        h,
        r,
        var,
        |a, b| *a += b,
        |i, s| (s / (span(i % w, w) * span(i / w, h)) as f64).sqrt(),
    );
    let total = p as u64 * spp;
    // (A sum that overflows: uniform too.)
    let s: f64 = sigma.iter().sum();
    if s <= 0.0 || !s.is_finite() {
        return vec![spp; p];
    }
    let floor = (spp / SPP_FLOOR_DIVISOR).max(1);
    let spare = (total - floor * p as u64) as f64;
    let cap = (spp.saturating_mul(MAX_SPP_FACTOR) - floor) as f64;
    // Water-filling: pixels whose share would pass the cap take the cap,
    // the rest share what is left in proportion to σ.
    let mut capped = vec![false; p];
    let mut left = spare;
    let sum = loop {
        let sum = (0..p)
            .filter(|&i| !capped[i])
            .map(|i| sigma[i])
            .sum::<f64>();
        let mut changed = false;
        for i in 0..p {
            if !capped[i] && sum > 0.0 && left * sigma[i] / sum > cap {
                capped[i] = true;
                left -= cap;
                changed = true;
            }
        }
        if !changed {
            break sum;
        }
    };
    let extra = |i: usize| {
        if capped[i] {
            cap
        } else if sum > 0.0 {
            left * sigma[i] / sum
        } else {
            0.0
        }
    };
    // Each pixel's extra samples as differences of the rounded-down running
    // sum, which ends at exactly `spare`.
    let spare = spare as u64;
    let (mut run, mut prev) = (0.0, 0u64);
    (0..p)
        .map(|i| {
            run += extra(i);
            let cur = if i + 1 == p {
                spare
            } else {
                (run.floor() as u64).min(spare)
            };
            let n = floor + cur.saturating_sub(prev);
            prev = prev.max(cur);
            n
        })
        .collect()
}

/// Pilot samples per pixel of adaptive MIS for passes of `spp`: extra
/// samples of their own randomization, drawn once before pass 0 and not
/// part of the image: an eighth of `spp`, at least 1 and at most
/// [`MAX_PILOT_SPP`].
#[must_use]
pub fn pilot_spp(spp: u64) -> u64 {
    (spp / 8).clamp(1, MAX_PILOT_SPP)
}

/// The variance allocation's floor: every pixel gets at least `spp /
/// SPP_FLOOR_DIVISOR` samples (and 1), whatever its pilot saw. With the
/// pilot pooled over 5 × 5 pixels ([`VARIANCE_POOL_RADIUS`]) a floor of
/// `spp / 16` instead of `spp / 8` leaves the shipped scenes' error as it
/// was (relative RMSE at 32 spp, the mean of 3 seeds: `spheres-ground`
/// 2.13% → 2.14%, its 99.9th percentile 13.9% → 13.7%; `spheres` 1.79% →
/// 1.77%) and gives the samples it frees to the noisy pixels:
/// `bench/two_spheres.toml` 1.112% → 1.086% (6 seeds; `spp / 32`: 1.071%).
pub const SPP_FLOOR_DIVISOR: u64 = 16;

/// Half the side of the window of pixels whose pilot variances
/// [`spp_counts`] pools into a pixel's standard deviation (5 × 5 pixels).
/// A pilot of a few samples per pixel rarely sees a pixel's rare bright
/// samples (a sun reflected in a glossy surface); pooled over 25 pixels
/// it sees them often enough. Measured against 3 × 3 (relative RMSE, the
/// mean of 3 to 6 seeds, against 2048-spp renders): `spheres-ground.toml`
/// at 8 spp 6.3% → 5.1% and its 99.9th percentile of the per-pixel error
/// 66% → 30%; at 32 spp 2.3% → 2.1%; `bench/two_spheres.toml` at 32 spp
/// 1.13% → 1.11%; 7 × 7 and wider no better.
pub const VARIANCE_POOL_RADIUS: usize = 2;

/// The most pilot samples per pixel: the allocation of a pixel pools the
/// pilots of 7 × 7 pixels ([`PILOT_RADIUS`]), 392 samples at this cap, which
/// tell three allocations' variances apart well enough; more would only
/// add time (at 256 spp an eighth was 32 per pixel, 12% of the render).
pub const MAX_PILOT_SPP: u64 = 8;

/// Half the side of the window of pixels whose pilots decide a pixel's
/// allocation (7 × 7 pixels).
pub const PILOT_RADIUS: usize = 3;

/// `f` on a pool of `opts.threads` threads: the current pool (rayon's
/// global one outside of any) when it has that many, else a new one.
fn on_pool<T: Send>(opts: &RenderSettings, f: impl FnOnce() -> T + Send) -> T {
    if let Some(n) = opts.threads
        && n != rayon::current_num_threads()
        && let Ok(pool) = rayon::ThreadPoolBuilder::new().num_threads(n).build()
    {
        return pool.install(f);
    }
    f()
}

/// Render whole passes of `opts.spp` samples per pixel until `budget` has
/// passed (at least one pass; never more than `max_passes`), and return
/// their mean, with the pass count in `stats.passes`. The image depends only
/// on the pass count: the same count gives the same bits whatever the
/// thread count or the machine's speed.
#[must_use]
pub fn render_progressive(
    scene: &Scene,
    opts: &RenderSettings,
    budget: Duration,
    max_passes: u64,
    progress: impl Fn(u64) + Sync,
) -> Image {
    render_until(scene, opts, Some(budget), max_passes, &NEVER, progress).expect(NOT_CANCELLED)
}

/// [`render_progressive`] that a caller can stop: whole passes until
/// `budget` has passed (with `None`, until `max_passes` are done; at least
/// one pass either way) or until `cancel` is set, whichever comes first.
/// `cancel` is read before every pass, every row and every block of
/// samples (of a pass and of the pilot): once it is set, the running pass
/// is abandoned within a block of samples per thread, and the mean of the
/// passes finished before it is returned, the same bits as an uncancelled
/// render of that many passes, or `None` if no pass finished. The library installs no signal handler: a program sets the
/// flag from its own (as `lobe render` does on Ctrl-C).
#[must_use]
pub fn render_until(
    scene: &Scene,
    opts: &RenderSettings,
    budget: Option<Duration>,
    max_passes: u64,
    cancel: &AtomicBool,
    progress: impl Fn(u64) + Sync,
) -> Option<Image> {
    let t0 = Instant::now();
    let max_passes = match opts.sequence {
        Sequence::Sobol => max_passes.min(SOBOL_MAX_SAMPLES / max_pixel_spp(opts)),
        _ => max_passes,
    }
    .max(1);
    on_pool(opts, || {
        let (mut sum, prior) = render_on_pool(scene, opts, 0, &progress, None, cancel)?;
        let mut passes = 1;
        // Go on while another pass, at the mean pass time so far, fits.
        while passes < max_passes && !cancel.load(Ordering::Relaxed) {
            if let Some(budget) = budget {
                let per_pass = t0.elapsed() / passes as u32;
                if t0.elapsed() + per_pass > budget {
                    break;
                }
            }
            let Some((img, _)) =
                render_on_pool(scene, opts, passes, &progress, prior.as_ref(), cancel)
            else {
                break;
            };
            for (a, b) in sum.pixels.iter_mut().zip(&img.pixels) {
                *a += *b;
            }
            sum.stats.camera_rays += img.stats.camera_rays;
            sum.stats.rays += img.stats.rays;
            sum.stats.nonfinite += img.stats.nonfinite;
            passes += 1;
        }
        let k = 1.0 / passes as f64;
        for p in &mut sum.pixels {
            *p *= k;
        }
        sum.stats.passes = passes;
        Some(sum)
    })
}

/// The first bounce's shading per pixel of adaptive MIS.
fn context<'a>(
    scene: &'a Scene,
    opts: &RenderSettings,
    pass: u64,
    light: &'a Light,
    shading: &'a [ObjectShading<'a>],
    progress: &'a (dyn Fn(u64) + Sync),
    batch: Option<&'a wavefront::Batch<'a>>,
) -> Context<'a> {
    Context {
        progress,
        // (Set by the caller that can be cancelled.)
        cancel: &NEVER,
        batch,
        scene,
        light,
        shading,
        spp: opts.spp.max(1),
        max_depth: opts.max_depth.max(1),
        seed: opts.seed,
        sequence: opts.sequence,
        pass,
        width: scene.camera.width as usize,
    }
}

fn shadings<'s>(scene: &'s Scene, opts: &RenderSettings) -> Vec<ObjectShading<'s>> {
    scene
        .objects
        .iter()
        .map(|o| object_shading(opts.strategy, &o.material))
        .collect()
}

fn add_stats(a: RenderStats, b: RenderStats) -> RenderStats {
    RenderStats {
        camera_rays: a.camera_rays + b.camera_rays,
        rays: a.rays + b.rays,
        nonfinite: a.nonfinite + b.nonfinite,
        passes: 1,
    }
}

/// [`add_stats`] of rows, `None` (a row skipped) if either is.
fn add_some_stats(a: Option<RenderStats>, b: Option<RenderStats>) -> Option<RenderStats> {
    Some(add_stats(a?, b?))
}

/// A pixel's sample values' luminance: count, sum and sum of squares.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Moments {
    n: u64,
    sum: f64,
    sum_sq: f64,
}

impl Moments {
    /// One sample value (a value that is not finite counts as 0, as in the
    /// image).
    #[inline]
    fn add(&mut self, v: Rgb) {
        self.n += 1;
        if v.is_finite() {
            let l = luminance(v);
            self.sum += l;
            self.sum_sq += l * l;
        }
    }

    /// The unbiased sample variance (0 for fewer than 2 samples).
    fn variance(&self) -> f64 {
        if self.n < 2 {
            return 0.0;
        }
        let n = self.n as f64;
        ((self.sum_sq - self.sum * self.sum / n) / (n - 1.0)).max(0.0)
    }
}

/// What pass 0's pilot decided, for every pass.
#[derive(Debug, Clone, Default)]
struct Prior {
    /// Adaptive MIS: per pixel the allocation its pooled pilots chose
    /// ([`pooled_allocations`]; empty otherwise).
    allocs: Vec<Allocation>,
    /// The variance allocation: per pixel its samples per pass.
    counts: Option<Vec<u64>>,
}

/// The pilot: per pixel, [`pilot_spp`] samples of their own randomization
/// (a seed apart from the image's); under adaptive MIS the balance
/// heuristic at the first bounce, recorded, and under the variance
/// allocation the values' moments ([`spp_counts`]). Their values are not
/// in the image. `None` when `cancel` was set before its last row finished.
fn pilot_phase(
    scene: &Scene,
    opts: &RenderSettings,
    cancel: &AtomicBool,
) -> Option<(Prior, RenderStats)> {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let shading = shadings(scene, opts);
    let light = Light::Env(scene.environment.clone());
    let pilot_opts = RenderSettings {
        seed: hash64(opts.seed ^ 0x7069_6c6f_7470_6978),
        spp: match opts.spp_allocation {
            // (A variance needs two samples.)
            SppAllocation::Variance => pilot_spp(opts.spp.max(1)).max(2),
            SppAllocation::Uniform => pilot_spp(opts.spp.max(1)),
        },
        ..*opts
    };
    // On the batch loop where it renders the scene: the same draws,
    // recorded from f32 rows.
    let batch = batch_loop(scene, opts);
    let ctx = Context {
        cancel,
        ..context(
            scene,
            &pilot_opts,
            0,
            &light,
            &shading,
            &|_| {},
            batch.as_ref(),
        )
    };
    let k = ctx.spp;
    let adaptive = is_adaptive(opts.strategy);
    let mode = if adaptive {
        FirstBounce::Pilot
    } else {
        FirstBounce::Plain
    };
    // (Made on rayon's threads, which share out the first touch of their
    // pages.)
    fn fresh<T: Default + Send>(n: usize) -> Vec<T> {
        (0..n).into_par_iter().map(|_| T::default()).collect()
    }
    let mut pilots: Vec<Pilot> = fresh(w * h);
    let mut moments: Vec<Moments> = fresh(w * h);
    if w == 0 {
        return Some((Prior::default(), RenderStats::default()));
    }
    let stats = pilots
        .par_chunks_mut(w)
        .zip(moments.par_chunks_mut(w))
        .enumerate()
        .map(|(y, (row, mrow))| {
            if ctx.cancel.load(Ordering::Relaxed) {
                return None;
            }
            let mut stats = RenderStats::default();
            if let Some(b) = ctx.batch {
                let mut sums = vec![Rgb::ZERO; w];
                let pilots = adaptive.then_some(row);
                stats = b.row(&ctx, y, &mut sums, &|_| (k, mode), pilots, Some(mrow));
            } else {
                for (x, (p, m)) in row.iter_mut().zip(mrow).enumerate() {
                    if ctx.cancel.load(Ordering::Relaxed) {
                        return None;
                    }
                    (_, *p, *m) = ctx.pixel(x, y, k, mode, &mut stats);
                }
            }
            // (Set during the row, the flag may have cut it short.)
            (!ctx.cancel.load(Ordering::Relaxed)).then_some(stats)
        })
        .reduce(|| Some(RenderStats::default()), add_some_stats)?;
    // The two decisions are independent: made side by side.
    let (counts, allocs) = rayon::join(
        || {
            (opts.spp_allocation == SppAllocation::Variance).then(|| {
                let var: Vec<f64> = moments.iter().map(Moments::variance).collect();
                spp_counts(&var, w, h, opts.spp.max(1))
            })
        },
        || match opts.strategy {
            Strategy::Mis(mis) if adaptive => pooled_allocations(&pilots, w, h, mis),
            _ => Vec::new(),
        },
    );
    Some((Prior { allocs, counts }, stats))
}

/// Every pixel's allocation (row by row): from the pilots of the pixels
/// within [`PILOT_RADIUS`] of it, merged, along the rows first and then
/// down the columns (14 merges a pixel instead of 49, for a render that
/// asks each pixel's allocation in every block it spans).
fn pooled_allocations(pilots: &[Pilot], w: usize, h: usize, mis: Mis) -> Vec<Allocation> {
    box_pool(
        w,
        h,
        PILOT_RADIUS,
        |i| pilots[i],
        Pilot::merge,
        |_, p| p.choose(mis.n_bsdf, mis.n_light),
    )
}

/// Each cell of a `w × h` grid (row by row, cell `i` is `cell(i)`) pooled
/// with the cells of the `(2r + 1)²` box around it (fewer at the edges) by
/// `merge`, starting from `T::default()`, and then `finish`ed (with its
/// index): along the rows first, then down the columns (`2(2r + 1)` merges
/// a cell instead of `(2r + 1)²`), each in increasing order. Both passes
/// run over rayon's threads, each cell's merges in the same order whatever
/// the thread; the pooled cells are finished as they come (no second grid
/// of them).
fn box_pool<T: Default + Send + Sync, U: Send>(
    w: usize,
    h: usize,
    r: usize,
    cell: impl Fn(usize) -> T + Sync,
    merge: impl Fn(&mut T, &T) + Sync,
    finish: impl Fn(usize, &T) -> U + Sync,
) -> Vec<U> {
    let across: Vec<T> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (y, x) = (i / w, i % w);
            let mut p = T::default();
            for xx in x.saturating_sub(r)..(x + r + 1).min(w) {
                merge(&mut p, &cell(y * w + xx));
            }
            p
        })
        .collect();
    (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (y, x) = (i / w, i % w);
            let mut p = T::default();
            for yy in y.saturating_sub(r)..(y + r + 1).min(h) {
                merge(&mut p, &across[yy * w + x]);
            }
            finish(i, &p)
        })
        .collect()
}

/// One pass, and what its pilot decided when it ran one (pass 0 runs the
/// pilot where the render needs one and returns it; later passes borrow
/// it as `prior`). `None` when `cancel` was set before its last row
/// finished: the pass is abandoned.
fn render_on_pool(
    scene: &Scene,
    opts: &RenderSettings,
    pass: u64,
    progress: &(dyn Fn(u64) + Sync),
    prior: Option<&Prior>,
    cancel: &AtomicBool,
) -> Option<(Image, Option<Prior>)> {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let shading = shadings(scene, opts);
    let light = Light::Env(scene.environment.clone());
    let batch = batch_loop(scene, opts);
    let ctx = Context {
        cancel,
        ..context(
            scene,
            opts,
            pass,
            &light,
            &shading,
            progress,
            batch.as_ref(),
        )
    };
    let mut img = Image::new(w, h);
    if w == 0 || h == 0 {
        return Some((img, None));
    }
    let spp = ctx.spp;
    let own = if prior.is_none() && needs_pilot(opts) {
        Some(pilot_phase(scene, opts, cancel)?)
    } else {
        None
    };
    let none = Prior::default();
    let (prior, pilot_stats) = match (&own, prior) {
        (Some((p, stats)), _) => (p, *stats),
        (None, Some(p)) => (p, RenderStats::default()),
        (None, None) => (&none, RenderStats::default()),
    };
    let count = |x: usize, y: usize| prior.counts.as_ref().map_or(spp, |c| c[y * w + x]);
    let stats = match opts.strategy {
        Strategy::Mis(mis) if mis.form == MisForm::Adaptive => {
            let allocs = &prior.allocs;
            // Pixels given to light sampling alone draw from the map's plain
            // distribution, whose tables wait for their first draw: built
            // here on the pool's threads instead of by the first of them.
            if allocs.contains(&Allocation::Light) {
                scene.environment.prepare_sampling();
            }
            render_rows(&ctx, &mut img.pixels, count, |x, y| {
                (count(x, y), FirstBounce::Allocated(allocs[y * w + x]))
            })?
        }
        s => {
            if s == Strategy::Light {
                scene.environment.prepare_sampling();
            }
            render_rows(&ctx, &mut img.pixels, count, |x, y| {
                (count(x, y), FirstBounce::Plain)
            })?
        }
    };
    for (i, px) in img.pixels.iter_mut().enumerate() {
        *px *= 1.0 / count(i % w, i / w) as f64;
    }
    img.spp.clone_from(&prior.counts);
    // The pilot's rays are work done, but not camera rays of the image.
    img.stats = RenderStats {
        rays: stats.rays + pilot_stats.rays,
        nonfinite: stats.nonfinite + pilot_stats.nonfinite,
        ..stats
    };
    Some((img, own.map(|(p, _)| p)))
}

/// Every pixel's samples `0..n` of the pass with first-bounce mode `mode`,
/// `(n, mode) = plan(x, y)` (`n = count(x, y)`, the cheaper call), rows in
/// parallel; stores each pixel's sum (not divided). `None` when
/// `ctx.cancel` was set before the last row finished: the rows not begun
/// are skipped and a row running stops at its next block (batch loop) or
/// progress step of a pixel (scalar loop).
fn render_rows(
    ctx: &Context<'_>,
    pixels: &mut [Rgb],
    count: impl Fn(usize, usize) -> u64,
    plan: impl Fn(usize, usize) -> (u64, FirstBounce) + Sync,
) -> Option<RenderStats> {
    let w = ctx.width;
    // The rows handed out to the threads the costliest first (by their
    // samples), so that no thread is left with a long row at the end while
    // the others wait; each row's pixels are the same whichever thread
    // takes it, and the stats are sums.
    let mut rows: Vec<(u64, usize, &mut [Rgb])> = pixels
        .chunks_mut(w)
        .enumerate()
        .map(|(y, row)| ((0..w).map(|x| count(x, y)).sum(), y, row))
        .collect();
    rows.sort_by_key(|&(cost, y, _)| (std::cmp::Reverse(cost), y));
    rows.into_iter()
        .par_bridge()
        .map(|(_, y, row)| {
            if ctx.cancel.load(Ordering::Relaxed) {
                return None;
            }
            let stats = if let Some(b) = ctx.batch {
                b.row(ctx, y, row, &|x| plan(x, y), None, None)
            } else {
                let mut stats = RenderStats::default();
                for (x, px) in row.iter_mut().enumerate() {
                    if ctx.cancel.load(Ordering::Relaxed) {
                        return None;
                    }
                    let (n, mode) = plan(x, y);
                    *px = ctx.pixel(x, y, n, mode, &mut stats).0;
                }
                stats
            };
            // Set during the row, the flag may have cut it short (a batch
            // row stops after its block, a pixel after its progress step):
            // a row finishes only if the flag was still clear at its end.
            (!ctx.cancel.load(Ordering::Relaxed)).then_some(stats)
        })
        .reduce(|| Some(RenderStats::default()), add_some_stats)
}

/// The randomization of pixel `index` for `seed` (hashed, so that
/// neighbouring pixels' patterns are unrelated).
#[must_use]
pub fn pixel_seed(seed: u64, index: u64) -> u64 {
    hash64(hash64(seed ^ 0x6c6f_6265_7265_6e64) ^ hash64(index))
}

/// Progress is reported every this many samples of a pixel (and at its end).
const PROGRESS_STEP: u64 = 4096;

struct Context<'a> {
    progress: &'a (dyn Fn(u64) + Sync),
    /// Set: rows not begun are skipped, and their pass abandoned.
    cancel: &'a AtomicBool,
    /// The batch loop, where it renders the scene (never for the pilot).
    batch: Option<&'a wavefront::Batch<'a>>,
    scene: &'a Scene,
    light: &'a Light,
    shading: &'a [ObjectShading<'a>],
    spp: u64,
    max_depth: u32,
    seed: u64,
    sequence: Sequence,
    pass: u64,
    width: usize,
}

/// What the scene lets through from a shading point at `p` (geometric
/// normal `ng`): shadow rays for light samples; a BSDF-sampled ray keeps its
/// hit, to continue the path.
struct SceneVisibility<'a> {
    scene: &'a Scene,
    p: DVec3,
    ng: DVec3,
    rays: u64,
    hit: Option<(Hit, usize)>,
}

impl Visibility for SceneVisibility<'_> {
    fn unoccluded(&mut self, dir: DVec3) -> bool {
        self.rays += 1;
        !self.scene.occluded(&spawn_ray(self.p, self.ng, dir))
    }

    fn escapes(&mut self, dir: DVec3) -> bool {
        self.rays += 1;
        self.hit = self
            .scene
            .intersect(&spawn_ray(self.p, self.ng, dir), f64::INFINITY);
        self.hit.is_none()
    }
}

impl Context<'_> {
    /// Pixel `(x, y)`'s `n` samples of the pass: their sum, in
    /// [`FirstBounce::Pilot`] mode the pilot statistics of their first
    /// bounces, and their values' moments.
    fn pixel(
        &self,
        x: usize,
        y: usize,
        n: u64,
        mode: FirstBounce,
        stats: &mut RenderStats,
    ) -> (Rgb, Pilot, Moments) {
        let pixel_seed = pixel_seed(self.seed, (y * self.width + x) as u64);
        let mut sum = Rgb::ZERO;
        let mut pilot = Pilot::default();
        let mut moments = Moments::default();
        let mut pending = 0u64;
        for i in 0..n {
            let ps = match self.sequence {
                // A fresh stratification per pass.
                Sequence::Stratified => PixelSample {
                    sequence: self.sequence,
                    seed: hash64(pixel_seed ^ hash64(self.pass)),
                    n,
                    index: i,
                },
                // The pixel's one sequence goes on.
                Sequence::Sobol | Sequence::Independent => PixelSample {
                    sequence: self.sequence,
                    seed: pixel_seed,
                    n,
                    index: self.pass * n + i,
                },
            };
            let j = ps.pair(dims::CAMERA);
            let ray = self.scene.camera.ray(x as f64 + j.x, y as f64 + j.y);
            stats.camera_rays += 1;
            let v = self.radiance(ray, &ps, mode, &mut pilot, stats);
            moments.add(v);
            if v.is_finite() {
                sum += v;
            } else {
                stats.nonfinite += 1;
            }
            pending += 1;
            if pending == PROGRESS_STEP {
                (self.progress)(pending);
                pending = 0;
                // Cancelled: the pixel is left unfinished (its pass is
                // abandoned, see `render_rows`).
                if self.cancel.load(Ordering::Relaxed) {
                    break;
                }
            }
        }
        if pending > 0 {
            (self.progress)(pending);
        }
        (sum, pilot, moments)
    }

    /// Radiance arriving along a camera ray.
    fn radiance(
        &self,
        ray: crate::geometry::Ray,
        ps: &PixelSample,
        mode: FirstBounce,
        pilot: &mut Pilot,
        stats: &mut RenderStats,
    ) -> Rgb {
        stats.rays += 1;
        let Some((mut hit, mut obj)) = self.scene.intersect(&ray, f64::INFINITY) else {
            return self.light.radiance(ray.dir);
        };
        let mut wo_world = -ray.dir;
        let mut beta = Rgb::ONE;
        let mut l = Rgb::ZERO;
        let mut depth = 1u32;
        let mut points = [[0.0; 3]; 2];
        loop {
            let shading = &self.shading[obj];
            let est = &shading.estimator;
            // Normals turned toward the viewer; the shading normal on the
            // geometric normal's side, and the geometric one where the
            // interpolated normal would put the viewer below the horizon.
            //
            // A transmitting material keeps the shape's own orientation
            // (outward on spheres and closed meshes): `wo` below its surface
            // is a view from inside. Its shading normal gives way to the
            // geometric one where the two put the viewer on different sides.
            let (ng, ns) = if shading.transmits {
                let side = hit.ng.dot(wo_world);
                let ns = if hit.ns.dot(wo_world) * side > 0.0 {
                    hit.ns
                } else {
                    hit.ng
                };
                (hit.ng, ns)
            } else {
                let ng = if hit.ng.dot(wo_world) < 0.0 {
                    -hit.ng
                } else {
                    hit.ng
                };
                let mut ns = if hit.ns.dot(ng) < 0.0 {
                    -hit.ns
                } else {
                    hit.ns
                };
                if ns.dot(wo_world) <= 0.0 {
                    ns = ng;
                }
                (ng, ns)
            };
            let frame = Frame::from_normal(ns);
            let wo = frame.to_local(wo_world);
            // At the horizon, or below an opaque surface: nothing scatters.
            if wo.z == 0.0 || (wo.z < 0.0 && !shading.transmits) {
                break;
            }
            let sp = ShadingPoint { frame, wo };
            let go_on = depth < self.max_depth;
            let strategy = est.strategy();
            // The random numbers, light samples' first, then the BSDF
            // sample's (lobe choice, direction).
            let k = strategy.points_per_sample();
            debug_assert!(k <= points.len());
            let b = depth - 1;
            let bsdf_point = || {
                let u = ps.pair(dims::bsdf_u(b));
                [ps.one(dims::bsdf_uc(b)), u.x, u.y]
            };
            // A lobe choice for the light point too: adaptive MIS may give
            // it to BSDF sampling.
            let light_point = || {
                let u = ps.pair(dims::light(b));
                [ps.pair(dims::bsdf_uc(b)).y, u.x, u.y]
            };
            match strategy {
                Strategy::Light => points[0] = light_point(),
                Strategy::Mis(m) if m.form != MisForm::OneSample => {
                    points[1] = light_point();
                    points[0] = bsdf_point();
                }
                _ => points[0] = bsdf_point(),
            }
            let mut vis = SceneVisibility {
                scene: self.scene,
                p: hit.p,
                ng,
                rays: 0,
                hit: None,
            };
            let e = match (mode, depth) {
                (FirstBounce::Pilot, 1) => {
                    est.estimate_pilot(&sp, self.light, &points[..k], &mut vis, pilot)
                }
                (FirstBounce::Allocated(a), 1) => {
                    est.with_allocation(a)
                        .estimate(&sp, self.light, &points[..k], &mut vis)
                }
                _ => est.estimate(&sp, self.light, &points[..k], &mut vis),
            };
            l += beta * e.value;
            if !go_on {
                stats.rays += vis.rays;
                break;
            }
            // Continue with the estimate's BSDF sample, or draw one where
            // it drew none (light sampling alone, one-sample MIS that chose
            // the light); where its draw failed, the path ends.
            let drawn = match e.bsdf {
                BsdfDraw::Drawn(d) => Some(d),
                BsdfDraw::Failed => None,
                BsdfDraw::NotDrawn => {
                    let uc = ps.one(dims::next_uc(b));
                    let u = ps.pair(dims::next_u(b));
                    shading.continuation.sample(wo, uc, u).map(|s| {
                        let dir = frame.to_world(s.wi);
                        let escaped = vis.escapes(dir);
                        DrawnBsdf {
                            sample: s,
                            dir,
                            escaped,
                        }
                    })
                }
            };
            stats.rays += vis.rays;
            let Some(d) = drawn else {
                break;
            };
            let Some((h2, o2)) = vis.hit.filter(|_| !d.escaped) else {
                break;
            };
            beta *= d.sample.weight;
            depth += 1;
            if depth > 3 {
                // Russian roulette after the third bounce.
                let q = beta.max_element().min(0.95);
                if q <= 0.0 || ps.one(dims::roulette(b)) >= q {
                    break;
                }
                beta /= q;
            }
            hit = h2;
            obj = o2;
            wo_world = -d.dir;
        }
        l
    }
}

/// The batch loop for `scene` where `opts` asks for it and it covers the
/// scene and strategy ([`batch_refusal`] says why not); else `None`, the
/// scalar loop.
fn batch_loop<'a>(scene: &'a Scene, opts: &RenderSettings) -> Option<wavefront::Batch<'a>> {
    match opts.render_loop {
        RenderLoop::Batch => {
            wavefront::Batch::new(scene, opts.strategy, opts.max_depth.max(1)).ok()
        }
        RenderLoop::Scalar => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(counts: &[u64], spp: u64) {
        let total: u64 = counts.iter().sum();
        assert_eq!(total, counts.len() as u64 * spp, "the total is w × h × spp");
        let floor = (spp / SPP_FLOOR_DIVISOR).max(1);
        assert!(counts.iter().all(|&n| n >= floor), "the floor {floor}");
        assert!(counts.iter().all(|&n| n <= MAX_SPP_FACTOR * spp), "the cap");
    }

    #[test]
    fn spp_counts_share_the_samples_out_by_standard_deviation() {
        // Zero, negative or not-finite variances everywhere: spp each.
        let (w, h) = (9, 7);
        for v in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(spp_counts(&vec![v; w * h], w, h, 16), vec![16; w * h]);
        }
        // Uniform variance: spp each (up to the rounding of the running sum).
        let c = spp_counts(&vec![2.5; w * h], w, h, 16);
        check(&c, 16);
        assert!(c.iter().all(|&n| n.abs_diff(16) <= 1), "{c:?}");
        // The left half 100 times the variance of the right half (pooled
        // over 5 × 5 pixels): away from the border between them, 10 times
        // the extra samples above the floor.
        let (w, h) = (40, 10);
        let var: Vec<f64> = (0..w * h)
            .map(|i| if i % w < w / 2 { 100.0 } else { 1.0 })
            .collect();
        for spp in [1, 7, 64, 1000] {
            let c = spp_counts(&var, w, h, spp);
            check(&c, spp);
            let floor = (spp / SPP_FLOOR_DIVISOR).max(1) as f64;
            let (l, r) = (c[5 * w + 5] as f64 - floor, c[5 * w + 35] as f64 - floor);
            // (Each count is rounded to a whole sample: up to 1 off in `l`,
            // 10 in `10 r`.)
            if spp >= 64 {
                assert!(
                    (l - 10.0 * r).abs() <= 11.0 + 0.02 * l,
                    "spp {spp}: {l} / {r}"
                );
            }
        }
    }

    #[test]
    fn spp_counts_cap_a_pixel_and_give_the_rest_to_the_others() {
        // One noisy pixel among quiet ones: it and its 5 × 5 neighbours
        // would take nearly everything, but stop at the cap.
        let (w, h) = (50, 40);
        let mut var = vec![1e-6; w * h];
        var[20 * w + 25] = 1e6;
        let spp = 16;
        let c = spp_counts(&var, w, h, spp);
        check(&c, spp);
        assert_eq!(c[20 * w + 25], MAX_SPP_FACTOR * spp);
        assert_eq!(c[19 * w + 24], MAX_SPP_FACTOR * spp);
        assert_eq!(c[18 * w + 27], MAX_SPP_FACTOR * spp);
        // Three pixels away it is outside the window.
        assert!(c[17 * w + 25] < spp, "{}", c[17 * w + 25]);
        // The rest share what the capped pixels leave (each ≥ the floor).
        assert!(c[0] >= 2 && c[0] < spp, "{}", c[0]);
    }

    #[test]
    fn moments_give_the_sample_variance_and_count_bad_values_as_zero() {
        let mut m = Moments::default();
        assert_eq!(m.variance(), 0.0);
        for v in [1.0, 2.0, 3.0, 4.0] {
            m.add(Rgb::splat(v));
        }
        assert!((m.variance() - 5.0 / 3.0).abs() < 1e-12, "{}", m.variance());
        m.add(Rgb::splat(f64::NAN));
        assert_eq!(m.n, 5);
        assert!((m.sum - 10.0).abs() < 1e-12);
    }
}
