//! Measured materials through every command (issue 11): `lobe tabulate`
//! writes a MERL table and a small RGL file of an analytic material, and
//! `eval`, `estimate`, `converge`, `plot` (with `--fit`), `render`,
//! `compare` and `fit` read them. Small sample counts: the point is that
//! each command takes the material and gives sane numbers (the library's
//! tests prove the sampler and the estimator).

use crate::common;
use common::one_line_error;

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::OnceLock;

fn lobe(args: &[&str], cwd: Option<&Path>, stdin: &str) -> Output {
    use std::io::Write;
    let mut c = Command::new(env!("CARGO_BIN_EXE_lobe"));
    c.args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    if let Some(d) = cwd {
        c.current_dir(d);
    }
    let mut child = c.spawn().expect("run lobe");
    let mut input = child.stdin.take().unwrap();
    let text = stdin.to_string();
    let writer = std::thread::spawn(move || input.write_all(text.as_bytes()));
    let o = child.wait_with_output().expect("wait for lobe");
    // A command that fails before reading stdin closes it: ignore the
    // broken pipe.
    let _ = writer.join().unwrap();
    o
}

fn ok(o: &Output, what: &str) -> String {
    assert!(
        o.status.success(),
        "{what}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout.clone()).unwrap()
}

/// The analytic material the files tabulate.
const ANALYTIC: &str = r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2,"kd":[0.1,0.15,0.05],"fresnel":{"type":"schlick","f0":[0.9,0.6,0.3]}}"#;

struct Files {
    dir: PathBuf,
    merl: PathBuf,
    rgl: PathBuf,
}

