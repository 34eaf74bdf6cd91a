//! Mitsuba 3's `roughconductor`: lobe's Cook-Torrance model under
//! Mitsuba's name, keys and defaults.
//!
//! | parameter | range | default | meaning |
//! |---|---|---|---|
//! | `distribution` | `ggx`, `beckmann` | `beckmann` | the NDF `D` (Mitsuba's default) |
//! | `alpha` | [1e-4, 2] | 0.1 | width of `D` |
//! | `alpha_u` | [1e-4, 2] | `alpha` | width along the tangent; with `alpha_v`, instead of `alpha` (anisotropic) |
//! | `alpha_v` | [1e-4, 2] | `alpha` | width along the bitangent |
//! | `material` | `none` or a conductor's name (`Au`, `Ag`, `Cu`, `Al`, `Cr`, ...) | `none` | a named conductor's RGB `eta`, `k` (Mitsuba's data); `none` reflects everything (`F = 1`) |
//! | `eta` | RGB ≥ 0 | `material`'s, else 0 | real part of the conductor's index; with or without `k`, instead of `material` |
//! | `k` | RGB ≥ 0 | `material`'s, else 1 | imaginary part of the conductor's index (absorption) |
//! | `specular_reflectance` | RGB in [0, 1] | 1 | multiplies the reflected part (not physical; Mitsuba's) |
//! | `sample_visible` | bool | true | Mitsuba's switch; lobe takes the strategy from each call instead, so only `true` is accepted |
//! | `multiscatter` | `none`, `kulla-conty`, `turquin` | `none` | energy compensation for the light that bounces between microfacets ([`crate::energy::compensation`]; GGX or Beckmann with a Smith term; not a Mitsuba key, and `none` is Mitsuba's lobe) |
//!
//! (This table is [`PARAMS`]; a test checks that they agree.)
//!
//! The same lobe as `cook-torrance` with `shadowing = smith-separable`
//! (Mitsuba's `G1(wo) G1(wi)`), `ks = specular_reflectance` and a
//! conductor's Fresnel term (`none` for `material = none`).

#[cfg(feature = "desc")]
use super::keys;
use super::keys::{ETA, K, MATERIAL, SPECULAR_REFLECTANCE};
use super::roughdielectric::{
    DISTRIBUTION, MITSUBA_ALPHA, MITSUBA_ALPHA_U, MITSUBA_ALPHA_V, SAMPLE_VISIBLE,
};
use super::{ModelInfo, Param};

/// The keys of Mitsuba's `roughconductor`.
pub const PARAMS: &[Param] = &[
    DISTRIBUTION,
    MITSUBA_ALPHA,
    MITSUBA_ALPHA_U,
    MITSUBA_ALPHA_V,
    MATERIAL,
    ETA,
    K,
    SPECULAR_REFLECTANCE,
    SAMPLE_VISIBLE,
    super::keys::MULTISCATTER,
];

pub const INFO: ModelInfo = ModelInfo {
    name: "roughconductor",
    params: PARAMS,
    #[cfg(feature = "desc")]
    from_desc,
};

#[cfg(feature = "desc")]
fn from_desc(d: &crate::desc::MaterialDesc) -> crate::error::Result<super::Lobes> {
    let mf = super::roughdielectric::mitsuba_microfacet(d, DISTRIBUTION, MITSUBA_ALPHA)?;
    let lobe = super::CookTorrance::new(
        keys::checked_colour(d.specular_reflectance, SPECULAR_REFLECTANCE)?,
        mf,
        crate::Shadowing::SmithSeparable,
        keys::conductor_fresnel(d)?,
    )?
    .with_multiscatter(keys::multiscatter(d)?)?;
    Ok(super::Lobes::only(super::Glossy::CookTorrance(lobe)))
}
