//! The measured kernel: MERL and RGL tables in the batch API.
//!
//! A measured material is a table lookup, not arithmetic: its cost is the
//! index computation (an `acos` and two `atan2` for MERL, the RGL warps'
//! searches) and the memory access, and a nearest-entry MERL lookup is
//! discontinuous, so that an index computed in f32 would pick the
//! neighbouring entry for inputs within f32 rounding of an entry's edge.
//! The kernel therefore runs lane by lane, converting each lane's f32
//! inputs to f64 (renormalized) and computing exactly as the scalar path does (the same
//! table code, [`crate::models::measured`]), over the `f32` tables that
//! the material already holds; its outputs are the scalar path's numbers
//! at the f32 inputs, rounded once to f32. The strategy is a const
//! parameter of the block loop and the table's format one match per call:
//! no allocation and no dynamic dispatch per sample. The code uses no
//! instruction of any SIMD level, so every level gives the same bits.
//!
//! Strategies, as [`crate::models::measured::Measured`] has them:
//! `uniform`, `cosine`, `brdf` (the tabulated half-vector sampler) and, for
//! RGL files, `vndf` (the file's luminance and visible-normal warps).

use super::block::{BOTH, EvalIn, EvalOut, F_ONLY, PDF_ONLY, SampleIn, SampleOut};
use crate::models::measured::{Measured, MeasuredData, Table};
use crate::{BsdfStrategy, Material, Rgb, warp};
use glam::{DVec2, DVec3};

/// `STRAT`: uniform hemisphere.
const UNIFORM: u8 = 0;
/// `STRAT`: cosine-weighted hemisphere.
const COSINE: u8 = 1;
/// `STRAT`: the tabulated half-vector sampler.
const BRDF: u8 = 2;
/// `STRAT`: an RGL file's own warps.
const VNDF: u8 = 3;

/// A measured table and a strategy, as a [`super::BatchSampler`] runs them.
#[derive(Clone)]
pub(crate) struct MeasuredKernel {
    data: std::sync::Arc<MeasuredData>,
    strat: u8,
    /// With a diffuse term: the material and strategy, run lane by lane
    /// through the material's [`crate::BsdfSampler`] (the
    /// mixture: `uc` chooses the lobe, the pdf is the mixture density, `f`
    /// the sum).
    mixture: Option<(Material, BsdfStrategy)>,
}

impl std::fmt::Debug for MeasuredKernel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "MeasuredKernel {{ path: {:?}, format: {}, strat: {}, diffuse: {:?} }}",
            self.data.path,
            self.data.table.format(),
            self.strat,
            self.mixture.as_ref().map(|(m, _)| m.diffuse.albedo)
        )
    }
}

impl PartialEq for MeasuredKernel {
    /// The same table (read once per file) and strategy.
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.data, &other.data)
            && self.strat == other.strat
            && self.mixture.as_ref().map(|(m, _)| m.diffuse.albedo)
                == other.mixture.as_ref().map(|(m, _)| m.diffuse.albedo)
    }
}

impl MeasuredKernel {
    /// The kernel of the measured material `m` (glossy lobe `lobe`) for
    /// `strategy` (which the caller has checked applies: `Material::check`).
    pub(crate) fn new(
        m: &Material,
        lobe: &Measured,
        strategy: BsdfStrategy,
    ) -> Option<MeasuredKernel> {
        let strat = match (strategy, &lobe.data.table) {
            (BsdfStrategy::Uniform, _) => UNIFORM,
            (BsdfStrategy::Cosine, _) => COSINE,
            (BsdfStrategy::Brdf, _) => BRDF,
            (BsdfStrategy::Vndf, Table::Rgl(_)) => VNDF,
            _ => return None,
        };
        Some(MeasuredKernel {
            data: lobe.data.clone(),
            strat,
            mixture: m.has_diffuse().then(|| (m.clone(), strategy)),
        })
    }

    /// Whether `sample` reads `uc` ([`Material::chooses_lobe`]).
    pub(crate) fn chooses_lobe(&self) -> bool {
        self.mixture
            .as_ref()
            .is_some_and(|(m, s)| m.chooses_lobe(*s))
    }
}

