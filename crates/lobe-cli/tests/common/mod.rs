//! Helpers shared by the command-line tests.
#![allow(dead_code)]

use std::process::Output;

/// The stderr of a failed run: exit code 1 and exactly one line
/// `lobe: error: …`.
pub fn one_line_error(o: &Output) -> String {
    assert_eq!(o.status.code(), Some(1), "{o:?}");
    let e = String::from_utf8(o.stderr.clone()).unwrap();
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.starts_with("lobe: error: "), "{e}");
    e
}
