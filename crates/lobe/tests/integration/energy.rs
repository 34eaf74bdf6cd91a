//! Energy compensation (issue 43): chi-square of the compensated samplers,
//! the white furnace of compensated conductors, the random walk as the
//! reference for coloured conductors and for the lobe's shape, the stored
//! albedo tables against a recomputation, the uncompensated lobes' bits,
//! and bad input.

use crate::common;
use glam::{DVec2, DVec3};
use lobe::energy::random_walk::RgbEstimate;
use lobe::energy::tabulate::{Shape, TABLES, node_estimate};
use lobe::energy::{AlbedoTables, RandomWalk};
use lobe::experiment::furnace::{FurnaceSettings, furnace};
use lobe::{BsdfStrategy, Glossy, Material, MaterialDesc};

const ALPHAS: [f64; 8] = [0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.85, 1.0];
const THETAS: [f64; 8] = [0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0, 89.0];

fn desc(json: &str) -> MaterialDesc {
    MaterialDesc::from_json(json).unwrap_or_else(|e| panic!("{json}: {e}"))
}

#[test]
fn chi2_compensated_samplers() {
    use BsdfStrategy::{BoundedVndf, Brdf, SphericalCaps, Vndf};
    let views: &[f64] = &[0.0, 60.0, 89.0];
    common::chi2_over_sphere(
        "energy",
        &[
            (
                r#"{"type":"cook-torrance","alpha":0.3,"multiscatter":"kulla-conty"}"#,
                &[Brdf, Vndf, SphericalCaps, BoundedVndf],
                views,
            ),
            (
                r#"{"type":"cook-torrance","alpha":1.0,"fresnel":{"type":"conductor"},"multiscatter":"kulla-conty"}"#,
                &[Brdf, Vndf],
                views,
            ),
            (
                r#"{"type":"roughconductor","distribution":"beckmann","alpha":0.7,"material":"Cu","multiscatter":"kulla-conty"}"#,
                &[Brdf, Vndf],
                views,
            ),
            (
                r#"{"type":"roughconductor","distribution":"ggx","alpha":0.5,"multiscatter":"turquin"}"#,
                &[Vndf, BoundedVndf],
                views,
            ),
            (
                r#"{"type":"cook-torrance","alpha_u":0.2,"alpha_v":0.8,"multiscatter":"kulla-conty"}"#,
                &[Vndf],
                views,
            ),
            (
                r#"{"type":"cook-torrance","alpha":0.6,"kd":0.3,"multiscatter":"kulla-conty"}"#,
                &[Vndf],
                views,
            ),
            (
                r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.5,"multiscatter":"turquin"}"#,
                &[Brdf, Vndf],
                &[0.0, 60.0, 89.0, 140.0],
            ),
            (
                r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.5,"multiscatter":"kulla-conty"}"#,
                &[Brdf, Vndf, SphericalCaps],
                &[0.0, 60.0, 89.0, 120.0, 140.0, 179.0],
            ),
            (
                r#"{"type":"roughdielectric","distribution":"beckmann","alpha":1.0,"int_ior":1,"ext_ior":1.5,"specular_transmittance":[0.9,0.5,0.2],"multiscatter":"kulla-conty"}"#,
                &[Vndf],
                &[0.0, 60.0, 140.0],
            ),
            (
                r#"{"type":"roughplastic","distribution":"beckmann","alpha":0.4,"multiscatter":"turquin"}"#,
                &[Brdf, Vndf],
                views,
            ),
            (
                r#"{"type":"roughplastic","distribution":"ggx","alpha":0.7,"multiscatter":"kulla-conty"}"#,
                &[Brdf, Vndf],
                views,
            ),
            (
                r#"{"type":"roughplastic","distribution":"ggx","alpha":0.8,"diffuse_reflectance":[0.9,0.4,0.1],"nonlinear":true,"multiscatter":"turquin"}"#,
                &[Vndf, SphericalCaps, BoundedVndf],
                views,
            ),
        ],
    );
}

