//! The parameter grid shared by the statistical tests: every model and
//! strategy over exponents 1 to 10⁴, alphas 0.02 to 1, anisotropy and view
//! angles 0 to 89°.

use glam::DVec3;
use lobe::stats::chi2::{Chi2Settings, chi2_test, sidak};
use lobe::{BsdfStrategy, Material, MaterialDesc};

/// One material of the grid, with a name for messages and failure files.
pub struct Case {
    pub name: String,
    pub json: String,
    pub material: Material,
    /// Whether the chi-square grid tests the material-blind strategies
    /// (`uniform`, `cosine`) on this case ([`plan`]).
    pub blind: bool,
}

pub fn case(json: &str) -> Case {
    let material = MaterialDesc::from_json(json)
        .and_then(|d| d.build())
        .unwrap_or_else(|e| panic!("{json}: {e}"));
    let name = json
        .trim_matches(|c| c == '{' || c == '}')
        .replace(['"', ' '], "")
        .replace([':', ','], "_")
        .replace(['[', ']'], "");
    Case {
        name,
        json: json.to_string(),
        material,
        blind: true,
    }
}

/// `cases` with the material-blind strategies tested on the first only.
fn blind_on_first(mut cases: Vec<Case>) -> Vec<Case> {
    for c in cases.iter_mut().skip(1) {
        c.blind = false;
    }
    cases
}

/// View angles (degrees) of the grid.
pub const VIEWS: [f64; 5] = [0.0, 30.0, 60.0, 80.0, 89.0];

#[must_use]
pub fn wo(theta_deg: f64) -> DVec3 {
    // A small azimuth (0.3 rad) so that anisotropic lobes are not seen along an axis.
    lobe::frame::wo_from_theta(theta_deg, 0.3f64.to_degrees())
}

pub const EXPONENTS: [f64; 5] = [1.0, 10.0, 100.0, 1000.0, 10000.0];
pub const ALPHAS: [f64; 4] = [0.02, 0.1, 0.3, 1.0];

/// Lecture models (Phong, Blinn-Phong) over the exponents, both forms, and
/// with a diffuse term.
pub fn phong_family() -> Vec<Case> {
    let mut v = Vec::new();
    for model in ["phong", "blinn-phong"] {
        let mut m = Vec::new();
        for n in EXPONENTS {
            m.push(case(&format!(r#"{{"type":"{model}","exponent":{n}}}"#)));
        }
        m.push(case(&format!(
            r#"{{"type":"{model}","exponent":5,"normalized":false,"ks":0.5}}"#
        )));
        m.push(case(&format!(
            r#"{{"type":"{model}","exponent":40,"ks":0.6,"kd":0.3}}"#
        )));
        v.extend(blind_on_first(m));
    }
    v
}

/// Cook-Torrance over distributions, isotropic alphas and one anisotropic
/// pair, with one two-lobe material per distribution.
pub fn microfacet_family() -> Vec<Case> {
    let mut v = Vec::new();
    for d in ["ggx", "beckmann", "blinn-phong"] {
        let mut m = Vec::new();
        for a in ALPHAS {
            m.push(case(&format!(
                r#"{{"type":"cook-torrance","distribution":"{d}","alpha":{a}}}"#
            )));
        }
        m.push(case(&format!(
            r#"{{"type":"cook-torrance","distribution":"{d}","alpha_u":0.05,"alpha_v":0.5}}"#
        )));
        m.push(case(&format!(
            r#"{{"type":"cook-torrance","distribution":"{d}","alpha":0.2,"kd":0.4,"fresnel":{{"type":"schlick","f0":0.3}}}}"#
        )));
        v.extend(blind_on_first(m));
    }
    v
}

pub fn lambert_family() -> Vec<Case> {
    vec![case(r#"{"type":"lambert","albedo":0.7}"#)]
}

/// Every case of the grid.
pub fn all_cases() -> Vec<Case> {
    let mut v = lambert_family();
    v.extend(phong_family());
    v.extend(microfacet_family());
    v
}

/// The (strategy, view) pairs tested for a case: the material-blind
/// strategies `uniform` and `cosine` at two views, on the first case of
/// each model and distribution only (`Case::blind`: `Material::sample` draws
/// them by the same warp whatever the material's parameters, so the others
/// would repeat the same test), the others at every view.
pub fn plan(c: &Case) -> Vec<(BsdfStrategy, f64)> {
    let mut v = Vec::new();
    for s in c.material.strategies() {
        match s {
            BsdfStrategy::Uniform | BsdfStrategy::Cosine if !c.blind => {}
            BsdfStrategy::Uniform | BsdfStrategy::Cosine => v.extend([(s, 0.0), (s, 60.0)]),
            _ => v.extend(VIEWS.iter().map(|&t| (s, t))),
        }
    }
    v
}

/// Number of tests in the whole chi-square grid (for the Šidák correction).
pub fn grid_size() -> usize {
    all_cases().iter().map(|c| plan(c).len()).sum()
}

/// Write a failed chi-square test's observed and expected tables to
/// `target/tmp/chi2-failures/<label>.csv` and return the path.
pub fn write_failure(
    r: &lobe::stats::chi2::Chi2Result,
    cfg: &lobe::stats::chi2::Chi2Settings,
    label: &str,
) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("chi2-failures");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{label}.csv"));
    r.write_tables(cfg, &path).unwrap();
    path
}

/// Chi-square tests of `(material, strategy, θo)` (`θo` beyond 90°: seen
/// from inside, at a small azimuth): the density part of each sampler
/// against its pdf over the whole sphere, Šidák-corrected; `prefix` starts
/// the names of the failure files. Samples of a delta part
/// count as lost (the pdf leaves them out, so `1 − ∫pdf` is their share).
pub fn chi2_over_sphere(prefix: &str, cases: &[(&str, &[BsdfStrategy], &[f64])]) {
    use rayon::prelude::*;
    let jobs: Vec<(Material, &str, BsdfStrategy, f64)> = cases
        .iter()
        .flat_map(|&(json, strategies, views)| {
            let m = Material::load(json).unwrap_or_else(|e| panic!("{json}: {e}"));
            strategies
                .iter()
                .flat_map(move |&s| views.iter().map(move |&t| (s, t)))
                .map(move |(s, t)| (m.clone(), json, s, t))
        })
        .collect();
    let alpha = sidak(0.01, jobs.len());
    let cfg = Chi2Settings::default();
    let failures: Vec<String> = jobs
        .par_iter()
        .filter_map(|(m, json, s, theta)| {
            let sampler = m.sampler(*s).unwrap_or_else(|e| panic!("{json} {s}: {e}"));
            let wo = lobe::frame::wo_from_theta(*theta, 0.3f64.to_degrees());
            let r = chi2_test(
                &cfg,
                |uc, u| {
                    sampler
                        .sample(wo, uc, u)
                        .filter(|x| !x.scattering.is_specular())
                        .map(|x| x.wi)
                },
                |wi| sampler.pdf(wo, wi),
            );
            if r.passes(alpha) {
                return None;
            }
            let name: String = json
                .chars()
                .filter(|c| c.is_ascii_alphanumeric() || *c == '.' || *c == '_')
                .collect();
            let label = format!("{prefix}_{name}_{s}_theta{theta}");
            let path = write_failure(&r, &cfg, &label);
            Some(format!(
                "{json} {s} θ={theta}: χ²={:.1} dof={} p={:.3e} < {alpha:.2e} {} (tables: {})",
                r.statistic,
                r.dof,
                r.p_value,
                r.message.clone().unwrap_or_default(),
                path.display()
            ))
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
