//! The Cook-Torrance GGX kernels (height-correlated Smith, Fresnel none or
//! Schlick), written once over [`Lanes`] and instantiated per level in
//! [`super::dispatch`].
//!
//! The algebra is the scalar path's, rearranged for f32. With
//! `Lo = ‖(αx wo.x, αy wo.y, wo.z)‖`, `Li` the same for `wi`, and `h = wo + wi`
//! unnormalized:
//! * `D(h) = 1/(π αx αy) · (|h|² / s)²`, `s = (hx/αx)² + (hy/αy)² + hz²`
//!   (no normalization of `h`);
//! * `1 + Λ(wo) = (wo.z + Lo) / (2 wo.z)` and
//!   `G2 = 1/(1 + Λo + Λi) = 2 wo.z wi.z / (wi.z Lo + wo.z Li)`, sums of
//!   positive terms with no cancellation, finite up to the horizon;
//! * `f = ks F D G2 / (4 wo.z wi.z) = ks F D / (2 (wi.z Lo + wo.z Li))`;
//! * vndf: `pdf = D / (4 wo.z (1 + Λo)) = D / (2 (wo.z + Lo))`,
//!   `weight = ks F wi.z (wo.z + Lo) / (wi.z Lo + wo.z Li)`;
//! * brdf: `pdf = D hz / (4 wo·h)`,
//!   `weight = ks F 2 wi.z (wo·h) / (hz (wi.z Lo + wo.z Li))`.
//!
//! No closures and no `array::map` here: everything must inline into the
//! `#[target_feature]` entry points for the intrinsics to inline (a closure
//! is a function of its own, compiled without the level's features).
//!
//! `sample` evaluates `f`, `pdf` and `weight` with the microfacet normal it
//! drew as the half vector (`|h| = 1`, `wo·h = wo·m`), as the scalar path
//! does; `eval_pdf` with `h = wo + wi`.

use super::lanes::Lanes;
use super::math::sincos_turns;

/// The material, in f32, as the kernels read it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GgxParams {
    pub ax: f32,
    pub ay: f32,
    pub inv_ax: f32,
    pub inv_ay: f32,
    /// `1/(π αx αy)`.
    pub inv_pi_axay: f32,
    /// `ks · F0` per channel (Schlick; `ks` without Fresnel).
    pub ks_f0: [f32; 3],
    /// `ks · (1 − F0)` per channel (0 without Fresnel).
    pub ks_1mf0: [f32; 3],
}

type V3<L> = [<L as Lanes>::F; 3];

#[inline(always)]
fn dot<L: Lanes>(l: L, a: V3<L>, b: V3<L>) -> L::F {
    l.mul_add(a[0], b[0], l.mul_add(a[1], b[1], a[2] * b[2]))
}

/// `m ? v : zero` for each of three.
#[inline(always)]
fn select3<L: Lanes>(l: L, m: L::M, v: V3<L>, zero: L::F) -> V3<L> {
    [
        l.select(m, v[0], zero),
        l.select(m, v[1], zero),
        l.select(m, v[2], zero),
    ]
}

/// `‖(αx w.x, αy w.y, w.z)‖`.
#[inline(always)]
fn stretched_len<L: Lanes>(l: L, p: &GgxParams, w: V3<L>) -> L::F {
    let x = w[0] * l.splat(p.ax);
    let y = w[1] * l.splat(p.ay);
    l.sqrt(l.mul_add(x, x, l.mul_add(y, y, w[2] * w[2])))
}

/// `f`, `pdf` and `weight` at `(wo, wi)`, and where they are meaningful
/// (both above the horizon, `wo·h > 0`).
pub(crate) struct Eval<L: Lanes> {
    pub ok: L::M,
    pub f: V3<L>,
    pub pdf: L::F,
    pub weight: V3<L>,
}

/// [`eval_at`] with the half vector `h = wo + wi` (not normalized).
#[inline(always)]
pub(crate) fn eval<L: Lanes, const VNDF: bool>(
    l: L,
    p: &GgxParams,
    wo: V3<L>,
    wi: V3<L>,
) -> Eval<L> {
    let h = [wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]];
    let hh = dot(l, h, h);
    let oh = dot(l, wo, h);
    eval_at::<L, VNDF>(l, p, wo, wi, h, hh, oh)
}

