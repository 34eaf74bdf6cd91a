//! `lobe eval`: evaluate, give the pdfs of, and sample a material, one JSON
//! line at a time (stdin to stdout).
//!
//! The hot loop reuses one line buffer, parses each line with a hand-written
//! serde visitor (no allocation unless the line is bad) and writes numbers
//! straight into a buffered stdout.

use anyhow::{Result, anyhow};
use clap::Args;
use glam::{DVec2, DVec3};
use lobe::{BsdfStrategy, Material};
use serde::de::{self, DeserializeSeed, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};
use std::cell::Cell;
use std::fmt;
use std::io::{self, BufRead, BufWriter, Write};

/// How far from 1 the length of `wo` or `wi` may be.
pub const UNIT_TOLERANCE: f64 = 1e-6;

/// The arguments of `lobe eval`.
#[derive(Args, Debug)]
#[command(
    about = "Evaluate f, the pdfs and samples of a material, one JSON line at a time",
    long_about = long_about(),
    after_help = "Example:\n  echo '{\"wo\":[0.6,0,0.8],\"wi\":[0,0,1]}' | lobe eval --material '{\"type\":\"cook-torrance\",\"alpha\":0.2}'\n\n\
                  `lobe eval --help` also lists the material keys and their defaults.",
    after_long_help = after_long_help(),
)]
pub struct EvalArgs {
    /// The material: JSON text, or @FILE.json, or @FILE.toml
    #[arg(long, short = 'm', value_name = "JSON|@FILE")]
    pub material: String,
    /// Answer the lines with the f32 SIMD batch kernels (lobe::batch), in
    /// blocks of 4096 lines: the same fields, f32 numbers, within 1e-4
    /// relative (f, pdf, weight) and 1e-5 absolute (wi) of the default f64 path
    #[arg(long)]
    pub batch: bool,
}

fn long_about() -> String {
    format!(
        "Read JSON lines on stdin and write one JSON object per line on stdout.\n\
         \n\
         An eval line gives f (without the cosine) and the pdf, in solid angle, of every\n\
         strategy that applies to the material:\n  \
         {{\"wo\":[x,y,z],\"wi\":[x,y,z]}}\n  \
         -> {{\"f\":[r,g,b],\"pdf\":{{\"uniform\":p,\"cosine\":p,\"brdf\":p,...}}}}\n\
         \n\
         A sample line draws one direction wi for wo with a strategy:\n  \
         {{\"wo\":[x,y,z],\"u\":[u1,u2],\"uc\":u,\"strategy\":\"vndf\"}}\n  \
         -> {{\"wi\":[x,y,z],\"pdf\":p,\"weight\":[r,g,b]}}\n\
         where weight = f cos(theta_i) / pdf. A failed sample (below the horizon) gives\n\
         {{\"wi\":null,\"pdf\":0,\"weight\":[0,0,0]}}; an estimator still counts it.\n\
         \n\
         Directions are in the local shading frame (+z is the normal), point away from\n\
         the surface, and must be unit vectors: |length - 1| <= {UNIT_TOLERANCE:e}. u1, u2 and uc\n\
         are in [0, 1). uc chooses the lobe of a two-lobe material (a diffuse term kd and\n\
         a glossy lobe): it is required there, for every strategy but uniform and cosine,\n\
         and must be an independent uniform number like u1 and u2 (a fixed uc always takes\n\
         the same lobe, which biases any average of the weights). A single-lobe material\n\
         does not use it and may omit it.\n\
         Strategies: {}.\n\
         Empty lines are skipped. Numbers are printed so that they parse back to the same\n\
         f64. A bad line, or a result that is not finite, stops with an error that names\n\
         the line and the field.\n\
         \n\
         --batch answers the same lines with the f32 SIMD kernels (lobe::batch) in blocks\n\
         of 4096 lines; numbers parse back to the same f32. It agrees with the default\n\
         f64 path to 1e-4 relative (f, pdf, weight) and 1e-5 absolute (wi).",
        BsdfStrategy::names()
    )
}

