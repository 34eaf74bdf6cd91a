//! Batched sampling and evaluation in f32 lanes, structure of arrays, with
//! runtime CPU dispatch: the fast path beside the scalar f64 one, which
//! stays the reference.
//!
//! A [`BatchSampler`] is built once for a material and a strategy; then
//! [`BatchSampler::sample`] fills caller-owned output slices for a block of
//! inputs, and [`BatchSampler::eval_pdf`] does the same for `(wo, wi)`
//! blocks. No allocation, no dynamic dispatch per sample: the level and the
//! strategy are chosen once per call, and the kernel runs over vectors of
//! 16 (AVX-512), 8 (AVX2 + FMA) or 1 (portable) lanes.
//!
//! ```
//! use lobe::batch::{BatchSampler, SampleBuffers};
//! use lobe::{BsdfStrategy, Fresnel, Glossy, Material, Microfacet, Ndf, Rgb, Shadowing};
//! use lobe::models::CookTorrance;
//! let ggx = Microfacet::new(Ndf::Ggx, 0.2, 0.2)?;
//! let lobe = CookTorrance::new(Rgb::ONE, ggx, Shadowing::SmithCorrelated, Fresnel::None)?;
//! let m = Material::with_diffuse(Rgb::ZERO, Glossy::CookTorrance(lobe))?;
//! let sampler = BatchSampler::new(&m, BsdfStrategy::Vndf).expect("GGX vndf is batched");
//! let (wx, wy, wz) = (vec![0.6f32; 100], vec![0.0; 100], vec![0.8; 100]);
//! let (u1, u2) = (vec![0.3f32; 100], vec![0.7; 100]);
//! let mut out = SampleBuffers::new(100);
//! sampler.sample(
//!     lobe::batch::SampleInput { wo: lobe::batch::Dirs { x: &wx, y: &wy, z: &wz }, u1: &u1, u2: &u2, uc: None },
//!     out.output(),
//! ).expect("all slices have 100 values");
//! assert!(out.valid.iter().all(|&v| v == 1) && out.pdf[0] > 0.0);
//! # Ok::<(), lobe::Error>(())
//! ```
//!
//! ## What is batched
//!
//! * **Cook-Torrance** with **GGX, Beckmann or the Blinn-Phong NDF**
//!   (isotropic or anisotropic alpha), **every shadowing term** (Smith
//!   height-correlated, separable, V-cavity), **every Fresnel term** (none,
//!   Schlick, dielectric, conductor), any `ks`, **every strategy the
//!   scalar path gives it**: `vndf` (GGX, Beckmann), `brdf`, `uniform`,
//!   `cosine`, and for GGX **`spherical-caps`** and **`bounded-vndf`**
//!   (`kernel::caps`; the Blinn-Phong NDF is `kernel::blinn_ndf`);
//! * **Phong** and **Blinn-Phong** (lecture and normalized forms, exponents
//!   0 to 10⁷; `kernel::phong`), strategies `brdf`, `uniform`, `cosine`;
//! * the **two-lobe mixture** `kd > 0`: `uc` chooses the lobe with the
//!   scalar path's probability (`Material::glossy_probability`), the pdf is
//!   the mixture, `f` the sum ([`BatchSampler::chooses_lobe`]; `uc = None`
//!   there is [`BatchError::MissingUc`]);
//! * the **Lambertian** material (`uniform`, `cosine`, `brdf`);
//! * **measured** materials (MERL and RGL tables: `uniform`, `cosine`,
//!   `brdf`, and `vndf` for RGL files), alone or with a diffuse term, lane
//!   by lane in f64 over the f32 tables (see `batch/measured.rs`: a table
//!   lookup, discontinuous for MERL's nearest entry, is not an f32
//!   computation): the scalar path's numbers at the f32 inputs, rounded
//!   once, the same at every level; with a diffuse term `uc` chooses the
//!   lobe as in the scalar mixture.
//!
//! Every model and strategy of the lecture, Cook-Torrance and the measured
//! tables is batched. The test `grid_every_supported_combination_builds`
//! walks every combination of those analytic models and checks that none
//! is refused. (A lecture-form `ks` whose `ks · K` is beyond f32's range is
//! refused with that reason.)
//!
//! Rough dielectrics (rough glass) with GGX or Beckmann, isotropic or
//! anisotropic, by every strategy the scalar path gives them (visible
//! normals, `D cos θm`, GGX's spherical caps, uniform and cosine over the
//! sphere): reflection and refraction through the generalized half vector,
//! seen from either side (`kernel::dielectric`; tested against the scalar
//! path over the whole sphere in `tests_dielectric.rs`). An index-matched
//! interface (a delta) takes the scalar path.
//!
//! **Rough plastic** (`roughplastic`, GGX or Beckmann, every strategy it
//! has) runs in the Cook-Torrance kernel: its coating is a Cook-Torrance
//! lobe (dielectric Fresnel, separable Smith), its base takes the place of
//! the Lambertian term (`scale T(μo) T(μi)`, `T` read from the material's
//! 64-cosine transmittance table, linear between nodes as the scalar path
//! reads it) and the coating's probability is the scalar path's
//! `(1 − T) w / ((1 − T) w + T (1 − w))`. **Turquin's energy compensation**
//! (`multiscatter = "turquin"`) of Cook-Torrance lobes and of rough
//! plastic's coating scales the lobe's `f` and weight by `1 + F0 (1 −
//! E)/E` (`1/E(μo, α, η)` for the coating), `E` read from the energy
//! table's 64 cosines at the lobe's `α`; the pdf is the single-scattering
//! lobe's. Both are tested against the scalar path like the rest (the
//! grid's `roughplastic` and `turquin` groups, chi-square included).
//!
//! The **smooth models** (`conductor`, `dielectric`, `thindielectric`,
//! `plastic`; `kernel::smooth`): a delta sample's `f` is its value times
//! the probability of the part drawn over `|cos θi|` and its pdf that
//! probability, as the scalar path's; glass and the thin sheet from either
//! side. **Two-sided** materials (`twosided` of any batched opaque model)
//! mirror a `wo` below the surface up and the sampled `wi` back
//! (`BatchSampler`, around the one-sided kernel). Both are tested against the scalar path over the
//! whole sphere (`tests_smooth.rs`).
//!
//! Refused with [`BatchError::Unsupported`], the scalar path serving them:
//! Kulla-Conty compensation (its added lobe and mixture sampling), rough
//! glass with Turquin's compensation, index-matched rough glass, a diffuse
//! term beside a smooth lobe, two-sided measured tables. `lobe bench
//! --all` lists them with the reason.
//!
//! Beckmann's visible slopes are drawn as the scalar path draws them (Heitz
//! and d'Eon 2014: the slope CDF inverted by Newton's method inside a
//! bisection bracket), in f32 lanes with the CDF written with `erfc` of
//! each tail, each lane frozen once converged (so that a lane's result does
//! not depend on its neighbours), started from a bilinear table of exact
//! slopes built once (65 × 129 values, by the scalar f64 inversion):
//! measured 1.5 Newton steps per sample, 2.5 per 16-lane vector, on the
//! tests' inputs.
//!
//! ## Outputs and conventions
//!
//! The same as the scalar path's ([`crate::BsdfSample`]), in f32:
//! * `wi`: the sampled unit direction, local frame, `z > 0`;
//! * `f`: `f_r(wo, wi)`, **without** the cosine;
//! * `pdf`: the density of `wi` in solid angle;
//! * `weight`: `f · cos θi / pdf`, the Monte Carlo weight (**cosine
//!   included**);
//! * `valid`: 1 for a sample, 0 for a failed one (the scalar path's `None`);
//!   every other output of a failed sample is 0.
//!
//! `f`, `pdf` and `weight` of a single lobe's sample use the microfacet
//! normal it drew as the half vector, as the scalar path does.
//! [`BatchSampler::eval`] and [`BatchSampler::pdf`] give the same bits as
//! the two halves of [`BatchSampler::eval_pdf`].
//!
//! ## Accuracy
//!
//! Measured against the scalar f64 path (the tests in `batch::tests` and
//! `batch::tests::grid`; `--nocapture` prints every figure): 10⁶ random
//! inputs per strategy for GGX with height-correlated Smith (grazing
//! `cos θ = 1e-7`, alpha 1e-4 to 1, anisotropy to 100) and ~9·10⁴ per
//! (distribution, strategy) pair over the whole grid (every shadowing ×
//! Fresnel, iso/aniso, kd = 0 and > 0, and Lambert):
//! * the same validity mask except within 1e-5 of the horizon;
//! * `wi` within 2.6e-6 absolute (under 2e-7 for uniform and cosine), except
//!   Beckmann vndf: within 4.3e-5 where the slope CDF is inverted within
//!   6e-8 of 1 at grazing views (about 1 sample in 10⁴), and within 1.2e-4
//!   where `u1 = 0` exactly (both paths clamp it to 1e-12, deep in the
//!   CDF's tail);
//! * `f`, `pdf`, `weight` within 1.4e-5 relative (GGX) and 2.2e-5
//!   (Beckmann, uniform, cosine, mixtures) wherever an f32 direction can
//!   carry them (where a 1e-7 change of direction moves them by less than
//!   1e-5). About one sample in 10⁴ (alpha ≈ 1e-4 at grazing views, where
//!   `D` changes by 1e-4 per 1e-8 of direction) differs by more, up to
//!   2e-2, all explained by the ~1e-6 difference of the two `wi`. Where `f`
//!   is evaluated at `h = wo + wi` (uniform, cosine, the diffuse lobe's
//!   samples) and `wi` mirrors a grazing `wo`, the f32 sum loses bits: at
//!   most one sample in 10⁴ exceeds 1e-4, by at most 2.2e-4 (measured);
//! * `eval_pdf`, `eval` and `pdf` within 2.1e-5 relative on the same f32
//!   inputs (zero where the f64 value is under f32's range, 1e-30);
//! * chi-square of the batch samples against the batch pdf: passes for
//!   every pair at two alphas and three views, the mixtures and Lambert;
//! * the same bits at every level, for any block size and thread split.
//!
//! `LOBE_TEST_SCALE=16` runs the grid comparisons on 16 times the inputs
//! (~1.4·10⁶ samples and ~1.6·10⁵ pairs per pair, at the scalar, AVX2 and
//! AVX-512 levels on a Zen 4; about 80 s). There, where an error passes
//! 1e-4 it is held to what the f32 inputs leave open instead: `f`, `pdf`,
//! `weight` to 1e-4 plus twice what moving `wi` by the two paths' `|Δwi|`
//! explains, or the change of the scalar value when `wo` and `wi` move in
//! length by `2⁻²³` (`wo·h` of a grazing view and a `wi` nearly `−wo`
//! mirrored is `(|wo|² + wo·wi)/|wo + wi|`, which a length change of 1e-8
//! moves by orders of magnitude); `wi` to 1e-5 plus twice the move of the
//! scalar `wi` when the uniforms move by `2⁻²³` and `wo` by `2⁻²³` in
//! length and direction (Beckmann vndf: 271 samples in 1.4·10⁶, `|Δwi|`
//! to 1.8e-4, where the slope CDF is inverted near 1 at grazing views).
//! One sample of the caps in 10⁶ (at the rim, `u2 → 1`, of a view at
//! `cos θ = 1e-7`, where `point + wh` cancels in f32) differs by 1.6e-5,
//! more than that explains, within the caps' 2e-5. The counts are printed.
//!
//! The models and strategies added after the first step, measured the same
//! way (`batch::tests::grid`, ~6·10⁴ samples and ~1.2·10⁴ pairs per pair):
//! * GGX `spherical-caps` and `bounded-vndf`: `wi` within 5.5e-6 (caps)
//!   and 1.4e-5 (bounded; where the cap's point is near `−wh` at grazing
//!   views, `point + wh` cancels in f32: 1 sample in 6·10⁴), `f`, `pdf`,
//!   `weight` within 1.4e-5 where conditioned; `eval_pdf` within 1.8e-6;
//! * the Blinn-Phong NDF (alpha 1e-4 to 1, exponents `2/α² − 2` up to
//!   2·10⁸): `wi` within 5e-7, samples within 5.6e-5 (uniform; 1.1e-5
//!   brdf), `eval_pdf` within 2.4e-5;
//! * Phong and Blinn-Phong (exponents 0 to 10⁷, kd = 0 and > 0): `wi`
//!   within 4e-7, `eval_pdf` within 1.8e-5 on the same f32 inputs (their
//!   `1 − cos` is computed with exact products and a compensated sum, and
//!   `cosⁿ` by `math::pow_cos`). A sample's `f` and `pdf` are `cosⁿ` of an
//!   angle that f32 directions fix only to ~1.2e-7 (their length is `1 ±
//!   1.2e-7`, which the scalar samplers take as 1), so at large `n` they
//!   are defined to `expm1(n · 2.4e-7)` (2.4e-4 at `n = 10³`, 2.4e-2 at
//!   10⁵). Against the f64 path given the view normalized in f64, brdf
//!   samples agree within 1.6e-5 at every exponent (`wi` within 4e-7);
//!   uniform and cosine samples, whose `f` is evaluated at the f32 `wi`,
//!   within 7.4e-5 except 12 values in 6·10⁴ (at `n ≥ 10⁵`) within that
//!   allowance;
//! * chi-square of the batch samples against the batch pdf passes for caps
//!   and bounded VNDF and the Blinn-Phong NDF's brdf (alpha 0.1 × 0.5),
//!   Phong `n = 20` alone and with a diffuse term, Blinn-Phong `n = 60`, at
//!   60° and 89° (also at 0° and alpha 0.3 in a longer run).
//!
//! ## Cost per sample
//!
//! Counted in the kernel source, for sample + eval + pdf as `lobe bench`
//! runs them. GGX vndf: `sample` about 95 flops (sincos 16, the disk warp
//! and basis 45, reflection and `f`/`pdf`/`weight` 34) with 10 square
//! roots and 10 divisions as written, three of them repeated
//! subexpressions (`‖stretched wo‖`, `√len2`, `√|m|² = √1`) that inlining
//! lets the compiler share; `eval_pdf` about 55 flops, 3 square roots, 4
//! divisions. GGX brdf: `sample` about 70 flops, 6 square roots, 7
//! divisions. Beckmann adds `exp` (20 flops) to `D`, `erfc` with `exp` (35
//! flops, 2 divisions) to each Smith `Λ`, and to vndf sampling two `erf⁻¹`
//! (about 40 flops each, one `log` and one square root) plus about 70
//! flops and 2 divisions per Newton step (2.5 steps per vector). Under
//! callgrind
//! (`LOBE_SIMD=avx2 lobe bench --strategy vndf --samples 262144 --reps
//! 1`): 480 instructions per vector of 8 GGX vndf samples, 70 per vector
//! of `eval_pdf`.
//!
//! Every model × strategy, measured in one run per level on one thread
//! (`LOBE_SIMD=avx512|avx2 lobe bench --material M --samples 4194304
//! --reps 3`, every strategy of `M`; AMD EPYC Zen 4, 2 cores shared with
//! other builds, so ±20%), in M samples/s of sample + eval_pdf, against
//! the arithmetic of the kernel (operations per sample counted in the
//! source, sample + eval_pdf, `+ − × ÷ √` and fused multiply-adds counted
//! once each, compares and selects not; the polynomials counted as `exp`
//! 20, `log` 17, `expm1` 28, `sincos` 16, `pow_cos` 80) and the rate that
//! makes (G operations/s at avx512); the scalar f64 path in the same run:
//!
//! | material | strategy | ops/sample | avx512 | avx2 | scalar f64 | Gop/s avx512 |
//! |---|---|---:|---:|---:|---:|---:|
//! | lambert | uniform | 36 | 327 | 235 | 24 | 12 |
//! | lambert | cosine | 43 | 310 | 195 | 21 | 13 |
//! | lambert | brdf | 43 | 247 | 192 | 18 | 11 |
//! | phong n=100 | uniform | 285 | 126 | 51 | 12 | 36 |
//! | phong n=100 | cosine | 290 | 91 | 49 | 11 | 26 |
//! | phong n=100 | brdf | 266 | 142 | 75 | 8 | 38 |
//! | blinn-phong n=100 | uniform | 230 | 126 | 54 | 10 | 29 |
//! | blinn-phong n=100 | cosine | 235 | 112 | 56 | 9 | 26 |
//! | blinn-phong n=100 | brdf | 230 | 135 | 66 | 5 | 31 |
//! | ggx α=0.2 | uniform | 135 | 187 | 134 | 10 | 25 |
//! | ggx α=0.2 | cosine | 140 | 175 | 123 | 10 | 25 |
//! | ggx α=0.2 | brdf | 125 | 180 | 119 | 8 | 22 |
//! | ggx α=0.2 | vndf | 150 | 110 | 89 | 5 | 17 |
//! | ggx α=0.2 | spherical-caps | 140 | 181 | 86 | 7 | 25 |
//! | ggx α=0.2 | bounded-vndf | 170 | 142 | 94 | 7 | 24 |
//! | ggx α=0.2, kd=0.3 | vndf | 220 | 120 | 76 | 5 | 26 |
//! | ggx α=0.2, kd=0.3 | spherical-caps | 210 | 140 | 83 | 5 | 29 |
//! | ggx α=0.2, kd=0.3 | bounded-vndf | 240 | 130 | 79 | 6 | 31 |
//! | beckmann α=0.2 | uniform | 310 | 83 | 28 | 4 | 26 |
//! | beckmann α=0.2 | brdf | 325 | 83 | 36 | 3 | 27 |
//! | beckmann α=0.2 | vndf | 585 | 35 | 20 | 1.5 | 21 |
//! | blinn-phong NDF α=0.2 | uniform | 465 | 67 | 34 | 3 | 31 |
//! | blinn-phong NDF α=0.2 | cosine | 470 | 62 | 33 | 3 | 29 |
//! | blinn-phong NDF α=0.2 | brdf | 530 | 57 | 28 | 3 | 30 |
//!
//! Every kernel runs at 20 to 40 G operations/s at avx512 (11 to 13 for
//! Lambert, whose few operations leave the time to the loads, stores and
//! the `eval_pdf` pass over memory), i.e. at about the same fraction of
//! the core's throughput: the cost of a model × strategy is its arithmetic.
//! The caps and Heitz's construction (vndf) draw the same visible normals
//! with about the same arithmetic; their figures here (181 and 110 M/s at
//! avx512, 86 and 89 at avx2) are not a ratio to quote from this shared
//! machine.
//! The heaviest are the Blinn-Phong NDF (its `cos^e` is a `pow_cos`, and
//! its Smith term is Beckmann's, `erfc` and `exp` twice) and Beckmann vndf
//! (the Newton inversion). `cargo bench -p lobe-bench --bench batch` times the
//! same work per material (blocks of 4096, criterion).
//!
//! The portable level uses `f32::mul_add` for bit-identical results: on an
//! x86-64 CPU without FMA that is a library call, and the portable level
//! runs about as fast as the scalar f64 path; it is the fallback, not a
//! fast path.
//!
//! ## Dispatch
//!
//! [`SimdLevel::best`] is AVX-512 (F, DQ, BW, VL) where the CPU has it,
//! else AVX2 + FMA, else the portable f32 loop; the environment variable
//! `LOBE_SIMD=scalar|avx2|avx512` forces one ([`SimdLevel::from_env`]; an
//! unknown or unavailable level is an error). One binary serves every CPU:
//! the kernels are written once over a small lane trait and compiled per
//! level inside `#[target_feature]` functions, entered only after
//! `is_x86_feature_detected!`. Every operation is exactly rounded (fused
//! multiply-add at every level), so the three levels give the same bits.

