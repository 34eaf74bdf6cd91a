//! Comparisons of strategies on one scene: renders at equal samples and at
//! equal time next to a high-spp reference, with their error metrics and
//! error maps (the numbers of `lobe compare` and of `lobe demo`'s
//! showcase; the figure is the caller's).
//!
//! * **RMSE** ([`rmse`]): the root mean square, over all pixels and the
//!   three channels, of the linear RGB difference from the reference.
//! * **Error map** ([`error_map`]): per pixel, the relative error of
//!   luminance `|Y − Y_ref| / (Y_ref + ε)`, with `ε` ([`error_epsilon`]) 1 %
//!   of the reference's mean luminance (so that black pixels do not divide
//!   by zero).
//! * **Equal time**: the budget is the time of `mis` (of the slowest strategy
//!   when `mis` is not compared) at `max(spp, MIN_EQUAL_TIME_SPP)`, measured
//!   without start-up; each strategy is rendered with the spp that bring its
//!   time within [`EQUAL_TIME_TOLERANCE`] of it ([`run_comparison`]).
//! * **Reference**: [`REFERENCE_STRATEGY`] at the reference spp, with the
//!   bitwise complement of the seed ([`reference_seed`]), so that its
//!   samples are independent of the compared renders' (the same seed would
//!   make `mis`'s first samples the reference's own and flatter its error).
//!
//! Nothing here prints or reads the system clock: progress goes to the
//! caller's [`Progress`] and times come from the caller's [`Clock`].

use crate::integrator::{Image, render};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use lobe::BsdfStrategy;
use lobe::estimator::{Heuristic, Strategy};
use lobe::math::luminance;
use lobe::progress::{Clock, Progress, timed};
use serde::Serialize;

/// The strategy of the reference render.
pub const REFERENCE_STRATEGY: Strategy = Strategy::mis(Heuristic::Balance);

/// Most samples per pixel an equal-time render may take.
pub const MAX_EQUAL_TIME_SPP: f64 = 1_048_576.0;

/// What to compare and how.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareSettings {
    pub strategies: Vec<Strategy>,
    /// Samples per pixel at equal samples.
    pub spp: u32,
    pub reference_spp: u32,
    pub seed: u64,
    /// The sample pattern of every render, the reference's included.
    pub sequence: lobe::sequence::Sequence,
    pub max_depth: u32,
    /// Threads of a local pool; `None` runs on rayon's current pool.
    pub threads: Option<usize>,
    /// Render the equal-time row too.
    pub equal_time: bool,
}

/// One render of a comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct Shot {
    pub strategy: Strategy,
    pub spp: u32,
    /// Seconds the render took on the caller's clock.
    pub time_s: f64,
    /// Against the reference (0 for the reference itself; NaN before it is
    /// measured).
    pub rmse: f64,
    pub image: Image,
}

/// The equal-time row.
#[derive(Debug, Clone, PartialEq)]
pub struct EqualTime {
    /// The time each strategy was given, in seconds.
    pub budget_s: f64,
    /// Where the budget comes from, e.g. `the time of mis at 16 spp`.
    pub budget_from: String,
    /// One shot per strategy, in the order of the equal-samples row. A shot
    /// whose spp equals the equal-samples spp is its pilot, not rendered
    /// again.
    pub shots: Vec<Shot>,
}

/// Every render of a comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    pub reference: Shot,
    pub reference_seed: u64,
    pub equal_samples: Vec<Shot>,
    pub equal_time: Option<EqualTime>,
}

/// [`default_strategies`] in words, for help texts.
pub const DEFAULT_STRATEGIES: &str =
    "brdf, vndf (when an object's material has it), light, mis-balance, mis-power and mis";

/// The default strategies for `scene` ([`DEFAULT_STRATEGIES`]).
#[must_use]
pub fn default_strategies(scene: &Scene) -> Vec<Strategy> {
    let mut v = vec![Strategy::Bsdf(BsdfStrategy::Brdf)];
    if scene
        .objects
        .iter()
        .any(|o| o.material.check(BsdfStrategy::Vndf).is_ok())
    {
        v.push(Strategy::Bsdf(BsdfStrategy::Vndf));
    }
    v.extend([
        Strategy::Light,
        Strategy::mis(Heuristic::Balance),
        Strategy::mis(Heuristic::Power),
        Strategy::MIS,
    ]);
    v
}

