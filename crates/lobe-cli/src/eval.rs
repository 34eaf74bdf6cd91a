//! `lobe eval`: evaluate, give the pdfs of, and sample a material, one JSON
//! line at a time (stdin to stdout).
//!
//! The hot loop reuses one line buffer, parses each line with a hand-written
//! serde visitor (no allocation unless the line is bad) and writes numbers
//! straight into a buffered stdout.

use crate::eval_line::{Failure, Request, UNIT_TOLERANCE, parse_line};
use anyhow::{Result, anyhow};
use clap::Args;
use glam::DVec3;
use lobe::{BsdfSampler, BsdfStrategy, Material};
use serde::Serialize;
use std::io::{self, BufRead, BufWriter, Write};

/// The arguments of `lobe eval`.
#[derive(Args, Debug)]
#[command(
    about = "Evaluate f, the pdfs and samples of a material, one JSON line at a time",
    long_about = long_about(),
    after_help = "Example:\n  echo '{\"wo\":[0.6,0,0.8],\"wi\":[0,0,1]}' | lobe eval --material '{\"type\":\"cook-torrance\",\"alpha\":0.2}'\n\n\
                  `lobe eval --help` also lists the material keys and their defaults.",
    after_long_help = after_long_help(),
)]
pub struct EvalArgs {
    /// The material: JSON text, or @FILE.json, or @FILE.toml
    #[arg(long, short = 'm', value_name = "JSON|@FILE")]
    pub material: String,
    /// Answer the lines with the f32 SIMD batch kernels (lobe::batch), in
    /// blocks of 4096 lines: the same fields, f32 numbers, within 1e-4
    /// relative (f, pdf, weight) and 1e-5 absolute (wi) of the default f64 path
    #[arg(long)]
    pub batch: bool,
}

fn long_about() -> String {
    format!(
        "Read JSON lines on stdin and write one JSON object per line on stdout.\n\
         \n\
         An eval line gives f (without the cosine) and the pdf, in solid angle, of every\n\
         strategy that applies to the material:\n  \
         {{\"wo\":[x,y,z],\"wi\":[x,y,z]}}\n  \
         -> {{\"f\":[r,g,b],\"pdf\":{{\"uniform\":p,\"cosine\":p,\"brdf\":p,...}}}}\n\
         \n\
         A sample line draws one direction wi for wo with a strategy:\n  \
         {{\"wo\":[x,y,z],\"u\":[u1,u2],\"uc\":u,\"strategy\":\"vndf\"}}\n  \
         -> {{\"wi\":[x,y,z],\"pdf\":p,\"weight\":[r,g,b]}}\n\
         where weight = f cos(theta_i) / pdf. A failed sample (below the horizon) gives\n\
         {{\"wi\":null,\"pdf\":0,\"weight\":[0,0,0]}}; an estimator still counts it.\n\
         \n\
         Directions are in the local shading frame (+z is the normal), point away from\n\
         the surface, and must be unit vectors: |length - 1| <= {UNIT_TOLERANCE:e}. u1, u2 and uc\n\
         are in [0, 1). uc chooses the lobe of a two-lobe material (a diffuse term kd and\n\
         a glossy lobe): it is required there, for every strategy but uniform and cosine,\n\
         and must be an independent uniform number like u1 and u2 (a fixed uc always takes\n\
         the same lobe, which biases any average of the weights). A single-lobe material\n\
         does not use it and may omit it.\n\
         Strategies: {}.\n\
         Empty lines are skipped. Numbers are printed so that they parse back to the same\n\
         f64. A bad line, or a result that is not finite, stops with an error that names\n\
         the line and the field.\n\
         \n\
         --batch answers the same lines with the f32 SIMD kernels (lobe::batch) in blocks\n\
         of 4096 lines; numbers parse back to the same f32. It agrees with the default\n\
         f64 path to 1e-4 relative (f, pdf, weight) and 1e-5 absolute (wi).",
        BsdfStrategy::names()
    )
}

fn after_long_help() -> String {
    format!(
        "Examples:\n  \
         echo '{{\"wo\":[0.6,0,0.8],\"wi\":[0,0,1]}}' | lobe eval --material '{{\"type\":\"cook-torrance\",\"alpha\":0.2}}'\n  \
         echo '{{\"wo\":[0.6,0,0.8],\"u\":[0.3,0.7],\"uc\":0.4,\"strategy\":\"vndf\"}}' | lobe eval -m @examples/gold.toml\n  \
         echo '{{\"wo\":[0.6,0,0.8],\"u\":[0.3,0.7],\"uc\":0.4,\"strategy\":\"vndf\"}}' | lobe eval -m @examples/ggx.toml\n\
         \n\
         A TOML material file (examples/gold.toml):\n  \
         type = \"cook-torrance\"\n  \
         alpha = 0.2\n  \
         fresnel = {{ type = \"conductor\" }}\n\
         \n\
         {}",
        lobe::models::defaults()
    )
}

