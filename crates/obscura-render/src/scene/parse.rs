//! The validating parser: raw structs to settings, every value checked, every error naming
//! the file, the key and the line.

use super::raw::{
    RawCamera, RawCameraPart, RawFilm, RawIntegrator, RawLight, RawMaterial, RawOp, RawSampler,
    RawScene, RawShape,
};
use super::settings::*;
use crate::error::RenderError;
use crate::locate::{key_at, line_of_offset};
use obscura_sample::SamplerKind;
use obscura_space::{SpaceError, Transform, World};
use serde::de::DeserializeOwned;
use std::path::Path;

/// Reads and validates a scene file.
pub fn load_description(path: &Path) -> Result<SceneDescription, RenderError> {
    parse_description(path, &read_scene(path)?)
}

/// Validates scene-file text; `path` names the file in messages and anchors relative paths.
pub fn parse_description(path: &Path, source: &str) -> Result<SceneDescription, RenderError> {
    let raw: RawScene = from_toml(path, source)?;
    let cx = Cx { file: path, source };
    let base = path.parent().unwrap_or(Path::new(""));
    let mut ignored = Vec::new();

    let film = cx.film(raw.film)?;
    let sampler = cx.sampler(raw.sampler)?;
    let integrator = cx.integrator(raw.integrator)?;
    let camera = cx.checked_camera(raw.camera, &film, base, &mut ignored)?;
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
        meshes: Default::default(),
        maps: Default::default(),
        source: source.into(),
    })
}

/// Reads and validates the camera's part of a scene file, as
/// [`parse_camera_description`] does.
pub fn load_camera_description(path: &Path) -> Result<CameraDescription, RenderError> {
    parse_camera_description(path, &read_scene(path)?)
}

/// Validates the camera's part of scene-file text: `[camera]` (with its sub-tables) and
/// `[film]` as [`parse_description`] checks them, and of `[sampler]` only `type`. Every other
/// table and key is skipped unchecked, so a scene whose shapes, materials, lights or integrator
/// the renderer refuses still gives its camera; but the whole text must be TOML, and errors
/// name the file's own lines. `path` names the file in messages and anchors relative paths
/// (a lens file, an aperture image).
pub fn parse_camera_description(
    path: &Path,
    source: &str,
) -> Result<CameraDescription, RenderError> {
    let raw: RawCameraPart = from_toml(path, source)?;
    let cx = Cx { file: path, source };
    let base = path.parent().unwrap_or(Path::new(""));
    let mut ignored = Vec::new();

    // The checks of `parse_description`, in its order, less those of the skipped keys.
    let film = cx.film(raw.film)?;
    let sampler = cx.sampler_kind(raw.sampler.kind.as_deref())?;
    let camera = cx.checked_camera(raw.camera, &film, base, &mut ignored)?;
    Ok(CameraDescription {
        file: path.to_path_buf(),
        film,
        sampler,
        camera,
        ignored,
        source: source.into(),
    })
}

/// The text of a scene file: unreadable and non-UTF-8 files are errors, the latter with the
/// line of the first bad byte.
fn read_scene(path: &Path) -> Result<String, RenderError> {
    let source = std::fs::read(path).map_err(|source| RenderError::Io {
        file: path.to_path_buf(),
        action: "cannot read the scene file",
        source,
    })?;
    String::from_utf8(source).map_err(|e| RenderError::Scene {
        file: path.to_path_buf(),
        line: Some(line_of_offset(
            &String::from_utf8_lossy(e.as_bytes()),
            e.utf8_error().valid_up_to(),
        )),
        key: None,
        message: "the file is not UTF-8 text".into(),
    })
}

