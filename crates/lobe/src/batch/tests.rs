//! The batch path against the scalar f64 reference, at every level this
//! CPU has (the others are reported as skipped).
//!
//! Tolerances, each measured and printed (`--nocapture`):
//! * validity: the same mask, except where `wi` is within 1e-5 of the
//!   horizon (for either path);
//! * `wi`: within 1e-5 absolute of the scalar sample's, or within what a
//!   change of 4 f32 ulps of `u` makes of the f64 sample (the f32 inputs
//!   cannot pin `wi` down better where the map `u → wi` is steep: grazing
//!   `wo` with tiny alpha);
//! * `f`, `pdf`, `weight` of a sample: within 1e-4 relative of the scalar
//!   `eval_pdf` at the batch's own `wi` (the f32 direction rounds by 6e-8,
//!   which for alpha = 1e-4 moves `D` by 1e-3: the f64 values of a
//!   *different* `wi` are no reference), with an absolute floor of 1e-30;
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
fn levels(test: &str) -> Vec<SimdLevel> {
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
fn uniform(rng: &mut impl Rng) -> f32 {
    (rng.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// A view direction: 10% at cos θ = 1e-7, 10% with cos θ log-uniform in
/// [1e-7, 1e-2], 1% at the normal, the rest uniform over the hemisphere.
fn random_wo(rng: &mut impl Rng) -> [f32; 3] {
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

fn d3(v: [f32; 3]) -> DVec3 {
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
struct Inputs {
    wo: [Vec<f32>; 3],
    u1: Vec<f32>,
    u2: Vec<f32>,
}

fn inputs(rng: &mut impl Rng, n: usize) -> Inputs {
    let mut wo = [vec![], vec![], vec![]];
    let (mut u1, mut u2) = (vec![], vec![]);
    for _ in 0..n {
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
    Inputs { wo, u1, u2 }
}

impl Inputs {
    fn input(&self) -> SampleInput<'_> {
        SampleInput {
            wo: self.wo(),
            u1: &self.u1,
            u2: &self.u2,
            uc: None,
        }
    }
    fn wo(&self) -> Dirs<'_> {
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
fn rel_err(a: f64, b: f64) -> f64 {
    let d = (a - b).abs();
    if d <= FLOOR { 0.0 } else { d / b.abs() }
}

#[derive(Default, Debug)]
struct Worst {
    mask_exempt: usize,
    mask_bad: Vec<String>,
    wi_abs: f64,
    wi_beyond_1e5: usize,
    wi_bad: Vec<String>,
    f_rel: f64,
    pdf_rel: f64,
    weight_rel: f64,
    ill_conditioned: usize,
    ill_rel: f64,
    bad: Vec<String>,
    valid: usize,
    count: usize,
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

/// The f64 change of the scalar sample's `wi` when `u` moves by 4 f32 ulps.
fn wi_sensitivity(m: &Material, s: BsdfStrategy, wo: DVec3, u: DVec2, wi: DVec3) -> f64 {
    let mut worst: f64 = 0.0;
    for (dx, dy) in [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)] {
        let du = 4.0 * f64::from(f32::EPSILON) * 0.5;
        let v = DVec2::new(
            (u.x + dx * du).clamp(0.0, 1.0 - 1e-9),
            (u.y + dy * du).clamp(0.0, 1.0 - 1e-9),
        );
        match m.sample(s, wo, 0.5, v) {
            Some(x) => worst = worst.max((x.wi - wi).abs().max_element()),
            None => return f64::INFINITY,
        }
    }
    worst
}

fn compare_samples(
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
        let wo = inp.wo_at(i);
        let u = DVec2::new(inp.u1[i].into(), inp.u2[i].into());
        let scalar = sp.sample(wo, 0.5, u);
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
                    w.wi_beyond_1e5 += 1;
                    let sens = wi_sensitivity(m, s, wo, u, x.wi);
                    if e > 1e-5 + sens {
                        w.wi_bad.push(format!(
                            "{m:?} {s} wo {wo} u {u}: wi {} vs {wi_b}, |Δ| {e:.2e}, 4-ulp sensitivity {sens:.2e}",
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
                let conditioned = explained.iter().all(|&x| x < 1e-6);
                for (k, &err) in errs.iter().enumerate() {
                    if err > REL + 2.0 * explained[k] {
                        w.bad.push(format!(
                            "{m:?} {s} wo {wo} u {u}: value {k}: {} vs {}, rel {err:.2e}, explained by |Δwi| = {e:.2e}: {:.2e}",
                            got[k], want[k], explained[k]
                        ));
                    }
                }
                if conditioned {
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
                 max |Δwi| {:.2e} ({} beyond 1e-5, all within the 4-ulp sensitivity: {}); \
                 max rel error: f {:.2e}, pdf {:.2e}, weight {:.2e}; \
                 ill-conditioned (|Δwi| moves a value by over 1e-6): {}, worst {:.2e}, each within 1e-4 + twice what |Δwi| explains",
                w.count,
                w.valid,
                w.mask_exempt,
                w.wi_abs,
                w.wi_beyond_1e5,
                w.wi_bad.is_empty(),
                w.f_rel,
                w.pdf_rel,
                w.weight_rel,
                w.ill_conditioned,
                w.ill_rel,
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
