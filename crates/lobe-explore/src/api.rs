//! The JSON API the page calls (docs/explore.md): one handler a view, each
//! a library call on the material the request describes. A request is
//! parsed here (a clear error naming the field otherwise) and bounded
//! ([`limits`]); the work runs on the blocking pool behind
//! [`crate::State`]'s gate.

use crate::error::ApiError;
use crate::state::State;
use glam::DVec3;
use lobe::experiment::estimate::{EstimateTableSettings, estimate_table};
use lobe::experiment::histogram::{WeightPixel, weight_pixels};
use lobe::experiment::warp_test::{interactive_config, warp_test};
use lobe::experiment::{albedo, lobe_grid, polar};
use lobe::models::{MODELS, Param, Range, Value as PValue};
use lobe::{BsdfStrategy, Material, MaterialDesc, Rgb};
use serde::Deserialize;
use serde_json::{Value, json};

/// The bounds of a request's work: beyond them it is refused with the
/// bound named, so that no request can hold the server for long.
pub mod limits {
    /// Polar plot angles.
    pub const MAX_STEPS: usize = 4001;
    /// The 3D lobe's grid.
    pub const MAX_THETA: usize = 180;
    pub const MAX_PHI: usize = 360;
    /// Albedo curve points.
    pub const MAX_ALBEDO_POINTS: usize = 91;
    /// Warp test draws, histogram and heat-map sides.
    pub const MAX_WARP_SAMPLES: usize = 1 << 20;
    pub const MAX_RES: usize = 128;
    /// Estimates per strategy.
    pub const MAX_ESTIMATE_SAMPLES: usize = 1 << 18;
    /// Lit sphere: side, samples per pixel and pass, passes.
    pub const MAX_SIZE: u32 = 512;
    pub const MAX_SPP: u64 = 256;
    pub const MAX_PASS: u64 = 4095;
    /// Camera samples of one pass, `size² × spp` (a 256² pass of 64).
    pub const MAX_PASS_SAMPLES: u64 = 1 << 22;
    /// A request body (a material description and settings).
    pub const MAX_BODY: usize = 64 * 1024;
}

/// A request body as JSON, or a clear error.
pub fn parse<T: serde::de::DeserializeOwned>(body: &[u8]) -> Result<T, ApiError> {
    serde_json::from_slice(body).map_err(|e| ApiError::bad(format!("request: {e}")))
}

/// A setting within `[1, max]` (its default where absent).
fn bounded<T: PartialOrd + Copy + std::fmt::Display>(
    name: &str,
    v: Option<T>,
    default: T,
    min: T,
    max: T,
) -> Result<T, ApiError> {
    let v = v.unwrap_or(default);
    if v < min || v > max {
        return Err(ApiError::bad(format!(
            "`{name}` {v} is outside [{min}, {max}]"
        )));
    }
    Ok(v)
}

/// A material as the page describes it (a Mitsuba-style dict), and the
/// [`Material`] it builds, every `path` in it resolved inside the data
/// directory first (no other file can be named).
pub struct Built {
    /// As the page wrote it (paths relative to the data directory).
    pub desc: MaterialDesc,
    pub material: Material,
}

/// Builds `v` (see [`Built`]).
pub fn build(state: &State, v: &Value) -> Result<Built, ApiError> {
    if !v.is_object() {
        return Err(ApiError::bad(
            "`material` must be an object such as {\"type\": \"diffuse\"}",
        ));
    }
    let desc: MaterialDesc =
        serde_json::from_value(v.clone()).map_err(|e| ApiError::bad(format!("material: {e}")))?;
    let mut resolved = v.clone();
    resolve_paths(state, &mut resolved)?;
    let inner: MaterialDesc =
        serde_json::from_value(resolved).map_err(|e| ApiError::bad(format!("material: {e}")))?;
    let material = inner
        .build()
        .map_err(|e| ApiError::bad(format!("material: {e}")))?;
    Ok(Built { desc, material })
}

