//! What both benchmarks use: the materials and how they are built. (Not a
//! benchmark target of its own: the package lists its targets, autobenches
//! off.)

use lobe::{Material, MaterialDesc};

/// The benchmarked materials: a short name for the group, and the JSON.
pub const MATERIALS: &[(&str, &str)] = &[
    ("lambert", r#"{"type":"lambert"}"#),
    (
        "phong-n100",
        r#"{"type":"phong","exponent":100,"normalized":true}"#,
    ),
    (
        "blinn-phong-n100",
        r#"{"type":"blinn-phong","exponent":100}"#,
    ),
    (
        "ggx-alpha0.2",
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2}"#,
    ),
    (
        "ggx-aniso-0.1x0.4",
        r#"{"type":"cook-torrance","distribution":"ggx","alpha_u":0.1,"alpha_v":0.4}"#,
    ),
    (
        "beckmann-alpha0.2",
        r#"{"type":"cook-torrance","distribution":"beckmann","alpha":0.2}"#,
    ),
    (
        "bp-ndf-alpha0.2",
        r#"{"type":"cook-torrance","distribution":"blinn-phong","alpha":0.2}"#,
    ),
    (
        "kd0.3-ggx-alpha0.2",
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2,"kd":0.3}"#,
    ),
    // Energy compensation: the f64 path's cost beside ggx-alpha0.2's.
    (
        "ggx-alpha0.2-kulla-conty",
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2,"multiscatter":"kulla-conty"}"#,
    ),
    (
        "ggx-alpha0.2-turquin",
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2,"multiscatter":"turquin"}"#,
    ),
];

/// The material a JSON description builds (a panic naming it otherwise).
pub fn material(json: &str) -> Material {
    MaterialDesc::from_json(json)
        .and_then(|d| d.build())
        .unwrap_or_else(|e| panic!("{json}: {e}"))
}
