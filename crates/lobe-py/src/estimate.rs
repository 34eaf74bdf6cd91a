//! `lobe.estimate`: the table that `lobe estimate --json` prints, from the
//! same library call ([`lobe::experiment::table::run_table_with`]), with the
//! CLI's light and strategy syntax (re-stated here: the CLI's parsers live
//! in the binary crate, which a library cannot depend on).

use glam::DVec3;
use lobe::estimator::{ShadingPoint, Strategy};
use lobe::experiment::table::{TableOptions, TableSettings, run_table_with};
use lobe::progress::SystemClock;
use lobe::sequence::Sequence;
use lobe::{BsdfStrategy, Frame, Light, Material, Rgb};

/// The settings of one call, as `lobe estimate`'s flags.
#[derive(Debug, Clone)]
pub struct EstimateArgs {
    /// The view direction (normalized), or `None` for `theta`.
    pub wo: Option<DVec3>,
    /// The view angle in degrees, `wo = (sin θ, 0, cos θ)` (default 30).
    pub theta: Option<f64>,
    pub light: String,
    pub normal: DVec3,
    pub tangent: DVec3,
    /// `all` or names.
    pub strategies: Vec<String>,
    pub samples: usize,
    pub sequence: String,
    pub seed: u64,
    pub replicas: usize,
    pub mis_bsdf: Option<String>,
    pub mis_samples: (u32, u32),
}

fn is_envmap_path(spec: &str) -> bool {
    std::path::Path::new(spec)
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| ["hdr", "pic", "exr"].contains(&e.to_ascii_lowercase().as_str()))
}

fn vec3(what: &str, spec: &str, s: &str) -> Result<DVec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!(
            "light {spec}: {what}: expected three numbers x,y,z"
        ));
    }
    let mut v = [0.0; 3];
    for (slot, p) in v.iter_mut().zip(&parts) {
        *slot = p
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("light {spec}: {what}: `{p}` is not a finite number"))?;
    }
    let v = DVec3::from_array(v);
    if v.length_squared() == 0.0 {
        return Err(format!(
            "light {spec}: {what}: the zero vector has no direction"
        ));
    }
    Ok(v)
}

/// A light in the CLI's syntax: `constant[:VALUE]`, `beam[:K[:X,Y,Z[:VALUE]]]`
/// (world direction, taken to the local frame by `frame`), `sky[:ELEVATION[:AZIMUTH]]`,
/// or an environment map file (`.hdr`, `.exr`).
pub fn parse_light(spec: &str, frame: &Frame) -> Result<Light, String> {
    let mut parts = spec.split(':');
    let kind = parts.next().unwrap_or_default();
    let number = |what: &str, s: &str| -> Result<f64, String> {
        let v: f64 = s
            .parse()
            .map_err(|_| format!("light {spec}: {what} `{s}` is not a number"))?;
        if !v.is_finite() || v < 0.0 {
            return Err(format!("light {spec}: {what} must be a finite number >= 0"));
        }
        Ok(v)
    };
    match kind {
        "constant" => {
            let v = parts.next().map_or(Ok(1.0), |s| number("value", s))?;
            if parts.next().is_some() {
                return Err(format!("light {spec}: expected constant[:VALUE]"));
            }
            Ok(Light::Constant(Rgb::splat(v)))
        }
        "beam" => {
            let k = parts.next().map_or(Ok(8.0), |s| number("exponent K", s))?;
            let d = parts.next().map_or(Ok(DVec3::new(0.0, 1.0, 0.5)), |s| {
                vec3("direction", spec, s)
            })?;
            let v = parts.next().map_or(Ok(1.0), |s| number("value", s))?;
            if parts.next().is_some() {
                return Err(format!("light {spec}: expected beam[:K[:X,Y,Z[:VALUE]]]"));
            }
            Ok(Light::Beam {
                dir: frame.to_local(d.normalize()),
                exponent: k,
                radiance: Rgb::splat(v),
            })
        }
        "sky" if spec != "sky" => {
            let (w, h, default_elevation, default_azimuth) = lobe_render::envmap_io::SKY;
            let elevation = parts
                .next()
                .map_or(Ok(default_elevation), |s| number("sun elevation", s))?;
            let azimuth = match parts.next() {
                None => default_azimuth,
                Some(s) => s
                    .parse::<f64>()
                    .ok()
                    .filter(|a| a.is_finite())
                    .ok_or_else(|| {
                        format!("light {spec}: sun azimuth `{s}` is not a finite number of degrees")
                    })?,
            };
            if parts.next().is_some() || elevation > 90.0 {
                return Err(format!(
                    "light {spec}: expected sky[:ELEVATION[:AZIMUTH]], the sun's elevation in [0, 90] degrees and its azimuth in degrees"
                ));
            }
            Ok(Light::Env(std::sync::Arc::new(lobe::envmap::EnvMap::sky(
                w, h, elevation, azimuth,
            ))))
        }
        _ if spec == "sky" || is_envmap_path(spec) => {
            let loaded = lobe_render::load_envmap_checked(std::path::Path::new(spec), 1.0, 0.0)
                .map_err(|e| format!("light {spec}: {e}"))?;
            Ok(Light::Env(std::sync::Arc::new(loaded.map)))
        }
        _ => Err(format!(
            "light {spec}: unknown light `{kind}`, expected constant[:VALUE], beam[:K[:X,Y,Z[:VALUE]]], sky[:ELEVATION[:AZIMUTH]], or an environment map FILE.hdr / FILE.exr"
        )),
    }
}