/// The seed of the reference: the complement of `seed`, so that its pixel
/// streams are independent of the compared renders'.
#[must_use]
pub fn reference_seed(seed: u64) -> u64 {
    !seed
}

/// The default reference spp: 16 × `spp`, at least 1024.
#[must_use]
pub fn default_reference_spp(spp: u32) -> u32 {
    spp.saturating_mul(16).max(1024)
}

/// Renders `scene` with `opts`, timed on `clock`, as a [`Shot`] whose RMSE
/// is not measured yet (NaN). Progress: one task `label` of one step per
/// pixel.
#[must_use]
pub fn render_one(
    scene: &Scene,
    opts: &RenderSettings,
    label: &str,
    progress: &dyn Progress,
    clock: &dyn Clock,
) -> Shot {
    let pixels = u64::from(scene.camera.width) * u64::from(scene.camera.height);
    progress.start(label, pixels.saturating_mul(opts.spp));
    let (image, time_s) = timed(clock, || render(scene, opts, |n| progress.advance(n)));
    Shot {
        strategy: opts.strategy,
        spp: u32::try_from(opts.spp).unwrap_or(u32::MAX),
        time_s,
        rmse: f64::NAN,
        image,
    }
}

/// The progress label of a render: `brdf 16 spp`, `brdf 40 spp, eq. time`,
/// `reference 1024 spp`.
fn label(strategy: Strategy, spp: u32, what: &str) -> String {
    match what {
        "" => format!("{strategy} {spp} spp"),
        "reference" => format!("reference {spp} spp"),
        _ => format!("{strategy} {spp} spp, {what}"),
    }
}

/// The equal-time budget is the time of a render of at least this many
/// samples per pixel: below it, whole samples per pixel cannot make the
/// times equal within [`EQUAL_TIME_TOLERANCE`] (at 4 spp one sample more
/// or less is 25 %; at 32 spp, with the slowest strategy at 20, 2.5 %).
pub const MIN_EQUAL_TIME_SPP: u32 = 32;

/// The equal-time budget is at least this many seconds: a shorter render's
/// time is mostly the machine's noise (10 to 20 % at 10 ms on a loaded
/// machine), and its spp are raised until it is not.
pub const MIN_EQUAL_TIME_S: f64 = 0.05;

/// How close to the budget an equal-time render's time is brought (as a
/// fraction of the budget), within [`EQUAL_TIME_TRIES`] renders.
pub const EQUAL_TIME_TOLERANCE: f64 = 0.03;

/// Most renders of one strategy to bring its time within
/// [`EQUAL_TIME_TOLERANCE`] of the budget; the closest is kept.
pub const EQUAL_TIME_TRIES: usize = 4;

/// A render shorter than this is timed as the fastest of
/// [`SHORT_RENDER_RUNS`] runs (the same image each time): a short render's
/// single time is mostly the machine's noise.
pub const SHORT_RENDER_S: f64 = 0.1;

/// Runs of a render shorter than [`SHORT_RENDER_S`].
pub const SHORT_RENDER_RUNS: usize = 3;

