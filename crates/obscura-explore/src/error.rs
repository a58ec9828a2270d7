//! The explorer's error type, and how each error answers an HTTP request.

use axum::Json;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use obscura_render::RenderError;

/// What can go wrong serving a page.
#[derive(Debug, thiserror::Error)]
pub enum ExploreError {
    /// The scene layer rejected the scene or a changed key.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The explorer refuses a request (an absurd resolution or spp, a malformed value).
    #[error("{key}: {message}")]
    Refused {
        /// The key at fault, such as `film.resolution`.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// The request names no session, or one that has ended.
    #[error("no such session: {0}")]
    NoSession(u64),
    /// Nothing is under the pixel asked about, or it is off the film.
    #[error("{0}")]
    NothingThere(String),
    /// A value in the request is malformed for its key: not a number, a negative or
    /// fractional count, a number JSON cannot hold, an unknown field. `key` is the scene key
    /// (`camera.fov`, `sampler.spp`) or the query parameter (`session`).
    #[error("{key}: {message}")]
    Malformed {
        /// The key at fault.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// The request is malformed where no key is at fault (not JSON, not an object).
    #[error("bad request: {0}")]
    BadRequest(String),
    /// The server could not do what was asked (a thread pool, a listener, an encoder).
    #[error("{0}")]
    Internal(String),
}

impl ExploreError {
    /// The scene key at fault, where the error names one.
    pub fn key(&self) -> Option<String> {
        match self {
            ExploreError::Render(RenderError::Scene { key, .. }) => key.clone(),
            ExploreError::Refused { key, .. } | ExploreError::Malformed { key, .. } => {
                Some(key.clone())
            }
            _ => None,
        }
    }

    /// The HTTP status this error answers with.
    pub fn status(&self) -> StatusCode {
        match self {
            ExploreError::Render(RenderError::Io { .. } | RenderError::Encode { .. })
            | ExploreError::Internal(_) => StatusCode::INTERNAL_SERVER_ERROR,
            ExploreError::Render(_)
            | ExploreError::Malformed { .. }
            | ExploreError::BadRequest(_) => StatusCode::BAD_REQUEST,
            ExploreError::Refused { .. } | ExploreError::NothingThere(_) => {
                StatusCode::UNPROCESSABLE_ENTITY
            }
            ExploreError::NoSession(_) => StatusCode::NOT_FOUND,
        }
    }

    /// The JSON body of an error answer: `{"error": message, "key": key-or-null}`.
    pub fn body(&self) -> serde_json::Value {
        serde_json::json!({ "error": self.to_string(), "key": self.key() })
    }
}

impl IntoResponse for ExploreError {
    fn into_response(self) -> Response {
        (self.status(), Json(self.body())).into_response()
    }
}
