//! The rough dielectric kernel: GGX (isotropic or anisotropic), visible
//! normals, reflection and refraction through the generalized half vector
//! (Walter et al. 2007), as `crate::models::RoughDielectric` computes them
//! in f64, seen from either side.
//!
//! Everything is computed on `wo`'s side: with `s = sign(wo.z)`, `up = s wo`
//! and `wi↑ = s wi` (a view from inside is the same algebra with the
//! relative index `η_s = 1/η`), the microfacet normal `m` has `m.z > 0`,
//! `c_o = up·m > 0`, and with `D`, Smith's separable `G1`, Fresnel
//! `F = F(c_o, η_s)`:
//! * reflection: `f = kr F D G1(up) G1(wi) / (4 up.z |wi.z|)`,
//!   `pdf = F D G1(up) / (4 up.z)`, `weight = kr G1(wi)`;
//! * refraction, `c_i = wi↑·m < 0`, `d = c_o + η_s c_i`:
//!   `f = kt (1 − F) D G1(up) G1(wi) |c_o c_i| / (up.z |wi.z| d²)` (times
//!   `η_s²` in importance mode), `pdf = D G1(up) c_o / up.z · (1 − F) η_s²
//!   |c_i| / d²`, `weight = kt G1(wi) / η_s²` (`kt G1(wi)` in importance
//!   mode).
//!
//! `sample` chooses reflection where `uc < F` (always under total internal
//! reflection), as the scalar path does.

use super::caps::cap_normal;
use super::{
    BECKMANN, BRDF, CAPS, COSINE, CtParams, GGX, INV_PI, INV_TWO_PI, Sampled, UNIFORM, V3, VNDF,
    beckmann_lambda1, beckmann_vndf_normal, cosine_hemisphere, dot, finish, ggx_vndf_normal,
    select3, stretched_len,
};
use crate::batch::lanes::Lanes;
use crate::batch::math::{exp, log1p, sincos_turns};

/// A rough dielectric in f32, as the kernel reads it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DielectricParams {
    /// The microfacets: `ax`, `ay`, `inv_pi_axay` (the rest unused).
    pub ct: CtParams,
    /// Relative index `η` (inside over outside) and its reciprocal.
    pub eta: f32,
    pub inv_eta: f32,
    /// `specular_reflectance`, `specular_transmittance` per channel.
    pub kr: [f32; 3],
    pub kt: [f32; 3],
    /// Importance transport: refraction keeps `η_s²` in `f`.
    pub importance: bool,
}

/// Smith's `G1` of a unit `w` (either side): GGX's `2|w.z| / (|w.z| +
/// ‖(αx w.x, αy w.y, w.z)‖)`, Beckmann's `1/(1 + Λ)`.
#[inline(always)]
fn g1<L: Lanes, const NDF: u8>(l: L, p: &CtParams, w: V3<L>) -> L::F {
    let z = l.abs(w[2]);
    if NDF == GGX {
        (z + z) / (z + stretched_len(l, p, w))
    } else {
        l.splat(1.0) / beckmann_lambda1(l, p, [w[0], w[1], z])
    }
}

/// `D` of a unit `m` (`m.z > 0`).
#[inline(always)]
fn d<L: Lanes, const NDF: u8>(l: L, p: &CtParams, m: V3<L>) -> L::F {
    if NDF == GGX {
        return d_ggx(l, p, m);
    }
    // Beckmann: exp(−(x² + y²)/z²) / (π αx αy z⁴), x, y stretched.
    let x = m[0] * l.splat(p.inv_ax);
    let y = m[1] * l.splat(p.inv_ay);
    let z2 = m[2] * m[2];
    let inv_z2 = l.splat(1.0) / z2;
    l.splat(p.inv_pi_axay) * exp(l, -(l.mul_add(x, x, y * y) * inv_z2)) * (inv_z2 * inv_z2)
}

/// GGX's `D` of a unit `m`.
#[inline(always)]
fn d_ggx<L: Lanes>(l: L, p: &CtParams, m: V3<L>) -> L::F {
    let x = m[0] * l.splat(p.inv_ax);
    let y = m[1] * l.splat(p.inv_ay);
    let s = l.mul_add(x, x, l.mul_add(y, y, m[2] * m[2]));
    l.splat(p.inv_pi_axay) / (s * s)
}

