//! Scenes: objects with materials under an environment map, seen by a
//! camera; built in code or read from a TOML file ([`load_scene`]).
//!
//! The file format ([`SceneDesc`]; unknown keys are errors):
//!
//! ```toml
//! [camera]
//! origin = [0, 1, 4]
//! target = [0, 1, 0]
//! up = [0, 1, 0]      # default
//! fov_y = 40          # degrees, vertical, in (0, 180); default 40
//! width = 320         # 1 to 16384; default 320
//! height = 240        # 1 to 16384; default 240
//!
//! [environment]
//! path = "forest.hdr" # .hdr or .exr, relative to the scene file; or "sky"
//! # or, instead of path, the built-in sky with its sun placed (degrees, as
//! # `--light sky:E:A`; each key defaults to the built-in sky's, 35 and 40):
//! # sky = { sun_elevation = 20, sun_azimuth = 120 }
//! scale = 1.0         # default 1
//! rotation_y = 0.0    # degrees about +Y; default 0
//!
//! [[object]]
//! type = "sphere"     # sphere (center, radius), plane (point, normal), mesh (path)
//! center = [0, 1, 0]
//! radius = 1
//! material = { type = "cook-torrance", distribution = "ggx", alpha = 0.3 }
//!
//! [render]            # every key optional
//! spp = 64
//! strategy = "mis"    # a BSDF strategy, light, mis or mis-power
//! seed = 1
//! sequence = "sobol"  # sobol, stratified or independent
//! max_depth = 1       # 1 = direct lighting
//! spp_allocation = "variance"  # variance (as a pilot estimates each pixel's noise) or uniform
//! ```

use crate::camera::{Camera, CameraError};
use crate::envmap_io::load_envmap_checked;
use crate::geometry::{Hit, Plane, Ray, Sphere};
use crate::mesh::Mesh;
use crate::settings::{RenderLoop, RenderSettings, SppAllocation};
use glam::DVec3;
use lobe::envmap::EnvMap;
use lobe::estimator::Strategy;
use lobe::{Material, MaterialDesc};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Largest accepted `max_depth`.
pub const MAX_DEPTH: u32 = 1024;

/// The geometry of an object.
#[derive(Debug, Clone)]
pub enum Shape {
    Sphere(Sphere),
    Plane(Plane),
    Mesh(Arc<Mesh>),
}

/// A shape with a material.
#[derive(Debug, Clone)]
pub struct Object {
    pub shape: Shape,
    pub material: Material,
}

/// A shape parameter that cannot be used: the field and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct ShapeError {
    pub field: &'static str,
    pub message: String,
}

fn finite_vec(field: &'static str, v: DVec3) -> Result<DVec3, ShapeError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ShapeError {
            field,
            message: format!("{v} is not a finite vector"),
        })
    }
}

impl Object {
    /// A sphere; `radius` must be a finite number > 0.
    pub fn sphere(center: DVec3, radius: f64, material: Material) -> Result<Object, ShapeError> {
        let center = finite_vec("center", center)?;
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(ShapeError {
                field: "radius",
                message: format!("{radius} is out of range: must be a finite number > 0"),
            });
        }
        Ok(Object {
            shape: Shape::Sphere(Sphere { center, radius }),
            material,
        })
    }

    /// An infinite plane through `point`; `normal` must be non-zero (it is
    /// normalized; either side of the plane can be seen).
    pub fn plane(point: DVec3, normal: DVec3, material: Material) -> Result<Object, ShapeError> {
        let point = finite_vec("point", point)?;
        let normal = finite_vec("normal", normal)?
            .try_normalize()
            .ok_or_else(|| ShapeError {
                field: "normal",
                message: "the zero vector has no direction".into(),
            })?;
        Ok(Object {
            shape: Shape::Plane(Plane { point, normal }),
            material,
        })
    }

    /// A triangle mesh.
    #[must_use]
    pub fn mesh(mesh: Arc<Mesh>, material: Material) -> Object {
        Object {
            shape: Shape::Mesh(mesh),
            material,
        }
    }

    #[inline]
    #[must_use]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<Hit> {
        match &self.shape {
            Shape::Sphere(s) => s.intersect(ray, t_max),
            Shape::Plane(p) => p.intersect(ray, t_max),
            Shape::Mesh(m) => m.intersect(ray, t_max),
        }
    }

    #[inline]
    #[must_use]
    pub fn occluded(&self, ray: &Ray, t_max: f64) -> bool {
        match &self.shape {
            Shape::Sphere(s) => s.blocks(ray, t_max),
            Shape::Plane(p) => p.intersect(ray, t_max).is_some(),
            Shape::Mesh(m) => m.occluded(ray, t_max),
        }
    }
}

