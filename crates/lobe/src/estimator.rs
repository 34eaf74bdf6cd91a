//! Monte Carlo estimation of reflected radiance at one shading point,
//! `L_o(wo) = ∫ f_r(wo, wi) L_i(wi) cos θi dωi`, by BSDF sampling, light
//! sampling or multiple importance sampling, and its deterministic
//! quadrature reference.
//!
//! One estimator serves `lobe estimate` and the renderer: a [`Light`] that is
//! a function of world direction, a [`Material`] in the local frame of a
//! [`ShadingPoint`], and a [`Visibility`] that says whether a direction
//! reaches the light ([`Unoccluded`] at one shading point; shadow rays in the
//! renderer). MIS lives here and nowhere else ([`ShadingEstimator::estimate`]).
//!
//! The `N` samples are cut into chunks of [`CHUNK`] samples; chunk `k` draws
//! its random numbers from its own stream, so the result depends only on the
//! seed, never on how many threads ran the chunks, as long as chunks are
//! merged in order ([`Accumulator::merge`]).

use crate::envmap::EnvMap;
use crate::light::{Light, LightDistribution};
use crate::material::BsdfSampler;
use crate::math::{Rgb, luminance};
pub use crate::sequence::CHUNK;
use crate::sequence::{self, Sequence};
use crate::stats::quadrature::{
    Tolerance, gauss_legendre_4x4, integrate_hemisphere, integrate_sphere,
};
use crate::stats::ttest::Moments;
pub use crate::strategy::{Heuristic, Mis, MisForm, NON_BSDF_NAMES, Strategy};
use crate::{BsdfSample, Error, Frame, Material};
use glam::{DVec2, DVec3};

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

impl<'m> ShadingEstimator<'m> {
    /// Validate `strategy` for `m` once, into an estimator of one shading
    /// point; the error says why a BSDF strategy does not apply.
    pub fn new(strategy: Strategy, m: &'m Material) -> Result<Self, Error> {
        if strategy == Strategy::Light && m.reach().delta {
            return Err(crate::strategy::light_never_hits(m));
        }
        let sampler = match strategy.bsdf_strategy(m) {
            Some(s) => Some(m.sampler(s)?),
            None => None,
        };
        let strategy = match strategy {
            Strategy::Mis(mis) => Strategy::Mis(Mis {
                bsdf: sampler.map(|s| s.strategy()),
                ..mis
            }),
            t => t,
        };
        Ok(ShadingEstimator {
            strategy,
            material: m,
            sampler,
            allocation: Allocation::Balance,
        })
    }
}

/// One shading point: its local frame (`+z` the normal) and the view
/// direction `wo` in that frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingPoint {
    pub frame: Frame,
    /// Toward the viewer, unit, local frame.
    pub wo: DVec3,
}

impl ShadingPoint {
    /// A point whose local frame is the world (`+z` the normal): the world
    /// directions of lights are local directions.
    #[must_use]
    pub fn local(wo: DVec3) -> Self {
        ShadingPoint {
            frame: Frame {
                s: DVec3::X,
                t: DVec3::Y,
                n: DVec3::Z,
            },
            wo,
        }
    }
}

/// Whether a direction from the shading point reaches the light.
pub trait Visibility {
    /// A light sample toward world direction `dir`: is it unoccluded (a
    /// shadow ray in a renderer)?
    fn unoccluded(&mut self, dir: DVec3) -> bool;
    /// A BSDF-sampled ray toward world direction `dir`: does it escape to
    /// the light, with nothing in the way? (A renderer traces it and keeps
    /// the hit to continue the path.)
    fn escapes(&mut self, dir: DVec3) -> bool;
}

/// Nothing is in the way: one shading point alone under its light.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Unoccluded;

impl Visibility for Unoccluded {
    #[inline]
    fn unoccluded(&mut self, _dir: DVec3) -> bool {
        true
    }
    #[inline]
    fn escapes(&mut self, _dir: DVec3) -> bool {
        true
    }
}

/// A BSDF sample that an estimate drew, for a renderer to continue its path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrawnBsdf {
    pub sample: BsdfSample,
    /// Its direction in the world.
    pub dir: DVec3,
    /// Whether it escaped to the light ([`Visibility::escapes`]).
    pub escaped: bool,
}

/// What an estimate's first BSDF draw gives a renderer to continue its path
/// with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BsdfDraw {
    /// The estimate drew no BSDF direction (light sampling, one-sample MIS
    /// that chose the light, adaptive MIS that gave its draws to the
    /// light): the renderer draws one of its own.
    NotDrawn,
    /// The first draw failed (no direction, as a sample below the horizon):
    /// the path ends there. Drawing again would give the path a second
    /// chance the estimate's failed sample did not have, and bias it.
    Failed,
    /// The first BSDF sample drawn.
    Drawn(DrawnBsdf),
}

