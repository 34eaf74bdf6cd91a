//! # lobe: BRDFs and their importance samplers
//!
//! `lobe` evaluates, samples and gives the pdf of the reflection models of the
//! classic lecture on importance sampling in BRDF evaluation (Phong,
//! Blinn-Phong, Cook-Torrance with GGX and Beckmann) and of the samplers that
//! renderers use today (visible normals, spherical caps, bounded VNDF). Every
//! sampler is proven against its pdf by the statistical tests in [`stats`].
//!
//! ## Conventions
//!
//! * Local shading frame, `+z` is the surface normal ([`Frame`] goes to and
//!   from the world).
//! * `wo` points toward the viewer, `wi` toward the light; both are unit
//!   vectors pointing away from the surface (for a transmission, `wi` is on
//!   the other side of it; `wo` below the surface sees glass from inside).
//! * [`Material::eval`] is `f_r` **without** the cosine.
//! * Pdfs are densities in **solid angle** over `wi`.
//! * A sample whose direction falls below the horizon is a *failed* sample:
//!   `sample` returns `None`, and an estimator still counts it in its `N`.
//!   Hence the pdf integrates over the sphere to the probability that a
//!   sample is not lost, which may be below one.
//! * `alpha` is the microfacet width parameter. Where "roughness" is
//!   accepted, `alpha = roughness²` (not pbrt-v4's square root).
//!
//! ## Cargo features
//!
//! Both on by default; without them the core needs only glam, libm and
//! rand/rand_pcg (`cargo build -p lobe --no-default-features`).
//!
//! * `desc`: material descriptions in JSON and TOML ([`desc`], serde).
//! * `stats`: the statistical tests, chi-square ([`stats::chi2`]) and
//!   Student's t ([`stats::t_test`], statrs). The deterministic quadrature
//!   ([`stats::quadrature`]) and [`stats::Moments`] are always there: the
//!   estimator's references and sums use them.
//!
//! ```
//! # #[cfg(feature = "desc")] {
//! use lobe::glam::{DVec2, DVec3};
//! use lobe::{BsdfStrategy, Material};
//! let m = Material::load(r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2}"#)?;
//! let vndf = m.sampler(BsdfStrategy::Vndf)?; // validated once: it has a pdf
//! let wo = DVec3::new(0.6, 0.0, 0.8); // local frame, +z the normal
//! if let Some(s) = vndf.sample(wo, 0.5, DVec2::new(0.3, 0.7)) {
//!     // s.wi, s.f (no cosine), s.pdf (solid angle), s.weight = f·cos/pdf
//!     let (f, pdf) = vndf.eval_pdf(wo, s.wi); // shared terms computed once
//!     assert!((pdf - s.pdf).abs() < 1e-9 * s.pdf && f == s.f);
//! }
//! # }
//! # Ok::<(), lobe::Error>(())
//! ```
//!
//! One shading point under a light, by any strategy (`lobe estimate` is
//! this plus formatting):
//!
//! ```
//! # #[cfg(feature = "desc")] {
//! use lobe::estimator::{EstimateSettings, ShadingPoint, estimate, reference};
//! use lobe::{Light, Material, Rgb, Strategy};
//! let m = Material::load(r#"{"type":"phong","exponent":100}"#)?;
//! let sp = ShadingPoint::local(lobe::frame::wo_from_theta(30.0, 0.0));
//! let light = Light::Constant(Rgb::ONE);
//! let strategy: Strategy = "mis".parse()?;
//! let acc = estimate(&m, &sp, &light, &EstimateSettings::independent(strategy, 1 << 16, 1))?;
//! let exact = reference(&m, &sp, &light, 1e-9);
//! assert!((acc.mean().x - exact.x).abs() < 5.0 * acc.std_error().x + 1e-12);
//! # }
//! # Ok::<(), lobe::Error>(())
//! ```

pub mod batch;
pub mod bsdf_strategy;
#[cfg(feature = "desc")]
pub mod desc;
pub mod energy;
pub mod envmap;
pub mod error;
pub mod estimator;
pub mod experiment;
pub mod fit;
pub mod frame;
pub mod fresnel;
pub mod ior;
pub mod light;
pub mod material;
pub mod math;
pub mod microfacet;
pub mod models;
pub(crate) mod parallel;
pub mod progress;
pub mod sample;
pub mod sequence;
pub mod stats;
pub mod strategy;
pub mod tabulate;
pub mod transport;
pub mod warp;

pub use bsdf_strategy::BsdfStrategy;
#[cfg(feature = "desc")]
pub use desc::MaterialDesc;
pub use error::Error;
pub use frame::Frame;
pub use fresnel::Fresnel;
pub use glam;
pub use light::Light;
pub use material::{BsdfSampler, Glossy, Material, ViewError};
pub use math::Rgb;
pub use microfacet::{Microfacet, Ndf, Shadowing};
pub use sample::{BsdfSample, Component, Delta, Deltas, LobeSample, Reach, Scattering};
pub use strategy::Strategy;
pub use transport::TransportMode;
