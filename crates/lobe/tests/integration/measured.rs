//! Measured materials (MERL and RGL tables written from analytic models):
//! evaluation against the model, reciprocity, the tabulated sampler's
//! chi-square and pdf consistency, the estimator's unbiasedness and
//! variance, relative paths, and every bad-file case.

use glam::{DVec2, DVec3};
use lobe::estimator::{EstimateSettings, ShadingPoint, estimate, reference};
use lobe::math::luminance;
use lobe::models::measured::merl::{self, Merl};
use lobe::models::measured::rgl::{self, Rgl};
use lobe::models::measured::{Measured, Table};
use lobe::stats::chi2::{Chi2Settings, TABLE_MAX_EVALS_PER_CELL, chi2_test, sidak};
use lobe::{BsdfStrategy, Glossy, Light, Material, Rgb};
use std::path::PathBuf;
use std::sync::OnceLock;

fn dir() -> PathBuf {
    // Under target/ (not /tmp, where a run's 200 MB of tables would stay):
    // each run overwrites the last one's files.
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("measured");
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn analytic(json: &str) -> Material {
    Material::load(json).unwrap()
}

const GGX: &str = r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.3,"kd":0.2,"fresnel":{"type":"schlick","f0":0.5}}"#;
const GLOSSY: &str = r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.1,"fresnel":{"type":"schlick","f0":0.8}}"#;
const BECKMANN: &str =
    r#"{"type":"cook-torrance","distribution":"beckmann","alpha":0.25,"kd":[0.3,0.2,0.1]}"#;

/// Every 101st entry is missing.
fn missing(i: usize) -> bool {
    i % 101 == 7
}

/// A MERL file of `json` (with missing entries), written once per test run.
fn merl_file(json: &str, name: &str) -> PathBuf {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _g = LOCK
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let m = analytic(json);
    let path = dir().join(name);
    if !path.exists() {
        let t = Merl::from_fn(|wo, wi| m.eval(wo, wi), missing);
        let tmp = path.with_extension("partial");
        std::fs::write(&tmp, t.to_bytes()).unwrap();
        std::fs::rename(&tmp, &path).unwrap();
    }
    path
}

fn merl_material(json: &str, name: &str, interp: &str) -> Material {
    let path = merl_file(json, name);
    Material::load(&format!(
        r#"{{"type":"measured","path":"{}","interpolation":"{interp}"}}"#,
        path.display()
    ))
    .unwrap()
}

pub(crate) fn ggx_merl() -> &'static Material {
    static M: OnceLock<Material> = OnceLock::new();
    M.get_or_init(|| merl_material(GGX, "ggx.binary", "nearest"))
}

fn glossy_merl() -> &'static Material {
    static M: OnceLock<Material> = OnceLock::new();
    M.get_or_init(|| merl_material(GLOSSY, "glossy.binary", "linear"))
}

pub(crate) fn beckmann_rgl() -> &'static Material {
    static M: OnceLock<Material> = OnceLock::new();
    M.get_or_init(|| {
        let m = analytic(BECKMANN);
        let path = dir().join("beckmann.bsdf");
        let bytes = Rgl::write(|wo, wi| m.eval(wo, wi), 16, 64, "beckmann");
        std::fs::write(&path, bytes).unwrap();
        Material::load(&format!(
            r#"{{"type":"measured","path":"{}"}}"#,
            path.display()
        ))
        .unwrap()
    })
}

fn wo(theta: f64) -> DVec3 {
    let t = theta.to_radians();
    DVec3::new(t.sin(), 0.0, t.cos())
}