/// One estimate at a shading point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingEstimate {
    /// `f L cos / p`, MIS-weighted where MIS is used (cosine included);
    /// zero for failed samples.
    pub value: Rgb,
    /// The first BSDF draw, for a renderer's path.
    pub bsdf: BsdfDraw,
}

/// A [`Strategy`] validated for one material ([`ShadingEstimator::new`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingEstimator<'m> {
    strategy: Strategy,
    material: &'m Material,
    sampler: Option<BsdfSampler<'m>>,
    /// Adaptive MIS only: how the draws of a sample are given out.
    allocation: Allocation,
}

/// How adaptive MIS ([`MisForm::Adaptive`]) gives out the `n_bsdf + n_light`
/// draws of one sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Allocation {
    /// All to BSDF sampling (the mean of their `f L cos / p`).
    Bsdf,
    /// `n_bsdf` BSDF and `n_light` light draws (from the MIS-compensated
    /// distribution) weighted by the balance heuristic: multi-sample MIS.
    #[default]
    Balance,
    /// All to light sampling from the plain distribution.
    Light,
}

impl Allocation {
    pub const ALL: [Allocation; 3] = [Allocation::Bsdf, Allocation::Balance, Allocation::Light];

    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Allocation::Bsdf => "bsdf",
            Allocation::Balance => "balance",
            Allocation::Light => "light",
        }
    }
}

/// A pilot's statistics for adaptive MIS: from samples of the multi-sample
/// balance heuristic with counts `(n_b, n_l)`, unbiased estimates of the
/// integrals that give the per-sample variance of every [`Allocation`].
///
/// With `g = lum(f L cos)` (visibility included), `q = n_b p_b + n_l p_c`
/// (`p_b` the BSDF strategy's pdf, `p_c` the compensated light pdf, `p_l`
/// the plain one), any `∫ h` is estimated by `Σ h(d)/q(d)` over the draws
/// `d` of a sample. Per sample of `n = n_b + n_l` draws:
/// * all to BSDF: `(∫ g²/p_b − μ²) / n`;
/// * all to light: `(∫ g²/p_l − μ²) / n`;
/// * balance: `∫ g²/q − n_b (∫ g p_b/q)² − n_l (∫ g p_c/q)²`.
///
/// A direction with `g > 0` that a strategy cannot draw (pdf 0) makes that
/// strategy's variance infinite. The light draws see what BSDF sampling
/// misses (a small sun), so a pilot does not mistake a heavy-tailed BSDF
/// estimator for a good one.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Pilot {
    /// Samples recorded.
    pub samples: u64,
    mu: f64,
    m_bsdf: f64,
    m_light: f64,
    m_q: f64,
    mu_b: f64,
    mu_l: f64,
    bsdf_blind: bool,
    light_blind: bool,
}

impl Pilot {
    /// Below this many effective draws ([`Pilot::effective_draws`]) the
    /// pilot's variances are too noisy to trust, and [`Pilot::choose`]
    /// keeps the balance heuristic.
    pub const MIN_EFFECTIVE_DRAWS: f64 = 64.0;

    /// One draw `d` of a pilot sample: `g = lum(f L cos)`, the three pdfs
    /// at it (`pb` the BSDF strategy's, `pc` the compensated light
    /// distribution's, `pl` the plain one's) and `q = n_b p_b + n_l p_c`,
    /// the density of the balance heuristic's mixture. Public for renderers
    /// that draw the pilot's samples themselves (lobe-render's batch loop);
    /// [`ShadingEstimator::estimate_pilot`] calls it for each draw.
    pub fn record(&mut self, g: f64, pb: f64, pc: f64, pl: f64, q: f64) {
        if g <= 0.0 || q <= 0.0 || !g.is_finite() {
            return;
        }
        self.mu += g / q;
        self.m_q += g * g / (q * q);
        self.mu_b += g * pb / (q * q);
        self.mu_l += g * pc / (q * q);
        if pb > 0.0 {
            self.m_bsdf += g * g / (pb * q);
        } else {
            self.bsdf_blind = true;
        }
        if pl > 0.0 {
            self.m_light += g * g / (pl * q);
        } else {
            self.light_blind = true;
        }
    }

    pub fn merge(&mut self, o: &Pilot) {
        self.samples += o.samples;
        self.mu += o.mu;
        self.m_bsdf += o.m_bsdf;
        self.m_light += o.m_light;
        self.m_q += o.m_q;
        self.mu_b += o.mu_b;
        self.mu_l += o.mu_l;
        self.bsdf_blind |= o.bsdf_blind;
        self.light_blind |= o.light_blind;
    }

