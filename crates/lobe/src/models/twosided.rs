//! Two-sided: an opaque material seen from both sides alike (Mitsuba 3's
//! `twosided`).
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `bsdf` | a material description | — | the material (required; or under the key `material`, as Mitsuba's examples write it) |
//! | `material` | a material description | — | the same, under Mitsuba's key |
//!
//! (This table is [`PARAMS`]; a test checks that they agree.)
//!
//! Seen from below the surface (`wo.z < 0`), `wo` and `wi` are mirrored
//! through it before the material sees them, so the back is the front.
//! The material must be opaque (glass has two sides already) and not
//! two-sided itself. Mitsuba's form with two different materials, front
//! and back, is not supported (an error says so).

use super::{ModelInfo, Param, Range, Value};

pub const BSDF: Param = Param {
    name: "bsdf",
    range: Range::Material,
    note: "",
    default: Value::Text("—"),
    meaning: "the material (required; or under the key `material`, as Mitsuba's examples write it)",
};
pub const MATERIAL: Param = Param {
    name: "material",
    meaning: "the same, under Mitsuba's key",
    ..BSDF
};

/// The keys of `twosided`.
pub const PARAMS: &[Param] = &[BSDF, MATERIAL];

pub const INFO: ModelInfo = ModelInfo {
    name: "twosided",
    params: PARAMS,
    #[cfg(feature = "desc")]
    from_desc,
};

#[cfg(feature = "desc")]
fn from_desc(d: &crate::desc::MaterialDesc) -> crate::error::Result<super::Lobes> {
    use crate::Error;
    use crate::desc::Nested;
    let (field, nested) = match (&d.bsdf, &d.material) {
        (Some(b), None) => ("bsdf", b.as_ref()),
        (None, Some(Nested::Material(m))) => ("material", m.as_ref()),
        (None, Some(Nested::Name(n))) => {
            return Err(Error::param(
                "material",
                format!("twosided needs a nested material object, not the name `{n}`"),
            ));
        }
        (Some(_), Some(_)) => {
            return Err(Error::param(
                "material",
                "a second nested material (Mitsuba's front and back): lobe's twosided takes one, the same on both sides",
            ));
        }
        (None, None) => return Err(Error::param("bsdf", "missing: twosided needs the material it wraps")),
    };
    if nested.kind == INFO.name {
        return Err(Error::param(field, "twosided around twosided: it has two sides already"));
    }
    let mut nested = nested.clone();
    if nested.base.is_none() {
        nested.base.clone_from(&d.base);
    }
    let m = nested
        .build()
        .map_err(|e| Error::Parse(format!("field `{field}`: {e}")))?
        .two_sided()
        .map_err(|e| match e {
            Error::Param { message, .. } => Error::Param {
                field: field.into(),
                message,
            },
            e => e,
        })?;
    Ok(super::Lobes {
        diffuse: m.diffuse,
        glossy: m.glossy,
        two_sided: true,
    })
}
