//! The scene file: parsing (serde + toml) and validation into a [`SceneDescription`].
//!
//! Parsing is strict: unknown keys are errors, every number is checked for NaN and range, and
//! every error names the file, the key and the line. Nothing here builds cameras or BVHs; see
//! [`crate::build`] for that.

use crate::error::RenderError;
use crate::locate::{key_at_line, line_of_key, line_of_offset};
use obscura_sample::SamplerKind;
use obscura_space::{Object, SpaceError, Transform, World};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

type V3 = [f32; 3];

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    film: RawFilm,
    #[serde(default)]
    sampler: RawSampler,
    #[serde(default)]
    integrator: RawIntegrator,
    camera: RawCamera,
    #[serde(default)]
    materials: BTreeMap<String, RawMaterial>,
    #[serde(default)]
    shapes: Vec<RawShape>,
    #[serde(default)]
    lights: Vec<RawLight>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFilm {
    resolution: [u32; 2],
    filter: Option<toml::Value>,
    crop: Option<[f32; 4]>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawSampler {
    #[serde(rename = "type")]
    kind: Option<String>,
    spp: Option<u32>,
    seed: Option<u64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawIntegrator {
    #[serde(rename = "type")]
    kind: Option<String>,
    max_depth: Option<u32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCamera {
    #[serde(rename = "type")]
    kind: Option<String>,
    eye: Option<V3>,
    target: Option<V3>,
    up: Option<V3>,
    fov: Option<f32>,
    fov_axis: Option<String>,
    screen_window: Option<[f32; 4]>,
    near: Option<f32>,
    far: Option<f32>,
    lens_radius: Option<f32>,
    focal_distance: Option<f32>,
    aperture_blades: Option<u32>,
    aperture_rotation: Option<f32>,
    shutter: Option<[f32; 2]>,
    eye_end: Option<V3>,
    target_end: Option<V3>,
    up_end: Option<V3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMaterial {
    #[serde(rename = "type")]
    kind: String,
    reflectance: Option<V3>,
    ior: Option<f32>,
    roughness: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawShape {
    #[serde(rename = "type")]
    kind: String,
    center: Option<V3>,
    radius: Option<f32>,
    origin: Option<V3>,
    edge_u: Option<V3>,
    edge_v: Option<V3>,
    file: Option<String>,
    material: Option<String>,
    emission: Option<V3>,
    transform: Option<Vec<RawOp>>,
    transform_end: Option<Vec<RawOp>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOp {
    scale: Option<V3>,
    rotate: Option<[f32; 4]>,
    translate: Option<V3>,
    matrix: Option<[f32; 16]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLight {
    #[serde(rename = "type")]
    kind: String,
    position: Option<V3>,
    intensity: Option<V3>,
    direction: Option<V3>,
    irradiance: Option<V3>,
    radiance: Option<V3>,
    file: Option<String>,
    transform: Option<Vec<RawOp>>,
}

/// A validated scene file: every value checked, paths resolved against the file's folder.
#[derive(Clone, Debug)]
pub struct SceneDescription {
    /// The scene file itself.
    pub file: PathBuf,
    /// `[film]`.
    pub film: FilmSettings,
    /// `[sampler]`.
    pub sampler: SamplerSettings,
    /// `[integrator]`.
    pub integrator: IntegratorSettings,
    /// `[camera]`.
    pub camera: CameraSettings,
    /// `[materials.NAME]`, in name order; shapes refer to them by index.
    pub materials: Vec<(String, MaterialSettings)>,
    /// `[[shapes]]`, in file order.
    pub shapes: Vec<ShapeSettings>,
    /// `[[lights]]`, in file order.
    pub lights: Vec<LightSettings>,
    /// Keys that were given but that the chosen model ignores (e.g. `fov` on an orthographic
    /// camera): worth a note to the user, not an error.
    pub ignored: Vec<String>,
}

/// `[film]`: the image's size and reconstruction filter.
#[derive(Clone, Debug)]
pub struct FilmSettings {
    /// Width and height in pixels, each >= 1.
    pub resolution: [u32; 2],
    /// The reconstruction filter.
    pub filter: FilterSettings,
    /// Optional crop window in NDC: x0, x1, y0, y1 (an extension of the format).
    pub crop: Option<[f32; 4]>,
}

/// A reconstruction filter and its radius in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FilterSettings {
    /// Constant over [-r, r]^2; default radius 0.5 (each sample counts for its own pixel only).
    Box {
        /// Radius in pixels.
        radius: f32,
    },
    /// A tent falling linearly to zero at the radius; default radius 1.
    Triangle {
        /// Radius in pixels.
        radius: f32,
    },
    /// A Gaussian with standard deviation radius / 3, shifted to zero at the radius; default 1.5.
    Gaussian {
        /// Radius in pixels.
        radius: f32,
    },
    /// Mitchell-Netravali with B = C = 1/3; default radius 2.
    Mitchell {
        /// Radius in pixels.
        radius: f32,
    },
}

impl FilterSettings {
    /// The filter's radius in pixels.
    pub fn radius(&self) -> f32 {
        match *self {
            FilterSettings::Box { radius }
            | FilterSettings::Triangle { radius }
            | FilterSettings::Gaussian { radius }
            | FilterSettings::Mitchell { radius } => radius,
        }
    }
    /// The filter's name in the scene format.
    pub fn name(&self) -> &'static str {
        match self {
            FilterSettings::Box { .. } => "box",
            FilterSettings::Triangle { .. } => "triangle",
            FilterSettings::Gaussian { .. } => "gaussian",
            FilterSettings::Mitchell { .. } => "mitchell",
        }
    }
}

/// `[sampler]`.
#[derive(Clone, Copy, Debug)]
pub struct SamplerSettings {
    /// Which sampler.
    pub kind: SamplerKind,
    /// Samples per pixel, >= 1.
    pub spp: u32,
    /// The seed every sample value derives from.
    pub seed: u64,
}

/// What the integrator computes per pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    /// Path-traced radiance.
    Path,
    /// Camera-space z of the first hit.
    Depth,
    /// Distance from the ray's origin to the first hit.
    Distance,
    /// World-space position of the first hit.
    Position,
    /// World-space shading normal of the first hit, facing the viewer.
    Normal,
    /// The material's reflectance at the first hit.
    Albedo,
}

impl IntegratorKind {
    /// Every integrator, in the order the scene format lists them.
    pub const ALL: [IntegratorKind; 6] = [
        IntegratorKind::Path,
        IntegratorKind::Depth,
        IntegratorKind::Distance,
        IntegratorKind::Position,
        IntegratorKind::Normal,
        IntegratorKind::Albedo,
    ];
    /// The scene-format name.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Path => "path",
            IntegratorKind::Depth => "depth",
            IntegratorKind::Distance => "distance",
            IntegratorKind::Position => "position",
            IntegratorKind::Normal => "normal",
            IntegratorKind::Albedo => "albedo",
        }
    }
    /// Parses a scene-format name.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// `[integrator]`.
#[derive(Clone, Copy, Debug)]
pub struct IntegratorSettings {
    /// Which integrator.
    pub kind: IntegratorKind,
    /// Longest path (path integrator only), >= 1.
    pub max_depth: u32,
}

/// Which camera model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraKind {
    /// Perspective projection (with an optional thin lens).
    Perspective,
    /// Orthographic projection (with an optional thin lens).
    Orthographic,
    /// Equirectangular 360 x 180 degree environment camera.
    Environment,
}

/// A look-at pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LookAt {
    /// The camera's position.
    pub eye: V3,
    /// A point the camera looks at.
    pub target: V3,
    /// Which way is up.
    pub up: V3,
}

/// `[camera]`, validated.
#[derive(Clone, Debug)]
pub struct CameraSettings {
    /// The model.
    pub kind: CameraKind,
    /// The pose at shutter open.
    pub start: LookAt,
    /// The pose at shutter close, when the camera moves.
    pub end: Option<LookAt>,
    /// Full field of view in degrees along `fov_axis` (perspective).
    pub fov: f32,
    /// `smaller`, `larger`, `x`, `y` or `diagonal`.
    pub fov_axis: String,
    /// Optional screen window: xmin, xmax, ymin, ymax.
    pub screen_window: Option<[f32; 4]>,
    /// Near clip.
    pub near: f32,
    /// Far clip.
    pub far: f32,
    /// Thin-lens radius; 0 for a pinhole.
    pub lens_radius: f32,
    /// Camera-space z of the plane in focus.
    pub focal_distance: f32,
    /// Aperture blades (0 = round).
    pub aperture_blades: u32,
    /// Rotation of a polygonal aperture, degrees.
    pub aperture_rotation: f32,
    /// Shutter open and close times.
    pub shutter: [f32; 2],
}

/// A material, validated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialSettings {
    /// Lambertian.
    Diffuse {
        /// Albedo per channel in [0, 1].
        reflectance: V3,
    },
    /// Perfect specular reflector.
    Mirror {
        /// Reflectance per channel in [0, 1].
        reflectance: V3,
    },
    /// Smooth glass.
    Dielectric {
        /// Index of refraction, > 0.
        ior: f32,
    },
    /// GGX rough conductor (an extension).
    RoughConductor {
        /// Reflectance at normal incidence per channel.
        reflectance: V3,
        /// Roughness in (0, 1].
        roughness: f32,
    },
}

