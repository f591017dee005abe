//! The JSON API under `/api/`: programs, machines, dialects, meshes and jobs.

use std::sync::Arc;

use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::Router;

use crate::error::ApiError;
use crate::state::AppState;

mod jobs;
mod programs;
mod setup;

/// The API routes.
pub fn routes() -> Router<Arc<AppState>> {
    Router::new()
        .route("/api/status", get(setup::status))
        .route("/api/programs", get(programs::list).post(programs::upload))
        .route("/api/programs/{id}", get(programs::info).delete(programs::remove))
        .route("/api/programs/{id}/geometry", get(programs::geometry))
        .route("/api/programs/{id}/text", get(programs::text))
        .route("/api/programs/{id}/check", post(programs::check))
        .route("/api/machines", get(setup::machines))
        .route("/api/machines/{name}", get(setup::machine).put(setup::save_machine).delete(setup::delete_machine))
        .route("/api/machine-preview", post(setup::preview))
        .route("/api/dialects", get(setup::dialects))
        .route("/api/dialects/{name}", get(setup::dialect).put(setup::save_dialect))
        .route("/api/meshes", get(setup::meshes).post(setup::upload_mesh))
        .route("/api/meshes/{name}/geometry", get(setup::mesh_geometry))
        .route("/api/jobs", get(jobs::list))
        .route("/api/jobs/optimize", post(jobs::optimize))
        .route("/api/jobs/layup", post(jobs::layup))
        .route("/api/jobs/{id}", get(jobs::get))
        .route("/api/jobs/{id}/cancel", post(jobs::cancel))
        .route("/api/jobs/{id}/events", get(jobs::events))
        .route("/api/jobs/{id}/files/{name}", get(jobs::file))
        .fallback(|| async { ApiError::NotFound("no such API route".into()) })
}

/// The body of an upload, with the size limit said in the server's words.
pub(crate) fn upload(state: &AppState, body: Result<Bytes, BytesRejection>) -> Result<Bytes, ApiError> {
    body.map_err(|e| {
        if e.status() == StatusCode::PAYLOAD_TOO_LARGE {
            ApiError::TooLarge(format!(
                "the upload is larger than the server takes ({} MiB; start it with --max-upload-mb to change)",
                state.config.max_upload >> 20
            ))
        } else {
            ApiError::bad(format!("the request body could not be read: {e}"))
        }
    })
}

/// An upload as UTF-8 text; otherwise an error naming the line and byte.
pub(crate) fn utf8(file: &str, bytes: &[u8]) -> Result<String, ApiError> {
    String::from_utf8(bytes.to_vec()).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
        let col = at - bytes[..at].iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1) + 1;
        ApiError::in_file(
            file,
            Some(line),
            format!("byte {col} (0x{:02x}) is not UTF-8 text; towpath reads UTF-8 (ASCII) files", bytes[at]),
        )
    })
}

/// A download with a file name.
pub(crate) fn attachment(name: &str, content_type: &'static str, body: Vec<u8>) -> Response {
    let disposition = format!("attachment; filename=\"{name}\"");
    ([(header::CONTENT_TYPE, content_type.to_string()), (header::CONTENT_DISPOSITION, disposition)], body)
        .into_response()
}

/// Builds a program's geometry ahead of the first request (the large panel at start).
pub(crate) async fn prewarm(s: &Arc<AppState>, p: &Arc<crate::state::ProgramEntry>) -> Result<(), ApiError> {
    programs::geometry_bytes(s, p).await.map(|_| ())
}
