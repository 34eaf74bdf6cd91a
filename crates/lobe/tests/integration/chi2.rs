//! Chi-square goodness of fit of `sample()` against `pdf()` for every model ×
//! strategy over the parameter grid, and the pdf's integral against the
//! probability that a sample is not lost.
//!
//! Significance 0.01 over the whole grid (Šidák). A failure writes the
//! observed and expected tables to `target/tmp/chi2-failures/<case>.csv`.

use crate::common;

use common::{Case, plan};
use glam::DVec2;
use lobe::BsdfStrategy;
use lobe::stats::chi2::{Chi2Settings, chi2_test, sidak, success_probability};

/// Every (case, strategy, θo) of `cases`, in parallel (each is independent
/// and deterministic; the failures are listed in the grid's order).
fn run(cases: Vec<Case>) {
    use rayon::prelude::*;
    let alpha = sidak(0.01, common::grid_size());
    let cfg = Chi2Settings::default();
    let jobs: Vec<(&Case, BsdfStrategy, f64)> = cases
        .iter()
        .flat_map(|c| plan(c).into_iter().map(move |(s, t)| (c, s, t)))
        .collect();
    let count = jobs.len();
    let failures: Vec<String> = jobs
        .par_iter()
        .flat_map_iter(|&(c, s, theta)| {
            let mut failures = Vec::new();
            let m = &c.material;
            let wo = common::wo(theta);
            let t0 = std::time::Instant::now();
            let r = chi2_test(
                &cfg,
                |uc, u| m.sampler(s).unwrap().sample(wo, uc, u).map(|x| x.wi),
                |wi| m.sampler(s).unwrap().pdf(wo, wi),
            );
            let label = format!("{}_{}_theta{}", c.name, s, theta);
            if std::env::var_os("LOBE_CHI2_VERBOSE").is_some() {
                eprintln!(
                    "{label}: p = {:.3e}, dof {}, {:.2} s",
                    r.p_value,
                    r.dof,
                    t0.elapsed().as_secs_f64()
                );
            }
            if !r.passes(alpha) {
                let path = common::write_failure(&r, &cfg, &label);
                failures.push(format!(
                    "{} {s} θ={theta}: χ²={:.1} dof={} p={:.3e} < {alpha:.2e} {} (tables: {})",
                    c.json,
                    r.statistic,
                    r.dof,
                    r.p_value,
                    r.message.clone().unwrap_or_default(),
                    path.display()
                ));
            }
            // ∫ pdf dω over the sphere = probability that a sample is not lost.
            let p = m.glossy_probability(wo);
            let lobes: Vec<(f64, f64)> = match s {
                BsdfStrategy::Uniform | BsdfStrategy::Cosine => vec![(1.0, 0.5)],
                _ => vec![(p, 0.5 * p), (1.0 - p, 0.5 * (1.0 + p))],
            };
            let kept = success_probability(
                |uc, u: DVec2| m.sampler(s).unwrap().sample(wo, uc, u).is_some(),
                &lobes,
                1024,
            );
            if (r.pdf_integral - kept).abs() > 1e-3 {
                failures.push(format!(
                    "{} {s} θ={theta}: ∫pdf = {:.6} but {:.6} of the samples are kept",
                    c.json, r.pdf_integral, kept
                ));
            }
            failures
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {count} tests failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn chi2_lambert() {
    run(common::lambert_family());
}

#[test]
fn chi2_phong_and_blinn_phong() {
    run(common::phong_family());
}

#[test]
fn chi2_microfacet_ggx() {
    run(common::microfacet_family()
        .into_iter()
        .filter(|c| c.json.contains("ggx"))
        .collect());
}

#[test]
fn chi2_microfacet_beckmann_and_blinn_ndf() {
    run(common::microfacet_family()
        .into_iter()
        .filter(|c| !c.json.contains("ggx"))
        .collect());
}

/// Every warp of `lobe::warp` against its `_pdf` partner, Nori style. The
/// disk is tested on the hemisphere: a uniform point `p` of the unit disk
/// lifted to `(p, √(1 − |p|²))` has the solid-angle density
/// `pdf_disk(p) · cos θ` (Malley's projection).
#[test]
fn chi2_warps() {
    use glam::DVec3;
    use lobe::warp;
    type Sampler = Box<dyn Fn(DVec2) -> DVec3>;
    type Pdf = Box<dyn Fn(DVec3) -> f64>;
    let lift = |p: glam::DVec2| DVec3::new(p.x, p.y, (1.0 - p.length_squared()).max(0.0).sqrt());
    let mut warps: Vec<(String, Sampler, Pdf)> = vec![
        (
            "uniform_disk_concentric".into(),
            Box::new(move |u| lift(warp::square_to_uniform_disk_concentric(u))),
            Box::new(|w: DVec3| {
                warp::square_to_uniform_disk_concentric_pdf(w.truncate()) * w.z.max(0.0)
            }),
        ),
        (
            "uniform_sphere".into(),
            Box::new(warp::square_to_uniform_sphere),
            Box::new(warp::square_to_uniform_sphere_pdf),
        ),
        (
            "uniform_hemisphere".into(),
            Box::new(warp::square_to_uniform_hemisphere),
            Box::new(warp::square_to_uniform_hemisphere_pdf),
        ),
        (
            "cosine_hemisphere".into(),
            Box::new(warp::square_to_cosine_hemisphere),
            Box::new(warp::square_to_cosine_hemisphere_pdf),
        ),
    ];
    for n in [0.0, 1.0, 10.0, 100.0, 1e4] {
        warps.push((
            format!("cos_power_n{n}"),
            Box::new(move |u| warp::square_to_cos_power(u, n)),
            Box::new(move |w| warp::square_to_cos_power_pdf(w, n)),
        ));
    }
    let alpha = sidak(0.01, warps.len());
    let cfg = Chi2Settings::default();
    let mut failures = Vec::new();
    for (name, sample, pdf) in &warps {
        let r = chi2_test(&cfg, |_, u| Some(sample(u)), pdf);
        if !r.passes(alpha) || (r.pdf_integral - 1.0).abs() > 1e-3 {
            let path = common::write_failure(&r, &cfg, &format!("warp_{name}"));
            failures.push(format!(
                "{name}: χ²={:.1} dof={} p={:.3e} < {alpha:.2e}, ∫pdf = {:.6} {} (tables: {})",
                r.statistic,
                r.dof,
                r.p_value,
                r.pdf_integral,
                r.message.clone().unwrap_or_default(),
                path.display()
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The harness can fail: a sampler checked against the wrong pdf is caught.
#[test]
fn chi2_catches_a_wrong_pdf() {
    let c = common::case(r#"{"type":"blinn-phong","exponent":20}"#);
    let m = c.material;
    let wo = common::wo(30.0);
    // The lecture's density over half vectors, used as if it were over wi.
    let r = chi2_test(
        &Chi2Settings::default(),
        |uc, u| {
            m.sampler(BsdfStrategy::Brdf)
                .unwrap()
                .sample(wo, uc, u)
                .map(|x| x.wi)
        },
        |wi| {
            let h = (wo + wi).normalize();
            if wi.z > 0.0 {
                21.0 / (2.0 * std::f64::consts::PI) * h.z.powf(20.0)
            } else {
                0.0
            }
        },
    );
    assert!(r.p_value < 1e-12, "p = {}", r.p_value);
}
