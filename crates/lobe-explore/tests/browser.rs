//! The page in a real browser: headless Chromium (Debian's `chromium`,
//! which CI's .ci/run installs) driven over the DevTools protocol. It
//! opens the page, waits for every view, moves a slider and changes a
//! material's model, and checks that the plots change, that no console
//! error or exception appeared, and that screenshots are not blank
//! (written to target/explore-screenshots/, and to
//! `$LOBE_EXPLORE_SCREENSHOTS` when set, which is how docs/ gets its
//! pictures). It prints each view's slider-to-picture time.

use serde_json::{Value, json};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use tungstenite::{Message, WebSocket, stream::MaybeTlsStream};

const CHROMIUM: &str = "/usr/bin/chromium";

/// Chromium, killed when dropped.
struct Browser(Child);

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A DevTools session on one page: commands by id, and every event seen.
struct Page {
    ws: WebSocket<MaybeTlsStream<TcpStream>>,
    next: u64,
    events: Vec<Value>,
}

impl Page {
    fn call(&mut self, method: &str, params: Value) -> Value {
        self.next += 1;
        let id = self.next;
        let msg = json!({"id": id, "method": method, "params": params});
        self.ws.send(Message::text(msg.to_string())).unwrap();
        loop {
            let m = self.ws.read().expect("the DevTools connection");
            let Message::Text(t) = m else { continue };
            let v: Value = serde_json::from_str(t.as_str()).unwrap();
            if v["id"] == id {
                assert!(v.get("error").is_none(), "{method}: {v}");
                return v["result"].clone();
            }
            if v.get("method").is_some() {
                self.events.push(v);
            }
        }
    }

    /// `expr` evaluated in the page (promises awaited), by value.
    fn eval(&mut self, expr: &str) -> Value {
        let r = self.call(
            "Runtime.evaluate",
            json!({"expression": expr, "returnByValue": true, "awaitPromise": true}),
        );
        assert!(r.get("exceptionDetails").is_none(), "{expr}: {r}");
        r["result"]["value"].clone()
    }

