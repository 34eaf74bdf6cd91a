//! Exact variances by quadrature: the per-sample variance of uniform
//! hemisphere sampling at one shading point, the baseline of every
//! "vs uniform" ratio, and the largest directional albedo of a material.
//!
//! A measured variance of uniform sampling cannot be trusted for a narrow
//! lobe: with `N` samples that never land in the lobe, the sample variance
//! is far too small (and the ratio against it meaningless). The exact one is
//! `Var = 2π ∫ lum(f L cos)² dω − μ²` with `μ = ∫ lum(f L cos) dω`, since
//! uniform sampling's sample value is `lum(f L cos) · 2π`.

use super::map_indices;
use crate::envmap::EnvMap;
use crate::estimator::ShadingPoint;
use crate::math::{Rgb, luminance, safe_acos};
use crate::stats::quadrature::{
    Tolerance, gauss_legendre_4x4, integrate_hemisphere, integrate_sphere,
};
use crate::{Light, Material};
use glam::DVec3;
use std::f64::consts::TAU;

/// Relative tolerance of the second-moment quadrature of
/// [`uniform_variance`].
pub const SECOND_MOMENT_TOLERANCE: f64 = 1e-7;

/// Evaluation budget of the second-moment quadrature under an analytic
/// light; a lobe too narrow to be resolved within it gives an unreliable
/// variance ([`UniformVariance::reliable`]).
pub const SECOND_MOMENT_MAX_EVALS: usize = 40_000_000;

/// The second-moment quadrature over a measured table, which is piecewise
/// smooth and never reaches [`SECOND_MOMENT_TOLERANCE`]: relative tolerance
/// `1e-5` within `4·10⁶` evaluations, and reliable when the quadrature's
/// own error estimate is within [`TABLE_SECOND_MOMENT_ACCEPT`] of the value.
pub const TABLE_SECOND_MOMENT_TOLERANCE: f64 = 1e-5;
/// See [`TABLE_SECOND_MOMENT_TOLERANCE`].
pub const TABLE_SECOND_MOMENT_MAX_EVALS: usize = 4_000_000;
/// See [`TABLE_SECOND_MOMENT_TOLERANCE`].
pub const TABLE_SECOND_MOMENT_ACCEPT: f64 = 1e-3;

/// The exact per-sample variance of uniform sampling (over the hemisphere
/// of `wo`, or the sphere for a material that transmits) of the luminance
/// of `f L |cos| / p` at one shading point; none (unreliable, infinite) for
/// a material with a delta part, which uniform sampling never draws.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "desc", derive(serde::Serialize))]
pub struct UniformVariance {
    /// `2π ∫ lum(f L cos)² dω − μ²` (never negative).
    pub variance: f64,
    /// `2π ∫ lum(f L cos)² dω`, the second moment of one sample.
    pub second_moment: f64,
    /// Whether the quadrature reached its tolerance; an unreliable value
    /// must not be used as a baseline.
    pub reliable: bool,
    /// How it was computed, in words.
    pub method: &'static str,
}

