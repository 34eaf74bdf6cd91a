//! Per-core throughput of the work a path tracer does for one BSDF sample:
//! `Material::sample`, then `Material::eval` and `Material::pdf` for the
//! returned direction (as for multiple importance sampling), on a batch of
//! precomputed random `(wo, uc, u)` triples.
//!
//! ```text
//! cargo bench -p lobe-bench --bench throughput
//! cargo bench -p lobe-bench --bench throughput -- ggx-alpha0.2/vndf   # one benchmark
//! ```
//!
//! Criterion reports elements/s; one element is one *attempted* sample
//! (a failed sample, `None`, costs its `sample` call and counts too).
//! The `sample-only` groups time `Material::sample` alone, for comparison.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::{DVec2, DVec3};
use lobe::{BsdfSampler, Rgb};
use rand::RngExt;
use std::f64::consts::PI;
use std::hint::black_box;
use std::time::Duration;

mod common;
use common::{MATERIALS, material};

/// Samples per timed iteration.
const BATCH: usize = 4096;

/// One precomputed input: view direction, lobe-choice number, direction numbers.
#[derive(Clone, Copy)]
struct Input {
    wo: DVec3,
    uc: f64,
    u: DVec2,
}

/// `BATCH` inputs with `wo` uniform over the upper hemisphere (random
/// azimuth, which matters for the anisotropic material), fixed seed.
fn inputs() -> Vec<Input> {
    let mut rng = rand_pcg::Pcg64::new(0x6c6f_6265, 0x7468_726f_7567_6870);
    (0..BATCH)
        .map(|_| {
            // cos θo uniform in (0, 1]: never exactly at the horizon.
            let cos_t: f64 = 1.0 - rng.random::<f64>();
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            let phi = 2.0 * PI * rng.random::<f64>();
            let wo = DVec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t);
            Input {
                wo,
                uc: rng.random(),
                u: DVec2::new(rng.random(), rng.random()),
            }
        })
        .collect()
}

/// The timed loop: sample, then eval and pdf for the sampled direction.
/// `wi` goes through `black_box` so that the compiler cannot reuse the `f`
/// and `pdf` that `sample` computed internally: a renderer calls `eval` and
/// `pdf` from elsewhere (light sampling, MIS), not on the same values inline.
#[inline(never)]
fn sample_eval_pdf(sampler: &BsdfSampler<'_>, inputs: &[Input]) -> (Rgb, Rgb, f64) {
    let m = sampler.material();
    let (mut weights, mut fs, mut pdfs) = (Rgb::ZERO, Rgb::ZERO, 0.0);
    for x in inputs {
        if let Some(s) = sampler.sample(x.wo, x.uc, x.u) {
            weights += s.weight;
            let wi = black_box(s.wi);
            fs += m.eval(x.wo, wi);
            pdfs += sampler.pdf(x.wo, wi);
        }
    }
    (weights, fs, pdfs)
}

/// `sample` alone (its result already carries `f` and `pdf`).
#[inline(never)]
fn sample_only(sampler: &BsdfSampler<'_>, inputs: &[Input]) -> Rgb {
    let mut weights = Rgb::ZERO;
    for x in inputs {
        if let Some(s) = sampler.sample(x.wo, x.uc, x.u) {
            weights += s.weight;
        }
    }
    weights
}

fn throughput(c: &mut Criterion) {
    let inputs = inputs();
    for &(name, json) in MATERIALS {
        let m = material(json);
        let mut group = c.benchmark_group(format!("throughput/{name}"));
        group.throughput(Throughput::Elements(BATCH as u64));
        for strategy in m.strategies() {
            let mut reported = false;
            group.bench_function(BenchmarkId::from_parameter(strategy), |b| {
                // Once, and only for benchmarks that the filter selects.
                if !reported {
                    let ok = inputs
                        .iter()
                        .filter(|x| {
                            m.sampler(strategy)
                                .is_ok_and(|s| s.sample(x.wo, x.uc, x.u).is_some())
                        })
                        .count();
                    eprintln!("throughput/{name}/{strategy}: {ok} of {BATCH} samples valid");
                    reported = true;
                }
                // The material and strategy are runtime values, as in a renderer.
                // Resolved once per benchmark, as a renderer resolves it once per material.
                let sampler = m
                    .sampler(strategy)
                    .expect("one of the material's strategies");
                b.iter(|| sample_eval_pdf(black_box(&sampler), black_box(&inputs)));
            });
        }
        group.finish();
    }

    // For comparison: the cost of `sample` alone, for the GGX material.
    let name = "ggx-alpha0.2";
    let json = MATERIALS
        .iter()
        .find(|(n, _)| *n == name)
        .expect("listed")
        .1;
    let m = material(json);
    let mut group = c.benchmark_group(format!("sample-only/{name}"));
    group.throughput(Throughput::Elements(BATCH as u64));
    for strategy in m.strategies() {
        group.bench_function(BenchmarkId::from_parameter(strategy), |b| {
            let sampler = m
                .sampler(strategy)
                .expect("one of the material's strategies");
            b.iter(|| sample_only(black_box(&sampler), black_box(&inputs)));
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(2))
        .sample_size(20)
        .without_plots();
    targets = throughput
}
criterion_main!(benches);