/// Fresnel reflectance at `c ∈ (0, 1]` for the relative index `eta`
/// (lanes), 1 under total internal reflection, and the refracted cosine.
#[inline(always)]
pub(super) fn fresnel<L: Lanes>(l: L, c: L::F, eta: L::F, inv_eta: L::F) -> (L::F, L::F) {
    let (ct, tir) = refracted_cos(l, c, inv_eta);
    (l.select(tir, l.splat(1.0), fresnel_cos(l, c, ct, eta)), ct)
}

/// The refracted cosine at `c` by Snell's law (0 under total internal
/// reflection), and where total internal reflection is.
#[inline(always)]
fn refracted_cos<L: Lanes>(l: L, c: L::F, inv_eta: L::F) -> (L::F, L::M) {
    let one = l.splat(1.0);
    let sin2_t = (one - c * c) * (inv_eta * inv_eta);
    let tir = l.gt(sin2_t, one) | l.eq(sin2_t, one);
    (l.sqrt(l.max(one - sin2_t, l.splat(0.0))), tir)
}

/// Fresnel reflectance at `c` whose refracted cosine `ct` is known.
#[inline(always)]
fn fresnel_cos<L: Lanes>(l: L, c: L::F, ct: L::F, eta: L::F) -> L::F {
    let ec = eta * c;
    let r_parl = (ec - ct) / (ec + ct);
    let ect = eta * ct;
    let r_perp = (c - ect) / (c + ect);
    l.splat(0.5) * l.mul_add(r_parl, r_parl, r_perp * r_perp)
}

/// What `wo`'s side gives: `s`, `up = s wo`, `η_s` and `1/η_s`.
#[inline(always)]
fn side<L: Lanes>(l: L, p: &DielectricParams, wo: V3<L>) -> (L::F, V3<L>, L::F, L::F) {
    let below = l.lt(wo[2], l.splat(0.0));
    let s = l.select(below, l.splat(-1.0), l.splat(1.0));
    let (e, ie) = (l.splat(p.eta), l.splat(p.inv_eta));
    (
        s,
        [wo[0] * s, wo[1] * s, wo[2] * s],
        l.select(below, ie, e),
        l.select(below, e, ie),
    )
}

/// `(f, pdf)` on `wo`'s side at the unit microfacet normal `m` (`m.z > 0`,
/// `c_o = up·m > 0`, `c_i = wi↑·m`), given `F` and `G1(up)`, `G1(wi)`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn f_pdf<L: Lanes, const NDF: u8, const STRAT: u8>(
    l: L,
    p: &DielectricParams,
    up: V3<L>,
    wi_up: V3<L>,
    m: V3<L>,
    c_o: L::F,
    c_i: L::F,
    fr: L::F,
    eta_s: L::F,
) -> (V3<L>, L::F) {
    let one = l.splat(1.0);
    let d = d::<L, NDF>(l, &p.ct, m);
    let (g1o, g1i) = (g1::<L, NDF>(l, &p.ct, up), g1::<L, NDF>(l, &p.ct, wi_up));
    let reflect = l.gt(wi_up[2], l.splat(0.0));
    let dg1o = d * g1o;
    let inv_oz = one / up[2];
    // Reflection: f = F D G1o G1i / (4 up.z |wi.z|); the pdf is F times the
    // normal's density over 4 c_o (visible normals: D G1o c_o / up.z).
    let fdg = fr * dg1o * inv_oz * l.splat(0.25);
    let fr_r = fdg * g1i / l.abs(wi_up[2]);
    let pdf_r = if STRAT == BRDF {
        fr * d * m[2] * l.splat(0.25) / c_o
    } else {
        fdg
    };
    // Refraction.
    let den = l.mul_add(eta_s, c_i, c_o);
    let inv_den2 = one / (den * den);
    let t = one - fr;
    let ci = l.abs(c_i);
    let pm = dg1o * c_o * inv_oz;
    // The normal's density: D cos θm for brdf, visible normals otherwise.
    let pm_s = if STRAT == BRDF { d * m[2] } else { pm };
    let pdf_t = pm_s * t * (eta_s * eta_s) * ci * inv_den2;
    let mut ft = t * dg1o * g1i * c_o * ci * inv_oz * inv_den2 / l.abs(wi_up[2]);
    if p.importance {
        ft = ft * (eta_s * eta_s);
    }
    let pdf = l.select(reflect, pdf_r, pdf_t);
    let f = [
        l.select(reflect, fr_r * l.splat(p.kr[0]), ft * l.splat(p.kt[0])),
        l.select(reflect, fr_r * l.splat(p.kr[1]), ft * l.splat(p.kt[1])),
        l.select(reflect, fr_r * l.splat(p.kr[2]), ft * l.splat(p.kt[2])),
    ];
    (f, pdf)
}

