//! Convergence curves: how fast the error of each strategy and sample
//! sequence falls with the number of samples (what `lobe converge` plots).
//!
//! For every strategy × sequence and every `N = 2^0 .. 2^K`, `R`
//! independent estimates of the luminance of `L_o(wo)` are compared with a
//! target (the quadrature reference); their root mean square error is the
//! curve, and the slope of `log RMSE` against `log N` is fitted by least
//! squares over the upper half of the range of `log N` (the small-`N` end is
//! dominated by the constant of the error, not by its rate). Plain Monte
//! Carlo falls as `N^-1/2` (slope −0.5); stratified and Sobol points fall
//! faster on smooth integrands.
//!
//! Each estimate is a [`EstimateSettings`] of exactly `N` samples (as a renderer taking
//! `N` samples would use), never a prefix of one long run, and run `r` at
//! `N = 2^k` has its own seed [`run_seed`]`(S, r, k)`, so that the estimates
//! at different `N` are independent of each other and the least-squares fit
//! sees independent errors. With the feature `parallel` the estimates run on
//! rayon's pool, one task per (series, run, N); each task depends only on
//! its inputs, so the numbers do not depend on the thread count.

use super::map_indices;
use crate::estimator::{EstimateSettings, ShadingPoint, Strategy, estimate};
use crate::progress::Progress;
use crate::sequence::{Sequence, hash64};
use crate::{Error, Light, Material};

/// Relative tolerance of the quadrature reference `lobe converge` uses as
/// its target.
pub const REFERENCE_TOLERANCE: f64 = 1e-9;

/// How many runs at which sample counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CurveSettings {
    /// Independent estimates per `N` (the RMSE is over these).
    pub runs: usize,
    /// Largest exponent `K`: `N = 2^0 .. 2^K`.
    pub max_exp: u32,
    /// Seed `S` of [`run_seed`].
    pub seed: u64,
}

/// The RMSE of one strategy × sequence at every `N`.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    pub strategy: Strategy,
    pub sequence: Sequence,
    /// `(N, RMSE)` for `N = 2^0 .. 2^K`.
    pub points: Vec<(usize, f64)>,
    /// Least-squares slope of log RMSE against log N over the upper half
    /// ([`fit_start`]); `None` when it cannot be fitted ([`fit_slope`]).
    pub slope: Option<f64>,
}

/// The seed of run `run` at `N = 2^exp`.
#[must_use]
pub fn run_seed(seed: u64, run: usize, exp: u32) -> u64 {
    hash64(hash64(hash64(seed) ^ run as u64) ^ u64::from(exp))
}

/// The first exponent of the fit: the upper half of `0..=max_exp`.
#[must_use]
pub fn fit_start(max_exp: u32) -> u32 {
    max_exp.div_ceil(2)
}

/// Number of samples [`curves`] draws for `series` series: the total of its
/// progress task.
#[must_use]
pub fn total_samples(series: usize, runs: usize, max_exp: u32) -> u64 {
    ((1u64 << (max_exp + 1)) - 1) * (series * runs) as u64
}

/// Every strategy × sequence, strategy-major.
#[must_use]
pub fn product(strategies: &[Strategy], sequences: &[Sequence]) -> Vec<(Strategy, Sequence)> {
    strategies
        .iter()
        .flat_map(|&s| sequences.iter().map(move |&q| (s, q)))
        .collect()
}

/// RMSE curves of `series` (strategy, sequence) against the luminance
/// `target` of `L_o(wo) = ∫ f L cos dω` (cosine included), each over
/// `settings.runs` runs at `N = 2^0 .. 2^max_exp`, with the slopes fitted
/// over the upper half of the exponents.
///
/// Progress: one task `converge` of [`total_samples`] steps (one per
/// sample). The result depends only on the arguments, not on the thread
/// count. The error says why a strategy does not apply to `m`.
pub fn curves(
    m: &Material,
    sp: &ShadingPoint,
    light: &Light,
    target: f64,
    series: &[(Strategy, Sequence)],
    settings: CurveSettings,
    progress: &dyn Progress,
) -> Result<Vec<Curve>, Error> {
    for (t, _) in series {
        crate::estimator::ShadingEstimator::new(*t, m)?;
    }
    let CurveSettings {
        runs,
        max_exp,
        seed,
    } = settings;
    progress.start("converge", total_samples(series.len(), runs, max_exp));
    let exps = max_exp + 1;
    // One task per (series, exponent, run), largest N first so that the long
    // tasks start early and the pool ends evenly.
    let mut tasks: Vec<(usize, u32, usize)> = Vec::new();
    for k in (0..exps).rev() {
        for i in 0..series.len() {
            for r in 0..runs {
                tasks.push((i, k, r));
            }
        }
    }
    let errors: Vec<f64> = map_indices(tasks.len(), |t| {
        let (i, k, r) = tasks[t];
        let (strategy, sequence) = series[i];
        let estimate_settings = EstimateSettings {
            strategy,
            sequence,
            samples: 1usize << k,
            seed: run_seed(seed, r, k),
        };
        let acc = estimate(m, sp, light, &estimate_settings).expect("checked above");
        progress.advance(estimate_settings.samples as u64);
        acc.lum.mean() - target
    });
    // Sum the squared errors in task order: the same sums on any thread count.
    let mut sq = vec![vec![0.0; exps as usize]; series.len()];
    for (&(i, k, _), e) in tasks.iter().zip(&errors) {
        sq[i][k as usize] += e * e;
    }
    let start = fit_start(max_exp) as usize;
    Ok(series
        .iter()
        .zip(sq)
        .map(|(&(strategy, sequence), sq)| {
            let points: Vec<(usize, f64)> = sq
                .iter()
                .enumerate()
                .map(|(k, s)| (1usize << k, (s / runs as f64).sqrt()))
                .collect();
            let slope = fit_slope(&points[start..]);
            Curve {
                strategy,
                sequence,
                points,
                slope,
            }
        })
        .collect())
}

