//! The Cook-Torrance kernels, written once over [`Lanes`] and instantiated
//! per level in [`super::dispatch`]: one instance per distribution (`NDF`:
//! GGX, Beckmann) and strategy (`STRAT`: vndf, brdf, uniform, cosine),
//! chosen once per block; the shadowing and Fresnel terms are block
//! constants read by a branch that every vector takes the same way.
//!
//! The algebra is the scalar path's, rearranged for f32. With
//! `Lo = ‖(αx wo.x, αy wo.y, wo.z)‖`, `Li` the same for `wi`, and `h = wo + wi`
//! unnormalized (or the drawn normal, of any length):
//! * GGX `D(h) = 1/(π αx αy) · (|h|² / s)²`, `s = (hx/αx)² + (hy/αy)² + hz²`;
//!   Beckmann `D(h) = 1/(π αx αy) · e^(−t) (|h|²/hz²)²`,
//!   `t = ((hx/αx)² + (hy/αy)²)/hz²` (both scale-invariant in `h`);
//! * GGX `1 + Λ(w) = (w.z + L)/(2 w.z)`; Beckmann
//!   `Λ(w) = (e^(−a²)/(a√π) − erfc a)/2`, `a = w.z/‖(αx w.x, αy w.y)‖`;
//! * GGX with height-correlated Smith (the fast path):
//!   `G2 = 2 wo.z wi.z / (wi.z Lo + wo.z Li)`, `f = ks F D / (2 (wi.z Lo + wo.z Li))`,
//!   vndf `pdf = D / (2 (wo.z + Lo))`; sums of positive terms, finite up to
//!   the horizon;
//! * otherwise `f = ks F D G / (4 wo.z wi.z)` with `G = 1/(1 + Λo + Λi)`,
//!   `1/((1 + Λo)(1 + Λi))` or the V-cavity `min(1, 2 hz wo.z/(wo·h),
//!   2 hz wi.z/(wi·h))`; vndf `pdf = D / (4 wo.z (1 + Λo))`;
//! * brdf `pdf = D hz / (4 wo·h)`; uniform `1/(2π)`; cosine `wi.z/π`;
//!   `weight = f wi.z / pdf`.
//!
//! No closures and no `array::map` here: everything must inline into the
//! `#[target_feature]` entry points for the intrinsics to inline (a closure
//! is a function of its own, compiled without the level's features).
//!
//! `sample` evaluates `f`, `pdf` and `weight` with the microfacet normal it
//! drew as the half vector (`wo·h = wi·h = wo·m`), as the scalar path does,
//! left unnormalized where the formulas are scale-invariant in `h` (GGX's
//! visible and `D cos` normals, Beckmann's `D cos` normal: no square root
//! and division for the length); `eval_pdf`, and `sample` for uniform and
//! cosine, with `h = wo + wi`.

use super::lanes::Lanes;
use super::math::{erfc_abs, erfc_exp, erfinv_u, erfinv_u_refined, exp, log1p, sincos_turns};

/// `NDF`: GGX.
pub(crate) const GGX: u8 = 0;
/// `NDF`: Beckmann.
pub(crate) const BECKMANN: u8 = 1;
/// `STRAT`: visible normals.
pub(crate) const VNDF: u8 = 0;
/// `STRAT`: `D(m) cos θm`.
pub(crate) const BRDF: u8 = 1;
/// `STRAT`: uniform hemisphere.
pub(crate) const UNIFORM: u8 = 2;
/// `STRAT`: cosine-weighted hemisphere.
pub(crate) const COSINE: u8 = 3;
/// `NDF`: the Blinn-Phong NDF (`blinn_ndf`).
pub(crate) const BLINN_PHONG: u8 = 2;
/// `STRAT`: GGX visible normals by spherical caps (`caps`).
pub(crate) const CAPS: u8 = 4;
/// `STRAT`: GGX bounded VNDF (`caps`).
pub(crate) const BOUNDED: u8 = 5;

// Kernels in files of their own, children of this module (they share its
// helpers): the spherical caps and bounded VNDF, the Blinn-Phong NDF, the
// Phong and Blinn-Phong models, the rough dielectric.
#[path = "blinn_ndf.rs"]
mod blinn_ndf;
#[path = "caps.rs"]
mod caps;
#[path = "dielectric.rs"]
pub(crate) mod dielectric;
#[path = "phong.rs"]
pub(crate) mod phong;
#[path = "smooth.rs"]
pub(crate) mod smooth;

const INV_SQRT_PI: f32 = 0.5 * std::f32::consts::FRAC_2_SQRT_PI;
const TWO_INV_SQRT_PI: f32 = std::f32::consts::FRAC_2_SQRT_PI;
const INV_PI: f32 = std::f32::consts::FRAC_1_PI;
const INV_TWO_PI: f32 = 0.159_154_94;

/// The shadowing term, a block constant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Shadow {
    Correlated,
    Separable,
    VCavity,
}

/// The Fresnel term times `ks`, per channel, a block constant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum FresnelP {
    /// Schlick (`F0 = 1` for no Fresnel): `ks F = ks F0 + ks (1 − F0)(1 − c)⁵`.
    Schlick { ks_f0: [f32; 3], ks_1mf0: [f32; 3] },
    /// Exact dielectric with relative index `eta`.
    Dielectric { ks: [f32; 3], eta: [f32; 3] },
    /// Exact conductor `eta + i k`.
    Conductor {
        ks: [f32; 3],
        eta: [f32; 3],
        k: [f32; 3],
    },
}

/// A Cook-Torrance lobe in f32, as the kernels read it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CtParams {
    pub ax: f32,
    pub ay: f32,
    pub inv_ax: f32,
    pub inv_ay: f32,
    /// `1/(π αx αy)`.
    pub inv_pi_axay: f32,
    pub fresnel: FresnelP,
    pub shadow: Shadow,
    /// Beckmann vndf: the starting points of the slope inversion
    /// ([`beckmann_guess_table`]); empty otherwise.
    pub guess: &'static [f32],
    /// Whether there is a glossy lobe (false: a Lambertian material).
    pub has_glossy: bool,
    /// `kd/π` per channel, the Lambertian term (0 for none).
    pub kd_pi: [f32; 3],
    /// `luminance(kd)`, the diffuse lobe's weight in the lobe choice.
    pub kd_lum: f32,
    /// Whether `uc` chooses between the glossy and the diffuse lobe (both
    /// present, strategy vndf or brdf).
    pub two_lobes: bool,
    /// Rough plastic's base in place of the Lambertian term (`kd_pi` and
    /// `kd_lum` are then 0).
    pub base: Option<PlasticBaseP>,
    /// Turquin's energy compensation of the glossy lobe.
    pub turquin: Option<TurquinP>,
}

/// Nodes of the tables below (rough plastic's transmittance, Mitsuba's
/// 64; the energy tables' cosines, lobe's 64).
pub(crate) const TABLE_NODES: usize = 64;

