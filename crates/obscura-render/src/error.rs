//! The renderer's one error type.

use std::fmt;
use std::path::PathBuf;

/// Why a scene could not be loaded or rendered, or an image not written.
///
/// Every message stands alone on one line: it names the file, and where known the key and line,
/// e.g. `scenes/dof.toml:14: camera.fov: must be in (0, 180) degrees, got 180`.
#[derive(Debug)]
pub enum RenderError {
    /// The scene file (or a file it names) is wrong.
    Scene {
        /// The file at fault.
        file: PathBuf,
        /// The 1-based line, where known.
        line: Option<usize>,
        /// The key at fault, as a path such as `camera.fov` or `shapes[2].radius`.
        key: Option<String>,
        /// What is wrong.
        message: String,
    },
    /// A file could not be read or written.
    Io {
        /// The file.
        file: PathBuf,
        /// What was being done, e.g. "cannot read".
        action: &'static str,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The image could not be encoded.
    Encode {
        /// The output file.
        file: PathBuf,
        /// The encoder's message.
        message: String,
    },
    /// A checkpoint file is corrupt, truncated, or belongs to another render.
    Checkpoint {
        /// The checkpoint file.
        file: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A render setting from the command line is invalid.
    Setting {
        /// The setting, e.g. `--spp`.
        name: &'static str,
        /// What is wrong.
        message: String,
    },
}

impl RenderError {
    /// A scene error about `key`; its line is looked up in the file (if it can be read).
    pub fn scene(
        file: impl Into<PathBuf>,
        key: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        let (file, key) = (file.into(), key.into());
        let line = std::fs::read_to_string(&file)
            .ok()
            .and_then(|source| crate::locate::line_of_key(&source, &key));
        RenderError::Scene {
            file,
            line,
            key: Some(key),
            message: message.into(),
        }
    }
}

impl fmt::Display for RenderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RenderError::Scene {
                file,
                line,
                key,
                message,
            } => {
                write!(f, "{}", file.display())?;
                if let Some(line) = line {
                    write!(f, ":{line}")?;
                }
                if let Some(key) = key {
                    write!(f, ": {key}")?;
                }
                write!(f, ": {message}")
            }
            RenderError::Io {
                file,
                action,
                source,
            } => {
                write!(f, "{}: {action}: {source}", file.display())
            }
            RenderError::Encode { file, message } => write!(f, "{}: {message}", file.display()),
            RenderError::Checkpoint { file, message } => {
                write!(f, "{}: checkpoint: {message}", file.display())
            }
            RenderError::Setting { name, message } => write!(f, "{name}: {message}"),
        }
    }
}

impl std::error::Error for RenderError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            RenderError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}
