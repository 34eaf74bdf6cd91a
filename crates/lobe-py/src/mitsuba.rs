//! Mitsuba 3 plugin names in `lobe.load_dict`, translated to lobe's own
//! material description (the keys of `--material`), which lobe's parser
//! then checks with its usual messages.
//!
//! | Mitsuba | lobe |
//! |---|---|
//! | `diffuse`: `reflectance` (0.5) | `lambert`, `albedo` |
//! | `roughconductor`: `distribution` (`beckmann`), `alpha` (0.1) or `alpha_u`/`alpha_v`, `material` (`none`) or `eta`/`k`, `specular_reflectance` (1) | `cook-torrance`, the same NDF and alpha, `shadowing = smith-separable` (Mitsuba's `G1(wi)·G1(wo)`), `ks`, `fresnel = conductor` (or `none` for `material = none`) |
//! | `roughplastic`: `distribution` (`beckmann`), `alpha` (0.1), `int_ior` (1.49), `ext_ior` (1.000277), each a number or a name of [`IORS`] (`bk7`, `water`, `air`, ...), `specular_reflectance` (1), `diffuse_reflectance` (0.5) | `cook-torrance` with `fresnel = dielectric`, `eta = int_ior/ext_ior`, `ks`, `kd`, `smith-separable`: the same specular lobe; the diffuse term is lobe's `kd/π`, **without** Mitsuba's Fresnel weighting and internal scattering, so the diffuse part differs |
//!
//! A colour is a number, `[r, g, b]`, or Mitsuba's `{"type": "rgb",
//! "value": ...}`. `material` names one of `none`, `Au`, `Ag`, `Cu`, `Al`
//! (RGB fits of their complex indices; Mitsuba integrates spectra, so
//! these are approximations). `sample_visible = true` is accepted (lobe's
//! strategy is an argument of each call: `vndf` samples visible normals);
//! `false` is refused with a hint. Any other key is an error naming it.

use serde_json::{Map, Value, json};

/// RGB fits of conductors' complex refractive index `(eta, k)`.
pub const CONDUCTORS: [(&str, [f64; 3], [f64; 3]); 4] = [
    ("Au", [0.143, 0.374, 1.442], [3.983, 2.385, 1.603]),
    ("Ag", [0.155, 0.117, 0.138], [4.828, 3.122, 2.147]),
    ("Cu", [0.200, 0.924, 1.102], [3.912, 2.452, 2.142]),
    ("Al", [1.657, 0.880, 0.521], [9.224, 6.270, 4.837]),
];

/// Named refractive indices that Mitsuba accepts for `int_ior`/`ext_ior`:
/// the published values (Hecht, *Optics*, 4th ed.; near 589 nm, 0–20 °C).
pub const IORS: [(&str, f64); 23] = [
    ("vacuum", 1.0),
    ("helium", 1.000_036),
    ("hydrogen", 1.000_132),
    ("air", 1.000_277),
    ("carbon dioxide", 1.000_45),
    ("water", 1.333),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.520_45),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.47),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.575),
    ("diamond", 2.419),
];

/// An index of refraction: a number, or a name of [`IORS`] (any case).
fn ior(plugin: &str, field: &str, v: &Value) -> Result<f64, String> {
    if let Value::String(name) = v {
        return IORS
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|&(_, x)| x)
            .ok_or_else(|| {
                let names: Vec<&str> = IORS.iter().map(|(n, _)| *n).collect();
                err(
                    plugin,
                    field,
                    format!(
                        "unknown index of refraction `{name}`: a number, or one of {}",
                        names.join(", ")
                    ),
                )
            });
    }
    number(plugin, field, v)
}

/// The Mitsuba plugin names that [`translate`] handles.
pub const PLUGINS: [&str; 3] = ["diffuse", "roughconductor", "roughplastic"];

fn err(plugin: &str, field: &str, message: impl std::fmt::Display) -> String {
    format!("material: field `{field}`: {message} (Mitsuba's `{plugin}`)")
}

