//! Every example in every `--help` runs as printed from the repository root
//! (issue 8): the example lines are taken from the help text itself, and
//! only `--out` is redirected into a temporary directory.

use std::path::{Path, PathBuf};
use std::process::Command;

const COMMANDS: [&str; 9] = [
    "", "demo", "eval", "estimate", "converge", "plot", "report", "render", "compare",
];

/// Examples not run, with the reason: the full demo and report take
/// minutes (their quick forms are run).
fn skipped(line: &str) -> Option<&'static str> {
    let words: Vec<&str> = line.split_whitespace().collect();
    match words.get(1).copied() {
        Some("demo") if !line.contains("--quick") => Some("the full demo takes about a minute"),
        Some("report") if !line.contains("--quick") => Some("the full report takes minutes"),
        _ => None,
    }
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The example command lines of one help text: the lines after
/// `Example:` or `Examples:` that start with `lobe ` or `echo `, with
/// continuation lines (ending in `\`) joined.
fn examples(help: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_examples = false;
    let mut pending = String::new();
    for line in help.lines() {
        let t = line.trim();
        if t == "Example:" || t == "Examples:" {
            in_examples = true;
            continue;
        }
        if !in_examples {
            continue;
        }
        if !pending.is_empty() {
            pending.push(' ');
            pending.push_str(t.trim_end_matches('\\').trim());
            if !t.ends_with('\\') {
                out.push(std::mem::take(&mut pending));
            }
            continue;
        }
        if t.starts_with("lobe ") || t.starts_with("echo ") {
            if t.ends_with('\\') {
                pending = t.trim_end_matches('\\').trim().to_string();
            } else {
                out.push(t.to_string());
            }
        } else if t.is_empty() {
            in_examples = false;
        }
    }
    out
}

/// The example with `--out X` moved under `tmp` (and `--out` added to
/// render and compare, which would write beside the current directory),
/// and anything after `&&` (opening a browser) dropped.
fn redirect(line: &str, tmp: &Path, k: usize) -> String {
    let line = line.split(" && ").next().unwrap();
    let mut words: Vec<String> = line.split(' ').map(str::to_string).collect();
    let dir = tmp.join(k.to_string());
    std::fs::create_dir_all(&dir).unwrap();
    let mut has_out = false;
    for i in 0..words.len() {
        if words[i] == "--out" && i + 1 < words.len() {
            let name = Path::new(&words[i + 1]).file_name().unwrap().to_owned();
            words[i + 1] = dir.join(name).display().to_string();
            has_out = true;
        }
    }
    let command = line
        .split('|')
        .next_back()
        .unwrap()
        .split_whitespace()
        .nth(1);
    if !has_out && matches!(command, Some("render" | "compare")) {
        words.push("--out".into());
        words.push(dir.join("out").display().to_string());
    }
    words.join(" ")
}

#[test]
fn every_help_example_runs_from_the_repository_root() {
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_lobe"));
    let tmp = std::env::temp_dir().join(format!("lobe-help-examples-{}", std::process::id()));
    let path = format!(
        "{}:{}",
        bin.parent().unwrap().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut ran = 0;
    let mut k = 0;
    for cmd in COMMANDS {
        let mut args: Vec<&str> = if cmd.is_empty() { vec![] } else { vec![cmd] };
        args.push("--help");
        let o = Command::new(&bin).args(&args).output().unwrap();
        assert!(o.status.success(), "lobe {cmd} --help");
        let help = String::from_utf8(o.stdout).unwrap();
        let lines = examples(&help);
        assert!(!lines.is_empty(), "lobe {cmd} --help has no example");
        for line in lines {
            k += 1;
            if let Some(why) = skipped(&line) {
                eprintln!("not run ({why}): {line}");
                continue;
            }
            let run = redirect(&line, &tmp, k);
            let o = Command::new("sh")
                .arg("-c")
                .arg(&run)
                .current_dir(root())
                .env("PATH", &path)
                .output()
                .unwrap();
            assert!(
                o.status.success(),
                "lobe {cmd} --help example failed:\n  {line}\nran as\n  {run}\nstderr: {}",
                String::from_utf8_lossy(&o.stderr)
            );
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(!err.contains("error"), "{line}: {err}");
            ran += 1;
        }
    }
    assert!(ran >= 15, "only {ran} examples ran");
    let _ = std::fs::remove_dir_all(&tmp);
}

#[test]
fn examples_are_found_in_a_help_text() {
    let help = "Examples:\n  lobe a --x 1 \\\n      --y 2\n  echo '{}' | lobe eval -m x\n\nMore text\n  lobe not-an-example";
    assert_eq!(
        examples(help),
        ["lobe a --x 1 --y 2", "echo '{}' | lobe eval -m x"]
    );
}
