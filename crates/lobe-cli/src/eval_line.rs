//! One input line of `lobe eval` (and `lobe eval --batch`): its keys, the
//! hand-written serde visitor that reads it without allocating, the checks
//! against the material, and why answering stopped ([`Failure`]).

use glam::{DVec2, DVec3};
use lobe::{BsdfStrategy, Material};
use serde::Deserialize;
use serde::de::{self, DeserializeSeed, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};
use std::cell::Cell;
use std::fmt;
use std::io;

/// How far from 1 the length of `wo` or `wi` may be.
pub const UNIT_TOLERANCE: f64 = 1e-6;

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
}
