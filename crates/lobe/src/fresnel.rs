//! Fresnel reflectance: none, Schlick, dielectric and conductor.
//!
//! `eval(cos)` takes the cosine between the direction and the microfacet
//! normal (for reflection `wo·h = wi·h`) and returns the RGB reflectance.

use crate::math::Rgb;
use glam::DVec3;

/// A Fresnel term.
///
/// | variant | parameters | meaning |
/// |---|---|---|
/// | `None` | | `F = 1` (what the albedo tables of the literature use) |
/// | `Schlick` | `f0` RGB in [0, 1] | `F0 + (1 − F0)(1 − cos)⁵` |
/// | `Dielectric` | `eta` RGB, > 0 | exact unpolarized Fresnel, `eta = η_inside / η_outside`; total internal reflection gives 1 |
/// | `Conductor` | `eta`, `k` RGB, `eta` > 0, `k` ≥ 0 | exact Fresnel with a complex index `eta + i k` |
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fresnel {
    None,
    Schlick { f0: Rgb },
    Dielectric { eta: Rgb },
    Conductor { eta: Rgb, k: Rgb },
}

impl Fresnel {
    /// Reflectance for the cosine `cos_theta` (clamped to [0, 1]).
    #[inline]
    #[must_use]
    pub fn eval(&self, cos_theta: f64) -> Rgb {
        let c = cos_theta.clamp(0.0, 1.0);
        match *self {
            Fresnel::None => Rgb::ONE,
            Fresnel::Schlick { f0 } => {
                let m = 1.0 - c;
                let m2 = m * m;
                f0 + (Rgb::ONE - f0) * (m2 * m2 * m)
            }
            Fresnel::Dielectric { eta } => Rgb::new(
                fr_dielectric(c, eta.x),
                fr_dielectric(c, eta.y),
                fr_dielectric(c, eta.z),
            ),
            Fresnel::Conductor { eta, k } => Rgb::new(
                fr_conductor(c, eta.x, k.x),
                fr_conductor(c, eta.y, k.y),
                fr_conductor(c, eta.z, k.z),
            ),
        }
    }
}

/// Unpolarized Fresnel reflectance of a dielectric interface seen from the
/// outside, relative index `eta`, cosine `c` in [0, 1].
#[must_use]
pub fn fr_dielectric(c: f64, eta: f64) -> f64 {
    let sin2_t = (1.0 - c * c) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let ct = (1.0 - sin2_t).sqrt();
    let r_parl = (eta * c - ct) / (eta * c + ct);
    let r_perp = (c - eta * ct) / (c + eta * ct);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// The Fresnel term of a dielectric interface for a direction on either
/// side ([`fresnel_dielectric`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DielectricFresnel {
    /// Reflectance `F` (1 past the critical angle, 0 for `eta = 1`).
    pub r: f64,
    /// Cosine of the refracted direction, on the other side of the
    /// interface from the incident one (sign opposite to `cos_theta_i`;
    /// 0 past the critical angle).
    pub cos_theta_t: f64,
    /// `η_t / η_i`: the index on the other side over the incident one
    /// (Mitsuba's `eta_it`; `eta` itself from outside).
    pub eta_it: f64,
    /// `η_i / η_t`, its reciprocal: the ratio Snell's law scales the
    /// tangential component by (`sin θt = eta_ti sin θi`).
    pub eta_ti: f64,
}