/// One sample, as `Material::sample` draws it for a measured material (a
/// single lobe): `(wi, f, pdf)`, `None` for a failed sample.
#[inline(always)]
fn sample_one<const S: u8>(d: &MeasuredData, wo: DVec3, u: DVec2) -> Option<(DVec3, Rgb, f64)> {
    if wo.z <= 0.0 {
        return None;
    }
    let (wi, pdf) = match S {
        UNIFORM => {
            let wi = warp::square_to_uniform_hemisphere(u);
            (wi, warp::square_to_uniform_hemisphere_pdf(wi))
        }
        COSINE => {
            let wi = warp::square_to_cosine_hemisphere(u);
            (wi, warp::square_to_cosine_hemisphere_pdf(wi))
        }
        BRDF => {
            let wi = d.sampler.sample(wo, u)?;
            (wi, d.sampler.pdf(wo, wi))
        }
        _ => {
            let Table::Rgl(r) = &d.table else {
                unreachable!("MeasuredKernel::new builds vndf for RGL files only")
            };
            let wi = r.sample_warps(wo, u)?;
            (wi, r.pdf_warps(wo, wi))
        }
    };
    if wi.z <= 0.0 {
        return None;
    }
    Some((wi, d.table.eval(wo, wi, d.interpolation), pdf))
}

/// `(f, pdf)` as `Material::eval_pdf` has them: zero unless both directions
/// are above the horizon.
#[inline(always)]
fn eval_pdf_one<const S: u8, const MODE: u8>(d: &MeasuredData, wo: DVec3, wi: DVec3) -> (Rgb, f64) {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return (Rgb::ZERO, 0.0);
    }
    let f = if MODE == PDF_ONLY {
        Rgb::ZERO
    } else {
        d.table.eval(wo, wi, d.interpolation)
    };
    let pdf = if MODE == F_ONLY {
        0.0
    } else {
        match S {
            UNIFORM => warp::square_to_uniform_hemisphere_pdf(wi),
            COSINE => warp::square_to_cosine_hemisphere_pdf(wi),
            BRDF => d.sampler.pdf(wo, wi),
            _ => match &d.table {
                Table::Rgl(r) => r.pdf_warps(wo, wi),
                Table::Merl(_) => unreachable!("vndf for RGL files only"),
            },
        }
    };
    (f, pdf)
}

/// Lane `i` of a block of directions, in f64 and renormalized: an f32 unit
/// vector's length is 1 only to 6e-8, which `wo + wi` in the retro-reflection
/// direction at grazing views (`1 + wo·wi` ~ 1e-5) amplifies to 1e-3 of the
/// pdf; the renormalized direction differs from the f64 one only by the
/// rounding of its direction (3e-8).
#[inline(always)]
fn dvec3(x: [&[f32]; 3], i: usize) -> DVec3 {
    DVec3::new(f64::from(x[0][i]), f64::from(x[1][i]), f64::from(x[2][i])).normalize_or_zero()
}

/// `sample` over a block, lane by lane: `lane(wo, u, uc)` gives the f64
/// `(wi, f, pdf)` of one lane, `None` for a failed sample.
fn sample_lanes(
    inp: SampleIn<'_>,
    (out, valid): SampleOut<'_, '_>,
    lane: impl Fn(DVec3, DVec2, f64) -> Option<(DVec3, Rgb, f64)>,
) {
    let n = inp[0].len();
    // Equal lengths, stated once.
    for s in &inp {
        assert_eq!(s.len(), n);
    }
    // `f` (outputs 3 to 5) may be empty: not wanted.
    for (j, o) in out.iter().enumerate() {
        assert!(o.len() == n || (o.is_empty() && (3..6).contains(&j)));
    }
    assert_eq!(valid.len(), n);
    for i in 0..n {
        let wo = dvec3([inp[0], inp[1], inp[2]], i);
        let u = DVec2::new(f64::from(inp[3][i]), f64::from(inp[4][i]));
        store_lane(i, lane(wo, u, f64::from(inp[5][i])), out, valid);
    }
}

/// Lane `i` of a sample's outputs from the f64 `(wi, f, pdf)`: the weight
/// as the scalar path's `finish` computes it, then everything in f32;
/// zeros and mask 0 for a failed sample or one that f32 cannot carry.
#[inline(always)]
fn store_lane(
    i: usize,
    x: Option<(DVec3, Rgb, f64)>,
    out: &mut [&mut [f32]; 10],
    valid: &mut [u8],
) {
    let s = x.and_then(|(wi, f, pdf)| {
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        let weight = f * (wi.z / pdf);
        let v = [
            wi.x as f32,
            wi.y as f32,
            wi.z as f32,
            f.x as f32,
            f.y as f32,
            f.z as f32,
            pdf as f32,
            weight.x as f32,
            weight.y as f32,
            weight.z as f32,
        ];
        (v[6] > 0.0 && v.iter().all(|x| x.is_finite())).then_some(v)
    });
    match s {
        Some(v) => {
            for (o, x) in out.iter_mut().zip(v) {
                if let Some(o) = o.get_mut(i) {
                    *o = x;
                }
            }
            valid[i] = 1;
        }
        None => {
            for o in out.iter_mut() {
                if let Some(o) = o.get_mut(i) {
                    *o = 0.0;
                }
            }
            valid[i] = 0;
        }
    }
}