/// Renders every strategy at equal samples (and at equal time when
/// `s.equal_time`), then the reference, and measures each render's RMSE
/// against the reference. Each render is one progress task (see
/// [`render_one`]); the times come from `clock`, and only the equal-time
/// spp depend on them.
///
/// Times are measured without start-up: every strategy is first rendered
/// once at 1 spp, untimed (progress task `warm-up`: the threads, the
/// lazily built tables, the first touch of memory), and a render shorter
/// than [`SHORT_RENDER_S`] is timed as the fastest of [`SHORT_RENDER_RUNS`]
/// runs.
///
/// Equal time: the budget is the time of `mis` (the slowest strategy when
/// `mis` is not compared) at `max(spp, MIN_EQUAL_TIME_SPP)`, or at more spp
/// when that takes less than [`MIN_EQUAL_TIME_S`]. Each other
/// strategy starts from the spp its equal-samples render's time per spp
/// gives, and is rendered again with the spp of the least-squares line
/// through its (spp, time) points so far (a render's time is a start-up of its own,
/// the pilots, plus a cost per sample) until its time is within
/// [`EQUAL_TIME_TOLERANCE`] of the budget, at most [`EQUAL_TIME_TRIES`]
/// renders; the render closest to the budget is kept.
#[must_use]
pub fn run_comparison(
    scene: &Scene,
    s: &CompareSettings,
    progress: &dyn Progress,
    clock: &dyn Clock,
) -> Comparison {
    let spp = s.spp.max(1);
    let opts = |strategy: Strategy, spp: u32, seed: u64| RenderSettings {
        spp: spp.into(),
        strategy,
        seed,
        sequence: s.sequence,
        max_depth: s.max_depth,
        threads: s.threads,
        ..RenderSettings::default()
    };
    for &m in &s.strategies {
        let _ = render_one(scene, &opts(m, 1, s.seed), "warm-up", progress, &NoClock);
    }
    let shot = |strategy: Strategy, spp: u32, seed: u64, what: &str| {
        let o = opts(strategy, spp, seed);
        let mut first = render_one(scene, &o, &label(strategy, spp, what), progress, clock);
        if what != "reference" && first.time_s < SHORT_RENDER_S {
            for _ in 1..SHORT_RENDER_RUNS {
                let again = render_one(scene, &o, &label(strategy, spp, what), progress, clock);
                first.time_s = first.time_s.min(again.time_s);
            }
        }
        first
    };
    let equal_samples: Vec<Shot> = s
        .strategies
        .iter()
        .map(|&m| shot(m, spp, s.seed, ""))
        .collect();
    let equal_time = s.equal_time.then(|| {
        let budget_spp = spp.max(MIN_EQUAL_TIME_SPP);
        let (k, why) = match equal_samples.iter().position(|x| x.strategy == Strategy::MIS) {
            Some(k) => (k, ""),
            None => {
                let k = (0..equal_samples.len())
                    .max_by(|&a, &b| equal_samples[a].time_s.total_cmp(&equal_samples[b].time_s))
                    .expect("at least one strategy");
                (k, ", the slowest")
            }
        };
        let budget_strategy = equal_samples[k].strategy;
        let mut budget_spp = budget_spp;
        let mut budget_shot = if budget_spp == spp {
            equal_samples[k].clone()
        } else {
            shot(budget_strategy, budget_spp, s.seed, "eq. time")
        };
        for _ in 0..EQUAL_TIME_TRIES {
            if budget_shot.time_s >= MIN_EQUAL_TIME_S || f64::from(budget_spp) >= MAX_EQUAL_TIME_SPP
            {
                break;
            }
            let scale = 1.1 * MIN_EQUAL_TIME_S / budget_shot.time_s.max(1e-9);
            budget_spp = (f64::from(budget_spp) * scale)
                .ceil()
                .clamp(f64::from(budget_spp) + 1.0, MAX_EQUAL_TIME_SPP) as u32;
            budget_shot = shot(budget_strategy, budget_spp, s.seed, "eq. time");
        }
        let budget_s = budget_shot.time_s;
        let mut budget_from = format!("the time of {budget_strategy} at {budget_spp} spp{why}");
        if budget_spp != spp {
            budget_from.push_str(&format!(
                "; at least {MIN_EQUAL_TIME_SPP} spp and {} ms, so that whole samples per pixel and the clock can make the times equal",
                MIN_EQUAL_TIME_S * 1e3
            ));
        }
        let shots = equal_samples
            .iter()
            .enumerate()
            .map(|(i, pilot)| {
                if i == k {
                    return budget_shot.clone();
                }
                let mut tried: Vec<Shot> = vec![pilot.clone()];
                let per_spp = pilot.time_s.max(1e-9) / f64::from(spp);
                let mut n = (budget_s / per_spp).round();
                for _ in 0..EQUAL_TIME_TRIES {
                    let n_u = n.clamp(1.0, MAX_EQUAL_TIME_SPP) as u32;
                    if tried.iter().any(|t| t.spp == n_u) {
                        break;
                    }
                    let x = shot(pilot.strategy, n_u, s.seed, "eq. time");
                    let (n1, t1) = (f64::from(x.spp), x.time_s);
                    tried.push(x);
                    if (t1 / budget_s - 1.0).abs() <= EQUAL_TIME_TOLERANCE {
                        break;
                    }
                    // The line `a + b·spp` through the points so far (least
                    // squares; the secant of two): `b` is the cost per spp
                    // without the start-up `a`.
                    n = match line_fit(&tried) {
                        Some((a, b)) if b > 0.0 => ((budget_s - a) / b).round(),
                        _ => (n1 * budget_s / t1.max(1e-12)).round(),
                    };
                }
                tried
                    .into_iter()
                    .min_by(|a, b| {
                        (a.time_s - budget_s)
                            .abs()
                            .total_cmp(&(b.time_s - budget_s).abs())
                    })
                    .expect("the pilot at least")
            })
            .collect();
        EqualTime {
            budget_s,
            budget_from,
            shots,
        }
    });
    let seed = reference_seed(s.seed);
    let mut reference = shot(
        REFERENCE_STRATEGY,
        s.reference_spp.max(1),
        seed,
        "reference",
    );
    reference.rmse = 0.0;
    let mut cmp = Comparison {
        reference,
        reference_seed: seed,
        equal_samples,
        equal_time,
    };
    let r = cmp.reference.image.clone();
    for shot in cmp.shots_mut() {
        shot.rmse = rmse(&shot.image, &r);
    }
    cmp
}