    /// The estimated per-sample variance of the luminance under each
    /// allocation, in the order of [`Allocation::ALL`], for counts
    /// `(n_b, n_l)`; infinite where a strategy cannot draw a direction
    /// that carries light.
    #[must_use]
    pub fn variances(&self, n_b: u32, n_l: u32) -> [f64; 3] {
        let k = self.samples.max(1) as f64;
        let (nb, nl) = (f64::from(n_b), f64::from(n_l));
        let n = nb + nl;
        let mu = self.mu / k;
        let bsdf = if self.bsdf_blind {
            f64::INFINITY
        } else {
            (self.m_bsdf / k - mu * mu).max(0.0) / n
        };
        let light = if self.light_blind {
            f64::INFINITY
        } else {
            (self.m_light / k - mu * mu).max(0.0) / n
        };
        let (mb, ml) = (self.mu_b / k, self.mu_l / k);
        let balance = (self.m_q / k - nb * mb * mb - nl * ml * ml).max(0.0);
        [bsdf, balance, light]
    }

    /// The effective number of the pilot's draws, `(Σ g/q)² / Σ (g/q)²`:
    /// how many carried light, weighted by how evenly.
    #[must_use]
    pub fn effective_draws(&self) -> f64 {
        if self.m_q > 0.0 {
            self.mu * self.mu / self.m_q
        } else {
            0.0
        }
    }

    /// The allocation of least estimated variance; a single strategy only
    /// when it beats the balance heuristic by a margin (5%), and only when
    /// the pilot saw enough light to tell ([`Pilot::MIN_EFFECTIVE_DRAWS`]):
    /// balance is the defensive choice.
    #[must_use]
    pub fn choose(&self, n_b: u32, n_l: u32) -> Allocation {
        if self.samples == 0 || self.effective_draws() < Self::MIN_EFFECTIVE_DRAWS {
            return Allocation::Balance;
        }
        let [b, m, l] = self.variances(n_b, n_l);
        let margin = 0.95;
        if b <= l && b < margin * m {
            Allocation::Bsdf
        } else if l < b && l < margin * m {
            Allocation::Light
        } else {
            Allocation::Balance
        }
    }
}

/// Pilot samples of adaptive MIS in an estimate of `n` samples.
#[must_use]
pub fn pilot_samples(n: usize) -> usize {
    (n / 16).clamp(256, 4096)
}

impl<'m> ShadingEstimator<'m> {
    /// The strategy, with its MIS BSDF strategy resolved.
    #[must_use]
    pub fn strategy(&self) -> Strategy {
        self.strategy
    }

