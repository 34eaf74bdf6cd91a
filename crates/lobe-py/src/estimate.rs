//! `lobe.estimate`: the table that `lobe estimate --json` prints, from the
//! same library call ([`lobe::experiment::estimate::estimate_table`], which
//! checks the settings as the CLI's), with the
//! CLI's light syntax ([`lobe_render::light_spec`]) and strategy names.

use glam::DVec3;
use lobe::estimator::ShadingPoint;
use lobe::experiment::estimate::{EstimateTableSettings, Setting, estimate_table};
use lobe::progress::SystemClock;
use lobe::{Frame, Light, Material};

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

/// A light in the CLI's syntax ([`lobe_render::light_spec`]): `constant[:VALUE]`,
/// `beam[:K[:X,Y,Z[:VALUE]]]` (world direction, taken to the local frame by
/// `frame`), `sky[:ELEVATION[:AZIMUTH]]`, or an environment map file.
pub fn parse_light(spec: &str, frame: &Frame) -> Result<Light, String> {
    lobe_render::light_spec::parse_light("light", spec, frame).map(|p| p.light)
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
    let settings = EstimateTableSettings {
        strategies: a.strategies.clone(),
        mis_bsdf: a.mis_bsdf.clone(),
        mis_samples: a.mis_samples,
        samples: a.samples,
        sequence: a.sequence.clone(),
        seed: a.seed,
        replicas: a.replicas,
    };
    let keyword = |s: Setting| match s {
        Setting::Strategies => "strategies",
        Setting::MisBsdf => "mis_bsdf",
        Setting::MisSamples => "mis_samples",
        Setting::Samples => "samples",
        Setting::Sequence => "sequence",
        Setting::Replicas => "replicas",
    };
    // The settings are checked before the light is parsed (a map may take
    // a while to load).
    let checked = settings.check(m).map_err(|e| e.named(keyword))?;
    let frame = Frame::from_normal_tangent(a.normal, a.tangent).ok_or_else(|| {
        format!(
            "tangent {} is parallel to normal {} (or one is zero)",
            a.tangent, a.normal
        )
    })?;
    let light = parse_light(&a.light, &frame)?;
    let sp = match light {
        Light::Env(_) => ShadingPoint { frame, wo },
        _ => ShadingPoint::local(wo),
    };
    let table = estimate_table(m, &sp, &light, &checked, &(), &SystemClock::new())
        .map_err(|e| e.named(keyword))?;
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