fn after_long_help() -> String {
    format!(
        "Examples:\n  \
         echo '{{\"wo\":[0.6,0,0.8],\"wi\":[0,0,1]}}' | lobe eval --material '{{\"type\":\"cook-torrance\",\"alpha\":0.2}}'\n  \
         echo '{{\"wo\":[0.6,0,0.8],\"u\":[0.3,0.7],\"uc\":0.4,\"strategy\":\"vndf\"}}' | lobe eval -m @examples/gold.toml\n  \
         echo '{{\"wo\":[0.6,0,0.8],\"u\":[0.3,0.7],\"uc\":0.4,\"strategy\":\"vndf\"}}' | lobe eval -m @examples/ggx.toml\n\
         \n\
         A TOML material file (examples/gold.toml):\n  \
         type = \"cook-torrance\"\n  \
         alpha = 0.2\n  \
         fresnel = {{ type = \"conductor\" }}\n\
         \n\
         {}",
        lobe::models::defaults()
    )
}

/// Run `lobe eval`: stdin to stdout.
pub fn run(args: &EvalArgs) -> Result<()> {
    let material = crate::common::load_material(&args.material)?;
    let mut out = BufWriter::with_capacity(1 << 16, io::stdout().lock());
    let result = if args.batch {
        crate::eval_batch::process_batch(&material, io::stdin().lock(), &mut out)
    } else {
        process(&material, io::stdin().lock(), &mut out)
    };
    // Flush what was computed before any error, so that the lines before a bad
    // line reach the reader.
    let flushed = out.flush();
    match result {
        Ok(()) => {}
        Err(Failure::Write(e)) if e.kind() == io::ErrorKind::BrokenPipe => return Ok(()),
        Err(Failure::Write(e)) => return Err(anyhow!("cannot write to stdout: {e}")),
        Err(Failure::Line(n, message)) => return Err(anyhow!("stdin line {n}: {message}")),
    }
    match flushed {
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => {
            Err(anyhow!("cannot write to stdout: {e}"))
        }
        _ => Ok(()),
    }
}

/// Why [`process`] stopped.
#[derive(Debug)]
pub enum Failure {
    /// A bad input line (or a result that is not finite), by line number.
    Line(usize, String),
    /// stdout failed (a closed pipe among others).
    Write(io::Error),
}

impl From<io::Error> for Failure {
    fn from(e: io::Error) -> Self {
        Failure::Write(e)
    }
}

/// Answer every line of `input` on `out`.
pub fn process<R: BufRead, W: Write>(
    material: &Material,
    mut input: R,
    out: &mut W,
) -> Result<(), Failure> {
    let strategies = material.strategies();
    // `"name":` for each strategy, written before its pdf.
    let keys: Vec<String> = strategies
        .iter()
        .map(|s| format!("\"{}\":", s.name()))
        .collect();
    let mut pdfs = vec![0.0; strategies.len()];
    let mut line = String::with_capacity(256);
    let mut n = 0usize;
    loop {
        line.clear();
        n += 1;
        match input.read_line(&mut line) {
            Ok(0) => return Ok(()),
            Ok(_) => {}
            Err(e) if e.kind() == io::ErrorKind::InvalidData => {
                return Err(Failure::Line(n, "not valid UTF-8".into()));
            }
            Err(e) => return Err(Failure::Line(n, format!("cannot read stdin: {e}"))),
        }
        let text = line.trim();
        if text.is_empty() {
            continue;
        }
        let request = parse_line(text)
            .and_then(|q| q.check(material, &strategies))
            .map_err(|m| Failure::Line(n, m))?;
        match request {
            Request::Eval { wo, wi, .. } => {
                let f = material.eval(wo, wi);
                if !f.is_finite() {
                    return Err(Failure::Line(
                        n,
                        format!("f is not finite ({f}) for wo {wo} and wi {wi}"),
                    ));
                }
                for (p, &s) in pdfs.iter_mut().zip(&strategies) {
                    *p = material.pdf(s, wo, wi);
                    if !p.is_finite() {
                        return Err(Failure::Line(
                            n,
                            format!(
                                "the pdf of strategy `{s}` is not finite ({p}) for wo {wo} and wi {wi}"
                            ),
                        ));
                    }
                }
                out.write_all(b"{\"f\":")?;
                write_vec3(out, f)?;
                out.write_all(b",\"pdf\":{")?;
                for (i, (key, &p)) in keys.iter().zip(&pdfs).enumerate() {
                    if i > 0 {
                        out.write_all(b",")?;
                    }
                    out.write_all(key.as_bytes())?;
                    write_f64(out, p)?;
                }
                out.write_all(b"}}\n")?;
            }
            Request::Sample {
                strategy,
                wo,
                u,
                uc,
                ..
            } => match material.sample(strategy, wo, uc, u) {
                None => out.write_all(b"{\"wi\":null,\"pdf\":0,\"weight\":[0,0,0]}\n")?,
                Some(s) => {
                    if !(s.wi.is_finite() && s.pdf.is_finite() && s.weight.is_finite()) {
                        return Err(Failure::Line(
                            n,
                            format!(
                                "the sample is not finite (wi {}, pdf {}, weight {})",
                                s.wi, s.pdf, s.weight
                            ),
                        ));
                    }
                    out.write_all(b"{\"wi\":")?;
                    write_vec3(out, s.wi)?;
                    out.write_all(b",\"pdf\":")?;
                    write_f64(out, s.pdf)?;
                    out.write_all(b",\"weight\":")?;
                    write_vec3(out, s.weight)?;
                    out.write_all(b"}\n")?;
                }
            },
        }
    }
}

