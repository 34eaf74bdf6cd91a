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

use super::{CtParams, Sampled, V3, dot, finish, ggx_vndf_normal, select3, stretched_len};
use crate::batch::lanes::Lanes;
use crate::batch::math::sincos_turns;

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

/// `2|w.z| / (|w.z| + ‖(αx w.x, αy w.y, w.z)‖)`, GGX's `G1` of a unit `w`.
#[inline(always)]
fn g1<L: Lanes>(l: L, p: &CtParams, w: V3<L>) -> L::F {
    let z = l.abs(w[2]);
    (z + z) / (z + stretched_len(l, p, w))
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
    let one = l.splat(1.0);
    let zero = l.splat(0.0);
    let sin2_t = (one - c * c) * (inv_eta * inv_eta);
    let tir = l.gt(sin2_t, one) | l.eq(sin2_t, one);
    let ct = l.sqrt(l.max(one - sin2_t, zero));
    let ec = eta * c;
    let r_parl = (ec - ct) / (ec + ct);
    let ect = eta * ct;
    let r_perp = (c - ect) / (c + ect);
    let r = l.splat(0.5) * l.mul_add(r_parl, r_parl, r_perp * r_perp);
    (l.select(tir, one, r), ct)
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
fn f_pdf<L: Lanes>(
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
    let d = d_ggx(l, &p.ct, m);
    let (g1o, g1i) = (g1(l, &p.ct, up), g1(l, &p.ct, wi_up));
    let reflect = l.gt(wi_up[2], l.splat(0.0));
    let dg1o = d * g1o;
    let inv_oz = one / up[2];
    // Reflection.
    let pdf_r = fr * dg1o * inv_oz * l.splat(0.25);
    let fr_r = pdf_r * g1i / l.abs(wi_up[2]);
    // Refraction.
    let den = l.mul_add(eta_s, c_i, c_o);
    let inv_den2 = one / (den * den);
    let t = one - fr;
    let ci = l.abs(c_i);
    let pm = dg1o * c_o * inv_oz;
    let pdf_t = pm * t * (eta_s * eta_s) * ci * inv_den2;
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

/// One vector of visible-normal samples (see the module docs).
#[inline(always)]
pub(crate) fn sample<L: Lanes>(
    l: L,
    p: &DielectricParams,
    wo: V3<L>,
    u1: L::F,
    u2: L::F,
    uc: L::F,
) -> Sampled<L> {
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    let (s, up, eta_s, inv_eta_s) = side(l, p, wo);
    let (sin, cos) = sincos_turns(l, u2);
    let (n, nn) = ggx_vndf_normal(l, &p.ct, up, u1, sin, cos);
    let inv_len = one / l.sqrt(nn);
    let m = [n[0] * inv_len, n[1] * inv_len, n[2] * inv_len];
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
    let (f, pdf) = f_pdf(l, p, up, wi_up, m, c_o, c_i, fr, eta_s);
    let g1i = g1(l, &p.ct, wi_up);
    let wt = if p.importance {
        g1i
    } else {
        g1i * (inv_eta_s * inv_eta_s)
    };
    let weight = [
        l.select(reflect, g1i * l.splat(p.kr[0]), wt * l.splat(p.kt[0])),
        l.select(reflect, g1i * l.splat(p.kr[1]), wt * l.splat(p.kt[1])),
        l.select(reflect, g1i * l.splat(p.kr[2]), wt * l.splat(p.kt[2])),
    ];
    let wi = [wi_up[0] * s, wi_up[1] * s, wi_up[2] * s];
    finish(l, valid, wi, f, pdf, weight)
}

/// `(f, pdf)` of visible-normal sampling at `(wo, wi)`, zero where no
/// microfacet takes `wo` to `wi` (or not finite), as the scalar path.
#[inline(always)]
pub(crate) fn eval_pdf<L: Lanes>(
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
    let (fr, _) = fresnel(l, l.min(c_o, one), eta_s, inv_eta_s);
    let (f, pdf) = f_pdf(l, p, up, wi_up, m, c_o, c_i, fr, eta_s);
    let f_ok = ok & l.is_finite(f[0]) & l.is_finite(f[1]) & l.is_finite(f[2]);
    let p_ok = ok & l.is_finite(pdf);
    (select3(l, f_ok, f, zero), l.select(p_ok, pdf, zero))
}