    /// The BSDF sampler the strategy uses (none for light sampling).
    #[must_use]
    pub fn sampler(&self) -> Option<BsdfSampler<'m>> {
        self.sampler
    }

    /// The allocation adaptive MIS uses (always `Balance` for any other
    /// strategy, where it means nothing).
    #[must_use]
    pub fn allocation(&self) -> Allocation {
        self.allocation
    }

    /// Whether this is adaptive MIS, which wants a pilot.
    #[must_use]
    pub fn is_adaptive(&self) -> bool {
        matches!(self.strategy, Strategy::Mis(m) if m.form == MisForm::Adaptive)
    }

    /// This estimator with adaptive MIS's draws given out by `a` (no
    /// effect on any other strategy).
    #[must_use]
    pub fn with_allocation(self, a: Allocation) -> Self {
        // Light sampling alone never draws a delta part.
        let a = if a == Allocation::Light && self.material.reach().delta {
            Allocation::Balance
        } else {
            a
        };
        ShadingEstimator {
            allocation: if self.is_adaptive() {
                a
            } else {
                Allocation::Balance
            },
            ..self
        }
    }

    /// Adaptive MIS at one shading point: run a pilot of
    /// [`pilot_samples`]`(settings.samples)` samples of its own (independent
    /// numbers, a seed apart from the settings', not part of the estimate) and
    /// return this estimator with the allocation the pilot chose. Any other
    /// strategy is returned as it is.
    #[must_use]
    pub fn prepare(&self, sp: &ShadingPoint, light: &Light, settings: &EstimateSettings) -> Self {
        let Strategy::Mis(mis) = self.strategy else {
            return *self;
        };
        if mis.form != MisForm::Adaptive {
            return *self;
        }
        let k = self.strategy.points_per_sample();
        let n = pilot_samples(settings.samples);
        let seed = sequence::hash64(settings.seed ^ 0x7069_6c6f_7421_0000);
        let mut points = vec![[0.0; 3]; n * k];
        sequence::fill(Sequence::Independent, seed, n * k, 0, 0, &mut points);
        let mut pilot = Pilot::default();
        for p in points.chunks_exact(k) {
            let _ = self.estimate_pilot(sp, light, p, &mut Unoccluded, &mut pilot);
        }
        self.with_allocation(pilot.choose(mis.n_bsdf, mis.n_light))
    }

    /// One sample of the multi-sample balance heuristic (adaptive MIS's
    /// pilot), recording in `pilot` what [`Pilot::choose`] needs. For a
    /// strategy that is not adaptive MIS, [`ShadingEstimator::estimate`].
    #[must_use]
    pub fn estimate_pilot(
        &self,
        sp: &ShadingPoint,
        light: &Light,
        points: &[[f64; 3]],
        vis: &mut impl Visibility,
        pilot: &mut Pilot,
    ) -> ShadingEstimate {
        match (self.strategy, self.sampler) {
            (Strategy::Mis(mis), Some(s)) if mis.form == MisForm::Adaptive => {
                let mut first = BsdfDraw::NotDrawn;
                pilot.samples += 1;
                let value = multi_sample(
                    self.material,
                    &s,
                    sp,
                    light,
                    Heuristic::Balance,
                    (mis.n_bsdf, mis.n_light),
                    points,
                    vis,
                    &mut first,
                    Some(pilot),
                );
                ShadingEstimate { value, bsdf: first }
            }
            _ => self.estimate(sp, light, points, vis),
        }
    }

    /// One estimate from `points`, [`Strategy::points_per_sample`] of them,
    /// each `[uc, u₁, u₂]`. Multi-sample MIS takes its `n_bsdf` BSDF points
    /// first, then its `n_light` light points (which use `u` only);
    /// one-sample MIS chooses the strategy with the point's `uc`.
    #[must_use]
    pub fn estimate(
        &self,
        sp: &ShadingPoint,
        light: &Light,
        points: &[[f64; 3]],
        vis: &mut impl Visibility,
    ) -> ShadingEstimate {
        let m = self.material;
        let dist = self.strategy.light_distribution();
        let mut first = BsdfDraw::NotDrawn;
        let value = match (self.strategy, self.sampler) {
            (Strategy::Bsdf(_), Some(s)) => {
                let p = points[0];
                match draw_bsdf(&s, sp, p, 1.0, vis, &mut first) {
                    Some((x, dir)) => x.weight * light.radiance(dir),
                    None => Rgb::ZERO,
                }
            }
            (Strategy::Light, _) => {
                let p = points[0];
                light_value(m, None, sp, light, dist, p, vis, |_, _| (1.0, 1.0))
            }
            (Strategy::Mis(mis), Some(s)) => {
                let (nb, nl) = (f64::from(mis.n_bsdf), f64::from(mis.n_light));
                let h = mis.heuristic;
                match mis.form {
                    MisForm::MultiSample => multi_sample(
                        m,
                        &s,
                        sp,
                        light,
                        h,
                        (mis.n_bsdf, mis.n_light),
                        points,
                        vis,
                        &mut first,
                        None,
                    ),
                    MisForm::Adaptive => match self.allocation {
                        Allocation::Balance => multi_sample(
                            m,
                            &s,
                            sp,
                            light,
                            Heuristic::Balance,
                            (mis.n_bsdf, mis.n_light),
                            points,
                            vis,
                            &mut first,
                            None,
                        ),
                        Allocation::Bsdf => {
                            let mut sum = Rgb::ZERO;
                            for p in points {
                                if let Some((x, dir)) = draw_bsdf(&s, sp, *p, 1.0, vis, &mut first)
                                {
                                    sum += x.weight * light.radiance(dir);
                                }
                            }
                            sum / points.len() as f64
                        }
                        Allocation::Light => {
                            let mut sum = Rgb::ZERO;
                            for p in points {
                                sum += light_value(
                                    m,
                                    None,
                                    sp,
                                    light,
                                    LightDistribution::Plain,
                                    *p,
                                    vis,
                                    |_, _| (1.0, 1.0),
                                );
                            }
                            sum / points.len() as f64
                        }
                    },
                    MisForm::OneSample => {
                        let p = points[0];
                        let cb = nb / (nb + nl);
                        let cl = 1.0 - cb;
                        if p[0] < cb {
                            // Reuse the choice number for the lobe choice, rescaled.
                            match draw_bsdf(&s, sp, p, cb, vis, &mut first) {
                                Some((x, dir)) if x.scattering.is_specular() => {
                                    x.weight * light.radiance(dir) / cb
                                }
                                Some((x, dir)) => {
                                    let w = h.weight(cb * x.pdf, cl * light.pdf(dist, dir));
                                    x.weight * light.radiance(dir) * (w / cb)
                                }
                                None => Rgb::ZERO,
                            }
                        } else {
                            light_value(m, Some(&s), sp, light, dist, p, vis, |pl, pb| {
                                (h.weight(cl * pl, cb * pb), cl)
                            })
                        }
                    }
                }
            }
            (_, None) => unreachable!("a BSDF or MIS strategy always has a sampler"),
        };
        ShadingEstimate { value, bsdf: first }
    }
}

