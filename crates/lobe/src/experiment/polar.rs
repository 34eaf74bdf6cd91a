//! Curves in the plane of incidence: the numbers of `lobe plot --kind polar`
//! and of the report's polar figures.
//!
//! The plane of incidence holds the normal (`+z`) and `wo`; a direction in
//! it is given by its signed angle `θi ∈ [−π/2, π/2]` from the normal,
//! positive on the viewer's side: `wi = (sin θi cos φo, sin θi sin φo,
//! cos θi)` where `φo` is the azimuth of `wo` (0 when `wo` is the normal).
//! So with `wo = (sin θo, 0, cos θo)` the viewer is at `θi = +θo` and the
//! mirror direction at `θi = −θo`, and `sin θi` is the direction's `x`:
//! the figures draw a point at [`figure_xy`], the viewer on the right and
//! the mirror side on the left, as the projected-hemisphere maps (the
//! warp-test histogram, the weight heat map, `x` to the right) and the
//! fit's incidence-plane plot ([`crate::fit::incidence_plane`]) do.
//!
//! Where the material transmits, or is seen from below (two-sided), the
//! curves go round the whole circle ([`PolarCurves::full_circle`]): `θi`
//! from −π to π, the directions below the surface at `|θi| > π/2`, so that
//! the transmitted lobe is drawn under the surface line. Delta parts (a
//! mirror reflection, smooth refraction) have no density and no curve.
//!
//! Two kinds of curve share one unit, 1/sr, so they can be drawn over the
//! same axes: the integrand of the furnace estimate divided by its integral,
//! `f·cos θi / albedo` (the density of a zero-variance sampler), and the pdf
//! in solid angle of a BSDF strategy. Where a strategy's pdf is much lower
//! than the integrand, the few samples that land there carry large weights.

use super::histogram::over_sphere;
use crate::estimator::{ShadingPoint, delta_reference, reference};
use crate::math::luminance;
use crate::{BsdfStrategy, Error, Light, Material, Rgb};
use glam::DVec3;

/// Relative tolerance of the quadrature albedo of [`integrand`].
pub const ALBEDO_TOLERANCE: f64 = 1e-6;

/// Points of a curve by default: 0.25° apart from −90° to 90° (twice as
/// many round the full circle).
pub const DEFAULT_STEPS: usize = 720;

/// What a [`PolarCurve`] shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CurveKind {
    /// `f·cos θi / albedo` in luminance: the cosine is included, and the
    /// curve is the density (1/sr) of a sampler with zero variance.
    Integrand,
    /// The pdf in solid angle (1/sr) of a BSDF strategy.
    Pdf(BsdfStrategy),
}

/// One curve in the plane of incidence.
#[derive(Debug, Clone, PartialEq)]
pub struct PolarCurve {
    /// What the values are.
    pub kind: CurveKind,
    /// `(θi in radians, value in 1/sr)`, θi increasing from −π/2 to π/2
    /// (−π to π round the full circle).
    pub points: Vec<(f64, f64)>,
}

impl PolarCurve {
    /// A legend text: `f·cos θi ÷ albedo (ideal pdf)` or `pdf vndf`.
    #[must_use]
    pub fn label(&self) -> String {
        match self.kind {
            CurveKind::Integrand => "f·cos θi ÷ albedo (ideal pdf)".to_string(),
            CurveKind::Pdf(s) => format!("pdf {s}"),
        }
    }

    /// The largest value (0 when there is none, non-finite values left out).
    #[must_use]
    pub fn max(&self) -> f64 {
        self.points
            .iter()
            .map(|p| p.1)
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max)
    }
}

/// The integrand and the pdfs at one view.
#[derive(Debug, Clone, PartialEq)]
pub struct PolarCurves {
    /// The view.
    pub wo: DVec3,
    /// The directional albedo `∫ f cos θi dω` (luminance) by quadrature,
    /// which divides the integrand.
    pub albedo: f64,
    /// `f·cos θi / albedo`.
    pub integrand: PolarCurve,
    /// One pdf per strategy asked for, in the order asked.
    pub pdfs: Vec<PolarCurve>,
    /// The curves go round the whole circle (the material transmits, or is
    /// seen from below), not over the upper half only.
    pub full_circle: bool,
}

impl PolarCurves {
    /// The integrand first, then the pdfs.
    #[must_use]
    pub fn all(&self) -> Vec<&PolarCurve> {
        std::iter::once(&self.integrand).chain(&self.pdfs).collect()
    }
}