/// Everything a render needs.
#[derive(Debug, Clone)]
pub struct Scene {
    pub camera: Camera,
    /// The only light; rays that escape see it.
    pub environment: Arc<EnvMap>,
    pub objects: Vec<Object>,
    /// The scene's own render settings (`[render]`); callers may override.
    pub settings: RenderSettings,
    /// Things worth telling the user (clamped texels, dropped triangles).
    pub warnings: Vec<String>,
}

impl Scene {
    /// A scene with no objects and default render settings.
    #[must_use]
    pub fn new(camera: Camera, environment: impl Into<Arc<EnvMap>>) -> Scene {
        Scene {
            camera,
            environment: environment.into(),
            objects: Vec::new(),
            settings: RenderSettings::default(),
            warnings: Vec::new(),
        }
    }

    /// Add an object (builder style).
    #[must_use]
    pub fn with(mut self, object: Object) -> Scene {
        self.objects.push(object);
        self
    }

    /// The nearest hit before `t_max` and the index of its object.
    #[inline]
    #[must_use]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<(Hit, usize)> {
        let mut best = None;
        let mut t = t_max;
        for (i, o) in self.objects.iter().enumerate() {
            if let Some(h) = o.intersect(ray, t) {
                t = h.t;
                best = Some((h, i));
            }
        }
        best
    }

    /// `true` when any object blocks the ray (the environment is at
    /// infinity).
    #[inline]
    #[must_use]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.objects.iter().any(|o| o.occluded(ray, f64::INFINITY))
    }
}

