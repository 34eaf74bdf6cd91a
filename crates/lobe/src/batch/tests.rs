//! The batch path against the scalar f64 reference, at every level this
//! CPU has (the others are reported as skipped).
//!
//! Tolerances, each measured and printed (`--nocapture`):
//! * validity: the same mask, except where `wi` is within 1e-5 of the
//!   horizon (for either path; measured: no exception needed);
//! * `wi`: within 1e-5 absolute of the scalar sample's;
//! * `f`, `pdf`, `weight` of a sample: within 1e-4 relative of the scalar
//!   sample's (absolute floor 1e-30), plus twice what the difference of the
//!   two `wi` explains: the largest relative change of the f64 value when
//!   its `wi` moves by that much. An f32 direction is only good to ~1e-7,
//!   and where the lobe is sharp (alpha = 1e-4: `D` moves by 1e-4 per 1e-8
//!   of direction) or `wi` grazes the horizon, no f32 sampler can do
//!   better; the test prints how many samples needed that allowance (about
//!   one in 10⁴) and the largest error where the direction explains less
//!   than 1e-5;
//! * `eval_pdf`: within 1e-4 relative of the scalar `eval_pdf` on the same
//!   f32 inputs, floor 1e-30, zero where the scalar is zero except within
//!   1e-5 of the horizon;
//! * no NaN or infinity anywhere.

use super::*;
use crate::models::CookTorrance;
use crate::{Microfacet, Ndf};
use glam::{DVec2, DVec3};
use rand::{Rng, RngExt, SeedableRng};
use rand_pcg::Pcg64;

const HORIZON: f64 = 1e-5;
const REL: f64 = 1e-4;
const FLOOR: f64 = 1e-30;

fn ggx(ax: f64, ay: f64, fresnel: Fresnel, ks: Rgb) -> Material {
    let mf = Microfacet::new(Ndf::Ggx, ax, ay).unwrap();
    let lobe = CookTorrance::new(ks, mf, Shadowing::SmithCorrelated, fresnel).unwrap();
    Material::with_diffuse(Rgb::ZERO, Glossy::CookTorrance(lobe)).unwrap()
}

/// The levels to test, and a note of the skipped ones.
pub(super) fn levels(test: &str) -> Vec<SimdLevel> {
    SimdLevel::ALL
        .into_iter()
        .filter(|l| {
            let ok = l.is_available();
            if !ok {
                eprintln!("{test}: level {l} skipped (not on this CPU)");
            }
            ok
        })
        .collect()
}

/// A uniform f32 in [0, 1), 24 random bits.
pub(super) fn uniform(rng: &mut impl Rng) -> f32 {
    (rng.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// A view direction: 10% at cos θ = 1e-7, 10% with cos θ log-uniform in
/// [1e-7, 1e-2], 1% at the normal, the rest uniform over the hemisphere.
pub(super) fn random_wo(rng: &mut impl Rng) -> [f32; 3] {
    let k: f64 = rng.random();
    let z: f64 = if k < 0.1 {
        1e-7
    } else if k < 0.2 {
        10f64.powf(rng.random_range(-7.0..-2.0))
    } else if k < 0.21 {
        1.0
    } else {
        1.0 - rng.random::<f64>()
    };
    let phi = std::f64::consts::TAU * rng.random::<f64>();
    let s = (1.0 - z * z).max(0.0).sqrt();
    [(s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32]
}

pub(super) fn d3(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0].into(), v[1].into(), v[2].into())
}

/// The materials of the comparison: fixed corners, then random alphas in
/// [1e-4, 1] with anisotropy up to 100, random Fresnel and ks.
fn materials(rng: &mut impl Rng) -> Vec<Material> {
    let mut v = vec![
        ggx(1e-4, 1e-4, Fresnel::None, Rgb::ONE),
        ggx(1.0, 1.0, Fresnel::None, Rgb::ONE),
        ggx(0.2, 0.2, Fresnel::None, Rgb::ONE),
        ggx(1e-4, 1e-2, Fresnel::None, Rgb::ONE),
        ggx(
            1e-2,
            1.0,
            Fresnel::Schlick {
                f0: Rgb::splat(0.04),
            },
            Rgb::ONE,
        ),
        ggx(
            1.0,
            1e-2,
            Fresnel::Schlick {
                f0: Rgb::new(0.9, 0.6, 0.3),
            },
            Rgb::new(0.5, 1.0, 0.8),
        ),
    ];
    while v.len() < 64 {
        let ax = 10f64.powf(rng.random_range(-4.0..0.0));
        let ay = (ax * 10f64.powf(rng.random_range(-2.0..2.0))).clamp(1e-4, 1.0);
        let fresnel = if rng.random::<bool>() {
            Fresnel::None
        } else {
            Fresnel::Schlick {
                f0: Rgb::new(rng.random(), rng.random(), rng.random()),
            }
        };
        let ks = Rgb::new(rng.random(), rng.random(), rng.random());
        v.push(ggx(ax, ay, fresnel, ks));
    }
    v
}

/// Inputs of one material: `n` view directions and uniforms (1% at the
/// ends 0 and 1 − 2⁻²⁴).
pub(super) struct Inputs {
    wo: [Vec<f32>; 3],
    u1: Vec<f32>,
    u2: Vec<f32>,
    uc: Vec<f32>,
}

pub(super) fn inputs(rng: &mut impl Rng, n: usize) -> Inputs {
    let mut wo = [vec![], vec![], vec![]];
    let (mut u1, mut u2, mut uc) = (vec![], vec![], vec![]);
    for _ in 0..n {
        uc.push(uniform(rng));
        let w = random_wo(rng);
        for c in 0..3 {
            wo[c].push(w[c]);
        }
        let mut u = [uniform(rng), uniform(rng)];
        if rng.random::<f64>() < 0.01 {
            u[rng.random_range(0..2)] = if rng.random() {
                0.0
            } else {
                1.0 - f32::EPSILON / 2.0
            };
        }
        u1.push(u[0]);
        u2.push(u[1]);
    }
    Inputs { wo, u1, u2, uc }
}

impl Inputs {
    pub(super) fn input(&self) -> SampleInput<'_> {
        SampleInput {
            wo: self.wo(),
            u1: &self.u1,
            u2: &self.u2,
            uc: Some(&self.uc),
        }
    }
    pub(super) fn wo(&self) -> Dirs<'_> {
        Dirs {
            x: &self.wo[0],
            y: &self.wo[1],
            z: &self.wo[2],
        }
    }
    fn wo_at(&self, i: usize) -> DVec3 {
        d3([self.wo[0][i], self.wo[1][i], self.wo[2][i]])
    }
}

