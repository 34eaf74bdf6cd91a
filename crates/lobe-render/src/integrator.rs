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
//! * **Light sampling** ([`EnvMap::sample`]): draw a world direction with
//!   density ∝ the map's luminance, take it to the local frame; below the
//!   horizon it is a failed sample; otherwise a shadow ray, and
//!   `f L cos / p_light` when it escapes.
//! * **MIS** (Veach's multi-sample form with one sample per strategy):
//!   both of the above, each weighted by the balance heuristic
//!   `p_t / (p_b + p_l)` (`mis`) or the power heuristic
//!   `p_t² / (p_b² + p_l²)` (`mis-power`), where the BSDF strategy is
//!   `vndf` when the material has it, else `brdf`, and the light strategy
//!   draws from the MIS-compensated distribution
//!   ([`EnvMap::sample_compensated`], density ∝ `max(0, lum − mean)`), as
//!   `lobe`'s estimator does ([`lobe::Light::sample_mis`]).
//!
//! This is [`lobe::estimator::technique_value`] with a shadow ray added.
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
//! # Determinism
//!
//! Pixel `(x, y)` draws every random number from its own PCG stream, seeded
//! from `(seed, y · width + x)`, so the image is the same bit for bit for
//! any thread count and any order of the rows.

use crate::geometry::{Hit, spawn_ray};
pub use crate::options::RenderOptions;
use crate::scene::Scene;
use glam::{DVec2, DVec3};
use lobe::estimator::{DrawnBsdf, MisForm, ShadingEstimator, ShadingPoint, Strategy, Visibility};
use lobe::light::Light;
use lobe::math::Rgb;
use lobe::sequence::hash64;
use lobe::{BsdfSampler, BsdfStrategy, Frame, Material};
use rand::RngExt;
use rand_pcg::Pcg64;
use rayon::prelude::*;

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

/// Render `scene` with `opts`. Rows are rendered in parallel (on a local
/// pool of `opts.threads` threads, else on rayon's current pool), each
/// written in place; `progress` is called with the number of samples
/// (camera rays) finished, every few thousand samples of a pixel and at its
/// end (they add up to `width × height × spp`).
#[must_use]
pub fn render(scene: &Scene, opts: &RenderOptions, progress: impl Fn(u64) + Sync) -> Image {
    if let Some(n) = opts.threads
        && let Ok(pool) = rayon::ThreadPoolBuilder::new().num_threads(n).build()
    {
        return pool.install(|| render_on_pool(scene, opts, &progress));
    }
    render_on_pool(scene, opts, &progress)
}

fn render_on_pool(scene: &Scene, opts: &RenderOptions, progress: &(dyn Fn(u64) + Sync)) -> Image {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let shading: Vec<ObjectShading> = scene
        .objects
        .iter()
        .map(|o| object_shading(opts.strategy, &o.material))
        .collect();
    let light = Light::Env(scene.environment.clone());
    let ctx = Context {
        progress,
        scene,
        light: &light,
        shading: &shading,
        spp: opts.spp.max(1),
        max_depth: opts.max_depth.max(1),
        seed: opts.seed,
        width: w,
    };
    let mut img = Image::new(w, h);
    if w == 0 || h == 0 {
        return img;
    }
    img.stats = img
        .pixels
        .par_chunks_mut(w)
        .enumerate()
        .map(|(y, row)| {
            let mut stats = RenderStats::default();
            for (x, px) in row.iter_mut().enumerate() {
                *px = ctx.pixel(x, y, &mut stats);
            }
            stats
        })
        .reduce(RenderStats::default, |a, b| RenderStats {
            camera_rays: a.camera_rays + b.camera_rays,
            rays: a.rays + b.rays,
            nonfinite: a.nonfinite + b.nonfinite,
        });
    img
}

/// The random stream of pixel `index` for `seed`: a PCG64 whose state and
/// stream are both hashed from the pair (so that neighbouring pixels'
/// streams are unrelated).
#[must_use]
pub fn pixel_rng(seed: u64, index: u64) -> Pcg64 {
    let a = hash64(seed ^ 0x6c6f_6265_7265_6e64);
    let b = hash64(index ^ a.rotate_left(23));
    let c = hash64(b ^ 0x9e37_79b9_7f4a_7c15);
    let d = hash64(a ^ c);
    Pcg64::new(
        (u128::from(a) << 64) | u128::from(b),
        (u128::from(c) << 64) | u128::from(d ^ index),
    )
}

/// Progress is reported every this many samples of a pixel (and at its end).
const PROGRESS_STEP: u64 = 4096;

struct Context<'a> {
    progress: &'a (dyn Fn(u64) + Sync),
    scene: &'a Scene,
    light: &'a Light,
    shading: &'a [ObjectShading<'a>],
    spp: u64,
    max_depth: u32,
    seed: u64,
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
    fn pixel(&self, x: usize, y: usize, stats: &mut RenderStats) -> Rgb {
        let mut rng = pixel_rng(self.seed, (y * self.width + x) as u64);
        let mut sum = Rgb::ZERO;
        let mut pending = 0u64;
        for _ in 0..self.spp {
            let (jx, jy): (f64, f64) = (rng.random(), rng.random());
            let ray = self.scene.camera.ray(x as f64 + jx, y as f64 + jy);
            stats.camera_rays += 1;
            let v = self.radiance(ray, &mut rng, stats);
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
        sum / self.spp as f64
    }

    /// Radiance arriving along a camera ray.
    fn radiance(&self, ray: crate::geometry::Ray, rng: &mut Pcg64, stats: &mut RenderStats) -> Rgb {
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
            match strategy {
                Strategy::Light => {
                    points[0] = [0.0, rng.random(), rng.random()];
                }
                Strategy::Mis(m) if m.form == MisForm::MultiSample => {
                    points[1] = [0.0, rng.random(), rng.random()];
                    points[0] = [rng.random(), rng.random(), rng.random()];
                }
                _ => points[0] = [rng.random(), rng.random(), rng.random()],
            }
            let mut vis = SceneVisibility {
                scene: self.scene,
                p: hit.p,
                ng,
                rays: 0,
                hit: None,
            };
            let e = est.estimate(&sp, self.light, &points[..k], &mut vis);
            l += beta * e.value;
            if !go_on {
                stats.rays += vis.rays;
                break;
            }
            // Continue with the estimate's BSDF sample, or draw one (light
            // sampling alone, or one-sample MIS that chose the light).
            let drawn = e.bsdf.or_else(|| {
                let uc: f64 = rng.random();
                let u = DVec2::new(rng.random(), rng.random());
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
                if q <= 0.0 || rng.random::<f64>() >= q {
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