/// The built-in showcase: four spheres (Lambert, Phong, GGX with a diffuse
/// term, Beckmann gold) on a grey Lambertian ground under the built-in sky,
/// as in `scenes/spheres-ground.toml`, at `width × height` (each 1 to
/// 16384; the vertical field of view is 40°).
pub fn showcase(width: u32, height: u32) -> Result<Scene, CameraError> {
    let camera = Camera::new(
        DVec3::new(0.0, 1.2, 6.0),
        DVec3::new(0.0, 0.8, 0.0),
        DVec3::Y,
        40.0,
        width,
        height,
    )?;
    let (w, h, el, az) = crate::envmap_io::SKY;
    let m = |json: &str| {
        MaterialDesc::from_json(json)
            .and_then(|d| d.build())
            .expect("the showcase materials are valid")
    };
    let sphere = |x: f64, mat: Material| {
        Object::sphere(DVec3::new(x, 0.8, 0.0), 0.8, mat).expect("a valid sphere")
    };
    Ok(Scene::new(camera, EnvMap::sky(w, h, el, az))
        .with(sphere(-2.4, m(r#"{"type":"lambert","albedo":[0.8,0.3,0.2]}"#)))
        .with(sphere(
            -0.8,
            m(r#"{"type":"phong","exponent":200,"ks":0.6,"kd":0.3}"#),
        ))
        .with(sphere(
            0.8,
            m(r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.15,"kd":[0.1,0.2,0.5]}"#),
        ))
        .with(sphere(
            2.4,
            m(r#"{"type":"cook-torrance","distribution":"beckmann","alpha":0.3,"fresnel":{"type":"conductor"}}"#),
        ))
        .with(
            Object::plane(DVec3::ZERO, DVec3::Y, m(r#"{"type":"lambert","albedo":0.5}"#))
                .expect("a valid plane"),
        ))
}

/// One sphere of `material` (radius 1 at the origin) seen from +z at
/// distance 4 in a square `size × size` view (vertical field of view 32°:
/// the sphere fills most of it), under `env`: a material's preview, as
/// `lobe explore` shows it. Errors: `size` outside 1 to 16384.
pub fn material_preview(
    material: Material,
    env: impl Into<Arc<EnvMap>>,
    size: u32,
) -> Result<Scene, CameraError> {
    let camera = Camera::new(
        DVec3::new(0.0, 0.0, 4.0),
        DVec3::ZERO,
        DVec3::Y,
        32.0,
        size,
        size,
    )?;
    Ok(Scene::new(camera, env)
        .with(Object::sphere(DVec3::ZERO, 1.0, material).expect("a unit sphere is valid")))
}

// ---------------------------------------------------------------------------
// The file format.

/// A scene file as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    pub camera: CameraDesc,
    pub environment: EnvironmentDesc,
    #[serde(default, rename = "object", skip_serializing_if = "Vec::is_empty")]
    pub objects: Vec<ObjectDesc>,
    #[serde(default)]
    pub render: RenderDesc,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    pub origin: [f64; 3],
    pub target: [f64; 3],
    #[serde(default = "default_up")]
    pub up: [f64; 3],
    #[serde(default = "default_fov")]
    pub fov_y: f64,
    #[serde(default = "default_width")]
    pub width: u32,
    #[serde(default = "default_height")]
    pub height: u32,
}

fn default_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}
fn default_fov() -> f64 {
    40.0
}
fn default_width() -> u32 {
    320
}
fn default_height() -> u32 {
    240
}
fn one() -> f64 {
    1.0
}

/// `[environment]`: a map (`path`) or the built-in sky with its sun
/// placed (`sky`); exactly one of the two.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentDesc {
    /// `.hdr` or `.exr`, relative to the scene file, or `sky`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<String>,
    /// The built-in sky with its sun where these keys say.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sky: Option<SkyDesc>,
    #[serde(default = "one")]
    pub scale: f64,
    #[serde(default)]
    pub rotation_y: f64,
}

/// `[environment] sky = { sun_elevation = E, sun_azimuth = A }`: the
/// built-in sky with its sun at elevation E in [0, 90] degrees above the
/// horizon and azimuth A degrees (0 is −Z), as `--light sky:E:A`; a key
/// left out takes the built-in sky's value ([`crate::envmap_io::SKY`]: 35
/// and 40, as `--light sky` and `path = "sky"`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SkyDesc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sun_elevation: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sun_azimuth: Option<f64>,
}

/// One `[[object]]`: `type` says which of the shape keys apply.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDesc {
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<String>,
    pub material: MaterialDesc,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderDesc {
    #[serde(default = "default_spp")]
    pub spp: u64,
    #[serde(default = "default_strategy")]
    pub strategy: String,
    #[serde(default = "default_seed")]
    pub seed: u64,
    #[serde(default = "default_sequence")]
    pub sequence: String,
    #[serde(default = "default_depth")]
    pub max_depth: u32,
    /// `variance` (the default) or `uniform` ([`crate::settings::SppAllocation`]).
    #[serde(default = "default_spp_allocation")]
    pub spp_allocation: String,
}

fn default_spp() -> u64 {
    64
}
fn default_strategy() -> String {
    "mis".into()
}
fn default_seed() -> u64 {
    1
}
fn default_sequence() -> String {
    "sobol".into()
}
fn default_depth() -> u32 {
    1
}
fn default_spp_allocation() -> String {
    "variance".into()
}

impl Default for RenderDesc {
    fn default() -> Self {
        RenderDesc {
            spp: default_spp(),
            strategy: default_strategy(),
            seed: default_seed(),
            sequence: default_sequence(),
            max_depth: default_depth(),
            spp_allocation: default_spp_allocation(),
        }
    }
}

/// One step of a field path: a key or an array index.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Segment {
    Key(String),
    Index(usize),
}

/// A field path such as `object[0].material.alpha`.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct FieldPath(pub Vec<Segment>);

impl FieldPath {
    fn of(parts: &[&str]) -> Self {
        FieldPath(parts.iter().map(|p| Segment::Key((*p).into())).collect())
    }

    fn key(mut self, k: &str) -> Self {
        for part in k.split('.') {
            self.0.push(Segment::Key(part.into()));
        }
        self
    }

    fn object(i: usize) -> Self {
        FieldPath(vec![Segment::Key("object".into()), Segment::Index(i)])
    }
}

impl fmt::Display for FieldPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (k, s) in self.0.iter().enumerate() {
            match s {
                Segment::Key(key) if k == 0 => f.write_str(key)?,
                Segment::Key(key) => write!(f, ".{key}")?,
                Segment::Index(i) => write!(f, "[{i}]")?,
            }
        }
        Ok(())
    }
}

/// What went wrong loading a scene. Every message names the file, and
/// where it can, the line, column and field.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The OS error is part of the message, not a `source()` (printing
    /// the chain would repeat it).
    #[error("{}: cannot read the scene file: {error}", path.display())]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{}", at_message(file, *at, field.as_ref(), message))]
    At {
        /// The scene file as given.
        file: String,
        /// 1-based line and column, when known.
        at: Option<(usize, usize)>,
        /// The field at fault, when there is one.
        field: Option<FieldPath>,
        message: String,
    },
}

