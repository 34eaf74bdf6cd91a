//! The page and its vendored plotting library, compiled into the binary:
//! nothing is fetched at run time.

use axum::http::header;
use axum::response::{IntoResponse, Response};

const INDEX: &str = include_str!("../web/index.html");
const APP: &str = include_str!("../web/app.js");
const STYLE: &str = include_str!("../web/style.css");
/// Plotly.js 4.1.2 (MIT, web/vendor/plotly.LICENSE), gzip-compressed;
/// served as it is with `Content-Encoding: gzip`.
const PLOTLY_GZ: &[u8] = include_bytes!("../web/vendor/plotly.min.js.gz");

/// A static asset by its URL path, or `None`.
pub fn asset(path: &str) -> Option<Response> {
    let text = |mime: &'static str, body: &'static str| {
        ([(header::CONTENT_TYPE, mime)], body).into_response()
    };
    Some(match path {
        "/" | "/index.html" => text("text/html; charset=utf-8", INDEX),
        "/app.js" => text("text/javascript; charset=utf-8", APP),
        "/style.css" => text("text/css; charset=utf-8", STYLE),
        "/vendor/plotly.min.js" => (
            [
                (header::CONTENT_TYPE, "text/javascript; charset=utf-8"),
                (header::CONTENT_ENCODING, "gzip"),
                (header::CACHE_CONTROL, "max-age=86400"),
            ],
            PLOTLY_GZ,
        )
            .into_response(),
        // No icon (a browser asks; an empty answer is not an error).
        "/favicon.ico" => axum::http::StatusCode::NO_CONTENT.into_response(),
        _ => return None,
    })
}
