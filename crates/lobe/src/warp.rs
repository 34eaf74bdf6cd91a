//! Warps from the unit square to directions, in pairs as in Nori:
//! `square_to_x(u)` draws a direction and `square_to_x_pdf(w)` is its density
//! in solid angle (the disk's: in area). Each pair is chi-square tested in
//! `tests/integration/chi2.rs` (`chi2_warps`; the disk lifted onto the hemisphere), and
//! the samplers use the `_pdf` partners as their densities: the material's
//! `uniform` and `cosine` strategies, Lambert's `brdf`, the Phong and
//! Blinn-Phong lobes ([`cos_power_pdf`]) and the constant and beam lights.

use crate::math::{INV_FOUR_PI, INV_PI, INV_TWO_PI, safe_sqrt};
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_PI_4, PI};

/// Uniform point on the unit disk, Shirley and Chiu's concentric map (keeps
/// strata compact, which matters for stratified and Sobol sequences).
#[inline]
#[must_use]
pub fn square_to_uniform_disk_concentric(u: DVec2) -> DVec2 {
    let o = 2.0 * u - DVec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return DVec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, FRAC_PI_4 * (o.y / o.x))
    } else {
        (o.y, 2.0 * FRAC_PI_4 - FRAC_PI_4 * (o.x / o.y))
    };
    let (s, c) = theta.sin_cos();
    r * DVec2::new(c, s)
}

#[inline]
#[must_use]
pub fn square_to_uniform_disk_concentric_pdf(p: DVec2) -> f64 {
    if p.length_squared() <= 1.0 {
        INV_PI
    } else {
        0.0
    }
}

/// Uniform direction on the whole sphere.
#[inline]
#[must_use]
pub fn square_to_uniform_sphere(u: DVec2) -> DVec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u.y).sin_cos();
    DVec3::new(r * c, r * s, z)
}

#[inline]
#[must_use]
pub fn square_to_uniform_sphere_pdf(_w: DVec3) -> f64 {
    INV_FOUR_PI
}

/// Uniform direction on the upper hemisphere (`z ≥ 0`), density `1/(2π)`.
/// The lecture's baseline strategy.
#[inline]
#[must_use]
pub fn square_to_uniform_hemisphere(u: DVec2) -> DVec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u.y).sin_cos();
    DVec3::new(r * c, r * s, z)
}

#[inline]
#[must_use]
pub fn square_to_uniform_hemisphere_pdf(w: DVec3) -> f64 {
    if w.z > 0.0 { INV_TWO_PI } else { 0.0 }
}

/// Cosine-weighted direction on the upper hemisphere (Malley's method),
/// density `cos θ / π`.
#[inline]
#[must_use]
pub fn square_to_cosine_hemisphere(u: DVec2) -> DVec3 {
    let d = square_to_uniform_disk_concentric(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    DVec3::new(d.x, d.y, z)
}

#[inline]
#[must_use]
pub fn square_to_cosine_hemisphere_pdf(w: DVec3) -> f64 {
    if w.z > 0.0 { w.z * INV_PI } else { 0.0 }
}

/// Direction around `+z` with density `(n+1)/(2π) cosⁿθ` (the lecture's
/// Phong and Blinn-Phong pdf): `cos θ = u₁^(1/(n+1))`, `φ = 2π u₂`.
///
/// Computed through logarithms so that `sin θ` keeps its precision for
/// exponents up to 10⁷.
#[inline]
#[must_use]
pub fn square_to_cos_power(u: DVec2, n: f64) -> DVec3 {
    let (cos_t, sin_t) = cos_sin_of_root(u.x, n + 1.0);
    let (s, c) = (2.0 * PI * u.y).sin_cos();
    DVec3::new(sin_t * c, sin_t * s, cos_t)
}

/// `(cos θ, sin θ)` for `cos θ = u^(1/m)` (`u` in `[0, 1]`, `m > 0`): the
/// polar angle of a cos-power lobe `cos^(m−1)θ` drawn by inversion.
///
/// Computed through logarithms, `cos θ = e^l` and `sin θ = √(−expm1(2l))`
/// with `l = ln(u)/m`, so that `sin θ` keeps its precision when `θ` is tiny
/// (exponents up to 10⁷). `u = 0` gives `cos θ = 0`, `sin θ = 1`: a valid
/// horizon direction.
#[inline]
#[must_use]
pub fn cos_sin_of_root(u: f64, m: f64) -> (f64, f64) {
    let l = u.ln() / m;
    (l.exp(), safe_sqrt(-(2.0 * l).exp_m1()))
}

/// Density of [`square_to_cos_power`]: `(n+1)/(2π) cosⁿθ` for `z > 0`.
#[inline]
#[must_use]
pub fn square_to_cos_power_pdf(w: DVec3, n: f64) -> f64 {
    cos_power_pdf(w.z, n)
}

/// The cos-power density `(n+1)/(2π) cosⁿθ` in solid angle, as a function
/// of `cos θ` (the angle to the lobe's axis), zero for `cos θ ≤ 0`: the
/// density of [`square_to_cos_power`] in a frame around any axis. The
/// Phong and Blinn-Phong samplers and the analytic beam light use it.
#[inline]
#[must_use]
pub fn cos_power_pdf(cos_theta: f64, n: f64) -> f64 {
    if cos_theta > 0.0 {
        (n + 1.0) * INV_TWO_PI * cos_theta.powf(n)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warps_give_unit_vectors_in_the_right_hemisphere() {
        for i in 0..=16 {
            for j in 0..=16 {
                let u = DVec2::new(i as f64 / 16.0, j as f64 / 16.0);
                for w in [
                    square_to_uniform_sphere(u),
                    square_to_uniform_hemisphere(u),
                    square_to_cosine_hemisphere(u),
                    square_to_cos_power(u, 0.0),
                    square_to_cos_power(u, 1e6),
                ] {
                    assert!((w.length() - 1.0).abs() < 1e-12, "{w} from {u}");
                }
                assert!(square_to_cosine_hemisphere(u).z >= 0.0);
                assert!(square_to_uniform_disk_concentric(u).length() <= 1.0 + 1e-12);
            }
        }
    }

    #[test]
    fn cos_power_keeps_precision_for_huge_exponents() {
        let w = square_to_cos_power(DVec2::new(0.5, 0.0), 1e7);
        // cos θ = 0.5^(1/(n+1)) = e^l with l = −ln2/(n+1): sin²θ = 1 − e^{2l} = −2l − 2l² − …
        let l = -std::f64::consts::LN_2 / (1e7 + 1.0);
        let expect = (-2.0 * l - 2.0 * l * l).sqrt();
        assert!(
            (w.x - expect).abs() < 1e-9 * expect,
            "{} vs {}",
            w.x,
            expect
        );
    }
}