fn at_message(
    file: &str,
    at: Option<(usize, usize)>,
    field: Option<&FieldPath>,
    message: &str,
) -> String {
    let mut s = file.to_string();
    if let Some((l, c)) = at {
        s += &format!(":{l}:{c}");
    }
    s += ": ";
    if let Some(f) = field {
        s += &format!("field {f}: ");
    }
    s + message
}

impl SceneError {
    /// The field at fault, if the error has one.
    #[must_use]
    pub fn field(&self) -> Option<String> {
        match self {
            SceneError::At { field, .. } => field.as_ref().map(ToString::to_string),
            SceneError::Io { .. } => None,
        }
    }
}

/// Read a scene file. Relative paths in it (environment map, meshes) are
/// taken relative to the file's directory.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|error| SceneError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    parse_scene(&text, path)
}

/// Parse scene text as if read from `path` (used for error messages and as
/// the base of relative paths).
pub fn parse_scene(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let file = path.display().to_string();
    let base = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let desc = parse_desc(text, &file)?;
    build(&desc, &base).map_err(|(field, message)| {
        let at = locate(text, &field);
        SceneError::At {
            file,
            at,
            field: Some(field),
            message,
        }
    })
}

/// Parse scene text into its description (no file is read, nothing is
/// checked beyond the types).
pub fn parse_desc(text: &str, file: &str) -> Result<SceneDesc, SceneError> {
    let at = |e: &toml::de::Error| e.span().map(|s| line_col(text, s.start));
    let root = toml::de::DeTable::parse(text).map_err(|e| SceneError::At {
        file: file.to_string(),
        at: at(&e),
        field: None,
        message: format!("invalid TOML: {}", one_line(e.message())),
    })?;
    let de = toml::Deserializer::from(root);
    serde_path_to_error::deserialize(de).map_err(|e| {
        let field = field_path(e.path());
        let inner = e.into_inner();
        let at = at(&inner).or_else(|| field.as_ref().and_then(|f| locate(text, f)));
        SceneError::At {
            file: file.to_string(),
            at,
            field,
            message: one_line(inner.message()),
        }
    })
}

fn one_line(s: &str) -> String {
    s.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

fn field_path(p: &serde_path_to_error::Path) -> Option<FieldPath> {
    use serde_path_to_error::Segment as S;
    let segs: Vec<Segment> = p
        .iter()
        .filter_map(|s| match s {
            S::Seq { index } => Some(Segment::Index(*index)),
            S::Map { key } => Some(Segment::Key(key.clone())),
            S::Enum { variant } => Some(Segment::Key(variant.clone())),
            S::Unknown => None,
        })
        .collect();
    (!segs.is_empty()).then_some(FieldPath(segs))
}

/// 1-based line and column (in characters) of byte `offset`.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[start..].chars().count() + 1)
}

/// Where `field` is written in `text`: the value of the deepest part of the
/// path that the file has.
fn locate(text: &str, field: &FieldPath) -> Option<(usize, usize)> {
    use toml::de::DeValue;
    let root = toml::de::DeTable::parse(text).ok()?;
    let mut span = None;
    let mut cur: Option<&toml::Spanned<DeValue>> = None;
    for seg in &field.0 {
        let next = match (cur, seg) {
            (None, Segment::Key(k)) => root.get_ref().get(k.as_str()),
            (None, Segment::Index(_)) => None,
            (Some(v), Segment::Key(k)) => v.get_ref().get(k.as_str()),
            (Some(v), Segment::Index(i)) => v.get_ref().get(*i),
        };
        match next {
            Some(v) => {
                span = Some(v.span());
                cur = Some(v);
            }
            None => break,
        }
    }
    span.map(|s| line_col(text, s.start))
}

type FieldResult<T> = Result<T, (FieldPath, String)>;

fn vec3(v: [f64; 3]) -> DVec3 {
    DVec3::from_array(v)
}