/// `eval_pdf` over a block, lane by lane: `lane(wo, wi)` gives the f64
/// `(f, pdf)`; the outputs `MODE` names are written.
fn eval_pdf_lanes<const MODE: u8>(
    inp: EvalIn<'_>,
    out: EvalOut<'_, '_>,
    lane: impl Fn(DVec3, DVec3) -> (Rgb, f64),
) {
    let n = inp[0].len();
    for s in &inp {
        assert_eq!(s.len(), n);
    }
    if MODE != PDF_ONLY {
        for o in &out[..3] {
            assert_eq!(o.len(), n);
        }
    }
    if MODE != F_ONLY {
        assert_eq!(out[3].len(), n);
    }
    #[allow(clippy::needless_range_loop)] // `i` indexes ten slices
    for i in 0..n {
        let wo = dvec3([inp[0], inp[1], inp[2]], i);
        let wi = dvec3([inp[3], inp[4], inp[5]], i);
        let (f, pdf) = lane(wo, wi);
        if MODE != PDF_ONLY {
            // Zero where not finite, as the Cook-Torrance kernels.
            let ok = f.is_finite();
            out[0][i] = if ok { f.x as f32 } else { 0.0 };
            out[1][i] = if ok { f.y as f32 } else { 0.0 };
            out[2][i] = if ok { f.z as f32 } else { 0.0 };
        }
        if MODE != F_ONLY {
            out[3][i] = if pdf.is_finite() { pdf as f32 } else { 0.0 };
        }
    }
}

/// `sample` over a block (lengths checked equal by the caller). With a
/// diffuse term, through the scalar mixture (`uc`, `inp[5]`, chooses the
/// lobe); without, the table's strategy directly (`uc` unread).
pub(crate) fn sample_block(k: &MeasuredKernel, inp: SampleIn<'_>, out: SampleOut<'_, '_>) {
    if let Some((m, s)) = &k.mixture {
        let sampler = m
            .sampler(*s)
            .expect("the strategy was checked when the kernel was made");
        return sample_lanes(inp, out, |wo, u, uc| {
            sampler.sample(wo, uc, u).map(|x| (x.wi, x.f, x.pdf))
        });
    }
    let d: &MeasuredData = &k.data;
    match k.strat {
        UNIFORM => sample_lanes(inp, out, |wo, u, _| sample_one::<UNIFORM>(d, wo, u)),
        COSINE => sample_lanes(inp, out, |wo, u, _| sample_one::<COSINE>(d, wo, u)),
        BRDF => sample_lanes(inp, out, |wo, u, _| sample_one::<BRDF>(d, wo, u)),
        _ => sample_lanes(inp, out, |wo, u, _| sample_one::<VNDF>(d, wo, u)),
    }
}

