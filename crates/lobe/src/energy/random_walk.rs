//! The multiple-scattering microfacet BSDFs of Heitz, Hanika, d'Eon and
//! Dachsbacher 2016 ("Multiple-Scattering Microfacet BSDFs with the Smith
//! Model"): a ray walks a random microsurface (Smith's uncorrelated
//! heights, uniform on `[−1, 1]`, and the slopes of GGX or Beckmann) and
//! bounces off microfacets until it leaves. The reference that energy
//! compensation is judged against.
//!
//! * A conductor: every bounce reflects, weighted by the facet's
//!   reflectance (tint times Fresnel).
//! * A dielectric: at every bounce the facet reflects with probability
//!   `F` and refracts otherwise, and a refracted ray walks on under the
//!   interface (the same microsurface seen from the other side: heights and
//!   normals negated, the relative index inverted) until it leaves above
//!   (reflected) or below (transmitted). Weights stay 1: the energy that
//!   importance carries, as lobe's dielectric tables count it (no `η²` at
//!   a refraction).
//! * Sampling is exact: [`RandomWalk::sample`] follows one walk from the
//!   viewer; the direction it leaves in is distributed as `f |cos θi|`
//!   normalized, and its weight is the product of the reflectances of the
//!   facets it met (1 for a white conductor and for a dielectric: the walk
//!   loses nothing).
//! * Evaluation is estimated: [`RandomWalk::eval_once`] follows one walk
//!   and adds at every bounce the chance of scattering toward `wi` and
//!   leaving unshadowed (next-event estimation); its mean is `f(wo, wi)`.
//!   [`RandomWalk::eval`] averages `walks` of them with a standard error.
//!
//! Its first bounce is the single-scattering lobe with the
//! height-correlated term `1/(1 + Λo + Λi)`. There is no pdf of a walk, so
//! the walk is not a lobe of [`crate::Material`]: it cannot be drawn by
//! another strategy or weighed by MIS. Walks are cut at [`MAX_BOUNCES`].

use crate::fresnel::{Fresnel, fresnel_dielectric, refract_about};
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

/// What a facet does to light.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Facets {
    /// Reflects, with reflectance `ks F(cos)`.
    Conductor { ks: Rgb, fresnel: Fresnel },
    /// Reflects or refracts; `eta` is the index below the surface over the
    /// index above it.
    Dielectric { eta: f64 },
}

/// A random-walk microsurface: its distribution and what its facets do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RandomWalk {
    microfacet: Microfacet,
    facets: Facets,
}

/// Where a walk is, in the frame of the side it is on (that side's
/// surface normal is `+z`: the upper side's frame is the shading frame,
/// the lower side's is its negation).
#[derive(Debug, Clone, Copy)]
struct Ray {
    /// Direction of travel.
    w: DVec3,
    /// Height.
    h: f64,
    /// Above the surface.
    outside: bool,
}

impl Ray {
    /// A ray leaving (`w` pointing away from the surface, shading frame)
    /// reversed: the ray that arrives along `−w` from its side, high above.
    fn arriving(w: DVec3) -> Ray {
        let outside = w.z > 0.0;
        Ray {
            w: -Ray::side(outside, w),
            h: START_HEIGHT,
            outside,
        }
    }

    /// A shading-frame vector in the frame of the side `outside` says (and
    /// back: the map is its own inverse).
    #[inline]
    fn side(outside: bool, v: DVec3) -> DVec3 {
        if outside { v } else { -v }
    }