/// The geometry of a shape, in its object space.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeGeometry {
    /// An analytic sphere.
    Sphere {
        /// Centre.
        center: V3,
        /// Radius, > 0.
        radius: f32,
    },
    /// The parallelogram origin + s edge_u + t edge_v.
    Quad {
        /// A corner.
        origin: V3,
        /// First edge.
        edge_u: V3,
        /// Second edge.
        edge_v: V3,
    },
    /// A Wavefront OBJ mesh.
    Mesh {
        /// The file, resolved against the scene file's folder.
        file: PathBuf,
    },
}

/// A `[[shapes]]` entry, validated.
#[derive(Clone, Debug)]
pub struct ShapeSettings {
    /// Its position in the file (for messages: `shapes[i]`).
    pub index: usize,
    /// Object-space geometry.
    pub geometry: ShapeGeometry,
    /// Index into [`SceneDescription::materials`], or `None` for the default grey diffuse.
    pub material: Option<usize>,
    /// Emitted radiance, when the shape is an area light.
    pub emission: Option<V3>,
    /// World from object at shutter open.
    pub transform: Transform<World, Object>,
    /// World from object at shutter close, when the shape moves.
    pub transform_end: Option<Transform<World, Object>>,
}

/// A `[[lights]]` entry, validated.
#[derive(Clone, Debug)]
pub enum LightSettings {
    /// A point light.
    Point {
        /// Position.
        position: V3,
        /// Radiant intensity per channel (W/sr).
        intensity: V3,
    },
    /// A light at infinity.
    Distant {
        /// The way the light travels.
        direction: V3,
        /// Irradiance on a surface facing it.
        irradiance: V3,
    },
    /// Light from every direction: constant or an equirectangular map.
    Environment {
        /// Constant radiance (or a scale on the map; default 1).
        radiance: V3,
        /// The map, resolved against the scene file's folder.
        file: Option<PathBuf>,
        /// World from light.
        transform: Transform<World, World>,
    },
}