/// The exact variance of uniform sampling ([`UniformVariance`]), given the
/// luminance `mean` of the reflected radiance (the quadrature reference's).
/// Under an analytic light: adaptive Gauss–Kronrod over the hemisphere.
/// Under an environment map: a sum over its texels, with the radiance
/// constant per texel (the map's nearest-texel lookup), of
/// `∫_texel lum(f L cos)² dω`, each by a refined 4 × 4 Gauss–Legendre rule as
/// in [`crate::estimator::reference_env_row`] (a smooth map's: over the cells
/// where its radiance is bilinear, [`EnvMap::bilinear_cells`]); its rows run in parallel
/// (feature `parallel`) and are summed in row order.
#[must_use]
pub fn uniform_variance(
    m: &Material,
    sp: &ShadingPoint,
    light: &Light,
    mean: f64,
) -> UniformVariance {
    if m.reach().delta {
        return UniformVariance {
            variance: f64::INFINITY,
            second_moment: f64::INFINITY,
            reliable: false,
            method: "none: uniform sampling never draws a delta part (a mirror or a smooth interface)",
        };
    }
    let (integral, reliable, method) = match light {
        Light::Env(map) => {
            let rows = map_indices(map.size().1, |j| env_row_second_moment(m, sp, map, j));
            let sum: f64 = rows.iter().sum();
            (
                sum,
                sum.is_finite(),
                if m.reach().transmits {
                    "exact, by quadrature: 4π Σ ∫ lum(f L |cos|)² dω − μ² over the sphere (refined 4×4 Gauss-Legendre per texel or cell)"
                } else if map.is_smooth() {
                    "exact, by quadrature: 2π Σ_cells ∫ lum(f L cos)² dω − μ² (its radiance interpolated; refined 4×4 Gauss-Legendre per cell between texel centres)"
                } else {
                    "exact, by quadrature: 2π Σ_texels ∫ lum(f L cos)² dω − μ² (refined 4×4 Gauss-Legendre per texel)"
                },
            )
        }
        _ => {
            let wo = sp.wo;
            let table = m.measured().is_some();
            let tol = if table {
                Tolerance::relative(TABLE_SECOND_MOMENT_TOLERANCE)
                    .with_max_evals(TABLE_SECOND_MOMENT_MAX_EVALS)
            } else {
                Tolerance::relative(SECOND_MOMENT_TOLERANCE).with_max_evals(SECOND_MOMENT_MAX_EVALS)
            };
            let g = |wi: DVec3| {
                let y =
                    luminance(m.eval(wo, wi) * light.radiance(sp.frame.to_world(wi))) * wi.z.abs();
                y * y
            };
            let e = if m.reach().transmits || (m.two_sided && wo.z < 0.0) {
                integrate_sphere(g, tol)
            } else {
                integrate_hemisphere(g, tol)
            };
            let close_enough = table && e.error <= TABLE_SECOND_MOMENT_ACCEPT * e.value.abs();
            (
                e.value,
                (e.converged || close_enough) && e.value.is_finite(),
                if m.reach().transmits {
                    "exact, by quadrature: 4π ∫ lum(f L |cos|)² dω − μ² over the sphere (adaptive Gauss-Kronrod)"
                } else {
                    "exact, by quadrature: 2π ∫ lum(f L cos)² dω − μ² (adaptive Gauss-Kronrod)"
                },
            )
        }
    };
    // Uniform sampling's density: over the hemisphere of `wo`, or over the
    // sphere for a material that transmits.
    let area = if m.reach().transmits { 2.0 * TAU } else { TAU };
    let second_moment = area * integral;
    UniformVariance {
        variance: (second_moment - mean * mean).max(0.0),
        second_moment,
        reliable,
        method,
    }
}

/// Row `j` of the environment map's `∫ lum(f L cos)² dω` (without the 2π);
/// a smooth map's ([`EnvMap::smooth`]) band `j` of cells over which its
/// radiance is bilinear ([`EnvMap::bilinear_cells`]), the interpolated `L`
/// in the integrand.
fn env_row_second_moment(m: &Material, sp: &ShadingPoint, map: &EnvMap, j: usize) -> f64 {
    let (wo, frame) = (sp.wo, &sp.frame);
    if map.is_smooth() {
        let mut sum = 0.0;
        for cell in map.bilinear_cells(j) {
            if cell.is_black() {
                continue;
            }
            let g = |c: f64, phi: f64| {
                let theta = safe_acos(c);
                let wi: DVec3 = frame.to_local(map.spherical_to_direction(theta, phi));
                // `f` is zero where the material does not scatter.
                let y = luminance(m.eval(wo, wi) * cell.radiance(theta, phi)) * wi.z.abs();
                y * y
            };
            let ((t0, t1), (p0, p1)) = (cell.theta, cell.phi);
            let mut cell_sum = 0.0;
            add_refined_second_moment(g, (t0.cos(), t1.cos(), p0, p1), &mut cell_sum);
            sum += cell_sum;
        }
        return sum;
    }
    let (w, _) = map.size();
    let mut sum = 0.0;
    for i in 0..w {
        let l: Rgb = map.texel(i, j);
        if l == Rgb::ZERO {
            continue;
        }
        let ((t0, t1), (p0, p1)) = map.texel_region(i, j);
        let g = |c: f64, phi: f64| {
            let d = map.spherical_to_direction(safe_acos(c), phi);
            let wi: DVec3 = frame.to_local(d);
            let y = luminance(m.eval(wo, wi) * l) * wi.z.abs();
            y * y
        };
        add_refined_second_moment(g, (t0.cos(), t1.cos(), p0, p1), &mut sum);
    }
    sum
}

