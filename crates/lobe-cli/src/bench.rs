//! `lobe bench`: throughput of the batch kernels (`lobe::batch`), with the
//! scalar f64 path as a peer measured in the same run.

use anyhow::{Context, Result, bail};
use clap::Args;
use glam::{DVec2, DVec3};
use lobe::batch::{BatchSampler, Dirs, EvalPdfBuffers, SampleBuffers, SampleInput};
use lobe::{BsdfStrategy, Material};
use rand::{RngExt, SeedableRng};
use std::hint::black_box;
use std::sync::Barrier;
use std::time::{Duration, Instant};

const GGX_02: &str = r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2}"#;
const BECKMANN_02: &str = r#"{"type":"cook-torrance","distribution":"beckmann","alpha":0.2}"#;

/// The default table (no `--material`; BENCHMARKS.md): the three rows issue 9 sets
/// goals for, against Mitsuba 3's figures.
const DEFAULT_TABLE: [(&str, BsdfStrategy); 3] = [
    (GGX_02, BsdfStrategy::Vndf),
    (GGX_02, BsdfStrategy::Brdf),
    (BECKMANN_02, BsdfStrategy::Vndf),
];

/// Samples per call of the batch API: the outputs stay in the L1/L2 caches.
const BLOCK: usize = 4096;

/// The fewest samples for a figure worth quoting (issue 9: at least 2²²;
/// the inputs, 20 bytes a sample, then far exceed the caches).
const QUOTABLE_SAMPLES: usize = 1 << 22;

#[derive(Args, Debug)]
#[command(
    about = "Throughput of the batch (SIMD) kernels, with the scalar f64 path as a peer",
    long_about = "Throughput of the batch kernels of lobe::batch in million samples per second: \
                  `msps` is sample + eval_pdf at the sampled direction (what a path tracer with MIS \
                  does per BSDF sample), `sample_msps` is sample alone, and `scalar_msps` is the \
                  scalar f64 path (Material::sample, then eval and pdf) on the same inputs, in the \
                  same run. The inputs (wo uniform over the hemisphere, u1, u2 uniform; fixed seed) \
                  are precomputed; each thread takes a contiguous part and runs it in blocks of 4096 \
                  samples into its own output buffers, summing the results. Each figure is the \
                  median of --reps warm repetitions (one more, untimed, runs first).\n\n\
                  The dispatch level is the best the CPU has unless LOBE_SIMD=scalar|avx2|avx512 \
                  forces one. Speed claims come from here or from `cargo bench`, never from timed \
                  tests; on a shared machine compare the ratios within one run.\n\n\
                  --all times the whole table of BENCHMARKS.md (about 12 minutes on 2 cores).",
    after_help = "Examples:\n  \
                  lobe bench\n  \
                  lobe bench --threads 1,2 --json\n  \
                  lobe bench --all --threads 1\n  \
                  lobe bench --material '{\"type\":\"cook-torrance\",\"distribution\":\"beckmann\",\"alpha\":0.2}' --strategy vndf,brdf\n  \
                  LOBE_SIMD=avx2 lobe bench --material '{\"type\":\"cook-torrance\",\"alpha_u\":0.1,\"alpha_v\":0.4}' --strategy vndf"
)]
pub struct BenchArgs {
    /// Material: JSON text, @file.json or @file.toml. Without it, the table
    /// of BENCHMARKS.md: GGX alpha 0.2 vndf and brdf, Beckmann alpha 0.2 vndf
    #[arg(long)]
    pub material: Option<String>,
    /// Comma-separated strategies (default: every strategy the material
    /// has; without --material, for GGX alpha 0.2)
    #[arg(long)]
    pub strategy: Option<String>,
    /// Worker threads, each on its own part of the inputs; a comma-separated
    /// list times each count (default 1; with --all, 1 and every CPU)
    #[arg(long, value_delimiter = ',')]
    pub threads: Option<Vec<usize>>,
    /// Precomputed inputs (at least 2^22 for a figure worth quoting)
    #[arg(long, short = 'n', default_value_t = 1 << 22)]
    pub samples: usize,
    /// Timed repetitions; the median is reported (default 7; with --all, 3)
    #[arg(long)]
    pub reps: Option<usize>,
    /// The whole table: every model (one material each, with Mitsuba 3's
    /// plugin names where it has them) × every strategy × every SIMD level
    /// this CPU runs, beside the scalar f64 path, × thread counts, in M
    /// samples/s and ns per sample (BENCHMARKS.md)
    #[arg(long, conflicts_with_all = ["material", "strategy"])]
    pub all: bool,
    /// Print JSON instead of a table
    #[arg(long)]
    pub json: bool,
}

