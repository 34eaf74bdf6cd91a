//! Microfacet distributions as a small value type, after pbrt-v4's
//! `TrowbridgeReitzDistribution`: the normal distribution `D`, Smith's
//! `Λ`, `G1`, the three shadowing terms, and the samplers of microfacet
//! normals with their densities.
//!
//! | parameter | range | meaning |
//! |---|---|---|
//! | `ndf` | GGX, Beckmann, Blinn-Phong | the normal distribution |
//! | `alpha_x`, `alpha_y` | [1e-4, 2] (Blinn-Phong: [1e-4, 1]) | widths along the tangent and bitangent; equal for an isotropic surface |
//!
//! The Blinn-Phong NDF is `D = √((eₓ+2)(e_y+2))/(2π) cos^{e(φ)}θ` with
//! `e(φ) = eₓcos²φ + e_y sin²φ` and `e = 2/α² − 2` (Walter et al. 2007; the
//! anisotropic form is Ashikhmin and Shirley's, normalized over projected
//! area). It has no closed-form Smith `Λ`; lobe uses Beckmann's `Λ` at the
//! same `α`, Walter et al.'s approximation. Because that `G` is not exactly
//! the one of its `D`, the Blinn-Phong NDF is not exactly energy conserving:
//! at `α = 0.3` its directional albedo with `F = 1` reaches about 1.02 at 89°.
//!
//! Samplers of the microfacet normal `wm` (densities over `wm` in solid angle):
//! * [`Microfacet::sample_wm`]: `D(wm) cos θm`, the lecture's `p ∝ D cos θ`.
//! * [`Microfacet::sample_visible`]: the visible normals `G1(wo) max(0, wo·wm) D(wm) / cos θo`
//!   (Heitz 2018 for GGX, Heitz and d'Eon 2014 for Beckmann).
//! * [`Microfacet::sample_visible_caps`]: the same distribution by Dupuy and
//!   Benyoub's spherical caps (GGX only).
//! * [`Microfacet::sample_visible_bounded`]: Eto and Tokuyoshi's bounded VNDF
//!   (GGX only); its density is over the *reflected* direction,
//!   [`Microfacet::pdf_reflect_bounded`].
//!
//! Turning a density over `wm` into one over the reflected `wi = 2(wo·wm)wm − wo`
//! takes the Jacobian `|dwm/dwi| = 1/(4 wo·wm)`.

use crate::math::{INV_PI, safe_sqrt};
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// The normal distribution function.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Ndf {
    /// Trowbridge-Reitz, a.k.a. GGX.
    Ggx,
    Beckmann,
    /// Blinn-Phong as a normal distribution, exponent `2/α² − 2`.
    BlinnPhong,
}

impl Ndf {
    pub const ALL: [Ndf; 3] = [Ndf::Ggx, Ndf::Beckmann, Ndf::BlinnPhong];
    pub const NAMES: &'static str = "ggx, beckmann, blinn-phong";

    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Ndf::Ggx => "ggx",
            Ndf::Beckmann => "beckmann",
            Ndf::BlinnPhong => "blinn-phong",
        }
    }
}

impl std::str::FromStr for Ndf {
    type Err = crate::Error;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ndf::ALL
            .into_iter()
            .find(|d| d.name() == s)
            .ok_or_else(|| crate::Error::UnknownName {
                field: "distribution".into(),
                value: s.into(),
                expected: Ndf::NAMES.into(),
            })
    }
}

/// The masking-shadowing term `G(wo, wi, wm)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Shadowing {
    /// `G1(wo) G1(wi)`.
    SmithSeparable,
    /// `1 / (1 + Λ(wo) + Λ(wi))` (Heitz 2014): the better model, and the one
    /// of the published albedo tables.
    SmithCorrelated,
    /// Cook and Torrance's V-cavity term
    /// `min(1, 2 cosθm cosθo / (wo·wm), 2 cosθm cosθi / (wi·wm))`.
    VCavity,
}

impl Shadowing {
    pub const ALL: [Shadowing; 3] = [
        Shadowing::SmithSeparable,
        Shadowing::SmithCorrelated,
        Shadowing::VCavity,
    ];
    pub const NAMES: &'static str = "smith-separable, smith-correlated, v-cavity";

    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Shadowing::SmithSeparable => "smith-separable",
            Shadowing::SmithCorrelated => "smith-correlated",
            Shadowing::VCavity => "v-cavity",
        }
    }
}

