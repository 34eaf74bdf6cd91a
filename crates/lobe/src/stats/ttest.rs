//! One-sample Student's t-test (feature `stats`) and running moments, for
//! checking that a Monte Carlo estimator's mean matches a reference value.

#[cfg(feature = "stats")]
use statrs::distribution::{ContinuousCDF, StudentsT};

/// Relative tolerance under which a zero-variance mean equals the reference.
#[cfg(feature = "stats")]
const ZERO_VARIANCE_REL: f64 = 1e-12;

/// Outcome of [`t_test`].
#[cfg(feature = "stats")]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TTest {
    /// `(mean − reference) / sqrt(variance / n)`.
    pub t: f64,
    /// Two-sided p-value from Student's t with `n − 1` degrees of freedom.
    pub p_value: f64,
}

#[cfg(feature = "stats")]
impl TTest {
    /// Whether the mean is compatible with the reference at level `alpha`
    /// (`p_value > alpha`; false for a NaN p-value).
    #[must_use]
    pub fn passes(&self, alpha: f64) -> bool {
        self.p_value > alpha
    }
}

/// Two-sided one-sample t-test of `H0: E[X] = reference`.
///
/// `mean` and `variance` are the sample mean and the unbiased sample variance
/// of one sample (not of the mean) of size `n`.
///
/// With `variance == 0`, the p-value is 1 when `mean` equals `reference`
/// within `1e-12` relative (`t = 0`), else 0 (`t = ±∞`). With `n < 2`, a
/// negative variance or non-finite inputs, `t` and `p_value` are NaN.
#[cfg(feature = "stats")]
#[must_use]
pub fn t_test(mean: f64, variance: f64, n: usize, reference: f64) -> TTest {
    let nan = TTest {
        t: f64::NAN,
        p_value: f64::NAN,
    };
    if n < 2
        || variance < 0.0
        || !variance.is_finite()
        || !mean.is_finite()
        || !reference.is_finite()
    {
        return nan;
    }
    let diff = mean - reference;
    if variance == 0.0 {
        let scale = mean.abs().max(reference.abs());
        return if diff.abs() <= ZERO_VARIANCE_REL * scale {
            TTest {
                t: 0.0,
                p_value: 1.0,
            }
        } else {
            TTest {
                t: f64::INFINITY.copysign(diff),
                p_value: 0.0,
            }
        };
    }
    let se = (variance / n as f64).sqrt();
    let t = diff / se;
    let p_value = match StudentsT::new(0.0, 1.0, (n - 1) as f64) {
        Ok(d) if t.is_finite() => (2.0 * d.sf(t.abs())).min(1.0),
        Ok(_) => 0.0,
        Err(_) => f64::NAN,
    };
    TTest { t, p_value }
}

/// Running count, mean and variance (Welford's update, Chan et al.'s merge).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    n: u64,
    mean: f64,
    /// Sum of squared deviations from the mean.
    m2: f64,
}

impl Moments {
    /// Empty accumulator.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one observation.
    pub fn push(&mut self, x: f64) {
        self.n += 1;
        let d = x - self.mean;
        self.mean += d / self.n as f64;
        self.m2 += d * (x - self.mean);
    }

    /// Adds every observation of `other` (as if pushed here).
    pub fn merge(&mut self, other: &Moments) {
        if other.n == 0 {
            return;
        }
        if self.n == 0 {
            *self = *other;
            return;
        }
        let (na, nb) = (self.n as f64, other.n as f64);
        let n = na + nb;
        let d = other.mean - self.mean;
        self.mean += d * (nb / n);
        self.m2 += other.m2 + d * d * (na * nb / n);
        self.n += other.n;
    }

    /// Number of observations.
    #[must_use]
    pub fn count(&self) -> usize {
        usize::try_from(self.n).unwrap_or(usize::MAX)
    }

    /// Sample mean (NaN when empty).
    #[must_use]
    pub fn mean(&self) -> f64 {
        if self.n == 0 { f64::NAN } else { self.mean }
    }

    /// Unbiased sample variance (NaN with fewer than two observations).
    #[must_use]
    pub fn variance(&self) -> f64 {
        if self.n < 2 {
            f64::NAN
        } else {
            (self.m2 / (self.n - 1) as f64).max(0.0)
        }
    }

    /// Standard error of the mean, `sqrt(variance / count)`.
    #[must_use]
    pub fn std_error(&self) -> f64 {
        (self.variance() / self.n as f64).sqrt()
    }

    /// [`t_test`] of these moments against `reference`.
    #[cfg(feature = "stats")]
    #[must_use]
    pub fn t_test(&self, reference: f64) -> TTest {
        t_test(self.mean(), self.variance(), self.count(), reference)
    }
}

impl Extend<f64> for Moments {
    fn extend<I: IntoIterator<Item = f64>>(&mut self, iter: I) {
        for x in iter {
            self.push(x);
        }
    }
}