mod block;
mod buffers;
mod dispatch;
mod kernel;
mod lanes;
mod math;
mod measured;
#[cfg(test)]
mod tests;

pub use buffers::{DirPairs, EvalPdfBuffers, SampleBuffers, SampleInputs};

use crate::energy::Multiscatter;
use crate::models::{CookTorrance, Glossy};
use crate::{BsdfStrategy, Fresnel, Material, Ndf, Rgb, Shadowing};
use dispatch::{Backend, Kernel};
use kernel::{CtParams, FresnelP, Shadow};

/// A dispatch level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SimdLevel {
    /// Portable Rust, one f32 lane.
    Scalar,
    /// AVX2 + FMA, 8 lanes.
    Avx2,
    /// AVX-512 F/DQ/BW/VL, 16 lanes.
    Avx512,
}

/// A step over arrays (plain loops that the compiler can vectorize), run by
/// [`SimdLevel::run`]: `run` is inlined into a `#[target_feature]` function
/// of the level and compiled for it. (A closure would be compiled on its
/// own, for the portable target.) Mark `run` `#[inline(always)]`.
pub trait Step {
    fn run(self);
}

impl SimdLevel {
    pub const ALL: [SimdLevel; 3] = [SimdLevel::Scalar, SimdLevel::Avx2, SimdLevel::Avx512];

