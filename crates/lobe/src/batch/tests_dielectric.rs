//! The rough dielectric kernel (GGX and Beckmann, every strategy) against the scalar
//! f64 path, at every level this CPU has, seen from outside and from
//! inside: the same samples (the same outcome, `wi` within 1e-5, `f`,
//! `pdf` and `weight` within 1e-4 relative), the same `eval_pdf` over the
//! whole sphere, and the same bits at every level.
//!
//! The tolerances grow by what f32 cannot avoid, measured on the f64 path
//! by moving its inputs by their rounding ([`conditioning`]): near the
//! horizon, next to total internal reflection, where the half vector
//! cancels, far in Beckmann's tail. Where `uc` is within
//! 1e-5 of the Fresnel reflectance, or a direction within 1e-4 of the
//! horizon, the two paths may choose differently: counted, at most one
//! sample in 10³.

use super::{d3, levels, random_wo, rel_err, uniform};
use crate::batch::{BatchSampler, EvalPdfBuffers, SampleBuffers, SampleInputs};
use crate::{BsdfSampler, BsdfStrategy, Material};
use glam::{DVec2, DVec3};
use rand::{Rng, RngExt, SeedableRng};
use rand_pcg::Pcg64;

const MATERIALS: [&str; 6] = [
    r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.3}"#,
    r#"{"type":"roughdielectric","distribution":"beckmann","alpha":0.3}"#,
    r#"{"type":"roughdielectric","distribution":"beckmann","alpha_u":0.05,"alpha_v":0.4,"int_ior":1.0,"ext_ior":1.5,"specular_transmittance":[0.9,0.5,0.2]}"#,
    r#"{"type":"roughdielectric","distribution":"ggx","alpha_u":0.1,"alpha_v":0.5,"int_ior":1.0,"ext_ior":1.33}"#,
    r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.02,"int_ior":"diamond","specular_transmittance":[0.9,0.5,0.2],"mode":"importance"}"#,
    r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.8,"specular_reflectance":0.7}"#,
];

/// Every (material, strategy) pair: each material of [`MATERIALS`] with
/// every strategy the scalar path gives it.
fn cases() -> Vec<(String, Material, BsdfStrategy)> {
    let mut v = Vec::new();
    for json in MATERIALS {
        let m = Material::load(json).unwrap();
        for s in m.strategies() {
            v.push((format!("{json} {s}"), m.clone(), s));
        }
    }
    v
}

/// A view over the sphere: `random_wo`'s (grazing ones included) on
/// either side.
fn wo_sphere(rng: &mut impl Rng) -> [f32; 3] {
    let w = random_wo(rng);
    if rng.random::<bool>() {
        [-w[0], -w[1], -w[2]]
    } else {
        w
    }
}

/// At the microfacet normal taking `wo` to `wi`, seen from `wo`'s side:
/// the Fresnel reflectance and `1 − sin²θt` (negative under total internal
/// reflection).
fn at_normal(m: &Material, wo: glam::DVec3, wi: glam::DVec3) -> (f64, f64) {
    let crate::Glossy::RoughDielectric(rd) = &m.glossy else {
        unreachable!("rough dielectrics only")
    };
    let eta = if wo.z > 0.0 { rd.eta } else { 1.0 / rd.eta };
    let h = if wo.z * wi.z > 0.0 {
        wo + wi
    } else {
        wo + wi * eta
    };
    let c = wo.dot(h.normalize()).abs();
    let fr = crate::fresnel::fresnel_dielectric(c, eta).r;
    (fr, 1.0 - (1.0 - c * c) / (eta * eta))
}