/// One vector of samples (see the module docs): a microfacet normal drawn
/// by the strategy (visible normals, `D cos θm`, GGX's spherical caps),
/// reflected or refracted as `uc` chooses; `uniform` and `cosine` draw over
/// the sphere, `u1` choosing the side first (half each), as the scalar
/// path's material does.
#[inline(always)]
pub(crate) fn sample<L: Lanes, const NDF: u8, const STRAT: u8>(
    l: L,
    p: &DielectricParams,
    wo: V3<L>,
    u1: L::F,
    u2: L::F,
    uc: L::F,
) -> Sampled<L> {
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    if STRAT == UNIFORM || STRAT == COSINE {
        let below = !l.lt(u1, l.splat(0.5));
        let v = l.select(below, l.mul_add(u1, l.splat(2.0), -one), u1 + u1);
        let w = if STRAT == COSINE {
            cosine_hemisphere(l, v, u2)
        } else {
            let (sin, cos) = sincos_turns(l, u2);
            let r = l.sqrt(l.max(l.mul_add(-v, v, one), zero));
            [r * cos, r * sin, v]
        };
        let wi = [w[0], w[1], l.select(below, -w[2], w[2])];
        let (f, pdf) = eval_pdf::<L, NDF, STRAT>(l, p, wo, wi);
        let ws = l.abs(wi[2]) / pdf;
        let weight = [f[0] * ws, f[1] * ws, f[2] * ws];
        let valid = !l.eq(wo[2], zero) & !l.eq(wi[2], zero);
        return finish(l, valid, wi, f, pdf, weight);
    }
    let (s, up, eta_s, inv_eta_s) = side(l, p, wo);
    let m = if STRAT == CAPS {
        cap_normal::<L, CAPS>(l, &p.ct, up, u1, u2)
    } else if STRAT == VNDF && NDF == BECKMANN {
        beckmann_vndf_normal(l, &p.ct, up, u1, u2).0
    } else {
        let (sin, cos) = sincos_turns(l, u2);
        let (n, nn) = if STRAT == VNDF {
            ggx_vndf_normal(l, &p.ct, up, u1, sin, cos)
        } else {
            // D(m) cos θm: slope radius² u/(1 − u) (GGX), −ln(1 − u)
            // (Beckmann), u below 1, as the Cook-Torrance kernel draws it.
            let u = l.min(u1, l.splat(1.0 - f32::EPSILON / 2.0));
            let (r, z) = if NDF == GGX {
                (l.sqrt(u), l.sqrt(one - u))
            } else {
                (l.sqrt(-log1p(l, -u)), one)
            };
            let n = [
                -(l.splat(p.ct.ax) * r * cos),
                -(l.splat(p.ct.ay) * r * sin),
                z,
            ];
            (n, dot(l, n, n))
        };
        let inv_len = one / l.sqrt(nn);
        [n[0] * inv_len, n[1] * inv_len, n[2] * inv_len]
    };
    let c_o = dot(l, up, m);
    let (fr, ct) = fresnel(l, c_o, eta_s, inv_eta_s);
    let reflect = l.lt(uc, fr);
    // Reflection 2 c_o m − up; refraction −up/η_s + (c_o/η_s − cos θt) m.
    let two_c = c_o + c_o;
    let k = l.mul_add(c_o, inv_eta_s, -ct);
    let wi_up = [
        l.select(
            reflect,
            l.mul_add(two_c, m[0], -up[0]),
            l.mul_add(k, m[0], -(up[0] * inv_eta_s)),
        ),
        l.select(
            reflect,
            l.mul_add(two_c, m[1], -up[1]),
            l.mul_add(k, m[1], -(up[1] * inv_eta_s)),
        ),
        l.select(
            reflect,
            l.mul_add(two_c, m[2], -up[2]),
            l.mul_add(k, m[2], -(up[2] * inv_eta_s)),
        ),
    ];
    let side_ok = l.select_mask(reflect, l.gt(wi_up[2], zero), l.lt(wi_up[2], zero));
    let valid = l.gt(up[2], zero) & l.gt(c_o, zero) & side_ok;
    let c_i = l.select(reflect, c_o, dot(l, wi_up, m));
    let (f, pdf) = f_pdf::<L, NDF, STRAT>(l, p, up, wi_up, m, c_o, c_i, fr, eta_s);
    let weight = if STRAT == BRDF {
        // f |cos θi| / pdf.
        let ws = l.abs(wi_up[2]) / pdf;
        [f[0] * ws, f[1] * ws, f[2] * ws]
    } else {
        // Visible normals (the caps draw them too): kr G1(wi), or kt G1(wi)
        // over η_s² for radiance.
        let g1i = g1::<L, NDF>(l, &p.ct, wi_up);
        let wt = if p.importance {
            g1i
        } else {
            g1i * (inv_eta_s * inv_eta_s)
        };
        [
            l.select(reflect, g1i * l.splat(p.kr[0]), wt * l.splat(p.kt[0])),
            l.select(reflect, g1i * l.splat(p.kr[1]), wt * l.splat(p.kt[1])),
            l.select(reflect, g1i * l.splat(p.kr[2]), wt * l.splat(p.kt[2])),
        ]
    };
    let wi = [wi_up[0] * s, wi_up[1] * s, wi_up[2] * s];
    finish(l, valid, wi, f, pdf, weight)
}

