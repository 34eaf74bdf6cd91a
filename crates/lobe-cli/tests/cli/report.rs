//! `lobe report --quick`, then the page opened in headless Chromium: the
//! page must load and every image on it must load.
//!
//! Chromium is required, not optional: CI installs it (`.ci/run`), and a
//! machine without it fails this test with a message saying how to install
//! it.

use std::path::{Path, PathBuf};
use std::process::Command;

const CHROMIUM: &str = "/usr/bin/chromium";

/// A fresh, empty directory.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("report-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The DOM of `page` after its load event, as headless Chromium sees it.
fn dump_dom(page: &Path, profile: &Path) -> String {
    assert!(
        Path::new(CHROMIUM).exists(),
        "{CHROMIUM} is missing: this test opens the report in headless Chromium. Install it with \
         `apt-get install -y --no-install-recommends chromium` (CI's .ci/run does)"
    );
    let url = format!("file://{}", page.display());
    let out = Command::new(CHROMIUM)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--disable-dev-shm-usage",
            &format!("--user-data-dir={}", profile.display()),
            "--virtual-time-budget=5000",
            "--dump-dom",
            &url,
        ])
        .output()
        .expect("run chromium");
    assert!(
        out.status.success(),
        "chromium failed ({}): {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("the DOM is UTF-8")
}

#[test]
fn quick_report_loads_in_chromium_with_every_image() {
    let dir = scratch("quick");
    let out_dir = dir.join("site");
    let out = Command::new(env!("CARGO_BIN_EXE_lobe"))
        .args(["report", "--quick", "--quiet", "--out"])
        .arg(&out_dir)
        .output()
        .expect("run lobe report");
    assert!(
        out.status.success(),
        "lobe report failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let index = out_dir.join("index.html");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        stdout.trim_end().lines().last().map(Path::new),
        Some(index.canonicalize().unwrap().as_path()),
        "the last line of stdout is the path of index.html: {stdout}"
    );

    // The page itself: self-contained, images beside it.
    let html = std::fs::read_to_string(&index).unwrap();
    let srcs: Vec<&str> = html
        .split("<img src=\"")
        .skip(1)
        .map(|s| &s[..s.find('"').unwrap()])
        .collect();
    assert!(
        srcs.len() >= 20,
        "expected the figures of four models, found {} images",
        srcs.len()
    );
    for src in &srcs {
        assert!(
            !src.contains("://") && !src.starts_with('/'),
            "image {src} is not beside the page"
        );
        assert!(src.ends_with(".png"), "image {src} is not a PNG");
        let bytes = std::fs::read(out_dir.join(src)).unwrap_or_else(|e| panic!("{src}: {e}"));
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{src} is not a PNG");
    }
    for external in [
        "<link",
        "@import",
        "<script src",
        "url(",
        "http://",
        "https://",
    ] {
        assert!(
            !html.contains(external),
            "the page must be self-contained, found `{external}`"
        );
    }
    for heading in [
        "Phong",
        "Blinn-Phong",
        "Cook-Torrance with GGX",
        "Cook-Torrance with Beckmann",
        "variance reduction",
        "efficiency",
        "Jacobian",
        "VNDF",
    ] {
        assert!(html.contains(heading), "`{heading}` is not on the page");
    }

    // In Chromium: the load event ran the page's check of every image.
    let dom = dump_dom(&index, &dir.join("chromium-profile"));
    let check = dom
        .split("id=\"image-check\">")
        .nth(1)
        .and_then(|s| s.split('<').next())
        .unwrap_or_else(|| panic!("no #image-check in the DOM:\n{dom}"));
    let expect = format!("ok {0}/{0} images loaded", srcs.len());
    assert_eq!(check, expect, "the page's image check");
    assert!(dom.contains("<h1>Importance sampling in BRDF evaluation</h1>"));
}