/// The relative error an f32 evaluation cannot avoid at `(wo, wi)`,
/// measured on the f64 path rather than modelled: four times the largest
/// relative change of its `f` and pdf (and the sample weight `f |wi.z| /
/// pdf` if `weight`) when both directions move by `delta`
/// in each coordinate (four draws, renormalized). The kernel's inputs and
/// steps round by about 1e-7 (`delta` 3e-7 stands for them); where that
/// moves the result far, f32 cannot say: near the horizon (`f` and the pdf
/// divide by `|wo.z|`, `|wi.z|`), next to total internal reflection
/// (`cos θt = √(1 − sin²θt)` in `F` and in refraction), where the half
/// vector cancels (`wo·m`, `m.z` of `D cos θm`'s density), and in
/// Beckmann's `exp(−tan²θm/α²)` far in its tail.
fn conditioning(sp: &BsdfSampler<'_>, wo: DVec3, wi: DVec3, delta: f64, weight: bool) -> f64 {
    let (f0, p0) = sp.eval_pdf(wo, wi);
    let w = |f: f64, p: f64, wi: DVec3| {
        if weight && p > 0.0 {
            f * wi.z.abs() / p
        } else {
            0.0
        }
    };
    let mut rng = Pcg64::seed_from_u64(wo.x.to_bits() ^ wi.y.to_bits());
    let mut jitter = |w: DVec3| {
        let d = DVec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - DVec3::ONE;
        (w + d * delta).normalize()
    };
    let mut worst = 0.0f64;
    for _ in 0..4 {
        let wi_j = jitter(wi);
        let (f, p) = sp.eval_pdf(jitter(wo), wi_j);
        worst = [
            rel_err(w(f.x, p, wi_j), w(f0.x, p0, wi)),
            rel_err(f.x, f0.x),
            rel_err(f.y, f0.y),
            rel_err(f.z, f0.z),
            rel_err(p, p0),
        ]
        .into_iter()
        .fold(worst, f64::max);
    }
    4.0 * worst
}

/// The inputs' rounding for [`conditioning`].
const ROUNDING: f64 = 3e-7;

/// Where [`conditioning`] allows more than this, the pair is counted as
/// ill-conditioned instead of compared: at the horizon (within 1e-2), or
/// elsewhere (total internal reflection's edge: at most 1% of them).
const ILL: f64 = 1e-2;

/// Whether the two paths may choose differently: `uc` within 1e-5 of `F`,
/// or a direction within 1e-4 of the horizon (where its side is rounding).
fn near_an_edge(m: &Material, wo: glam::DVec3, uc: f64, wi: Option<glam::DVec3>) -> bool {
    if wo.z.abs() < 1e-4 || wi.is_some_and(|w| w.z.abs() < 1e-4) {
        return true;
    }
    let Some(wi) = wi else { return false };
    let (fr, cos2_t) = at_normal(m, wo, wi);
    (uc - fr).abs() < 1e-5 || cos2_t.abs() < 1e-5
}