    /// Go through the surface at the current point, on along `w_below`
    /// (this side's frame).
    #[inline]
    fn cross(&mut self, w_below: DVec3) {
        self.w = -w_below;
        self.h = -self.h;
        self.outside = !self.outside;
    }
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
        Self::on(microfacet, Facets::Conductor { ks, fresnel })
    }

    /// The walk on a rough dielectric interface: `microfacet` (GGX or
    /// Beckmann), `eta` the index below over the index above; the error
    /// names the field that is wrong.
    pub fn dielectric(microfacet: Microfacet, eta: f64) -> crate::error::Result<Self> {
        if !(eta.is_finite() && eta > 0.0) {
            return Err(crate::Error::param(
                "int_ior",
                format!("the relative index must be positive and finite, not {eta}"),
            ));
        }
        Self::on(microfacet, Facets::Dielectric { eta })
    }

    fn on(microfacet: Microfacet, facets: Facets) -> crate::error::Result<Self> {
        if !matches!(microfacet.ndf(), Ndf::Ggx | Ndf::Beckmann) {
            return Err(crate::Error::param(
                "distribution",
                "the random walk needs the slopes of ggx or beckmann",
            ));
        }
        Ok(RandomWalk { microfacet, facets })
    }

    /// Whether light goes through (a dielectric).
    #[must_use]
    pub fn transmits(&self) -> bool {
        matches!(self.facets, Facets::Dielectric { .. })
    }

    /// The relative index seen from the side `outside` says: the far
    /// side's over the near side's (1 for a conductor, unused).
    #[inline]
    fn eta_from(&self, outside: bool) -> f64 {
        match self.facets {
            Facets::Dielectric { eta } if outside => eta,
            Facets::Dielectric { eta } => 1.0 / eta,
            Facets::Conductor { .. } => 1.0,
        }
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

    /// The reflectance of a facet at cosine `c` (`c > 0`), from the side
    /// `outside` says.
    #[inline]
    fn reflectance(&self, c: f64, outside: bool) -> Rgb {
        match self.facets {
            Facets::Conductor { ks, fresnel } => ks * fresnel.eval(c),
            Facets::Dielectric { .. } => {
                Rgb::splat(fresnel_dielectric(c, self.eta_from(outside)).r)
            }
        }
    }

    /// `A(w) = (1 + Λ(w)) w.z`, the microsurface's area projected along
    /// `w` (either side of the mean surface), per unit area.
    #[inline]
    fn projected_area(&self, w: DVec3) -> f64 {
        (1.0 + self.lambda(w)) * w.z
    }

    /// The phase function of one bounce seen from `v` (the side's frame,
    /// `v` away from the facet) toward `wi` on the same side (`wi.z > 0`):
    /// `F D(h) / (4 A(v))`, `h` the half vector.
    #[inline]
    fn phase(&self, v: DVec3, wi: DVec3, outside: bool) -> Rgb {
        let Some(h) = (v + wi).try_normalize() else {
            return Rgb::ZERO;
        };
        let c = v.dot(h);
        let area = self.projected_area(v);
        if h.z <= 0.0 || c <= 0.0 || area <= 0.0 {
            return Rgb::ZERO;
        }
        self.reflectance(c, outside) * (self.microfacet.d(h) / (4.0 * area))
    }

    /// The phase function of a refraction seen from `v` (the side's frame)
    /// toward `wt` below (`wt.z < 0`): `(1 − F) (v·m) D(m) η² |wt·m| /
    /// (A(v) (v·m + η wt·m)²)`, `m` the generalized half vector, `η` the
    /// far side's index over the near side's.
    #[inline]
    fn phase_through(&self, v: DVec3, wt: DVec3, outside: bool) -> f64 {
        let eta = self.eta_from(outside);
        let Some(m) = (v + wt * eta).try_normalize() else {
            return 0.0;
        };
        let m = if m.z < 0.0 { -m } else { m };
        let (cv, ct) = (v.dot(m), wt.dot(m));
        let area = self.projected_area(v);
        if cv <= 0.0 || ct >= 0.0 || area <= 0.0 {
            return 0.0;
        }
        let f = fresnel_dielectric(cv, eta).r;
        let denom = cv + eta * ct;
        (1.0 - f) * cv * self.microfacet.d(m) * eta * eta * (-ct) / (area * denom * denom)
    }

    /// The ray's next meeting with the microsurface (its height moved
    /// there); `false` if it leaves.
    #[inline]
    fn advance(&self, ray: &mut Ray, u: f64) -> bool {
        match self.next_height(ray.w, ray.h, u) {
            Some(h) => {
                ray.h = h;
                true
            }
            None => false,
        }
    }

    /// One bounce where the ray is: a visible normal (`u`), then a
    /// reflection or (a dielectric's, with probability `1 − F`: `uc`) a
    /// refraction. Returns the weight of the bounce, `None` where the walk
    /// is cut (no normal, a degenerate direction).
    #[inline]
    fn scatter(&self, ray: &mut Ray, u: DVec2, uc: f64) -> Option<Rgb> {
        let v = -ray.w;
        let m = self.sample_visible(v, u)?;
        let c = v.dot(m);
        if c.is_nan() || c <= 0.0 {
            return None;
        }
        match self.facets {
            Facets::Conductor { .. } => {
                let d = reflect(v, m);
                if !d.is_finite() {
                    return None;
                }
                ray.w = d;
                Some(self.reflectance(c, ray.outside))
            }
            Facets::Dielectric { .. } => {
                let eta = self.eta_from(ray.outside);
                let f = fresnel_dielectric(c, eta).r;
                if uc < f {
                    ray.w = reflect(v, m);
                } else {
                    // Into the other medium, whichever way it points (a
                    // steep facet can send it up: it meets the surface again).
                    ray.cross(refract_about(v, m, eta)?.try_normalize()?);
                }
                ray.w.is_finite().then_some(Rgb::ONE)
            }
        }
    }

    /// Next-event estimation from where the ray is toward `wi` (shading
    /// frame): the phase function toward it times the chance that it
    /// leaves from there unshadowed, on the side it points to.
    #[inline]
    fn toward(&self, ray: &Ray, wi: DVec3) -> Rgb {
        let v = -ray.w;
        let w = Ray::side(ray.outside, wi);
        if w.z > 0.0 {
            self.phase(v, w, ray.outside) * self.g1_at(w, ray.h)
        } else if self.transmits() {
            Rgb::splat(self.phase_through(v, w, ray.outside) * self.g1_at(-w, -ray.h))
        } else {
            Rgb::ZERO
        }
    }

    /// Random numbers of one bounce: the visible normal's, and (a
    /// dielectric's) the choice between reflection and refraction.
    #[inline]
    fn bounce_numbers(&self, rng: &mut Pcg64) -> (DVec2, f64) {
        let u = DVec2::new(rng.random::<f64>(), rng.random::<f64>());
        let uc = if self.transmits() {
            rng.random::<f64>()
        } else {
            0.0
        };
        (u, uc)
    }

    /// One walk from the viewer at `wo` (a conductor's above the surface, a
    /// dielectric's either side).
    pub fn sample(&self, wo: DVec3, rng: &mut Pcg64) -> WalkSample {
        let mut ray = Ray::arriving(wo);
        let mut weight = Rgb::ONE;
        let mut bounces = 0;
        while self.advance(&mut ray, rng.random::<f64>()) {
            bounces += 1;
            let (u, uc) = self.bounce_numbers(rng);
            match self.scatter(&mut ray, u, uc) {
                Some(w) if bounces < MAX_BOUNCES => weight *= w,
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
            wi: Some(Ray::side(ray.outside, ray.w)),
            weight,
            bounces,
        }
    }

    /// One estimate of `f(wo, wi)` (no cosine): a walk from `wo` with
    /// next-event estimation toward `wi` at every bounce.
    pub fn eval_once(&self, wo: DVec3, wi: DVec3, rng: &mut Pcg64) -> Rgb {
        if wo.z == 0.0 || wi.z == 0.0 || (!self.transmits() && (wo.z < 0.0 || wi.z < 0.0)) {
            return Rgb::ZERO;
        }
        let mut ray = Ray::arriving(wo);
        let mut throughput = Rgb::ONE;
        let mut sum = Rgb::ZERO;
        for _ in 0..MAX_BOUNCES {
            if !self.advance(&mut ray, rng.random::<f64>()) {
                break;
            }
            let nee = self.toward(&ray, wi);
            if nee.is_finite() {
                sum += throughput * nee;
            }
            let (u, uc) = self.bounce_numbers(rng);
            match self.scatter(&mut ray, u, uc) {
                Some(w) => throughput *= w,
                None => break,
            }
        }
        sum / wi.z.abs()
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
                m.push(white.phase(o, wi, true).x * white.g1_at(wi, h) / wi.z);
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

    /// A dielectric walk loses nothing: every walk leaves, above or below,
    /// with weight 1, from either side.
    #[test]
    fn a_dielectric_walk_loses_nothing() {
        for ndf in [Ndf::Ggx, Ndf::Beckmann] {
            for alpha in [0.1, 0.5, 1.0] {
                let mf = Microfacet::new(ndf, alpha, alpha).unwrap();
                let w = RandomWalk::dielectric(mf, 1.5).unwrap();
                let mut rng = crate::sequence::chunk_rng(5, 0);
                let mut below = 0;
                for theta in [0.0, 45.0, 80.0, 89.0, 100.0, 135.0, 180.0] {
                    for _ in 0..2000 {
                        let s = w.sample(wo(theta), &mut rng);
                        let wi = s.wi.expect("a walk is not cut");
                        assert!((wi.length() - 1.0).abs() < 1e-9, "{wi}");
                        assert_eq!(s.weight, Rgb::ONE);
                        below += usize::from(wi.z < 0.0);
                    }
                }
                // Most light goes through glass, from either side.
                assert!(below > 7000, "{ndf:?} α {alpha}: {below} of 14000 below");
            }
        }
    }

    /// A dielectric walk's estimated eval integrates, over each hemisphere,
    /// to the share of sampled walks that leave there (reflection and
    /// transmission, from outside and from inside): the refraction's phase
    /// function and the shadowing on the far side agree with the sampler.
    #[test]
    fn dielectric_eval_integrates_to_the_sampled_split() {
        let mf = Microfacet::new(Ndf::Ggx, 0.5, 0.5).unwrap();
        let w = RandomWalk::dielectric(mf, 1.5).unwrap();
        for theta in [50.0, 140.0] {
            let o = wo(theta);
            let mut rng = crate::sequence::chunk_rng(9, 0);
            let mut up = Moments::new();
            for _ in 0..200_000 {
                let s = w.sample(o, &mut rng);
                up.push(f64::from(u8::from(s.wi.unwrap().z > 0.0)));
            }
            let (nmu, nphi, walks) = (96, 96, 16);
            let rule = crate::stats::quadrature::gauss_legendre(nmu);
            for side in [1.0, -1.0] {
                let (mut integral, mut var) = (0.0, 0.0);
                for (a, &(t, wt)) in rule.iter().enumerate() {
                    let mu = 0.5 * (t + 1.0);
                    for p in 0..nphi {
                        let phi = (p as f64 + 0.5) / nphi as f64 * std::f64::consts::TAU;
                        let r = (1.0 - mu * mu).sqrt();
                        let wi = DVec3::new(r * phi.cos(), r * phi.sin(), side * mu);
                        let stream = usize::from(side < 0.0) * 10_000 + a * nphi + p;
                        let e = w.eval(o, wi, walks, 4, stream);
                        let c = 0.5 * wt * mu * std::f64::consts::TAU / nphi as f64;
                        integral += e.mean.x * c;
                        var += e.std_error.x * e.std_error.x * c * c;
                    }
                }
                let sampled = if side > 0.0 {
                    up.mean()
                } else {
                    1.0 - up.mean()
                };
                let se = (var + up.std_error().powi(2)).sqrt();
                assert!(
                    (integral - sampled).abs() < 5.0 * se + 5e-3,
                    "θo {theta}, {}: quadrature of eval {integral} vs sampled {sampled} (se {se})",
                    if side > 0.0 { "above" } else { "below" }
                );
            }
        }
    }
}
