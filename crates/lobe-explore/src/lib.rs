//! `lobe explore`: a local HTTP server and the page it serves, on which a
//! user edits materials and sees their lobes, albedo, a lit sphere, the
//! warp test of a sampler and each strategy's variance, updated as a slider
//! moves. Every number the page shows comes from a library call of
//! `lobe` or `lobe-render` ([`api`]); this crate only parses, bounds and
//! serves. The API is documented in docs/explore.md.
//!
//! ```no_run
//! let server = lobe_explore::Server::bind(&lobe_explore::Config::default()).unwrap();
//! println!("{}", server.url());
//! server.run();
//! ```

pub mod api;
mod assets;
pub mod error;
pub mod sandbox;
pub mod state;

use axum::Router;
use axum::extract::{Request, State as AxState};
use axum::http::{Method, StatusCode};
use axum::response::{IntoResponse, Response};
use error::ApiError;
use sandbox::DataDir;
use serde_json::Value;
use state::State;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

/// How the server starts.
#[derive(Debug, Clone)]
pub struct Config {
    /// The address to listen on: 127.0.0.1 unless asked otherwise.
    pub host: IpAddr,
    /// 0 picks a free port.
    pub port: u16,
    /// The only directory files are read from (measured tables,
    /// environment maps); none: no file is read.
    pub data: Option<PathBuf>,
    /// The materials the page opens with (descriptions as JSON objects);
    /// empty: the page's own two.
    pub materials: Vec<Value>,
    /// A line on standard error for each API request: method, path,
    /// status, milliseconds (and the error's message).
    pub log: bool,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            host: IpAddr::V4(Ipv4Addr::LOCALHOST),
            port: 0,
            data: None,
            materials: Vec::new(),
            log: false,
        }
    }
}

/// Requests waiting or running at once beyond which the server answers
/// 503 at once (a burst never queues unbounded work).
const MAX_PENDING: usize = 256;

/// A bound server: its listener and state.
pub struct Server {
    runtime: tokio::runtime::Runtime,
    listener: tokio::net::TcpListener,
    addr: SocketAddr,
    state: Arc<State>,
}

impl Server {
    /// Checks `config` (the data directory exists, the materials build)
    /// and binds the port; errors say which.
    pub fn bind(config: &Config) -> Result<Server, String> {
        let data = DataDir::new(config.data.as_deref())?;
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        let state = Arc::new(State::new(data, config.log, config.materials.clone(), cpus));
        for (i, m) in config.materials.iter().enumerate() {
            api::build(&state, m).map_err(|e| format!("--material #{}: {}", i + 1, e.message))?;
        }
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .enable_all()
            .build()
            .map_err(|e| format!("cannot start the server's runtime: {e}"))?;
        let want = SocketAddr::new(config.host, config.port);
        let listener = runtime
            .block_on(tokio::net::TcpListener::bind(want))
            .map_err(|e| format!("cannot listen on {want}: {e}"))?;
        let addr = listener
            .local_addr()
            .map_err(|e| format!("cannot listen on {want}: {e}"))?;
        Ok(Server {
            runtime,
            listener,
            addr,
            state,
        })
    }

    /// The page's address, e.g. `http://127.0.0.1:8000/`.
    #[must_use]
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }

    /// Serves until the process ends.
    pub fn run(self) -> Result<(), String> {
        let app = router(self.state);
        self.runtime
            .block_on(async move { axum::serve(self.listener, app).await })
            .map_err(|e| format!("the server stopped: {e}"))
    }

    /// Serves on a thread of its own (tests); returns the URL.
    pub fn spawn(self) -> String {
        let url = self.url();
        std::thread::spawn(move || self.run());
        url
    }
}

/// The routes: the page's files, `GET /api/models`, `GET /api/data` and
/// the views by `POST /api/<view>`.
pub fn router(state: Arc<State>) -> Router {
    Router::new().fallback(handle).with_state(state)
}

