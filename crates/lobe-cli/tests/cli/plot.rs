//! `lobe plot` end to end: the built binary writes readable PNGs of the
//! expected sizes, and refuses bad input with one line and a non-zero exit.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const GGX: &str = r#"{"type":"cook-torrance","alpha":0.3}"#;
const PHONG: &str = r#"{"type":"phong","exponent":50}"#;

fn lobe(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lobe"))
        .args(args)
        .output()
        .expect("the lobe binary runs")
}

/// A fresh directory under Cargo's temporary directory for the tests.
fn fresh_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn stdout_lines(out: &Output) -> Vec<String> {
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(str::to_string)
        .collect()
}

/// Decodes `path`, checks its size, that it is not one flat colour, and
/// that the top strip (the title) holds dark pixels: text was drawn.
fn check_png(path: &Path, size: (u32, u32)) {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{} does not decode: {e}", path.display()))
        .to_rgb8();
    assert_eq!(img.dimensions(), size, "{}", path.display());
    let colours: HashSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    assert!(
        colours.len() > 20,
        "{}: only {} colours",
        path.display(),
        colours.len()
    );
    let title_ink = (0..img.width())
        .flat_map(|x| (0..30).map(move |y| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&c| c < 100))
        .count();
    assert!(
        title_ink > 50,
        "{}: no title text ({title_ink} dark pixels at the top)",
        path.display()
    );
}