/// Check a description and load what it names.
fn build(desc: &SceneDesc, base: &Path) -> FieldResult<Scene> {
    let c = &desc.camera;
    let camera = Camera::new(
        vec3(c.origin),
        vec3(c.target),
        vec3(c.up),
        c.fov_y,
        c.width,
        c.height,
    )
    .map_err(|e| (FieldPath::of(&["camera", e.field]), e.message))?;

    let e = &desc.environment;
    let env_field = |k: &str| FieldPath::of(&["environment", k]);
    if !(e.scale.is_finite() && e.scale >= 0.0) {
        return Err((
            env_field("scale"),
            format!("{} is out of range: must be a finite number >= 0", e.scale),
        ));
    }
    if !e.rotation_y.is_finite() {
        return Err((
            env_field("rotation_y"),
            format!("{} is not a finite number", e.rotation_y),
        ));
    }
    let mut warnings = Vec::new();
    let map = match (&e.path, &e.sky) {
        (Some(_), Some(_)) => {
            return Err((
                env_field("sky"),
                "`path` and `sky` are exclusive: `path` names a map (or \"sky\", the built-in sky as it is), `sky` places the built-in sky's sun; give one of them".into(),
            ));
        }
        (None, None) => {
            return Err((
                FieldPath::of(&["environment"]),
                "missing `path` (an .hdr or .exr map, or \"sky\") or `sky` (the built-in sky with its sun: sky = { sun_elevation = 35, sun_azimuth = 40 })".into(),
            ));
        }
        (None, Some(sky)) => {
            let (_, _, elevation, azimuth) = crate::envmap_io::SKY;
            let elevation = sky.sun_elevation.unwrap_or(elevation);
            let azimuth = sky.sun_azimuth.unwrap_or(azimuth);
            let sky_field = |k: &str| FieldPath::of(&["environment", "sky", k]);
            if !crate::envmap_io::sun_elevation_ok(elevation) {
                return Err((
                    sky_field("sun_elevation"),
                    format!(
                        "{elevation} is out of range: the sun's elevation is in [0, 90] degrees above the horizon"
                    ),
                ));
            }
            if !crate::envmap_io::sun_azimuth_ok(azimuth) {
                return Err((
                    sky_field("sun_azimuth"),
                    format!("{azimuth} is not a finite number of degrees"),
                ));
            }
            let (map, clamped) = crate::envmap_io::sky(elevation, azimuth, e.scale, e.rotation_y)
                .map_err(|err| (env_field("sky"), err.to_string()))?;
            if clamped > 0 {
                warnings.push(format!(
                    "environment.sky: {clamped} texels with negative, infinite or NaN channels were clamped to 0"
                ));
            }
            map
        }
        (Some(path), None) => {
            if let Some(sun) = path.strip_prefix("sky:") {
                let mut parts = sun.splitn(2, ':');
                let (el, az) = (parts.next().unwrap_or("E"), parts.next().unwrap_or("A"));
                return Err((
                    env_field("path"),
                    format!(
                        "`{path}`: a scene places the sky's sun with keys of their own: sky = {{ sun_elevation = {el}, sun_azimuth = {az} }} instead of path"
                    ),
                ));
            }
            let env_path = if path == "sky" {
                PathBuf::from("sky")
            } else {
                base.join(path)
            };
            let loaded = load_envmap_checked(&env_path, e.scale, e.rotation_y)
                .map_err(|err| (env_field("path"), err.to_string()))?;
            warnings.extend(loaded.warnings);
            loaded.map
        }
    };

    let r = &desc.render;
    let render_field = |k: &str| FieldPath::of(&["render", k]);
    if r.spp == 0 {
        return Err((render_field("spp"), "0: at least 1 sample per pixel".into()));
    }
    if r.max_depth == 0 || r.max_depth > MAX_DEPTH {
        return Err((
            render_field("max_depth"),
            format!(
                "{} is out of range: must be 1 (direct lighting) to {MAX_DEPTH}",
                r.max_depth
            ),
        ));
    }
    let strategy: Strategy = r
        .strategy
        .parse()
        .map_err(|e: lobe::Error| (render_field("strategy"), e.to_string()))?;

    let sequence: lobe::sequence::Sequence = r
        .sequence
        .parse()
        .map_err(|e: lobe::Error| (render_field("sequence"), e.to_string()))?;

    let spp_allocation: SppAllocation = r
        .spp_allocation
        .parse()
        .map_err(|e: String| (render_field("spp_allocation"), e))?;

    let mut scene = Scene::new(camera, map);
    scene.settings = RenderSettings {
        spp: r.spp,
        strategy,
        seed: r.seed,
        sequence,
        max_depth: r.max_depth,
        threads: None,
        render_loop: RenderLoop::Batch,
        spp_allocation,
    };
    let mut meshes: HashMap<PathBuf, Arc<Mesh>> = HashMap::new();
    for (i, o) in desc.objects.iter().enumerate() {
        let object = build_object(i, o, base, &mut meshes, &mut warnings)?;
        scene.objects.push(object);
    }
    scene.warnings = warnings;
    Ok(scene)
}

