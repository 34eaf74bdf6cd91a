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

#[test]
fn bench_all_covers_every_model_and_level() {
    let o = lobe(
        &[
            "bench",
            "--all",
            "--samples",
            "4096",
            "--reps",
            "1",
            "--threads",
            "1,2",
            "--json",
        ],
        None,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let levels: Vec<&str> = v["levels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l.as_str().unwrap())
        .collect();
    assert_eq!(levels[0], "scalar", "{levels:?}");
    assert_eq!(v["threads"], serde_json::json!([1, 2]));
    let rows = v["results"].as_array().unwrap();
    // Every model of lobe's list but the measured one (it needs a file).
    let models: std::collections::BTreeSet<String> = rows
        .iter()
        .map(|r| {
            let m: serde_json::Value =
                serde_json::from_str(r["material"].as_str().unwrap()).unwrap();
            m["type"].as_str().unwrap().to_string()
        })
        .collect();
    for name in [
        "diffuse",
        "phong",
        "blinn-phong",
        "cook-torrance",
        "roughconductor",
        "roughdielectric",
        "roughplastic",
        "conductor",
        "dielectric",
        "thindielectric",
        "plastic",
        "twosided",
    ] {
        assert!(models.contains(name), "{name} missing from {models:?}");
    }
    let find = |case: &str, strategy: &str, threads: u64| {
        rows.iter()
            .find(|r| r["case"] == case && r["strategy"] == strategy && r["threads"] == threads)
            .unwrap_or_else(|| panic!("no row {case} {strategy} {threads}"))
    };
    // A batched row has a figure at every level; an unbatched one says why.
    for t in [1, 2] {
        let r = find("roughplastic GGX α 0.2", "vndf", t);
        assert!(r["f64"]["msps"].as_f64().unwrap() > 0.0, "{r}");
        for l in &levels {
            let x = r[*l]["msps"].as_f64().unwrap();
            assert!(x > 0.0 && (r[*l]["ns_per_sample"].as_f64().unwrap() * x - 1e3).abs() < 1e-6);
        }
        let r = find("conductor", "brdf", t);
        assert!(r[levels[0]]["msps"].as_f64().unwrap() > 0.0, "{r}");
        let r = find("cook-torrance GGX α 0.2, Kulla-Conty", "vndf", t);
        assert!(
            r[levels[0]]["not_batched"]
                .as_str()
                .unwrap()
                .contains("Kulla-Conty"),
            "{r}"
        );
    }
    // --all is the whole table: not with --material.
    let o = lobe(
        &["bench", "--all", "--material", "{\"type\":\"diffuse\"}"],
        None,
    );
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--all"));
}
