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
//! "value": ...}`. `material` is `none` or one of Mitsuba's conductor
//! names (`Au`, `Ag`, `Cu`, `Al`, `Cr`, `W`, ... 34, and their `_palik` aliases: [`CONDUCTORS`]),
//! with the RGB `(eta, k)` that Mitsuba's RGB variants use (but `AlSb`,
//! whose RGB eta has a zero channel: an error says so). `sample_visible = true` is accepted (lobe's
//! strategy is an argument of each call: `vndf` samples visible normals);
//! `false` is refused with a hint. Any other key is an error naming it.

use serde_json::{Map, Value, json};

/// The conductors Mitsuba 3 names in `material` and their complex
/// refractive index `(eta, k)` in RGB: the values Mitsuba's RGB variants
/// use (its spectral data integrated to sRGB, read from Mitsuba 3.9.1's
/// `scalar_rgb` plugin with `mi.traverse`; `bench/mitsuba_conductors.py`
/// prints them), to 6 digits. Mitsuba's `_palik` names are the same data.
#[rustfmt::skip]
#[allow(clippy::unreadable_literal, clippy::excessive_precision)]
pub const CONDUCTORS: [(&str, [f64; 3], [f64; 3]); 65] = [
    ("a-C", [2.94405, 2.22714, 1.96816], [0.887465, 0.799299, 0.81529]),
    ("Ag", [0.155276, 0.116728, 0.138388], [4.82835, 3.12222, 2.1469]),
    ("Al", [1.6575, 0.880405, 0.521244], [9.22381, 6.2695, 4.837]),
    ("AlAs", [3.6053, 3.23294, 2.21632], [0.000679437, 0.0, 0.00751271]),
    ("AlAs_palik", [3.6053, 3.23294, 2.21632], [0.000679437, 0.0, 0.00751271]),
    ("AlSb", [0.0, 4.13937, 4.66925], [0.0, 0.0940091, 1.30057]),
    ("AlSb_palik", [0.0, 4.13937, 4.66925], [0.0, 0.0940091, 1.30057]),
    ("Au", [0.143036, 0.375307, 1.44205], [3.983, 2.38556, 1.60336]),
    ("Be", [4.18501, 3.18503, 2.78406], [3.83547, 3.01012, 2.86899]),
    ("Be_palik", [4.18501, 3.18503, 2.78406], [3.83547, 3.01012, 2.86899]),
    ("Cr", [4.36967, 2.91651, 1.6549], [5.20655, 4.23131, 3.7547]),
    ("CsI", [2.1449, 1.70232, 1.66243], [0.0, 0.0, 0.0]),
    ("CsI_palik", [2.1449, 1.70232, 1.66243], [0.0, 0.0, 0.0]),
    ("Cu", [0.201005, 0.92375, 1.10222], [3.91326, 2.45305, 2.14209]),
    ("Cu_palik", [0.213229, 0.919715, 1.10241], [3.92187, 2.45733, 2.13658]),
    ("Cu2O", [3.55177, 2.94987, 2.75188], [0.114207, 0.193897, 0.606134]),
    ("Cu2O_palik", [3.55177, 2.94987, 2.75188], [0.114207, 0.193897, 0.606134]),
    ("CuO", [3.24754, 2.44781, 2.21022], [0.52109, 0.570031, 0.722179]),
    ("CuO_palik", [3.24754, 2.44781, 2.21022], [0.52109, 0.570031, 0.722179]),
    ("d-C", [2.70872, 2.31883, 2.2289], [0.0, 0.0, 0.0]),
    ("d-C_palik", [2.70872, 2.31883, 2.2289], [0.0, 0.0, 0.0]),
    ("Hg", [2.39894, 1.44003, 0.90957], [6.32759, 4.37192, 3.42176]),
    ("Hg_palik", [2.39894, 1.44003, 0.90957], [6.32759, 4.37192, 3.42176]),
    ("HgTe", [4.77904, 3.2312, 2.6599], [1.63161, 1.58081, 1.72929]),
    ("HgTe_palik", [4.77904, 3.2312, 2.6599], [1.63161, 1.58081, 1.72929]),
    ("Ir", [3.0863, 2.08219, 1.61791], [5.59215, 4.06709, 3.26731]),
    ("Ir_palik", [3.0863, 2.08219, 1.61791], [5.59215, 4.06709, 3.26731]),
    ("K", [0.0640432, 0.0464098, 0.0381849], [2.1042, 1.34894, 0.913126]),
    ("K_palik", [0.0640432, 0.0464098, 0.0381849], [2.1042, 1.34894, 0.913126]),
    ("Li", [0.265791, 0.195618, 0.220949], [3.54015, 2.31112, 1.66861]),
    ("Li_palik", [0.265791, 0.195618, 0.220949], [3.54015, 2.31112, 1.66861]),
    ("MgO", [2.08958, 1.65072, 1.59488], [4.3327e-12, 0.0, 2.49865e-11]),
    ("MgO_palik", [2.08958, 1.65072, 1.59488], [4.3327e-12, 0.0, 2.49865e-11]),
    ("Mo", [4.48397, 3.52513, 2.77631], [4.11144, 3.42083, 3.15061]),
    ("Mo_palik", [4.48397, 3.52513, 2.77631], [4.11144, 3.42083, 3.15061]),
    ("Na_palik", [0.0602694, 0.0561409, 0.0619884], [3.17927, 2.11249, 1.57904]),
    ("Nb", [3.42007, 2.79009, 2.39563], [3.44139, 2.73767, 2.57975]),
    ("Nb_palik", [3.42007, 2.79009, 2.39563], [3.44139, 2.73767, 2.57975]),
    ("Ni_palik", [2.3673, 1.66337, 1.46708], [4.49881, 3.05015, 2.34544]),
    ("Rh", [2.58579, 1.86022, 1.55426], [6.78226, 4.70299, 3.97607]),
    ("Rh_palik", [2.58579, 1.86022, 1.55426], [6.78226, 4.70299, 3.97607]),
    ("Se", [4.05831, 2.84294, 2.82085], [0.75405, 0.638444, 0.521808]),
    ("Se_palik", [4.05831, 2.84294, 2.82085], [0.75405, 0.638444, 0.521808]),
    ("SiC", [3.17234, 2.52597, 2.47937], [7.53766e-07, 0.0, 1.01925e-05]),
    ("SiC_palik", [3.17234, 2.52597, 2.47937], [7.53766e-07, 0.0, 1.01925e-05]),
    ("SnTe", [4.52425, 1.98164, 1.28159], [0.0, 0.0, 0.0]),
    ("SnTe_palik", [4.52425, 1.98164, 1.28159], [0.0, 0.0, 0.0]),
    ("Ta", [2.06272, 2.39294, 2.62793], [2.40836, 1.74149, 1.94703]),
    ("Ta_palik", [2.06272, 2.39294, 2.62793], [2.40836, 1.74149, 1.94703]),
    ("Te", [7.39023, 4.4821, 2.63711], [3.25602, 3.52706, 3.29205]),
    ("Te_palik", [7.39023, 4.4821, 2.63711], [3.25602, 3.52706, 3.29205]),
    ("ThF4", [1.83071, 1.44223, 1.38765], [0.0, 0.0, 0.0]),
    ("ThF4_palik", [1.83071, 1.44223, 1.38765], [0.0, 0.0, 0.0]),
    ("TiC", [3.70053, 2.83742, 2.58229], [3.26564, 2.35159, 2.17279]),
    ("TiC_palik", [3.70053, 2.83742, 2.58229], [3.26564, 2.35159, 2.17279]),
    ("TiN", [1.64845, 1.15052, 1.37982], [3.36833, 1.9435, 1.10207]),
    ("TiN_palik", [1.64845, 1.15052, 1.37982], [3.36833, 1.9435, 1.10207]),
    ("TiO2", [3.45661, 2.80174, 2.90517], [0.000105265, 0.0, 0.000652887]),
    ("TiO2_palik", [3.45661, 2.80174, 2.90517], [0.000105265, 0.0, 0.000652887]),
    ("VC", [3.65757, 2.75274, 2.53267], [3.0683, 2.19869, 1.96319]),
    ("VC_palik", [3.65757, 2.75274, 2.53267], [3.0683, 2.19869, 1.96319]),
    ("V_palik", [4.27758, 3.51295, 2.76107], [3.4913, 2.88945, 3.11152]),
    ("VN", [2.8656, 2.11919, 1.94009], [3.03224, 2.05612, 1.61631]),
    ("VN_palik", [2.8656, 2.11919, 1.94009], [3.03224, 2.05612, 1.61631]),
    ("W", [4.37082, 3.30025, 2.99841], [3.50064, 2.60487, 2.27323]),
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
                        if eta.iter().any(|&e| e <= 0.0) {
                            return Err(err(
                                kind,
                                "material",
                                format!(
                                    "`{name}`: Mitsuba's RGB eta {eta:?} has a zero channel (its spectrum clamped out of gamut), which lobe's conductor Fresnel term does not take; give eta and k"
                                ),
                            ));
                        }
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
    fn every_named_conductor_loads_and_evaluates() {
        let wo = glam::DVec3::new(0.6, 0.0, 0.8);
        for (name, eta, _) in CONDUCTORS {
            if name.starts_with("AlSb") {
                let e = load(json!({"type": "roughconductor", "material": name})).unwrap_err();
                assert!(
                    e.contains("field `material`") && e.contains("zero channel"),
                    "{e}"
                );
                continue;
            }
            let m = load(json!({"type": "roughconductor", "material": name, "alpha": 0.3}))
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let lobe::Glossy::CookTorrance(c) = m.glossy else {
                panic!()
            };
            assert!(
                matches!(c.fresnel, lobe::Fresnel::Conductor { eta: e, .. } if e == lobe::Rgb::from_array(eta)),
                "{name}"
            );
            let f = m.eval(wo, glam::DVec3::new(-0.6, 0.0, 0.8));
            assert!(
                f.to_array().iter().all(|x| x.is_finite() && *x >= 0.0),
                "{name}: {f:?}"
            );
        }
        assert_eq!(
            CONDUCTORS
                .iter()
                .filter(|c| !c.0.ends_with("_palik"))
                .count(),
            34
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
