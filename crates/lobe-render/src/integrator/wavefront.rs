//! The batch loop: direct lighting in blocks of [`BLOCK`] samples, the BSDF
//! sampled and evaluated by [`lobe::batch::BatchSampler`] (f32 lanes,
//! structure of arrays) per object, the environment looked up once per
//! direction ([`lobe::envmap::EnvMap::lookup`], [`lobe::envmap::EnvMap::sample_lookup`]),
//! shadow rays traced for the whole block. See the parent module's doc
//! ("Batch loop") for what it covers and how it is checked.

use super::{Context, FirstBounce, Moments, RenderStats, dims, pixel_seed};
use crate::ray_block::{HitBlock, NO_HIT, RayBlock, Vec3Block, spawn_many};
use crate::scene::{Scene, Shape};
use glam::{DVec2, DVec3};
use lobe::batch::{
    BatchSampler, Dirs, DirsMut, EvalPdfOutput, RgbMut, SampleInput, SampleOutput, SimdLevel, Step,
};
use lobe::envmap::{EnvLookup, EnvMap};
use lobe::estimator::{Allocation, Heuristic, MisForm, Pilot, Strategy};
use lobe::math::{Rgb, luminance};
use lobe::sequence::{Sequence, SobolKeys, hash64, pair_point_seeded, pair_seed, sobol_pairs};
use lobe::{BsdfStrategy, Frame};
use std::sync::atomic::Ordering;

/// Samples shaded together: camera rays, then every BSDF draw of the block
/// in one [`BatchSampler::sample`] call per object, every light draw in one
/// [`BatchSampler::eval_pdf`] call per object, then the shadow rays.
pub const BLOCK: usize = 256;

/// The technique of a render, as the batch loop runs it.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    /// One BSDF draw.
    Bsdf,
    /// One light draw from the plain distribution.
    Light,
    /// One BSDF and one compensated light draw, weighted by the heuristic.
    Mis(Heuristic),
    /// Adaptive MIS: per pixel, as the allocation says.
    Adaptive,
}

/// What one of a sample's two draws is (a plain `u8`: the loop compares
/// them often).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
enum Slot {
    Unused,
    Bsdf,
    /// A light draw from the plain distribution.
    Light,
    /// A light draw from the MIS-compensated distribution.
    LightCompensated,
}

/// A pixel's draws and how they combine.
#[derive(Debug, Clone, Copy, PartialEq)]
struct PixelPlan {
    slots: [Slot; 2],
    /// `None`: the mean of the draws; `Some(h)`: slot 0 (BSDF) and slot 1
    /// (compensated light) weighted by `h`.
    mis: Option<Heuristic>,
}

/// The batch loop's state for one render: a batch sampler per object.
#[derive(Debug)]
pub(super) struct Batch<'a> {
    samplers: Vec<BatchSampler>,
    kind: Kind,
    env: &'a EnvMap,
    /// The SIMD level of the block's Sobol points (the BSDF kernels').
    level: SimdLevel,
    /// Per object, the film box outside of which no camera ray meets it
    /// ([`crate::camera::Camera::film_bounds`] of a sphere's bounding box),
    /// or `None` (planes, meshes, a sphere behind or around the camera).
    film_bounds: Vec<Option<[f64; 4]>>,
    /// Whether a material of the scene chooses a lobe (reads `uc`).
    lobe_choice: bool,
}

/// Why the batch loop does not render `scene` with `strategy` and
/// `max_depth` (the scalar loop does), or `None` when it does.
#[must_use]
pub fn batch_refusal(scene: &Scene, strategy: Strategy, max_depth: u32) -> Option<String> {
    Batch::new(scene, strategy, max_depth).err()
}