/// The techniques: `all` ([`lobe::strategy::ALL_MEANS`]) or names, each
/// checked against the material ([`Strategy::parse_list`]).
pub fn parse_strategies(
    names: &[String],
    m: &Material,
    mis_bsdf: BsdfStrategy,
    (n_bsdf, n_light): (u32, u32),
) -> Result<Vec<Strategy>, String> {
    let v = Strategy::parse_list(
        names.iter().map(String::as_str),
        m,
        mis_bsdf,
        n_bsdf,
        n_light,
    )
    .map_err(|e| format!("strategies: {e}"))?;
    if v.is_empty() {
        return Err("strategies: the list is empty".into());
    }
    Ok(v)
}

/// Runs the table and returns it as the JSON text `lobe estimate --json`
/// prints.
pub fn estimate_json(m: &Material, a: &EstimateArgs) -> Result<String, String> {
    let wo = match (a.wo, a.theta) {
        (Some(_), Some(_)) => return Err("give wo or theta, not both".into()),
        (Some(w), None) => {
            if !(w.is_finite() && w.z > 0.0) {
                return Err(format!(
                    "wo {w}: the view direction must be finite and above the horizon (z > 0 in the local frame)"
                ));
            }
            w.normalize()
        }
        (None, t) => {
            // As the CLI's --theta.
            let t = t.unwrap_or(30.0);
            if !t.is_finite() || !(0.0..90.0).contains(&t) {
                return Err(format!(
                    "theta {t}: the view angle must be in [0, 90) degrees"
                ));
            }
            let r = t.to_radians();
            DVec3::new(r.sin(), 0.0, r.cos())
        }
    };
    if a.samples < 2 {
        return Err(format!(
            "samples {}: an estimate with a variance needs at least 2 samples",
            a.samples
        ));
    }
    let frame = Frame::from_normal_tangent(a.normal, a.tangent).ok_or_else(|| {
        format!(
            "tangent {} is parallel to normal {} (or one is zero)",
            a.tangent, a.normal
        )
    })?;
    let light = parse_light(&a.light, &frame)?;
    let mis_bsdf = match &a.mis_bsdf {
        Some(name) => {
            let s: BsdfStrategy = name.parse().map_err(|e| format!("mis_bsdf: {e}"))?;
            m.check(s).map_err(|e| format!("mis_bsdf: {e}"))?;
            s
        }
        None => m.best_bsdf_strategy(),
    };
    let (b, l) = a.mis_samples;
    if !(1..=64).contains(&b) || !(1..=64).contains(&l) {
        return Err(format!(
            "mis_samples ({b}, {l}): expected two counts, each 1 to 64"
        ));
    }
    let strategies = parse_strategies(&a.strategies, m, mis_bsdf, a.mis_samples)?;
    let sequence: Sequence = a.sequence.parse().map_err(|_| {
        format!(
            "sequence: unknown sequence `{}`, expected independent, stratified or sobol",
            a.sequence
        )
    })?;
    let sp = match light {
        Light::Env(_) => ShadingPoint { frame, wo },
        _ => ShadingPoint::local(wo),
    };
    let table = run_table_with(
        m,
        &sp,
        &light,
        &strategies,
        TableOptions {
            settings: TableSettings {
                sequence,
                samples: a.samples,
                seed: a.seed,
            },
            replicas: a.replicas,
        },
        &(),
        &SystemClock::new(),
    )
    .map_err(|e| e.to_string())?;
    for row in &table.strategies {
        if !row.mean.iter().chain(&row.stderr).all(|v| v.is_finite()) || !row.variance.is_finite() {
            return Err(format!(
                "strategy {}: the estimate is not a finite number (mean {:?}, variance {})",
                row.name, row.mean, row.variance
            ));
        }
    }
    serde_json::to_string(&table).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_of_the_cli() {
        let m = Material::load(r#"{"type":"phong","exponent":20}"#).unwrap();
        let a = EstimateArgs {
            wo: None,
            theta: Some(30.0),
            light: "beam:16:1,1,0".into(),
            normal: DVec3::Y,
            tangent: DVec3::X,
            strategies: vec!["brdf".into(), "mis".into()],
            samples: 1000,
            sequence: "independent".into(),
            seed: 1,
            replicas: 16,
            mis_bsdf: None,
            mis_samples: (1, 1),
        };
        let j: serde_json::Value = serde_json::from_str(&estimate_json(&m, &a).unwrap()).unwrap();
        let rows = j["strategies"].as_array().unwrap();
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[0]["name"], "brdf");
        assert!(rows[0]["mean"][0].as_f64().unwrap() > 0.0);
        let e = estimate_json(
            &m,
            &EstimateArgs {
                strategies: vec!["vndf".into()],
                ..a.clone()
            },
        )
        .unwrap_err();
        assert!(
            e.starts_with("strategies: strategy `vndf` does not apply"),
            "{e}"
        );
        let e = estimate_json(
            &m,
            &EstimateArgs {
                light: "lamp".into(),
                ..a
            },
        )
        .unwrap_err();
        assert!(e.contains("unknown light `lamp`"), "{e}");
    }
}
