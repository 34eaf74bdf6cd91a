//! Small math helpers shared by the models: RGB values, trigonometry in the
//! local frame, reflection.

use glam::DVec3;
use std::f64::consts::PI;

/// Linear RGB triple. A `DVec3` so that it carries glam's arithmetic.
pub type Rgb = DVec3;

pub const INV_PI: f64 = 1.0 / PI;
pub const INV_TWO_PI: f64 = 0.5 / PI;
pub const INV_FOUR_PI: f64 = 0.25 / PI;

/// Rec. 709 luminance of a linear RGB value.
#[inline]
#[must_use]
pub fn luminance(c: Rgb) -> f64 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// `sqrt(max(x, 0))`: never a NaN from a tiny negative rounding error.
#[inline]
#[must_use]
pub fn safe_sqrt(x: f64) -> f64 {
    x.max(0.0).sqrt()
}

/// `acos` with its argument clamped to [-1, 1].
#[inline]
#[must_use]
pub fn safe_acos(x: f64) -> f64 {
    x.clamp(-1.0, 1.0).acos()
}

/// Mirror `w` about the unit axis `n`: `2 (w·n) n − w`.
///
/// This is pbrt's convention (both vectors point away from the surface), the
/// opposite of glam's `reflect`, which takes an incident direction.
#[inline]
#[must_use]
pub fn reflect(w: DVec3, n: DVec3) -> DVec3 {
    2.0 * w.dot(n) * n - w
}

/// Mirror direction about the shading normal `+z`.
#[inline]
#[must_use]
pub fn mirror_z(w: DVec3) -> DVec3 {
    DVec3::new(-w.x, -w.y, w.z)
}

/// `(cos φ, sin φ)` of a direction, `(1, 0)` at the pole.
#[inline]
#[must_use]
pub fn cos_sin_phi(w: DVec3) -> (f64, f64) {
    let r2 = w.x * w.x + w.y * w.y;
    if r2 <= 0.0 {
        (1.0, 0.0)
    } else {
        let inv = 1.0 / r2.sqrt();
        ((w.x * inv).clamp(-1.0, 1.0), (w.y * inv).clamp(-1.0, 1.0))
    }
}

/// `true` when `w` is a unit vector to `1e-6` (for debug assertions).
#[inline]
#[must_use]
pub fn is_unit(w: DVec3) -> bool {
    (w.length_squared() - 1.0).abs() < 1e-6
}

/// Check an RGB parameter: every channel finite and in `[0, max]`.
pub(crate) fn check_rgb(field: &str, c: Rgb, max: f64) -> crate::error::Result<Rgb> {
    for v in c.to_array() {
        if !v.is_finite() || v < 0.0 || v > max {
            return Err(crate::Error::param(
                field,
                format!("{v} is out of range: each channel must be a number in [0, {max}]"),
            ));
        }
    }
    Ok(c)
}