impl<'a> Batch<'a> {
    pub(super) fn new(
        scene: &'a Scene,
        strategy: Strategy,
        max_depth: u32,
    ) -> Result<Self, String> {
        if max_depth > 1 {
            return Err(format!(
                "max_depth {max_depth} (the batch loop does direct lighting, max_depth 1)"
            ));
        }
        let kind = match strategy {
            Strategy::Bsdf(_) => Kind::Bsdf,
            Strategy::Light => Kind::Light,
            Strategy::Mis(m) if m.n_bsdf == 1 && m.n_light == 1 => match m.form {
                MisForm::MultiSample => Kind::Mis(m.heuristic),
                MisForm::Adaptive => Kind::Adaptive,
                MisForm::OneSample => {
                    return Err(format!("one-sample MIS `{strategy}` (not batched)"));
                }
            },
            Strategy::Mis(_) => {
                return Err(format!(
                    "MIS `{strategy}` with other than one BSDF and one light draw (not batched)"
                ));
            }
        };
        let mut samplers = Vec::with_capacity(scene.objects.len());
        for (i, o) in scene.objects.iter().enumerate() {
            let m = &o.material;
            if m.reach().transmits {
                // Its frames keep the surface's orientation, and its light
                // samples cross the surface: the scalar loop's.
                return Err(format!(
                    "object {i} ({}): glass takes the scalar loop (the batch loop renders opaque materials)",
                    m.model_name()
                ));
            }
            if m.reach().delta {
                // Mirrors and smooth plastic: light sampling cannot reach a
                // delta part, so its paths continue by the BSDF sample
                // alone, which the scalar loop does.
                return Err(format!(
                    "object {i} ({}): a delta lobe takes the scalar loop",
                    m.model_name()
                ));
            }
            let est = super::object_shading(strategy, m).estimator;
            // The scalar path's BSDF strategy for the object; light sampling
            // only evaluates `f`, which every strategy's kernel gives.
            let s = match est.sampler() {
                Some(s) => s.strategy(),
                None => m.best_bsdf_strategy(),
            };
            let b = BatchSampler::new(m, s)
                .or_else(|e| match est.sampler() {
                    None => BatchSampler::new(m, BsdfStrategy::Brdf),
                    Some(_) => Err(e),
                })
                .map_err(|e| format!("object {i} ({}, {s}): {e}", m.model_name()))?;
            samplers.push(b);
        }
        let level = samplers
            .first()
            .map_or_else(SimdLevel::best, BatchSampler::level);
        let film_bounds = scene
            .objects
            .iter()
            .map(|o| match &o.shape {
                Shape::Sphere(s) => {
                    let r = DVec3::splat(s.radius * (1.0 + 1e-9));
                    scene.camera.film_bounds(s.center - r, s.center + r)
                }
                Shape::Plane(_) | Shape::Mesh(_) => None,
            })
            .collect();
        let lobe_choice = samplers.iter().any(BatchSampler::chooses_lobe);
        Ok(Batch {
            lobe_choice,
            samplers,
            kind,
            env: &scene.environment,
            level,
            film_bounds,
        })
    }

    fn plan(&self, mode: FirstBounce) -> PixelPlan {
        let mean = |slots| PixelPlan { slots, mis: None };
        let mis = |h| PixelPlan {
            slots: [Slot::Bsdf, Slot::LightCompensated],
            mis: Some(h),
        };
        let plain = Slot::Light;
        match (self.kind, mode) {
            (Kind::Bsdf, _) => mean([Slot::Bsdf, Slot::Unused]),
            (Kind::Light, _) => mean([plain, Slot::Unused]),
            (Kind::Mis(h), _) => mis(h),
            (Kind::Adaptive, FirstBounce::Allocated(Allocation::Bsdf)) => {
                mean([Slot::Bsdf, Slot::Bsdf])
            }
            (Kind::Adaptive, FirstBounce::Allocated(Allocation::Light)) => mean([plain, plain]),
            (Kind::Adaptive, _) => mis(Heuristic::Balance),
        }
    }
}

/// Per sample of a block that hits a surface facing the camera.
#[derive(Debug, Clone, Copy)]
struct Point {
    /// The sample's index in the block (its column is `RowBlock::px[m]`, its
    /// estimate goes to `RowBlock::value[m]`).
    m: u32,
    /// The object hit.
    obj: u32,
    p: DVec3,
    ng: DVec3,
    frame: Frame,
    wo: DVec3,
    plan: PixelPlan,
    /// The numbers of the two draws, `[uc, u₁, u₂]`.
    u: [[f64; 3]; 2],
}

/// Per draw (two per sample) of a block.
#[derive(Debug, Clone, Copy)]
struct Draw {
    /// What the draw is (its sample's plan's slot).
    slot: Slot,
    /// A BSDF draw: `wi` local; a light draw: the world direction.
    dir: DVec3,
    /// The light draw's local `wi`.
    wi: DVec3,
    /// The map at the draw's direction (read only when `ok`): a light
    /// draw's texel, an escaping BSDF draw's lookup.
    light: EnvLookup,
    /// BSDF draw: the weight `f cos / p`; light draw: `f`.
    f: Rgb,
    /// BSDF draw: its pdf; light draw: the BSDF strategy's pdf at `wi`.
    pdf: f64,
    ok: bool,
}

impl Default for Draw {
    fn default() -> Self {
        Draw {
            slot: Slot::Unused,
            dir: DVec3::ZERO,
            wi: DVec3::ZERO,
            light: EnvLookup::default(),
            f: Rgb::ZERO,
            pdf: 0.0,
            ok: false,
        }
    }
}

