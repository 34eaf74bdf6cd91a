//! Computing the albedo tables ([`super::table`]) with lobe's own sampler
//! and estimator: at each node, `N` directions drawn by visible normals
//! (Heitz 2018 for GGX, Heitz and d'Eon 2014 for Beckmann), whose weight
//! `f cos θi / pdf` with `F = 1` is `G(wo, wi) / G1(wo)`: `G1(wi)` for the
//! separable term, `(1 + Λo) / (1 + Λo + Λi)` for the height-correlated
//! one, 0 for a direction below the horizon. The samples are jittered, in
//! independent replicas: the mean of the replicas is the node's value, and
//! their spread its standard error. Each node has its own random
//! stream (a function of the seed, the table and the node), so the numbers
//! are the same for any thread count and any subset recomputed.

use super::table::{AlbedoTable, AlbedoTables, alpha_node, mu_node};
use crate::math::reflect;
use crate::microfacet::{Microfacet, Ndf, Shadowing};
use crate::progress::Progress;
use crate::stats::Moments;
use glam::{DVec2, DVec3};
use rand::RngExt;

/// The tables lobe compensates with: both distributions with Smith's
/// separable and height-correlated terms.
pub const TABLES: [(Ndf, Shadowing); 4] = [
    (Ndf::Ggx, Shadowing::SmithSeparable),
    (Ndf::Ggx, Shadowing::SmithCorrelated),
    (Ndf::Beckmann, Shadowing::SmithSeparable),
    (Ndf::Beckmann, Shadowing::SmithCorrelated),
];

/// The size and the samples of a table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TabulateSettings {
    pub n_mu: usize,
    pub n_alpha: usize,
    /// Samples per node.
    pub samples: u64,
    pub seed: u64,
}

impl TabulateSettings {
    /// What the built-in tables were made with (`lobe tabulate-energy`'s
    /// defaults).
    pub const BUILTIN: TabulateSettings = TabulateSettings {
        n_mu: 64,
        n_alpha: 64,
        samples: 1 << 16,
        seed: 1,
    };
}

/// The random stream of node `(j, i)` of the table of `ndf`, `shadowing`.
fn stream(ndf: Ndf, shadowing: Shadowing, j: usize, i: usize) -> usize {
    let t = TABLES
        .iter()
        .position(|&p| p == (ndf, shadowing))
        .unwrap_or(TABLES.len());
    (t << 40) | (j << 20) | i
}

/// Independent replicas per node: the node's standard error is their spread.
pub const REPLICAS: u64 = 16;

/// The estimate of `E(μ, α)` at node `(j, i)` of a table: the mean of
/// [`REPLICAS`] independent jittered estimates of `samples / REPLICAS`
/// visible-normal samples each (one point per cell of an `nx × ny` grid
/// over `u`, [`crate::sequence::grid_shape`], else per row), from the
/// node's own stream; the [`Moments`] are those of the replicas' means.
#[must_use]
pub fn node_estimate(
    ndf: Ndf,
    shadowing: Shadowing,
    (j, i): (usize, usize),
    (n_mu, n_alpha): (usize, usize),
    samples: u64,
    seed: u64,
) -> Moments {
    let (mu, alpha) = (mu_node(i, n_mu), alpha_node(j, n_alpha));
    let mut rng = crate::sequence::chunk_rng(seed, stream(ndf, shadowing, j, i));
    let mf = Microfacet::new(ndf, alpha, alpha).expect("a node's alpha is in range");
    let wo = DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let lo = mf.lambda(wo);
    let weight = |u: DVec2| {
        let w = mf
            .sample_visible(wo, u)
            .map(|wm| reflect(wo, wm))
            .filter(|wi| wi.z > 0.0)
            .map_or(0.0, |wi| match shadowing {
                Shadowing::SmithCorrelated => (1.0 + lo) / (1.0 + lo + mf.lambda(wi)),
                _ => mf.g1(wi),
            });
        if w.is_finite() { w } else { 0.0 }
    };
    let n = (samples / REPLICAS).max(1) as usize;
    let (nx, ny) = match crate::sequence::grid_shape(n) {
        (0, _) => (n, 1),
        g => g,
    };
    let mut replicas = Moments::new();
    for _ in 0..REPLICAS {
        let mut sum = 0.0;
        for a in 0..nx {
            for b in 0..ny {
                let u = DVec2::new(
                    (a as f64 + rng.random::<f64>()) / nx as f64,
                    (b as f64 + rng.random::<f64>()) / ny as f64,
                );
                sum += weight(u);
            }
        }
        replicas.push(sum / (nx * ny) as f64);
    }
    replicas
}

/// The table of `ndf` and `shadowing` (Smith's terms only: the weight above
/// is theirs). Reports `n_mu·n_alpha` steps to `progress`.
#[must_use]
pub fn tabulate(
    ndf: Ndf,
    shadowing: Shadowing,
    s: &TabulateSettings,
    progress: &dyn Progress,
) -> AlbedoTable {
    let nodes = crate::parallel::map_indices(s.n_mu * s.n_alpha, |k| {
        let m = node_estimate(
            ndf,
            shadowing,
            (k / s.n_mu, k % s.n_mu),
            (s.n_mu, s.n_alpha),
            s.samples,
            s.seed,
        );
        progress.advance(1);
        (m.mean().clamp(0.0, 1.0), m.std_error())
    });
    let (values, errors) = nodes.into_iter().unzip();
    AlbedoTable::new(
        ndf,
        shadowing,
        (s.n_mu, s.n_alpha),
        (s.samples, s.seed),
        values,
        errors,
    )
    .expect("estimates of an albedo are albedos")
}

/// Every table of [`TABLES`], one task of `progress` each.
#[must_use]
pub fn tabulate_all(s: &TabulateSettings, progress: &dyn Progress) -> AlbedoTables {
    AlbedoTables {
        tables: TABLES
            .iter()
            .map(|&(ndf, sh)| {
                progress.start(
                    &format!("{} {}", ndf.name(), sh.name()),
                    (s.n_mu * s.n_alpha) as u64,
                );
                tabulate(ndf, sh, s, progress)
            })
            .collect(),
    }
}
