//! The renderer's one error type.

use std::path::{Path, PathBuf};

/// Why a scene could not be loaded or rendered, or an image not written.
///
/// Every message stands alone on one line: it names the file, and where known the key and line,
/// e.g. `scenes/dof.toml:14: camera.fov: must be in (0, 180) degrees, got 180`.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The scene file (or a file it names) is wrong.
    #[error("{}", located(file, *line, key.as_deref(), message))]
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
    /// The image could not be encoded.
    #[error("{}: {message}", file.display())]
    Encode {
        /// The output file.
        file: PathBuf,
        /// The encoder's message.
        message: String,
    },
    /// A checkpoint file is corrupt, truncated, or belongs to another render.
    #[error("{}: checkpoint: {message}", file.display())]
    Checkpoint {
        /// The checkpoint file.
        file: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A slice's partial file is corrupt, truncated, or does not belong with the others.
    #[error("{}: partial: {message}", file.display())]
    Partial {
        /// The partial file.
        file: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A render setting from the command line is invalid.
    #[error("{name}: {message}")]
    Setting {
        /// The setting, e.g. `--spp`.
        name: &'static str,
        /// What is wrong.
        message: String,
    },
}

impl RenderError {
    /// A scene error at `key` (a path such as `camera.fov`), with the key's line found in the
    /// file's `source` text.
    pub(crate) fn at_key(file: &Path, source: &str, key: &str, message: impl Into<String>) -> Self {
        RenderError::Scene {
            file: file.to_path_buf(),
            line: crate::locate::line_of_key(source, key),
            key: Some(key.to_string()),
            message: message.into(),
        }
    }
}

/// `file[:line][: key]: message`, the one-line form of a scene error.
fn located(file: &Path, line: Option<usize>, key: Option<&str>, message: &str) -> String {
    let mut out = file.display().to_string();
    if let Some(line) = line {
        out += &format!(":{line}");
    }
    if let Some(key) = key {
        out += &format!(": {key}");
    }
    out + ": " + message
}
