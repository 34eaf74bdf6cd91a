//! `lobe eval` end to end: the built binary, stdin to stdout.

use glam::{DVec2, DVec3};
use lobe::{BsdfStrategy, MaterialDesc};
use serde_json::Value;
use std::f64::consts::PI;
use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Stdio};

struct Run {
    code: Option<i32>,
    stdout: String,
    stderr: String,
}

/// Run `lobe ARGS` with `input` on stdin (written from a thread, so that a
/// large input cannot dead-lock against stdout).
fn lobe(args: &[&str], input: impl Into<Vec<u8>>) -> Run {
    let mut child = Command::new(env!("CARGO_BIN_EXE_lobe"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start lobe");
    let mut stdin = child.stdin.take().unwrap();
    let input = input.into();
    let writer = std::thread::spawn(move || {
        // lobe may stop early on an error: a closed pipe is fine.
        let _ = stdin.write_all(&input);
    });
    let out = child.wait_with_output().expect("run lobe");
    writer.join().unwrap();
    Run {
        code: out.status.code(),
        stdout: String::from_utf8(out.stdout).expect("stdout is UTF-8"),
        stderr: String::from_utf8(out.stderr).expect("stderr is UTF-8"),
    }
}

fn eval(material: &str, input: &str) -> Run {
    lobe(&["eval", "--material", material], input)
}

/// The output lines, parsed; panics with stderr unless the run succeeded.
fn ok_lines(run: &Run) -> Vec<Value> {
    assert_eq!(run.code, Some(0), "stderr: {}", run.stderr);
    // Issue 8: a material that gains energy is warned about (one line).
    assert!(
        run.stderr
            .lines()
            .all(|l| l.starts_with("lobe: warning: ") && l.contains("reflects more light")),
        "stderr: {}",
        run.stderr
    );
    run.stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{l}: {e}")))
        .collect()
}

/// Assert a one-line error that contains every piece of `needles`.
fn assert_error(run: &Run, needles: &[&str]) {
    assert_eq!(
        run.code,
        Some(1),
        "stdout: {}\nstderr: {}",
        run.stdout,
        run.stderr
    );
    let err = run.stderr.as_str();
    assert!(err.starts_with("lobe: error: "), "{err}");
    assert_eq!(err.lines().count(), 1, "not one line: {err}");
    for n in needles {
        assert!(err.contains(n), "{err:?} does not contain {n:?}");
    }
}

fn vec3(v: &Value) -> DVec3 {
    let a = v
        .as_array()
        .unwrap_or_else(|| panic!("{v} is not an array"));
    assert_eq!(a.len(), 3);
    DVec3::new(
        a[0].as_f64().unwrap(),
        a[1].as_f64().unwrap(),
        a[2].as_f64().unwrap(),
    )
}

fn json3(v: DVec3) -> String {
    // Rust's f64 Display is the shortest string that parses back exactly.
    format!("[{},{},{}]", v.x, v.y, v.z)
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + 1e-300
}

fn dir(theta: f64, phi: f64) -> DVec3 {
    lobe::frame::spherical_direction(theta, phi)
}

fn tmp(name: &str, text: &str) -> PathBuf {
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::write(&path, text).unwrap();
    path
}

const CT: &str = r#"{"type":"cook-torrance","alpha":0.2}"#;
const CT_KD: &str = r#"{"type":"cook-torrance","alpha":0.3,"kd":[0.3,0.2,0.1],"fresnel":{"type":"schlick","f0":[0.9,0.6,0.3]}}"#;

#[test]
fn lambert_f_is_albedo_over_pi_and_cosine_pdf_is_cos_over_pi() {
    let albedo = DVec3::new(0.2, 0.5, 0.8);
    let dirs: Vec<(DVec3, DVec3)> = (0..20)
        .map(|i| {
            let t = i as f64 / 20.0;
            (
                dir(1.5 * t, 0.3 + 5.0 * t),
                dir(1.55 * (1.0 - t), 2.0 - 3.0 * t),
            )
        })
        .collect();
    let input: String = dirs
        .iter()
        .map(|(wo, wi)| format!("{{\"wo\":{},\"wi\":{}}}\n", json3(*wo), json3(*wi)))
        .collect();
    let run = eval(r#"{"type":"lambert","albedo":[0.2,0.5,0.8]}"#, &input);
    let lines = ok_lines(&run);
    assert_eq!(lines.len(), dirs.len());
    for ((_, wi), line) in dirs.iter().zip(&lines) {
        let f = vec3(&line["f"]);
        for c in 0..3 {
            assert!(close(f[c], albedo[c] / PI, 1e-14), "{line}");
        }
        let pdf = line["pdf"].as_object().unwrap();
        assert!(
            close(pdf["cosine"].as_f64().unwrap(), wi.z / PI, 1e-14),
            "{line}"
        );
        assert!(
            close(pdf["uniform"].as_f64().unwrap(), 0.5 / PI, 1e-14),
            "{line}"
        );
    }
    // Every strategy that applies, in the core's order.
    let m = MaterialDesc::from_json(r#"{"type":"lambert"}"#)
        .unwrap()
        .build()
        .unwrap();
    let names: Vec<&str> = m.strategies().iter().map(|s| s.name()).collect();
    let first = run.stdout.lines().next().unwrap();
    let positions: Vec<usize> = names
        .iter()
        .map(|n| {
            first
                .find(&format!("\"{n}\":"))
                .unwrap_or_else(|| panic!("{n} in {first}"))
        })
        .collect();
    assert!(positions.windows(2).all(|w| w[0] < w[1]), "{first}");
    assert_eq!(lines[0]["pdf"].as_object().unwrap().len(), names.len());
    // Below the horizon: zero.
    let line = &ok_lines(&eval(
        r#"{"type":"lambert"}"#,
        r#"{"wo":[0,0,-1],"wi":[0,0,1]}"#,
    ))[0];
    assert_eq!(vec3(&line["f"]), DVec3::ZERO);
    assert_eq!(line["pdf"]["cosine"].as_f64(), Some(0.0));
}

/// Sample lines, then the pdf lines of the directions they returned: the two
/// pdfs agree, and weight = f cos / pdf.
#[test]
fn samples_round_trip_through_pdf_lines() {
    for material in [
        CT,
        CT_KD,
        r#"{"type":"phong","exponent":20,"kd":0.2,"ks":0.5}"#,
        r#"{"type":"lambert"}"#,
    ] {
        let m = MaterialDesc::from_json(material).unwrap().build().unwrap();
        let mut queries = Vec::new();
        for s in m.strategies() {
            for i in 0..40 {
                let wo = dir(0.05 + 1.4 * (i % 8) as f64 / 8.0, i as f64);
                let u = DVec2::new(
                    (i as f64 * 0.618_034) % 1.0,
                    (i as f64 * 0.414_213_5 + 0.1) % 1.0,
                );
                let uc = (i as f64 * 0.271_828) % 1.0;
                queries.push((s, wo, u, uc));
            }
        }
        let input: String = queries
            .iter()
            .map(|(s, wo, u, uc)| {
                format!(
                    "{{\"wo\":{},\"u\":[{},{}],\"uc\":{uc},\"strategy\":\"{s}\"}}\n",
                    json3(*wo),
                    u.x,
                    u.y
                )
            })
            .collect();
        let samples = ok_lines(&eval(material, &input));
        assert_eq!(samples.len(), queries.len());

        let mut pdf_input = String::new();
        let mut drawn = Vec::new();
        for ((s, wo, u, uc), out) in queries.iter().zip(&samples) {
            // Full precision: the printed numbers are exactly the core's.
            let expected = m.sampler(*s).unwrap().sample(*wo, *uc, *u);
            if out["wi"].is_null() {
                assert!(expected.is_none(), "{material} {s}: {out}");
                assert_eq!(out["pdf"].as_f64(), Some(0.0));
                assert_eq!(vec3(&out["weight"]), DVec3::ZERO);
                continue;
            }
            let e = expected
                .unwrap_or_else(|| panic!("{material} {s}: the core failed, lobe gave {out}"));
            let wi = vec3(&out["wi"]);
            assert_eq!(wi, e.wi, "{out}");
            assert_eq!(
                out["pdf"].as_f64().unwrap().to_bits(),
                e.pdf.to_bits(),
                "{out}"
            );
            assert_eq!(vec3(&out["weight"]), e.weight, "{out}");
            pdf_input += &format!("{{\"wo\":{},\"wi\":{}}}\n", json3(*wo), json3(wi));
            drawn.push((*s, wi, out.clone()));
        }
        assert!(
            drawn.len() > queries.len() / 2,
            "{material}: too many failed samples"
        );
        let evals = ok_lines(&eval(material, &pdf_input));
        assert_eq!(evals.len(), drawn.len());
        for ((s, wi, sample), ev) in drawn.iter().zip(&evals) {
            let pdf = sample["pdf"].as_f64().unwrap();
            let pdf_line = ev["pdf"][s.name()].as_f64().unwrap();
            assert!(
                close(pdf, pdf_line, 1e-9),
                "{material} {s}: sample pdf {pdf}, pdf line {pdf_line}"
            );
            let f = vec3(&ev["f"]);
            let weight = vec3(&sample["weight"]);
            for c in 0..3 {
                assert!(
                    close(weight[c], f[c] * wi.z / pdf, 1e-9),
                    "{material} {s}: {sample} vs {ev}"
                );
            }
        }
    }
}

#[test]
fn failed_samples_give_null() {
    // Below the horizon.
    let line = &ok_lines(&eval(
        CT,
        r#"{"wo":[0,0,-1],"u":[0.3,0.7],"strategy":"vndf"}"#,
    ))[0];
    assert!(line["wi"].is_null());
    assert_eq!(line["pdf"].as_f64(), Some(0.0));
    assert_eq!(vec3(&line["weight"]), DVec3::ZERO);

    // A classic half-vector sample at grazing wo that falls below the horizon.
    let m = MaterialDesc::from_json(CT).unwrap().build().unwrap();
    let wo = dir(1.45, 0.0);
    let u = (0..64 * 64)
        .map(|k| DVec2::new((k % 64) as f64 / 64.0, (k / 64) as f64 / 64.0))
        .find(|&u| {
            m.sampler(BsdfStrategy::Brdf)
                .unwrap()
                .sample(wo, 0.5, u)
                .is_none()
        })
        .expect("a failed brdf sample at grazing wo");
    let input = format!(
        "{{\"wo\":{},\"u\":[{},{}],\"strategy\":\"brdf\"}}\n",
        json3(wo),
        u.x,
        u.y
    );
    let run = eval(CT, &input);
    assert_eq!(run.stdout, "{\"wi\":null,\"pdf\":0,\"weight\":[0,0,0]}\n");
    assert_eq!(run.code, Some(0));
}

#[test]
fn empty_lines_are_skipped_and_uc_is_required_with_two_lobes() {
    let input = "\n{\"wo\":[0,0,1],\"wi\":[0,0,1]}\n\n  \n{\"wo\":[0,0,1],\"u\":[0.1,0.2],\"strategy\":\"cosine\"}\r\n\n";
    let lines = ok_lines(&eval(CT_KD, input));
    assert_eq!(lines.len(), 2);
    // Issue 8: uc no longer defaults to 0.5 where it chooses a lobe (a fixed
    // uc always takes the same lobe, a silent bias): an error naming it.
    let run = eval(
        CT_KD,
        r#"{"wo":[0.6,0,0.8],"u":[0.1,0.2],"strategy":"brdf"}"#,
    );
    assert_eq!(run.code, Some(1));
    assert!(
        run.stderr.contains("stdin line 1: field \"uc\": missing")
            && run.stderr.contains("two lobes"),
        "{}",
        run.stderr
    );
    // A single-lobe material may omit it: it does not change the sample.
    let one = r#"{"type":"cook-torrance","alpha":0.3}"#;
    let with_uc = ok_lines(&eval(
        one,
        r#"{"wo":[0.6,0,0.8],"u":[0.1,0.2],"uc":0.5,"strategy":"brdf"}"#,
    ));
    let without = ok_lines(&eval(
        one,
        r#"{"wo":[0.6,0,0.8],"u":[0.1,0.2],"strategy":"brdf"}"#,
    ));
    assert_eq!(with_uc, without);
}

/// Issue 8: the issue's example, with `uc` drawn like `u`: the mean weight
/// of a two-lobe material is its albedo (0.798), not the 0.938 that the
/// old default `uc = 0.5` gave.
#[test]
fn random_uc_gives_the_albedo() {
    let m = r#"{"type":"cook-torrance","alpha":0.6,"kd":0.5,"ks":0.5}"#;
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut input = String::new();
    for _ in 0..40_000 {
        input += &format!(
            "{{\"wo\":[0.5,0,0.8660254037844386],\"u\":[{},{}],\"uc\":{},\"strategy\":\"vndf\"}}\n",
            next(),
            next(),
            next()
        );
    }
    let lines = ok_lines(&eval(m, &input));
    let mean: f64 = lines
        .iter()
        .map(|l| l["weight"][0].as_f64().unwrap())
        .sum::<f64>()
        / lines.len() as f64;
    assert!((mean - 0.798).abs() < 0.01, "mean weight {mean}");
}

#[test]
fn malformed_lines_name_the_line_and_field() {
    let good = "{\"wo\":[0,0,1],\"wi\":[0,0,1]}\n";
    // (input line, needles); the bad line is line 3, after a good line and an empty one.
    let cases: &[(&str, &[&str])] = &[
        (
            r#"{"wo":[0,0,1],"wi":[0,0,1]"#,
            &["stdin line 3", "invalid JSON"],
        ),
        (r#"not json"#, &["stdin line 3", "invalid JSON"]),
        (r#"[0,0,1]"#, &["stdin line 3", "JSON object"]),
        (
            r#"{"wi":[0,0,1]}"#,
            &["stdin line 3", "field \"wo\": missing"],
        ),
        (
            r#"{"wo":[0,0,1]}"#,
            &["stdin line 3", "field \"wi\": missing"],
        ),
        (
            r#"{"wo":[0,1],"wi":[0,0,1]}"#,
            &["stdin line 3", "field \"wo\": expected 3 numbers"],
        ),
        (
            r#"{"wo":[0,0,1],"wi":[0,0,1,0]}"#,
            &["stdin line 3", "field \"wi\": expected 3 numbers"],
        ),
        (
            r#"{"wo":[0,0,"1"],"wi":[0,0,1]}"#,
            &["stdin line 3", "field \"wo\"", "expected a number"],
        ),
        (
            r#"{"wo":"up","wi":[0,0,1]}"#,
            &["stdin line 3", "field \"wo\"", "array of 3 numbers"],
        ),
        (
            r#"{"wo":[0,0,2],"wi":[0,0,1]}"#,
            &["stdin line 3", "field \"wo\"", "unit vector", "length is 2"],
        ),
        (
            r#"{"wo":[0,0,1],"wi":[0.6,0,0.80001]}"#,
            &["stdin line 3", "field \"wi\"", "unit vector"],
        ),
        (
            r#"{"wo":[0,0,0],"wi":[0,0,1]}"#,
            &["stdin line 3", "field \"wo\"", "length zero"],
        ),
        (
            r#"{"wo":[1e300,1e300,0],"wi":[0,0,1]}"#,
            &["stdin line 3", "field \"wo\"", "not finite"],
        ),
        (
            r#"{"wo":[0,0,1],"wi":[0,0,1e999]}"#,
            &["stdin line 3", "field \"wi\"", "out of range"],
        ),
        (
            r#"{"wo":[0,0,1],"wi":[0,0,1],"w":1}"#,
            &["stdin line 3", "unknown key \"w\""],
        ),
        (
            r#"{"wo":[0,0,1],"wo":[0,0,1],"wi":[0,0,1]}"#,
            &["stdin line 3", "field \"wo\": given twice"],
        ),
        (
            r#"{"wo":[0,0,1],"u":[0.5,0.5],"strategy":"vdnf"}"#,
            &["stdin line 3", "field \"strategy\"", "vdnf", "vndf"],
        ),
        (
            r#"{"wo":[0,0,1],"u":[0.5,0.5],"strategy":3}"#,
            &["stdin line 3", "field \"strategy\""],
        ),
        (
            r#"{"wo":[0,0,1],"u":[0.5,1.0],"strategy":"vndf"}"#,
            &["stdin line 3", "field \"u\"", "[0, 1)"],
        ),
        (
            r#"{"wo":[0,0,1],"u":[-0.1,0.5],"strategy":"vndf"}"#,
            &["stdin line 3", "field \"u\"", "[0, 1)"],
        ),
        (
            r#"{"wo":[0,0,1],"u":[0.5],"strategy":"vndf"}"#,
            &["stdin line 3", "field \"u\": expected 2 numbers"],
        ),
        (
            r#"{"wo":[0,0,1],"u":[0.5,0.5],"uc":1,"strategy":"vndf"}"#,
            &["stdin line 3", "field \"uc\"", "[0, 1)"],
        ),
        (
            r#"{"wo":[0,0,1],"strategy":"vndf"}"#,
            &["stdin line 3", "field \"u\": missing"],
        ),
        (
            r#"{"wo":[0,0,1],"wi":[0,0,1],"u":[0.5,0.5],"strategy":"vndf"}"#,
            &["stdin line 3", "field \"wi\""],
        ),
        (
            r#"{"wo":[0,0,1],"wi":[0,0,1],"u":[0.5,0.5]}"#,
            &["stdin line 3", "field \"u\"", "strategy"],
        ),
    ];
    for (bad, needles) in cases {
        let run = eval(CT, &format!("{good}\n{bad}\n{good}"));
        assert_error(&run, needles);
        // The answer to the good line before the error is not lost.
        assert_eq!(run.stdout.lines().count(), 1, "{bad}: {}", run.stdout);
    }
    let run = lobe(
        &["eval", "-m", CT],
        b"{\"wo\":[0,0,1],\"wi\":[0,0,\xff]}\n".to_vec(),
    );
    assert_error(&run, &["stdin line 1", "UTF-8"]);
}

#[test]
fn a_strategy_that_does_not_apply_is_an_error() {
    let run = eval(
        r#"{"type":"lambert"}"#,
        r#"{"wo":[0,0,1],"u":[0.5,0.5],"strategy":"vndf"}"#,
    );
    assert_error(
        &run,
        &[
            "stdin line 1",
            "field \"strategy\"",
            "vndf",
            "does not apply",
        ],
    );
    let run = eval(
        r#"{"type":"cook-torrance","distribution":"beckmann"}"#,
        r#"{"wo":[0,0,1],"u":[0.5,0.5],"strategy":"spherical-caps"}"#,
    );
    assert_error(&run, &["stdin line 1", "spherical-caps", "does not apply"]);
}

#[test]
fn bad_materials_name_the_field() {
    let cases: &[(&str, &[&str])] = &[
        (
            r#"{"type":"phong","exponent":"a"}"#,
            &["material: ", "field `exponent`"],
        ),
        (
            r#"{"type":"phong","exponent":-1}"#,
            &["material: ", "field `exponent`"],
        ),
        (
            r#"{"type":"phong","exponnt":3}"#,
            &["material: ", "exponnt"],
        ),
        (r#"{"type":"glass"}"#, &["material: ", "`type`", "glass"]),
        (r#"{"alpha":0.2}"#, &["material: ", "missing field `type`"]),
        (
            r#"{"type":"cook-torrance","fresnel":{"type":"schlick","f0":"x"}}"#,
            &["material: ", "fresnel.f0"],
        ),
        (
            r#"{"type":"cook-torrance","alpha":0.2"#,
            &["material: ", "invalid JSON"],
        ),
        (r#"{"type":"lambert"} x"#, &["material: ", "invalid JSON"]),
        ("lambert", &["material: ", "JSON"]),
    ];
    for (material, needles) in cases {
        // The material is checked before any input is read.
        let run = eval(material, "");
        assert_error(&run, needles);
        assert!(run.stdout.is_empty());
    }
}

#[test]
fn material_files_json_and_toml() {
    let input = "{\"wo\":[0.6,0,0.8],\"wi\":[0,0.28,0.96]}\n{\"wo\":[0.6,0,0.8],\"u\":[0.2,0.9],\"uc\":0.1,\"strategy\":\"vndf\"}\n";
    let expected = eval(CT_KD, input);
    assert_eq!(ok_lines(&expected).len(), 2);

    let json = tmp("material.json", CT_KD);
    let toml = tmp(
        "material.toml",
        "type = \"cook-torrance\"\nalpha = 0.3\nkd = [0.3, 0.2, 0.1]\n\n[fresnel]\ntype = \"schlick\"\nf0 = [0.9, 0.6, 0.3]\n",
    );
    for path in [&json, &toml] {
        let run = eval(&format!("@{}", path.display()), input);
        ok_lines(&run);
        assert_eq!(run.stdout, expected.stdout, "{}", path.display());
    }
    // The example of `lobe eval --help`.
    let gold = tmp(
        "gold.toml",
        "type = \"cook-torrance\"\nalpha = 0.2\nfresnel = { type = \"conductor\" }\n",
    );
    assert_eq!(
        ok_lines(&eval(&format!("@{}", gold.display()), input)).len(),
        2
    );

    let bad = tmp("bad.toml", "type = \"phong\"\n\nexponent = \"a\"\n");
    assert_error(
        &eval(&format!("@{}", bad.display()), ""),
        &["material (file ", "bad.toml", "field `exponent`", "line 3"],
    );
    let bad = tmp("range.toml", "type = \"phong\"\nexponent = -2\n");
    assert_error(
        &eval(&format!("@{}", bad.display()), ""),
        &["material (file ", "range.toml)", "field `exponent`"],
    );
    let bad = tmp("syntax.toml", "type = \"phong\"\nexponent = \n");
    assert_error(
        &eval(&format!("@{}", bad.display()), ""),
        &["material (file ", "invalid TOML", "line 2"],
    );
    let bad = tmp("bad.json", "{\"type\":\"phong\",\n\"exponent\":true}");
    assert_error(
        &eval(&format!("@{}", bad.display()), ""),
        &["material (file ", "bad.json", "field `exponent`", "line 2"],
    );

    let missing = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("no-such-material.toml");
    assert_error(
        &eval(&format!("@{}", missing.display()), ""),
        &["material (file ", "no-such-material.toml", "cannot read"],
    );
    assert_error(&eval("@", ""), &["material: ", "file name"]);
}

#[test]
fn help_shows_examples_and_material_defaults() {
    let run = lobe(&["eval", "--help"], "");
    assert_eq!(run.code, Some(0));
    assert!(
        run.stdout.contains(lobe::models::defaults()),
        "{}",
        run.stdout
    );
    assert!(
        run.stdout.contains("Examples:") && run.stdout.contains("lobe eval"),
        "{}",
        run.stdout
    );
    assert!(run.stdout.contains(&BsdfStrategy::names()));
    for args in [&["--help"][..], &["demo", "--help"], &["eval", "-h"]] {
        let run = lobe(args, "");
        assert_eq!(run.code, Some(0), "{args:?}");
        assert!(run.stdout.contains("Example"), "{args:?}: {}", run.stdout);
    }
    // Usage errors are clap's (exit 2).
    assert_eq!(lobe(&["eval"], "").code, Some(2));
    assert_eq!(lobe(&["frobnicate"], "").code, Some(2));
}

/// Every model, strategy and awkward direction (poles, grazing, below the
/// horizon): an answer, never a crash or a NaN.
#[test]
fn awkward_directions_never_crash() {
    let materials = [
        r#"{"type":"lambert","albedo":0}"#,
        r#"{"type":"phong","exponent":0}"#,
        r#"{"type":"phong","exponent":1e7,"kd":0.5}"#,
        r#"{"type":"blinn-phong","exponent":1e7,"normalized":false}"#,
        r#"{"type":"cook-torrance","alpha":1e-4}"#,
        r#"{"type":"cook-torrance","alpha":2}"#,
        r#"{"type":"cook-torrance","alpha_u":1e-4,"alpha_v":2,"distribution":"beckmann","shadowing":"v-cavity"}"#,
        r#"{"type":"cook-torrance","alpha":1e-4,"distribution":"blinn-phong","fresnel":{"type":"dielectric"}}"#,
    ];
    let dirs = [
        DVec3::Z,
        -DVec3::Z,
        DVec3::X,
        DVec3::new(1.0, 0.0, 1e-12).normalize(),
        DVec3::new(0.0, -1.0, 1e-300),
        dir(1e-8, 0.0),
        DVec3::new(-0.6, 0.0, 0.8),
        DVec3::new(0.6, 0.0, 0.8),
    ];
    let us = [
        [0.0, 0.0],
        [0.5, 0.5],
        [0.999_999_999_999, 0.999_999_999_999],
        [0.0, 0.999_999_999_999],
    ];
    for material in materials {
        let m = MaterialDesc::from_json(material).unwrap().build().unwrap();
        let mut input = String::new();
        for wo in dirs {
            for wi in dirs {
                input += &format!("{{\"wo\":{},\"wi\":{}}}\n", json3(wo), json3(wi));
            }
            for s in m.strategies() {
                for u in us {
                    for uc in [0.0, 0.999_999] {
                        input += &format!(
                            "{{\"wo\":{},\"u\":[{},{}],\"uc\":{uc},\"strategy\":\"{s}\"}}\n",
                            json3(wo),
                            u[0],
                            u[1]
                        );
                    }
                }
            }
        }
        let run = eval(material, &input);
        // A non-finite result would be an error that names the line: either
        // way, no panic (101) and no NaN on stdout.
        assert!(
            run.code == Some(0) || (run.code == Some(1) && run.stderr.contains("not finite")),
            "{material}: {}",
            run.stderr
        );
        assert!(
            !run.stdout.contains("NaN") && !run.stdout.contains("inf"),
            "{material}"
        );
        if run.code == Some(0) {
            assert_eq!(ok_lines(&run).len(), input.lines().count());
        }
    }
}

/// A million lines of both kinds (the time is measured by hand, not here).
#[test]
fn a_million_lines() {
    let n = 1_000_000;
    let mut input = String::with_capacity(n * 80);
    let strategies = [
        "vndf",
        "brdf",
        "cosine",
        "spherical-caps",
        "bounded-vndf",
        "uniform",
    ];
    for i in 0..n {
        let t = (i as f64 * 0.618_033_988_749_895) % 1.0;
        let wo = dir(1.5 * t, 6.0 * t);
        if i % 2 == 0 {
            let wi = dir(1.5 * (1.0 - t), 2.0 - 3.0 * t);
            input += &format!("{{\"wo\":{},\"wi\":{}}}\n", json3(wo), json3(wi));
        } else {
            let u = (
                (i as f64 * 0.414_213_562) % 1.0,
                (i as f64 * 0.732_050_807) % 1.0,
            );
            let s = strategies[i % strategies.len()];
            input += &format!(
                "{{\"wo\":{},\"u\":[{},{}],\"uc\":{t},\"strategy\":\"{s}\"}}\n",
                json3(wo),
                u.0,
                u.1
            );
        }
    }
    let run = eval(CT_KD, &input);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert_eq!(run.stdout.lines().count(), n);
    let first: Value = serde_json::from_str(run.stdout.lines().next().unwrap()).unwrap();
    assert!(first["f"].is_array() && first["pdf"]["vndf"].is_f64());
    let last: Value = serde_json::from_str(run.stdout.lines().last().unwrap()).unwrap();
    assert!(last.get("wi").is_some() && last["weight"].is_array());
}