#[test]
fn all_kinds_write_readable_pngs() {
    let dir = fresh_dir("plot-all");
    let d = dir.to_str().unwrap();
    let out = lobe(&[
        "plot",
        "--material",
        GGX,
        "--theta",
        "60",
        "--strategy",
        "vndf",
        "--kind",
        "all",
        "--samples",
        "100000",
        "--out",
        d,
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let expected = [
        ("polar.png", (800, 500)),
        ("histogram-vndf.png", (800, 400)),
        ("weights-vndf.png", (640, 600)),
    ];
    let lines = stdout_lines(&out);
    assert_eq!(lines.len(), expected.len(), "stdout: {lines:?}");
    for ((name, size), line) in expected.iter().zip(&lines) {
        let path = dir.join(name);
        assert_eq!(Path::new(line), path, "printed path");
        check_png(&path, *size);
    }
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("p = "),
        "the chi-square p-value is reported: {err}"
    );
}

#[test]
fn uniform_sampling_of_phong_and_an_explicit_view() {
    let dir = fresh_dir("plot-phong");
    let d = dir.to_str().unwrap();
    for kind in ["histogram", "weights"] {
        let out = lobe(&[
            "plot",
            "--material",
            PHONG,
            "--wo",
            "0.5,0.2,0.8",
            "--strategy",
            "uniform",
            "--kind",
            kind,
            "--samples",
            "100000",
            "--res",
            "32",
            "--out",
            d,
            "-q",
        ]);
        assert!(
            out.status.success(),
            "{kind}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(stdout_lines(&out).len(), 1);
    }
    check_png(&dir.join("histogram-uniform.png"), (800, 400));
    check_png(&dir.join("weights-uniform.png"), (640, 600));
}

#[test]
fn bad_input_fails_with_one_line() {
    let dir = fresh_dir("plot-bad");
    let d = dir.to_str().unwrap();
    let file = dir.join("a-file");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(&file, "").unwrap();
    let under_file = file.join("sub");
    let under_file = under_file.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--kind", "bogus", "--strategy", "vndf"], "--kind"),
        (vec!["--strategy", "bogus"], "--strategy"),
        (
            vec!["--strategy", "spherical-caps", "--material", PHONG],
            "does not apply",
        ),
        (
            vec![
                "--strategy",
                "vndf",
                "--kind",
                "histogram",
                "--samples",
                "0",
            ],
            "--samples",
        ),
        (vec!["--strategy", "vndf", "--res", "0"], "--res"),
        (vec!["--strategy", "vndf", "--res", "1025"], "--res"),
        (vec!["--strategy", "vndf", "--theta", "90"], "--theta"),
        (vec!["--strategy", "vndf", "--theta", "-1"], "--theta"),
        (vec!["--kind", "weights"], "--strategy"),
        (vec!["--strategy", "vndf", "--material", "{"], "material"),
        // Smooth glass and mirrors have only delta lobes: no density to
        // draw, refused by name rather than drawn empty.
        (
            vec![
                "--strategy",
                "brdf",
                "--material",
                r#"{"type":"dielectric"}"#,
            ],
            "only into single directions",
        ),
        (
            vec![
                "--strategy",
                "brdf",
                "--material",
                r#"{"type":"conductor"}"#,
            ],
            "only into single directions",
        ),
        // Fits and comparisons are of reflection.
        (
            vec![
                "--kind",
                "polar",
                "--material",
                r#"{"type":"roughdielectric"}"#,
                "--against",
                GGX,
            ],
            "transmits",
        ),
        (vec!["--strategy", "vndf", "--out", under_file], "--out"),
    ];
    for (extra, needle) in cases {
        // A case may give its own --material or --out; the defaults are
        // added only when it does not.
        let mut full: Vec<&str> = vec!["plot", "-q"];
        full.extend(&extra);
        if !extra.contains(&"--material") {
            full.extend(["--material", GGX]);
        }
        if !extra.contains(&"--out") {
            full.extend(["--out", d]);
        }
        let out = lobe(&full);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{full:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{full:?}: {err}");
        assert!(
            err.starts_with("lobe: error:") && err.contains(needle),
            "{full:?}: {err}"
        );
        assert!(!err.contains("panicked"), "{full:?}: {err}");
    }
}

#[test]
fn help_shows_an_example() {
    let out = lobe(&["plot", "--help"]);
    assert!(out.status.success());
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(help.contains("Examples:") && help.contains("lobe plot --material"));
}

/// Runs `lobe plot --kind polar` with `extra` into `dir` and returns the
/// PNG's bytes, after checking it.
fn polar(dir: &Path, extra: &[&str]) -> Vec<u8> {
    let mut args = vec![
        "plot",
        "--material",
        r#"{"type":"cook-torrance","alpha":0.2,"kd":0.3}"#,
        "--kind",
        "polar",
        "--out",
        dir.to_str().unwrap(),
        "-q",
    ];
    args.extend_from_slice(extra);
    let out = lobe(&args);
    assert!(
        out.status.success(),
        "{extra:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let path = dir.join("polar.png");
    assert_eq!(stdout_lines(&out), [path.display().to_string()]);
    check_png(&path, (800, 500));
    std::fs::read(&path).unwrap()
}

#[test]
fn polar_honours_theta_strategy_and_scale() {
    let dir = fresh_dir("plot-polar");
    let base = polar(&dir, &["--theta", "30", "--strategy", "vndf"]);
    let other_view = polar(&dir, &["--theta", "70", "--strategy", "vndf"]);
    let other_strategy = polar(&dir, &["--theta", "30", "--strategy", "uniform"]);
    let every_strategy = polar(&dir, &["--theta", "30"]);
    let log = polar(
        &dir,
        &["--theta", "30", "--strategy", "vndf", "--scale", "log"],
    );
    let linear = polar(
        &dir,
        &["--theta", "30", "--strategy", "vndf", "--scale", "linear"],
    );
    assert_eq!(linear, base, "linear is the default scale");
    for (what, png) in [
        ("--theta", &other_view),
        ("--strategy", &other_strategy),
        ("no --strategy", &every_strategy),
        ("--scale log", &log),
    ] {
        assert_ne!(png, &base, "{what} changes the figure");
    }
    // An explicit view in another plane of incidence.
    polar(&dir, &["--wo", "0.3,0.4,0.866", "--strategy", "brdf"]);
}

#[test]
fn polar_refuses_a_bad_scale_or_strategy() {
    let dir = fresh_dir("plot-polar-bad");
    let d = dir.to_str().unwrap();
    for (extra, needle) in [
        (vec!["--scale", "cubic"], "--scale cubic: unknown scale"),
        (
            vec!["--strategy", "vndf", "--material", PHONG],
            "does not apply",
        ),
        (vec!["--strategy", "bogus"], "--strategy"),
    ] {
        let mut full: Vec<&str> = vec!["plot", "-q", "--kind", "polar", "--out", d];
        full.extend(&extra);
        if !extra.contains(&"--material") {
            full.extend(["--material", GGX]);
        }
        let out = lobe(&full);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{full:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{full:?}: {err}");
        assert!(
            err.starts_with("lobe: error:") && err.contains(needle),
            "{full:?}: {err}"
        );
    }
    assert!(!dir.join("polar.png").exists());
}

/// `--against` (and `--fit`, which fits first) draws a second material
/// against `--material` in four polar panels: polar-fit.png, with the data
/// in black and the other material in red.
#[test]
fn polar_draws_a_material_against_another() {
    let dir = fresh_dir("plot-against");
    let d = dir.to_str().unwrap();
    let other = r#"{"type":"cook-torrance","alpha":0.5,"kd":0.2}"#;
    let out = lobe(&[
        "plot",
        "--kind",
        "polar",
        "-m",
        GGX,
        "--against",
        other,
        "--out",
        d,
        "-q",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines = stdout_lines(&out);
    assert_eq!(lines.len(), 2, "{lines:?}");
    assert!(lines[1].ends_with("polar-fit.png"), "{lines:?}");
    let path = Path::new(&lines[1]);
    check_png(path, (1200, 760));
    let img = image::open(path).unwrap().to_rgb8();
    let count = |f: &dyn Fn([u8; 3]) -> bool| img.pixels().filter(|p| f(p.0)).count();
    let red = count(&|[r, g, b]| r > 180 && g < 90 && b < 80);
    let black = count(&|[r, g, b]| r < 40 && g < 40 && b < 40);
    assert!(
        red > 1000 && black > 1000,
        "red {red}, black {black} pixels"
    );
    // Only with a polar figure.
    let out = lobe(&[
        "plot", "--kind", "weights", "-m", GGX, "-s", "vndf", "--fit", "--out", d,
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--fit and --against draw polar figures"),
        "{err}"
    );
}

/// Glass and a two-sided material seen from below: the polar plot goes
/// round the full circle (a taller figure, with ink below the surface
/// line), the maps show both hemispheres (wider or taller figures), and
/// the warp test passes over the sphere.
#[test]
fn glass_and_views_from_below_are_drawn_over_the_sphere() {
    for (material, theta, strategy) in [
        (
            r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.3}"#,
            "40",
            "vndf",
        ),
        (r#"{"type":"roughdielectric","alpha":0.3}"#, "150", "brdf"),
        (r#"{"type":"roughplastic","alpha":0.2}"#, "30", "vndf"),
        (
            r#"{"type":"twosided","material":{"type":"roughconductor","alpha":0.3}}"#,
            "120",
            "vndf",
        ),
    ] {
        let dir = fresh_dir(&format!("plot-sphere-{theta}-{strategy}"));
        let d = dir.to_str().unwrap();
        let out = lobe(&[
            "plot",
            "-q",
            "--material",
            material,
            "--theta",
            theta,
            "--strategy",
            strategy,
            "--samples",
            "100000",
            "--res",
            "32",
            "--out",
            d,
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{material} {theta}: {err}");
        assert!(err.contains("pass at 1%"), "{material} {theta}: {err}");
        let sphere = !material.contains("plastic");
        let (polar, hist, weights) = if sphere {
            ((800, 820), (800, 740), (1000, 560))
        } else {
            ((800, 500), (800, 400), (640, 600))
        };
        check_png(&dir.join("polar.png"), polar);
        check_png(&dir.join(format!("histogram-{strategy}.png")), hist);
        check_png(&dir.join(format!("weights-{strategy}.png")), weights);
    }
}
