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

/// The scene of the render tests: a sphere of radius 1 on a plane under the
/// built-in sky, seen from 4 units away, at `width × height`, with one
/// bounce of `mis` and `spp` samples per pixel; `sphere` and `plane` are
/// inline TOML materials.
pub fn sphere_scene(width: u32, height: u32, sphere: &str, plane: &str, spp: u32) -> String {
    format!(
        r#"[camera]
origin = [0, 1, 4]
target = [0, 1, 0]
up = [0, 1, 0]
fov_y = 40
width = {width}
height = {height}

[environment]
path = "sky"
scale = 1.0
rotation_y = 0.0

[[object]]
type = "sphere"
center = [0, 1, 0]
radius = 1
material = {sphere}

[[object]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = {plane}

[render]
spp = {spp}
strategy = "mis"
seed = 1
max_depth = 1
"#
    )
}