/// `(f, pdf)` of the strategy at `(wo, wi)`, zero where no microfacet
/// takes `wo` to `wi` (or not finite), as the scalar path; `uniform` and
/// `cosine` have their density over the sphere wherever neither direction
/// is on the horizon.
#[inline(always)]
pub(crate) fn eval_pdf<L: Lanes, const NDF: u8, const STRAT: u8>(
    l: L,
    p: &DielectricParams,
    wo: V3<L>,
    wi: V3<L>,
) -> (V3<L>, L::F) {
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    let (s, up, eta_s, inv_eta_s) = side(l, p, wo);
    let wi_up = [wi[0] * s, wi[1] * s, wi[2] * s];
    let reflect = l.gt(wi_up[2], zero);
    // The generalized half vector, turned to +z.
    let k = l.select(reflect, one, eta_s);
    let h = [
        l.mul_add(k, wi_up[0], up[0]),
        l.mul_add(k, wi_up[1], up[1]),
        l.mul_add(k, wi_up[2], up[2]),
    ];
    let hh = dot(l, h, h);
    let flip = l.lt(h[2], zero);
    let inv = l.select(flip, -one, one) / l.sqrt(hh);
    let m = [h[0] * inv, h[1] * inv, h[2] * inv];
    let c_o = dot(l, up, m);
    let c_i = dot(l, wi_up, m);
    // Each direction on the side of the microfacet it is on of the surface.
    let ok = l.gt(up[2], zero)
        & !l.eq(wi_up[2], zero)
        & l.gt(hh, zero)
        & l.gt(c_o, zero)
        & l.gt(c_i * wi_up[2], zero);
    let c_o1 = l.min(c_o, one);
    // A refraction's cos θt is |wi·m| itself: from c_o by Snell's law it
    // cancels next to total internal reflection, where c_o hardly moves
    // with the directions (the f64 path's F there is well-conditioned).
    let (ct_snell, tir) = refracted_cos(l, c_o1, inv_eta_s);
    let ct = l.select(reflect, ct_snell, l.abs(c_i));
    let fr = l.select(tir & reflect, one, fresnel_cos(l, c_o1, ct, eta_s));
    let (f, pdf) = f_pdf::<L, NDF, STRAT>(l, p, up, wi_up, m, c_o, c_i, fr, eta_s);
    let f_ok = ok & l.is_finite(f[0]) & l.is_finite(f[1]) & l.is_finite(f[2]);
    if STRAT == UNIFORM || STRAT == COSINE {
        let hemi = if STRAT == UNIFORM {
            l.splat(INV_TWO_PI)
        } else {
            l.abs(wi[2]) * l.splat(INV_PI)
        };
        let on = !l.eq(wo[2], zero) & !l.eq(wi[2], zero);
        return (
            select3(l, f_ok, f, zero),
            l.select(on, l.splat(0.5) * hemi, zero),
        );
    }
    let p_ok = ok & l.is_finite(pdf);
    (select3(l, f_ok, f, zero), l.select(p_ok, pdf, zero))
}
