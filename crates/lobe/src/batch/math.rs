//! Vector math for the batch kernels, written once over [`Lanes`].
//!
//! Besides the exactly rounded `+ − × ÷ √` and fused multiply-add of the
//! lanes, the kernels need: the sine and cosine of the disk angle `2π u`
//! ([`sincos_turns`]), [`exp`], [`log`] and [`log1p`], the complementary
//! error function ([`erfc_exp`], with `exp(−x²)` beside it) and the inverse
//! error function ([`erfinv_u`]) for Beckmann. Each is branch-free, uses
//! only the lanes' exactly rounded operations (the same bits at every
//! level), and has its maximum error over its domain, measured against f64
//! by the tests below (`--nocapture` prints them), in its doc comment.
//! The polynomial coefficients are discrete minimax fits made by
//! `fit_math.py` (and `fit_sincos.py`) beside this file.

// The coefficients keep the fit's f64 digits (rounded to f32 by the compiler).
#![allow(clippy::excessive_precision)]

use super::lanes::Lanes;

// Minimax coefficients on [−π/4, π/4] (Cephes-style reduction), fitted by
// `fit_sincos.py` beside this file: `sin x ≈ x + x³ (S0 + S1 x² + S2 x⁴)`
// (relative error 3.8e-9 in exact arithmetic), `cos x ≈ 1 − x²/2 + x⁴ (C0 +
// C1 x² + C2 x⁴)` (absolute error 9.5e-11). Rounded to f32.
const S0: f32 = -0.166_666_55;
const S1: f32 = 0.008_332_161;
const S2: f32 = -0.000_195_152_83;
const C0: f32 = 0.041_666_646;
const C1: f32 = -0.001_388_736_8;
const C2: f32 = 2.443_845_1e-5;

/// `(sin 2πt, cos 2πt)` for `t` in turns, lane by lane.
///
/// The argument is reduced exactly to the nearest quarter turn
/// (`t = q/4 + r`, `|r| ≤ 1/8`, exact for `|t| < 2²²`), the polynomials are
/// evaluated at `x = 2πr ∈ [−π/4, π/4]` and the quadrant `q mod 4` swaps
/// and negates them. Branch-free; the same bits at every level.
///
/// Maximum error against f64 `sin_cos(2πt)`, measured by the test
/// `batch::math::tests::sincos_error` over the 2²⁴ points `t = i/2²⁴` of
/// `[0, 1)`, 2²⁰ random `f32` in `[−4, 4]` and powers of two down to
/// 2⁻⁹⁹, at every level (the same bits at each): **1.07e-7 absolute** for
/// both sine and cosine (under 2 ulp of 1; the f32 rounding of `2πr`
/// dominates, the polynomials are 30 to 1000 times more accurate), and
/// for `t ∈ (0, 1/16]` a relative error of the sine of at most **1.45e-7**.
#[inline(always)]
pub(crate) fn sincos_turns<L: Lanes>(l: L, t: L::F) -> (L::F, L::F) {
    let q = l.round(t * l.splat(4.0));
    // Exact: q/4 is exact and close to t.
    let r = l.mul_add(q, l.splat(-0.25), t);
    let x = r * l.splat(std::f32::consts::TAU);
    let x2 = x * x;
    let ps = l.mul_add(l.mul_add(x2, l.splat(S2), l.splat(S1)), x2, l.splat(S0));
    let sin = l.mul_add(x * x2, ps, x);
    let pc = l.mul_add(l.mul_add(x2, l.splat(C2), l.splat(C1)), x2, l.splat(C0));
    let cos = l.mul_add(x2 * x2, pc, l.mul_add(x2, l.splat(-0.5), l.splat(1.0)));
    // Quadrant q mod 4, as a float in {0, 1, 2, 3}.
    let qm = l.mul_add(l.floor(q * l.splat(0.25)), l.splat(-4.0), q);
    let (one, two, three) = (l.splat(1.0), l.splat(2.0), l.splat(3.0));
    let odd = l.eq(qm, one) | l.eq(qm, three);
    let sin_neg = l.eq(qm, two) | l.eq(qm, three);
    let cos_neg = l.eq(qm, one) | l.eq(qm, two);
    let s = l.select(odd, cos, sin);
    let c = l.select(odd, sin, cos);
    (l.select(sin_neg, -s, s), l.select(cos_neg, -c, c))
}