/// A finite `f64`, shortest form that parses back to the same value.
fn write_f64<W: Write>(out: &mut W, x: f64) -> io::Result<()> {
    x.serialize(&mut serde_json::Serializer::new(out))
        .map_err(io::Error::from)
}

fn write_vec3<W: Write>(out: &mut W, v: DVec3) -> io::Result<()> {
    out.write_all(b"[")?;
    write_f64(out, v.x)?;
    out.write_all(b",")?;
    write_f64(out, v.y)?;
    out.write_all(b",")?;
    write_f64(out, v.z)?;
    out.write_all(b"]")
}

// ---------------------------------------------------------------------------
// Input lines
// ---------------------------------------------------------------------------

/// The keys of an input line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Key {
    Wo,
    Wi,
    U,
    Uc,
    BsdfStrategy,
}

const KEY_NAMES: &str = "wo, wi, u, uc, strategy";

impl Key {
    fn name(self) -> &'static str {
        match self {
            Key::Wo => "wo",
            Key::Wi => "wi",
            Key::U => "u",
            Key::Uc => "uc",
            Key::BsdfStrategy => "strategy",
        }
    }
}

impl<'de> Deserialize<'de> for Key {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Key;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "one of the keys {KEY_NAMES}")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Key, E> {
                Ok(match v {
                    "wo" => Key::Wo,
                    "wi" => Key::Wi,
                    "u" => Key::U,
                    "uc" => Key::Uc,
                    "strategy" => Key::BsdfStrategy,
                    _ => {
                        return Err(E::custom(format_args!(
                            "unknown key {v:?} (the keys are {KEY_NAMES})"
                        )));
                    }
                })
            }
        }
        d.deserialize_identifier(V)
    }
}

/// A JSON number.
struct Num(f64);

impl<'de> Deserialize<'de> for Num {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Num;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Num, E> {
                Ok(Num(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Num, E> {
                Ok(Num(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Num, E> {
                Ok(Num(v as f64))
            }
        }
        d.deserialize_f64(V)
    }
}

/// A JSON array of exactly `N` numbers.
struct Numbers<const N: usize>([f64; N]);

impl<'de, const N: usize> Deserialize<'de> for Numbers<N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<const N: usize>;
        impl<'de, const N: usize> Visitor<'de> for V<N> {
            type Value = Numbers<N>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "an array of {N} numbers")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Numbers<N>, A::Error> {
                let mut a = [0.0; N];
                for (i, slot) in a.iter_mut().enumerate() {
                    *slot = match seq.next_element::<Num>()? {
                        Some(x) => x.0,
                        None => {
                            return Err(de::Error::custom(format_args!(
                                "expected {N} numbers, got {i}"
                            )));
                        }
                    };
                }
                if seq.next_element::<IgnoredAny>()?.is_some() {
                    return Err(de::Error::custom(format_args!(
                        "expected {N} numbers, got more"
                    )));
                }
                Ok(Numbers(a))
            }
        }
        d.deserialize_seq(V::<N>)
    }
}

/// A strategy given by name.
struct StrategyName(BsdfStrategy);

impl<'de> Deserialize<'de> for StrategyName {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = StrategyName;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "a strategy name ({})", BsdfStrategy::names())
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<StrategyName, E> {
                v.parse().map(StrategyName).map_err(|_| {
                    E::custom(format_args!(
                        "unknown strategy {v:?}, expected one of: {}",
                        BsdfStrategy::names()
                    ))
                })
            }
        }
        d.deserialize_str(V)
    }
}

