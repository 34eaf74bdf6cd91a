//! Glass, mirrors and plastic (issue 42): chi-square over the whole sphere
//! for every model and strategy with a density, seen from outside, at
//! grazing angles and from inside; the delta parts drawn with the Fresnel
//! probabilities in the right directions; white furnaces; reciprocity; no
//! NaN at the edges; and values read from Mitsuba 3.9.1's plugins.

use crate::common;
use glam::{DVec2, DVec3};
use lobe::{BsdfStrategy, Material, Rgb, Scattering};

fn load(json: &str) -> Material {
    Material::load(json).unwrap_or_else(|e| panic!("{json}: {e}"))
}

/// `wo` at polar angle `theta` degrees (beyond 90: below the surface, seen
/// from inside), at a small azimuth.
fn wo(theta: f64) -> DVec3 {
    lobe::frame::wo_from_theta(theta, 0.3f64.to_degrees())
}

const OUTSIDE_AND_IN: &[f64] = &[0.0, 60.0, 89.0, 140.0];

#[test]
fn chi2_rough_dielectric() {
    use BsdfStrategy::{Brdf, Cosine, SphericalCaps, Uniform, Vndf};
    common::chi2_over_sphere(
        "glass",
        &[
            (
                r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.3}"#,
                &[Brdf, Vndf, SphericalCaps, Uniform, Cosine],
                OUTSIDE_AND_IN,
            ),
            (
                r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.05,"int_ior":1.33}"#,
                &[Vndf],
                OUTSIDE_AND_IN,
            ),
            (
                r#"{"type":"roughdielectric","distribution":"beckmann","alpha":0.5}"#,
                &[Brdf, Vndf],
                OUTSIDE_AND_IN,
            ),
            (
                r#"{"type":"roughdielectric","distribution":"ggx","alpha_u":0.05,"alpha_v":0.4}"#,
                &[Vndf],
                OUTSIDE_AND_IN,
            ),
            // Light from the denser side: from outside, total internal reflection past 41.8°.
            (
                r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.2,"int_ior":1.0,"ext_ior":1.5}"#,
                &[Brdf, Vndf],
                OUTSIDE_AND_IN,
            ),
        ],
    );
}

#[test]
fn chi2_plastic_and_two_sided() {
    use BsdfStrategy::{BoundedVndf, Brdf, Cosine, SphericalCaps, Uniform, Vndf};
    common::chi2_over_sphere(
        "glass",
        &[
            (
                r#"{"type":"roughplastic","distribution":"ggx","alpha":0.2,"diffuse_reflectance":[0.2,0.5,0.8]}"#,
                &[Brdf, Vndf, SphericalCaps, BoundedVndf, Uniform, Cosine],
                &[0.0, 60.0, 89.0],
            ),
            (
                r#"{"type":"roughplastic","alpha":0.4,"nonlinear":true}"#,
                &[Brdf, Vndf],
                &[0.0, 60.0, 89.0],
            ),
            // The density part of smooth plastic: its base.
            (
                r#"{"type":"plastic","diffuse_reflectance":0.3}"#,
                &[Brdf],
                &[0.0, 60.0, 89.0],
            ),
            // Seen from below, a two-sided material is its front mirrored.
            (
                r#"{"type":"twosided","bsdf":{"type":"roughconductor","distribution":"ggx","alpha":0.3,"material":"Cu"}}"#,
                &[Vndf, Cosine],
                &[30.0, 150.0],
            ),
            (
                r#"{"type":"twosided","material":{"type":"diffuse","reflectance":0.6}}"#,
                &[Brdf],
                &[120.0],
            ),
        ],
    );
}