#[test]
fn dielectric_samples_match_the_scalar_path() {
    let mut rng = Pcg64::seed_from_u64(0xd1e1);
    let n = 20_000;
    let mut report = Vec::new();
    for (json, m, strategy) in cases() {
        let sp = m.sampler(strategy).unwrap();
        let mut inp = SampleInputs::default();
        for _ in 0..n {
            inp.push(
                wo_sphere(&mut rng),
                uniform(&mut rng),
                uniform(&mut rng),
                uniform(&mut rng),
            );
        }
        let mut first: Option<SampleBuffers> = None;
        for level in levels("dielectric_samples_match_the_scalar_path") {
            let b = BatchSampler::with_level(&m, strategy, level).unwrap();
            assert_eq!(
                b.chooses_lobe(),
                !matches!(strategy, BsdfStrategy::Uniform | BsdfStrategy::Cosine)
            );
            let mut out = SampleBuffers::new(n);
            b.sample(inp.input(true), out.output()).unwrap();
            let (mut edges, mut bad, mut valid, mut below) = (0usize, Vec::new(), 0usize, 0usize);
            let (mut ill, mut grazing) = (0usize, 0usize);
            let (mut wi_max, mut rel_max) = (0.0f64, 0.0f64);
            for j in 0..n {
                let wo = d3([inp.wo[0][j], inp.wo[1][j], inp.wo[2][j]]);
                let uc = f64::from(inp.uc[j]);
                let u = DVec2::new(inp.u1[j].into(), inp.u2[j].into());
                let s = sp.sample(wo, uc, u);
                let got = out.valid[j] != 0;
                let values = [
                    out.f[0][j],
                    out.f[1][j],
                    out.f[2][j],
                    out.pdf[j],
                    out.weight[0][j],
                    out.weight[1][j],
                    out.weight[2][j],
                    out.wi[0][j],
                    out.wi[1][j],
                    out.wi[2][j],
                ];
                assert!(
                    values.iter().all(|v| v.is_finite()),
                    "{json} {level}: not finite at {j}"
                );
                let edge = near_an_edge(&m, wo, uc, s.map(|x| x.wi));
                match s {
                    Some(x) if got => {
                        valid += 1;
                        let wi = d3([out.wi[0][j], out.wi[1][j], out.wi[2][j]]);
                        below += usize::from(wi.z * wo.z < 0.0);
                        let dwi = (wi - x.wi).abs().max_element();
                        let rel = [
                            rel_err(out.f[0][j].into(), x.f.x),
                            rel_err(out.f[2][j].into(), x.f.z),
                            rel_err(out.pdf[j].into(), x.pdf),
                            rel_err(out.weight[0][j].into(), x.weight.x),
                            rel_err(out.weight[2][j].into(), x.weight.z),
                        ]
                        .into_iter()
                        .fold(0.0, f64::max);
                        // Moving by the two directions' difference too.
                        let allowance = conditioning(&sp, wo, x.wi, ROUNDING.max(dwi), true);
                        if allowance > ILL {
                            if wo.z.abs() < 1e-2 || x.wi.z.abs() < 1e-2 {
                                grazing += 1;
                            } else {
                                ill += 1;
                            }
                            continue;
                        }
                        if dwi > 1e-5 + allowance || rel > 1e-4 + allowance {
                            if edge {
                                edges += 1;
                            } else {
                                bad.push(format!("wo {wo} uc {uc} u {u}: wi {wi} vs {} (Δ {dwi:.1e}), rel {rel:.1e}", x.wi));
                            }
                        } else {
                            wi_max = wi_max.max(dwi);
                            rel_max = rel_max.max(rel);
                        }
                    }
                    None if !got => {}
                    _ => {
                        if edge {
                            edges += 1;
                        } else {
                            bad.push(format!(
                                "wo {wo} uc {uc} u {u}: scalar {:?}, batch valid {got}",
                                s.map(|x| x.wi)
                            ));
                        }
                    }
                }
            }
            report.push(format!(
                "{json} {level}: {valid} of {n} valid ({below} refracted), max |Δwi| {wi_max:.1e}, max rel {rel_max:.1e}; ill-conditioned: {grazing} at the horizon, {ill} elsewhere; at an edge {edges}; beyond {}",
                bad.len()
            ));
            assert!(
                ill * 100 <= n,
                "{json} {level}: {ill} ill-conditioned samples"
            );
            assert!(
                bad.is_empty() && edges * 1000 <= n,
                "{json} {level}: {} beyond the tolerances, {edges} at an edge; first: {}",
                bad.len(),
                bad.first().cloned().unwrap_or_default()
            );
            assert!(
                below * 4 > valid,
                "{json}: refraction is most of the samples"
            );
            match &first {
                None => first = Some(out),
                Some(f) => assert!(
                    f.wi == out.wi
                        && f.f == out.f
                        && f.pdf == out.pdf
                        && f.weight == out.weight
                        && f.valid == out.valid,
                    "{json}: {level} gives other bits than the first level"
                ),
            }
        }
    }
    eprintln!("{}", report.join("\n"));
}

