//! The reflection models, one file each. Each is a *lobe*: one term of a
//! material's BRDF (a material is a Lambertian lobe plus at most one
//! glossy lobe, [`Lobes`]); a *model* is the kind of lobe (its `type` name and
//! file); [`Bxdf`] is the interface every lobe implements.
//!
//! A model file holds everything about its model: the type, its
//! [`Bxdf`] implementation, its parameter table ([`Param`]s, with ranges and
//! defaults, from which its doc table and the text of `lobe eval --help`
//! are made), its table of strategies ([`Bxdf::sampler`]: one arm per
//! strategy it has, into a small `Copy` sampler value), its range checks,
//! and how it is built from a material description. It publishes all of
//! that as one [`ModelInfo`] named `INFO`. Adding a model is one new file
//! and one line in the list at the end of this file ([`MODELS`], and the
//! [`Glossy`] and [`GlossySampler`] variants that the same line declares);
//! docs/ARCHITECTURE.md has the checklist.

use crate::BsdfStrategy;
use crate::math::Rgb;
use crate::sample::{Deltas, LobeSample, Reach, Scattering};
use glam::{DVec2, DVec3};
use std::fmt::{self, Write as _};

pub mod lambert;
pub use lambert::Lambert;

/// One lobe of a material, evaluated and sampled by its own samplers.
/// `uniform` and `cosine` ignore the lobe: the material draws them
/// for every model, so a model's table of strategies lists only its own
/// (`brdf` and the microfacet strategies).
///
/// A strategy is resolved once, by [`Bxdf::sampler`], into a small `Copy`
/// value of the model's own type; `sample` and `pdf` take that value and
/// never see a strategy it does not have.
///
/// Directions: a lobe that does not transmit ([`Reach::transmits`] false)
/// is called with `wo.z > 0` (and `wi.z > 0` for `eval` and `pdf`); one that
/// transmits is called with any `wo` off the horizon and any `wi`, and
/// `wo.z < 0` means seen from inside. A delta part ([`Reach::delta`]) is in
/// neither `eval` nor `pdf`: only `sample` reaches it ([`LobeSample`] says
/// how its `f` and `pdf` are given).
pub trait Bxdf {
    /// The model's samplers: one value per strategy it has (an enum, or a
    /// unit struct where it has one).
    type Sampler: Copy + fmt::Debug + PartialEq;
    /// The model's table of strategies: the sampler for `strategy`, or why
    /// the model has none (the caller lists the strategies it has).
    fn sampler(&self, strategy: BsdfStrategy) -> Result<Self::Sampler, String>;
    /// What its samples are when it reflects with a density: diffuse or
    /// glossy reflection (a lobe with several parts says in each
    /// [`LobeSample`] which it drew).
    fn scattering(&self) -> Scattering;
    /// Whether it transmits, has a delta part, chooses between parts with
    /// `uc`; the lecture's models reflect only, with a density.
    fn reach(&self) -> Reach {
        Reach::REFLECTION
    }
    /// `f(wo, wi)` of this lobe, without the cosine (delta parts left out).
    fn eval(&self, wo: DVec3, wi: DVec3) -> Rgb;
    /// Draw `wi` by `sampler` (`uc` chooses a part where the lobe has
    /// several); `None` for a failed sample (below the horizon).
    fn sample(&self, sampler: Self::Sampler, wo: DVec3, uc: f64, u: DVec2) -> Option<DVec3>;
    /// Density in solid angle of what `sample` returns (delta parts left out).
    fn pdf(&self, sampler: Self::Sampler, wo: DVec3, wi: DVec3) -> f64;
    /// `sample`, and `eval` and `pdf` at the sampled direction, sharing what
    /// they have in common (a model may override it for speed; a model with
    /// a delta part must, to return it).
    #[inline]
    fn sample_eval(
        &self,
        sampler: Self::Sampler,
        wo: DVec3,
        uc: f64,
        u: DVec2,
    ) -> Option<LobeSample> {
        let wi = self.sample(sampler, wo, uc, u)?;
        Some(LobeSample {
            wi,
            f: self.eval(wo, wi),
            pdf: self.pdf(sampler, wo, wi),
            scattering: self.scattering(),
        })
    }
    /// `(eval, pdf)` at one `wi`, sharing what they have in common (a model
    /// may override it for speed; the numbers must be the same as the two
    /// calls).
    #[inline]
    fn eval_pdf(&self, sampler: Self::Sampler, wo: DVec3, wi: DVec3) -> (Rgb, f64) {
        (self.eval(wo, wi), self.pdf(sampler, wo, wi))
    }
    /// The delta parts at `wo` ([`Reach::delta`]): what a quadrature of
    /// `eval` leaves out. None for a lobe with a density only.
    fn deltas(&self, _wo: DVec3) -> Deltas {
        Deltas::NONE
    }
    /// An estimate of the lobe's directional albedo (luminance), used to
    /// choose between lobes.
    fn albedo_hint(&self, wo: DVec3) -> f64;
}