impl std::str::FromStr for Shadowing {
    type Err = crate::Error;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Shadowing::ALL
            .into_iter()
            .find(|d| d.name() == s)
            .ok_or_else(|| crate::Error::UnknownName {
                field: "shadowing".into(),
                value: s.into(),
                expected: Shadowing::NAMES.into(),
            })
    }
}

/// A microfacet distribution: which NDF and its two widths.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Microfacet {
    ndf: Ndf,
    alpha_x: f64,
    alpha_y: f64,
    /// `1/αx`, `1/αy` and `1/(π αx αy)`, kept for the hot path.
    inv_ax: f64,
    inv_ay: f64,
    inv_pi_axay: f64,
}

/// Smallest accepted alpha: below it the lobe is a delta that f64 cannot hold.
pub const MIN_ALPHA: f64 = 1e-4;
/// Largest accepted alpha (Blinn-Phong NDF: 1, where its exponent reaches 0).
pub const MAX_ALPHA: f64 = 2.0;

impl Microfacet {
    /// A distribution with widths `alpha_x`, `alpha_y`; refuses widths out of
    /// range or not finite, naming the field.
    pub fn new(ndf: Ndf, alpha_x: f64, alpha_y: f64) -> crate::error::Result<Self> {
        let max = if ndf == Ndf::BlinnPhong {
            1.0
        } else {
            MAX_ALPHA
        };
        for (field, a) in [("alpha_u", alpha_x), ("alpha_v", alpha_y)] {
            if !a.is_finite() || !(MIN_ALPHA..=max).contains(&a) {
                return Err(crate::Error::param(
                    field,
                    format!(
                        "{a} is out of range: alpha must be a number in [{MIN_ALPHA}, {max}] for {}",
                        ndf.name()
                    ),
                ));
            }
        }
        Ok(Microfacet {
            ndf,
            alpha_x,
            alpha_y,
            inv_ax: 1.0 / alpha_x,
            inv_ay: 1.0 / alpha_y,
            inv_pi_axay: INV_PI / (alpha_x * alpha_y),
        })
    }

    #[must_use]
    pub fn ndf(&self) -> Ndf {
        self.ndf
    }

    #[must_use]
    pub fn alpha(&self) -> (f64, f64) {
        (self.alpha_x, self.alpha_y)
    }

    #[must_use]
    pub fn is_isotropic(&self) -> bool {
        self.alpha_x == self.alpha_y
    }

    /// Blinn-Phong exponents `(eₓ, e_y)` for the widths.
    #[inline]
    fn blinn_exponents(&self) -> (f64, f64) {
        (
            2.0 / (self.alpha_x * self.alpha_x) - 2.0,
            2.0 / (self.alpha_y * self.alpha_y) - 2.0,
        )
    }

    /// The normal distribution `D(wm)`, normalized so that `∫ D cosθm dωm = 1`.
    #[inline]
    #[must_use]
    pub fn d(&self, wm: DVec3) -> f64 {
        if wm.z <= 0.0 {
            return 0.0;
        }
        let z2 = wm.z * wm.z;
        let x = wm.x * self.inv_ax;
        let y = wm.y * self.inv_ay;
        match self.ndf {
            Ndf::Ggx => {
                let s = x * x + y * y + z2;
                self.inv_pi_axay / (s * s)
            }
            Ndf::Beckmann => {
                let e = (x * x + y * y) / z2;
                if e > 700.0 {
                    return 0.0;
                }
                (-e).exp() * self.inv_pi_axay / (z2 * z2)
            }
            Ndf::BlinnPhong => {
                let (ex, ey) = self.blinn_exponents();
                let r2 = wm.x * wm.x + wm.y * wm.y;
                let e = if r2 > 0.0 {
                    (ex * wm.x * wm.x + ey * wm.y * wm.y) / r2
                } else {
                    0.5 * (ex + ey)
                };
                self.inv_pi_axay * wm.z.powf(e)
            }
        }
    }