    /// The name `LOBE_SIMD` takes.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            SimdLevel::Scalar => "scalar",
            SimdLevel::Avx2 => "avx2",
            SimdLevel::Avx512 => "avx512",
        }
    }

    /// f32 lanes per vector.
    #[must_use]
    pub fn lanes(self) -> usize {
        match self {
            SimdLevel::Scalar => 1,
            SimdLevel::Avx2 => 8,
            SimdLevel::Avx512 => 16,
        }
    }

    /// Runs `step` compiled for this level where the CPU has it, else
    /// compiled for the portable target. Plain IEEE arithmetic gives the
    /// same bits at every level (Rust does not fuse multiply-adds).
    #[inline(always)]
    pub fn run(self, step: impl Step) {
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            fn avx2(step: impl Step) {
                step.run();
            }
            #[target_feature(enable = "avx512f,avx512dq,avx512bw,avx512vl,avx2,fma")]
            fn avx512(step: impl Step) {
                step.run();
            }
            match self {
                // SAFETY: the level is available, so the CPU has its features.
                SimdLevel::Avx512 if self.is_available() => return unsafe { avx512(step) },
                SimdLevel::Avx2 if self.is_available() => return unsafe { avx2(step) },
                _ => {}
            }
        }
        step.run();
    }

    /// Whether this CPU runs the level.
    #[must_use]
    pub fn is_available(self) -> bool {
        Backend::new(self).is_some()
    }

    /// The widest level this CPU runs.
    #[must_use]
    pub fn best() -> SimdLevel {
        SimdLevel::ALL
            .into_iter()
            .rev()
            .find(|l| l.is_available())
            .unwrap_or(SimdLevel::Scalar)
    }

    /// The level forced by `LOBE_SIMD`, else [`SimdLevel::best`]. An unknown
    /// name, or a level this CPU lacks, is an error.
    pub fn from_env() -> Result<SimdLevel, BatchError> {
        match std::env::var("LOBE_SIMD") {
            Err(_) => Ok(SimdLevel::best()),
            Ok(s) if s.is_empty() => Ok(SimdLevel::best()),
            Ok(s) => {
                let level: SimdLevel = s.parse()?;
                level.check()?;
                Ok(level)
            }
        }
    }

    /// `Ok` when this CPU runs the level.
    pub fn check(self) -> Result<(), BatchError> {
        if self.is_available() {
            Ok(())
        } else {
            Err(BatchError::Level {
                level: self.name().into(),
                reason: format!(
                    "this CPU lacks it (available: {})",
                    SimdLevel::ALL
                        .into_iter()
                        .filter(|l| l.is_available())
                        .map(SimdLevel::name)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            })
        }
    }
}