/// Deserializes scene-file text into raw structs: a syntax error anywhere, an unknown key or a
/// value of the wrong type is an error at the line serde's span points to.
fn from_toml<T: DeserializeOwned>(path: &Path, source: &str) -> Result<T, RenderError> {
    toml::from_str(source).map_err(|e| {
        let at = e.span().map(|s| s.start);
        let message = e.message().trim();
        let key = at.and_then(|at| key_at(source, at, message));
        // A table missing from the file has no line (serde points at the file's start).
        let missing_table = message.starts_with("missing field")
            && key.as_deref().is_some_and(|k| !k.contains(['.', '[']));
        RenderError::Scene {
            file: path.to_path_buf(),
            line: at
                .filter(|_| !missing_table)
                .map(|at| line_of_offset(source, at)),
            key,
            message: in_toml_words(message),
        }
    })
}

/// Serde's message in the scene format's words: Rust's number types and serde's `sequence`
/// and `map` become what a TOML file has (a number, an array, a table).
fn in_toml_words(message: &str) -> String {
    [
        ("expected f32", "expected a number"),
        ("expected f64", "expected a number"),
        ("expected u8", "expected a whole number"),
        ("expected u32", "expected a whole number"),
        ("expected u64", "expected a whole number"),
        ("expected usize", "expected a whole number"),
        ("expected i32", "expected an integer"),
        ("expected i64", "expected an integer"),
        ("expected a sequence", "expected an array"),
        ("expected a map", "expected a table"),
    ]
    .iter()
    .fold(message.to_string(), |m, (rust, toml)| m.replace(rust, toml))
}

/// `kind` with its indefinite article: "an integer", "a string".
fn with_article(kind: &str) -> String {
    let an = kind.starts_with(['a', 'e', 'i', 'o', 'u']);
    format!("{} {kind}", if an { "an" } else { "a" })
}

/// The file and its text, for errors that find their own line.
pub(super) struct Cx<'a> {
    pub(super) file: &'a Path,
    source: &'a str,
}