    /// Smith's `Λ(w)`: `G1 = 1/(1 + Λ)`. Infinite at the horizon.
    #[inline]
    #[must_use]
    pub fn lambda(&self, w: DVec3) -> f64 {
        let (ax, ay) = (w.x * self.alpha_x, w.y * self.alpha_y);
        let r2 = ax * ax + ay * ay;
        let z2 = w.z * w.z;
        match self.ndf {
            // Λ = (√(1 + α²tan²θ) − 1)/2 = (‖(αx wx, αy wy, wz)‖/|wz| − 1)/2:
            // one square root and one division (infinite at the horizon).
            Ndf::Ggx => 0.5 * ((r2 + z2).sqrt() / w.z.abs() - 1.0),
            Ndf::Beckmann | Ndf::BlinnPhong => {
                let a2t2 = r2 / z2;
                if !a2t2.is_finite() {
                    return f64::INFINITY;
                }
                if a2t2 == 0.0 {
                    return 0.0;
                }
                let a = 1.0 / a2t2.sqrt();
                // (erf(a) − 1)/2 + exp(−a²)/(2a√π), written with erfc for precision.
                0.5 * ((-a * a).exp() / (a * PI.sqrt()) - libm::erfc(a)).max(0.0)
            }
        }
    }

    /// Smith masking `G1(w) = 1 / (1 + Λ(w))`.
    #[inline]
    #[must_use]
    pub fn g1(&self, w: DVec3) -> f64 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Masking-shadowing `G(wo, wi, wm)` for the chosen term. Both directions
    /// in the upper hemisphere; `wm` their half vector.
    #[inline]
    #[must_use]
    pub fn g(&self, shadowing: Shadowing, wo: DVec3, wi: DVec3, wm: DVec3) -> f64 {
        self.g_with_lambda_o(shadowing, self.lambda(wo), wo, wi, wm)
    }

    /// [`Microfacet::g`] given `lambda_o = Λ(wo)`, for a caller that has it
    /// already (the pdf of visible normals needs it too).
    #[inline]
    #[must_use]
    pub fn g_with_lambda_o(
        &self,
        shadowing: Shadowing,
        lambda_o: f64,
        wo: DVec3,
        wi: DVec3,
        wm: DVec3,
    ) -> f64 {
        match shadowing {
            Shadowing::SmithSeparable => 1.0 / (1.0 + lambda_o) * self.g1(wi),
            Shadowing::SmithCorrelated => 1.0 / (1.0 + lambda_o + self.lambda(wi)),
            Shadowing::VCavity => {
                let go = 2.0 * wm.z * wo.z / wo.dot(wm);
                let gi = 2.0 * wm.z * wi.z / wi.dot(wm);
                1.0f64.min(go).min(gi).max(0.0)
            }
        }
    }

    /// Draw `wm` with density `D(wm) cos θm` (the lecture's sampler).
    #[must_use]
    pub fn sample_wm(&self, u: DVec2) -> DVec3 {
        match self.ndf {
            // Both are stretch-invariant: draw the slope for α = 1, then scale.
            Ndf::Ggx | Ndf::Beckmann => {
                let u1 = u.x.min(1.0 - f64::EPSILON / 2.0);
                let r2 = if self.ndf == Ndf::Ggx {
                    u1 / (1.0 - u1)
                } else {
                    -(-u1).ln_1p()
                };
                let r = r2.sqrt();
                let (s, c) = (2.0 * PI * u.y).sin_cos();
                slope_to_normal(self.alpha_x * r * c, self.alpha_y * r * s)
            }
            Ndf::BlinnPhong => {
                let (ex, ey) = self.blinn_exponents();
                // Marginal of φ ∝ 1/((eₓ+2)cos²φ + (e_y+2)sin²φ):
                // tan φ = √((eₓ+2)/(e_y+2)) tan(2πu₂), kept in u₂'s quadrant.
                let phi = if ex == ey {
                    2.0 * PI * u.y
                } else {
                    let t = 2.0 * PI * u.y;
                    let k = ((ex + 2.0) / (ey + 2.0)).sqrt();
                    let (st, ct) = t.sin_cos();
                    (k * st).atan2(ct)
                };
                let (sp, cp) = phi.sin_cos();
                let e = ex * cp * cp + ey * sp * sp;
                // cos θ = u₁^(1/(e+2)), through logarithms for precision.
                let (cos_t, sin_t) = crate::warp::cos_sin_of_root(u.x, e + 2.0);
                DVec3::new(sin_t * cp, sin_t * sp, cos_t)
            }
        }
    }

    /// Density of [`Microfacet::sample_wm`] over `wm`: `D(wm) cos θm`.
    #[inline]
    #[must_use]
    pub fn pdf_wm(&self, wm: DVec3) -> f64 {
        self.d(wm) * wm.z.max(0.0)
    }