/// A Mitsuba colour: a number, `[r, g, b]`, or `{"type": "rgb", "value": ...}`.
fn colour(plugin: &str, field: &str, v: &Value) -> Result<Value, String> {
    match v {
        Value::Number(_) => Ok(v.clone()),
        Value::Array(a) if a.len() == 3 && a.iter().all(Value::is_number) => Ok(v.clone()),
        Value::Object(o) => {
            let kind = o.get("type").and_then(Value::as_str);
            match (kind, o.get("value")) {
                (Some("rgb" | "spectrum"), Some(inner)) if o.len() == 2 => {
                    colour(plugin, field, inner)
                }
                _ => Err(err(
                    plugin,
                    field,
                    "expected a number, [r, g, b] or {\"type\": \"rgb\", \"value\": [r, g, b]}",
                )),
            }
        }
        _ => Err(err(
            plugin,
            field,
            format!("{v} is not a number or an [r, g, b] array"),
        )),
    }
}

fn number(plugin: &str, field: &str, v: &Value) -> Result<f64, String> {
    v.as_f64()
        .ok_or_else(|| err(plugin, field, format!("{v} is not a number")))
}

fn distribution(plugin: &str, o: &Map<String, Value>) -> Result<Value, String> {
    match o.get("distribution") {
        None => Ok(json!("beckmann")),
        Some(Value::String(s)) if s == "ggx" || s == "beckmann" => Ok(json!(s)),
        Some(v) => Err(err(
            plugin,
            "distribution",
            format!("unknown value {v}, expected one of: beckmann, ggx"),
        )),
    }
}

fn check_keys(plugin: &str, o: &Map<String, Value>, known: &[&str]) -> Result<(), String> {
    for k in o.keys() {
        if k != "type" && !known.contains(&k.as_str()) {
            return Err(err(
                plugin,
                k,
                format!("unknown parameter, expected one of: {}", known.join(", ")),
            ));
        }
    }
    Ok(())
}

fn sample_visible(plugin: &str, o: &Map<String, Value>) -> Result<(), String> {
    match o.get("sample_visible") {
        None | Some(Value::Bool(true)) => Ok(()),
        Some(Value::Bool(false)) => Err(err(
            plugin,
            "sample_visible",
            "false is not a material parameter in lobe: pass strategy=\"brdf\" to sample, pdf and eval_pdf instead",
        )),
        Some(v) => Err(err(
            plugin,
            "sample_visible",
            format!("{v} is not true or false"),
        )),
    }
}