/// `|a − b| / (|b| + floor)` with the relative tolerance's floor, 0 when
/// both are tiny.
pub(super) fn rel_err(a: f64, b: f64) -> f64 {
    let d = (a - b).abs();
    if d <= FLOOR { 0.0 } else { d / b.abs() }
}

#[derive(Default, Debug)]
pub(super) struct Worst {
    mask_exempt: usize,
    mask_bad: Vec<String>,
    wi_abs: f64,
    /// `wi` beyond 1e-5 but within 1e-5 + twice `wi_rounding_change`.
    pub(super) wi_explained: usize,
    wi_bad: Vec<String>,
    /// The largest `|Δwi|` of `wi_bad`.
    pub(super) wi_bad_max: f64,
    f_rel: f64,
    pdf_rel: f64,
    weight_rel: f64,
    ill_conditioned: usize,
    ill_rel: f64,
    /// The largest relative error of a conditioned sample less twice what
    /// its `|Δwi|` explains.
    pub(super) excess: f64,
    beyond_rel: usize,
    bad: Vec<String>,
    valid: usize,
    count: usize,
    /// Give the scalar path `wo` normalized in f64 (the lecture models,
    /// whose scalar samplers take the f32 view's length, `1 ± 1.2e-7`, as
    /// 1: see `grid::lecture_allowance`).
    pub(super) unit_wo: bool,
}

/// The largest relative change of the scalar `(f, pdf, weight)` at `wi`
/// when `wi` moves by `delta` (at least 1e-7) in any of four tangent
/// directions: what a difference `delta` of the sampled directions explains.
fn explained_change(m: &Material, s: BsdfStrategy, wo: DVec3, wi: DVec3, delta: f64) -> [f64; 7] {
    let sp = m.sampler(s).unwrap();
    let values = |wi: DVec3| {
        let (f, pdf) = sp.eval_pdf(wo, wi);
        let w = f * (wi.z / pdf);
        [f.x, f.y, f.z, pdf, w.x, w.y, w.z]
    };
    let base = values(wi);
    let frame = crate::Frame::from_normal(wi);
    let d = delta.max(1e-7);
    let mut worst = [0.0f64; 7];
    for t in [frame.s, -frame.s, frame.t, -frame.t] {
        let v = values((wi + d * t).normalize());
        for k in 0..7 {
            let c = if base[k] == 0.0 {
                f64::INFINITY
            } else {
                ((v[k] - base[k]) / base[k]).abs()
            };
            worst[k] = worst[k].max(if c.is_finite() { c } else { f64::INFINITY });
        }
    }
    worst
}

/// The largest relative change of the scalar `(f, pdf)` at the f32 pair
/// `(wo, wi)` when the pair's lengths move within their f32 rounding: each
/// vector at lengths `1 − 2⁻²³`, 1 (as given) and `1 + 2⁻²³`, and both
/// normalized in f64. Near `wi = −wo` at grazing angles the half vector is
/// the sum of nearly opposite vectors and `wo·h` is `(|wo|² + wo·wi)/|wo +
/// wi|`: a length change of 1e-8 moves it, and with it `f` and `pdf`, by
/// orders of magnitude, or across 0. Neither path's value is defined there
/// to better than this change (the input rounding's counterpart of
/// `explained_change`).
pub(super) fn length_rounding_change(
    sp: &crate::BsdfSampler<'_>,
    wo: DVec3,
    wi: DVec3,
) -> [f64; 4] {
    let e = f64::from(f32::EPSILON);
    let values = |o: DVec3, i: DVec3| {
        let (f, p) = sp.eval_pdf(o, i);
        [f.x, f.y, f.z, p]
    };
    let base = values(wo, wi);
    let mut worst = [0.0f64; 4];
    let mut visit = |v: [f64; 4]| {
        for k in 0..4 {
            let c = if v[k] == base[k] {
                0.0
            } else if base[k] == 0.0 {
                f64::INFINITY
            } else {
                ((v[k] - base[k]) / base[k]).abs()
            };
            worst[k] = worst[k].max(if c.is_nan() { f64::INFINITY } else { c });
        }
    };
    for a in [1.0 - e, 1.0, 1.0 + e] {
        for b in [1.0 - e, 1.0, 1.0 + e] {
            visit(values(wo * a, wi * b));
        }
    }
    visit(values(wo.normalize(), wi.normalize()));
    worst
}

/// The largest move of the scalar sample's `wi` when its inputs move
/// within what f32 kernels resolve: each uniform by `±2⁻²³` (the f32
/// kernels evaluate functions of `u` whose terms are O(1), to about that
/// absolute error: the Beckmann slope CDF inverted near 1), and the view by
/// `2⁻²³` in length and in four tangent directions (the f32 components fix
/// its direction to about that; the caps' point near `−wh` at the rim,
/// `u2 → 1`, is a sum that cancels and magnifies it). Where the warp is
/// steep (grazing views) this is far above the 1e-5 the batch `wi` is held
/// to elsewhere; where a neighbour falls below the horizon, infinite.
fn wi_rounding_change(sp: &crate::BsdfSampler<'_>, wo: DVec3, uc: f64, u: DVec2, wi: DVec3) -> f64 {
    let e = f64::from(f32::EPSILON);
    let top = 1.0 - f64::EPSILON / 2.0;
    let mut worst = 0.0f64;
    let mut visit = |o: DVec3, v: DVec2| {
        let v = v.clamp(DVec2::ZERO, DVec2::splat(top));
        // A neighbour that is no sample (below the horizon) leaves `wi`
        // undetermined: any difference is explained.
        worst = worst.max(match sp.sample(o, uc, v) {
            Some(x) => (x.wi - wi).abs().max_element(),
            None => f64::INFINITY,
        });
    };
    for dx in [-e, 0.0, e] {
        for dy in [-e, 0.0, e] {
            visit(wo, u + DVec2::new(dx, dy));
        }
    }
    visit(wo * (1.0 - e), u);
    visit(wo * (1.0 + e), u);
    let frame = crate::Frame::from_normal(wo.normalize());
    for t in [frame.s, -frame.s, frame.t, -frame.t] {
        visit((wo + e * t).normalize() * wo.length(), u);
    }
    worst
}