impl std::fmt::Display for SimdLevel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for SimdLevel {
    type Err = BatchError;
    fn from_str(s: &str) -> Result<Self, BatchError> {
        SimdLevel::ALL
            .into_iter()
            .find(|l| l.name() == s)
            .ok_or_else(|| BatchError::Level {
                level: s.into(),
                reason: "unknown level, expected one of: scalar, avx2, avx512".into(),
            })
    }
}

/// What the batch API refuses.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BatchError {
    /// A slice whose length is not the block's (the length of `wo.x`).
    Length {
        slice: &'static str,
        expected: usize,
        found: usize,
    },
    /// A material or strategy the batch path does not have (yet); the
    /// scalar path serves it.
    Unsupported { reason: String },
    /// A strategy the material does not have at all (the scalar path
    /// refuses it too: `Material::check`).
    Inapplicable { reason: String },
    /// A `LOBE_SIMD` level that is unknown or that this CPU lacks.
    Level { level: String, reason: String },
    /// `uc` is `None` where the material has two lobes for `uc` to choose
    /// between.
    MissingUc,
}

impl std::fmt::Display for BatchError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BatchError::Length {
                slice,
                expected,
                found,
            } => write!(
                f,
                "slice `{slice}` has {found} values, expected {expected} (the length of `wo.x`)"
            ),
            BatchError::Unsupported { reason } => {
                write!(
                    f,
                    "not in the batch path: {reason} (the scalar path has it)"
                )
            }
            BatchError::Inapplicable { reason } => f.write_str(reason),
            BatchError::Level { level, reason } => write!(f, "SIMD level `{level}`: {reason}"),
            BatchError::MissingUc => write!(
                f,
                "slice `uc` is missing: it chooses between the material's glossy and diffuse lobes"
            ),
        }
    }
}

impl std::error::Error for BatchError {}

/// Three f32 slices: the x, y, z components of a block of directions.
#[derive(Debug, Clone, Copy)]
pub struct Dirs<'a> {
    pub x: &'a [f32],
    pub y: &'a [f32],
    pub z: &'a [f32],
}

/// Three mutable f32 slices for a block of directions.
#[derive(Debug)]
pub struct DirsMut<'a> {
    pub x: &'a mut [f32],
    pub y: &'a mut [f32],
    pub z: &'a mut [f32],
}

/// Three mutable f32 slices for a block of RGB values.
#[derive(Debug)]
pub struct RgbMut<'a> {
    pub r: &'a mut [f32],
    pub g: &'a mut [f32],
    pub b: &'a mut [f32],
}

/// The inputs of [`BatchSampler::sample`]: `wo` (unit, local frame) and the
/// uniforms in `[0, 1)`. `uc` chooses the lobe where the material has two
/// ([`BatchSampler::chooses_lobe`]; `None` there is
/// [`BatchError::MissingUc`]); single-lobe materials do not read it (its
/// length is still checked).
#[derive(Debug, Clone, Copy)]
pub struct SampleInput<'a> {
    pub wo: Dirs<'a>,
    pub u1: &'a [f32],
    pub u2: &'a [f32],
    pub uc: Option<&'a [f32]>,
}

/// The outputs of [`BatchSampler::sample`] (see the module doc: `f` without
/// the cosine, `weight = f · cos θi / pdf`, `valid` 1 or 0, zeros for a
/// failed sample).
#[derive(Debug)]
pub struct SampleOutput<'a> {
    pub wi: DirsMut<'a>,
    pub f: RgbMut<'a>,
    pub pdf: &'a mut [f32],
    pub weight: RgbMut<'a>,
    pub valid: &'a mut [u8],
}

/// The outputs of [`BatchSampler::eval_pdf`]: `f` without the cosine, the
/// pdf in solid angle; zero below the horizon.
#[derive(Debug)]
pub struct EvalPdfOutput<'a> {
    pub f: RgbMut<'a>,
    pub pdf: &'a mut [f32],
}

/// How a batch kernel writes an output: through the caches (the default),
/// or with streaming (non-temporal) stores, which send each line to memory
/// without reading it first and without evicting anything from the caches:
/// for outputs far larger than the caches that are not read again soon
/// (about a third less memory traffic; `lobe-py` writes its NumPy results
/// so). The same values either way. A block streams an output only where
/// its slice starts aligned to the level's vector (32 bytes at `avx2`, 64
/// at `avx512`); otherwise, and at the portable level, and for measured
/// materials, the store is plain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Store {
    #[default]
    Cached,
    Streamed,
}

/// A material and strategy prepared for the batch kernels at one level.
/// Cloning it is cheap (a measured table is shared, not copied).
#[derive(Debug, Clone)]
pub struct BatchSampler {
    kernel: Kernel,
    strategy: BsdfStrategy,
    backend: Backend,
    /// A two-sided material: `wo` below the surface is mirrored up (`z`
    /// by its absolute value, as `Material` does) for the one-sided kernel
    /// and the sampled `wi` mirrored back, chunk by chunk around the
    /// kernel calls (the kernels themselves carry no two-sided code: in
    /// them it cost GGX brdf 25% at AVX-512 even where it was off).
    two_sided: bool,
}