/// Precomputed inputs in structure-of-arrays layout.
pub(crate) struct Inputs {
    wo: [Vec<f32>; 3],
    u1: Vec<f32>,
    u2: Vec<f32>,
    uc: Vec<f32>,
}

impl Inputs {
    pub(crate) fn new(n: usize) -> Self {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(0x6c6f_6265_6265_6e63);
        let mut v = Inputs {
            wo: [vec![], vec![], vec![]],
            u1: Vec::with_capacity(n),
            u2: Vec::with_capacity(n),
            uc: Vec::with_capacity(n),
        };
        for _ in 0..n {
            let cos_t: f64 = 1.0 - rng.random::<f64>();
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            let phi = std::f64::consts::TAU * rng.random::<f64>();
            let w = [sin_t * phi.cos(), sin_t * phi.sin(), cos_t];
            for (c, x) in v.wo.iter_mut().zip(w) {
                c.push(x as f32);
            }
            // 24 random bits: uniform f32 in [0, 1).
            v.u1.push((rng.random::<u32>() >> 8) as f32 / (1u32 << 24) as f32);
            v.u2.push((rng.random::<u32>() >> 8) as f32 / (1u32 << 24) as f32);
            v.uc.push((rng.random::<u32>() >> 8) as f32 / (1u32 << 24) as f32);
        }
        v
    }

    fn input(&self, r: std::ops::Range<usize>) -> SampleInput<'_> {
        SampleInput {
            wo: Dirs {
                x: &self.wo[0][r.clone()],
                y: &self.wo[1][r.clone()],
                z: &self.wo[2][r.clone()],
            },
            u1: &self.u1[r.clone()],
            u2: &self.u2[r.clone()],
            uc: Some(&self.uc[r]),
        }
    }

    fn len(&self) -> usize {
        self.u1.len()
    }
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Mode {
    /// Batch sample, then batch eval_pdf at the sampled directions.
    SampleEvalPdf,
    /// Batch sample alone.
    Sample,
    /// The scalar f64 path: sample, then eval and pdf.
    Scalar,
}

/// What one timing runs: the mode, the material and strategy, the inputs.
#[derive(Clone, Copy)]
pub(crate) struct Job<'a> {
    pub mode: Mode,
    pub m: &'a Material,
    pub strategy: BsdfStrategy,
    /// The batch kernel (`None` for the scalar path's jobs).
    pub b: Option<&'a BatchSampler>,
    pub inputs: &'a Inputs,
}

/// One thread's work on `range`; returns a sum of the results so that
/// nothing is optimized away.
fn work(
    job: Job<'_>,
    range: std::ops::Range<usize>,
    out: &mut SampleBuffers,
    ev: &mut EvalPdfBuffers,
) -> f64 {
    let Job {
        mode,
        m,
        strategy,
        b,
        inputs,
    } = job;
    let mut total = 0.0f64;
    if mode == Mode::Scalar {
        let sampler = m
            .sampler(strategy)
            .expect("the strategy was checked when the job was made");
        for i in range {
            let wo = DVec3::new(
                inputs.wo[0][i].into(),
                inputs.wo[1][i].into(),
                inputs.wo[2][i].into(),
            );
            let u = DVec2::new(inputs.u1[i].into(), inputs.u2[i].into());
            if let Some(s) = sampler.sample(wo, inputs.uc[i].into(), u) {
                let wi = black_box(s.wi);
                total += s.weight.x + m.eval(wo, wi).x + sampler.pdf(wo, wi);
            }
        }
        return total;
    }
    let b = b.expect("a batch job has its kernel");
    let mut start = range.start;
    while start < range.end {
        let end = (start + BLOCK).min(range.end);
        let len = end - start;
        let mut o = out.output();
        // Trim the block buffers to this block's length.
        o.wi.x = &mut o.wi.x[..len];
        o.wi.y = &mut o.wi.y[..len];
        o.wi.z = &mut o.wi.z[..len];
        o.f.r = &mut o.f.r[..len];
        o.f.g = &mut o.f.g[..len];
        o.f.b = &mut o.f.b[..len];
        o.pdf = &mut o.pdf[..len];
        o.weight.r = &mut o.weight.r[..len];
        o.weight.g = &mut o.weight.g[..len];
        o.weight.b = &mut o.weight.b[..len];
        o.valid = &mut o.valid[..len];
        let input = inputs.input(start..end);
        b.sample(input, o).expect("lengths match");
        let mut sum = 0.0f32;
        if mode == Mode::SampleEvalPdf {
            let mut e = ev.output();
            e.f.r = &mut e.f.r[..len];
            e.f.g = &mut e.f.g[..len];
            e.f.b = &mut e.f.b[..len];
            e.pdf = &mut e.pdf[..len];
            let wi = black_box(out.wi());
            let wi = Dirs {
                x: &wi.x[..len],
                y: &wi.y[..len],
                z: &wi.z[..len],
            };
            b.eval_pdf(input.wo, wi, e).expect("lengths match");
            sum +=
                sum_f32(&out.weight[0][..len]) + sum_f32(&ev.f[0][..len]) + sum_f32(&ev.pdf[..len]);
        } else {
            sum += sum_f32(&out.weight[0][..len]);
        }
        total += f64::from(sum);
        start = end;
    }
    total
}

