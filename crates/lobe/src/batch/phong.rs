//! The lecture models, Phong and Blinn-Phong (`crate::models::phong`,
//! `crate::models::blinn_phong`), in f32 lanes: one instance per model
//! (`MODEL`: [`PHONG`], [`BLINN`]) and strategy (`STRAT`: brdf, uniform,
//! cosine), the same conventions as the Cook-Torrance kernels (a child of
//! [`super`], whose helpers it shares).
//!
//! Both lobes are `ks K cosⁿ` of an angle: Phong's between `wi` and the
//! mirror of `wo`, Blinn-Phong's `θh`. Everything is written with
//! `t = 1 − cos` of that angle, computed without cancellation, and
//! `cosⁿ` by [`pow_cos`] from `t` and `c = cos` (each without cancellation), so that exponents up to 10⁷ keep their
//! precision:
//! * Phong: `t = 1 − mirror(wo)·wi` with the products split exactly by
//!   fused multiply-adds and the sum compensated (TwoSum), so that `t` is
//!   relative to itself however small (the f64 path's `1 − cos α` on the
//!   same f32 inputs);
//! * Blinn-Phong: with `h = wo + wi`, `t = (hx² + hy²) / (|h| (|h| + hz))`.
//!
//! `brdf` draws the lobe's axis angle by `cos θ = u1^(1/(n+1))` through
//! logarithms (`l = ln u1 / (n+1)`, `cos θ = e^l`, `sin θ = √(−expm1(2l))`,
//! as `crate::warp::cos_sin_of_root`), `φ = 2π u2`: Phong around the mirror
//! direction (Duff et al.'s frame), Blinn-Phong the half vector, reflected.
//! A sample's `cosⁿ` is `e^(n l)`, exact for the drawn direction, so `f`,
//! `pdf` and `weight` are those of the direction drawn (as the Cook-Torrance
//! kernels use the drawn normal). Pdfs: Phong `(n+1)/(2π) cosⁿα`,
//! Blinn-Phong `(n+1)/(2π) cosⁿθh / (4 wo·h)`, mixed with the cosine
//! lobe's `wi.z/π` with the scalar path's (constant) lobe-choice
//! probability where `kd > 0`.

use super::super::lanes::Lanes;
use super::super::math::{exp, expm1, log, pow_cos, sincos_turns};
use super::{
    COSINE, Eval, INV_PI, INV_TWO_PI, Sampled, UNIFORM, V3, cosine_hemisphere, dot, finish,
    with_weight,
};

/// `MODEL`: Phong.
pub(crate) const PHONG: u8 = 0;
/// `MODEL`: Blinn-Phong.
pub(crate) const BLINN: u8 = 1;

/// A Phong or Blinn-Phong material in f32, as the kernels read it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LectureParams {
    /// The exponent `n`.
    pub n: f32,
    /// `1/(n + 1)`: the sampler's root.
    pub inv_m: f32,
    /// `(n + 1)/(2π)`: the lobe pdf's factor.
    pub pdf_k: f32,
    /// `ks K` per channel (`K` the normalization, 1 for the lecture form).
    pub ks_norm: [f32; 3],
    /// `ks K / pdf_k`: a lobe sample's `weight / cos θi` (Phong; times
    /// `4 wo·h` for Blinn-Phong).
    pub ks_w: [f32; 3],
    /// `kd/π` per channel.
    pub kd_pi: [f32; 3],
    /// The probability of drawing from the glossy lobe (1 without a
    /// diffuse term), `Material::glossy_probability`: constant for these
    /// models, whose albedo hint does not depend on `wo`.
    pub p_glossy: f32,
    /// Whether `uc` chooses the lobe (`kd > 0`, strategy brdf).
    pub two_lobes: bool,
}

