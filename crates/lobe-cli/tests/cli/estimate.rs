//! `lobe estimate` end to end: the table and JSON, the same numbers for any
//! thread count, and one-line errors for bad input.

use std::process::{Command, Output};

fn lobe(args: &[&str], threads: Option<&str>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_lobe"));
    c.args(args);
    if let Some(t) = threads {
        c.env("RAYON_NUM_THREADS", t);
    }
    c.output().expect("run lobe")
}

const GGX: &str = r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2,"kd":0.1}"#;

fn json(threads: &str, sequence: &str) -> serde_json::Value {
    let o = lobe(
        &[
            "estimate",
            "--material",
            GGX,
            "--theta",
            "60",
            "--light",
            "beam:8:0.3,1,0.2",
            "--samples",
            "100000",
            "--seed",
            "7",
            "--sequence",
            sequence,
            "--json",
            "--quiet",
        ],
        Some(threads),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // Wall time and efficiency are measurements of this run, not results.
    for row in v["strategies"].as_array_mut().unwrap() {
        row.as_object_mut().unwrap().remove("time_s");
        row.as_object_mut().unwrap().remove("efficiency");
    }
    v
}

#[test]
fn same_seed_same_json_whatever_the_thread_count() {
    for seq in ["independent", "stratified", "sobol"] {
        assert_eq!(json("1", seq), json("2", seq), "{seq}");
    }
}

#[test]
fn json_has_every_field_and_estimates_agree_with_the_reference() {
    let v = json("2", "independent");
    let r = v["reference"].as_array().unwrap();
    assert_eq!(r.len(), 3);
    let names: Vec<&str> = v["strategies"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "uniform",
            "cosine",
            "brdf",
            "vndf",
            "spherical-caps",
            "bounded-vndf",
            "light",
            "mis",
            "mis-balance",
            "mis-power"
        ]
    );
    for s in v["strategies"].as_array().unwrap() {
        for k in [
            "samples",
            "mean",
            "stderr",
            "variance",
            "variance_reduction",
        ] {
            assert!(s.get(k).is_some(), "missing {k}");
        }
        for c in 0..3 {
            let (m, e, r) = (
                s["mean"][c].as_f64().unwrap(),
                s["stderr"][c].as_f64().unwrap(),
                r[c].as_f64().unwrap(),
            );
            assert!((m - r).abs() <= 5.0 * e, "{}: {m} ± {e} vs {r}", s["name"]);
        }
    }
    // Issue 8: against uniform's exact variance by quadrature (before: the
    // measured one, which made uniform's own ratio exactly 1).
    let u = v["strategies"][0]["variance_reduction"].as_f64().unwrap();
    assert!((u - 1.0).abs() < 0.05, "{u}");
    assert_eq!(v["stderr_method"], "independent-samples");
    assert!(v["replicas"].is_null());
    assert!(v["uniform_variance"]["reliable"].as_bool().unwrap());
}

/// Issue 41: under the sky's sun, cosine sampling's weights are heavy
/// tailed: its standard error is marked `!` with a one-line legend, light
/// sampling's is not, and the JSON says which; a smooth case prints no mark
/// and no legend.
#[test]
fn heavy_tails_mark_the_standard_error_and_only_then_a_legend() {
    let run = |light: &str, json: bool| {
        let mut args = vec![
            "estimate",
            "-m",
            r#"{"type":"lambert"}"#,
            "--theta",
            "30",
            "--light",
            light,
            "--strategy",
            "cosine,light",
            "--quiet",
        ];
        if json {
            args.push("--json");
        }
        let o = lobe(&args, None);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).unwrap()
    };
    let out = run("sky", false);
    let row = |name: &str| out.lines().find(|l| l.starts_with(name)).unwrap();
    assert!(row("cosine ").contains('!'), "{out}");
    assert!(!row("light ").contains('!'), "{out}");
    let legend: Vec<&str> = out.lines().filter(|l| l.starts_with("!: ")).collect();
    assert_eq!(legend.len(), 1, "{out}");
    assert!(
        legend[0].contains("heavy-tailed") && legend[0].contains("0.15"),
        "{out}"
    );
    let v: serde_json::Value = serde_json::from_str(&run("sky", true)).unwrap();
    let rows = v["strategies"].as_array().unwrap();
    assert_eq!(rows[0]["stderr_reliable"], false);
    assert!(rows[0]["variance_rel_stderr"].as_f64().unwrap() > 0.15);
    assert_eq!(rows[1]["stderr_reliable"], true);
    let out = run("beam:4:0,0,1", false);
    assert!(!out.contains('!'), "{out}");
}