/// Unpolarized Fresnel reflectance of a dielectric interface of relative
/// index `eta = η_inside / η_outside` for a direction whose cosine with the
/// normal is `cos_theta_i`: positive outside, negative inside (then the
/// relative index is `1/eta`). Total internal reflection gives `r = 1`.
#[must_use]
pub fn fresnel_dielectric(cos_theta_i: f64, eta: f64) -> DielectricFresnel {
    let outside = cos_theta_i >= 0.0;
    let (eta_it, eta_ti) = if outside {
        (eta, 1.0 / eta)
    } else {
        (1.0 / eta, eta)
    };
    let ci = cos_theta_i.abs().min(1.0);
    let cos2_t = 1.0 - eta_ti * eta_ti * (1.0 - ci * ci);
    if cos2_t <= 0.0 {
        return DielectricFresnel {
            r: 1.0,
            cos_theta_t: 0.0,
            eta_it,
            eta_ti,
        };
    }
    let ct = cos2_t.sqrt();
    let r = if eta == 1.0 {
        0.0
    } else if ci == 0.0 {
        1.0
    } else {
        // With n = eta_it: r_s = (cos i − n cos t)/(cos i + n cos t),
        // r_p = (n cos i − cos t)/(n cos i + cos t).
        let rs = (ci - eta_it * ct) / (ci + eta_it * ct);
        let rp = (eta_it * ci - ct) / (eta_it * ci + ct);
        0.5 * (rs * rs + rp * rp)
    };
    DielectricFresnel {
        r,
        cos_theta_t: if outside { -ct } else { ct },
        eta_it,
        eta_ti,
    }
}

/// The direction refracted from `w` through an interface of normal `+z`,
/// given [`DielectricFresnel::cos_theta_t`] and `eta_ti` for `w`'s cosine
/// (both directions point away from the surface, on opposite sides).
#[inline]
#[must_use]
pub fn refract(w: DVec3, cos_theta_t: f64, eta_ti: f64) -> DVec3 {
    DVec3::new(-eta_ti * w.x, -eta_ti * w.y, cos_theta_t)
}

/// The direction refracted from `w` through a microfacet of normal `m`
/// (`w·m` either sign), with the relative index `eta` of the interface
/// (`η_inside / η_outside`, inside being below `m`); `None` past the
/// critical angle.
#[inline]
#[must_use]
pub fn refract_about(w: DVec3, m: DVec3, eta: f64) -> Option<DVec3> {
    let c = w.dot(m);
    let f = fresnel_dielectric(c, eta);
    if f.cos_theta_t == 0.0 && f.r == 1.0 && eta != 1.0 {
        return None;
    }
    // w_t = −eta_ti w + (eta_ti c + cos θt) m, with cos θt signed opposite to c.
    Some(m * (f.eta_ti * c + f.cos_theta_t) - w * f.eta_ti)
}

/// Mean Fresnel reflectance of a dielectric interface under uniform
/// (diffuse) light from the side where the relative index is `eta`:
/// `2 ∫₀¹ F(μ, eta) μ dμ`, by Gauss-Legendre quadrature past the critical
/// angle (to about 1e-10; a test checks Stokes' relation between the two
/// sides to 1e-9).
#[must_use]
pub fn diffuse_reflectance(eta: f64) -> f64 {
    // Below the critical cosine (eta < 1) everything is reflected: that
    // part integrates to `μc²` exactly.
    let mu_c = if eta < 1.0 {
        (1.0 - eta * eta).max(0.0).sqrt()
    } else {
        0.0
    };
    let mut sum = mu_c * mu_c;
    // μ = μc + (1 − μc) t²: where F falls from 1 like √(μ − μc), the
    // integrand is smooth in t. 64 intervals in t of 4-point Gauss-Legendre.
    const X: [f64; 4] = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    const W: [f64; 4] = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    let (a, len) = (mu_c, 1.0 - mu_c);
    let n = 64;
    let h = 1.0 / f64::from(n);
    for i in 0..n {
        let c = (f64::from(i) + 0.5) * h;
        for k in 0..4 {
            for sgn in [-1.0, 1.0] {
                let t = c + sgn * 0.5 * h * X[k];
                let mu = a + len * t * t;
                // dμ = 2 len t dt; the rule's weight on [c − h/2, c + h/2] is W h/2.
                sum +=
                    2.0 * (0.5 * h * W[k]) * fresnel_dielectric(mu, eta).r * mu * (2.0 * len * t);
            }
        }
    }
    sum
}