/// Every `path` value in `v`, at any depth, replaced by the file it names
/// inside the data directory (or the request refused).
fn resolve_paths(state: &State, v: &mut Value) -> Result<(), ApiError> {
    match v {
        Value::Object(map) => {
            for (k, x) in map.iter_mut() {
                if k == "path" {
                    let Value::String(rel) = x else {
                        return Err(ApiError::bad("material: `path` must be a string"));
                    };
                    let p = state.data.resolve(rel).map_err(ApiError::bad)?;
                    *x = Value::String(p.to_string_lossy().into_owned());
                } else {
                    resolve_paths(state, x)?;
                }
            }
        }
        Value::Array(xs) => {
            for x in xs {
                resolve_paths(state, x)?;
            }
        }
        _ => {}
    }
    Ok(())
}

/// The view direction at `theta_o`, `phi_o` degrees
/// ([`Material::view_direction`]).
pub fn view(m: &Material, theta_o: f64, phi_o: f64) -> Result<DVec3, ApiError> {
    m.view_direction(theta_o, phi_o)
        .map_err(|e| ApiError::bad(e.named("`theta_o`", "`phi_o`")))
}

fn rgb(c: Rgb) -> [f64; 3] {
    [c.x, c.y, c.z]
}

/// What every view request has: the material and the view.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialRequest {
    pub material: Value,
}

