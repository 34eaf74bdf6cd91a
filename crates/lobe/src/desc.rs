//! Material descriptions: what a user writes in JSON or TOML, checked by
//! each model's own file ([`crate::models`]: its keys, ranges and defaults,
//! listed by [`crate::models::defaults`]), with errors that name the field.

use crate::Error;
use crate::fresnel::Fresnel;
use crate::math::Rgb;
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};

pub const DEFAULT_F0: f64 = 0.04;
pub const DEFAULT_DIELECTRIC_ETA: f64 = 1.5;
pub const DEFAULT_CONDUCTOR_ETA: [f64; 3] = [0.143, 0.374, 1.442];
pub const DEFAULT_CONDUCTOR_K: [f64; 3] = [3.983, 2.385, 1.603];

/// A colour: one number for grey, or `[r, g, b]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Color {
    Grey(f64),
    Rgb([f64; 3]),
}

impl Color {
    #[must_use]
    pub fn rgb(self) -> Rgb {
        match self {
            Color::Grey(v) => Rgb::splat(v),
            Color::Rgb(c) => Rgb::from_array(c),
        }
    }
}

impl<'de> Deserialize<'de> for Color {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Color;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number, an [r, g, b] array of three numbers or {\"type\": \"rgb\", \"value\": [r, g, b]}")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Color, E> {
                Ok(Color::Grey(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Color, E> {
                Ok(Color::Grey(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Color, E> {
                Ok(Color::Grey(v as f64))
            }
            /// Mitsuba's form: `{"type": "rgb", "value": [r, g, b]}` (or
            /// `"spectrum"` with one number), nothing else in it.
            fn visit_map<A: de::MapAccess<'de>>(self, mut map: A) -> Result<Color, A::Error> {
                let (mut kind, mut value): (Option<String>, Option<Color>) = (None, None);
                while let Some(key) = map.next_key::<String>()? {
                    match key.as_str() {
                        "type" => kind = Some(map.next_value()?),
                        "value" => value = Some(map.next_value()?),
                        other => {
                            return Err(de::Error::custom(format!(
                                "unknown key `{other}` in a colour: expected {{\"type\": \"rgb\", \"value\": [r, g, b]}}"
                            )));
                        }
                    }
                }
                match (kind.as_deref(), value) {
                    (Some("rgb" | "spectrum"), Some(v)) => Ok(v),
                    (Some(k), _) if k != "rgb" && k != "spectrum" => {
                        Err(de::Error::custom(format!(
                            "a colour of type `{k}` is not supported: give a number, [r, g, b] or {{\"type\": \"rgb\", \"value\": [r, g, b]}}"
                        )))
                    }
                    _ => Err(de::Error::custom(
                        "a colour object needs \"type\": \"rgb\" and \"value\": [r, g, b]",
                    )),
                }
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Color, A::Error> {
                let mut c = [0.0; 3];
                for (i, slot) in c.iter_mut().enumerate() {
                    *slot = seq
                        .next_element()?
                        .ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                if seq.next_element::<f64>()?.is_some() {
                    return Err(de::Error::invalid_length(4, &self));
                }
                Ok(Color::Rgb(c))
            }
        }
        d.deserialize_any(V)
    }
}

/// An index of refraction as written: a number, or a name of
/// [`crate::ior::IORS`] (`bk7`, `water`, `air`, ...).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Ior {
    Number(f64),
    Name(String),
}

impl<'de> Deserialize<'de> for Ior {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Ior;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an index of refraction: a number or a name (bk7, water, air, ...)")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Ior, E> {
                Ok(Ior::Number(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Ior, E> {
                Ok(Ior::Number(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Ior, E> {
                Ok(Ior::Number(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Ior, E> {
                Ok(Ior::Name(v.to_string()))
            }
        }
        d.deserialize_any(V)
    }
}

impl Ior {
    /// The index: the number, or the named one's; `field` names the key in
    /// the error (an unknown name, or a number not finite or not > 0).
    pub fn value(&self, field: &str) -> Result<f64, Error> {
        let v = match self {
            Ior::Number(v) => *v,
            Ior::Name(n) => crate::ior::dielectric(field, n)?,
        };
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(Error::param(
                field,
                format!("{v} is out of range: an index of refraction must be a number > 0"),
            ))
        }
    }
}

/// Mitsuba's `material`: a conductor's name (`conductor`,
/// `roughconductor`), or the nested material of `twosided`.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Nested {
    Name(String),
    Material(Box<MaterialDesc>),
}

impl<'de> Deserialize<'de> for Nested {
    /// A string, or an object read as a [`MaterialDesc`] (its errors name
    /// the nested field).
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Nested;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a conductor's name or a nested material object")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Nested, E> {
                Ok(Nested::Name(v.to_string()))
            }
            fn visit_map<A: de::MapAccess<'de>>(self, map: A) -> Result<Nested, A::Error> {
                MaterialDesc::deserialize(de::value::MapAccessDeserializer::new(map))
                    .map(|m| Nested::Material(Box::new(m)))
            }
        }
        d.deserialize_any(V)
    }
}

/// A Fresnel term as written by a user.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FresnelDesc {
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub f0: Option<Color>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub eta: Option<Color>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub k: Option<Color>,
}

/// A material as written by a user; [`MaterialDesc::build`] checks it and
/// turns it into a [`Material`](crate::Material).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDesc {
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub albedo: Option<Color>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ks: Option<Color>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kd: Option<Color>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exponent: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub normalized: Option<bool>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub distribution: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alpha: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alpha_u: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alpha_v: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub roughness: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shadowing: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fresnel: Option<FresnelDesc>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub path: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interpolation: Option<String>,
    // Mitsuba 3's keys, for the models named after its plugins.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reflectance: Option<Color>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diffuse_reflectance: Option<Color>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub specular_reflectance: Option<Color>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub specular_transmittance: Option<Color>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub int_ior: Option<Ior>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ext_ior: Option<Ior>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub eta: Option<Color>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub k: Option<Color>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub material: Option<Nested>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bsdf: Option<Box<MaterialDesc>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nonlinear: Option<bool>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sample_visible: Option<bool>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mode: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub multiscatter: Option<String>,
    /// The directory relative paths (`path`) are taken from: the directory
    /// of the file the description was read from; `None` for the working
    /// directory. Not a key.
    #[serde(skip)]
    pub base: Option<std::path::PathBuf>,
}

impl MaterialDesc {
    /// Parse a JSON object (nothing may follow it); the error starts with
    /// `material: ` and names the field, or says `invalid JSON` with the
    /// line and column.
    pub fn from_json(text: &str) -> Result<Self, Error> {
        parse_json(text).map_err(|m| Error::Parse(format!("material: {m}")))
    }

