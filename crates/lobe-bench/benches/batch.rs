//! Per-core throughput of the batch kernels (`lobe::batch`) for every
//! model × strategy: `BatchSampler::sample` over a block of precomputed
//! inputs, then `BatchSampler::eval_pdf` at the sampled directions (what a
//! path tracer with MIS does per BSDF sample), beside the scalar
//! `throughput` bench's materials. The level is the best the CPU has unless
//! `LOBE_SIMD=scalar|avx2|avx512` forces one (printed once).
//!
//! ```text
//! cargo bench -p lobe-bench --bench batch
//! LOBE_SIMD=avx2 cargo bench -p lobe-bench --bench batch -- ggx-alpha0.2/vndf
//! ```
//!
//! Criterion reports elements/s; one element is one attempted sample.
//! `lobe bench --material M --strategy S` measures the same work over 2²²
//! samples with the thread count and the scalar f64 peer in the same run.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use lobe::batch::{BatchSampler, Dirs, EvalPdfBuffers, SampleBuffers, SampleInput};
use rand::RngExt;
use std::hint::black_box;
use std::time::Duration;

mod common;
use common::{MATERIALS, material};

/// Samples per call (the outputs stay in the L1/L2 caches).
const BLOCK: usize = 4096;

/// Precomputed inputs, structure of arrays: `wo` uniform over the upper
/// hemisphere (random azimuth), `u1`, `u2`, `uc` uniform; fixed seed.
struct Inputs {
    wo: [Vec<f32>; 3],
    u1: Vec<f32>,
    u2: Vec<f32>,
    uc: Vec<f32>,
}

fn inputs() -> Inputs {
    let mut rng = rand_pcg::Pcg64::new(0x6c6f_6265, 0x6261_7463_6862_656e);
    let mut v = Inputs {
        wo: [vec![], vec![], vec![]],
        u1: vec![],
        u2: vec![],
        uc: vec![],
    };
    for _ in 0..BLOCK {
        let cos_t: f64 = 1.0 - rng.random::<f64>();
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let phi = std::f64::consts::TAU * rng.random::<f64>();
        v.wo[0].push((sin_t * phi.cos()) as f32);
        v.wo[1].push((sin_t * phi.sin()) as f32);
        v.wo[2].push(cos_t as f32);
        v.u1.push(rng.random());
        v.u2.push(rng.random());
        v.uc.push(rng.random());
    }
    v
}

/// The timed work: sample the block, then eval_pdf at the sampled `wi`
/// (through `black_box`, as a renderer calls it from elsewhere).
#[inline(never)]
fn sample_eval_pdf(
    b: &BatchSampler,
    inp: &Inputs,
    out: &mut SampleBuffers,
    ev: &mut EvalPdfBuffers,
) -> f32 {
    let wo = Dirs {
        x: &inp.wo[0],
        y: &inp.wo[1],
        z: &inp.wo[2],
    };
    let input = SampleInput {
        wo,
        u1: &inp.u1,
        u2: &inp.u2,
        uc: b.chooses_lobe().then_some(&inp.uc[..]),
    };
    b.sample(input, out.output()).expect("lengths match");
    let wi = black_box(out.wi());
    b.eval_pdf(wo, wi, ev.output()).expect("lengths match");
    out.weight[0][7] + ev.f[0][11] + ev.pdf[13]
}

fn batch(c: &mut Criterion) {
    let inputs = inputs();
    let mut out = SampleBuffers::new(BLOCK);
    let mut ev = EvalPdfBuffers::new(BLOCK);
    let mut said = false;
    for &(name, json) in MATERIALS {
        if json.contains("multiscatter") {
            // Energy compensation has no batch kernel yet: f64 path only.
            continue;
        }
        let m = material(json);
        let mut group = c.benchmark_group(format!("batch/{name}"));
        group.throughput(Throughput::Elements(BLOCK as u64));
        for strategy in m.strategies() {
            let b = BatchSampler::new(&m, strategy).expect("every analytic model is batched");
            if !said {
                eprintln!("batch: SIMD level {}", b.level());
                said = true;
            }
            group.bench_function(BenchmarkId::from_parameter(strategy), |bench| {
                bench.iter(|| sample_eval_pdf(black_box(&b), &inputs, &mut out, &mut ev));
            });
        }
        group.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(2))
        .sample_size(20)
        .without_plots();
    targets = batch
}
criterion_main!(benches);
