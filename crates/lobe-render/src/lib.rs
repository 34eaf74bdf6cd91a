//! lobe-render: a small renderer that shows `lobe`'s samplers, light
//! sampling and MIS as images.
//!
//! Spheres, infinite planes and OBJ triangle meshes (with a BVH) under an
//! environment map, the only light, seen by a pinhole camera. Each camera
//! ray's hit estimates the reflected radiance by BSDF sampling, light
//! sampling or MIS exactly as `lobe::estimator` does, plus a shadow ray
//! ([`mod@integrator`] module docs); `max_depth > 1` adds path tracing.
//! [`compare`] renders several methods at equal samples and equal time
//! against a reference and measures their errors.
//!
//! ```no_run
//! use lobe_render::{load_scene, render};
//! let scene = load_scene(std::path::Path::new("scene.toml"))?;
//! let image = render(&scene, &scene.settings, |_| {});
//! image.write_exr(std::path::Path::new("scene.exr"))?;
//! image.write_png(std::path::Path::new("scene.png"), &lobe_render::ToneMap::default())?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! A scene in code:
//!
//! ```
//! use lobe_render::{Camera, Object, RenderSettings, Scene, render};
//! use lobe::estimator::Strategy;
//! use lobe::{envmap::EnvMap, Material, Rgb, BsdfStrategy};
//! use glam::DVec3;
//! let camera = Camera::new(DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO, DVec3::Y, 40.0, 8, 6)?;
//! let scene = Scene::new(camera, EnvMap::constant(Rgb::ONE))
//!     .with(Object::sphere(DVec3::ZERO, 1.0, Material::lambert(Rgb::ONE)?)?);
//! let opts = RenderSettings { spp: 4, strategy: Strategy::Bsdf(BsdfStrategy::Cosine), ..Default::default() };
//! let img = render(&scene, &opts, |_| {});
//! // The white furnace: 1 to f32 rounding on the batch loop (the default)...
//! assert!((img.get(4, 3).x - 1.0).abs() < 1e-6);
//! // ... and to f64 rounding on the scalar one.
//! let opts = RenderSettings { render_loop: lobe_render::RenderLoop::Scalar, ..opts };
//! assert!((render(&scene, &opts, |_| {}).get(4, 3).x - 1.0).abs() < 1e-9);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod camera;
pub mod compare;
pub mod envmap_io;
pub mod geometry;
pub mod integrator;
pub mod light_spec;
pub mod mesh;
pub mod output;
pub mod ray_block;
pub mod scene;
pub mod settings;

pub use camera::{Camera, CameraError};
pub use envmap_io::{LoadError, LoadedEnvMap, load_envmap, load_envmap_checked};
pub use geometry::{Hit, Ray};
pub use integrator::{Image, RenderStats, fallbacks, render, strategy_for};
pub use mesh::{Mesh, MeshError};
pub use output::{OutputError, ToneMap};
pub use scene::{Object, Scene, SceneDesc, SceneError, Shape, load_scene, parse_scene, showcase};
pub use settings::{RenderLoop, RenderSettings, SppAllocation};
