//! The light syntax of `lobe estimate --light` and of the Python package's
//! `lobe.estimate(light=...)`, parsed in one place:
//!
//! * `constant[:VALUE]`: the white furnace, radiance VALUE (default 1);
//! * `beam[:K[:X,Y,Z[:VALUE]]]`: radiance VALUE·max(0, ω·d)^K toward the
//!   world direction d (default K = 8, d = (0, 1, 0.5), VALUE = 1), taken to
//!   the local frame by the shading frame;
//! * `sky[:ELEVATION[:AZIMUTH]]`: the built-in sky with its sun (degrees);
//! * an environment map file (`.hdr`, `.pic`, `.exr`, any case), or `sky`.

use glam::DVec3;
use lobe::{Frame, Light, Rgb};
use std::path::Path;
use std::sync::Arc;

/// A parsed light and what loading it warned about (a map's clamped or
/// negative texels, for example).
#[derive(Debug, Clone)]
pub struct ParsedLight {
    pub light: Light,
    pub warnings: Vec<String>,
}

/// Whether `spec` names an environment map file: `.hdr`, `.pic` or `.exr`,
/// in any case.
#[must_use]
pub fn is_envmap_path(spec: &str) -> bool {
    Path::new(spec)
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| ["hdr", "pic", "exr"].contains(&e.to_ascii_lowercase().as_str()))
}

/// Three finite numbers `x,y,z`, not all zero (a direction); errors start
/// with `what` and the text.
pub fn parse_vec3(what: &str, s: &str) -> Result<DVec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!("{what} {s}: expected three numbers x,y,z"));
    }
    let mut v = [0.0; 3];
    for (slot, p) in v.iter_mut().zip(&parts) {
        *slot = p
            .parse::<f64>()
            .map_err(|_| format!("{what} {s}: `{p}` is not a number"))?;
        if !slot.is_finite() {
            return Err(format!("{what} {s}: `{p}` is not a finite number"));
        }
    }
    let v = DVec3::from_array(v);
    if v.length_squared() == 0.0 {
        return Err(format!("{what} {s}: the zero vector has no direction"));
    }
    Ok(v)
}

