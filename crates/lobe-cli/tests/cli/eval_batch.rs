//! `lobe eval --batch` against the default f64 path (issue 9): the same
//! lines give the same fields, within 1e-4 relative (f, pdf, weight) and
//! 1e-5 absolute (wi), for every batched model and strategy; and a
//! material the batch path lacks is a clear error.

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use serde_json::Value;
use std::io::Write;
use std::process::{Command, Stdio};

fn run(args: &[&str], input: &str) -> (Option<i32>, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_lobe"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start lobe");
    let mut stdin = child.stdin.take().unwrap();
    let input = input.as_bytes().to_vec();
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let out = child.wait_with_output().expect("run lobe");
    writer.join().unwrap();
    (
        out.status.code(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

fn lines(stdout: &str) -> Vec<Value> {
    stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{l}: {e}")))
        .collect()
}

fn nums(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(a) => a.iter().map(|x| x.as_f64().unwrap()).collect(),
        Value::Number(n) => vec![n.as_f64().unwrap()],
        _ => panic!("{v} is not numbers"),
    }
}

/// Relative agreement; values below `floor` compare absolutely (an f32
/// cannot carry a relative 1e-4 of a subnormal).
fn close_rel(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs() + 1e-30
}

/// A direction of the upper hemisphere, with grazing ones over-represented.
fn direction(rng: &mut Pcg64) -> [f64; 3] {
    let z: f64 = if rng.random::<f64>() < 0.1 {
        rng.random_range(1e-3..0.05)
    } else {
        rng.random_range(0.05..1.0)
    };
    let phi = rng.random_range(0.0..std::f64::consts::TAU);
    let s = (1.0 - z * z).sqrt();
    [s * phi.cos(), s * phi.sin(), z]
}

fn json3(v: [f64; 3]) -> String {
    format!("[{},{},{}]", v[0], v[1], v[2])
}

/// Every analytic model: Lambert, Phong, Blinn-Phong, Cook-Torrance with
/// GGX (every strategy, spherical caps and bounded VNDF included), Beckmann
/// and the Blinn-Phong NDF, every Fresnel and shadowing term, a diffuse
/// term. (The measured model is another step's.) `(material, with eval
/// lines, only these strategies' sample lines (empty: all))`.
const MATERIALS: &[(&str, bool, &[&str])] = &[
    (r#"{"type":"lambert","albedo":[0.2,0.5,0.8]}"#, true, &[]),
    (
        r#"{"type":"cook-torrance","distribution":"beckmann","alpha":0.15,"fresnel":{"type":"conductor"}}"#,
        true,
        &[],
    ),
    (
        r#"{"type":"cook-torrance","distribution":"beckmann","alpha_u":0.1,"alpha_v":0.4,"kd":0.2,"ks":0.7,"shadowing":"smith-separable","fresnel":{"type":"dielectric","eta":1.5}}"#,
        true,
        &[],
    ),
    (
        r#"{"type":"cook-torrance","distribution":"beckmann","alpha":0.5,"shadowing":"v-cavity","fresnel":{"type":"schlick","f0":[0.9,0.6,0.3]}}"#,
        true,
        &[],
    ),
    (r#"{"type":"cook-torrance","alpha":0.2}"#, true, &[]),
    (
        r#"{"type":"cook-torrance","alpha_u":0.05,"alpha_v":0.3,"kd":[0.3,0.2,0.1],"fresnel":{"type":"schlick","f0":[0.9,0.6,0.3]}}"#,
        true,
        &[],
    ),
    (
        r#"{"type":"cook-torrance","distribution":"blinn-phong","alpha":0.25,"kd":0.1,"shadowing":"v-cavity"}"#,
        true,
        &[],
    ),
    (
        r#"{"type":"phong","exponent":60,"kd":[0.2,0.1,0.3]}"#,
        true,
        &[],
    ),
    (
        r#"{"type":"blinn-phong","exponent":200,"normalized":false,"ks":0.5}"#,
        true,
        &[],
    ),
];

/// Lines per kind (eval lines, and sample lines per strategy): 1800 keeps
/// the test's cost where it was before the models above were added.
const LINES: usize = 1800;

#[test]
fn batch_agrees_with_the_f64_path_for_every_model_and_strategy() {
    let mut rng = Pcg64::seed_from_u64(9);
    for &(material, with_eval, only) in MATERIALS {
        // The strategies that apply, from the default path's eval line.
        let probe = r#"{"wo":[0,0,1],"wi":[0,0,1]}"#;
        let (code, out, err) = run(&["eval", "-m", material], probe);
        assert_eq!(code, Some(0), "{material}: {err}");
        let mut strategies: Vec<String> = lines(&out)[0]["pdf"]
            .as_object()
            .unwrap()
            .keys()
            .cloned()
            .collect();
        if !only.is_empty() {
            strategies.retain(|s| only.contains(&s.as_str()));
        }
        let mut input = String::new();
        for _ in 0..if with_eval { LINES } else { 0 } {
            let (wo, wi) = (direction(&mut rng), direction(&mut rng));
            input += &format!("{{\"wo\":{},\"wi\":{}}}\n", json3(wo), json3(wi));
        }
        for s in &strategies {
            for _ in 0..LINES {
                let wo = direction(&mut rng);
                // u in f32 so that both paths see the same numbers.
                let u: [f32; 3] = [rng.random(), rng.random(), rng.random()];
                input += &format!(
                    "{{\"wo\":{},\"u\":[{},{}],\"uc\":{},\"strategy\":\"{s}\"}}\n",
                    json3(wo),
                    f64::from(u[0]),
                    f64::from(u[1]),
                    f64::from(u[2])
                );
            }
        }
        let (c1, reference, e1) = run(&["eval", "-m", material], &input);
        assert_eq!(c1, Some(0), "{material}: {e1}");
        let (c2, batch, e2) = run(&["eval", "--batch", "-m", material], &input);
        assert_eq!(c2, Some(0), "{material} --batch: {e2}");
        let (reference, batch) = (lines(&reference), lines(&batch));
        assert_eq!(reference.len(), batch.len(), "{material}");
        let (mut worst_rel, mut worst_abs, mut differ) = (0.0f64, 0.0f64, 0usize);
        let mut grazing = 0usize;
        for (i, (r, b)) in reference.iter().zip(&batch).enumerate() {
            let mut bad = false;
            let mut check_rel = |a: &Value, e: &Value| {
                for (x, y) in nums(a).into_iter().zip(nums(e)) {
                    if !close_rel(x, y, 1e-4) {
                        bad = true;
                    }
                    if y.abs() > 1e-30 {
                        worst_rel = worst_rel.max((x - y).abs() / y.abs());
                    }
                }
            };
            if r.get("f").is_some() {
                check_rel(&b["f"], &r["f"]);
                for s in &strategies {
                    check_rel(&b["pdf"][s], &r["pdf"][s]);
                }
            } else if r["wi"].is_null() || b["wi"].is_null() {
                if r["wi"].is_null() != b["wi"].is_null() {
                    bad = true;
                }
            } else if nums(&r["wi"])[2] < 1e-3 {
                // Within 1e-3 of the horizon an f32 direction cannot carry
                // cos θi to 1e-4 relative (its z is off by up to 3e-8), and
                // the weight moves with it: wi is checked, f and weight not.
                grazing += 1;
                for (x, y) in nums(&b["wi"]).into_iter().zip(nums(&r["wi"])) {
                    if (x - y).abs() > 1e-5 {
                        bad = true;
                    }
                }
            } else {
                check_rel(&b["pdf"], &r["pdf"]);
                // The weight carries cos θi: an f32 wi whose z is off by
                // |Δz| moves it by |Δz|/z relative (Beckmann vndf's wi is
                // good to ~1e-6 at grazing views, module doc of lobe::batch).
                let dz = (nums(&b["wi"])[2] - nums(&r["wi"])[2]).abs() / nums(&r["wi"])[2];
                for (x, y) in nums(&b["weight"]).into_iter().zip(nums(&r["weight"])) {
                    if !close_rel(x, y, 1e-4 + 2.0 * dz) {
                        bad = true;
                    }
                    if y.abs() > 1e-30 {
                        worst_rel = worst_rel.max(((x - y).abs() / y.abs() - 2.0 * dz).max(0.0));
                    }
                }
                for (x, y) in nums(&b["wi"]).into_iter().zip(nums(&r["wi"])) {
                    worst_abs = worst_abs.max((x - y).abs());
                    if (x - y).abs() > 1e-5 {
                        bad = true;
                    }
                }
            }
            if bad {
                differ += 1;
                if differ <= 3 {
                    eprintln!("{material}: line {}: f64 {r} batch {b}", i + 1);
                }
            }
        }
        eprintln!(
            "{material}: {} lines ({grazing} grazing), worst relative {worst_rel:.2e}, worst wi {worst_abs:.2e}, {differ} beyond tolerance",
            reference.len()
        );
        assert_eq!(differ, 0, "{material}: {differ} lines beyond tolerance");
    }
}

/// What the f32 kernels cannot carry (a lecture-form `ks` beyond f32's
/// range) is a clear error naming the line and the strategy.
#[test]
fn an_unbatched_material_is_a_clear_error() {
    let (code, _, err) = run(
        &[
            "eval",
            "--batch",
            "-m",
            r#"{"type":"phong","normalized":false,"ks":1e300}"#,
        ],
        "{\"wo\":[0,0,1],\"u\":[0.5,0.5],\"strategy\":\"brdf\"}\n",
    );
    assert_eq!(code, Some(1));
    // (After the warning that this material reflects more than it receives.)
    assert!(
        err.contains("lobe: error: stdin line 1: --batch, strategy `brdf`: ")
            && err.contains("f32"),
        "{err}"
    );
}

/// Measured tables (issue 11): an RGL file that `lobe tabulate` writes,
/// every strategy it has (uniform, cosine, brdf, vndf), eval and sample
/// lines, against the f64 path with the tolerances above. About 4 s of CPU
/// (each process builds the table's sampler). MERL tables run the same
/// kernel (`lobe::batch` checks it bit for bit against the scalar path at
/// the f32 inputs); here they would add 4 s (35 MB read and a sampler built
/// per process; measured: worst 5.2e-7 relative, 7.6e-8 in wi).
#[test]
fn measured_tables_agree_with_the_f64_path() {
    let dir = std::env::temp_dir().join(format!("lobe-eval-batch-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let analytic = r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2,"kd":0.1,"fresnel":{"type":"schlick","f0":[0.9,0.6,0.3]}}"#;
    let mut rng = Pcg64::seed_from_u64(11);
    for (format, name, extra) in [("rgl", "t.bsdf", &["--views", "6", "--grid", "24"][..])] {
        let path = dir.join(name);
        let p = path.to_str().unwrap();
        let mut args = vec!["tabulate", "-m", analytic, "--format", format, "--out", p];
        args.extend_from_slice(extra);
        let (code, _, err) = run(&args, "");
        assert_eq!(code, Some(0), "{err}");
        let material = format!(r#"{{"type":"measured","path":"{p}"}}"#);
        let strategies: &[&str] = if format == "rgl" {
            &["uniform", "cosine", "brdf", "vndf"]
        } else {
            &["uniform", "cosine", "brdf"]
        };
        let mut input = String::new();
        for _ in 0..1000 {
            let (wo, wi) = (direction(&mut rng), direction(&mut rng));
            input += &format!("{{\"wo\":{},\"wi\":{}}}\n", json3(wo), json3(wi));
        }
        for s in strategies {
            for _ in 0..1000 {
                let wo = direction(&mut rng);
                let u: [f32; 2] = [rng.random(), rng.random()];
                input += &format!(
                    "{{\"wo\":{},\"u\":[{},{}],\"strategy\":\"{s}\"}}\n",
                    json3(wo),
                    f64::from(u[0]),
                    f64::from(u[1])
                );
            }
        }
        let (c1, reference, e1) = run(&["eval", "-m", &material], &input);
        assert_eq!(c1, Some(0), "{format}: {e1}");
        let (c2, batch, e2) = run(&["eval", "--batch", "-m", &material], &input);
        assert_eq!(c2, Some(0), "{format} --batch: {e2}");
        let (reference, batch) = (lines(&reference), lines(&batch));
        assert_eq!(reference.len(), batch.len());
        let (mut worst_rel, mut worst_abs, mut differ) = (0.0f64, 0.0f64, 0usize);
        for (i, (r, b)) in reference.iter().zip(&batch).enumerate() {
            let mut bad = false;
            let mut rel = |a: &Value, e: &Value| {
                for (x, y) in nums(a).into_iter().zip(nums(e)) {
                    bad |= !close_rel(x, y, 1e-4);
                    if y.abs() > 1e-30 {
                        worst_rel = worst_rel.max((x - y).abs() / y.abs());
                    }
                }
            };
            if r.get("f").is_some() {
                rel(&b["f"], &r["f"]);
                let keys: Vec<&String> = r["pdf"].as_object().unwrap().keys().collect();
                assert_eq!(keys.len(), strategies.len(), "{r}");
                for s in keys {
                    rel(&b["pdf"][s], &r["pdf"][s]);
                }
            } else if r["wi"].is_null() || b["wi"].is_null() {
                bad |= r["wi"].is_null() != b["wi"].is_null();
            } else {
                let grazing = nums(&r["wi"])[2] < 1e-3;
                if !grazing {
                    rel(&b["pdf"], &r["pdf"]);
                    rel(&b["weight"], &r["weight"]);
                }
                for (x, y) in nums(&b["wi"]).into_iter().zip(nums(&r["wi"])) {
                    worst_abs = worst_abs.max((x - y).abs());
                    bad |= (x - y).abs() > 1e-5;
                }
            }
            if bad {
                differ += 1;
                if differ <= 3 {
                    eprintln!(
                        "{format}: line {}: {}\n  f64 {r}\n  batch {b}",
                        i + 1,
                        input.lines().nth(i).unwrap_or("")
                    );
                }
            }
        }
        eprintln!(
            "measured {format}: {} lines, worst relative {worst_rel:.2e}, worst wi {worst_abs:.2e}, {differ} beyond tolerance",
            reference.len()
        );
        assert_eq!(differ, 0, "{format}: {differ} lines beyond tolerance");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
