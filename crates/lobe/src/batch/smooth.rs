//! The smooth models' kernels (delta lobes): `conductor`, `dielectric`,
//! `thindielectric` and `plastic`, as `crate::models::{conductor,
//! dielectric, thindielectric, plastic}` compute them in f64.
//!
//! A delta sample is what the scalar path's `LobeSample` is: `wi` the
//! mirror (or refracted, or straight-through) direction, `pdf` the
//! probability of the part drawn (1 for a mirror), `f = value · pdf /
//! |cos θi|` and `weight = value`, `value` the part's `∫ f |cos θi| dωi`
//! divided by its probability: a conductor's `ks F(cos θo)`, glass's
//! reflectance `kr` or transmittance `kt` (times `η_ti²` for radiance), a
//! thin sheet's `kr` or `kt`, a plastic coating's `ks F / P`. `eval_pdf` is
//! zero for a delta; a plastic's base has `f = scale (1 − F(θo))(1 − F(θi))`
//! and `pdf = (1 − P) cos θi / π`.
//!
//! The conductor and the plastic reflect only (`wo.z > 0`); glass and the
//! thin sheet take `wo` from either side (`wo.z ≠ 0`), `uc` choosing
//! reflection where `uc < R`.

use super::dielectric::fresnel;
use super::{FresnelP, INV_PI, Sampled, V3, cosine_hemisphere, finish, ks_fresnel, select3};
use crate::batch::lanes::Lanes;

/// The kernels' model codes (their first const parameter).
pub(crate) const CONDUCTOR: u8 = 0;
pub(crate) const DIELECTRIC: u8 = 1;
pub(crate) const THIN: u8 = 2;
pub(crate) const PLASTIC: u8 = 3;

/// A smooth model in f32, as the kernels read it (each reads its part).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SmoothParams {
    /// Conductor: `specular_reflectance` times its Fresnel term.
    pub fresnel: FresnelP,
    /// Relative index `η` (inside over outside) and `1/η`: glass, the thin
    /// sheet, the plastic's coating.
    pub eta: f32,
    pub inv_eta: f32,
    /// `specular_reflectance`, `specular_transmittance` per channel.
    pub kr: [f32; 3],
    pub kt: [f32; 3],
    /// Glass in radiance transport: a refraction's value times `η_ti²`.
    pub radiance: bool,
    /// Plastic: the base's `ρ'/(π η²)` per channel and the coating's weight
    /// `w` in the lobe choice (`models::plastic::Base`).
    pub scale: [f32; 3],
    pub w: f32,
}

/// `a · x` per channel. (Functions, not closures, in the kernels: a closure
/// that is not inlined loses the caller's target features.)
#[inline(always)]
fn scale3<L: Lanes>(l: L, a: [f32; 3], x: L::F) -> V3<L> {
    [l.splat(a[0]) * x, l.splat(a[1]) * x, l.splat(a[2]) * x]
}

/// `v · x` per channel.
#[inline(always)]
fn mul3<L: Lanes>(_l: L, v: V3<L>, x: L::F) -> V3<L> {
    [v[0] * x, v[1] * x, v[2] * x]
}

/// `m ? a : b` per channel (`super::select3` where `b` is zero).
#[inline(always)]
fn select3m<L: Lanes>(l: L, m: L::M, a: V3<L>, b: V3<L>) -> V3<L> {
    [
        l.select(m, a[0], b[0]),
        l.select(m, a[1], b[1]),
        l.select(m, a[2], b[2]),
    ]
}

/// `(P, 1 − P)`, the plastic's probability of drawing its coating when a
/// fraction `f` of the light from `wo` reflects off it
/// (`Base::coating_probability(1 − f)`), `1 − P` computed on its own.
#[inline(always)]
fn plastic_choice<L: Lanes>(l: L, p: &SmoothParams, f: L::F) -> (L::F, L::F) {
    let zero = l.splat(0.0);
    let ps = f * l.splat(p.w);
    let pd = (l.splat(1.0) - f) * l.splat(1.0 - p.w);
    let s = ps + pd;
    let some = l.gt(s, zero);
    (
        l.select(some, ps / s, zero),
        l.select(some, pd / s, l.splat(1.0)),
    )
}

/// The plastic base's `f` at `(wo, wi)` given `1 − F(θo)`.
#[inline(always)]
fn plastic_base<L: Lanes>(l: L, p: &SmoothParams, t_o: L::F, wi: V3<L>) -> V3<L> {
    let (fi, _) = fresnel(l, wi[2], l.splat(p.eta), l.splat(p.inv_eta));
    let tt = t_o * (l.splat(1.0) - fi);
    scale3(l, p.scale, tt)
}

