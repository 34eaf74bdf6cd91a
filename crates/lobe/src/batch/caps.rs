//! GGX visible normals by spherical caps (Dupuy and Benyoub 2023) and the
//! bounded VNDF (Eto and Tokuyoshi 2023), for the Cook-Torrance kernels of
//! [`super`] (a child, sharing its helpers), as `Microfacet::
//! sample_visible_caps` and `sample_visible_bounded` draw them: a uniform
//! point of the cap `z ∈ [−b, 1]` of the unit sphere (`φ = 2π u1`, `z = (1 −
//! u2)(1 + b) − b`) plus the stretched view direction `wh`, unstretched;
//! `b = wh.z` (caps) or `k(wo) wh.z` (bounded, `k = (1 − a²) s² / (s² + a²
//! wo.z²)`, `s = 1 + ‖wo.xy‖`, `a = min(αx, αy)`).
//!
//! Written without cancellation: `1 − z² = u2 (1 + b) ((1 − u2)(1 + b) +
//! 1 − b)` and `hz = z + wh.z = (1 − u2)(1 + b) + (wh.z − b)`, both sums of
//! non-negative terms, with `wh.z − b = (1 − k) wh.z`, `1 − k = a² (wo.z² +
//! s²)/(s² + a² wo.z²)` (within 1e-8 of 0 at alpha 1e-4, where `1 − k` from
//! `k` would be all rounding) and `1 − wh.z = |wh.xy|²/(1 + wh.z)`.
//!
//! Densities: the caps draw the visible normals exactly, so their pdf is
//! vndf's, `D / (2 (wo.z + Lo))`; the bounded VNDF's is
//! `D / (2 (k wo.z + Lo))`, vndf's times `(wo.z + Lo)/(k wo.z + Lo)`
//! (`Lo = ‖(αx wo.x, αy wo.y, wo.z)‖`).

use super::super::lanes::Lanes;
use super::super::math::sincos_turns;
use super::{
    BOUNDED, CtParams, Eval, GGX, INV_PI, Sampled, Shadow, V3, VNDF, dot, eval_at, eval_h, finish,
    mixture_pdf, plus_diffuse, reflect_or_diffuse, select3, stretched_len, with_weight,
};

/// The visible normal of the caps (`STRAT = CAPS`) or of the bounded VNDF.
#[inline(always)]
pub(super) fn cap_normal<L: Lanes, const STRAT: u8>(
    l: L,
    p: &CtParams,
    wo: V3<L>,
    u1: L::F,
    u2: L::F,
) -> V3<L> {
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    let (ax, ay) = (l.splat(p.ax), l.splat(p.ay));
    let w = [wo[0] * ax, wo[1] * ay, wo[2]];
    let inv = one / l.sqrt(dot(l, w, w));
    let wh = [w[0] * inv, w[1] * inv, w[2] * inv];
    // b = wh.z − d with d = (1 − k) wh.z (0 for the caps); 1 − b = (1 −
    // wh.z) + d, 1 − wh.z = |wh.xy|²/(1 + wh.z): each without cancellation.
    let d = if STRAT == BOUNDED {
        one_minus_k(l, p, wo) * wh[2]
    } else {
        zero
    };
    let b = wh[2] - d;
    let one_m_b = l.mul_add(wh[0], wh[0], wh[1] * wh[1]) / (one + wh[2]) + d;
    let (s, c) = sincos_turns(l, u1);
    let omu = one - u2;
    let opb = one + b;
    let sin_t = l.sqrt(l.max(u2 * opb * l.mul_add(omu, opb, one_m_b), zero));
    let hz = l.mul_add(omu, opb, d);
    let h = [l.mul_add(sin_t, c, wh[0]), l.mul_add(sin_t, s, wh[1]), hz];
    let n = [
        ax * h[0],
        ay * h[1],
        l.max(h[2], l.splat(f32::MIN_POSITIVE)),
    ];
    let inv = one / l.sqrt(dot(l, n, n));
    [n[0] * inv, n[1] * inv, n[2] * inv]
}

/// `1 − k(wo)` of the bounded VNDF, `a² (wo.z² + s²) / (s² + a² wo.z²)`:
/// `k` itself is within `a²` (1e-8) of 1 for small alphas, where `1 − k`
/// computed from it would be all rounding.
#[inline(always)]
fn one_minus_k<L: Lanes>(l: L, p: &CtParams, wo: V3<L>) -> L::F {
    let a = p.ax.min(p.ay).clamp(0.0, 1.0);
    let a2 = l.splat(a * a);
    let s = l.splat(1.0) + l.sqrt(l.mul_add(wo[0], wo[0], wo[1] * wo[1]));
    let s2 = s * s;
    a2 * l.mul_add(wo[2], wo[2], s2) / l.mul_add(a2 * wo[2], wo[2], s2)
}