/// `f`, `pdf`, `weight` given a half vector `h` of any length (`hh = |h|²`,
/// `oh = wo·h`). The sampler passes the unit normal it drew: where `wi` is
/// nearly `−wo` (grazing retro-reflection) `wo + wi` in f32 is mostly the
/// rounding of `wi`, and the drawn normal is the accurate half vector.
#[inline(always)]
fn eval_at<L: Lanes, const VNDF: bool>(
    l: L,
    p: &GgxParams,
    wo: V3<L>,
    wi: V3<L>,
    h: V3<L>,
    hh: L::F,
    oh: L::F,
) -> Eval<L> {
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    let ok = l.gt(wo[2], zero) & l.gt(wi[2], zero) & l.gt(oh, zero);
    let cos_oh = l.min(oh / l.sqrt(hh), one);
    // D, scale-invariant in h.
    let sx = h[0] * l.splat(p.inv_ax);
    let sy = h[1] * l.splat(p.inv_ay);
    let s = l.mul_add(sx, sx, l.mul_add(sy, sy, h[2] * h[2]));
    let q = hh / s;
    let d = l.splat(p.inv_pi_axay) * q * q;
    // Height-correlated Smith.
    let lo = stretched_len(l, p, wo);
    let li = stretched_len(l, p, wi);
    let rden = one / l.mul_add(wi[2], lo, wo[2] * li);
    let dg = l.splat(0.5) * d * rden;
    // Schlick (F0 = 1 for no Fresnel): ks F = ks F0 + ks (1 − F0) (1 − c)⁵.
    let m = one - cos_oh;
    let m2 = m * m;
    let m5 = m2 * m2 * m;
    let ksf = [
        l.mul_add(l.splat(p.ks_1mf0[0]), m5, l.splat(p.ks_f0[0])),
        l.mul_add(l.splat(p.ks_1mf0[1]), m5, l.splat(p.ks_f0[1])),
        l.mul_add(l.splat(p.ks_1mf0[2]), m5, l.splat(p.ks_f0[2])),
    ];
    let (pdf, wscale) = if VNDF {
        let pdf = l.splat(0.5) * d / (wo[2] + lo);
        (pdf, wi[2] * (wo[2] + lo) * rden)
    } else {
        let pdf = l.splat(0.25) * d * h[2] / oh;
        (pdf, l.splat(2.0) * wi[2] * oh * rden / h[2])
    };
    Eval {
        ok,
        f: [ksf[0] * dg, ksf[1] * dg, ksf[2] * dg],
        pdf,
        weight: [ksf[0] * wscale, ksf[1] * wscale, ksf[2] * wscale],
    }
}

/// One vector of samples: `(valid, wi, f, pdf, weight)`, zero where not valid.
pub(crate) struct Sampled<L: Lanes> {
    pub valid: L::M,
    pub wi: V3<L>,
    pub f: V3<L>,
    pub pdf: L::F,
    pub weight: V3<L>,
}

