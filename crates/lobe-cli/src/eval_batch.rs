//! `lobe eval --batch`: the same lines as `lobe eval`, answered by the f32
//! batch kernels ([`lobe::batch::BatchSampler`]) in blocks.
//!
//! Lines are read and checked one at a time exactly as the default path
//! does (same errors, same line numbers); up to [`BLOCK`] checked lines are
//! gathered, split by kind (eval lines, and sample lines per strategy),
//! run through the kernels, and written back in input order. The numbers
//! printed are the f32 results, in the shortest form that parses back to
//! the same f32.

use crate::eval_line::{Failure, Request, parse_line, unit_interval_f32};
use lobe::batch::{BatchSampler, DirPairs, EvalPdfBuffers, SampleBuffers, SampleInputs};
use lobe::{BsdfStrategy, Material};
use serde::Serialize;
use std::io::{self, BufRead, Write};

/// Lines per block.
pub const BLOCK: usize = 4096;

/// The eval lines of a block: their pairs, `f` from the first strategy's
/// kernel and one pdf column per strategy.
#[derive(Default)]
struct EvalLines {
    /// Input line number of each, for errors.
    line: Vec<usize>,
    pairs: DirPairs,
    out: EvalPdfBuffers,
    pdfs: Vec<Vec<f32>>,
}

/// The sample lines of one strategy in a block.
#[derive(Default)]
struct SampleLines {
    /// Input line number of each, for errors.
    line: Vec<usize>,
    inputs: SampleInputs,
    out: SampleBuffers,
}

/// A direction as the line gave it (checked to be unit within
/// [`crate::eval_line::UNIT_TOLERANCE`]), rounded to f32.
fn f32x3(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

/// Where each line of a block went.
#[derive(Clone, Copy)]
enum Place {
    Eval(usize),
    /// Strategy index, entry.
    Sample(usize, usize),
}

/// Answer every line of `input` on `out` through the batch kernels.
pub fn process_batch<R: BufRead, W: Write>(
    material: &Material,
    mut input: R,
    out: &mut W,
) -> Result<(), Failure> {
    let strategies = material.strategies();
    let keys: Vec<String> = strategies
        .iter()
        .map(|s| format!("\"{}\":", s.name()))
        .collect();
    // Built on first use, so that a material whose batch path lacks a
    // strategy still answers the lines that do not need it.
    let mut samplers: Vec<Option<BatchSampler>> = strategies.iter().map(|_| None).collect();
    let mut evals = EvalLines::default();
    let mut samples: Vec<SampleLines> = strategies.iter().map(|_| SampleLines::default()).collect();
    let mut places: Vec<Place> = Vec::with_capacity(BLOCK);
    let mut line = String::with_capacity(256);
    let mut n = 0usize;
    loop {
        if places.len() == BLOCK {
            run_block(
                material,
                &strategies,
                &keys,
                &mut samplers,
                &mut evals,
                &mut samples,
                &mut places,
                out,
            )?;
        }
        line.clear();
        n += 1;
        let read = input.read_line(&mut line);
        let stop: Option<Failure> = match read {
            Ok(0) => None,
            Ok(_) => {
                let text = line.trim();
                if text.is_empty() {
                    continue;
                }
                match parse_line(text).and_then(|q| q.check(material, &strategies)) {
                    Err(m) => Some(Failure::Line(n, m)),
                    Ok(Request::Eval {
                        given: [wo, wi], ..
                    }) => {
                        places.push(Place::Eval(evals.line.len()));
                        evals.line.push(n);
                        evals.pairs.push(f32x3(wo), f32x3(wi));
                        continue;
                    }
                    Ok(Request::Sample {
                        strategy,
                        given_wo: wo,
                        u,
                        uc,
                        ..
                    }) => {
                        let k = strategies
                            .iter()
                            .position(|&s| s == strategy)
                            .expect("check() accepts only the material's strategies");
                        let c = &mut samples[k];
                        places.push(Place::Sample(k, c.line.len()));
                        c.line.push(n);
                        c.inputs.push(
                            f32x3(wo),
                            unit_interval_f32(u.x),
                            unit_interval_f32(u.y),
                            unit_interval_f32(uc),
                        );
                        continue;
                    }
                }
            }
            Err(e) if e.kind() == io::ErrorKind::InvalidData => {
                Some(Failure::Line(n, "not valid UTF-8".into()))
            }
            Err(e) => Some(Failure::Line(n, format!("cannot read stdin: {e}"))),
        };
        // End of input or a bad line: answer the lines before it first.
        run_block(
            material,
            &strategies,
            &keys,
            &mut samplers,
            &mut evals,
            &mut samples,
            &mut places,
            out,
        )?;
        return match stop {
            None => Ok(()),
            Some(f) => Err(f),
        };
    }
}

/// The sampler of strategy `k`, built on first use; the error names the
/// first line that needed it.
fn sampler<'a>(
    samplers: &'a mut [Option<BatchSampler>],
    material: &Material,
    strategy: BsdfStrategy,
    k: usize,
    line: usize,
) -> Result<&'a BatchSampler, Failure> {
    if samplers[k].is_none() {
        let s = BatchSampler::new(material, strategy)
            .map_err(|e| Failure::Line(line, format!("--batch, strategy `{strategy}`: {e}")))?;
        samplers[k] = Some(s);
    }
    Ok(samplers[k].as_ref().expect("just built"))
}