/// Values per chunk of a two-sided material's mirrored inputs (a stack
/// array).
const TWO_SIDED_CHUNK: usize = 1024;

/// Each output's values in `r` (an empty output, one not written, stays
/// empty).
fn chunk_of<'a, const N: usize>(
    o: &'a mut [&mut [f32]; N],
    r: std::ops::Range<usize>,
) -> [&'a mut [f32]; N] {
    o.each_mut().map(|s| {
        if s.is_empty() {
            &mut s[..]
        } else {
            &mut s[r.clone()]
        }
    })
}

impl BatchSampler {
    /// For `material` and `strategy` at [`SimdLevel::from_env`] (the best
    /// level unless `LOBE_SIMD` says otherwise). Errors: what the batch path
    /// does not cover ([`BatchError::Unsupported`], see the module doc), a
    /// bad `LOBE_SIMD`.
    pub fn new(material: &Material, strategy: BsdfStrategy) -> Result<Self, BatchError> {
        Self::with_level(material, strategy, SimdLevel::from_env()?)
    }

    /// At a given level (an error if this CPU lacks it).
    pub fn with_level(
        material: &Material,
        strategy: BsdfStrategy,
        level: SimdLevel,
    ) -> Result<Self, BatchError> {
        let kernel = kernel_for(material, strategy)?;
        level.check()?;
        let backend = Backend::new(level).expect("checked");
        Ok(BatchSampler {
            kernel,
            strategy,
            backend,
            two_sided: material.two_sided,
        })
    }

    /// Whether `sample` reads `uc` (the material has a glossy and a diffuse
    /// lobe and the strategy samples them: `Material::chooses_lobe`).
    #[must_use]
    pub fn chooses_lobe(&self) -> bool {
        match &self.kernel {
            Kernel::CookTorrance { p, .. } => p.two_lobes,
            Kernel::Measured(k) => k.chooses_lobe(),
            Kernel::Lecture { p, .. } => p.two_lobes,
            Kernel::Dielectric { strat, .. } => {
                *strat != kernel::UNIFORM && *strat != kernel::COSINE
            }
            Kernel::Smooth { model, .. } => *model != kernel::smooth::CONDUCTOR,
        }
    }

    /// The level the kernels run at.
    #[must_use]
    pub fn level(&self) -> SimdLevel {
        self.backend.level()
    }

    #[must_use]
    pub fn strategy(&self) -> BsdfStrategy {
        self.strategy
    }

    /// Sample a block: for each `i`, `wi`, `f` (no cosine), `pdf` (solid
    /// angle), `weight = f·cos θi/pdf` and `valid` for `(wo[i], u1[i],
    /// u2[i])`. Every slice must have the length of `input.wo.x` (`f`'s
    /// three may instead all be empty: not wanted); otherwise a
    /// [`BatchError::Length`] names the first that does not, and nothing is
    /// written.
    pub fn sample(&self, input: SampleInput<'_>, out: SampleOutput<'_>) -> Result<(), BatchError> {
        self.sample_with(input, out, Store::Cached)
    }

