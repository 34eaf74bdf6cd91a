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
