//! Adaptive MIS (`mis`, issue 10): never worse than its parts. Over a grid
//! of materials, views and lights, the allocation a pilot chooses has an
//! exact variance per draw at most 1.1× that of the better single strategy
//! (BSDF sampling by the material's best strategy, or light sampling),
//! with every variance computed by quadrature, not from samples (a
//! heavy-tailed estimator's sample variance can be far too small); and the
//! estimator is unbiased and its sample variance is the one predicted.

use crate::common;

use glam::DVec3;
use lobe::estimator::{
    Allocation, EstimateSettings, ShadingEstimator, ShadingPoint, Strategy, estimate, reference,
};
use lobe::light::LightDistribution;
use lobe::math::luminance;
use lobe::sequence::Sequence;
use lobe::stats::quadrature::{Tolerance, integrate_hemisphere};
use lobe::{Light, Material, Rgb};

/// Exact per-draw variances of one draw of BSDF sampling, of light
/// sampling (plain distribution), and of the 1 + 1 balance heuristic (its
/// per-sample variance, for two draws), and the mean.
struct Exact {
    mu: f64,
    bsdf: f64,
    light: f64,
    balance: f64,
}

fn exact(m: &Material, wo: DVec3, light: &Light) -> Exact {
    let s = m.sampler(m.best_bsdf_strategy()).unwrap();
    let g = |wi: DVec3| luminance(m.eval(wo, wi) * light.radiance(wi)) * wi.z;
    let tol = Tolerance::relative(1e-6);
    let int = |h: &dyn Fn(DVec3) -> f64| integrate_hemisphere(h, tol).value;
    let pb = |wi: DVec3| s.pdf(wo, wi);
    let pc = |wi: DVec3| light.pdf(LightDistribution::Compensated, wi);
    let pl = |wi: DVec3| light.pdf(LightDistribution::Plain, wi);
    let safe = |num: f64, den: f64| if num == 0.0 { 0.0 } else { num / den };
    let mu = int(&|wi| g(wi));
    let bsdf = int(&|wi| safe(g(wi).powi(2), pb(wi))) - mu * mu;
    let light_v = int(&|wi| safe(g(wi).powi(2), pl(wi))) - mu * mu;
    let m2 = int(&|wi| safe(g(wi).powi(2), pb(wi) + pc(wi)));
    let mb = int(&|wi| safe(g(wi) * pb(wi), pb(wi) + pc(wi)));
    let ml = int(&|wi| safe(g(wi) * pc(wi), pb(wi) + pc(wi)));
    Exact {
        mu,
        bsdf,
        light: light_v,
        balance: m2 - mb * mb - ml * ml,
    }
}

fn lights() -> Vec<(&'static str, Light)> {
    vec![
        ("constant", Light::Constant(Rgb::ONE)),
        (
            "beam:5",
            Light::Beam {
                dir: DVec3::new(-0.4, 0.3, 0.8).normalize(),
                exponent: 5.0,
                radiance: Rgb::splat(2.0),
            },
        ),
        (
            "beam:60",
            Light::Beam {
                dir: DVec3::new(0.5, 0.1, 0.7).normalize(),
                exponent: 60.0,
                radiance: Rgb::splat(20.0),
            },
        ),
    ]
}