// exp: e^r ≈ 1 + r + r² P(r) on [−ln2/2, ln2/2], relative error 5.2e-11
// in exact arithmetic (fit_math.py exp).
const EXP_P: [f32; 6] = [
    0.500_000_006_764_458,
    0.166_666_658_693_277_6,
    0.041_666_295_088_491_075,
    0.008_333_497_029_742_391,
    0.001_394_464_888_411_923_7,
    0.000_197_903_403_943_014,
];
const LN2_HI: f32 = std::f32::consts::LN_2;
/// `ln 2 − LN2_HI`.
const LN2_LO: f32 = -1.904_654_3e-9;
/// Below this `exp` returns 0 (`e^x` is under `f32::MIN_POSITIVE`).
const EXP_MIN: f32 = -87.336_55;

/// `e^x`, lane by lane, for `x` in `[−87.33, 88.72]`; 0 below (no
/// subnormals), `+∞` above.
///
/// Cody-Waite reduction `x = n ln2 + r` (`ln 2` split in two, fused
/// multiply-adds), the minimax polynomial above, and `2ⁿ` from the exponent
/// bits. Maximum relative error against f64, measured by `math_errors` on
/// 2²⁰ points of `[−87.3, 88.7]` and 2²⁰ of `[−1, 1]`: **8.1e-8** (under 1
/// ulp).
#[inline(always)]
pub(crate) fn exp<L: Lanes>(l: L, x: L::F) -> L::F {
    exp_hl(l, x, l.splat(0.0))
}

/// `e^(hi + lo)` for a small correction `lo` (`|lo| ≤ ulp(hi)`), e.g. the
/// rounding error of `hi = −z²`: the correction enters after the reduction,
/// where it is not lost. Same error as [`exp`] relative to `e^(hi+lo)`.
#[inline(always)]
pub(crate) fn exp_hl<L: Lanes>(l: L, hi: L::F, lo: L::F) -> L::F {
    let xc = l.min(l.max(hi, l.splat(EXP_MIN)), l.splat(88.72));
    let n = l.round(xc * l.splat(std::f32::consts::LOG2_E));
    let r = l.mul_add(n, l.splat(-LN2_HI), xc);
    let r = l.mul_add(n, l.splat(-LN2_LO), r) + lo;
    let mut p = l.splat(EXP_P[5]);
    for &c in EXP_P[..5].iter().rev() {
        p = l.mul_add(p, r, l.splat(c));
    }
    let e = l.mul_add(r * r, p, r) + l.splat(1.0);
    // 2ⁿ in two halves so that n = 128 (x near 88.7) stays in range.
    let n1 = l.floor(n * l.splat(0.5));
    let y = e * l.exp2i(n1) * l.exp2i(n - n1);
    let y = l.select(l.lt(hi, l.splat(EXP_MIN)), l.splat(0.0), y);
    l.select(l.gt(hi, l.splat(88.72)), l.splat(f32::INFINITY), y)
}

/// `e^x − 1`, lane by lane, accurate for small `x` (no cancellation): for
/// `|x| < ln 2 / 2` the reduced polynomial of [`exp`] without its leading
/// 1 (`x + x² P(x)`), elsewhere `exp(x) − 1` (where `|e^x − 1| > 0.29`,
/// nothing cancels). `−1` below −87.3, `+∞` above 88.7. Maximum relative
/// error against f64 `exp_m1`, measured by `math_errors` on 2²⁰ points of
/// `[−1, 1]`, 2²⁰ of `[−87, 88]` and `±10⁻ᵏ`, `k ≤ 30`: **2.3e-7** (about
/// 2 ulp, largest just above `ln 2 / 2` where the rounding of `e^x` is
/// relative to `e^x`, not to `e^x − 1`).
#[inline(always)]
pub(crate) fn expm1<L: Lanes>(l: L, x: L::F) -> L::F {
    let mut p = l.splat(EXP_P[5]);
    for &c in EXP_P[..5].iter().rev() {
        p = l.mul_add(p, x, l.splat(c));
    }
    let small = l.mul_add(x * x, p, x);
    let big = exp(l, x) - l.splat(1.0);
    l.select(
        l.lt(l.abs(x), l.splat(0.5 * std::f32::consts::LN_2)),
        small,
        big,
    )
}

