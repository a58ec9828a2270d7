//! The view a page looks through: the scene file's TOML with the `[camera]` keys, the
//! resolution and the samples per pixel the page changed, validated by the scene layer.
//!
//! A change is applied to the TOML document and the whole text parsed again by
//! [`obscura_render::parse_description`], so the explorer accepts exactly what a scene file
//! accepts and its errors name the same keys.

use crate::error::ExploreError;
use obscura_render::{RenderError, SceneDescription, parse_description};
use serde::Deserialize;
use serde_json::Value as Json;
use std::path::{Path, PathBuf};
use toml::{Table, Value as Toml};

/// The largest film edge a page may ask for, in pixels.
pub const MAX_EDGE: u32 = 4096;
/// The most pixels a page may ask for (a 2048 x 2048 film).
pub const MAX_PIXELS: u64 = 2048 * 2048;
/// The most samples per pixel a page may ask for.
pub const MAX_SPP: u32 = 65_536;

/// A change a page asks for. Every field is optional; `camera` keys set to `null` are removed
/// (so that switching the model can drop the old model's keys).
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViewChange {
    /// `[camera]` keys, as the scene format spells them, with JSON values.
    #[serde(default)]
    pub camera: serde_json::Map<String, Json>,
    /// `[film] resolution`.
    #[serde(default)]
    pub resolution: Option<[u32; 2]>,
    /// `[sampler] spp`.
    #[serde(default)]
    pub spp: Option<u32>,
}

/// A scene file and the view a page has made of it.
#[derive(Clone, Debug)]
pub struct View {
    /// The scene file's path (meshes and maps are found relative to it).
    path: PathBuf,
    /// The document, with the page's changes.
    doc: Table,
    /// The validated description of `doc`.
    description: SceneDescription,
}

impl View {
    /// Reads and validates the scene file at `path`.
    pub fn load(path: &Path) -> Result<View, ExploreError> {
        let text = std::fs::read_to_string(path).map_err(|source| RenderError::Io {
            file: path.to_path_buf(),
            action: "cannot read",
            source,
        })?;
        View::parse(path, &text)
    }

    /// Validates scene text as if read from `path`.
    pub fn parse(path: &Path, text: &str) -> Result<View, ExploreError> {
        let description = parse_description(path, text)?;
        let doc: Table = text
            .parse()
            .map_err(|e: toml::de::Error| RenderError::Scene {
                file: path.to_path_buf(),
                line: None,
                key: None,
                message: e.to_string(),
            })?;
        Ok(View {
            path: path.to_path_buf(),
            doc,
            description,
        })
    }

    /// The validated description.
    pub fn description(&self) -> &SceneDescription {
        &self.description
    }

    /// The view as a scene file (TOML text that `obscura check` accepts).
    pub fn to_toml(&self) -> String {
        // Serialising a table of TOML values cannot fail.
        toml::to_string(&self.doc).unwrap_or_default()
    }

    /// The `[camera]` table as JSON (missing keys take the format's defaults).
    pub fn camera_json(&self) -> Json {
        let camera = self
            .doc
            .get("camera")
            .cloned()
            .unwrap_or(Toml::Table(Table::new()));
        serde_json::to_value(camera).unwrap_or(Json::Null)
    }

    /// The view with `change` applied, validated; `self` is untouched when it fails.
    pub fn apply(&self, change: &ViewChange) -> Result<View, ExploreError> {
        let mut doc = self.doc.clone();
        if let Some([w, h]) = change.resolution {
            check_resolution(w, h)?;
            let film = table_mut(&mut doc, "film");
            film.insert(
                "resolution".into(),
                Toml::Array(vec![
                    Toml::Integer(i64::from(w)),
                    Toml::Integer(i64::from(h)),
                ]),
            );
            // A crop window or screen window written for the old shape may no longer fit;
            // the scene layer says so if it does not.
        }
        if let Some(spp) = change.spp {
            if spp == 0 || spp > MAX_SPP {
                return Err(ExploreError::Refused {
                    key: "sampler.spp".into(),
                    message: format!("must be in 1..={MAX_SPP}, got {spp}"),
                });
            }
            table_mut(&mut doc, "sampler").insert("spp".into(), Toml::Integer(i64::from(spp)));
        }
        if !change.camera.is_empty() {
            let camera = table_mut(&mut doc, "camera");
            for (key, value) in &change.camera {
                if value.is_null() {
                    camera.remove(key);
                } else {
                    let v = toml_of(value).ok_or_else(|| ExploreError::Refused {
                        key: format!("camera.{key}"),
                        message: format!("not a scene-file value: {value}"),
                    })?;
                    camera.insert(key.clone(), v);
                }
            }
        }
        let text = toml::to_string(&doc).map_err(|e| ExploreError::Refused {
            key: "camera".into(),
            message: e.to_string(),
        })?;
        // The line numbers would be those of the regenerated text, not of the user's file.
        let description = parse_description(&self.path, &text).map_err(|e| match e {
            RenderError::Scene {
                file, key, message, ..
            } => RenderError::Scene {
                file,
                line: None,
                key,
                message,
            },
            other => other,
        })?;
        let [w, h] = description.film.resolution;
        check_resolution(w, h)?;
        if description.sampler.spp > MAX_SPP {
            return Err(ExploreError::Refused {
                key: "sampler.spp".into(),
                message: format!("must be at most {MAX_SPP}, got {}", description.sampler.spp),
            });
        }
        Ok(View {
            path: self.path.clone(),
            doc,
            description,
        })
    }
}