/// Run `lobe eval`: stdin to stdout.
pub fn run(args: &EvalArgs) -> Result<()> {
    let material = crate::common::load_material(&args.material)?;
    let mut out = BufWriter::with_capacity(1 << 16, io::stdout().lock());
    let result = if args.batch {
        crate::eval_batch::process_batch(&material, io::stdin().lock(), &mut out)
    } else {
        process(&material, io::stdin().lock(), &mut out)
    };
    // Flush what was computed before any error, so that the lines before a bad
    // line reach the reader.
    let flushed = out.flush();
    match result {
        Ok(()) => {}
        Err(Failure::Write(e)) if e.kind() == io::ErrorKind::BrokenPipe => return Ok(()),
        Err(Failure::Write(e)) => return Err(anyhow!("cannot write to stdout: {e}")),
        Err(Failure::Line(n, message)) => return Err(anyhow!("stdin line {n}: {message}")),
    }
    match flushed {
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => {
            Err(anyhow!("cannot write to stdout: {e}"))
        }
        _ => Ok(()),
    }
}

/// Answer every line of `input` on `out`.
pub fn process<R: BufRead, W: Write>(
    material: &Material,
    mut input: R,
    out: &mut W,
) -> Result<(), Failure> {
    let strategies = material.strategies();
    // Each strategy resolved once: the material has every one of them.
    let samplers: Vec<BsdfSampler<'_>> = strategies
        .iter()
        .filter_map(|&s| material.sampler(s).ok())
        .collect();
    // `"name":` for each strategy, written before its pdf.
    let keys: Vec<String> = strategies
        .iter()
        .map(|s| format!("\"{}\":", s.name()))
        .collect();
    let mut pdfs = vec![0.0; strategies.len()];
    let mut line = String::with_capacity(256);
    let mut n = 0usize;
    loop {
        line.clear();
        n += 1;
        match input.read_line(&mut line) {
            Ok(0) => return Ok(()),
            Ok(_) => {}
            Err(e) if e.kind() == io::ErrorKind::InvalidData => {
                return Err(Failure::Line(n, "not valid UTF-8".into()));
            }
            Err(e) => return Err(Failure::Line(n, format!("cannot read stdin: {e}"))),
        }
        let text = line.trim();
        if text.is_empty() {
            continue;
        }
        let request = parse_line(text)
            .and_then(|q| q.check(material, &strategies))
            .map_err(|m| Failure::Line(n, m))?;
        match request {
            Request::Eval { wo, wi, .. } => {
                let f = material.eval(wo, wi);
                if !f.is_finite() {
                    return Err(Failure::Line(
                        n,
                        format!("f is not finite ({f}) for wo {wo} and wi {wi}"),
                    ));
                }
                for (p, sampler) in pdfs.iter_mut().zip(&samplers) {
                    let s = sampler.strategy();
                    *p = sampler.pdf(wo, wi);
                    if !p.is_finite() {
                        return Err(Failure::Line(
                            n,
                            format!(
                                "the pdf of strategy `{s}` is not finite ({p}) for wo {wo} and wi {wi}"
                            ),
                        ));
                    }
                }
                out.write_all(b"{\"f\":")?;
                write_vec3(out, f)?;
                out.write_all(b",\"pdf\":{")?;
                for (i, (key, &p)) in keys.iter().zip(&pdfs).enumerate() {
                    if i > 0 {
                        out.write_all(b",")?;
                    }
                    out.write_all(key.as_bytes())?;
                    write_f64(out, p)?;
                }
                out.write_all(b"}}\n")?;
            }
            Request::Sample {
                strategy,
                wo,
                u,
                uc,
                ..
            } => match samplers
                .iter()
                .find(|x| x.strategy() == strategy)
                .and_then(|x| x.sample(wo, uc, u))
            {
                None => out.write_all(b"{\"wi\":null,\"pdf\":0,\"weight\":[0,0,0]}\n")?,
                Some(s) => {
                    if !(s.wi.is_finite() && s.pdf.is_finite() && s.weight.is_finite()) {
                        return Err(Failure::Line(
                            n,
                            format!(
                                "the sample is not finite (wi {}, pdf {}, weight {})",
                                s.wi, s.pdf, s.weight
                            ),
                        ));
                    }
                    out.write_all(b"{\"wi\":")?;
                    write_vec3(out, s.wi)?;
                    out.write_all(b",\"pdf\":")?;
                    write_f64(out, s.pdf)?;
                    out.write_all(b",\"weight\":")?;
                    write_vec3(out, s.weight)?;
                    out.write_all(b"}\n")?;
                }
            },
        }
    }
}