/// Mitsuba 3's fit of [`diffuse_reflectance`] (its
/// `fresnel_diffuse_reflectance`): Egan and Hilgeman's polynomial for
/// `eta < 1`, d'Eon and Irving's otherwise. Plastic uses it for the light
/// the coating sends back into the base; a test bounds its error against
/// the exact integral.
#[must_use]
pub fn diffuse_reflectance_fit(eta: f64) -> f64 {
    if eta < 1.0 {
        -1.4399 * eta * eta + 0.7099 * eta + 0.6681 + 0.0636 / eta
    } else {
        let x = 1.0 / eta;
        0.919_317 + x * (-3.4793 + x * (6.753_35 + x * (-7.809_89 + x * (4.985_54 - 1.368_81 * x))))
    }
}

/// Unpolarized Fresnel reflectance of a conductor with complex index
/// `eta + i k`, cosine `c` in [0, 1].
#[must_use]
pub fn fr_conductor(c: f64, eta: f64, k: f64) -> f64 {
    let n = Complex { re: eta, im: k };
    let sin2_i = 1.0 - c * c;
    // cos θt = sqrt(1 − sin²θi / n²)
    let sin2_t = Complex {
        re: sin2_i,
        im: 0.0,
    }
    .div(n.mul(n));
    let cos_t = Complex {
        re: 1.0 - sin2_t.re,
        im: -sin2_t.im,
    }
    .sqrt();
    let ci = Complex { re: c, im: 0.0 };
    let r_parl = n.mul(ci).sub(cos_t).div(n.mul(ci).add(cos_t));
    let r_perp = ci.sub(n.mul(cos_t)).div(ci.add(n.mul(cos_t)));
    let r = 0.5 * (r_parl.norm2() + r_perp.norm2());
    if r.is_finite() {
        r.clamp(0.0, 1.0)
    } else {
        1.0
    }
}

#[derive(Clone, Copy)]
struct Complex {
    re: f64,
    im: f64,
}