impl Cx<'_> {
    pub(super) fn err(&self, key: &str, message: impl Into<String>) -> RenderError {
        RenderError::at_key(self.file, self.source, key, message)
    }

    /// `[camera]` validated, then built once with the film: what needs the film too (a
    /// fisheye's field of view, a square film) is checked by the camera crate's constructors.
    fn checked_camera(
        &self,
        raw: RawCamera,
        film: &FilmSettings,
        base: &Path,
        ignored: &mut Vec<String>,
    ) -> Result<CameraSettings, RenderError> {
        let camera = self.camera(raw, base, ignored)?;
        crate::build::build_camera(&camera, film.resolution, film.crop)
            .map_err(|e| self.camera_err(e))?;
        Ok(camera)
    }

    pub(super) fn finite(&self, key: &str, v: &[f32]) -> Result<(), RenderError> {
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
            None => FilterSettings::gaussian(1.5),
            Some(toml::Value::String(name)) => self.filter(&name, None)?,
            Some(toml::Value::Table(t)) => {
                let mut name = None;
                let mut radius = None;
                let mut sigma = None;
                for (k, v) in t {
                    match (k.as_str(), v) {
                        ("type", toml::Value::String(s)) => name = Some(s),
                        ("radius", toml::Value::Float(r)) => radius = Some(r as f32),
                        ("radius", toml::Value::Integer(r)) => radius = Some(r as f32),
                        ("sigma", toml::Value::Float(s)) => sigma = Some(s as f32),
                        ("sigma", toml::Value::Integer(s)) => sigma = Some(s as f32),
                        ("type" | "radius" | "sigma", v) => {
                            return Err(self.err(
                                &format!("film.filter.{k}"),
                                format!("has the wrong type ({})", v.type_str()),
                            ));
                        }
                        (other, _) => {
                            return Err(self.err(
                                "film.filter",
                                format!(
                                    "unknown key `{other}`, expected `type`, `radius` or `sigma`"
                                ),
                            ));
                        }
                    }
                }
                let name = name.ok_or_else(|| self.err("film.filter", "missing key `type`"))?;
                let filter = self.filter(&name, radius)?;
                match (filter, sigma) {
                    (_, None) => filter,
                    (FilterSettings::Gaussian { radius, .. }, Some(sigma)) => {
                        self.gaussian_sigma(radius, sigma)?
                    }
                    (other, Some(_)) => {
                        return Err(self.err(
                            "film.filter.sigma",
                            format!(
                                "applies only to the gaussian filter, not to `{}`",
                                other.name()
                            ),
                        ));
                    }
                }
            }
            Some(other) => {
                return Err(self.err(
                    "film.filter",
                    format!(
                        "must be a filter name or a table {{ type, radius }}, got {}",
                        with_article(other.type_str())
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
            if r > FilterSettings::MAX_RADIUS {
                return Err(self.err(
                    "film.filter.radius",
                    format!(
                        "must be at most {} pixels, got {r}",
                        FilterSettings::MAX_RADIUS
                    ),
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
            "gaussian" => FilterSettings::gaussian(radius.unwrap_or(1.5)),
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

    /// The Gaussian of `radius` with an explicit standard deviation
    /// ([`FilterSettings::sigma_fits`]).
    fn gaussian_sigma(&self, radius: f32, sigma: f32) -> Result<FilterSettings, RenderError> {
        self.positive("film.filter.sigma", sigma)?;
        if !FilterSettings::sigma_fits(radius, sigma) {
            return Err(self.err(
                "film.filter.sigma",
                format!(
                    "must be at most {} pixels and {} x radius ({radius}), got {sigma}",
                    FilterSettings::MAX_RADIUS,
                    FilterSettings::MAX_SIGMA_PER_RADIUS
                ),
            ));
        }
        Ok(FilterSettings::Gaussian { radius, sigma })
    }

    fn sampler(&self, s: RawSampler) -> Result<SamplerSettings, RenderError> {
        let kind = self.sampler_kind(s.kind.as_deref())?;
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

    /// `[sampler] type`; Sobol when absent.
    fn sampler_kind(&self, name: Option<&str>) -> Result<SamplerKind, RenderError> {
        match name {
            None => Ok(SamplerKind::Sobol),
            Some(name) => name.parse().map_err(|_| {
                self.err(
                    "sampler.type",
                    format!("unknown sampler `{name}`, expected independent, stratified, halton or sobol"),
                )
            }),
        }
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

fn show(v: &[f32]) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
    format!("[{}]", parts.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A film and a camera the renderer accepts.
    const CAMERA: &str =
        "[film]\nresolution = [32, 24]\n[camera]\ntype = \"perspective\"\nfov = 40.0\n";

    /// The camera's part of `text`, or its error as (key, line, message).
    fn camera_part(
        text: &str,
    ) -> Result<CameraDescription, (Option<String>, Option<usize>, String)> {
        parse_camera_description(Path::new("s.toml"), text).map_err(|e| match e {
            RenderError::Scene {
                key, line, message, ..
            } => (key, line, message),
            other => panic!("not a scene error: {other}"),
        })
    }

    /// The 1-based line of `text` that reads `line`.
    fn line_of(text: &str, line: &str) -> usize {
        text.lines().position(|l| l == line).expect(line) + 1
    }

    /// Each table the renderer refuses is skipped unread: the camera, its film and its sampler
    /// type still come through, and the camera builds.
    #[test]
    fn a_scene_refused_elsewhere_still_gives_its_camera() {
        for refused in [
            "[[shapes]]\ntype = \"torus\"\nbogus = [\n  [1.0, 2.0],\n]\n",
            "[[shapes]]\ntype = \"sphere\"\nradius = 1.0\nmaterial = \"undefined\"\n",
            "[materials.m]\ntype = \"nonsense\"\n",
            "[integrator]\ntype = \"mist\"\nmax_depth = 0\n",
            "[[lights]]\ntype = \"laser\"\n",
            "[foo]\nbar = 1\n",
            "version = 3\nmaterials.y.type = \"nonsense\"\n",
            "[sampler]\ntype = \"halton\"\nspp = 0\nbogus = 1\n",
        ] {
            let text = format!("{refused}{CAMERA}");
            assert!(
                parse_description(Path::new("s.toml"), &text).is_err(),
                "the renderer refuses {refused}"
            );
            let d = camera_part(&text).unwrap_or_else(|e| panic!("{refused}: {e:?}"));
            assert_eq!(d.film.resolution, [32, 24], "{refused}");
            assert_eq!(d.camera.kind, CameraKind::Perspective, "{refused}");
            assert_eq!(d.camera.fov, 40.0, "{refused}");
            d.camera().unwrap_or_else(|e| panic!("{refused}: {e}"));
        }
    }

    /// An error in `[camera]` (or `[film]`) names its key and its line in the file, past the
    /// skipped tables before it; unknown keys in the tables read are still errors.
    #[test]
    fn camera_errors_name_their_key_and_the_files_line() {
        let skipped = "[[shapes]]\ntype = \"torus\"\ntransform = [\n  [1.0, 0.0],\n]\n\
                       [integrator]\ntype = \"mist\"\n";
        for (film, camera, key) in [
            ("", "fov = 180.0", "camera.fov"),
            ("", "bogus = 1", "camera.bogus"),
            ("", "eye = [0.0, 0.0]", "camera.eye"),
            ("", "[camera.stereo]\nbogus = 1", "camera.stereo.bogus"),
            ("crop = [0.5, 0.2, 0.0, 1.0]", "", "film.crop"),
        ] {
            let text = format!(
                "{skipped}[film]\nresolution = [32, 24]\n{film}\n[camera]\n{camera}\n[[lights]]\n"
            );
            let written = [film, camera].concat();
            let line = line_of(&text, written.lines().last().unwrap());
            let (k, l, message) = camera_part(&text).expect_err(key);
            assert_eq!(
                (k.as_deref(), l),
                (Some(key), Some(line)),
                "{camera}{film}: {message}"
            );
        }
    }

    /// A Gaussian's standard deviation is its own key, a third of the radius by default; it
    /// belongs to the Gaussian alone and is bounded like the radius.
    #[test]
    fn a_gaussian_filter_takes_its_sigma() {
        let film = |filter: &str| {
            format!("[film]\nresolution = [32, 24]\nfilter = {filter}\n[camera]\nfov = 40.0\n")
        };
        for (filter, radius, sigma) in [
            ("\"gaussian\"", 1.5, 0.5),
            ("{ type = \"gaussian\", radius = 3 }", 3.0, 1.0),
            (
                "{ type = \"gaussian\", radius = 2.0, sigma = 0.5 }",
                2.0,
                0.5,
            ),
            ("{ type = \"gaussian\", sigma = 2 }", 1.5, 2.0),
        ] {
            let d = camera_part(&film(filter)).unwrap_or_else(|e| panic!("{filter}: {e:?}"));
            assert_eq!(
                d.film.filter,
                FilterSettings::Gaussian { radius, sigma },
                "{filter}"
            );
        }
        for (filter, wanted) in [
            (
                "{ type = \"box\", sigma = 0.5 }",
                "applies only to the gaussian",
            ),
            ("{ type = \"gaussian\", sigma = 0.0 }", "must be > 0"),
            ("{ type = \"gaussian\", sigma = -1.0 }", "must be > 0"),
            ("{ type = \"gaussian\", sigma = \"wide\" }", "wrong type"),
            (
                "{ type = \"gaussian\", radius = 16, sigma = 17 }",
                "at most 16",
            ),
            (
                "{ type = \"gaussian\", radius = 0.1, sigma = 2.5 }",
                "20 x radius",
            ),
        ] {
            let (key, line, message) = camera_part(&film(filter)).expect_err(filter);
            assert_eq!(
                (key.as_deref(), line),
                (Some("film.filter.sigma"), Some(3)),
                "{filter}: {message}"
            );
            assert!(message.contains(wanted), "{filter}: {message}");
        }
        let (key, _, message) =
            camera_part(&film("{ type = \"gaussian\", stddev = 0.5 }")).unwrap_err();
        assert_eq!(key.as_deref(), Some("film.filter"), "{message}");
        assert!(message.contains("unknown key `stddev`"), "{message}");
    }

    /// Of `[sampler]`, `type` alone is read: other keys, even unknown ones, are skipped, but
    /// an unknown sampler is an error at its line.
    #[test]
    fn only_the_sampler_type_is_read() {
        let d = camera_part(CAMERA).unwrap();
        assert_eq!(d.sampler, SamplerKind::Sobol, "the format's default");
        let text = format!("[sampler]\ntype = \"halton\"\nspp = 0\nseed = -1\nbogus = 1\n{CAMERA}");
        assert_eq!(camera_part(&text).unwrap().sampler, SamplerKind::Halton);
        let text = format!("[sampler]\nspp = 4\ntype = \"nope\"\n{CAMERA}");
        let (key, line, message) = camera_part(&text).unwrap_err();
        assert_eq!(
            (key.as_deref(), line),
            (Some("sampler.type"), Some(3)),
            "{message}"
        );
        assert!(message.contains("unknown sampler `nope`"), "{message}");
        // Written inline or with dotted keys, the type is read all the same.
        for sampler in [
            "sampler = { type = \"halton\", spp = 0 }\n",
            "sampler.type = \"halton\"\nsampler.spp = 0\n",
        ] {
            let d = camera_part(&format!("{sampler}{CAMERA}")).unwrap();
            assert_eq!(d.sampler, SamplerKind::Halton, "{sampler}");
        }
        let (key, _, message) = camera_part(&format!("sampler = 5\n{CAMERA}")).unwrap_err();
        assert_eq!(key.as_deref(), Some("sampler"), "{message}");
        assert!(message.ends_with("expected a table"), "{message}");
    }

    /// The skipped tables are still read as TOML: a syntax error in one is an error at its
    /// line.
    #[test]
    fn a_syntax_error_anywhere_is_an_error() {
        for (bad, at) in [
            ("[[shapes]]\nradius = 1.0.0\n", "radius = 1.0.0"),
            (
                "[materials.m]\ntype = \"a\"\ntype = \"b\"\n",
                "type = \"b\"",
            ),
            ("[integrator\ntype = \"path\"\n", "[integrator"),
        ] {
            let text = format!("{CAMERA}{bad}");
            let (_, line, message) = camera_part(&text).expect_err(bad);
            assert_eq!(line, Some(line_of(&text, at)), "{bad}: {message}");
        }
    }

    /// A table given as another kind of value, an array included, says it wants a table, in
    /// the scene format's words: no Rust struct's name (`expected struct RawFilm`) in the
    /// message, and no table filled from an array by position.
    #[test]
    fn a_value_where_a_table_belongs_asks_for_a_table() {
        let body = "[[shapes]]\ntype = \"sphere\"\nradius = 1.0\n";
        for (bad, key) in [
            (
                format!("film = 3\n[camera]\ntype = \"perspective\"\n{body}"),
                "film",
            ),
            (format!("sampler = 5\n{CAMERA}{body}"), "sampler"),
            (
                format!("integrator = \"path\"\n{CAMERA}{body}"),
                "integrator",
            ),
            (
                format!("{CAMERA}rolling_shutter = 3\n{body}"),
                "camera.rolling_shutter",
            ),
            (format!("{CAMERA}stereo = [1]\n{body}"), "camera.stereo"),
            (
                format!("{CAMERA}{body}transform = [5]\n"),
                "shapes[0].transform",
            ),
            (format!("{CAMERA}[materials]\nm = 3\n{body}"), "materials.m"),
            (format!("lights = [7]\n{CAMERA}{body}"), "lights"),
            // Arrays where a table belongs: serde alone would fill the table by position.
            (
                format!("{CAMERA}stereo = [0.1, 5.0, \"separate\"]\n{body}"),
                "camera.stereo",
            ),
            (
                format!("{CAMERA}rolling_shutter = [0.5, \"top_to_bottom\"]\n{body}"),
                "camera.rolling_shutter",
            ),
            (
                format!("{CAMERA}{body}transform = [[[2, 2, 2]]]\n"),
                "shapes[0].transform",
            ),
            (
                format!("film = [[8, 8]]\n[camera]\ntype = \"perspective\"\n{body}"),
                "film",
            ),
            (format!("materials = 5\n{CAMERA}{body}"), "materials"),
        ] {
            let e = parse_description(Path::new("s.toml"), &bad).expect_err(&bad);
            let text = e.to_string();
            assert!(
                text.contains("expected a table") && !text.contains("Raw"),
                "{bad}: {text}"
            );
            let RenderError::Scene { key: Some(k), .. } = &e else {
                panic!("{bad}: no key in {e:?}");
            };
            assert!(k.starts_with(key), "{bad}: key {k}, want {key}");
        }
    }

    /// Serde's other type words become the scene format's: arrays, numbers; and an error on a
    /// line with several keys names the key at fault, a duplicate key its own name.
    #[test]
    fn errors_name_the_key_at_fault_in_toml_words() {
        let body = "[[shapes]]\ntype = \"sphere\"\nradius = 1.0\n";
        for (bad, want, words) in [
            (
                format!("shapes = 5\n{CAMERA}"),
                "shapes",
                "expected an array",
            ),
            (
                format!("{CAMERA}near = \"close\"\n{body}"),
                "camera.near",
                "expected a number",
            ),
            (
                format!("{CAMERA}rolling_shutter = {{ readout = 0.5, direction = 3 }}\n{body}"),
                "camera.rolling_shutter.direction",
                "expected a string",
            ),
            (
                format!("{CAMERA}rolling_shutter = {{ bogus = 1, readout = 0.5 }}\n{body}"),
                "camera.rolling_shutter.bogus",
                "unknown field",
            ),
            (
                format!(
                    "{CAMERA}{body}transform = [{{ rotate = \"x\" }}, {{ translate = [0, 1, 0] }}]\n"
                ),
                "shapes[0].transform[0].rotate",
                "expected an array",
            ),
            (
                format!("{CAMERA}fov = 30.0\n{body}"),
                "camera.fov",
                "duplicate key",
            ),
            (
                "[film]\nresolution = [4, 4]\n".to_string(),
                "camera",
                "missing field `camera`",
            ),
        ] {
            let e = parse_description(Path::new("s.toml"), &bad).expect_err(&bad);
            let RenderError::Scene { key, message, .. } = &e else {
                panic!("{bad}: not a scene error: {e:?}");
            };
            assert_eq!(key.as_deref(), Some(want), "{bad}: {e}");
            assert!(
                message.contains(words) && !message.contains("Raw"),
                "{bad}: {e}"
            );
        }
        // A bad point of a multi-line shutter curve: its own row.
        let text = format!(
            "{CAMERA}shutter_curve = [\n  [0.0, 0.0],\n  [0.5, -1.0],\n  [1.0, 0.0],\n]\n{body}"
        );
        let e = parse_description(Path::new("s.toml"), &text).unwrap_err();
        let RenderError::Scene { key, line, .. } = &e else {
            panic!("not a scene error: {e:?}");
        };
        assert_eq!(key.as_deref(), Some("camera.shutter_curve[1]"), "{e}");
        assert_eq!(*line, Some(line_of(&text, "  [0.5, -1.0],")), "{e}");
        // A table missing from the file has no line to point at.
        let e =
            parse_description(Path::new("s.toml"), "[film]\nresolution = [4, 4]\n").unwrap_err();
        assert!(matches!(e, RenderError::Scene { line: None, .. }), "{e:?}");
    }
}