#[test]
fn the_table_names_the_reference_method() {
    let o = lobe(
        &[
            "estimate",
            "--material",
            r#"{"type":"phong","exponent":100}"#,
            "--theta",
            "30",
            "--samples",
            "4096",
            "--quiet",
        ],
        None,
    );
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success());
    assert!(
        out.contains("quadrature") && out.contains("brdf") && out.contains("uniform"),
        "{out}"
    );
}

#[test]
fn bad_input_is_one_line_and_non_zero() {
    let cases: [(&[&str], &str); 8] = [
        (&["--strategy", "importance"], "unknown strategy"),
        (&["--strategy", "vndf"], "vndf"),
        (&["--sequence", "halton"], "sequence"),
        (&["--samples", "0"], "--samples"),
        (&["--theta", "90"], "--theta"),
        (&["--wo", "0,0,-1"], "below the horizon"),
        (&["--light", "sun"], "--light"),
        (
            &["--material", r#"{"type":"phong","exponent":-3}"#],
            "exponent",
        ),
    ];
    for (extra, expect) in cases {
        let mut args = vec!["estimate", "--quiet"];
        if extra[0] != "--material" {
            args.extend(["--material", r#"{"type":"phong"}"#]);
        }
        args.extend_from_slice(extra);
        let o = lobe(&args, None);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.contains(expect) && !err.contains("panicked"),
            "{args:?}: {err}"
        );
    }
}

/// Issue 41: the `unreliable` note is printed only when a row is unreliable
/// (uniform sampling of a very narrow lobe with few samples misses it).
#[test]
fn the_unreliable_note_only_when_a_row_is_unreliable() {
    let note = "unreliable: the estimate";
    let smooth = lobe(
        &[
            "estimate",
            "-m",
            r#"{"type":"phong","exponent":10}"#,
            "-n",
            "4096",
            "-q",
        ],
        None,
    );
    assert!(smooth.status.success());
    let out = String::from_utf8_lossy(&smooth.stdout);
    assert!(!out.contains("unreliable"), "{out}");
    let narrow = lobe(
        &[
            "estimate",
            "-m",
            r#"{"type":"phong","exponent":100000}"#,
            "-n",
            "64",
            "--strategy",
            "uniform,brdf",
            "-q",
        ],
        None,
    );
    assert!(narrow.status.success());
    let out = String::from_utf8_lossy(&narrow.stdout);
    let uniform = out.lines().find(|l| l.starts_with("uniform ")).unwrap();
    assert!(uniform.contains("unreliable"), "{out}");
    assert!(out.contains(note), "{out}");
}

/// Issue 41: a zero-variance estimator (BRDF sampling of Lambert under a
/// constant light: every sample is the albedo) prints a variance of 0 and
/// `exact`, not the rounding's 3e-33 and 7.7e31x; the JSON says the same.
#[test]
fn a_zero_variance_estimator_is_exact() {
    let args = [
        "estimate",
        "-m",
        r#"{"type":"lambert"}"#,
        "--strategy",
        "uniform,brdf",
        "-n",
        "4096",
        "-q",
    ];
    let o = lobe(&args, None);
    assert!(o.status.success());
    let out = String::from_utf8_lossy(&o.stdout);
    let brdf: Vec<&str> = out
        .lines()
        .find(|l| l.starts_with("brdf "))
        .unwrap()
        .split_whitespace()
        .collect();
    // strategy, estimate, std. error, rel. err, variance, vs uniform, time, efficiency
    assert_eq!(brdf[2], "0.000000", "{out}");
    assert_eq!(brdf[4], "0", "{out}");
    assert_eq!(brdf[5], "exact", "{out}");
    assert!(
        !out.contains("e31") && !out.contains("e32") && !out.contains("e33"),
        "{out}"
    );
    assert!(out.contains("exact: zero variance up to rounding"), "{out}");
    let mut args = args.to_vec();
    args.push("--json");
    let v: serde_json::Value = serde_json::from_slice(&lobe(&args, None).stdout).unwrap();
    let row = &v["strategies"][1];
    assert_eq!(row["name"], "brdf");
    assert_eq!(row["variance"], 0.0);
    assert!(row["variance_reduction"].is_null(), "{row}");
    // Uniform's row is not exact.
    assert!(v["strategies"][0]["variance"].as_f64().unwrap() > 0.1);
}