impl Complex {
    fn add(self, o: Self) -> Self {
        Complex {
            re: self.re + o.re,
            im: self.im + o.im,
        }
    }
    fn sub(self, o: Self) -> Self {
        Complex {
            re: self.re - o.re,
            im: self.im - o.im,
        }
    }
    fn mul(self, o: Self) -> Self {
        Complex {
            re: self.re * o.re - self.im * o.im,
            im: self.re * o.im + self.im * o.re,
        }
    }
    fn div(self, o: Self) -> Self {
        let d = o.re * o.re + o.im * o.im;
        Complex {
            re: (self.re * o.re + self.im * o.im) / d,
            im: (self.im * o.re - self.re * o.im) / d,
        }
    }
    fn norm2(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
    /// Principal square root.
    fn sqrt(self) -> Self {
        let m = self.norm2().sqrt();
        let re = (0.5 * (m + self.re)).max(0.0).sqrt();
        let im = (0.5 * (m - self.re)).max(0.0).sqrt().copysign(self.im);
        Complex { re, im }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_known_values() {
        // Normal incidence: ((η − 1)/(η + 1))², 0.04 for η = 1.5.
        assert!((fr_dielectric(1.0, 1.5) - 0.04).abs() < 1e-12);
        // Grazing incidence reflects everything.
        assert!((fr_dielectric(0.0, 1.5) - 1.0).abs() < 1e-12);
        // Brewster angle: r_parallel vanishes, F = r_perp² / 2.
        let tb = 1.5f64.atan();
        let (c, s) = (tb.cos(), tb.sin());
        let ct = (1.0 - s * s / 2.25).sqrt();
        let rs = (c - 1.5 * ct) / (c + 1.5 * ct);
        assert!((fr_dielectric(c, 1.5) - 0.5 * rs * rs).abs() < 1e-12);
        // Total internal reflection from inside glass.
        assert_eq!(fr_dielectric(0.3, 1.0 / 1.5), 1.0);
    }

    #[test]
    fn conductor_matches_dielectric_without_absorption_and_normal_incidence_formula() {
        for &c in &[0.0, 0.1, 0.5, 0.9, 1.0] {
            assert!((fr_conductor(c, 1.5, 0.0) - fr_dielectric(c, 1.5)).abs() < 1e-12);
        }
        // Normal incidence: ((η−1)² + k²) / ((η+1)² + k²).
        let (eta, k) = (0.2, 3.9);
        let expect = ((eta - 1.0) * (eta - 1.0) + k * k) / ((eta + 1.0) * (eta + 1.0) + k * k);
        assert!((fr_conductor(1.0, eta, k) - expect).abs() < 1e-12);
    }

    /// Mitsuba's values for the smooth plastic's default index (its notes),
    /// the fit against the exact integral, and the exact integral against
    /// its closed form at normal-ish indices (Stokes: a white interface
    /// reflects from inside `1 − (1 − F̄_ext)/η²`).
    #[test]
    fn diffuse_reflectance_exact_and_fitted() {
        assert!((diffuse_reflectance_fit(1.5) - 0.091_774_3).abs() < 1e-6);
        assert!((diffuse_reflectance_fit(1.0 / 1.5) - 0.596_811_1).abs() < 1e-6);
        for eta in [1.2, 1.33, 1.5, 1.8, 2.4] {
            let (ext, int) = (diffuse_reflectance(eta), diffuse_reflectance(1.0 / eta));
            assert!(
                (int - (1.0 - (1.0 - ext) / (eta * eta))).abs() < 1e-9,
                "{eta}: {ext} {int}"
            );
            for e in [eta, 1.0 / eta] {
                let (exact, fit) = (diffuse_reflectance(e), diffuse_reflectance_fit(e));
                assert!(
                    (exact - fit).abs() < 6e-3,
                    "eta {e}: exact {exact}, fit {fit}"
                );
            }
        }
        assert_eq!(diffuse_reflectance(1.0), 0.0);
    }

    /// Both sides, total internal reflection, index matching, and the
    /// refracted direction obeys Snell's law.
    #[test]
    fn dielectric_from_either_side() {
        let f = fresnel_dielectric(0.5, 1.5);
        assert!((f.r - 0.089_186_7).abs() < 1e-6 && (f.cos_theta_t + 0.816_496_6).abs() < 1e-6);
        let f = fresnel_dielectric(-0.5, 1.5);
        assert_eq!((f.r, f.cos_theta_t), (1.0, 0.0));
        let f = fresnel_dielectric(-0.9, 1.5);
        assert!((f.r - 0.046_332_6).abs() < 1e-6 && (f.cos_theta_t - 0.756_637_3).abs() < 1e-6);
        assert_eq!(fresnel_dielectric(0.3, 1.0).r, 0.0);
        // Snell: η_o sin θo = η_t sin θt, the refracted direction unit.
        let wo = DVec3::new(0.6, 0.0, 0.8);
        let f = fresnel_dielectric(wo.z, 1.5);
        let wt = refract(wo, f.cos_theta_t, f.eta_ti);
        assert!((wt.length() - 1.0).abs() < 1e-12 && wt.z < 0.0);
        assert!((0.6 - 1.5 * wt.x.hypot(wt.y)).abs() < 1e-12);
        // The same through a tilted microfacet.
        let m = DVec3::new(0.3, 0.1, 0.9).normalize();
        let wt = refract_about(wo, m, 1.5).unwrap();
        let sin = |w: DVec3| w.cross(m).length();
        assert!((sin(wo) - 1.5 * sin(wt)).abs() < 1e-12 && wt.dot(m) < 0.0);
        assert!(
            refract_about(
                DVec3::new(0.9, 0.0, -0.435_889_894_354_067_4),
                DVec3::Z,
                1.5
            )
            .is_none()
        );
    }

    #[test]
    fn schlick_end_points() {
        let f = Fresnel::Schlick {
            f0: Rgb::new(0.04, 0.5, 1.0),
        };
        assert!((f.eval(1.0) - Rgb::new(0.04, 0.5, 1.0)).length() < 1e-15);
        assert!((f.eval(0.0) - Rgb::ONE).length() < 1e-15);
    }
}
