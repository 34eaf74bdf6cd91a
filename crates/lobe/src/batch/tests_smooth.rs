//! The smooth models' kernels (`kernel::smooth`: conductor, dielectric,
//! thin dielectric, plastic) and two-sided materials against the scalar
//! f64 path, at every level this CPU has, with `wo` over the whole sphere:
//! the same samples (the same outcome, `wi` within 1e-5, `f`, `pdf` and
//! `weight` within 1e-4 relative, or 1e-4 absolute where the value is
//! below 1), the same `eval_pdf` and the same bits at every level.
//!
//! Where the two paths may choose differently they are counted and held to
//! one sample in 10³: `uc` within 1e-5 of the reflectance (the f32 Fresnel
//! term differs from the f64 one by ~1e-7), or a direction within 1e-4 of
//! the horizon (where `f = value · pdf / |cos θi|` and the pdf's cosine
//! magnify the inputs' rounding).

use super::{bits, d3, levels, rel_err, uniform};
use crate::batch::{BatchSampler, EvalPdfBuffers, SampleBuffers, SampleInputs};
use crate::{BsdfStrategy, Material};
use glam::{DVec2, DVec3};
use rand::{Rng, RngExt, SeedableRng};
use rand_pcg::Pcg64;

/// (description, strategy): every smooth model, both transport modes, a
/// rarer inside, tints; two-sided materials of each batched kind.
const CASES: &[(&str, BsdfStrategy)] = &[
    (r#"{"type":"conductor"}"#, BsdfStrategy::Brdf),
    (
        r#"{"type":"conductor","material":"Au","specular_reflectance":[0.9,0.8,1.0]}"#,
        BsdfStrategy::Brdf,
    ),
    (r#"{"type":"dielectric"}"#, BsdfStrategy::Brdf),
    (
        r#"{"type":"dielectric","int_ior":1.0,"ext_ior":1.33,"specular_transmittance":[0.9,0.5,0.2]}"#,
        BsdfStrategy::Brdf,
    ),
    (
        r#"{"type":"dielectric","int_ior":"diamond","mode":"importance","specular_reflectance":0.7}"#,
        BsdfStrategy::Brdf,
    ),
    (
        r#"{"type":"thindielectric","int_ior":1.7,"specular_transmittance":[0.5,0.9,0.9]}"#,
        BsdfStrategy::Brdf,
    ),
    (r#"{"type":"plastic"}"#, BsdfStrategy::Brdf),
    (
        r#"{"type":"plastic","diffuse_reflectance":[0.8,0.3,0.1],"nonlinear":true,"int_ior":2.0}"#,
        BsdfStrategy::Brdf,
    ),
    (
        r#"{"type":"twosided","material":{"type":"diffuse","reflectance":[0.2,0.5,0.8]}}"#,
        BsdfStrategy::Cosine,
    ),
    (
        r#"{"type":"twosided","material":{"type":"diffuse"}}"#,
        BsdfStrategy::Uniform,
    ),
    (
        r#"{"type":"twosided","material":{"type":"roughconductor","distribution":"ggx","alpha":0.3,"material":"Cu"}}"#,
        BsdfStrategy::Vndf,
    ),
    (
        r#"{"type":"twosided","material":{"type":"roughplastic","distribution":"beckmann","alpha":0.2}}"#,
        BsdfStrategy::Brdf,
    ),
    (
        r#"{"type":"twosided","material":{"type":"conductor"}}"#,
        BsdfStrategy::Brdf,
    ),
    (
        r#"{"type":"twosided","material":{"type":"plastic"}}"#,
        BsdfStrategy::Brdf,
    ),
];

/// A uniform direction over the sphere, with one in 50 within 1e-3 of the
/// horizon.
fn sphere(rng: &mut impl Rng) -> [f32; 3] {
    let z: f64 = if rng.random::<f64>() < 0.02 {
        rng.random_range(-1e-3..1e-3)
    } else {
        rng.random_range(-1.0..1.0)
    };
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * rng.random::<f64>();
    let w = DVec3::new(r * phi.cos(), r * phi.sin(), z).normalize();
    [w.x as f32, w.y as f32, w.z as f32]
}

/// Whether the two paths may part at this sample: a direction near the
/// horizon, or `uc` within 1e-5 of where the scalar path's choice of part
/// changes (found by moving `uc`).
fn near_an_edge(
    sp: &crate::BsdfSampler<'_>,
    wo: DVec3,
    uc: f64,
    u: DVec2,
    s: Option<crate::BsdfSample>,
) -> bool {
    if wo.z.abs() < 1e-4 || s.is_some_and(|x| x.wi.z.abs() < 1e-4) {
        return true;
    }
    let part = |x: Option<crate::BsdfSample>| x.map(|x| x.scattering);
    [uc - 1e-5, uc + 1e-5]
        .into_iter()
        .filter(|v| (0.0..1.0).contains(v))
        .any(|v| part(sp.sample(wo, v, u)) != part(s))
}

/// The batch value `a` against the scalar `b`: absolute below 1, relative
/// above.
fn err(a: f32, b: f64) -> f64 {
    let a = f64::from(a);
    if b.abs() < 1.0 {
        (a - b).abs()
    } else {
        rel_err(a, b)
    }
}

#[test]
fn smooth_and_two_sided_samples_match_the_scalar_path() {
    let mut rng = Pcg64::seed_from_u64(0x5a0f);
    let n = 20_000;
    let mut report = Vec::new();
    for &(json, strategy) in CASES {
        let m = Material::load(json).unwrap();
        let sp = m.sampler(strategy).unwrap();
        let mut inp = SampleInputs::default();
        for _ in 0..n {
            inp.push(
                sphere(&mut rng),
                uniform(&mut rng),
                uniform(&mut rng),
                uniform(&mut rng),
            );
        }
        let mut first: Option<SampleBuffers> = None;
        for level in levels("smooth_and_two_sided_samples_match_the_scalar_path") {
            let b = BatchSampler::with_level(&m, strategy, level)
                .unwrap_or_else(|e| panic!("{json} {strategy}: {e}"));
            let mut out = SampleBuffers::new(n);
            b.sample(inp.input(true), out.output()).unwrap();
            let (mut edges, mut bad, mut valid) = (0usize, Vec::new(), 0usize);
            let (mut wi_max, mut rel_max) = (0.0f64, 0.0f64);
            for j in 0..n {
                let wo = d3([inp.wo[0][j], inp.wo[1][j], inp.wo[2][j]]);
                let uc = f64::from(inp.uc[j]);
                let u = DVec2::new(inp.u1[j].into(), inp.u2[j].into());
                let s = sp.sample(wo, uc, u);
                let got = out.valid[j] != 0;
                let edge = near_an_edge(&sp, wo, uc, u, s);
                match s {
                    Some(x) if got => {
                        valid += 1;
                        let wi = d3([out.wi[0][j], out.wi[1][j], out.wi[2][j]]);
                        let dwi = (wi - x.wi).abs().max_element();
                        let rel = [
                            err(out.f[0][j], x.f.x),
                            err(out.f[1][j], x.f.y),
                            err(out.f[2][j], x.f.z),
                            err(out.pdf[j], x.pdf),
                            err(out.weight[0][j], x.weight.x),
                            err(out.weight[1][j], x.weight.y),
                            err(out.weight[2][j], x.weight.z),
                        ]
                        .into_iter()
                        .fold(0.0, f64::max);
                        if dwi > 1e-5 || rel > 1e-4 {
                            if edge {
                                edges += 1;
                            } else {
                                bad.push(format!(
                                    "wo {wo} uc {uc} u {u}: wi {wi} vs {} (Δ {dwi:.1e}), f {:?} vs {}, pdf {} vs {}, weight {:?} vs {} (err {rel:.1e})",
                                    x.wi,
                                    [out.f[0][j], out.f[1][j], out.f[2][j]],
                                    x.f,
                                    out.pdf[j],
                                    x.pdf,
                                    [out.weight[0][j], out.weight[1][j], out.weight[2][j]],
                                    x.weight
                                ));
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
                "{json} {strategy} {level}: {valid} of {n} valid, max |Δwi| {wi_max:.1e}, max err {rel_max:.1e}; at an edge {edges}; beyond {}",
                bad.len()
            ));
            assert!(valid * 4 > n, "{json}: {valid} of {n} samples valid");
            assert!(
                bad.is_empty() && edges * 1000 <= n,
                "{json} {level}: {} beyond the tolerances, {edges} at an edge; first: {}",
                bad.len(),
                bad.first().cloned().unwrap_or_default()
            );
            match &first {
                None => first = Some(out),
                Some(f) => assert!(
                    bits(f) == bits(&out),
                    "{json}: {level} gives other bits than the first level"
                ),
            }
        }
    }
    eprintln!("{}", report.join("\n"));
}

fn dirs(v: &[Vec<f32>; 3]) -> crate::batch::Dirs<'_> {
    crate::batch::Dirs {
        x: &v[0],
        y: &v[1],
        z: &v[2],
    }
}

#[test]
fn smooth_and_two_sided_eval_pdf_matches_the_scalar_path() {
    let mut rng = Pcg64::seed_from_u64(0x5a10);
    let n = 20_000;
    for &(json, strategy) in CASES {
        let m = Material::load(json).unwrap();
        let sp = m.sampler(strategy).unwrap();
        let mut wo = [vec![], vec![], vec![]];
        let mut wi = [vec![], vec![], vec![]];
        for _ in 0..n {
            let (a, b) = (sphere(&mut rng), sphere(&mut rng));
            for c in 0..3 {
                wo[c].push(a[c]);
                wi[c].push(b[c]);
            }
        }
        let mut first: Option<EvalPdfBuffers> = None;
        for level in levels("smooth_and_two_sided_eval_pdf_matches_the_scalar_path") {
            let b = BatchSampler::with_level(&m, strategy, level).unwrap();
            let mut out = EvalPdfBuffers::new(n);
            b.eval_pdf(dirs(&wo), dirs(&wi), out.output()).unwrap();
            let mut bad = Vec::new();
            for j in 0..n {
                let a = d3([wo[0][j], wo[1][j], wo[2][j]]);
                let c = d3([wi[0][j], wi[1][j], wi[2][j]]);
                if a.z.abs() < 1e-4 || c.z.abs() < 1e-4 {
                    continue;
                }
                let f = m.eval(a, c);
                let pdf = sp.pdf(a, c);
                let e = [
                    err(out.f[0][j], f.x),
                    err(out.f[1][j], f.y),
                    err(out.f[2][j], f.z),
                    err(out.pdf[j], pdf),
                ]
                .into_iter()
                .fold(0.0, f64::max);
                if e > 1e-4 {
                    bad.push(format!(
                        "wo {a} wi {c}: f {:?} vs {f}, pdf {} vs {pdf}",
                        [out.f[0][j], out.f[1][j], out.f[2][j]],
                        out.pdf[j]
                    ));
                }
            }
            assert!(
                bad.is_empty(),
                "{json} {level}: {} pairs beyond 1e-4; first: {}",
                bad.len(),
                bad[0]
            );
            match &first {
                None => first = Some(out),
                Some(f) => assert!(
                    f.f == out.f && f.pdf == out.pdf,
                    "{json}: {level} gives other bits than the first level"
                ),
            }
        }
    }
}
