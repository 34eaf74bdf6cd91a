//! Vector math for the batch kernels, written once over [`Lanes`].
//!
//! Besides the exactly rounded `+ − × ÷ √` and fused multiply-add of the
//! lanes, the kernels need one transcendental: the sine and cosine of the
//! disk angle `2π u`, [`sincos_turns`].

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