/// Knuth's TwoSum: `a + b = s + e` exactly.
#[inline(always)]
fn two_sum<L: Lanes>(a: L::F, b: L::F) -> (L::F, L::F) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `(t, c)` with `c = cos` of the lobe's angle at `(wo, wi)` and `t = 1 −
/// c`, each without cancellation, and `wo·h/|h|` (1 for Phong).
#[inline(always)]
fn lobe_t<L: Lanes, const MODEL: u8>(l: L, wo: V3<L>, wi: V3<L>) -> ((L::F, L::F), L::F) {
    if MODEL == PHONG {
        // 1 − (−wo.x wi.x − wo.y wi.y + wo.z wi.z), each product split
        // exactly (p + e), the sum compensated.
        let pz = wo[2] * wi[2];
        let ez = l.mul_add(wo[2], wi[2], -pz);
        let px = wo[0] * wi[0];
        let ex = l.mul_add(wo[0], wi[0], -px);
        let py = wo[1] * wi[1];
        let ey = l.mul_add(wo[1], wi[1], -py);
        let (s1, e1) = two_sum::<L>(l.splat(1.0), -pz);
        let (s2, e2) = two_sum::<L>(s1, px);
        let (s3, e3) = two_sum::<L>(s2, py);
        let t = s3 + ((e1 + e2 + e3) + (ex + ey - ez));
        let (c1, f1) = two_sum::<L>(pz, -px);
        let (c2, f2) = two_sum::<L>(c1, -py);
        let c = c2 + ((f1 + f2) + (ez - ex - ey));
        ((t, c), l.splat(1.0))
    } else {
        let h = [wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]];
        let r2 = l.mul_add(h[0], h[0], h[1] * h[1]);
        let hl = l.sqrt(l.mul_add(h[2], h[2], r2));
        ((r2 / (hl * (hl + h[2])), h[2] / hl), dot(l, wo, h) / hl)
    }
}

/// `(cosⁿ for f, cosⁿ for the pdf)` from `(t, c)`: zero where `c ≤ 0`,
/// except that `f` of `n = 0` is 1 everywhere (the scalar path's `0⁰ = 1`).
#[inline(always)]
fn cos_n<L: Lanes>(l: L, p: &LectureParams, (t, c): (L::F, L::F)) -> (L::F, L::F) {
    let one = l.splat(1.0);
    let lobe = l.gt(c, l.splat(0.0));
    if p.n == 0.0 {
        return (one, l.select(lobe, one, l.splat(0.0)));
    }
    let v = pow_cos(l, t, c, l.splat(p.n));
    (v, v)
}

/// `f`, `pdf`, `weight` at `(wo, wi)` given the lobe's `cos_oh` (Blinn-Phong)
/// and `cosⁿ` (for `f`, for the pdf).
#[inline(always)]
fn eval_cn<L: Lanes, const MODEL: u8, const STRAT: u8>(
    l: L,
    p: &LectureParams,
    wo: V3<L>,
    wi: V3<L>,
    cos_oh: L::F,
    (cf, cp): (L::F, L::F),
) -> Eval<L> {
    let zero = l.splat(0.0);
    let above = l.gt(wo[2], zero) & l.gt(wi[2], zero);
    let f = [
        l.mul_add(l.splat(p.ks_norm[0]), cf, l.splat(p.kd_pi[0])),
        l.mul_add(l.splat(p.ks_norm[1]), cf, l.splat(p.kd_pi[1])),
        l.mul_add(l.splat(p.ks_norm[2]), cf, l.splat(p.kd_pi[2])),
    ];
    let pd = wi[2] * l.splat(INV_PI);
    let pdf = match STRAT {
        UNIFORM => l.splat(INV_TWO_PI),
        COSINE => pd,
        _ => {
            let pg = l.splat(p.pdf_k) * cp;
            let pg = if MODEL == BLINN {
                l.select(l.gt(cos_oh, zero), pg / (l.splat(4.0) * cos_oh), zero)
            } else {
                pg
            };
            if p.p_glossy == 1.0 {
                pg
            } else {
                l.mul_add(l.splat(p.p_glossy), pg - pd, pd)
            }
        }
    };
    with_weight(above, f, pdf, wi[2])
}

/// `(f, pdf)` of `eval_pdf`: zero below the horizon or where not finite.
#[inline(always)]
pub(crate) fn eval_pdf<L: Lanes, const MODEL: u8, const STRAT: u8>(
    l: L,
    p: &LectureParams,
    wo: V3<L>,
    wi: V3<L>,
) -> (V3<L>, L::F) {
    let zero = l.splat(0.0);
    let (t, cos_oh) = lobe_t::<L, MODEL>(l, wo, wi);
    let e = eval_cn::<L, MODEL, STRAT>(l, p, wo, wi, cos_oh, cos_n(l, p, t));
    let f_ok = e.ok & l.is_finite(e.f[0]) & l.is_finite(e.f[1]) & l.is_finite(e.f[2]);
    let p_ok = e.ok & l.is_finite(e.pdf);
    (
        [
            l.select(f_ok, e.f[0], zero),
            l.select(f_ok, e.f[1], zero),
            l.select(f_ok, e.f[2], zero),
        ],
        l.select(p_ok, e.pdf, zero),
    )
}

