//! Computing the albedo tables ([`super::table`]) with lobe's own sampler
//! and estimator: at each node, `N` microfacet normals drawn by visible
//! normals (Heitz 2018 for GGX, Heitz and d'Eon 2014 for Beckmann). For a
//! conductor the weight `f cos θi / pdf` with `F = 1` is
//! `G(wo, wi) / G1(wo)`: `G1(wi)` for the separable term,
//! `(1 + Λo) / (1 + Λo + Λi)` for the height-correlated one, 0 for a
//! direction below the horizon. For a dielectric (importance mode, Smith's
//! separable term) it is `G1(wi)` whether the sample reflects or refracts,
//! so the node's integrand is its expectation over the two,
//! `F G1(wi_r) + (1 − F) G1(wi_t)` (0 for a direction on the wrong side). The samples are jittered, in
//! independent replicas: the mean of the replicas is the node's value, and
//! their spread its standard error. Each node has its own random
//! stream (a function of the seed, the table and the node), so the numbers
//! are the same for any thread count and any subset recomputed.

use super::table::{AlbedoTable, AlbedoTables, Surface, alpha_node, eta_node, mu_node};
use crate::fresnel::{fresnel_dielectric, refract_about};
use crate::math::reflect;
use crate::microfacet::{Microfacet, Ndf, Shadowing};
use crate::progress::Progress;
use crate::stats::Moments;
use glam::{DVec2, DVec3};
use rand::RngExt;

/// The tables lobe compensates with: both distributions with Smith's
/// separable and height-correlated terms for conductors, and with the
/// separable term for dielectrics.
pub const TABLES: [(Ndf, Surface); 6] = [
    (Ndf::Ggx, Surface::Conductor(Shadowing::SmithSeparable)),
    (Ndf::Ggx, Surface::Conductor(Shadowing::SmithCorrelated)),
    (Ndf::Beckmann, Surface::Conductor(Shadowing::SmithSeparable)),
    (
        Ndf::Beckmann,
        Surface::Conductor(Shadowing::SmithCorrelated),
    ),
    (Ndf::Ggx, Surface::Dielectric),
    (Ndf::Beckmann, Surface::Dielectric),
];

/// The nodes and samples of one kind of table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shape {
    pub n_mu: usize,
    pub n_alpha: usize,
    /// `η` nodes (dielectric tables; conductors' have 1).
    pub n_eta: usize,
    /// Samples per node.
    pub samples: u64,
}

/// The shapes of the tables and the seed of their streams.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TabulateSettings {
    pub conductor: Shape,
    pub dielectric: Shape,
    pub seed: u64,
}

impl TabulateSettings {
    /// What the built-in tables were made with (`lobe tabulate-energy`'s
    /// defaults).
    pub const BUILTIN: TabulateSettings = TabulateSettings {
        conductor: Shape {
            n_mu: 64,
            n_alpha: 64,
            n_eta: 1,
            samples: 1 << 16,
        },
        dielectric: Shape {
            n_mu: 64,
            n_alpha: 32,
            n_eta: 25,
            samples: 1 << 12,
        },
        seed: 1,
    };

    /// The shape of a table of `surface`.
    #[must_use]
    pub fn shape(&self, surface: Surface) -> Shape {
        match surface {
            Surface::Conductor(_) => Shape {
                n_eta: 1,
                ..self.conductor
            },
            Surface::Dielectric => self.dielectric,
        }
    }
}

/// The random stream of node `(k, j, i)` of the table of `ndf`, `surface`.
fn stream(ndf: Ndf, surface: Surface, (k, j, i): (usize, usize, usize)) -> usize {
    let t = TABLES
        .iter()
        .position(|&p| p == (ndf, surface))
        .unwrap_or(TABLES.len());
    (t << 48) | (k << 32) | (j << 16) | i
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
    surface: Surface,
    (k, j, i): (usize, usize, usize),
    shape: Shape,
    seed: u64,
) -> Moments {
    let (mu, alpha) = (mu_node(i, shape.n_mu), alpha_node(j, shape.n_alpha));
    let eta = eta_node(k, shape.n_eta);
    let mut rng = crate::sequence::chunk_rng(seed, stream(ndf, surface, (k, j, i)));
    let mf = Microfacet::new(ndf, alpha, alpha).expect("a node's alpha is in range");
    let wo = DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let lo = mf.lambda(wo);
    let weight = |u: DVec2| {
        let Some(wm) = mf.sample_visible(wo, u) else {
            return 0.0;
        };
        let w = match surface {
            Surface::Conductor(shadowing) => {
                let wi = reflect(wo, wm);
                if wi.z <= 0.0 {
                    0.0
                } else if shadowing == Shadowing::SmithCorrelated {
                    (1.0 + lo) / (1.0 + lo + mf.lambda(wi))
                } else {
                    mf.g1(wi)
                }
            }
            Surface::Dielectric => {
                let f = fresnel_dielectric(wo.dot(wm), eta).r;
                let wr = reflect(wo, wm);
                let r = if wr.z > 0.0 { f * mf.g1(wr) } else { 0.0 };
                let t = match refract_about(wo, wm, eta) {
                    Some(wt) if wt.z < 0.0 && f < 1.0 => (1.0 - f) * mf.g1(wt),
                    _ => 0.0,
                };
                r + t
            }
        };
        if w.is_finite() { w } else { 0.0 }
    };
    let samples = shape.samples;
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

/// The table of `ndf` and `surface` (Smith's terms only: the weights above
/// are theirs). Reports one step per node to `progress`.
#[must_use]
pub fn tabulate(
    ndf: Ndf,
    surface: Surface,
    s: &TabulateSettings,
    progress: &dyn Progress,
) -> AlbedoTable {
    let shape = s.shape(surface);
    let (nm, na) = (shape.n_mu, shape.n_alpha);
    let nodes = crate::parallel::map_indices(nm * na * shape.n_eta, |n| {
        let m = node_estimate(
            ndf,
            surface,
            (n / (nm * na), n / nm % na, n % nm),
            shape,
            s.seed,
        );
        progress.advance(1);
        (m.mean().clamp(0.0, 1.0), m.std_error())
    });
    let (values, errors) = nodes.into_iter().unzip();
    AlbedoTable::new(
        ndf,
        surface,
        (nm, na, shape.n_eta),
        (shape.samples, s.seed),
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
            .map(|&(ndf, surface)| {
                let shape = s.shape(surface);
                progress.start(
                    &format!("{} {}", ndf.name(), surface.name()),
                    (shape.n_mu * shape.n_alpha * shape.n_eta) as u64,
                );
                tabulate(ndf, surface, s, progress)
            })
            .collect(),
    }
}