/// Reads and validates a scene file.
pub fn load_description(path: &Path) -> Result<SceneDescription, RenderError> {
    let source = std::fs::read(path).map_err(|source| RenderError::Io {
        file: path.to_path_buf(),
        action: "cannot read the scene file",
        source,
    })?;
    let source = String::from_utf8(source).map_err(|e| RenderError::Scene {
        file: path.to_path_buf(),
        line: Some(line_of_offset(
            &String::from_utf8_lossy(e.as_bytes()),
            e.utf8_error().valid_up_to(),
        )),
        key: None,
        message: "the file is not UTF-8 text".into(),
    })?;
    parse_description(path, &source)
}

/// Validates scene-file text; `path` names the file in messages and anchors relative paths.
pub fn parse_description(path: &Path, source: &str) -> Result<SceneDescription, RenderError> {
    let raw: RawScene = toml::from_str(source).map_err(|e| {
        let line = e.span().map(|s| line_of_offset(source, s.start));
        RenderError::Scene {
            file: path.to_path_buf(),
            line,
            key: line.and_then(|l| key_at_line(source, l)),
            message: e.message().trim().to_string(),
        }
    })?;
    let cx = Cx { file: path, source };
    let base = path.parent().unwrap_or(Path::new(""));
    let mut ignored = Vec::new();

    let film = cx.film(raw.film)?;
    let sampler = cx.sampler(raw.sampler)?;
    let integrator = cx.integrator(raw.integrator)?;
    let camera = cx.camera(raw.camera, &mut ignored)?;
    let mut materials = Vec::new();
    for (name, m) in raw.materials {
        let m = cx.material(&name, m)?;
        materials.push((name, m));
    }
    let shapes = raw
        .shapes
        .into_iter()
        .enumerate()
        .map(|(i, s)| cx.shape(i, s, &materials, base))
        .collect::<Result<Vec<_>, _>>()?;
    let lights = raw
        .lights
        .into_iter()
        .enumerate()
        .map(|(i, l)| cx.light(i, l, base))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(SceneDescription {
        file: path.to_path_buf(),
        film,
        sampler,
        integrator,
        camera,
        materials,
        shapes,
        lights,
        ignored,
    })
}

/// The file and its text, for errors that find their own line.
struct Cx<'a> {
    file: &'a Path,
    source: &'a str,
}