/// A sample's weight is `f cos θi / pdf` with the compensated `f` and the
/// mixture pdf, and `eval_pdf` is the two calls.
#[test]
fn compensated_samples_weigh_f_cos_over_pdf() {
    for json in [
        r#"{"type":"cook-torrance","alpha":0.8,"fresnel":{"type":"conductor"},"multiscatter":"kulla-conty"}"#,
        r#"{"type":"roughconductor","distribution":"beckmann","alpha":0.4,"material":"Au","multiscatter":"turquin"}"#,
        r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.7,"multiscatter":"turquin"}"#,
        r#"{"type":"roughplastic","distribution":"ggx","alpha":0.6,"multiscatter":"turquin"}"#,
        r#"{"type":"roughdielectric","distribution":"beckmann","alpha":0.9,"int_ior":1.33,"multiscatter":"kulla-conty"}"#,
        r#"{"type":"roughplastic","distribution":"beckmann","alpha":0.8,"multiscatter":"kulla-conty"}"#,
    ] {
        let m = Material::load(json).unwrap();
        let s = m.sampler(BsdfStrategy::Vndf).unwrap();
        let mut rng = lobe::sequence::chunk_rng(3, 0);
        for k in 0..2000 {
            use rand::RngExt;
            let wo = lobe::frame::wo_from_theta(f64::from(k % 89), 30.0);
            let u = DVec2::new(rng.random(), rng.random());
            let Some(x) = s.sample(wo, rng.random(), u) else {
                continue;
            };
            let (f, pdf) = s.eval_pdf(wo, x.wi);
            assert!(
                (pdf - x.pdf).abs() <= 1e-12 * pdf,
                "{json}: {pdf} vs {}",
                x.pdf
            );
            assert!((f - m.eval(wo, x.wi)).abs().max_element() <= 1e-12 * f.max_element());
            let w = f * x.wi.z.abs() / pdf;
            assert!((w - x.weight).abs().max_element() <= 1e-9 * w.max_element());
        }
    }
}

/// The white furnace of `jsons` at `alphas` (θo over [`THETAS`]), both
/// kinds of compensation: the largest `|albedo − 1|` of any channel and
/// where, the darkest uncompensated albedo, whether any cell had a walk.
struct WhiteFurnace {
    worst: f64,
    at: String,
    darkest: f64,
    walked: bool,
}

fn white_furnace(jsons: &[&str], alphas: &[f64]) -> WhiteFurnace {
    let s = FurnaceSettings {
        thetas: THETAS.to_vec(),
        alphas: alphas.to_vec(),
        walks: 0,
        seed: 1,
    };
    let mut w = WhiteFurnace {
        worst: 0.0,
        at: String::new(),
        darkest: 1.0,
        walked: false,
    };
    for json in jsons {
        let f = furnace(&desc(json), &s, &()).unwrap();
        for r in &f.rows {
            w.walked |= r.walk.is_some();
            w.darkest = w.darkest.min(r.none.x);
            for (kind, a) in [("kulla-conty", r.kulla_conty), ("turquin", r.turquin)] {
                let err = (a - lobe::Rgb::ONE).abs().max_element();
                if err > w.worst {
                    w.worst = err;
                    w.at = format!(
                        "{json} {kind} α {} θo {}: {a:?} (none {})",
                        r.alpha, r.theta, r.none.x
                    );
                }
            }
        }
    }
    w
}

/// Compensated white conductors reflect 1 within 0.5% for every θo and α
/// of the issue's range, GGX and Beckmann, Smith's separable (Mitsuba's
/// `roughconductor`) and height-correlated (`cook-torrance`) terms, both
/// kinds of compensation; the uncompensated lobes lose up to 70%.
#[test]
fn white_furnace_of_compensated_conductors() {
    let w = white_furnace(
        &[
            r#"{"type":"roughconductor","distribution":"ggx"}"#,
            r#"{"type":"roughconductor","distribution":"beckmann"}"#,
            r#"{"type":"cook-torrance","distribution":"ggx"}"#,
            r#"{"type":"cook-torrance","distribution":"beckmann"}"#,
        ],
        &ALPHAS,
    );
    eprintln!(
        "white furnace: worst |albedo − 1| {:.2e} ({}); darkest uncompensated {:.3}",
        w.worst, w.at, w.darkest
    );
    assert!(w.worst < 5e-3, "{}", w.at);
    assert!(
        w.darkest < 0.35,
        "the uncompensated lobes should lose energy: {}",
        w.darkest
    );
}