/// Multi-sample MIS with counts `(n_b, n_l)`: `points` holds the BSDF
/// points, then the light points. With `pilot`, every draw is recorded
/// (balance heuristic only).
#[allow(clippy::too_many_arguments)]
fn multi_sample(
    m: &Material,
    s: &BsdfSampler,
    sp: &ShadingPoint,
    light: &Light,
    h: Heuristic,
    (n_b, n_l): (u32, u32),
    points: &[[f64; 3]],
    vis: &mut impl Visibility,
    first: &mut BsdfDraw,
    mut pilot: Option<&mut Pilot>,
) -> Rgb {
    let dist = LightDistribution::Compensated;
    let (nb, nl) = (f64::from(n_b), f64::from(n_l));
    let mut sum = Rgb::ZERO;
    for p in &points[..n_b as usize] {
        if let Some((x, dir)) = draw_bsdf(s, sp, *p, 1.0, vis, first) {
            if x.scattering.is_specular() {
                // A delta part: light sampling never draws it (weight 1).
                sum += x.weight * light.radiance(dir) / nb;
                continue;
            }
            let pc = light.pdf(dist, dir);
            let w = h.weight(nb * x.pdf, nl * pc);
            let v = x.weight * light.radiance(dir);
            sum += v * (w / nb);
            if let Some(pilot) = pilot.as_deref_mut() {
                let g = luminance(v) * x.pdf;
                let pl = light.pdf(LightDistribution::Plain, dir);
                pilot.record(g, x.pdf, pc, pl, nb * x.pdf + nl * pc);
            }
        }
    }
    for p in &points[n_b as usize..] {
        let Some(d) = light_draw(m, Some(s), sp, light, dist, *p, vis) else {
            continue;
        };
        let w = h.weight(nl * d.pdf, nb * d.pdf_bsdf);
        sum += d.f_l_cos * (w / (nl * d.pdf));
        if let Some(pilot) = pilot.as_deref_mut() {
            let pl = light.pdf(LightDistribution::Plain, d.dir);
            pilot.record(
                luminance(d.f_l_cos),
                d.pdf_bsdf,
                d.pdf,
                pl,
                nb * d.pdf_bsdf + nl * d.pdf,
            );
        }
    }
    sum
}

/// A light sample that carries light: `f L cos` at its direction, its pdf
/// and the BSDF strategy's pdf there (0 without a sampler).
struct LightDraw {
    f_l_cos: Rgb,
    pdf: f64,
    pdf_bsdf: f64,
    dir: DVec3,
}

/// Draw a light sample from point `p` (its `u` only); `None` for a failed
/// one (no sample, below the horizon, `f = 0`, occluded).
#[inline]
fn light_draw(
    m: &Material,
    bsdf: Option<&BsdfSampler>,
    sp: &ShadingPoint,
    light: &Light,
    dist: LightDistribution,
    p: [f64; 3],
    vis: &mut impl Visibility,
) -> Option<LightDraw> {
    let ls = light.sample(dist, DVec2::new(p[1], p[2]))?;
    let wi = sp.frame.to_local(ls.dir);
    // Below the horizon `f` is zero but where the material transmits (or
    // is two-sided and seen from below).
    if wi.z == 0.0 {
        return None;
    }
    let (f, pb) = match bsdf {
        Some(s) => s.eval_pdf(sp.wo, wi),
        None => (m.eval(sp.wo, wi), 0.0),
    };
    if f == Rgb::ZERO || !vis.unoccluded(ls.dir) {
        return None;
    }
    Some(LightDraw {
        f_l_cos: f * light.radiance(ls.dir) * wi.z.abs(),
        pdf: ls.pdf,
        pdf_bsdf: pb,
        dir: ls.dir,
    })
}