fn dir_of(theta: f64, phi: f64) -> DVec3 {
    let (t, p) = (theta.to_radians(), phi.to_radians());
    DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

#[test]
fn merl_entries_evaluate_back_to_the_model() {
    let m = ggx_merl();
    let a = analytic(GGX);
    let mut checked = 0;
    for ih in (0..90).step_by(7) {
        for id in (0..90).step_by(11) {
            for ip in (0..180).step_by(13) {
                let (o, i) = merl::centre(ih, id, ip);
                if o.z <= 0.0 || i.z <= 0.0 {
                    continue;
                }
                let got = m.eval(o, i);
                let idx = ip + 180 * (id + 90 * ih);
                if missing(idx) {
                    assert_eq!(got, Rgb::ZERO, "a missing entry reflects nothing");
                    continue;
                }
                let want = a.eval(o, i);
                // f32 storage: 1e-6 relative.
                assert!(
                    (got - want).abs().max_element() <= 1e-6 * want.max_element() + 1e-9,
                    "entry ({ih},{id},{ip}): {got} vs {want}"
                );
                // Reciprocity: one entry for both orders.
                assert_eq!(m.eval(i, o), got);
                checked += 1;
            }
        }
    }
    assert!(checked > 500, "{checked}");
}

#[test]
fn merl_linear_interpolation_is_within_the_resolution() {
    // Off the entries' centres, trilinear lookup of a rough lobe stays
    // within 3% of the model (nearest: within a bin's step).
    let m = merl_material(BECKMANN, "beckmann.binary", "linear");
    let a = analytic(BECKMANN);
    let mut worst: f64 = 0.0;
    for (to, ti, p) in [
        (10.0, 20.0, 170.0),
        (30.0, 40.0, 200.0),
        (45.0, 45.0, 180.0),
        (60.0, 20.0, 90.0),
        (5.0, 70.0, 30.0),
    ] {
        let (o, i) = (dir_of(to, 0.0), dir_of(ti, p));
        let (g, w) = (luminance(m.eval(o, i)), luminance(a.eval(o, i)));
        worst = worst.max((g - w).abs() / w);
    }
    assert!(worst < 0.03, "worst relative error {worst}");
}

#[test]
fn rgl_values_match_the_model_within_the_resolution() {
    let m = beckmann_rgl();
    let a = analytic(BECKMANN);
    let mut worst: f64 = 0.0;
    // At a tabulated view (θ = k·89°/15) the table is exact at its grid
    // points and bilinear between them.
    let t = 89.0 / 15.0 * 5.0;
    for (ti, p) in [
        (20.0, 180.0),
        (30.0, 150.0),
        (45.0, 200.0),
        (10.0, 90.0),
        (60.0, 180.0),
    ] {
        let (o, i) = (dir_of(t, 0.0), dir_of(ti, p));
        let (g, w) = (luminance(m.eval(o, i)), luminance(a.eval(o, i)));
        worst = worst.max((g - w).abs() / w);
    }
    assert!(worst < 0.03, "worst relative error {worst}");
}

/// Chi-square of the tabulated sampler in the space of `wi` at several
/// views (MERL nearest and linear, RGL), the cells' probabilities by
/// cubature of the pdf. The pdf is piecewise constant over half-vector
/// cells, so the cubature gets a smaller budget per cell (as for
/// environment maps). The glossy table (α = 0.1) is tested at 30° only: at
/// normal incidence its lobe sits in the polar cells, where ~100 wedges of
/// the half-vector table meet and the cubature does not converge (error
/// ~1e-3 of the ring's mass, which fails the test). The exact test of the
/// half-vector cells (`sampler::tests`, every view) covers that case.
#[test]
fn chi2_of_the_tabulated_sampler() {
    let cfg = Chi2Settings {
        samples: 400_000,
        n_z: 40,
        n_phi: 80,
        ..lobe::experiment::warp_test::chi2_config(ggx_merl())
    };
    assert_eq!(cfg.max_evals_per_cell, TABLE_MAX_EVALS_PER_CELL);
    let cases: [(&str, &Material); 3] = [
        ("ggx-merl-nearest", ggx_merl()),
        ("glossy-merl-linear", glossy_merl()),
        ("beckmann-rgl", beckmann_rgl()),
    ];
    let thetas = [0.0, 30.0, 60.0, 80.0];
    let alpha = sidak(0.01, 9);
    let mut failures = Vec::new();
    for (name, m) in cases {
        for theta in thetas {
            if name.starts_with("glossy") && theta != 30.0 {
                continue;
            }
            let o = wo(theta);
            let r = chi2_test(
                &cfg,
                |uc, u| {
                    m.sampler(BsdfStrategy::Brdf)
                        .unwrap()
                        .sample(o, uc, u)
                        .map(|s| s.wi)
                },
                |wi| m.sampler(BsdfStrategy::Brdf).unwrap().pdf(o, wi),
            );
            eprintln!(
                "{name} θo={theta}: χ² = {:.1}, dof {}, p = {:.3}",
                r.statistic, r.dof, r.p_value
            );
            if !r.passes(alpha) {
                failures.push(format!(
                    "{name} θo={theta}: p = {:.3e} {:?}",
                    r.p_value, r.message
                ));
            }
            if (r.pdf_integral - (1.0 - r.lost_observed / cfg.samples as f64)).abs() > 2e-3 {
                failures.push(format!(
                    "{name} θo={theta}: ∫pdf = {} but {} samples of {} are lost",
                    r.pdf_integral, r.lost_observed, cfg.samples
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The pdf that `sample` returns is `pdf(wo, wi)` of the same pair, and
/// `eval_pdf` agrees (pbrt-v4#207 swapped wo and wi in one of them).
#[test]
fn sampled_pdf_is_the_pdf_of_the_pair() {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    for m in [ggx_merl(), glossy_merl(), beckmann_rgl()] {
        let mut n = 0;
        for _ in 0..20_000 {
            let o = dir_of(rng.random::<f64>() * 89.0, rng.random::<f64>() * 360.0);
            let u = DVec2::new(rng.random(), rng.random());
            let Some(s) = m
                .sampler(BsdfStrategy::Brdf)
                .unwrap()
                .sample(o, rng.random(), u)
            else {
                continue;
            };
            n += 1;
            let p = m.sampler(BsdfStrategy::Brdf).unwrap().pdf(o, s.wi);
            assert!((s.pdf - p).abs() <= 1e-12 * p, "{} vs {p}", s.pdf);
            let (f, p2) = m.sampler(BsdfStrategy::Brdf).unwrap().eval_pdf(o, s.wi);
            assert_eq!((f, p2), (m.eval(o, s.wi), p));
            assert_eq!(s.f, f);
            // Swapping the directions is another pair: its pdf is its own.
            assert!(p > 0.0);
        }
        assert!(n > 15_000);
    }
}

/// The estimate of a measured material (a MERL table, linear, and an RGL
/// file) under constant light and a beam is unbiased (t-test within 4
/// standard errors of the quadrature reference), for every strategy
/// (uniform, cosine, brdf, and for the RGL file vndf).
#[test]
fn estimates_are_unbiased() {
    let lights = [
        Light::Constant(Rgb::new(1.0, 0.8, 0.6)),
        Light::Beam {
            dir: DVec3::new(-0.5, 0.2, 0.8).normalize(),
            exponent: 8.0,
            radiance: Rgb::splat(2.0),
        },
    ];
    let merl = merl_material(BECKMANN, "beckmann.binary", "linear");
    let mut failures = Vec::new();
    let mut seed = 0;
    for (name, m, thetas) in [
        ("merl", &merl, &[0.0, 45.0, 75.0][..]),
        ("rgl", beckmann_rgl(), &[0.0, 45.0, 75.0][..]),
    ] {
        for &theta in thetas {
            let sp = ShadingPoint::local(wo(theta));
            for light in &lights {
                let r = luminance(reference(m, &sp, light, 1e-6));
                for s in m.strategies() {
                    seed += 1;
                    let acc = estimate(
                        m,
                        &sp,
                        light,
                        &EstimateSettings::independent(s, 1 << 15, seed),
                    )
                    .unwrap();
                    let (mean, se) = (acc.lum.mean(), acc.lum.std_error());
                    if (mean - r).abs() > 4.0 * se + 1e-5 * r {
                        failures.push(format!(
                            "{name} θ={theta} {light:?} {s}: {mean} ± {se}, reference {r}"
                        ));
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// For a glossy table (α = 0.1) the tabulated sampler's variance is at
/// least 4× lower than cosine sampling's.
#[test]
fn tabulated_sampling_beats_cosine_on_a_glossy_table() {
    let m = glossy_merl();
    let light = Light::Constant(Rgb::ONE);
    for theta in [0.0, 30.0, 60.0] {
        let sp = ShadingPoint::local(wo(theta));
        let var = |s: BsdfStrategy| {
            let acc = estimate(
                m,
                &sp,
                &light,
                &EstimateSettings::independent(s, 1 << 16, 3),
            )
            .unwrap();
            acc.lum.variance()
        };
        let (vb, vc) = (var(BsdfStrategy::Brdf), var(BsdfStrategy::Cosine));
        eprintln!(
            "θo={theta}: variance brdf {vb:.4e}, cosine {vc:.4e}, ratio {:.1}",
            vc / vb
        );
        assert!(vc >= 4.0 * vb, "θo={theta}: brdf {vb} vs cosine {vc}");
    }
}

/// A table lives as long as a material holds it: the cache keeps it only
/// while it is in use, so a process that loads many files (a server) does
/// not keep every table it ever read.
#[test]
fn a_table_is_freed_with_the_last_material_that_holds_it() {
    let weak_data = |m: &Material| match &m.glossy {
        Glossy::Measured(x) => std::sync::Arc::downgrade(&x.data),
        _ => panic!("not measured"),
    };
    let a = merl_material(GLOSSY, "freed.binary", "linear");
    let b = merl_material(GLOSSY, "freed.binary", "linear");
    let c = a.clone();
    let w = weak_data(&a);
    assert!(std::sync::Arc::ptr_eq(
        &w.upgrade().unwrap(),
        &weak_data(&b).upgrade().unwrap()
    ));
    drop((a, b));
    assert!(w.upgrade().is_some(), "a clone still holds the table");
    drop(c);
    assert!(w.upgrade().is_none(), "the table outlived every material");
    // Named again, it is read again.
    let d = merl_material(GLOSSY, "freed.binary", "linear");
    assert!(weak_data(&d).upgrade().is_some());
}

#[test]
fn the_table_is_shared_and_only_the_listed_strategies_apply() {
    let a = merl_material(GGX, "ggx.binary", "nearest");
    let b = ggx_merl();
    let (Glossy::Measured(x), Glossy::Measured(y)) = (&a.glossy, &b.glossy) else {
        panic!("not measured")
    };
    assert!(
        std::sync::Arc::ptr_eq(&x.data, &y.data),
        "one file, one table"
    );
    assert_eq!(
        a.strategies(),
        vec![
            BsdfStrategy::Uniform,
            BsdfStrategy::Cosine,
            BsdfStrategy::Brdf
        ]
    );
    let e = a.sampler(BsdfStrategy::Vndf).unwrap_err().to_string();
    assert!(e.contains("MERL table has no visible-normal warp"), "{e}");
    let (table, sampler) = x.memory();
    eprintln!(
        "MERL table {} bytes, sampler {} bytes, read {:.3} s, sampler built in {:.3} s",
        table, sampler, x.data.read_seconds, x.data.build_seconds
    );
    assert_eq!(table, 90 * 90 * 180 * 12);
    // "Reading a 33 MB MERL file takes well under a second."
    assert!(
        x.data.read_seconds < 1.0,
        "read in {} s",
        x.data.read_seconds
    );
}

#[test]
fn relative_paths_are_relative_to_the_file_that_names_them() {
    let sub = dir().join("sub");
    std::fs::create_dir_all(&sub).unwrap();
    let m = analytic(GGX);
    std::fs::write(
        sub.join("t.bsdf"),
        Rgl::write(|o, i| m.eval(o, i), 4, 8, "t"),
    )
    .unwrap();
    std::fs::write(sub.join("m.json"), r#"{"type":"measured","path":"t.bsdf"}"#).unwrap();
    std::fs::write(
        sub.join("m.toml"),
        "type = \"measured\"\npath = \"t.bsdf\"\n",
    )
    .unwrap();
    for f in ["m.json", "m.toml"] {
        let mm = Material::load(&format!("@{}", sub.join(f).display())).unwrap();
        assert_eq!(mm.model_name(), "measured");
    }
    // Inline JSON: the working directory.
    let e = Material::load(r#"{"type":"measured","path":"surely-not-here.bsdf"}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("file surely-not-here.bsdf: cannot read"), "{e}");
    let e = Material::load(&format!(
        r#"{{"type":"measured","path":"{}","interpolation":"linear"}}"#,
        sub.join("t.bsdf").display()
    ))
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("`interpolation`: applies to MERL tables only"),
        "{e}"
    );
    let e = Material::load(r#"{"type":"measured"}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("`path`: missing"), "{e}");
    let e = Material::load(r#"{"type":"measured","path":"x","interpolation":"cubic"}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown value `cubic`"), "{e}");
}

fn parse_err(bytes: &[u8]) -> String {
    match Table::parse(bytes, "bad.file") {
        Ok(t) => panic!("accepted a bad file as {}", t.format()),
        Err(e) => {
            let s = e.to_string();
            assert!(s.starts_with("file bad.file: "), "{s}");
            s
        }
    }
}

fn small_merl_bytes() -> Vec<u8> {
    let path = merl_file(GGX, "ggx.binary");
    std::fs::read(path).unwrap()
}

#[test]
fn bad_merl_files_get_clear_errors() {
    let good = small_merl_bytes();
    assert!(Table::parse(&good, "good").is_ok());
    let e = parse_err(&good[..7]);
    assert!(e.contains("truncated: 7 bytes"), "{e}");
    let e = parse_err(&good[..good.len() - 8]);
    assert!(e.contains("truncated: the header claims"), "{e}");
    let mut dims = good.clone();
    dims[8..12].copy_from_slice(&360i32.to_le_bytes());
    let e = parse_err(&dims);
    assert!(
        e.contains("dimensions 90×90×360") && e.contains("expected MERL's 90×90×180"),
        "{e}"
    );
    let mut huge = good[..12].to_vec();
    huge[0..4].copy_from_slice(&i32::MAX.to_le_bytes());
    let e = parse_err(&huge);
    assert!(e.contains("dimensions 2147483647×90×180"), "{e}");
    let mut long = good.clone();
    long.extend_from_slice(&[0; 16]);
    let e = parse_err(&long);
    assert!(e.contains("16 bytes after"), "{e}");
    for (bad, word) in [(f64::NAN, "NaN"), (f64::INFINITY, "inf")] {
        let mut b = good.clone();
        let at = 12 + 8 * (2 * merl::N + 5);
        b[at..at + 8].copy_from_slice(&bad.to_le_bytes());
        let e = parse_err(&b);
        assert!(
            e.contains("entry 5 of the blue channel") && e.contains(word),
            "{e}"
        );
    }
    let mut none = good[..12].to_vec();
    none.extend(std::iter::repeat_n((-1.0f64).to_le_bytes(), 3 * merl::N).flatten());
    let e = parse_err(&none);
    assert!(e.contains("no valid entry"), "{e}");
}

fn small_rgl_bytes() -> Vec<u8> {
    let m = analytic(GGX);
    Rgl::write(|o, i| m.eval(o, i), 3, 6, "small")
}

/// Rebuild a tensor file with one field changed (`None` drops it).
fn edit_rgl(name: &str, f: impl Fn(&mut rgl::Field) -> bool) -> Vec<u8> {
    let fields = rgl::parse_tensor(&small_rgl_bytes()).unwrap();
    let mut list: Vec<(&str, rgl::Field)> = Vec::new();
    let order = [
        "description",
        "jacobian",
        "theta_i",
        "phi_i",
        "ndf",
        "sigma",
        "vndf",
        "luminance",
        "rgb",
    ];
    for n in order {
        let mut fld = fields[n].clone();
        if n == name && !f(&mut fld) {
            continue;
        }
        list.push((n, fld));
    }
    rgl::write_tensor(&list)
}

#[test]
fn bad_rgl_files_get_clear_errors() {
    let good = small_rgl_bytes();
    assert!(Table::parse(&good, "good").is_ok());
    let e = parse_err(&good[..15]);
    assert!(e.contains("truncated: 15 bytes"), "{e}");
    let e = parse_err(&good[..40]);
    assert!(
        e.contains("truncated: the file ends at byte 40 inside the header of field"),
        "{e}"
    );
    let e = parse_err(&good[..good.len() - 4]);
    assert!(
        e.contains("field `rgb`") && e.contains("claims bytes"),
        "{e}"
    );
    let e = parse_err(&edit_rgl("vndf", |_| false));
    assert!(e.contains("missing field `vndf`"), "{e}");
    let e = parse_err(&edit_rgl("rgb", |_| false));
    assert!(e.contains("missing field `rgb`"), "{e}");
    let e = parse_err(&edit_rgl("rgb", |f| {
        f.data[8..12].copy_from_slice(&f32::NAN.to_le_bytes());
        true
    }));
    assert!(e.contains("field `rgb`: entry 2 is NaN"), "{e}");
    let e = parse_err(&edit_rgl("luminance", |f| {
        f.data[0..4].copy_from_slice(&f32::INFINITY.to_le_bytes());
        true
    }));
    assert!(e.contains("field `luminance`: entry 0 is inf"), "{e}");
    let e = parse_err(&edit_rgl("rgb", |f| {
        f.data.iter_mut().for_each(|b| *b = 0);
        true
    }));
    assert!(e.contains("no valid entry"), "{e}");
    let e = parse_err(&edit_rgl("phi_i", |f| {
        *f = rgl::Field::f32(&[4], &[0.0, 1.0, 2.0, 3.0]);
        true
    }));
    assert!(e.contains("anisotropic table (phi_i has 4 entries)"), "{e}");
    let e = parse_err(&edit_rgl("vndf", |f| {
        f.shape = vec![1, 2, 6, 6];
        f.data.truncate(2 * 36 * 4);
        true
    }));
    assert!(
        e.contains("field `vndf` has shape [1, 2, 6, 6], expected [1, 3,"),
        "{e}"
    );
    let e = parse_err(&edit_rgl("theta_i", |f| {
        f.dtype = rgl::DType::F64;
        f.shape = vec![1];
        f.data.truncate(8);
        true
    }));
    assert!(e.contains("field `theta_i` is F64"), "{e}");
    let mut header = good.clone();
    header[12] = 2;
    let e = parse_err(&header);
    assert!(e.contains("version 2.0"), "{e}");
    // Neither format.
    let e = parse_err(b"hello, this is not a table at all");
    assert!(
        e.contains("not an RGL file") && e.contains("not a MERL file"),
        "{e}"
    );
}

#[test]
fn a_measured_material_names_its_file_in_errors() {
    let p = dir().join("garbage.binary");
    std::fs::write(&p, b"0123456789abcdef").unwrap();
    let e = Material::load(&format!(
        r#"{{"type":"measured","path":"{}"}}"#,
        p.display()
    ))
    .unwrap_err()
    .to_string();
    assert!(e.contains(&format!("file {}: ", p.display())), "{e}");
    let _ = Measured::load(&p, None).unwrap_err();
}

/// `lobe fit` recovers the parameters of a tabulated analytic material
/// (GGX and Beckmann, each with a Lambert term and missing entries): alpha
/// within 5%, kd and f0 within 0.02.
#[test]
fn fit_recovers_a_tabulated_material() {
    for (json, name, ndf, alpha, f0, kd) in [
        (
            r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.15,"kd":[0.1,0.2,0.05],"fresnel":{"type":"schlick","f0":[0.9,0.6,0.3]}}"#,
            "fit-ggx.binary",
            lobe::Ndf::Ggx,
            0.15,
            Rgb::new(0.9, 0.6, 0.3),
            Rgb::new(0.1, 0.2, 0.05),
        ),
        (
            r#"{"type":"cook-torrance","distribution":"beckmann","alpha":0.3,"kd":[0.3,0.2,0.1],"fresnel":{"type":"schlick","f0":[0.5,0.4,0.6]}}"#,
            "fit-beckmann.binary",
            lobe::Ndf::Beckmann,
            0.3,
            Rgb::new(0.5, 0.4, 0.6),
            Rgb::new(0.3, 0.2, 0.1),
        ),
    ] {
        let m = merl_material(json, name, "nearest");
        let t0 = std::time::Instant::now();
        let fit = lobe::fit::fit_cook_torrance(&m, ndf).unwrap();
        eprintln!(
            "{name}: {} error {:.3e} ({} evaluations over {} pairs, {:.1} s)",
            fit.to_json(),
            fit.error,
            fit.evaluations,
            fit.pairs,
            t0.elapsed().as_secs_f64()
        );
        assert!(
            (fit.alpha_u - alpha).abs() <= 0.05 * alpha && fit.alpha_v == fit.alpha_u,
            "{name}: alpha {} {}",
            fit.alpha_u,
            fit.alpha_v
        );
        let lobe::Fresnel::Schlick { f0: fitted } = fit.fresnel else {
            panic!("{name}: {:?}", fit.fresnel)
        };
        assert!(
            (fitted - f0).abs().max_element() <= 0.02,
            "{name}: f0 {fitted}"
        );
        assert!(
            (fit.kd - kd).abs().max_element() <= 0.02,
            "{name}: kd {}",
            fit.kd
        );
        // The printed material is accepted by --material.
        assert!(Material::load(&fit.to_json()).is_ok());
    }
}

/// RGL's own scheme (`vndf`: the file's luminance warp, then its
/// visible-normal warp, as Mitsuba 3 samples): chi-square of its samples
/// against its pdf at two views, one of the file's tabulated views and one
/// between two, and the pdf `sample` returns is `pdf` of the pair. MERL
/// tables have no such warps (`vndf` refused).
#[test]
fn chi2_of_the_rgl_warps() {
    let m = beckmann_rgl();
    assert!(m.strategies().contains(&BsdfStrategy::Vndf));
    let e = ggx_merl()
        .sampler(BsdfStrategy::Vndf)
        .unwrap_err()
        .to_string();
    assert!(e.contains("MERL table has no visible-normal warp"), "{e}");
    let cfg = Chi2Settings {
        samples: 200_000,
        n_z: 32,
        n_phi: 64,
        max_evals_per_cell: 2000,
        ..Chi2Settings::default()
    };
    let alpha = sidak(0.01, 2);
    let mut failures = Vec::new();
    // 17.8° is a tabulated view (89°·3/15); 60° lies between two.
    for theta in [17.8, 60.0] {
        let o = dir_of(theta, 30.0);
        let r = chi2_test(
            &cfg,
            |uc, u| {
                m.sampler(BsdfStrategy::Vndf)
                    .unwrap()
                    .sample(o, uc, u)
                    .map(|s| s.wi)
            },
            |wi| m.sampler(BsdfStrategy::Vndf).unwrap().pdf(o, wi),
        );
        eprintln!(
            "beckmann-rgl vndf θo={theta}: χ² = {:.1}, dof {}, p = {:.3}, ∫pdf = {:.4}, lost {}",
            r.statistic, r.dof, r.p_value, r.pdf_integral, r.lost_observed
        );
        if !r.passes(alpha) {
            failures.push(format!("θo={theta}: p = {:.3e} {:?}", r.p_value, r.message));
        }
        if (r.pdf_integral - (1.0 - r.lost_observed / cfg.samples as f64)).abs() > 3e-3 {
            failures.push(format!(
                "θo={theta}: ∫pdf = {} but {} samples of {} are lost",
                r.pdf_integral, r.lost_observed, cfg.samples
            ));
        }
        for k in 0..200 {
            let u = DVec2::new(
                (k as f64 + 0.5) / 200.0,
                ((k * 37) % 200) as f64 / 200.0 + 0.0025,
            );
            if let Some(s) = m.sampler(BsdfStrategy::Vndf).unwrap().sample(o, 0.5, u) {
                let p = m.sampler(BsdfStrategy::Vndf).unwrap().pdf(o, s.wi);
                assert!(
                    p > 0.0 && (s.pdf - p).abs() <= 1e-12 * p,
                    "{} vs {p}",
                    s.pdf
                );
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// `lobe fit --fresnel conductor` recovers a conductor's `eta` and `k`
/// (within 5%), alpha (5%) and kd (0.02) from a MERL table lobe tabulated
/// itself.
#[test]
fn fit_recovers_a_conductor() {
    use lobe::fit::{FitSettings, FresnelFit};
    let json = r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2,"kd":[0.05,0.1,0.02],"fresnel":{"type":"conductor","eta":[0.2,0.5,1.4],"k":[3.5,2.4,1.8]}}"#;
    let m = merl_material(json, "fit-conductor.binary", "nearest");
    let t0 = std::time::Instant::now();
    let opts = FitSettings {
        fresnel: FresnelFit::Conductor,
        ..FitSettings::default()
    };
    let fit = lobe::fit::fit(&m, opts).unwrap();
    eprintln!(
        "conductor: {} error {:.3e} ({} evaluations, {:.1} s)",
        fit.to_json(),
        fit.error,
        fit.evaluations,
        t0.elapsed().as_secs_f64()
    );
    let lobe::Fresnel::Conductor { eta, k } = fit.fresnel else {
        panic!("{:?}", fit.fresnel)
    };
    let rel = |a: Rgb, b: Rgb| ((a - b).abs() / b).max_element();
    assert!(rel(eta, Rgb::new(0.2, 0.5, 1.4)) <= 0.05, "eta {eta}");
    assert!(rel(k, Rgb::new(3.5, 2.4, 1.8)) <= 0.05, "k {k}");
    assert!((fit.alpha_u - 0.2).abs() <= 0.01, "alpha {}", fit.alpha_u);
    assert!(
        (fit.kd - Rgb::new(0.05, 0.1, 0.02)).abs().max_element() <= 0.02,
        "kd {}",
        fit.kd
    );
    assert!(Material::load(&fit.to_json()).is_ok());
}

/// An anisotropic fit recovers `alpha_u` and `alpha_v` (within 5%) of an
/// anisotropic target (an analytic one: the tables lobe reads are
/// isotropic), and `alpha_u ≈ alpha_v` for an isotropic MERL table.
#[test]
fn fit_recovers_anisotropic_alphas() {
    use lobe::fit::FitSettings;
    let opts = FitSettings {
        anisotropic: true,
        ..FitSettings::default()
    };
    let aniso = analytic(
        r#"{"type":"cook-torrance","distribution":"ggx","alpha_u":0.1,"alpha_v":0.3,"kd":0.1,"fresnel":{"type":"schlick","f0":[0.9,0.8,0.6]}}"#,
    );
    let t0 = std::time::Instant::now();
    let fit = lobe::fit::fit(&aniso, opts).unwrap();
    eprintln!(
        "anisotropic: {} error {:.3e} ({} evaluations, {:.1} s)",
        fit.to_json(),
        fit.error,
        fit.evaluations,
        t0.elapsed().as_secs_f64()
    );
    assert!(
        (fit.alpha_u - 0.1).abs() <= 0.005,
        "alpha_u {}",
        fit.alpha_u
    );
    assert!(
        (fit.alpha_v - 0.3).abs() <= 0.015,
        "alpha_v {}",
        fit.alpha_v
    );
    assert!(Material::load(&fit.to_json()).is_ok());
    let iso = lobe::fit::fit(ggx_merl(), opts).unwrap();
    eprintln!(
        "isotropic table, anisotropic fit: {} error {:.3e}",
        iso.to_json(),
        iso.error
    );
    assert!(
        (iso.alpha_u - 0.3).abs() <= 0.015 && (iso.alpha_v - 0.3).abs() <= 0.015,
        "alpha_u {} alpha_v {}",
        iso.alpha_u,
        iso.alpha_v
    );
}

/// The fields of the small RGL file, in the writer's order, with `edit`
/// applied to the list (to replace, drop or add fields).
fn rgl_with(edit: impl FnOnce(&mut Vec<(&'static str, rgl::Field)>)) -> Vec<u8> {
    let fields = rgl::parse_tensor(&small_rgl_bytes()).unwrap();
    let mut list: Vec<(&'static str, rgl::Field)> = [
        "description",
        "jacobian",
        "theta_i",
        "phi_i",
        "ndf",
        "sigma",
        "vndf",
        "luminance",
        "rgb",
    ]
    .into_iter()
    .map(|n| (n, fields[n].clone()))
    .collect();
    edit(&mut list);
    rgl::write_tensor(&list)
}

fn field_f32(f: &rgl::Field) -> Vec<f32> {
    f.data
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// Pairs above the horizon at several views, off the tabulated ones.
fn rgl_pairs() -> Vec<(DVec3, DVec3)> {
    let mut v = Vec::new();
    for (to, po) in [(5.0, 0.0), (25.0, 40.0), (50.0, 200.0), (70.0, 300.0)] {
        for (ti, dp) in [(10.0, 180.0), (30.0, 150.0), (45.0, 200.0), (60.0, 90.0)] {
            v.push((dir_of(to, po), dir_of(ti, po + dp)));
        }
    }
    v
}

/// A spectral RGL file (`spectra` + `wavelengths` instead of `rgb`) is
/// reduced to RGB when read: a flat spectrum of value `s` is RGB `(s, s,
/// s)` (white balanced), so the file whose spectrum at every grid point is
/// the RGB file's green channel reads as that green channel in all three;
/// a spectrum that is zero below 600 nm reads as red.
#[test]
fn spectral_rgl_files_are_reduced_to_rgb() {
    let plain = Table::parse(&small_rgl_bytes(), "rgb").unwrap();
    let wavelengths: Vec<f32> = (0..48).map(|i| 360.0 + 10.0 * i as f32).collect();
    let spectral = |spectrum: &dyn Fn(f32, f32) -> f32| {
        rgl_with(|list| {
            let rgb = list.pop().unwrap().1;
            let (np, nt, n1, n2) = (rgb.shape[0], rgb.shape[1], rgb.shape[3], rgb.shape[4]);
            let values = field_f32(&rgb);
            let nl = wavelengths.len();
            let mut out = vec![0f32; np * nt * nl * n1 * n2];
            for slice in 0..np * nt {
                for (l, &lambda) in wavelengths.iter().enumerate() {
                    for k in 0..n1 * n2 {
                        let green = values[(slice * 3 + 1) * n1 * n2 + k];
                        out[(slice * nl + l) * n1 * n2 + k] = spectrum(lambda, green);
                    }
                }
            }
            list.push(("wavelengths", rgl::Field::f32(&[nl], &wavelengths)));
            list.push(("spectra", rgl::Field::f32(&[np, nt, nl, n1, n2], &out)));
        })
    };
    let flat = Table::parse(&spectral(&|_, g| g), "flat").unwrap();
    let red = Table::parse(&spectral(&|l, g| if l >= 600.0 { g } else { 0.0 }), "red").unwrap();
    let mut checked = 0;
    for (o, i) in rgl_pairs() {
        let want = plain.eval(o, i, merl::Interpolation::Nearest).y;
        if want <= 1e-6 {
            continue;
        }
        let got = flat.eval(o, i, merl::Interpolation::Nearest);
        for c in 0..3 {
            assert!(
                (got[c] - want).abs() <= 1e-5 * want,
                "channel {c}: {got} vs {want}"
            );
        }
        let r = red.eval(o, i, merl::Interpolation::Nearest);
        assert!(
            r.x > 0.3 * want && r.y < 0.5 * r.x && r.z < 0.1 * r.x,
            "{r} of {want}"
        );
        checked += 1;
    }
    assert!(checked >= 12, "{checked}");
    // A spectral file with `spectra` missing names the field.
    let e = parse_err(&rgl_with(|list| {
        list.pop();
        list.push(("wavelengths", rgl::Field::f32(&[2], &[500.0, 600.0])));
    }));
    assert!(e.contains("missing field `spectra`"), "{e}");
}

/// `jacobian = 1`: the file's value is multiplied by `ndf(u_m) / (4
/// sigma(u_wo))`, `u = (√(θ/(π/2)), (φ + π)/(2π))` (with `φm` relative to
/// `φo`), both tables bilinear over the unit square: here `ndf = 1 + 3 x`
/// and `sigma = 2 + y`, so the ratio to the `jacobian = 0` file is known.
#[test]
fn rgl_jacobian_scales_by_ndf_over_sigma() {
    let plain = Table::parse(&small_rgl_bytes(), "plain").unwrap();
    let scaled = Table::parse(
        &rgl_with(|list| {
            for (name, f) in list.iter_mut() {
                match *name {
                    "jacobian" => *f = rgl::Field::u8(&[1]),
                    "ndf" => *f = rgl::Field::f32(&[2, 2], &[1.0, 4.0, 1.0, 4.0]),
                    "sigma" => *f = rgl::Field::f32(&[2, 2], &[2.0, 2.0, 3.0, 3.0]),
                    _ => {}
                }
            }
        }),
        "jacobian",
    )
    .unwrap();
    let mut checked = 0;
    for (o, i) in rgl_pairs() {
        let a = plain.eval(o, i, merl::Interpolation::Nearest);
        if a.y <= 1e-6 {
            continue;
        }
        let b = scaled.eval(o, i, merl::Interpolation::Nearest);
        let m = (o + i).normalize();
        let u_m = (m.z.acos() / std::f64::consts::FRAC_PI_2).sqrt();
        let phi_o = o.y.atan2(o.x);
        let v_o = (phi_o + std::f64::consts::PI) / std::f64::consts::TAU;
        let want = (1.0 + 3.0 * u_m) / (4.0 * (2.0 + v_o));
        let ratio = b.y / a.y;
        assert!(
            (ratio - want).abs() <= 2e-5 * want,
            "wo {o} wi {i}: ratio {ratio} vs {want}"
        );
        checked += 1;
    }
    assert!(checked >= 12, "{checked}");
    // With the Jacobian, a sigma ≤ 0 is refused.
    let e = parse_err(&rgl_with(|list| {
        for (name, f) in list.iter_mut() {
            match *name {
                "jacobian" => *f = rgl::Field::u8(&[1]),
                "sigma" => *f = rgl::Field::f32(&[2, 2], &[1.0, 0.0, 1.0, 1.0]),
                _ => {}
            }
        }
    }));
    assert!(e.contains("`sigma` has a value ≤ 0"), "{e}");
}