/// The signed angles of `steps + 1` points from −π/2 to π/2 (radians), or
/// with `full_circle` of `2 steps + 1` points from −π to π.
#[must_use]
pub fn angles(steps: usize, full_circle: bool) -> Vec<f64> {
    let steps = steps.max(1);
    let (n, half) = if full_circle {
        (2 * steps, 180.0)
    } else {
        (steps, 90.0)
    };
    (0..=n)
        .map(|i| (-half + 2.0 * half * i as f64 / n as f64).to_radians())
        .collect()
}

/// Whether the curves of `m` at `wo` go round the whole circle: where the
/// maps cover the whole sphere ([`over_sphere`]: it transmits, or it is
/// seen from below).
#[must_use]
pub fn full_circle(m: &Material, wo: DVec3) -> bool {
    over_sphere(m, wo)
}

/// Where a polar figure draws the point at signed angle `theta_i` (radians)
/// and radius `r`: `(r sin θi, r cos θi)`, `x` to the right and the normal
/// up, so that a direction lies on the side of its own `x` in the
/// projected-hemisphere maps (for `wo` of azimuth 0): the mirror side on
/// the left, the viewer on the right.
#[must_use]
pub fn figure_xy(theta_i: f64, r: f64) -> (f64, f64) {
    (r * theta_i.sin(), r * theta_i.cos())
}

/// The unit direction at signed angle `theta_i` (radians) in the plane of
/// incidence of `wo` (see the module documentation).
#[must_use]
pub fn plane_direction(wo: DVec3, theta_i: f64) -> DVec3 {
    let h = DVec3::new(wo.x, wo.y, 0.0);
    let (cx, cy) = if h.length_squared() > 1e-24 {
        let h = h.normalize();
        (h.x, h.y)
    } else {
        (1.0, 0.0)
    };
    let s = theta_i.sin();
    DVec3::new(s * cx, s * cy, theta_i.cos()).normalize()
}

/// The directional albedo `∫ f |cos θi| dω` at `wo` of the material's
/// density (luminance; the cosine is included; over the sphere where it
/// transmits), by adaptive quadrature to [`ALBEDO_TOLERANCE`]: delta parts
/// (a mirror reflection, smooth refraction), which have no curve, are left
/// out, so that the integrand of [`integrand`] integrates to 1.
#[must_use]
pub fn albedo(m: &Material, wo: DVec3) -> f64 {
    let sp = ShadingPoint::local(wo);
    let light = Light::Constant(Rgb::ONE);
    luminance(reference(m, &sp, &light, ALBEDO_TOLERANCE) - delta_reference(m, &sp, &light))
}

/// `f·|cos θi| / albedo` (luminance, cosine included) at the [`angles`]
/// of `steps` ([`full_circle`] where it applies), given the albedo; zero
/// everywhere when the albedo is not positive.
#[must_use]
pub fn integrand(m: &Material, wo: DVec3, albedo: f64, steps: usize) -> PolarCurve {
    let full = full_circle(m, wo);
    let scale = if albedo > 0.0 && albedo.is_finite() {
        1.0 / albedo
    } else {
        0.0
    };
    PolarCurve {
        kind: CurveKind::Integrand,
        points: angles(steps, full)
            .into_iter()
            .map(|t| {
                let wi = plane_direction(wo, t);
                let cos = if full { wi.z.abs() } else { wi.z.max(0.0) };
                (t, luminance(m.eval(wo, wi)) * cos * scale)
            })
            .collect(),
    }
}

/// The pdf in solid angle of `strategy` at the [`angles`] of `steps`
/// ([`full_circle`] where it applies). The error says why the strategy does
/// not apply to `m`.
pub fn pdf(
    m: &Material,
    strategy: BsdfStrategy,
    wo: DVec3,
    steps: usize,
) -> Result<PolarCurve, Error> {
    let sampler = m.sampler(strategy)?;
    Ok(PolarCurve {
        kind: CurveKind::Pdf(strategy),
        points: angles(steps, full_circle(m, wo))
            .into_iter()
            .map(|t| (t, sampler.pdf(wo, plane_direction(wo, t))))
            .collect(),
    })
}

/// The integrand and the pdf of each of `strategies` at `wo`, each at
/// `steps + 1` angles. The error names the first strategy that does not
/// apply.
pub fn curves(
    m: &Material,
    wo: DVec3,
    strategies: &[BsdfStrategy],
    steps: usize,
) -> Result<PolarCurves, Error> {
    let a = albedo(m, wo);
    let pdfs = strategies
        .iter()
        .map(|&s| pdf(m, s, wo, steps))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(PolarCurves {
        wo,
        albedo: a,
        integrand: integrand(m, wo, a, steps),
        pdfs,
        full_circle: full_circle(m, wo),
    })
}

/// The strategies of a polar figure when none is chosen: every strategy of
/// `m` but spherical caps (the same density as visible normals).
#[must_use]
pub fn default_strategies(m: &Material) -> Vec<BsdfStrategy> {
    m.strategies()
        .into_iter()
        .filter(|&s| s != BsdfStrategy::SphericalCaps)
        .collect()
}

