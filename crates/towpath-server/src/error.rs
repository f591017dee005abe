//! API errors: a status code and a JSON body naming the file, the line and the problem.

use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use serde::Serialize;

/// Why a request was refused or failed. Every variant becomes a JSON body
/// `{"error": "...", "file": "...", "line": n}` with the variant's status code.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ApiError {
    /// The request or an uploaded file is wrong (400): `file` and `line` say where, when known.
    #[error("{message}")]
    BadInput {
        /// What is wrong.
        message: String,
        /// The uploaded or named file the problem is in.
        file: Option<String>,
        /// 1-based line in that file.
        line: Option<usize>,
    },
    /// Nothing by that name (404).
    #[error("{0}")]
    NotFound(String),
    /// The upload is larger than the server takes (413).
    #[error("{0}")]
    TooLarge(String),
    /// Too many jobs are waiting (429).
    #[error("{0}")]
    Busy(String),
    /// The request conflicts with the state (409), e.g. a result of a job that has not finished.
    #[error("{0}")]
    Conflict(String),
    /// A bug or an I/O failure on the server (500).
    #[error("{0}")]
    Internal(String),
}

impl ApiError {
    /// A bad request without a file.
    pub fn bad(message: impl Into<String>) -> Self {
        ApiError::BadInput { message: message.into(), file: None, line: None }
    }

    /// A problem in a file, at a line if known.
    pub fn in_file(file: &str, line: Option<usize>, message: impl Into<String>) -> Self {
        ApiError::BadInput { message: message.into(), file: Some(file.to_string()), line }
    }

    /// The HTTP status of the error.
    pub fn status(&self) -> StatusCode {
        match self {
            ApiError::BadInput { .. } => StatusCode::BAD_REQUEST,
            ApiError::NotFound(_) => StatusCode::NOT_FOUND,
            ApiError::TooLarge(_) => StatusCode::PAYLOAD_TOO_LARGE,
            ApiError::Busy(_) => StatusCode::TOO_MANY_REQUESTS,
            ApiError::Conflict(_) => StatusCode::CONFLICT,
            ApiError::Internal(_) => StatusCode::INTERNAL_SERVER_ERROR,
        }
    }
}

#[derive(Serialize)]
struct Body<'a> {
    error: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    file: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    line: Option<usize>,
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let (file, line) = match &self {
            ApiError::BadInput { file, line, .. } => (file.as_deref(), *line),
            _ => (None, None),
        };
        // The message says where first, as the CLI does: `file: line N: problem`.
        let error = match (file, line) {
            (Some(f), Some(l)) => format!("{f}: line {l}: {self}"),
            (Some(f), None) => format!("{f}: {self}"),
            _ => self.to_string(),
        };
        (self.status(), axum::Json(Body { error, file, line })).into_response()
    }
}

impl From<std::io::Error> for ApiError {
    fn from(e: std::io::Error) -> Self {
        ApiError::Internal(format!("workspace: {e}"))
    }
}

/// Result of a handler.
pub type ApiResult<T> = Result<T, ApiError>;