pub(super) fn compare_samples(
    m: &Material,
    s: BsdfStrategy,
    inp: &Inputs,
    out: &SampleBuffers,
    w: &mut Worst,
) {
    let sp = m.sampler(s).unwrap();
    let all = [
        &out.wi[0], &out.wi[1], &out.wi[2], &out.f[0], &out.f[1], &out.f[2], &out.pdf,
    ];
    for (k, v) in all
        .iter()
        .chain(&[&out.weight[0], &out.weight[1], &out.weight[2]])
        .enumerate()
    {
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            w.bad.push(format!("output {k}[{i}] = {}", v[i]));
        }
    }
    for i in 0..inp.u1.len() {
        w.count += 1;
        let wo = if w.unit_wo {
            inp.wo_at(i).normalize()
        } else {
            inp.wo_at(i)
        };
        let u = DVec2::new(inp.u1[i].into(), inp.u2[i].into());
        let scalar = sp.sample(wo, inp.uc[i].into(), u);
        let valid = out.valid[i] == 1;
        let wi_b = d3([out.wi[0][i], out.wi[1][i], out.wi[2][i]]);
        let near = |z: f64| z < HORIZON;
        match (scalar, valid) {
            (None, false) => continue,
            (Some(x), false) => {
                if near(x.wi.z) {
                    w.mask_exempt += 1;
                } else {
                    w.mask_bad.push(format!(
                        "{m:?} {s} wo {wo} u {u}: scalar {x:?}, batch invalid"
                    ));
                }
                continue;
            }
            (None, true) => {
                if near(wi_b.z) {
                    w.mask_exempt += 1;
                } else {
                    w.mask_bad.push(format!(
                        "{m:?} {s} wo {wo} u {u}: scalar None, batch wi {wi_b}"
                    ));
                }
                continue;
            }
            (Some(x), true) => {
                w.valid += 1;
                let e = (x.wi - wi_b).abs().max_element();
                w.wi_abs = w.wi_abs.max(e);
                if e > 1e-5 {
                    let c = wi_rounding_change(&sp, wo, inp.uc[i].into(), u, x.wi);
                    if e <= 1e-5 + 2.0 * c {
                        w.wi_explained += 1;
                    } else {
                        w.wi_bad_max = w.wi_bad_max.max(e);
                        w.wi_bad.push(format!(
                            "{m:?} {s} wo {wo} u {u}: wi {} vs {wi_b}, |Δ| {e:.2e}, explained by the inputs' rounding: {c:.2e}",
                            x.wi
                        ));
                    }
                }
                // f, pdf, weight against the scalar sample's: 1e-4 relative,
                // plus what the difference of the two wi explains.
                let fb = [out.f[0][i], out.f[1][i], out.f[2][i]].map(f64::from);
                let wb = [out.weight[0][i], out.weight[1][i], out.weight[2][i]].map(f64::from);
                let got = [fb[0], fb[1], fb[2], out.pdf[i].into(), wb[0], wb[1], wb[2]];
                let want = [
                    x.f[0],
                    x.f[1],
                    x.f[2],
                    x.pdf,
                    x.weight[0],
                    x.weight[1],
                    x.weight[2],
                ];
                let errs: Vec<f64> = got
                    .iter()
                    .zip(&want)
                    .map(|(&g, &r)| rel_err(g, r))
                    .collect();
                let worst = errs.iter().copied().fold(0.0, f64::max);
                let explained = explained_change(m, s, wo, x.wi, e);
                let conditioned = explained.iter().all(|&x| x < 1e-5);
                if worst > REL {
                    w.beyond_rel += 1;
                }
                // Where a tangent move of wi does not explain an error, the
                // inputs' length rounding may (wo·h of a grazing wo and a
                // wi nearly −wo mirrored; see `length_rounding_change`).
                let mut lengths: Option<[f64; 4]> = None;
                let mut conditioned = conditioned;
                for (k, &err) in errs.iter().enumerate() {
                    if err > REL + 2.0 * explained[k] {
                        let c =
                            *lengths.get_or_insert_with(|| length_rounding_change(&sp, wo, x.wi));
                        let by_length = if k < 4 { c[k] } else { c[k - 4] + c[3] };
                        if err <= REL + 2.0 * by_length {
                            conditioned = false;
                            continue;
                        }
                        w.bad.push(format!(
                            "{m:?} {s} wo {wo} u {u}: value {k}: {} vs {}, rel {err:.2e}, explained by |Δwi| = {e:.2e}: {:.2e}, by length rounding: {by_length:.2e}",
                            got[k], want[k], explained[k]
                        ));
                    }
                }
                if conditioned {
                    // What the 1e-4 bound holds: the error less twice what
                    // the wi difference explains (under 1e-5 here).
                    let excess = (0..7)
                        .map(|k| errs[k] - 2.0 * explained[k])
                        .fold(0.0, f64::max);
                    w.excess = w.excess.max(excess);
                    w.f_rel = w.f_rel.max(errs[0]).max(errs[1]).max(errs[2]);
                    w.pdf_rel = w.pdf_rel.max(errs[3]);
                    w.weight_rel = w.weight_rel.max(errs[4]).max(errs[5]).max(errs[6]);
                } else {
                    w.ill_conditioned += 1;
                    w.ill_rel = w.ill_rel.max(worst);
                }
            }
        }
    }
}

/// ~10⁶ random inputs per strategy, at every level: mask, wi, f, pdf,
/// weight against the scalar f64 path.
#[test]
fn batch_sample_matches_scalar() {
    let mut rng = Pcg64::seed_from_u64(0x0ba7c4);
    let mats = materials(&mut rng);
    let n = 16_387; // not a multiple of 16: the tail runs too
    let sets: Vec<Inputs> = mats.iter().map(|_| inputs(&mut rng, n)).collect();
    for level in levels("batch_sample_matches_scalar") {
        for s in [BsdfStrategy::Vndf, BsdfStrategy::Brdf] {
            let mut w = Worst::default();
            let mut out = SampleBuffers::new(n);
            for (m, inp) in mats.iter().zip(&sets) {
                let b = BatchSampler::with_level(m, s, level).unwrap();
                b.sample(inp.input(), out.output()).unwrap();
                compare_samples(m, s, inp, &out, &mut w);
            }
            eprintln!(
                "batch_sample_matches_scalar {level} {s}: {} samples, {} valid; mask differs near the horizon: {}; \
                 max |Δwi| {:.2e}; \
                 max rel error: f {:.2e}, pdf {:.2e}, weight {:.2e}; \
                 where |Δwi| moves a value by over 1e-5: {} samples, worst {:.2e}; {} beyond 1e-4, each within 1e-4 + twice what |Δwi| explains",
                w.count,
                w.valid,
                w.mask_exempt,
                w.wi_abs,
                w.f_rel,
                w.pdf_rel,
                w.weight_rel,
                w.ill_conditioned,
                w.ill_rel,
                w.beyond_rel,
            );
            let show = |v: &[String]| v.iter().take(5).cloned().collect::<Vec<_>>().join("\n");
            assert!(
                w.bad.is_empty(),
                "{level} {s}: not finite: {}",
                show(&w.bad)
            );
            assert!(
                w.mask_bad.is_empty(),
                "{level} {s}: {} masks differ:\n{}",
                w.mask_bad.len(),
                show(&w.mask_bad)
            );
            assert!(
                w.wi_bad.is_empty(),
                "{level} {s}: {} wi differ:\n{}",
                w.wi_bad.len(),
                show(&w.wi_bad)
            );
            assert!(
                w.f_rel < REL && w.pdf_rel < REL && w.weight_rel < REL,
                "{level} {s}: {w:?}"
            );
        }
    }
}