/// What a key of a material description accepts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Range {
    /// A colour (one number or `[r, g, b]`), each channel in `[0, max]`
    /// (`max` infinite: any number `≥ 0`).
    Colour { max: f64 },
    /// A number in `[min, max]`.
    Number { min: f64, max: f64 },
    /// `true` or `false`.
    Bool,
    /// One of these names (comma separated).
    Names(&'static str),
    /// The path of a data file (a measured table).
    File,
    /// An index of refraction: a number `> 0` or a name of
    /// [`crate::ior::IORS`].
    Ior,
    /// `none` or the name of a conductor of [`crate::ior::CONDUCTORS`].
    Conductor,
    /// A nested material description.
    Material,
}

/// The default of a key of a material description.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Value {
    /// A number (for a colour: grey).
    Number(f64),
    Bool(bool),
    Name(&'static str),
    /// No value of its own: the text says what applies.
    Text(&'static str),
}

impl Value {
    /// The number; panics (at compile time when used in a `const`) otherwise.
    #[must_use]
    pub const fn number(self) -> f64 {
        match self {
            Value::Number(v) => v,
            _ => panic!("not a number"),
        }
    }

    /// The flag; panics (at compile time when used in a `const`) otherwise.
    #[must_use]
    pub const fn flag(self) -> bool {
        match self {
            Value::Bool(b) => b,
            _ => panic!("not a bool"),
        }
    }

    /// The name; panics (at compile time when used in a `const`) otherwise.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Value::Name(s) => s,
            _ => panic!("not a name"),
        }
    }
}

/// One key of a material description: its name, what it accepts, its
/// default and what it means. The one place these facts are written.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Param {
    /// The key as written in JSON or TOML.
    pub name: &'static str,
    pub range: Range,
    /// Said after the range, for what the range alone does not say.
    pub note: &'static str,
    pub default: Value,
    pub meaning: &'static str,
}

/// A number as people write it: `1e7`, `1e-4`, `0.3`.
struct Num(f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let v = self.0;
        if v != 0.0 && (v.abs() >= 1e5 || v.abs() < 1e-3) {
            write!(f, "{v:e}")
        } else {
            write!(f, "{v}")
        }
    }
}