/// Rough plastic's base (`models::roughplastic`): `f_d = scale T(μo)
/// T(μi)`, `T` linear in `μ` between [`TABLE_NODES`] evenly spaced nodes;
/// the coating is chosen with probability `(1 − T(μo)) w / ((1 − T(μo)) w
/// + T(μo)(1 − w))`, 0 where both are 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PlasticBaseP {
    pub scale: [f32; 3],
    pub w: f32,
    pub t: [f32; TABLE_NODES],
}

/// Turquin's scaling of a glossy lobe (`energy::compensation::Turquin`):
/// `f` and `weight` times `1 + F0 (1 − E)/E`, `E = max(E(μo), e_min)`
/// linear in `√μo` between [`TABLE_NODES`] evenly spaced nodes (the energy
/// table's row at the lobe's `α`); the pdf is the single-scattering one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TurquinP {
    pub f0: [f32; 3],
    pub e: [f32; TABLE_NODES],
    /// The least `E` divided by (1e-3 for a conductor's table, 0.01 for a
    /// dielectric's).
    pub e_min: f32,
}

impl CtParams {
    /// Whether the material has a diffuse term beside the glossy lobe (a
    /// Lambertian `kd` or rough plastic's base).
    #[inline(always)]
    pub(crate) fn has_diffuse(&self) -> bool {
        self.kd_lum != 0.0 || self.kd_pi != [0.0; 3] || self.base.is_some()
    }
}

/// `table` at `x ∈ [0, 1]` (clamped), linear between its evenly spaced
/// nodes, as the scalar path's tables interpolate.
#[inline(always)]
pub(crate) fn lerp_table<L: Lanes>(l: L, table: &[f32; TABLE_NODES], x: L::F) -> L::F {
    let top = (TABLE_NODES - 1) as f32;
    let x = l.min(l.max(x, l.splat(0.0)), l.splat(1.0)) * l.splat(top);
    let i = l.min(l.floor(x), l.splat(top - 1.0));
    let a = l.gather(table, i);
    let b = l.gather(table, i + l.splat(1.0));
    l.mul_add(b - a, x - i, a)
}

/// Rough plastic's `T(μ)`.
#[inline(always)]
fn plastic_t<L: Lanes>(l: L, b: &PlasticBaseP, mu: L::F) -> L::F {
    lerp_table(l, &b.t, mu)
}

/// The glossy lobe's [`Eval`] with Turquin's scaling where the material
/// has it (`f` and `weight`; the pdf is unchanged).
#[inline(always)]
fn turquin_scaled<L: Lanes>(l: L, p: &CtParams, wo: V3<L>, e: Eval<L>) -> Eval<L> {
    let Some(t) = &p.turquin else { return e };
    let one = l.splat(1.0);
    let ev = l.max(
        lerp_table(l, &t.e, l.sqrt(l.max(wo[2], l.splat(0.0)))),
        l.splat(t.e_min),
    );
    let r = (one - ev) / ev;
    let k = [
        l.mul_add(l.splat(t.f0[0]), r, one),
        l.mul_add(l.splat(t.f0[1]), r, one),
        l.mul_add(l.splat(t.f0[2]), r, one),
    ];
    Eval {
        ok: e.ok,
        f: [e.f[0] * k[0], e.f[1] * k[1], e.f[2] * k[2]],
        pdf: e.pdf,
        weight: [e.weight[0] * k[0], e.weight[1] * k[1], e.weight[2] * k[2]],
    }
}

/// Cells of the guess table along `cos θ` and along the normal-incidence
/// slope `g = erf⁻¹(2u1 − 1) ∈ [−G_MAX, G_MAX]`.
pub(crate) const GUESS_NC: usize = 64;
pub(crate) const GUESS_NG: usize = 128;
const G_MAX: f32 = 4.0;

/// The exact (f64, the scalar path's) visible slope `x(cos θ, g)` at the
/// `(GUESS_NC + 1) × (GUESS_NG + 1)` nodes, row by row in `cos θ`, built
/// once: bilinear interpolation in it starts the Newton iteration of
/// [`beckmann_vndf_normal`] within about 1e-3 of the root, so that a vector
/// needs a few steps instead of the ~9 from `g` alone.
pub(crate) fn beckmann_guess_table() -> &'static [f32] {
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t = Vec::with_capacity((GUESS_NC + 1) * (GUESS_NG + 1));
        for i in 0..=GUESS_NC {
            // Keep off the exact horizon (cot θ = 0).
            let c = (i as f64 / GUESS_NC as f64).max(1e-4);
            for j in 0..=GUESS_NG {
                let g = f64::from(G_MAX) * (2.0 * j as f64 / GUESS_NG as f64 - 1.0);
                let u = 0.5 * libm::erfc(-g);
                let (x, _) =
                    crate::microfacet::beckmann_visible_slope_11(c, glam::DVec2::new(u, 0.5));
                t.push(x as f32);
            }
        }
        t
    })
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
fn stretched_len<L: Lanes>(l: L, p: &CtParams, w: V3<L>) -> L::F {
    let x = w[0] * l.splat(p.ax);
    let y = w[1] * l.splat(p.ay);
    l.sqrt(l.mul_add(x, x, l.mul_add(y, y, w[2] * w[2])))
}

/// `1 + Λ(w)` of Beckmann (and the Blinn-Phong NDF's Smith term), `+∞` at
/// the horizon, 1 at the normal.
#[inline(always)]
fn beckmann_lambda1<L: Lanes>(l: L, p: &CtParams, w: V3<L>) -> L::F {
    let x = w[0] * l.splat(p.ax);
    let y = w[1] * l.splat(p.ay);
    let r = l.sqrt(l.mul_add(x, x, y * y));
    let a = w[2] / r;
    let inv_a = r / w[2];
    let (erfc_a, e) = erfc_exp(l, a);
    lambda1_from(l, erfc_a, e, inv_a)
}

/// `1 + Λ = 1 + max(0, (e^(−a²)/(a √π) − erfc a)/2)` of Beckmann from
/// `erfc a`, `e^(−a²)` and `1/a` (`a = cot θ` in the stretched frame):
/// shared by [`beckmann_lambda1`] and the visible-normal sampler, which has
/// these terms from its normalization.
#[inline(always)]
fn lambda1_from<L: Lanes>(l: L, erfc_a: L::F, e: L::F, inv_a: L::F) -> L::F {
    let lam = l.splat(0.5) * l.mul_add(e * inv_a, l.splat(INV_SQRT_PI), -erfc_a);
    l.max(lam, l.splat(0.0)) + l.splat(1.0)
}