impl FromIterator<f64> for Moments {
    fn from_iter<I: IntoIterator<Item = f64>>(iter: I) -> Self {
        let mut m = Self::new();
        m.extend(iter);
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[cfg(feature = "stats")]
    use rand::{RngExt, SeedableRng};
    #[cfg(feature = "stats")]
    use rand_pcg::Pcg64;

    #[test]
    fn moments_match_two_pass_formulas() {
        let xs: Vec<f64> = (0..1000)
            .map(|i| 1e6 + ((i * 37) % 101) as f64 * 0.5)
            .collect();
        let m: Moments = xs.iter().copied().collect();
        let mean = xs.iter().sum::<f64>() / 1000.0;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 999.0;
        assert_eq!(m.count(), 1000);
        assert!((m.mean() - mean).abs() < 1e-9);
        assert!(
            (m.variance() - var).abs() < 1e-9 * var,
            "{} {var}",
            m.variance()
        );
        assert!((m.std_error() - (var / 1000.0).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn merge_equals_sequential() {
        let xs: Vec<f64> = (0..257)
            .map(|i| (i as f64 * 0.731).sin() * 3.0 + 2.0)
            .collect();
        let all: Moments = xs.iter().copied().collect();
        let mut a: Moments = xs[..100].iter().copied().collect();
        let b: Moments = xs[100..].iter().copied().collect();
        a.merge(&b);
        assert_eq!(a.count(), all.count());
        assert!((a.mean() - all.mean()).abs() < 1e-13);
        assert!((a.variance() - all.variance()).abs() < 1e-12);
        let mut e = Moments::new();
        e.merge(&all);
        assert_eq!(e, all);
        let mut f = all;
        f.merge(&Moments::new());
        assert_eq!(f, all);
    }

    #[cfg(feature = "stats")]
    #[test]
    fn degenerate_moments() {
        let m = Moments::new();
        assert!(m.mean().is_nan() && m.variance().is_nan() && m.std_error().is_nan());
        let mut m = Moments::new();
        m.push(3.0);
        assert_eq!(m.mean(), 3.0);
        assert!(m.variance().is_nan());
        assert!(m.t_test(3.0).p_value.is_nan());
    }

    #[cfg(feature = "stats")]
    #[test]
    fn t_test_known_values() {
        // t = 2 with 9 dof: two-sided p = 0.076_552_823_770_69... (Simpson on the density)
        let r = t_test(2.0, 10.0, 10, 0.0);
        assert!((r.t - 2.0).abs() < 1e-15);
        assert!((r.p_value - 0.076_552_823_770_69).abs() < 1e-12, "{r:?}");
        // Symmetric in the sign of the difference.
        let s = t_test(-2.0, 10.0, 10, 0.0);
        assert_eq!(s.t, -r.t);
        assert!((s.p_value - r.p_value).abs() < 1e-15);
        // Large n: close to the normal, p(|Z| > 1.96) ≈ 0.05.
        let r = t_test(1.96, 1e7, 10_000_000, 0.0);
        assert!((r.p_value - 0.049_995_790_296).abs() < 1e-6, "{r:?}");
        assert!(t_test(0.0, 1.0, 100, 0.0).p_value == 1.0);
    }

    #[cfg(feature = "stats")]
    #[test]
    fn zero_variance_and_bad_input() {
        assert_eq!(
            t_test(1.0, 0.0, 10, 1.0 + 1e-14),
            TTest {
                t: 0.0,
                p_value: 1.0
            }
        );
        let r = t_test(1.0, 0.0, 10, 1.0 + 1e-9);
        assert_eq!((r.t, r.p_value), (f64::NEG_INFINITY, 0.0));
        assert_eq!(t_test(0.0, 0.0, 10, 0.0).p_value, 1.0);
        assert!(t_test(0.0, -1.0, 10, 0.0).p_value.is_nan());
        assert!(t_test(0.0, 1.0, 1, 0.0).p_value.is_nan());
        assert!(t_test(f64::NAN, 1.0, 10, 0.0).p_value.is_nan());
        assert!(!t_test(f64::NAN, 1.0, 10, 0.0).passes(0.01));
    }

    #[cfg(feature = "stats")]
    #[test]
    fn detects_biased_estimator_and_accepts_unbiased() {
        let mut rng = Pcg64::seed_from_u64(11);
        let unbiased: Moments = (0..100_000).map(|_| rng.random::<f64>()).collect();
        assert!(
            unbiased.t_test(0.5).passes(0.001),
            "{:?}",
            unbiased.t_test(0.5)
        );
        let biased: Moments = (0..100_000).map(|_| rng.random::<f64>() * 1.01).collect();
        assert!(
            biased.t_test(0.5).p_value < 1e-6,
            "{:?}",
            biased.t_test(0.5)
        );
    }
}
