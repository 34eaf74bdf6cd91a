//! Experiments: the numbers behind every table and figure of the `lobe`
//! command line, as plain functions of plain values.
//!
//! * [`table`]: one shading point, every strategy, against a quadrature
//!   reference (`lobe estimate`); [`estimate`]: its settings, checked once
//!   for every front end.
//! * [`converge`]: RMSE against the number of samples, with fitted slopes
//!   (`lobe converge`).
//! * [`histogram`]: sample histograms and sample weights over the projected
//!   hemisphere, and the fraction of failed samples (`lobe plot`,
//!   `lobe report`).
//! * [`polar`]: the integrand and each strategy's pdf in the plane of
//!   incidence (`lobe plot --kind polar`, `lobe report`).
//! * [`warp_test`]: Nori's warp test of a sampler, histograms and
//!   chi-square (`lobe plot`, `lobe report`; feature `stats`).
//! * [`furnace`]: the white furnace, albedo against `θo` and `α` with and
//!   without energy compensation and by the random walk (`lobe furnace`;
//!   feature `desc`).
//! * [`variance`]: exact variances by quadrature (the baseline of "vs
//!   uniform") and the largest directional albedo of a material.
//!
//! Progress and time reach these functions only through the
//! [`Progress`](crate::progress::Progress) and [`Clock`](crate::progress::Clock)
//! the caller passes. With the cargo feature `parallel` (on by default) the
//! work runs on rayon's pool; the work is cut into pieces that depend only on
//! the inputs and merged in a fixed order, so the numbers are the same with
//! or without the feature and for any thread count.

pub mod albedo;
pub mod converge;
pub mod estimate;
#[cfg(feature = "desc")]
pub mod furnace;
pub mod histogram;
pub mod lobe_grid;
pub mod polar;
pub mod table;
pub mod variance;
#[cfg(feature = "stats")]
pub mod warp_test;

use crate::estimator::{
    Accumulator, EstimateSettings, ShadingEstimator, ShadingPoint, delta_reference, estimate_chunk,
    reference, reference_env_row,
};
use crate::progress::Progress;
use crate::{Error, Light, Material, Rgb};

pub(crate) use crate::parallel::map_indices;

/// [`crate::estimator::estimate`] with its chunks run in parallel (feature
/// `parallel`) and merged in chunk order: the same numbers as the serial
/// estimate, for any thread count. Calls `progress.advance(k)` after each
/// chunk of `k` samples (it does not call `start`). The error says why the
/// settings' strategy does not apply to `m`.
pub fn estimate_chunked(
    m: &Material,
    sp: &ShadingPoint,
    light: &Light,
    settings: &EstimateSettings,
    progress: &dyn Progress,
) -> Result<Accumulator, Error> {
    let est = ShadingEstimator::new(settings.strategy, m)?.prepare(sp, light, settings);
    let parts = map_indices(settings.chunks(), |c| {
        let a = estimate_chunk(&est, sp, light, settings, c);
        progress.advance(a.count() as u64);
        a
    });
    let mut acc = Accumulator::default();
    for p in &parts {
        acc.merge(p);
    }
    Ok(acc)
}

/// [`crate::estimator::reference`], the reflected radiance `∫ f L cos dω`
/// by quadrature, with an environment map's rows summed in parallel (feature
/// `parallel`) in row order: the same number as the serial reference.
#[must_use]
pub fn reference_rows(m: &Material, sp: &ShadingPoint, light: &Light, rel: f64) -> Rgb {
    match light {
        Light::Env(map) => {
            let rows = map_indices(map.size().1, |j| reference_env_row(m, sp, map, j, rel));
            rows.iter().fold(Rgb::ZERO, |a, &b| a + b) + delta_reference(m, sp, light)
        }
        _ => reference(m, sp, light, rel),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimator::{Strategy, estimate};
    use crate::sequence::Sequence;
    use crate::{BsdfStrategy, Frame};
    use glam::DVec3;
    use std::sync::Arc;
    use std::sync::atomic::{AtomicU64, Ordering};

    struct Count(AtomicU64);
    impl Progress for Count {
        fn advance(&self, n: u64) {
            self.0.fetch_add(n, Ordering::Relaxed);
        }
    }

    #[test]
    fn chunked_estimate_equals_the_serial_one() {
        let m = Material::lambert(Rgb::splat(0.7)).unwrap();
        let sp = ShadingPoint::local(DVec3::new(0.5, 0.0, 0.75f64.sqrt()));
        let light = Light::Beam {
            dir: DVec3::new(0.2, 0.3, 0.9).normalize(),
            exponent: 8.0,
            radiance: Rgb::ONE,
        };
        for sequence in Sequence::ALL {
            let settings = EstimateSettings {
                strategy: Strategy::Bsdf(BsdfStrategy::Uniform),
                sequence,
                samples: 3 * crate::estimator::CHUNK + 17,
                seed: 5,
            };
            let count = Count(AtomicU64::new(0));
            let a = estimate_chunked(&m, &sp, &light, &settings, &count).unwrap();
            assert_eq!(
                a,
                estimate(&m, &sp, &light, &settings).unwrap(),
                "{sequence}"
            );
            assert_eq!(count.0.load(Ordering::Relaxed), settings.samples as u64);
        }
    }

    #[test]
    fn row_reference_equals_the_serial_one() {
        let map = crate::envmap::EnvMap::sky(16, 8, 30.0, 40.0);
        let light = Light::Env(Arc::new(map));
        let sp = ShadingPoint {
            frame: Frame::from_normal_tangent(DVec3::Y, DVec3::X).unwrap(),
            wo: DVec3::new(0.3, 0.0, 0.954).normalize(),
        };
        // A density, and delta parts (a mirror, glass, a coating), whose
        // exact terms both references add.
        let lambert = Material::lambert(Rgb::splat(0.5)).unwrap();
        let lobes = |g| Material::from(crate::models::Lobes::only(g));
        let mirror = lobes(crate::Glossy::Conductor(crate::models::Conductor::new(
            crate::Fresnel::None,
            Rgb::ONE,
        )));
        let plastic = lobes(crate::Glossy::Plastic(
            crate::models::Plastic::new(Rgb::splat(0.5), Rgb::ONE, 1.49, false).unwrap(),
        ));
        for m in [lambert, mirror, plastic] {
            let a = reference_rows(&m, &sp, &light, 1e-6);
            assert_eq!(a, reference(&m, &sp, &light, 1e-6), "{}", m.model_name());
            assert!(a.x > 0.0, "{}", m.model_name());
        }
    }
}