/// Compensated rough glass passes on all it receives: `R + T` (importance
/// mode, no absorption) within 1% of 1 for GGX and Beckmann, both kinds of
/// compensation, seen from the rarer side (η 1.5) and from the denser one
/// (η 1/1.5, total internal reflection), θo up to 89°, α 0.05 to 1.
#[test]
fn white_furnace_of_compensated_rough_glass() {
    let w = white_furnace(
        &[
            r#"{"type":"roughdielectric","distribution":"ggx","int_ior":1.5,"ext_ior":1}"#,
            r#"{"type":"roughdielectric","distribution":"ggx","int_ior":1,"ext_ior":1.5}"#,
            r#"{"type":"roughdielectric","distribution":"beckmann","int_ior":1.5,"ext_ior":1}"#,
            r#"{"type":"roughdielectric","distribution":"beckmann","int_ior":1,"ext_ior":1.5}"#,
        ],
        &[0.05, 0.2, 0.5, 1.0],
    );
    eprintln!(
        "rough glass furnace: worst |R + T − 1| {:.2e} ({})",
        w.worst, w.at
    );
    assert!(w.worst < 0.01, "{}", w.at);
}

/// A white base under a compensated rough coating sends back all the light
/// it receives, as under a smooth coating (whose Fresnel term alone says
/// what is reflected and what goes in): the albedo is 1 within 1% for GGX
/// and Beckmann, indices 1.2, 1.49 (polypropylene, the default) and 2.5,
/// linear and nonlinear, θo up to 89°, α 0.05 to 1. Mitsuba's
/// uncompensated rough plastic loses up to 85% at α 1 (Mitsuba 3 issue
/// 1155).
#[test]
fn white_furnace_of_compensated_rough_plastic() {
    let w = white_furnace(
        &[
            r#"{"type":"roughplastic","distribution":"ggx","diffuse_reflectance":1}"#,
            r#"{"type":"roughplastic","distribution":"beckmann","diffuse_reflectance":1}"#,
            r#"{"type":"roughplastic","distribution":"ggx","diffuse_reflectance":1,"int_ior":2.5,"nonlinear":true}"#,
            r#"{"type":"roughplastic","distribution":"beckmann","diffuse_reflectance":1,"int_ior":1.2}"#,
        ],
        &[0.05, 0.2, 0.5, 1.0],
    );
    eprintln!(
        "rough plastic furnace: worst |albedo − 1| {:.2e} ({}); darkest uncompensated {:.3}",
        w.worst, w.at, w.darkest
    );
    assert!(!w.walked, "a rough plastic has no random walk");
    assert!(w.worst < 0.01, "{}", w.at);
    assert!(
        w.darkest < 0.2,
        "Mitsuba's rough plastic should lose energy: {}",
        w.darkest
    );
}

