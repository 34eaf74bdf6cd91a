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
//! * **MIS** (Veach's multi-sample form with one sample per technique):
//!   both of the above, each weighted by the balance heuristic
//!   `p_t / (p_b + p_l)` (`mis`) or the power heuristic
//!   `p_t² / (p_b² + p_l²)` (`mis-power`), where the BSDF technique is
//!   `vndf` when the material has it, else `brdf`, and the light technique
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
//! At every vertex, the same technique: light sampling adds next-event
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

use crate::scene::Scene;
use glam::DVec2;
use lobe::envmap::EnvMap;
use lobe::estimator::Heuristic;
use lobe::math::Rgb;
use lobe::sequence::hash64;
use lobe::{Frame, Material, Strategy};
use rand::RngExt;
use rand_pcg::Pcg64;
use rayon::prelude::*;

use crate::geometry::spawn_ray;

/// How the reflected radiance is estimated (the scene's `strategy`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// BSDF sampling by a strategy (falls back to `brdf` per object).
    Bsdf(Strategy),
    /// Light sampling of the environment map alone.
    Light,
    /// BSDF and light sampling combined by multi-sample MIS, one sample each.
    Mis(Heuristic),
}

impl Method {
    /// Every accepted name, for help and error messages.
    pub const NAMES: &'static str =
        "uniform, cosine, brdf, vndf, spherical-caps, bounded-vndf, light, mis, mis-power";

    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Method::Bsdf(s) => s.name(),
            Method::Light => "light",
            Method::Mis(Heuristic::Balance) => "mis",
            Method::Mis(Heuristic::Power) => "mis-power",
        }
    }

    /// Every method, in [`Method::NAMES`] order.
    #[must_use]
    pub fn all() -> Vec<Method> {
        let mut v: Vec<Method> = Strategy::ALL.into_iter().map(Method::Bsdf).collect();
        v.extend([
            Method::Light,
            Method::Mis(Heuristic::Balance),
            Method::Mis(Heuristic::Power),
        ]);
        v
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Method {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Method::all()
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| format!("unknown strategy `{s}`, expected one of: {}", Method::NAMES))
    }
}

/// What to render: samples per pixel, the method, the seed, the path
/// depth, and the thread count.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderOptions {
    /// Samples (camera rays) per pixel, at least 1.
    pub spp: u32,
    pub method: Method,
    pub seed: u64,
    /// 1 = direct lighting; more adds bounces. At least 1.
    pub max_depth: u32,
    /// Threads of a local pool; `None` runs on rayon's current pool.
    pub threads: Option<usize>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            spp: 64,
            method: Method::Mis(Heuristic::Balance),
            seed: 1,
            max_depth: 1,
            threads: None,
        }
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

/// How one object is shaded under a [`Method`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectPlan {
    /// The strategy that draws BSDF samples (for MIS, and for continuing
    /// paths).
    pub bsdf: Strategy,
    /// Whether light samples (next-event estimation) are taken.
    pub light: bool,
    /// How a BSDF-sampled ray that escapes to the environment counts.
    pub escape: Escape,
}

/// The weight of the environment seen by a BSDF-sampled ray.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Escape {
    /// In full (BSDF sampling alone).
    Full,
    /// Not at all (light sampling alone gives the direct light).
    None,
    /// MIS-weighted against light sampling.
    Mis(Heuristic),
}