/// Draw a BSDF sample from point `p` (`uc = p[0] / uc_scale`), record the
/// first one drawn, and return it with its world direction if it escapes.
#[inline]
fn draw_bsdf(
    s: &BsdfSampler,
    sp: &ShadingPoint,
    p: [f64; 3],
    uc_scale: f64,
    vis: &mut impl Visibility,
    first: &mut BsdfDraw,
) -> Option<(BsdfSample, DVec3)> {
    let uc = if uc_scale == 1.0 {
        p[0]
    } else {
        p[0] / uc_scale
    };
    let Some(x) = s.sample(sp.wo, uc, DVec2::new(p[1], p[2])) else {
        if *first == BsdfDraw::NotDrawn {
            *first = BsdfDraw::Failed;
        }
        return None;
    };
    let dir = sp.frame.to_world(x.wi);
    let escaped = vis.escapes(dir);
    if *first == BsdfDraw::NotDrawn {
        *first = BsdfDraw::Drawn(DrawnBsdf {
            sample: x,
            dir,
            escaped,
        });
    }
    escaped.then_some((x, dir))
}

/// One light sample's value `f L cos · w / (n p_light)` from point `p`
/// (its `u` only): zero for a failed sample (no sample, below the horizon,
/// `f = 0`, occluded). `weight(p_light, p_bsdf)` gives the MIS weight `w`
/// and the strategy's count `n` (`p_bsdf` is 0 without `bsdf`); `f` and
/// `p_bsdf` come from one [`BsdfSampler::eval_pdf`].
#[inline]
#[allow(clippy::too_many_arguments)]
fn light_value(
    m: &Material,
    bsdf: Option<&BsdfSampler>,
    sp: &ShadingPoint,
    light: &Light,
    dist: LightDistribution,
    p: [f64; 3],
    vis: &mut impl Visibility,
    weight: impl FnOnce(f64, f64) -> (f64, f64),
) -> Rgb {
    let Some(d) = light_draw(m, bsdf, sp, light, dist, p, vis) else {
        return Rgb::ZERO;
    };
    let (w, n) = weight(d.pdf, d.pdf_bsdf);
    if n == 1.0 {
        d.f_l_cos * (w / d.pdf)
    } else {
        d.f_l_cos * (w / (n * d.pdf))
    }
}

/// The settings of one [`estimate`]: a strategy, a sequence, a number of
/// samples and a seed. One sample of multi-sample MIS draws `n_bsdf + n_light` directions
/// (as one sample per pixel of a renderer's MIS does); compare strategies of
/// different cost by efficiency, 1/(variance × time).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimateSettings {
    pub strategy: Strategy,
    pub sequence: Sequence,
    /// Number of samples (of `points_per_sample` directions each).
    pub samples: usize,
    pub seed: u64,
}

impl EstimateSettings {
    /// `samples` independent samples with `seed`.
    #[must_use]
    pub fn independent(strategy: impl Into<Strategy>, samples: usize, seed: u64) -> Self {
        EstimateSettings {
            strategy: strategy.into(),
            sequence: Sequence::Independent,
            samples,
            seed,
        }
    }

    /// Number of samples (each of `points_per_sample` draws).
    #[must_use]
    pub fn estimates(&self) -> usize {
        self.samples
    }

    /// Number of chunks of [`CHUNK`] estimates.
    #[must_use]
    pub fn chunks(&self) -> usize {
        self.estimates().div_ceil(CHUNK)
    }
}

/// Estimate chunk by chunk, in order, on this thread. A caller with threads
/// runs [`estimate_chunk`] for every chunk and merges them in chunk order,
/// which gives the same numbers. The error says why the settings' strategy
/// does not apply to `m`.
pub fn estimate(
    m: &Material,
    sp: &ShadingPoint,
    light: &Light,
    settings: &EstimateSettings,
) -> Result<Accumulator, Error> {
    let est = ShadingEstimator::new(settings.strategy, m)?.prepare(sp, light, settings);
    let mut acc = Accumulator::default();
    for chunk in 0..settings.chunks() {
        acc.merge(&estimate_chunk(&est, sp, light, settings, chunk));
    }
    Ok(acc)
}