/// `eval_pdf` on ~10⁶ `(wo, wi)` pairs: random, sampled (near the peak),
/// `wi = wo` and the mirror direction, grazing included.
#[test]
fn batch_eval_pdf_matches_scalar() {
    let mut rng = Pcg64::seed_from_u64(0xe7a1);
    let mats = materials(&mut rng);
    let n = 8_195;
    for level in levels("batch_eval_pdf_matches_scalar") {
        for s in [BsdfStrategy::Vndf, BsdfStrategy::Brdf] {
            let (mut f_rel, mut pdf_rel, mut exempt, mut count) = (0.0f64, 0.0f64, 0usize, 0usize);
            let mut bad = Vec::new();
            let mut rng = Pcg64::seed_from_u64(0x5eed);
            let mut out = EvalPdfBuffers::new(n);
            for m in &mats {
                let sp = m.sampler(s).unwrap();
                let mut wo = [vec![], vec![], vec![]];
                let mut wi = [vec![], vec![], vec![]];
                for j in 0..n {
                    let o = random_wo(&mut rng);
                    let i = match j % 6 {
                        0 | 1 => random_wo(&mut rng),
                        2 | 3 => {
                            match sp.sample(d3(o), 0.5, DVec2::new(rng.random(), rng.random())) {
                                Some(x) => [x.wi.x as f32, x.wi.y as f32, x.wi.z as f32],
                                None => random_wo(&mut rng),
                            }
                        }
                        4 => o,
                        _ => [-o[0], -o[1], o[2]],
                    };
                    for c in 0..3 {
                        wo[c].push(o[c]);
                        wi[c].push(i[c]);
                    }
                }
                let b = BatchSampler::with_level(m, s, level).unwrap();
                b.eval_pdf(dirs(&wo), dirs(&wi), out.output()).unwrap();
                for j in 0..n {
                    count += 1;
                    let o = d3([wo[0][j], wo[1][j], wo[2][j]]);
                    let i = d3([wi[0][j], wi[1][j], wi[2][j]]);
                    let (f, pdf) = sp.eval_pdf(o, i);
                    let fb = [out.f[0][j], out.f[1][j], out.f[2][j]];
                    let pb = out.pdf[j];
                    if !(fb.iter().all(|v| v.is_finite()) && pb.is_finite()) {
                        bad.push(format!("{s} {o} {i}: not finite {fb:?} {pb}"));
                        continue;
                    }
                    if (pdf == 0.0) != (pb == 0.0) {
                        if o.z.min(i.z) < HORIZON {
                            exempt += 1;
                        } else {
                            bad.push(format!("{s} {o} {i}: pdf {pdf} vs {pb}"));
                        }
                        continue;
                    }
                    for c in 0..3 {
                        f_rel = f_rel.max(rel_err(fb[c].into(), f[c]));
                    }
                    pdf_rel = pdf_rel.max(rel_err(pb.into(), pdf));
                }
            }
            eprintln!(
                "batch_eval_pdf_matches_scalar {level} {s}: {count} pairs; max rel error f {f_rel:.2e}, pdf {pdf_rel:.2e}; \
                 zero on one side only, within 1e-5 of the horizon: {exempt}"
            );
            assert!(
                bad.is_empty(),
                "{level} {s}: {}",
                bad[..bad.len().min(5)].join("\n")
            );
            assert!(
                f_rel < REL && pdf_rel < REL,
                "{level} {s}: f {f_rel}, pdf {pdf_rel}"
            );
        }
    }
}

pub(super) fn dirs(v: &[Vec<f32>; 3]) -> Dirs<'_> {
    Dirs {
        x: &v[0],
        y: &v[1],
        z: &v[2],
    }
}

pub(super) fn bits(b: &SampleBuffers) -> Vec<u32> {
    let mut v: Vec<u32> = Vec::new();
    for a in b.wi.iter().chain(&b.f).chain([&b.pdf]).chain(&b.weight) {
        v.extend(a.iter().map(|x| x.to_bits()));
    }
    v.extend(b.valid.iter().map(|&x| u32::from(x)));
    v
}

/// The materials and strategies of the determinism test: one of each
/// kernel family (GGX's two samplers, Beckmann's per-lane Newton iteration,
/// the Blinn-Phong NDF, spherical caps, a two-lobe mixture that reads `uc`,
/// Phong and Blinn-Phong, Lambert, a measured table).
fn determinism_cases() -> Vec<(String, Material, BsdfStrategy)> {
    use crate::models::{BlinnPhong, Phong};
    let ct = |ndf: Ndf, ax: f64, ay: f64, kd: Rgb| {
        let mf = Microfacet::new(ndf, ax, ay).unwrap();
        let f = Fresnel::Schlick {
            f0: Rgb::new(0.9, 0.5, 0.2),
        };
        let lobe = CookTorrance::new(Rgb::ONE, mf, Shadowing::SmithCorrelated, f).unwrap();
        Material::with_diffuse(kd, Glossy::CookTorrance(lobe)).unwrap()
    };
    let kd = Rgb::new(0.4, 0.3, 0.2);
    let phong = Glossy::Phong(Phong::new(Rgb::ONE, 30.0, true).unwrap());
    let blinn = Glossy::BlinnPhong(BlinnPhong::new(Rgb::ONE, 200.0, true).unwrap());
    let mut v = vec![
        (
            "ggx".to_string(),
            ct(Ndf::Ggx, 0.05, 0.5, Rgb::ZERO),
            BsdfStrategy::Vndf,
        ),
        (
            "ggx".into(),
            ct(Ndf::Ggx, 0.05, 0.5, Rgb::ZERO),
            BsdfStrategy::Brdf,
        ),
        (
            "ggx".into(),
            ct(Ndf::Ggx, 0.3, 0.1, Rgb::ZERO),
            BsdfStrategy::SphericalCaps,
        ),
        (
            "ggx + lambert".into(),
            ct(Ndf::Ggx, 0.2, 0.2, kd),
            BsdfStrategy::Vndf,
        ),
        (
            "beckmann".into(),
            ct(Ndf::Beckmann, 0.4, 0.1, Rgb::ZERO),
            BsdfStrategy::Vndf,
        ),
        (
            "beckmann + lambert".into(),
            ct(Ndf::Beckmann, 0.3, 0.3, kd),
            BsdfStrategy::Brdf,
        ),
        (
            "blinn-phong ndf".into(),
            ct(Ndf::BlinnPhong, 0.2, 0.2, Rgb::ZERO),
            BsdfStrategy::Brdf,
        ),
        (
            "phong + lambert".into(),
            Material::with_diffuse(kd, phong).unwrap(),
            BsdfStrategy::Brdf,
        ),
        (
            "blinn-phong".into(),
            Material::with_diffuse(Rgb::ZERO, blinn).unwrap(),
            BsdfStrategy::Brdf,
        ),
        (
            "lambert".into(),
            Material::lambert(kd).unwrap(),
            BsdfStrategy::Cosine,
        ),
    ];
    // An RGL table of a GGX + Lambert material (per-lane f64 kernels).
    let a = super::measured::tests::analytic();
    let rgl = crate::models::measured::rgl::Rgl::write(|o, i| a.eval(o, i), 6, 24, "determinism");
    let table = super::measured::tests::measured(&rgl, "t.bsdf", None);
    v.push(("measured".into(), table, BsdfStrategy::Brdf));
    v
}