/// The delta parts: reflection with probability `F` (the pane's `R'`, the
/// coating's share), in the mirror direction; refraction by Snell's law
/// (straight through for the pane), with the weights Mitsuba gives.
#[test]
fn delta_parts_directions_probabilities_and_weights() {
    let n = 10_000;
    let eta: f64 = 1.5046 / 1.000_277;
    for theta in [0.0, 30.0, 60.0, 85.0, 120.0, 150.0] {
        let wo = wo(theta);
        let inside = wo.z < 0.0;
        let f = lobe::fresnel::fresnel_dielectric(wo.z, eta);
        // Smooth glass, radiance: reflection weight 1, refraction (η_o/η_i)².
        let m = load(r#"{"type":"dielectric"}"#);
        let s = m.sampler(BsdfStrategy::Brdf).unwrap();
        let mut reflected = 0;
        for i in 0..n {
            let uc = (i as f64 + 0.5) / n as f64;
            let x = s.sample(wo, uc, DVec2::splat(0.5)).unwrap();
            let mirror = DVec3::new(-wo.x, -wo.y, wo.z);
            if x.scattering == Scattering::SpecularReflection {
                reflected += 1;
                assert!(
                    (x.wi - mirror).length() < 1e-12
                        && (x.weight - Rgb::ONE).abs().max_element() < 1e-12
                );
                assert!((x.pdf - f.r).abs() < 1e-12);
            } else {
                assert_eq!(x.scattering, Scattering::SpecularTransmission);
                assert!(x.wi.z * wo.z < 0.0 && (x.wi.length() - 1.0).abs() < 1e-12);
                // Snell: η_o sin θo = η_i sin θi, in the plane of incidence.
                let (eo, ei) = if inside { (eta, 1.0) } else { (1.0, eta) };
                let sin = |w: DVec3| w.x.hypot(w.y);
                assert!((eo * sin(wo) - ei * sin(x.wi)).abs() < 1e-12, "θ {theta}");
                assert!(x.wi.truncate().dot(wo.truncate()) <= 0.0);
                let want = (eo / ei) * (eo / ei);
                assert!(
                    (x.weight.x - want).abs() < 1e-12,
                    "θ {theta}: {} vs {want}",
                    x.weight.x
                );
            }
        }
        let expect = (f.r * n as f64).ceil();
        assert!(
            (reflected as f64 - expect).abs() <= 1.0,
            "θ {theta}: {reflected} reflected, F = {}",
            f.r
        );
        // Importance mode: every weight 1 (R + T = 1 exactly).
        let m = load(r#"{"type":"dielectric","mode":"importance"}"#);
        let s = m.sampler(BsdfStrategy::Brdf).unwrap();
        for uc in [0.0, 0.3, 0.999] {
            let x = s.sample(wo, uc, DVec2::splat(0.5)).unwrap();
            assert!((x.weight - Rgb::ONE).abs().max_element() < 1e-12);
        }
        // The pane: R' = 2R/(1 + R) from either side, straight through otherwise.
        let m = load(r#"{"type":"thindielectric","int_ior":1.5,"ext_ior":1.0}"#);
        let s = m.sampler(BsdfStrategy::Brdf).unwrap();
        let r = lobe::fresnel::fresnel_dielectric(wo.z.abs(), 1.5).r;
        let r2 = 2.0 * r / (1.0 + r);
        let below = s.sample(wo, r2 - 1e-9, DVec2::ZERO).unwrap();
        let above = s.sample(wo, r2 + 1e-9, DVec2::ZERO).unwrap();
        assert_eq!(below.scattering, Scattering::SpecularReflection);
        assert_eq!(above.scattering, Scattering::SpecularTransmission);
        assert!(
            (above.wi + wo).length() < 1e-15
                && (above.weight - Rgb::ONE).abs().max_element() < 1e-12
        );
        assert!(
            (below.pdf - r2).abs() < 1e-12,
            "θ {theta}: {} vs {r2}",
            below.pdf
        );
    }
    // Mitsuba's R' at cos θ = 0.9327, η = 1.5: 0.0775437.
    let pane = lobe::models::ThinDielectric::new(1.5, Rgb::ONE, Rgb::ONE).unwrap();
    assert!((pane.reflectance(0.9327) - 0.077_543_7).abs() < 1e-6);
}

/// Smooth conductors: the mirror direction, weight `F`; a mirror (`none`)
/// reflects everything; gold is yellow; from below a one-sided mirror is
/// black, a two-sided one is not; `uniform` and `cosine` are refused with
/// the reason.
#[test]
fn smooth_conductor() {
    let wo = wo(40.0);
    let mirror = load(r#"{"type":"conductor"}"#);
    let x = mirror
        .sampler(BsdfStrategy::Brdf)
        .unwrap()
        .sample(wo, 0.5, DVec2::ZERO)
        .unwrap();
    assert_eq!(x.scattering, Scattering::SpecularReflection);
    assert!((x.wi - DVec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-15);
    assert!(
        (x.weight - Rgb::ONE).abs().max_element() < 1e-12,
        "{}",
        x.weight
    );
    let gold = load(r#"{"type":"conductor","material":"Au"}"#);
    let w = gold
        .sampler(BsdfStrategy::Brdf)
        .unwrap()
        .sample(wo, 0.5, DVec2::ZERO)
        .unwrap()
        .weight;
    assert!(w.x > w.y && w.y > w.z && w.x < 1.0, "gold {w}");
    let (eta, k) = lobe::ior::conductor("material", "Au").unwrap();
    let f = lobe::Fresnel::Conductor { eta, k }.eval(wo.z);
    assert!((w - f).abs().max_element() < 1e-12);
    let below = DVec3::new(wo.x, wo.y, -wo.z);
    assert!(
        gold.sampler(BsdfStrategy::Brdf)
            .unwrap()
            .sample(below, 0.5, DVec2::ZERO)
            .is_none()
    );
    let two = load(r#"{"type":"twosided","bsdf":{"type":"conductor","material":"Au"}}"#);
    let x = two
        .sampler(BsdfStrategy::Brdf)
        .unwrap()
        .sample(below, 0.5, DVec2::ZERO)
        .unwrap();
    assert!((x.wi - DVec3::new(-wo.x, -wo.y, -wo.z)).length() < 1e-15 && x.weight == w);
    for s in [
        BsdfStrategy::Uniform,
        BsdfStrategy::Cosine,
        BsdfStrategy::Vndf,
    ] {
        let e = gold.sampler(s).unwrap_err().to_string();
        assert!(e.contains("delta") || e.contains("smooth"), "{s}: {e}");
    }
    // Mitsuba: `k` alone (eta 0) is a mirror; `eta` alone takes k = 1.
    let k_only = load(r#"{"type":"conductor","k":1}"#);
    let w = k_only
        .sampler(BsdfStrategy::Brdf)
        .unwrap()
        .sample(wo, 0.5, DVec2::ZERO)
        .unwrap()
        .weight;
    assert!((w - Rgb::ONE).abs().max_element() < 1e-9, "{w}");
}

/// White furnaces: `∫ f |cos θi| dωi` over the sphere. Smooth glass: R + T = 1
/// exactly (importance mode, no η² factor). Rough glass: R + T ≤ 1, the
/// loss (light that single scattering drops) growing with α; plastic
/// with a white base loses only what its coating's Fresnel term and
/// internal reflection keep in.
#[test]
fn white_furnace() {
    let estimate = |m: &Material, s: BsdfStrategy, wo: DVec3| -> (f64, f64) {
        let sampler = m.sampler(s).unwrap();
        let n = 200_000;
        let mut rng = lobe::sequence::chunk_rng(7, 0);
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..n {
            use rand::RngExt;
            let (uc, u) = (rng.random::<f64>(), DVec2::new(rng.random(), rng.random()));
            let w = sampler.sample(wo, uc, u).map_or(0.0, |x| x.weight.x);
            sum += w;
            sum2 += w * w;
        }
        let mean = sum / n as f64;
        (mean, ((sum2 / n as f64 - mean * mean) / n as f64).sqrt())
    };
    let mut losses = Vec::new();
    for alpha in [0.05, 0.2, 0.5, 1.0] {
        let m = load(&format!(
            r#"{{"type":"roughdielectric","distribution":"ggx","alpha":{alpha},"int_ior":1.5,"ext_ior":1.0,"mode":"importance"}}"#
        ));
        let (mean, se) = estimate(&m, BsdfStrategy::Vndf, wo(45.0));
        assert!(mean <= 1.0 + 4.0 * se, "α {alpha}: R + T = {mean} ± {se}");
        losses.push((alpha, 1.0 - mean, se));
    }
    eprintln!("rough dielectric GGX η 1.5, θo 45°: (α, 1 − (R + T), se) = {losses:.4?}");
    assert!(losses[0].1 < 0.01, "{losses:?}");
    assert!(
        losses.windows(2).all(|w| w[1].1 > w[0].1 - 3.0 * w[1].2),
        "{losses:?}"
    );
    let m = load(r#"{"type":"dielectric","mode":"importance"}"#);
    for t in [0.0, 45.0, 89.0, 135.0] {
        let (mean, se) = estimate(&m, BsdfStrategy::Brdf, wo(t));
        assert!((mean - 1.0).abs() < 1e-12 && se < 1e-9, "θ {t}: {mean}");
    }
}

/// `f(wo, wi) = f(wi, wo)` for plastic, rough plastic and two-sided
/// materials, and `f(wo, wi)/η_o² = f(wi, wo)/η_i²` for rough glass.
#[test]
fn reciprocity() {
    let dirs: Vec<DVec3> = (0..24)
        .map(|i| {
            let t = 0.13 + 2.9 * (i as f64 / 24.0);
            lobe::frame::spherical_direction(t, 1.7 * i as f64)
        })
        .collect();
    let symmetric = [
        r#"{"type":"plastic","diffuse_reflectance":[0.2,0.5,0.8]}"#,
        r#"{"type":"roughplastic","distribution":"ggx","alpha":0.3,"nonlinear":true}"#,
        r#"{"type":"twosided","bsdf":{"type":"roughconductor","alpha_u":0.1,"alpha_v":0.3}}"#,
    ];
    for json in symmetric {
        let m = load(json);
        for &a in &dirs {
            for &b in &dirs {
                let (x, y) = (m.eval(a, b), m.eval(b, a));
                assert!(
                    (x - y).abs().max_element() <= 1e-12 * x.max_element().max(1e-300),
                    "{json} {a} {b}: {x} {y}"
                );
            }
        }
    }
    let eta = 1.33;
    let m = load(
        r#"{"type":"roughdielectric","distribution":"beckmann","alpha":0.4,"int_ior":1.33,"ext_ior":1.0}"#,
    );
    let n = |w: DVec3| if w.z > 0.0 { 1.0 } else { eta };
    for &a in &dirs {
        for &b in &dirs {
            let (x, y) = (
                m.eval(a, b).x / (n(a) * n(a)),
                m.eval(b, a).x / (n(b) * n(b)),
            );
            assert!(
                (x - y).abs() <= 1e-12 * x.max(y).max(1e-300),
                "{a} {b}: {x} {y}"
            );
        }
    }
}

/// Every new model at the edges: `wi = −wo`, `wi = wo`, grazing, the
/// smallest α, index-matched glass (pure transmission, a delta): finite
/// values, and samples with finite positive pdfs and weights.
#[test]
fn no_nan_at_the_edges() {
    let materials = [
        r#"{"type":"conductor","material":"Cu"}"#,
        r#"{"type":"dielectric"}"#,
        r#"{"type":"dielectric","int_ior":1.0,"ext_ior":1.0}"#,
        r#"{"type":"thindielectric"}"#,
        r#"{"type":"roughdielectric","distribution":"ggx","alpha":1e-4}"#,
        r#"{"type":"roughdielectric","distribution":"beckmann","alpha":2}"#,
        r#"{"type":"roughdielectric","alpha":0.3,"int_ior":"water","ext_ior":"water"}"#,
        r#"{"type":"plastic","diffuse_reflectance":0}"#,
        r#"{"type":"roughplastic","alpha":1e-4}"#,
        r#"{"type":"twosided","bsdf":{"type":"plastic"}}"#,
    ];
    let views = [
        DVec3::Z,
        -DVec3::Z,
        DVec3::new(1.0, 0.0, 1e-9).normalize(),
        DVec3::new(1.0, 0.0, -1e-9).normalize(),
        DVec3::new(0.6, 0.0, 0.8),
        DVec3::new(0.6, 0.0, -0.8),
    ];
    for json in materials {
        let m = load(json);
        for s in m.strategies() {
            let sampler = m.sampler(s).unwrap();
            for &wo in &views {
                for wi in [
                    -wo,
                    wo,
                    DVec3::new(-wo.x, -wo.y, wo.z),
                    DVec3::new(0.0, 1.0, 1e-12).normalize(),
                ] {
                    let (f, p) = sampler.eval_pdf(wo, wi);
                    assert!(
                        f.is_finite() && p.is_finite() && p >= 0.0,
                        "{json} {s} {wo} {wi}: {f} {p}"
                    );
                    assert_eq!((f, p), (m.eval(wo, wi), sampler.pdf(wo, wi)), "{json} {s}");
                }
                for uc in [0.0, 0.5, 0.999_999] {
                    for u in [DVec2::ZERO, DVec2::splat(0.5), DVec2::splat(0.999_999)] {
                        if let Some(x) = sampler.sample(wo, uc, u) {
                            assert!(
                                x.pdf > 0.0 && x.pdf.is_finite() && x.weight.is_finite(),
                                "{json} {s} {wo}: {x:?}"
                            );
                            assert!((x.wi.length() - 1.0).abs() < 1e-9, "{json} {s}: {x:?}");
                        }
                    }
                }
            }
        }
    }
    // Index-matched rough glass is a straight pass: a delta, weight 1.
    let m = load(r#"{"type":"roughdielectric","alpha":0.3,"int_ior":1.2,"ext_ior":1.2}"#);
    assert!(m.reach().delta && m.sampler(BsdfStrategy::Uniform).is_err());
    let x = m
        .sampler(BsdfStrategy::Vndf)
        .unwrap()
        .sample(wo(30.0), 0.5, DVec2::splat(0.3))
        .unwrap();
    assert!(
        (x.wi + wo(30.0)).length() < 1e-15 && (x.weight - Rgb::ONE).abs().max_element() < 1e-12
    );
}

/// Values read from Mitsuba 3.9.1's plugins (`scalar_rgb`): `eval` (f times
/// the cosine of the light's direction) and `pdf` (visible normals) at
/// Mitsuba's `wi = (0.714143, 0, 0.7)` (lobe's `wo`, toward the viewer)
/// and `wo = (−0.3, 0.2, ±0.932738)` (lobe's `wi`), default IORs.
#[test]
fn known_values_from_mitsuba() {
    let v = DVec3::new(0.714_143, 0.0, 0.7).normalize();
    let v_dn = DVec3::new(v.x, v.y, -v.z);
    let l_r = DVec3::new(-0.3, 0.2, 0.932_738).normalize();
    let l_t = DVec3::new(l_r.x, l_r.y, -l_r.z);
    let check =
        |json: &str, s: BsdfStrategy, wo: DVec3, wi: DVec3, eval: f64, pdf: f64, tol: f64| {
            let m = load(json);
            let (f, p) = m.sampler(s).unwrap().eval_pdf(wo, wi);
            let fc = f.x * wi.z.abs();
            assert!(
                (fc - eval).abs() <= tol * eval,
                "{json} {wo} {wi}: eval·cos {fc} vs Mitsuba's {eval}"
            );
            assert!(
                (p - pdf).abs() <= tol * pdf,
                "{json} {wo} {wi}: pdf {p} vs Mitsuba's {pdf}"
            );
        };
    let ggx = r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.3}"#;
    let vndf = BsdfStrategy::Vndf;
    check(ggx, vndf, v, l_r, 0.017_243, 0.017_301, 2e-3);
    check(ggx, vndf, v, l_t, 0.158_238, 0.359_224, 2e-3);
    check(ggx, vndf, v_dn, l_r, 0.036_331, 0.016_111, 2e-3);
    check(ggx, vndf, v_dn, l_t, 0.026_086, 0.026_174, 2e-3);
    let imp = r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.3,"mode":"importance"}"#;
    check(imp, vndf, v, l_t, 0.358_024, 0.359_224, 2e-3);
    check(imp, vndf, v_dn, l_r, 0.016_057, 0.016_111, 2e-3);
    check(
        r#"{"type":"plastic"}"#,
        BsdfStrategy::Brdf,
        v,
        l_r,
        0.149_233,
        0.268_916,
        1e-3,
    );
    check(
        r#"{"type":"roughplastic"}"#,
        vndf,
        v,
        l_r,
        0.143_738,
        0.268_935,
        2e-3,
    );
    check(
        r#"{"type":"roughplastic","distribution":"ggx","alpha":0.3}"#,
        vndf,
        v,
        l_r,
        0.116_402,
        0.311_546,
        2e-3,
    );
    let m = load(r#"{"type":"roughconductor","distribution":"ggx","alpha":0.3,"material":"Au"}"#);
    let (f, p) = m.sampler(vndf).unwrap().eval_pdf(v, l_r);
    assert!(
        (f.x * l_r.z - 0.391_351).abs() < 2e-3 * 0.391_351
            && (p - 0.406_340).abs() < 2e-3 * 0.406_34
    );
}

/// Bad input: a clear error naming the field.
#[test]
fn bad_input_names_the_field() {
    let err = |json: &str| match Material::load(json) {
        Ok(_) => panic!("{json} was accepted"),
        Err(e) => e.to_string(),
    };
    let cases = [
        (r#"{"type":"dielectric","int_ior":-1}"#, "int_ior"),
        (r#"{"type":"dielectric","int_ior":"glass"}"#, "int_ior"),
        (r#"{"type":"dielectric","ext_ior":"nan"}"#, "ext_ior"),
        (r#"{"type":"conductor","k":-1}"#, "k"),
        (r#"{"type":"conductor","material":"Gold"}"#, "Au"),
        (r#"{"type":"roughdielectric","alpha":-0.1}"#, "alpha"),
        (
            r#"{"type":"roughdielectric","distribution":"phong"}"#,
            "distribution",
        ),
        (
            r#"{"type":"roughdielectric","sample_visible":false}"#,
            "sample_visible",
        ),
        (
            r#"{"type":"roughplastic","alpha_u":0.1,"alpha_v":0.2}"#,
            "alpha_u",
        ),
        (
            r#"{"type":"twosided","bsdf":{"type":"dielectric"}}"#,
            "transmits",
        ),
        (
            r#"{"type":"twosided","bsdf":{"type":"twosided","bsdf":{"type":"diffuse"}}}"#,
            "twosided",
        ),
        (r#"{"type":"twosided"}"#, "bsdf"),
        (r#"{"type":"dielectric","eta":1.5}"#, "eta"),
        (r#"{"type":"plastic","kd":0.5}"#, "kd"),
        (
            r#"{"type":"diffuse","reflectance":{"type":"bitmap","filename":"x.png"}}"#,
            "reflectance",
        ),
        (
            r#"{"type":"twosided","bsdf":{"type":"diffuse","albedo":0.5}}"#,
            "albedo",
        ),
    ];
    for (json, needle) in cases {
        let e = err(json);
        assert!(e.contains(needle), "{json}: {e}");
    }
    // Colours as Mitsuba writes them.
    let m = load(r#"{"type":"diffuse","reflectance":{"type":"rgb","value":[0.2,0.4,0.6]}}"#);
    assert_eq!(m.diffuse.albedo, Rgb::new(0.2, 0.4, 0.6));
}

/// Every conductor Mitsuba names loads (but `AlSb`, whose RGB index has a
/// zero channel), as `conductor` and `roughconductor`, with finite values;
/// named indices of refraction in any case; Mitsuba's keys of
/// `roughconductor` and `diffuse` become lobe's models.
#[test]
fn mitsuba_names() {
    let wo = DVec3::new(0.6, 0.0, 0.8);
    let wi = DVec3::new(-0.6, 0.0, 0.8);
    for (name, eta, _) in lobe::ior::CONDUCTORS {
        for kind in ["conductor", "roughconductor"] {
            let json = format!(r#"{{"type":"{kind}","material":"{name}"}}"#);
            if name.starts_with("AlSb") {
                let e = Material::load(&json).unwrap_err().to_string();
                assert!(
                    e.contains("field `material`") && e.contains("zero eta"),
                    "{e}"
                );
                continue;
            }
            let m = load(&json);
            let f = if kind == "conductor" {
                m.sampler(BsdfStrategy::Brdf)
                    .unwrap()
                    .sample(wo, 0.5, DVec2::ZERO)
                    .unwrap()
                    .weight
            } else {
                m.eval(wo, wi)
            };
            assert!(
                f.to_array().iter().all(|x| x.is_finite() && *x >= 0.0),
                "{json}: {f}"
            );
            if let lobe::Glossy::CookTorrance(c) = &m.glossy {
                assert!(
                    matches!(c.fresnel, lobe::Fresnel::Conductor { eta: e, .. } if e == Rgb::from_array(eta))
                );
                assert_eq!(c.shadowing, lobe::Shadowing::SmithSeparable);
                assert_eq!(
                    (c.microfacet.ndf(), c.microfacet.alpha()),
                    (lobe::Ndf::Beckmann, (0.1, 0.1))
                );
            }
        }
    }
    assert_eq!(
        lobe::ior::CONDUCTORS
            .iter()
            .filter(|c| !c.0.ends_with("_palik"))
            .count(),
        34
    );
    let m = load(r#"{"type":"roughdielectric","int_ior":"BK7","ext_ior":"Water"}"#);
    let lobe::Glossy::RoughDielectric(g) = &m.glossy else {
        panic!()
    };
    assert_eq!(g.eta, 1.5046 / 1.333);
    let m = load(r#"{"type":"dielectric"}"#);
    let lobe::Glossy::Dielectric(g) = &m.glossy else {
        panic!()
    };
    assert_eq!(g.eta, 1.5046 / 1.000_277, "Mitsuba's defaults: bk7 in air");
    let m = load(r#"{"type":"plastic"}"#);
    let lobe::Glossy::Plastic(p) = &m.glossy else {
        panic!()
    };
    assert_eq!(
        (p.eta, p.diffuse_reflectance),
        (1.49 / 1.000_277, Rgb::splat(0.5))
    );
    let m = load(
        r#"{"type":"roughconductor","distribution":"ggx","alpha_u":0.1,"alpha_v":0.3,"specular_reflectance":0.5}"#,
    );
    let lobe::Glossy::CookTorrance(c) = &m.glossy else {
        panic!()
    };
    assert_eq!(
        (c.microfacet.alpha(), c.ks, c.fresnel),
        ((0.1, 0.3), Rgb::splat(0.5), lobe::Fresnel::None)
    );
    assert_eq!(
        load(r#"{"type":"diffuse"}"#).diffuse.albedo,
        Rgb::splat(0.5)
    );
    let e = Material::load(r#"{"type":"roughconductor","alpha":0.1,"alpah_u":2}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown field `alpah_u`"), "{e}");
}

/// Every strategy's estimate of the light leaving glass, metal and plastic
/// is unbiased: within 4 standard errors of the quadrature reference over
/// the sphere plus the delta parts' exact terms, seen from outside and
/// from inside, under a furnace and beams from above and from below.
/// Light sampling alone is refused where the material has a delta part.
#[test]
fn estimates_are_unbiased_over_the_sphere() {
    use lobe::estimator::{EstimateSettings, ShadingPoint, Strategy, estimate, reference};
    use lobe::math::luminance;
    let lights = [
        lobe::Light::Constant(Rgb::new(1.0, 0.8, 0.6)),
        lobe::Light::Beam {
            dir: DVec3::new(-0.5, 0.2, 0.8).normalize(),
            exponent: 8.0,
            radiance: Rgb::splat(2.0),
        },
        lobe::Light::Beam {
            dir: DVec3::new(0.3, -0.2, -0.9).normalize(),
            exponent: 4.0,
            radiance: Rgb::splat(1.5),
        },
    ];
    let materials = [
        r#"{"type":"conductor","material":"Cu"}"#,
        r#"{"type":"dielectric"}"#,
        r#"{"type":"thindielectric"}"#,
        r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.3}"#,
        r#"{"type":"roughdielectric","distribution":"beckmann","alpha_u":0.1,"alpha_v":0.3,"int_ior":1.33}"#,
        r#"{"type":"plastic","diffuse_reflectance":[0.2,0.5,0.8]}"#,
        r#"{"type":"roughplastic","distribution":"ggx","alpha":0.2}"#,
        r#"{"type":"twosided","bsdf":{"type":"roughconductor","distribution":"ggx","alpha":0.3}}"#,
    ];
    let mut failures = Vec::new();
    let mut count = 0u64;
    for json in materials {
        let m = load(json);
        let mut strategies: Vec<Strategy> =
            m.strategies().into_iter().map(Strategy::from).collect();
        strategies.extend(
            ["mis", "mis-balance", "mis-power", "mis-one"].map(|s| s.parse::<Strategy>().unwrap()),
        );
        if m.reach().delta {
            let e = lobe::estimator::ShadingEstimator::new(Strategy::Light, &m).unwrap_err();
            assert!(e.to_string().contains("delta"), "{json}: {e}");
        } else {
            strategies.push(Strategy::Light);
        }
        for theta in [30.0, 75.0, 140.0] {
            let sp = ShadingPoint::local(wo(theta));
            for light in &lights {
                let r = luminance(reference(&m, &sp, light, 1e-6));
                for &s in &strategies {
                    count += 1;
                    let settings = EstimateSettings::independent(s, 1 << 14, count);
                    let acc = estimate(&m, &sp, light, &settings).unwrap();
                    let (mean, se) = (acc.lum.mean(), acc.lum.std_error());
                    if (mean - r).abs() > 4.0 * se + 1e-5 * r.abs() {
                        failures.push(format!(
                            "{json} θ={theta} {light:?} {s}: {mean} ± {se}, reference {r}"
                        ));
                    }
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {count}:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
