//! The JSON API over HTTP (docs/explore.md): every view answers with the
//! shapes the page draws; bad input of every kind gets a clear error and
//! the server stays up, also under a burst of 1000 requests; only files
//! under `--data` are read.

use lobe_explore::{Config, Server};
use serde_json::{Value, json};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::PathBuf;

/// `host:port` of a server started on a free port.
fn start(config: Config) -> String {
    let url = Server::bind(&config).unwrap().spawn();
    url.trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string()
}

/// One request (HTTP/1.1, the connection closed after it): status and
/// body.
fn request(addr: &str, method: &str, path: &str, body: &[u8]) -> (u16, String) {
    let mut s = TcpStream::connect(addr).unwrap();
    let head = format!(
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
        body.len()
    );
    s.write_all(head.as_bytes()).unwrap();
    s.write_all(body).unwrap();
    let mut out = Vec::new();
    s.read_to_end(&mut out).unwrap();
    let text = String::from_utf8_lossy(&out).into_owned();
    let status: u16 = text
        .split(' ')
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("no status in {text:.200}"));
    let body = text.split_once("\r\n\r\n").map_or("", |x| x.1).to_string();
    (status, body)
}

fn post(addr: &str, path: &str, v: &Value) -> (u16, Value) {
    let (s, b) = request(addr, "POST", path, v.to_string().as_bytes());
    (
        s,
        serde_json::from_str(&b).unwrap_or_else(|e| panic!("{path}: {e}: {b:.300}")),
    )
}