#[test]
fn dielectric_eval_pdf_matches_the_scalar_path_over_the_sphere() {
    let mut rng = Pcg64::seed_from_u64(0xd1e2);
    let n = 20_000;
    for (json, m, strategy) in cases() {
        let sp = m.sampler(strategy).unwrap();
        let mut pairs = crate::batch::DirPairs::default();
        for j in 0..n {
            let o = wo_sphere(&mut rng);
            let i = if j % 2 == 0 {
                wo_sphere(&mut rng)
            } else {
                match sp.sample(d3(o), rng.random(), DVec2::new(rng.random(), rng.random())) {
                    Some(x) => [x.wi.x as f32, x.wi.y as f32, x.wi.z as f32],
                    None => wo_sphere(&mut rng),
                }
            };
            pairs.push(o, i);
        }
        for level in levels("dielectric_eval_pdf_matches_the_scalar_path_over_the_sphere") {
            let b = BatchSampler::with_level(&m, strategy, level).unwrap();
            let mut out = EvalPdfBuffers::new(n);
            b.eval_pdf(pairs.wo(), pairs.wi(), out.output()).unwrap();
            let (mut worst, mut edges, mut nonzero) = (0.0f64, 0usize, 0usize);
            let mut worst_at = String::new();
            let (mut ill, mut grazing) = (0usize, 0usize);
            let mut bad = Vec::new();
            for j in 0..n {
                let o = d3([pairs.wo[0][j], pairs.wo[1][j], pairs.wo[2][j]]);
                let i = d3([pairs.wi[0][j], pairs.wi[1][j], pairs.wi[2][j]]);
                let (f, pdf) = sp.eval_pdf(o, i);
                let got = [out.f[0][j], out.f[1][j], out.f[2][j], out.pdf[j]].map(f64::from);
                assert!(
                    got.iter().all(|v| v.is_finite()),
                    "{json} {level}: not finite"
                );
                nonzero += usize::from(pdf > 0.0);
                let e = [
                    rel_err(got[0], f.x),
                    rel_err(got[1], f.y),
                    rel_err(got[2], f.z),
                    rel_err(got[3], pdf),
                ]
                .into_iter()
                .fold(0.0, f64::max);
                let allowance = conditioning(&sp, o, i, ROUNDING, false);
                if allowance > ILL {
                    // At the horizon (a fifth of `random_wo`'s views graze
                    // it) or at total internal reflection's edge: f32
                    // cannot say; counted.
                    if o.z.abs() < 1e-2 || i.z.abs() < 1e-2 {
                        grazing += 1;
                    } else {
                        ill += 1;
                    }
                    continue;
                }
                if e > 1e-4 + allowance {
                    if o.z.abs() < 1e-4 || i.z.abs() < 1e-4 {
                        edges += 1;
                    } else {
                        bad.push(format!(
                            "wo {o} wi {i} (allowance {allowance:.1e}): f {got:?} vs {f} {pdf}"
                        ));
                    }
                } else if e > worst {
                    worst = e;
                    worst_at = format!(
                        "wo {o} wi {i} (allowance {allowance:.1e}): f {got:?} vs {f} {pdf}"
                    );
                }
            }
            eprintln!(
                "{json} {level}: eval_pdf max rel {worst:.1e} ({nonzero} of {n} nonzero); ill-conditioned: {grazing} at the horizon, {ill} elsewhere; next to the horizon {edges}; worst at {worst_at}"
            );
            assert!(
                ill * 100 <= n,
                "{json} {level}: {ill} ill-conditioned pairs"
            );
            assert!(nonzero * 3 > n, "{json}: most pairs have a density");
            assert!(
                bad.is_empty() && edges * 1000 <= n,
                "{json} {level}: {} beyond 1e-4; first: {}",
                bad.len(),
                bad.first().cloned().unwrap_or_default()
            );
        }
    }
}
