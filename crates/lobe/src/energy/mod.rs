//! Energy lost and given back: single-scattering microfacet lobes lose the
//! light that bounces more than once between microfacets (a white GGX
//! conductor at `α = 1` reflects about 60% of a white furnace at grazing
//! angles); this module measures the loss and compensates it.
//!
//! * [`table`]: tables of the directional albedo `E(μ, α)` and its average,
//!   their file format, and the tables built into lobe.
//! * [`tabulate`]: computing those tables with lobe's own estimator
//!   (`lobe tabulate-energy`).
//! * [`compensation`]: the material key `multiscatter`: Kulla and Conty
//!   2017's added lobe and Turquin 2019's scaling.
//! * [`random_walk`]: Heitz et al. 2016's random walk on the microsurface,
//!   the reference the compensated lobes are judged against.

pub mod compensation;
pub mod random_walk;
pub mod table;
pub mod tabulate;

pub use compensation::{Compensation, DielectricMultiscatter, Multiscatter};
pub use random_walk::RandomWalk;
pub use table::{AlbedoTable, AlbedoTables};