/// One input line, as given.
#[derive(Debug, Default)]
pub(crate) struct Query {
    wo: Option<[f64; 3]>,
    wi: Option<[f64; 3]>,
    u: Option<[f64; 2]>,
    uc: Option<f64>,
    strategy: Option<BsdfStrategy>,
}

/// Parses a line; records in `field` the key whose value is being read, so
/// that an error names it.
struct LineSeed<'a> {
    field: &'a Cell<Option<Key>>,
}

impl<'de> DeserializeSeed<'de> for LineSeed<'_> {
    type Value = Query;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Query, D::Error> {
        d.deserialize_map(self)
    }
}

impl<'de> Visitor<'de> for LineSeed<'_> {
    type Value = Query;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON object with keys among wo, wi, u, uc, strategy")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Query, A::Error> {
        fn twice<E: de::Error>(given: bool) -> Result<(), E> {
            if given {
                Err(E::custom("given twice"))
            } else {
                Ok(())
            }
        }
        let mut q = Query::default();
        while let Some(key) = map.next_key::<Key>()? {
            self.field.set(Some(key));
            match key {
                Key::Wo => {
                    twice(q.wo.is_some())?;
                    q.wo = Some(map.next_value::<Numbers<3>>()?.0);
                }
                Key::Wi => {
                    twice(q.wi.is_some())?;
                    q.wi = Some(map.next_value::<Numbers<3>>()?.0);
                }
                Key::U => {
                    twice(q.u.is_some())?;
                    q.u = Some(map.next_value::<Numbers<2>>()?.0);
                }
                Key::Uc => {
                    twice(q.uc.is_some())?;
                    q.uc = Some(map.next_value::<Num>()?.0);
                }
                Key::BsdfStrategy => {
                    twice(q.strategy.is_some())?;
                    q.strategy = Some(map.next_value::<StrategyName>()?.0);
                }
            }
            self.field.set(None);
        }
        Ok(q)
    }
}

/// Parse one non-empty line; the error names the field where it can.
pub(crate) fn parse_line(text: &str) -> Result<Query, String> {
    let field = Cell::new(None);
    let mut de = serde_json::Deserializer::from_str(text);
    let parsed = LineSeed { field: &field }
        .deserialize(&mut de)
        .and_then(|q| de.end().map(|()| q));
    parsed.map_err(|e| {
        let message = json_message(&e);
        match field.get() {
            Some(key) => format!("field \"{}\": {message}", key.name()),
            None => message,
        }
    })
}

/// A serde_json error without its "at line 1 column N" (every input is one
/// line); syntax errors keep the column.
fn json_message(e: &serde_json::Error) -> String {
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let bare = full.strip_suffix(&suffix).unwrap_or(&full);
    match e.classify() {
        serde_json::error::Category::Syntax | serde_json::error::Category::Eof => {
            format!("invalid JSON: {bare} (column {})", e.column())
        }
        _ => bare.to_string(),
    }
}

/// A checked line. `wo` and `wi` are normalized for the f64 path;
/// `given` holds them as the line gave them (unit within
/// [`UNIT_TOLERANCE`]): the batch path rounds those to f32 as they are, as
/// the Python package does with its arrays, so that both give the same bits
/// (normalizing in f64 first would move some by an f32 ulp).
#[derive(Debug, Clone, Copy)]
pub(crate) enum Request {
    Eval {
        wo: DVec3,
        wi: DVec3,
        given: [[f64; 3]; 2],
    },
    Sample {
        strategy: BsdfStrategy,
        wo: DVec3,
        given_wo: [f64; 3],
        u: DVec2,
        uc: f64,
    },
}