/// Rough glass against the dielectric random walk: the share of the light
/// each reflects (the rest is transmitted; both pass on all of it). The
/// uncompensated lobe's `R` is the single-scattering `R_ss`, Turquin's is
/// `R_ss / (R_ss + T_ss)`: it splits the light that bounces more than once
/// as the first bounce does. The walk is the reference.
#[test]
fn rough_glass_reflects_like_the_dielectric_walk() {
    use lobe::stats::quadrature::{Tolerance, integrate_sphere_region};
    use std::f64::consts::{FRAC_PI_2, PI};
    let mut rows = Vec::new();
    let mut stream = 0;
    for (ndf, ext, int) in [
        ("ggx", 1.0, 1.5),
        ("ggx", 1.5, 1.0),
        ("beckmann", 1.0, 1.5),
        ("beckmann", 1.5, 1.0),
    ] {
        for alpha in [0.2, 0.5, 1.0] {
            let at = |kind: &str| {
                Material::load(&format!(
                    r#"{{"type":"roughdielectric","distribution":"{ndf}","alpha":{alpha},"int_ior":{int},"ext_ior":{ext},"mode":"importance","multiscatter":"{kind}"}}"#
                ))
                .unwrap()
            };
            let (none, tq, kc) = (at("none"), at("turquin"), at("kulla-conty"));
            let Glossy::RoughDielectric(rd) = &none.glossy else {
                unreachable!()
            };
            let walk = RandomWalk::dielectric(rd.microfacet, rd.eta).unwrap();
            for theta in [0.0, 45.0, 75.0] {
                let wo = lobe::frame::wo_from_theta(theta, 0.0);
                let reflected = |m: &Material| {
                    let f = |wi: DVec3| m.eval(wo, wi).x * wi.z;
                    let tol = Tolerance::relative(1e-4).with_initial(32, 32);
                    2.0 * integrate_sphere_region(f, (0.0, FRAC_PI_2), (0.0, PI), tol).value
                };
                let mut rng = lobe::sequence::chunk_rng(21, stream);
                stream += 1;
                let n = 100_000;
                let up = (0..n)
                    .filter(|_| walk.sample(wo, &mut rng).wi.is_some_and(|w| w.z > 0.0))
                    .count() as f64
                    / n as f64;
                let se = (up * (1.0 - up) / n as f64).sqrt();
                rows.push((
                    ndf,
                    rd.eta,
                    alpha,
                    theta,
                    reflected(&none),
                    reflected(&tq),
                    reflected(&kc),
                    up,
                    se,
                ));
            }
        }
    }
    eprintln!("rough glass, reflected share: ndf η α θo | none turquin kulla-conty | walk ± s.e.");
    let (mut closer, mut worst) = (0, (0.0f64, String::new()));
    let (mut kc_worst, mut kc_closer) = (0.0f64, 0);
    for &(ndf, eta, alpha, theta, none, tq, kc, walk, se) in &rows {
        eprintln!(
            "{ndf:9} {eta:.3} {alpha:.1} {theta:2} | {none:.4} {tq:.4} {kc:.4} | {walk:.4} ± {se:.4}"
        );
        kc_worst = kc_worst.max((kc - walk).abs());
        kc_closer += usize::from((kc - walk).abs() <= (tq - walk).abs() + 3.0 * se);
        closer += usize::from((tq - walk).abs() <= (none - walk).abs() + 3.0 * se);
        if (tq - walk).abs() > worst.0 {
            worst = (
                (tq - walk).abs(),
                format!("{ndf} η {eta:.3} α {alpha} θo {theta}: turquin {tq:.4}, walk {walk:.4}"),
            );
        }
    }
    eprintln!(
        "turquin at least as close as none in {closer} of {}; worst |R − R_walk| {:.4} ({})",
        rows.len(),
        worst.0,
        worst.1
    );
    // Compensation never moves the split away from the walk's. (How far
    // it stays is measured, not an aim: from the denser side at α 1 the
    // walk reflects up to 0.45 where Turquin's split gives 0.09, the light
    // that total internal reflection keeps inside; docs/energy.md.)
    assert_eq!(closer, rows.len(), "turquin moved R away from the walk");
    eprintln!(
        "kulla-conty at least as close as turquin in {kc_closer} of {}; worst |R − R_walk| {kc_worst:.4}",
        rows.len()
    );
    // Kulla-Conty's per-side split is nearer the walk than Turquin's where
    // Turquin's is worst (from the denser side).
    assert!(
        kc_worst < worst.0,
        "kulla-conty {kc_worst} vs turquin {}",
        worst.0
    );
}

/// Kulla-Conty's lobes keep rough glass reciprocal (radiance mode):
/// `f(a, b)/η_a² = f(b, a)/η_b²` with the added reflection and
/// transmission, from either side, GGX and Beckmann.
#[test]
fn kulla_conty_glass_is_reciprocal() {
    let dirs = [
        DVec3::new(0.3, 0.1, 0.9).normalize(),
        DVec3::new(-0.5, 0.2, 0.4).normalize(),
        DVec3::new(0.8, 0.0, 0.1).normalize(),
        DVec3::new(0.1, -0.6, -0.7).normalize(),
        DVec3::new(-0.2, 0.3, -0.5).normalize(),
        DVec3::new(0.0, 0.2, -0.98).normalize(),
    ];
    for json in [
        r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.8,"int_ior":1.5,"ext_ior":1,"multiscatter":"kulla-conty"}"#,
        r#"{"type":"roughdielectric","distribution":"beckmann","alpha":0.4,"int_ior":1.33,"ext_ior":1,"multiscatter":"kulla-conty"}"#,
    ] {
        let m = Material::load(json).unwrap();
        let Glossy::RoughDielectric(rd) = &m.glossy else {
            unreachable!()
        };
        let n = |w: DVec3| if w.z > 0.0 { 1.0 } else { rd.eta };
        let mut added = 0.0f64;
        for &a in &dirs {
            for &b in &dirs {
                let (fab, fba) = (m.eval(a, b).x, m.eval(b, a).x);
                added = added.max(fab);
                let (l, r) = (fab / (n(a) * n(a)), fba / (n(b) * n(b)));
                assert!(
                    (l - r).abs() <= 1e-12 * l.abs().max(1e-300),
                    "{json} {a} {b}: {l} vs {r}"
                );
            }
        }
        assert!(added > 0.0);
    }
}

