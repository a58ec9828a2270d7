//! Other renderers' scenes for Obscura: pbrt-v4 scene files and Mitsuba 3 XML, with their PLY
//! meshes, read into the renderer's own scene description.
//!
//! - [`import`] reads a `.pbrt` or `.xml` file (by its extension) into an [`Imported`] scene;
//! - [`Imported::description`] gives the renderer's [`SceneDescription`](obscura_render::SceneDescription),
//!   its meshes held in memory, ready for [`RenderScene::build`](obscura_render::RenderScene::build);
//! - [`Imported::write`] writes the equivalent scene-format TOML and its meshes as OBJ files
//!   (`obscura convert`).
//!
//! The decision to know: an import produces scene-format TOML text, which the renderer then
//! validates exactly as it validates a hand-written scene, so there is one owner of every
//! check; errors it finds are moved back to the imported file's line. The camera goes across
//! as its exact world-from-camera matrix (`camera.pose`), which keeps pbrt's mirrored
//! left-handed look-at and Mitsuba's conventions as they are. What cannot be mapped is a
//! warning naming the file, the line and the directive, or an error where the image would be
//! wrong (docs/import.md lists both).
//!
//! Not for: rendering (obscura-render), nor writing pbrt or Mitsuba files.
//!
//! ```
//! let pbrt = r#"
//!     LookAt 0 0 5  0 0 0  0 1 0
//!     Camera "perspective" "float fov" 40
//!     Film "rgb" "integer xresolution" 32 "integer yresolution" 24
//!     WorldBegin
//!     Shape "sphere" "float radius" 1
//! "#;
//! let imported = obscura_import::parse_pbrt("inline.pbrt".as_ref(), pbrt)?;
//! let d = imported.description()?;
//! assert_eq!(d.film.resolution, [32, 24]);
//! assert_eq!(d.camera.fov, 40.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

mod error;
mod mitsuba;
mod pbrt;
mod ply;
mod scene;

pub use error::{ImportError, Location};
pub use mitsuba::{import_mitsuba, parse_mitsuba};
pub use pbrt::{import_pbrt, parse_pbrt};
pub use ply::parse_ply;
pub use scene::Imported;

use std::path::Path;

/// Whether a path names a scene this crate imports (`.pbrt`, or `.xml` for Mitsuba 3).
pub fn is_importable(path: &Path) -> bool {
    matches!(
        path.extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref(),
        Some("pbrt" | "xml")
    )
}

/// Reads any scene file the renderer takes: the scene format's TOML as it is, a `.pbrt` or
/// `.xml` through [`import`]. The [`Imported`] scene, when there is one, holds the import's
/// warnings for the caller to show and [`Imported::locate`] for the renderer's later errors.
pub fn load(
    path: &Path,
) -> Result<(obscura_render::SceneDescription, Option<Imported>), obscura_render::RenderError> {
    if !is_importable(path) {
        return Ok((obscura_render::load_description(path)?, None));
    }
    let imported = import(path)?;
    Ok((imported.description()?, Some(imported)))
}

/// Imports a pbrt-v4 (`.pbrt`) or Mitsuba 3 (`.xml`) scene, by the file's extension.
pub fn import(path: &Path) -> Result<Imported, ImportError> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("xml") => import_mitsuba(path),
        Some("pbrt") => import_pbrt(path),
        _ => Err(ImportError::Scene {
            file: path.to_path_buf(),
            line: None,
            message: "not a scene this importer reads: expected a .pbrt or .xml file".into(),
        }),
    }
}