/// `(1 − t)ⁿ` for `t ∈ [0, 1)` and `n ≥ 0` lane by lane (`n` may differ
/// per lane): `exp(n · log1p(−t))`, written with `t` so that the sharp
/// lobes `cosⁿ` with `n` up to 2·10⁸ (the Phong and Blinn-Phong exponents,
/// the Blinn-Phong NDF at alpha 1e-4) keep their precision: the caller
/// computes `t = 1 − cos` without cancellation. The error grows with the
/// size of the exponent `|n ln(1 − t)|` (the rounding of the argument of
/// `exp`): measured by `math_errors` against f64 on 2²⁰ log-uniform `t` in
/// `[1e-12, 1)` × log-uniform `n` in `[1e-3, 2e8]` (results under
/// `f32::MIN_POSITIVE`, which [`exp`] flushes to 0, excluded), the relative error is at most **2.3e-7 · (1 + |n ln(1 −
/// t)|)** (under 2e-5 wherever the result is above 1e-38). `t = 1` gives
/// 0 for `n > 0`; `n = 0` must be handled by the caller (`0 · (−∞)`).
#[inline(always)]
pub(crate) fn pow_1m<L: Lanes>(l: L, t: L::F, n: L::F) -> L::F {
    exp(l, n * log1p(l, -t))
}

/// `cⁿ` for `c = 1 − t ∈ (0, 1]`, `n ≥ 0` lane by lane, given both `t`
/// and `c` (each computed by the caller without cancellation): [`pow_1m`]
/// where `t < 1/2` (a sharp lobe near its peak), `exp(n ln c)` elsewhere
/// (where `1 − t` would lose the bits of a small `c`; `c` is clamped to
/// `f32::MIN_POSITIVE`, `c ≤ 0` gives 0 for `n > 0`). Measured by
/// `math_errors_expm1_pow` with `c` log-uniform in `[1e-30, 1]` (below 1/2
/// the `ln c` branch) and the `t` of [`pow_1m`]: the same bound, **2.3e-7 ·
/// (1 + |n ln c|)** relative. `n = 0` must be handled by the caller.
#[inline(always)]
pub(crate) fn pow_cos<L: Lanes>(l: L, t: L::F, c: L::F, n: L::F) -> L::F {
    let far = exp(l, n * log(l, l.max(c, l.splat(f32::MIN_POSITIVE))));
    let far = l.select(l.gt(c, l.splat(0.0)), far, l.splat(0.0));
    l.select(l.lt(t, l.splat(0.5)), pow_1m(l, t, n), far)
}

// log1p(f) ≈ f − f²/2 + f³ P(f) on [√½ − 1, √2 − 1], relative error 5.8e-9
// in exact arithmetic (fit_math.py log).
const LOG_P: [f32; 8] = [
    0.333_333_317_082_765_3,
    -0.250_008_210_366_223_7,
    0.200_012_268_279_149_4,
    -0.166_233_572_326_685_06,
    0.142_017_589_914_484_43,
    -0.131_601_844_293_900_04,
    0.127_615_711_443_992_42,
    -0.076_344_839_949_657_75,
];

/// `ln(1 + f)` for `f` in `[√½ − 1, √2 − 1]`.
#[inline(always)]
fn log1p_reduced<L: Lanes>(l: L, f: L::F) -> L::F {
    let mut p = l.splat(LOG_P[7]);
    for &c in LOG_P[..7].iter().rev() {
        p = l.mul_add(p, f, l.splat(c));
    }
    let f2 = f * f;
    l.mul_add(f2 * f, p, l.mul_add(f2, l.splat(-0.5), f))
}

/// `ln x`, lane by lane, for normal positive `x` (and `+∞`); `−∞` at 0.
/// Subnormal `x` are outside its domain (the kernels never pass one).
///
/// `x = m 2ᵉ` from the bits, `m` moved into `[√½, √2)`, then
/// `e ln 2 + log1p(m − 1)` (`m − 1` is exact). Maximum error against f64,
/// measured by `math_errors` on 2²⁰ log-uniform points of
/// `[1.2e-38, 3.4e38]` and 2²⁰ of `[0.5, 2]`: **5.9e-8 absolute** where
/// `|ln x| < 1`, **9.1e-8 relative** elsewhere.
#[inline(always)]
pub(crate) fn log<L: Lanes>(l: L, x: L::F) -> L::F {
    let (m, e) = l.frexp(x);
    let big = l.gt(m, l.splat(std::f32::consts::SQRT_2));
    let m = l.select(big, m * l.splat(0.5), m);
    let e = l.select(big, e + l.splat(1.0), e);
    let f = m - l.splat(1.0);
    let y = l.mul_add(
        e,
        l.splat(LN2_HI),
        l.mul_add(e, l.splat(LN2_LO), log1p_reduced(l, f)),
    );
    let y = l.select(l.eq(x, l.splat(0.0)), l.splat(f32::NEG_INFINITY), y);
    l.select(l.eq(x, l.splat(f32::INFINITY)), x, y)
}

