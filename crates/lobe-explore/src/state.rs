//! What the handlers share: the data directory, the page's first
//! materials, the environment maps loaded so far, and the gate that lets
//! one computation per CPU run at once.

use crate::error::ApiError;
use crate::sandbox::DataDir;
use lobe::envmap::EnvMap;
use serde_json::Value;
use std::collections::HashMap;
use std::sync::atomic::AtomicUsize;
use std::sync::{Arc, Mutex};
use tokio::sync::Semaphore;

/// What the handlers share.
pub struct State {
    pub data: DataDir,
    /// A line on standard error for each API request.
    pub(crate) log: bool,
    /// The `--material`s, for `GET /api/models`.
    pub(crate) materials: Vec<Value>,
    /// Environment maps by name, loaded once.
    envmaps: Mutex<HashMap<String, Arc<EnvMap>>>,
    /// Computations at once: one per CPU (each is parallel itself).
    pub(crate) gate: Arc<Semaphore>,
    /// Requests waiting or running.
    pub(crate) pending: AtomicUsize,
}

impl State {
    /// A state letting `cpus` computations run at once.
    #[must_use]
    pub fn new(data: DataDir, log: bool, materials: Vec<Value>, cpus: usize) -> Self {
        State {
            data,
            log,
            materials,
            envmaps: Mutex::new(HashMap::new()),
            gate: Arc::new(Semaphore::new(cpus.max(1))),
            pending: AtomicUsize::new(0),
        }
    }

    /// The environment map `name` names ("sky" or a data file), cached.
    pub fn envmap(&self, name: &str) -> Result<Arc<EnvMap>, ApiError> {
        if let Some(m) = self.envmaps.lock().ok().and_then(|m| m.get(name).cloned()) {
            return Ok(m);
        }
        let m = self.load_envmap(name)?;
        if let Ok(mut cache) = self.envmaps.lock() {
            // At most a few maps are kept (each can be large).
            if cache.len() >= 4 {
                cache.clear();
            }
            cache.insert(name.to_string(), m.clone());
        }
        Ok(m)
    }

    /// The built-in sky, or a file of the data directory.
    fn load_envmap(&self, name: &str) -> Result<Arc<EnvMap>, ApiError> {
        if name == "sky" {
            let (e, a, scale, rot) = (35.0, 40.0, 1.0, 0.0);
            let (map, _) = lobe_render::envmap_io::sky(e, a, scale, rot)
                .map_err(|e| ApiError::internal(e.to_string()))?;
            return Ok(Arc::new(map));
        }
        let path = self.data.resolve(name).map_err(ApiError::bad)?;
        let (map, _) = lobe_render::envmap_io::load_envmap(&path, 1.0, 0.0)
            .map_err(|e| ApiError::bad(format!("`{name}`: {e}")))?;
        Ok(Arc::new(map))
    }
}