fn build_object(
    i: usize,
    o: &ObjectDesc,
    base: &Path,
    meshes: &mut HashMap<PathBuf, Arc<Mesh>>,
    warnings: &mut Vec<String>,
) -> FieldResult<Object> {
    let at = |k: &str| FieldPath::object(i).key(k);
    let keys: &[&str] = match o.kind.as_str() {
        "sphere" => &["center", "radius"],
        "plane" => &["point", "normal"],
        "mesh" => &["path"],
        other => {
            return Err((
                at("type"),
                format!("unknown object type `{other}`, expected one of: sphere, plane, mesh"),
            ));
        }
    };
    let present = [
        ("center", o.center.is_some()),
        ("radius", o.radius.is_some()),
        ("point", o.point.is_some()),
        ("normal", o.normal.is_some()),
        ("path", o.path.is_some()),
    ];
    for (name, given) in present {
        if given && !keys.contains(&name) {
            return Err((
                at(name),
                format!(
                    "does not apply to type {} (its keys: {}, material)",
                    o.kind,
                    keys.join(", ")
                ),
            ));
        }
        if !given && keys.contains(&name) {
            return Err((at(name), format!("missing: type {} needs it", o.kind)));
        }
    }
    let material = o
        .material
        .clone()
        .relative_to(base)
        .build()
        .map_err(|e| material_error(i, &o.material, e))?;
    let shape_err = |e: ShapeError| (at(e.field), e.message);
    match o.kind.as_str() {
        "sphere" => Object::sphere(
            vec3(o.center.unwrap_or_default()),
            o.radius.unwrap_or_default(),
            material,
        )
        .map_err(shape_err),
        "plane" => Object::plane(
            vec3(o.point.unwrap_or_default()),
            vec3(o.normal.unwrap_or_default()),
            material,
        )
        .map_err(shape_err),
        _ => {
            let p = base.join(o.path.as_deref().unwrap_or_default());
            let mesh = match meshes.get(&p) {
                Some(m) => m.clone(),
                None => {
                    let m = Arc::new(Mesh::load_obj(&p).map_err(|e| (at("path"), e.to_string()))?);
                    if m.degenerate > 0 {
                        warnings.push(format!(
                            "{}: {} triangles without area were dropped",
                            p.display(),
                            m.degenerate
                        ));
                    }
                    meshes.insert(p, m.clone());
                    m
                }
            };
            Ok(Object::mesh(mesh, material))
        }
    }
}