/// `ln(1 + x)` for `x > −1`, accurate for small `x`: `u = 1 + x`, then
/// `ln u · x / (u − 1)` (Goldberg's correction of the rounding of `u`), `x`
/// where `u = 1`. Maximum relative error against f64, measured by
/// `math_errors` on 2²⁰ points of `(−1, 1)` and 2²⁰ of `±[1e-30, 1e-2]`:
/// **2.1e-7**.
#[inline(always)]
pub(crate) fn log1p<L: Lanes>(l: L, x: L::F) -> L::F {
    let one = l.splat(1.0);
    let u = x + one;
    let d = u - one;
    let y = log(l, u) * (x / d);
    l.select(l.eq(d, l.splat(0.0)), x, y)
}

// erf(x) ≈ x P(x²) on [0, 1], relative error 1.2e-9 in exact arithmetic.
const ERF_P: [f32; 7] = [
    1.128_379_165_729_288_5,
    -0.376_126_258_322_967_6,
    0.112_835_852_170_700_29,
    -0.026_853_814_388_294_75,
    0.005_188_331_922_499_965,
    -0.000_801_022_853_877_418_1,
    7.853_971_499_078_448e-5,
];
// erfc(z) ≈ exp(−z²) · Σ c_k t^(k+1), t = 1/(1 + z/2), on [1, 10],
// relative error 1.2e-8 in exact arithmetic (fit_math.py erfc, DEG=9).
const ERFC_Q: [f32; 9] = [
    0.282_077_272_013_307_23,
    0.282_552_090_654_930_37,
    0.241_724_936_639_931_53,
    0.208_289_787_797_186_5,
    -0.039_323_536_906_657_34,
    0.293_677_322_219_706_1,
    -0.495_732_447_188_216_13,
    0.284_385_196_294_392_74,
    -0.057_614_296_177_581_93,
];

/// `(erfc x, e^(−x²))` for any `x`, lane by lane.
///
/// `|x| < 1`: `1 ∓ |x| P(x²)`; `|x| ≥ 1`: `e^(−x²) t Q(t)`, `t = 1/(1 +
/// |x|/2)`, with `e^(−x²)` from the exactly split `x² = hi + lo` (so that
/// the rounding of `x²`, up to 4e-6 at `|x| = 9`, does not enter the
/// exponential); `erfc(−z) = 2 − erfc z`. The exponential is the second
/// result: the Beckmann kernels need it too. Maximum relative error of
/// `erfc` against f64, measured by `math_errors` on 2²⁰ points of
/// `[−4, 9.2]` (where `erfc x ≥ 1e-37`): **8.0e-7**, largest just below `|x| = 1` where `1 − erf` loses a few bits (`erfc` is relative
/// to itself, however small: the tails of Beckmann's slope CDF rely on
/// it); of `e^(−x²)`: 9.1e-8.
#[inline(always)]
pub(crate) fn erfc_exp<L: Lanes>(l: L, x: L::F) -> (L::F, L::F) {
    let (c, e) = erfc_abs(l, l.abs(x));
    let neg = l.lt(x, l.splat(0.0));
    (l.select(neg, l.splat(2.0) - c, c), e)
}

/// `(erfc z, e^(−z²))` for `z ≥ 0` (or `+∞`), as in [`erfc_exp`].
#[inline(always)]
pub(crate) fn erfc_abs<L: Lanes>(l: L, z: L::F) -> (L::F, L::F) {
    let one = l.splat(1.0);
    let hi = z * z;
    let lo = l.mul_add(z, z, -hi);
    let e = exp_hl(l, -hi, -lo);
    // Small z.
    let mut p = l.splat(ERF_P[6]);
    for &c in ERF_P[..6].iter().rev() {
        p = l.mul_add(p, hi, l.splat(c));
    }
    let erf_z = z * p;
    // Large z.
    let t = one / l.mul_add(z, l.splat(0.5), one);
    let mut q = l.splat(ERFC_Q[8]);
    for &c in ERFC_Q[..8].iter().rev() {
        q = l.mul_add(q, t, l.splat(c));
    }
    let erfc_big = e * (t * q);
    (l.select(l.lt(z, one), one - erf_z, erfc_big), e)
}