impl Query {
    /// Check the keys present, the vectors and the strategy.
    pub(crate) fn check(
        self,
        material: &Material,
        strategies: &[BsdfStrategy],
    ) -> Result<Request, String> {
        const KINDS: &str = "an eval line has wo and wi; a sample line has wo, u, strategy, and uc where the material has two lobes";
        let given_wo = self
            .wo
            .ok_or_else(|| format!("field \"wo\": missing ({KINDS})"))?;
        let wo = unit_vector(Key::Wo, given_wo)?;
        let Some(strategy) = self.strategy else {
            if self.u.is_some() || self.uc.is_some() {
                let key = if self.u.is_some() { "u" } else { "uc" };
                return Err(format!(
                    "field \"{key}\": only in a sample line, which also needs \"strategy\" ({KINDS})"
                ));
            }
            let given_wi = self
                .wi
                .ok_or_else(|| format!("field \"wi\": missing ({KINDS})"))?;
            let wi = unit_vector(Key::Wi, given_wi)?;
            return Ok(Request::Eval {
                wo,
                wi,
                given: [given_wo, given_wi],
            });
        };
        if self.wi.is_some() {
            return Err(format!(
                "field \"wi\": not allowed in a sample line, which draws wi ({KINDS})"
            ));
        }
        let u = self
            .u
            .ok_or_else(|| format!("field \"u\": missing ({KINDS})"))?;
        for x in u {
            unit_interval(Key::U, x)?;
        }
        if !strategies.contains(&strategy) {
            let reason = match material.check(strategy) {
                Err(e) => e.to_string(),
                Ok(()) => format!("strategy `{strategy}` does not apply to this material"),
            };
            return Err(format!("field \"strategy\": {reason}"));
        }
        let uc = match self.uc {
            Some(uc) => uc,
            None if material.chooses_lobe(strategy) => {
                return Err(format!(
                    "field \"uc\": missing; this material has two lobes (a diffuse term and a glossy lobe) and strategy `{strategy}` chooses between them with uc, so give an independent uniform number in [0, 1) (a fixed uc always takes the same lobe and biases the mean weight)"
                ));
            }
            // Not used: one lobe, or a strategy that does not choose one.
            None => 0.5,
        };
        unit_interval(Key::Uc, uc)?;
        Ok(Request::Sample {
            strategy,
            wo,
            given_wo,
            u: DVec2::from_array(u),
            uc,
        })
    }
}

/// A unit vector to [`UNIT_TOLERANCE`]. One that is off by more than rounding
/// is normalized, so that the core always gets a unit vector.
fn unit_vector(key: Key, v: [f64; 3]) -> Result<DVec3, String> {
    let w = DVec3::from_array(v);
    let len = w.length();
    let name = key.name();
    if !len.is_finite() {
        return Err(format!(
            "field \"{name}\": must be a unit vector, its length is not finite"
        ));
    }
    if len == 0.0 {
        return Err(format!(
            "field \"{name}\": must be a unit vector, it has length zero"
        ));
    }
    if (len - 1.0).abs() > UNIT_TOLERANCE {
        return Err(format!(
            "field \"{name}\": must be a unit vector (to {UNIT_TOLERANCE:e}), its length is {len}"
        ));
    }
    Ok(if (len - 1.0).abs() > 4.0 * f64::EPSILON {
        w / len
    } else {
        w
    })
}

/// `x` of [0, 1) in f32, kept below 1 (rounding to f32 may give 1).
pub(crate) fn unit_interval_f32(x: f64) -> f32 {
    (x as f32).min(1.0 - f32::EPSILON / 2.0)
}

fn unit_interval(key: Key, x: f64) -> Result<(), String> {
    if (0.0..1.0).contains(&x) {
        Ok(())
    } else {
        Err(format!(
            "field \"{}\": {x} is out of range [0, 1)",
            key.name()
        ))
    }
}

// ---------------------------------------------------------------------------
// The material
// ---------------------------------------------------------------------------

#[cfg(test)]
mod tests {
    use super::*;

    fn run_lines(material: &str, input: &str) -> Result<String, String> {
        let m = lobe::Material::load(material).map_err(|e| e.to_string())?;
        let mut out = Vec::new();
        match process(&m, input.as_bytes(), &mut out) {
            Ok(()) => Ok(String::from_utf8(out).unwrap()),
            Err(Failure::Line(n, m)) => Err(format!("stdin line {n}: {m}")),
            Err(Failure::Write(e)) => Err(e.to_string()),
        }
    }

