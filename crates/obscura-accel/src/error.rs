//! The crate's one error type.

use core::fmt;
use std::path::PathBuf;

/// Why a mesh, an OBJ file, a shape or a scene was refused. Every message stands alone: it
/// names the file and, where known, the line.
#[derive(Debug, Clone, PartialEq)]
pub enum AccelError {
    /// The OBJ file could not be opened or read.
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        reason: String,
    },
    /// The OBJ file is malformed.
    Obj {
        /// The file.
        path: PathBuf,
        /// The 1-based line, where known.
        line: Option<usize>,
        /// What is wrong.
        reason: String,
    },
    /// A mesh given in memory is invalid (non-finite position, index out of range, ...).
    Mesh(String),
    /// A shape's parameters are invalid (non-finite, zero radius, degenerate quad, ...).
    Shape(String),
    /// A placement (instance transform) is invalid.
    Placement(String),
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

impl fmt::Display for AccelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AccelError::Io { path, reason } => {
                write!(f, "{}: cannot read the OBJ file: {reason}", path.display())
            }
            AccelError::Obj {
                path,
                line: Some(line),
                reason,
            } => write!(f, "{}: line {line}: {reason}", path.display()),
            AccelError::Obj {
                path,
                line: None,
                reason,
            } => write!(f, "{}: {reason}", path.display()),
            AccelError::Mesh(reason) => write!(f, "triangle mesh: {reason}"),
            AccelError::Shape(reason) => write!(f, "shape: {reason}"),
            AccelError::Placement(reason) => write!(f, "instance placement: {reason}"),
        }
    }
}

impl std::error::Error for AccelError {}
