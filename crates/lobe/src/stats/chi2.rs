//! Chi-square goodness-of-fit test of a direction sampler against its pdf.
//!
//! The sphere is cut into an equal-area histogram: `n_z` bins uniform in
//! `z = cos(theta) ∈ [−1, 1]` times `n_phi` bins uniform in
//! `phi = atan2(y, x) ∈ [0, 2π)`. The sampler fills the histogram from a
//! seeded PCG stream; the expected count of every cell is the number of
//! samples times the integral of the pdf over the cell, computed with the
//! adaptive cubature of [`super::quadrature`]. Failed samples (`None`) go into
//! a separate *lost* bin whose expected count is what the pdf does not cover:
//! `samples × (1 − ∫ pdf dω)`.
//!
//! Bins whose expected count is below `min_expected` are pooled into one bin,
//! and the statistic `Σ (O − E)² / E` is compared with a chi-square
//! distribution with `bins − 1` degrees of freedom.

use super::quadrature::{Estimate, Tolerance, integrate_sphere_region_many};
use glam::{DVec2, DVec3};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::cell::Cell;
use std::f64::consts::TAU;
use std::fmt::Write as _;
use std::io::{BufWriter, Write as _};
use std::path::Path;

/// Probability below which a bin counts as impossible: a sample observed
/// there fails the test outright.
const ZERO_PROBABILITY: f64 = 1e-12;

/// Largest accepted `| |ω| − 1 |` of a sampled direction.
const UNIT_TOLERANCE: f64 = 1e-6;

/// Per-cell cubature tolerance: about 1e-10 absolute probability, with at
/// most `max_evals` pdf evaluations per cell.
fn cell_tolerance(max_evals: usize) -> Tolerance {
    Tolerance::new(1e-10, 1e-8).with_max_evals(max_evals)
}

/// Settings of [`chi2_test`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chi2Settings {
    /// Number of bins in `z = cos(theta)` over the whole sphere `[−1, 1]`.
    pub n_z: usize,
    /// Number of bins in `phi` over `[0, 2π)`.
    pub n_phi: usize,
    /// Number of samples drawn (failed ones included).
    pub samples: usize,
    /// Seed of the `Pcg64` stream the uniforms come from.
    pub seed: u64,
    /// Bins expecting fewer counts than this are pooled together.
    pub min_expected: f64,
    /// Pdf evaluations allowed per cell for its expected count. A pdf with
    /// discontinuities inside cells (an environment map's texel edges) makes
    /// the adaptive rule refine along them; a smaller budget keeps it fast at
    /// a still negligible error.
    pub max_evals_per_cell: usize,
}

impl Default for Chi2Settings {
    /// 100 `z` bins (so `50 × 100` cells on the upper hemisphere), 100 `phi`
    /// bins, one million samples, `min_expected = 5`.
    fn default() -> Self {
        Self {
            n_z: 100,
            n_phi: 100,
            samples: 1_000_000,
            seed: 0x5eed_1ab0_c0ff_ee00,
            min_expected: 5.0,
            max_evals_per_cell: 250_000,
        }
    }
}

/// [`Chi2Settings::max_evals_per_cell`] for a measured table's samplers:
/// their pdfs are piecewise constant (or piecewise smooth), so a cell that
/// straddles a bin edge would spend the default budget refining along it.
/// With 4000 evaluations per cell the tables' chi-square tests
/// (`crates/lobe/tests/integration/measured.rs`) pass at 400 000 samples.
pub const TABLE_MAX_EVALS_PER_CELL: usize = 4000;

impl Chi2Settings {
    /// Bounds `(z0, z1, phi0, phi1)` of cell `(iz, iphi)`.
    #[must_use]
    pub fn cell_bounds(&self, iz: usize, iphi: usize) -> (f64, f64, f64, f64) {
        let nz = self.n_z.max(1) as f64;
        let np = self.n_phi.max(1) as f64;
        let z = |i: usize| {
            if i >= self.n_z {
                1.0
            } else {
                -1.0 + 2.0 * (i as f64 / nz)
            }
        };
        let p = |i: usize| {
            if i >= self.n_phi {
                TAU
            } else {
                TAU * (i as f64 / np)
            }
        };
        (z(iz), z(iz + 1), p(iphi), p(iphi + 1))
    }

    /// The cell `(iz, iphi)` containing the unit direction `w`.
    #[must_use]
    pub fn cell_of(&self, w: DVec3) -> (usize, usize) {
        let nz = self.n_z.max(1);
        let np = self.n_phi.max(1);
        let z = w.z.clamp(-1.0, 1.0);
        let iz = ((z + 1.0) * 0.5 * nz as f64) as usize;
        let mut phi = w.y.atan2(w.x);
        if phi < 0.0 {
            phi += TAU;
        }
        let ip = (phi / TAU * np as f64) as usize;
        (iz.min(nz - 1), ip.min(np - 1))
    }
}