    /// Density of visible normals `G1(wo) max(0, wo·wm) D(wm) / cos θo`.
    #[inline]
    #[must_use]
    pub fn pdf_visible(&self, wo: DVec3, wm: DVec3) -> f64 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        self.g1(wo) * wo.dot(wm).max(0.0) * self.d(wm) / wo.z
    }

    /// Density over the reflected direction `wi` of visible-normal sampling
    /// (Heitz 2018, [`Microfacet::sample_visible`] and the spherical caps),
    /// given `d = D(wm)` at the half vector and `lambda_o = Λ(wo)`:
    /// `pdf_visible / (4 wo·wm)`, which simplifies to
    /// `G1(wo) D(wm) / (4 cos θo)`.
    #[inline]
    #[must_use]
    pub fn pdf_visible_reflect(d: f64, lambda_o: f64, wo: DVec3) -> f64 {
        d * (0.25 / wo.z) / (1.0 + lambda_o)
    }

    /// Draw a visible normal for `wo` (upper hemisphere). GGX: Heitz 2018's
    /// projected-hemisphere construction. Beckmann: Heitz and d'Eon 2014's
    /// slope sampling with a numerical inversion of the slope CDF. Blinn-Phong
    /// NDF: not supported (returns `None`).
    #[must_use]
    pub fn sample_visible(&self, wo: DVec3, u: DVec2) -> Option<DVec3> {
        match self.ndf {
            Ndf::Ggx => Some(self.sample_visible_ggx(wo, u)),
            Ndf::Beckmann => Some(self.sample_visible_beckmann(wo, u)),
            Ndf::BlinnPhong => None,
        }
    }

    fn stretch(&self, w: DVec3) -> DVec3 {
        DVec3::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize()
    }

    fn unstretch_normal(&self, h: DVec3) -> DVec3 {
        DVec3::new(self.alpha_x * h.x, self.alpha_y * h.y, h.z.max(1e-300)).normalize()
    }

    fn sample_visible_ggx(&self, wo: DVec3, u: DVec2) -> DVec3 {
        let wh = self.stretch(wo);
        // Orthonormal basis around the stretched view direction.
        let len2 = wh.x * wh.x + wh.y * wh.y;
        let t1 = if len2 > 0.0 {
            DVec3::new(-wh.y, wh.x, 0.0) * (1.0 / len2.sqrt())
        } else {
            DVec3::X
        };
        let t2 = wh.cross(t1);
        // A point on the unit disk, warped onto the projected visible half.
        let r = u.x.sqrt();
        let (s, c) = (2.0 * PI * u.y).sin_cos();
        let p1 = r * c;
        let mut p2 = r * s;
        let h = 0.5 * (1.0 + wh.z);
        p2 = (1.0 - h) * safe_sqrt(1.0 - p1 * p1) + h * p2;
        let nh = p1 * t1 + p2 * t2 + safe_sqrt(1.0 - p1 * p1 - p2 * p2) * wh;
        self.unstretch_normal(nh)
    }

    fn sample_visible_beckmann(&self, wo: DVec3, u: DVec2) -> DVec3 {
        let wi = self.stretch(wo);
        let (cos_phi, sin_phi) = crate::math::cos_sin_phi(wi);
        let (sx, sy) = beckmann_visible_slope_11(wi.z.clamp(-1.0, 1.0), u);
        // Rotate the slope from the frame where wi lies in the xz plane, then stretch.
        let x = cos_phi * sx - sin_phi * sy;
        let y = sin_phi * sx + cos_phi * sy;
        slope_to_normal(self.alpha_x * x, self.alpha_y * y)
    }

    /// Dupuy and Benyoub 2023: a visible normal of GGX as the sum of the
    /// stretched view direction and a uniform point on a spherical cap.
    /// Same distribution as [`Microfacet::sample_visible`] for GGX.
    #[must_use]
    pub fn sample_visible_caps(&self, wo: DVec3, u: DVec2) -> DVec3 {
        let wh = self.stretch(wo);
        self.cap_normal(wh, wh.z, u)
    }

    /// `k(wo)` of the bounded VNDF: how much of the spherical cap is kept.
    #[inline]
    fn bounded_k(&self, wo: DVec3) -> f64 {
        let a = self.alpha_x.min(self.alpha_y).clamp(0.0, 1.0);
        let s = 1.0 + (wo.x * wo.x + wo.y * wo.y).sqrt();
        let (a2, s2) = (a * a, s * s);
        (1.0 - a2) * s2 / (s2 + a2 * wo.z * wo.z)
    }

    /// Eto and Tokuyoshi 2023, "Bounded VNDF sampling for Smith-GGX
    /// reflections": sample a smaller spherical cap that leaves out most of
    /// the normals whose reflection falls below the horizon. GGX only; the
    /// density of the reflected direction is [`Microfacet::pdf_reflect_bounded`].
    #[must_use]
    pub fn sample_visible_bounded(&self, wo: DVec3, u: DVec2) -> DVec3 {
        let wh = self.stretch(wo);
        let b = if wo.z > 0.0 {
            self.bounded_k(wo) * wh.z
        } else {
            wh.z
        };
        self.cap_normal(wh, b, u)
    }

    /// The spherical-cap construction of Dupuy and Benyoub, shared by
    /// [`Microfacet::sample_visible_caps`] (`b = wh.z`) and the bounded VNDF
    /// (a smaller `b`): a uniform point on the cap `z ∈ [−b, 1]` of the unit
    /// sphere plus the stretched view direction `wh`, unstretched into a
    /// microfacet normal.
    #[inline]
    fn cap_normal(&self, wh: DVec3, b: f64, u: DVec2) -> DVec3 {
        let phi = 2.0 * PI * u.x;
        let z = (1.0 - u.y) * (1.0 + b) - b;
        let sin_t = safe_sqrt(1.0 - z * z);
        let (s, c) = phi.sin_cos();
        let h = DVec3::new(sin_t * c, sin_t * s, z) + wh;
        self.unstretch_normal(h)
    }

    /// Density over the reflected direction `wi` of bounded VNDF sampling
    /// (`wo`, `wi` in the upper hemisphere).
    #[must_use]
    pub fn pdf_reflect_bounded(&self, wo: DVec3, wi: DVec3) -> f64 {
        self.pdf_reflect_bounded_d(self.d((wo + wi).normalize_or_zero()), wo)
    }

    /// [`Microfacet::pdf_reflect_bounded`] given `d`, `D` at the half vector
    /// of `wo` and `wi` (for callers that have it).
    #[must_use]
    pub fn pdf_reflect_bounded_d(&self, d: f64, wo: DVec3) -> f64 {
        let ax = self.alpha_x * wo.x;
        let ay = self.alpha_y * wo.y;
        let len2 = ax * ax + ay * ay;
        let t = (len2 + wo.z * wo.z).sqrt();
        if wo.z >= 0.0 {
            d / (2.0 * (self.bounded_k(wo) * wo.z + t))
        } else {
            d * (t - wo.z) / (2.0 * len2)
        }
    }
}