/// `erf⁻¹(2u − 1)` for `u ∈ [1e-12, 1 − 1e-12]` (the clamp of the
/// Beckmann sampler), accurate in the tails: [`erfinv_u`] where its `w <
/// 16`, the asymptotic `|x| ≈ √(t − ln(π t)/2)`, `t = −ln(2 min(u, 1 − u))`
/// beyond (where Giles' polynomial, made for `f32` arguments `2u − 1`,
/// fails), then two Newton steps on `erf x − (2u − 1)` with the residual
/// written with `erfc` of the tail (`erfc(−x) − 2u` for `x < 0`, `2(1 − u)
/// − erfc x` otherwise) so that it stays relative to itself. Maximum
/// relative error against f64, measured by `math_errors` on the points of
/// [`erfinv_u`] and `u = 10⁻ᵏ`, `1 − 10⁻ᵏ`, `k ≤ 12`: **3.1e-7**.
#[inline(always)]
pub(crate) fn erfinv_u_refined<L: Lanes>(l: L, u: L::F) -> L::F {
    let one = l.splat(1.0);
    let two = l.splat(2.0);
    let lower = l.lt(u, l.splat(0.5));
    let m = l.select(lower, u, one - u);
    let w = -log(l, l.splat(4.0) * u * (one - u));
    let t = -log(l, two * m);
    let z = l.sqrt(l.mul_add(l.splat(-0.5), log(l, l.splat(std::f32::consts::PI) * t), t));
    let tail = l.select(lower, -z, z);
    let mut x = l.select(l.lt(w, l.splat(16.0)), erfinv_u(l, u), tail);
    for _ in 0..2 {
        let (c, e) = erfc_abs(l, l.abs(x));
        let g = l.select(
            l.lt(x, l.splat(0.0)),
            l.mul_add(-two, u, c),
            l.mul_add(two, one - u, -c),
        );
        let step = g / (l.splat(std::f32::consts::FRAC_2_SQRT_PI) * e);
        x = l.select(l.is_finite(step), x - step, x);
    }
    x
}

/// `erf⁻¹(2u − 1)` for `u ∈ (0, 1)`, lane by lane: M. Giles'
/// single-precision approximation ("Approximating the erfinv function",
/// GPU Computing Gems, 2011), its `w = −ln(1 − y²)` taken as
/// `−ln(4u(1 − u))` so that nothing cancels near `u = 0` or `1`. Both of
/// its branches are evaluated and one selected. Maximum error against f64
/// (`erf⁻¹` by Newton on `libm::erf`), measured by `math_errors` on 2²⁰
/// points `u` of `(0, 1)` and the powers of two `2⁻ᵏ`, `1 − 2⁻ᵏ`, `k ≤ 24`:
/// **2.6e-7 relative** (about 2 ulp).
#[inline(always)]
pub(crate) fn erfinv_u<L: Lanes>(l: L, u: L::F) -> L::F {
    let one = l.splat(1.0);
    let y = l.mul_add(u, l.splat(2.0), -one);
    let w = -log(l, l.splat(4.0) * u * (one - u));
    let a = w - l.splat(2.5);
    let mut p = l.splat(2.810_226_36e-08);
    for k in [
        3.432_739_39e-07,
        -3.523_387_7e-06,
        -4.391_506_54e-06,
        0.000_218_580_87,
        -0.001_253_725_03,
        -0.004_177_681_64,
        0.246_640_727,
        1.501_409_41,
    ] {
        p = l.mul_add(p, a, l.splat(k));
    }
    let b = l.sqrt(w) - l.splat(3.0);
    let mut q = l.splat(-0.000_200_214_257);
    for k in [
        0.000_100_950_558,
        0.001_349_343_22,
        -0.003_673_428_44,
        0.005_739_507_73,
        -0.007_622_461_3,
        0.009_438_870_47,
        1.001_674_06,
        2.832_976_82,
    ] {
        q = l.mul_add(q, b, l.splat(k));
    }
    l.select(l.lt(w, l.splat(5.0)), p, q) * y
}

#[cfg(test)]
mod tests {
    use super::super::{SimdLevel, dispatch};
    use rand::{RngExt, SeedableRng};

