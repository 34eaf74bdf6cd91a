//! Monte Carlo estimation of reflected radiance
//! `L_o(wo) = ∫ f_r(wo, wi) L_i(wi) cos θi dωi` with a chosen strategy, and
//! its deterministic quadrature reference.
//!
//! The `N` samples are cut into chunks of [`CHUNK`] samples; chunk `k` draws
//! its random numbers from its own stream, so the result depends only on the
//! seed, never on how many threads ran the chunks, as long as chunks are
//! merged in order ([`Accumulator::merge`]).

use crate::envmap::EnvMap;
use crate::light::Light;
use crate::math::{Rgb, luminance};
use crate::sequence::{self, Sequence};
use crate::stats::quadrature::{Tolerance, gauss_legendre_4x4, integrate_hemisphere};
use crate::stats::ttest::Moments;
use crate::{Frame, Material, Strategy};
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

/// How Multiple Importance Sampling weights its techniques (Veach 1997).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Heuristic {
    /// `w_t = n_t p_t / Σ n p`.
    Balance,
    /// `w_t = (n_t p_t)² / Σ (n p)²`.
    Power,
}

/// Multi-sample MIS draws `n_bsdf` and `n_light` samples for every estimate;
/// one-sample MIS draws one, choosing the technique with probability
/// `n_t / (n_bsdf + n_light)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MisForm {
    MultiSample,
    OneSample,
}

/// BSDF sampling combined with light sampling.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Mis {
    /// The BSDF strategy (the material's best by default).
    pub bsdf: Strategy,
    pub heuristic: Heuristic,
    pub form: MisForm,
    pub n_bsdf: u32,
    pub n_light: u32,
}

/// How the directions of an estimate are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Technique {
    /// BSDF sampling by a strategy.
    Bsdf(Strategy),
    /// Light sampling alone.
    Light,
    /// Both, combined by MIS.
    Mis(Mis),
}

impl std::fmt::Display for Technique {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

impl From<Strategy> for Technique {
    fn from(s: Strategy) -> Self {
        Technique::Bsdf(s)
    }
}

impl Technique {
    /// `mis` and `mis-power` with one sample of each technique, multi-sample,
    /// on the BSDF strategy `bsdf`.
    #[must_use]
    pub fn mis(bsdf: Strategy, heuristic: Heuristic) -> Self {
        Technique::Mis(Mis {
            bsdf,
            heuristic,
            form: MisForm::MultiSample,
            n_bsdf: 1,
            n_light: 1,
        })
    }

    /// The name used on the command line and in tables.
    #[must_use]
    pub fn name(&self) -> String {
        match self {
            Technique::Bsdf(s) => s.name().to_string(),
            Technique::Light => "light".into(),
            Technique::Mis(m) => {
                let mut n = String::from(if m.heuristic == Heuristic::Balance {
                    "mis"
                } else {
                    "mis-power"
                });
                if m.form == MisForm::OneSample {
                    n.push_str("-one");
                }
                n
            }
        }
    }

