//! The multiple-scattering microfacet reflection of Heitz, Hanika, d'Eon
//! and Dachsbacher 2016 ("Multiple-Scattering Microfacet BSDFs with the
//! Smith Model"): a ray walks a random microsurface (Smith's
//! uncorrelated heights, uniform on `[−1, 1]`, and the slopes of GGX or
//! Beckmann) and bounces off microfacets until it leaves. The reference
//! that energy compensation is judged against.
//!
//! * Sampling is exact: [`RandomWalk::sample`] follows one walk from the
//!   viewer; the direction it leaves in is distributed as `f cos θi`
//!   normalized, and its weight is the product of the reflectances of the
//!   facets it met (1 for a white conductor: the walk loses nothing).
//! * Evaluation is estimated: [`RandomWalk::eval_once`] follows one walk
//!   and adds at every bounce the chance of scattering toward `wi` and
//!   leaving unshadowed (next-event estimation); its mean is `f(wo, wi)`.
//!   [`RandomWalk::eval`] averages `walks` of them with a standard error.
//!
//! Its first bounce is the single-scattering lobe with the
//! height-correlated term `1/(1 + Λo + Λi)`. There is no pdf of a walk, so
//! the walk is not a lobe of [`crate::Material`]: it cannot be drawn by
//! another strategy or weighed by MIS. Conductors only (a reflectance per
//! bounce, tint times Fresnel); walks are cut at [`MAX_BOUNCES`].

use crate::fresnel::Fresnel;
use crate::math::{Rgb, reflect};
use crate::microfacet::{Microfacet, Ndf};
use crate::stats::Moments;
use glam::{DVec2, DVec3};
use rand::RngExt;
use rand_pcg::Pcg64;

/// Bounces after which a walk is cut (its light is lost): far beyond what
/// carries energy (the tests' white walks, α up to 2, all leave before it).
pub const MAX_BOUNCES: u32 = 1000;

/// A height above the microsurface, where every walk starts.
const START_HEIGHT: f64 = 2.0;

/// One walk's result: where it left and with what weight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WalkSample {
    /// The direction it left in (upper hemisphere); `None` if it was cut.
    pub wi: Option<DVec3>,
    /// The product of the reflectances it met (`f cos θi / p`).
    pub weight: Rgb,
    /// Bounces on the microsurface.
    pub bounces: u32,
}

/// An estimate with its standard error, per channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RgbEstimate {
    pub mean: Rgb,
    pub std_error: Rgb,
}

impl RgbEstimate {
    fn of(m: &[Moments; 3]) -> Self {
        RgbEstimate {
            mean: Rgb::new(m[0].mean(), m[1].mean(), m[2].mean()),
            std_error: Rgb::new(m[0].std_error(), m[1].std_error(), m[2].std_error()),
        }
    }
}

/// A random-walk conductor: its microsurface and the reflectance of one
/// facet, `ks F(cos)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RandomWalk {
    microfacet: Microfacet,
    ks: Rgb,
    fresnel: Fresnel,
}

/// `C1(h)`, the height CDF of the uniform distribution on `[−1, 1]`.
#[inline]
fn c1(h: f64) -> f64 {
    (0.5 * (h + 1.0)).clamp(0.0, 1.0)
}

/// Its inverse.
#[inline]
fn inv_c1(u: f64) -> f64 {
    (2.0 * u - 1.0).clamp(-1.0, 1.0)
}

impl RandomWalk {
    /// The walk on `microfacet` (GGX or Beckmann) with facets of
    /// reflectance `ks F`; the error names the distribution it lacks.
    pub fn conductor(
        microfacet: Microfacet,
        ks: Rgb,
        fresnel: Fresnel,
    ) -> crate::error::Result<Self> {
        if !matches!(microfacet.ndf(), Ndf::Ggx | Ndf::Beckmann) {
            return Err(crate::Error::param(
                "distribution",
                "the random walk needs the slopes of ggx or beckmann",
            ));
        }
        Ok(RandomWalk {
            microfacet,
            ks,
            fresnel,
        })
    }

    /// Smith's `Λ` of a direction of travel or view `w` on either side:
    /// `Λ(w)` above the surface, `−1 − Λ(−w)` below it.
    #[inline]
    fn lambda(&self, w: DVec3) -> f64 {
        if w.z >= 0.0 {
            self.microfacet.lambda(w)
        } else {
            -1.0 - self.microfacet.lambda(-w)
        }
    }

    /// The chance that `w` (upper hemisphere) leaves from height `h`
    /// unshadowed: `C1(h)^Λ(w)`.
    #[inline]
    fn g1_at(&self, w: DVec3, h: f64) -> f64 {
        if w.z <= 0.0 {
            return 0.0;
        }
        let l = self.lambda(w);
        if l <= 0.0 { 1.0 } else { c1(h).powf(l) }
    }