impl fmt::Display for Range {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match *self {
            Range::Colour { max } if max.is_infinite() => f.write_str("RGB ≥ 0"),
            Range::Colour { max } => write!(f, "RGB in [0, {}]", Num(max)),
            Range::Number { min, max } if max.is_infinite() => write!(f, "≥ {}", Num(min)),
            Range::Number { min, max } => write!(f, "[{}, {}]", Num(min), Num(max)),
            Range::Bool => f.write_str("bool"),
            Range::File => f.write_str("a file (MERL .binary or RGL .bsdf, by content)"),
            Range::Ior => f.write_str(
                "> 0, or a name (`bk7`, `water`, `air`, ...: the list ends `lobe eval --help`)",
            ),
            Range::Conductor => {
                f.write_str("`none` or a conductor's name (`Au`, `Ag`, `Cu`, `Al`, `Cr`, ...)")
            }
            Range::Material => f.write_str("a material description"),
            Range::Names(names) => {
                let mut first = true;
                for n in names.split(',') {
                    if !first {
                        f.write_str(", ")?;
                    }
                    first = false;
                    write!(f, "`{}`", n.trim())?;
                }
                Ok(())
            }
        }
    }
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match *self {
            Value::Number(v) => write!(f, "{}", Num(v)),
            Value::Bool(b) => write!(f, "{b}"),
            Value::Name(s) => write!(f, "`{s}`"),
            Value::Text(s) => f.write_str(s),
        }
    }
}

impl Param {
    /// The range and its note, as the doc table and the help text show it.
    #[must_use]
    pub fn range_text(&self) -> String {
        if self.note.is_empty() {
            self.range.to_string()
        } else {
            format!("{} {}", self.range, self.note)
        }
    }

    /// Check a colour against `[0, max]`, `max` the range's unless the
    /// model relaxes it (`max` given).
    pub fn check_colour(&self, c: Rgb, max: Option<f64>) -> crate::error::Result<Rgb> {
        let max = match (max, self.range) {
            (Some(m), _) => m,
            (None, Range::Colour { max }) => max,
            (None, _) => f64::MAX,
        };
        check_rgb(self.name, c, if max.is_infinite() { f64::MAX } else { max })
    }

    /// Check a number against the range: `what` names it in the message
    /// ("the exponent must be a number in ...").
    pub fn check_number(&self, v: f64, what: &str) -> crate::error::Result<f64> {
        let Range::Number { min, max } = self.range else {
            return Ok(v);
        };
        if !v.is_finite() || !(min..=max).contains(&v) {
            return Err(crate::Error::param(
                self.name,
                format!("{v} is out of range: {what} must be a number in [{min}, {max}]"),
            ));
        }
        Ok(v)
    }
}

/// Everything about one model: its `type` name, its keys and how it is
/// built from a description.
#[derive(Debug, Clone, Copy)]
pub struct ModelInfo {
    /// The value of `type` in a description.
    pub name: &'static str,
    /// Its keys, in the order the docs show them.
    pub params: &'static [Param],
    /// Build the material's lobes from a description whose keys all belong
    /// to `params` (checked by `MaterialDesc::build`).
    #[cfg(feature = "desc")]
    pub from_desc: fn(&crate::desc::MaterialDesc) -> crate::error::Result<Lobes>,
}

impl ModelInfo {
    /// The parameter table in Markdown, as the model's doc comment shows it.
    #[must_use]
    pub fn doc_table(&self) -> String {
        let mut s = String::from("| parameter | range | default | meaning |\n|---|---|---|---|\n");
        for p in self.params {
            let _ = writeln!(
                s,
                "| `{}` | {} | {} | {} |",
                p.name,
                p.range_text(),
                p.default,
                p.meaning
            );
        }
        s
    }

    /// The keys of this model.
    pub fn keys(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.params.iter().map(|p| p.name)
    }
}

/// The model of `type` name `name`.
#[must_use]
pub fn find(name: &str) -> Option<&'static ModelInfo> {
    MODELS.iter().copied().find(|m| m.name == name)
}

/// The model names, `sep` between them.
#[must_use]
pub fn names(sep: &str) -> String {
    MODELS.iter().map(|m| m.name).collect::<Vec<_>>().join(sep)
}

/// A material's lobes, as a model builds them from a description: a
/// Lambertian term and at most one glossy lobe, and whether it is seen from
/// both sides. `Material` is made of them.
#[derive(Debug, Clone, PartialEq)]
pub struct Lobes {
    pub diffuse: Lambert,
    pub glossy: Glossy,
    pub two_sided: bool,
}