/// Add `∫ g` over `(cos θ, φ) ∈ [c0, c1] × [p0, p1]` to `sum`, cell by
/// accepted cell: the 4 × 4 Gauss–Legendre rule, compared with the same
/// rule on the cell's four quarters and refined where they differ by more
/// than [`SECOND_MOMENT_TOLERANCE`] (relative) and `1e-15` (up to 6 levels).
fn add_refined_second_moment(
    g: impl Fn(f64, f64) -> f64 + Copy,
    (c0, c1, p0, p1): (f64, f64, f64, f64),
    sum: &mut f64,
) {
    let mut stack = vec![(c0, c1, p0, p1, 0u32)];
    while let Some((c0, c1, a, b, depth)) = stack.pop() {
        let whole = gauss_legendre_4x4(g, c0, c1, a, b);
        let (cm, pm) = (0.5 * (c0 + c1), 0.5 * (a + b));
        let quarters = [
            (c0, cm, a, pm),
            (cm, c1, a, pm),
            (c0, cm, pm, b),
            (cm, c1, pm, b),
        ];
        let parts: f64 = quarters
            .iter()
            .map(|&(x0, x1, y0, y1)| gauss_legendre_4x4(g, x0, x1, y0, y1))
            .sum();
        if depth < 6
            && (whole - parts).abs() > SECOND_MOMENT_TOLERANCE * parts.abs().max(1e-300)
            && (whole - parts).abs() > 1e-15
        {
            stack.extend(quarters.map(|(x0, x1, y0, y1)| (x0, x1, y0, y1, depth + 1)));
        } else {
            *sum += parts;
        }
    }
}

/// View angles (degrees from the normal) at which [`max_albedo`] measures
/// the directional albedo.
pub const ALBEDO_THETAS: [f64; 7] = [0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0];

/// The largest directional albedo of a material over [`ALBEDO_THETAS`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "desc", derive(serde::Serialize))]
pub struct MaxAlbedo {
    /// `max_θ ∫ lum(f(wo(θ), wi)) cos θi dωi`: the fraction of a white
    /// furnace's light reflected toward the worst view.
    pub albedo: f64,
    /// The view angle where it is reached, degrees.
    pub theta_deg: f64,
}

impl MaxAlbedo {
    /// Whether the material reflects more than it receives (by more than
    /// the quadrature's error).
    #[must_use]
    pub fn gains_energy(self) -> bool {
        self.albedo > 1.0 + 1e-3
    }
}