/// The estimates of chunk `chunk` of `settings`, by `est` (the settings' strategy
/// validated for the material, and for adaptive MIS
/// [`ShadingEstimator::prepare`]d at this point).
#[must_use]
pub fn estimate_chunk(
    est: &ShadingEstimator,
    sp: &ShadingPoint,
    light: &Light,
    settings: &EstimateSettings,
    chunk: usize,
) -> Accumulator {
    let k = settings.strategy.points_per_sample();
    let first = chunk * CHUNK;
    let len = CHUNK.min(settings.estimates().saturating_sub(first));
    let mut points = vec![[0.0; 3]; len * k];
    if k == 1 || settings.sequence == Sequence::Independent {
        // Independent numbers: the points of one sample are consecutive.
        sequence::fill(
            settings.sequence,
            settings.seed,
            settings.estimates() * k,
            chunk,
            first * k,
            &mut points,
        );
    } else {
        // Stratified or Sobol: point `t` of every sample comes from stream
        // `t`, an independently randomized sequence of `N` points, so each
        // strategy of MIS is as well distributed as it is alone.
        let mut stream = vec![[0.0; 3]; len];
        for t in 0..k {
            sequence::fill(
                settings.sequence,
                sequence::stream_seed(settings.seed, t),
                settings.estimates(),
                chunk,
                first,
                &mut stream,
            );
            for (i, p) in stream.iter().enumerate() {
                points[i * k + t] = *p;
            }
        }
    }
    let mut acc = Accumulator::default();
    for p in points.chunks_exact(k) {
        acc.push(est.estimate(sp, light, p, &mut Unoccluded).value);
    }
    acc
}

/// The finest relative tolerance a quadrature reference over a measured
/// table is asked for. A table's values are piecewise constant (MERL's
/// nearest entry) or piecewise smooth between its nodes, so adaptive
/// quadrature converges slowly on it and cannot reach `1e-9` within any
/// budget; `1e-6` is still far below the standard error of any estimate
/// it is compared with.
pub const TABLE_REFERENCE_TOLERANCE: f64 = 1e-6;

/// The evaluation budget of a quadrature reference over a measured table,
/// per channel (the analytic models keep [`Tolerance`]'s default).
pub const TABLE_REFERENCE_MAX_EVALS: usize = 2_000_000;

/// The tolerance of [`reference`] for `m` when `rel` is asked for: `rel`
/// itself for an analytic model; for a measured table at most
/// [`TABLE_REFERENCE_TOLERANCE`], within [`TABLE_REFERENCE_MAX_EVALS`].
#[must_use]
pub fn reference_tolerance(m: &Material, rel: f64) -> Tolerance {
    if m.measured().is_some() {
        Tolerance::relative(rel.max(TABLE_REFERENCE_TOLERANCE))
            .with_max_evals(TABLE_REFERENCE_MAX_EVALS)
    } else {
        Tolerance::relative(rel)
    }
}

/// The reflected radiance by deterministic quadrature (f64), per channel.
/// For an analytic light: adaptive Gauss–Kronrod over the hemisphere to
/// `rel` relative accuracy ([`reference_tolerance`]: a measured table gets
/// at most `1e-6`). For an environment map: a sum over the map's
/// texels of the texel's radiance times `∫ f cos dω` over the texel
/// ([`reference_env_row`]).
#[must_use]
pub fn reference(m: &Material, sp: &ShadingPoint, light: &Light, rel: f64) -> Rgb {
    let wo = sp.wo;
    if let Light::Env(map) = light {
        let mut sum = Rgb::ZERO;
        for j in 0..map.size().1 {
            sum += reference_env_row(m, sp, map, j, rel);
        }
        return sum + delta_reference(m, sp, light);
    }
    let sphere = m.reach().transmits || (m.two_sided && wo.z < 0.0);
    let channel = |c: usize| {
        let f =
            |wi: DVec3| (m.eval(wo, wi) * light.radiance(sp.frame.to_world(wi)))[c] * wi.z.abs();
        let tol = reference_tolerance(m, rel);
        if sphere {
            integrate_sphere(f, tol).value
        } else {
            integrate_hemisphere(f, tol).value
        }
    };
    Rgb::new(channel(0), channel(1), channel(2)) + delta_reference(m, sp, light)
}

/// What the delta parts of `m` add to the reflected radiance, exactly:
/// `Σ value · L(wi)` over [`Material::deltas`] (part of [`reference`]).
#[must_use]
pub fn delta_reference(m: &Material, sp: &ShadingPoint, light: &Light) -> Rgb {
    let mut sum = Rgb::ZERO;
    for d in m.deltas(sp.wo).iter() {
        sum += d.value * light.radiance(sp.frame.to_world(d.wi));
    }
    sum
}