impl Lobes {
    /// A glossy lobe plus a diffuse term `kd/π`; the error names `kd`. A
    /// diffuse term goes only beside an opaque lobe with a density and one
    /// part (not glass, a mirror or plastic, which has a base of its own).
    pub fn with_diffuse(kd: Rgb, glossy: Glossy) -> crate::error::Result<Self> {
        let diffuse = Lambert::new(kd).map_err(|_| {
            crate::Error::param(
                "kd",
                format!("{kd} is out of range: each channel must be in [0, 1]"),
            )
        })?;
        let reach = glossy.reach();
        if kd != Rgb::ZERO && (reach.transmits || reach.delta || reach.chooses) {
            return Err(crate::Error::param(
                "kd",
                format!(
                    "a diffuse term goes only beside an opaque lobe with a density; {} {}",
                    glossy.model_name(),
                    if reach.transmits {
                        "transmits"
                    } else if reach.delta {
                        "has a delta part"
                    } else {
                        "has parts of its own"
                    }
                ),
            ));
        }
        Ok(Lobes {
            diffuse,
            glossy,
            two_sided: false,
        })
    }

    /// One lobe and no diffuse term.
    #[must_use]
    pub fn only(glossy: Glossy) -> Self {
        Lobes {
            diffuse: Lambert { albedo: Rgb::ZERO },
            glossy,
            two_sided: false,
        }
    }
}

/// The key `kd` of every glossy model: the diffuse term the material adds.
pub const KD: Param = Param {
    name: "kd",
    range: Range::Colour { max: 1.0 },
    note: "",
    default: Value::Number(0.0),
    meaning: "diffuse colour, added as `kd/π`",
};

pub(crate) use crate::math::check_rgb;

/// A colour key of a description, or its default.
#[cfg(feature = "desc")]
pub(crate) fn colour(c: Option<crate::desc::Color>, p: Param) -> Rgb {
    c.map_or(Rgb::splat(p.default.number()), crate::desc::Color::rgb)
}

/// `(ks, kd, exponent, normalized)` of a lecture model (Phong, Blinn-Phong)
/// from a description, each at its default when absent.
#[cfg(feature = "desc")]
fn lecture_keys(
    d: &crate::desc::MaterialDesc,
    ks: Param,
    exponent: Param,
    normalized: Param,
) -> (Rgb, Rgb, f64, bool) {
    (
        colour(d.ks, ks),
        colour(d.kd, KD),
        d.exponent.unwrap_or(exponent.default.number()),
        d.normalized.unwrap_or(normalized.default.flag()),
    )
}

/// Largest accepted Phong and Blinn-Phong exponent.
pub const MAX_EXPONENT: f64 = 1e7;