/// Outcome of [`chi2_test`].
#[derive(Clone, Debug, PartialEq)]
pub struct Chi2Result {
    /// `Σ (O − E)² / E` over the bins after pooling (infinite on a hard
    /// failure).
    pub statistic: f64,
    /// Degrees of freedom: number of bins after pooling, minus one.
    pub dof: usize,
    /// Survival function of the chi-square distribution at `statistic`; 0 on
    /// a hard failure (see `message`).
    pub p_value: f64,
    /// Observed counts, row-major `n_z × n_phi`: cell `(iz, iphi)` at
    /// `iz * n_phi + iphi`.
    pub observed: Vec<f64>,
    /// Expected counts, laid out as `observed`.
    pub expected: Vec<f64>,
    /// Number of failed samples (`None`).
    pub lost_observed: f64,
    /// Expected number of failed samples, `samples × max(0, 1 − pdf_integral)`.
    pub lost_expected: f64,
    /// Sum over the cells of `∫ pdf dω`: the pdf's integral over the sphere.
    pub pdf_integral: f64,
    /// Why the test failed outright, and notes (pooling, cubature that did
    /// not converge, a pdf integrating above one); `None` when there is
    /// nothing to say.
    pub message: Option<String>,
}

impl Chi2Result {
    /// Whether the sampler is accepted at significance level `alpha`
    /// (`p_value > alpha`; a hard failure has `p_value = 0` and never passes).
    #[must_use]
    pub fn passes(&self, alpha: f64) -> bool {
        self.p_value > alpha
    }

    /// Writes the histogram as CSV with the header
    /// `iz,iphi,z0,z1,phi0,phi1,observed,expected`, one line per cell, then a
    /// last line `lost,,,,,,<observed>,<expected>` for the lost bin.
    ///
    /// `cfg` must be the configuration the result was computed with.
    ///
    /// # Errors
    ///
    /// I/O errors, and `InvalidInput` when the table sizes do not match `cfg`.
    pub fn write_tables(&self, cfg: &Chi2Settings, path: &Path) -> std::io::Result<()> {
        let cells = cfg.n_z.checked_mul(cfg.n_phi);
        if cells != Some(self.observed.len()) || self.expected.len() != self.observed.len() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "chi-square tables do not match the configuration",
            ));
        }
        let mut out = BufWriter::new(std::fs::File::create(path)?);
        writeln!(out, "iz,iphi,z0,z1,phi0,phi1,observed,expected")?;
        for iz in 0..cfg.n_z {
            for ip in 0..cfg.n_phi {
                let (z0, z1, p0, p1) = cfg.cell_bounds(iz, ip);
                let k = iz * cfg.n_phi + ip;
                writeln!(
                    out,
                    "{iz},{ip},{z0},{z1},{p0},{p1},{},{}",
                    self.observed[k], self.expected[k]
                )?;
            }
        }
        writeln!(
            out,
            "lost,,,,,,{},{}",
            self.lost_observed, self.lost_expected
        )?;
        out.flush()
    }
}

/// Šidák-corrected significance level for each of `tests` independent tests
/// so that the family-wise level is `alpha`: `1 − (1 − alpha)^(1/tests)`.
///
/// Computed as `−expm1(ln_1p(−alpha) / tests)`, accurate for tiny `alpha`.
/// `tests == 0` is treated as one test.
#[must_use]
pub fn sidak(alpha: f64, tests: usize) -> f64 {
    let n = tests.max(1) as f64;
    -((-alpha).ln_1p() / n).exp_m1()
}

/// Deterministic probability that a sample is not lost.
///
/// For each `(weight, uc)` in `lobes`, counts the midpoints
/// `u = ((i + ½)/grid, (j + ½)/grid)` of a `grid × grid` lattice where
/// `sample(uc, u)` succeeds and returns `Σ weight × (fraction of lattice
/// points that succeed)`. Compare it with the pdf's integral over the sphere.
/// `grid == 0` is read as one; a lobe of weight 0 is not run (it adds
/// nothing).
///
/// The lattice is counted adaptively: it is cut into at most 64 × 64 tiles,
/// and a tile whose four corner points and centre point all agree is
/// counted whole; otherwise it is split in four, down to tiles of at most
/// 4 × 4 points, which are counted point by point. The count is that of
/// every point except where a lost (or kept) region lies wholly inside a
/// tile without touching its corners or centre, that is, a region smaller
/// than a 64th of the square on a side: at most about 2.4e-4 of the
/// probability per such island. The cost is that of the region's boundary,
/// a few percent of `grid²` calls for a 1024 lattice.
#[must_use]
pub fn success_probability(
    sample: impl Fn(f64, DVec2) -> bool,
    lobes: &[(f64, f64)],
    grid: usize,
) -> f64 {
    let g = grid.max(1);
    let total = (g * g) as f64;
    lobes
        .iter()
        .filter(|&&(weight, _)| weight != 0.0)
        .map(|&(weight, uc)| weight * (lattice_hits(|u| sample(uc, u), g) as f64 / total))
        .sum()
}