/// `ks F(c)` per channel.
#[inline(always)]
fn ks_fresnel<L: Lanes>(l: L, f: &FresnelP, c: L::F) -> V3<L> {
    let one = l.splat(1.0);
    match *f {
        FresnelP::Schlick { ks_f0, ks_1mf0 } => {
            let m = one - c;
            let m2 = m * m;
            let m5 = m2 * m2 * m;
            [
                l.mul_add(l.splat(ks_1mf0[0]), m5, l.splat(ks_f0[0])),
                l.mul_add(l.splat(ks_1mf0[1]), m5, l.splat(ks_f0[1])),
                l.mul_add(l.splat(ks_1mf0[2]), m5, l.splat(ks_f0[2])),
            ]
        }
        FresnelP::Dielectric { ks, eta } => [
            l.splat(ks[0]) * fr_dielectric(l, c, eta[0]),
            l.splat(ks[1]) * fr_dielectric(l, c, eta[1]),
            l.splat(ks[2]) * fr_dielectric(l, c, eta[2]),
        ],
        FresnelP::Conductor { ks, eta, k } => [
            l.splat(ks[0]) * fr_conductor(l, c, eta[0], k[0]),
            l.splat(ks[1]) * fr_conductor(l, c, eta[1], k[1]),
            l.splat(ks[2]) * fr_conductor(l, c, eta[2], k[2]),
        ],
    }
}

/// `ks F(cos θ)` per channel at `cos θ = wo·h/|h|` (`oh`, `hh = |h|²`);
/// without the square root and division where `F` is a constant (Schlick
/// with `F0 = 1`, Fresnel `none`).
#[inline(always)]
fn ks_fresnel_h<L: Lanes>(l: L, f: &FresnelP, oh: L::F, hh: L::F) -> V3<L> {
    match *f {
        FresnelP::Schlick { ks_f0, ks_1mf0 } if ks_1mf0 == [0.0; 3] => {
            [l.splat(ks_f0[0]), l.splat(ks_f0[1]), l.splat(ks_f0[2])]
        }
        _ => ks_fresnel(l, f, l.min(oh / l.sqrt(hh), l.splat(1.0))),
    }
}

/// Unpolarized dielectric reflectance, `c ∈ [0, 1]` (1 under total
/// internal reflection), as `crate::fresnel::fr_dielectric`.
#[inline(always)]
fn fr_dielectric<L: Lanes>(l: L, c: L::F, eta: f32) -> L::F {
    let one = l.splat(1.0);
    let e = l.splat(eta);
    let sin2_t = (one - c * c) * l.splat(1.0 / (eta * eta));
    let tir = l.gt(sin2_t, l.splat(1.0)) | l.eq(sin2_t, one);
    let ct = l.sqrt(l.max(one - sin2_t, l.splat(0.0)));
    let ec = e * c;
    let r_parl = (ec - ct) / (ec + ct);
    let ect = e * ct;
    let r_perp = (c - ect) / (c + ect);
    let r = l.splat(0.5) * l.mul_add(r_parl, r_parl, r_perp * r_perp);
    l.select(tir, one, r)
}

/// Unpolarized conductor reflectance for the index `eta + i k`, `c ∈ [0,
/// 1]`, clamped to `[0, 1]` (1 where not finite), as
/// `crate::fresnel::fr_conductor`; in the closed real form: with
/// `s² = 1 − c²`, `t = η² − k² − s²`, `A = √(t² + 4η²k²)`, `a = √((A + t)/2)`,
/// `Rs = (A + c² − 2ac)/(A + c² + 2ac)`,
/// `Rp = Rs (A c² + s⁴ − 2 a c s²)/(A c² + s⁴ + 2 a c s²)`, `R = (Rs + Rp)/2`.
#[inline(always)]
fn fr_conductor<L: Lanes>(l: L, c: L::F, eta: f32, k: f32) -> L::F {
    let one = l.splat(1.0);
    let c2 = c * c;
    let s2 = one - c2;
    let t = l.splat(eta * eta - k * k) - s2;
    let a2 = l.sqrt(l.mul_add(t, t, l.splat(4.0 * eta * eta * k * k)));
    let a = l.sqrt(l.max(l.splat(0.5) * (a2 + t), l.splat(0.0)));
    let two_ac = l.splat(2.0) * a * c;
    let rs = (a2 + c2 - two_ac) / (a2 + c2 + two_ac);
    let u = l.mul_add(a2, c2, s2 * s2);
    let v = two_ac * s2;
    let rp = rs * (u - v) / (u + v);
    let r = l.splat(0.5) * (rs + rp);
    let r = l.min(l.max(r, l.splat(0.0)), one);
    l.select(l.is_finite(r), r, one)
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
pub(crate) fn eval<L: Lanes, const NDF: u8, const STRAT: u8>(
    l: L,
    p: &CtParams,
    wo: V3<L>,
    wi: V3<L>,
) -> Eval<L> {
    let h = [wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]];
    let hh = dot(l, h, h);
    let oh = dot(l, wo, h);
    let ih = if p.shadow == Shadow::VCavity {
        dot(l, wi, h)
    } else {
        oh
    };
    eval_h::<L, NDF, STRAT>(l, p, wo, wi, h, hh, oh, ih)
}

/// [`eval`] given the half vector (as [`eval_at`]), with the diffuse term
/// and the lobe-choice mixture where the material has them.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn eval_h<L: Lanes, const NDF: u8, const STRAT: u8>(
    l: L,
    p: &CtParams,
    wo: V3<L>,
    wi: V3<L>,
    h: V3<L>,
    hh: L::F,
    oh: L::F,
    ih: L::F,
) -> Eval<L> {
    if p.has_glossy && !p.has_diffuse() {
        return eval_at::<L, NDF, STRAT>(l, p, wo, wi, h, hh, oh, ih, None);
    }
    // A diffuse term: f = glossy + kd/π; for vndf and brdf the pdf is the
    // mixture P p_g + (1 − P) cos θi/π of the lobe choice, as
    // `Material::pdf` has it.
    let zero = l.splat(0.0);
    let above = l.gt(wo[2], zero) & l.gt(wi[2], zero);
    let (fg, pg) = if p.has_glossy {
        let e = eval_at::<L, NDF, STRAT>(l, p, wo, wi, h, hh, oh, ih, None);
        (select3(l, e.ok, e.f, zero), l.select(e.ok, e.pdf, zero))
    } else {
        ([zero; 3], zero)
    };
    let pd = wi[2] * l.splat(INV_PI);
    let pdf = match STRAT {
        UNIFORM => l.splat(INV_TWO_PI),
        COSINE => pd,
        _ if !p.has_glossy => pd,
        _ => mixture_pdf(l, p, wo, pg, pd),
    };
    with_weight(above, plus_diffuse(l, p, fg, wo, wi, above), pdf, wi[2])
}

/// `P p_g + (1 − P) p_d` at `wo`, the two lobes' mixture density, with
/// `1 − P` computed on its own ([`lobe_choice`]). (Not `p_d + P (p_g −
/// p_d)`: where `P` rounds to 1, as under a plastic's coating that lets
/// almost nothing through, that cancels a tiny `p_g`, and `1 − P` from `P`
/// is mostly rounding.)
#[inline(always)]
pub(super) fn mixture_pdf<L: Lanes>(l: L, p: &CtParams, wo: V3<L>, pg: L::F, pd: L::F) -> L::F {
    let (pr, q) = lobe_choice(l, p, wo, true);
    l.mul_add(pr, pg, q * pd)
}

