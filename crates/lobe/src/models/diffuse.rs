//! Mitsuba 3's `diffuse`: lobe's Lambertian model under Mitsuba's name,
//! key and default.
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `reflectance` | RGB in [0, 1] | 0.5 | fraction of light reflected, from every direction |
//!
//! (This table is [`PARAMS`]; a test checks that they agree.)
//!
//! The same material as `{"type": "lambert", "albedo": reflectance}`.

use super::{ModelInfo, Param, Range, Value};

pub const REFLECTANCE: Param = Param {
    name: "reflectance",
    range: Range::Colour { max: 1.0 },
    note: "",
    default: Value::Number(0.5),
    meaning: "fraction of light reflected, from every direction",
};

/// The keys of Mitsuba's `diffuse`.
pub const PARAMS: &[Param] = &[REFLECTANCE];

pub const INFO: ModelInfo = ModelInfo {
    name: "diffuse",
    params: PARAMS,
    #[cfg(feature = "desc")]
    from_desc,
};

#[cfg(feature = "desc")]
fn from_desc(d: &crate::desc::MaterialDesc) -> crate::error::Result<super::Lobes> {
    let albedo = super::keys::checked_colour(d.reflectance, REFLECTANCE)?;
    Ok(super::Lobes {
        diffuse: super::Lambert { albedo },
        glossy: super::Glossy::None,
        two_sided: false,
    })
}