/// A 400 whose message contains `needle`.
fn refused(addr: &str, path: &str, v: &Value, needle: &str) {
    let (s, b) = post(addr, path, v);
    let msg = b["error"].as_str().unwrap_or_default();
    assert!(
        s == 400 && msg.contains(needle),
        "{path} {v}: {s} {b} (wanted 400 with {needle:?})"
    );
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("lobe-explore-api-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const GOLD: &str = r#"{"type":"roughconductor","alpha":0.2,"material":"Au"}"#;

#[test]
fn every_view_answers() {
    let a = start(Config::default());
    let (s, body) = request(&a, "GET", "/api/models", b"");
    assert_eq!(s, 200);
    let models: Value = serde_json::from_str(&body).unwrap();
    let names: Vec<&str> = models["models"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    for n in [
        "diffuse",
        "roughconductor",
        "roughdielectric",
        "roughplastic",
        "measured",
    ] {
        assert!(names.contains(&n), "{n} in {names:?}");
    }
    let alpha = &models["models"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["name"] == "roughconductor")
        .unwrap()["params"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "alpha")
        .unwrap()
        .clone();
    assert_eq!(alpha["kind"], "number");
    assert_eq!(alpha["log"], true);
    assert!(
        models["strategies"]
            .as_array()
            .unwrap()
            .iter()
            .all(|s| s["description"].is_string())
    );

    let m: Value = serde_json::from_str(GOLD).unwrap();
    let (s, d) = post(&a, "/api/material", &json!({"material": m}));
    assert_eq!(s, 200, "{d}");
    assert_eq!(d["model"], "roughconductor");
    assert!(
        d["strategies"]
            .as_array()
            .unwrap()
            .iter()
            .any(|s| s == "vndf")
    );
    assert!(d["toml"].as_str().unwrap().contains("alpha = 0.2"), "{d}");
    assert!(
        d["python"]
            .as_str()
            .unwrap()
            .starts_with("{\"type\": \"roughconductor\""),
        "{d}"
    );
    let back: Value = serde_json::from_str(d["json"].as_str().unwrap()).unwrap();
    assert_eq!(back, m);

    let (s, p) = post(
        &a,
        "/api/polar",
        &json!({"material": m, "theta_o": 40, "steps": 181}),
    );
    assert_eq!(s, 200, "{p}");
    let fcos = p["fcos"].as_array().unwrap();
    assert_eq!(fcos.len(), p["theta_deg"].as_array().unwrap().len());
    assert!(fcos.iter().any(|v| v.as_f64().unwrap() > 0.0));
    assert!(p["pdfs"]["vndf"].as_array().unwrap().len() == fcos.len());
    assert!(p["albedo"].as_f64().unwrap() > 0.5);

    let (s, l) = post(
        &a,
        "/api/lobe",
        &json!({"material": m, "theta_o": 40, "n_theta": 10, "n_phi": 12}),
    );
    assert_eq!(s, 200, "{l}");
    assert_eq!(l["values"].as_array().unwrap().len(), 11);
    assert_eq!(l["values"][0].as_array().unwrap().len(), 13);

    let (s, al) = post(&a, "/api/albedo", &json!({"material": m, "n": 4}));
    assert_eq!(s, 200, "{al}");
    assert_eq!(al["albedo"].as_array().unwrap().len(), 4);

    let (s, w) = post(
        &a,
        "/api/warp",
        &json!({"material": m, "strategy": "vndf", "theta_o": 40, "samples": 5000, "res": 8, "heat_res": 8}),
    );
    assert_eq!(s, 200, "{w}");
    assert_eq!(w["observed"].as_array().unwrap().len(), 64);
    assert_eq!(w["weights"].as_array().unwrap().len(), 64);
    assert!(w["chi2"]["p_value"].as_f64().unwrap() > 1e-3, "{w}");

    let (s, e) = post(
        &a,
        "/api/estimate",
        &json!({"material": m, "theta_o": 40, "samples": 256}),
    );
    assert_eq!(s, 200, "{e}");
    let rows = e["rows"].as_array().unwrap();
    assert!(
        rows.iter().any(|r| r["name"] == "vndf") && rows.iter().all(|r| r["variance"].is_number())
    );

    let (s, sp) = post(
        &a,
        "/api/sphere",
        &json!({"material": m, "size": 16, "spp": 1, "pass": 3}),
    );
    assert_eq!(s, 200, "{sp:.300}");
    let rgb = sp["rgb"].as_array().unwrap();
    assert_eq!(rgb.len(), 16 * 16 * 3);
    assert!(rgb.iter().all(|v| v.as_f64().unwrap().is_finite()));
    assert!(rgb.iter().any(|v| v.as_f64().unwrap() > 0.0));

    // Glass from below the surface.
    let glass = json!({"type": "roughdielectric", "alpha": 0.2});
    let (s, p) = post(
        &a,
        "/api/polar",
        &json!({"material": glass, "theta_o": 150, "steps": 41}),
    );
    assert_eq!(s, 200, "{p}");
    assert_eq!(p["full_circle"], true);
}

#[test]
fn bad_input_gets_a_clear_error_and_the_server_stays_up() {
    let a = start(Config::default());
    let m: Value = serde_json::from_str(GOLD).unwrap();
    let (s, b) = request(&a, "POST", "/api/polar", b"{not json");
    assert!(s == 400 && b.contains("request:"), "{s} {b}");
    refused(&a, "/api/polar", &json!({"material": m}), "theta_o");
    refused(
        &a,
        "/api/polar",
        &json!({"material": m, "theta_o": 40, "extra": 1}),
        "extra",
    );
    refused(
        &a,
        "/api/polar",
        &json!({"material": {"type": "velvet"}, "theta_o": 40}),
        "velvet",
    );
    refused(
        &a,
        "/api/polar",
        &json!({"material": {"type": "roughconductor", "alpha": -1}, "theta_o": 40}),
        "alpha",
    );
    refused(
        &a,
        "/api/polar",
        &json!({"material": "diffuse", "theta_o": 40}),
        "object",
    );
    refused(
        &a,
        "/api/polar",
        &json!({"material": m, "theta_o": 95}),
        "theta_o",
    );
    refused(
        &a,
        "/api/polar",
        &json!({"material": m, "theta_o": "forty"}),
        "request:",
    );
    refused(
        &a,
        "/api/polar",
        &json!({"material": m, "theta_o": 40, "steps": 100_000_000}),
        "steps",
    );
    refused(
        &a,
        "/api/warp",
        &json!({"material": m, "strategy": "vndf", "theta_o": 40, "samples": 1u64 << 40}),
        "samples",
    );
    refused(
        &a,
        "/api/warp",
        &json!({"material": m, "strategy": "magic", "theta_o": 40}),
        "strategy",
    );
    refused(
        &a,
        "/api/warp",
        &json!({"material": {"type": "diffuse"}, "strategy": "vndf", "theta_o": 40}),
        "strategy",
    );
    refused(
        &a,
        "/api/sphere",
        &json!({"material": m, "size": 100_000}),
        "size",
    );
    refused(
        &a,
        "/api/sphere",
        &json!({"material": m, "env": "/etc/passwd"}),
        "--data",
    );
    refused(
        &a,
        "/api/estimate",
        &json!({"material": m, "theta_o": 40, "samples": 1u64 << 30}),
        "samples",
    );
    // No data directory: no file is read, whatever the path.
    refused(
        &a,
        "/api/polar",
        &json!({"material": {"type": "measured", "path": "/etc/passwd"}, "theta_o": 40}),
        "--data",
    );
    refused(&a, "/api/fit", &json!({"file": "../x.binary"}), "--data");
    let big = vec![b' '; 70 * 1024];
    let (s, b) = request(&a, "POST", "/api/polar", &big);
    assert!(s == 413 && b.contains("larger"), "{s} {b}");
    let (s, b) = request(&a, "GET", "/api/nothing", b"");
    assert!(s == 404 && b.contains("no such"), "{s} {b}");
    let (s, _) = request(&a, "DELETE", "/api/polar", b"");
    assert_eq!(s, 405);
    let (s, _) = request(&a, "GET", "/", b"");
    assert_eq!(s, 200);
}

#[test]
fn only_files_under_data_are_read() {
    let d = scratch("data");
    let data = d.join("data");
    std::fs::create_dir_all(data.join("tables")).unwrap();
    let gold = lobe::Material::load(GOLD).unwrap();
    let bytes = lobe::tabulate::to_bytes(
        &gold,
        lobe::tabulate::Format::Rgl(lobe::tabulate::RglResolution { n_theta: 6, n: 24 }),
    );
    std::fs::write(data.join("tables/gold.bsdf"), &bytes).unwrap();
    std::fs::write(d.join("outside.bsdf"), &bytes).unwrap();
    std::os::unix::fs::symlink(d.join("outside.bsdf"), data.join("link.bsdf")).unwrap();
    let a = start(Config {
        data: Some(data.clone()),
        ..Config::default()
    });
    let (_, b) = request(&a, "GET", "/api/data", b"");
    let v: Value = serde_json::from_str(&b).unwrap();
    assert_eq!(
        v["files"],
        json!([{"path": "tables/gold.bsdf", "kind": "measured"}])
    );
    let measured = json!({"type": "measured", "path": "tables/gold.bsdf"});
    let (s, p) = post(
        &a,
        "/api/polar",
        &json!({"material": measured, "theta_o": 30, "steps": 61}),
    );
    assert_eq!(s, 200, "{p}");
    // The description keeps the relative path (the absolute one stays on
    // the server).
    let (_, d2) = post(&a, "/api/material", &json!({"material": measured}));
    assert!(
        d2["json"]
            .as_str()
            .unwrap()
            .contains("\"tables/gold.bsdf\""),
        "{d2}"
    );
    for bad in [
        "../outside.bsdf",
        "tables/../../outside.bsdf",
        "/etc/passwd",
        "link.bsdf",
        "tables",
    ] {
        refused(
            &a,
            "/api/polar",
            &json!({"material": {"type": "measured", "path": bad}, "theta_o": 30}),
            bad,
        );
        refused(&a, "/api/fit", &json!({"file": bad}), bad);
    }
    let (s, f) = post(&a, "/api/fit", &json!({"file": "tables/gold.bsdf"}));
    assert_eq!(s, 200, "{f}");
    assert_eq!(f["material"]["type"], "cook-torrance", "{f}");
    let alpha = f["material"]["alpha"].as_f64().unwrap();
    assert!((alpha - 0.2).abs() < 0.05, "{f}");
}

#[test]
fn a_burst_of_1000_requests() {
    let a = start(Config::default());
    let m: Value = serde_json::from_str(GOLD).unwrap();
    let polar = json!({"material": m, "theta_o": 40, "steps": 91}).to_string();
    let statuses: Vec<u16> = std::thread::scope(|s| {
        let hs: Vec<_> = (0..50)
            .map(|t| {
                let (a, polar) = (&a, &polar);
                s.spawn(move || {
                    (0..20)
                        .map(|k| match (t + k) % 4 {
                            0 => request(a, "GET", "/api/models", b"").0,
                            1 => request(a, "POST", "/api/polar", polar.as_bytes()).0,
                            2 => request(a, "POST", "/api/polar", b"{bad").0,
                            _ => request(a, "GET", "/app.js", b"").0,
                        })
                        .collect::<Vec<u16>>()
                })
            })
            .collect();
        hs.into_iter().flat_map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(statuses.len(), 1000);
    // Every request answered: 200, 400 for the bad ones, or 503 when too
    // many computations wait.
    assert!(
        statuses.iter().all(|s| [200, 400, 503].contains(s)),
        "{statuses:?}"
    );
    assert_eq!(statuses.iter().filter(|&&s| s == 400).count(), 250);
    let (s, p) = post(&a, "/api/polar", &serde_json::from_str(&polar).unwrap());
    assert_eq!(s, 200, "{p}");
}
