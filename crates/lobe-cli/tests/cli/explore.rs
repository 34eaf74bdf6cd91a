//! `lobe explore`: the URL first on stdout, the server answering, its
//! `--material`s on the page; bad arguments are one-line errors.

use super::common::one_line_error;
use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Command, Stdio};

fn lobe() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_lobe"));
    c.current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    c
}

#[test]
fn explore_prints_its_url_and_serves_the_page() {
    let mut child = lobe()
        .args([
            "explore",
            "--port",
            "0",
            "--material",
            "@examples/gold.toml",
            "--material",
            r#"{"type":"roughdielectric","alpha":0.1}"#,
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    let url = first.trim();
    assert!(
        url.starts_with("http://127.0.0.1:") && url.ends_with('/'),
        "{url}"
    );
    let addr = url.trim_start_matches("http://").trim_end_matches('/');
    let mut s = std::net::TcpStream::connect(addr).unwrap();
    write!(
        s,
        "GET /api/models HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut out = String::new();
    s.read_to_string(&mut out).unwrap();
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(out.starts_with("HTTP/1.1 200"), "{out:.200}");
    let body: serde_json::Value =
        serde_json::from_str(out.split_once("\r\n\r\n").unwrap().1).unwrap();
    let initial = body["initial"].as_array().unwrap();
    assert_eq!(initial.len(), 2);
    assert_eq!(initial[1]["type"], "roughdielectric");
}

#[test]
fn bad_explore_arguments_are_one_line_errors() {
    let o = lobe()
        .args(["explore", "--material", r#"{"type":"velvet"}"#])
        .output()
        .unwrap();
    let e = one_line_error(&o);
    assert!(e.contains("--material #1") && e.contains("velvet"), "{e}");
    let o = lobe()
        .args(["explore", "--data", "/no/such/directory"])
        .output()
        .unwrap();
    let e = one_line_error(&o);
    assert!(e.contains("--data /no/such/directory"), "{e}");
    // A measured table outside --data is refused.
    let o = lobe()
        .args([
            "explore",
            "--material",
            r#"{"type":"measured","path":"/etc/passwd"}"#,
        ])
        .output()
        .unwrap();
    let e = one_line_error(&o);
    assert!(e.contains("--data"), "{e}");
}