/// The glossy `fg` plus the diffuse term where `above` (both directions
/// above the horizon), as `Material::eval` adds them; no cosine: `kd/π`,
/// or rough plastic's `scale T(μo) T(μi)`.
#[inline(always)]
pub(super) fn plus_diffuse<L: Lanes>(
    l: L,
    p: &CtParams,
    fg: V3<L>,
    wo: V3<L>,
    wi: V3<L>,
    above: L::M,
) -> V3<L> {
    let zero = l.splat(0.0);
    // `array::map` with closures, on purpose: this is the two-lobe path,
    // inlined (cold) into every single-lobe instance too, and written out
    // in full it cost GGX brdf's sampler 35% at AVX-512 (Zen 4, `lobe
    // bench`: 370 -> 237 M/s for its `sample`): the whole instance's code
    // layout and registers, not the single-lobe work, changed.
    let d = match &p.base {
        None => p.kd_pi.map(|c| l.splat(c)),
        Some(b) => {
            let tt = plastic_t(l, b, wo[2]) * plastic_t(l, b, wi[2]);
            b.scale.map(|c| l.splat(c) * tt)
        }
    };
    [
        fg[0] + l.select(above, d[0], zero),
        fg[1] + l.select(above, d[1], zero),
        fg[2] + l.select(above, d[2], zero),
    ]
}

/// The [`Eval`] of `f` (no cosine) and `pdf` valid where `ok`, with
/// `weight = f·cos θi/pdf` (`cos_i` the cosine).
#[inline(always)]
pub(super) fn with_weight<L: Lanes>(ok: L::M, f: V3<L>, pdf: L::F, cos_i: L::F) -> Eval<L> {
    let ws = cos_i / pdf;
    Eval {
        ok,
        f,
        pdf,
        weight: [f[0] * ws, f[1] * ws, f[2] * ws],
    }
}

/// The probability of choosing the glossy lobe, as
/// `Material::glossy_probability`: `g/(g + d)`, `g = luminance(ks F(cos θo))`,
/// `d = luminance(kd)`; 1/2 where both are 0. Rough plastic's as
/// `RoughPlastic::coating_probability`.
#[inline(always)]
fn glossy_probability<L: Lanes>(l: L, p: &CtParams, wo: V3<L>) -> L::F {
    lobe_choice(l, p, wo, false).0
}

/// `(P, 1 − P)` of [`glossy_probability`], `1 − P` computed as `d/(g + d)`
/// (with `want_q`; else 0): accurate where `P` is within rounding of 1.
#[inline(always)]
fn lobe_choice<L: Lanes>(l: L, p: &CtParams, wo: V3<L>, want_q: bool) -> (L::F, L::F) {
    let zero = l.splat(0.0);
    let (g, d, none) = if let Some(b) = &p.base {
        let t = plastic_t(l, b, wo[2]);
        let ps = (l.splat(1.0) - t) * l.splat(b.w);
        let pd = t * l.splat(1.0 - b.w);
        (ps, pd, (zero, l.splat(1.0)))
    } else {
        let c = l.min(l.max(wo[2], zero), l.splat(1.0));
        let ksf = ks_fresnel(l, &p.fresnel, c);
        let g = l.mul_add(
            l.splat(0.2126),
            ksf[0],
            l.mul_add(l.splat(0.7152), ksf[1], l.splat(0.0722) * ksf[2]),
        );
        (g, l.splat(p.kd_lum), (l.splat(0.5), l.splat(0.5)))
    };
    let s = g + d;
    let some = l.gt(s, zero);
    let pr = l.select(some, g / s, none.0);
    let q = if want_q {
        l.select(some, d / s, none.1)
    } else {
        zero
    };
    (pr, q)
}

/// `f`, `pdf`, `weight` given a half vector `h` of any length (`hh = |h|²`,
/// `oh = wo·h`, `ih = wi·h`, read by the V-cavity term only). The sampler
/// passes the normal it drew: where `wi` is nearly `−wo` (grazing
/// retro-reflection) `wo + wi` in f32 is mostly the rounding of `wi`, and
/// the drawn normal is the accurate half vector. `lam1o_pre`: `1 + Λ(wo)`
/// where the caller has it (Beckmann's visible-normal sampler computes its
/// `erfc` and exponential on the way), else computed here.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn eval_at<L: Lanes, const NDF: u8, const STRAT: u8>(
    l: L,
    p: &CtParams,
    wo: V3<L>,
    wi: V3<L>,
    h: V3<L>,
    hh: L::F,
    oh: L::F,
    ih: L::F,
    lam1o_pre: Option<L::F>,
) -> Eval<L> {
    let e = eval_single::<L, NDF, STRAT>(l, p, wo, wi, h, hh, oh, ih, lam1o_pre);
    turquin_scaled(l, p, wo, e)
}