    /// [`BatchSampler::sample`] with the outputs stored as `store` says
    /// (the same values; `valid`, one byte a sample, always through the
    /// caches), and `f` optional: three empty slices there mean it is not
    /// wanted (`weight` and `pdf` hold what most callers need of it), and
    /// nothing is written for it.
    pub fn sample_with(
        &self,
        input: SampleInput<'_>,
        out: SampleOutput<'_>,
        store: Store,
    ) -> Result<(), BatchError> {
        let n = input.wo.x.len();
        let check = |slice: &'static str, found: usize| {
            if found == n {
                Ok(())
            } else {
                Err(BatchError::Length {
                    slice,
                    expected: n,
                    found,
                })
            }
        };
        check("wo.y", input.wo.y.len())?;
        check("wo.z", input.wo.z.len())?;
        check("u1", input.u1.len())?;
        check("u2", input.u2.len())?;
        if let Some(uc) = input.uc {
            check("uc", uc.len())?;
        }
        check("wi.x", out.wi.x.len())?;
        check("wi.y", out.wi.y.len())?;
        check("wi.z", out.wi.z.len())?;
        let want_f = !(out.f.r.is_empty() && out.f.g.is_empty() && out.f.b.is_empty());
        if want_f || n == 0 {
            check("f.r", out.f.r.len())?;
            check("f.g", out.f.g.len())?;
            check("f.b", out.f.b.len())?;
        }
        check("pdf", out.pdf.len())?;
        check("weight.r", out.weight.r.len())?;
        check("weight.g", out.weight.g.len())?;
        check("weight.b", out.weight.b.len())?;
        check("valid", out.valid.len())?;
        let uc = match input.uc {
            Some(uc) => uc,
            None if self.chooses_lobe() => {
                return Err(BatchError::MissingUc);
            }
            // Not read: a single lobe.
            None => input.u1,
        };
        let inp = [input.wo.x, input.wo.y, input.wo.z, input.u1, input.u2, uc];
        let mut o = [
            out.wi.x,
            out.wi.y,
            out.wi.z,
            out.f.r,
            out.f.g,
            out.f.b,
            out.pdf,
            out.weight.r,
            out.weight.g,
            out.weight.b,
        ];
        let w = dispatch::SampleWrites {
            f: want_f,
            stream: store == Store::Streamed && !self.two_sided,
        };
        if !self.two_sided {
            dispatch::sample(self.backend, &self.kernel, inp, (&mut o, out.valid), w);
            return Ok(());
        }
        // Two-sided: chunks with |wo.z|, then wi.z mirrored back where wo
        // was below.
        let mut z = [0.0f32; TWO_SIDED_CHUNK];
        let mut start = 0;
        while start < n {
            let r = start..(start + TWO_SIDED_CHUNK).min(n);
            let len = r.len();
            for (d, s) in z.iter_mut().zip(&inp[2][r.clone()]) {
                *d = s.abs();
            }
            let part = [
                &inp[0][r.clone()],
                &inp[1][r.clone()],
                &z[..len],
                &inp[3][r.clone()],
                &inp[4][r.clone()],
                &inp[5][r.clone()],
            ];
            let mut o_part = chunk_of(&mut o, r.clone());
            let valid = &mut out.valid[r.clone()];
            dispatch::sample(self.backend, &self.kernel, part, (&mut o_part, valid), w);
            for (wz, oz) in o_part[2].iter_mut().zip(&inp[2][r.clone()]) {
                if *oz < 0.0 {
                    *wz = -*wz;
                }
            }
            start = r.end;
        }
        Ok(())
    }

    /// `f` (no cosine) and the pdf (solid angle, of this sampler's
    /// strategy) for each `(wo[i], wi[i])`, zero below the horizon. Every
    /// slice must have the length of `wo.x` ([`BatchError::Length`]
    /// otherwise, nothing written).
    pub fn eval_pdf(
        &self,
        wo: Dirs<'_>,
        wi: Dirs<'_>,
        out: EvalPdfOutput<'_>,
    ) -> Result<(), BatchError> {
        self.eval_pdf_with(wo, wi, out, Store::Cached)
    }

    /// [`BatchSampler::eval_pdf`] with both outputs stored as `store` says
    /// (the same values).
    pub fn eval_pdf_with(
        &self,
        wo: Dirs<'_>,
        wi: Dirs<'_>,
        out: EvalPdfOutput<'_>,
        store: Store,
    ) -> Result<(), BatchError> {
        let o = [out.f.r, out.f.g, out.f.b, out.pdf];
        self.run_eval_pdf(wo, wi, block::BOTH, o, store)
    }

    /// `eval_pdf` writing what `mode` names into `o` (`f.rgb`, `pdf`; the
    /// ones not written empty), after checking the lengths.
    fn run_eval_pdf(
        &self,
        wo: Dirs<'_>,
        wi: Dirs<'_>,
        mode: u8,
        mut o: [&mut [f32]; 4],
        store: Store,
    ) -> Result<(), BatchError> {
        let lens = [
            ("f.r", o[0].len()),
            ("f.g", o[1].len()),
            ("f.b", o[2].len()),
            ("pdf", o[3].len()),
        ];
        let written = match mode {
            block::F_ONLY => &lens[..3],
            block::PDF_ONLY => &lens[3..],
            _ => &lens[..],
        };
        check_pairs(wo, wi, written)?;
        if !self.two_sided {
            dispatch::eval_pdf(
                self.backend,
                &self.kernel,
                mode,
                [wo.x, wo.y, wo.z, wi.x, wi.y, wi.z],
                &mut o,
                store == Store::Streamed,
            );
            return Ok(());
        }
        // Two-sided: both directions mirrored where wo is below.
        let n = wo.x.len();
        let (mut zo, mut zi) = ([0.0f32; TWO_SIDED_CHUNK], [0.0f32; TWO_SIDED_CHUNK]);
        let mut start = 0;
        while start < n {
            let r = start..(start + TWO_SIDED_CHUNK).min(n);
            let len = r.len();
            for ((a, b), (&oz, &iz)) in zo
                .iter_mut()
                .zip(zi.iter_mut())
                .zip(wo.z[r.clone()].iter().zip(&wi.z[r.clone()]))
            {
                *a = oz.abs();
                *b = if oz < 0.0 { -iz } else { iz };
            }
            let mut o_part = chunk_of(&mut o, r.clone());
            dispatch::eval_pdf(
                self.backend,
                &self.kernel,
                mode,
                [
                    &wo.x[r.clone()],
                    &wo.y[r.clone()],
                    &zo[..len],
                    &wi.x[r.clone()],
                    &wi.y[r.clone()],
                    &zi[..len],
                ],
                &mut o_part,
                false,
            );
            start = r.end;
        }
        Ok(())
    }

    /// `f(wo[i], wi[i])` without the cosine, zero below the horizon: the
    /// `f` of [`BatchSampler::eval_pdf`] (the same bits) without its pdf.
    pub fn eval(&self, wo: Dirs<'_>, wi: Dirs<'_>, f: RgbMut<'_>) -> Result<(), BatchError> {
        self.eval_with(wo, wi, f, Store::Cached)
    }

    /// [`BatchSampler::eval`] with `f` stored as `store` says (the same
    /// values).
    pub fn eval_with(
        &self,
        wo: Dirs<'_>,
        wi: Dirs<'_>,
        f: RgbMut<'_>,
        store: Store,
    ) -> Result<(), BatchError> {
        self.run_eval_pdf(wo, wi, block::F_ONLY, [f.r, f.g, f.b, &mut []], store)
    }

    /// The pdf (solid angle) of this sampler's strategy at `(wo[i], wi[i])`,
    /// zero below the horizon: the pdf of [`BatchSampler::eval_pdf`] (the
    /// same bits) without `f`.
    pub fn pdf(&self, wo: Dirs<'_>, wi: Dirs<'_>, pdf: &mut [f32]) -> Result<(), BatchError> {
        self.pdf_with(wo, wi, pdf, Store::Cached)
    }

    /// [`BatchSampler::pdf`] with the pdf stored as `store` says (the same
    /// values).
    pub fn pdf_with(
        &self,
        wo: Dirs<'_>,
        wi: Dirs<'_>,
        pdf: &mut [f32],
        store: Store,
    ) -> Result<(), BatchError> {
        self.run_eval_pdf(
            wo,
            wi,
            block::PDF_ONLY,
            [&mut [], &mut [], &mut [], pdf],
            store,
        )
    }
}

