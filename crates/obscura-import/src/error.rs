//! The importer's one error type.

use std::path::PathBuf;

/// Why a pbrt-v4 or Mitsuba 3 scene could not be imported.
///
/// Every message stands alone on one line and names the file and, where known, the line:
/// `scenes/room.pbrt:12: Camera: unknown camera "realistic"`.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// The scene (or a file it includes) is malformed, or asks for what would render wrongly.
    #[error("{}{}: {message}", file.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Scene {
        /// The file at fault (the scene or an included file, mesh or map).
        file: PathBuf,
        /// The 1-based line, where known.
        line: Option<usize>,
        /// What is wrong, starting with the directive or element at fault.
        message: String,
    },
    /// A file could not be read or written.
    #[error("{}: {action}: {source}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// What was being done, e.g. "cannot read".
        action: &'static str,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// The scene description the import produced was refused by the renderer (the message
    /// names the imported file and the line the refused value came from).
    #[error("{0}")]
    Render(#[from] obscura_render::RenderError),
}

impl From<ImportError> for obscura_render::RenderError {
    /// As the renderer's error, so the command line reports both kinds alike (exit status 2).
    fn from(e: ImportError) -> Self {
        match e {
            ImportError::Scene {
                file,
                line,
                message,
            } => obscura_render::RenderError::Scene {
                file,
                line,
                key: None,
                message,
            },
            ImportError::Io {
                file,
                action,
                source,
            } => obscura_render::RenderError::Io {
                file,
                action,
                source,
            },
            ImportError::Render(e) => e,
        }
    }
}

/// A source position: file and 1-based line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// The file.
    pub file: std::sync::Arc<PathBuf>,
    /// The 1-based line.
    pub line: usize,
}

impl Location {
    /// An error at this position.
    pub(crate) fn error(&self, message: impl Into<String>) -> ImportError {
        ImportError::Scene {
            file: self.file.as_ref().clone(),
            line: Some(self.line),
            message: message.into(),
        }
    }
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.file.display(), self.line)
    }
}