/// Number of midpoints of the `g × g` lattice where `hit` is true, counted
/// as [`success_probability`] describes.
fn lattice_hits(hit: impl Fn(DVec2) -> bool, g: usize) -> usize {
    let inv = 1.0 / g as f64;
    let at = |i: usize, j: usize| hit(DVec2::new((i as f64 + 0.5) * inv, (j as f64 + 0.5) * inv));
    // Points of the half-open index rectangle [i0, i1) × [j0, j1) that hit.
    fn count(
        at: &impl Fn(usize, usize) -> bool,
        i0: usize,
        i1: usize,
        j0: usize,
        j1: usize,
    ) -> usize {
        let (w, h) = (i1 - i0, j1 - j0);
        if w == 0 || h == 0 {
            return 0;
        }
        if w <= 4 && h <= 4 {
            return (i0..i1)
                .flat_map(|i| (j0..j1).map(move |j| (i, j)))
                .filter(|&(i, j)| at(i, j))
                .count();
        }
        let first = at(i0, j0);
        let uniform = [
            (i1 - 1, j0),
            (i0, j1 - 1),
            (i1 - 1, j1 - 1),
            ((i0 + i1) / 2, (j0 + j1) / 2),
        ]
        .iter()
        .all(|&(i, j)| at(i, j) == first);
        if uniform {
            return if first { w * h } else { 0 };
        }
        let (im, jm) = ((i0 + i1) / 2, (j0 + j1) / 2);
        count(at, i0, im, j0, jm)
            + count(at, im, i1, j0, jm)
            + count(at, i0, im, jm, j1)
            + count(at, im, i1, jm, j1)
    }
    let tiles = g.min(64);
    let edge = |k: usize| k * g / tiles;
    (0..tiles)
        .flat_map(|a| (0..tiles).map(move |b| (a, b)))
        .map(|(a, b)| count(&at, edge(a), edge(a + 1), edge(b), edge(b + 1)))
        .sum()
}

/// Runs the chi-square goodness-of-fit test of `sample` against `pdf`.
///
/// `sample(uc, u)` receives three independent uniforms in `[0, 1)` drawn in
/// that order (`uc`, `u.x`, `u.y`) from `Pcg64::seed_from_u64(cfg.seed)`, so
/// the test is deterministic for a seed. `pdf` is a density in solid angle
/// over the whole sphere; it may integrate to less than one, the rest being
/// the probability that a sample is lost (`None`).
///
/// The test fails outright (`p_value = 0`, `statistic = ∞`, with a
/// `message`) when the pdf is negative or not finite somewhere it is
/// evaluated, when a sampled direction is not finite or not of unit length
/// (within 1e-6), when a bin whose probability is below 1e-12 receives a
/// sample, or when the configuration is empty (`n_z`, `n_phi` or `samples`
/// zero).
///
/// Bins (cells and the lost bin) expecting fewer than `cfg.min_expected`
/// counts are pooled into one bin; if that pooled bin still expects fewer
/// than `min_expected`, it is merged into the kept bin with the smallest
/// expectation, so that no observed mass escapes the statistic.
#[must_use]
pub fn chi2_test(
    cfg: &Chi2Settings,
    sample: impl Fn(f64, DVec2) -> Option<DVec3>,
    pdf: impl Fn(DVec3) -> f64,
) -> Chi2Result {
    chi2_test_many(cfg, sample, |dirs, out| {
        for (p, &w) in out.iter_mut().zip(dirs) {
            *p = pdf(w);
        }
    })
}

/// [`chi2_test`] with a pdf evaluated many directions at a time:
/// `pdf(dirs, out)` sets `out[i]` to the density at `dirs[i]` (up to 225
/// directions a call, the nodes of one cubature rectangle). Same test, same
/// numbers; for batch kernels, whose cost per call is far above their cost
/// per lane.
#[must_use]
pub fn chi2_test_many(
    cfg: &Chi2Settings,
    sample: impl Fn(f64, DVec2) -> Option<DVec3>,
    pdf: impl Fn(&[DVec3], &mut [f64]),
) -> Chi2Result {
    let bad_pdf: Cell<Option<(DVec3, f64)>> = Cell::new(None);
    let checked_pdf = |dirs: &[DVec3], out: &mut [f64]| {
        pdf(dirs, out);
        for (p, &w) in out.iter_mut().zip(dirs) {
            if !(*p >= 0.0 && p.is_finite()) {
                if bad_pdf.get().is_none() {
                    bad_pdf.set(Some((w, *p)));
                }
                *p = 0.0;
            }
        }
    };
    let tol = cell_tolerance(cfg.max_evals_per_cell);
    let mut result = chi2_test_cells(cfg, sample, |z0, z1, p0, p1| {
        // theta decreases with z.
        let theta = (z1.clamp(-1.0, 1.0).acos(), z0.clamp(-1.0, 1.0).acos());
        integrate_sphere_region_many(checked_pdf, theta, (p0, p1), tol)
    });
    if let Some((w, p)) = bad_pdf.get() {
        let msg = format!("pdf({w}) = {p} is not a finite non-negative number");
        result.statistic = f64::INFINITY;
        result.p_value = 0.0;
        result.message = Some(match result.message.take() {
            Some(m) => format!("{msg}; {m}"),
            None => msg,
        });
    }
    result
}

