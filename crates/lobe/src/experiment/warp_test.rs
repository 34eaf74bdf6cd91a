//! Nori's warp test of one sampler at one view: the projected histograms
//! of its draws beside the counts its pdf expects, and the chi-square test
//! of the draws against the pdf over the whole sphere (`lobe plot --kind
//! histogram`, `lobe report`, Python). One library call, so that every
//! front end runs the same test.

use super::histogram::{Histograms, projected_histograms};
use crate::progress::Progress;
use crate::stats::chi2::{Chi2Result, Chi2Settings, TABLE_MAX_EVALS_PER_CELL, chi2_test};
use crate::{BsdfSampler, Material};
use glam::DVec3;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// The chi-square configuration that suits the samplers of `m`: the
/// default, with [`TABLE_MAX_EVALS_PER_CELL`] for a measured table (whose
/// piecewise-constant pdf a cell straddling a bin edge would otherwise
/// refine along at length).
#[must_use]
pub fn chi2_config(m: &Material) -> Chi2Settings {
    let base = Chi2Settings::default();
    if m.measured().is_some() {
        Chi2Settings {
            max_evals_per_cell: TABLE_MAX_EVALS_PER_CELL,
            ..base
        }
    } else {
        base
    }
}

/// The chi-square bins (in `z` and in `φ`) of [`interactive_config`].
pub const INTERACTIVE_BINS: usize = 16;

/// [`chi2_config`] with `samples` draws and [`INTERACTIVE_BINS`]² bins, as
/// `lobe report --quick` has them: a test that answers while a slider
/// moves (`lobe explore`, Python's `lobe.warp_test`).
#[must_use]
pub fn interactive_config(m: &Material, samples: usize) -> Chi2Settings {
    Chi2Settings {
        n_z: INTERACTIVE_BINS,
        n_phi: INTERACTIVE_BINS,
        samples,
        ..chi2_config(m)
    }
}

/// What [`warp_test`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct WarpTest {
    /// The draws and the expected counts over the projected hemisphere
    /// (both hemispheres where the material transmits).
    pub histograms: Histograms,
    /// The chi-square test over the sphere.
    pub chi2: Chi2Result,
    /// The test's configuration (bins, samples, seed).
    pub config: Chi2Settings,
}

/// The warp test of `sampler` at `wo`: `config.samples` draws from
/// `config.seed` into a `res × res` histogram over the projected
/// hemisphere ([`projected_histograms`]), and the chi-square test with
/// `config` ([`chi2_test`]; [`chi2_config`] gives the one that suits a
/// material). Progress: the task `histogram` (its draws), then
/// `chi-square` (its draws), then `chi-square: expected` (the cubature of
/// the expected counts, of no steps).
#[must_use]
pub fn warp_test(
    sampler: &BsdfSampler<'_>,
    wo: DVec3,
    config: Chi2Settings,
    res: usize,
    progress: &dyn Progress,
) -> WarpTest {
    const STEP: u64 = 1 << 16;
    let histograms = projected_histograms(sampler, wo, config.samples, config.seed, res, progress);
    progress.start("chi-square", config.samples as u64);
    let drawn = AtomicU64::new(0);
    let integrating = AtomicBool::new(false);
    let chi2 = chi2_test(
        &config,
        |uc, u| {
            if drawn.fetch_add(1, Ordering::Relaxed) % STEP == STEP - 1 {
                progress.advance(STEP);
            }
            // A delta part has no density: its samples count as lost, as
            // the pdf leaves them out.
            sampler
                .sample(wo, uc, u)
                .filter(|x| !x.scattering.is_specular())
                .map(|x| x.wi)
        },
        |wi| {
            // The first pdf call starts the cubature of the expected counts.
            if !integrating.load(Ordering::Relaxed) && !integrating.swap(true, Ordering::Relaxed) {
                progress.start("chi-square: expected", 0);
            }
            sampler.pdf(wo, wi)
        },
    );
    WarpTest {
        histograms,
        chi2,
        config,
    }
}
