//! The crate's one error type.

use std::path::PathBuf;

/// Why a mesh, an OBJ file, a shape or a scene was refused. Every message stands alone: it
/// names the file and, where known, the line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AccelError {
    /// The OBJ file could not be opened or read.
    #[error("{}: cannot read the OBJ file: {reason}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        reason: String,
    },
    /// The OBJ file is malformed.
    #[error("{}: {}{reason}", path.display(), line_prefix(*line))]
    Obj {
        /// The file.
        path: PathBuf,
        /// The 1-based line, where known.
        line: Option<usize>,
        /// What is wrong.
        reason: String,
    },
    /// A mesh given in memory is invalid (non-finite position, index out of range, ...).
    #[error("triangle mesh: {0}")]
    Mesh(String),
    /// A shape's parameters are invalid (non-finite, zero radius, degenerate quad, ...).
    #[error("shape: {0}")]
    Shape(String),
    /// A placement (instance transform) is invalid.
    #[error("instance placement: {0}")]
    Placement(String),
}

/// `"line N: "` where the line is known, else nothing.
fn line_prefix(line: Option<usize>) -> String {
    line.map_or(String::new(), |line| format!("line {line}: "))
}

impl AccelError {
    /// Attaches a file name to a mesh-validation error (used by the OBJ loader).
    pub(crate) fn in_file(self, path: &std::path::Path) -> Self {
        match self {
            AccelError::Mesh(reason) => AccelError::Obj {
                path: path.to_path_buf(),
                line: None,
                reason,
            },
            other => other,
        }
    }
}