    /// Sequence points used by one estimate (`n_bsdf + n_light` for
    /// multi-sample MIS, else 1).
    #[must_use]
    pub fn points_per_sample(&self) -> usize {
        match self {
            Technique::Mis(m) if m.form == MisForm::MultiSample => (m.n_bsdf + m.n_light) as usize,
            _ => 1,
        }
    }
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

impl Heuristic {
    /// The weight of a technique whose (count-scaled) density is `a`
    /// against another's `b`.
    #[inline]
    #[must_use]
    pub fn weight(self, a: f64, b: f64) -> f64 {
        match self {
            Heuristic::Balance => a / (a + b),
            Heuristic::Power => a * a / (a * a + b * b),
        }
    }
}

/// One estimate of `technique` from its `points` (`points_per_sample` of them).
#[must_use]
pub fn technique_value(
    m: &Material,
    t: &Technique,
    wo: DVec3,
    light: &Light,
    points: &[[f64; 3]],
) -> Rgb {
    match t {
        Technique::Bsdf(s) => {
            let p = points[0];
            sample_value(m, *s, wo, light, p[0], DVec2::new(p[1], p[2]))
        }
        Technique::Light => {
            let p = points[0];
            match light.sample(DVec2::new(p[1], p[2])) {
                Some((wi, pdf)) if wi.z > 0.0 => m.eval(wo, wi) * light.radiance(wi) * (wi.z / pdf),
                _ => Rgb::ZERO,
            }
        }
        Technique::Mis(mis) => {
            let (nb, nl) = (f64::from(mis.n_bsdf), f64::from(mis.n_light));
            match mis.form {
                MisForm::MultiSample => {
                    let mut sum = Rgb::ZERO;
                    for p in &points[..mis.n_bsdf as usize] {
                        if let Some(x) = m.sample(mis.bsdf, wo, p[0], DVec2::new(p[1], p[2])) {
                            let w = mis.heuristic.weight(nb * x.pdf, nl * light.pdf_mis(x.wi));
                            sum += x.weight * light.radiance(x.wi) * (w / nb);
                        }
                    }
                    for p in &points[mis.n_bsdf as usize..] {
                        if let Some((wi, pl)) = light.sample_mis(DVec2::new(p[1], p[2]))
                            && wi.z > 0.0
                        {
                            let w = mis.heuristic.weight(nl * pl, nb * m.pdf(mis.bsdf, wo, wi));
                            sum += m.eval(wo, wi) * light.radiance(wi) * (wi.z * w / (nl * pl));
                        }
                    }
                    sum
                }
                MisForm::OneSample => {
                    let p = points[0];
                    let cb = nb / (nb + nl);
                    let cl = 1.0 - cb;
                    if p[0] < cb {
                        // Reuse the choice number for the lobe choice, rescaled.
                        let uc = p[0] / cb;
                        match m.sample(mis.bsdf, wo, uc, DVec2::new(p[1], p[2])) {
                            Some(x) => {
                                let w = mis.heuristic.weight(cb * x.pdf, cl * light.pdf_mis(x.wi));
                                x.weight * light.radiance(x.wi) * (w / cb)
                            }
                            None => Rgb::ZERO,
                        }
                    } else {
                        match light.sample_mis(DVec2::new(p[1], p[2])) {
                            Some((wi, pl)) if wi.z > 0.0 => {
                                let w = mis.heuristic.weight(cl * pl, cb * m.pdf(mis.bsdf, wo, wi));
                                m.eval(wo, wi) * light.radiance(wi) * (wi.z * w / (cl * pl))
                            }
                            _ => Rgb::ZERO,
                        }
                    }
                }
            }
        }
    }
}

/// What one estimate is: a technique, a sequence, a number of samples and a
/// seed. One sample of multi-sample MIS draws `n_bsdf + n_light` directions
/// (as one sample per pixel of a renderer's MIS does); compare techniques of
/// different cost by efficiency, 1/(variance × time).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plan {
    pub technique: Technique,
    pub sequence: Sequence,
    /// Number of samples (of `points_per_sample` directions each).
    pub samples: usize,
    pub seed: u64,
}

impl Plan {
    /// `samples` independent samples with `seed`.
    #[must_use]
    pub fn independent(technique: impl Into<Technique>, samples: usize, seed: u64) -> Self {
        Plan {
            technique: technique.into(),
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
/// which gives the same numbers.
#[must_use]
pub fn estimate(m: &Material, wo: DVec3, light: &Light, plan: &Plan) -> Accumulator {
    let mut acc = Accumulator::default();
    for chunk in 0..plan.chunks() {
        acc.merge(&estimate_chunk(m, wo, light, plan, chunk));
    }
    acc
}

/// The estimates of chunk `chunk`.
#[must_use]
pub fn estimate_chunk(
    m: &Material,
    wo: DVec3,
    light: &Light,
    plan: &Plan,
    chunk: usize,
) -> Accumulator {
    let k = plan.technique.points_per_sample();
    let first = chunk * CHUNK;
    let len = CHUNK.min(plan.estimates().saturating_sub(first));
    let mut points = vec![[0.0; 3]; len * k];
    sequence::fill(
        plan.sequence,
        plan.seed,
        plan.estimates() * k,
        chunk,
        first * k,
        &mut points,
    );
    let mut acc = Accumulator::default();
    for p in points.chunks_exact(k) {
        acc.push(technique_value(m, &plan.technique, wo, light, p));
    }
    acc
}

/// The reflected radiance by deterministic quadrature (f64), per channel.
/// For an analytic light: adaptive Gauss–Kronrod over the hemisphere to
/// `rel` relative accuracy. For an environment map: a sum over the map's
/// texels of the texel's radiance times `∫ f cos dω` over the texel
/// ([`reference_env_row`]).
#[must_use]
pub fn reference(m: &Material, wo: DVec3, light: &Light, rel: f64) -> Rgb {
    if let Light::Env { map, frame } = light {
        let mut sum = Rgb::ZERO;
        for j in 0..map.size().1 {
            sum += reference_env_row(m, wo, map, frame, j, rel);
        }
        return sum;
    }
    let channel = |c: usize| {
        integrate_hemisphere(
            |wi| (m.eval(wo, wi) * light.radiance(wi))[c] * wi.z,
            Tolerance::relative(rel),
        )
        .value
    };
    Rgb::new(channel(0), channel(1), channel(2))
}

/// Row `j` of the environment-map reference: `Σ_i L(i, j) ∫_texel f cos dω`.
/// Each texel integral is a 4 × 4 Gauss–Legendre rule in `(cos θ, φ)`,
/// compared with the same rule on the texel's four quarters and refined
/// where they differ by more than `rel` (up to 6 levels).
#[must_use]
pub fn reference_env_row(
    m: &Material,
    wo: DVec3,
    map: &EnvMap,
    frame: &Frame,
    j: usize,
    rel: f64,
) -> Rgb {
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
            if wi.z <= 0.0 {
                0.0
            } else {
                luminance(m.eval(wo, wi)) * wi.z
            }
        };
        let gc = |c: f64, phi: f64| {
            let d = map.spherical_to_direction(crate::math::safe_acos(c), phi);
            let wi = frame.to_local(d);
            if wi.z <= 0.0 {
                Rgb::ZERO
            } else {
                m.eval(wo, wi) * wi.z
            }
        };
        // Refine on luminance, integrate RGB on the accepted cells.
        let mut stack = vec![(t0.cos(), t1.cos(), p0, p1, 0u32)];
        while let Some((c0, c1, a, b, depth)) = stack.pop() {
            let whole = gauss_legendre_4x4(g, c0, c1, a, b);
            let (cm, pm) = (0.5 * (c0 + c1), 0.5 * (a + b));
            let parts = gauss_legendre_4x4(g, c0, cm, a, pm)
                + gauss_legendre_4x4(g, cm, c1, a, pm)
                + gauss_legendre_4x4(g, c0, cm, pm, b)
                + gauss_legendre_4x4(g, cm, c1, pm, b);
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
                    sum += l * gauss_legendre_4x4(gc, x0, x1, y0, y1);
                }
            }
        }
    }
    sum
}