/// The unit normal of the microfacet with slopes `(x, y)`: `(−x, −y, 1)/‖·‖`.
#[inline]
fn slope_to_normal(x: f64, y: f64) -> DVec3 {
    DVec3::new(-x, -y, 1.0).normalize()
}

/// Visible slopes of the Beckmann distribution with α = 1 for a direction in
/// the xz plane with `cos θ = cos_theta` (Heitz and d'Eon 2014).
///
/// The slope `x̃` along the view azimuth has density ∝ `(1 − x̃ tanθ) e^{−x̃²}`
/// on `x̃ < cotθ`; its CDF in the variable `b = erf(x̃)` is
/// `(1 + b + tanθ e^{−x̃²}/√π) / (1 + erf(cotθ) + tanθ e^{−cot²θ}/√π)`,
/// with derivative ∝ `1 − x̃ tanθ`. It is inverted by Newton's method kept
/// inside a bisection bracket. The slope `ỹ` is an independent Gaussian.
pub(crate) fn beckmann_visible_slope_11(cos_theta: f64, u: DVec2) -> (f64, f64) {
    let u1 = u.x.clamp(1e-12, 1.0 - 1e-12);
    let u2 = u.y.clamp(1e-12, 1.0 - 1e-12);
    let sy = erf_inv(2.0 * u2 - 1.0);
    if cos_theta > 1.0 - 1e-12 {
        // Normal incidence: the ordinary Gaussian slopes.
        return (erf_inv(2.0 * u1 - 1.0), sy);
    }
    let sin_theta = safe_sqrt(1.0 - cos_theta * cos_theta);
    let tan_t = sin_theta / cos_theta;
    let cot_t = cos_theta / sin_theta;
    let inv_sqrt_pi = 1.0 / PI.sqrt();
    let c = libm::erf(cot_t);
    let norm = 1.0 / (1.0 + c + inv_sqrt_pi * tan_t * (-cot_t * cot_t).exp());
    // Newton's method on the slope itself, kept inside a bisection bracket:
    // one erf and one exp per step. Below -8 the CDF is under 1e-27·tanθ.
    let (mut lo, mut hi) = (-8.0f64, cot_t);
    let two_inv_sqrt_pi = 2.0 * inv_sqrt_pi;
    let mut x = erf_inv_estimate(2.0 * u1 - 1.0).clamp(lo, hi);
    for _ in 0..100 {
        let e = (-x * x).exp();
        let value = norm * (1.0 + libm::erf(x) + inv_sqrt_pi * tan_t * e) - u1;
        if value.abs() < 1e-14 {
            break;
        }
        if value > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let deriv = norm * two_inv_sqrt_pi * e * (1.0 - x * tan_t);
        let next = x - value / deriv;
        x = if next > lo && next < hi && next.is_finite() {
            next
        } else {
            0.5 * (lo + hi)
        };
        if hi - lo < 1e-14 {
            break;
        }
    }
    (x, sy)
}