    /// Max |error| of sin and cos against f64, and the max relative error of
    /// the sine for small arguments.
    fn errors(t: &[f32], s: &[f32], c: &[f32]) -> (f64, f64, f64) {
        let (mut es, mut ec, mut rel) = (0.0f64, 0.0f64, 0.0f64);
        for ((&t, &s), &c) in t.iter().zip(s).zip(c) {
            let (se, ce) = (std::f64::consts::TAU * f64::from(t)).sin_cos();
            es = es.max((f64::from(s) - se).abs());
            ec = ec.max((f64::from(c) - ce).abs());
            if t > 0.0 && t <= 0.0625 {
                rel = rel.max(((f64::from(s) - se) / se).abs());
            }
        }
        (es, ec, rel)
    }

    #[test]
    fn sincos_error() {
        let mut t: Vec<f32> = (0..1u32 << 24)
            .map(|i| i as f32 / (1u32 << 24) as f32)
            .collect();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        t.extend((0..1 << 20).map(|_| rng.random_range(-4.0f32..4.0)));
        // Tiny arguments, for the relative error near zero.
        t.extend((1..200).map(|k| 2f32.powi(-k / 2)));
        let mut s = vec![0.0; t.len()];
        let mut c = vec![0.0; t.len()];
        let mut reference: Option<(Vec<f32>, Vec<f32>)> = None;
        for level in SimdLevel::ALL {
            if !level.is_available() {
                eprintln!("sincos_error: level {level} skipped (not on this CPU)");
                continue;
            }
            dispatch::sincos_slice(level, &t, &mut s, &mut c);
            let (es, ec, rel) = errors(&t, &s, &c);
            eprintln!(
                "sincos_error {level}: sin {es:.3e}, cos {ec:.3e} absolute; sin {rel:.3e} relative on (0, 1/16]"
            );
            assert!(es < 1.3e-7 && ec < 1.3e-7, "{level}: {es} {ec}");
            assert!(rel < 2.5e-7, "{level}: {rel}");
            match &reference {
                None => reference = Some((s.clone(), c.clone())),
                Some((s0, c0)) => {
                    assert!(s0.iter().zip(&s).all(|(a, b)| a.to_bits() == b.to_bits()));
                    assert!(c0.iter().zip(&c).all(|(a, b)| a.to_bits() == b.to_bits()));
                }
            }
        }
    }
}

#[cfg(test)]
mod accuracy {
    use super::super::SimdLevel;
    use super::super::dispatch::{MathFn, math_slice};
    use rand::{RngExt, SeedableRng};

    /// Runs `f` at every level, checks the same bits, returns the outputs.
    fn run(f: MathFn, x: &[f32]) -> (Vec<f32>, Vec<f32>) {
        let mut first: Option<(Vec<f32>, Vec<f32>)> = None;
        for level in SimdLevel::ALL {
            if !level.is_available() {
                eprintln!("math_errors: level {level} skipped (not on this CPU)");
                continue;
            }
            let (mut a, mut b) = (vec![0.0; x.len()], vec![0.0; x.len()]);
            math_slice(level, f, x, &mut a, &mut b);
            match &first {
                None => first = Some((a, b)),
                Some((a0, b0)) => {
                    let same = |p: &[f32], q: &[f32]| {
                        p.iter().zip(q).all(|(u, v)| u.to_bits() == v.to_bits())
                    };
                    assert!(same(a0, &a) && same(b0, &b), "{f:?}: {level} differs");
                }
            }
        }
        first.unwrap()
    }

    fn rel(got: f32, want: f64) -> f64 {
        if want == 0.0 && got == 0.0 {
            0.0
        } else {
            ((f64::from(got) - want) / want).abs()
        }
    }

    fn uniform(rng: &mut rand_pcg::Pcg64, n: usize, a: f64, b: f64) -> Vec<f32> {
        (0..n).map(|_| rng.random_range(a..b) as f32).collect()
    }

    /// `erf⁻¹(2u − 1)` in f64 for any `u ∈ (0, 1)`, however close to 0 or
    /// 1: Newton on `erfc(−x) = 2 min(u, 1 − u)`, relative in the tail.
    fn erfinv_u_f64(u: f64) -> f64 {
        let (t, sign) = if u < 0.5 { (u, 1.0) } else { (1.0 - u, -1.0) };
        let mut x = crate::microfacet::erf_inv(2.0 * t - 1.0);
        if !x.is_finite() {
            x = -(-(2.0 * t).ln()).sqrt();
        }
        for _ in 0..60 {
            let g = libm::erfc(-x) - 2.0 * t;
            let d = 2.0 / std::f64::consts::PI.sqrt() * (-x * x).exp();
            x -= g / d;
        }
        sign * x
    }

