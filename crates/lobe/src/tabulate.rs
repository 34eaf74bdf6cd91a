//! Tabulate a material as a measured BRDF file: a MERL `.binary` table or
//! an isotropic RGL `.bsdf` file ([`crate::models::measured`] reads both),
//! so that lobe's analytic models can be carried to other renderers
//! (Mitsuba 3's `measured` plugin reads the RGL files written here).

use crate::Material;
use crate::models::measured::{merl::Merl, rgl::Rgl};
use glam::DVec3;

/// The format of a tabulated file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// MERL `.binary`: 90 × 90 × 180 (θh, θd, φd) RGB doubles, `f` at each
    /// entry's centre; entries whose centre is below the horizon are
    /// written as missing (−1).
    Merl,
    /// RGL `.bsdf` (isotropic, RGB): `f cos θi` on the sample grid of a
    /// visible-normal warp built from the material, at [`RglResolution`].
    Rgl(RglResolution),
}

/// The resolution of a tabulated RGL file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RglResolution {
    /// View elevations, uniform in `[0, 89°]`.
    pub n_theta: usize,
    /// The sample grid is `n × n`.
    pub n: usize,
}

impl Default for RglResolution {
    /// 16 views, a 64 × 64 grid (about 1.3 MB).
    fn default() -> Self {
        RglResolution { n_theta: 16, n: 64 }
    }
}

impl std::str::FromStr for Format {
    type Err = crate::Error;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "merl" => Ok(Format::Merl),
            "rgl" => Ok(Format::Rgl(RglResolution::default())),
            other => Err(crate::Error::UnknownName {
                field: "format".into(),
                value: other.into(),
                expected: "merl, rgl".into(),
            }),
        }
    }
}

/// The MERL table of `m`: `f(wo, wi)` at every entry's centre.
#[must_use]
pub fn merl_table(m: &Material) -> Merl {
    Merl::from_fn(|wo, wi| m.eval(wo, wi), |_| false)
}

/// The bytes of the file of `m` in `format`.
#[must_use]
pub fn to_bytes(m: &Material, format: Format) -> Vec<u8> {
    let f = |wo: DVec3, wi: DVec3| m.eval(wo, wi);
    match format {
        Format::Merl => merl_table(m).to_bytes(),
        Format::Rgl(r) => Rgl::write(
            f,
            r.n_theta.max(2),
            r.n.max(2),
            &format!("tabulated by lobe from a {} material", m.model_name()),
        ),
    }
}

/// Write the file of `m` in `format` to `path`; returns its size in bytes.
pub fn write(m: &Material, format: Format, path: &std::path::Path) -> crate::error::Result<usize> {
    let bytes = to_bytes(m, format);
    std::fs::write(path, &bytes)
        .map_err(|e| crate::Error::file(path.display(), format!("cannot write: {e}")))?;
    Ok(bytes.len())
}
