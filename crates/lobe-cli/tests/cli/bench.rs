//! `lobe bench`: the JSON parses and has its fields; bad input is a
//! one-line error. No timing assertions: speed claims never come from tests.

use crate::common;

use std::process::{Command, Output};

fn lobe(args: &[&str], simd: Option<&str>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_lobe"));
    c.args(args);
    match simd {
        Some(s) => c.env("LOBE_SIMD", s),
        None => c.env_remove("LOBE_SIMD"),
    };
    c.output().expect("run lobe")
}

#[test]
fn bench_json_parses() {
    let o = lobe(&["bench", "--samples", "65536", "--json"], None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(["scalar", "avx2", "avx512"].contains(&v["simd"].as_str().unwrap()));
    assert!(!v["cpu"].as_str().unwrap().is_empty());
    assert_eq!(v["threads"], 1);
    assert_eq!(v["samples"], 65536);
    // Fewer samples than a quotable figure needs: said on stderr, not stdout.
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("below 2^22"), "{err}");
    let r = v["results"].as_array().unwrap();
    let names: Vec<&str> = r.iter().map(|x| x["strategy"].as_str().unwrap()).collect();
    // The default table (BENCHMARKS.md): GGX vndf, GGX brdf, Beckmann vndf.
    assert_eq!(names, ["vndf", "brdf", "vndf"]);
    assert!(r[2]["material"].as_str().unwrap().contains("beckmann"));
    for x in r {
        for k in ["msps", "sample_msps", "scalar_msps"] {
            assert!(x[k].as_f64().unwrap() > 0.0, "{k}: {x}");
        }
    }
}

#[test]
fn bench_forced_level_and_threads() {
    let o = lobe(
        &[
            "bench",
            "--samples",
            "4096",
            "--reps",
            "1",
            "--threads",
            "2",
            "--strategy",
            "brdf",
            "--json",
        ],
        Some("scalar"),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["simd"], "scalar");
    assert_eq!(v["threads"], 2);
    assert_eq!(v["results"].as_array().unwrap().len(), 1);
}

#[test]
fn bench_errors_are_one_line() {
    let o = lobe(&["bench", "--samples", "16"], Some("sse9"));
    assert!(!o.status.success());
    let e = common::one_line_error(&o);
    assert!(e.contains("sse9"), "{e}");
    // A strategy the material does not have: refused as the scalar path
    // refuses it, without claiming the scalar path has it.
    let o = lobe(
        &[
            "bench",
            "--samples",
            "16",
            "--material",
            r#"{"type":"phong","exponent":10}"#,
            "--strategy",
            "spherical-caps",
        ],
        None,
    );
    assert!(!o.status.success());
    let e = common::one_line_error(&o);
    assert!(
        e.contains("spherical-caps")
            && e.contains("does not apply")
            && !e.contains("scalar path has it"),
        "{e}"
    );
}