/// Reusable structure-of-arrays buffers of one row.
struct RowBlock {
    a: [Vec<f32>; 6],
    out: [Vec<f32>; 10],
    valid: Vec<u8>,
    /// The draw indices of every BSDF or light draw, by bucket `2 · object
    /// + (1 for a light draw)`: in each bucket the draws in draw order.
    buckets: Vec<Vec<u32>>,
    /// The block's Sobol pairs: per sample, the scramble keys of its
    /// [`PAIRS`] pairs, its index, and the points.
    pair_seeds: [Vec<SobolKeys>; PAIRS],
    pair_index: Vec<u32>,
    pair_x: [Vec<f64>; PAIRS],
    pair_y: [Vec<f64>; PAIRS],
    /// The seeds (pairs 1.. of [`PixelSeeds::all`]) and indices of the
    /// samples that hit.
    hit_seeds: [Vec<SobolKeys>; PAIRS],
    hit_index: Vec<u32>,
    /// The block's light draws `(compensated, u)`, their results, and
    /// (here and for `bsdf_dirs`) their draw indices.
    light_u: Vec<(bool, DVec2)>,
    light_out: Vec<Option<(DVec3, EnvLookup)>>,
    draw_index: Vec<usize>,
    /// The escaping BSDF draws' world directions and the map there.
    bsdf_dirs: Vec<DVec3>,
    bsdf_env: Vec<EnvLookup>,
    /// The map's radiance where camera rays escape.
    miss_radiance: Vec<Rgb>,
    /// The block's film positions `(x, y)` in pixels.
    film: (Vec<f64>, Vec<f64>),
    /// Independent or stratified numbers: each sample's pair seeds, index,
    /// and its pixel's samples in the pass.
    each: Vec<(PixelSeeds, u64, u64)>,
    /// Each sample's pixel column, plan, and value (the map's radiance
    /// where its camera ray escapes, else its estimate).
    px: Vec<f64>,
    /// The block's pixels in order: `(column, samples of it)`.
    runs: Vec<(usize, usize)>,
    plans: Vec<PixelPlan>,
    value: Vec<Rgb>,
    /// The block's camera rays and their hits; then its shadow rays.
    rays: RayBlock,
    hits: HitBlock,
    /// The shadow rays' origins (the hit points), normals and directions,
    /// each ray's draw index, and whether it is blocked.
    shadow_p: Vec3Block,
    shadow_ng: Vec3Block,
    shadow_dir: Vec3Block,
    shadow_draw: Vec<usize>,
    blocked: Vec<bool>,
}

/// The pairs a sample of the batch loop draws: camera, BSDF direction,
/// lobe choice, light ([`PixelSeeds`] in this order).
const PAIRS: usize = 4;

impl RowBlock {
    fn new() -> Self {
        let v = || vec![0.0f32; 2 * BLOCK];
        RowBlock {
            a: std::array::from_fn(|_| v()),
            out: std::array::from_fn(|_| v()),
            valid: vec![0; 2 * BLOCK],
            buckets: Vec::new(),
            pair_seeds: std::array::from_fn(|_| Vec::with_capacity(BLOCK)),
            pair_index: Vec::with_capacity(BLOCK),
            pair_x: std::array::from_fn(|_| vec![0.0; BLOCK]),
            pair_y: std::array::from_fn(|_| vec![0.0; BLOCK]),
            hit_seeds: std::array::from_fn(|_| Vec::with_capacity(BLOCK)),
            hit_index: Vec::with_capacity(BLOCK),
            light_u: Vec::with_capacity(2 * BLOCK),
            light_out: Vec::with_capacity(2 * BLOCK),
            draw_index: Vec::with_capacity(2 * BLOCK),
            bsdf_dirs: Vec::with_capacity(2 * BLOCK),
            bsdf_env: Vec::with_capacity(2 * BLOCK),
            miss_radiance: Vec::with_capacity(BLOCK),
            film: (Vec::with_capacity(BLOCK), Vec::with_capacity(BLOCK)),
            each: Vec::with_capacity(BLOCK),
            px: Vec::with_capacity(BLOCK),
            runs: Vec::with_capacity(BLOCK),
            plans: Vec::with_capacity(BLOCK),
            value: Vec::with_capacity(BLOCK),
            rays: RayBlock::default(),
            hits: HitBlock::default(),
            shadow_p: Vec3Block::default(),
            shadow_ng: Vec3Block::default(),
            shadow_dir: Vec3Block::default(),
            shadow_draw: Vec::with_capacity(2 * BLOCK),
            blocked: Vec::with_capacity(2 * BLOCK),
        }
    }
}

/// A row's reusable buffers: its ray block, points and draws.
type RowBuffers = (RowBlock, Vec<Point>, Vec<Draw>);

thread_local! {
    /// A worker thread's row buffers, kept between the rows it renders (a
    /// row's would otherwise be allocated and zeroed for each row).
    static ROW_BUFFERS: std::cell::Cell<Option<RowBuffers>> = const { std::cell::Cell::new(None) };
}

/// The pair seeds of one pixel.
#[derive(Debug, Clone, Copy)]
struct PixelSeeds {
    camera: u64,
    bsdf_u: u64,
    bsdf_uc: u64,
    light: u64,
}

impl PixelSeeds {
    fn all(&self) -> [u64; PAIRS] {
        [self.camera, self.bsdf_u, self.bsdf_uc, self.light]
    }
}

