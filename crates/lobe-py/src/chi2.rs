//! `lobe.chi2`'s statistics: lobe's own harness ([`lobe::stats::chi2`]) fed
//! with samples drawn and cell probabilities integrated outside it (by a
//! Python sampler and a vectorized pdf), so that the histogram, the lost
//! bin, the pooling of small cells, the hard failures and the p-value are
//! exactly the Rust test's.

use glam::{DVec2, DVec3};
use lobe::stats::chi2::{Chi2Result, Chi2Settings, chi2_test_cells};
use lobe::stats::quadrature::Estimate;
use rand::{RngExt, SeedableRng};
use std::cell::Cell;

/// The uniforms the harness draws for `samples` samples with `seed`: per
/// sample `(uc, u.x, u.y)`, in that order, from `Pcg64::seed_from_u64(seed)`.
#[must_use]
pub fn uniforms(seed: u64, samples: usize) -> Vec<[f64; 3]> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    (0..samples)
        .map(|_| {
            let uc: f64 = rng.random();
            let ux: f64 = rng.random();
            let uy: f64 = rng.random();
            [uc, ux, uy]
        })
        .collect()
}

/// Runs [`chi2_test_cells`] on precomputed samples: `dirs[i]` is sample `i`'s
/// direction, or `None` for a lost (failed) sample; `cell_probs` is the
/// pdf's integral over each cell, row-major `n_z × n_phi` (cell `(iz, iphi)`
/// at `iz * n_phi + iphi`), with its error estimate in `cell_errors`.
#[must_use]
pub fn test_cells(
    n_z: usize,
    n_phi: usize,
    min_expected: f64,
    dirs: &[Option<DVec3>],
    cell_probs: &[f64],
    cell_errors: &[f64],
) -> Chi2Result {
    let cfg = Chi2Settings {
        n_z,
        n_phi,
        samples: dirs.len(),
        seed: 0,
        min_expected,
        max_evals_per_cell: 0,
    };
    debug_assert_eq!(cell_probs.len(), n_z * n_phi);
    let next = Cell::new(0usize);
    let sample = |_: f64, _: DVec2| {
        let i = next.get();
        next.set(i + 1);
        dirs[i]
    };
    chi2_test_cells(&cfg, sample, |z0, z1, p0, p1| {
        // The cell whose bounds these are (its centre lies inside it).
        let zc = 0.5 * (z0 + z1);
        let pc = 0.5 * (p0 + p1);
        let r = (1.0 - zc * zc).max(0.0).sqrt();
        let (iz, ip) = cfg.cell_of(DVec3::new(r * pc.cos(), r * pc.sin(), zc));
        let k = iz * n_phi + ip;
        let value = cell_probs[k];
        let error = cell_errors[k];
        Estimate {
            value,
            error,
            evals: 0,
            converged: value.is_finite() && error.is_finite(),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_1_PI, TAU};

    /// The same result as the harness on its own when the cell
    /// probabilities are exact: cosine sampling, closed-form cells.
    #[test]
    fn equals_the_harness() {
        let cfg = Chi2Settings {
            n_z: 20,
            n_phi: 40,
            samples: 100_000,
            seed: 3,
            ..Chi2Settings::default()
        };
        let cosine = |u: DVec2| {
            let r = u.x.sqrt();
            let phi = TAU * u.y;
            Some(DVec3::new(
                r * phi.cos(),
                r * phi.sin(),
                (1.0 - u.x).max(0.0).sqrt(),
            ))
        };
        let cell = |z0: f64, z1: f64, p0: f64, p1: f64| {
            let (a, b) = (z0.max(0.0), z1.max(0.0));
            (b * b - a * a) * 0.5 * (p1 - p0) * FRAC_1_PI
        };
        let direct = chi2_test_cells(
            &cfg,
            |_, u| cosine(u),
            |z0, z1, p0, p1| Estimate {
                value: cell(z0, z1, p0, p1),
                error: 0.0,
                evals: 0,
                converged: true,
            },
        );
        let dirs: Vec<_> = uniforms(cfg.seed, cfg.samples)
            .into_iter()
            .map(|[_, x, y]| cosine(DVec2::new(x, y)))
            .collect();
        let mut probs = vec![0.0; 800];
        for iz in 0..20 {
            for ip in 0..40 {
                let (z0, z1, p0, p1) = cfg.cell_bounds(iz, ip);
                probs[iz * 40 + ip] = cell(z0, z1, p0, p1);
            }
        }
        let ours = test_cells(20, 40, cfg.min_expected, &dirs, &probs, &vec![0.0; 800]);
        assert_eq!(ours, direct);
        assert!(
            ours.passes(0.01),
            "{} {} {} {:?}",
            ours.p_value,
            ours.statistic,
            ours.dof,
            ours.message
        );
        // A wrong pdf (uniform hemisphere) fails.
        let wrong = vec![1.0 / 1600.0; 800];
        let bad = test_cells(20, 40, 5.0, &dirs, &wrong, &vec![0.0; 800]);
        assert!(!bad.passes(0.01), "{bad:?}");
    }
}