    /// The next height where a ray travelling along `wr` from height `h`
    /// meets the microsurface, or `None` if it leaves.
    #[inline]
    fn next_height(&self, wr: DVec3, h: f64, u: f64) -> Option<f64> {
        if wr.z > 0.9999 {
            return None;
        }
        if wr.z < -0.9999 {
            return Some(inv_c1(u * c1(h)));
        }
        if wr.z.abs() < 1e-4 {
            return Some(h);
        }
        if u > 1.0 - self.g1_at(wr, h) {
            return None;
        }
        let l = self.lambda(wr);
        Some(inv_c1(c1(h) / (1.0 - u).powf(1.0 / l)))
    }

    /// A visible normal seen from `w` (either side of the surface).
    #[inline]
    fn sample_visible(&self, w: DVec3, u: DVec2) -> Option<DVec3> {
        match self.microfacet.ndf() {
            // The spherical-cap construction holds for every direction.
            Ndf::Ggx => Some(self.microfacet.sample_visible_caps(w, u)),
            _ => self.microfacet.sample_visible(w, u),
        }
    }

    /// The reflectance of a facet at cosine `c`.
    #[inline]
    fn reflectance(&self, c: f64) -> Rgb {
        self.ks * self.fresnel.eval(c)
    }

    /// The phase function of one bounce, seen from `w` (either side),
    /// toward `wi`: `F D(h) / (4 A(w))`, `A(w) = (1 + Λ(w)) w.z` the
    /// projected area, `h` the half vector.
    #[inline]
    fn phase(&self, w: DVec3, wi: DVec3) -> Rgb {
        let Some(h) = (w + wi).try_normalize() else {
            return Rgb::ZERO;
        };
        let c = w.dot(h);
        if h.z <= 0.0 || c <= 0.0 {
            return Rgb::ZERO;
        }
        let area = (1.0 + self.lambda(w)) * w.z;
        if area <= 0.0 {
            return Rgb::ZERO;
        }
        self.reflectance(c) * (self.microfacet.d(h) / (4.0 * area))
    }

    /// One walk from the viewer at `wo` (upper hemisphere).
    pub fn sample(&self, wo: DVec3, rng: &mut Pcg64) -> WalkSample {
        let mut wr = -wo;
        let mut h = START_HEIGHT;
        let mut weight = Rgb::ONE;
        let mut bounces = 0;
        loop {
            match self.next_height(wr, h, rng.random::<f64>()) {
                None => break,
                Some(next) => h = next,
            }
            bounces += 1;
            let w = -wr;
            let u = DVec2::new(rng.random::<f64>(), rng.random::<f64>());
            let wm = self.sample_visible(w, u);
            let next = wm.map(|wm| (reflect(w, wm), w.dot(wm)));
            match next {
                Some((d, c)) if bounces < MAX_BOUNCES && d.is_finite() && c > 0.0 => {
                    weight *= self.reflectance(c);
                    wr = d;
                }
                _ => {
                    return WalkSample {
                        wi: None,
                        weight: Rgb::ZERO,
                        bounces,
                    };
                }
            }
        }
        WalkSample {
            wi: Some(wr),
            weight,
            bounces,
        }
    }