/// Gold and copper: the random walk (every bounce, a Fresnel term at each)
/// against Kulla-Conty's compensated lobe on the height-correlated
/// single-scattering lobe the walk starts with. Compensation brings every
/// channel closer to the walk; the light it adds is more saturated than the
/// single-scattering lobe's, as in the walk (blue/red falls); and the
/// albedo is within 2% of the walk's for α ≤ 0.5 at θo ≤ 45°. (At α = 1
/// Kulla-Conty's colour term falls short by up to 7% in green and blue:
/// its Fresnel average weighs bounces by the cosine, the walk's bounces
/// meet the facets at more grazing angles, where the metals reflect more.)
#[test]
fn coloured_conductors_gain_saturation_like_the_random_walk() {
    let s = FurnaceSettings {
        thetas: vec![0.0, 45.0, 75.0],
        alphas: vec![0.2, 0.5, 1.0],
        walks: 40_000,
        seed: 5,
    };
    for metal in ["Au", "Cu"] {
        let (eta, k) = lobe::ior::conductor("material", metal).unwrap();
        let json = format!(
            r#"{{"type":"cook-torrance","fresnel":{{"type":"conductor","eta":[{},{},{}],"k":[{},{},{}]}}}}"#,
            eta.x, eta.y, eta.z, k.x, k.y, k.z
        );
        let f = furnace(&desc(&json), &s, &()).unwrap();
        for r in &f.rows {
            let RgbEstimate {
                mean: w,
                std_error: se,
            } = r.walk.unwrap();
            let (none, kc) = (r.none, r.kulla_conty);
            let at = format!("{metal} α {} θo {}", r.alpha, r.theta);
            for c in 0..3 {
                assert!(
                    (kc[c] - w[c]).abs() < (none[c] - w[c]).abs() + 4.0 * se[c],
                    "{at} channel {c}: compensated {} uncompensated {} walk {} ± {}",
                    kc[c],
                    none[c],
                    w[c],
                    se[c]
                );
                if r.alpha <= 0.5 && r.theta <= 45.0 {
                    assert!(
                        (kc[c] / w[c] - 1.0).abs() < 0.02 + 4.0 * se[c] / w[c],
                        "{at} channel {c}: compensated {} walk {} ± {}",
                        kc[c],
                        w[c],
                        se[c]
                    );
                }
            }
            // Saturation of what multiple scattering adds: blue over red.
            let ratio = |c: lobe::Rgb| c.z / c.x;
            let (walk_ms, kc_ms) = (w - none, kc - none);
            assert!(
                ratio(kc_ms) < ratio(none) && ratio(walk_ms) < ratio(none),
                "{at}: b/r of the single lobe {:.3}, of the added light: compensated {:.3}, walk {:.3}",
                ratio(none),
                ratio(kc_ms),
                ratio(walk_ms)
            );
        }
    }
}

