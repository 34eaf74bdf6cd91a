//! The Blinn-Phong NDF inside Cook-Torrance (`crate::microfacet`,
//! `Ndf::BlinnPhong`): its `D` and its `D(m) cos θm` sampler, for the
//! Cook-Torrance kernels of [`super`] (a child, sharing its helpers). Its
//! Smith term is Beckmann's at the same alpha, as the scalar path has it
//! (`super::beckmann_lambda1`), and its strategies are brdf, uniform and
//! cosine (no visible-normal sampler).
//!
//! `D(h) = 1/(π αx αy) · cos θh^e(φ)`, `e(φ) = (eₓ hx² + e_y hy²)/(hx² +
//! hy²)`, `e = 2/α² − 2` (up to 2·10⁸ at alpha 1e-4), with `cos^e` by
//! [`pow_cos`] from `cos θh = hz/|h|` and `t = 1 − cos θh = (hx² + hy²)/(|h| (|h| +
//! hz))`, without cancellation; scale-invariant in `h`.

use super::super::lanes::Lanes;
use super::super::math::{exp, expm1, log, pow_cos, sincos_turns};
use super::{CtParams, V3};

/// The exponents `(eₓ, e_y) = (2/αx² − 2, 2/αy² − 2)`.
#[inline(always)]
fn exponents(p: &CtParams) -> (f32, f32) {
    (
        2.0 * p.inv_ax * p.inv_ax - 2.0,
        2.0 * p.inv_ay * p.inv_ay - 2.0,
    )
}

/// `D(h)` for a half vector of any length (`hh = |h|²`); 0 where `hz ≤ 0`.
#[inline(always)]
pub(super) fn d<L: Lanes>(l: L, p: &CtParams, h: V3<L>, hh: L::F) -> L::F {
    let zero = l.splat(0.0);
    let (ex, ey) = exponents(p);
    let x2 = h[0] * h[0];
    let y2 = h[1] * h[1];
    let r2 = x2 + y2;
    let hl = l.sqrt(hh);
    let t = r2 / (hl * (hl + h[2]));
    let e = l.select(
        l.gt(r2, zero),
        l.mul_add(l.splat(ex), x2, l.splat(ey) * y2) / r2,
        l.splat(0.5 * (ex + ey)),
    );
    let c = pow_cos(l, t, h[2] / hl, e);
    l.select(l.gt(h[2], zero), l.splat(p.inv_pi_axay) * c, zero)
}

/// A normal `m` with density `D(m) cos θm`, as `Microfacet::sample_wm`: the
/// azimuth by `tan φ = (αy/αx) tan(2π u2)` in `u2`'s quadrant, then `cos θ
/// = u1^(1/(e(φ) + 2))` through logarithms.
#[inline(always)]
pub(super) fn sample_normal<L: Lanes>(l: L, p: &CtParams, u1: L::F, u2: L::F) -> V3<L> {
    let zero = l.splat(0.0);
    let (ex, ey) = exponents(p);
    let (st, ct) = sincos_turns(l, u2);
    let (sp, cp) = if p.ax == p.ay {
        (st, ct)
    } else {
        let ks = l.splat(p.ay / p.ax) * st;
        let inv = l.splat(1.0) / l.sqrt(l.mul_add(ct, ct, ks * ks));
        (ks * inv, ct * inv)
    };
    let e = l.mul_add(l.splat(ex), cp * cp, l.splat(ey) * (sp * sp));
    let lg = log(l, u1) / (e + l.splat(2.0));
    let cos_t = exp(l, lg);
    let sin_t = l.sqrt(l.max(-expm1(l, lg + lg), zero));
    [sin_t * cp, sin_t * sp, cos_t]
}
