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
use lobe::batch::{BatchSampler, Dirs, DirsMut, EvalPdfOutput, RgbMut, SampleInput, SampleOutput};
use lobe::{BsdfStrategy, Material};
use serde::Serialize;
use std::io::{self, BufRead, Write};

/// Lines per block.
pub const BLOCK: usize = 4096;

/// Structure-of-arrays columns of one kind of line in a block.
#[derive(Default)]
struct Columns {
    /// Position of each entry among the block's lines.
    slot: Vec<usize>,
    /// Input line number, for errors.
    line: Vec<usize>,
    a: [Vec<f32>; 3],
    b: [Vec<f32>; 3],
    u1: Vec<f32>,
    u2: Vec<f32>,
    uc: Vec<f32>,
    // Outputs.
    f: [Vec<f32>; 3],
    pdf: Vec<f32>,
    weight: [Vec<f32>; 3],
    valid: Vec<u8>,
    /// One pdf column per strategy (eval lines).
    pdfs: Vec<Vec<f32>>,
}

impl Columns {
    fn clear(&mut self) {
        self.slot.clear();
        self.line.clear();
        for v in self.a.iter_mut().chain(&mut self.b) {
            v.clear();
        }
        self.u1.clear();
        self.u2.clear();
        self.uc.clear();
    }

    fn len(&self) -> usize {
        self.slot.len()
    }

    /// Size the output columns to the inputs.
    fn size_outputs(&mut self, pdf_columns: usize) {
        let n = self.len();
        for v in self.f.iter_mut().chain(&mut self.weight) {
            v.resize(n, 0.0);
        }
        self.pdf.resize(n, 0.0);
        self.valid.resize(n, 0);
        self.pdfs.resize_with(pdf_columns, Vec::new);
        for p in &mut self.pdfs {
            p.resize(n, 0.0);
        }
    }
}

/// A direction as the line gave it (checked to be unit within
/// [`crate::eval_line::UNIT_TOLERANCE`]), rounded to f32.
fn push3(cols: &mut [Vec<f32>; 3], v: [f64; 3]) {
    cols[0].push(v[0] as f32);
    cols[1].push(v[1] as f32);
    cols[2].push(v[2] as f32);
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
    let mut evals = Columns::default();
    let mut samples: Vec<Columns> = strategies.iter().map(|_| Columns::default()).collect();
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
                        places.push(Place::Eval(evals.len()));
                        evals.slot.push(places.len() - 1);
                        evals.line.push(n);
                        push3(&mut evals.a, wo);
                        push3(&mut evals.b, wi);
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
                        places.push(Place::Sample(k, c.len()));
                        c.slot.push(places.len() - 1);
                        c.line.push(n);
                        push3(&mut c.a, wo);
                        c.u1.push(unit_interval_f32(u.x));
                        c.u2.push(unit_interval_f32(u.y));
                        c.uc.push(unit_interval_f32(uc));
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
    evals: &mut Columns,
    samples: &mut [Columns],
    places: &mut Vec<Place>,
    out: &mut W,
) -> Result<(), Failure> {
    if places.is_empty() {
        return Ok(());
    }
    // Eval lines: f from the first strategy's kernel (as the Python
    // package's `Material.eval`: GGX's vndf and brdf kernels compute f
    // another way, equal to rounding), and every strategy's pdf.
    if evals.len() > 0 {
        evals.size_outputs(strategies.len());
        let first = evals.line[0];
        for (k, &s) in strategies.iter().enumerate() {
            let sampler = sampler(samplers, material, s, k, first)?;
            let c = &mut *evals;
            if k == 0 {
                let [fr, fg, fb] = &mut c.f;
                sampler.eval_pdf(
                    dirs(&c.a),
                    dirs(&c.b),
                    EvalPdfOutput {
                        f: RgbMut {
                            r: fr,
                            g: fg,
                            b: fb,
                        },
                        pdf: &mut c.pdfs[k],
                    },
                )
            } else {
                sampler.pdf(dirs(&c.a), dirs(&c.b), &mut c.pdfs[k])
            }
            .expect("columns of one length");
        }
    }
    for (k, c) in samples.iter_mut().enumerate() {
        if c.len() == 0 {
            continue;
        }
        c.size_outputs(0);
        let sampler = sampler(samplers, material, strategies[k], k, c.line[0])?;
        let uc = material.chooses_lobe(strategies[k]).then_some(&c.uc[..]);
        let [wx, wy, wz] = &mut c.b;
        for v in [&mut *wx, &mut *wy, &mut *wz] {
            v.resize(c.slot.len(), 0.0);
        }
        let [fr, fg, fb] = &mut c.f;
        let [r, g, b] = &mut c.weight;
        sampler
            .sample(
                SampleInput {
                    wo: dirs(&c.a),
                    u1: &c.u1,
                    u2: &c.u2,
                    uc,
                },
                SampleOutput {
                    wi: DirsMut {
                        x: wx,
                        y: wy,
                        z: wz,
                    },
                    f: RgbMut {
                        r: fr,
                        g: fg,
                        b: fb,
                    },
                    pdf: &mut c.pdf,
                    weight: RgbMut { r, g, b },
                    valid: &mut c.valid,
                },
            )
            .expect("columns of one length");
    }
    // Write in input order.
    for &place in places.iter() {
        match place {
            Place::Eval(i) => {
                let c = &*evals;
                let f = [c.f[0][i], c.f[1][i], c.f[2][i]];
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
                    let p = c.pdfs[k][i];
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
                let c = &samples[k];
                if c.valid[i] == 0 {
                    out.write_all(b"{\"wi\":null,\"pdf\":0,\"weight\":[0,0,0]}\n")?;
                    continue;
                }
                let wi = [c.b[0][i], c.b[1][i], c.b[2][i]];
                let w = [c.weight[0][i], c.weight[1][i], c.weight[2][i]];
                let p = c.pdf[i];
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
    evals.clear();
    for c in samples.iter_mut() {
        c.clear();
    }
    Ok(())
}

fn dirs(c: &[Vec<f32>; 3]) -> Dirs<'_> {
    Dirs {
        x: &c[0],
        y: &c[1],
        z: &c[2],
    }
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