/// The tables `t.binary` (MERL) and `t.bsdf` (RGL, 6 views, 24²), written
/// by `lobe tabulate` once per build of `lobe`, and a fresh directory of
/// this process's own for the commands' outputs (`dir`), beside them.
///
/// Test runners that give each test its own process (`cargo nextest`)
/// share the tables: a process writes them into a directory of its own
/// and renames it into place; the loser of a race drops its copy. Older
/// builds' tables are removed, with the output directories beside them.
/// (A shared directory removed and rewritten by every process made the
/// others read half-written tables.)
fn files() -> &'static Files {
    static F: OnceLock<Files> = OnceLock::new();
    F.get_or_init(|| {
        // Under target/, not /tmp, where each run's 35 MB table would stay.
        let base = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
        let bin = std::fs::metadata(env!("CARGO_BIN_EXE_lobe")).unwrap();
        let stamp = bin
            .modified()
            .unwrap()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap()
            .as_nanos() as u64
            ^ bin.len();
        let tables = base.join(format!("cli-measured-{stamp:016x}"));
        if !tables.join("t.bsdf").exists() {
            for e in std::fs::read_dir(&base).into_iter().flatten().flatten() {
                let name = e.file_name().to_string_lossy().into_owned();
                let stale = name == "cli-measured"
                    || (name.starts_with("cli-measured-") && !name.starts_with("cli-measured-tmp"));
                if stale && e.path() != tables {
                    let _ = std::fs::remove_dir_all(e.path());
                }
            }
            let tmp = base.join(format!("cli-measured-tmp-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&tmp);
            std::fs::create_dir_all(&tmp).unwrap();
            tabulate(&tmp);
            if std::fs::rename(&tmp, &tables).is_err() {
                let _ = std::fs::remove_dir_all(&tmp);
            }
            assert!(tables.join("t.bsdf").exists(), "{}", tables.display());
        }
        let dir = tables.join(format!("run-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Files {
            merl: tables.join("t.binary"),
            rgl: tables.join("t.bsdf"),
            dir,
        }
    })
}

/// Write the MERL and RGL tables of [`ANALYTIC`] into `dir`, checking what
/// `lobe tabulate` says.
fn tabulate(dir: &Path) {
    let (merl, rgl) = (dir.join("t.binary"), dir.join("t.bsdf"));
    let o = lobe(
        &[
            "tabulate",
            "-m",
            ANALYTIC,
            "--format",
            "merl",
            "--out",
            merl.to_str().unwrap(),
        ],
        None,
        "",
    );
    ok(&o, "tabulate merl");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("34992012 bytes, merl table of a cook-torrance material"),
        "{err}"
    );
    assert_eq!(std::fs::metadata(&merl).unwrap().len(), 34_992_012);
    let o = lobe(
        &[
            "tabulate",
            "-m",
            ANALYTIC,
            "--format",
            "rgl",
            "--views",
            "6",
            "--grid",
            "24",
            "--out",
            rgl.to_str().unwrap(),
        ],
        None,
        "",
    );
    ok(&o, "tabulate rgl");
}

fn measured(path: &Path) -> String {
    format!(
        r#"{{"type":"measured","path":{:?}}}"#,
        path.to_str().unwrap()
    )
}

fn parse_lines(s: &str) -> Vec<Value> {
    s.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

fn lum(v: &Value) -> f64 {
    let c: Vec<f64> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// `lobe eval` (and `--batch`) of both files near the analytic model's
/// values: MERL nearest within a bin's step, MERL linear and RGL closer.
#[test]
fn eval_reads_both_tables_near_the_model() {
    let f = files();
    // Views and lights in the plane of incidence and off it (θ, φ in degrees).
    let dir = |t: f64, p: f64| {
        let (t, p) = (t.to_radians(), p.to_radians());
        format!("[{},{},{}]", t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    };
    let mut input = String::new();
    for (to, ti, p) in [
        (10.0, 20.0, 170.0),
        (30.0, 35.0, 185.0),
        (45.0, 40.0, 160.0),
        (20.0, 50.0, 90.0),
        (60.0, 30.0, 200.0),
    ] {
        input += &format!("{{\"wo\":{},\"wi\":{}}}\n", dir(to, 0.0), dir(ti, p));
    }
    let want = parse_lines(&ok(&lobe(&["eval", "-m", ANALYTIC], None, &input), "eval"));
    let merl_linear = format!(
        r#"{{"type":"measured","path":{:?},"interpolation":"linear"}}"#,
        f.merl.to_str().unwrap()
    );
    for (name, m, tol, batch) in [
        ("merl nearest", measured(&f.merl), 0.25, false),
        ("merl linear", merl_linear, 0.05, true),
        ("rgl", measured(&f.rgl), 0.08, true),
    ] {
        let mut runs = vec![(
            "eval",
            parse_lines(&ok(&lobe(&["eval", "-m", &m], None, &input), name)),
        )];
        if batch {
            let o = lobe(&["eval", "--batch", "-m", &m], None, &input);
            runs.push(("eval --batch", parse_lines(&ok(&o, name))));
        }
        for (how, got) in runs {
            assert_eq!(got.len(), want.len(), "{name} {how}");
            for (g, w) in got.iter().zip(&want) {
                let (g, w) = (lum(&g["f"]), lum(&w["f"]));
                assert!(
                    g.is_finite() && (g - w).abs() <= tol * w,
                    "{name} {how}: {g} vs the model's {w}"
                );
                eprintln!("{name} {how}: f {g:.5} model {w:.5}");
            }
        }
    }
}

/// `lobe estimate` of both tables: every strategy each has (uniform,
/// cosine, brdf, and vndf for RGL) and light sampling and MIS, within 5
/// standard errors of the quadrature reference, whose albedo is within 3%
/// (MERL) or 5% (RGL, 6 views on a 24² grid) of the analytic material's.
#[test]
fn estimate_takes_measured_tables() {
    let f = files();
    let analytic = {
        let o = lobe(
            &[
                "estimate", "-m", ANALYTIC, "--theta", "40", "-n", "4096", "--json", "--quiet",
            ],
            None,
            "",
        );
        let v: Value = serde_json::from_str(&ok(&o, "estimate analytic")).unwrap();
        lum(&v["reference"])
    };
    for (path, has_vndf, albedo_tol) in [(&f.merl, false, 0.03), (&f.rgl, true, 0.05)] {
        let m = measured(path);
        let o = lobe(
            &[
                "estimate", "-m", &m, "--theta", "40", "--light", "beam:8", "-n", "20000",
                "--json", "--quiet",
            ],
            None,
            "",
        );
        let v: Value = serde_json::from_str(&ok(&o, "estimate")).unwrap();
        let names: Vec<&str> = v["strategies"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s["name"].as_str().unwrap())
            .collect();
        for s in ["uniform", "cosine", "brdf", "light", "mis"] {
            assert!(names.contains(&s), "{}: {names:?}", path.display());
        }
        assert_eq!(names.contains(&"vndf"), has_vndf, "{names:?}");
        let r = v["reference"].as_array().unwrap();
        for s in v["strategies"].as_array().unwrap() {
            for c in 0..3 {
                let (mean, se, want) = (
                    s["mean"][c].as_f64().unwrap(),
                    s["stderr"][c].as_f64().unwrap(),
                    r[c].as_f64().unwrap(),
                );
                assert!(
                    (mean - want).abs() <= 5.0 * se + 1e-6,
                    "{} {}: {mean} ± {se} vs {want}",
                    path.display(),
                    s["name"]
                );
            }
        }
        // The furnace: the table's albedo is the analytic material's.
        let o = lobe(
            &[
                "estimate", "-m", &m, "--theta", "40", "-n", "4096", "--json", "--quiet",
            ],
            None,
            "",
        );
        let v: Value = serde_json::from_str(&ok(&o, "estimate furnace")).unwrap();
        let got = lum(&v["reference"]);
        assert!(
            (got - analytic).abs() <= albedo_tol * analytic,
            "{}: albedo {got} vs the model's {analytic}",
            path.display()
        );
        // The exact variance of uniform sampling is reliable on a table, so
        // every strategy has a variance reduction.
        for s in v["strategies"].as_array().unwrap() {
            assert!(
                s["variance_reduction"].as_f64().is_some_and(|x| x > 0.0),
                "{}: {s}",
                path.display()
            );
        }
    }
}

/// `lobe converge` of a measured table writes its curves.
#[test]
fn converge_takes_a_measured_table() {
    let f = files();
    for (name, path) in [("merl", &f.merl), ("rgl", &f.rgl)] {
        converge_writes_curves(&f.dir.join(format!("conv-{name}")), path);
    }
}

fn converge_writes_curves(prefix: &Path, table: &Path) {
    let o = lobe(
        &[
            "converge",
            "-m",
            &measured(table),
            "--theta",
            "30",
            "--strategy",
            "uniform,cosine,brdf",
            "--sequence",
            "independent",
            "--runs",
            "4",
            "--max-exp",
            "6",
            "--out",
            prefix.to_str().unwrap(),
            "--quiet",
        ],
        None,
        "",
    );
    ok(&o, "converge");
    let csv = std::fs::read_to_string(prefix.with_extension("csv")).unwrap();
    for s in ["uniform", "cosine", "brdf"] {
        assert!(csv.contains(s), "{csv}");
    }
    // 3 series × 7 sample counts, and a header.
    assert!(csv.lines().count() >= 22, "{csv}");
    for ext in ["svg", "png"] {
        assert!(prefix.with_extension(ext).exists(), "{ext}");
    }
}

/// `lobe plot` of a measured table: every kind with its tabulated sampler
/// (the histogram's chi-square passes), and `--kind polar --fit` draws the
/// fit against the data.
#[test]
fn plot_takes_a_measured_table_and_draws_its_fit() {
    let f = files();
    let out = f.dir.join("plot");
    let o = lobe(
        &[
            "plot",
            "-m",
            &measured(&f.merl),
            "--theta",
            "45",
            "-s",
            "brdf",
            "--samples",
            "100000",
            "--res",
            "24",
            "--fit",
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ],
        None,
        "",
    );
    let stdout = ok(&o, "plot");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains(": pass at"), "{err}");
    assert!(
        err.contains(r#"fit: {"type":"cook-torrance","distribution":"ggx""#),
        "{err}"
    );
    for name in [
        "polar.png",
        "polar-fit.png",
        "histogram-brdf.png",
        "weights-brdf.png",
    ] {
        assert!(stdout.contains(name), "{stdout}");
        let img = image::open(out.join(name)).unwrap();
        assert!(img.width() > 100 && img.height() > 100, "{name}");
    }
}

/// `lobe fit` of the MERL table recovers the tabulated parameters (alpha
/// within 5%, f0 and kd within 0.02), prints a material `--material`
/// accepts and the error; the RGL file (an approximation of the model on a
/// 24² grid) gives a fit near them.
#[test]
fn fit_recovers_the_tabulated_parameters() {
    let f = files();
    let o = lobe(&["fit", f.merl.to_str().unwrap()], None, "");
    let text = ok(&o, "fit");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2, "{text}");
    assert!(lines[1].starts_with("error E = "), "{text}");
    // The first line is a material --material takes.
    let o = lobe(
        &["eval", "-m", lines[0]],
        None,
        "{\"wo\":[0,0,1],\"wi\":[0.6,0,0.8]}\n",
    );
    ok(&o, "eval of the fitted material");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.is_empty(), "{err}");

    let check =
        |path: &Path, extra: &[&str], alpha: f64, f0: [f64; 3], kd: [f64; 3], tol: (f64, f64)| {
            let mut args = vec!["fit", path.to_str().unwrap(), "--json"];
            args.extend_from_slice(extra);
            let o = lobe(&args, None, "");
            let v: Value = serde_json::from_str(&ok(&o, "fit --json")).unwrap();
            eprintln!("{}: {v}", path.display());
            let m = &v["material"];
            let a = m["alpha"].as_f64().unwrap();
            assert!(
                (a - alpha).abs() <= tol.0 * alpha,
                "{}: alpha {a}",
                path.display()
            );
            for c in 0..3 {
                let (g0, gd) = (
                    m["fresnel"]["f0"][c].as_f64().unwrap(),
                    m["kd"][c].as_f64().unwrap(),
                );
                assert!(
                    (g0 - f0[c]).abs() <= tol.1,
                    "{}: f0 {}",
                    path.display(),
                    m["fresnel"]
                );
                assert!(
                    (gd - kd[c]).abs() <= tol.1,
                    "{}: kd {}",
                    path.display(),
                    m["kd"]
                );
            }
            assert!(v["error"].as_f64().unwrap() >= 0.0);
            // The table's memory and build time are reported on stderr.
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(err.contains("MB") && err.contains("built in"), "{err}");
        };
    check(
        &f.merl,
        &[],
        0.2,
        [0.9, 0.6, 0.3],
        [0.1, 0.15, 0.05],
        (0.05, 0.02),
    );
    check(
        &f.rgl,
        &[],
        0.2,
        [0.9, 0.6, 0.3],
        [0.1, 0.15, 0.05],
        (0.1, 0.05),
    );

    // --distribution beckmann fits a Beckmann lobe (the library's tests
    // recover a Beckmann table's parameters).
    let o = lobe(
        &[
            "fit",
            f.merl.to_str().unwrap(),
            "--distribution",
            "beckmann",
            "--json",
        ],
        None,
        "",
    );
    let v: Value = serde_json::from_str(&ok(&o, "fit beckmann")).unwrap();
    assert_eq!(v["material"]["distribution"], "beckmann", "{v}");
}

/// The render tests' scene with the sphere of `material` (TOML).
fn sphere_scene(material: &str) -> String {
    common::sphere_scene(16, 12, material, r#"{ type = "lambert", albedo = 0.5 }"#, 4)
}

/// The sphere of a measured table, named relative to the scene file.
fn table_scene(table: &str) -> String {
    sphere_scene(&format!(r#"{{ type = "measured", path = "{table}" }}"#))
}

/// `lobe render` and `lobe compare` of a scene whose sphere is a measured
/// table named relative to the scene file; the measured sphere renders
/// like the analytic one it tabulates (mean within 5%).
#[test]
fn render_and_compare_take_measured_tables() {
    let f = files();
    let mean = |scene: &str, name: &str| -> f64 {
        let path = f.dir.join(format!("{name}.toml"));
        std::fs::write(&path, scene).unwrap();
        let o = lobe(
            &[
                "render",
                path.to_str().unwrap(),
                "--spp",
                "64",
                "--out",
                name,
                "--quiet",
            ],
            Some(&f.dir),
            "",
        );
        ok(&o, name);
        let img = image::open(f.dir.join(format!("{name}.png")))
            .unwrap()
            .to_rgb8();
        assert_eq!(img.dimensions(), (16, 12));
        img.pixels()
            .map(|p| f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2]))
            .sum::<f64>()
    };
    let analytic_scene = sphere_scene(
        r#"{ type = "cook-torrance", distribution = "ggx", alpha = 0.2, kd = [0.1, 0.15, 0.05], fresnel = { type = "schlick", f0 = [0.9, 0.6, 0.3] } }"#,
    );
    let want = mean(&analytic_scene, "analytic");
    // The tables are one directory up from this process's `dir`.
    for table in ["t.binary", "t.bsdf"] {
        let scene = table_scene(&format!("../{table}"));
        let got = mean(&scene, &format!("scene-{table}").replace('.', "-"));
        assert!(
            (got - want).abs() <= 0.05 * want,
            "{table}: PNG sum {got} vs the analytic sphere's {want}"
        );
    }
    let scene = f.dir.join("cmp.toml");
    std::fs::write(&scene, table_scene("../t.bsdf")).unwrap();
    let o = lobe(
        &[
            "compare",
            scene.to_str().unwrap(),
            "--spp",
            "2",
            "--reference-spp",
            "16",
            "--strategy",
            "brdf,light,mis",
            "--out",
            "cmp",
            "--quiet",
        ],
        Some(&f.dir),
        "",
    );
    ok(&o, "compare");
    let v: Value =
        serde_json::from_str(&std::fs::read_to_string(f.dir.join("cmp.json")).unwrap()).unwrap();
    assert!(f.dir.join("cmp.png").exists(), "{v}");
}

/// A bad table is a one-line error naming the file, from any command.
#[test]
fn bad_tables_are_one_line_errors_naming_the_file() {
    let f = files();
    let bad = f.dir.join("short.binary");
    std::fs::write(&bad, &std::fs::read(&f.merl).unwrap()[..1000]).unwrap();
    let name = bad.display().to_string();
    let m = measured(&bad);
    for args in [
        vec!["eval", "-m", &m],
        vec!["estimate", "-m", &m, "-n", "16", "--quiet"],
        vec!["fit", &name],
        vec![
            "tabulate",
            "-m",
            &m,
            "--format",
            "rgl",
            "--out",
            "/dev/null",
        ],
    ] {
        let o = lobe(&args, None, "{\"wo\":[0,0,1],\"wi\":[0,0,1]}\n");
        let e = one_line_error(&o);
        assert!(
            e.contains(&format!("file {name}: truncated: the header claims")),
            "{args:?}: {e}"
        );
    }
}

/// `lobe report --material` of a measured RGL table and an analytic
/// material that transmits (rough glass): one section each, the table's
/// summary, the glass's note, every strategy's row and every figure beside
/// the page.
#[test]
fn report_takes_measured_materials() {
    let f = files();
    let out = f.dir.join("report");
    let o = lobe(
        &[
            "report",
            "--quick",
            "--quiet",
            "--material",
            &measured(&f.rgl),
            "--material",
            r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.3}"#,
            "--out",
            out.to_str().unwrap(),
        ],
        None,
        "",
    );
    ok(&o, "report --material");
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    for text in [
        "Material 1: measured (t.bsdf)",
        "Material 2: roughdielectric",
        "It transmits: its integrals",
        "RGL table",
        "relative tolerance 1e-6",
        "<code>brdf</code>",
        "<code>vndf</code>",
    ] {
        assert!(html.contains(text), "`{text}` is not on the page");
    }
    // The lecture's models are not reported.
    assert!(!html.contains("id=\"phong\""));
    let srcs: Vec<&str> = html
        .split("<img src=\"")
        .skip(1)
        .map(|s| &s[..s.find('"').unwrap()])
        .collect();
    // Per material: convergence, polar, two warp tests and three weight maps.
    assert_eq!(srcs.len(), 14, "{srcs:?}");
    for src in srcs {
        let img = image::open(out.join(src)).unwrap_or_else(|e| panic!("{src}: {e}"));
        assert!(img.width() > 100, "{src}");
    }
}