    /// The maximum errors written in the doc comments of `exp`, `log`,
    /// `log1p`, `erfc_exp` and `erfinv_u`, measured against f64 (each bound
    /// asserted a little above the measured value), at every level with the
    /// same bits. Cost: about 1 s in release.
    #[test]
    fn math_errors() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(0x3a7);
        let n = 1 << 20;
        // exp
        let mut x = uniform(&mut rng, n, -87.3, 88.7);
        x.extend(uniform(&mut rng, n, -1.0, 1.0));
        let (y, _) = run(MathFn::Exp, &x);
        let e = x
            .iter()
            .zip(&y)
            .map(|(&x, &y)| rel(y, f64::from(x).exp()))
            .fold(0.0, f64::max);
        eprintln!("math_errors exp: max rel {e:.3e}");
        assert!(e < 1e-7, "exp {e}");
        let (y, _) = run(MathFn::Exp, &[-87.4, -100.0, 89.0, f32::NEG_INFINITY]);
        assert_eq!(y, [0.0, 0.0, f32::INFINITY, 0.0]);
        // log
        let mut x: Vec<f32> = (0..n)
            .map(|_| 10f64.powf(rng.random_range(-37.9..38.5)) as f32)
            .collect();
        x.extend(uniform(&mut rng, n, 0.5, 2.0));
        let (y, _) = run(MathFn::Log, &x);
        let (mut ea, mut er) = (0.0f64, 0.0f64);
        for (&x, &y) in x.iter().zip(&y) {
            let w = f64::from(x).ln();
            if w.abs() < 1.0 {
                ea = ea.max((f64::from(y) - w).abs());
            } else {
                er = er.max(rel(y, w));
            }
        }
        eprintln!("math_errors log: max abs {ea:.3e} where |ln x| < 1, max rel {er:.3e} elsewhere");
        assert!(ea < 7e-8 && er < 1e-7, "log {ea} {er}");
        let (y, _) = run(MathFn::Log, &[0.0, 1.0, f32::INFINITY]);
        assert_eq!(y, [f32::NEG_INFINITY, 0.0, f32::INFINITY]);
        // log1p
        let mut x = uniform(&mut rng, n, -1.0, 1.0);
        x.retain(|&v| v > -1.0);
        x.extend((0..n).map(|i| {
            let v = 10f64.powf(rng.random_range(-30.0..-2.0)) as f32;
            if i % 2 == 0 { v } else { -v }
        }));
        let (y, _) = run(MathFn::Log1p, &x);
        let e = x
            .iter()
            .zip(&y)
            .map(|(&x, &y)| rel(y, f64::from(x).ln_1p()))
            .fold(0.0, f64::max);
        eprintln!("math_errors log1p: max rel {e:.3e}");
        assert!(e < 2.5e-7, "log1p {e}");
        // erfc and exp(-x²)
        let x = uniform(&mut rng, n, -4.0, 9.2);
        let (c, ex) = run(MathFn::ErfcExp, &x);
        let (mut ec, mut ee) = (0.0f64, 0.0f64);
        for ((&x, &c), &ex) in x.iter().zip(&c).zip(&ex) {
            let x = f64::from(x);
            ec = ec.max(rel(c, libm::erfc(x)));
            ee = ee.max(rel(ex, (-x * x).exp()));
        }
        eprintln!("math_errors erfc: max rel {ec:.3e}; exp(-x²): max rel {ee:.3e}");
        assert!(ec < 9e-7 && ee < 1.5e-7, "erfc {ec} {ee}");
        // erfinv(2u − 1)
        let mut u: Vec<f32> = (0..n).map(|_| rng.random_range(0.0..1.0) as f32).collect();
        u.retain(|&v| v > 0.0 && v < 1.0);
        for k in 1..=24 {
            u.push(2f32.powi(-k));
            u.push(1.0 - 2f32.powi(-k));
        }
        let (y, _) = run(MathFn::ErfinvU, &u);
        let e = u
            .iter()
            .zip(&y)
            .map(|(&u, &y)| rel(y, crate::microfacet::erf_inv(2.0 * f64::from(u) - 1.0)))
            .fold(0.0, f64::max);
        eprintln!("math_errors erfinv: max rel {e:.3e}");
        assert!(e < 3e-7, "erfinv {e}");
        for k in 1..=12 {
            u.push(10f32.powi(-k));
            u.push(1.0 - 10f32.powi(-k).max(f32::EPSILON / 2.0));
        }
        let (y, _) = run(MathFn::ErfinvURefined, &u);
        let e = u
            .iter()
            .zip(&y)
            .map(|(&u, &y)| rel(y, erfinv_u_f64(f64::from(u))))
            .fold(0.0, f64::max);
        eprintln!("math_errors erfinv refined: max rel {e:.3e}");