/// `2π ∫ v(θ) sin θ dθ` over `θ ∈ [0, π/2]` from the curve's points on one
/// side (`side = 1.0` the viewer's side, `−1.0` the mirror side), by the
/// trapezoidal rule: the integral over the hemisphere of a curve that does
/// not depend on the azimuth (any curve at `wo = +z` of an isotropic
/// material, or uniform and cosine sampling).
#[must_use]
pub fn hemisphere_integral(curve: &PolarCurve, side: f64) -> f64 {
    let pts: Vec<(f64, f64)> = curve
        .points
        .iter()
        .filter(|p| p.0 * side >= 0.0)
        .map(|&(t, v)| (t.abs(), if v.is_finite() { v } else { 0.0 }))
        .collect();
    let mut sum = 0.0;
    for w in pts.windows(2) {
        let (a, b) = (w[0], w[1]);
        sum += 0.5 * (a.1 * a.0.sin() + b.1 * b.0.sin()) * (b.0 - a.0).abs();
    }
    std::f64::consts::TAU * sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::wo_from_theta;

    #[cfg(feature = "desc")]
    fn ggx(alpha: f64) -> Material {
        crate::MaterialDesc::from_json(&format!(
            r#"{{"type":"cook-torrance","distribution":"ggx","alpha":{alpha}}}"#
        ))
        .unwrap()
        .build()
        .unwrap()
    }

    #[test]
    fn lambert_with_cosine_sampling_is_the_ideal_pdf() {
        let m = Material::lambert(Rgb::splat(0.6)).unwrap();
        let wo = wo_from_theta(40.0, 0.0);
        let c = curves(&m, wo, &[BsdfStrategy::Cosine], 360).unwrap();
        assert!((c.albedo - 0.6).abs() < 1e-6, "albedo {}", c.albedo);
        assert_eq!(c.pdfs.len(), 1);
        for (a, b) in c.integrand.points.iter().zip(&c.pdfs[0].points) {
            assert_eq!(a.0, b.0);
            assert!((a.1 - b.1).abs() < 1e-6, "θi {}: {} vs {}", a.0, a.1, b.1);
        }
        // cos θi / π at the normal.
        assert!((c.integrand.max() - std::f64::consts::FRAC_1_PI).abs() < 1e-6);
    }

    #[cfg(feature = "desc")]
    #[test]
    fn pdfs_integrate_to_the_kept_fraction_at_the_normal() {
        let m = ggx(0.3);
        let s = [
            BsdfStrategy::Uniform,
            BsdfStrategy::Cosine,
            BsdfStrategy::Brdf,
            BsdfStrategy::Vndf,
        ];
        let c = curves(&m, DVec3::Z, &s, 20_000).unwrap();
        for curve in c.all() {
            // A pdf integrates to the fraction of samples that stay above
            // the horizon (brdf sampling loses the reflections of steep
            // microfacets); the ideal pdf to one.
            let kept = match curve.kind {
                CurveKind::Integrand => 1.0,
                CurveKind::Pdf(st) => {
                    1.0 - crate::experiment::histogram::lost_fraction(&m, st, DVec3::Z, 400_000, 7)
                        .unwrap()
                }
            };
            for side in [-1.0, 1.0] {
                let i = hemisphere_integral(curve, side);
                assert!((i - kept).abs() < 3e-3, "{}: {i} vs {kept}", curve.label());
            }
        }
        assert!(
            hemisphere_integral(&c.pdfs[2], 1.0) < 0.95,
            "brdf loses samples"
        );
    }

    #[cfg(feature = "desc")]
    /// Rough glass at the normal: the curves go round the full circle,
    /// the integrand integrates to 1 over the sphere (both sides' halves,
    /// up to θ = π), most of it below the surface, and each pdf to the
    /// fraction of its samples that are kept.
    #[cfg(feature = "desc")]
    #[test]
    fn glass_goes_round_the_full_circle_and_integrates_to_one() {
        let m = Material::load(r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.3}"#)
            .unwrap();
        let c = curves(
            &m,
            DVec3::Z,
            &[BsdfStrategy::Uniform, BsdfStrategy::Vndf],
            DEFAULT_STEPS,
        )
        .unwrap();
        assert!(c.full_circle);
        assert_eq!(c.integrand.points.len(), 2 * DEFAULT_STEPS + 1);
        let (first, last) = (
            c.integrand.points[0].0,
            c.integrand.points[2 * DEFAULT_STEPS].0,
        );
        assert!(
            (first + std::f64::consts::PI).abs() < 1e-12
                && (last - std::f64::consts::PI).abs() < 1e-12
        );
        let whole = |curve: &PolarCurve| {
            0.5 * (hemisphere_integral(curve, 1.0) + hemisphere_integral(curve, -1.0))
        };
        let i = whole(&c.integrand);
        assert!((i - 1.0).abs() < 2e-3, "integrand over the sphere: {i}");
        let below: f64 = c
            .integrand
            .points
            .iter()
            .filter(|p| p.0.abs() > std::f64::consts::FRAC_PI_2)
            .map(|p| p.1)
            .sum();
        let above: f64 = c
            .integrand
            .points
            .iter()
            .filter(|p| p.0.abs() < std::f64::consts::FRAC_PI_2)
            .map(|p| p.1)
            .sum();
        assert!(below > 5.0 * above, "below {below}, above {above}");
        let uniform = whole(&c.pdfs[0]);
        assert!(
            (uniform - 1.0).abs() < 1e-3,
            "uniform over the sphere: {uniform}"
        );
        let vndf = whole(&c.pdfs[1]);
        assert!(vndf > 0.9 && vndf < 1.0 + 1e-3, "vndf: {vndf}");
        // Smooth glass has no density: the albedo of its curves is 0.
        let smooth = Material::load(r#"{"type":"dielectric"}"#).unwrap();
        assert_eq!(albedo(&smooth, DVec3::Z), 0.0);
    }

    #[test]
    fn the_peak_is_on_the_mirror_side_and_strategies_are_checked() {
        let m = ggx(0.1);
        let wo = wo_from_theta(50.0, 30.0);
        let c = curves(&m, wo, &[BsdfStrategy::Vndf], 720).unwrap();
        let (t, _) = c
            .pdfs
            .first()
            .unwrap()
            .points
            .iter()
            .copied()
            .fold((0.0, 0.0), |a, p| if p.1 > a.1 { p } else { a });
        assert!(
            (t.to_degrees() + 50.0).abs() < 5.0,
            "peak at {}°",
            t.to_degrees()
        );
        // The plane of incidence holds wo at +θo.
        let v = plane_direction(wo, 50f64.to_radians());
        assert!((v - wo).length() < 1e-12, "{v} vs {wo}");
        let lambert = Material::lambert(Rgb::splat(0.5)).unwrap();
        assert!(curves(&lambert, wo, &[BsdfStrategy::Vndf], 10).is_err());
        assert_eq!(
            default_strategies(&m),
            [
                BsdfStrategy::Uniform,
                BsdfStrategy::Cosine,
                BsdfStrategy::Brdf,
                BsdfStrategy::Vndf,
                BsdfStrategy::BoundedVndf
            ]
        );
    }

    /// Issue 41: the polar figure and the warp-test histogram put the
    /// mirror side on the same side. For a sharp Phong lobe at θo = 45°
    /// (wo toward +x), the polar curve's peak is drawn at negative x, and
    /// the histogram's fullest column is at negative x; the viewer's
    /// direction is drawn at positive x, its own.
    #[cfg(feature = "desc")]
    #[test]
    fn the_polar_figure_and_the_histogram_agree_in_orientation() {
        let m = crate::MaterialDesc::from_json(r#"{"type":"phong","exponent":200}"#)
            .unwrap()
            .build()
            .unwrap();
        let wo = wo_from_theta(45.0, 0.0);
        assert!(wo.x > 0.0);
        let c = curves(&m, wo, &[BsdfStrategy::Brdf], 720).unwrap();
        for curve in c.all() {
            let (t, _) = curve
                .points
                .iter()
                .copied()
                .fold((0.0, 0.0), |a, p| if p.1 > a.1 { p } else { a });
            let (x, _) = figure_xy(t, 1.0);
            // Drawn where the direction's own x is.
            assert!((x - plane_direction(wo, t).x).abs() < 1e-12);
            assert!(
                x < -0.6,
                "{}: peak at θi {}°, x {x}",
                curve.label(),
                t.to_degrees()
            );
        }
        assert!((figure_xy(45f64.to_radians(), 1.0).0 - wo.x).abs() < 1e-12);
        let res = 32;
        let h = crate::experiment::histogram::projected_histograms(
            &m.sampler(BsdfStrategy::Brdf).unwrap(),
            wo,
            100_000,
            1,
            res,
            &(),
        );
        let column = |i: usize| (0..res).map(|j| h.observed[j * res + i]).sum::<f64>();
        let fullest = (0..res)
            .max_by(|&a, &b| column(a).total_cmp(&column(b)))
            .unwrap();
        let x = (fullest as f64 + 0.5) / res as f64 * 2.0 - 1.0;
        assert!(x < -0.6, "the histogram's fullest column is at x {x}");
    }
}