/// The same bits whatever the block size, the thread split and the level,
/// for every kernel family (`determinism_cases`), `uc` included.
#[test]
fn batch_same_numbers_for_any_block_thread_and_level() {
    let mut rng = Pcg64::seed_from_u64(0xb10c);
    let n = 10_007;
    let inp = inputs(&mut rng, n);
    // The inputs of `range`, `uc` included (the one-lobe kernels ignore it).
    let part = |r: std::ops::Range<usize>| SampleInput {
        wo: Dirs {
            x: &inp.wo[0][r.clone()],
            y: &inp.wo[1][r.clone()],
            z: &inp.wo[2][r.clone()],
        },
        u1: &inp.u1[r.clone()],
        u2: &inp.u2[r.clone()],
        uc: Some(&inp.uc[r]),
    };
    for (name, m, s) in determinism_cases() {
        let mut reference: Option<Vec<u32>> = None;
        for level in levels("batch_same_numbers") {
            let b = BatchSampler::with_level(&m, s, level).unwrap();
            let mut whole = SampleBuffers::new(n);
            b.sample(inp.input(), whole.output()).unwrap();
            assert!(
                whole.valid.iter().filter(|&&v| v == 1).count() > n / 4,
                "{name} {s} {level}: too few valid samples for the test to mean anything"
            );
            let whole = bits(&whole);
            // Blocks of odd sizes, one after the other.
            for block in [1usize, 3, 7, 15, 17, 100, 4097] {
                let mut parts = SampleBuffers::new(n);
                let mut start = 0;
                while start < n {
                    let end = (start + block).min(n);
                    let r = start..end;
                    let mut one = SampleBuffers::new(end - start);
                    b.sample(part(r.clone()), one.output()).unwrap();
                    for (d, s) in parts.wi.iter_mut().zip(&one.wi) {
                        d[r.clone()].copy_from_slice(s);
                    }
                    for (d, s) in parts.f.iter_mut().zip(&one.f) {
                        d[r.clone()].copy_from_slice(s);
                    }
                    for (d, s) in parts.weight.iter_mut().zip(&one.weight) {
                        d[r.clone()].copy_from_slice(s);
                    }
                    parts.pdf[r.clone()].copy_from_slice(&one.pdf);
                    parts.valid[r.clone()].copy_from_slice(&one.valid);
                    start = end;
                }
                assert!(
                    bits(&parts) == whole,
                    "{name} {level} {s}: block {block} differs"
                );
            }
            // Two and three threads, each on its own part.
            for threads in [2usize, 3] {
                let chunk = n.div_ceil(threads);
                let results: Vec<SampleBuffers> = std::thread::scope(|scope| {
                    let handles: Vec<_> = (0..threads)
                        .map(|t| {
                            let r = (t * chunk).min(n)..((t + 1) * chunk).min(n);
                            let (b, part) = (&b, &part);
                            scope.spawn(move || {
                                let mut one = SampleBuffers::new(r.len());
                                b.sample(part(r), one.output()).unwrap();
                                one
                            })
                        })
                        .collect();
                    handles.into_iter().map(|h| h.join().unwrap()).collect()
                });
                let mut joined = Vec::new();
                let per_part: Vec<Vec<u32>> = results.iter().map(bits).collect();
                // Re-interleave each part's arrays into the whole's layout.
                for k in 0..11 {
                    for (p, r) in per_part.iter().zip(&results) {
                        let len = r.pdf.len();
                        joined.extend_from_slice(&p[k * len..(k + 1) * len]);
                    }
                }
                assert!(
                    joined == whole,
                    "{name} {level} {s}: {threads} threads differ"
                );
            }
            match &reference {
                None => reference = Some(whole),
                Some(r) => assert!(
                    *r == whole,
                    "{name} {level} {s}: differs from the first level"
                ),
            }
        }
    }
}