/// A sum with 16 independent accumulators (vectorizable), so that the
/// checksum costs little next to the kernels.
fn sum_f32(v: &[f32]) -> f32 {
    let mut acc = [0.0f32; 16];
    let mut chunks = v.chunks_exact(16);
    for c in &mut chunks {
        for (a, x) in acc.iter_mut().zip(c) {
            *a += x;
        }
    }
    acc.iter().sum::<f32>() + chunks.remainder().iter().sum::<f32>()
}

/// The median wall time of `reps` timed runs (after one warm-up run) of
/// `threads` workers, each on its part of the inputs.
pub(crate) fn time(job: Job<'_>, threads: usize, reps: usize) -> Duration {
    let inputs = job.inputs;
    let n = inputs.len();
    let chunk = n.div_ceil(threads);
    let start = Barrier::new(threads + 1);
    let end = Barrier::new(threads + 1);
    let mut times = Vec::with_capacity(reps);
    std::thread::scope(|scope| {
        for t in 0..threads {
            let range = (t * chunk).min(n)..((t + 1) * chunk).min(n);
            let (start, end) = (&start, &end);
            scope.spawn(move || {
                let mut out = SampleBuffers::new(BLOCK);
                let mut ev = EvalPdfBuffers::new(BLOCK);
                for _ in 0..=reps {
                    start.wait();
                    black_box(work(job, range.clone(), &mut out, &mut ev));
                    end.wait();
                }
            });
        }
        for rep in 0..=reps {
            let t0 = Instant::now();
            start.wait();
            end.wait();
            if rep > 0 {
                times.push(t0.elapsed());
            }
        }
    });
    times.sort();
    times[times.len() / 2]
}

/// The CPU from /proc/cpuinfo: its model name and, where the file gives
/// them, family and model numbers (a virtual machine's name may be only
/// "AMD EPYC" for several generations: family 25 model 1 is Zen 3, model
/// 17 Zen 4).
pub(crate) fn cpu_model() -> String {
    let Ok(info) = std::fs::read_to_string("/proc/cpuinfo") else {
        return "unknown".into();
    };
    let field = |key: &str| {
        info.lines()
            .find(|l| l.split(':').next().is_some_and(|k| k.trim() == key))
            .and_then(|l| l.split_once(':'))
            .map(|(_, v)| v.trim().to_string())
    };
    let name = field("model name").unwrap_or_else(|| "unknown".into());
    match (field("cpu family"), field("model")) {
        (Some(f), Some(m)) => format!("{name} (family {f}, model {m})"),
        _ => name,
    }
}

fn parse_strategies(list: &str) -> Result<Vec<BsdfStrategy>> {
    list.split(',')
        .map(|s| s.trim().parse::<BsdfStrategy>())
        .collect::<Result<_, _>>()
        .context("--strategy")
}

