//! Mitsuba 3 XML scenes.

use crate::error::ImportError;
use crate::scene::Imported;
use std::path::Path;

/// Reads a Mitsuba 3 XML scene file.
pub fn import_mitsuba(path: &Path) -> Result<Imported, ImportError> {
    let text = std::fs::read_to_string(path).map_err(|source| ImportError::Io {
        file: path.to_path_buf(),
        action: "cannot read",
        source,
    })?;
    parse_mitsuba(path, &text)
}

/// Imports Mitsuba 3 XML text; `path` names it in messages and anchors relative files.
pub fn parse_mitsuba(path: &Path, _text: &str) -> Result<Imported, ImportError> {
    Err(ImportError::Scene {
        file: path.to_path_buf(),
        line: None,
        message: "Mitsuba 3 import is not implemented yet".into(),
    })
}
