//! The view a page looks through: the scene file's TOML with the `[camera]` keys, the
//! resolution and the samples per pixel the page changed, validated by the scene layer.
//!
//! A change is applied to the TOML document and the whole text parsed again by
//! [`obscura_render::parse_description`], so the explorer accepts exactly what a scene file
//! accepts and its errors name the same keys.
//!
//! The explorer's limits (film edges, pixels, spp) hold for what it renders. A page asking
//! for more is refused; a scene file asking for more is previewed at the limits (the film
//! scaled down in proportion, the spp capped), the view says so in [`View::clamps`], and the
//! saved scene file keeps the file's own values. A stereo pair renders two films, so its
//! eyes' pixels count twice, and its side-by-side preview is twice as wide as one eye.

use crate::error::ExploreError;
use crate::request::{keyed, parse_keyed};
use crate::stereo::{pair_layout, shown};
use obscura_render::{RenderError, SceneDescription, StereoLayout, parse_description};
use serde_json::Value as Json;
use std::path::{Path, PathBuf};
use toml::{Table, Value as Toml};

/// The largest edge of the image the explorer renders, in pixels (a stereo pair's side-by-side
/// preview is twice one eye's width).
pub const MAX_EDGE: u32 = 4096;
/// The most pixels the explorer renders (a 2048 x 2048 film; a stereo pair's two films count
/// together).
pub const MAX_PIXELS: u64 = 2048 * 2048;
/// The most samples per pixel the explorer renders.
pub const MAX_SPP: u32 = 65_536;

/// A change a page asks for. Every field is optional; `camera` keys set to `null` are removed
/// (so that switching the model can drop the old model's keys).
#[derive(Clone, Debug, Default)]
pub struct ViewChange {
    /// `[camera]` keys, as the scene format spells them, with JSON values.
    pub camera: serde_json::Map<String, Json>,
    /// `[film] resolution`.
    pub resolution: Option<[u32; 2]>,
    /// `[sampler] spp`.
    pub spp: Option<u32>,
}

impl ViewChange {
    /// Reads a change from its JSON text,
    /// `{"camera": {KEY: VALUE, ...}, "resolution": [W, H], "spp": N}`. An error names the
    /// key at fault as the scene format does (`camera.fov`, `film.resolution`,
    /// `sampler.spp`): a malformed value is [`ExploreError::Malformed`], a count beyond what
    /// the explorer renders [`ExploreError::Refused`].
    pub fn from_json(text: &[u8]) -> Result<ViewChange, ExploreError> {
        let value = parse_keyed(text).map_err(|(key, message)| {
            // The request's `resolution` and `spp` are the scene's `film.resolution` and
            // `sampler.spp`.
            let key = key.map(|k| match k.split('.').next() {
                Some("resolution") => "film.resolution".to_string(),
                Some("spp") => "sampler.spp".to_string(),
                _ => k,
            });
            keyed(key, message)
        })?;
        let Json::Object(fields) = value else {
            return Err(ExploreError::BadRequest(format!(
                "a change is a JSON object with camera, resolution or spp, got {value}"
            )));
        };
        let mut change = ViewChange::default();
        for (key, value) in fields {
            match key.as_str() {
                "camera" => match value {
                    Json::Object(keys) => change.camera = keys,
                    Json::Null => {}
                    other => {
                        return Err(ExploreError::Malformed {
                            key: "camera".into(),
                            message: format!(
                                "must be an object of [camera] keys and values, got {other}"
                            ),
                        });
                    }
                },
                "resolution" => {
                    change.resolution = match &value {
                        Json::Null => None,
                        Json::Array(edges) if edges.len() == 2 => Some([
                            count("film.resolution", &edges[0], MAX_EDGE)?,
                            count("film.resolution", &edges[1], MAX_EDGE)?,
                        ]),
                        other => {
                            return Err(ExploreError::Malformed {
                                key: "film.resolution".into(),
                                message: format!("must be [width, height] in pixels, got {other}"),
                            });
                        }
                    }
                }
                "spp" => {
                    change.spp = match &value {
                        Json::Null => None,
                        v => Some(count("sampler.spp", v, MAX_SPP)?),
                    }
                }
                other => {
                    return Err(ExploreError::Malformed {
                        key: other.into(),
                        message: "unknown field; a change has camera, resolution and spp".into(),
                    });
                }
            }
        }
        Ok(change)
    }
}