/// [`chi2_test`] with the probability of each cell given by `cell_probability(z0,
/// z1, phi0, phi1)` instead of a cubature of a pdf: for samplers whose
/// cell probabilities are known in closed form (a piecewise-constant
/// environment map whose texels line up with the cells).
#[must_use]
pub fn chi2_test_cells(
    cfg: &Chi2Settings,
    sample: impl Fn(f64, DVec2) -> Option<DVec3>,
    mut cell_probability: impl FnMut(f64, f64, f64, f64) -> Estimate,
) -> Chi2Result {
    let (nz, np) = (cfg.n_z, cfg.n_phi);
    let Some(ncells) = nz.checked_mul(np).filter(|&n| n > 0 && cfg.samples > 0) else {
        return Chi2Result {
            statistic: f64::INFINITY,
            dof: 0,
            p_value: 0.0,
            observed: Vec::new(),
            expected: Vec::new(),
            lost_observed: 0.0,
            lost_expected: 0.0,
            pdf_integral: 0.0,
            message: Some("invalid configuration: n_z, n_phi and samples must be > 0".into()),
        };
    };
    let n = cfg.samples as f64;
    let mut failures: Vec<String> = Vec::new();
    let mut notes: Vec<String> = Vec::new();

    // Histogram of the sampler.
    let mut observed = vec![0.0; ncells];
    let mut lost_observed = 0.0;
    let mut invalid = 0usize;
    let mut first_invalid = None;
    let mut rng = Pcg64::seed_from_u64(cfg.seed);
    for i in 0..cfg.samples {
        let uc: f64 = rng.random();
        let ux: f64 = rng.random();
        let uy: f64 = rng.random();
        let u = DVec2::new(ux, uy);
        match sample(uc, u) {
            None => lost_observed += 1.0,
            Some(w) => {
                if w.is_finite() && (w.length() - 1.0).abs() <= UNIT_TOLERANCE {
                    let (iz, ip) = cfg.cell_of(w);
                    observed[iz * np + ip] += 1.0;
                } else {
                    invalid += 1;
                    first_invalid.get_or_insert((i, uc, u, w));
                }
            }
        }
    }
    if let Some((i, uc, u, w)) = first_invalid {
        failures.push(format!(
            "{invalid} sampled directions are not finite unit vectors; first: sample {i}, \
             uc = {uc}, u = ({}, {}) gave {w}",
            u.x, u.y
        ));
    }

    // Expected counts from each cell's probability.
    let mut expected = vec![0.0; ncells];
    let mut probs = vec![0.0; ncells];
    let mut unconverged = 0usize;
    let mut worst_error: f64 = 0.0;
    for iz in 0..nz {
        for ip in 0..np {
            let (z0, z1, p0, p1) = cfg.cell_bounds(iz, ip);
            let est = cell_probability(z0, z1, p0, p1);
            if !est.converged {
                unconverged += 1;
                worst_error = worst_error.max(est.error);
            }
            let k = iz * np + ip;
            probs[k] = est.value.max(0.0);
            expected[k] = n * probs[k];
        }
    }
    if unconverged > 0 {
        notes.push(format!(
            "cubature did not converge in {unconverged} cells (largest error estimate {worst_error:e})"
        ));
    }
    let pdf_integral: f64 = probs.iter().sum();
    if pdf_integral > 1.0 + 1e-6 {
        notes.push(format!("pdf integrates to {pdf_integral} > 1"));
    }
    let lost_prob = (1.0 - pdf_integral).max(0.0);
    let lost_expected = n * lost_prob;

    // Observations where the pdf has no mass.
    let mut impossible = 0.0;
    let mut first_impossible = None;
    for (k, (&o, &p)) in observed.iter().zip(&probs).enumerate() {
        if o > 0.0 && p <= ZERO_PROBABILITY {
            impossible += o;
            first_impossible.get_or_insert(k);
        }
    }
    if let Some(k) = first_impossible {
        let (iz, ip) = (k / np, k % np);
        let (z0, z1, p0, p1) = cfg.cell_bounds(iz, ip);
        failures.push(format!(
            "{impossible} samples fell where the pdf integrates to ~0; first cell ({iz}, {ip}) \
             z ∈ [{z0}, {z1}], phi ∈ [{p0}, {p1}] with {} samples and probability {:e}",
            observed[k], probs[k]
        ));
    }
    if lost_observed > 0.0 && lost_prob <= ZERO_PROBABILITY {
        failures.push(format!(
            "{lost_observed} samples were lost but the pdf integrates to {pdf_integral}"
        ));
    }

    let mut result = Chi2Result {
        statistic: f64::INFINITY,
        dof: 0,
        p_value: 0.0,
        observed,
        expected,
        lost_observed,
        lost_expected,
        pdf_integral,
        message: None,
    };

    if failures.is_empty() {
        let (statistic, dof, p_value) = pooled_statistic(&result, cfg.min_expected, &mut notes);
        result.statistic = statistic;
        result.dof = dof;
        result.p_value = p_value;
    }
    failures.extend(notes);
    if !failures.is_empty() {
        let mut msg = String::new();
        for (i, m) in failures.iter().enumerate() {
            if i > 0 {
                msg.push_str("; ");
            }
            let _ = write!(msg, "{m}");
        }
        result.message = Some(msg);
    }
    result
}