#[test]
fn adaptive_mis_is_never_worse_than_its_parts() {
    let materials = [
        r#"{"type":"cook-torrance","alpha":0.05}"#,
        r#"{"type":"cook-torrance","alpha":0.2,"fresnel":{"type":"conductor"}}"#,
        r#"{"type":"cook-torrance","alpha":0.5,"kd":0.3,"ks":0.6}"#,
        r#"{"type":"cook-torrance","distribution":"beckmann","alpha":0.1}"#,
        r#"{"type":"lambert"}"#,
        r#"{"type":"phong","exponent":100}"#,
    ];
    let mut worst = (0.0f64, String::new());
    let mut issue_case = None;
    for json in materials {
        let m = common::case(json).material;
        for theta in [0.0, 60.0, 80.0] {
            let wo = common::wo(theta);
            let sp = ShadingPoint::local(wo);
            for (name, light) in lights() {
                let e = exact(&m, wo, &light);
                let plan = EstimateSettings {
                    strategy: Strategy::MIS,
                    sequence: Sequence::Independent,
                    samples: 1 << 16,
                    seed: 3,
                };
                let est = ShadingEstimator::new(Strategy::MIS, &m)
                    .unwrap()
                    .prepare(&sp, &light, &plan);
                let per_draw = match est.allocation() {
                    Allocation::Bsdf => e.bsdf,
                    Allocation::Light => e.light,
                    Allocation::Balance => 2.0 * e.balance,
                };
                // Variances below rounding (a zero-variance strategy) are 0.
                let floor = 1e-12 * e.mu * e.mu;
                let best = e.bsdf.min(e.light).max(floor);
                let ratio = per_draw.max(floor) / best;
                let case = format!(
                    "{json} θo {theta} {name}: chose {}, per draw {per_draw:.3e}, bsdf {:.3e}, light {:.3e}, balance {:.3e}",
                    est.allocation().name(),
                    e.bsdf,
                    e.light,
                    2.0 * e.balance
                );
                eprintln!("{case}: ratio {ratio:.3}");
                if json.contains("0.05") && theta == 60.0 && name == "constant" {
                    issue_case = Some(2.0 * e.balance / e.bsdf);
                }
                if ratio > worst.0 {
                    worst = (ratio, case.clone());
                }
                assert!(
                    per_draw <= 1.1 * best,
                    "{case}: {ratio:.3}× the better strategy"
                );
            }
        }
    }
    eprintln!("worst: {:.3}× ({})", worst.0, worst.1);
    // The issue's case: on a bright even sky, a shiny GGX seen at 60°, the
    // balance heuristic's variance per draw is several times BSDF
    // sampling's, and adaptive MIS does not pay it.
    let r = issue_case.expect("the grid has the issue's case");
    assert!(r > 2.0, "balance / vndf per draw = {r}");
}

/// Unbiased, and the sample variance is the exact variance of the chosen
/// allocation (per sample: two draws).
#[test]
fn adaptive_mis_is_unbiased_with_the_predicted_variance() {
    for json in [
        r#"{"type":"cook-torrance","alpha":0.05}"#,
        r#"{"type":"cook-torrance","alpha":0.5,"kd":0.3,"ks":0.6}"#,
        r#"{"type":"lambert"}"#,
    ] {
        let m = common::case(json).material;
        for (name, light) in lights() {
            let wo = common::wo(60.0);
            let sp = ShadingPoint::local(wo);
            let plan = EstimateSettings {
                strategy: Strategy::MIS,
                sequence: Sequence::Independent,
                samples: 1 << 17,
                seed: 11,
            };
            let acc = estimate(&m, &sp, &light, &plan).unwrap();
            let r = luminance(reference(&m, &sp, &light, 1e-9));
            let mean = acc.lum.mean();
            let se = acc.lum.std_error();
            assert!(
                (mean - r).abs() <= 5.0 * se + 1e-12,
                "{json} {name}: {mean} ± {se} vs {r}"
            );
            let est = ShadingEstimator::new(Strategy::MIS, &m)
                .unwrap()
                .prepare(&sp, &light, &plan);
            let e = exact(&m, wo, &light);
            let predicted = match est.allocation() {
                Allocation::Bsdf => e.bsdf / 2.0,
                Allocation::Light => e.light / 2.0,
                Allocation::Balance => e.balance,
            };
            let var = acc.lum.variance();
            eprintln!(
                "{json} {name}: {} variance {var:.4e}, predicted {predicted:.4e}",
                est.allocation().name()
            );
            if predicted > 1e-20 {
                assert!(
                    (var / predicted - 1.0).abs() < 0.25,
                    "{json} {name}: variance {var} vs predicted {predicted}"
                );
            }
        }
    }
}