#[test]
fn batch_errors_name_the_slice_and_the_unsupported() {
    let m = ggx(0.2, 0.2, Fresnel::None, Rgb::ONE);
    let b = BatchSampler::with_level(&m, BsdfStrategy::Vndf, SimdLevel::Scalar).unwrap();
    let v = vec![0.5f32; 8];
    let short = vec![0.5f32; 7];
    let mut out = SampleBuffers::new(8);
    let input = SampleInput {
        wo: Dirs {
            x: &v,
            y: &v,
            z: &v,
        },
        u1: &v,
        u2: &short,
        uc: None,
    };
    let e = b.sample(input, out.output()).unwrap_err();
    assert_eq!(
        e,
        BatchError::Length {
            slice: "u2",
            expected: 8,
            found: 7
        }
    );
    assert!(
        e.to_string().contains("`u2` has 7 values, expected 8"),
        "{e}"
    );
    let input = SampleInput {
        u2: &v,
        uc: Some(&short),
        ..input
    };
    assert!(matches!(
        b.sample(input, out.output()),
        Err(BatchError::Length { slice: "uc", .. })
    ));
    let mut small = SampleBuffers::new(7);
    let input = SampleInput { uc: None, ..input };
    assert!(matches!(
        b.sample(input, small.output()),
        Err(BatchError::Length { slice: "wi.x", .. })
    ));
    let mut e_out = EvalPdfBuffers::new(8);
    let d = Dirs {
        x: &v,
        y: &v,
        z: &v,
    };
    let d7 = Dirs { z: &short, ..d };
    assert!(matches!(
        b.eval_pdf(d, d7, e_out.output()),
        Err(BatchError::Length { slice: "wi.z", .. })
    ));
    assert!(b.eval_pdf(d, d, e_out.output()).is_ok());
    let empty: &[f32] = &[];
    let mut none = SampleBuffers::new(0);
    let e = Dirs {
        x: empty,
        y: empty,
        z: empty,
    };
    assert!(
        b.sample(
            SampleInput {
                wo: e,
                u1: empty,
                u2: empty,
                uc: None
            },
            none.output()
        )
        .is_ok()
    );

    // What the first step does not batch: a clear error, the scalar path has it.
    let unsupported =
        |m: &Material, s: BsdfStrategy| match BatchSampler::with_level(m, s, SimdLevel::Scalar) {
            Err(BatchError::Inapplicable { reason }) => reason,
            other => panic!("{other:?}"),
        };
    assert!(BatchSampler::with_level(&m, BsdfStrategy::SphericalCaps, SimdLevel::Scalar).is_ok());
    let blinn = {
        let mf = Microfacet::new(Ndf::BlinnPhong, 0.2, 0.2).unwrap();
        let l = CookTorrance::new(Rgb::ONE, mf, Shadowing::SmithCorrelated, Fresnel::None).unwrap();
        Material::with_diffuse(Rgb::ZERO, Glossy::CookTorrance(l)).unwrap()
    };
    // What the scalar path refuses, the batch path refuses with its reason.
    assert!(unsupported(&blinn, BsdfStrategy::Vndf).contains("ggx or beckmann"));
    let two_lobes = Material {
        diffuse: crate::models::Lambert::new(Rgb::splat(0.3)).unwrap(),
        ..m.clone()
    };
    let b2 = BatchSampler::with_level(&two_lobes, BsdfStrategy::Vndf, SimdLevel::Scalar).unwrap();
    assert!(b2.chooses_lobe());
    let mut o8 = SampleBuffers::new(8);
    let no_uc = SampleInput {
        wo: Dirs {
            x: &v,
            y: &v,
            z: &v,
        },
        u1: &v,
        u2: &v,
        uc: None,
    };
    let e = b2.sample(no_uc, o8.output()).unwrap_err();
    assert_eq!(e, BatchError::MissingUc);
    assert!(e.to_string().contains("`uc`"), "{e}");
    assert!(
        b2.sample(
            SampleInput {
                uc: Some(&v),
                ..no_uc
            },
            o8.output()
        )
        .is_ok()
    );
    let phong = Material {
        diffuse: crate::models::Lambert::new(Rgb::ZERO).unwrap(),
        glossy: Glossy::Phong(crate::models::Phong::new(Rgb::splat(0.5), 10.0, true).unwrap()),
        two_sided: false,
    };
    assert!(unsupported(&phong, BsdfStrategy::Vndf).contains("Phong"));

    // Levels by name.
    assert_eq!("avx2".parse::<SimdLevel>().unwrap(), SimdLevel::Avx2);
    assert!(matches!(
        "sse9".parse::<SimdLevel>(),
        Err(BatchError::Level { .. })
    ));
    for l in SimdLevel::ALL {
        assert_eq!(l.check().is_ok(), l.is_available());
        if !l.is_available() {
            let e = BatchSampler::with_level(&m, BsdfStrategy::Vndf, l).unwrap_err();
            assert!(e.to_string().contains("lacks"), "{e}");
        }
    }
    assert!(SimdLevel::Scalar.is_available() && SimdLevel::best().is_available());
}