/// Pools the bins, computes the statistic, its degrees of freedom and p-value.
fn pooled_statistic(
    r: &Chi2Result,
    min_expected: f64,
    notes: &mut Vec<String>,
) -> (f64, usize, f64) {
    let min_e = if min_expected.is_nan() {
        0.0
    } else {
        min_expected
    };
    let mut kept: Vec<(f64, f64)> = Vec::new(); // (observed, expected)
    let (mut pool_o, mut pool_e, mut pooled) = (0.0, 0.0, 0usize);
    let bins = r
        .observed
        .iter()
        .zip(&r.expected)
        .map(|(&o, &e)| (o, e))
        .chain(std::iter::once((r.lost_observed, r.lost_expected)));
    for (o, e) in bins {
        if e < min_e || e <= 0.0 {
            pool_o += o;
            pool_e += e;
            pooled += 1;
        } else {
            kept.push((o, e));
        }
    }
    if pooled > 0 {
        if pool_e >= min_e && pool_e > 0.0 {
            kept.push((pool_o, pool_e));
        } else if pool_o > 0.0 || pool_e > 0.0 {
            if let Some(smallest) = kept.iter_mut().min_by(|a, b| a.1.total_cmp(&b.1)) {
                smallest.0 += pool_o;
                smallest.1 += pool_e;
                if pool_o > 0.0 {
                    notes.push(format!(
                        "{pooled} pooled bins expected only {pool_e:.3} (observed {pool_o}); \
                         merged into the smallest kept bin"
                    ));
                }
            } else {
                kept.push((pool_o, pool_e));
            }
        }
    }
    let statistic: f64 = kept
        .iter()
        .filter(|&&(_, e)| e > 0.0)
        .map(|&(o, e)| (o - e) * (o - e) / e)
        .sum();
    let dof = kept.len().saturating_sub(1);
    if dof == 0 {
        notes.push("fewer than two bins after pooling: no test possible".into());
        return (statistic, 0, 1.0);
    }
    let p = match ChiSquared::new(dof as f64) {
        Ok(d) => d.sf(statistic),
        Err(_) => f64::NAN,
    };
    (statistic, dof, p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_1_PI, PI};

    fn uniform_sphere(u: DVec2) -> DVec3 {
        let z = 1.0 - 2.0 * u.x;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = TAU * u.y;
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    fn cosine_hemisphere(u: DVec2) -> DVec3 {
        let r = u.x.sqrt();
        let phi = TAU * u.y;
        let z = (1.0 - u.x).max(0.0).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    fn cosine_pdf(w: DVec3) -> f64 {
        w.z.max(0.0) * FRAC_1_PI
    }

    const UNIFORM_PDF: f64 = 0.25 * FRAC_1_PI;

    #[test]
    fn uniform_sphere_passes() {
        let cfg = Chi2Settings::default();
        let r = chi2_test(&cfg, |_, u| Some(uniform_sphere(u)), |_| UNIFORM_PDF);
        assert!(r.passes(0.01), "{r:?}");
        assert!((r.pdf_integral - 1.0).abs() < 1e-9, "{}", r.pdf_integral);
        // 10 000 cells; the lost bin expects ~0 and is merged into one.
        assert_eq!(r.dof, 100 * 100 - 1);
        assert_eq!(r.message, None);
        assert_eq!(r.lost_observed, 0.0);
        assert_eq!(r.observed.iter().sum::<f64>(), 1e6);
    }

    #[test]
    fn cosine_hemisphere_passes() {
        let cfg = Chi2Settings::default();
        let r = chi2_test(&cfg, |_, u| Some(cosine_hemisphere(u)), cosine_pdf);
        assert!(r.passes(0.01), "{r:?}");
        assert!((r.pdf_integral - 1.0).abs() < 1e-9);
        // The lowest upper row (z < 0.02, 4 counts per cell), the lower
        // hemisphere and the lost bin are pooled: 4900 cells + 1 pooled bin.
        assert_eq!(r.dof, 4900);
        // The expected counts match the closed form per cell: N/(2π n_phi)
        // · π (z1² − z0²) for z ≥ 0.
        let k = 75 * 100 + 3;
        let (z0, z1, _, _) = cfg.cell_bounds(75, 3);
        let exact = 1e6 * (z1 * z1 - z0 * z0) / 100.0;
        assert!(
            (r.expected[k] - exact).abs() < 1e-6,
            "{} {exact}",
            r.expected[k]
        );
    }

    #[test]
    fn wrong_pdf_fails() {
        let cfg = Chi2Settings::default();
        // Cosine samples against the uniform-hemisphere pdf.
        let r = chi2_test(
            &cfg,
            |_, u| Some(cosine_hemisphere(u)),
            |w| if w.z >= 0.0 { 0.5 * FRAC_1_PI } else { 0.0 },
        );
        assert!(r.p_value < 1e-6, "{r:?}");
        assert!(!r.passes(0.01));
        // Cosine samples against the uniform-sphere pdf: mass below the
        // horizon is never sampled.
        let r = chi2_test(&cfg, |_, u| Some(cosine_hemisphere(u)), |_| UNIFORM_PDF);
        assert!(r.p_value < 1e-6, "{r:?}");
    }

    #[test]
    fn slightly_wrong_pdf_fails() {
        // A cosine-power lobe sampled with exponent 10 and tested with 11.
        let sample = |e: f64| {
            move |_: f64, u: DVec2| {
                let z = (1.0 - u.x).powf(1.0 / (e + 1.0));
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = TAU * u.y;
                Some(DVec3::new(r * phi.cos(), r * phi.sin(), z))
            }
        };
        let pdf = |e: f64| move |w: DVec3| (e + 1.0) / TAU * w.z.max(0.0).powf(e);
        let cfg = Chi2Settings::default();
        assert!(chi2_test(&cfg, sample(10.0), pdf(10.0)).passes(0.01));
        assert!(chi2_test(&cfg, sample(10.0), pdf(11.0)).p_value < 1e-6);
    }

    #[test]
    fn lost_samples_are_accounted_for() {
        let cfg = Chi2Settings::default();
        let sample = |uc: f64, u: DVec2| (uc >= 0.5).then(|| cosine_hemisphere(u));
        let r = chi2_test(&cfg, sample, |w| 0.5 * cosine_pdf(w));
        assert!(r.passes(0.01), "{r:?}");
        assert!((r.lost_expected - 5e5).abs() < 1e-2);
        assert!((r.lost_observed - 5e5).abs() < 5e3);
        // The same sampler against the un-halved pdf.
        let r = chi2_test(&cfg, sample, cosine_pdf);
        assert_eq!(r.p_value, 0.0, "{r:?}");
        assert!(r.message.as_deref().unwrap().contains("lost"));
        // And against a pdf halved too much.
        let r = chi2_test(&cfg, sample, |w| 0.45 * cosine_pdf(w));
        assert!(r.p_value < 1e-6, "{r:?}");
    }

    /// Phong-like lobe `(n+1)/(2π) cos^n` around an axis tilted by `tilt`
    /// about `y`: a sampler (`None` below the horizon) and its pdf.
    fn tilted_lobe(
        n: f64,
        tilt: f64,
    ) -> (
        impl Fn(f64, DVec2) -> Option<DVec3> + Copy,
        impl Fn(DVec3) -> f64 + Copy,
    ) {
        let (st, ct) = tilt.sin_cos();
        let axis = DVec3::new(st, 0.0, ct);
        let sample = move |_: f64, u: DVec2| {
            let z = (1.0 - u.x).powf(1.0 / (n + 1.0));
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = TAU * u.y;
            let l = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            let w = DVec3::new(l.x * ct + l.z * st, l.y, -l.x * st + l.z * ct);
            (w.z > 0.0).then_some(w)
        };
        let pdf = move |w: DVec3| {
            if w.z > 0.0 {
                (n + 1.0) / TAU * w.dot(axis).max(0.0).powf(n)
            } else {
                0.0
            }
        };
        (sample, pdf)
    }

    #[test]
    fn narrow_tilted_lobe_passes_and_detects_a_small_error() {
        let cfg = Chi2Settings::default();
        let (sample, pdf) = tilted_lobe(1e4, 40f64.to_radians());
        let r = chi2_test(&cfg, sample, pdf);
        assert!(r.passes(0.01), "{r:?}");
        assert!((r.pdf_integral - 1.0).abs() < 1e-8, "{}", r.pdf_integral);
        // Tested against a lobe 2 % narrower.
        let (_, narrower) = tilted_lobe(1.02e4, 40f64.to_radians());
        assert!(chi2_test(&cfg, sample, narrower).p_value < 1e-6);
    }

    #[test]
    fn lobe_clipped_by_the_horizon() {
        // A wide lobe tilted by 70°: a good part of it is lost below the
        // horizon, and the pdf integrates to the success probability.
        let cfg = Chi2Settings::default();
        let (sample, pdf) = tilted_lobe(10.0, 70f64.to_radians());
        let r = chi2_test(&cfg, sample, pdf);
        assert!(r.passes(0.01), "{r:?}");
        assert!(r.lost_expected > 5e4, "{r:?}");
        let success = success_probability(|uc, u| sample(uc, u).is_some(), &[(1.0, 0.5)], 2000);
        assert!(
            (success - r.pdf_integral).abs() < 1e-4,
            "{success} vs {}",
            r.pdf_integral
        );
    }

    /// Prints how long default-config tests take:
    /// `cargo test -p lobe --lib chi2_timings -- --ignored --nocapture`.
    #[test]
    #[ignore = "timing report, not a check"]
    fn chi2_timings() {
        let cfg = Chi2Settings::default();
        let time = |name: &str, f: &dyn Fn() -> Chi2Result| {
            let t = std::time::Instant::now();
            let r = f();
            eprintln!(
                "{name}: {:.3} s, p = {:.4}, dof = {}",
                t.elapsed().as_secs_f64(),
                r.p_value,
                r.dof
            );
        };
        time("uniform sphere", &|| {
            chi2_test(&cfg, |_, u| Some(uniform_sphere(u)), |_| UNIFORM_PDF)
        });
        time("cosine hemisphere", &|| {
            chi2_test(&cfg, |_, u| Some(cosine_hemisphere(u)), cosine_pdf)
        });
        let (s, p) = tilted_lobe(1e4, 40f64.to_radians());
        time("lobe n=1e4 tilted 40°", &|| chi2_test(&cfg, s, p));
        let (s, p) = tilted_lobe(10.0, 70f64.to_radians());
        time("lobe n=10 tilted 70°, clipped", &|| chi2_test(&cfg, s, p));
        let t = std::time::Instant::now();
        let mut rng = Pcg64::seed_from_u64(1);
        let mut acc = DVec3::ZERO;
        for _ in 0..cfg.samples {
            let u = DVec2::new(rng.random(), rng.random());
            let _: f64 = rng.random();
            acc += cosine_hemisphere(u);
        }
        eprintln!("sampling alone: {:.3} s ({acc})", t.elapsed().as_secs_f64());
    }

    #[test]
    fn samples_where_pdf_is_zero_fail() {
        let cfg = Chi2Settings {
            samples: 100_000,
            ..Chi2Settings::default()
        };
        // Samples the upper hemisphere uniformly but the pdf claims the
        // cap z > 0.98 (the top row of cells) is never sampled.
        let r = chi2_test(
            &cfg,
            |_, u| {
                let mut w = uniform_sphere(u);
                w.z = w.z.abs();
                Some(w)
            },
            |w| {
                if w.z >= 0.0 && w.z < 0.98 {
                    0.5 * FRAC_1_PI / 0.98
                } else {
                    0.0
                }
            },
        );
        assert_eq!(r.p_value, 0.0);
        assert!(
            r.message.as_deref().unwrap().contains("~0"),
            "{:?}",
            r.message
        );
    }

    #[test]
    fn non_unit_direction_and_bad_pdf_fail() {
        let cfg = Chi2Settings {
            samples: 10_000,
            n_z: 10,
            n_phi: 10,
            ..Chi2Settings::default()
        };
        let r = chi2_test(&cfg, |_, u| Some(1.01 * uniform_sphere(u)), |_| UNIFORM_PDF);
        assert_eq!(r.p_value, 0.0);
        assert!(r.message.as_deref().unwrap().contains("unit"));
        let r = chi2_test(
            &cfg,
            |_, u| Some(uniform_sphere(u)),
            |w| if w.x > 0.9 { f64::NAN } else { UNIFORM_PDF },
        );
        assert_eq!(r.p_value, 0.0);
        assert!(
            r.message.as_deref().unwrap().contains("pdf"),
            "{:?}",
            r.message
        );
        let r = chi2_test(
            &Chi2Settings { n_z: 0, ..cfg },
            |_, u| Some(uniform_sphere(u)),
            |_| UNIFORM_PDF,
        );
        assert_eq!(r.p_value, 0.0);
    }

    #[test]
    fn deterministic_per_seed() {
        let cfg = Chi2Settings {
            samples: 20_000,
            n_z: 20,
            n_phi: 20,
            ..Chi2Settings::default()
        };
        let s = |_: f64, u: DVec2| Some(uniform_sphere(u));
        let a = chi2_test(&cfg, s, |_| UNIFORM_PDF);
        let b = chi2_test(&cfg, s, |_| UNIFORM_PDF);
        let c = chi2_test(&Chi2Settings { seed: 7, ..cfg }, s, |_| UNIFORM_PDF);
        assert_eq!(a, b);
        assert_ne!(a.observed, c.observed);
    }

    #[test]
    fn p_values_are_roughly_uniform_under_the_null() {
        // 40 small tests with different seeds: a valid sampler must not be
        // rejected often, and the p-values must spread over (0, 1).
        let cfg = Chi2Settings {
            samples: 20_000,
            n_z: 20,
            n_phi: 20,
            ..Chi2Settings::default()
        };
        let ps: Vec<f64> = (0..40)
            .map(|s| {
                chi2_test(
                    &Chi2Settings { seed: s, ..cfg },
                    |_, u| Some(cosine_hemisphere(u)),
                    cosine_pdf,
                )
                .p_value
            })
            .collect();
        let rejected = ps.iter().filter(|&&p| p < 0.01).count();
        assert!(rejected <= 3, "{ps:?}");
        let low = ps.iter().filter(|&&p| p < 0.5).count();
        assert!((8..=32).contains(&low), "{ps:?}");
    }

    #[test]
    fn binning_conventions() {
        let cfg = Chi2Settings::default();
        assert_eq!(cfg.cell_of(DVec3::Z), (99, 0));
        assert_eq!(cfg.cell_of(DVec3::new(0.0, 0.0, -1.0)), (0, 0));
        assert_eq!(cfg.cell_of(DVec3::new(0.0, -1.0, 0.0)), (50, 75));
        let w = DVec3::new(1.0, -1e-300, 0.0).normalize();
        assert_eq!(cfg.cell_of(w).1, 99);
        let (z0, z1, p0, p1) = cfg.cell_bounds(99, 99);
        assert_eq!((z1, p1), (1.0, TAU));
        assert!((z0 - 0.98).abs() < 1e-15 && (p0 - 0.99 * TAU).abs() < 1e-14);
    }

    #[test]
    fn sidak_is_accurate() {
        assert!((sidak(0.05, 1) - 0.05).abs() < 1e-17);
        assert_eq!(sidak(0.05, 0), sidak(0.05, 1));
        let a = sidak(0.01, 10);
        assert!(((1.0 - a).powi(10) - 0.99).abs() < 1e-15);
        // Tiny alpha: ≈ alpha / n without cancellation.
        let a = sidak(1e-12, 1000);
        assert!((a / 1e-15 - 1.0).abs() < 1e-9, "{a}");
        assert_eq!(sidak(1.0, 5), 1.0);
        assert_eq!(sidak(0.0, 5), 0.0);
    }

    #[test]
    fn success_probability_midpoint_rule() {
        let lose_half = |uc: f64, _: DVec2| uc >= 0.5;
        let p = success_probability(lose_half, &[(0.3, 0.2), (0.7, 0.8)], 16);
        assert!((p - 0.7).abs() < 1e-15);
        // A disc in u-space of radius 0.5: success ≈ π/4.
        let disc = |_: f64, u: DVec2| (u - DVec2::splat(0.5)).length_squared() < 0.25;
        let p = success_probability(disc, &[(1.0, 0.0)], 1000);
        assert!((p - PI / 4.0).abs() < 1e-4, "{p}");
        assert_eq!(success_probability(disc, &[], 10), 0.0);
        // Lattices that are not a multiple of the 64 tiles, and smaller.
        for g in [1, 3, 63, 65, 100, 1000] {
            let all = success_probability(|_, _| true, &[(1.0, 0.0)], g);
            assert_eq!(all, 1.0, "{g}");
            assert_eq!(
                success_probability(|_, _| false, &[(1.0, 0.0)], g),
                0.0,
                "{g}"
            );
        }
        assert!(success_probability(disc, &[(1.0, 0.0)], 0) > 0.0);
    }

    /// The adaptive count against every point of the lattice, on regions
    /// with curved, straight, thin and many-piece boundaries, and the number
    /// of calls it makes.
    #[test]
    fn adaptive_count_matches_the_full_lattice() {
        use std::cell::Cell;
        type Shape = (&'static str, fn(DVec2) -> bool);
        let shapes: [Shape; 4] = [
            ("disc", |u| (u - DVec2::splat(0.5)).length_squared() < 0.2),
            ("annulus", |u| {
                (0.05..0.15).contains(&(u - DVec2::new(0.3, 0.6)).length_squared())
            }),
            ("wedge", |u| u.y < 0.9 * u.x + 0.03 && u.y > 0.7 * u.x),
            ("stripes", |u| {
                ((u.x * 9.0).floor() as i32 + (u.y * 5.0).floor() as i32) % 2 == 0
            }),
        ];
        for (name, shape) in shapes {
            for g in [257, 1024] {
                let full = (0..g)
                    .flat_map(|i| (0..g).map(move |j| (i, j)))
                    .filter(|&(i, j)| {
                        shape(DVec2::new(
                            (i as f64 + 0.5) / g as f64,
                            (j as f64 + 0.5) / g as f64,
                        ))
                    })
                    .count();
                let calls = Cell::new(0usize);
                let hits = lattice_hits(
                    |u| {
                        calls.set(calls.get() + 1);
                        shape(u)
                    },
                    g,
                );
                assert_eq!(hits, full, "{name} on {g}²");
                if g == 1024 {
                    assert!(calls.get() < g * g / 8, "{name}: {} calls", calls.get());
                }
            }
        }
    }

    #[test]
    fn tables_are_written() {
        let cfg = Chi2Settings {
            samples: 1000,
            n_z: 4,
            n_phi: 3,
            ..Chi2Settings::default()
        };
        let r = chi2_test(&cfg, |_, u| Some(uniform_sphere(u)), |_| UNIFORM_PDF);
        let path = std::env::temp_dir().join(format!("lobe-chi2-{}.csv", std::process::id()));
        r.write_tables(&cfg, &path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 1 + 12 + 1);
        assert_eq!(lines[0], "iz,iphi,z0,z1,phi0,phi1,observed,expected");
        assert!(lines[1].starts_with("0,0,-1,-0.5,0,"));
        assert!(lines[13].starts_with("lost,,,,,,0,"));
        let wrong = Chi2Settings { n_z: 5, ..cfg };
        assert!(r.write_tables(&wrong, &path).is_err());
    }
}
