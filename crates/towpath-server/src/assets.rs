//! The front end, embedded in the binary: `crates/towpath-server/assets/` is the committed
//! output of `web/build.sh` (see `web/README.md`), so a build needs no Node.js.

use axum::http::{header, StatusCode, Uri};
use axum::response::{IntoResponse, Response};

#[derive(rust_embed::RustEmbed)]
#[folder = "assets/"]
struct Assets;

fn content_type(path: &str) -> &'static str {
    match path.rsplit('.').next() {
        Some("html") => "text/html; charset=utf-8",
        Some("js") => "text/javascript; charset=utf-8",
        Some("css") => "text/css; charset=utf-8",
        Some("svg") => "image/svg+xml",
        Some("png") => "image/png",
        Some("json") => "application/json",
        _ => "application/octet-stream",
    }
}

/// Serves an embedded file; `/` is the app's page. Paths are looked up in the embedded table
/// only, never on disk.
pub async fn serve(uri: Uri) -> Response {
    let path = uri.path().trim_start_matches('/');
    let path = if path.is_empty() { "index.html" } else { path };
    let Some(f) = Assets::get(path) else {
        return (StatusCode::NOT_FOUND, "not found").into_response();
    };
    // For front-end work: `TOWPATH_WEB_DIR=crates/towpath-server/assets` serves the same names
    // (only names the binary embeds) from that folder, so a rebuilt bundle shows without
    // rebuilding the binary.
    let body = std::env::var_os("TOWPATH_WEB_DIR")
        .and_then(|dir| std::fs::read(std::path::Path::new(&dir).join(path)).ok())
        .unwrap_or_else(|| f.data.into_owned());
    ([(header::CONTENT_TYPE, content_type(path)), (header::CACHE_CONTROL, "no-cache")], body).into_response()
}

/// Names of the embedded files.
pub fn names() -> Vec<String> {
    Assets::iter().map(|s| s.into_owned()).collect()
}
