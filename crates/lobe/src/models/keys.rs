//! Keys that several models share, under Mitsuba 3's names and with its
//! defaults (the glass, conductor and plastic models are named after its
//! plugins and read the dicts a Mitsuba user writes).

use super::{Param, Range, Value};
#[cfg(feature = "desc")]
use crate::math::Rgb;

pub const INT_IOR: Param = Param {
    name: "int_ior",
    range: Range::Ior,
    note: "",
    default: Value::Name("bk7"),
    meaning: "index of refraction inside (below the surface); `bk7` is 1.5046",
};
pub const EXT_IOR: Param = Param {
    name: "ext_ior",
    range: Range::Ior,
    note: "",
    default: Value::Name("air"),
    meaning: "index of refraction outside (above the surface); `air` is 1.000277",
};
pub const SPECULAR_REFLECTANCE: Param = Param {
    name: "specular_reflectance",
    range: Range::Colour { max: 1.0 },
    note: "",
    default: Value::Number(1.0),
    meaning: "multiplies the reflected part (not physical; Mitsuba's)",
};
pub const SPECULAR_TRANSMITTANCE: Param = Param {
    name: "specular_transmittance",
    range: Range::Colour { max: 1.0 },
    note: "",
    default: Value::Number(1.0),
    meaning: "multiplies the transmitted part (not physical; Mitsuba's)",
};
pub const MODE: Param = Param {
    name: "mode",
    range: Range::Names(crate::transport::TransportMode::NAMES),
    note: "",
    default: Value::Name("radiance"),
    meaning: "what is carried: radiance scales refraction by `(η_i/η_t)²`, importance does not (not a Mitsuba key: its context says)",
};
pub const MULTISCATTER: Param = Param {
    name: "multiscatter",
    range: Range::Names(crate::energy::Compensation::NAMES),
    note: "",
    default: Value::Name("none"),
    meaning: "energy compensation for the light that bounces between microfacets ([`crate::energy::compensation`]; GGX or Beckmann with a Smith term; not a Mitsuba key, and `none` is Mitsuba's lobe)",
};
pub const MATERIAL: Param = Param {
    name: "material",
    range: Range::Conductor,
    note: "",
    default: Value::Name("none"),
    meaning: "a named conductor's RGB `eta`, `k` (Mitsuba's data); `none` reflects everything (`F = 1`)",
};
pub const ETA: Param = Param {
    name: "eta",
    range: Range::Colour { max: f64::INFINITY },
    note: "",
    default: Value::Text("`material`'s, else 0"),
    meaning: "real part of the conductor's index; with or without `k`, instead of `material`",
};
pub const K: Param = Param {
    name: "k",
    range: Range::Colour { max: f64::INFINITY },
    note: "",
    default: Value::Text("`material`'s, else 1"),
    meaning: "imaginary part of the conductor's index (absorption)",
};

/// `η = int_ior / ext_ior` of a description, each at `int`'s and `ext`'s
/// default when absent; the error names the key.
#[cfg(feature = "desc")]
pub(crate) fn relative_ior(
    d: &crate::desc::MaterialDesc,
    int: Param,
    ext: Param,
) -> crate::error::Result<f64> {
    let read = |v: &Option<crate::desc::Ior>, p: Param| match v {
        Some(ior) => ior.value(p.name),
        None => match p.default {
            Value::Name(n) => crate::ior::dielectric(p.name, n),
            Value::Number(x) => Ok(x),
            _ => unreachable!("an index's default is a name or a number"),
        },
    };
    Ok(read(&d.int_ior, int)? / read(&d.ext_ior, ext)?)
}

/// The transport mode of a description (`mode`), radiance when absent.
#[cfg(feature = "desc")]
pub(crate) fn mode(d: &crate::desc::MaterialDesc) -> crate::error::Result<crate::TransportMode> {
    d.mode.as_deref().unwrap_or(MODE.default.name()).parse()
}

/// The key `multiscatter`, `none` when absent.
#[cfg(feature = "desc")]
pub(crate) fn multiscatter(
    d: &crate::desc::MaterialDesc,
) -> crate::error::Result<crate::energy::Compensation> {
    d.multiscatter
        .as_deref()
        .unwrap_or(MULTISCATTER.default.name())
        .parse()
}

/// A conductor's Fresnel term from `material` or `eta` and `k` (or lobe's
/// `fresnel` object), `F = 1` for `material = none`, the default.
#[cfg(feature = "desc")]
pub(crate) fn conductor_fresnel(
    d: &crate::desc::MaterialDesc,
) -> crate::error::Result<crate::Fresnel> {
    use crate::desc::Nested;
    use crate::{Error, Fresnel};
    let given = [
        d.material.is_some(),
        d.eta.is_some() || d.k.is_some(),
        d.fresnel.is_some(),
    ];
    if given.iter().filter(|&&g| g).count() > 1 {
        return Err(Error::param(
            "material",
            "give only one of material, eta/k, fresnel",
        ));
    }
    if let Some(f) = &d.fresnel {
        return f.build();
    }
    match (&d.material, d.eta, d.k) {
        (None, None, None) => Ok(Fresnel::None),
        (Some(Nested::Name(n)), ..) if n == "none" => Ok(Fresnel::None),
        (Some(Nested::Name(n)), ..) => {
            let (eta, k) = crate::ior::conductor("material", n)?;
            Ok(Fresnel::Conductor { eta, k })
        }
        (Some(Nested::Material(_)), ..) => Err(Error::param(
            "material",
            "a conductor's material is a name (Au, Ag, Cu, ...), not a nested material",
        )),
        // Mitsuba's defaults: `eta` 0, `k` 1 (so `k` alone is a mirror's).
        (None, eta, k) => {
            let eta = crate::math::check_rgb(
                "eta",
                eta.map_or(Rgb::ZERO, crate::desc::Color::rgb),
                f64::MAX,
            )?;
            let k =
                crate::math::check_rgb("k", k.map_or(Rgb::ONE, crate::desc::Color::rgb), f64::MAX)?;
            if (0..3).any(|i| eta[i] == 0.0 && k[i] == 0.0) {
                return Err(Error::param(
                    "k",
                    "eta and k are both 0 in a channel: not a conductor",
                ));
            }
            Ok(Fresnel::Conductor { eta, k })
        }
    }
}

/// A colour key of a description, or its default, checked against its range.
#[cfg(feature = "desc")]
pub(crate) fn checked_colour(c: Option<crate::desc::Color>, p: Param) -> crate::error::Result<Rgb> {
    p.check_colour(super::colour(c, p), None)
}
