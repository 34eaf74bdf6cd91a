//! `lobe demo --quick`: the tour and the showcase run end to end and say
//! where they wrote the figure and the numbers.

use serde_json::Value;
use std::path::Path;
use std::process::Command;

#[test]
fn quick_demo_writes_the_showcase() {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("demo-quick");
    let _ = std::fs::remove_dir_all(&d);
    let out = d.join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_lobe"))
        .args(["demo", "--quick", "--quiet", "--out", out.to_str().unwrap()])
        .output()
        .expect("run lobe");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        o.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );

    // The tour: the four models and the pointers to the other commands.
    for s in [
        "Phong n=100",
        "Blinn-Phong n=100",
        "GGX",
        "Beckmann",
        "uniform",
        "vndf",
        "lobe report --out report",
        "lobe estimate --help",
    ] {
        assert!(stdout.contains(s), "missing {s:?} in:\n{stdout}");
    }

    // The showcase, and where it went.
    let png = out.join("showcase.png");
    let json = out.join("showcase.json");
    assert!(
        stdout.contains(&png.display().to_string()) && stdout.contains(&json.display().to_string()),
        "{stdout}"
    );
    let img = image::open(&png).expect("the PNG decodes").to_rgb8();
    let j: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(
        img.dimensions(),
        (
            j["figure"]["width"].as_u64().unwrap() as u32,
            j["figure"]["height"].as_u64().unwrap() as u32
        )
    );
    let rows = j["equal_samples"].as_array().unwrap();
    let names: Vec<&str> = rows
        .iter()
        .map(|r| r["strategy"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["brdf", "light", "mis"]);
    for r in rows {
        let e = r["rmse"].as_f64().unwrap();
        assert!(e.is_finite() && e > 0.0, "{r}");
    }
    assert!(j["reference"]["spp"].as_u64().unwrap() > rows[0]["spp"].as_u64().unwrap());
    for name in ["reference", "brdf", "light", "mis"] {
        let p = out.join(format!("{name}.png"));
        assert!(p.exists(), "{}", p.display());
    }
}

/// Issue 41: the tour's `vs uniform` is uniform's exact variance over the
/// printed variance, and the header says so: every ratio is reproduced from
/// the printed numbers (uniform's exact variance beside the reference, the
/// row's variance) to the printed precision.
#[test]
fn the_tour_ratio_is_the_printed_exact_variance_over_the_printed_one() {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("demo-ratio");
    let o = Command::new(env!("CARGO_BIN_EXE_lobe"))
        .args(["demo", "--quick", "--quiet", "--out", d.to_str().unwrap()])
        .output()
        .expect("run lobe");
    assert!(o.status.success());
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("'vs uniform' is uniform's exact variance"),
        "{stdout}"
    );
    let mut exact = None;
    let mut checked = 0;
    for line in stdout
        .lines()
        .take_while(|l| !l.starts_with("brdf is the lecture"))
    {
        if let Some((_, v)) = line.split_once(", uniform's exact variance ") {
            exact = Some(v.trim().parse::<f64>().unwrap());
            continue;
        }
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.len() == 5 && w[4].ends_with('x') {
            let variance: f64 = w[3].parse().unwrap();
            let ratio: f64 = w[4].trim_end_matches('x').parse().unwrap();
            let want = exact.unwrap() / variance;
            assert!(
                (ratio - want).abs() <= 1e-3 * want + 0.05,
                "{line}: {ratio} against {want}\n{stdout}"
            );
            checked += 1;
        }
    }
    assert!(checked >= 8, "{checked}\n{stdout}");
}