/// A count (pixels, samples) from JSON, at most `max`: a whole number >= 0 (malformed
/// otherwise); refused when too large for a u32 (smaller ones past `max`, and 0, are refused
/// by [`View::apply`]).
fn count(key: &str, value: &Json, max: u32) -> Result<u32, ExploreError> {
    let whole = match value {
        Json::Number(n) => n.as_u64().or_else(|| {
            n.as_f64()
                .filter(|v| *v >= 0.0 && v.fract() == 0.0 && *v < u64::MAX as f64)
                .map(|v| v as u64)
        }),
        _ => None,
    };
    let Some(whole) = whole else {
        return Err(ExploreError::Malformed {
            key: key.into(),
            message: format!("must be a whole number from 1 to {max}, got {value}"),
        });
    };
    u32::try_from(whole).map_err(|_| ExploreError::Refused {
        key: key.into(),
        message: format!("must be at most {max}, got {whole}"),
    })
}

/// A scene-file setting the explorer renders below the file's value, to stay within its
/// limits.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Clamp {
    /// The scene key: `film.resolution` or `sampler.spp`.
    pub key: &'static str,
    /// The scene file's value.
    pub file: Json,
    /// The value the explorer renders.
    pub rendered: Json,
    /// Says so, for the page.
    pub message: String,
}

/// A scene file and the view a page has made of it.
#[derive(Clone, Debug)]
pub struct View {
    /// The scene file's path (meshes and maps are found relative to it).
    path: PathBuf,
    /// The document, with the page's changes.
    doc: Table,
    /// The validated description of `doc`, as the explorer renders it: within its limits.
    description: SceneDescription,
    /// The scene file's settings that `description` renders below their values.
    clamps: Vec<Clamp>,
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