impl Cx<'_> {
    fn err(&self, key: &str, message: impl Into<String>) -> RenderError {
        RenderError::Scene {
            file: self.file.to_path_buf(),
            line: line_of_key(self.source, key),
            key: Some(key.to_string()),
            message: message.into(),
        }
    }

    fn finite(&self, key: &str, v: &[f32]) -> Result<(), RenderError> {
        if v.iter().all(|x| x.is_finite()) {
            Ok(())
        } else {
            Err(self.err(key, format!("must be finite, got {}", show(v))))
        }
    }

    fn positive(&self, key: &str, v: f32) -> Result<f32, RenderError> {
        self.finite(key, &[v])?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(key, format!("must be > 0, got {v}")))
        }
    }

    fn colour(&self, key: &str, v: V3, max_one: bool) -> Result<V3, RenderError> {
        self.finite(key, &v)?;
        if v.iter().any(|&c| c < 0.0) {
            return Err(self.err(key, format!("must not be negative, got {}", show(&v))));
        }
        if max_one && v.iter().any(|&c| c > 1.0) {
            return Err(self.err(
                key,
                format!("must lie in [0, 1] (energy conservation), got {}", show(&v)),
            ));
        }
        Ok(v)
    }

    fn film(&self, f: RawFilm) -> Result<FilmSettings, RenderError> {
        let [w, h] = f.resolution;
        if w == 0 || h == 0 {
            return Err(self.err(
                "film.resolution",
                format!("width and height must be >= 1, got [{w}, {h}]"),
            ));
        }
        let filter = match f.filter {
            None => FilterSettings::Gaussian { radius: 1.5 },
            Some(toml::Value::String(name)) => self.filter(&name, None)?,
            Some(toml::Value::Table(t)) => {
                let mut name = None;
                let mut radius = None;
                for (k, v) in t {
                    match (k.as_str(), v) {
                        ("type", toml::Value::String(s)) => name = Some(s),
                        ("radius", toml::Value::Float(r)) => radius = Some(r as f32),
                        ("radius", toml::Value::Integer(r)) => radius = Some(r as f32),
                        ("type" | "radius", v) => {
                            return Err(self.err(
                                &format!("film.filter.{k}"),
                                format!("has the wrong type ({})", v.type_str()),
                            ));
                        }
                        (other, _) => {
                            return Err(self.err(
                                "film.filter",
                                format!("unknown key `{other}`, expected `type` or `radius`"),
                            ));
                        }
                    }
                }
                let name = name.ok_or_else(|| self.err("film.filter", "missing key `type`"))?;
                self.filter(&name, radius)?
            }
            Some(other) => {
                return Err(self.err(
                    "film.filter",
                    format!(
                        "must be a filter name or a table {{ type, radius }}, got a {}",
                        other.type_str()
                    ),
                ));
            }
        };
        if let Some(c) = f.crop {
            self.finite("film.crop", &c)?;
            let ok = (0.0..=1.0).contains(&c[0])
                && (0.0..=1.0).contains(&c[1])
                && (0.0..=1.0).contains(&c[2])
                && (0.0..=1.0).contains(&c[3])
                && c[0] < c[1]
                && c[2] < c[3];
            if !ok {
                return Err(self.err(
                    "film.crop",
                    format!("must be x0 < x1, y0 < y1 within [0, 1], got {}", show(&c)),
                ));
            }
        }
        Ok(FilmSettings {
            resolution: [w, h],
            filter,
            crop: f.crop,
        })
    }

    fn filter(&self, name: &str, radius: Option<f32>) -> Result<FilterSettings, RenderError> {
        if let Some(r) = radius {
            self.positive("film.filter.radius", r)?;
            if r > 16.0 {
                return Err(self.err(
                    "film.filter.radius",
                    format!("must be at most 16 pixels, got {r}"),
                ));
            }
        }
        Ok(match name {
            "box" => FilterSettings::Box {
                radius: radius.unwrap_or(0.5),
            },
            "triangle" => FilterSettings::Triangle {
                radius: radius.unwrap_or(1.0),
            },
            "gaussian" => FilterSettings::Gaussian {
                radius: radius.unwrap_or(1.5),
            },
            "mitchell" => FilterSettings::Mitchell {
                radius: radius.unwrap_or(2.0),
            },
            other => {
                return Err(self.err(
                    "film.filter",
                    format!(
                        "unknown filter `{other}`, expected box, triangle, gaussian or mitchell"
                    ),
                ));
            }
        })
    }

    fn sampler(&self, s: RawSampler) -> Result<SamplerSettings, RenderError> {
        let kind = match s.kind.as_deref() {
            None => SamplerKind::Sobol,
            Some(name) => name.parse().map_err(|_| {
                self.err(
                    "sampler.type",
                    format!("unknown sampler `{name}`, expected independent, stratified, halton or sobol"),
                )
            })?,
        };
        let spp = s.spp.unwrap_or(16);
        if spp == 0 {
            return Err(self.err("sampler.spp", "must be >= 1, got 0"));
        }
        Ok(SamplerSettings {
            kind,
            spp,
            seed: s.seed.unwrap_or(0),
        })
    }

    fn integrator(&self, i: RawIntegrator) -> Result<IntegratorSettings, RenderError> {
        let kind = match i.kind.as_deref() {
            None => IntegratorKind::Path,
            Some(name) => IntegratorKind::parse(name).ok_or_else(|| {
                self.err(
                    "integrator.type",
                    format!("unknown integrator `{name}`, expected path, depth, distance, position, normal or albedo"),
                )
            })?,
        };
        let max_depth = i.max_depth.unwrap_or(8);
        if max_depth == 0 {
            return Err(self.err("integrator.max_depth", "must be >= 1, got 0"));
        }
        Ok(IntegratorSettings { kind, max_depth })
    }

    fn camera(
        &self,
        c: RawCamera,
        ignored: &mut Vec<String>,
    ) -> Result<CameraSettings, RenderError> {
        let kind = match c.kind.as_deref().unwrap_or("perspective") {
            "perspective" => CameraKind::Perspective,
            "orthographic" => CameraKind::Orthographic,
            "environment" => CameraKind::Environment,
            other => {
                return Err(self.err(
                    "camera.type",
                    format!("unknown camera `{other}`, expected perspective, orthographic or environment"),
                ));
            }
        };
        let v3 = |key: &str, v: Option<V3>, default: V3| -> Result<V3, RenderError> {
            let v = v.unwrap_or(default);
            self.finite(&format!("camera.{key}"), &v)?;
            Ok(v)
        };
        let start = LookAt {
            eye: v3("eye", c.eye, [0.0, 0.0, 0.0])?,
            target: v3("target", c.target, [0.0, 0.0, -1.0])?,
            up: v3("up", c.up, [0.0, 1.0, 0.0])?,
        };
        let end = if c.eye_end.is_some() || c.target_end.is_some() || c.up_end.is_some() {
            Some(LookAt {
                eye: v3("eye_end", c.eye_end, start.eye)?,
                target: v3("target_end", c.target_end, start.target)?,
                up: v3("up_end", c.up_end, start.up)?,
            })
        } else {
            None
        };
        self.look_at("camera", &start)?;
        if let Some(end) = &end {
            self.look_at("camera.eye_end", end)?;
        }

        let mut note = |key: &str, given: bool| {
            if given {
                ignored.push(format!(
                    "camera.{key} is ignored by the {} camera",
                    kind_name(kind)
                ));
            }
        };
        let perspective = kind == CameraKind::Perspective;
        let projective = kind != CameraKind::Environment;
        note("fov", !perspective && c.fov.is_some());
        note("fov_axis", !perspective && c.fov_axis.is_some());
        note("screen_window", !projective && c.screen_window.is_some());
        note("lens_radius", !projective && c.lens_radius.is_some());
        note("focal_distance", !projective && c.focal_distance.is_some());

        let fov = c.fov.unwrap_or(90.0);
        self.finite("camera.fov", &[fov])?;
        if perspective && !(fov > 0.0 && fov < 180.0) {
            return Err(self.err(
                "camera.fov",
                format!("must be in (0, 180) degrees, got {fov}"),
            ));
        }
        let fov_axis = c.fov_axis.unwrap_or_else(|| "smaller".into());
        if !["smaller", "larger", "x", "y", "diagonal"].contains(&fov_axis.as_str()) {
            return Err(self.err(
                "camera.fov_axis",
                format!("unknown axis `{fov_axis}`, expected smaller, larger, x, y or diagonal"),
            ));
        }
        if let Some(w) = c.screen_window {
            self.finite("camera.screen_window", &w)?;
            if !(w[0] < w[1] && w[2] < w[3]) {
                return Err(self.err(
                    "camera.screen_window",
                    format!(
                        "must be [xmin, xmax, ymin, ymax] with xmin < xmax and ymin < ymax, got {}",
                        show(&w)
                    ),
                ));
            }
        }
        let near = c.near.unwrap_or(if perspective { 0.001 } else { 0.0 });
        let far = c.far.unwrap_or(1.0e30);
        self.finite("camera.near", &[near])?;
        self.finite("camera.far", &[far])?;
        if near < 0.0 || (perspective && near <= 0.0) {
            let bound = if perspective {
                "> 0 for a perspective camera"
            } else {
                ">= 0"
            };
            return Err(self.err("camera.near", format!("must be {bound}, got {near}")));
        }
        if near >= far {
            return Err(self.err(
                "camera.far",
                format!("must be greater than near ({near}), got {far}"),
            ));
        }
        let lens_radius = c.lens_radius.unwrap_or(0.0);
        self.finite("camera.lens_radius", &[lens_radius])?;
        if lens_radius < 0.0 {
            return Err(self.err(
                "camera.lens_radius",
                format!("must be >= 0, got {lens_radius}"),
            ));
        }
        let focal_distance =
            self.positive("camera.focal_distance", c.focal_distance.unwrap_or(1.0))?;
        let aperture_blades = c.aperture_blades.unwrap_or(0);
        if aperture_blades != 0 && !(3..=64).contains(&aperture_blades) {
            return Err(self.err(
                "camera.aperture_blades",
                format!("must be 0 (round) or 3 to 64, got {aperture_blades}"),
            ));
        }
        let aperture_rotation = c.aperture_rotation.unwrap_or(0.0);
        self.finite("camera.aperture_rotation", &[aperture_rotation])?;
        let shutter = c.shutter.unwrap_or([0.0, 1.0]);
        self.finite("camera.shutter", &shutter)?;
        if shutter[1] < shutter[0] {
            return Err(self.err(
                "camera.shutter",
                format!(
                    "close must not be before open, got [{}, {}]",
                    shutter[0], shutter[1]
                ),
            ));
        }
        Ok(CameraSettings {
            kind,
            start,
            end,
            fov,
            fov_axis,
            screen_window: c.screen_window,
            near,
            far,
            lens_radius,
            focal_distance,
            aperture_blades,
            aperture_rotation,
            shutter,
        })
    }

    /// Checks a look-at frame the way obscura-space will build it.
    fn look_at(&self, key: &str, l: &LookAt) -> Result<(), RenderError> {
        let t = Transform::<World, obscura_space::Camera>::look_at(
            obscura_space::Point3::new(l.eye[0], l.eye[1], l.eye[2]),
            obscura_space::Point3::new(l.target[0], l.target[1], l.target[2]),
            obscura_space::Vector3::new(l.up[0], l.up[1], l.up[2]),
        );
        match t {
            Ok(_) => Ok(()),
            Err(SpaceError::DegenerateLookAt(why)) => {
                let key = if why.starts_with("up") {
                    if key == "camera" {
                        "camera.up"
                    } else {
                        "camera.up_end"
                    }
                } else if key == "camera" {
                    "camera.target"
                } else {
                    "camera.target_end"
                };
                Err(self.err(key, why))
            }
            Err(e) => Err(self.err(key, e.to_string())),
        }
    }

    fn material(&self, name: &str, m: RawMaterial) -> Result<MaterialSettings, RenderError> {
        let key = |k: &str| format!("materials.{name}.{k}");
        let unused = |k: &str, given: bool| -> Result<(), RenderError> {
            if given {
                Err(self.err(&key(k), format!("a {} material has no key `{k}`", m.kind)))
            } else {
                Ok(())
            }
        };
        match m.kind.as_str() {
            "diffuse" | "mirror" => {
                unused("ior", m.ior.is_some())?;
                unused("roughness", m.roughness.is_some())?;
                let default = if m.kind == "diffuse" { [0.5; 3] } else { [1.0; 3] };
                let reflectance = self.colour(&key("reflectance"), m.reflectance.unwrap_or(default), true)?;
                Ok(if m.kind == "diffuse" {
                    MaterialSettings::Diffuse { reflectance }
                } else {
                    MaterialSettings::Mirror { reflectance }
                })
            }
            "dielectric" => {
                unused("reflectance", m.reflectance.is_some())?;
                unused("roughness", m.roughness.is_some())?;
                let ior = self.positive(&key("ior"), m.ior.unwrap_or(1.5))?;
                Ok(MaterialSettings::Dielectric { ior })
            }
            "rough_conductor" => {
                unused("ior", m.ior.is_some())?;
                let reflectance = self.colour(&key("reflectance"), m.reflectance.unwrap_or([0.9; 3]), true)?;
                let roughness = self.positive(&key("roughness"), m.roughness.unwrap_or(0.3))?;
                if roughness > 1.0 {
                    return Err(self.err(&key("roughness"), format!("must be in (0, 1], got {roughness}")));
                }
                Ok(MaterialSettings::RoughConductor { reflectance, roughness })
            }
            other => Err(self.err(
                &key("type"),
                format!("unknown material `{other}`, expected diffuse, mirror, dielectric or rough_conductor"),
            )),
        }
    }

    fn shape(
        &self,
        i: usize,
        s: RawShape,
        materials: &[(String, MaterialSettings)],
        base: &Path,
    ) -> Result<ShapeSettings, RenderError> {
        let key = |k: &str| format!("shapes[{i}].{k}");
        let need = |k: &str, v: Option<V3>| -> Result<V3, RenderError> {
            let v = v.ok_or_else(|| {
                self.err(
                    &format!("shapes[{i}]"),
                    format!("a {} needs the key `{k}`", s.kind),
                )
            })?;
            self.finite(&key(k), &v)?;
            Ok(v)
        };
        let foreign = |names: &[(&str, bool)]| -> Result<(), RenderError> {
            match names.iter().find(|(_, given)| *given) {
                Some((k, _)) => Err(self.err(&key(k), format!("a {} has no key `{k}`", s.kind))),
                None => Ok(()),
            }
        };
        let geometry = match s.kind.as_str() {
            "sphere" => {
                foreign(&[
                    ("origin", s.origin.is_some()),
                    ("edge_u", s.edge_u.is_some()),
                    ("edge_v", s.edge_v.is_some()),
                    ("file", s.file.is_some()),
                ])?;
                let center = s.center.unwrap_or([0.0; 3]);
                self.finite(&key("center"), &center)?;
                let radius = s.radius.ok_or_else(|| {
                    self.err(&format!("shapes[{i}]"), "a sphere needs the key `radius`")
                })?;
                let radius = self.positive(&key("radius"), radius)?;
                ShapeGeometry::Sphere { center, radius }
            }
            "quad" => {
                foreign(&[
                    ("center", s.center.is_some()),
                    ("radius", s.radius.is_some()),
                    ("file", s.file.is_some()),
                ])?;
                let origin = need("origin", s.origin)?;
                let edge_u = need("edge_u", s.edge_u)?;
                let edge_v = need("edge_v", s.edge_v)?;
                let n = glam::Vec3::from(edge_u).cross(glam::Vec3::from(edge_v));
                if n.length() <= 0.0 || n.is_nan() {
                    return Err(self.err(
                        &key("edge_v"),
                        "edge_u and edge_v are parallel or zero: the quad has no area",
                    ));
                }
                ShapeGeometry::Quad {
                    origin,
                    edge_u,
                    edge_v,
                }
            }
            "mesh" => {
                foreign(&[
                    ("center", s.center.is_some()),
                    ("radius", s.radius.is_some()),
                    ("origin", s.origin.is_some()),
                    ("edge_u", s.edge_u.is_some()),
                    ("edge_v", s.edge_v.is_some()),
                ])?;
                let file = s.file.as_ref().ok_or_else(|| {
                    self.err(&format!("shapes[{i}]"), "a mesh needs the key `file`")
                })?;
                ShapeGeometry::Mesh {
                    file: base.join(file),
                }
            }
            other => {
                return Err(self.err(
                    &key("type"),
                    format!("unknown shape `{other}`, expected sphere, quad or mesh"),
                ));
            }
        };
        let material =
            match &s.material {
                None => None,
                Some(name) => Some(materials.iter().position(|(n, _)| n == name).ok_or_else(
                    || {
                        let known: Vec<&str> = materials.iter().map(|(n, _)| n.as_str()).collect();
                        let known = if known.is_empty() {
                            "none are defined".to_string()
                        } else {
                            format!("defined: {}", known.join(", "))
                        };
                        self.err(
                            &key("material"),
                            format!("undefined material `{name}` ({known})"),
                        )
                    },
                )?),
            };
        let emission = match s.emission {
            Some(e) => Some(self.colour(&key("emission"), e, false)?),
            None => None,
        };
        let transform = match &s.transform {
            Some(ops) => self.transform(&key("transform"), ops)?,
            None => Transform::IDENTITY,
        };
        let transform_end = match &s.transform_end {
            Some(ops) => Some(self.transform(&key("transform_end"), ops)?),
            None => None,
        };
        Ok(ShapeSettings {
            index: i,
            geometry,
            material,
            emission,
            transform,
            transform_end,
        })
    }

    /// Composes a list of operations, each applied to the object after the ones before it.
    fn transform<S: obscura_space::Space>(
        &self,
        key: &str,
        ops: &[RawOp],
    ) -> Result<Transform<World, S>, RenderError> {
        let mut world_from_object = Transform::<World, S>::IDENTITY;
        for (j, op) in ops.iter().enumerate() {
            let k = format!("{key}[{j}]");
            let given = [
                op.scale.is_some(),
                op.rotate.is_some(),
                op.translate.is_some(),
                op.matrix.is_some(),
            ];
            if given.iter().filter(|&&g| g).count() != 1 {
                return Err(self.err(
                    &k,
                    "each operation must have exactly one of scale, rotate, translate or matrix",
                ));
            }
            let step: Result<Transform<World, World>, SpaceError> = if let Some(s) = op.scale {
                self.finite(&format!("{k}.scale"), &s)?;
                Transform::scale(s.into())
            } else if let Some(r) = op.rotate {
                self.finite(&format!("{k}.rotate"), &r)?;
                Transform::rotate(r[0], glam::Vec3::new(r[1], r[2], r[3]))
            } else if let Some(t) = op.translate {
                self.finite(&format!("{k}.translate"), &t)?;
                Transform::translate(t.into())
            } else {
                let m = op.matrix.unwrap_or_default();
                self.finite(&format!("{k}.matrix"), &m)?;
                Transform::from_rows(m)
            };
            let step = step.map_err(|e| self.err(&k, e.to_string()))?;
            // Later operations apply after earlier ones: they multiply on the left.
            world_from_object = step * world_from_object;
        }
        Ok(world_from_object)
    }

    fn light(&self, i: usize, l: RawLight, base: &Path) -> Result<LightSettings, RenderError> {
        let key = |k: &str| format!("lights[{i}].{k}");
        let foreign = |names: &[(&str, bool)]| -> Result<(), RenderError> {
            match names.iter().find(|(_, given)| *given) {
                Some((k, _)) => {
                    Err(self.err(&key(k), format!("a {} light has no key `{k}`", l.kind)))
                }
                None => Ok(()),
            }
        };
        let need = |k: &str, v: Option<V3>| -> Result<V3, RenderError> {
            let v = v.ok_or_else(|| {
                self.err(
                    &format!("lights[{i}]"),
                    format!("a {} light needs the key `{k}`", l.kind),
                )
            })?;
            self.finite(&key(k), &v)?;
            Ok(v)
        };
        match l.kind.as_str() {
            "point" => {
                foreign(&[
                    ("direction", l.direction.is_some()),
                    ("irradiance", l.irradiance.is_some()),
                    ("radiance", l.radiance.is_some()),
                    ("file", l.file.is_some()),
                    ("transform", l.transform.is_some()),
                ])?;
                let position = need("position", l.position)?;
                let intensity =
                    self.colour(&key("intensity"), need("intensity", l.intensity)?, false)?;
                Ok(LightSettings::Point {
                    position,
                    intensity,
                })
            }
            "distant" => {
                foreign(&[
                    ("position", l.position.is_some()),
                    ("intensity", l.intensity.is_some()),
                    ("radiance", l.radiance.is_some()),
                    ("file", l.file.is_some()),
                    ("transform", l.transform.is_some()),
                ])?;
                let direction = need("direction", l.direction)?;
                if glam::Vec3::from(direction).length() == 0.0 {
                    return Err(self.err(&key("direction"), "must not be the zero vector"));
                }
                let irradiance =
                    self.colour(&key("irradiance"), need("irradiance", l.irradiance)?, false)?;
                Ok(LightSettings::Distant {
                    direction,
                    irradiance,
                })
            }
            "environment" => {
                foreign(&[
                    ("position", l.position.is_some()),
                    ("intensity", l.intensity.is_some()),
                    ("direction", l.direction.is_some()),
                    ("irradiance", l.irradiance.is_some()),
                ])?;
                if l.radiance.is_none() && l.file.is_none() {
                    return Err(self.err(
                        &format!("lights[{i}]"),
                        "an environment light needs `radiance` or `file`",
                    ));
                }
                let radiance =
                    self.colour(&key("radiance"), l.radiance.unwrap_or([1.0; 3]), false)?;
                let transform = match &l.transform {
                    Some(ops) => self.transform(&key("transform"), ops)?,
                    None => Transform::IDENTITY,
                };
                Ok(LightSettings::Environment {
                    radiance,
                    file: l.file.map(|f| base.join(f)),
                    transform,
                })
            }
            other => Err(self.err(
                &key("type"),
                format!("unknown light `{other}`, expected point, distant or environment"),
            )),
        }
    }
}

fn kind_name(kind: CameraKind) -> &'static str {
    match kind {
        CameraKind::Perspective => "perspective",
        CameraKind::Orthographic => "orthographic",
        CameraKind::Environment => "environment",
    }
}

fn show(v: &[f32]) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
    format!("[{}]", parts.join(", "))
}