/// Row `j` of the environment-map reference: `Σ_i L(i, j) ∫_texel f cos dω`.
/// Each texel integral is a 4 × 4 Gauss–Legendre rule in `(cos θ, φ)`,
/// compared with the same rule on the texel's four quarters and refined
/// where they differ by more than `rel` (up to 6 levels). A smooth map's
/// ([`EnvMap::smooth`]) band `j` of cells instead, over which its radiance
/// is bilinear ([`EnvMap::bilinear_cells`]): `Σ ∫_cell L f cos dω`, the same
/// rule and refinement on the product, smooth inside each cell.
#[must_use]
pub fn reference_env_row(m: &Material, sp: &ShadingPoint, map: &EnvMap, j: usize, rel: f64) -> Rgb {
    let (wo, frame) = (sp.wo, &sp.frame);
    if map.is_smooth() {
        let mut sum = Rgb::ZERO;
        for cell in map.bilinear_cells(j) {
            if cell.is_black() {
                continue;
            }
            let gc = |c: f64, phi: f64| {
                let theta = crate::math::safe_acos(c);
                let wi = frame.to_local(map.spherical_to_direction(theta, phi));
                // `f` is zero where the material does not scatter.
                m.eval(wo, wi) * cell.radiance(theta, phi) * wi.z.abs()
            };
            let ((t0, t1), (p0, p1)) = (cell.theta, cell.phi);
            sum += refined_4x4(gc, (t0.cos(), t1.cos(), p0, p1), rel);
        }
        return sum;
    }
    let (w, _) = map.size();
    let mut sum = Rgb::ZERO;
    for i in 0..w {
        let l = map.texel(i, j);
        if l == Rgb::ZERO {
            continue;
        }
        let ((t0, t1), (p0, p1)) = map.texel_region(i, j);
        let g = |c: f64, phi: f64| {
            let d = map.spherical_to_direction(crate::math::safe_acos(c), phi);
            let wi = frame.to_local(d);
            luminance(m.eval(wo, wi)) * wi.z.abs()
        };
        let gc = |c: f64, phi: f64| {
            let d = map.spherical_to_direction(crate::math::safe_acos(c), phi);
            let wi = frame.to_local(d);
            m.eval(wo, wi) * wi.z.abs()
        };
        // Refine on luminance, integrate RGB on the accepted cells.
        refine_4x4(g, (t0.cos(), t1.cos(), p0, p1), rel, |x0, x1, y0, y1| {
            sum += l * gauss_legendre_4x4(gc, x0, x1, y0, y1);
        });
    }
    sum
}

/// `∫ gc` over `(cos θ, φ) ∈ [c0, c1] × [p0, p1]` by the 4 × 4
/// Gauss–Legendre rule on [`refine_4x4`]'s accepted cells, refined on the
/// luminance of `gc`.
fn refined_4x4(gc: impl Fn(f64, f64) -> Rgb, cell: (f64, f64, f64, f64), rel: f64) -> Rgb {
    let mut sum = Rgb::ZERO;
    refine_4x4(
        |c, phi| luminance(gc(c, phi)),
        cell,
        rel,
        |x0, x1, y0, y1| {
            sum += gauss_legendre_4x4(&gc, x0, x1, y0, y1);
        },
    );
    sum
}

/// The cells of `(cos θ, φ) ∈ [c0, c1] × [p0, p1]` on which the 4 × 4
/// Gauss–Legendre rule of `g` agrees with the same rule on the cell's four
/// quarters within `rel` (relative) or `1e-15` (up to 6 levels of
/// refinement): `accept(c0, c1, φ0, φ1)` is called with each accepted cell's
/// quarters, in a fixed order.
fn refine_4x4(
    g: impl Fn(f64, f64) -> f64,
    (c0, c1, p0, p1): (f64, f64, f64, f64),
    rel: f64,
    mut accept: impl FnMut(f64, f64, f64, f64),
) {
    let mut stack = vec![(c0, c1, p0, p1, 0u32)];
    while let Some((c0, c1, a, b, depth)) = stack.pop() {
        let whole = gauss_legendre_4x4(&g, c0, c1, a, b);
        let (cm, pm) = (0.5 * (c0 + c1), 0.5 * (a + b));
        let parts = gauss_legendre_4x4(&g, c0, cm, a, pm)
            + gauss_legendre_4x4(&g, cm, c1, a, pm)
            + gauss_legendre_4x4(&g, c0, cm, pm, b)
            + gauss_legendre_4x4(&g, cm, c1, pm, b);
        if depth < 6
            && (whole - parts).abs() > rel * parts.abs().max(1e-300)
            && (whole - parts).abs() > 1e-15
        {
            stack.extend([
                (c0, cm, a, pm, depth + 1),
                (cm, c1, a, pm, depth + 1),
                (c0, cm, pm, b, depth + 1),
                (cm, c1, pm, b, depth + 1),
            ]);
        } else {
            for (x0, x1, y0, y1) in [
                (c0, cm, a, pm),
                (cm, c1, a, pm),
                (c0, cm, pm, b),
                (cm, c1, pm, b),
            ] {
                accept(x0, x1, y0, y1);
            }
        }
    }
}