/// The plan for a material under `method` (with the `brdf` fallback).
#[must_use]
pub fn plan(method: Method, m: &Material) -> ObjectPlan {
    match method {
        Method::Bsdf(s) => ObjectPlan {
            bsdf: if m.check(s).is_ok() {
                s
            } else {
                Strategy::Brdf
            },
            light: false,
            escape: Escape::Full,
        },
        Method::Light => ObjectPlan {
            bsdf: m.best_bsdf_strategy(),
            light: true,
            escape: Escape::None,
        },
        Method::Mis(h) => ObjectPlan {
            bsdf: m.best_bsdf_strategy(),
            light: true,
            escape: Escape::Mis(h),
        },
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

/// The objects on which `method`'s BSDF strategy falls back to `brdf`.
#[must_use]
pub fn fallbacks(scene: &Scene, method: Method) -> Vec<Fallback> {
    let Method::Bsdf(s) = method else {
        return Vec::new();
    };
    scene
        .objects
        .iter()
        .enumerate()
        .filter_map(|(i, o)| {
            let used = plan(method, &o.material).bsdf;
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
/// written in place; `progress` is called after each row with the number of
/// pixels it finished (they add up to `width × height`).
#[must_use]
pub fn render(scene: &Scene, opts: &RenderOptions, progress: impl Fn(u64) + Sync) -> Image {
    if let Some(n) = opts.threads
        && let Ok(pool) = rayon::ThreadPoolBuilder::new().num_threads(n).build()
    {
        return pool.install(|| render_on_pool(scene, opts, &progress));
    }
    render_on_pool(scene, opts, &progress)
}

fn render_on_pool(scene: &Scene, opts: &RenderOptions, progress: &(impl Fn(u64) + Sync)) -> Image {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let plans: Vec<ObjectPlan> = scene
        .objects
        .iter()
        .map(|o| plan(opts.method, &o.material))
        .collect();
    let ctx = Context {
        scene,
        env: &scene.environment,
        plans: &plans,
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
            progress(row.len() as u64);
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

struct Context<'a> {
    scene: &'a Scene,
    env: &'a EnvMap,
    plans: &'a [ObjectPlan],
    spp: u32,
    max_depth: u32,
    seed: u64,
    width: usize,
}

impl Context<'_> {
    fn pixel(&self, x: usize, y: usize, stats: &mut RenderStats) -> Rgb {
        let mut rng = pixel_rng(self.seed, (y * self.width + x) as u64);
        let mut sum = Rgb::ZERO;
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
        }
        sum / f64::from(self.spp)
    }

    /// Radiance arriving along a camera ray.
    fn radiance(&self, ray: crate::geometry::Ray, rng: &mut Pcg64, stats: &mut RenderStats) -> Rgb {
        stats.rays += 1;
        let Some((mut hit, mut obj)) = self.scene.intersect(&ray, f64::INFINITY) else {
            return self.env.eval(ray.dir);
        };
        let mut wo_world = -ray.dir;
        let mut beta = Rgb::ONE;
        let mut l = Rgb::ZERO;
        let mut depth = 1u32;
        loop {
            let m = &self.scene.objects[obj].material;
            let plan = &self.plans[obj];
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
            if plan.light {
                let u = DVec2::new(rng.random(), rng.random());
                // MIS draws from the compensated distribution, as lobe's
                // estimator does (`Light::sample_mis`).
                let drawn = match plan.escape {
                    Escape::Mis(_) => self.env.sample_compensated(u),
                    _ => self.env.sample(u),
                };
                if let Some((d, pl)) = drawn {
                    let wi = frame.to_local(d);
                    if wi.z > 0.0 {
                        let f = m.eval(wo, wi);
                        if f != Rgb::ZERO {
                            stats.rays += 1;
                            if !self.scene.occluded(&spawn_ray(hit.p, ng, d)) {
                                let w = match plan.escape {
                                    Escape::Mis(h) => h.weight(pl, m.pdf(plan.bsdf, wo, wi)),
                                    _ => 1.0,
                                };
                                l += beta * f * self.env.eval(d) * (wi.z * w / pl);
                            }
                        }
                    }
                }
            }
            let go_on = depth < self.max_depth;
            if plan.escape == Escape::None && !go_on {
                break;
            }
            let uc: f64 = rng.random();
            let u = DVec2::new(rng.random(), rng.random());
            let Some(s) = m.sample(plan.bsdf, wo, uc, u) else {
                break;
            };
            let d = frame.to_world(s.wi).normalize();
            let next = spawn_ray(hit.p, ng, d);
            stats.rays += 1;
            match self.scene.intersect(&next, f64::INFINITY) {
                None => {
                    let w = match plan.escape {
                        Escape::Full => 1.0,
                        Escape::None => 0.0,
                        Escape::Mis(h) => h.weight(s.pdf, self.env.pdf_compensated(d)),
                    };
                    if w > 0.0 {
                        l += beta * s.weight * self.env.eval(d) * w;
                    }
                    break;
                }
                Some((h2, o2)) => {
                    if !go_on {
                        break;
                    }
                    beta *= s.weight;
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
                    wo_world = -d;
                }
            }
        }
        l
    }
}
