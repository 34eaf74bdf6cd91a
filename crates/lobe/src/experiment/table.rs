//! The estimation table of one shading point: every technique with the same
//! samples, sequence and seed, against a quadrature reference (what
//! `lobe estimate` prints).

use super::{estimate_chunked, reference_rows};
use crate::estimator::{Plan, ShadingPoint, Strategy};
use crate::math::luminance;
use crate::progress::{Clock, Progress, timed};
use crate::sequence::Sequence;
use crate::{BsdfStrategy, Error, Light, Material};

/// Relative tolerance of the quadrature reference of [`run_table`].
pub const REFERENCE_TOLERANCE: f64 = 1e-9;

/// How every technique of a table is run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableSettings {
    pub sequence: Sequence,
    /// Samples per technique (each of `points_per_sample` directions).
    pub samples: usize,
    /// Seed of the sample sequence, the same for every technique.
    pub seed: u64,
}

/// One technique's result.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "desc", derive(serde::Serialize))]
pub struct Row {
    /// The technique's name ([`Strategy::name`]).
    pub name: String,
    pub samples: usize,
    /// The estimate of `L_o = ∫ f L cos dω` (RGB; the cosine is included).
    pub mean: [f64; 3],
    /// Standard error of the mean, per channel.
    pub stderr: [f64; 3],
    /// Relative error of the luminance of the mean against the reference's
    /// (the absolute error when the reference is zero).
    pub relative_error: f64,
    /// Per-sample variance of the luminance of `f·L·cos/p`.
    pub variance: f64,
    /// Uniform's variance over this one; `None` when this one is zero.
    pub variance_reduction: Option<f64>,
    /// Seconds the estimate took on the caller's clock.
    pub time_s: f64,
    /// `1/(variance × time)`; `None` when the variance is zero.
    pub efficiency: Option<f64>,
}

/// A comparison of techniques at one shading point.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "desc", derive(serde::Serialize))]
pub struct Table {
    /// `L_o` by deterministic quadrature (RGB, f64).
    pub reference: [f64; 3],
    /// How the reference was computed, in words.
    pub reference_method: &'static str,
    /// The sequence's name.
    pub sequence: String,
    /// One row per requested technique, in the requested order.
    pub strategies: Vec<Row>,
}

