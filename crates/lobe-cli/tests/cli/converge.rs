//! `lobe converge` end to end: the built binary, its files and its errors.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A smooth integrand: Phong n = 10 under a smooth beam light, sampled with
/// the cosine strategy (`f·L·cos/p = π f L` is smooth over the square).
const MATERIAL: &str = r#"{"type":"phong","exponent":10}"#;
const LIGHT: &str = "beam:8";

/// A fresh, empty directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("converge-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn lobe(args: &[&str], threads: Option<&str>) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_lobe"));
    cmd.args(args);
    if let Some(t) = threads {
        cmd.env("RAYON_NUM_THREADS", t);
    }
    cmd.output().expect("run lobe")
}

fn converge(prefix: &Path, extra: &[&str], threads: Option<&str>) -> Output {
    let prefix = prefix.to_str().unwrap();
    let mut args = vec![
        "converge",
        "--material",
        MATERIAL,
        "--theta",
        "30",
        "--light",
        LIGHT,
        "--out",
        prefix,
        "--quiet",
    ];
    args.extend_from_slice(extra);
    lobe(&args, threads)
}

fn assert_ok(out: &Output) {
    assert!(
        out.status.success(),
        "lobe converge failed: {}\n{}",
        String::from_utf8_lossy(&out.stderr),
        String::from_utf8_lossy(&out.stdout)
    );
}

/// The slope of every `strategy/sequence` in the CSV, with a check of its shape.
fn slopes(csv: &str, max_exp: u32) -> BTreeMap<String, f64> {
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("strategy,sequence,n,rmse,slope"));
    let mut out = BTreeMap::new();
    let mut rows: BTreeMap<String, Vec<u64>> = BTreeMap::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 5, "line {line}");
        let key = format!("{}/{}", f[0], f[1]);
        let n: u64 = f[2].parse().unwrap();
        let rmse: f64 = f[3].parse().unwrap();
        assert!(rmse.is_finite() && rmse >= 0.0, "line {line}");
        let slope: f64 = f[4].parse().unwrap_or_else(|_| panic!("no slope: {line}"));
        if let Some(&s) = out.get(&key) {
            assert_eq!(s, slope, "one slope per series: {line}");
        }
        out.insert(key.clone(), slope);
        rows.entry(key).or_default().push(n);
    }
    let expect: Vec<u64> = (0..=max_exp).map(|k| 1u64 << k).collect();
    for (key, ns) in &rows {
        assert_eq!(ns, &expect, "{key}: N must be 2^0 .. 2^{max_exp}");
    }
    out
}