/// The compensated lobe's shape: `f` on a grid of directions (θo 0°, 45°,
/// 75°; θi 0° to 80°; φ 0°, 90°, 180°) against the random walk's estimate
/// of `f`, where the walk's standard error is below 2%.
///
/// The issue's aim is 10% everywhere; Kulla-Conty's lobe does not meet it.
/// Its added lobe `(1 − E(μo))(1 − E(μi))` has no azimuth, while the
/// walk's multiply scattered light at α = 0.3 gathers around the mirror
/// direction (twice to five times Kulla-Conty's there) and is thinner on
/// the viewer's side (0.65×): measured (2·10⁴ walks a point) worst 25% at
/// α 0.3, θo 45°, θi 60° on the viewer's side; 16% at α 1 (θo 0°, θi
/// 80°); 5% at α 0.6; the median is 2.5%. This test holds that state (worst
/// below 30%, median below 5%) so that it cannot get worse unseen.
#[test]
fn lobe_shape_against_the_random_walk() {
    let mut errors: Vec<(f64, String)> = Vec::new();
    for alpha in [0.3, 0.6, 1.0] {
        let m = Material::load(&format!(
            r#"{{"type":"cook-torrance","alpha":{alpha},"multiscatter":"kulla-conty"}}"#
        ))
        .unwrap();
        let Glossy::CookTorrance(ct) = &m.glossy else {
            unreachable!()
        };
        let walk = RandomWalk::conductor(ct.microfacet, ct.ks, ct.fresnel).unwrap();
        let mut stream = 0;
        for theta_o in [0.0, 45.0, 75.0] {
            let wo = lobe::frame::wo_from_theta(theta_o, 0.0);
            for theta_i in [0.0, 20.0, 40.0, 60.0, 80.0] {
                for phi in [0.0, 90.0, 180.0] {
                    let wi = lobe::frame::wo_from_theta(theta_i, phi);
                    stream += 1;
                    let e = walk.eval(wo, wi, 20_000, 9, stream);
                    let (w, se) = (e.mean.x, e.std_error.x);
                    if !(w > 0.0 && se < 0.02 * w) {
                        continue;
                    }
                    let f = m.eval(wo, wi).x;
                    errors.push((
                        (f / w - 1.0).abs(),
                        format!("α {alpha} θo {theta_o} θi {theta_i} φ {phi}: f {f:.4} walk {w:.4} ± {se:.4}"),
                    ));
                }
            }
        }
    }
    errors.sort_by(|a, b| a.0.total_cmp(&b.0));
    let median = errors[errors.len() / 2].0;
    let worst = errors.last().unwrap();
    let within = errors.iter().filter(|e| e.0 < 0.10).count();
    eprintln!(
        "lobe shape: {} directions, {within} within 10%, median {median:.3}, worst {:.3} ({})",
        errors.len(),
        worst.0,
        worst.1
    );
    assert!(errors.len() > 100, "{}", errors.len());
    assert!(median < 0.05, "median {median}");
    assert!(worst.0 < 0.30, "{}", worst.1);
}