/// [`eval_at`] of the single-scattering lobe.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn eval_single<L: Lanes, const NDF: u8, const STRAT: u8>(
    l: L,
    p: &CtParams,
    wo: V3<L>,
    wi: V3<L>,
    h: V3<L>,
    hh: L::F,
    oh: L::F,
    ih: L::F,
    lam1o_pre: Option<L::F>,
) -> Eval<L> {
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    let ok = l.gt(wo[2], zero) & l.gt(wi[2], zero) & l.gt(oh, zero);
    // D, scale-invariant in h: GGX's s = sxy + hz² (its division below).
    let sx = h[0] * l.splat(p.inv_ax);
    let sy = h[1] * l.splat(p.inv_ay);
    let sxy = l.mul_add(sx, sx, sy * sy);
    let hz2 = h[2] * h[2];
    let s = sxy + hz2;
    if NDF == GGX && p.shadow == Shadow::Correlated && (STRAT == VNDF || STRAT == BRDF) {
        // The fast path: height-correlated Smith without cancellation,
        // with R = wi.z Lo + wo.z Li, P = wo.z + Lo:
        // f = ks F D/(2R), vndf pdf = D/(2P), weight = ks F wi.z P/R;
        // brdf pdf = D hz/(4 wo·h), weight = 2 ks F wi.z (wo·h)/(R hz).
        // Two divisions for vndf, 1/(s P) and 1/R, three for brdf, each
        // denominator bounded away from 0 and ∞ above the horizon.
        let lo = stretched_len(l, p, wo);
        let li = stretched_len(l, p, wi);
        let rr = l.mul_add(wi[2], lo, wo[2] * li);
        let ksf = ks_fresnel_h(l, &p.fresnel, oh, hh);
        let kd = l.splat(p.inv_pi_axay);
        let (dg, pdf, wscale) = if STRAT == VNDF {
            // 1/(s P) needs only wo and the normal, so it starts while
            // wi's stretched length (for R) is still being computed;
            // 1/R comes last. One division of the three products was one
            // long chain: splitting it cut GGX vndf s+e+p 5% (lobe bench,
            // AVX2 on Zen 3).
            let pp = wo[2] + lo;
            let isp = one / (s * pp);
            // q = hh/s, D = q²/(π αx αy).
            let q = hh * pp * isp;
            let d = kd * q * q;
            let pdf = l.splat(0.5) * d * (s * isp);
            let ir = one / rr;
            (l.splat(0.5) * d * ir, pdf, wi[2] * pp * ir)
        } else {
            // 1/s, 1/(wo·h hz) and 1/R apart, for the same reason (GGX
            // brdf s+e+p 10% faster than with 1/(s R) as one division).
            let is = one / s;
            let q = hh * is;
            let d = kd * q * q;
            let ioz = one / (oh * h[2]);
            let pdf = l.splat(0.25) * d * (h[2] * h[2]) * ioz;
            let ir = one / rr;
            let w0 = l.splat(2.0) * (oh * oh) * ioz;
            (l.splat(0.5) * d * ir, pdf, w0 * wi[2] * ir)
        };
        return Eval {
            ok,
            f: [ksf[0] * dg, ksf[1] * dg, ksf[2] * dg],
            pdf,
            weight: [ksf[0] * wscale, ksf[1] * wscale, ksf[2] * wscale],
        };
    }
    let d = if NDF == GGX {
        let q = hh / s;
        l.splat(p.inv_pi_axay) * q * q
    } else {
        let inv_z2 = one / hz2;
        let q = hh * inv_z2;
        l.splat(p.inv_pi_axay) * exp(l, -(sxy * inv_z2)) * (q * q)
    };
    let d = if NDF == BLINN_PHONG {
        blinn_ndf::d(l, p, h, hh)
    } else {
        d
    };
    let ksf = ks_fresnel_h(l, &p.fresnel, oh, hh);
    // General: 1 + Λo (also the vndf pdf's), 1 + Λi, G.
    let (lam1o, lo) = if NDF == GGX {
        let lo = stretched_len(l, p, wo);
        (l.splat(0.5) * (wo[2] + lo) / wo[2], lo)
    } else {
        // A match, not `unwrap_or_else`: a closure does not inherit the
        // caller's target features, and where it is not inlined (the test
        // profile's many codegen units) its vector operations become calls
        // (the batch chi-square grid ran 3.5 times as long).
        let lam1o = match lam1o_pre {
            Some(v) => v,
            None => beckmann_lambda1(l, p, wo),
        };
        (lam1o, zero)
    };
    let g = match p.shadow {
        Shadow::VCavity => {
            let two_hz = h[2] + h[2];
            let go = two_hz * wo[2] / oh;
            let gi = two_hz * wi[2] / ih;
            l.max(l.min(l.min(one, go), gi), zero)
        }
        shadow => {
            let lam1i = if NDF == GGX {
                let li = stretched_len(l, p, wi);
                l.splat(0.5) * (wi[2] + li) / wi[2]
            } else {
                beckmann_lambda1(l, p, wi)
            };
            if shadow == Shadow::Correlated {
                one / (lam1o + lam1i - one)
            } else {
                one / (lam1o * lam1i)
            }
        }
    };
    let dg = d * g * (l.splat(0.25) / (wo[2] * wi[2]));
    let pdf = match STRAT {
        VNDF if NDF == GGX => l.splat(0.5) * d / (wo[2] + lo),
        VNDF => l.splat(0.25) * d / (wo[2] * lam1o),
        BRDF => l.splat(0.25) * d * h[2] / oh,
        UNIFORM => l.splat(INV_TWO_PI),
        _ => wi[2] * l.splat(INV_PI),
    };
    let f = [ksf[0] * dg, ksf[1] * dg, ksf[2] * dg];
    let ws = wi[2] / pdf;
    Eval {
        ok,
        f,
        pdf,
        weight: [f[0] * ws, f[1] * ws, f[2] * ws],
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

/// Heitz 2018's visible GGX normal for `wo`, with `(sin, cos)` of `2π u2`,
/// not normalized: `(n, |n|²)`, `n` along the unit normal the scalar path
/// draws (the evaluation is scale-invariant in the half vector, and the
/// reflection divides by `|n|²`: no square root for the length).
///
/// Three divisions per vector: one reciprocal for the basis and `1 − h`,
/// one for `1 − u1` over `a + |rs|`, one for the normal's `z` where `p2 < 0`.
#[inline(always)]
fn ggx_vndf_normal<L: Lanes>(
    l: L,
    p: &CtParams,
    wo: V3<L>,
    u1: L::F,
    sin: L::F,
    cos: L::F,
) -> (V3<L>, L::F) {
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    let (ax, ay) = (l.splat(p.ax), l.splat(p.ay));
    // The stretched view direction w, |w| = wl, its tangent length txy,
    // and a basis around it.
    let w = [wo[0] * ax, wo[1] * ay, wo[2]];
    let sxy2 = l.mul_add(w[0], w[0], w[1] * w[1]);
    let has = l.gt(sxy2, zero);
    let txy = l.sqrt(sxy2);
    let wl = l.sqrt(l.mul_add(w[2], w[2], sxy2));
    // One reciprocal r = 1/(tx wl e), e = wl + w.z, tx = txy (1 at the pole):
    // 1/txy = wl e r, 1/wl = tx e r, and 1 − h = (1 − wh.z)/2 =
    // txy²/(2 wl e) (no cancellation near the normal).
    let tx = l.select(has, txy, one);
    let e = wl + w[2];
    let wle = wl * e;
    let r = one / (tx * wle);
    let il = wle * r;
    let inv = tx * e * r;
    let whz = w[2] * inv;
    let t1 = [
        l.select(has, -w[1] * il, one),
        l.select(has, w[0] * il, zero),
    ];
    // t2 = wh × (t1x, t1y, 0); its z is the tangent length of wh (0 at the pole).
    let tl = txy * inv;
    let t2 = [-whz * t1[1], whz * t1[0], tl];
    // A point of the unit disk (p1, p2), its lower half squeezed onto
    // the visible part: p2 ← (1 − h) a + h p2 with a = √(1 − p1²) and
    // h = (1 + wh.z)/2. Written so that nothing cancels where the f32
    // result would be all rounding (the rim of the disk, u1 → 1, and
    // the rim of the visible part, grazing views): with rs = r sin,
    // (a − rs)(a + rs) = 1 − u1 exactly.
    let rt = l.sqrt(u1);
    let p1 = rt * cos;
    let one_m_u = one - u1;
    let a = l.sqrt(l.mul_add(u1, sin * sin, one_m_u));
    let rs = rt * sin;
    // One of a ± rs is a + |rs|; the other is (1 − u1) over it.
    let big = a + l.abs(rs);
    let small = one_m_u / big;
    let rs_pos = l.gt(rs, zero);
    let a_minus = l.select(rs_pos, small, big);
    let a_plus = l.select(rs_pos, big, small);
    let omh = l.splat(0.5) * (txy * txy) * (tx * r);
    let hv = one - omh;
    // p2 = (1 − h) a + h rs = h (a + rs) − wh.z a: small terms where
    // p2 is small at grazing views, where nh.z needs it to full precision.
    let p2 = l.mul_add(hv, a_plus, -(whz * a));
    // pz² = a² − p2² = (a − p2)(a + p2) = h (a − rs) (2(1 − h) a + h (a + rs)).
    let pz = l.sqrt(hv * a_minus * l.mul_add(omh + omh, a, hv * a_plus));
    // nh.z = p2 tl + pz wh.z; for p2 < 0 through
    // (pz wh.z)² − (p2 tl)² = (a wh.z − p2) h (a + rs).
    let nz_pos = l.mul_add(p2, tl, pz * whz);
    let nz_neg = (l.mul_add(a, whz, -p2) * hv * a_plus) / l.mul_add(pz, whz, -(p2 * tl));
    let whx = w[0] * inv;
    let why = w[1] * inv;
    let nh = [
        l.mul_add(p1, t1[0], l.mul_add(p2, t2[0], pz * whx)),
        l.mul_add(p1, t1[1], l.mul_add(p2, t2[1], pz * why)),
        l.select(l.lt(p2, zero), nz_neg, nz_pos),
    ];
    // Unstretch into the microfacet normal, of length between min(α, 1)
    // and max(α, 1).
    let n = [
        ax * nh[0],
        ay * nh[1],
        l.max(nh[2], l.splat(f32::MIN_POSITIVE)),
    ];
    (n, dot(l, n, n))
}

/// Most Newton steps of the Beckmann slope inversion (each lane stops when
/// its step falls under 4e-7 relative; measured: at most 9 in the tests).
const BECKMANN_MAX_STEPS: usize = 24;

/// A Newton step of the Beckmann slope inversion under this times
/// `max(|x|, 1)` ends the lane's iteration. Measured against 1e-3 (grid
/// test, AVX2): 1.81 instead of 2.54 steps per vector, but the sampled
/// directions drift up to 2.1e-4 from the scalar path's (beyond the tests'
/// 1e-4).
const BECKMANN_STEP_TOL: f32 = 1e-4;

/// `e⁻¹⁶`, where Giles' `erf⁻¹` stops being accurate (`w = 16`).
const E_MINUS_16: f32 = 1.125_351_7e-7;

#[cfg(test)]
thread_local! {
    /// Newton steps and calls (vectors) of the Beckmann inversion on this
    /// thread, for the tests' report.
    pub(crate) static STEPS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
    pub(crate) static STEPS_CALLS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Heitz and d'Eon 2014's visible Beckmann normal for `wo`, as the scalar
/// `Microfacet::sample_visible` draws it: the slope along the stretched
/// view azimuth inverts its CDF `(erfc(−x) + tanθ e^(−x²)/√π) / (erfc(−cotθ)
/// + tanθ e^(−cot²θ)/√π)` (written with `erfc`, relative to itself in the
/// lower tail) by Newton's method inside a bisection bracket, each lane
/// frozen once converged (so a lane's result does not depend on its
/// neighbours); the other slope is `erf⁻¹(2u2 − 1)`.
#[inline(always)]
fn beckmann_vndf_normal<L: Lanes>(
    l: L,
    p: &CtParams,
    wo: V3<L>,
    u1: L::F,
    u2: L::F,
) -> (V3<L>, L::F) {
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    let (ax, ay) = (l.splat(p.ax), l.splat(p.ay));
    let w = [wo[0] * ax, wo[1] * ay, wo[2]];
    let len2 = l.mul_add(w[0], w[0], w[1] * w[1]);
    let sl = l.sqrt(len2);
    let inv = one / l.sqrt(len2 + w[2] * w[2]);
    // sin θ from the tangent part: accurate near the normal.
    let (sin_t, cos_t) = (sl * inv, w[2] * inv);
    let has = l.gt(len2, zero);
    let il = one / sl;
    let cphi = l.select(has, l.min(w[0] * il, one), one);
    let sphi = l.select(has, l.max(l.min(w[1] * il, one), -one), zero);
    let cphi = l.max(cphi, -one);
    let lo_u = l.splat(1e-12);
    let hi_u = l.splat(1.0 - f32::EPSILON / 2.0);
    let u1 = l.min(l.max(u1, lo_u), hi_u);
    let u2 = l.min(l.max(u2, lo_u), hi_u);
    // Giles' erf⁻¹ is good to 2.6e-7 where w = −ln(4u(1 − u)) < 16; the
    // refined one (three logarithms, two Newton steps) only for the vectors
    // with a lane beyond (u2 within 3e-8 of 0 or 1: in practice u2 = 0).
    // Lane by lane the same value either way.
    let sy = {
        // w ≥ 16 where 4u(1 − u) ≤ e⁻¹⁶ (no logarithm of its own).
        let plain = erfinv_u(l, u2);
        let tail = !l.gt(l.splat(4.0) * u2 * (one - u2), l.splat(E_MINUS_16));
        if l.any(tail) {
            l.select(tail, erfinv_u_refined(l, u2), plain)
        } else {
            plain
        }
    };
    let tan_t = sin_t / cos_t;
    let cot_t = cos_t / sin_t;
    let k = tan_t * l.splat(INV_SQRT_PI);
    // erfc(cot θ), and the normalization with 1 + erf(cot θ) = 2 − erfc(cot θ).
    let (erfc_cot, e_top) = erfc_abs(l, cot_t);
    let norm = one / l.mul_add(k, e_top, l.splat(2.0) - erfc_cot);
    // Above u1 = 1/2 the residual is written with 1 − CDF (relative to
    // itself where u1 → 1): 1 − CDF = norm ((erfc x − erfc cot θ) + k (e^(−cot²θ) − e^(−x²))).
    let upper = l.gt(u1, l.splat(0.5));
    let one_m_u1 = one - u1;
    let mut lo = l.splat(-8.0);
    let mut hi = l.min(cot_t, l.splat(9.0));
    // The start: bilinear in the table at (cos θ, g = erf⁻¹(2u1 − 1)).
    let g = erfinv_u(l, u1);
    let fc = cos_t * l.splat(GUESS_NC as f32);
    let ic = l.min(l.floor(fc), l.splat(GUESS_NC as f32 - 1.0));
    let tc = fc - ic;
    let fg = l.mul_add(
        l.min(l.max(g, l.splat(-G_MAX)), l.splat(G_MAX)),
        l.splat(GUESS_NG as f32 / (2.0 * G_MAX)),
        l.splat(GUESS_NG as f32 / 2.0),
    );
    let ig = l.min(l.floor(fg), l.splat(GUESS_NG as f32 - 1.0));
    let tg = fg - ig;
    let row = l.splat((GUESS_NG + 1) as f32);
    let i00 = l.mul_add(ic, row, ig);
    let t = p.guess;
    let x00 = l.gather(t, i00);
    let x01 = l.gather(t, i00 + one);
    let x10 = l.gather(t, i00 + row);
    let x11 = l.gather(t, i00 + row + one);
    let x0 = l.mul_add(tg, x01 - x00, x00);
    let x1 = l.mul_add(tg, x11 - x10, x10);
    let table_x = l.mul_add(tc, x1 - x0, x0);
    // Beyond the table's g (the tails), g itself.
    let in_table = l.lt(l.abs(g), l.splat(G_MAX));
    let mut x = l.min(l.max(l.select(in_table, table_x, g), lo), hi);
    let mut done = l.lt(one, zero);
    let deriv_k = norm * l.splat(TWO_INV_SQRT_PI);
    for _ in 0..BECKMANN_MAX_STEPS {
        let (ez, e) = erfc_abs(l, l.abs(x));
        let two_m = l.splat(2.0) - ez;
        let xneg = l.lt(x, zero);
        let erfc_negx = l.select(xneg, ez, two_m);
        let erfc_x = l.select(xneg, two_m, ez);
        let v_lo = l.mul_add(norm, l.mul_add(k, e, erfc_negx), -u1);
        let v_hi = one_m_u1 - norm * l.mul_add(k, e_top - e, erfc_x - erfc_cot);
        let value = l.select(upper, v_hi, v_lo);
        let active = !done;
        let pos = l.gt(value, zero);
        hi = l.select(pos & active, x, hi);
        lo = l.select(!pos & active, x, lo);
        let deriv = deriv_k * e * l.mul_add(-x, tan_t, one);
        let next = x - value / deriv;
        // Inclusive: a converged step lands on the bracket's end it set.
        let inside = !(l.lt(next, lo) | l.gt(next, hi)) & l.is_finite(next);
        let xn = l.select(inside, next, l.splat(0.5) * (lo + hi));
        // Converged when the Newton step is under 1e-4 of max(|x|, 1)
        // (slopes are of order 1 in units of alpha): Newton's error after a
        // step s is about s² F''/(2F'), under 1e-7 here (the tests measure
        // the result against the scalar path's, converged to 1e-14).
        let small = inside
            & !l.gt(
                l.abs(xn - x),
                l.mul_add(
                    l.max(l.abs(x), one),
                    l.splat(BECKMANN_STEP_TOL),
                    l.splat(0.0),
                ),
            );
        x = l.select(active, xn, x);
        done = done | small | l.eq(value, zero);
        #[cfg(test)]
        STEPS.with(|s| s.set(s.get() + 1));
        if !l.any(!done) {
            break;
        }
    }
    #[cfg(test)]
    STEPS_CALLS.with(|s| s.set(s.get() + 1));
    let sx = x;
    // Rotate back to the view azimuth, then stretch.
    let mx = l.mul_add(cphi, sx, -(sphi * sy));
    let my = l.mul_add(sphi, sx, cphi * sy);
    let n = [-(ax * mx), -(ay * my), one];
    let inv = one / l.sqrt(dot(l, n, n));
    // 1 + Λ(wo) from the terms of the normalization.
    (
        [n[0] * inv, n[1] * inv, inv],
        lambda1_from(l, erfc_cot, e_top, tan_t),
    )
}

#[inline(always)]
pub(crate) fn sample<L: Lanes, const NDF: u8, const STRAT: u8>(
    l: L,
    p: &CtParams,
    wo: V3<L>,
    u1: L::F,
    u2: L::F,
    uc: L::F,
) -> Sampled<L> {
    if STRAT == CAPS || STRAT == BOUNDED {
        return caps::sample::<L, STRAT>(l, p, wo, u1, u2, uc);
    }
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    let (ax, ay) = (l.splat(p.ax), l.splat(p.ay));
    let e;
    let wi;
    let mut valid = l.gt(wo[2], zero);
    if (STRAT == VNDF || STRAT == BRDF) && !p.has_glossy {
        // A Lambertian material: its own sampler, cosine-weighted.
        let wi = cosine_hemisphere(l, u1, u2);
        let e = eval::<L, NDF, STRAT>(l, p, wo, wi);
        return finish(l, valid & l.gt(wi[2], zero), wi, e.f, e.pdf, e.weight);
    }
    if STRAT == VNDF || STRAT == BRDF {
        // The drawn normal m and |m|² (not normalized: the evaluation is
        // scale-invariant in the half vector); Beckmann vndf's 1 + Λ(wo).
        let mut lam1o = None;
        let (m, mm) = if STRAT == VNDF && NDF == GGX {
            let (sin, cos) = sincos_turns(l, u2);
            ggx_vndf_normal(l, p, wo, u1, sin, cos)
        } else if STRAT == VNDF {
            let (m, lam) = beckmann_vndf_normal(l, p, wo, u1, u2);
            lam1o = Some(lam);
            (m, one)
        } else if NDF == BLINN_PHONG {
            (blinn_ndf::sample_normal(l, p, u1, u2), one)
        } else {
            // D(m) cos θm: slope radius² u/(1 − u) (GGX), −ln(1 − u)
            // (Beckmann), u below 1; GGX's normal (−αx r cos, −αy r sin, 1)
            // times √(1 − u), no division.
            let (sin, cos) = sincos_turns(l, u2);
            let u = l.min(u1, l.splat(1.0 - f32::EPSILON / 2.0));
            let (r, z) = if NDF == GGX {
                (l.sqrt(u), l.sqrt(one - u))
            } else {
                (l.sqrt(-log1p(l, -u)), one)
            };
            let n = [-(ax * r * cos), -(ay * r * sin), z];
            (n, dot(l, n, n))
        };
        let r = reflect_or_diffuse(l, p, wo, m, mm, u1, u2, uc);
        wi = r.wi;
        if p.two_lobes {
            let e = eval_h::<L, NDF, STRAT>(l, p, wo, wi, r.h, r.hh, r.oh, r.ih);
            return finish(l, r.valid, wi, e.f, e.pdf, e.weight);
        }
        valid = r.valid;
        e = eval_at::<L, NDF, STRAT>(l, p, wo, wi, r.h, r.hh, r.oh, r.ih, lam1o);
        valid = valid & e.ok;
    } else {
        wi = if STRAT == UNIFORM {
            let (sin, cos) = sincos_turns(l, u2);
            let r = l.sqrt(l.max(l.mul_add(-u1, u1, one), zero));
            [r * cos, r * sin, u1]
        } else {
            cosine_hemisphere(l, u1, u2)
        };
        e = eval::<L, NDF, STRAT>(l, p, wo, wi);
        // f is zero where the lobe is (wo·h ≤ 0), not a failed sample.
        let f = select3(l, e.ok, e.f, zero);
        let weight = select3(l, e.ok, e.weight, zero);
        return finish(l, valid & l.gt(wi[2], zero), wi, f, e.pdf, weight);
    }
    finish(l, valid, wi, e.f, e.pdf, e.weight)
}

/// `wo` reflected about a drawn microfacet normal, with what `f` and the
/// pdf are evaluated at: for one lobe, the normal itself as the half vector
/// (`|h|² = mm`, `wo·h = wi·h = wo·m`); where `uc` chooses between the lobe
/// and the diffuse term (`p.two_lobes`), as `Material::sample` does: `uc <
/// P` keeps the reflection, else a cosine-weighted direction with `h = wo +
/// wi` (the drawn normal stays the half vector where the lobe drew: accurate
/// where `wo + wi` is mostly rounding).
pub(crate) struct Reflected<L: Lanes> {
    /// `wo` above the horizon and the direction a sample (`wo·m > 0` for
    /// the lobe's, `wi.z > 0` for the diffuse term's).
    pub valid: L::M,
    pub wi: V3<L>,
    pub h: V3<L>,
    pub hh: L::F,
    pub oh: L::F,
    pub ih: L::F,
}

#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn reflect_or_diffuse<L: Lanes>(
    l: L,
    p: &CtParams,
    wo: V3<L>,
    m: V3<L>,
    mm: L::F,
    u1: L::F,
    u2: L::F,
    uc: L::F,
) -> Reflected<L> {
    let zero = l.splat(0.0);
    let om = dot(l, wo, m);
    // 2 (wo·m̂) m̂ = 2 (wo·m)/|m|² m (one division, none where |m| = 1).
    let two_om = (om + om) / mm;
    let wi = [
        l.mul_add(two_om, m[0], -wo[0]),
        l.mul_add(two_om, m[1], -wo[1]),
        l.mul_add(two_om, m[2], -wo[2]),
    ];
    let valid = l.gt(wo[2], zero) & l.gt(om, zero);
    if !p.two_lobes {
        return Reflected {
            valid,
            wi,
            h: m,
            hh: mm,
            oh: om,
            ih: om,
        };
    }
    let wd = cosine_hemisphere(l, u1, u2);
    let choose = l.lt(uc, glossy_probability(l, p, wo));
    let wi = [
        l.select(choose, wi[0], wd[0]),
        l.select(choose, wi[1], wd[1]),
        l.select(choose, wi[2], wd[2]),
    ];
    let valid = l.select_mask(choose, valid, l.gt(wo[2], zero)) & l.gt(wi[2], zero);
    let hd = [wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]];
    let h = [
        l.select(choose, m[0], hd[0]),
        l.select(choose, m[1], hd[1]),
        l.select(choose, m[2], hd[2]),
    ];
    let hh = l.select(choose, mm, dot(l, hd, hd));
    let oh = l.select(choose, om, dot(l, wo, hd));
    let ih = if p.shadow == Shadow::VCavity {
        l.select(choose, om, dot(l, wi, hd))
    } else {
        oh
    };
    Reflected {
        valid,
        wi,
        h,
        hh,
        oh,
        ih,
    }
}

/// The sample where `valid`, its pdf positive and everything finite; zeros
/// elsewhere.
#[inline(always)]
fn finish<L: Lanes>(
    l: L,
    valid: L::M,
    wi: V3<L>,
    f: V3<L>,
    pdf: L::F,
    weight: V3<L>,
) -> Sampled<L> {
    let zero = l.splat(0.0);
    // All seven finite at once: f, weight and pdf are never negative, so
    // their sum is finite exactly where each is (NaN and ∞ carry through a
    // sum of non-negative terms; finite terms below f32::MAX/7 stay finite).
    let sum = (f[0] + f[1]) + (f[2] + weight[0]) + ((weight[1] + weight[2]) + pdf);
    let finite = l.is_finite(sum);
    let valid = valid & l.gt(pdf, zero) & finite;
    Sampled {
        valid,
        wi: select3(l, valid, wi, zero),
        f: select3(l, valid, f, zero),
        pdf: l.select(valid, pdf, zero),
        weight: select3(l, valid, weight, zero),
    }
}

/// Shirley and Chiu's concentric map of `(u1, u2)` onto the unit disk,
/// lifted to the hemisphere, as `crate::warp::square_to_cosine_hemisphere`.
#[inline(always)]
fn cosine_hemisphere<L: Lanes>(l: L, u1: L::F, u2: L::F) -> V3<L> {
    let zero = l.splat(0.0);
    let one = l.splat(1.0);
    let ox = l.mul_add(u1, l.splat(2.0), -one);
    let oy = l.mul_add(u2, l.splat(2.0), -one);
    let xbig = l.gt(l.abs(ox), l.abs(oy));
    // θ = π/4 · oy/ox, or π/2 − π/4 · ox/oy: in turns, /8.
    let q = l.select(xbig, oy / ox, ox / oy);
    let t = l.select(
        xbig,
        q * l.splat(0.125),
        l.mul_add(q, l.splat(-0.125), l.splat(0.25)),
    );
    let r = l.select(xbig, ox, oy);
    let (s, c) = sincos_turns(l, t);
    let origin = l.eq(ox, zero) & l.eq(oy, zero);
    let dx = l.select(origin, zero, r * c);
    let dy = l.select(origin, zero, r * s);
    // 1 − |d|² = (1 − |r|)(1 + |r|), exact where the disk's rim makes
    // 1 − |d|² all rounding.
    let ar = l.abs(r);
    let z = l.sqrt(l.max((one - ar) * (one + ar), zero));
    [dx, dy, z]
}

/// `(f, pdf)` of `eval_pdf`: each zero where not meaningful or not finite,
/// as the scalar path does.
#[inline(always)]
pub(crate) fn eval_pdf<L: Lanes, const NDF: u8, const STRAT: u8>(
    l: L,
    p: &CtParams,
    wo: V3<L>,
    wi: V3<L>,
) -> (V3<L>, L::F) {
    // The caps draw the visible normals: vndf's f and pdf.
    if STRAT == CAPS {
        return eval_pdf::<L, NDF, VNDF>(l, p, wo, wi);
    }
    if STRAT == BOUNDED {
        return caps::eval_pdf_bounded(l, p, wo, wi);
    }
    let zero = l.splat(0.0);
    let e = eval::<L, NDF, STRAT>(l, p, wo, wi);
    let f_ok = e.ok & l.is_finite(e.f[0]) & l.is_finite(e.f[1]) & l.is_finite(e.f[2]);
    let above = l.gt(wo[2], zero) & l.gt(wi[2], zero);
    // Uniform and cosine have a pdf wherever both are above the horizon.
    let p_ok = if STRAT == UNIFORM || STRAT == COSINE {
        above
    } else {
        e.ok
    } & l.is_finite(e.pdf);
    (select3(l, f_ok, e.f, zero), l.select(p_ok, e.pdf, zero))
}
