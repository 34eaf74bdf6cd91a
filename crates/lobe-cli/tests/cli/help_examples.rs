//! Every example in every `--help` runs as printed from the repository root
//! (issues 8 and 41): the example lines are taken from the help text of
//! `lobe` and of every subcommand `lobe --help` lists; `--out` is
//! redirected into a temporary directory (where a later example of the
//! same help finds what an earlier one wrote, as `lobe fit` reads what
//! `lobe tabulate` wrote), and `lobe bench` runs with small sizes.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The subcommands `lobe --help` lists.
fn commands(bin: &Path) -> Vec<String> {
    let o = Command::new(bin).arg("--help").output().unwrap();
    let help = String::from_utf8(o.stdout).unwrap();
    let mut v = vec![String::new()];
    let mut on = false;
    for line in help.lines() {
        if line.starts_with("Commands:") {
            on = true;
            continue;
        }
        if on {
            match line.split_whitespace().next() {
                Some(c) if line.starts_with("  ") && c != "help" => v.push(c.to_string()),
                Some(_) => {}
                None => break,
            }
        }
    }
    v
}

/// Examples not run, with the reason: the full demo and report take
/// minutes (their quick forms are run).
fn skipped(line: &str) -> Option<&'static str> {
    let words: Vec<&str> = line.split_whitespace().collect();
    match words.get(1).copied() {
        Some("demo") if !line.contains("--quick") => Some("the full demo takes about a minute"),
        Some("report") if !line.contains("--quick") => Some("the full report takes minutes"),
        Some("explore") => Some(
            "a server that runs until stopped (tests/cli/explore.rs and crates/lobe-explore's tests start it)",
        ),
        Some("sweep") => Some(
            "needs the Python package with its dask extra (python/tests/test_sweeps.py runs it)",
        ),
        _ => None,
    }
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Whether a line is a command: `lobe …`, `echo …`, or either after
/// environment assignments (`LOBE_SIMD=avx2 lobe bench`).
fn is_command(t: &str) -> bool {
    let rest = t
        .split_whitespace()
        .skip_while(|w| w.contains('=') && !w.starts_with('-') && !w.starts_with('\''))
        .collect::<Vec<_>>();
    matches!(rest.first(), Some(&"lobe" | &"echo"))
}

/// The example command lines of one help text: the lines after a line
/// starting `Example` and ending in `:` that are commands ([`is_command`]),
/// with continuation lines (ending in `\`) joined.
fn examples(help: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_examples = false;
    let mut pending = String::new();
    for line in help.lines() {
        let t = line.trim();
        if t.starts_with("Example") && t.ends_with(':') {
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
        if is_command(t) {
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
fn redirect(line: &str, tmp: &Path, k: &str) -> String {
    let line = line.split(" && ").next().unwrap();
    let mut words: Vec<String> = line.split(' ').map(str::to_string).collect();
    let dir = tmp.join(k);
    std::fs::create_dir_all(&dir).unwrap();
    let mut has_out = false;
    for i in 0..words.len() {
        if words[i] == "--out" && i + 1 < words.len() {
            let name = Path::new(&words[i + 1]).file_name().unwrap().to_owned();
            words[i + 1] = dir.join(name).display().to_string();
            has_out = true;
        } else if !words[i].starts_with('-') && dir.join(&words[i]).is_file() {
            // An input an earlier example of this help wrote.
            words[i] = dir.join(&words[i]).display().to_string();
        }
    }
    let command = line
        .split('|')
        .next_back()
        .unwrap()
        .split_whitespace()
        .skip_while(|w| *w != "lobe")
        .nth(1);
    if !has_out && matches!(command, Some("render" | "compare")) {
        words.push("--out".into());
        words.push(dir.join("out").display().to_string());
    }
    if command == Some("bench") {
        // Small sizes: the default takes about a minute.
        words.extend(["-n", "65536", "--reps", "1"].map(String::from));
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
    let commands = commands(&bin);
    for c in [
        "demo", "eval", "render", "compare", "bench", "tabulate", "fit",
    ] {
        assert!(commands.iter().any(|x| x == c), "{c} not in {commands:?}");
    }
    for cmd in &commands {
        let mut args: Vec<&str> = if cmd.is_empty() { vec![] } else { vec![cmd] };
        args.push("--help");
        let o = Command::new(&bin).args(&args).output().unwrap();
        assert!(o.status.success(), "lobe {cmd} --help");
        let help = String::from_utf8(o.stdout).unwrap();
        let lines = examples(&help);
        assert!(!lines.is_empty(), "lobe {cmd} --help has no example");
        for line in lines {
            if let Some(why) = skipped(&line) {
                eprintln!("not run ({why}): {line}");
                continue;
            }
            let run = redirect(&line, &tmp, if cmd.is_empty() { "lobe" } else { cmd });
            let t0 = std::time::Instant::now();
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
            eprintln!("{:6.2} s: {line}", t0.elapsed().as_secs_f64());
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(!err.contains("error"), "{line}: {err}");
            // Issue 41: an example a user starts from does not warn.
            assert!(!err.contains("warning"), "{line}: {err}");
            ran += 1;
        }
    }
    assert!(ran >= 30, "only {ran} examples ran");
    let _ = std::fs::remove_dir_all(&tmp);
}

#[test]
fn examples_are_found_in_a_help_text() {
    let help = "Examples:\n  lobe a --x 1 \\\n      --y 2\n  echo '{}' | lobe eval -m x\n  LOBE_SIMD=avx2 lobe bench\n\nMore text\n  lobe not-an-example\nExamples (with a note):\n  lobe b";
    assert_eq!(
        examples(help),
        [
            "lobe a --x 1 --y 2",
            "echo '{}' | lobe eval -m x",
            "LOBE_SIMD=avx2 lobe bench",
            "lobe b"
        ]
    );
}