/// One vector of samples.
#[inline(always)]
pub(crate) fn sample<L: Lanes, const MODEL: u8, const STRAT: u8>(
    l: L,
    p: &LectureParams,
    wo: V3<L>,
    u1: L::F,
    u2: L::F,
    uc: L::F,
) -> Sampled<L> {
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    let above_o = l.gt(wo[2], zero);
    if STRAT == UNIFORM || STRAT == COSINE {
        let wi = if STRAT == UNIFORM {
            let (sin, cos) = sincos_turns(l, u2);
            let r = l.sqrt(l.max(l.mul_add(-u1, u1, one), zero));
            [r * cos, r * sin, u1]
        } else {
            cosine_hemisphere(l, u1, u2)
        };
        let (t, cos_oh) = lobe_t::<L, MODEL>(l, wo, wi);
        let e = eval_cn::<L, MODEL, STRAT>(l, p, wo, wi, cos_oh, cos_n(l, p, t));
        return finish(l, above_o & l.gt(wi[2], zero), wi, e.f, e.pdf, e.weight);
    }
    // The lobe: cos θ = u1^(1/(n+1)) around its axis, φ = 2π u2.
    let lg = log(l, u1) * l.splat(p.inv_m);
    let cos_t = exp(l, lg);
    let sin2 = -expm1(l, lg + lg);
    let sin_t = l.sqrt(l.max(sin2, zero));
    let (s, c) = sincos_turns(l, u2);
    let (x, y) = (sin_t * c, sin_t * s);
    // cosⁿ of the drawn direction, exact: e^(n l) (0 at u1 = 0).
    let cn = if p.n == 0.0 {
        one
    } else {
        exp(l, l.splat(p.n) * lg)
    };
    let (wi_g, om, ok_g) = if MODEL == PHONG {
        // Duff et al.'s frame around r = mirror(wo) (r.z = wo.z > 0 where valid).
        let r = [-wo[0], -wo[1], wo[2]];
        let a = -(one / (one + r[2]));
        let b = r[0] * r[1] * a;
        let sx = [l.mul_add(r[0] * r[0], a, one), b, -r[0]];
        let ty = [b, l.mul_add(r[1] * r[1], a, one), -r[1]];
        let wi = [
            l.mul_add(sx[0], x, l.mul_add(ty[0], y, r[0] * cos_t)),
            l.mul_add(sx[1], x, l.mul_add(ty[1], y, r[1] * cos_t)),
            l.mul_add(sx[2], x, l.mul_add(ty[2], y, r[2] * cos_t)),
        ];
        (wi, one, l.gt(wi[2], zero))
    } else {
        let h = [x, y, cos_t];
        let om = dot(l, wo, h);
        let two_om = om + om;
        let wi = [
            l.mul_add(two_om, h[0], -wo[0]),
            l.mul_add(two_om, h[1], -wo[1]),
            l.mul_add(two_om, h[2], -wo[2]),
        ];
        (wi, om, l.gt(om, zero) & l.gt(wi[2], zero))
    };
    if !p.two_lobes {
        let f = [
            l.splat(p.ks_norm[0]) * cn,
            l.splat(p.ks_norm[1]) * cn,
            l.splat(p.ks_norm[2]) * cn,
        ];
        let (pdf, ws) = if MODEL == PHONG {
            (l.splat(p.pdf_k) * cn, wi_g[2])
        } else {
            let four_om = l.splat(4.0) * om;
            (l.splat(p.pdf_k) * cn / four_om, four_om * wi_g[2])
        };
        let weight = [
            l.splat(p.ks_w[0]) * ws,
            l.splat(p.ks_w[1]) * ws,
            l.splat(p.ks_w[2]) * ws,
        ];
        return finish(l, above_o & ok_g, wi_g, f, pdf, weight);
    }
    // uc < P: the lobe's direction, else a cosine-weighted one; then f and
    // the mixture pdf at it, as `Material::sample`.
    let wd = cosine_hemisphere(l, u1, u2);
    let choose = l.lt(uc, l.splat(p.p_glossy));
    let wi = [
        l.select(choose, wi_g[0], wd[0]),
        l.select(choose, wi_g[1], wd[1]),
        l.select(choose, wi_g[2], wd[2]),
    ];
    let valid = l.select_mask(choose, above_o & ok_g, above_o) & l.gt(wi[2], zero);
    let (td, cos_oh_d) = lobe_t::<L, MODEL>(l, wo, wd);
    let (cfd, cpd) = cos_n(l, p, td);
    let cos_oh = l.select(choose, om, cos_oh_d);
    let cns = (l.select(choose, cn, cfd), l.select(choose, cn, cpd));
    let e = eval_cn::<L, MODEL, STRAT>(l, p, wo, wi, cos_oh, cns);
    finish(l, valid, wi, e.f, e.pdf, e.weight)
}