/// Parse a light description (module doc); an analytic light's world
/// direction is taken to the local `frame`. `flag` names the option in
/// errors (`--light`, `light`).
pub fn parse_light(flag: &str, spec: &str, frame: &Frame) -> Result<ParsedLight, String> {
    let plain = |light| {
        Ok(ParsedLight {
            light,
            warnings: Vec::new(),
        })
    };
    let mut parts = spec.split(':');
    let kind = parts.next().unwrap_or_default();
    let number = |what: &str, s: &str| -> Result<f64, String> {
        let v: f64 = s
            .parse()
            .map_err(|_| format!("{flag} {spec}: {what} `{s}` is not a number"))?;
        if !v.is_finite() || v < 0.0 {
            return Err(format!(
                "{flag} {spec}: {what} must be a finite number >= 0"
            ));
        }
        Ok(v)
    };
    match kind {
        "constant" => {
            let v = parts.next().map_or(Ok(1.0), |s| number("value", s))?;
            if parts.next().is_some() {
                return Err(format!("{flag} {spec}: expected constant[:VALUE]"));
            }
            plain(Light::Constant(Rgb::splat(v)))
        }
        "beam" => {
            let k = parts.next().map_or(Ok(8.0), |s| number("exponent K", s))?;
            let d = parts.next().map_or(Ok(DVec3::new(0.0, 1.0, 0.5)), |s| {
                parse_vec3(&format!("{flag} {spec}: direction"), s)
            })?;
            let v = parts.next().map_or(Ok(1.0), |s| number("value", s))?;
            if parts.next().is_some() {
                return Err(format!("{flag} {spec}: expected beam[:K[:X,Y,Z[:VALUE]]]"));
            }
            plain(Light::Beam {
                dir: frame.to_local(d.normalize()),
                exponent: k,
                radiance: Rgb::splat(v),
            })
        }
        "sky" if spec != "sky" => {
            // `sky:ELEVATION[:AZIMUTH]`: the built-in sky with its sun elsewhere.
            let (w, h, default_elevation, default_azimuth) = crate::envmap_io::SKY;
            let elevation = parts
                .next()
                .map_or(Ok(default_elevation), |s| number("sun elevation", s))?;
            let azimuth = match parts.next() {
                None => default_azimuth,
                Some(s) => s
                    .parse::<f64>()
                    .ok()
                    .filter(|&a| crate::envmap_io::sun_azimuth_ok(a))
                    .ok_or_else(|| {
                        format!(
                            "{flag} {spec}: sun azimuth `{s}` is not a finite number of degrees"
                        )
                    })?,
            };
            if parts.next().is_some() || !crate::envmap_io::sun_elevation_ok(elevation) {
                return Err(format!(
                    "{flag} {spec}: expected sky[:ELEVATION[:AZIMUTH]], the sun's elevation in [0, 90] degrees above the horizon and its azimuth in degrees (0 is -Z)"
                ));
            }
            plain(Light::Env(Arc::new(lobe::envmap::EnvMap::sky(
                w, h, elevation, azimuth,
            ))))
        }
        _ if spec == "sky" || is_envmap_path(spec) => {
            let loaded = crate::load_envmap_checked(Path::new(spec), 1.0, 0.0)
                .map_err(|e| format!("{flag} {spec}: {e}"))?;
            Ok(ParsedLight {
                light: Light::Env(Arc::new(loaded.map)),
                warnings: loaded.warnings,
            })
        }
        "lobe" => Err(format!(
            "{flag} {spec}: the analytic light `lobe` is now called `beam` (beam[:K[:X,Y,Z[:VALUE]]])"
        )),
        _ => Err(format!(
            "{flag} {spec}: unknown light `{kind}`, expected constant[:VALUE], beam[:K[:X,Y,Z[:VALUE]]], sky[:ELEVATION[:AZIMUTH]], or an environment map FILE.hdr / FILE.exr (any case)"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lights_and_their_errors() {
        let f = Frame::from_normal(DVec3::Z);
        let l = parse_light("--light", "beam:4:0,0,2:3", &f).unwrap().light;
        match l {
            Light::Beam {
                dir,
                exponent,
                radiance,
            } => {
                assert!((dir - DVec3::Z).length() < 1e-12);
                assert_eq!((exponent, radiance), (4.0, Rgb::splat(3.0)));
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            parse_light("light", "constant", &f).unwrap().light,
            Light::Constant(c) if c == Rgb::ONE
        ));
        assert!(matches!(
            parse_light("light", "sky:30", &f).unwrap().light,
            Light::Env(_)
        ));
        for (spec, msg) in [
            (
                "constant:-1",
                "--light constant:-1: value must be a finite number >= 0",
            ),
            (
                "constant:1:2",
                "--light constant:1:2: expected constant[:VALUE]",
            ),
            (
                "beam:8:0,0",
                "--light beam:8:0,0: direction 0,0: expected three numbers x,y,z",
            ),
            (
                "beam:8:0,0,0",
                "--light beam:8:0,0,0: direction 0,0,0: the zero vector has no direction",
            ),
            (
                "sky:95",
                "--light sky:95: expected sky[:ELEVATION[:AZIMUTH]]",
            ),
            (
                "sky:30:x",
                "--light sky:30:x: sun azimuth `x` is not a finite number of degrees",
            ),
            ("lobe:3", "is now called `beam`"),
            ("lamp", "--light lamp: unknown light `lamp`"),
            ("nowhere.exr", "--light nowhere.exr: "),
        ] {
            let e = parse_light("--light", spec, &f).unwrap_err();
            assert!(e.contains(msg), "{spec}: {e}");
        }
        assert!(is_envmap_path("a/b.HDR") && is_envmap_path("x.exr") && !is_envmap_path("x.png"));
    }
}