    /// One estimate of `f(wo, wi)` (no cosine): a walk from `wo` with
    /// next-event estimation toward `wi` at every bounce.
    pub fn eval_once(&self, wo: DVec3, wi: DVec3, rng: &mut Pcg64) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let mut wr = -wo;
        let mut h = START_HEIGHT;
        let mut throughput = Rgb::ONE;
        let mut sum = Rgb::ZERO;
        for _ in 0..MAX_BOUNCES {
            match self.next_height(wr, h, rng.random::<f64>()) {
                None => break,
                Some(next) => h = next,
            }
            let w = -wr;
            let nee = self.phase(w, wi) * self.g1_at(wi, h);
            if nee.is_finite() {
                sum += throughput * nee;
            }
            let u = DVec2::new(rng.random::<f64>(), rng.random::<f64>());
            let Some(wm) = self.sample_visible(w, u) else {
                break;
            };
            let c = w.dot(wm);
            let d = reflect(w, wm);
            if !(c > 0.0 && d.is_finite()) {
                break;
            }
            throughput *= self.reflectance(c);
            wr = d;
        }
        sum / wi.z
    }

    /// The mean of `walks` estimates of `f(wo, wi)` from the stream
    /// `(seed, stream)`.
    #[must_use]
    pub fn eval(&self, wo: DVec3, wi: DVec3, walks: u64, seed: u64, stream: usize) -> RgbEstimate {
        let mut rng = crate::sequence::chunk_rng(seed, stream);
        let mut m = [Moments::new(), Moments::new(), Moments::new()];
        for _ in 0..walks {
            let f = self.eval_once(wo, wi, &mut rng);
            for (k, v) in f.to_array().into_iter().enumerate() {
                m[k].push(v);
            }
        }
        RgbEstimate::of(&m)
    }

    /// The directional albedo `∫ f cos θi dωi` at `wo`: the mean weight of
    /// `walks` walks from the stream `(seed, stream)`.
    #[must_use]
    pub fn albedo(&self, wo: DVec3, walks: u64, seed: u64, stream: usize) -> RgbEstimate {
        let mut rng = crate::sequence::chunk_rng(seed, stream);
        let mut m = [Moments::new(), Moments::new(), Moments::new()];
        for _ in 0..walks {
            let w = self.sample(wo, &mut rng).weight;
            for (k, v) in w.to_array().into_iter().enumerate() {
                m[k].push(v);
            }
        }
        RgbEstimate::of(&m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::microfacet::Shadowing;

    fn wo(theta_deg: f64) -> DVec3 {
        let t = theta_deg.to_radians();
        DVec3::new(t.sin(), 0.0, t.cos())
    }

    /// A white walk loses nothing: every walk leaves, weight 1, upward.
    #[test]
    fn a_white_walk_reflects_everything() {
        for ndf in [Ndf::Ggx, Ndf::Beckmann] {
            for alpha in [0.1, 0.5, 1.0, 2.0] {
                let w = RandomWalk::conductor(
                    Microfacet::new(ndf, alpha, alpha).unwrap(),
                    Rgb::ONE,
                    Fresnel::None,
                )
                .unwrap();
                let mut rng = crate::sequence::chunk_rng(7, 0);
                for theta in [0.0, 45.0, 80.0, 89.0] {
                    for _ in 0..2000 {
                        let s = w.sample(wo(theta), &mut rng);
                        let wi = s.wi.expect("a walk is not cut");
                        assert!(wi.z > 0.0 && (wi.length() - 1.0).abs() < 1e-9, "{wi}");
                        assert_eq!(s.weight, Rgb::ONE);
                    }
                }
            }
        }
    }

    /// The walk's albedo (by sampling) is the integral of its estimated
    /// eval (by quadrature of the estimates), and its first bounce is the
    /// single-scattering lobe with the height-correlated term.
    #[test]
    fn eval_integrates_to_the_sampled_albedo_and_starts_with_single_scattering() {
        let alpha = 0.6;
        let mf = Microfacet::new(Ndf::Ggx, alpha, alpha).unwrap();
        let gold = Fresnel::Conductor {
            eta: Rgb::new(0.143, 0.374, 1.442),
            k: Rgb::new(3.983, 2.385, 1.603),
        };
        let w = RandomWalk::conductor(mf, Rgb::ONE, gold).unwrap();
        let o = wo(60.0);
        let sampled = w.albedo(o, 200_000, 3, 0);
        // Cosine-weighted quadrature over the hemisphere with a few walks
        // per point: ∫ f cos dω = ∫∫ f(μ, φ) μ dμ dφ.
        let (nmu, nphi, walks) = (24, 24, 200);
        let rule = crate::stats::quadrature::gauss_legendre(nmu);
        let mut integral = Rgb::ZERO;
        let mut var = Rgb::ZERO;
        for (a, &(t, wt)) in rule.iter().enumerate() {
            let mu = 0.5 * (t + 1.0);
            for p in 0..nphi {
                let phi = (p as f64 + 0.5) / nphi as f64 * std::f64::consts::TAU;
                let s = (1.0 - mu * mu).sqrt();
                let wi = DVec3::new(s * phi.cos(), s * phi.sin(), mu);
                let e = w.eval(o, wi, walks, 4, a * nphi + p);
                let c = 0.5 * wt * mu * std::f64::consts::TAU / nphi as f64;
                integral += e.mean * c;
                var += e.std_error * e.std_error * c * c;
            }
        }
        for k in 0..3 {
            let se = (var[k] + sampled.std_error[k].powi(2)).sqrt();
            assert!(
                (integral[k] - sampled.mean[k]).abs() < 5.0 * se + 2e-3,
                "channel {k}: quadrature of eval {} vs sampled albedo {} (se {se})",
                integral[k],
                sampled.mean[k]
            );
        }
        // First bounce only: the single-scattering lobe (F = 1 for the check).
        let white = RandomWalk::conductor(mf, Rgb::ONE, Fresnel::None).unwrap();
        let wi = wo(-30.0);
        let single = {
            let h = (o + wi).normalize();
            mf.d(h) * mf.g(Shadowing::SmithCorrelated, o, wi, h) / (4.0 * o.z * wi.z)
        };
        let mut rng = crate::sequence::chunk_rng(11, 0);
        let mut m = Moments::new();
        for _ in 0..200_000 {
            let mut h = START_HEIGHT;
            let first = white.next_height(-o, h, rng.random::<f64>());
            if let Some(next) = first {
                h = next;
                m.push(white.phase(o, wi).x * white.g1_at(wi, h) / wi.z);
            } else {
                m.push(0.0);
            }
        }
        assert!(
            (m.mean() - single).abs() < 5.0 * m.std_error(),
            "first bounce {} ± {} vs single scattering {single}",
            m.mean(),
            m.std_error()
        );
    }
}