    /// Validates scene text as if read from `path`. A resolution or spp beyond the
    /// explorer's limits is previewed at the limits ([`View::clamps`]).
    pub fn parse(path: &Path, text: &str) -> Result<View, ExploreError> {
        let mut description = parse_description(path, text)?;
        let clamps = clamp_to_limits(&mut description);
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
            clamps,
        })
    }

    /// The validated description, as the explorer renders it (within its limits).
    pub fn description(&self) -> &SceneDescription {
        &self.description
    }

    /// The scene file's settings that the explorer renders below their values (none when
    /// the scene is within its limits).
    pub fn clamps(&self) -> &[Clamp] {
        &self.clamps
    }

    /// The view as a scene file (TOML text that `obscura check` accepts). A resolution or
    /// spp the explorer previews at its limits keeps the scene file's value here.
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
            // A single film's limits first, so absurd sizes never reach the parser; a stereo
            // pair's tighter ones once the new view is known to be one (below).
            check_resolution(w, h, Limits::of(None))?;
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
                    let v = toml_of(value).ok_or_else(|| ExploreError::Malformed {
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
        let mut description = parse_description(&self.path, &text).map_err(|e| match e {
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
        // What the page asked for is within the limits (checked here, for a pair too); what
        // the file asks for is previewed at them.
        if let Some([w, h]) = change.resolution {
            check_resolution(w, h, Limits::of_view(&description))?;
        }
        let clamps = clamp_to_limits(&mut description);
        Ok(View {
            path: self.path.clone(),
            doc,
            description,
            clamps,
        })
    }
}

/// The explorer's limits on one film of a view: for a stereo pair, each eye's, so that the
/// pair's preview image and both films together stay within [`MAX_EDGE`] and [`MAX_PIXELS`].
#[derive(Clone, Copy, Debug, PartialEq)]
struct Limits {
    /// The widest film.
    max_width: u32,
    /// The tallest film.
    max_height: u32,
    /// The most pixels in one film.
    max_pixels: u64,
    /// Whether the view is a stereo pair (for the messages).
    pair: bool,
}

impl Limits {
    /// The limits of a view whose stereo pair, if any, is previewed as `shown`: a single film
    /// has all of them; each eye of a pair half the pixels (two films), and half the width when
    /// the eyes are shown side by side (the preview is two films wide).
    fn of(shown: Option<StereoLayout>) -> Limits {
        let (max_width, max_pixels) = match shown {
            None => (MAX_EDGE, MAX_PIXELS),
            Some(StereoLayout::Anaglyph) => (MAX_EDGE, MAX_PIXELS / 2),
            Some(StereoLayout::SideBySide | StereoLayout::Separate) => {
                (MAX_EDGE / 2, MAX_PIXELS / 2)
            }
        };
        Limits {
            max_width,
            max_height: MAX_EDGE,
            max_pixels,
            pair: shown.is_some(),
        }
    }

    /// The limits of the view `d` renders.
    fn of_view(d: &SceneDescription) -> Limits {
        Limits::of(pair_layout(d).map(shown))
    }

    /// Whether the explorer renders a `w` x `h` film under these limits.
    fn admit(&self, w: u32, h: u32) -> bool {
        w >= 1
            && h >= 1
            && w <= self.max_width
            && h <= self.max_height
            && u64::from(w) * u64::from(h) <= self.max_pixels
    }

    /// The limits in words, for the messages.
    fn describe(&self) -> String {
        if self.pair {
            format!(
                "per eye of a stereo pair, which renders two films: width at most {}, height \
                 at most {}, at most {} pixels (the pair's preview at most {MAX_EDGE} pixels \
                 on an edge and {MAX_PIXELS} in all)",
                self.max_width, self.max_height, self.max_pixels
            )
        } else {
            format!("each edge at most {MAX_EDGE}, at most {MAX_PIXELS} pixels")
        }
    }
}

/// The largest film within `limits` with the shape of `w` x `h` (the shorter edge follows
/// the longer in proportion, rounded down, at least 1; an even height stays even, as the ODS
/// camera needs); `w` x `h` itself when within them.
fn preview_resolution(w: u32, h: u32, limits: Limits) -> [u32; 2] {
    if limits.admit(w, h) {
        return [w, h];
    }
    let (long, short) = (w.max(h), w.min(h));
    let follow = |l: u32| ((u64::from(l) * u64::from(short) / u64::from(long)) as u32).max(1);
    let shape = |l: u32| {
        if w >= h {
            [l, follow(l)]
        } else {
            [follow(l), l]
        }
    };
    // The longest edge that fits: both edges grow with `l`, so `fits` only turns false as
    // `l` grows; bisect. A 1 x 1 film always fits.
    let fits = |l: u32| {
        let [a, b] = shape(l);
        limits.admit(a, b)
    };
    let (mut lo, mut hi) = (1, long);
    while lo < hi {
        let mid = lo + (hi - lo).div_ceil(2);
        if fits(mid) {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    let [pw, mut ph] = shape(lo);
    if h.is_multiple_of(2) && !ph.is_multiple_of(2) {
        // One row less fits; one more where the film is a single row.
        ph = if ph > 1 { ph - 1 } else { 2 };
    }
    [pw, ph]
}

/// Brings the resolution and spp of `d` within the explorer's limits (the film scaled down in
/// proportion, the OpenCV intrinsics with it, so the picture keeps its framing; the spp
/// capped), saying what it changed.
fn clamp_to_limits(d: &mut SceneDescription) -> Vec<Clamp> {
    let mut clamps = Vec::new();
    let [w, h] = d.film.resolution;
    let limits = Limits::of_view(d);
    let [pw, ph] = preview_resolution(w, h, limits);
    if [pw, ph] != [w, h] {
        // OpenCV pixel centres are at integers: raster (u + 0.5) scales.
        if let Some(k) = &mut d.camera.intrinsics {
            let (sx, sy) = (f64::from(pw) / f64::from(w), f64::from(ph) / f64::from(h));
            k.fx *= sx;
            k.fy *= sy;
            k.cx = (k.cx + 0.5) * sx - 0.5;
            k.cy = (k.cy + 0.5) * sy - 0.5;
        }
        d.film.resolution = [pw, ph];
        clamps.push(Clamp {
            key: "film.resolution",
            file: serde_json::json!([w, h]),
            rendered: serde_json::json!([pw, ph]),
            message: format!(
                "film.resolution: the scene's {w} x {h} is previewed at {pw} x {ph}{}, the \
                 explorer's limit ({}); a saved scene keeps {w} x {h}",
                if limits.pair { " per eye" } else { "" },
                limits.describe()
            ),
        });
    }
    let spp = d.sampler.spp;
    if spp > MAX_SPP {
        d.sampler.spp = MAX_SPP;
        clamps.push(Clamp {
            key: "sampler.spp",
            file: serde_json::json!(spp),
            rendered: serde_json::json!(MAX_SPP),
            message: format!(
                "sampler.spp: the scene's {spp} is previewed at {MAX_SPP}, the explorer's \
                 limit; a saved scene keeps {spp}"
            ),
        });
    }
    clamps
}

/// Refuses films a page asks for that are too large to explore interactively.
fn check_resolution(w: u32, h: u32, limits: Limits) -> Result<(), ExploreError> {
    if !limits.admit(w, h) {
        return Err(ExploreError::Refused {
            key: "film.resolution".into(),
            message: format!(
                "{w} x {h} is outside what the explorer renders: each edge at least 1, {}",
                limits.describe()
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
        ViewChange::from_json(json.as_bytes()).unwrap()
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

    /// The scene text with its film and spp replaced.
    fn scene_with(resolution: [u32; 2], spp: u32) -> String {
        SCENE
            .replace(
                "resolution = [32, 24]",
                &format!("resolution = [{}, {}]", resolution[0], resolution[1]),
            )
            .replace("spp = 4", &format!("spp = {spp}"))
    }

    #[test]
    fn a_scene_file_beyond_the_limits_is_previewed_at_them() {
        let v = View::parse(
            Path::new("test.toml"),
            &scene_with([10_000, 10_000], 10_000_000),
        )
        .unwrap();
        assert_eq!(v.description().film.resolution, [2048, 2048]);
        assert_eq!(v.description().sampler.spp, MAX_SPP);
        let keys: Vec<_> = v.clamps().iter().map(|c| c.key).collect();
        assert_eq!(keys, ["film.resolution", "sampler.spp"]);
        assert_eq!(v.clamps()[0].file, serde_json::json!([10_000, 10_000]));
        assert_eq!(v.clamps()[0].rendered, serde_json::json!([2048, 2048]));
        assert!(v.clamps()[0].message.contains("2048 x 2048"));
        // A saved scene keeps the file's own values.
        let saved = parse_description(Path::new("saved.toml"), &v.to_toml()).unwrap();
        assert_eq!(saved.film.resolution, [10_000, 10_000]);
        assert_eq!(saved.sampler.spp, 10_000_000);
        // A camera change keeps the preview; a page's own resolution and spp end it.
        let moved = v.apply(&change(r#"{"camera": {"fov": 30}}"#)).unwrap();
        assert_eq!(moved.description().film.resolution, [2048, 2048]);
        assert_eq!(moved.clamps(), v.clamps());
        let own = v
            .apply(&change(r#"{"resolution": [64, 48], "spp": 8}"#))
            .unwrap();
        assert_eq!(own.description().film.resolution, [64, 48]);
        assert!(own.clamps().is_empty());
        // Within the limits, nothing changes.
        assert!(view().clamps().is_empty());
        assert_eq!(view().description().film.resolution, [32, 24]);
    }

    #[test]
    fn preview_resolutions_by_hand() {
        for ((w, h), want) in [
            ((10_000, 10_000), [2048, 2048]),
            ((4096, 1024), [4096, 1024]),
            ((2048, 2049), [2047, 2048]),
            // 2730 x 1535 is the largest 16:9 film; the height stays even.
            ((3840, 2160), [2730, 1534]),
            ((5000, 10), [4096, 8]),
            ((10, 5000), [8, 4096]),
            ((100_000, 2), [4096, 2]),
            ((100_000, 1), [4096, 1]),
        ] {
            assert_eq!(
                preview_resolution(w, h, Limits::of(None)),
                want,
                "{w} x {h}"
            );
        }
        // A stereo pair: each eye at most 2048 * 2048 / 2 = 2097152 pixels, and at most 2048
        // wide when the eyes are side by side.
        let (sbs, anaglyph) = (
            Limits::of(Some(StereoLayout::SideBySide)),
            Limits::of(Some(StereoLayout::Anaglyph)),
        );
        assert_eq!(Limits::of(Some(StereoLayout::Separate)), sbs);
        for ((w, h), limits, want) in [
            // 1448^2 = 2096704 fits, 1449^2 = 2099601 does not.
            ((2048, 2048), sbs, [1448, 1448]),
            ((2048, 2048), anaglyph, [1448, 1448]),
            // Side by side: the width binds (2048 * 512 is only 1048576 pixels).
            ((4096, 1024), sbs, [2048, 512]),
            // Anaglyph: the pixels bind; 2896 * 724 = 2096704, 2897 * 724 = 2097428.
            ((4096, 1024), anaglyph, [2896, 724]),
            // 1931 * floor(1931 * 9 / 16) = 1931 * 1086 = 2097066; 1932 * 1086 = 2098152.
            ((3840, 2160), sbs, [1931, 1086]),
            // A 1080p pair fits either way.
            ((1920, 1080), sbs, [1920, 1080]),
            ((1920, 1080), anaglyph, [1920, 1080]),
        ] {
            assert_eq!(
                preview_resolution(w, h, limits),
                want,
                "{w} x {h}, {limits:?}"
            );
        }
    }

    /// The test scene as a perspective stereo pair laid out as `layout`.
    fn stereo_scene(resolution: [u32; 2], layout: &str) -> String {
        format!(
            "{}\n[camera.stereo]\nconvergence = 5.0\nlayout = \"{layout}\"\n",
            scene_with(resolution, 4)
        )
    }

    #[test]
    fn a_stereo_pair_counts_twice_against_the_pixel_limit() {
        // The file's film is previewed at the pair's limit, and says so per eye.
        let v = View::parse(
            Path::new("test.toml"),
            &stereo_scene([2048, 2048], "side_by_side"),
        )
        .unwrap();
        assert_eq!(v.description().film.resolution, [1448, 1448]);
        let clamp = &v.clamps()[0];
        assert_eq!(clamp.key, "film.resolution");
        assert!(
            clamp.message.contains("1448 x 1448 per eye") && clamp.message.contains("stereo"),
            "{}",
            clamp.message
        );
        // The same film without the pair is within the limits.
        let mono = View::parse(Path::new("test.toml"), &scene_with([2048, 2048], 4)).unwrap();
        assert!(mono.clamps().is_empty());
        // A page asking a pair for a film whose two eyes exceed the limits is refused, also
        // when it turns the pair on in the same change...
        let pair =
            View::parse(Path::new("test.toml"), &stereo_scene([64, 48], "anaglyph")).unwrap();
        for (from, json) in [
            (&pair, r#"{"resolution": [2048, 2048]}"#),
            (&pair, r#"{"resolution": [1449, 1449]}"#),
            (
                &mono,
                r#"{"resolution": [2048, 2048], "camera": {"stereo": {"convergence": 5}}}"#,
            ),
        ] {
            let e = from.apply(&change(json)).unwrap_err();
            assert!(matches!(e, ExploreError::Refused { .. }), "{json}: {e}");
            assert_eq!(e.key().as_deref(), Some("film.resolution"), "{e}");
            assert!(e.to_string().contains("stereo pair"), "{e}");
        }
        assert_eq!(
            pair.apply(&change(r#"{"resolution": [1448, 1448]}"#))
                .unwrap()
                .description()
                .film
                .resolution,
            [1448, 1448]
        );
        // ...side by side, a pair is at most 2048 wide per eye; an anaglyph's eyes overlap.
        let wide = r#"{"resolution": [3000, 100]}"#;
        assert!(pair.apply(&change(wide)).is_ok());
        let sbs = pair
            .apply(&change(
                r#"{"camera": {"stereo": {"convergence": 5, "layout": "separate"}}}"#,
            ))
            .unwrap();
        assert!(sbs.apply(&change(wide)).is_err());
        // A camera change that turns a pair on over a large film previews it at the limit.
        let turned = mono
            .apply(&change(r#"{"camera": {"stereo": {"convergence": 5}}}"#))
            .unwrap();
        assert_eq!(turned.description().film.resolution, [1448, 1448]);
        assert_eq!(turned.clamps().len(), 1);
    }

    #[test]
    fn a_previewed_opencv_camera_keeps_its_framing() {
        let text = SCENE
            .replace("resolution = [32, 24]", "resolution = [8000, 6000]")
            .replace(
                "fov = 40.0",
                "type = \"opencv\"\nfx = 5000.0\nfy = 5200.0\ncx = 4100.0\ncy = 2900.0\n\
             distortion = [0.05, -0.01, 0.001, 0.002]",
            );
        let file = parse_description(Path::new("test.toml"), &text).unwrap();
        let v = View::parse(Path::new("test.toml"), &text).unwrap();
        let [pw, ph] = v.description().film.resolution;
        assert_eq!([pw, ph], preview_resolution(8000, 6000, Limits::of(None)));
        let (sx, sy) = (pw as f32 / 8000.0, ph as f32 / 6000.0);
        let (full, preview) = (
            obscura_render::camera_of(&file).unwrap(),
            obscura_render::camera_of(v.description()).unwrap(),
        );
        let direction = |camera: &obscura_camera::AnyCamera, x: f32, y: f32| {
            use obscura_camera::Camera;
            let p = obscura_space::Point2::<obscura_space::Raster>::new(x, y);
            let d = camera
                .generate_ray(&obscura_camera::CameraSample::at(p))
                .unwrap()
                .ray
                .direction;
            glam::Vec3::new(d.x, d.y, d.z).normalize()
        };
        for (x, y) in [
            (4100.5, 2900.5),
            (0.0, 0.0),
            (7999.0, 10.0),
            (1234.5, 5678.0),
        ] {
            let a = direction(&full, x, y);
            let b = direction(&preview, x * sx, y * sy);
            // A tenth of a full-size pixel's angle (f32 directions).
            assert!(
                (a - b).length() < 2e-5,
                "raster ({x}, {y}): {a} against {b}"
            );
        }
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

        /// A preview film is within the limits (a single film's or a stereo pair's), as large
        /// as they allow with the file's shape, and the file's own film when that is within
        /// them.
        #[test]
        fn preview_resolution_fits_and_keeps_the_shape(
            w in 1u32..200_000,
            h in 1u32..200_000,
            pair in prop::sample::select(vec![
                None,
                Some(StereoLayout::SideBySide),
                Some(StereoLayout::Anaglyph),
            ]),
        ) {
            let limits = Limits::of(pair);
            let [pw, ph] = preview_resolution(w, h, limits);
            prop_assert!(limits.admit(pw, ph), "{} x {}", pw, ph);
            if limits.admit(w, h) {
                prop_assert_eq!([pw, ph], [w, h]);
            } else {
                let (long, short, plong, pshort) =
                    if w >= h { (w, h, pw, ph) } else { (h, w, ph, pw) };
                // The shorter edge follows the longer, give or take the even-height row.
                let follow = (u64::from(plong) * u64::from(short) / u64::from(long)).max(1);
                prop_assert!(u64::from(pshort).abs_diff(follow) <= 1, "{} x {}", pw, ph);
                // One pixel more along the longer edge would not fit (two where the longer
                // edge is an even height, which may have given up one to stay even).
                let next = if w < h && h % 2 == 0 { plong + 2 } else { plong + 1 };
                let next_short =
                    (u64::from(next) * u64::from(short) / u64::from(long)).max(1) as u32;
                let [nw, nh] = if w >= h { [next, next_short] } else { [next_short, next] };
                prop_assert!(next > long || !limits.admit(nw, nh), "{} x {}", pw, ph);
            }
            if h % 2 == 0 {
                prop_assert_eq!(ph % 2, 0);
            }
        }
    }
}