/// Least-squares line `time = a + b · spp` through the shots; `None` when
/// they do not span two spp.
fn line_fit(shots: &[Shot]) -> Option<(f64, f64)> {
    let k = shots.len() as f64;
    let mx = shots.iter().map(|s| f64::from(s.spp)).sum::<f64>() / k;
    let my = shots.iter().map(|s| s.time_s).sum::<f64>() / k;
    let sxx: f64 = shots.iter().map(|s| (f64::from(s.spp) - mx).powi(2)).sum();
    let sxy: f64 = shots
        .iter()
        .map(|s| (f64::from(s.spp) - mx) * (s.time_s - my))
        .sum();
    (sxx > 0.0).then(|| {
        let b = sxy / sxx;
        (my - b * mx, b)
    })
}

/// A clock that never moves: the warm-up renders are not timed.
struct NoClock;
impl Clock for NoClock {
    fn now(&self) -> std::time::Duration {
        std::time::Duration::ZERO
    }
}

impl Comparison {
    /// Every compared shot: equal samples, then equal time.
    pub fn shots(&self) -> impl Iterator<Item = &Shot> {
        self.equal_samples.iter().chain(
            self.equal_time
                .as_ref()
                .map(|e| e.shots.iter())
                .into_iter()
                .flatten(),
        )
    }

    fn shots_mut(&mut self) -> impl Iterator<Item = &mut Shot> {
        self.equal_samples.iter_mut().chain(
            self.equal_time
                .as_mut()
                .map(|e| e.shots.iter_mut())
                .into_iter()
                .flatten(),
        )
    }
}

/// Root mean square over all pixels and channels of the linear RGB
/// difference `a − reference` (over the pixels both have; 0 for none).
#[must_use]
pub fn rmse(a: &Image, reference: &Image) -> f64 {
    let n = a.pixels.len().min(reference.pixels.len());
    if n == 0 {
        return 0.0;
    }
    let sum: f64 = a
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(p, r)| (*p - *r).length_squared())
        .sum();
    (sum / (3 * n) as f64).sqrt()
}

/// `ε` of the error maps: 1 % of the reference's mean luminance (negative
/// pixels counted as 0), or 1e-6 when that mean is not positive and finite.
#[must_use]
pub fn error_epsilon(reference: &Image) -> f64 {
    let n = reference.pixels.len().max(1) as f64;
    let mean = reference
        .pixels
        .iter()
        .map(|p| luminance(*p).max(0.0))
        .sum::<f64>()
        / n;
    if mean > 0.0 && mean.is_finite() {
        0.01 * mean
    } else {
        1e-6
    }
}