    /// Parse a TOML table; the error starts with `material: ` and names the
    /// field, or says `invalid TOML`, with the line.
    pub fn from_toml(text: &str) -> Result<Self, Error> {
        parse_toml(text).map_err(|m| Error::Parse(format!("material: {m}")))
    }

    /// A description with only the `type` set (every other key at its default).
    #[must_use]
    pub fn of_type(kind: &str) -> Self {
        MaterialDesc {
            kind: kind.to_string(),
            ..Default::default()
        }
    }

    /// The description as one line of JSON: the keys it has, in a fixed
    /// order ([`MaterialDesc::from_json`] reads it back).
    #[must_use]
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// The description as a TOML table ([`MaterialDesc::from_toml`] reads
    /// it back).
    pub fn to_toml(&self) -> Result<String, Error> {
        toml::to_string(self)
            .map_err(|e| Error::Parse(format!("material: cannot be written as TOML: {e}")))
    }

    /// The description as a Python dict literal, for `lobe.load_dict`
    /// (and Mitsuba 3's `mi.load_dict` where the model is Mitsuba's).
    #[must_use]
    pub fn to_python(&self) -> String {
        python_literal(&self.to_json())
    }

    /// The same description, its relative paths taken from `dir` (the
    /// directory of the file that names it).
    #[must_use]
    pub fn relative_to(mut self, dir: &std::path::Path) -> Self {
        self.base = Some(dir.to_path_buf());
        self
    }