/// lobe's description of a Mitsuba dict, or the dict itself when its
/// `type` is not one of [`PLUGINS`]. Errors start with `material: field`
/// and name the Mitsuba key.
pub fn translate(v: Value) -> Result<Value, String> {
    let Value::Object(o) = &v else {
        return Ok(v);
    };
    let Some(kind) = o.get("type").and_then(Value::as_str) else {
        return Ok(v);
    };
    match kind {
        "diffuse" => {
            check_keys(kind, o, &["reflectance"])?;
            let albedo = match o.get("reflectance") {
                Some(c) => colour(kind, "reflectance", c)?,
                None => json!(0.5),
            };
            Ok(json!({"type": "lambert", "albedo": albedo}))
        }
        "roughconductor" => {
            check_keys(
                kind,
                o,
                &[
                    "distribution",
                    "alpha",
                    "alpha_u",
                    "alpha_v",
                    "material",
                    "eta",
                    "k",
                    "specular_reflectance",
                    "sample_visible",
                ],
            )?;
            sample_visible(kind, o)?;
            let mut out = Map::new();
            out.insert("type".into(), json!("cook-torrance"));
            out.insert("distribution".into(), distribution(kind, o)?);
            alpha(kind, o, &mut out, true)?;
            out.insert("shadowing".into(), json!("smith-separable"));
            if let Some(c) = o.get("specular_reflectance") {
                out.insert("ks".into(), colour(kind, "specular_reflectance", c)?);
            } else {
                out.insert("ks".into(), json!(1.0));
            }
            let fresnel = match (o.get("material"), o.get("eta"), o.get("k")) {
                (Some(_), Some(_), _) | (Some(_), _, Some(_)) => {
                    return Err(err(
                        kind,
                        "material",
                        "give either material or eta and k, not both",
                    ));
                }
                (None, None, None) => json!({"type": "none"}),
                (Some(Value::String(name)), None, None) => {
                    if name == "none" {
                        json!({"type": "none"})
                    } else if let Some((_, eta, k)) = CONDUCTORS.iter().find(|c| c.0 == name) {
                        json!({"type": "conductor", "eta": eta, "k": k})
                    } else {
                        return Err(err(
                            kind,
                            "material",
                            format!(
                                "unknown conductor `{name}`, expected one of: none, {}; or give eta and k",
                                CONDUCTORS.map(|c| c.0).join(", ")
                            ),
                        ));
                    }
                }
                (Some(m), None, None) => {
                    return Err(err(kind, "material", format!("{m} is not a name")));
                }
                (None, eta, k) => {
                    let (Some(eta), Some(k)) = (eta, k) else {
                        let missing = if eta.is_none() { "eta" } else { "k" };
                        return Err(err(
                            kind,
                            missing,
                            "eta and k go together (a conductor's complex index)",
                        ));
                    };
                    json!({"type": "conductor", "eta": colour(kind, "eta", eta)?, "k": colour(kind, "k", k)?})
                }
            };
            out.insert("fresnel".into(), fresnel);
            Ok(Value::Object(out))
        }
        "roughplastic" => {
            check_keys(
                kind,
                o,
                &[
                    "distribution",
                    "alpha",
                    "int_ior",
                    "ext_ior",
                    "specular_reflectance",
                    "diffuse_reflectance",
                    "nonlinear",
                    "sample_visible",
                ],
            )?;
            sample_visible(kind, o)?;
            match o.get("nonlinear") {
                None | Some(Value::Bool(false)) => {}
                Some(v) => {
                    return Err(err(
                        kind,
                        "nonlinear",
                        format!("{v}: lobe has only the linear (default) form"),
                    ));
                }
            }
            let int_ior = o
                .get("int_ior")
                .map_or(Ok(1.49), |v| ior(kind, "int_ior", v))?;
            let ext_ior = o
                .get("ext_ior")
                .map_or(Ok(1.000_277), |v| ior(kind, "ext_ior", v))?;
            if !(int_ior > 0.0 && ext_ior > 0.0 && int_ior.is_finite() && ext_ior.is_finite()) {
                return Err(err(
                    kind,
                    "int_ior",
                    "int_ior and ext_ior must be finite numbers > 0",
                ));
            }
            let mut out = Map::new();
            out.insert("type".into(), json!("cook-torrance"));
            out.insert("distribution".into(), distribution(kind, o)?);
            alpha(kind, o, &mut out, false)?;
            out.insert("shadowing".into(), json!("smith-separable"));
            let ks = o
                .get("specular_reflectance")
                .map_or(Ok(json!(1.0)), |c| colour(kind, "specular_reflectance", c))?;
            let kd = o
                .get("diffuse_reflectance")
                .map_or(Ok(json!(0.5)), |c| colour(kind, "diffuse_reflectance", c))?;
            out.insert("ks".into(), ks);
            out.insert("kd".into(), kd);
            out.insert(
                "fresnel".into(),
                json!({"type": "dielectric", "eta": int_ior / ext_ior}),
            );
            Ok(Value::Object(out))
        }
        _ => Ok(v),
    }
}

