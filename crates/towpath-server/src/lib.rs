//! # towpath-server: the local web application
//!
//! `towpath serve` runs [`serve`]: an HTTP server (axum on tokio), on the loopback address unless
//! told otherwise, that serves the front end (embedded in the binary, see [`assets`]) and a
//! JSON API under `/api/` (the `api` module):
//!
//! - programs: the built-in demo parts and the large panel, uploads parsed by `towpath-nc` and
//!   refused with the file, line and problem, and each program's geometry as typed arrays
//!   ([`geometry`]);
//! - machines and dialects (TOML, or the machine editor's JSON, with a live tool-point preview)
//!   and meshes;
//! - background [`jobs`] (optimize, layup) with a bounded number running at once and a queue,
//!   cancel, wall-time limits, and progress as server-sent events;
//! - a [`workspace`] folder in which everything uploaded, saved or produced is kept, so a bad
//!   request or a restart loses nothing; requests name files only by checked [`names`].
//!
//! Every call into the library crates goes through [`adapt`], the one place to follow their
//! API changes.

#![warn(missing_docs)]

pub mod adapt;
mod api;
pub mod assets;
pub mod error;
pub mod geometry;
pub mod jobs;
pub mod names;
pub mod state;
pub mod workspace;

use std::net::SocketAddr;
use std::sync::Arc;

use axum::extract::{DefaultBodyLimit, Request};
use axum::http::{header, Method, StatusCode};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::Router;

pub use error::ApiError;
pub use state::{AppState, Config};

/// The whole application: API, front end, body limit and the same-origin rule.
pub fn router(state: Arc<AppState>) -> Router {
    let limit = state.config.max_upload;
    Router::new()
        .merge(api::routes())
        .fallback(assets::serve)
        .layer(DefaultBodyLimit::max(limit))
        .layer(middleware::from_fn(same_origin))
        .with_state(state)
}

/// CORS stays off (no `Access-Control-*` header is ever sent), and a request that changes
/// something is refused when a browser says it comes from another origin than the server's
/// own (another web site, or a DNS-rebound name).
async fn same_origin(req: Request, next: Next) -> Response {
    if req.method() != Method::GET && req.method() != Method::HEAD {
        let host = req.headers().get(header::HOST).and_then(|h| h.to_str().ok()).unwrap_or("");
        if let Some(origin) = req.headers().get(header::ORIGIN).and_then(|o| o.to_str().ok()) {
            let origin_host = origin.split("://").nth(1).unwrap_or("");
            if origin_host != host {
                return (
                    StatusCode::FORBIDDEN,
                    axum::Json(serde_json::json!({
                        "error": format!("requests from {origin} are refused: the app answers its own page only")
                    })),
                )
                    .into_response();
            }
        }
    }
    next.run(req).await
}

/// Starts the server and runs until Ctrl-C. `ready` is called with the bound address (the port
/// may have been 0).
pub async fn serve(config: Config, ready: impl FnOnce(SocketAddr, &AppState)) -> std::io::Result<()> {
    let addr = format!("{}:{}", config.host, config.port);
    let listener = tokio::net::TcpListener::bind(&addr).await?;
    let bound = listener.local_addr()?;
    let state = AppState::new(config)?;
    if state.config.prewarm_panel {
        let st = state.clone();
        tokio::spawn(async move {
            if let Ok(p) = st.program(state::PANEL_ID) {
                let _ = api::prewarm(&st, &p).await;
            }
        });
    }
    ready(bound, &state);
    axum::serve(listener, router(state))
        .with_graceful_shutdown(async {
            let _ = tokio::signal::ctrl_c().await;
        })
        .await
}

/// [`serve`] on a runtime of its own, for the command line.
pub fn serve_blocking(config: Config, ready: impl FnOnce(SocketAddr, &AppState)) -> std::io::Result<()> {
    tokio::runtime::Builder::new_multi_thread().enable_all().build()?.block_on(serve(config, ready))
}