/// Refuses films too large to explore interactively.
fn check_resolution(w: u32, h: u32) -> Result<(), ExploreError> {
    if w == 0 || h == 0 || w > MAX_EDGE || h > MAX_EDGE || u64::from(w) * u64::from(h) > MAX_PIXELS
    {
        return Err(ExploreError::Refused {
            key: "film.resolution".into(),
            message: format!(
                "{w} x {h} is outside what the explorer renders: each edge 1..={MAX_EDGE}, \
                 at most {MAX_PIXELS} pixels"
            ),
        });
    }
    Ok(())
}

/// The sub-table `name` of `doc`, made when missing (or when something else stood there).
fn table_mut<'a>(doc: &'a mut Table, name: &str) -> &'a mut Table {
    let entry = doc
        .entry(name.to_string())
        .or_insert_with(|| Toml::Table(Table::new()));
    if !entry.is_table() {
        *entry = Toml::Table(Table::new());
    }
    match entry {
        Toml::Table(t) => t,
        _ => unreachable!("made a table just above"),
    }
}

/// The TOML value of a JSON value; None for null and numbers TOML cannot hold.
fn toml_of(value: &Json) -> Option<Toml> {
    Some(match value {
        Json::Null => return None,
        Json::Bool(b) => Toml::Boolean(*b),
        Json::Number(n) => match n.as_i64() {
            Some(i) => Toml::Integer(i),
            None => Toml::Float(n.as_f64()?),
        },
        Json::String(s) => Toml::String(s.clone()),
        Json::Array(a) => Toml::Array(a.iter().map(toml_of).collect::<Option<_>>()?),
        Json::Object(o) => Toml::Table(
            o.iter()
                .map(|(k, v)| Some((k.clone(), toml_of(v)?)))
                .collect::<Option<_>>()?,
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const SCENE: &str = r#"
[film]
resolution = [32, 24]
[sampler]
spp = 4
[integrator]
type = "distance"
[camera]
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
fov = 40.0
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
"#;

    fn view() -> View {
        View::parse(Path::new("test.toml"), SCENE).unwrap()
    }

    fn change(json: &str) -> ViewChange {
        serde_json::from_str(json).unwrap()
    }

    #[test]
    fn a_camera_key_reaches_the_description() {
        let v = view()
            .apply(&change(
                r#"{"camera": {"lens_radius": 0.25, "focal_distance": 4}}"#,
            ))
            .unwrap();
        assert_eq!(v.description().camera.lens.radius, 0.25);
        assert_eq!(v.description().camera.lens.focal_distance, 4.0);
    }

    #[test]
    fn a_bad_key_is_refused_with_its_name_and_the_view_is_kept() {
        let v = view();
        let e = v
            .apply(&change(r#"{"camera": {"fov": 400.0}}"#))
            .unwrap_err();
        assert_eq!(e.key().as_deref(), Some("camera.fov"), "{e}");
        // No line number: it would count lines of the regenerated text, not of the file.
        assert!(
            matches!(
                e,
                ExploreError::Render(RenderError::Scene { line: None, .. })
            ),
            "{e:?}"
        );
        let e = v
            .apply(&change(r#"{"camera": {"no_such_key": 1}}"#))
            .unwrap_err();
        assert!(e.to_string().contains("no_such_key"), "{e}");
        assert_eq!(v.description().camera.fov, 40.0);
    }

    #[test]
    fn absurd_sizes_are_refused() {
        let v = view();
        for json in [
            r#"{"resolution": [100000, 10]}"#,
            r#"{"resolution": [0, 10]}"#,
            r#"{"resolution": [4096, 4096]}"#,
            r#"{"spp": 0}"#,
            r#"{"spp": 1000000}"#,
        ] {
            assert!(matches!(
                v.apply(&change(json)),
                Err(ExploreError::Refused { .. })
            ));
        }
    }

    #[test]
    fn null_removes_a_key() {
        let v = view()
            .apply(&change(r#"{"camera": {"fov": 60.0}}"#))
            .unwrap()
            .apply(&change(r#"{"camera": {"fov": null}}"#))
            .unwrap();
        // The same as a file that never had the key.
        let without =
            View::parse(Path::new("test.toml"), &SCENE.replace("fov = 40.0", "")).unwrap();
        assert_eq!(v.description().camera.fov, without.description().camera.fov);
        assert_ne!(v.description().camera.fov, 60.0);
    }

    proptest! {
        /// The saved scene file parses back to the same description.
        #[test]
        fn saved_view_round_trips(radius in 0.0f32..2.0, focus in 0.1f32..100.0, fov in 1.0f32..170.0) {
            let json = format!(
                r#"{{"camera": {{"lens_radius": {radius}, "focal_distance": {focus}, "fov": {fov}}}}}"#
            );
            let v = view().apply(&change(&json)).unwrap();
            let again = View::parse(Path::new("test.toml"), &v.to_toml()).unwrap();
            prop_assert_eq!(again.description().camera.lens.radius, radius);
            prop_assert_eq!(again.description().camera.lens.focal_distance, focus);
            prop_assert_eq!(again.description().camera.fov, fov);
        }
    }
}
