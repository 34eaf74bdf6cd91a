//! Fresnel reflectance: none, Schlick, dielectric and conductor.
//!
//! `eval(cos)` takes the cosine between the direction and the microfacet
//! normal (for reflection `wo·h = wi·h`) and returns the RGB reflectance.

use crate::math::Rgb;

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

    #[test]
    fn schlick_end_points() {
        let f = Fresnel::Schlick {
            f0: Rgb::new(0.04, 0.5, 1.0),
        };
        assert!((f.eval(1.0) - Rgb::new(0.04, 0.5, 1.0)).length() < 1e-15);
        assert!((f.eval(0.0) - Rgb::ONE).length() < 1e-15);
    }
}
