//! Statistical tests that prove the samplers against their pdfs.
//!
//! * [`quadrature`]: deterministic adaptive cubature on rectangles and on
//!   regions of the sphere, to integrate pdfs to about `1e-9`.
//! * `chi2` (feature `stats`): the chi-square goodness-of-fit harness every sampler goes
//!   through (equal-area histogram on the sphere, failed samples in a *lost*
//!   bin).
//! * [`ttest`]: running moments (always) and Student's t-test (feature
//!   `stats`), to check the means of Monte Carlo estimators.

#[cfg(feature = "stats")]
pub mod chi2;
pub mod quadrature;
pub mod ttest;

#[cfg(feature = "stats")]
pub use chi2::{Chi2Result, Chi2Settings, chi2_test, chi2_test_many, sidak, success_probability};
pub use quadrature::{
    Estimate, Tolerance, integrate_2d, integrate_hemisphere, integrate_sphere,
    integrate_sphere_region, integrate_sphere_region_many,
};
pub use ttest::Moments;
#[cfg(feature = "stats")]
pub use ttest::{TTest, t_test};