/// Inverse error function in f64: Giles' approximation refined by Newton
/// steps on `libm::erf`.
#[must_use]
pub fn erf_inv(y: f64) -> f64 {
    if y <= -1.0 {
        return f64::NEG_INFINITY;
    }
    if y >= 1.0 {
        return f64::INFINITY;
    }
    let mut x = erf_inv_estimate(y);
    let two_over_sqrt_pi = 2.0 / PI.sqrt();
    for _ in 0..3 {
        let err = libm::erf(x) - y;
        let d = two_over_sqrt_pi * (-x * x).exp();
        if d == 0.0 {
            break;
        }
        x -= err / d;
    }
    x
}

/// Giles' single-precision approximation of the inverse error function
/// (M. Giles, "Approximating the erfinv function"), about 1e-7 accurate.
fn erf_inv_estimate(y: f64) -> f64 {
    let w = -((1.0 - y) * (1.0 + y)).ln();
    if w < 5.0 {
        let w = w - 2.5;
        let mut p = 2.810_226_36e-08;
        p = 3.432_739_39e-07 + p * w;
        p = -3.523_387_7e-06 + p * w;
        p = -4.391_506_54e-06 + p * w;
        p = 0.000_218_580_87 + p * w;
        p = -0.001_253_725_03 + p * w;
        p = -0.004_177_681_64 + p * w;
        p = 0.246_640_727 + p * w;
        p = 1.501_409_41 + p * w;
        p * y
    } else {
        let w = w.sqrt() - 3.0;
        let mut p = -0.000_200_214_257;
        p = 0.000_100_950_558 + p * w;
        p = 0.001_349_343_22 + p * w;
        p = -0.003_673_428_44 + p * w;
        p = 0.005_739_507_73 + p * w;
        p = -0.007_622_461_3 + p * w;
        p = 0.009_438_870_47 + p * w;
        p = 1.001_674_06 + p * w;
        p = 2.832_976_82 + p * w;
        p * y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erf_inv_inverts_erf() {
        for i in -999..=999 {
            let y = i as f64 / 1000.0;
            let x = erf_inv(y);
            assert!((libm::erf(x) - y).abs() < 1e-14, "{y}");
        }
    }

    #[test]
    fn refuses_bad_alpha() {
        assert!(Microfacet::new(Ndf::Ggx, -0.1, 0.1).is_err());
        assert!(Microfacet::new(Ndf::Ggx, f64::NAN, 0.1).is_err());
        assert!(Microfacet::new(Ndf::BlinnPhong, 1.2, 0.1).is_err());
        assert!(Microfacet::new(Ndf::Beckmann, 0.3, 0.2).is_ok());
    }

    #[test]
    fn ggx_lambda_known_value() {
        // α tanθ = 1: Λ = (√2 − 1)/2.
        let m = Microfacet::new(Ndf::Ggx, 0.5, 0.5).unwrap();
        let w = DVec3::new(2.0, 0.0, 1.0).normalize();
        assert!((m.lambda(w) - 0.5 * (2f64.sqrt() - 1.0)).abs() < 1e-14);
    }
}
