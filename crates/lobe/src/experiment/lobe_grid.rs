//! The lobe in 3D: the luminance of `f·|cos θ|` over a grid of directions
//! (θ from the normal, φ around it), whose surface `value × direction`
//! is the shape a BRDF explorer turns in 3D (`lobe explore`).

use super::histogram::over_sphere;
use crate::Material;
use crate::math::luminance;
use glam::DVec3;

/// [`grid`]'s values.
#[derive(Debug, Clone, PartialEq)]
pub struct LobeGrid {
    /// The polar angles in radians, `n_theta + 1` from 0 to π/2 (to π with
    /// `sphere`).
    pub theta: Vec<f64>,
    /// The azimuths in radians, `n_phi + 1` from 0 to 2π (the last closes
    /// the surface).
    pub phi: Vec<f64>,
    /// Row-major: `values[i * phi.len() + j]` at `theta[i]`, `phi[j]`;
    /// delta parts (no density) are left out.
    pub values: Vec<f64>,
    /// Over the whole sphere: the material transmits, or is seen from
    /// below ([`over_sphere`]).
    pub sphere: bool,
}

/// The luminance of `f(wo, wi)·|cos θi|` at `wi = (sin θ cos φ, sin θ sin
/// φ, cos θ)` over `n_theta + 1` angles θ and `n_phi + 1` azimuths φ (see
/// [`LobeGrid`]); rows in parallel, the same numbers for any thread count.
#[must_use]
pub fn grid(m: &Material, wo: DVec3, n_theta: usize, n_phi: usize) -> LobeGrid {
    let (n_theta, n_phi) = (n_theta.max(1), n_phi.max(1));
    let sphere = over_sphere(m, wo);
    let top = if sphere {
        std::f64::consts::PI
    } else {
        std::f64::consts::FRAC_PI_2
    };
    let theta: Vec<f64> = (0..=n_theta)
        .map(|i| top * i as f64 / n_theta as f64)
        .collect();
    let phi: Vec<f64> = (0..=n_phi)
        .map(|j| std::f64::consts::TAU * j as f64 / n_phi as f64)
        .collect();
    let rows = crate::parallel::map_indices(theta.len(), |i| {
        let (st, ct) = theta[i].sin_cos();
        phi.iter()
            .map(|&p| {
                let (sp, cp) = p.sin_cos();
                let wi = DVec3::new(st * cp, st * sp, ct);
                let v = luminance(m.eval(wo, wi)) * ct.abs();
                if v.is_finite() { v } else { 0.0 }
            })
            .collect::<Vec<f64>>()
    });
    LobeGrid {
        theta,
        phi,
        values: rows.concat(),
        sphere,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lambert_is_a_sphere_of_cosines() {
        // f·cos of a white Lambertian surface is cos θ / π at every φ.
        let m = Material::load(r#"{"type":"diffuse","reflectance":1.0}"#).unwrap();
        let g = grid(&m, DVec3::Z, 8, 6);
        assert!(!g.sphere);
        assert_eq!((g.theta.len(), g.phi.len(), g.values.len()), (9, 7, 63));
        for (i, t) in g.theta.iter().enumerate() {
            for j in 0..g.phi.len() {
                let want = t.cos().max(0.0) / std::f64::consts::PI;
                assert!((g.values[i * 7 + j] - want).abs() < 1e-12, "{t} {j}");
            }
        }
    }

    #[test]
    fn glass_covers_the_sphere_and_peaks_near_the_mirror_direction() {
        let m = Material::load(r#"{"type":"roughconductor","alpha":0.1}"#).unwrap();
        let wo = crate::frame::wo_from_theta(40.0, 0.0);
        let g = grid(&m, wo, 90, 72);
        let (k, _) = g
            .values
            .iter()
            .enumerate()
            .fold((0, 0.0), |b, (k, &v)| if v > b.1 { (k, v) } else { b });
        let (i, j) = (k / g.phi.len(), k % g.phi.len());
        // The mirror direction is at θ 40°, φ 180°.
        assert!(
            (g.theta[i].to_degrees() - 40.0).abs() <= 3.0,
            "{}",
            g.theta[i].to_degrees()
        );
        assert!(
            (g.phi[j].to_degrees() - 180.0).abs() <= 5.0,
            "{}",
            g.phi[j].to_degrees()
        );
        let glass = Material::load(r#"{"type":"roughdielectric","alpha":0.2}"#).unwrap();
        let g = grid(&glass, wo, 10, 8);
        assert!(g.sphere && (g.theta[10] - std::f64::consts::PI).abs() < 1e-12);
        assert!(g.values[g.values.len() - 20..].iter().any(|&v| v > 0.0));
    }
}