/// A finite `f64`, shortest form that parses back to the same value.
fn write_f64<W: Write>(out: &mut W, x: f64) -> io::Result<()> {
    x.serialize(&mut serde_json::Serializer::new(out))
        .map_err(io::Error::from)
}

fn write_vec3<W: Write>(out: &mut W, v: DVec3) -> io::Result<()> {
    out.write_all(b"[")?;
    write_f64(out, v.x)?;
    out.write_all(b",")?;
    write_f64(out, v.y)?;
    out.write_all(b",")?;
    write_f64(out, v.z)?;
    out.write_all(b"]")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run_lines(material: &str, input: &str) -> Result<String, String> {
        let m = lobe::Material::load(material).map_err(|e| e.to_string())?;
        let mut out = Vec::new();
        match process(&m, input.as_bytes(), &mut out) {
            Ok(()) => Ok(String::from_utf8(out).unwrap()),
            Err(Failure::Line(n, m)) => Err(format!("stdin line {n}: {m}")),
            Err(Failure::Write(e)) => Err(e.to_string()),
        }
    }

    #[test]
    fn errors_name_line_and_field() {
        let lambert = r#"{"type":"lambert"}"#;
        let e = run_lines(
            lambert,
            "{\"wo\":[0,0,1],\"wi\":[0,0,1]}\n\n{\"wo\":[0,1],\"wi\":[0,0,1]}\n",
        )
        .unwrap_err();
        assert_eq!(e, "stdin line 3: field \"wo\": expected 3 numbers, got 2");
        let e = run_lines(lambert, r#"{"wo":[0,0,1],"wi":[0,0,"a"]}"#).unwrap_err();
        assert_eq!(
            e,
            "stdin line 1: field \"wi\": invalid type: string \"a\", expected a number"
        );
        let e = run_lines(lambert, r#"{"wo":[0,0,1],"w":[0,0,1]}"#).unwrap_err();
        assert!(e.starts_with("stdin line 1: unknown key \"w\""), "{e}");
        let e = run_lines(lambert, r#"{"wo":[0,0,1],"wo":[0,0,1]}"#).unwrap_err();
        assert_eq!(e, "stdin line 1: field \"wo\": given twice");
        let e = run_lines(lambert, r#"{"wo":[0,0,1],"wi":[0,0,1]} x"#).unwrap_err();
        assert!(
            e.starts_with("stdin line 1: invalid JSON: trailing characters"),
            "{e}"
        );
        let e = run_lines(lambert, r#"[1]"#).unwrap_err();
        assert!(e.starts_with("stdin line 1: invalid type: sequence"), "{e}");
    }

    #[test]
    fn numbers_round_trip() {
        let mut v = Vec::new();
        for x in [
            0.1,
            1.0 / 3.0,
            1e-300,
            5e-324,
            1e300,
            f64::MAX,
            0.0,
            -0.0,
            3.0,
        ] {
            v.clear();
            write_f64(&mut v, x).unwrap();
            let back: f64 = serde_json::from_slice(&v).unwrap();
            assert_eq!(
                back.to_bits(),
                x.to_bits(),
                "{}",
                String::from_utf8_lossy(&v)
            );
        }
    }

    /// Issue 8: a sample line without `uc` on a two-lobe material is an
    /// error naming the field (it used to default to 0.5, always taking the
    /// same lobe); a single-lobe material, or a strategy that does not
    /// choose a lobe, may omit it.
    #[test]
    fn uc_is_required_where_it_chooses_a_lobe() {
        let two = r#"{"type":"cook-torrance","alpha":0.6,"kd":0.5,"ks":0.5}"#;
        let line = r#"{"wo":[0.5,0,0.8660254037844386],"u":[0.3,0.7],"strategy":"vndf"}"#;
        let e = run_lines(two, line).unwrap_err();
        assert!(e.starts_with("stdin line 1: field \"uc\": missing"), "{e}");
        assert!(e.contains("two lobes"), "{e}");
        let with_uc =
            r#"{"wo":[0.5,0,0.8660254037844386],"u":[0.3,0.7],"uc":0.9,"strategy":"vndf"}"#;
        assert!(run_lines(two, with_uc).is_ok());
        let cosine = r#"{"wo":[0.5,0,0.8660254037844386],"u":[0.3,0.7],"strategy":"cosine"}"#;
        assert!(run_lines(two, cosine).is_ok());
        let one = r#"{"type":"cook-torrance","alpha":0.6}"#;
        assert!(run_lines(one, line).is_ok());
    }
}