    pub(crate) fn present_fields(&self) -> [(&'static str, bool); 28] {
        [
            ("albedo", self.albedo.is_some()),
            ("ks", self.ks.is_some()),
            ("kd", self.kd.is_some()),
            ("exponent", self.exponent.is_some()),
            ("normalized", self.normalized.is_some()),
            ("distribution", self.distribution.is_some()),
            ("alpha", self.alpha.is_some()),
            ("alpha_u", self.alpha_u.is_some()),
            ("alpha_v", self.alpha_v.is_some()),
            ("roughness", self.roughness.is_some()),
            ("shadowing", self.shadowing.is_some()),
            ("fresnel", self.fresnel.is_some()),
            ("path", self.path.is_some()),
            ("interpolation", self.interpolation.is_some()),
            ("reflectance", self.reflectance.is_some()),
            ("diffuse_reflectance", self.diffuse_reflectance.is_some()),
            ("specular_reflectance", self.specular_reflectance.is_some()),
            (
                "specular_transmittance",
                self.specular_transmittance.is_some(),
            ),
            ("int_ior", self.int_ior.is_some()),
            ("ext_ior", self.ext_ior.is_some()),
            ("eta", self.eta.is_some()),
            ("k", self.k.is_some()),
            ("material", self.material.is_some()),
            ("bsdf", self.bsdf.is_some()),
            ("nonlinear", self.nonlinear.is_some()),
            ("sample_visible", self.sample_visible.is_some()),
            ("mode", self.mode.is_some()),
            ("multiscatter", self.multiscatter.is_some()),
        ]
    }
}

/// Parse a command-line style material argument: JSON text, or `@FILE`
/// naming a `.toml` file (TOML) or any other file (JSON). Returns the
/// description and where it came from (`material` or `material (file
/// FILE)`), with which every error starts; [`crate::Material::load`] builds it.
pub fn parse_material_arg(arg: &str) -> Result<(MaterialDesc, String), Error> {
    let fail = |m: String| Error::Parse(m);
    let (desc, origin) = match arg.strip_prefix('@') {
        Some("") => {
            return Err(fail(
                "material: `@` needs a file name (@FILE.json or @FILE.toml)".into(),
            ));
        }
        Some(path) => {
            let origin = format!("material (file {path})");
            let text = std::fs::read_to_string(path)
                .map_err(|e| fail(format!("{origin}: cannot read {path}: {e}")))?;
            let is_toml = std::path::Path::new(path)
                .extension()
                .is_some_and(|x| x.eq_ignore_ascii_case("toml"));
            let desc = if is_toml {
                parse_toml(&text)
            } else {
                parse_json(&text)
            };
            let dir = std::path::Path::new(path)
                .parent()
                .unwrap_or(std::path::Path::new(""));
            (
                desc.map_err(|m| fail(format!("{origin}: {m}")))?
                    .relative_to(dir),
                origin,
            )
        }
        None => {
            let origin = "material".to_string();
            let desc = parse_json(arg).map_err(|m| {
                if arg.trim_start().starts_with('{') {
                    fail(format!("{origin}: {m}"))
                } else {
                    fail(format!(
                        "{origin}: not a JSON object (give JSON text, @FILE.json or @FILE.toml): {m}"
                    ))
                }
            })?;
            (desc, origin)
        }
    };
    Ok((desc, origin))
}

/// `field `a.b`: ` for an error below the top level, else nothing (also
/// for a path of unknown segments only, as a syntax error's can be: it
/// names no field).
fn field_prefix(path: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    if path.iter().all(|s| matches!(s, Segment::Unknown)) {
        return String::new();
    }
    let path = path.to_string();
    if path == "." || path.is_empty() {
        String::new()
    } else {
        format!("field `{path}`: ")
    }
}

/// A JSON description; the message names the field or says `invalid JSON`.
fn parse_json(text: &str) -> Result<MaterialDesc, String> {
    let mut de = serde_json::Deserializer::from_str(text);
    let desc: MaterialDesc = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let prefix = field_prefix(e.path());
        let inner = e.into_inner();
        let kind = match inner.classify() {
            serde_json::error::Category::Syntax | serde_json::error::Category::Eof => {
                "invalid JSON: "
            }
            _ => "",
        };
        format!("{prefix}{kind}{inner}")
    })?;
    de.end().map_err(|e| format!("invalid JSON: {e}"))?;
    Ok(desc)
}

/// A TOML description; the message names the field or says `invalid TOML`,
/// with the line.
fn parse_toml(text: &str) -> Result<MaterialDesc, String> {
    let at = |e: &toml::de::Error| match e.span() {
        Some(span) => {
            let line = text.as_bytes()[..span.start.min(text.len())]
                .iter()
                .filter(|&&b| b == b'\n')
                .count()
                + 1;
            format!(" (line {line})")
        }
        None => String::new(),
    };
    let de = toml::Deserializer::parse(text)
        .map_err(|e| format!("invalid TOML: {}{}", e.message(), at(&e)))?;
    serde_path_to_error::deserialize(de).map_err(|e| {
        let prefix = field_prefix(e.path());
        let inner = e.inner();
        format!("{prefix}{}{}", inner.message(), at(inner))
    })
}

impl FresnelDesc {
    pub fn build(&self) -> Result<Fresnel, Error> {
        let allowed: &[&str] = match self.kind.as_str() {
            "none" => &[],
            "schlick" => &["f0"],
            "dielectric" => &["eta"],
            "conductor" => &["eta", "k"],
            other => {
                return Err(Error::UnknownName {
                    field: "fresnel.type".into(),
                    value: other.into(),
                    expected: "none, schlick, dielectric, conductor".into(),
                });
            }
        };
        for (name, present) in [
            ("f0", self.f0.is_some()),
            ("eta", self.eta.is_some()),
            ("k", self.k.is_some()),
        ] {
            if present && !allowed.contains(&name) {
                return Err(Error::param(
                    &format!("fresnel.{name}"),
                    format!("does not apply to fresnel type {}", self.kind),
                ));
            }
        }
        let positive = |field: &str, c: Rgb| -> Result<Rgb, Error> {
            if c.to_array().iter().all(|v| v.is_finite() && *v > 0.0) {
                Ok(c)
            } else {
                Err(Error::param(
                    field,
                    format!("{c} is out of range: each channel must be a number > 0"),
                ))
            }
        };
        Ok(match self.kind.as_str() {
            "none" => Fresnel::None,
            "schlick" => Fresnel::Schlick {
                f0: crate::math::check_rgb(
                    "fresnel.f0",
                    self.f0.map_or(Rgb::splat(DEFAULT_F0), Color::rgb),
                    1.0,
                )?,
            },
            "dielectric" => Fresnel::Dielectric {
                eta: positive(
                    "fresnel.eta",
                    self.eta
                        .map_or(Rgb::splat(DEFAULT_DIELECTRIC_ETA), Color::rgb),
                )?,
            },
            _ => Fresnel::Conductor {
                eta: positive(
                    "fresnel.eta",
                    self.eta
                        .map_or(Rgb::from_array(DEFAULT_CONDUCTOR_ETA), Color::rgb),
                )?,
                k: crate::math::check_rgb(
                    "fresnel.k",
                    self.k
                        .map_or(Rgb::from_array(DEFAULT_CONDUCTOR_K), Color::rgb),
                    f64::MAX,
                )?,
            },
        })
    }
}

/// JSON text as a Python literal, keys in their order: `true`, `false` and
/// `null` become `True`, `False` and `None` outside strings, and a space
/// follows each `:` and `,` as Python writes dicts.
fn python_literal(json: &str) -> String {
    let mut out = String::with_capacity(json.len() + json.len() / 4);
    let mut chars = json.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' => {
                out.push('"');
                while let Some(d) = chars.next() {
                    out.push(d);
                    if d == '\\' {
                        if let Some(e) = chars.next() {
                            out.push(e);
                        }
                    } else if d == '"' {
                        break;
                    }
                }
            }
            ':' | ',' => {
                out.push(c);
                out.push(' ');
            }
            't' | 'f' | 'n' => {
                let mut word = String::from(c);
                while let Some(&d) = chars.peek() {
                    if !d.is_ascii_alphabetic() {
                        break;
                    }
                    word.push(d);
                    chars.next();
                }
                out.push_str(match word.as_str() {
                    "true" => "True",
                    "false" => "False",
                    "null" => "None",
                    w => w,
                });
            }
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Glossy;
    use crate::microfacet::Shadowing;
    use crate::models::{self, defaults};