#[test]
fn sobol_beats_monte_carlo_on_a_smooth_integrand() {
    let dir = scratch("slopes");
    let prefix = dir.join("phong");
    let out = converge(
        &prefix,
        &[
            "--strategy",
            "cosine",
            "--seed",
            "2",
            "--runs",
            "64",
            "--max-exp",
            "14",
        ],
        None,
    );
    assert_ok(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("upper half"), "stdout: {stdout}");

    for ext in ["csv", "svg", "png"] {
        let p = dir.join(format!("phong.{ext}"));
        let len = std::fs::metadata(&p)
            .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
            .len();
        assert!(len > 100, "{} is nearly empty", p.display());
    }
    let png = std::fs::read(dir.join("phong.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "not a PNG");
    let img = image::load_from_memory(&png).expect("the PNG decodes");
    assert!(img.width() >= 400 && img.height() >= 300);
    let svg = std::fs::read_to_string(dir.join("phong.svg")).unwrap();
    assert!(svg.contains("<svg"), "not an SVG");

    let csv = std::fs::read_to_string(dir.join("phong.csv")).unwrap();
    let s = slopes(&csv, 14);
    assert_eq!(s.len(), 3, "three series: {s:?}");
    let independent = s["cosine/independent"];
    let stratified = s["cosine/stratified"];
    let sobol = s["cosine/sobol"];
    eprintln!("slopes: independent {independent}, stratified {stratified}, sobol {sobol}");
    assert!(
        (independent + 0.5).abs() < 0.1,
        "independent sampling converges as N^-1/2, got slope {independent}"
    );
    assert!(
        sobol < -0.75,
        "Sobol points converge faster than N^-3/4 on a smooth integrand, got slope {sobol}"
    );
    assert!(
        stratified < independent,
        "stratification helps: {stratified} vs {independent}"
    );
}

#[test]
fn same_seed_gives_the_same_csv_on_any_thread_count() {
    let dir = scratch("threads");
    let mut csvs = Vec::new();
    for threads in ["1", "2"] {
        let prefix = dir.join(format!("t{threads}"));
        let out = converge(
            &prefix,
            &[
                "--runs",
                "6",
                "--max-exp",
                "10",
                "--strategy",
                "uniform,brdf",
                "--seed",
                "2",
            ],
            Some(threads),
        );
        assert_ok(&out);
        csvs.push(std::fs::read(dir.join(format!("t{threads}.csv"))).unwrap());
    }
    assert!(!csvs[0].is_empty());
    assert!(
        csvs[0] == csvs[1],
        "RAYON_NUM_THREADS=1 and =2 gave different CSVs"
    );
    // A different seed gives different numbers.
    let prefix = dir.join("other");
    let out = converge(
        &prefix,
        &[
            "--runs",
            "6",
            "--max-exp",
            "10",
            "--strategy",
            "uniform,brdf",
            "--seed",
            "8",
        ],
        None,
    );
    assert_ok(&out);
    assert!(std::fs::read(dir.join("other.csv")).unwrap() != csvs[0]);
}

/// A failure with exit code 1 and a one-line message naming `needle`.
fn assert_one_line_error(out: &Output, needle: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "stderr: {stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "stderr: {stderr}");
    assert!(stderr.starts_with("lobe: error: "), "stderr: {stderr}");
    assert!(stderr.contains(needle), "`{needle}` not in: {stderr}");
}

#[test]
fn bad_inputs_fail_with_one_line() {
    let dir = scratch("errors");
    let prefix = dir.join("x");
    let cases: [(&[&str], &str); 5] = [
        (&["--sequence", "halton"], "halton"),
        (&["--sequence", "sobol,nope"], "nope"),
        (&["--max-exp", "21"], "--max-exp 21"),
        (&["--runs", "0"], "--runs 0"),
        (&["--strategy", "vndf"], "vndf"),
    ];
    for (extra, needle) in cases {
        let out = converge(&prefix, extra, None);
        assert_one_line_error(&out, needle);
    }
    assert!(
        !dir.join("x.csv").exists(),
        "nothing is written on a bad input"
    );
}

#[test]
fn help_has_an_example() {
    let out = lobe(&["converge", "--help"], None);
    assert!(out.status.success());
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(help.contains("lobe converge --material"), "{help}");
    assert!(help.contains("--max-exp"), "{help}");
}

/// Many curves: one panel per sequence side by side, the light in the
/// title, every strategy in the legends.
#[test]
fn many_curves_get_a_panel_per_sequence() {
    let dir = scratch("many");
    let prefix = dir.join("ggx");
    let out = lobe(
        &[
            "converge",
            "-m",
            r#"{"type":"cook-torrance","alpha":0.2}"#,
            "--theta",
            "45",
            "--light",
            "beam:8",
            "--runs",
            "2",
            "--max-exp",
            "4",
            "--out",
            prefix.to_str().unwrap(),
            "--quiet",
        ],
        None,
    );
    assert_ok(&out);
    let csv = std::fs::read_to_string(dir.join("ggx.csv")).unwrap();
    let series: std::collections::BTreeSet<(String, String)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0].to_string(), f[1].to_string())
        })
        .collect();
    assert!(series.len() >= 20, "{} series", series.len());
    let img = image::open(dir.join("ggx.png")).unwrap();
    assert!(
        img.width() >= 1200 && img.width() > img.height(),
        "three panels side by side: {}×{}",
        img.width(),
        img.height()
    );
    let svg = std::fs::read_to_string(dir.join("ggx.svg")).unwrap();
    for text in [
        "light beam:8",
        "independent samples",
        "stratified samples",
        "sobol samples",
        "bounded-vndf",
        "mis-power",
    ] {
        assert!(svg.contains(text), "{text:?} is not in the SVG");
    }
}

/// Issue 41: a zero-variance estimator's curve is `exact` with an empty
/// slope and RMSE 0, not the slope of its rounding (0.001).
#[test]
fn a_zero_variance_estimator_has_no_slope() {
    let dir = scratch("exact");
    let prefix = dir.join("lambert");
    let o = lobe(
        &[
            "converge",
            "-m",
            r#"{"type":"lambert"}"#,
            "--strategy",
            "brdf,uniform",
            "--sequence",
            "independent",
            "--max-exp",
            "8",
            "--runs",
            "4",
            "--out",
            prefix.to_str().unwrap(),
            "-q",
        ],
        None,
    );
    assert_ok(&o);
    let out = String::from_utf8_lossy(&o.stdout);
    let brdf = out.lines().find(|l| l.starts_with("brdf ")).unwrap();
    assert_eq!(brdf.split_whitespace().nth(1), Some("exact"), "{out}");
    let uniform = out.lines().find(|l| l.starts_with("uniform ")).unwrap();
    let s: f64 = uniform.split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!(s < -0.3, "{out}");
    let csv = std::fs::read_to_string(dir.join("lambert.csv")).unwrap();
    for l in csv.lines().filter(|l| l.starts_with("brdf,")) {
        assert!(l.ends_with(",0,"), "{l}");
    }
}