/// Declares the glossy models, one line each: the module, the type (which
/// names the [`Glossy`] and [`GlossySampler`] variants), and puts the
/// module's `INFO` in [`MODELS`]. Both enums dispatch statically over the
/// variants.
macro_rules! glossy_models {
    (
        lobes: $($module:ident :: $ty:ident),* $(,)?;
        names: $($alias:ident),* $(,)?
    ) => {
        $(pub mod $module; pub use $module::$ty;)*
        $(pub mod $alias;)*

        /// Every model, Lambert first, then the lobes, then the models
        /// whose lobe is another's (Mitsuba's names for lobe's models, and
        /// `twosided`).
        pub const MODELS: &[&ModelInfo] = &[&lambert::INFO, $(&$module::INFO,)* $(&$alias::INFO),*];

        /// The glossy lobe of a material (static dispatch). `None` reflects
        /// nothing.
        #[derive(Debug, Clone, PartialEq)]
        pub enum Glossy {
            None,
            $($ty($ty)),*
        }

        /// A glossy lobe with one of its samplers ([`Glossy::sampler`]):
        /// what a material's sampler draws the glossy lobe with. `None`
        /// draws nothing.
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub enum GlossySampler<'m> {
            None,
            $($ty(&'m $ty, <$ty as Bxdf>::Sampler)),*
        }

        impl Glossy {
            /// The `type` name of the material with this lobe.
            #[must_use]
            pub fn model_name(&self) -> &'static str {
                match self {
                    Glossy::None => lambert::INFO.name,
                    $(Glossy::$ty(_) => $module::INFO.name),*
                }
            }

            /// The lobe's sampler for `strategy` ([`Bxdf::sampler`]), or why
            /// it has none.
            pub fn sampler(&self, strategy: BsdfStrategy) -> Result<GlossySampler<'_>, String> {
                match self {
                    Glossy::None => Err("no glossy lobe".into()),
                    $(Glossy::$ty(l) => Ok(GlossySampler::$ty(l, l.sampler(strategy)?))),*
                }
            }

            /// What the lobe's samples are; `None` for no lobe.
            #[must_use]
            pub fn scattering(&self) -> Option<Scattering> {
                match self {
                    Glossy::None => None,
                    $(Glossy::$ty(l) => Some(l.scattering())),*
                }
            }

            /// [`Bxdf::eval`]; zero for no lobe.
            #[inline]
            #[must_use]
            pub fn eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
                match self {
                    Glossy::None => Rgb::ZERO,
                    $(Glossy::$ty(l) => l.eval(wo, wi)),*
                }
            }

            /// [`Bxdf::reach`]; for no lobe, an opaque one's.
            #[inline]
            #[must_use]
            pub fn reach(&self) -> Reach {
                match self {
                    Glossy::None => Reach::REFLECTION,
                    $(Glossy::$ty(l) => l.reach()),*
                }
            }

            /// [`Bxdf::deltas`]; none for no lobe.
            #[inline]
            #[must_use]
            pub fn deltas(&self, wo: DVec3) -> Deltas {
                match self {
                    Glossy::None => Deltas::NONE,
                    $(Glossy::$ty(l) => l.deltas(wo)),*
                }
            }

            /// [`Bxdf::albedo_hint`]; zero for no lobe.
            #[inline]
            #[must_use]
            pub fn albedo_hint(&self, wo: DVec3) -> f64 {
                match self {
                    Glossy::None => 0.0,
                    $(Glossy::$ty(l) => l.albedo_hint(wo)),*
                }
            }
        }

        impl GlossySampler<'_> {
            /// [`Bxdf::sample`].
            #[inline]
            #[must_use]
            pub fn sample(&self, wo: DVec3, uc: f64, u: DVec2) -> Option<DVec3> {
                match self {
                    GlossySampler::None => None,
                    $(GlossySampler::$ty(l, s) => l.sample(*s, wo, uc, u)),*
                }
            }
            /// [`Bxdf::pdf`].
            #[inline]
            #[must_use]
            pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
                match self {
                    GlossySampler::None => 0.0,
                    $(GlossySampler::$ty(l, s) => l.pdf(*s, wo, wi)),*
                }
            }
            /// [`Bxdf::sample_eval`].
            #[inline]
            #[must_use]
            pub fn sample_eval(&self, wo: DVec3, uc: f64, u: DVec2) -> Option<LobeSample> {
                match self {
                    GlossySampler::None => None,
                    $(GlossySampler::$ty(l, s) => l.sample_eval(*s, wo, uc, u)),*
                }
            }
            /// [`Bxdf::eval_pdf`].
            #[inline]
            #[must_use]
            pub fn eval_pdf(&self, wo: DVec3, wi: DVec3) -> (Rgb, f64) {
                match self {
                    GlossySampler::None => (Rgb::ZERO, 0.0),
                    $(GlossySampler::$ty(l, s) => l.eval_pdf(*s, wo, wi)),*
                }
            }
        }
    };
}

glossy_models! {
    lobes:
        phong::Phong,
        blinn_phong::BlinnPhong,
        cook_torrance::CookTorrance,
        measured::Measured,
        conductor::Conductor,
        dielectric::Dielectric,
        thindielectric::ThinDielectric,
        roughdielectric::RoughDielectric,
        plastic::Plastic,
        roughplastic::RoughPlastic;
    names:
        diffuse,
        roughconductor,
        twosided,
}