/// The glossy lobe's `f`, `pdf`, `weight` at a half vector (as
/// `super::eval_at`), with the bounded VNDF's pdf for `STRAT = BOUNDED`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn eval_at_caps<L: Lanes, const STRAT: u8>(
    l: L,
    p: &CtParams,
    wo: V3<L>,
    wi: V3<L>,
    h: V3<L>,
    hh: L::F,
    oh: L::F,
    ih: L::F,
) -> Eval<L> {
    let e = eval_at::<L, GGX, VNDF>(l, p, wo, wi, h, hh, oh, ih, None);
    if STRAT != BOUNDED {
        return e;
    }
    let lo = stretched_len(l, p, wo);
    // k wo.z + Lo = (wo.z + Lo) − (1 − k) wo.z.
    let ratio = (wo[2] + lo) / ((wo[2] + lo) - one_minus_k(l, p, wo) * wo[2]);
    let inv = l.splat(1.0) / ratio;
    Eval {
        ok: e.ok,
        f: e.f,
        pdf: e.pdf * ratio,
        weight: [e.weight[0] * inv, e.weight[1] * inv, e.weight[2] * inv],
    }
}

/// As `super::eval_h`: with the diffuse term and the lobe-choice mixture
/// where the material has them.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn eval_h_caps<L: Lanes, const STRAT: u8>(
    l: L,
    p: &CtParams,
    wo: V3<L>,
    wi: V3<L>,
    h: V3<L>,
    hh: L::F,
    oh: L::F,
    ih: L::F,
) -> Eval<L> {
    if STRAT != BOUNDED {
        return eval_h::<L, GGX, VNDF>(l, p, wo, wi, h, hh, oh, ih);
    }
    if !p.has_diffuse() {
        return eval_at_caps::<L, STRAT>(l, p, wo, wi, h, hh, oh, ih);
    }
    let zero = l.splat(0.0);
    let above = l.gt(wo[2], zero) & l.gt(wi[2], zero);
    let e = eval_at_caps::<L, STRAT>(l, p, wo, wi, h, hh, oh, ih);
    let fg = select3(l, e.ok, e.f, zero);
    let pg = l.select(e.ok, e.pdf, zero);
    let pd = wi[2] * l.splat(INV_PI);
    let pdf = mixture_pdf(l, p, wo, pg, pd);
    with_weight(above, plus_diffuse(l, p, fg, wo, wi, above), pdf, wi[2])
}

/// One vector of samples (`STRAT`: [`CAPS`] or [`BOUNDED`]).
#[inline(always)]
pub(super) fn sample<L: Lanes, const STRAT: u8>(
    l: L,
    p: &CtParams,
    wo: V3<L>,
    u1: L::F,
    u2: L::F,
    uc: L::F,
) -> Sampled<L> {
    let m = cap_normal::<L, STRAT>(l, p, wo, u1, u2);
    let r = reflect_or_diffuse(l, p, wo, m, l.splat(1.0), u1, u2, uc);
    if p.two_lobes {
        let e = eval_h_caps::<L, STRAT>(l, p, wo, r.wi, r.h, r.hh, r.oh, r.ih);
        return finish(l, r.valid, r.wi, e.f, e.pdf, e.weight);
    }
    let e = eval_at_caps::<L, STRAT>(l, p, wo, r.wi, r.h, r.hh, r.oh, r.ih);
    finish(l, r.valid & e.ok, r.wi, e.f, e.pdf, e.weight)
}

/// `(f, pdf)` of `eval_pdf` for the bounded VNDF (the caps' is vndf's).
#[inline(always)]
pub(super) fn eval_pdf_bounded<L: Lanes>(
    l: L,
    p: &CtParams,
    wo: V3<L>,
    wi: V3<L>,
) -> (V3<L>, L::F) {
    let zero = l.splat(0.0);
    let h = [wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]];
    let hh = dot(l, h, h);
    let oh = dot(l, wo, h);
    let ih = if p.shadow == Shadow::VCavity {
        dot(l, wi, h)
    } else {
        oh
    };
    let e = eval_h_caps::<L, BOUNDED>(l, p, wo, wi, h, hh, oh, ih);
    let f_ok = e.ok & l.is_finite(e.f[0]) & l.is_finite(e.f[1]) & l.is_finite(e.f[2]);
    let p_ok = e.ok & l.is_finite(e.pdf);
    (select3(l, f_ok, e.f, zero), l.select(p_ok, e.pdf, zero))
}