        assert!(e < 3.5e-7, "erfinv refined {e}");
    }

    /// The maximum errors written in the doc comments of `expm1` and
    /// `pow_1m`, against f64, at every level with the same bits. Cost:
    /// about 0.5 s in release.
    #[test]
    fn math_errors_expm1_pow() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(0x90e);
        let n = 1 << 20;
        let mut x = uniform(&mut rng, n, -1.0, 1.0);
        x.extend(uniform(&mut rng, n, -87.0, 88.0));
        for k in 1..=30 {
            x.push(10f32.powi(-k));
            x.push(-10f32.powi(-k));
        }
        let (y, _) = run(MathFn::Expm1, &x);
        let e = x
            .iter()
            .zip(&y)
            .map(|(&x, &y)| rel(y, f64::from(x).exp_m1()))
            .fold(0.0, f64::max);
        eprintln!("math_errors expm1: max rel {e:.3e}");
        assert!(e < 2.5e-7, "expm1 {e}");
        // (1 − t)^n: log-uniform t and n, one n per block of 4096.
        let (mut worst, mut worst_abs) = (0.0f64, 0.0f64);
        for _ in 0..256 {
            let p = 10f64.powf(rng.random_range(-3.0..8.3)) as f32;
            let t: Vec<f32> = (0..4096)
                .map(|_| 10f64.powf(rng.random_range(-12.0..0.0)) as f32)
                .filter(|&t| t < 1.0)
                .collect();
            let (y, _) = run(MathFn::Pow1m(p.to_bits()), &t);
            for (&t, &y) in t.iter().zip(&y) {
                let lnr = f64::from(p) * (-f64::from(t)).ln_1p();
                let want = lnr.exp();
                // exp flushes below f32::MIN_POSITIVE to 0.
                if want < 1.2e-38 {
                    continue;
                }
                let r = rel(y, want);
                if r / (1.0 + lnr.abs()) > 2.5e-7 {
                    eprintln!("pow_1m: t {t:e} n {p:e}: {y:e} vs {want:e}");
                }
                worst = worst.max(r / (1.0 + lnr.abs()));
                worst_abs = worst_abs.max(r);
            }
        }
        eprintln!(
            "math_errors pow_1m: max rel / (1 + |n ln(1 − t)|) {worst:.3e}, max rel {worst_abs:.3e}"
        );
        assert!(
            worst < 2.5e-7 && worst_abs < 2.5e-5,
            "pow_1m {worst} {worst_abs}"
        );
        let (y, _) = run(MathFn::Pow1m(3f32.to_bits()), &[1.0, 0.0]);
        assert_eq!(y, [0.0, 1.0]);
        // cⁿ from c (t = 1 − c, exact where the t branch is taken).
        let mut worst_c = 0.0f64;
        for _ in 0..256 {
            let p = 10f64.powf(rng.random_range(-3.0..8.3)) as f32;
            let c: Vec<f32> = (0..4096)
                .map(|_| 10f64.powf(rng.random_range(-30.0..0.0)) as f32)
                .collect();
            let (y, _) = run(MathFn::PowCos(p.to_bits()), &c);
            for (&c, &y) in c.iter().zip(&y) {
                let lnr = f64::from(p) * f64::from(c).ln();
                let want = lnr.exp();
                if want < 1.2e-38 {
                    continue;
                }
                worst_c = worst_c.max(rel(y, want) / (1.0 + lnr.abs()));
            }
        }
        eprintln!("math_errors pow_cos: max rel / (1 + |n ln c|) {worst_c:.3e}");
        assert!(worst_c < 2.5e-7, "pow_cos {worst_c}");
    }
}
