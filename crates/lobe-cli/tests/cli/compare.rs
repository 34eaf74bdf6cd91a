//! `lobe compare` end to end on a tiny scene: the figure decodes with the
//! size of its layout, the JSON has every strategy in both rows with a
//! finite positive RMSE, MIS is no worse than the worse of BSDF and light
//! sampling, and bad input fails with one line.

use crate::common;
use common::one_line_error;

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn lobe(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lobe"))
        .args(args)
        .output()
        .expect("run lobe")
}

fn dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("compare-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A glossy GGX sphere (vndf applies) on a Lambertian ground under the
/// built-in sky: BSDF sampling misses the sun on the ground, light sampling
/// is noisy on the sphere.
const SCENE: &str = r#"[camera]
origin = [0, 1, 4]
target = [0, 0.7, 0]
fov_y = 40
width = 48
height = 32

[environment]
path = "sky"

[[object]]
type = "sphere"
center = [0, 0.7, 0]
radius = 0.7
material = { type = "cook-torrance", distribution = "ggx", alpha = 0.1, kd = 0.2 }

[[object]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = { type = "lambert", albedo = 0.5 }

[render]
spp = 8
"#;

#[test]
fn writes_the_grid_and_the_numbers() {
    let d = dir("grid");
    let scene = d.join("scene.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let out = d.join("cmp");
    let o = lobe(&[
        "compare",
        scene.to_str().unwrap(),
        "--spp",
        "4",
        "--reference-spp",
        "128",
        "--seed",
        "3",
        "--threads",
        "2",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let png_path = d.join("cmp.png");
    let json_path = d.join("cmp.json");
    assert!(
        stdout.contains(&png_path.display().to_string())
            && stdout.contains(&json_path.display().to_string()),
        "{stdout}"
    );

    let j: Value = serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    assert_eq!(j["reference"]["spp"], 128);
    assert!(j["reference"]["time_s"].as_f64().unwrap() > 0.0);
    assert_eq!(
        (j["width"].as_u64(), j["height"].as_u64()),
        (Some(48), Some(32))
    );
    // The default strategies: brdf, vndf (the sphere has it), light, and the
    // three MIS side by side.
    let want = ["brdf", "vndf", "light", "mis-balance", "mis-power", "mis"];
    let mut rmse = std::collections::HashMap::new();
    for section in ["equal_samples", "equal_time"] {
        let rows = j[section]
            .as_array()
            .unwrap_or_else(|| panic!("{section}: {j}"));
        let names: Vec<&str> = rows
            .iter()
            .map(|r| r["strategy"].as_str().unwrap())
            .collect();
        assert_eq!(names, want, "{section}");
        for r in rows {
            let e = r["rmse"].as_f64().unwrap();
            assert!(e.is_finite() && e > 0.0, "{section}: {r}");
            assert!(r["spp"].as_u64().unwrap() >= 1, "{r}");
            assert!(r["time_s"].as_f64().unwrap() > 0.0, "{r}");
            if section == "equal_samples" {
                assert_eq!(r["spp"], 4, "{r}");
                rmse.insert(r["strategy"].as_str().unwrap().to_string(), e);
            }
        }
    }
    let budget = j["time_budget_s"].as_f64().unwrap();
    assert!(budget > 0.0, "{j}");
    // Issue 41: the header says what was equalized, and the times are
    // equal: within 3% by construction, which lobe-render's tests check
    // under a fake clock. Here, on a real clock, only within a factor of 2:
    // two tests side by side on two cores moved renders of 50 ms by 27%
    // (a timed test is not a benchmark; before the fix the spread was
    // 3.2 to 6.9 ms against 6.5 ms).
    assert!(
        stdout.contains("Equal time: ") && stdout.contains("(the time of mis at "),
        "{stdout}"
    );
    for r in j["equal_time"].as_array().unwrap() {
        let t = r["time_s"].as_f64().unwrap();
        assert!((0.5..2.0).contains(&(t / budget)), "{r} against {budget}");
        assert!(r["worst_pixel_share"].as_f64().unwrap() <= 1.0, "{r}");
    }
    // The help names the defaults it runs.
    let help = String::from_utf8(lobe(&["compare", "--help"]).stdout).unwrap();
    assert!(
        help.contains("(default: brdf, vndf (when an object's material has it), light, mis-balance, mis-power and mis)"),
        "{help}"
    );
    // MIS is no worse than the worse of its two strategies.
    assert!(
        rmse["mis"] <= rmse["brdf"].max(rmse["light"]),
        "RMSE: {rmse:?}"
    );

    // The figure: its size is the layout's, which holds the reference cell
    // and one cell (render and error map) per strategy and row, each image
    // shown 5× (48 pixels wide is scaled up to at least 240).
    let f = &j["figure"];
    let (fw, fh) = (
        f["width"].as_u64().unwrap() as u32,
        f["height"].as_u64().unwrap() as u32,
    );
    let png = image::open(&png_path).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (fw, fh));
    assert_eq!(
        (f["image_width"].as_u64(), f["image_height"].as_u64()),
        (Some(240), Some(160))
    );
    let (cw, ch) = match f["error_map"].as_str().unwrap() {
        "below" => (240, 2 * 160),
        "beside" => (2 * 240, 160),
        other => panic!("error_map {other}"),
    };
    let (cols, rows) = match f["layout"].as_str().unwrap() {
        "sections-as-rows" => (1 + want.len() as u32, 2),
        "strategies-as-rows" => (2, 1 + want.len() as u32),
        other => panic!("layout {other}"),
    };
    assert!(fw >= cols * cw && fw < cols * (cw + 60) + 60, "{f}");
    assert!(fh >= rows * ch && fh < rows * (ch + 100) + 100, "{f}");
    // Not blank: the renders and error maps are there.
    let distinct: std::collections::HashSet<[u8; 3]> = png.pixels().map(|p| p.0).collect();
    assert!(distinct.len() > 200, "{} colours", distinct.len());
    let scale = &f["error_scale"];
    assert!(scale["lo"].as_f64().unwrap() < scale["hi"].as_f64().unwrap());
}

#[test]
fn the_same_seed_gives_the_same_equal_sample_errors() {
    let d = dir("seed");
    let scene = d.join("scene.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let mut runs = Vec::new();
    for (k, threads) in ["1", "2"].iter().enumerate() {
        let out = d.join(format!("run{k}"));
        let o = lobe(&[
            "compare",
            scene.to_str().unwrap(),
            "--spp",
            "2",
            "--reference-spp",
            "16",
            "--strategies",
            "light,mis",
            "--threads",
            threads,
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let j: Value =
            serde_json::from_str(&std::fs::read_to_string(d.join(format!("run{k}.json"))).unwrap())
                .unwrap();
        let rmse: Vec<f64> = j["equal_samples"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r["rmse"].as_f64().unwrap())
            .collect();
        assert_eq!(rmse.len(), 2);
        runs.push(rmse);
    }
    assert_eq!(runs[0], runs[1]);
}

#[test]
fn bad_input_fails_with_one_line() {
    let d = dir("errors");
    let scene = d.join("scene.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let s = scene.to_str().unwrap();
    let out = d.join("x");
    let o = out.to_str().unwrap();

    let missing = d.join("nowhere.toml");
    let e = one_line_error(&lobe(&[
        "compare",
        missing.to_str().unwrap(),
        "--out",
        o,
        "--quiet",
    ]));
    assert!(e.contains("nowhere.toml"), "{e}");

    let e = one_line_error(&lobe(&["compare", s, "--spp", "0", "--out", o, "--quiet"]));
    assert!(e.contains("--spp 0"), "{e}");

    let e = one_line_error(&lobe(&[
        "compare",
        s,
        "--strategies",
        "brdf,fast",
        "--out",
        o,
        "--quiet",
    ]));
    assert!(e.contains("unknown strategy `fast`"), "{e}");

    let e = one_line_error(&lobe(&[
        "compare",
        s,
        "--reference-spp",
        "0",
        "--out",
        o,
        "--quiet",
    ]));
    assert!(e.contains("--reference-spp 0"), "{e}");
    assert!(!d.join("x.png").exists() && !d.join("x.json").exists());
}

#[test]
fn help_has_an_example() {
    let o = lobe(&["compare", "--help"]);
    assert!(o.status.success());
    let s = String::from_utf8_lossy(&o.stdout);
    // Issue 8: the examples name the shipped scene, and the flag is
    // `--strategy` as in every other command (`--strategies` is a hidden
    // alias).
    assert!(s.contains("lobe compare examples/scene.toml"), "{s}");
    assert!(
        s.contains("--reference-spp") && s.contains("--strategy "),
        "{s}"
    );
    assert!(!s.contains("--strategies"), "{s}");
}