/// Estimates `L_o(wo) = ∫ f_r(wo, wi) L(wi) cos θi dωi` with every technique
/// of `techniques` (same samples, sequence and seed) and compares each with
/// the quadrature reference ([`REFERENCE_TOLERANCE`]). The variance
/// reduction is against `uniform` BSDF sampling, which is run too (and left
/// out of the rows) when it is not in the list.
///
/// Progress: one task `estimating` of `samples × techniques` steps (one per
/// sample). Each row's time is measured on `clock`; every other number
/// depends only on the arguments, not on the thread count. The error says
/// why a technique does not apply to `m`.
pub fn run_table(
    m: &Material,
    sp: &ShadingPoint,
    light: &Light,
    techniques: &[Strategy],
    settings: TableSettings,
    progress: &dyn Progress,
    clock: &dyn Clock,
) -> Result<Table, Error> {
    let TableSettings {
        sequence,
        samples,
        seed,
    } = settings;
    let reference = reference_rows(m, sp, light, REFERENCE_TOLERANCE);
    let r_lum = luminance(reference);
    let uniform = Strategy::Bsdf(BsdfStrategy::Uniform);
    let mut todo: Vec<Strategy> = techniques.to_vec();
    if !todo.contains(&uniform) {
        todo.push(uniform);
    }
    progress.start("estimating", (samples * todo.len()) as u64);
    let mut rows: Vec<(Strategy, Row)> = Vec::new();
    for &s in &todo {
        let plan = Plan {
            strategy: s,
            sequence,
            samples,
            seed,
        };
        let (acc, time_s) = timed(clock, || estimate_chunked(m, sp, light, &plan, progress));
        let acc = acc?;
        let mean = acc.mean();
        let variance = acc.lum.variance();
        let relative_error = if r_lum != 0.0 {
            (luminance(mean) - r_lum).abs() / r_lum.abs()
        } else {
            luminance(mean).abs()
        };
        rows.push((
            s,
            Row {
                name: s.name(),
                samples,
                mean: mean.to_array(),
                stderr: acc.std_error().to_array(),
                relative_error,
                variance,
                variance_reduction: None,
                time_s,
                efficiency: (variance > 0.0).then(|| 1.0 / (variance * time_s.max(1e-9))),
            },
        ));
    }
    let uniform = rows
        .iter()
        .find(|(s, _)| *s == uniform)
        .map_or(f64::NAN, |(_, r)| r.variance);
    let mut out = Vec::new();
    for (s, mut row) in rows {
        if !techniques.contains(&s) {
            continue;
        }
        row.variance_reduction = (row.variance > 0.0).then(|| uniform / row.variance);
        out.push(row);
    }
    Ok(Table {
        reference: reference.to_array(),
        reference_method: if matches!(light, Light::Env(_)) {
            "a sum over the map's texels of radiance × ∫ f cos dω (4×4 Gauss-Legendre per texel, refined to 1e-9 relative, f64)"
        } else {
            "deterministic adaptive quadrature (Gauss-Kronrod, f64, relative tolerance 1e-9)"
        },
        sequence: sequence.name().to_string(),
        strategies: out,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Rgb;
    use crate::estimator::{Heuristic, Mis, MisForm};
    use glam::DVec3;
    use std::sync::Mutex;
    use std::time::Duration;

    /// A clock that advances one second per reading.
    struct Ticks(Mutex<u64>);
    impl Clock for Ticks {
        fn now(&self) -> Duration {
            let mut t = self.0.lock().unwrap();
            *t += 1;
            Duration::from_secs(*t)
        }
    }

    #[derive(Default)]
    struct Record(Mutex<(Vec<(String, u64)>, u64)>);
    impl Progress for Record {
        fn start(&self, label: &str, total: u64) {
            self.0.lock().unwrap().0.push((label.to_string(), total));
        }
        fn advance(&self, n: u64) {
            self.0.lock().unwrap().1 += n;
        }
    }

    fn settings(samples: usize) -> TableSettings {
        TableSettings {
            sequence: Sequence::Independent,
            samples,
            seed: 1,
        }
    }

    /// A Lambert furnace: `L_o` is the albedo, cosine sampling has zero
    /// variance, and uniform's variance reduction is exactly 1.
    #[test]
    fn lambert_furnace() {
        let m = Material::lambert(Rgb::splat(0.8)).unwrap();
        let wo = DVec3::new(0.5, 0.0, 0.75f64.sqrt());
        let sp = ShadingPoint::local(wo);
        let light = Light::Constant(Rgb::ONE);
        let techniques = [
            Strategy::Bsdf(BsdfStrategy::Uniform),
            Strategy::Bsdf(BsdfStrategy::Cosine),
        ];
        let progress = Record::default();
        let t = run_table(
            &m,
            &sp,
            &light,
            &techniques,
            settings(10_000),
            &progress,
            &Ticks(Mutex::new(0)),
        )
        .unwrap();
        for c in t.reference {
            assert!((c - 0.8).abs() < 1e-9, "{c}");
        }
        assert_eq!(t.sequence, "independent");
        assert_eq!(t.strategies.len(), 2);
        let (u, c) = (&t.strategies[0], &t.strategies[1]);
        assert_eq!((u.name.as_str(), c.name.as_str()), ("uniform", "cosine"));
        assert_eq!(u.variance_reduction, Some(1.0));
        assert!(u.variance > 0.0 && u.relative_error < 0.02, "{u:?}");
        assert!(u.stderr[0] > 0.0);
        assert!(c.variance < 1e-20, "{c:?}");
        assert!(c.relative_error < 1e-12, "{c:?}");
        // Zero up to rounding: an enormous (or infinite) reduction.
        assert!(c.variance_reduction.is_none_or(|r| r > 1e12), "{c:?}");
        // The fake clock advances 1 s between the two readings of a row.
        assert_eq!(u.time_s, 1.0);
        assert_eq!(u.efficiency, Some(1.0 / u.variance));
        let p = progress.0.lock().unwrap();
        assert_eq!(p.0, vec![("estimating".to_string(), 20_000)]);
        assert_eq!(p.1, 20_000);
    }

    /// Uniform is run for the variance reduction though not listed; the
    /// rows keep the requested order.
    #[test]
    fn variance_reduction_without_uniform_in_the_list() {
        let m = Material::lambert(Rgb::splat(0.5)).unwrap();
        let wo = DVec3::Z;
        let sp = ShadingPoint::local(wo);
        let light = Light::Beam {
            dir: DVec3::new(0.3, 0.0, 1.0).normalize(),
            exponent: 20.0,
            radiance: Rgb::ONE,
        };
        let mis = Strategy::Mis(Mis {
            bsdf: Some(BsdfStrategy::Cosine),
            heuristic: Heuristic::Balance,
            form: MisForm::MultiSample,
            n_bsdf: 1,
            n_light: 1,
        });
        let techniques = [Strategy::Light, mis, Strategy::Bsdf(BsdfStrategy::Cosine)];
        let t = run_table(
            &m,
            &sp,
            &light,
            &techniques,
            settings(8192),
            &(),
            &Ticks(Mutex::new(0)),
        )
        .unwrap();
        let names: Vec<&str> = t.strategies.iter().map(|r| r.name.as_str()).collect();
        assert_eq!(names, ["light", "mis", "cosine"]);
        let all = run_table(
            &m,
            &sp,
            &light,
            &[Strategy::Bsdf(BsdfStrategy::Uniform)],
            settings(8192),
            &(),
            &Ticks(Mutex::new(0)),
        )
        .unwrap();
        let uniform = all.strategies[0].variance;
        for r in &t.strategies {
            assert_eq!(
                r.variance_reduction,
                Some(uniform / r.variance),
                "{}",
                r.name
            );
            assert!(r.relative_error < 0.05, "{r:?}");
        }
        // Sampling the sharp light beats uniform sampling.
        assert!(t.strategies[0].variance_reduction.unwrap() > 2.0);
    }
}