    fn err(json: &str) -> String {
        match MaterialDesc::from_json(json).and_then(|d| d.build()) {
            Ok(m) => panic!("{json} was accepted: {m:?}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn the_help_text_is_made_from_the_tables() {
        let text = defaults();
        for m in models::MODELS {
            assert!(text.contains(&format!("type {}:", m.name)), "{text}");
            for p in m.params {
                let line = format!(
                    "  {:<13} {}; default",
                    p.name,
                    p.range_text().replace('`', "")
                );
                assert!(text.contains(&line), "{line:?} not in\n{text}");
            }
        }
        assert!(text.contains("default eta 1.5") && text.contains("default f0 0.04"));
    }

    #[test]
    fn defaults_and_colours() {
        let m = MaterialDesc::from_json(r#"{"type":"lambert"}"#)
            .unwrap()
            .build()
            .unwrap();
        assert_eq!(m.diffuse.albedo, Rgb::splat(0.8));
        let m = MaterialDesc::from_json(
            r#"{"type":"phong","ks":[0.1,0.2,0.3],"kd":0.5,"exponent":10}"#,
        )
        .unwrap()
        .build()
        .unwrap();
        assert_eq!(m.diffuse.albedo, Rgb::splat(0.5));
        let Glossy::Phong(p) = m.glossy else { panic!() };
        assert_eq!(p.ks, Rgb::new(0.1, 0.2, 0.3));
        assert!(p.normalized);
        let m = MaterialDesc::from_json(r#"{"type":"cook-torrance","roughness":0.5}"#)
            .unwrap()
            .build()
            .unwrap();
        let Glossy::CookTorrance(c) = m.glossy else {
            panic!()
        };
        assert_eq!(c.microfacet.alpha(), (0.25, 0.25));
        assert_eq!(c.shadowing, Shadowing::SmithCorrelated);
        assert_eq!(c.fresnel, Fresnel::None);
    }

    #[test]
    fn bad_input_names_the_field() {
        assert!(err(r#"{"type":"phong","exponent":-1}"#).contains("`exponent`"));
        assert!(err(r#"{"type":"cook-torrance","alpha":-0.1}"#).contains("`alpha`:"));
        assert!(err(r#"{"type":"cook-torrance","roughness":2}"#).contains("`roughness`:"));
        assert!(
            err(r#"{"type":"cook-torrance","alpha_u":0.1,"alpha_v":9}"#).contains("`alpha_v`:")
        );
        assert!(
            err(r#"{"type":"cook-torrance","distribution":"ggz"}"#)
                .contains("`distribution`: unknown value `ggz`")
        );
        assert!(err(r#"{"type":"cook-torrance","shadowing":"x"}"#).contains("shadowing"));
        assert!(
            err(r#"{"type":"lambert","exponent":3}"#)
                .contains("`exponent`: does not apply to type lambert")
        );
        assert!(err(r#"{"type":"glass"}"#).contains("`type`"));
        assert!(err(r#"{"type":"phong","ks":[1,2]}"#).contains("ks"));
        assert!(err(r#"{"type":"phong","exponnt":3}"#).contains("unknown field `exponnt`"));
        // A syntax error at the top level names no field (not "field `?`").
        let e = err(r#"{"type":"phong","#);
        assert!(e.contains("invalid JSON") && !e.contains("field"), "{e}");
        assert!(
            err(r#"{"type":"cook-torrance","fresnel":{"type":"conductor","f0":0.5}}"#)
                .contains("fresnel.f0")
        );
        assert!(
            err(r#"{"type":"cook-torrance","fresnel":{"type":"dielectric","eta":0}}"#)
                .contains("fresnel.eta")
        );
        assert!(err(r#"{"type":"cook-torrance","alpha_u":0.1}"#).contains("alpha_v"));
        assert!(err(r#"{"type":"lambert","albedo":1.5}"#).contains("albedo"));
    }

    #[test]
    fn descriptions_are_written_back_as_json_toml_and_python() {
        let text = r#"{"type":"twosided","bsdf":{"type":"roughplastic","alpha":0.3,"diffuse_reflectance":[0.2,0.4,0.6],"int_ior":"polypropylene","nonlinear":true}}"#;
        let d = MaterialDesc::from_json(text).unwrap();
        assert_eq!(d.to_json(), text);
        assert_eq!(MaterialDesc::from_toml(&d.to_toml().unwrap()).unwrap(), d);
        assert_eq!(
            d.to_python(),
            r#"{"type": "twosided", "bsdf": {"type": "roughplastic", "alpha": 0.3, "diffuse_reflectance": [0.2, 0.4, 0.6], "int_ior": "polypropylene", "nonlinear": True}}"#
        );
        // Quotes and escapes inside strings stay as they are.
        assert_eq!(
            python_literal(r#"{"a":"t,\"x:null"}"#),
            r#"{"a": "t,\"x:null"}"#
        );
    }

    #[test]
    fn toml_and_json_give_the_same_description() {
        let j =
            MaterialDesc::from_json(r#"{"type":"cook-torrance","alpha":0.2,"kd":[0.1,0.2,0.3]}"#)
                .unwrap();
        let t = MaterialDesc::from_toml(
            "type = \"cook-torrance\"\nalpha = 0.2\nkd = [0.1, 0.2, 0.3]\n",
        )
        .unwrap();
        assert_eq!(j, t);
        let e = MaterialDesc::from_toml("type = \"phong\"\nexponnt = 3\n").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("material: field `exponnt`: unknown field `exponnt`"),
            "{e}"
        );
        assert!(e.to_string().contains("(line 2)"), "{e}");
        let e = MaterialDesc::from_toml("type = \n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("material: invalid TOML: "), "{e}");
        let e = MaterialDesc::from_json(r#"{"type":"lambert"} x"#)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("material: invalid JSON: trailing characters"),
            "{e}"
        );
        let e = MaterialDesc::from_json(r#"{"type":"phong","ks":[1,"a",3]}"#)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("material: field `ks"), "{e}");
    }

    #[test]
    fn loader_reads_inline_text_and_files() {
        let m = crate::Material::load(r#"{"type":"phong","exponent":10}"#).unwrap();
        assert_eq!(
            m.model_name(),
            MaterialDesc::from_json(r#"{"type":"phong","exponent":10}"#)
                .unwrap()
                .build()
                .unwrap()
                .model_name()
        );
        let dir = std::env::temp_dir().join(format!("lobe-desc-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let toml_path = dir.join("m.toml");
        std::fs::write(&toml_path, "type = \"lambert\"\nalbedo = 0.5\n").unwrap();
        let m = crate::Material::load(&format!("@{}", toml_path.display())).unwrap();
        assert_eq!(m.diffuse.albedo, Rgb::splat(0.5));
        let json_path = dir.join("m.json");
        std::fs::write(&json_path, r#"{"type":"lambert","albedo":2}"#).unwrap();
        let e = crate::Material::load(&format!("@{}", json_path.display()))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(&format!(
                "material (file {}): field `albedo`",
                json_path.display()
            )),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(
            crate::Material::load("@").unwrap_err().to_string(),
            "material: `@` needs a file name (@FILE.json or @FILE.toml)"
        );
        let e = crate::Material::load("@/nonexistent/lobe.json")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(
                "material (file /nonexistent/lobe.json): cannot read /nonexistent/lobe.json: "
            ),
            "{e}"
        );
        let e = crate::Material::load("phong").unwrap_err().to_string();
        assert!(e.starts_with("material: not a JSON object (give JSON text, @FILE.json or @FILE.toml): invalid JSON"), "{e}");
        let e = crate::Material::load(r#"{"type":"glass"}"#)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("material: field `type`"), "{e}");
    }
}