/// The built-in tables against a recomputation of some of their nodes
/// with another seed: within the combined standard error.
#[test]
fn stored_tables_match_a_recomputation() {
    let tables = AlbedoTables::builtin();
    let mut checked = 0;
    for (ndf, surface) in TABLES {
        let t = tables.get(ndf, surface).unwrap();
        let shape = Shape {
            n_mu: t.n_mu,
            n_alpha: t.n_alpha,
            n_eta: t.n_eta,
            samples: 1 << 14,
        };
        for (e, j, i) in [
            (0, 1, 1),
            (3, 6, 3),
            (5, 10, 0),
            (12, 20, 40),
            (20, 31, 63),
            (24, 45, 10),
            (9, 63, 2),
            (16, 63, 63),
        ] {
            let (e, j, i) = (
                e * (t.n_eta - 1) / 24,
                j * (t.n_alpha - 1) / 63,
                i * (t.n_mu - 1) / 63,
            );
            let m = node_estimate(ndf, surface, (e, j, i), shape, 12_345);
            let k = (e * t.n_alpha + j) * t.n_mu + i;
            let se = (m.std_error().powi(2) + t.std_errors[k].powi(2)).sqrt();
            assert!(
                (m.mean() - t.values[k]).abs() <= 5.0 * se + 1e-6,
                "{ndf:?} {surface:?} node ({e}, {j}, {i}): stored {} ± {}, recomputed {} ± {}",
                t.values[k],
                t.std_errors[k],
                m.mean(),
                m.std_error()
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 48);
}

/// Without compensation the lobes give the bits they gave before energy
/// compensation existed (values printed by lobe at commit 30bb039; the
/// rough plastics' at 6fdba28, before they had the key).
#[test]
fn uncompensated_lobes_are_unchanged_bit_for_bit() {
    let golden = include_str!("energy_golden.txt");
    let mats = [
        r#"{"type":"roughconductor","distribution":"ggx","alpha":0.3,"material":"Au"}"#,
        r#"{"type":"roughconductor","distribution":"beckmann","alpha":0.7}"#,
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.5,"kd":0.2,"fresnel":{"type":"schlick"}}"#,
        r#"{"type":"roughplastic","distribution":"ggx","alpha":0.3,"diffuse_reflectance":[0.8,0.5,0.2]}"#,
        r#"{"type":"roughplastic","distribution":"beckmann","alpha":0.6,"nonlinear":true}"#,
    ];
    let mut lines = golden.lines();
    for j in mats {
        for none in [false, true] {
            let json = if none {
                j.replacen('{', r#"{"multiscatter":"none","#, 1)
            } else {
                j.to_string()
            };
            let m = Material::load(&json).unwrap();
            let mut lines = lines.clone();
            for s in [BsdfStrategy::Brdf, BsdfStrategy::Vndf] {
                let smp = m.sampler(s).unwrap();
                for (k, t) in [10.0f64, 50.0, 80.0].iter().enumerate() {
                    let wo = lobe::frame::wo_from_theta(*t, 20.0);
                    let u = DVec2::new(0.3 + 0.2 * k as f64, 0.7);
                    let x = smp.sample(wo, 0.4, u).unwrap();
                    let wi = DVec3::new(-0.3, 0.1 * k as f64, 0.8).normalize();
                    let f = m.eval(wo, wi);
                    let p = smp.pdf(wo, wi);
                    let now = format!(
                        "{:#x} {:#x} {:#x} {:#x} {:#x} {:#x} {:#x}",
                        x.wi.x.to_bits(),
                        x.weight.y.to_bits(),
                        x.pdf.to_bits(),
                        f.x.to_bits(),
                        f.z.to_bits(),
                        p.to_bits(),
                        x.f.y.to_bits()
                    );
                    assert_eq!(Some(now.as_str()), lines.next(), "{json} {s} θo {t}");
                }
            }
        }
        for _ in 0..6 {
            lines.next();
        }
    }
}

#[test]
fn bad_input_names_the_field() {
    let err = |json: &str| Material::load(json).unwrap_err().to_string();
    let e = err(r#"{"type":"cook-torrance","multiscatter":"heitz"}"#);
    assert!(
        e.contains("multiscatter") && e.contains("kulla-conty"),
        "{e}"
    );
    let e = err(r#"{"type":"cook-torrance","shadowing":"v-cavity","multiscatter":"kulla-conty"}"#);
    assert!(e.contains("multiscatter") && e.contains("v-cavity"), "{e}");
    let e =
        err(r#"{"type":"cook-torrance","distribution":"blinn-phong","multiscatter":"turquin"}"#);
    assert!(
        e.contains("multiscatter") && e.contains("blinn-phong"),
        "{e}"
    );
    let e = err(r#"{"type":"phong","multiscatter":"kulla-conty"}"#);
    assert!(e.contains("multiscatter"), "{e}");
    let e =
        err(r#"{"type":"roughplastic","int_ior":1,"ext_ior":1.33,"multiscatter":"kulla-conty"}"#);
    assert!(
        e.contains("multiscatter") && e.contains("int_ior ≥ ext_ior"),
        "{e}"
    );
    // Beyond the dielectric tables' η, and a plastic's coating rarer than the outside.
    let e = err(r#"{"type":"roughdielectric","int_ior":4,"multiscatter":"turquin"}"#);
    assert!(e.contains("multiscatter") && e.contains("1/3 to 3"), "{e}");
    let e = err(r#"{"type":"roughplastic","int_ior":1,"ext_ior":1.33,"multiscatter":"turquin"}"#);
    assert!(
        e.contains("multiscatter") && e.contains("int_ior ≥ ext_ior"),
        "{e}"
    );
    // The furnace refuses what it cannot compare.
    let s = FurnaceSettings {
        walks: 0,
        ..FurnaceSettings::standard()
    };
    let e = furnace(&desc(r#"{"type":"phong"}"#), &s, &())
        .unwrap_err()
        .to_string();
    assert!(e.contains("type") || e.contains("alpha"), "{e}");
    let bad = FurnaceSettings {
        thetas: vec![90.0],
        ..s.clone()
    };
    let e = furnace(&desc(r#"{"type":"cook-torrance"}"#), &bad, &())
        .unwrap_err()
        .to_string();
    assert!(e.contains("theta") && e.contains("89.9"), "{e}");
}