type View = fn(&State, &[u8]) -> Result<Value, ApiError>;

async fn handle(AxState(state): AxState<Arc<State>>, req: Request) -> Response {
    let path = req.uri().path().to_string();
    let method = req.method().clone();
    if method == Method::GET {
        return match path.as_str() {
            "/api/models" => {
                let mut v = api::models(&state);
                v["initial"] = Value::Array(state.materials.clone());
                axum::Json(v).into_response()
            }
            "/api/data" => {
                axum::Json(serde_json::json!({ "files": state.data.list() })).into_response()
            }
            p => assets::asset(p).unwrap_or_else(|| not_found(p)),
        };
    }
    let view: View = match (method.clone(), path.as_str()) {
        (Method::POST, "/api/material") => api::material,
        (Method::POST, "/api/polar") => api::polar,
        (Method::POST, "/api/lobe") => api::lobe,
        (Method::POST, "/api/albedo") => api::albedo,
        (Method::POST, "/api/warp") => api::warp,
        (Method::POST, "/api/estimate") => api::estimate,
        (Method::POST, "/api/sphere") => api::sphere,
        (Method::POST, "/api/fit") => api::fit,
        (Method::POST, p) => return not_found(p),
        (m, p) => {
            return ApiError {
                status: StatusCode::METHOD_NOT_ALLOWED,
                message: format!("{m} {p}: the page's files are GET, the views POST"),
            }
            .into_response();
        }
    };
    let body = match axum::body::to_bytes(req.into_body(), api::limits::MAX_BODY).await {
        Ok(b) => b,
        Err(_) => {
            return ApiError {
                status: StatusCode::PAYLOAD_TOO_LARGE,
                message: format!(
                    "the request is larger than {} KiB",
                    api::limits::MAX_BODY / 1024
                ),
            }
            .into_response();
        }
    };
    let t = std::time::Instant::now();
    let log = state.log;
    let r = run_view(state, view, body).await;
    if log {
        let ms = t.elapsed().as_secs_f64() * 1e3;
        match &r {
            Ok(_) => eprintln!("lobe explore: POST {path} 200 {ms:.0} ms"),
            Err(e) => eprintln!(
                "lobe explore: POST {path} {} {ms:.0} ms: {}",
                e.status.as_u16(),
                e.message
            ),
        }
    }
    match r {
        Ok(v) => axum::Json(v).into_response(),
        Err(e) => e.into_response(),
    }
}

fn not_found(path: &str) -> Response {
    ApiError {
        status: StatusCode::NOT_FOUND,
        message: format!("{path}: no such page or API"),
    }
    .into_response()
}

/// Counts a request pending until dropped.
struct Pending<'a>(&'a AtomicUsize);

impl Drop for Pending<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Runs `view` on the blocking pool, one per CPU at once, at most
/// [`MAX_PENDING`] waiting; a panic in it is an error response, not the
/// server's end.
async fn run_view(
    state: Arc<State>,
    view: View,
    body: axum::body::Bytes,
) -> Result<Value, ApiError> {
    let _pending = Pending(&state.pending);
    if state.pending.fetch_add(1, Ordering::SeqCst) >= MAX_PENDING {
        return Err(ApiError::busy());
    }
    let permit = state
        .gate
        .clone()
        .acquire_owned()
        .await
        .map_err(|_| ApiError::internal("the server is stopping"))?;
    let st = state.clone();
    let r = tokio::task::spawn_blocking(move || {
        let _permit = permit;
        view(&st, &body)
    })
    .await;
    match r {
        Ok(r) => r,
        Err(e) => Err(ApiError::internal(format!(
            "the computation failed: {}",
            panic_text(e)
        ))),
    }
}

fn panic_text(e: tokio::task::JoinError) -> String {
    match e.try_into_panic() {
        Ok(p) => p
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| (*s).to_string()))
            .unwrap_or_else(|| "a panic".into()),
        Err(e) => e.to_string(),
    }
}
