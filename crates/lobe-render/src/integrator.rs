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
//! (multi-sample MIS gives each technique its own dimensions), the
//! continuation's direction and lobe choice, and Russian roulette. The
//! pattern ([`RenderOptions::sequence`]) is `sobol` (Owen-scrambled,
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
//! # Batch loop
//!
//! [`RenderOptions::render_loop`] is [`RenderLoop::Batch`] by default: for
//! direct lighting (`max_depth = 1`) with a BSDF strategy, `light`, or MIS
//! with one BSDF and one light draw (`mis`, `mis-balance`, `mis-power`),
//! each row is rendered in blocks of [`BLOCK`] samples (consecutive samples
//! of consecutive pixels), the whole row at the block's SIMD level: the
//! camera rays and their hits (f64 lanes, [`crate::lanes`], testing only
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
pub use crate::options::{RenderLoop, RenderOptions};
use crate::scene::Scene;
use glam::{DVec2, DVec3};
use lobe::estimator::{
    Allocation, DrawnBsdf, Mis, MisForm, Pilot, ShadingEstimator, ShadingPoint, Strategy,
    Visibility,
};
use lobe::light::Light;
use lobe::math::Rgb;
use lobe::sequence::{Sequence, hash64, pair_point};
use lobe::{BsdfSampler, BsdfStrategy, Frame, Material};
use rayon::prelude::*;
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
    /// As the estimator is (every technique but adaptive MIS; adaptive MIS
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
}

/// The strategy `strategy` becomes on material `m`: a BSDF strategy that
/// does not apply falls back to `brdf`, which applies to every material.
#[must_use]
pub fn strategy_for(strategy: Strategy, m: &Material) -> Strategy {
    match strategy {
        Strategy::Bsdf(s) if m.check(s).is_err() => Strategy::Bsdf(BsdfStrategy::Brdf),
        t => t,
    }
}

fn object_shading(strategy: Strategy, m: &Material) -> ObjectShading<'_> {
    let estimator = strategy_for(strategy, m)
        .for_material(m)
        .or_else(|_| Strategy::Bsdf(BsdfStrategy::Brdf).for_material(m))
        .expect("brdf applies to every material");
    let continuation = estimator.sampler().unwrap_or_else(|| {
        m.sampler(m.best_bsdf_strategy())
            .expect("the best BSDF strategy applies")
    });
    ObjectShading {
        estimator,
        continuation,
    }
}

/// An object whose material does not take the requested strategy.
#[derive(Debug, Clone, PartialEq)]
pub struct Fallback {
    pub object: usize,
    pub model: &'static str,
    pub requested: BsdfStrategy,
    pub used: BsdfStrategy,
}

/// The objects on which `strategy`'s BSDF strategy falls back to `brdf`.
#[must_use]
pub fn fallbacks(scene: &Scene, strategy: Strategy) -> Vec<Fallback> {
    let Strategy::Bsdf(s) = strategy else {
        return Vec::new();
    };
    scene
        .objects
        .iter()
        .enumerate()
        .filter_map(|(i, o)| {
            let Strategy::Bsdf(used) = strategy_for(strategy, &o.material) else {
                return None;
            };
            (used != s).then(|| Fallback {
                object: i,
                model: o.material.model_name(),
                requested: s,
                used,
            })
        })
        .collect()
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
pub fn render(scene: &Scene, opts: &RenderOptions, progress: impl Fn(u64) + Sync) -> Image {
    render_pass(scene, opts, 0, progress)
}

/// Pass `pass` of a progressive render: `opts.spp` more samples per pixel
/// (see the module doc); the mean of passes `0..P` is the image of `P`
/// passes. Sobol takes `(pass + 1) · spp ≤ 2³²` ([`SOBOL_MAX_SAMPLES`]).
#[must_use]
pub fn render_pass(
    scene: &Scene,
    opts: &RenderOptions,
    pass: u64,
    progress: impl Fn(u64) + Sync,
) -> Image {
    on_pool(opts, || {
        if pass > 0 && is_adaptive(opts.strategy) {
            // The allocations of later passes come from pass 0's pilot.
            let pilots = pilot_phase(scene, opts).0;
            render_on_pool(scene, opts, pass, &progress, Some(&pilots)).0
        } else {
            render_on_pool(scene, opts, pass, &progress, None).0
        }
    })
}

/// Whether `s` is adaptive MIS, whose first bounce a per-pixel pilot tunes.
fn is_adaptive(s: Strategy) -> bool {
    matches!(s, Strategy::Mis(m) if m.form == MisForm::Adaptive)
}

/// Pilot samples per pixel of adaptive MIS for passes of `spp`: extra
/// samples of their own randomization, drawn once before pass 0 and not
/// part of the image: an eighth of `spp`, at least 1 and at most
/// [`MAX_PILOT_SPP`].
#[must_use]
pub fn pilot_spp(spp: u64) -> u64 {
    (spp / 8).clamp(1, MAX_PILOT_SPP)
}

/// The most pilot samples per pixel: the allocation of a pixel pools the
/// pilots of 7 × 7 pixels ([`PILOT_RADIUS`]), 392 samples at this cap, which
/// tell three allocations' variances apart well enough; more would only
/// add time (at 256 spp an eighth was 32 per pixel, 12% of the render).
pub const MAX_PILOT_SPP: u64 = 8;

/// Half the side of the window of pixels whose pilots decide a pixel's
/// allocation (7 × 7 pixels).
pub const PILOT_RADIUS: usize = 3;

fn on_pool<T: Send>(opts: &RenderOptions, f: impl FnOnce() -> T + Send) -> T {
    if let Some(n) = opts.threads
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
    opts: &RenderOptions,
    budget: Duration,
    max_passes: u64,
    progress: impl Fn(u64) + Sync,
) -> Image {
    let t0 = Instant::now();
    let max_passes = match opts.sequence {
        Sequence::Sobol => max_passes.min(SOBOL_MAX_SAMPLES / opts.spp.max(1)),
        _ => max_passes,
    }
    .max(1);
    on_pool(opts, || {
        let (mut sum, pilots) = render_on_pool(scene, opts, 0, &progress, None);
        let mut passes = 1;
        // Go on while another pass, at the mean pass time so far, fits.
        while passes < max_passes {
            let per_pass = t0.elapsed() / passes as u32;
            if t0.elapsed() + per_pass > budget {
                break;
            }
            let img = render_on_pool(scene, opts, passes, &progress, Some(&pilots)).0;
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
        sum
    })
}

/// The first bounce's shading per pixel of adaptive MIS.
fn context<'a>(
    scene: &'a Scene,
    opts: &RenderOptions,
    pass: u64,
    light: &'a Light,
    shading: &'a [ObjectShading<'a>],
    progress: &'a (dyn Fn(u64) + Sync),
    batch: Option<&'a wavefront::Batch<'a>>,
) -> Context<'a> {
    Context {
        progress,
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

fn shadings<'s>(scene: &'s Scene, opts: &RenderOptions) -> Vec<ObjectShading<'s>> {
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