fn material_error(i: usize, desc: &MaterialDesc, e: lobe::Error) -> (FieldPath, String) {
    let base = FieldPath::object(i).key("material");
    match e {
        lobe::Error::Param { field, message } => {
            // lobe checks `alpha` and `roughness` as the alpha_u/alpha_v they
            // become: name the key the user wrote.
            let field = match field.as_str() {
                "alpha_u" | "alpha_v" if desc.alpha_u.is_none() && desc.alpha_v.is_none() => {
                    if desc.alpha.is_some() {
                        "alpha".to_string()
                    } else if desc.roughness.is_some() {
                        "roughness".to_string()
                    } else {
                        field
                    }
                }
                _ => field,
            };
            (base.key(&field), message)
        }
        lobe::Error::UnknownName {
            field,
            value,
            expected,
        } => (
            base.key(&field),
            format!("unknown value `{value}`, expected one of: {expected}"),
        ),
        other => (base, other.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
[camera]
origin = [0, 1, 4]
target = [0, 1, 0]
fov_y = 40
width = 32
height = 24

[environment]
path = "sky"

[[object]]
type = "sphere"
center = [0, 1, 0]
radius = 1
material = { type = "cook-torrance", distribution = "ggx", alpha = 0.3 }

[[object]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = { type = "lambert" }

[render]
spp = 4
strategy = "vndf"
"#;

    fn err(text: &str) -> String {
        match parse_scene(text, Path::new("scene.toml")) {
            Ok(_) => panic!("accepted:\n{text}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn a_good_scene_loads() {
        let s = parse_scene(GOOD, Path::new("scene.toml")).unwrap();
        assert_eq!(s.objects.len(), 2);
        assert_eq!(s.settings.spp, 4);
        assert_eq!(
            s.settings.strategy,
            Strategy::Bsdf(lobe::BsdfStrategy::Vndf)
        );
        assert_eq!(s.camera.width, 32);
    }

    #[test]
    fn errors_name_file_line_and_field() {
        let e = err(&GOOD.replace("radius = 1", "radius = \"a\""));
        assert_eq!(
            e,
            "scene.toml:15:10: field object[0].radius: invalid type: string \"a\", expected f64"
        );
        let e = err(&GOOD.replace("radius = 1", "radius = -1"));
        assert!(
            e.starts_with("scene.toml:15:10: field object[0].radius: -1 is out of range"),
            "{e}"
        );
        let e = err(&GOOD.replace("alpha = 0.3", "alpha = -0.3"));
        assert!(e.starts_with("scene.toml:16:"), "{e}");
        assert!(e.contains("field object[0].material.alpha: "), "{e}");
        let e = err(&GOOD.replace("fov_y = 40", "fov_y = 180"));
        assert!(
            e.starts_with("scene.toml:5:9: field camera.fov_y: 180"),
            "{e}"
        );
        let e = err(&GOOD.replace("width = 32", "width = 0"));
        assert!(
            e.starts_with("scene.toml:6:9: field camera.width: 0"),
            "{e}"
        );
        let e = err(&GOOD.replace("height = 24", "height = 20000"));
        assert!(
            e.contains("field camera.height: 20000 is out of range"),
            "{e}"
        );
        let e = err(&GOOD.replace("spp = 4", "spp = 0"));
        assert!(e.contains("field render.spp:"), "{e}");
        let e = err(&GOOD.replace("normal = [0, 1, 0]", "normal = [0, 0, 0]"));
        assert!(e.contains("field object[1].normal: the zero vector"), "{e}");
        let e = err(&GOOD.replace("radius = 1", "radius = nan"));
        assert!(
            e.contains("field object[0].radius: NaN is out of range"),
            "{e}"
        );
        let e = err(&GOOD.replace("strategy = \"vndf\"", "strategy = \"vndff\""));
        assert!(
            e.contains("field render.strategy: unknown strategy `vndff`"),
            "{e}"
        );
        let e = err(&GOOD.replace("radius = 1", "radius = 1\nradiu = 2"));
        assert!(e.starts_with("scene.toml:16:"), "{e}");
        assert!(e.contains("unknown field `radiu`"), "{e}");
        let e = err(&GOOD.replace("type = \"plane\"", "type = \"cube\""));
        assert!(
            e.contains("field object[1].type: unknown object type `cube`"),
            "{e}"
        );
        let e = err(&GOOD.replace("radius = 1", ""));
        assert!(e.contains("field object[0].radius: missing"), "{e}");
        let e = err(&GOOD.replace("[render]", "[render"));
        assert!(e.starts_with("scene.toml:24:"), "{e}");
        assert!(e.contains("invalid TOML"), "{e}");
        let e = err(&GOOD.replace("path = \"sky\"", "path = \"nowhere/forest.hdr\""));
        assert!(
            e.contains("field environment.path: nowhere/forest.hdr"),
            "{e}"
        );
        let e = err(&GOOD.replace(
            "type = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]",
            "type = \"mesh\"\npath = \"no/bunny.obj\"",
        ));
        assert!(e.contains("field object[1].path: no/bunny.obj"), "{e}");
        let e = err(&GOOD.replace("[camera]\norigin = [0, 1, 4]\n", "[camera]\n"));
        assert!(e.contains("missing field `origin`"), "{e}");
    }

    /// The environment of `GOOD` with `environment` in place of its
    /// `path = "sky"` line.
    fn with_environment(environment: &str) -> String {
        GOOD.replace("path = \"sky\"\n", &format!("{environment}\n"))
    }

    fn environment(environment: &str) -> Arc<EnvMap> {
        let text = with_environment(environment);
        match parse_scene(&text, Path::new("scene.toml")) {
            Ok(s) => s.environment,
            Err(e) => panic!("{environment}: {e}"),
        }
    }

    fn same_map(a: &EnvMap, b: &EnvMap) -> bool {
        let (w, h) = a.size();
        a.size() == b.size()
            && (0..h).all(|j| (0..w).all(|i| a.texel(i, j) == b.texel(i, j)))
            && [DVec3::Y, DVec3::X, DVec3::new(0.3, 0.4, -0.8).normalize()]
                .iter()
                .all(|&d| a.eval(d) == b.eval(d) && a.pdf(d) == b.pdf(d))
    }

    /// Issue 41: `sky = { sun_elevation, sun_azimuth }` is the light of
    /// `--light sky:E:A`; `sky = {}` (or a key left out) takes the
    /// built-in sky's values, as `path = "sky"` and `--light sky` do.
    #[test]
    fn the_sky_keys_place_the_sun_as_the_light_option_does() {
        use crate::light_spec::parse_light;
        let frame = lobe::Frame::from_normal(DVec3::Z);
        let light = |spec: &str| match parse_light("--light", spec, &frame).unwrap().light {
            lobe::Light::Env(m) => m,
            other => panic!("{other:?}"),
        };
        let keyed = environment("sky = { sun_elevation = 20, sun_azimuth = 120 }");
        assert!(same_map(&keyed, &light("sky:20:120")));
        assert!(!same_map(&keyed, &light("sky:20:121")));
        assert!(!same_map(&keyed, &light("sky:21:120")));
        let inline = environment("[environment.sky]\nsun_elevation = 90\nsun_azimuth = -30.5");
        assert!(same_map(&inline, &light("sky:90:-30.5")));
        // Defaults: the built-in sky's (35, 40), key by key.
        let plain = environment("path = \"sky\"");
        assert!(same_map(&environment("sky = {}"), &plain));
        assert!(same_map(&plain, &light("sky:35:40")));
        assert!(same_map(
            &environment("sky = { sun_elevation = 20 }"),
            &light("sky:20:40")
        ));
        assert!(same_map(
            &environment("sky = { sun_azimuth = 120 }"),
            &light("sky:35:120")
        ));
        // scale and rotation_y apply as to path = "sky".
        let turned = "scale = 2\nrotation_y = 30";
        assert!(same_map(
            &environment(&format!("sky = {{}}\n{turned}")),
            &environment(&format!("path = \"sky\"\n{turned}"))
        ));
        // And a render under it is the same image.
        let render = |env: &str| {
            let s = parse_scene(&with_environment(env), Path::new("scene.toml")).unwrap();
            crate::render(&s, &s.settings, |_| {}).pixels
        };
        assert_eq!(render("sky = {}"), render("path = \"sky\""));
    }

    /// Issue 41: the sun's keys take exactly what `--light sky:E:A` takes,
    /// and a value refused names the key, the file and the line.
    #[test]
    fn the_sky_keys_take_what_the_light_option_takes() {
        use crate::light_spec::parse_light;
        let frame = lobe::Frame::from_normal(DVec3::Z);
        let elevations = ["-1", "-0.0", "0", "20", "90", "90.5", "1e3", "nan", "inf"];
        let azimuths = ["-400", "0", "120", "720", "inf", "-inf", "nan"];
        for el in elevations {
            for az in azimuths {
                let text = with_environment(&format!(
                    "sky = {{ sun_elevation = {el}, sun_azimuth = {az} }}"
                ));
                let scene = parse_scene(&text, Path::new("scene.toml"));
                let option = parse_light("--light", &format!("sky:{el}:{az}"), &frame);
                assert_eq!(scene.is_ok(), option.is_ok(), "{el}, {az}");
            }
        }
        let e = err(&with_environment("sky = { sun_elevation = 95 }"));
        assert_eq!(
            e,
            "scene.toml:10:25: field environment.sky.sun_elevation: 95 is out of range: the sun's elevation is in [0, 90] degrees above the horizon"
        );
        let e = err(&with_environment("sky = { sun_elevation = -5 }"));
        assert!(
            e.contains("field environment.sky.sun_elevation: -5 is out of range"),
            "{e}"
        );
        let e = err(&with_environment("sky = { sun_azimuth = nan }"));
        assert!(
            e.starts_with("scene.toml:10:")
                && e.contains("field environment.sky.sun_azimuth: NaN is not a finite number"),
            "{e}"
        );
        let e = err(&with_environment("sky = { sun_elevation = \"high\" }"));
        assert!(
            e.contains("field environment.sky.sun_elevation: invalid type"),
            "{e}"
        );
        let e = err(&with_environment("sky = { sun_height = 20 }"));
        assert!(e.contains("unknown field `sun_height`"), "{e}");
        let e = err(&with_environment(
            "path = \"sky\"\nsky = { sun_elevation = 20 }",
        ));
        assert!(
            e.starts_with("scene.toml:11:")
                && e.contains("field environment.sky: `path` and `sky` are exclusive"),
            "{e}"
        );
        let e = err(&with_environment("scale = 1"));
        assert!(
            e.starts_with("scene.toml:") && e.contains("field environment: missing `path`"),
            "{e}"
        );
        let e = err(&with_environment("path = \"sky:20:120\""));
        assert!(
            e.contains(
                "field environment.path: `sky:20:120`: a scene places the sky's sun with keys of their own: sky = { sun_elevation = 20, sun_azimuth = 120 } instead of path"
            ),
            "{e}"
        );
    }
}