#[inline(always)]
pub(crate) fn sample<L: Lanes, const VNDF: bool>(
    l: L,
    p: &GgxParams,
    wo: V3<L>,
    u1: L::F,
    u2: L::F,
) -> Sampled<L> {
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    let (ax, ay) = (l.splat(p.ax), l.splat(p.ay));
    let (sin, cos) = sincos_turns(l, u2);
    let m = if VNDF {
        // Heitz 2018: the stretched view direction and a basis around it.
        let w = [wo[0] * ax, wo[1] * ay, wo[2]];
        let inv = one / l.sqrt(dot(l, w, w));
        let wh = [w[0] * inv, w[1] * inv, w[2] * inv];
        let len2 = l.mul_add(wh[0], wh[0], wh[1] * wh[1]);
        let has = l.gt(len2, zero);
        let il = one / l.sqrt(len2);
        let t1 = [
            l.select(has, -wh[1] * il, one),
            l.select(has, wh[0] * il, zero),
        ];
        // t2 = wh × (t1x, t1y, 0); its z is √len2 (0 at the pole).
        let tl = l.sqrt(len2);
        let t2 = [-wh[2] * t1[1], wh[2] * t1[0], tl];
        // A point of the unit disk (p1, p2), its lower half squeezed onto
        // the visible part: p2 ← (1 − h) a + h p2 with a = √(1 − p1²) and
        // h = (1 + wh.z)/2. Written so that nothing cancels where the f32
        // result would be all rounding (the rim of the disk, u1 → 1, and
        // the rim of the visible part, grazing views): with rs = r sin,
        // (a − rs)(a + rs) = 1 − u1 exactly.
        let r = l.sqrt(u1);
        let p1 = r * cos;
        let one_m_u = one - u1;
        let a = l.sqrt(l.mul_add(u1, sin * sin, one_m_u));
        let rs = r * sin;
        // One of a ± rs is a + |rs|; the other is (1 − u1) over it.
        let big = a + l.abs(rs);
        let small = one_m_u / big;
        let rs_pos = l.gt(rs, zero);
        let a_minus = l.select(rs_pos, small, big);
        let a_plus = l.select(rs_pos, big, small);
        // 1 − h = len2 / (2 (1 + wh.z)).
        let omh = l.splat(0.5) * len2 / (one + wh[2]);
        let hv = one - omh;
        // p2 = (1 − h) a + h rs = h (a + rs) − wh.z a: small terms where
        // p2 is small at grazing views, where nh.z needs it to full precision.
        let p2 = l.mul_add(hv, a_plus, -(wh[2] * a));
        // pz² = a² − p2² = (a − p2)(a + p2) = h (a − rs) (2(1 − h) a + h (a + rs)).
        let pz = l.sqrt(hv * a_minus * l.mul_add(omh + omh, a, hv * a_plus));
        // nh.z = p2 tl + pz wh.z; for p2 < 0 through
        // (pz wh.z)² − (p2 tl)² = (a wh.z − p2) h (a + rs).
        let nz_pos = l.mul_add(p2, tl, pz * wh[2]);
        let nz_neg = (l.mul_add(a, wh[2], -p2) * hv * a_plus) / l.mul_add(pz, wh[2], -(p2 * tl));
        let nh = [
            l.mul_add(p1, t1[0], l.mul_add(p2, t2[0], pz * wh[0])),
            l.mul_add(p1, t1[1], l.mul_add(p2, t2[1], pz * wh[1])),
            l.select(l.lt(p2, zero), nz_neg, nz_pos),
        ];
        // Unstretch into the microfacet normal.
        let n = [
            ax * nh[0],
            ay * nh[1],
            l.max(nh[2], l.splat(f32::MIN_POSITIVE)),
        ];
        let inv = one / l.sqrt(dot(l, n, n));
        [n[0] * inv, n[1] * inv, n[2] * inv]
    } else {
        // D(m) cos θm: slope radius² = u/(1 − u), u below 1.
        let u = l.min(u1, l.splat(1.0 - f32::EPSILON / 2.0));
        let r = l.sqrt(u / (one - u));
        let n = [-(ax * r * cos), -(ay * r * sin), one];
        let inv = one / l.sqrt(dot(l, n, n));
        [n[0] * inv, n[1] * inv, inv]
    };
    let om = dot(l, wo, m);
    let two_om = om + om;
    let wi = [
        l.mul_add(two_om, m[0], -wo[0]),
        l.mul_add(two_om, m[1], -wo[1]),
        l.mul_add(two_om, m[2], -wo[2]),
    ];
    let e = eval_at::<L, VNDF>(l, p, wo, wi, m, one, om);
    let finite = l.is_finite(e.f[0])
        & l.is_finite(e.f[1])
        & l.is_finite(e.f[2])
        & l.is_finite(e.weight[0])
        & l.is_finite(e.weight[1])
        & l.is_finite(e.weight[2])
        & l.is_finite(e.pdf);
    let valid = l.gt(om, zero) & e.ok & l.gt(e.pdf, zero) & finite;
    Sampled {
        valid,
        wi: select3(l, valid, wi, zero),
        f: select3(l, valid, e.f, zero),
        pdf: l.select(valid, e.pdf, zero),
        weight: select3(l, valid, e.weight, zero),
    }
}

/// `(f, pdf)` of `eval_pdf`: each zero where not meaningful or not finite,
/// as the scalar path does.
#[inline(always)]
pub(crate) fn eval_pdf<L: Lanes, const VNDF: bool>(
    l: L,
    p: &GgxParams,
    wo: V3<L>,
    wi: V3<L>,
) -> (V3<L>, L::F) {
    let zero = l.splat(0.0);
    let e = eval::<L, VNDF>(l, p, wo, wi);
    let f_ok = e.ok & l.is_finite(e.f[0]) & l.is_finite(e.f[1]) & l.is_finite(e.f[2]);
    let p_ok = e.ok & l.is_finite(e.pdf);
    (select3(l, f_ok, e.f, zero), l.select(p_ok, e.pdf, zero))
}