fn alpha(
    plugin: &str,
    o: &Map<String, Value>,
    out: &mut Map<String, Value>,
    anisotropic: bool,
) -> Result<(), String> {
    let (a, au, av) = (o.get("alpha"), o.get("alpha_u"), o.get("alpha_v"));
    if a.is_some() && (au.is_some() || av.is_some()) {
        return Err(err(
            plugin,
            "alpha",
            "give either alpha or alpha_u and alpha_v, not both",
        ));
    }
    if anisotropic && (au.is_some() || av.is_some()) {
        let (Some(u), Some(v)) = (au, av) else {
            let missing = if au.is_none() { "alpha_u" } else { "alpha_v" };
            return Err(err(plugin, missing, "alpha_u and alpha_v go together"));
        };
        out.insert("alpha_u".into(), json!(number(plugin, "alpha_u", u)?));
        out.insert("alpha_v".into(), json!(number(plugin, "alpha_v", v)?));
        return Ok(());
    }
    let a = a.map_or(Ok(0.1), |v| number(plugin, "alpha", v))?;
    out.insert("alpha".into(), json!(a));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(v: Value) -> Result<lobe::Material, String> {
        let t = translate(v)?;
        lobe::Material::load(&t.to_string()).map_err(|e| e.to_string())
    }

    #[test]
    fn plugins_become_lobe_materials() {
        let m = load(
            json!({"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.2, 0.4, 0.6]}}),
        )
        .unwrap();
        assert_eq!(m.diffuse.albedo, lobe::Rgb::new(0.2, 0.4, 0.6));
        let m =
            load(json!({"type": "roughconductor", "distribution": "ggx", "alpha": 0.2})).unwrap();
        let lobe::Glossy::CookTorrance(c) = m.glossy else {
            panic!()
        };
        assert_eq!(c.microfacet.alpha(), (0.2, 0.2));
        assert_eq!(c.microfacet.ndf(), lobe::Ndf::Ggx);
        assert_eq!(c.shadowing, lobe::Shadowing::SmithSeparable);
        assert_eq!(c.fresnel, lobe::Fresnel::None);
        let m = load(
            json!({"type": "roughconductor", "material": "Cu", "alpha_u": 0.1, "alpha_v": 0.3}),
        )
        .unwrap();
        let lobe::Glossy::CookTorrance(c) = m.glossy else {
            panic!()
        };
        assert_eq!(c.microfacet.ndf(), lobe::Ndf::Beckmann);
        assert_eq!(c.microfacet.alpha(), (0.1, 0.3));
        assert!(matches!(c.fresnel, lobe::Fresnel::Conductor { .. }));
        let m = load(json!({"type": "roughplastic", "distribution": "ggx", "int_ior": 1.5, "ext_ior": 1.0, "diffuse_reflectance": 0.3})).unwrap();
        assert_eq!(m.diffuse.albedo, lobe::Rgb::splat(0.3));
        let lobe::Glossy::CookTorrance(c) = m.glossy else {
            panic!()
        };
        assert_eq!(
            c.fresnel,
            lobe::Fresnel::Dielectric {
                eta: lobe::Rgb::splat(1.5)
            }
        );
    }

    #[test]
    fn named_indices_of_refraction() {
        let m =
            load(json!({"type": "roughplastic", "int_ior": "BK7", "ext_ior": "water"})).unwrap();
        let lobe::Glossy::CookTorrance(c) = m.glossy else {
            panic!()
        };
        assert_eq!(
            c.fresnel,
            lobe::Fresnel::Dielectric {
                eta: lobe::Rgb::splat(1.5046 / 1.333)
            }
        );
        let e = load(json!({"type": "roughplastic", "int_ior": "glass"})).unwrap_err();
        assert!(
            e.contains("field `int_ior`: unknown index of refraction `glass`") && e.contains("bk7"),
            "{e}"
        );
    }

    #[test]
    fn bad_keys_are_named() {
        let e = load(json!({"type": "roughconductor", "alpha": 0.1, "alpah_u": 2})).unwrap_err();
        assert!(
            e.starts_with("material: field `alpah_u`: unknown parameter"),
            "{e}"
        );
        let e = load(json!({"type": "roughconductor", "material": "Xx"})).unwrap_err();
        assert!(e.contains("`material`: unknown conductor `Xx`"), "{e}");
        let e = load(json!({"type": "roughconductor", "alpha": -1})).unwrap_err();
        assert!(e.starts_with("material: field `alpha`"), "{e}");
        let e = load(json!({"type": "roughconductor", "eta": 1.0})).unwrap_err();
        assert!(e.contains("field `k`"), "{e}");
        let e = load(json!({"type": "roughplastic", "nonlinear": true})).unwrap_err();
        assert!(e.contains("field `nonlinear`"), "{e}");
        let e = load(json!({"type": "diffuse", "reflectance": "red"})).unwrap_err();
        assert!(e.contains("field `reflectance`"), "{e}");
    }
}
