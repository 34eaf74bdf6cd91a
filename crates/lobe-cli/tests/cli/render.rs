//! `lobe render` end to end: both files written and readable, the same
//! image for any thread count, and one-line errors that name the file, the
//! line and the field.

use crate::common;
use common::one_line_error;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn lobe(args: &[&str], cwd: Option<&Path>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_lobe"));
    c.args(args);
    if let Some(d) = cwd {
        c.current_dir(d);
    }
    c.output().expect("run lobe")
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("lobe-cli-render-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A glossy sphere on a Phong plane.
fn test_scene() -> String {
    common::sphere_scene(
        20,
        14,
        r#"{ type = "cook-torrance", distribution = "ggx", alpha = 0.3 }"#,
        r#"{ type = "phong", exponent = 20, kd = 0.4, ks = 0.3 }"#,
        64,
    )
}

#[test]
fn writes_exr_and_png() {
    let d = dir("out");
    let scene = d.join("scene.toml");
    std::fs::write(&scene, test_scene()).unwrap();
    let out = d.join("img");
    let o = lobe(
        &[
            "render",
            scene.to_str().unwrap(),
            "--spp",
            "2",
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ],
        None,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let png = image::open(d.join("img.png")).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (20, 14));
    // The EXR reads back (as an environment map, the same decoder) with the
    // size of the image and finite, non-negative values.
    let (exr, clamped) = lobe_render::load_envmap(&d.join("img.exr"), 1.0, 0.0).unwrap();
    assert_eq!((exr.size(), clamped), ((20, 14), 0));
    let sky = (0..20).map(|i| exr.texel(i, 0)).fold(0.0, |a, t| a + t.y);
    assert!(sky > 0.0);

    // By default the files are named after the scene, in the current
    // directory; --strategy and --seed override the scene.
    let o = lobe(
        &[
            "render",
            "scene.toml",
            "--spp",
            "1",
            "--strategy",
            "vndf",
            "--seed",
            "5",
            "--quiet",
        ],
        Some(&d),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("vndf") && stdout.contains("1 spp"),
        "{stdout}"
    );
    assert!(d.join("scene.exr").exists() && d.join("scene.png").exists());

    // One-sample MIS has no batch loop: the scalar loop renders the scene,
    // and says so once; with --loop scalar there is nothing to say. (The
    // Phong plane is batched.)
    let note = |extra: &[&str]| {
        let mut args = vec!["render", "scene.toml", "--spp", "1", "--out", "n"];
        args.extend_from_slice(extra);
        let o = lobe(&args, Some(&d));
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    assert!(!note(&[]).contains("scalar loop"));
    let e = note(&["--strategy", "mis-one"]);
    assert_eq!(e.matches("the scalar loop renders this").count(), 1, "{e}");
    assert!(e.contains("one-sample MIS"), "{e}");
    assert!(!note(&["--strategy", "mis-one", "--loop", "scalar"]).contains("scalar loop"));

    // The variance allocation (the default: `scene.spp.png` was written
    // above): the counts' range in the summary and a picture of them beside
    // the image; none with --spp-allocation uniform; a bad name is a
    // one-line error.
    assert!(d.join("scene.spp.png").exists());
    let o = lobe(
        &[
            "render",
            "scene.toml",
            "--spp",
            "2",
            "--spp-allocation",
            "uniform",
            "--out",
            "u",
        ],
        Some(&d),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("(20x14, 2 spp, sobol"));
    assert!(d.join("u.png").exists() && !d.join("u.spp.png").exists());
    let o = lobe(
        &[
            "render",
            "scene.toml",
            "--spp",
            "16",
            "--spp-allocation",
            "variance",
            "--out",
            "v",
        ],
        Some(&d),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("16 spp on average, allocated by variance: ")
            && stdout.contains("v.spp.png (samples per pixel)"),
        "{stdout}"
    );
    let counts = image::open(d.join("v.spp.png")).unwrap().to_rgb8();
    assert_eq!(counts.dimensions(), (20, 14));
    // The fewest samples black, the most pale yellow.
    let lum = |p: &image::Rgb<u8>| p.0.iter().map(|&c| u32::from(c)).sum::<u32>();
    assert_eq!(counts.pixels().map(lum).min(), Some(5));
    assert_eq!(counts.pixels().map(lum).max(), Some(252 + 252 + 191));
    let o = lobe(
        &[
            "render",
            "scene.toml",
            "--spp-allocation",
            "even",
            "--out",
            "e",
        ],
        Some(&d),
    );
    let e = one_line_error(&o);
    assert!(
        e.contains(
            "--spp-allocation: unknown spp allocation `even`, expected one of: uniform, variance"
        ),
        "{e}"
    );
}

#[test]
fn threads_do_not_change_the_image() {
    let d = dir("threads");
    let scene = d.join("s.toml");
    std::fs::write(
        &scene,
        test_scene().replace("max_depth = 1", "max_depth = 4"),
    )
    .unwrap();
    let mut files = Vec::new();
    for t in ["1", "2"] {
        let out = d.join(format!("t{t}"));
        let o = lobe(
            &[
                "render",
                scene.to_str().unwrap(),
                "--spp",
                "3",
                "--threads",
                t,
                "--out",
                out.to_str().unwrap(),
                "--quiet",
            ],
            None,
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        files.push(std::fs::read(d.join(format!("t{t}.exr"))).unwrap());
    }
    assert_eq!(files[0], files[1]);
}

#[test]
fn errors_are_one_line_and_name_file_line_and_field() {
    let d = dir("errors");
    let scene = d.join("scene.toml");
    let run = |text: &str| {
        std::fs::write(&scene, text).unwrap();
        let out = d.join("x");
        one_line_error(&lobe(
            &[
                "render",
                scene.to_str().unwrap(),
                "--quiet",
                "--out",
                out.to_str().unwrap(),
            ],
            None,
        ))
    };
    let e = run(&test_scene().replace("radius = 1", "radius = \"a\""));
    assert!(
        e.contains(&format!(
            "{}:17:10: field object[0].radius: invalid type: string \"a\", expected f64",
            scene.display()
        )),
        "{e}"
    );
    let e = run(&test_scene().replace("alpha = 0.3", "alpha = 7"));
    assert!(
        e.contains("scene.toml:18:") && e.contains("field object[0].material.alpha: "),
        "{e}"
    );
    let e = run(&test_scene().replace("fov_y = 40", "fov_y = 0"));
    assert!(e.contains("scene.toml:5:9: field camera.fov_y: "), "{e}");
    let e = run(&test_scene().replace("\"sky\"", "\"forest.hdr\""));
    assert!(
        e.contains(&d.join("forest.hdr").display().to_string()),
        "{e}"
    );
    let e = run(&test_scene().replace(
        "type = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]",
        "type = \"mesh\"\npath = \"meshes/bunny.obj\"",
    ));
    assert!(
        e.contains(&d.join("meshes/bunny.obj").display().to_string()),
        "{e}"
    );
    assert!(e.contains("field object[1].path"), "{e}");
    let e = run("[camera\n");
    assert!(e.contains("scene.toml:1:"), "{e}");

    std::fs::write(&scene, test_scene()).unwrap();
    let e = one_line_error(&lobe(
        &["render", scene.to_str().unwrap(), "--strategy", "fast"],
        None,
    ));
    assert!(e.contains("--strategy: unknown strategy `fast`"), "{e}");
    let e = one_line_error(&lobe(
        &["render", scene.to_str().unwrap(), "--loop", "fast"],
        None,
    ));
    assert!(e.contains("--loop: unknown loop `fast`"), "{e}");
    let e = one_line_error(&lobe(
        &["render", d.join("none.toml").to_str().unwrap()],
        None,
    ));
    assert!(e.contains("none.toml: cannot read the scene file: "), "{e}");
    // The OS reason once, not once more from the error chain.
    assert_eq!(e.matches("os error").count(), 1, "{e}");
}

/// `--spp` takes any u64; more samples than fit in 64 bits in all, or a
/// number past u64, is a clear one-line error (issue 8, item 7).
#[test]
fn huge_spp_is_accepted_or_refused_clearly() {
    let d = dir("huge-spp");
    let scene = d.join("scene.toml");
    std::fs::write(&scene, test_scene()).unwrap();
    let s = scene.to_str().unwrap();
    let e = one_line_error(&lobe(&["render", s, "--spp", "18446744073709551615"], None));
    assert!(
        e.contains("--spp 18446744073709551615") && e.contains("64 bits"),
        "{e}"
    );
    let out = lobe(&["render", s, "--spp", "18446744073709551616"], None);
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("--spp") && e.contains("too large"), "{e}");
    // Sobol's 2^32 points per pixel: the variance allocation can give a
    // pixel 64 × spp, so 2^26 + 1 spp is refused, and says why.
    let e = one_line_error(&lobe(
        &[
            "render",
            s,
            "--spp",
            "67108865",
            "--spp-allocation",
            "variance",
        ],
        None,
    ));
    assert!(
        e.contains("--spp 67108865: the sobol sequence has 2^32 points per pixel (the variance allocation gives a pixel up to 64 × spp)"),
        "{e}"
    );
}

/// Issue 41: every command checks its outputs the same way, before the
/// work: a missing folder is created (render and compare refused it, and
/// render only after rendering), a file in the way of a folder is a
/// one-line error at once; a bad LOBE_SIMD is one error naming it.
#[test]
fn outputs_are_checked_before_the_work_the_same_way_everywhere() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("outputs-41");
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_lobe"))
            .args(args)
            .current_dir(&root)
            .output()
            .unwrap()
    };
    let new = |name: &str| d.join("missing").join(name).display().to_string();
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        (
            [
                "render",
                "examples/scene.toml",
                "--spp",
                "1",
                "-q",
                "--out",
                &new("r"),
            ]
            .map(String::from)
            .to_vec(),
            vec!["r.exr", "r.png"],
        ),
        (
            [
                "compare",
                "examples/scene.toml",
                "--spp",
                "1",
                "--reference-spp",
                "2",
                "--strategy",
                "brdf",
                "-q",
                "--out",
                &new("c"),
            ]
            .map(String::from)
            .to_vec(),
            vec!["c.png", "c.json"],
        ),
        (
            [
                "converge",
                "-m",
                r#"{"type":"lambert"}"#,
                "--max-exp",
                "2",
                "--runs",
                "1",
                "-q",
                "--out",
                &new("v"),
            ]
            .map(String::from)
            .to_vec(),
            vec!["v.csv"],
        ),
    ];
    std::fs::write(d.join("file"), b"").unwrap();
    for (args, files) in cases {
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = run(&a);
        assert!(
            o.status.success(),
            "{a:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        for f in files {
            assert!(d.join("missing").join(f).is_file(), "{a:?}: {f}");
        }
        // A file where the folder should be: refused at once, in one line.
        let blocked: Vec<String> = args
            .iter()
            .map(|w| w.replace("/missing/", "/file/"))
            .collect();
        let b: Vec<&str> = blocked.iter().map(String::as_str).collect();
        let t0 = std::time::Instant::now();
        let e = common::one_line_error(&run(&b));
        assert!(e.contains("is a file, not a directory"), "{b:?}: {e}");
        assert!(t0.elapsed().as_secs_f64() < 5.0);
    }
    let o = Command::new(env!("CARGO_BIN_EXE_lobe"))
        .args(["estimate", "-m", r#"{"type":"lambert"}"#, "-n", "64", "-q"])
        .env("LOBE_SIMD", "neon")
        .output()
        .unwrap();
    let e = common::one_line_error(&o);
    assert!(e.starts_with("lobe: error: LOBE_SIMD=neon: "), "{e}");
}

/// Issue 41: a long render is not silent when stderr is not a terminal
/// (here a pipe): plain progress lines, the first one not nonsense.
#[test]
fn a_render_shows_progress_lines_off_a_terminal() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("progress-41");
    let o = Command::new(env!("CARGO_BIN_EXE_lobe"))
        .args([
            "render",
            "examples/scene.toml",
            "--spp",
            "512",
            "--spp-allocation",
            "uniform",
        ])
        .arg("--out")
        .arg(&out)
        .current_dir(&root)
        .env("LOBE_PROGRESS_EVERY", "0.1")
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .unwrap();
    assert!(o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    let lines: Vec<&str> = e
        .lines()
        .filter(|l| l.starts_with("lobe: rendering "))
        .collect();
    assert!(!lines.is_empty(), "{e}");
    assert!(lines[0].contains("% (") && lines[0].contains(" of "), "{e}");
    assert!(!e.contains("3w") && !e.contains("weeks"), "{e}");
}

/// Issue 41: SIGINT or SIGTERM during a `--time` render writes the passes
/// finished so far, with their spp in the EXR's header and on stderr, and
/// exits with 128 + the signal's number; during a render's only pass it
/// writes nothing and says so.
#[cfg(unix)]
#[test]
fn an_interrupted_render_writes_the_passes_it_finished() {
    use std::io::BufRead;
    use std::process::Stdio;
    use std::sync::mpsc;
    use std::time::{Duration, Instant};
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let d = dir("interrupt");
    // The render's stderr lines, and the percentage of the plain progress
    // lines (one pass of samples is 100%).
    let start = |args: &[&str], out: &Path| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_lobe"))
            .args([
                "render",
                "examples/scene.toml",
                "--spp-allocation",
                "uniform",
            ])
            .args(args)
            .arg("--out")
            .arg(out)
            .current_dir(&root)
            .env("LOBE_PROGRESS_EVERY", "0.05")
            .stderr(Stdio::piped())
            .stdout(Stdio::null())
            .spawn()
            .unwrap();
        let (tx, rx) = mpsc::channel();
        let stderr = child.stderr.take().unwrap();
        std::thread::spawn(move || {
            for l in std::io::BufReader::new(stderr).lines() {
                let Ok(l) = l else { return };
                if tx.send(l).is_err() {
                    return;
                }
            }
        });
        (child, rx)
    };
    let percent = |l: &str| -> Option<f64> {
        let rest = l.strip_prefix("lobe: rendering ")?;
        rest.split('%').next()?.trim().parse().ok()
    };
    let kill = |pid: u32, sig: &str| {
        let s = Command::new("kill")
            .arg(format!("-{sig}"))
            .arg(pid.to_string())
            .status()
            .unwrap();
        assert!(s.success());
    };
    for (sig, name, status) in [("INT", "SIGINT", 130), ("TERM", "SIGTERM", 143)] {
        let out = d.join(format!("timed-{sig}"));
        let t0 = Instant::now();
        let (mut child, rx) = start(&["--spp", "4", "--time", "30"], &out);
        // Signalled once a progress line shows more than two passes' samples
        // done: two passes finished, whatever the third's progress (past
        // 100% alone is one pass finished and part of the second, which a
        // slower pass, under the smooth sky or a loaded machine, had not
        // finished when the signal came).
        let mut lines = Vec::new();
        loop {
            let l = rx
                .recv_timeout(Duration::from_secs(8))
                .unwrap_or_else(|e| panic!("no progress past two passes ({e}): {lines:?}"));
            let past = percent(&l).is_some_and(|p| p > 200.0);
            lines.push(l);
            if past {
                break;
            }
        }
        kill(child.id(), sig);
        let code = child.wait().unwrap().code();
        lines.extend(rx.iter());
        assert!(t0.elapsed() < Duration::from_secs(10), "{lines:?}");
        assert_eq!(code, Some(status), "{lines:?}");
        let last = lines.last().unwrap();
        let head = format!("lobe: interrupted ({name}) after ");
        let rest = last
            .strip_prefix(head.as_str())
            .unwrap_or_else(|| panic!("{lines:?}"));
        // "N passes (K spp, 4 a pass) in S s of --time 30; wrote ..."
        let passes: u64 = rest.split(' ').next().unwrap().parse().unwrap();
        assert!(passes >= 2, "{last}");
        let spp_said = format!("({} spp, 4 a pass)", 4 * passes);
        assert!(rest.contains(&spp_said), "{last}");
        assert!(
            rest.contains("of --time 30; wrote ") && rest.contains(".exr") && rest.contains(".png"),
            "{last}"
        );
        let exr = out.with_extension("exr");
        let meta = exr::meta::MetaData::read_from_file(&exr, false).unwrap();
        let h = &meta.headers[0];
        let attrs: std::collections::HashMap<_, _> = h
            .shared_attributes
            .other
            .iter()
            .chain(&h.own_attributes.other)
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect();
        use exr::meta::attribute::AttributeValue;
        assert_eq!(
            attrs.get("spp"),
            Some(&AttributeValue::F64((4 * passes) as f64)),
            "{attrs:?}"
        );
        let note = h.own_attributes.comments.as_ref().unwrap().to_string();
        assert!(note.starts_with(&format!("interrupted ({name})")), "{note}");
        assert!(out.with_extension("png").exists());
    }

    // A render without --time is one pass: interrupted in it, nothing.
    let out = d.join("whole");
    let (mut child, rx) = start(&["--spp", "100000"], &out);
    let mut lines = Vec::new();
    loop {
        let l = rx.recv_timeout(Duration::from_secs(8)).unwrap();
        let started = percent(&l).is_some();
        lines.push(l);
        if started {
            break;
        }
    }
    kill(child.id(), "INT");
    let code = child.wait().unwrap().code();
    lines.extend(rx.iter());
    assert_eq!(code, Some(130), "{lines:?}");
    let last = lines.last().unwrap();
    assert!(
        last.starts_with("lobe: interrupted (SIGINT) after ")
            && last.contains("before the first pass")
            && last.ends_with("nothing written"),
        "{lines:?}"
    );
    for ext in ["exr", "png", "spp.png"] {
        assert!(!d.join(format!("whole.{ext}")).exists(), "{ext}");
    }
}

/// Issue 41: a scene places the built-in sky's sun with
/// `[environment] sky = { sun_elevation, sun_azimuth }`: the same image as
/// the default sky when the keys are the defaults, another one elsewhere,
/// and one line naming the file, the line and the key for a bad value.
#[test]
fn a_scene_places_the_skys_sun() {
    let d = dir("sky-keys");
    let render = |name: &str, environment: &str| {
        let scene = d.join(format!("{name}.toml"));
        let text = test_scene().replace("path = \"sky\"", environment);
        std::fs::write(&scene, text).unwrap();
        let out = d.join(name);
        let o = lobe(
            &[
                "render",
                scene.to_str().unwrap(),
                "--spp",
                "2",
                "--out",
                out.to_str().unwrap(),
                "--quiet",
            ],
            None,
        );
        (o, out.with_extension("exr"), scene)
    };
    let read = |p: &Path| std::fs::read(p).unwrap();
    let (o, plain, _) = render("plain", "path = \"sky\"");
    assert!(o.status.success(), "{o:?}");
    let (o, defaults, _) = render("defaults", "sky = { sun_elevation = 35, sun_azimuth = 40 }");
    assert!(o.status.success(), "{o:?}");
    assert_eq!(read(&plain), read(&defaults));
    let (o, low, _) = render("low", "sky = { sun_elevation = 5, sun_azimuth = 120 }");
    assert!(o.status.success(), "{o:?}");
    assert_ne!(read(&plain), read(&low));
    let (o, _, scene) = render("bad", "sky = { sun_elevation = 91, sun_azimuth = 120 }");
    let e = one_line_error(&o);
    assert!(
        e.contains(&format!(
            "{}:10:25: field environment.sky.sun_elevation: 91 is out of range",
            scene.display()
        )),
        "{e}"
    );
}

/// A scene's material that reflects more than it receives is warned about
/// as `--material` is, naming the file and the object, with the hint that
/// Cook-Torrance's default Fresnel term is F = 1; the example scene is not.
#[test]
fn a_scene_material_that_gains_energy_is_warned_about() {
    let d = dir("energy");
    let scene = d.join("scene.toml");
    std::fs::write(
        &scene,
        common::sphere_scene(
            8,
            6,
            r#"{ type = "cook-torrance", distribution = "ggx", alpha = 0.3, kd = 0.5 }"#,
            r#"{ type = "lambert", albedo = 0.5 }"#,
            64,
        ),
    )
    .unwrap();
    let run = |scene: &str, out: &Path| {
        lobe(
            &[
                "render",
                scene,
                "--spp",
                "1",
                "--quiet",
                "--out",
                out.to_str().unwrap(),
            ],
            Some(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")),
        )
    };
    let o = run(scene.to_str().unwrap(), &d.join("a"));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let e = String::from_utf8_lossy(&o.stderr);
    let warning: Vec<&str> = e.lines().filter(|l| l.contains("warning")).collect();
    assert_eq!(warning.len(), 1, "{e}");
    assert!(
        warning[0].contains("scene.toml: object 1's material reflects more light than it receives")
            && warning[0].contains("its default, none, is F = 1"),
        "{e}"
    );
    let o = run("examples/scene.toml", &d.join("b"));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!e.contains("warning"), "{e}");
}