/// `eval_pdf` over a block, writing the outputs `mode` names.
pub(crate) fn eval_pdf_block(k: &MeasuredKernel, mode: u8, inp: EvalIn<'_>, out: EvalOut<'_, '_>) {
    macro_rules! by_mode {
        ($lane:expr) => {
            match mode {
                F_ONLY => eval_pdf_lanes::<F_ONLY>(inp, out, $lane),
                PDF_ONLY => eval_pdf_lanes::<PDF_ONLY>(inp, out, $lane),
                _ => eval_pdf_lanes::<BOTH>(inp, out, $lane),
            }
        };
    }
    if let Some((m, s)) = &k.mixture {
        let sampler = m
            .sampler(*s)
            .expect("the strategy was checked when the kernel was made");
        return by_mode!(|wo, wi| sampler.eval_pdf(wo, wi));
    }
    let d: &MeasuredData = &k.data;
    macro_rules! by_strat {
        ($s:ident) => {
            match mode {
                F_ONLY => eval_pdf_lanes::<F_ONLY>(inp, out, |wo, wi| {
                    eval_pdf_one::<$s, F_ONLY>(d, wo, wi)
                }),
                PDF_ONLY => eval_pdf_lanes::<PDF_ONLY>(inp, out, |wo, wi| {
                    eval_pdf_one::<$s, PDF_ONLY>(d, wo, wi)
                }),
                _ => eval_pdf_lanes::<BOTH>(inp, out, |wo, wi| eval_pdf_one::<$s, BOTH>(d, wo, wi)),
            }
        };
    }
    match k.strat {
        UNIFORM => by_strat!(UNIFORM),
        COSINE => by_strat!(COSINE),
        BRDF => by_strat!(BRDF),
        _ => by_strat!(VNDF),
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::super::{
        BatchSampler, Dirs, EvalPdfBuffers, RgbMut, SampleBuffers, SampleInput, SimdLevel, Store,
    };
    use crate::models::measured::Measured;
    use crate::models::measured::merl::Merl;
    use crate::models::measured::rgl::Rgl;
    use crate::{BsdfStrategy, Glossy, Material, Rgb};
    use glam::{DVec2, DVec3};

    /// A GGX + Lambert material to tabulate.
    pub(in crate::batch) fn analytic() -> Material {
        let lobe = crate::models::CookTorrance::new(
            Rgb::new(0.9, 0.7, 0.5),
            crate::Microfacet::new(crate::Ndf::Ggx, 0.2, 0.2).unwrap(),
            crate::Shadowing::SmithCorrelated,
            crate::Fresnel::None,
        )
        .unwrap();
        Material::with_diffuse(Rgb::splat(0.1), Glossy::CookTorrance(lobe)).unwrap()
    }

    pub(in crate::batch) fn measured(
        bytes: &[u8],
        name: &str,
        interp: Option<crate::models::measured::Interpolation>,
    ) -> Material {
        let lobe = Measured::from_bytes(bytes, std::path::Path::new(name), interp).unwrap();
        Material::with_diffuse(Rgb::ZERO, Glossy::Measured(lobe)).unwrap()
    }

    /// Every level gives the same bits, and they are the scalar path's
    /// numbers at the f32 inputs (renormalized in f64) rounded to f32 (the
    /// same computation), for MERL (nearest and linear) and RGL tables,
    /// alone and with a diffuse term (`uc` chooses the lobe), and every
    /// strategy.
    fn dirs(w: &[Vec<f32>; 3]) -> Dirs<'_> {
        Dirs {
            x: &w[0],
            y: &w[1],
            z: &w[2],
        }
    }

    #[test]
    fn measured_kernel_is_the_scalar_path_at_every_level() {
        let a = analytic();
        let merl = Merl::from_fn(|o, i| a.eval(o, i), |k| k % 97 == 3).to_bytes();
        let rgl = Rgl::write(|o, i| a.eval(o, i), 6, 24, "batch test");
        let cases = [
            ("merl-nearest", measured(&merl, "t.binary", None)),
            (
                "merl-linear",
                measured(
                    &merl,
                    "t.binary",
                    Some(crate::models::measured::Interpolation::Linear),
                ),
            ),
            ("rgl", measured(&rgl, "t.bsdf", None)),
        ];
        // The same tables with a diffuse term: the two-lobe mixture, `uc`
        // choosing the lobe where the strategy samples both.
        let with_kd = |m: &Material| {
            let mut m = m.clone();
            m.diffuse = crate::models::Lambert::new(Rgb::new(0.3, 0.2, 0.1)).unwrap();
            m
        };
        let cases = [
            cases[0].clone(),
            cases[1].clone(),
            cases[2].clone(),
            ("merl-nearest + kd", with_kd(&cases[0].1)),
            ("rgl + kd", with_kd(&cases[2].1)),
        ];
        let n = 3001;
        // Inputs in f32: views with grazing ones, uniforms.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 40) as f32) / (1u64 << 24) as f32
        };
        let mut wo = [vec![0f32; n], vec![0f32; n], vec![0f32; n]];
        let mut wi = [vec![0f32; n], vec![0f32; n], vec![0f32; n]];
        let (mut u1, mut u2, mut uc) = (vec![0f32; n], vec![0f32; n], vec![0f32; n]);
        for k in 0..n {
            for w in [&mut wo, &mut wi] {
                let z = if k % 10 == 0 {
                    1e-3 + 0.05 * next()
                } else {
                    next()
                };
                let phi = std::f32::consts::TAU * next();
                let s = (1.0 - z * z).max(0.0).sqrt();
                w[0][k] = s * phi.cos();
                w[1][k] = s * phi.sin();
                w[2][k] = z;
            }
            u1[k] = next();
            u2[k] = next();
            uc[k] = next();
        }
        let d = |w: &[Vec<f32>; 3], k: usize| {
            DVec3::new(w[0][k].into(), w[1][k].into(), w[2][k].into()).normalize_or_zero()
        };
        for (name, m) in &cases {
            for s in m.strategies() {
                let mut first: Option<(SampleBuffers, EvalPdfBuffers)> = None;
                for level in SimdLevel::ALL.into_iter().filter(|l| l.is_available()) {
                    let b = BatchSampler::with_level(m, s, level).unwrap();
                    assert_eq!(b.chooses_lobe(), m.chooses_lobe(s), "{name} {s}");
                    let mut out = SampleBuffers::new(n);
                    if b.chooses_lobe() {
                        let r = b.sample(
                            SampleInput {
                                wo: dirs(&wo),
                                u1: &u1,
                                u2: &u2,
                                uc: None,
                            },
                            out.output(),
                        );
                        assert!(
                            matches!(r, Err(super::super::BatchError::MissingUc)),
                            "{name} {s}: {r:?}"
                        );
                    }
                    b.sample(
                        SampleInput {
                            wo: dirs(&wo),
                            u1: &u1,
                            u2: &u2,
                            uc: Some(&uc),
                        },
                        out.output(),
                    )
                    .unwrap();
                    // Without `f` (empty: not wanted), streamed: the rest
                    // the same bits.
                    let mut no_f = SampleBuffers::new(n);
                    {
                        let mut o = no_f.output();
                        o.f = RgbMut {
                            r: &mut [],
                            g: &mut [],
                            b: &mut [],
                        };
                        let input = SampleInput {
                            wo: dirs(&wo),
                            u1: &u1,
                            u2: &u2,
                            uc: Some(&uc),
                        };
                        b.sample_with(input, o, Store::Streamed).unwrap();
                    }
                    no_f.f = out.f.clone();
                    assert_eq!(no_f, out, "{name} {s} {level}: sample without f");
                    let mut ep = EvalPdfBuffers::new(n);
                    b.eval_pdf(dirs(&wo), dirs(&wi), ep.output()).unwrap();
                    // eval and pdf alone: the same bits as eval_pdf.
                    let mut f = EvalPdfBuffers::new(n);
                    {
                        let o = f.output();
                        b.eval(dirs(&wo), dirs(&wi), o.f).unwrap();
                        b.pdf(dirs(&wo), dirs(&wi), o.pdf).unwrap();
                    }
                    assert_eq!(f, ep, "{name} {s} {level}: eval/pdf vs eval_pdf");
                    match &first {
                        None => first = Some((out, ep)),
                        Some((o0, e0)) => {
                            assert_eq!(
                                &out, o0,
                                "{name} {s} {level}: sample differs between levels"
                            );
                            assert_eq!(
                                &ep, e0,
                                "{name} {s} {level}: eval_pdf differs between levels"
                            );
                        }
                    }
                }
                let (out, ep) = first.unwrap();
                let mut valid = 0;
                for k in 0..n {
                    let o = d(&wo, k);
                    let r = m.sampler(s).unwrap().sample(
                        o,
                        uc[k].into(),
                        DVec2::new(u1[k].into(), u2[k].into()),
                    );
                    match r {
                        None => assert_eq!(out.valid[k], 0, "{name} {s} #{k}"),
                        Some(r) => {
                            valid += 1;
                            let want = [
                                r.wi.x, r.wi.y, r.wi.z, r.f.x, r.f.y, r.f.z, r.pdf, r.weight.x,
                                r.weight.y, r.weight.z,
                            ]
                            .map(|x| x as f32);
                            let got = [
                                out.wi[0][k],
                                out.wi[1][k],
                                out.wi[2][k],
                                out.f[0][k],
                                out.f[1][k],
                                out.f[2][k],
                                out.pdf[k],
                                out.weight[0][k],
                                out.weight[1][k],
                                out.weight[2][k],
                            ];
                            assert_eq!(out.valid[k], 1, "{name} {s} #{k}");
                            assert_eq!(got, want, "{name} {s} #{k}");
                        }
                    }
                    let (f, p) = m.sampler(s).unwrap().eval_pdf(o, d(&wi, k));
                    let got = [ep.f[0][k], ep.f[1][k], ep.f[2][k], ep.pdf[k]];
                    assert_eq!(
                        got,
                        [f.x, f.y, f.z, p].map(|x| x as f32),
                        "{name} {s} eval_pdf #{k}"
                    );
                }
                assert!(valid > n / 2, "{name} {s}: {valid} valid samples of {n}");
            }
        }
        // MERL tables have no vndf; RGL files do; with kd the brdf (and
        // RGL's vndf) strategies choose a lobe.
        assert!(cases[3].1.chooses_lobe(BsdfStrategy::Brdf));
        assert!(cases[4].1.chooses_lobe(BsdfStrategy::Vndf));
        assert_eq!(cases[0].1.strategies().len(), 3);
        assert!(cases[2].1.strategies().contains(&BsdfStrategy::Vndf));
    }
}