/// Least-squares slope of `log RMSE` against `log N`, over the points
/// `(N, RMSE)` whose RMSE is positive and finite; `None` with fewer than two
/// such points (or when they all have the same `N`).
#[must_use]
pub fn fit_slope(points: &[(usize, f64)]) -> Option<f64> {
    let xy: Vec<(f64, f64)> = points
        .iter()
        .filter(|(_, e)| *e > 0.0 && e.is_finite())
        .map(|&(n, e)| ((n as f64).log2(), e.log2()))
        .collect();
    if xy.len() < 2 {
        return None;
    }
    let k = xy.len() as f64;
    let mx = xy.iter().map(|p| p.0).sum::<f64>() / k;
    let my = xy.iter().map(|p| p.1).sum::<f64>() / k;
    let sxy: f64 = xy.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = xy.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimator::reference;
    use crate::math::luminance;
    use crate::{BsdfStrategy, Rgb};
    use glam::DVec3;

    #[test]
    fn slope_of_an_exact_power_law() {
        for slope in [-0.5, -1.0, -1.5, 0.25] {
            let points: Vec<(usize, f64)> = (0..12)
                .map(|k| (1usize << k, 3.0 * f64::from(1u32 << k).powf(slope)))
                .collect();
            let s = fit_slope(&points).unwrap();
            assert!((s - slope).abs() < 1e-12, "{s} vs {slope}");
        }
        // Zero and non-finite errors are left out.
        let s = fit_slope(&[(1, 1.0), (2, 0.0), (4, 0.5), (8, f64::NAN)]).unwrap();
        assert!((s + 0.5).abs() < 1e-12, "{s}");
        assert_eq!(fit_slope(&[(4, 1.0)]), None);
        assert_eq!(fit_slope(&[(4, 1.0), (4, 2.0)]), None);
        assert_eq!(fit_slope(&[(1, 0.0), (2, 0.0), (4, 0.0)]), None);
    }

    #[test]
    fn seeds_and_counts() {
        assert_ne!(run_seed(1, 0, 3), run_seed(1, 1, 3));
        assert_ne!(run_seed(1, 0, 3), run_seed(1, 0, 4));
        assert_eq!(run_seed(7, 2, 5), run_seed(7, 2, 5));
        assert_eq!(fit_start(12), 6);
        assert_eq!(fit_start(11), 6);
        assert_eq!(total_samples(2, 3, 4), 31 * 6);
        let p = product(
            &[Strategy::Light, BsdfStrategy::Cosine.into()],
            &[Sequence::Independent, Sequence::Sobol],
        );
        assert_eq!(p.len(), 4);
        assert_eq!(p[1], (Strategy::Light, Sequence::Sobol));
    }

    /// Independent sampling converges as `N^-1/2`; the zero-variance
    /// estimator (cosine sampling of a Lambert furnace) has no slope.
    #[test]
    fn independent_sampling_falls_as_one_over_root_n() {
        let m = Material::lambert(Rgb::splat(0.8)).unwrap();
        let wo = DVec3::new(0.5, 0.0, 0.75f64.sqrt());
        let sp = ShadingPoint::local(wo);
        let light = Light::Beam {
            dir: DVec3::new(0.2, 0.1, 1.0).normalize(),
            exponent: 4.0,
            radiance: Rgb::ONE,
        };
        let target = luminance(reference(&m, &sp, &light, REFERENCE_TOLERANCE));
        let series = product(
            &[BsdfStrategy::Uniform.into(), BsdfStrategy::Cosine.into()],
            &[Sequence::Independent],
        );
        let settings = CurveSettings {
            runs: 64,
            max_exp: 12,
            seed: 3,
        };
        let c = curves(&m, &sp, &light, target, &series, settings, &()).unwrap();
        assert_eq!(c.len(), 2);
        for curve in &c {
            assert_eq!(curve.points.len(), 13);
            let first = curve.points[0].1;
            let last = curve.points[12].1;
            assert!(last < first / 20.0, "{:?}", curve.points);
            let s = curve.slope.unwrap();
            assert!((s + 0.5).abs() < 0.1, "{}: slope {s}", curve.strategy);
        }
        let furnace = Light::Constant(Rgb::ONE);
        let target = luminance(reference(&m, &sp, &furnace, REFERENCE_TOLERANCE));
        let exact = curves(
            &m,
            &sp,
            &furnace,
            target,
            &[(BsdfStrategy::Cosine.into(), Sequence::Independent)],
            settings,
            &(),
        )
        .unwrap();
        assert!(exact[0].points.iter().all(|p| p.1 < 1e-12), "{exact:?}");
    }
}