pub fn run(args: &BenchArgs) -> Result<()> {
    let threads = match &args.threads {
        Some(list) => list.clone(),
        None if args.all => {
            let cpus = std::thread::available_parallelism().map_or(1, usize::from);
            if cpus > 1 { vec![1, cpus] } else { vec![1] }
        }
        None => vec![1],
    };
    if threads.is_empty() || threads.contains(&0) {
        bail!("--threads: every count must be at least 1");
    }
    let reps = args.reps.unwrap_or(if args.all { 3 } else { 7 });
    if args.samples == 0 || reps == 0 {
        bail!("--samples and --reps must be at least 1");
    }
    if args.all {
        return crate::bench_all::run(args.samples, &threads, reps, args.json);
    }
    // (material text, material, strategy) rows.
    let mut rows: Vec<(String, Material, BsdfStrategy)> = Vec::new();
    match &args.material {
        None if args.strategy.is_none() => {
            for (text, s) in DEFAULT_TABLE {
                rows.push((
                    text.to_string(),
                    Material::load(text).context("default table")?,
                    s,
                ));
            }
        }
        None => {
            let m = Material::load(GGX_02).context("default material")?;
            for s in parse_strategies(args.strategy.as_deref().unwrap_or_default())? {
                rows.push((GGX_02.to_string(), m.clone(), s));
            }
        }
        Some(text) => {
            let m = Material::load(text).context("--material")?;
            let strategies = match &args.strategy {
                Some(list) => parse_strategies(list)?,
                None => m.strategies(),
            };
            for s in strategies {
                rows.push((text.clone(), m.clone(), s));
            }
        }
    }
    let samplers: Vec<BatchSampler> = rows
        .iter()
        .map(|(text, m, s)| {
            BatchSampler::new(m, *s).with_context(|| format!("--material {text} --strategy {s}"))
        })
        .collect::<Result<_>>()?;
    let level = samplers.first().map(BatchSampler::level);
    // After every argument is checked: an error stays one line.
    if args.samples < QUOTABLE_SAMPLES {
        eprintln!(
            "lobe bench: note: --samples {} is below 2^22 = {QUOTABLE_SAMPLES}: more of the inputs \
             stay in the caches, so these figures are not comparable with BENCHMARKS.md's",
            args.samples
        );
    }
    let inputs = Inputs::new(args.samples);
    let msps = |d: Duration| args.samples as f64 / d.as_secs_f64() / 1e6;
    let level = level.map_or("none", |l| l.name());
    let cpu = cpu_model();
    // Progress: three timings per row and thread count (on a terminal a
    // bar; otherwise a line every few seconds).
    let bar = crate::common::progress((3 * rows.len() * threads.len()) as u64, "timing", false);
    let mut tables = Vec::new();
    for &t in &threads {
        let mut results = Vec::new();
        for ((text, m, s), b) in rows.iter().zip(&samplers) {
            bar.set_message(format!("timing {s}, {t} threads"));
            let job = |mode| Job {
                mode,
                m,
                strategy: *s,
                b: Some(b),
                inputs: &inputs,
            };
            let full = time(job(Mode::SampleEvalPdf), t, reps);
            let sample = time(job(Mode::Sample), t, reps);
            bar.inc(2);
            let scalar = time(job(Mode::Scalar), t, reps);
            bar.inc(1);
            results.push((text.as_str(), *s, msps(full), msps(sample), msps(scalar)));
        }
        tables.push((t, results));
    }
    bar.finish_and_clear();
    if args.json {
        let objects: Vec<serde_json::Value> = tables
            .iter()
            .map(|(t, results)| {
                serde_json::json!({
                    "simd": level,
                    "cpu": cpu,
                    "threads": t,
                    "samples": args.samples,
                    "reps": reps,
                    "block": BLOCK,
                    "results": results.iter().map(|&(text, s, x, y, z)| serde_json::json!({
                        "material": text,
                        "strategy": s.name(),
                        "msps": x,
                        "sample_msps": y,
                        "scalar_msps": z,
                    })).collect::<Vec<_>>(),
                })
            })
            .collect();
        // One thread count: one object (the shape bench/side_by_side.py
        // reads); several: a list of them.
        let v = match <[_; 1]>::try_from(objects) {
            Ok([one]) => one,
            Err(all) => serde_json::Value::Array(all),
        };
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        for (t, results) in tables {
            println!(
                "cpu {cpu}; simd {level}; {t} threads; {} samples, median of {reps} reps; M samples/s",
                args.samples
            );
            println!(
                "{:<58} {:<15} {:>16} {:>8} {:>17} {:>8}",
                "material", "strategy", "sample+eval+pdf", "sample", "scalar f64 s+e+p", "speedup"
            );
            for (text, s, x, y, z) in results {
                println!(
                    "{text:<58} {:<15} {x:>16.1} {y:>8.1} {z:>17.1} {:>7.1}x",
                    s.name(),
                    x / z
                );
            }
        }
    }
    Ok(())
}