    /// Waits until `expr` is true (at most `secs`).
    fn wait_for(&mut self, expr: &str, secs: u64) {
        let t = Instant::now();
        while self.eval(expr) != json!(true) {
            assert!(
                t.elapsed() < Duration::from_secs(secs),
                "waited {secs} s for {expr}; errors: {}",
                self.eval("JSON.stringify(window.lobeExplore && window.lobeExplore.errors)")
            );
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    /// Console errors, uncaught exceptions and error log entries so far.
    fn errors(&self) -> Vec<String> {
        self.events
            .iter()
            .filter(|e| match e["method"].as_str() {
                Some("Runtime.exceptionThrown") => true,
                Some("Runtime.consoleAPICalled") => e["params"]["type"] == "error",
                Some("Log.entryAdded") => e["params"]["entry"]["level"] == "error",
                _ => false,
            })
            .map(|e| e["params"].to_string())
            .collect()
    }

    /// A screenshot, checked not blank, written where the module doc says.
    fn screenshot(&mut self, name: &str) {
        use base64::Engine;
        let r = self.call("Page.captureScreenshot", json!({"format": "png"}));
        let png = base64::engine::general_purpose::STANDARD
            .decode(r["data"].as_str().unwrap())
            .unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        let mut colours = std::collections::HashSet::new();
        for p in img.pixels().step_by(7) {
            colours.insert(p.0);
        }
        assert!(
            colours.len() > 500,
            "{name}: {} colours, a blank page?",
            colours.len()
        );
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("explore-screenshots");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(format!("{name}.png")), &png).unwrap();
        if let Some(d) = std::env::var_os("LOBE_EXPLORE_SCREENSHOTS") {
            std::fs::create_dir_all(&d).unwrap();
            std::fs::write(PathBuf::from(d).join(format!("{name}.png")), &png).unwrap();
        }
    }
}

/// A GET's body: read up to its `Content-Length` (Chromium's DevTools
/// server keeps the connection open).
fn http_get(addr: &str, path: &str) -> String {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut buf = Vec::new();
    let mut chunk = [0u8; 8192];
    loop {
        let n = s.read(&mut chunk).unwrap();
        buf.extend_from_slice(&chunk[..n]);
        let text = String::from_utf8_lossy(&buf).into_owned();
        if let Some((head, body)) = text.split_once("\r\n\r\n") {
            let len = head.lines().find_map(|l| {
                let (k, v) = l.split_once(':')?;
                k.eq_ignore_ascii_case("content-length")
                    .then(|| v.trim().parse::<usize>().ok())
                    .flatten()
            });
            if n == 0 || len.is_some_and(|len| body.len() >= len) {
                return body.to_string();
            }
        }
        assert!(n > 0, "no answer from {addr}{path}");
    }
}

/// Chromium started headless on `url`'s page, and a DevTools session on it.
fn open(url: &str, profile: &Path) -> (Browser, Page) {
    assert!(
        Path::new(CHROMIUM).exists(),
        "{CHROMIUM} is missing: `apt-get install -y --no-install-recommends chromium` (CI's .ci/run does)"
    );
    let _ = std::fs::remove_dir_all(profile);
    std::fs::create_dir_all(profile).unwrap();
    let child = Command::new(CHROMIUM)
        .args([
            "--headless",
            "--no-sandbox",
            // WebGL (the 3D lobe) on the CPU.
            "--enable-unsafe-swiftshader",
            "--disable-dev-shm-usage",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--window-size=1400,1000",
            "--remote-debugging-port=0",
            &format!("--user-data-dir={}", profile.display()),
            "about:blank",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("start chromium");
    let browser = Browser(child);
    // Chromium writes its port to DevToolsActivePort once it listens.
    let port_file = profile.join("DevToolsActivePort");
    let t = Instant::now();
    let port = loop {
        if let Some(p) = std::fs::read_to_string(&port_file)
            .ok()
            .and_then(|s| s.lines().next().map(str::to_string))
            .filter(|p| !p.is_empty())
        {
            break p;
        }
        assert!(
            t.elapsed() < Duration::from_secs(30),
            "chromium did not start"
        );
        std::thread::sleep(Duration::from_millis(50));
    };
    let addr = format!("127.0.0.1:{port}");
    let targets: Value = serde_json::from_str(&http_get(&addr, "/json/list")).unwrap();
    let ws_url = targets
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["type"] == "page")
        .expect("a page target")["webSocketDebuggerUrl"]
        .as_str()
        .unwrap()
        .to_string();
    let (ws, _) = tungstenite::connect(ws_url).unwrap();
    let mut page = Page {
        ws,
        next: 0,
        events: Vec::new(),
    };
    page.call("Runtime.enable", json!({}));
    page.call("Log.enable", json!({}));
    page.call("Page.enable", json!({}));
    page.call("Page.navigate", json!({"url": url}));
    (browser, page)
}

/// `#id`'s `data-version`.
fn version(page: &mut Page, id: &str) -> i64 {
    let v = page.eval(&format!(
        "Number(document.getElementById('{id}').dataset.version || 0)"
    ));
    v.as_i64().unwrap_or(0)
}

/// The polar plot's first trace, as text (to see that it changed).
fn polar_trace(page: &mut Page) -> String {
    page.eval("JSON.stringify(document.getElementById('polar').data[0].r)")
        .to_string()
}

#[test]
fn the_page_works_in_chromium() {
    let url = lobe_explore::Server::bind(&lobe_explore::Config::default())
        .unwrap()
        .spawn();
    let profile = Path::new(env!("CARGO_TARGET_TMPDIR")).join("explore-chromium");
    let (_browser, mut page) = open(&url, &profile);
    page.wait_for("!!(window.lobeExplore && window.lobeExplore.ready)", 120);
    page.screenshot("explore-start");
    let views = ["polar", "lobe3d", "albedo", "warp", "estimate"];
    let before: Vec<i64> = views.iter().map(|v| version(&mut page, v)).collect();
    assert!(before.iter().all(|&v| v >= 1), "{views:?} {before:?}");
    let trace = polar_trace(&mut page);

    // Move the first material's α slider.
    page.eval(
        "(() => { const s = document.querySelector('.material[data-index=\"0\"] input[type=range][data-param=\"alpha\"]'); \
         s.value = String(Number(s.min) + 0.8 * (Number(s.max) - Number(s.min))); \
         s.dispatchEvent(new Event('input', {bubbles: true})); return true; })()",
    );
    let changed = |page: &mut Page, before: &[i64]| -> bool {
        views.iter().zip(before).all(|(v, b)| version(page, v) > *b)
    };
    let t = Instant::now();
    while !changed(&mut page, &before) {
        assert!(
            t.elapsed() < Duration::from_secs(120),
            "the views did not follow the slider"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    assert_ne!(
        polar_trace(&mut page),
        trace,
        "the polar plot did not change"
    );
    for v in views {
        let ms = page.eval(&format!("document.getElementById('{v}').dataset.ms"));
        eprintln!("slider to picture, {v}: {ms} ms");
    }
    page.screenshot("explore-slider");

    // Make the first material rough glass: the polar plot covers the
    // sphere.
    let before: Vec<i64> = views.iter().map(|v| version(&mut page, v)).collect();
    page.eval(
        "(() => { const s = document.querySelector('.material[data-index=\"0\"] select.model'); \
         s.value = 'roughdielectric'; s.dispatchEvent(new Event('change', {bubbles: true})); return true; })()",
    );
    let t = Instant::now();
    while !changed(&mut page, &before) {
        assert!(
            t.elapsed() < Duration::from_secs(120),
            "the views did not follow the model"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    let span =
        page.eval("Math.max(...document.getElementById('polar').data[0].theta.map(Math.abs))");
    assert!(
        span.as_f64().unwrap() > 170.0,
        "glass's polar plot spans {span}"
    );
    page.screenshot("explore-glass");

    let page_errors = page.eval("JSON.stringify(window.lobeExplore.errors)");
    assert_eq!(page_errors, json!("[]"), "errors shown on the page");
    let errors = page.errors();
    assert!(errors.is_empty(), "console errors: {errors:#?}");

    // A material the server refuses (a glass cannot be two-sided): the
    // server's message is shown on the page, and the page goes on.
    page.eval(
        "(() => { const c = document.querySelector('.material[data-index=\"0\"] .twosided'); \
         c.checked = true; c.dispatchEvent(new Event('change', {bubbles: true})); return true; })()",
    );
    page.wait_for(
        "!document.getElementById('error').hidden && document.getElementById('error').textContent.length > 0",
        60,
    );
    let shown = page.eval("document.getElementById('error').textContent");
    eprintln!("shown on the page: {shown}");
    assert!(shown.as_str().unwrap().contains("material"), "{shown}");
    let before = version(&mut page, "polar");
    page.eval(
        "(() => { const c = document.querySelector('.material[data-index=\"0\"] .twosided'); \
         c.checked = false; c.dispatchEvent(new Event('change', {bubbles: true})); return true; })()",
    );
    let t = Instant::now();
    while version(&mut page, "polar") <= before {
        assert!(
            t.elapsed() < Duration::from_secs(60),
            "the page did not recover"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}

#[test]
fn a_measured_table_beside_its_fit() {
    // A data directory with one RGL table of a known material.
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("explore-data");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("tables")).unwrap();
    let paint = lobe::Material::load(
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.25,"kd":0.1,"ks":0.6}"#,
    )
    .unwrap();
    let bytes = lobe::tabulate::to_bytes(
        &paint,
        lobe::tabulate::Format::Rgl(lobe::tabulate::RglResolution { n_theta: 6, n: 24 }),
    );
    std::fs::write(dir.join("tables/paint.bsdf"), bytes).unwrap();
    let url = lobe_explore::Server::bind(&lobe_explore::Config {
        data: Some(dir),
        ..lobe_explore::Config::default()
    })
    .unwrap()
    .spawn();
    let profile = Path::new(env!("CARGO_TARGET_TMPDIR")).join("explore-chromium-data");
    let (_browser, mut page) = open(&url, &profile);
    page.wait_for("!!(window.lobeExplore && window.lobeExplore.ready)", 120);
    page.wait_for(
        "[...document.querySelectorAll('#data-file option')].some(o => o.value === 'tables/paint.bsdf')",
        30,
    );
    // Load the table as a material (it becomes the active one), then fit it.
    page.eval(
        "(() => { const s = document.getElementById('data-file'); s.value = 'tables/paint.bsdf'; \
         s.dispatchEvent(new Event('change', {bubbles: true})); \
         document.getElementById('load-data').click(); return true; })()",
    );
    page.wait_for("document.querySelectorAll('.material').length === 3", 30);
    page.wait_for("!document.getElementById('fit').disabled", 60);
    page.eval("(() => { document.getElementById('fit').click(); return true; })()");
    page.wait_for("document.querySelectorAll('.material').length === 4", 120);
    // The polar plot overlays the table and its fit (and the two others).
    page.wait_for(
        "document.getElementById('polar').data.filter(t => /^[0-9]+\\. /.test(t.name || '')).length === 4",
        60,
    );
    let names = page.eval("JSON.stringify(document.getElementById('polar').data.map(t => t.name))");
    assert!(
        names.as_str().unwrap().contains("4. fit of paint.bsdf"),
        "{names}"
    );
    let status = page.eval("document.getElementById('fit-status').textContent");
    assert!(status.as_str().unwrap().contains("error"), "{status}");
    // Let the lit sphere refine a few passes before the picture.
    std::thread::sleep(Duration::from_secs(3));
    page.screenshot("explore-measured");
    let page_errors = page.eval("JSON.stringify(window.lobeExplore.errors)");
    assert_eq!(page_errors, json!("[]"), "errors shown on the page");
    let errors = page.errors();
    assert!(errors.is_empty(), "console errors: {errors:#?}");
}
