//! `lobe bench --all`: the whole table of BENCHMARKS.md, every model ×
//! strategy × SIMD level this CPU runs (beside the scalar f64 path) ×
//! thread count, in M samples/s and ns per sample.

use crate::bench::{Inputs, Job, Mode, cpu_model, time};
use anyhow::{Context, Result};
use lobe::Material;
use lobe::batch::{BatchError, BatchSampler, SimdLevel};
use std::time::Duration;

/// One material per model (and the variants whose kernels differ), with
/// Mitsuba 3's plugin names and parameters wherever Mitsuba has the model,
/// so that `bench/mitsuba_kernels.py --cases-from` can load the same
/// description with `mi.load_dict`. Measured tables need a file and are
/// not in the table (`lobe bench --material` times one).
pub(crate) const CASES: &[(&str, &str)] = &[
    ("diffuse", r#"{"type":"diffuse","reflectance":0.5}"#),
    ("phong n 50", r#"{"type":"phong","ks":0.8,"exponent":50}"#),
    (
        "blinn-phong n 50",
        r#"{"type":"blinn-phong","ks":0.8,"exponent":50}"#,
    ),
    (
        "cook-torrance GGX α 0.2",
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2}"#,
    ),
    (
        "cook-torrance Beckmann α 0.2",
        r#"{"type":"cook-torrance","distribution":"beckmann","alpha":0.2}"#,
    ),
    (
        "cook-torrance Blinn-Phong NDF α 0.2",
        r#"{"type":"cook-torrance","distribution":"blinn-phong","alpha":0.2}"#,
    ),
    (
        "cook-torrance GGX α 0.1 × 0.4",
        r#"{"type":"cook-torrance","distribution":"ggx","alpha_u":0.1,"alpha_v":0.4}"#,
    ),
    (
        "cook-torrance GGX α 0.2 + diffuse",
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2,"ks":0.5,"kd":0.5}"#,
    ),
    (
        "cook-torrance GGX α 0.2, Turquin",
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2,"multiscatter":"turquin"}"#,
    ),
    (
        "cook-torrance GGX α 0.2, Kulla-Conty",
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2,"multiscatter":"kulla-conty"}"#,
    ),
    (
        "roughconductor GGX α 0.2",
        r#"{"type":"roughconductor","distribution":"ggx","alpha":0.2,"material":"none"}"#,
    ),
    (
        "roughconductor Beckmann α 0.2",
        r#"{"type":"roughconductor","distribution":"beckmann","alpha":0.2,"material":"none"}"#,
    ),
    (
        "roughconductor GGX α 0.1 × 0.4, gold",
        r#"{"type":"roughconductor","distribution":"ggx","alpha_u":0.1,"alpha_v":0.4,"material":"Au"}"#,
    ),
    (
        "roughdielectric GGX α 0.2",
        r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.2}"#,
    ),
    (
        "roughdielectric Beckmann α 0.2",
        r#"{"type":"roughdielectric","distribution":"beckmann","alpha":0.2}"#,
    ),
    (
        "roughplastic GGX α 0.2",
        r#"{"type":"roughplastic","distribution":"ggx","alpha":0.2}"#,
    ),
    ("conductor", r#"{"type":"conductor"}"#),
    ("dielectric", r#"{"type":"dielectric"}"#),
    ("thindielectric", r#"{"type":"thindielectric"}"#),
    ("plastic", r#"{"type":"plastic"}"#),
    (
        "twosided diffuse",
        r#"{"type":"twosided","material":{"type":"diffuse","reflectance":0.5}}"#,
    ),
];

/// One timing: M samples/s, or why the level has no kernel for the row.
enum Cell {
    Msps(f64),
    NotBatched(String),
}

struct Row {
    label: &'static str,
    material: &'static str,
    strategy: lobe::BsdfStrategy,
    threads: usize,
    /// The scalar f64 path (`Material`'s sampler, then eval and pdf).
    f64_msps: f64,
    /// One cell per level of `levels`.
    cells: Vec<Cell>,
}

/// Runs the table and prints it (Markdown, or JSON with `json`).
pub(crate) fn run(samples: usize, threads: &[usize], reps: usize, json: bool) -> Result<()> {
    let levels: Vec<SimdLevel> = SimdLevel::ALL
        .into_iter()
        .filter(|l| l.is_available())
        .collect();
    // The f64 path is 20-50× slower and compute bound: a quarter of the
    // inputs (the same first quarter) keeps the table's time in minutes.
    let scalar_samples = (samples / 4).max(1);
    let inputs = Inputs::new(samples);
    let scalar_inputs = Inputs::new(scalar_samples);
    let mut plan = Vec::new();
    for &(label, text) in CASES {
        let m = Material::load(text).with_context(|| format!("bench case {label}: {text}"))?;
        for s in m.strategies() {
            plan.push((label, text, m.clone(), s));
        }
    }
    let bar = crate::common::progress(
        (plan.len() * threads.len() * (levels.len() + 1)) as u64,
        "timing",
        false,
    );
    let msps = |n: usize, d: Duration| n as f64 / d.as_secs_f64() / 1e6;
    let mut rows = Vec::new();
    for &t in threads {
        for (label, text, m, s) in &plan {
            bar.set_message(format!("{label} {s}, {t} threads"));
            let scalar = Job {
                mode: Mode::Scalar,
                m,
                strategy: *s,
                b: None,
                inputs: &scalar_inputs,
            };
            let f64_msps = msps(scalar_samples, time(scalar, t, reps));
            bar.inc(1);
            let mut cells = Vec::new();
            for &level in &levels {
                let cell = match BatchSampler::with_level(m, *s, level) {
                    Ok(b) => {
                        let batch = Job {
                            mode: Mode::SampleEvalPdf,
                            b: Some(&b),
                            inputs: &inputs,
                            ..scalar
                        };
                        Cell::Msps(msps(samples, time(batch, t, reps)))
                    }
                    Err(BatchError::Unsupported { reason }) => Cell::NotBatched(reason),
                    Err(e) => return Err(e).context(format!("{label} {s} at {level}")),
                };
                bar.inc(1);
                cells.push(cell);
            }
            rows.push(Row {
                label,
                material: text,
                strategy: *s,
                threads: t,
                f64_msps,
                cells,
            });
        }
    }
    bar.finish_and_clear();
    let cpu = cpu_model();
    if json {
        print_json(&cpu, &levels, samples, scalar_samples, threads, reps, &rows)
    } else {
        print_markdown(&cpu, &levels, samples, scalar_samples, reps, &rows);
        Ok(())
    }
}

/// A level's column head.
fn level_head(l: SimdLevel) -> String {
    match l {
        SimdLevel::Scalar => "f32 portable (1 lane)".into(),
        SimdLevel::Avx2 => "AVX2 (8 lanes)".into(),
        SimdLevel::Avx512 => "AVX-512 (16 lanes)".into(),
    }
}

/// `M/s · ns` of a throughput on `threads` threads: ns is the wall time per
/// sample (1000 / M/s), so two threads halve it where they scale.
fn cell_text(msps: f64) -> String {
    format!("{msps:.1} · {:.1} ns", 1e3 / msps)
}

fn print_markdown(
    cpu: &str,
    levels: &[SimdLevel],
    samples: usize,
    scalar_samples: usize,
    reps: usize,
    rows: &[Row],
) {
    let names: Vec<&str> = levels.iter().map(|l| l.name()).collect();
    println!(
        "CPU: {cpu}; SIMD levels it runs: {}; lobe {}. Sample + eval + pdf at the sampled \
         direction per sample; M samples/s · wall ns per sample; {samples} inputs \
         ({scalar_samples} for the f64 path), median of {reps} warm reps.\n",
        names.join(", "),
        env!("CARGO_PKG_VERSION"),
    );
    let mut head = String::from("| model | strategy | threads | f64 scalar path |");
    let mut rule = String::from("|---|---|---:|---:|");
    for &l in levels {
        head += &format!(" {} |", level_head(l));
        rule += "---:|";
    }
    head += " best / f64 |";
    rule += "---:|";
    println!("{head}\n{rule}");
    // (case, reason) -> the strategies it holds for.
    let mut reasons: Vec<(&str, String, Vec<String>)> = Vec::new();
    for r in rows {
        let mut line = format!(
            "| {} | {} | {} | {} |",
            r.label,
            r.strategy,
            r.threads,
            cell_text(r.f64_msps)
        );
        let mut best: Option<f64> = None;
        for c in &r.cells {
            match c {
                Cell::Msps(x) => {
                    best = Some(best.map_or(*x, |b: f64| b.max(*x)));
                    line += &format!(" {} |", cell_text(*x));
                }
                Cell::NotBatched(reason) => {
                    line += " — |";
                    let s = r.strategy.to_string();
                    match reasons
                        .iter_mut()
                        .find(|(l, why, _)| *l == r.label && why == reason)
                    {
                        Some((_, _, list)) if !list.contains(&s) => list.push(s),
                        Some(_) => {}
                        None => reasons.push((r.label, reason.clone(), vec![s])),
                    }
                }
            }
        }
        match best {
            Some(b) => line += &format!(" {:.1}× |", b / r.f64_msps),
            None => line += " — |",
        }
        println!("{line}");
    }
    println!("\nThe materials:\n");
    let mut seen = Vec::new();
    for r in rows {
        if !seen.contains(&r.label) {
            seen.push(r.label);
            println!("* {}: `{}`", r.label, r.material);
        }
    }
    if !reasons.is_empty() {
        println!("\n— = no batch kernel (the scalar path serves it):\n");
        for (label, reason, strategies) in reasons {
            println!("* {label} ({}): {reason}", strategies.join(", "));
        }
    }
}

fn print_json(
    cpu: &str,
    levels: &[SimdLevel],
    samples: usize,
    scalar_samples: usize,
    threads: &[usize],
    reps: usize,
    rows: &[Row],
) -> Result<()> {
    let results: Vec<serde_json::Value> = rows
        .iter()
        .map(|r| {
            let mut o = serde_json::json!({
                "case": r.label,
                "material": r.material,
                "strategy": r.strategy.name(),
                "threads": r.threads,
                "f64": {"msps": r.f64_msps, "ns_per_sample": 1e3 / r.f64_msps},
            });
            for (l, c) in levels.iter().zip(&r.cells) {
                o[l.name()] = match c {
                    Cell::Msps(x) => serde_json::json!({"msps": x, "ns_per_sample": 1e3 / x}),
                    Cell::NotBatched(reason) => serde_json::json!({"not_batched": reason}),
                };
            }
            o
        })
        .collect();
    let v = serde_json::json!({
        "cpu": cpu,
        "levels": levels.iter().map(|l| l.name()).collect::<Vec<_>>(),
        "threads": threads,
        "samples": samples,
        "scalar_samples": scalar_samples,
        "reps": reps,
        "lobe": env!("CARGO_PKG_VERSION"),
        "results": results,
    });
    println!("{}", serde_json::to_string_pretty(&v)?);
    Ok(())
}