#[inline(always)]
pub(crate) fn sample<L: Lanes, const MODEL: u8>(
    l: L,
    p: &SmoothParams,
    wo: V3<L>,
    u1: L::F,
    u2: L::F,
    uc: L::F,
) -> Sampled<L> {
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    let mirror = [-wo[0], -wo[1], wo[2]];
    let ok_up = l.gt(wo[2], zero);
    match MODEL {
        CONDUCTOR => {
            let c = l.min(l.max(wo[2], zero), one);
            let v = ks_fresnel(l, &p.fresnel, c);
            let f = mul3(l, v, one / wo[2]);
            finish(l, ok_up, mirror, f, one, v)
        }
        DIELECTRIC => {
            let below = l.lt(wo[2], zero);
            let (e, ie) = (l.splat(p.eta), l.splat(p.inv_eta));
            // η_s on wo's side, and η_ti = 1/η_s.
            let (eta_s, eta_ti) = (l.select(below, ie, e), l.select(below, e, ie));
            let c = l.abs(wo[2]);
            let (r, ct) = fresnel(l, c, eta_s, eta_ti);
            let reflect = l.lt(uc, r);
            let neg_ct = l.select(below, ct, -ct);
            let wi = [
                l.select(reflect, mirror[0], -(eta_ti * wo[0])),
                l.select(reflect, mirror[1], -(eta_ti * wo[1])),
                l.select(reflect, mirror[2], neg_ct),
            ];
            let pdf = l.select(reflect, r, one - r);
            let scale_t = if p.radiance { eta_ti * eta_ti } else { one };
            let v = select3m(l, reflect, scale3(l, p.kr, one), scale3(l, p.kt, scale_t));
            let f = mul3(l, v, pdf / l.abs(wi[2]));
            finish(l, !l.eq(wo[2], zero), wi, f, pdf, v)
        }
        THIN => {
            let c = l.abs(wo[2]);
            let (r1, _) = fresnel(l, c, l.splat(p.eta), l.splat(p.inv_eta));
            // The sheet's two interfaces: R + T² R / (1 − R²).
            let t1 = one - r1;
            let r = l.select(l.lt(r1, one), r1 + t1 * t1 * r1 / (one - r1 * r1), r1);
            let reflect = l.lt(uc, r);
            let wi = [
                l.select(reflect, mirror[0], -wo[0]),
                l.select(reflect, mirror[1], -wo[1]),
                l.select(reflect, mirror[2], -wo[2]),
            ];
            let pdf = l.select(reflect, r, one - r);
            let v = select3m(l, reflect, scale3(l, p.kr, one), scale3(l, p.kt, one));
            let f = mul3(l, v, pdf / c);
            finish(l, !l.eq(wo[2], zero), wi, f, pdf, v)
        }
        _ => {
            // PLASTIC.
            let (fo, _) = fresnel(l, wo[2], l.splat(p.eta), l.splat(p.inv_eta));
            let (pc, pb) = plastic_choice(l, p, fo);
            let coat = l.lt(uc, pc);
            let wd = cosine_hemisphere(l, u1, u2);
            let wi = [
                l.select(coat, mirror[0], wd[0]),
                l.select(coat, mirror[1], wd[1]),
                l.select(coat, mirror[2], wd[2]),
            ];
            // The coating: f = kr F / cos θi, pdf P, weight kr F / P.
            let fc = scale3(l, p.kr, fo / wo[2]);
            let wc = scale3(l, p.kr, fo / pc);
            // The base: its f, (1 − P) cos θi / π, f cos θi / pdf.
            let fb = plastic_base(l, p, one - fo, wi);
            let pdf_b = pb * wi[2] * l.splat(INV_PI);
            let f = select3m(l, coat, fc, fb);
            let weight = select3m(l, coat, wc, mul3(l, fb, wi[2] / pdf_b));
            let pdf = l.select(coat, pc, pdf_b);
            finish(l, ok_up & l.gt(wi[2], zero), wi, f, pdf, weight)
        }
    }
}

/// `(f, pdf)`: zero for the delta models; the plastic's base where both
/// directions are above the surface.
#[inline(always)]
pub(crate) fn eval_pdf<L: Lanes, const MODEL: u8>(
    l: L,
    p: &SmoothParams,
    wo: V3<L>,
    wi: V3<L>,
) -> (V3<L>, L::F) {
    let zero = l.splat(0.0);
    if MODEL != PLASTIC {
        return ([zero; 3], zero);
    }
    let one = l.splat(1.0);
    let above = l.gt(wo[2], zero) & l.gt(wi[2], zero);
    let (fo, _) = fresnel(l, wo[2], l.splat(p.eta), l.splat(p.inv_eta));
    let (_, pb) = plastic_choice(l, p, fo);
    let f = plastic_base(l, p, one - fo, wi);
    let pdf = pb * wi[2] * l.splat(INV_PI);
    let ok = above & l.is_finite(pdf);
    (select3(l, ok, f, zero), l.select(ok, pdf, zero))
}