/// `POST /api/material`: the model, its strategies, and the description
/// as JSON, TOML and a Python dict.
pub fn material(state: &State, body: &[u8]) -> Result<Value, ApiError> {
    let r: MaterialRequest = parse(body)?;
    let b = build(state, &r.material)?;
    let m = &b.material;
    let toml = b
        .desc
        .to_toml()
        .map_err(|e| ApiError::bad(format!("material: {e}")))?;
    Ok(json!({
        "model": b.desc.kind,
        "strategies": m.strategies().iter().map(|s| s.name()).collect::<Vec<_>>(),
        "transmits": m.reach().transmits,
        "two_sided": m.two_sided,
        "json": b.desc.to_json(),
        "toml": toml,
        "python": b.desc.to_python(),
    }))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PolarRequest {
    material: Value,
    theta_o: f64,
    #[serde(default)]
    phi_o: f64,
    steps: Option<usize>,
}

/// `POST /api/polar`: f·cos in the plane of incidence and each
/// strategy's pdf there.
pub fn polar(state: &State, body: &[u8]) -> Result<Value, ApiError> {
    let r: PolarRequest = parse(body)?;
    let steps = bounded("steps", r.steps, 361, 8, limits::MAX_STEPS)?;
    let b = build(state, &r.material)?;
    let m = &b.material;
    let wo = view(m, r.theta_o, r.phi_o)?;
    let fcos = polar::integrand(m, wo, 1.0, steps);
    let mut pdfs = serde_json::Map::new();
    for s in m.strategies() {
        let c = polar::pdf(m, s, wo, steps).map_err(|e| ApiError::bad(e.to_string()))?;
        pdfs.insert(
            s.name().into(),
            c.points.iter().map(|p| p.1).collect::<Vec<_>>().into(),
        );
    }
    Ok(json!({
        "full_circle": polar::full_circle(m, wo),
        "theta_deg": fcos.points.iter().map(|p| p.0.to_degrees()).collect::<Vec<_>>(),
        "fcos": fcos.points.iter().map(|p| p.1).collect::<Vec<_>>(),
        "pdfs": pdfs,
        "albedo": lobe::math::luminance(albedo::albedo_curve(m, &[r.theta_o], r.phi_o, ALBEDO_GRID)[0]),
    }))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LobeRequest {
    material: Value,
    theta_o: f64,
    #[serde(default)]
    phi_o: f64,
    n_theta: Option<usize>,
    n_phi: Option<usize>,
}

/// `POST /api/lobe`: f·cos over a grid of directions (the 3D lobe).
pub fn lobe(state: &State, body: &[u8]) -> Result<Value, ApiError> {
    let r: LobeRequest = parse(body)?;
    let n_theta = bounded("n_theta", r.n_theta, 45, 2, limits::MAX_THETA)?;
    let n_phi = bounded("n_phi", r.n_phi, 90, 3, limits::MAX_PHI)?;
    let b = build(state, &r.material)?;
    let wo = view(&b.material, r.theta_o, r.phi_o)?;
    let g = lobe_grid::grid(&b.material, wo, n_theta, n_phi);
    let rows: Vec<&[f64]> = g.values.chunks(g.phi.len()).collect();
    Ok(json!({
        "sphere": g.sphere,
        "theta_deg": g.theta.iter().map(|t| t.to_degrees()).collect::<Vec<_>>(),
        "phi_deg": g.phi.iter().map(|t| t.to_degrees()).collect::<Vec<_>>(),
        "values": rows,
    }))
}

/// The albedo's sample grid side (`albedo_curve`): about three digits.
const ALBEDO_GRID: usize = 64;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AlbedoRequest {
    material: Value,
    #[serde(default)]
    phi_o: f64,
    n: Option<usize>,
}

/// `POST /api/albedo`: the directional albedo against θo (RGB).
pub fn albedo(state: &State, body: &[u8]) -> Result<Value, ApiError> {
    let r: AlbedoRequest = parse(body)?;
    let n = bounded("n", r.n, 19, 2, limits::MAX_ALBEDO_POINTS)?;
    if !r.phi_o.is_finite() {
        return Err(ApiError::bad("`phi_o` must be a number"));
    }
    let b = build(state, &r.material)?;
    // θo over [0, 89]: n points, the last short of the horizon.
    let thetas: Vec<f64> = (0..n).map(|i| 89.0 * i as f64 / (n - 1) as f64).collect();
    let a = albedo::albedo_curve(&b.material, &thetas, r.phi_o, ALBEDO_GRID);
    Ok(json!({
        "theta_deg": thetas,
        "albedo": a.into_iter().map(rgb).collect::<Vec<_>>(),
    }))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WarpRequest {
    material: Value,
    strategy: String,
    theta_o: f64,
    #[serde(default)]
    phi_o: f64,
    samples: Option<usize>,
    res: Option<usize>,
    heat_res: Option<usize>,
}

/// `POST /api/warp`: Nori's warp test (histogram of the draws against the
/// pdf's, chi-square over the sphere) and the weight heat map.
pub fn warp(state: &State, body: &[u8]) -> Result<Value, ApiError> {
    let r: WarpRequest = parse(body)?;
    let samples = bounded("samples", r.samples, 20_000, 100, limits::MAX_WARP_SAMPLES)?;
    let res = bounded("res", r.res, 24, 4, limits::MAX_RES)?;
    let heat_res = bounded("heat_res", r.heat_res, 48, 4, limits::MAX_RES)?;
    let strategy: BsdfStrategy = r
        .strategy
        .parse()
        .map_err(|e: lobe::Error| ApiError::bad(format!("`strategy`: {e}")))?;
    let b = build(state, &r.material)?;
    let m = &b.material;
    let wo = view(m, r.theta_o, r.phi_o)?;
    let sp = m
        .sampler(strategy)
        .map_err(|e| ApiError::bad(format!("`strategy`: {e}")))?;
    let w = warp_test(&sp, wo, interactive_config(m, samples), res, &());
    let weights: Vec<Option<f64>> = weight_pixels(&sp, wo, heat_res)
        .into_iter()
        .map(|p| match p {
            WeightPixel::Weight(x) => Some(x),
            WeightPixel::ZeroF => Some(0.0),
            WeightPixel::Outside | WeightPixel::Unsampled => None,
        })
        .collect();
    let c = &w.chi2;
    Ok(json!({
        "res": w.histograms.res,
        "sphere": w.histograms.sphere,
        "observed": w.histograms.observed,
        "expected": w.histograms.expected,
        "chi2": {
            "statistic": c.statistic,
            "dof": c.dof,
            "p_value": c.p_value,
            "passes": c.passes(0.01),
            "message": c.message,
        },
        "heat_res": heat_res,
        "weights": weights,
    }))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EstimateRequest {
    material: Value,
    theta_o: f64,
    #[serde(default)]
    phi_o: f64,
    samples: Option<usize>,
}

/// `POST /api/estimate`: each strategy's estimate of the reflected
/// radiance under a white constant sky at this view, its variance and
/// efficiency (`lobe estimate`'s table).
pub fn estimate(state: &State, body: &[u8]) -> Result<Value, ApiError> {
    let r: EstimateRequest = parse(body)?;
    let samples = bounded("samples", r.samples, 4096, 64, limits::MAX_ESTIMATE_SAMPLES)?;
    let b = build(state, &r.material)?;
    let m = &b.material;
    let wo = view(m, r.theta_o, r.phi_o)?;
    let settings = EstimateTableSettings {
        strategies: vec!["all".into()],
        mis_bsdf: None,
        mis_samples: (1, 1),
        samples,
        sequence: "independent".into(),
        seed: 1,
        replicas: 16,
    };
    let checked = settings.check(m).map_err(settings_error)?;
    let table = estimate_table(
        m,
        &lobe::estimator::ShadingPoint::local(wo),
        &lobe::Light::Constant(Rgb::ONE),
        &checked,
        &(),
        &lobe::progress::SystemClock::new(),
    )
    .map_err(settings_error)?;
    Ok(json!({
        "reference": table.reference,
        "light": "constant 1",
        "samples": samples,
        "rows": table.strategies,
    }))
}

/// An estimate's settings error in the API's names.
fn settings_error(e: lobe::experiment::estimate::SettingsError) -> ApiError {
    use lobe::experiment::estimate::Setting;
    ApiError::bad(e.named(|s| match s {
        Setting::Samples => "`samples`",
        Setting::Strategies => "strategies",
        Setting::MisBsdf | Setting::MisSamples => "MIS",
        Setting::Sequence => "sequence",
        Setting::Replicas => "replicas",
    }))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereRequest {
    material: Value,
    #[serde(default = "sky")]
    env: String,
    size: Option<u32>,
    spp: Option<u64>,
    #[serde(default)]
    pass: u64,
}

fn sky() -> String {
    "sky".into()
}

/// `POST /api/sphere`: one pass of lobe's renderer over a sphere of the
/// material under the built-in sky or an environment map of the data
/// directory; the mean of passes `0..P` is the `P`-pass image.
pub fn sphere(state: &State, body: &[u8]) -> Result<Value, ApiError> {
    let r: SphereRequest = parse(body)?;
    let size = bounded("size", r.size, 96, 8, limits::MAX_SIZE)?;
    let spp = bounded("spp", r.spp, 4, 1, limits::MAX_SPP)?;
    let pass = bounded("pass", Some(r.pass), 0, 0, limits::MAX_PASS)?;
    let work = u64::from(size) * u64::from(size) * spp;
    if work > limits::MAX_PASS_SAMPLES {
        return Err(ApiError::bad(format!(
            "`size`² × `spp` = {work} samples in one pass: at most {} (fewer samples a pass, more passes)",
            limits::MAX_PASS_SAMPLES
        )));
    }
    let b = build(state, &r.material)?;
    let env = state.envmap(&r.env)?;
    let scene = lobe_render::scene::material_preview(b.material, env, size)
        .map_err(|e| ApiError::bad(e.to_string()))?;
    let opts = lobe_render::RenderSettings {
        spp,
        spp_allocation: lobe_render::SppAllocation::Uniform,
        ..lobe_render::RenderSettings::default()
    };
    let img = lobe_render::integrator::render_pass(&scene, &opts, pass, |_| {});
    Ok(json!({
        "width": img.width,
        "height": img.height,
        "pass": pass,
        "spp": spp,
        "rgb": img.to_rgb32f(),
    }))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FitRequest {
    file: String,
    distribution: Option<String>,
    fresnel: Option<String>,
    #[serde(default)]
    anisotropic: bool,
}

/// `POST /api/fit`: `lobe fit` of a measured table of the data directory.
pub fn fit(state: &State, body: &[u8]) -> Result<Value, ApiError> {
    let r: FitRequest = parse(body)?;
    let path = state.data.resolve(&r.file).map_err(ApiError::bad)?;
    let distribution = match r.distribution.as_deref().unwrap_or("ggx") {
        "ggx" => lobe::Ndf::Ggx,
        "beckmann" => lobe::Ndf::Beckmann,
        d => {
            return Err(ApiError::bad(format!(
                "`distribution` {d}: ggx or beckmann"
            )));
        }
    };
    let fresnel = r
        .fresnel
        .as_deref()
        .unwrap_or("schlick")
        .parse()
        .map_err(|e: lobe::Error| ApiError::bad(format!("`fresnel`: {e}")))?;
    let table = lobe::models::measured::Measured::load(&path, None)
        .map_err(|e| ApiError::bad(format!("`{}`: {e}", r.file)))?;
    let m = Material::with_diffuse(Rgb::ZERO, lobe::Glossy::Measured(table))
        .map_err(|e| ApiError::bad(e.to_string()))?;
    let f = lobe::fit::fit(
        &m,
        lobe::fit::FitSettings {
            distribution,
            fresnel,
            anisotropic: r.anisotropic,
        },
    )
    .map_err(|e| ApiError::bad(e.to_string()))?;
    let material: Value =
        serde_json::from_str(&f.to_json()).map_err(|e| ApiError::internal(e.to_string()))?;
    Ok(json!({
        "material": material,
        "error": f.error,
        "evaluations": f.evaluations,
    }))
}

/// A slider's span for a number: what people explore, inside what the
/// model accepts (log-scaled where the parameter spans decades).
fn slider(name: &str, min: f64, max: f64) -> (f64, f64, bool) {
    match name {
        "alpha" | "alpha_u" | "alpha_v" => (0.001_f64.max(min), 1.0_f64.min(max), true),
        "roughness" => (0.03_f64.max(min), 1.0_f64.min(max), false),
        "exponent" => (1.0_f64.max(min), 10_000.0_f64.min(max), true),
        _ if max.is_finite() => (min, max, false),
        _ => (min, min.max(0.0) + 10.0, false),
    }
}

fn param_json(p: &Param, data_files: &[String]) -> Value {
    let default = match p.default {
        PValue::Number(v) => json!(v),
        PValue::Bool(b) => json!(b),
        PValue::Name(s) => json!(s),
        PValue::Text(_) => Value::Null,
    };
    let mut o = json!({"name": p.name, "meaning": p.meaning, "default": default});
    let extra = match p.range {
        Range::Colour { max } => {
            json!({"kind": "colour", "max": if max.is_finite() { max } else { 1.0 }})
        }
        Range::Number { min, max } => {
            let (lo, hi, log) = slider(p.name, min, max);
            json!({"kind": "number", "min": lo, "max": hi, "log": log})
        }
        Range::Bool => json!({"kind": "bool"}),
        Range::Names(names) => {
            json!({"kind": "choice", "choices": names.split(", ").collect::<Vec<_>>()})
        }
        Range::File => json!({"kind": "file", "choices": data_files}),
        Range::Ior => {
            json!({"kind": "ior", "choices": lobe::ior::IORS.iter().map(|i| i.0).collect::<Vec<_>>()})
        }
        Range::Conductor => {
            let mut names = vec!["none"];
            names.extend(lobe::ior::CONDUCTORS.iter().map(|c| c.0));
            json!({"kind": "choice", "choices": names})
        }
        Range::Material => json!({"kind": "material"}),
    };
    if let (Value::Object(o), Value::Object(e)) = (&mut o, extra) {
        o.extend(e);
    }
    o
}

/// `GET /api/models`: every model with its parameters (and slider
/// spans), the strategies, and the data directory's files.
pub fn models(state: &State) -> Value {
    let files = state.data.list();
    let measured: Vec<String> = files
        .iter()
        .filter(|f| f.kind == crate::sandbox::DataKind::Measured)
        .map(|f| f.path.clone())
        .collect();
    let models: Vec<Value> = MODELS
        .iter()
        .map(|info| {
            let example = match info.name {
                "measured" => measured
                    .first()
                    .map(|p| json!({"type": "measured", "path": p})),
                "twosided" => Some(json!({"type": "twosided", "bsdf": {"type": "diffuse"}})),
                n => Some(json!({"type": n})),
            };
            json!({
                "name": info.name,
                "params": info.params.iter().map(|p| param_json(p, &measured)).collect::<Vec<_>>(),
                "example": example,
            })
        })
        .collect();
    let strategies: Vec<Value> = BsdfStrategy::ALL
        .iter()
        .map(|s| json!({"name": s.name(), "description": lobe::strategy::description(s.name())}))
        .collect();
    json!({"models": models, "strategies": strategies, "data_files": files})
}