/// Per pixel, the relative error of luminance `|Y − Y_ref| / (Y_ref + ε)`
/// (`Y_ref` clamped at 0), row-major like the images.
#[must_use]
pub fn error_map(image: &Image, reference: &Image, eps: f64) -> Vec<f64> {
    image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(p, r)| {
            let yr = luminance(*r).max(0.0);
            (luminance(*p) - yr).abs() / (yr + eps)
        })
        .collect()
}

/// Decades an error colour scale spans.
pub const SCALE_DECADES: i32 = 4;

/// A logarithmic colour scale from `lo` to `hi` (both powers of ten).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LogScale {
    pub lo: f64,
    pub hi: f64,
}

impl LogScale {
    /// The scale of `maps`: its top is the power of ten at or above the
    /// 99th percentile of the positive finite values (1 when there are
    /// none), and it spans [`SCALE_DECADES`] decades.
    #[must_use]
    pub fn of(maps: &[Vec<f64>]) -> LogScale {
        let mut v: Vec<f64> = maps
            .iter()
            .flatten()
            .copied()
            .filter(|x| *x > 0.0 && x.is_finite())
            .collect();
        let top = if v.is_empty() {
            0
        } else {
            let k = ((v.len() - 1) as f64 * 0.99).round() as usize;
            let (_, p, _) = v.select_nth_unstable_by(k, f64::total_cmp);
            p.log10().ceil() as i32
        };
        LogScale {
            lo: 10f64.powi(top - SCALE_DECADES),
            hi: 10f64.powi(top),
        }
    }

    /// Position of `x` on the scale, clamped to [0, 1] (0 for NaN).
    #[must_use]
    pub fn t(&self, x: f64) -> f64 {
        if x.is_nan() || x <= self.lo {
            return 0.0;
        }
        ((x.log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10())).clamp(0.0, 1.0)
    }
}

/// An RGB8 picture (`w × h`, row-major, 3 bytes a pixel) and its size.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rgb8 {
    pub bytes: Vec<u8>,
    pub width: usize,
    pub height: usize,
}

/// Resizes the RGB8 picture `rgb` of `w × h` pixels: by the integer factor
/// `up` when it is above 1 (nearest neighbour), else down by `down` when it
/// is above 1 (box average, rounded; the size is `w / down × h / down`, at
/// least 1), else unchanged.
#[must_use]
pub fn resample(rgb: &[u8], w: usize, h: usize, up: usize, down: usize) -> Rgb8 {
    if up > 1 {
        let (ow, oh) = (w * up, h * up);
        let mut out = vec![0u8; ow * oh * 3];
        for y in 0..oh {
            for x in 0..ow {
                let s = ((y / up) * w + x / up) * 3;
                let d = (y * ow + x) * 3;
                out[d..d + 3].copy_from_slice(&rgb[s..s + 3]);
            }
        }
        Rgb8 {
            bytes: out,
            width: ow,
            height: oh,
        }
    } else if down > 1 {
        let (ow, oh) = ((w / down).max(1), (h / down).max(1));
        let mut out = vec![0u8; ow * oh * 3];
        for y in 0..oh {
            for x in 0..ow {
                let mut acc = [0u32; 3];
                let mut cnt = 0u32;
                for yy in y * down..((y + 1) * down).min(h) {
                    for xx in x * down..((x + 1) * down).min(w) {
                        let s = (yy * w + xx) * 3;
                        for c in 0..3 {
                            acc[c] += u32::from(rgb[s + c]);
                        }
                        cnt += 1;
                    }
                }
                let d = (y * ow + x) * 3;
                for c in 0..3 {
                    out[d + c] = ((acc[c] + cnt / 2) / cnt.max(1)) as u8;
                }
            }
        }
        Rgb8 {
            bytes: out,
            width: ow,
            height: oh,
        }
    } else {
        Rgb8 {
            bytes: rgb.to_vec(),
            width: w,
            height: h,
        }
    }
}