/// Chi-square of the batch samplers against the scalar pdf
/// (`lobe::stats::chi2`), at every level. The uniforms are the harness's
/// own stream, drawn ahead and sampled as one block; the expected counts
/// (the cubature of the pdf) are computed once per case and shared by the
/// levels.
#[cfg(feature = "stats")]
#[test]
fn batch_chi2() {
    use crate::stats::chi2::{Chi2Settings, chi2_test, chi2_test_cells, sidak};
    use crate::stats::quadrature::Estimate;
    use std::cell::Cell;
    let cfg = Chi2Settings {
        samples: 500_000,
        ..Chi2Settings::default()
    };
    let cases = [
        ggx(0.02, 0.02, Fresnel::None, Rgb::ONE),
        ggx(
            0.3,
            0.3,
            Fresnel::Schlick {
                f0: Rgb::splat(0.3),
            },
            Rgb::ONE,
        ),
        ggx(1.0, 1.0, Fresnel::None, Rgb::ONE),
        ggx(0.05, 0.5, Fresnel::None, Rgb::ONE),
    ];
    let views = [0.0, 60.0, 89.0];
    let lv = levels("batch_chi2");
    let alpha = sidak(0.01, cases.len() * views.len() * 2 * lv.len());
    // The harness's stream: uc, u.x, u.y per sample.
    let mut rng = Pcg64::seed_from_u64(cfg.seed);
    let (mut u1, mut u2) = (Vec::new(), Vec::new());
    for _ in 0..cfg.samples {
        let _uc: f64 = rng.random();
        let x: f64 = rng.random();
        let y: f64 = rng.random();
        // Round down into [0, 1) in f32.
        let f = |v: f64| {
            let r = v as f32;
            if f64::from(r) > v { r.next_down() } else { r }
        };
        u1.push(f(x));
        u2.push(f(y));
    }
    let mut failures = Vec::new();
    for (ci, m) in cases.iter().enumerate() {
        for &theta in &views {
            let wo = crate::frame::wo_from_theta(theta, 0.3f64.to_degrees());
            let wo32 = [wo.x as f32, wo.y as f32, wo.z as f32];
            let n = cfg.samples;
            let wox = vec![wo32[0]; n];
            let woy = vec![wo32[1]; n];
            let woz = vec![wo32[2]; n];
            let wo64 = d3(wo32);
            for s in [BsdfStrategy::Vndf, BsdfStrategy::Brdf] {
                let mut cells: Option<Vec<f64>> = None;
                for &level in &lv {
                    let b = BatchSampler::with_level(m, s, level).unwrap();
                    let mut out = SampleBuffers::new(n);
                    let input = SampleInput {
                        wo: Dirs {
                            x: &wox,
                            y: &woy,
                            z: &woz,
                        },
                        u1: &u1,
                        u2: &u2,
                        uc: None,
                    };
                    b.sample(input, out.output()).unwrap();
                    let next = Cell::new(0usize);
                    let sample = |_uc: f64, u: DVec2| {
                        let i = next.get();
                        next.set(i + 1);
                        debug_assert!((f64::from(u1[i]) - u.x).abs() < 1e-7);
                        (out.valid[i] == 1).then(|| {
                            DVec3::new(
                                out.wi[0][i].into(),
                                out.wi[1][i].into(),
                                out.wi[2][i].into(),
                            )
                        })
                    };
                    let r = match &cells {
                        None => {
                            let sp = m.sampler(s).unwrap();
                            let r = chi2_test(&cfg, sample, |wi| sp.pdf(wo64, wi));
                            cells = Some(r.expected.iter().map(|e| e / n as f64).collect());
                            r
                        }
                        Some(p) => {
                            let k = Cell::new(0usize);
                            chi2_test_cells(&cfg, sample, |_, _, _, _| {
                                let v = p[k.get()];
                                k.set(k.get() + 1);
                                Estimate {
                                    value: v,
                                    error: 0.0,
                                    evals: 0,
                                    converged: true,
                                }
                            })
                        }
                    };
                    eprintln!(
                        "batch_chi2 {level} {s} θ={theta} case {ci}: p = {:.3e}",
                        r.p_value
                    );
                    if !r.passes(alpha) {
                        failures.push(format!(
                            "{level} {s} θ={theta} {:?}: χ²={:.1} dof={} p={:.3e} {}",
                            m.glossy,
                            r.statistic,
                            r.dof,
                            r.p_value,
                            r.message.clone().unwrap_or_default()
                        ));
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Two vectors at a time ([`dispatch`]'s `X2`, which the AVX-512 level runs
/// for the visible-normal samplers) give the bits of one vector at a time:
/// checked here on the portable lanes (`X2<Scalar>` against `Scalar`), so
/// that every machine runs it, with an odd block for the padded tail, for
/// every kernel `X2` runs, both Fresnel kinds and a diffuse term.
#[test]
fn two_vectors_at_a_time_give_the_same_bits() {
    use super::dispatch::{self as d, Kernel};
    use super::lanes::Scalar;
    let mut rng = Pcg64::seed_from_u64(0x7832);
    let n = 4097;
    let mut inp: [Vec<f32>; 6] = Default::default();
    for _ in 0..n {
        let wo = random_wo(&mut rng);
        for c in 0..3 {
            inp[c].push(wo[c]);
        }
        for v in &mut inp[3..] {
            v.push(uniform(&mut rng));
        }
    }
    let beckmann = {
        let mf = Microfacet::new(Ndf::Beckmann, 0.2, 0.6).unwrap();
        let lobe = CookTorrance::new(
            Rgb::splat(0.8),
            mf,
            Shadowing::SmithCorrelated,
            Fresnel::Schlick {
                f0: Rgb::splat(0.04),
            },
        )
        .unwrap();
        Material::with_diffuse(Rgb::splat(0.3), Glossy::CookTorrance(lobe)).unwrap()
    };
    let materials = [
        ggx(0.2, 0.2, Fresnel::None, Rgb::ONE),
        ggx(
            1e-4,
            0.5,
            Fresnel::Schlick {
                f0: Rgb::new(0.9, 0.6, 0.3),
            },
            Rgb::ONE,
        ),
        beckmann,
        ggx(0.2, 0.2, Fresnel::None, Rgb::ONE),
        ggx(
            0.05,
            0.3,
            Fresnel::Schlick {
                f0: Rgb::new(0.9, 0.6, 0.3),
            },
            Rgb::splat(0.5),
        ),
    ];
    // The last two through GGX's brdf sampler, which X2 runs at AVX2.
    let strategy = |mi: usize| {
        if mi < 3 {
            BsdfStrategy::Vndf
        } else {
            BsdfStrategy::Brdf
        }
    };
    let mut checked = 0;
    for (mi, m) in materials.iter().enumerate() {
        let b = BatchSampler::with_level(m, strategy(mi), SimdLevel::Scalar).unwrap();
        let k: &Kernel = &b.kernel;
        assert!(
            d::runs_x2(k, false, false),
            "material {mi}: a kernel that X2 runs"
        );
        let ins = [
            &inp[0][..],
            &inp[1][..],
            &inp[2][..],
            &inp[3][..],
            &inp[4][..],
            &inp[5][..],
        ];
        let run = |x2: bool| {
            let mut out: [Vec<f32>; 10] = std::array::from_fn(|_| vec![0.0; n]);
            let mut valid = vec![0u8; n];
            let mut ev: [Vec<f32>; 4] = std::array::from_fn(|_| vec![0.0; n]);
            {
                let mut o = out.each_mut().map(|v| &mut v[..]);
                let plain = d::SampleWrites {
                    f: true,
                    stream: false,
                };
                if x2 {
                    d::sample_x2(Scalar, k, ins, (&mut o, &mut valid), plain);
                } else {
                    d::sample_level(Scalar, k, ins, (&mut o, &mut valid), plain);
                }
            }
            {
                let ein = [
                    ins[0],
                    ins[1],
                    ins[2],
                    &out[0][..],
                    &out[1][..],
                    &out[2][..],
                ];
                let mut e = ev.each_mut().map(|v| &mut v[..]);
                if x2 && d::runs_x2(k, true, false) {
                    d::eval_pdf_x2(Scalar, k, super::block::BOTH, ein, &mut e, false);
                } else {
                    d::eval_pdf_level(Scalar, k, super::block::BOTH, ein, &mut e, false);
                }
            }
            (out, valid, ev)
        };
        let (one, x2) = (run(false), run(true));
        assert_eq!(one.1, x2.1, "material {mi}: valid masks differ");
        let same_bits = |a: &[Vec<f32>], b: &[Vec<f32>], what: &str| {
            for (c, (a, b)) in a.iter().zip(b).enumerate() {
                for i in 0..n {
                    let (x, y) = (a[i].to_bits(), b[i].to_bits());
                    assert_eq!(x, y, "material {mi}: {what} output {c} at {i}");
                }
            }
        };
        same_bits(&one.0, &x2.0, "sample");
        same_bits(&one.2, &x2.2, "eval_pdf");
        assert!(
            one.1.iter().filter(|&&v| v == 1).count() > n / 2,
            "material {}: most samples valid",
            mi
        );
        checked += 1;
    }
    assert_eq!(checked, materials.len());
}

/// The whole model × strategy × Fresnel × shadowing grid.
#[path = "tests_grid.rs"]
mod grid;

/// The rough dielectric kernel over the sphere.
#[path = "tests_dielectric.rs"]
mod dielectric;

/// The smooth models' kernels and two-sided materials over the sphere.
#[path = "tests_smooth.rs"]
mod smooth;

/// A zeroed `n`-value slice of `v` starting at a 128-byte boundary plus
/// `shift` values.
fn aligned_part(v: &mut Vec<f32>, n: usize, shift: usize) -> &mut [f32] {
    v.clear();
    v.resize(n + 32 + shift, 0.0);
    let a = v.as_ptr().align_offset(128);
    &mut v[a + shift..a + shift + n]
}

/// Copies of the [`aligned_part`]s of `bufs`.
fn aligned_parts(bufs: &[Vec<f32>], n: usize, shift: usize) -> Vec<Vec<f32>> {
    bufs.iter()
        .map(|v| {
            let o = v.as_ptr().align_offset(128) + shift;
            v[o..o + n].to_vec()
        })
        .collect()
}

/// `sample_with` into buffers at a 128-byte boundary plus `shift` values:
/// `wi`, `f` (if `with_f`; else not wanted), `pdf`, `weight`, and `valid`.
fn sample_aligned(
    b: &BatchSampler,
    input: SampleInput<'_>,
    shift: usize,
    with_f: bool,
    store: Store,
) -> (Vec<Vec<f32>>, Vec<u8>) {
    let n = input.wo.x.len();
    let mut bufs: Vec<Vec<f32>> = (0..if with_f { 10 } else { 7 })
        .map(|_| Vec::new())
        .collect();
    let mut valid = vec![0u8; n];
    {
        let mut it = bufs.iter_mut().map(|v| aligned_part(v, n, shift));
        let mut next = || it.next().expect("enough buffers");
        let (x, y, z) = (next(), next(), next());
        let f = if with_f {
            let (r, g, b) = (next(), next(), next());
            RgbMut { r, g, b }
        } else {
            RgbMut {
                r: &mut [],
                g: &mut [],
                b: &mut [],
            }
        };
        let pdf = next();
        let (r, g, bl) = (next(), next(), next());
        let out = SampleOutput {
            wi: DirsMut { x, y, z },
            f,
            pdf,
            weight: RgbMut { r, g, b: bl },
            valid: &mut valid,
        };
        b.sample_with(input, out, store).unwrap();
    }
    (aligned_parts(&bufs, n, shift), valid)
}

/// `eval_pdf_with` into buffers as [`sample_aligned`]: `f`, `pdf`.
fn eval_pdf_aligned(
    b: &BatchSampler,
    wo: Dirs<'_>,
    wi: Dirs<'_>,
    shift: usize,
    store: Store,
) -> Vec<Vec<f32>> {
    let n = wo.x.len();
    let mut bufs: Vec<Vec<f32>> = (0..4).map(|_| Vec::new()).collect();
    {
        let mut it = bufs.iter_mut().map(|v| aligned_part(v, n, shift));
        let mut next = || it.next().expect("four buffers");
        let (r, g, bl, pdf) = (next(), next(), next(), next());
        let out = EvalPdfOutput {
            f: RgbMut { r, g, b: bl },
            pdf,
        };
        b.eval_pdf_with(wo, wi, out, store).unwrap();
    }
    aligned_parts(&bufs, n, shift)
}

/// Whether two lists of arrays hold the same bits.
fn same_bits(a: &[Vec<f32>], b: &[&Vec<f32>]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| {
            x.len() == y.len()
                && x.iter()
                    .zip(y.iter())
                    .all(|(p, q)| p.to_bits() == q.to_bits())
        })
}

#[test]
fn streamed_stores_give_the_same_bits() {
    let mut rng = Pcg64::seed_from_u64(0x57_4ea3);
    let n = 4096 + 37;
    let inp = inputs(&mut rng, n);
    let beckmann = Microfacet::new(Ndf::Beckmann, 0.3, 0.3).unwrap();
    let cases = [
        (ggx(0.2, 0.2, Fresnel::None, Rgb::ONE), BsdfStrategy::Vndf),
        (ggx(0.2, 0.2, Fresnel::None, Rgb::ONE), BsdfStrategy::Brdf),
        (
            Material::with_diffuse(
                Rgb::ZERO,
                Glossy::CookTorrance(
                    CookTorrance::new(
                        Rgb::ONE,
                        beckmann,
                        Shadowing::SmithCorrelated,
                        Fresnel::None,
                    )
                    .unwrap(),
                ),
            )
            .unwrap(),
            BsdfStrategy::Vndf,
        ),
    ];
    for (m, s) in &cases {
        for level in levels("streamed_stores") {
            let b = BatchSampler::with_level(m, *s, level).unwrap();
            let mut plain = SampleBuffers::new(n);
            b.sample(inp.input(), plain.output()).unwrap();
            let mut pe = EvalPdfBuffers::new(n);
            b.eval_pdf(inp.input().wo, plain.wi(), pe.output()).unwrap();
            let all: Vec<&Vec<f32>> = plain
                .wi
                .iter()
                .chain(&plain.f)
                .chain(std::iter::once(&plain.pdf))
                .chain(&plain.weight)
                .collect();
            let no_f: Vec<&Vec<f32>> = plain
                .wi
                .iter()
                .chain(std::iter::once(&plain.pdf))
                .chain(&plain.weight)
                .collect();
            let ev: Vec<&Vec<f32>> = pe.f.iter().chain(std::iter::once(&pe.pdf)).collect();
            // 128- and 64-byte aligned (streamed), one value off (plain
            // stores); `f` wanted and not.
            for shift in [0usize, 1, 16] {
                for store in [Store::Streamed, Store::Cached] {
                    let what = format!("{level} {s} shift {shift} {store:?}");
                    let (got, valid) = sample_aligned(&b, inp.input(), shift, true, store);
                    assert!(
                        same_bits(&got, &all) && valid == plain.valid,
                        "{what}: sample"
                    );
                    let (got, valid) = sample_aligned(&b, inp.input(), shift, false, store);
                    assert!(
                        same_bits(&got, &no_f) && valid == plain.valid,
                        "{what}: no f"
                    );
                    let got = eval_pdf_aligned(&b, inp.input().wo, plain.wi(), shift, store);
                    assert!(same_bits(&got, &ev), "{what}: eval_pdf");
                }
            }
        }
    }
}