/// The pilot of adaptive MIS: per pixel, [`pilot_spp`] samples of their own
/// randomization (a seed apart from the image's), the balance heuristic at
/// the first bounce, recorded; their values are not used.
fn pilot_phase(scene: &Scene, opts: &RenderOptions) -> (Vec<Pilot>, RenderStats) {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let shading = shadings(scene, opts);
    let light = Light::Env(scene.environment.clone());
    let pilot_opts = RenderOptions {
        seed: hash64(opts.seed ^ 0x7069_6c6f_7470_6978),
        spp: pilot_spp(opts.spp.max(1)),
        ..*opts
    };
    // On the batch loop where it renders the scene: the same draws,
    // recorded from f32 lanes.
    let batch = batch_loop(scene, opts);
    let ctx = context(
        scene,
        &pilot_opts,
        0,
        &light,
        &shading,
        &|_| {},
        batch.as_ref(),
    );
    let k = ctx.spp;
    let mut pilots = vec![Pilot::default(); w * h];
    if w == 0 {
        return (pilots, RenderStats::default());
    }
    let stats = pilots
        .par_chunks_mut(w)
        .enumerate()
        .map(|(y, row)| {
            let mut stats = RenderStats::default();
            if let Some(b) = ctx.batch {
                let mut sums = vec![Rgb::ZERO; w];
                stats = b.row(&ctx, y, &mut sums, &|_| FirstBounce::Pilot, Some(row));
            } else {
                for (x, p) in row.iter_mut().enumerate() {
                    *p = ctx.pixel(x, y, 0..k, FirstBounce::Pilot, &mut stats).1;
                }
            }
            stats
        })
        .reduce(RenderStats::default, add_stats);
    (pilots, stats)
}

/// The allocation of pixel `(x, y)`: from the pilots of the pixels within
/// [`PILOT_RADIUS`], merged.
fn pooled_allocation(
    pilots: &[Pilot],
    w: usize,
    h: usize,
    x: usize,
    y: usize,
    mis: Mis,
) -> Allocation {
    let mut p = Pilot::default();
    for yy in y.saturating_sub(PILOT_RADIUS)..(y + PILOT_RADIUS + 1).min(h) {
        for xx in x.saturating_sub(PILOT_RADIUS)..(x + PILOT_RADIUS + 1).min(w) {
            p.merge(&pilots[yy * w + xx]);
        }
    }
    p.choose(mis.n_bsdf, mis.n_light)
}