    #[test]
    fn errors_name_line_and_field() {
        let lambert = r#"{"type":"lambert"}"#;
        let e = run_lines(
            lambert,
            "{\"wo\":[0,0,1],\"wi\":[0,0,1]}\n\n{\"wo\":[0,1],\"wi\":[0,0,1]}\n",
        )
        .unwrap_err();
        assert_eq!(e, "stdin line 3: field \"wo\": expected 3 numbers, got 2");
        let e = run_lines(lambert, r#"{"wo":[0,0,1],"wi":[0,0,"a"]}"#).unwrap_err();
        assert_eq!(
            e,
            "stdin line 1: field \"wi\": invalid type: string \"a\", expected a number"
        );
        let e = run_lines(lambert, r#"{"wo":[0,0,1],"w":[0,0,1]}"#).unwrap_err();
        assert!(e.starts_with("stdin line 1: unknown key \"w\""), "{e}");
        let e = run_lines(lambert, r#"{"wo":[0,0,1],"wo":[0,0,1]}"#).unwrap_err();
        assert_eq!(e, "stdin line 1: field \"wo\": given twice");
        let e = run_lines(lambert, r#"{"wo":[0,0,1],"wi":[0,0,1]} x"#).unwrap_err();
        assert!(
            e.starts_with("stdin line 1: invalid JSON: trailing characters"),
            "{e}"
        );
        let e = run_lines(lambert, r#"[1]"#).unwrap_err();
        assert!(e.starts_with("stdin line 1: invalid type: sequence"), "{e}");
    }

    #[test]
    fn numbers_round_trip() {
        let mut v = Vec::new();
        for x in [
            0.1,
            1.0 / 3.0,
            1e-300,
            5e-324,
            1e300,
            f64::MAX,
            0.0,
            -0.0,
            3.0,
        ] {
            v.clear();
            write_f64(&mut v, x).unwrap();
            let back: f64 = serde_json::from_slice(&v).unwrap();
            assert_eq!(
                back.to_bits(),
                x.to_bits(),
                "{}",
                String::from_utf8_lossy(&v)
            );
        }
    }

    #[test]
    fn unit_vectors() {
        assert!(
            unit_vector(Key::Wo, [0.0, 0.0, 1.0 + 9e-7])
                .is_ok_and(|w| (w.length() - 1.0).abs() < 1e-15)
        );
        assert!(unit_vector(Key::Wo, [0.0, 0.0, 1.0 + 2e-6]).is_err());
        assert!(unit_vector(Key::Wo, [0.0, 0.0, 0.0]).is_err());
        assert!(unit_vector(Key::Wo, [1e300, 1e300, 0.0]).is_err());
        let w = [0.6, 0.0, 0.8];
        assert_eq!(unit_vector(Key::Wo, w).unwrap().to_array(), w);
    }

    /// Issue 8: a sample line without `uc` on a two-lobe material is an
    /// error naming the field (it used to default to 0.5, always taking the
    /// same lobe); a single-lobe material, or a strategy that does not
    /// choose a lobe, may omit it.
    #[test]
    fn uc_is_required_where_it_chooses_a_lobe() {
        let two = r#"{"type":"cook-torrance","alpha":0.6,"kd":0.5,"ks":0.5}"#;
        let line = r#"{"wo":[0.5,0,0.8660254037844386],"u":[0.3,0.7],"strategy":"vndf"}"#;
        let e = run_lines(two, line).unwrap_err();
        assert!(e.starts_with("stdin line 1: field \"uc\": missing"), "{e}");
        assert!(e.contains("two lobes"), "{e}");
        let with_uc =
            r#"{"wo":[0.5,0,0.8660254037844386],"u":[0.3,0.7],"uc":0.9,"strategy":"vndf"}"#;
        assert!(run_lines(two, with_uc).is_ok());
        let cosine = r#"{"wo":[0.5,0,0.8660254037844386],"u":[0.3,0.7],"strategy":"cosine"}"#;
        assert!(run_lines(two, cosine).is_ok());
        let one = r#"{"type":"cook-torrance","alpha":0.6}"#;
        assert!(run_lines(one, line).is_ok());
    }
}