pub mod keys;

#[cfg(feature = "desc")]
/// The material keys, their values and defaults, printed by `lobe eval --help`:
/// made from each model's parameter table ([`crate::models::MODELS`]).
#[must_use]
pub fn defaults() -> &'static str {
    static TEXT: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TEXT.get_or_init(defaults_text)
}

#[cfg(feature = "desc")]
fn defaults_text() -> String {
    use std::fmt::Write as _;
    let plain = |s: &str| s.replace('`', "");
    let mut s = format!(
        "Material keys (JSON or TOML); colours are a number or [r, g, b]:\n  \
         {:<13} {}      (required)\n",
        "type",
        names(" | ")
    );
    for m in MODELS {
        let _ = writeln!(s, "type {}:", m.name);
        for p in m.params {
            let _ = writeln!(
                s,
                "  {:<13} {}; default {}; {}",
                p.name,
                plain(&p.range_text()),
                plain(&p.default.to_string()),
                plain(p.meaning)
            );
        }
    }
    let rgb = |c: [f64; 3]| format!("[{},{},{}]", c[0], c[1], c[2]);
    s.push_str("fresnel (cook-torrance), one of:");
    for (object, says) in [
        (r#"{"type":"none"}"#, "F = 1".to_string()),
        (
            r#"{"type":"schlick","f0":c}"#,
            format!("default f0 {}", crate::desc::DEFAULT_F0),
        ),
        (
            r#"{"type":"dielectric","eta":c}"#,
            format!("default eta {}", crate::desc::DEFAULT_DIELECTRIC_ETA),
        ),
        (
            r#"{"type":"conductor","eta":c,"k":c}"#,
            format!(
                "default gold, eta {} k {}",
                rgb(crate::desc::DEFAULT_CONDUCTOR_ETA),
                rgb(crate::desc::DEFAULT_CONDUCTOR_K)
            ),
        ),
    ] {
        let _ = write!(s, "\n  {object:<35} {says}");
    }
    let names = |v: Vec<&str>| v.join(", ");
    let _ = write!(
        s,
        "\nNamed indices of refraction (int_ior, ext_ior; any case):\n  {}\nNamed conductors (material; Mitsuba's RGB data):\n  none, {}",
        names(crate::ior::IORS.iter().map(|(n, _)| *n).collect()),
        names(crate::ior::CONDUCTORS.iter().map(|(n, _, _)| *n).collect())
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The doc comment at the top of each model file shows its parameter
    /// table: the one made from `INFO.params`.
    #[test]
    fn doc_tables_are_the_param_tables() {
        // Every model's own file, found by its name (`blinn-phong` →
        // `blinn_phong.rs`): no list to keep beside `MODELS`.
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/models");
        let sources: Vec<(&str, String)> = MODELS
            .iter()
            .map(|m| {
                let path = dir.join(format!("{}.rs", m.name.replace('-', "_")));
                let src = std::fs::read_to_string(&path)
                    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                (m.name, src)
            })
            .collect();
        for (name, src) in &sources {
            let doc: String = src
                .lines()
                .filter_map(|l| l.strip_prefix("//!"))
                .map(|l| format!("{}\n", l.strip_prefix(' ').unwrap_or(l)))
                .collect();
            let table = find(name).unwrap().doc_table();
            assert!(
                doc.contains(&table),
                "the doc table of {name} is not its parameter table; it should read:\n{table}"
            );
        }
    }

    #[test]
    fn numbers_read_as_written() {
        assert_eq!(Num(1e7).to_string(), "1e7");
        assert_eq!(Num(1e-4).to_string(), "1e-4");
        assert_eq!(Num(0.3).to_string(), "0.3");
        assert_eq!(Num(32.0).to_string(), "32");
    }
}