/// Every input slice and each of `outputs` has the length of `wo.x`.
fn check_pairs(
    wo: Dirs<'_>,
    wi: Dirs<'_>,
    outputs: &[(&'static str, usize)],
) -> Result<(), BatchError> {
    let n = wo.x.len();
    for &(slice, found) in [
        ("wo.y", wo.y.len()),
        ("wo.z", wo.z.len()),
        ("wi.x", wi.x.len()),
        ("wi.y", wi.y.len()),
        ("wi.z", wi.z.len()),
    ]
    .iter()
    .chain(outputs)
    {
        if found != n {
            return Err(BatchError::Length {
                slice,
                expected: n,
                found,
            });
        }
    }
    Ok(())
}

/// The kernel and its f32 parameters for a material and strategy, or why
/// the batch path does not have them. A two-sided material gets its
/// one-sided kernel: [`BatchSampler`] mirrors a `wo` below the surface up
/// around it (`BatchSampler::two_sided`).
fn kernel_for(m: &Material, strategy: BsdfStrategy) -> Result<Kernel, BatchError> {
    let unsupported = |reason: String| Err(BatchError::Unsupported { reason });
    if let Err(e) = m.check(strategy) {
        return Err(BatchError::Inapplicable {
            reason: e.to_string(),
        });
    }
    let c3 = |c: Rgb| [c.x as f32, c.y as f32, c.z as f32];
    let kd = m.diffuse.albedo;
    let kd_pi = c3(kd * crate::math::INV_PI);
    let kd_lum = crate::math::luminance(kd) as f32;
    let lobe = match &m.glossy {
        Glossy::CookTorrance(lobe) => lobe,
        Glossy::None => {
            // A Lambertian material: cosine-weighted (uniform for uniform).
            let strat = if strategy == BsdfStrategy::Uniform {
                kernel::UNIFORM
            } else {
                kernel::COSINE
            };
            return Ok(Kernel::CookTorrance {
                ndf: kernel::GGX,
                strat,
                p: CtParams {
                    inv_pi_axay: 0.0,
                    shadow: Shadow::Correlated,
                    has_glossy: false,
                    kd_pi,
                    kd_lum,
                    ..microfacets_only(1.0, 1.0)
                },
            });
        }
        Glossy::Measured(_) if m.two_sided => {
            return unsupported("not yet batched: two-sided measured tables".into());
        }
        Glossy::Measured(lobe) => {
            return match measured::MeasuredKernel::new(m, lobe, strategy) {
                Some(k) => Ok(Kernel::Measured(Box::new(k))),
                None => unsupported(format!("strategy `{strategy}` of a measured table")),
            };
        }
        Glossy::Phong(lobe) => {
            return lecture_kernel(m, strategy, kernel::phong::PHONG, lobe.ks, lobe.exponent, {
                if lobe.normalized {
                    (lobe.exponent + 2.0) * crate::math::INV_TWO_PI
                } else {
                    1.0
                }
            });
        }
        Glossy::BlinnPhong(lobe) => {
            return lecture_kernel(m, strategy, kernel::phong::BLINN, lobe.ks, lobe.exponent, {
                if lobe.normalized {
                    crate::models::blinn_phong::normalization(lobe.exponent)
                } else {
                    1.0
                }
            });
        }
        Glossy::RoughDielectric(rd)
            if rd.multiscatter != crate::energy::DielectricMultiscatter::None =>
        {
            return unsupported(format!(
                "not yet batched: energy compensation (multiscatter {})",
                rd.multiscatter.kind()
            ));
        }
        Glossy::RoughDielectric(rd) => return dielectric_kernel(rd, strategy),
        Glossy::RoughPlastic(rp) => return rough_plastic_kernel(m, rp, strategy),
        Glossy::Conductor(_)
        | Glossy::Dielectric(_)
        | Glossy::ThinDielectric(_)
        | Glossy::Plastic(_) => return smooth_kernel(m),
    };
    let turquin = match &lobe.multiscatter {
        Multiscatter::None => None,
        Multiscatter::Turquin(t) => {
            let row = t.row();
            if row.table().n_mu != kernel::TABLE_NODES {
                return unsupported(format!(
                    "energy table of {} cosines (the kernels read {})",
                    row.table().n_mu,
                    kernel::TABLE_NODES
                ));
            }
            Some(kernel::TurquinP {
                f0: c3(t.f0()),
                e: table_nodes(|x| row.e(x * x)),
                e_min: 1e-3,
            })
        }
        Multiscatter::KullaConty(_) => {
            return unsupported(
                "not yet batched: Kulla-Conty energy compensation (its added lobe and the \
                 mixture sampling it)"
                    .into(),
            );
        }
    };
    let p = CtParams {
        kd_pi,
        kd_lum,
        two_lobes: m.chooses_lobe(strategy),
        turquin,
        ..cook_torrance_params(lobe, strategy)
    };
    Ok(Kernel::CookTorrance {
        ndf: ndf_code(lobe.microfacet.ndf()),
        strat: strat_code(strategy),
        p,
    })
}

/// `f(x)` at [`kernel::TABLE_NODES`] evenly spaced `x ∈ [0, 1]`, in f32.
fn table_nodes(f: impl Fn(f64) -> f64) -> [f32; kernel::TABLE_NODES] {
    let top = (kernel::TABLE_NODES - 1) as f64;
    std::array::from_fn(|j| f(j as f64 / top) as f32)
}

fn ndf_code(ndf: Ndf) -> u8 {
    match ndf {
        Ndf::Ggx => kernel::GGX,
        Ndf::Beckmann => kernel::BECKMANN,
        Ndf::BlinnPhong => kernel::BLINN_PHONG,
    }
}

fn strat_code(strategy: BsdfStrategy) -> u8 {
    match strategy {
        BsdfStrategy::Vndf => kernel::VNDF,
        BsdfStrategy::Brdf => kernel::BRDF,
        BsdfStrategy::Uniform => kernel::UNIFORM,
        BsdfStrategy::Cosine => kernel::COSINE,
        BsdfStrategy::SphericalCaps => kernel::CAPS,
        BsdfStrategy::BoundedVndf => kernel::BOUNDED,
    }
}

/// A single-scattering Cook-Torrance lobe's kernel parameters: no diffuse
/// term, no lobe choice, no compensation (callers set what differs).
fn cook_torrance_params(lobe: &CookTorrance, strategy: BsdfStrategy) -> CtParams {
    let CookTorrance {
        ks,
        microfacet,
        shadowing,
        fresnel,
        multiscatter: _,
    } = *lobe;
    let (ax, ay) = microfacet.alpha();
    let fresnel = fresnel_params(ks, fresnel);
    let shadow = match shadowing {
        Shadowing::SmithCorrelated => Shadow::Correlated,
        Shadowing::SmithSeparable => Shadow::Separable,
        Shadowing::VCavity => Shadow::VCavity,
    };
    CtParams {
        fresnel,
        shadow,
        guess: if microfacet.ndf() == Ndf::Beckmann && strategy == BsdfStrategy::Vndf {
            kernel::beckmann_guess_table()
        } else {
            &[]
        },
        ..microfacets_only(ax, ay)
    }
}

/// The smooth models (`kernel::smooth`): strategy brdf, their only one
/// (`m.check` accepted it); a diffuse term beside a delta lobe is refused.
fn smooth_kernel(m: &Material) -> Result<Kernel, BatchError> {
    use kernel::smooth;
    if m.diffuse.albedo != Rgb::ZERO {
        return Err(BatchError::Unsupported {
            reason: "not yet batched: a diffuse term beside a smooth (delta) lobe".into(),
        });
    }
    let c3 = |c: Rgb| [c.x as f32, c.y as f32, c.z as f32];
    let mut p = smooth::SmoothParams {
        fresnel: FresnelP::Schlick {
            ks_f0: [0.0; 3],
            ks_1mf0: [0.0; 3],
        },
        eta: 1.0,
        inv_eta: 1.0,
        kr: [0.0; 3],
        kt: [0.0; 3],
        radiance: false,
        scale: [0.0; 3],
        w: 0.0,
    };
    let with_eta = |p: &mut smooth::SmoothParams, eta: f64| {
        p.eta = eta as f32;
        p.inv_eta = (1.0 / eta) as f32;
    };
    let model = match &m.glossy {
        Glossy::Conductor(c) => {
            p.fresnel = fresnel_params(c.specular_reflectance, c.fresnel);
            smooth::CONDUCTOR
        }
        Glossy::Dielectric(d) => {
            if d.eta == 1.0 {
                return Err(BatchError::Unsupported {
                    reason: "smooth dielectric: index-matched (η = 1), it passes light straight on"
                        .into(),
                });
            }
            with_eta(&mut p, d.eta);
            p.kr = c3(d.specular_reflectance);
            p.kt = c3(d.specular_transmittance);
            p.radiance = d.mode == crate::TransportMode::Radiance;
            smooth::DIELECTRIC
        }
        Glossy::ThinDielectric(d) => {
            with_eta(&mut p, d.eta);
            p.kr = c3(d.specular_reflectance);
            p.kt = c3(d.specular_transmittance);
            smooth::THIN
        }
        Glossy::Plastic(pl) => {
            with_eta(&mut p, pl.eta);
            p.kr = c3(pl.specular_reflectance);
            let base = pl.base();
            p.scale = c3(base.scale);
            p.w = base.specular_weight as f32;
            smooth::PLASTIC
        }
        _ => unreachable!("called for the smooth models only"),
    };
    Ok(Kernel::Smooth { model, p })
}

/// `ks` times the Fresnel term, as the kernels read it.
fn fresnel_params(ks: Rgb, fresnel: Fresnel) -> FresnelP {
    let c3 = |c: Rgb| [c.x as f32, c.y as f32, c.z as f32];
    match fresnel {
        Fresnel::None => FresnelP::Schlick {
            ks_f0: c3(ks),
            ks_1mf0: [0.0; 3],
        },
        Fresnel::Schlick { f0 } => FresnelP::Schlick {
            ks_f0: c3(ks * f0),
            ks_1mf0: c3(ks * (Rgb::ONE - f0)),
        },
        Fresnel::Dielectric { eta } => FresnelP::Dielectric {
            ks: c3(ks),
            eta: c3(eta),
        },
        Fresnel::Conductor { eta, k } => FresnelP::Conductor {
            ks: c3(ks),
            eta: c3(eta),
            k: c3(k),
        },
    }
}

/// Rough plastic (`models::roughplastic`): its coating as a Cook-Torrance
/// lobe (dielectric Fresnel, separable Smith) with the base in place of
/// the Lambertian term; Turquin's compensated coating scales the coating
/// by `1/E(μo, α, η)` (its transmittance table already compensated).
fn rough_plastic_kernel(
    m: &Material,
    rp: &crate::models::RoughPlastic,
    strategy: BsdfStrategy,
) -> Result<Kernel, BatchError> {
    use crate::energy::DielectricMultiscatter;
    let unsupported = |reason: String| Err(BatchError::Unsupported { reason });
    let turquin = match &rp.multiscatter {
        DielectricMultiscatter::None => None,
        DielectricMultiscatter::Turquin(t) => {
            if t.mu_nodes() != kernel::TABLE_NODES {
                return unsupported(format!(
                    "energy table of {} cosines (the kernels read {})",
                    t.mu_nodes(),
                    kernel::TABLE_NODES
                ));
            }
            Some(kernel::TurquinP {
                f0: [1.0; 3],
                e: table_nodes(|x| t.albedo(x * x, rp.eta)),
                e_min: crate::energy::compensation::MIN_DIELECTRIC_E as f32,
            })
        }
        DielectricMultiscatter::KullaConty(_) => {
            return unsupported(
                "not yet batched: Kulla-Conty energy compensation (its added lobe and the \
                 mixture sampling it)"
                    .into(),
            );
        }
    };
    let c3 = |c: Rgb| [c.x as f32, c.y as f32, c.z as f32];
    let base = rp.base();
    let p = CtParams {
        two_lobes: m.chooses_lobe(strategy),
        base: Some(kernel::PlasticBaseP {
            scale: c3(base.scale),
            w: base.specular_weight as f32,
            t: table_nodes(|x| rp.transmittance(x)),
        }),
        turquin,
        ..cook_torrance_params(&rp.coating, strategy)
    };
    Ok(Kernel::CookTorrance {
        ndf: ndf_code(rp.coating.microfacet.ndf()),
        strat: strat_code(strategy),
        p,
    })
}

/// The microfacets of `(ax, ay)` alone, as [`CtParams`]: a glossy lobe
/// with no Fresnel term (Schlick with `F0 = 0`), separable shadowing, no
/// diffuse term and no lobe choice; callers set what differs.
fn microfacets_only(ax: f64, ay: f64) -> CtParams {
    CtParams {
        ax: ax as f32,
        ay: ay as f32,
        inv_ax: (1.0 / ax) as f32,
        inv_ay: (1.0 / ay) as f32,
        inv_pi_axay: (crate::math::INV_PI / (ax * ay)) as f32,
        fresnel: FresnelP::Schlick {
            ks_f0: [0.0; 3],
            ks_1mf0: [0.0; 3],
        },
        shadow: Shadow::Separable,
        guess: &[],
        has_glossy: true,
        kd_pi: [0.0; 3],
        kd_lum: 0.0,
        two_lobes: false,
        base: None,
        turquin: None,
    }
}

/// The rough dielectric's kernel (`kernel::dielectric`): GGX or Beckmann,
/// every strategy the scalar path gives it (`m.check` accepted it:
/// visible normals, `D cos θm`, GGX's spherical caps, uniform and cosine
/// over the sphere); the index-matched interface (a delta) is scalar only.
fn dielectric_kernel(
    rd: &crate::models::RoughDielectric,
    strategy: BsdfStrategy,
) -> Result<Kernel, BatchError> {
    if rd.eta == 1.0 {
        return Err(BatchError::Unsupported {
            reason: "rough dielectric: index-matched (η = 1), it is a delta".into(),
        });
    }
    let ndf = rd.microfacet.ndf();
    if ndf == Ndf::BlinnPhong {
        return Err(BatchError::Unsupported {
            reason: "rough dielectric: GGX or Beckmann (not the Blinn-Phong NDF)".into(),
        });
    }
    let (ax, ay) = rd.microfacet.alpha();
    let c3 = |c: Rgb| [c.x as f32, c.y as f32, c.z as f32];
    let ct = CtParams {
        guess: if ndf == Ndf::Beckmann && strategy == BsdfStrategy::Vndf {
            kernel::beckmann_guess_table()
        } else {
            &[]
        },
        ..microfacets_only(ax, ay)
    };
    Ok(Kernel::Dielectric {
        ndf: ndf_code(ndf),
        strat: strat_code(strategy),
        p: kernel::dielectric::DielectricParams {
            ct,
            eta: rd.eta as f32,
            inv_eta: (1.0 / rd.eta) as f32,
            kr: c3(rd.specular_reflectance),
            kt: c3(rd.specular_transmittance),
            importance: rd.mode == crate::TransportMode::Importance,
        },
    })
}

/// The kernel of a Phong (`model = PHONG`) or Blinn-Phong material with
/// specular colour `ks`, exponent `n` and normalization `norm` (`f = ks ·
/// norm · cosⁿ`); strategies brdf, uniform, cosine (`m.check` accepted it).
fn lecture_kernel(
    m: &Material,
    strategy: BsdfStrategy,
    model: u8,
    ks: Rgb,
    n: f64,
    norm: f64,
) -> Result<Kernel, BatchError> {
    let strat = match strategy {
        BsdfStrategy::Brdf => kernel::BRDF,
        BsdfStrategy::Uniform => kernel::UNIFORM,
        BsdfStrategy::Cosine => kernel::COSINE,
        other => {
            return Err(BatchError::Unsupported {
                reason: format!("strategy `{other}` for model `{}`", m.model_name()),
            });
        }
    };
    let c3 = |c: Rgb| [c.x as f32, c.y as f32, c.z as f32];
    let pdf_k = (n + 1.0) * crate::math::INV_TWO_PI;
    let ks_norm = ks * norm;
    if ks_norm.max_element() > f64::from(f32::MAX) / 1e3 {
        return Err(BatchError::Unsupported {
            reason: format!(
                "ks × normalization = {:e} is beyond f32's range",
                ks_norm.max_element()
            ),
        });
    }
    let kd = m.diffuse.albedo;
    let p = kernel::phong::LectureParams {
        n: n as f32,
        inv_m: (1.0 / (n + 1.0)) as f32,
        pdf_k: pdf_k as f32,
        ks_norm: c3(ks_norm),
        ks_w: c3(ks_norm / pdf_k),
        kd_pi: c3(kd * crate::math::INV_PI),
        // Constant for these models (their albedo hint ignores wo).
        p_glossy: m.glossy_probability(glam::DVec3::Z) as f32,
        two_lobes: m.chooses_lobe(strategy),
    };
    Ok(Kernel::Lecture { model, strat, p })
}
