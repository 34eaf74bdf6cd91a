//! Deterministic properties of every model: sample/pdf/weight agree,
//! reciprocity, energy conservation, the known values of the literature,
//! unbiasedness (Student t-test against quadrature), no NaN under extreme
//! inputs, and bad parameters refused.

use crate::common;

use glam::{DVec2, DVec3};
use lobe::math::{Rgb, luminance};
use lobe::stats::quadrature::{Tolerance, integrate_hemisphere};
use lobe::stats::ttest::{Moments, t_test};
use lobe::{BsdfStrategy, Material};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;

/// Directional albedo `∫ f cos dωi` (luminance) by deterministic quadrature.
fn albedo(m: &Material, wo: DVec3) -> f64 {
    integrate_hemisphere(
        |wi| luminance(m.eval(wo, wi)) * wi.z,
        Tolerance::relative(1e-7),
    )
    .value
}

fn random_wo(rng: &mut Pcg64) -> DVec3 {
    let z: f64 = rng.random::<f64>().max(1e-3);
    let phi = 2.0 * std::f64::consts::PI * rng.random::<f64>();
    let r = (1.0 - z * z).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[test]
fn sample_pdf_and_weight_agree_with_pdf_and_eval() {
    let mut rng = Pcg64::seed_from_u64(7);
    for c in common::all_cases() {
        let m = c.material;
        for s in m.strategies() {
            for _ in 0..2000 {
                let wo = random_wo(&mut rng);
                let (uc, u) = (rng.random::<f64>(), DVec2::new(rng.random(), rng.random()));
                let Some(x) = m.sampler(s).unwrap().sample(wo, uc, u) else {
                    continue;
                };
                assert!(
                    x.wi.z > 0.0 && (x.wi.length() - 1.0).abs() < 1e-9,
                    "{} {s}: wi {}",
                    c.json,
                    x.wi
                );
                let pdf = m.sampler(s).unwrap().pdf(wo, x.wi);
                assert!(
                    (x.pdf - pdf).abs() <= 1e-4 * pdf,
                    "{} {s}: sample pdf {} vs pdf() {pdf}",
                    c.json,
                    x.pdf
                );
                let f = m.eval(wo, x.wi);
                let w = f * x.wi.z / pdf;
                assert!(
                    (x.weight - w).abs().max_element() <= 1e-4 * w.max_element().max(1e-300),
                    "{} {s}: weight",
                    c.json
                );
                assert!(
                    (x.f - f).abs().max_element() <= 1e-9 * f.max_element(),
                    "{} {s}: f",
                    c.json
                );
            }
        }
    }
}

#[test]
fn eval_is_reciprocal() {
    let mut rng = Pcg64::seed_from_u64(8);
    for c in common::all_cases() {
        for _ in 0..2000 {
            let (a, b) = (random_wo(&mut rng), random_wo(&mut rng));
            let (f1, f2) = (c.material.eval(a, b), c.material.eval(b, a));
            assert!(
                (f1 - f2).abs().max_element() <= 1e-9 * f1.max_element().max(1e-300),
                "{}: {f1} vs {f2}",
                c.json
            );
        }
    }
}

#[test]
fn energy_conserving_models_reflect_at_most_what_they_receive() {
    // Without a diffuse term (kd/π plus a specular lobe is not coupled), and
    // without the Blinn-Phong NDF, whose Smith term is Walter et al.'s
    // approximation and so not exactly the one of its D (about 2% too much
    // light at 89°; see microfacet.rs).
    let mut cases: Vec<_> = common::microfacet_family()
        .into_iter()
        .filter(|c| !c.json.contains("kd") && !c.json.contains(r#""blinn-phong""#))
        .collect();
    for sh in ["smith-separable", "v-cavity"] {
        cases.push(common::case(&format!(
            r#"{{"type":"cook-torrance","alpha":0.5,"shadowing":"{sh}"}}"#
        )));
    }
    // Normalized lecture models with ks + kd ≤ 1.
    cases.extend(
        common::phong_family()
            .into_iter()
            .filter(|c| !c.json.contains("normalized")),
    );
    for c in cases {
        for theta in [0.0, 30.0, 60.0, 80.0, 89.0] {
            let e = albedo(&c.material, common::wo(theta));
            assert!(e <= 1.0 + 1e-6, "{} at θ={theta}: albedo {e}", c.json);
        }
    }
}

#[test]
fn normalized_lecture_models_reflect_exactly_ks_at_normal_incidence() {
    for model in ["phong", "blinn-phong"] {
        for n in [0.0, 1.0, 10.0, 100.0, 1000.0, 10000.0] {
            let c = common::case(&format!(r#"{{"type":"{model}","exponent":{n},"ks":0.75}}"#));
            let e = albedo(&c.material, DVec3::Z);
            assert!(
                (e - 0.75).abs() < 1e-5,
                "{model} n={n}: albedo {e}, expected ks = 0.75"
            );
        }
    }
}

#[test]
fn lambert_furnace_is_exact() {
    let c = common::case(r#"{"type":"lambert","albedo":[0.2,0.5,0.9]}"#);
    let mut rng = Pcg64::seed_from_u64(9);
    for _ in 0..10_000 {
        let wo = random_wo(&mut rng);
        for s in [BsdfStrategy::Cosine, BsdfStrategy::Brdf] {
            let x = c
                .material
                .sampler(s)
                .unwrap()
                .sample(wo, rng.random(), DVec2::new(rng.random(), rng.random()))
                .unwrap();
            assert!(
                (x.weight - Rgb::new(0.2, 0.5, 0.9)).abs().max_element() < 1e-12,
                "{s}: {}",
                x.weight
            );
        }
    }
    let e = integrate_hemisphere(
        |wi| c.material.eval(DVec3::Z, wi).y * wi.z,
        Tolerance::relative(1e-10),
    )
    .value;
    assert!((e - 0.5).abs() < 1e-9, "{e}");
}

/// Directional albedo of GGX with F = 1 and height-correlated Smith
/// (the values of Kulla and Conty's and Turquin's energy-compensation tables).
#[test]
fn ggx_directional_albedo_matches_the_published_values() {
    let table = [
        (0.0666, 1.0, 0.99507),
        (0.0666, 0.4839, 0.98589),
        (0.2664, 1.0, 0.90387),
        (0.2664, 0.4839, 0.84330),
        (1.0, 1.0, 0.30685),
        (1.0, 0.4839, 0.45778),
    ];
    for (alpha, mu, expect) in table {
        let c = common::case(&format!(
            r#"{{"type":"cook-torrance","distribution":"ggx","alpha":{alpha},"shadowing":"smith-correlated"}}"#
        ));
        let wo = DVec3::new((1.0f64 - mu * mu).sqrt(), 0.0, mu);
        let e = albedo(&c.material, wo);
        assert!(
            (e - expect).abs() < 1e-3,
            "alpha {alpha}, mu {mu}: E = {e}, published {expect}"
        );
    }
    // alpha = 1 at normal incidence has the closed form 1 − ln 2.
    let c = common::case(r#"{"type":"cook-torrance","alpha":1}"#);
    assert!((albedo(&c.material, DVec3::Z) - (1.0 - std::f64::consts::LN_2)).abs() < 1e-6);
}

/// Every strategy's mean weight matches the quadrature albedo (Student t).
#[test]
fn every_strategy_is_unbiased() {
    let cases = common::all_cases();
    let mut tests = Vec::new();
    for c in &cases {
        for s in c.material.strategies() {
            // Material-blind strategies on very narrow lobes have heavy-tailed
            // weights whose sample variance is unreliable at this N.
            let blind = matches!(s, BsdfStrategy::Uniform | BsdfStrategy::Cosine);
            if blind
                && (c.json.contains("0.02") || c.json.contains("000") || c.json.contains("0.05"))
            {
                continue;
            }
            for theta in [0.0, 45.0, 75.0] {
                tests.push((c, s, theta));
            }
        }
    }
    let alpha = lobe::stats::chi2::sidak(0.01, tests.len());
    let mut failures = Vec::new();
    for (i, (c, s, theta)) in tests.iter().enumerate() {
        let wo = common::wo(*theta);
        let reference = albedo(&c.material, wo);
        let mut rng = Pcg64::seed_from_u64(1000 + i as u64);
        let mut mom = Moments::default();
        for _ in 0..200_000 {
            let x = c.material.sampler(*s).unwrap().sample(
                wo,
                rng.random(),
                DVec2::new(rng.random(), rng.random()),
            );
            mom.push(x.map_or(0.0, |x| luminance(x.weight)));
        }
        // The quadrature is good to ~1e-7 relative: fold that into the
        // standard error so that zero-variance estimators compare sanely.
        let n = mom.count();
        let quad_err = 1e-7 * reference.abs();
        let t = t_test(
            mom.mean(),
            mom.variance() + n as f64 * quad_err * quad_err,
            n,
            reference,
        );
        if t.p_value < alpha {
            failures.push(format!(
                "{} {s} θ={theta}: mean {} ± {}, quadrature {reference}, p = {:e}",
                c.json,
                mom.mean(),
                mom.std_error(),
                t.p_value
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} failed:\n{}",
        failures.len(),
        tests.len(),
        failures.join("\n")
    );
}

fn extreme_materials() -> Vec<common::Case> {
    let mut v = Vec::new();
    for n in [0.0, 1e6] {
        for model in ["phong", "blinn-phong"] {
            v.push(common::case(&format!(
                r#"{{"type":"{model}","exponent":{n},"kd":0.2,"ks":0.5}}"#
            )));
            v.push(common::case(&format!(
                r#"{{"type":"{model}","exponent":{n},"normalized":false}}"#
            )));
        }
    }
    for d in ["ggx", "beckmann", "blinn-phong"] {
        for (au, av) in [
            (1e-4, 1e-4),
            (1.0, 1.0),
            (0.01, 1.0),
            (1.0, 0.01),
            (1e-4, 1e-2),
        ] {
            for sh in ["smith-separable", "smith-correlated", "v-cavity"] {
                v.push(common::case(&format!(
                    r#"{{"type":"cook-torrance","distribution":"{d}","alpha_u":{au},"alpha_v":{av},"shadowing":"{sh}","kd":0.1,"fresnel":{{"type":"conductor"}}}}"#
                )));
            }
        }
    }
    v
}

fn check_finite(m: &Material, json: &str, wo: DVec3, wi: DVec3, uc: f64, u: DVec2) {
    let f = m.eval(wo, wi);
    assert!(
        f.is_finite() && f.min_element() >= 0.0,
        "{json}: eval({wo}, {wi}) = {f}"
    );
    for s in m.strategies() {
        let p = m.sampler(s).unwrap().pdf(wo, wi);
        assert!(
            p.is_finite() && p >= 0.0,
            "{json} {s}: pdf({wo}, {wi}) = {p}"
        );
        if let Some(x) = m.sampler(s).unwrap().sample(wo, uc, u) {
            assert!(
                x.wi.is_finite() && x.pdf.is_finite() && x.pdf > 0.0,
                "{json} {s}: sample {x:?}"
            );
            assert!(
                x.weight.is_finite() && x.weight.min_element() >= 0.0,
                "{json} {s}: weight {x:?} for wo {wo}, u {u}"
            );
        }
    }
}

/// Grazing directions, wo = wi, the mirror pair, and the unit square's corners.
#[test]
fn no_nan_at_the_edges() {
    let grazing = [1e-7, 1e-4, 0.5, 1.0];
    let corners = [0.0, 1e-12, 0.5, 1.0 - 1e-16, 1.0 - f64::EPSILON / 2.0];
    for c in extreme_materials() {
        for &z in &grazing {
            for phi in [0.0, 1.0, 2.5] {
                let r = (1.0f64 - z * z).max(0.0).sqrt();
                let wo = DVec3::new(r * f64::cos(phi), r * f64::sin(phi), z);
                let mirror = DVec3::new(-wo.x, -wo.y, wo.z);
                for wi in [wo, mirror, -wo, DVec3::Z, DVec3::new(r, 0.0, z)] {
                    for &a in &corners {
                        for &b in &corners {
                            check_finite(&c.material, &c.json, wo, wi, a, DVec2::new(a, b));
                        }
                    }
                }
            }
        }
    }
}

mod prop {
    use super::*;
    use proptest::prelude::*;

    fn direction() -> impl proptest::strategy::Strategy<Value = DVec3> {
        (
            prop_oneof![Just(1e-7), Just(1.0), 1e-7..1.0f64],
            0.0..std::f64::consts::TAU,
        )
            .prop_map(|(z, phi)| {
                let r = (1.0f64 - z * z).max(0.0).sqrt();
                DVec3::new(r * phi.cos(), r * phi.sin(), z)
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 4000, ..ProptestConfig::default() })]
        #[test]
        fn never_nan_or_negative(wo in direction(), wi in direction(), uc in 0.0..1.0f64, u1 in 0.0..1.0f64, u2 in 0.0..1.0f64, k in 0usize..1000) {
            let cases = extreme_materials();
            let c = &cases[k % cases.len()];
            check_finite(&c.material, &c.json, wo, wi, uc, DVec2::new(u1, u2));
        }
    }
}

#[test]
fn bad_parameters_are_refused_with_the_field_named() {
    use lobe::models::{BlinnPhong, Phong};
    use lobe::{Microfacet, Ndf};
    let e = Phong::new(Rgb::ONE, -1.0, true).unwrap_err().to_string();
    assert!(e.contains("exponent"), "{e}");
    let e = BlinnPhong::new(Rgb::ONE, f64::NAN, true)
        .unwrap_err()
        .to_string();
    assert!(e.contains("exponent"), "{e}");
    let e = Phong::new(Rgb::new(f64::NAN, 0.0, 0.0), 3.0, true)
        .unwrap_err()
        .to_string();
    assert!(e.contains("ks"), "{e}");
    let e = Microfacet::new(Ndf::Ggx, -0.5, 0.5)
        .unwrap_err()
        .to_string();
    assert!(e.contains("alpha_u"), "{e}");
    let e = Microfacet::new(Ndf::Beckmann, 0.5, f64::NAN)
        .unwrap_err()
        .to_string();
    assert!(e.contains("alpha_v"), "{e}");
    let e = "trowbridge".parse::<Ndf>().unwrap_err().to_string();
    assert!(e.contains("distribution") && e.contains("ggx"), "{e}");
    let e = "importance"
        .parse::<BsdfStrategy>()
        .unwrap_err()
        .to_string();
    assert!(e.contains("strategy") && e.contains("vndf"), "{e}");
    let m = common::case(r#"{"type":"phong"}"#).material;
    assert!(m.check(BsdfStrategy::Vndf).is_err());
    let m = common::case(r#"{"type":"cook-torrance","distribution":"beckmann"}"#).material;
    assert!(m.check(BsdfStrategy::Vndf).is_ok() && m.check(BsdfStrategy::BoundedVndf).is_err());
}

/// `eval_pdf` is `(eval, pdf)` bit for bit, for every model and strategy,
/// at random and at degenerate directions (wo = wi, grazing, mirror), and a
/// validated sampler gives the same numbers.
#[test]
fn eval_pdf_is_eval_and_pdf_bit_for_bit() {
    let mut rng = Pcg64::seed_from_u64(11);
    let mut checked = 0usize;
    for c in common::all_cases() {
        let m = c.material;
        for s in m.strategies() {
            let sampler = m.sampler(s).unwrap();
            for k in 0..3000 {
                let wo = random_wo(&mut rng);
                let wi = match k % 4 {
                    0 => wo,
                    1 => DVec3::new(-wo.x, -wo.y, wo.z),
                    2 => DVec3::new(1.0, 0.0, 1e-7).normalize(),
                    _ => random_wo(&mut rng),
                };
                let (f, p) = m.sampler(s).unwrap().eval_pdf(wo, wi);
                let (f0, p0) = (m.eval(wo, wi), m.sampler(s).unwrap().pdf(wo, wi));
                assert!(
                    f.to_array().map(f64::to_bits) == f0.to_array().map(f64::to_bits)
                        && p.to_bits() == p0.to_bits(),
                    "{} {s} wo {wo} wi {wi}: eval_pdf ({f}, {p}) vs ({f0}, {p0})",
                    c.json
                );
                assert_eq!(sampler.eval_pdf(wo, wi), (f, p));
                assert_eq!(sampler.pdf(wo, wi).to_bits(), p.to_bits());
                checked += 1;
            }
        }
    }
    assert!(checked > 100_000, "{checked}");
}

/// A strategy that does not apply to a material has no sampler: the error
/// says why, so there is no meaningless pdf to ask for.
#[test]
fn a_strategy_that_does_not_apply_has_no_sampler() {
    let m = common::case(r#"{"type":"phong","exponent":10}"#).material;
    let e = m.sampler(BsdfStrategy::Vndf).unwrap_err().to_string();
    assert!(e.contains("vndf") && e.contains("does not apply"), "{e}");
    assert!(m.sampler(BsdfStrategy::Brdf).is_ok());
}