#[allow(clippy::too_many_arguments)]
fn run_block<W: Write>(
    material: &Material,
    strategies: &[BsdfStrategy],
    keys: &[String],
    samplers: &mut [Option<BatchSampler>],
    evals: &mut EvalLines,
    samples: &mut [SampleLines],
    places: &mut Vec<Place>,
    out: &mut W,
) -> Result<(), Failure> {
    if places.is_empty() {
        return Ok(());
    }
    // Eval lines: f from the first strategy's kernel (as the Python
    // package's `Material.eval`: GGX's vndf and brdf kernels compute f
    // another way, equal to rounding), and every strategy's pdf.
    if !evals.pairs.is_empty() {
        let n = evals.pairs.len();
        evals.out.resize(n);
        evals.pdfs.resize_with(strategies.len(), Vec::new);
        let first = evals.line[0];
        for (k, &s) in strategies.iter().enumerate() {
            let sampler = sampler(samplers, material, s, k, first)?;
            let (wo, wi) = (evals.pairs.wo(), evals.pairs.wi());
            if k == 0 {
                sampler.eval_pdf(wo, wi, evals.out.output())
            } else {
                evals.pdfs[k].resize(n, 0.0);
                sampler.pdf(wo, wi, &mut evals.pdfs[k])
            }
            .expect("columns of one length");
        }
    }
    for (k, c) in samples.iter_mut().enumerate() {
        if c.inputs.is_empty() {
            continue;
        }
        c.out.resize(c.inputs.len());
        let sampler = sampler(samplers, material, strategies[k], k, c.line[0])?;
        sampler
            .sample(c.inputs.input(sampler.chooses_lobe()), c.out.output())
            .expect("columns of one length");
    }
    // Write in input order.
    for &place in places.iter() {
        match place {
            Place::Eval(i) => {
                let c = &*evals;
                let f = [c.out.f[0][i], c.out.f[1][i], c.out.f[2][i]];
                if !f.iter().all(|x| x.is_finite()) {
                    return Err(Failure::Line(
                        c.line[i],
                        format!("f is not finite ({f:?}) in f32"),
                    ));
                }
                out.write_all(b"{\"f\":")?;
                write3(out, f)?;
                out.write_all(b",\"pdf\":{")?;
                for (k, key) in keys.iter().enumerate() {
                    let p = if k == 0 { c.out.pdf[i] } else { c.pdfs[k][i] };
                    if !p.is_finite() {
                        return Err(Failure::Line(
                            c.line[i],
                            format!(
                                "the pdf of strategy `{}` is not finite ({p}) in f32",
                                strategies[k]
                            ),
                        ));
                    }
                    if k > 0 {
                        out.write_all(b",")?;
                    }
                    out.write_all(key.as_bytes())?;
                    write_f32(out, p)?;
                }
                out.write_all(b"}}\n")?;
            }
            Place::Sample(k, i) => {
                let (c, o) = (&samples[k], &samples[k].out);
                if o.valid[i] == 0 {
                    out.write_all(b"{\"wi\":null,\"pdf\":0,\"weight\":[0,0,0]}\n")?;
                    continue;
                }
                let wi = [o.wi[0][i], o.wi[1][i], o.wi[2][i]];
                let w = [o.weight[0][i], o.weight[1][i], o.weight[2][i]];
                let p = o.pdf[i];
                if !(wi.iter().chain(&w).all(|x| x.is_finite()) && p.is_finite()) {
                    return Err(Failure::Line(
                        c.line[i],
                        format!(
                            "the sample is not finite in f32 (wi {wi:?}, pdf {p}, weight {w:?})"
                        ),
                    ));
                }
                out.write_all(b"{\"wi\":")?;
                write3(out, wi)?;
                out.write_all(b",\"pdf\":")?;
                write_f32(out, p)?;
                out.write_all(b",\"weight\":")?;
                write3(out, w)?;
                out.write_all(b"}\n")?;
            }
        }
    }
    places.clear();
    evals.line.clear();
    evals.pairs.clear();
    for c in samples.iter_mut() {
        c.line.clear();
        c.inputs.clear();
    }
    Ok(())
}

/// A finite `f32`, shortest form that parses back to the same f32.
fn write_f32<W: Write>(out: &mut W, x: f32) -> io::Result<()> {
    x.serialize(&mut serde_json::Serializer::new(out))
        .map_err(io::Error::from)
}

fn write3<W: Write>(out: &mut W, v: [f32; 3]) -> io::Result<()> {
    out.write_all(b"[")?;
    write_f32(out, v[0])?;
    out.write_all(b",")?;
    write_f32(out, v[1])?;
    out.write_all(b",")?;
    write_f32(out, v[2])?;
    out.write_all(b"]")
}