impl Batch<'_> {
    /// Samples `0..n` of the pass of every pixel `x` of row `y`, `(n, mode)
    /// = plan(x)` (its count and first-bounce mode), the pixel sums (not
    /// divided) into `row`. With `pilots` (adaptive MIS's pilot, every mode
    /// [`FirstBounce::Pilot`]), each sample's draws are recorded in its
    /// pixel's [`Pilot`] as [`lobe::estimator::ShadingEstimator::estimate_pilot`]
    /// records them; with `moments`, each sample's value in its pixel's
    /// [`Moments`].
    ///
    /// The whole row runs at the block's SIMD level ([`SimdLevel::run`]):
    /// the glue between the batch calls is compiled with the level's
    /// instructions too (the same arithmetic, so the same bits).
    pub(super) fn row(
        &self,
        ctx: &Context<'_>,
        y: usize,
        row: &mut [Rgb],
        plan: &(dyn Fn(usize) -> (u64, FirstBounce) + Sync),
        pilots: Option<&mut [Pilot]>,
        moments: Option<&mut [Moments]>,
    ) -> RenderStats {
        struct Row<'r, 'b, 'c> {
            batch: &'r Batch<'b>,
            ctx: &'r Context<'c>,
            y: usize,
            row: &'r mut [Rgb],
            plan: &'r (dyn Fn(usize) -> (u64, FirstBounce) + Sync),
            pilots: Option<&'r mut [Pilot]>,
            moments: Option<&'r mut [Moments]>,
            stats: &'r mut RenderStats,
        }
        impl Step for Row<'_, '_, '_> {
            #[inline(always)]
            fn run(self) {
                *self.stats = self.batch.row_at_level(
                    self.ctx,
                    self.y,
                    self.row,
                    self.plan,
                    self.pilots,
                    self.moments,
                );
            }
        }
        let mut stats = RenderStats::default();
        self.level.run(Row {
            batch: self,
            ctx,
            y,
            row,
            plan,
            pilots,
            moments,
            stats: &mut stats,
        });
        stats
    }

    #[inline(always)]
    fn row_at_level(
        &self,
        ctx: &Context<'_>,
        y: usize,
        row: &mut [Rgb],
        plan: &(dyn Fn(usize) -> (u64, FirstBounce) + Sync),
        mut pilots: Option<&mut [Pilot]>,
        mut moments: Option<&mut [Moments]>,
    ) -> RenderStats {
        let mut stats = RenderStats::default();
        // The thread's buffers from its last row (every block writes what
        // it reads), or new ones.
        let (mut rows, mut pts, mut draws) = ROW_BUFFERS.take().unwrap_or_else(|| {
            (
                RowBlock::new(),
                Vec::with_capacity(BLOCK),
                vec![Draw::default(); 2 * BLOCK],
            )
        });
        // The next sample: pixel `x`'s sample `i0` of `n` (its count).
        let (mut x, mut i0) = (0usize, 0u64);
        while x < row.len() {
            pts.clear();
            let sobol = ctx.sequence == Sequence::Sobol;
            // The block's samples, pixel by pixel: each one's column, plan
            // and index in its pixel's sequence, and (Sobol) its pairs'
            // seeds; independent or stratified numbers: its seeds.
            for v in &mut rows.pair_seeds {
                v.clear();
            }
            rows.pair_index.clear();
            rows.px.clear();
            rows.runs.clear();
            rows.plans.clear();
            rows.each.clear();
            let mut filled = 0usize;
            while filled < BLOCK && x < row.len() {
                // (A pixel's plan is asked again when its samples go on in
                // the next block.)
                let (n, mode) = plan(x);
                let run = ((n - i0) as usize).min(BLOCK - filled);
                if run > 0 {
                    let seeds = pixel_seeds(ctx, x, y);
                    let plan = self.plan(mode);
                    rows.px.extend(std::iter::repeat_n(x as f64, run));
                    rows.runs.push((x, run));
                    rows.plans.extend(std::iter::repeat_n(plan, run));
                    for i in i0..i0 + run as u64 {
                        let index = match ctx.sequence {
                            Sequence::Stratified => i,
                            Sequence::Sobol | Sequence::Independent => ctx.pass * n + i,
                        };
                        if sobol {
                            debug_assert!(index <= u64::from(u32::MAX));
                            rows.pair_index.push(index as u32);
                        } else {
                            rows.each.push((seeds, index, n));
                        }
                    }
                    if sobol {
                        for (v, s) in rows.pair_seeds.iter_mut().zip(seeds.all()) {
                            v.extend(std::iter::repeat_n(SobolKeys::new(s), run));
                        }
                    }
                    filled += run;
                    i0 += run as u64;
                }
                if i0 == n {
                    x += 1;
                    i0 = 0;
                }
            }
            if filled == 0 {
                continue;
            }
            // The camera pairs of every sample; the other pairs (below)
            // only for the samples that hit.
            let n = rows.px.len();
            let (jx, jy) = (&mut rows.pair_x[0][..n], &mut rows.pair_y[0][..n]);
            if sobol {
                sobol_pairs(self.level, &rows.pair_seeds[0], &rows.pair_index, jx, jy);
            } else {
                for ((&(seeds, index, n), x), y) in rows.each.iter().zip(jx).zip(jy) {
                    [*x, *y] = seeded_pair(ctx, &seeds, n, index, 0).to_array();
                }
            }
            // The block's camera rays, traced together.
            rows.film.0.clear();
            rows.film.1.clear();
            let yf = y as f64;
            let (jx, jy) = (&rows.pair_x[0][..n], &rows.pair_y[0][..n]);
            rows.film
                .0
                .extend(rows.px.iter().zip(jx).map(|(&x, &j)| x + j));
            rows.film.1.extend(jy.iter().map(|&j| yf + j));
            self.camera_points(ctx, y, &mut pts, &mut rows, &mut stats);
            if sobol {
                // The shading pairs of the samples that hit, compacted: a
                // gather per array, written by index (no `push`es).
                let n = pts.len();
                rows.hit_index.resize(n, 0);
                for (h, pt) in rows.hit_index.iter_mut().zip(&pts) {
                    *h = rows.pair_index[pt.m as usize];
                }
                for p in self.shading_pairs() {
                    let (dst, src) = (&mut rows.hit_seeds[p], &rows.pair_seeds[p]);
                    dst.resize(n, SobolKeys::default());
                    for (d, pt) in dst.iter_mut().zip(&pts) {
                        *d = src[pt.m as usize];
                    }
                }
                for p in self.shading_pairs() {
                    sobol_pairs(
                        self.level,
                        &rows.hit_seeds[p],
                        &rows.hit_index,
                        &mut rows.pair_x[p][..n],
                        &mut rows.pair_y[p][..n],
                    );
                }
                for (h, pt) in pts.iter_mut().enumerate() {
                    let (px, py) = (&rows.pair_x, &rows.pair_y);
                    self.assign_u(pt, |p| DVec2::new(px[p][h], py[p][h]));
                }
            }
            self.shade(
                ctx.scene,
                &pts,
                &mut draws,
                &mut rows,
                &mut stats,
                pilots.as_deref_mut(),
            );
            // Each pixel's values added to its sum in sample order, the sum
            // held in a register over the pixel's run.
            let mut m = 0;
            for &(x, run) in &rows.runs {
                let mut acc = row[x];
                for v in &rows.value[m..m + run] {
                    if v.is_finite() {
                        acc += *v;
                    } else {
                        stats.nonfinite += 1;
                    }
                }
                row[x] = acc;
                if let Some(mo) = moments.as_deref_mut() {
                    for v in &rows.value[m..m + run] {
                        mo[x].add(*v);
                    }
                }
                m += run;
            }
            (ctx.progress)(filled as u64);
            // Cancelled: the row is left unfinished (its pass is
            // abandoned, see `render_rows`).
            if ctx.cancel.load(Ordering::Relaxed) {
                break;
            }
        }
        ROW_BUFFERS.set(Some((rows, pts, draws)));
        stats
    }

    /// The camera rays of a block of row `y` (film positions `rows.film`), their
    /// hits and shading frames: a [`Point`] in `pts` per sample that hits
    /// and faces the camera, in sample order; `rows.value` the map's
    /// radiance for a sample whose ray escapes, else zero. With
    /// independent or stratified numbers (`rows.each`) the points also get
    /// their draws' numbers.
    #[inline(always)]
    fn camera_points(
        &self,
        ctx: &Context<'_>,
        y: usize,
        pts: &mut Vec<Point>,
        rows: &mut RowBlock,
        stats: &mut RenderStats,
    ) {
        let n = rows.film.0.len();
        ctx.scene
            .camera
            .rays_many(self.level, &rows.film.0, &rows.film.1, &mut rows.rays);
        stats.camera_rays += n as u64;
        stats.rays += n as u64;
        // The objects whose film box the block's pixels overlap (the block
        // covers [x0, x1 + 1) × [y, y + 1) of the film).
        let (x0, x1) = (rows.px[0], rows.px[n - 1] + 1.0);
        let y = y as f64;
        let may_hit = |k: usize| {
            self.film_bounds[k]
                .is_none_or(|b| x1 >= b[0] && x0 <= b[1] && y + 1.0 >= b[2] && y <= b[3])
        };
        ctx.scene
            .intersect_many_where(self.level, &rows.rays, &mut rows.hits, may_hit);
        rows.bsdf_dirs.clear();
        rows.draw_index.clear();
        rows.value.clear();
        rows.value.resize(n, Rgb::ZERO);
        // (Slices borrowed once, see `Vec3Block::view`.)
        let h = &rows.hits;
        let (obj, hp, hng, hns) = (&h.obj[..n], h.p.view(n), h.ng.view(n), h.ns.view(n));
        let (dirs, plans) = (rows.rays.dir.view(n), &rows.plans[..n]);
        for m in 0..n {
            let dir = dirs.get(m);
            if obj[m] == NO_HIT {
                rows.bsdf_dirs.push(dir);
                rows.draw_index.push(m);
                continue;
            }
            // The scalar loop's normals (see `Context::radiance`).
            let wo_world = -dir;
            let (hng, hns) = (hng.get(m), hns.get(m));
            let ng = if hng.dot(wo_world) < 0.0 { -hng } else { hng };
            let mut ns = if hns.dot(ng) < 0.0 { -hns } else { hns };
            if ns.dot(wo_world) <= 0.0 {
                ns = ng;
            }
            let frame = Frame::from_normal(ns);
            let wo = frame.to_local(wo_world);
            if wo.z <= 0.0 {
                continue;
            }
            let mut pt = Point {
                m: m as u32,
                obj: obj[m],
                p: hp.get(m),
                ng,
                frame,
                wo,
                plan: plans[m],
                u: [[0.0; 3]; 2],
            };
            if let Some(&(seeds, index, n)) = rows.each.get(m) {
                self.assign_u(&mut pt, |p| seeded_pair(ctx, &seeds, n, index, p));
            }
            pts.push(pt);
        }
        // The map's radiance where the rays escape.
        let e = rows.bsdf_dirs.len();
        rows.miss_radiance.resize(e, Rgb::ZERO);
        self.env
            .eval_many(&rows.bsdf_dirs, &mut rows.miss_radiance[..e]);
        for (&m, &l) in rows.draw_index.iter().zip(&rows.miss_radiance[..e]) {
            rows.value[m] = l;
        }
    }

    /// The pairs of [`PixelSeeds::all`] a sample that hits draws: all but
    /// the camera's, and not the lobe choice's when no material chooses a
    /// lobe (nothing reads it).
    fn shading_pairs(&self) -> impl Iterator<Item = usize> + use<> {
        let lobe_choice = self.lobe_choice;
        (1..PAIRS).filter(move |&p| p != 2 || lobe_choice)
    }

    /// The numbers of `pt`'s draws from its pairs (`pair(p)`, pair `p` of
    /// [`PixelSeeds::all`]), as the scalar loop takes them: the BSDF point
    /// `[bsdf_uc.x, bsdf_u]`, the light point `[bsdf_uc.y, light]`; light
    /// sampling alone takes the light point.
    #[inline(always)]
    fn assign_u(&self, pt: &mut Point, pair: impl Fn(usize) -> DVec2) {
        let plan = pt.plan;
        let light_alone = matches!(self.kind, Kind::Light);
        // Light draws do not read `uc`, nor a BSDF draw of a scene where no
        // material chooses a lobe.
        let uc = if self.lobe_choice && plan.slots.contains(&Slot::Bsdf) {
            pair(2)
        } else {
            DVec2::ZERO
        };
        let bsdf_point = || {
            let u = pair(1);
            [uc.x, u.x, u.y]
        };
        let light_point = || {
            let u = pair(3);
            [uc.y, u.x, u.y]
        };
        pt.u[0] = if light_alone {
            light_point()
        } else {
            bsdf_point()
        };
        if plan.slots[1] != Slot::Unused {
            pt.u[1] = light_point();
        }
    }

    /// The draws of a block: BSDF samples and light samples' `f` and pdf
    /// in batches per object, then the shadow rays and the estimates (into
    /// `rows.value`, at each point's sample).
    #[inline(always)]
    fn shade(
        &self,
        scene: &Scene,
        pts: &[Point],
        draws: &mut [Draw],
        rows: &mut RowBlock,
        stats: &mut RenderStats,
        mut pilots: Option<&mut [Pilot]>,
    ) {
        // Light draws first: their directions, by sampling the map for the
        // whole block (`EnvMap::sample_lookup_many`).
        // A draw's bucket: its object, then BSDF 0 / light 1.
        let buckets = 2 * self.samplers.len();
        rows.buckets.resize_with(buckets, Vec::new);
        for b in &mut rows.buckets {
            b.clear();
        }
        let bucket = |obj: u32, light: bool| 2 * obj as usize + usize::from(light);
        rows.light_u.clear();
        rows.draw_index.clear();
        let draws = &mut draws[..2 * pts.len()];
        for (i, (pt, pair)) in pts.iter().zip(draws.chunks_exact_mut(2)).enumerate() {
            for (s, d) in pair.iter_mut().enumerate() {
                // Every other field of a draw is written before it is read
                // (a light draw that gets no direction stays not `ok`).
                let slot = pt.plan.slots[s];
                d.slot = slot;
                d.ok = false;
                match slot {
                    Slot::Unused => {}
                    Slot::Bsdf => {
                        rows.buckets[bucket(pt.obj, false)].push((2 * i + s) as u32);
                    }
                    Slot::Light | Slot::LightCompensated => {
                        let compensated = slot == Slot::LightCompensated;
                        rows.light_u
                            .push((compensated, DVec2::new(pt.u[s][1], pt.u[s][2])));
                        rows.draw_index.push(2 * i + s);
                    }
                }
            }
        }
        let n = rows.light_u.len();
        rows.light_out.resize(n, None);
        self.env
            .sample_lookup_many(&rows.light_u, &mut rows.light_out[..n]);
        for (&di, out) in rows.draw_index.iter().zip(&rows.light_out[..n]) {
            let pt = &pts[di / 2];
            let Some((dir, l)) = *out else {
                continue;
            };
            let wi = pt.frame.to_local(dir);
            if wi.z <= 0.0 {
                continue;
            }
            let d = &mut draws[di];
            d.dir = dir;
            d.wi = wi;
            d.light = l;
            rows.buckets[bucket(pt.obj, true)].push(di as u32);
        }
        // One batch call per object and kind of draw.
        for b in 0..buckets {
            if !rows.buckets[b].is_empty() {
                self.batch_group(b, pts, draws, rows);
            }
        }
        // The shadow rays of the block, traced together: the BSDF draws'
        // (a failed draw when blocked), and the light draws' that carry
        // light (`f ≠ 0`).
        // Written by index into arrays of the most rays there can be, then
        // cut to the rays there are.
        let most = 2 * pts.len();
        rows.shadow_p.resize(most);
        rows.shadow_ng.resize(most);
        rows.shadow_dir.resize(most);
        rows.shadow_draw.resize(most, 0);
        let mut r = 0;
        let (mut sp, mut sng) = (rows.shadow_p.view_mut(most), rows.shadow_ng.view_mut(most));
        let (mut sdir, sdraw) = (
            rows.shadow_dir.view_mut(most),
            &mut rows.shadow_draw[..most],
        );
        for (i, (pt, pair)) in pts.iter().zip(draws.chunks_exact_mut(2)).enumerate() {
            for (s, d) in pair.iter_mut().enumerate() {
                if !d.ok {
                    continue;
                }
                let dir = match d.slot {
                    Slot::Bsdf => {
                        // The world direction, kept for the lookup.
                        d.dir = pt.frame.to_world(d.dir).normalize();
                        d.dir
                    }
                    Slot::Light | Slot::LightCompensated if d.f != Rgb::ZERO => d.dir,
                    _ => continue,
                };
                sp.set(r, pt.p);
                sng.set(r, pt.ng);
                sdir.set(r, dir);
                sdraw[r] = 2 * i + s;
                r += 1;
            }
        }
        rows.shadow_p.truncate(r);
        rows.shadow_ng.truncate(r);
        rows.shadow_dir.truncate(r);
        rows.shadow_draw.truncate(r);
        stats.rays += r as u64;
        spawn_many(
            self.level,
            &rows.shadow_p,
            &rows.shadow_ng,
            &rows.shadow_dir,
            &mut rows.rays,
        );
        scene.occluded_many(self.level, &rows.rays, &mut rows.blocked);
        // The map at the BSDF directions that escape, for the whole block
        // (`EnvMap::lookup_many`); a blocked draw has no light.
        rows.bsdf_dirs.clear();
        rows.draw_index.clear();
        for (&di, &blocked) in rows.shadow_draw.iter().zip(&rows.blocked) {
            let d = &mut draws[di];
            if blocked {
                d.ok = false;
            } else if d.slot == Slot::Bsdf {
                rows.bsdf_dirs.push(d.dir);
                rows.draw_index.push(di);
            }
        }
        let n = rows.bsdf_dirs.len();
        rows.bsdf_env.resize(n, EnvLookup::default());
        self.env
            .lookup_many(&rows.bsdf_dirs, &mut rows.bsdf_env[..n]);
        for (&di, &l) in rows.draw_index.iter().zip(&rows.bsdf_env[..n]) {
            draws[di].light = l;
        }
        // The estimates, in sample order.
        let (px, value) = (&rows.px[..], &mut rows.value[..]);
        for (pt, pair) in pts.iter().zip(draws.chunks_exact(2)) {
            let mut sum = Rgb::ZERO;
            let mut n = 0.0;
            let m = pt.m as usize;
            let mut pilot = pilots.as_deref_mut().map(|p| &mut p[px[m] as usize]);
            if let Some(p) = pilot.as_deref_mut() {
                p.samples += 1;
            }
            for d in pair {
                if d.slot == Slot::Unused {
                    continue;
                }
                n += 1.0;
                if !d.ok {
                    continue;
                }
                // (Unoccluded: a blocked draw is not `ok`; a BSDF draw that
                // is `ok` escapes and was looked up.)
                let l = d.light;
                match d.slot {
                    Slot::Unused => {}
                    Slot::Bsdf => {
                        let v = d.f * l.radiance;
                        if let Some(p) = pilot.as_deref_mut() {
                            let q = d.pdf + l.pdf_compensated;
                            p.record(luminance(v) * d.pdf, d.pdf, l.pdf_compensated, l.pdf, q);
                        }
                        sum += match pt.plan.mis {
                            None => v,
                            Some(h) => v * h.weight(d.pdf, l.pdf_compensated),
                        };
                    }
                    Slot::Light | Slot::LightCompensated => {
                        if d.f == Rgb::ZERO {
                            continue;
                        }
                        let v = d.f * l.radiance * d.wi.z;
                        if let Some(p) = pilot.as_deref_mut() {
                            let q = d.pdf + l.pdf_compensated;
                            p.record(luminance(v), d.pdf, l.pdf_compensated, l.pdf, q);
                        }
                        let p = if d.slot == Slot::LightCompensated {
                            l.pdf_compensated
                        } else {
                            l.pdf
                        };
                        sum += match pt.plan.mis {
                            None => v / p,
                            Some(h) => v * (h.weight(p, d.pdf) / p),
                        };
                    }
                }
            }
            value[m] = match pt.plan.mis {
                None if n > 1.0 => sum / n,
                _ => sum,
            };
        }
    }

    /// The draws of bucket `b` (`rows.buckets[b]`, all of object `b / 2`
    /// and of one kind) in one batch call: BSDF draws (`b` even) sampled,
    /// light draws evaluated.
    #[inline(always)]
    fn batch_group(&self, b: usize, pts: &[Point], draws: &mut [Draw], rows: &mut RowBlock) {
        let (sampler, bsdf) = (&self.samplers[b / 2], b.is_multiple_of(2));
        // One lane per draw of the bucket (never empty).
        let keys = &rows.buckets[b];
        let m = keys.len();
        {
            let [a0, a1, a2, a3, a4, a5] = &mut rows.a;
            let (a0, a1, a2) = (&mut a0[..m], &mut a1[..m], &mut a2[..m]);
            let (a3, a4, a5) = (&mut a3[..m], &mut a4[..m], &mut a5[..m]);
            for (k, &di) in keys.iter().enumerate() {
                let di = di as usize;
                let (pt, s) = (&pts[di / 2], di % 2);
                debug_assert_eq!(draws[di].slot == Slot::Bsdf, bsdf);
                a0[k] = pt.wo.x as f32;
                a1[k] = pt.wo.y as f32;
                a2[k] = pt.wo.z as f32;
                if bsdf {
                    a3[k] = pt.u[s][1] as f32;
                    a4[k] = pt.u[s][2] as f32;
                    a5[k] = pt.u[s][0] as f32;
                } else {
                    let wi = draws[di].wi;
                    a3[k] = wi.x as f32;
                    a4[k] = wi.y as f32;
                    a5[k] = wi.z as f32;
                }
            }
        }
        let [a0, a1, a2, a3, a4, a5] = &rows.a;
        let [o0, o1, o2, o3, o4, o5, o6, o7, o8, o9] = &mut rows.out;
        let wo = Dirs {
            x: &a0[..m],
            y: &a1[..m],
            z: &a2[..m],
        };
        if bsdf {
            sampler
                .sample(
                    SampleInput {
                        wo,
                        u1: &a3[..m],
                        u2: &a4[..m],
                        uc: Some(&a5[..m]),
                    },
                    SampleOutput {
                        wi: DirsMut {
                            x: &mut o0[..m],
                            y: &mut o1[..m],
                            z: &mut o2[..m],
                        },
                        f: RgbMut {
                            r: &mut o3[..m],
                            g: &mut o4[..m],
                            b: &mut o5[..m],
                        },
                        pdf: &mut o6[..m],
                        weight: RgbMut {
                            r: &mut o7[..m],
                            g: &mut o8[..m],
                            b: &mut o9[..m],
                        },
                        valid: &mut rows.valid[..m],
                    },
                )
                .expect("equal lengths, uc given");
        } else {
            sampler
                .eval_pdf(
                    wo,
                    Dirs {
                        x: &a3[..m],
                        y: &a4[..m],
                        z: &a5[..m],
                    },
                    EvalPdfOutput {
                        f: RgbMut {
                            r: &mut o3[..m],
                            g: &mut o4[..m],
                            b: &mut o5[..m],
                        },
                        pdf: &mut o6[..m],
                    },
                )
                .expect("equal lengths");
        }
        let o: [&[f32]; 10] = std::array::from_fn(|c| &rows.out[c][..m]);
        let valid = &rows.valid[..m];
        for (k, &di) in keys.iter().enumerate() {
            let di = di as usize;
            debug_assert_eq!(draws[di].slot == Slot::Bsdf, bsdf);
            let d = &mut draws[di];
            let rgb = |c: usize| {
                Rgb::new(
                    f64::from(o[c][k]),
                    f64::from(o[c + 1][k]),
                    f64::from(o[c + 2][k]),
                )
            };
            if bsdf {
                d.ok = valid[k] == 1;
                d.dir = DVec3::new(f64::from(o[0][k]), f64::from(o[1][k]), f64::from(o[2][k]));
                d.f = rgb(7);
            } else {
                d.ok = true;
                d.f = rgb(3);
            }
            d.pdf = f64::from(o[6][k]);
        }
    }
}

/// Pair `p` of [`PixelSeeds::all`] for sample `index` of a pixel with `n`
/// samples in the pass, drawn alone (independent or stratified numbers).
fn seeded_pair(ctx: &Context<'_>, seeds: &PixelSeeds, n: u64, index: u64, p: usize) -> DVec2 {
    DVec2::from_array(pair_point_seeded(ctx.sequence, seeds.all()[p], n, index))
}

/// The pair seeds of pixel `(x, y)` in `ctx`'s pass.
fn pixel_seeds(ctx: &Context<'_>, x: usize, y: usize) -> PixelSeeds {
    let ps = pixel_seed(ctx.seed, (y * ctx.width + x) as u64);
    let seed = match ctx.sequence {
        Sequence::Stratified => hash64(ps ^ hash64(ctx.pass)),
        Sequence::Sobol | Sequence::Independent => ps,
    };
    PixelSeeds {
        camera: pair_seed(seed, dims::CAMERA),
        bsdf_u: pair_seed(seed, dims::bsdf_u(0)),
        bsdf_uc: pair_seed(seed, dims::bsdf_uc(0)),
        light: pair_seed(seed, dims::light(0)),
    }
}