/// One pass; for adaptive MIS also the per-pixel pilots (pass 0 draws them
/// in its first [`pilot_spp`] samples; later passes take `prior`).
fn render_on_pool(
    scene: &Scene,
    opts: &RenderOptions,
    pass: u64,
    progress: &(dyn Fn(u64) + Sync),
    prior: Option<&[Pilot]>,
) -> (Image, Vec<Pilot>) {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let shading = shadings(scene, opts);
    let light = Light::Env(scene.environment.clone());
    let batch = batch_loop(scene, opts);
    let ctx = context(
        scene,
        opts,
        pass,
        &light,
        &shading,
        progress,
        batch.as_ref(),
    );
    let mut img = Image::new(w, h);
    if w == 0 || h == 0 {
        return (img, Vec::new());
    }
    let spp = ctx.spp;
    let k = 1.0 / spp as f64;
    let mis = match opts.strategy {
        Strategy::Mis(mis) if mis.form == MisForm::Adaptive => mis,
        _ => {
            img.stats = render_rows(&ctx, &mut img.pixels, |_, _| (0..spp, FirstBounce::Plain));
            for px in &mut img.pixels {
                *px *= k;
            }
            return (img, Vec::new());
        }
    };
    let (pilots, pilot_stats) = match prior {
        Some(p) => (p.to_vec(), RenderStats::default()),
        None => pilot_phase(scene, opts),
    };
    let stats = render_rows(&ctx, &mut img.pixels, |x, y| {
        let a = pooled_allocation(&pilots, w, h, x, y, mis);
        (0..spp, FirstBounce::Allocated(a))
    });
    for px in &mut img.pixels {
        *px *= k;
    }
    // The pilot's rays are work done, but not camera rays of the image.
    img.stats = RenderStats {
        rays: stats.rays + pilot_stats.rays,
        nonfinite: stats.nonfinite + pilot_stats.nonfinite,
        ..stats
    };
    (img, pilots)
}

/// Every pixel's samples `range` with first-bounce mode `mode`, as chosen
/// per pixel, rows in parallel; stores each pixel's sum (not divided).
fn render_rows(
    ctx: &Context<'_>,
    pixels: &mut [Rgb],
    plan: impl Fn(usize, usize) -> (std::ops::Range<u64>, FirstBounce) + Sync,
) -> RenderStats {
    let w = ctx.width;
    pixels
        .par_chunks_mut(w)
        .enumerate()
        .map(|(y, row)| {
            if let Some(b) = ctx.batch {
                return b.row(ctx, y, row, &|x| plan(x, y).1, None);
            }
            let mut stats = RenderStats::default();
            for (x, px) in row.iter_mut().enumerate() {
                let (range, mode) = plan(x, y);
                *px = ctx.pixel(x, y, range, mode, &mut stats).0;
            }
            stats
        })
        .reduce(RenderStats::default, add_stats)
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
    /// Samples `range` of pixel `(x, y)`: their sum, and in
    /// [`FirstBounce::Pilot`] mode the pilot statistics of their first
    /// bounces.
    fn pixel(
        &self,
        x: usize,
        y: usize,
        range: std::ops::Range<u64>,
        mode: FirstBounce,
        stats: &mut RenderStats,
    ) -> (Rgb, Pilot) {
        let pixel_seed = pixel_seed(self.seed, (y * self.width + x) as u64);
        let mut sum = Rgb::ZERO;
        let mut pilot = Pilot::default();
        let mut pending = 0u64;
        for i in range {
            let ps = match self.sequence {
                // A fresh stratification per pass.
                Sequence::Stratified => PixelSample {
                    sequence: self.sequence,
                    seed: hash64(pixel_seed ^ hash64(self.pass)),
                    n: self.spp,
                    index: i,
                },
                // The pixel's one sequence goes on.
                Sequence::Sobol | Sequence::Independent => PixelSample {
                    sequence: self.sequence,
                    seed: pixel_seed,
                    n: self.spp,
                    index: self.pass * self.spp + i,
                },
            };
            let j = ps.pair(dims::CAMERA);
            let ray = self.scene.camera.ray(x as f64 + j.x, y as f64 + j.y);
            stats.camera_rays += 1;
            let v = self.radiance(ray, &ps, mode, &mut pilot, stats);
            if v.is_finite() {
                sum += v;
            } else {
                stats.nonfinite += 1;
            }
            pending += 1;
            if pending == PROGRESS_STEP {
                (self.progress)(pending);
                pending = 0;
            }
        }
        if pending > 0 {
            (self.progress)(pending);
        }
        (sum, pilot)
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
            let frame = Frame::from_normal(ns);
            let wo = frame.to_local(wo_world);
            if wo.z <= 0.0 {
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
            // Continue with the estimate's BSDF sample, or draw one (light
            // sampling alone, or one-sample MIS that chose the light).
            let drawn = e.bsdf.or_else(|| {
                let uc = ps.one(dims::next_uc(b));
                let u = ps.pair(dims::next_u(b));
                let s = shading.continuation.sample(wo, uc, u)?;
                let dir = frame.to_world(s.wi);
                let escaped = vis.escapes(dir);
                Some(DrawnBsdf {
                    sample: s,
                    dir,
                    escaped,
                })
            });
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
fn batch_loop<'a>(scene: &'a Scene, opts: &RenderOptions) -> Option<wavefront::Batch<'a>> {
    match opts.render_loop {
        RenderLoop::Batch => {
            wavefront::Batch::new(scene, opts.strategy, opts.max_depth.max(1)).ok()
        }
        RenderLoop::Scalar => None,
    }
}