/// The largest directional albedo of `m` over a few view angles
/// ([`ALBEDO_THETAS`]), of the flux (glass carrying importance,
/// [`Material::carrying_importance`]), by adaptive quadrature to `1e-5` relative (a budget
/// of 2·10⁶ evaluations per angle, so that a very narrow lobe costs a
/// fraction of a second). A physically plausible material has at most 1.
#[must_use]
pub fn max_albedo(m: &Material) -> MaxAlbedo {
    // Of the flux: radiance refracted into a less dense medium grows by
    // (η_i/η_t)² without any energy being made.
    let m = &m.carrying_importance();
    let mut best = MaxAlbedo {
        albedo: 0.0,
        theta_deg: 0.0,
    };
    for theta in ALBEDO_THETAS {
        let t = theta.to_radians();
        let wo = DVec3::new(t.sin(), 0.0, t.cos());
        let tol = Tolerance::relative(1e-5).with_max_evals(2_000_000);
        let g = |wi: DVec3| luminance(m.eval(wo, wi)) * wi.z.abs();
        let density = if m.reach().transmits {
            integrate_sphere(g, tol).value
        } else {
            integrate_hemisphere(g, tol).value
        };
        let a = density + m.deltas(wo).iter().map(|d| luminance(d.value)).sum::<f64>();
        if a > best.albedo {
            best = MaxAlbedo {
                albedo: a,
                theta_deg: theta,
            };
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Frame;
    use crate::models::Phong;
    use std::sync::Arc;

    /// Lambert (albedo ρ) under a constant light 1: a uniform sample is
    /// `2ρ cos θ`, with mean ρ and second moment `4ρ²/3`, so the variance
    /// is `ρ²/3` exactly.
    #[test]
    fn lambert_under_a_constant_light_has_the_closed_form() {
        let rho = 0.8;
        let m = Material::lambert(Rgb::splat(rho)).unwrap();
        let sp = ShadingPoint::local(DVec3::new(0.5, 0.0, 0.75f64.sqrt()));
        let v = uniform_variance(&m, &sp, &Light::Constant(Rgb::ONE), rho);
        assert!(v.reliable);
        assert!(
            (v.second_moment - 4.0 * rho * rho / 3.0).abs() < 1e-9,
            "{v:?}"
        );
        assert!((v.variance - rho * rho / 3.0).abs() < 1e-9, "{v:?}");
    }

    /// The same closed form under a constant environment map (texel sum).
    #[test]
    fn lambert_under_a_constant_map_has_the_closed_form() {
        let rho = 0.5;
        let m = Material::lambert(Rgb::splat(rho)).unwrap();
        let (map, _) = EnvMap::new(16, 8, vec![Rgb::ONE; 16 * 8], 1.0, 0.0).unwrap();
        let sp = ShadingPoint {
            frame: Frame::from_normal_tangent(DVec3::Y, DVec3::X).unwrap(),
            wo: DVec3::Z,
        };
        let v = uniform_variance(&m, &sp, &Light::Env(Arc::new(map)), rho);
        assert!(v.reliable);
        assert!((v.variance - rho * rho / 3.0).abs() < 1e-6, "{v:?}");
    }

    /// A physically plausible material stays at most 1; Phong with
    /// kd + ks > 1 is found to gain energy.
    #[test]
    fn max_albedo_finds_energy_gain() {
        let lambert = max_albedo(&Material::lambert(Rgb::splat(0.8)).unwrap());
        assert!((lambert.albedo - 0.8).abs() < 1e-4, "{lambert:?}");
        assert!(!lambert.gains_energy());
        let phong = Material::with_diffuse(
            Rgb::splat(0.8),
            crate::Glossy::Phong(Phong::new(Rgb::splat(0.5), 20.0, true).unwrap()),
        )
        .unwrap();
        let a = max_albedo(&phong);
        assert!(a.gains_energy(), "{a:?}");
        assert!(a.albedo > 1.2, "{a:?}");
    }

    /// Glass less dense than its outside (an air bubble in water): its
    /// radiance grows on refraction by `(η_i/η_t)²`, its flux does not, so
    /// no energy gain is found (its radiance-mode albedo is above 1.1).
    #[cfg(feature = "desc")]
    #[test]
    fn glass_into_a_less_dense_medium_makes_no_energy() {
        for json in [
            r#"{"type":"dielectric","int_ior":1.0,"ext_ior":1.33}"#,
            r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.3,"int_ior":1.0,"ext_ior":1.33}"#,
        ] {
            let m = Material::load(json).unwrap();
            let a = max_albedo(&m);
            assert!(!a.gains_energy() && a.albedo > 0.9, "{json}: {a:?}");
            let radiance = max_albedo_of_radiance(&m);
            assert!(radiance > 1.1, "{json}: radiance-mode albedo {radiance}");
        }
    }

    /// The largest albedo at the same angles without the flux view.
    #[cfg(feature = "desc")]
    fn max_albedo_of_radiance(m: &Material) -> f64 {
        ALBEDO_THETAS
            .iter()
            .map(|t| {
                let t = t.to_radians();
                let wo = DVec3::new(t.sin(), 0.0, t.cos());
                let tol = Tolerance::relative(1e-5).with_max_evals(2_000_000);
                integrate_sphere(|wi| luminance(m.eval(wo, wi)) * wi.z.abs(), tol).value
                    + m.deltas(wo).iter().map(|d| luminance(d.value)).sum::<f64>()
            })
            .fold(0.0, f64::max)
    }
}
