//! What both importers produce: a scene in Obscura's terms, with the place in the imported
//! file that each part came from, written out as scene-format TOML.

use crate::error::{ImportError, Location};
use glam::DMat4;
use obscura_accel::TriangleMesh;
use obscura_render::{Image, RenderError, SceneDescription};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// `[film]`.
#[derive(Clone, Debug)]
pub(crate) struct FilmIr {
    pub(crate) resolution: [u32; 2],
    pub(crate) crop: Option<[f32; 4]>,
    pub(crate) filter: Option<FilterIr>,
    pub(crate) loc: Option<Location>,
}

/// `[film] filter`: Obscura's filter name, its radius and, for a Gaussian, the standard
/// deviation the source gave (`None`: Obscura's default, a third of the radius).
#[derive(Clone, Copy, Debug)]
pub(crate) struct FilterIr {
    pub(crate) kind: &'static str,
    pub(crate) radius: f32,
    pub(crate) sigma: Option<f32>,
}

impl FilterIr {
    /// A filter of `kind` and `radius` with its default shape.
    pub(crate) fn new(kind: &'static str, radius: f32) -> Self {
        Self {
            kind,
            radius,
            sigma: None,
        }
    }
}

/// `[camera]`: the model and its keys, the pose as world-from-camera matrices.
#[derive(Clone, Debug)]
pub(crate) struct CameraIr {
    pub(crate) loc: Location,
    pub(crate) kind: &'static str,
    pub(crate) pose: DMat4,
    pub(crate) pose_end: Option<DMat4>,
    pub(crate) fov: Option<f32>,
    pub(crate) fov_axis: Option<&'static str>,
    pub(crate) screen_window: Option<[f32; 4]>,
    pub(crate) lens_radius: f32,
    pub(crate) focal_distance: Option<f32>,
    pub(crate) shutter: [f32; 2],
    pub(crate) near: Option<f32>,
    pub(crate) far: Option<f32>,
    /// A lens system (pbrt's `realistic`).
    pub(crate) realistic: Option<RealisticIr>,
}

/// A lens system's keys.
#[derive(Clone, Debug)]
pub(crate) struct RealisticIr {
    /// The lens file's path, resolved against the scene file's folder.
    pub(crate) lens_file: std::path::PathBuf,
    pub(crate) aperture_diameter: f32,
    pub(crate) focus_distance: f32,
    pub(crate) film_diagonal: f32,
    /// The stop's shape when not round.
    pub(crate) stop: Option<StopIr>,
}

/// A stop's shape other than round.
#[derive(Clone, Debug)]
pub(crate) enum StopIr {
    /// `aperture_blades`, `aperture_rotation` (degrees).
    Blades(u32, f32),
    /// `aperture_image`, resolved against the scene file's folder.
    Image(std::path::PathBuf),
}

/// A material in the scene format's terms.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum MaterialIr {
    Diffuse([f32; 3]),
    Mirror([f32; 3]),
    Dielectric(f32),
    RoughConductor([f32; 3], f32),
}

/// A shape's geometry in its object space; meshes index [`Ir::meshes`].
#[derive(Clone, Debug)]
pub(crate) enum GeometryIr {
    Sphere {
        center: [f32; 3],
        radius: f32,
    },
    Quad {
        origin: [f32; 3],
        edge_u: [f32; 3],
        edge_v: [f32; 3],
    },
    Mesh(usize),
}

/// A `[[shapes]]` entry.
#[derive(Clone, Debug)]
pub(crate) struct ShapeIr {
    pub(crate) loc: Location,
    pub(crate) geometry: GeometryIr,
    pub(crate) material: Option<String>,
    pub(crate) emission: Option<[f32; 3]>,
    pub(crate) transform: DMat4,
    pub(crate) transform_end: Option<DMat4>,
}

/// A `[[lights]]` entry.
#[derive(Clone, Debug)]
pub(crate) enum LightIr {
    Point {
        position: [f32; 3],
        intensity: [f32; 3],
    },
    Distant {
        direction: [f32; 3],
        irradiance: [f32; 3],
    },
    Environment {
        radiance: [f32; 3],
        /// A map file the scene names, or one the import made (`Ir::maps`).
        file: Option<MapIr>,
        transform: Option<DMat4>,
    },
}

/// An environment map: a file as the scene names it, or one the import made.
#[derive(Clone, Debug)]
pub(crate) enum MapIr {
    File(PathBuf),
    Made(usize),
}

/// An imported scene before it becomes text.
#[derive(Clone, Debug, Default)]
pub(crate) struct Ir {
    pub(crate) film: Option<FilmIr>,
    pub(crate) sampler: Option<(&'static str, u32, Option<u64>, Location)>,
    pub(crate) integrator: Option<(&'static str, Option<u32>, Location)>,
    pub(crate) camera: Option<CameraIr>,
    pub(crate) materials: Vec<(String, MaterialIr, Location)>,
    pub(crate) shapes: Vec<ShapeIr>,
    pub(crate) lights: Vec<(LightIr, Location)>,
    pub(crate) meshes: Vec<(String, Arc<TriangleMesh>)>,
    /// Equirectangular maps the import made, by file name within the mesh folder.
    pub(crate) maps: Vec<(String, Arc<Image>)>,
    pub(crate) warnings: Vec<String>,
    /// The materials' names, for uniqueness.
    names: std::collections::HashSet<String>,
    /// Anonymous materials by their settings.
    anonymous: HashMap<String, String>,
}

impl Ir {
    /// Records a warning that names its place.
    pub(crate) fn warn(&mut self, loc: &Location, message: impl std::fmt::Display) {
        self.warnings.push(format!("{loc}: {message}"));
    }

    /// Adds a material under a unique bare-key name made from `wanted`; returns the name.
    /// An `anonymous` material equal to an earlier anonymous one is that one (exporters write
    /// a `Material` per shape).
    pub(crate) fn add_material(
        &mut self,
        wanted: &str,
        m: MaterialIr,
        loc: &Location,
        anonymous: bool,
    ) -> String {
        let key = format!("{m:?}");
        if let Some(name) = self.anonymous.get(&key).filter(|_| anonymous) {
            return name.clone();
        }
        let name = self.material_name(wanted);
        self.names.insert(name.clone());
        if anonymous {
            self.anonymous.insert(key, name.clone());
        }
        self.materials.push((name.clone(), m, loc.clone()));
        name
    }

    /// A material's name, unique and a bare TOML key, from `wanted`.
    fn material_name(&self, wanted: &str) -> String {
        let mut base: String = wanted
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        if base.is_empty() {
            base = "material".into();
        }
        let mut name = base.clone();
        let mut n = 1;
        while self.names.contains(&name) {
            n += 1;
            name = format!("{base}-{n}");
        }
        name
    }
}

/// A scene read from a pbrt-v4 or Mitsuba 3 file, as Obscura's scene-format text plus the
/// meshes it names (held in memory until [`Imported::write`] writes them as OBJ files).
#[derive(Clone, Debug)]
pub struct Imported {
    /// The imported file.
    pub source: PathBuf,
    /// Scene-format TOML; its meshes are named `MESH_DIR/NAME.obj` relative to the file.
    toml: String,
    /// The mesh folder the TOML names, relative to the TOML file.
    mesh_dir: String,
    /// The meshes, by file name within the mesh folder.
    meshes: Vec<(String, Arc<TriangleMesh>)>,
    /// The maps the import made, by file name within the mesh folder.
    maps: Vec<(String, Arc<Image>)>,
    /// For each TOML line from which on an item came from a place in the imported files.
    origins: Vec<(usize, Location)>,
    /// The files the TOML names outside its mesh folder (lens files, maps): the 0-based index
    /// of the line that names each, its key, and the path as written (relative to the
    /// imported file's folder, or absolute).
    external: Vec<External>,
    /// What was approximated or left out, each naming file, line and directive.
    pub warnings: Vec<String>,
}

impl Imported {
    pub(crate) fn new(source: &Path, ir: Ir) -> Result<Imported, ImportError> {
        let stem = source
            .file_stem()
            .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
        let mesh_dir = format!("{stem}-meshes");
        let base = source.parent().unwrap_or(Path::new(""));
        let Emitted {
            toml,
            origins,
            external,
        } = emit(&ir, &mesh_dir, base, source)?;
        Ok(Imported {
            source: source.to_path_buf(),
            toml,
            mesh_dir,
            meshes: ir.meshes,
            maps: ir.maps,
            origins,
            external,
            warnings: ir.warnings,
        })
    }

    /// The scene-format text (meshes named under `NAME-meshes/` beside the scene).
    pub fn toml(&self) -> &str {
        &self.toml
    }

    /// The scene, validated by the renderer as a TOML file would be, its meshes in memory.
    /// Errors name the imported file and the line the refused value came from.
    pub fn description(&self) -> Result<SceneDescription, ImportError> {
        let mut d = obscura_render::parse_description(&self.source, &self.toml)
            .map_err(|e| ImportError::Render(self.locate(e)))?;
        let base = self.source.parent().unwrap_or(Path::new(""));
        let meshes: HashMap<PathBuf, Arc<TriangleMesh>> = self
            .meshes
            .iter()
            .map(|(name, m)| (base.join(&self.mesh_dir).join(name), m.clone()))
            .collect();
        d.meshes = Arc::new(meshes);
        let maps: HashMap<PathBuf, Arc<Image>> = self
            .maps
            .iter()
            .map(|(name, m)| (base.join(&self.mesh_dir).join(name), m.clone()))
            .collect();
        d.maps = Arc::new(maps);
        Ok(d)
    }

    /// A renderer error about this scene (from [`Imported::description`] or from building it)
    /// moved to the imported file's line the refused value came from.
    pub fn locate(&self, e: RenderError) -> RenderError {
        match e {
            RenderError::Scene {
                file,
                line: Some(line),
                key,
                message,
            } if file == self.source => {
                let at = self.origins.iter().rev().find(|(l, _)| *l <= line);
                match at {
                    Some((_, loc)) => RenderError::Scene {
                        file: loc.file.as_ref().clone(),
                        line: Some(loc.line),
                        key: key.map(|k| format!("{k} (Obscura's key)")),
                        message,
                    },
                    None => RenderError::Scene {
                        file,
                        line: None,
                        key,
                        message,
                    },
                }
            }
            other => other,
        }
    }

    /// Writes the scene as a TOML file at `out`, with its meshes as OBJ files in the folder
    /// `STEM-meshes` beside it (STEM being `out`'s). Returns the files written.
    pub fn write(&self, out: &Path) -> Result<Vec<PathBuf>, ImportError> {
        let stem = out
            .file_stem()
            .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
        let mesh_dir = format!("{stem}-meshes");
        let out_base = folder(out);
        // Paths in the text (maps, mesh folder) are relative to the TOML file: rewrite them for
        // the output's folder.
        let text = self.text_for(out_base, &mesh_dir)?;
        let io = |file: &Path, action| {
            let file = file.to_path_buf();
            move |source| ImportError::Io {
                file,
                action,
                source,
            }
        };
        let mut written = Vec::new();
        if !self.meshes.is_empty() || !self.maps.is_empty() {
            let dir = out_base.join(&mesh_dir);
            std::fs::create_dir_all(&dir).map_err(io(&dir, "cannot create the mesh folder"))?;
            for (name, mesh) in &self.meshes {
                let path = dir.join(name);
                std::fs::write(&path, obj_text(mesh)).map_err(io(&path, "cannot write"))?;
                written.push(path);
            }
            for (name, map) in &self.maps {
                let path = dir.join(name);
                let info = obscura_render::ImageInfo {
                    partial: false,
                    samples_per_pixel: 1,
                };
                obscura_render::write_image(&path, map, &info)?;
                written.push(path);
            }
        }
        std::fs::write(out, text).map_err(io(out, "cannot write"))?;
        written.push(out.to_path_buf());
        Ok(written)
    }

    /// The TOML text with its relative paths made relative to `out_base`.
    fn text_for(&self, out_base: &Path, mesh_dir: &str) -> Result<String, ImportError> {
        let src_base = folder(&self.source);
        let same = |a: &Path, b: &Path| {
            a == b
                || (a.canonicalize().ok().is_some()
                    && a.canonicalize().ok() == b.canonicalize().ok())
        };
        let mut text = self.toml.replace(
            &format!("file = \"{}/", self.mesh_dir),
            &format!("file = \"{mesh_dir}/"),
        );
        if !same(src_base, out_base) && !self.external.is_empty() {
            // Files named relative to the imported file (lens files, maps): absolute in the
            // copy, which is read from another folder.
            let abs = std::path::absolute(src_base).map_err(|source| ImportError::Io {
                file: src_base.to_path_buf(),
                action: "cannot resolve the folder",
                source,
            })?;
            let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
            for e in &self.external {
                if let Some(line) = lines.get_mut(e.line) {
                    *line = format!(
                        "{} = {}",
                        e.key,
                        quote(&abs.join(&e.path).to_string_lossy())
                    );
                }
            }
            text = lines.join("\n");
            text.push('\n');
        }
        Ok(text)
    }
}

/// The folder a file is in (`.` for a bare file name).
fn folder(file: &Path) -> &Path {
    match file.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// A TOML basic string.
pub(crate) fn quote(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => {
                let _ = write!(out, "\\u{:04X}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// An f32 as TOML writes it, exactly (the shortest text that reads back to the same value).
fn num(x: f32) -> String {
    let s = format!("{x:?}");
    if s.contains(['.', 'e', 'E']) || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        s + ".0"
    }
}

fn v3(v: [f32; 3]) -> String {
    format!("[{}, {}, {}]", num(v[0]), num(v[1]), num(v[2]))
}

/// A matrix's 16 numbers, row-major, as the scene format's `matrix` and `pose` take them.
fn rows(m: &DMat4) -> String {
    let r = m.transpose().to_cols_array();
    let r: Vec<String> = r.iter().map(|&x| num(x as f32)).collect();
    format!("[{}]", r.join(", "))
}

/// Checks that a matrix is finite in f32 (the scene format's precision).
fn finite_matrix(m: &DMat4, loc: &Location, what: &str) -> Result<(), ImportError> {
    if m.to_cols_array().iter().all(|x| (*x as f32).is_finite()) {
        Ok(())
    } else {
        Err(loc.error(format!("{what}: the transform has NaN or huge entries")))
    }
}

/// A file the TOML names outside its mesh folder, which a copy written elsewhere must name by
/// its absolute path.
#[derive(Clone, Debug)]
struct External {
    /// The 0-based index of the TOML line `key = "path"`.
    line: usize,
    key: &'static str,
    /// As written: relative to the imported file's folder, or absolute.
    path: PathBuf,
}

/// What [`emit`] writes.
struct Emitted {
    /// The scene as TOML.
    toml: String,
    /// The TOML line from which on each item came from where.
    origins: Vec<(usize, Location)>,
    /// The files it names outside its mesh folder.
    external: Vec<External>,
}

/// The scene as TOML, with where its parts came from and the files it names.
fn emit(ir: &Ir, mesh_dir: &str, base: &Path, source: &Path) -> Result<Emitted, ImportError> {
    let mut out = String::new();
    let mut origins = Vec::new();
    let mut external = Vec::new();
    // Writes `key = "path"` for a file the import resolved against the imported file's folder
    // (`path` as found from the working folder), relative to that folder, where the TOML's
    // reader looks. Lines are counted on from the last call, as `line` does below.
    let (mut file_counted, mut file_lines) = (0usize, 0usize);
    let mut name_file = |out: &mut String, key: &'static str, path: &Path| {
        file_lines += out[file_counted..].matches('\n').count();
        file_counted = out.len();
        let rel = path.strip_prefix(base).unwrap_or(path).to_path_buf();
        let _ = writeln!(out, "{key} = {}", quote(&rel.to_string_lossy()));
        external.push(External {
            line: file_lines,
            key,
            path: rel,
        });
    };
    // The line the text has reached, counted on from the last call (emitting stays linear).
    let (mut counted, mut lines) = (0usize, 0usize);
    let mut line = |out: &String| {
        lines += out[counted..].matches('\n').count();
        counted = out.len();
        lines + 1
    };
    let _ = writeln!(
        out,
        "# Imported from {} by obscura-import; every table says where it came from.",
        source.display()
    );
    let film = ir.film.clone().unwrap_or(FilmIr {
        resolution: [1280, 720],
        crop: None,
        filter: None,
        loc: None,
    });
    if let Some(loc) = &film.loc {
        origins.push((line(&out), loc.clone()));
        let _ = writeln!(out, "\n# {loc}");
    } else {
        out.push('\n');
    }
    let _ = writeln!(out, "[film]");
    let _ = writeln!(
        out,
        "resolution = [{}, {}]",
        film.resolution[0], film.resolution[1]
    );
    if let Some(f) = film.filter {
        let sigma = f
            .sigma
            .map_or(String::new(), |s| format!(", sigma = {}", num(s)));
        let _ = writeln!(
            out,
            "filter = {{ type = \"{}\", radius = {}{sigma} }}",
            f.kind,
            num(f.radius)
        );
    }
    if let Some(c) = film.crop {
        let _ = writeln!(
            out,
            "crop = [{}, {}, {}, {}]",
            num(c[0]),
            num(c[1]),
            num(c[2]),
            num(c[3])
        );
    }
    if let Some((kind, spp, seed, loc)) = &ir.sampler {
        origins.push((line(&out), loc.clone()));
        let _ = writeln!(out, "\n# {loc}\n[sampler]\ntype = \"{kind}\"\nspp = {spp}");
        if let Some(seed) = seed {
            let _ = writeln!(out, "seed = {seed}");
        }
    }
    if let Some((kind, depth, loc)) = &ir.integrator {
        origins.push((line(&out), loc.clone()));
        let _ = writeln!(out, "\n# {loc}\n[integrator]\ntype = \"{kind}\"");
        if let Some(d) = depth {
            let _ = writeln!(out, "max_depth = {d}");
        }
    }
    let camera = ir.camera.as_ref().ok_or_else(|| ImportError::Scene {
        file: source.to_path_buf(),
        line: None,
        message: "the scene has no camera".into(),
    })?;
    origins.push((line(&out), camera.loc.clone()));
    let _ = writeln!(
        out,
        "\n# {}\n[camera]\ntype = \"{}\"",
        camera.loc, camera.kind
    );
    finite_matrix(&camera.pose, &camera.loc, "Camera")?;
    let _ = writeln!(out, "pose = {}", rows(&camera.pose));
    if let Some(end) = &camera.pose_end {
        finite_matrix(end, &camera.loc, "Camera")?;
        let _ = writeln!(out, "pose_end = {}", rows(end));
    }
    if let Some(fov) = camera.fov {
        let _ = writeln!(out, "fov = {}", num(fov));
    }
    if let Some(axis) = camera.fov_axis {
        let _ = writeln!(out, "fov_axis = \"{axis}\"");
    }
    if let Some(w) = camera.screen_window {
        let _ = writeln!(
            out,
            "screen_window = [{}, {}, {}, {}]",
            num(w[0]),
            num(w[1]),
            num(w[2]),
            num(w[3])
        );
    }
    if camera.lens_radius != 0.0 {
        let _ = writeln!(out, "lens_radius = {}", num(camera.lens_radius));
    }
    if let Some(f) = camera.focal_distance {
        let _ = writeln!(out, "focal_distance = {}", num(f));
    }
    if let Some(r) = &camera.realistic {
        name_file(&mut out, "lens_file", &r.lens_file);
        let _ = writeln!(out, "aperture_diameter = {}", num(r.aperture_diameter));
        let _ = writeln!(out, "focus_distance = {}", num(r.focus_distance));
        let _ = writeln!(out, "film_diagonal = {}", num(r.film_diagonal));
        match &r.stop {
            Some(StopIr::Blades(blades, rotation)) => {
                let _ = writeln!(out, "aperture_blades = {blades}");
                let _ = writeln!(out, "aperture_rotation = {}", num(*rotation));
            }
            Some(StopIr::Image(file)) => name_file(&mut out, "aperture_image", file),
            None => {}
        }
    }
    if let Some(n) = camera.near {
        let _ = writeln!(out, "near = {}", num(n));
    }
    if let Some(f) = camera.far {
        let _ = writeln!(out, "far = {}", num(f));
    }
    let _ = writeln!(
        out,
        "shutter = [{}, {}]",
        num(camera.shutter[0]),
        num(camera.shutter[1])
    );

    for (name, m, loc) in &ir.materials {
        origins.push((line(&out), loc.clone()));
        let _ = writeln!(out, "\n# {loc}\n[materials.{name}]");
        let _ = match m {
            MaterialIr::Diffuse(r) => writeln!(out, "type = \"diffuse\"\nreflectance = {}", v3(*r)),
            MaterialIr::Mirror(r) => writeln!(out, "type = \"mirror\"\nreflectance = {}", v3(*r)),
            MaterialIr::Dielectric(ior) => {
                writeln!(out, "type = \"dielectric\"\nior = {}", num(*ior))
            }
            MaterialIr::RoughConductor(r, a) => writeln!(
                out,
                "type = \"rough_conductor\"\nreflectance = {}\nroughness = {}",
                v3(*r),
                num(*a)
            ),
        };
    }
    for s in &ir.shapes {
        origins.push((line(&out), s.loc.clone()));
        let _ = writeln!(out, "\n# {}\n[[shapes]]", s.loc);
        let _ = match &s.geometry {
            GeometryIr::Sphere { center, radius } => writeln!(
                out,
                "type = \"sphere\"\ncenter = {}\nradius = {}",
                v3(*center),
                num(*radius)
            ),
            GeometryIr::Quad {
                origin,
                edge_u,
                edge_v,
            } => writeln!(
                out,
                "type = \"quad\"\norigin = {}\nedge_u = {}\nedge_v = {}",
                v3(*origin),
                v3(*edge_u),
                v3(*edge_v)
            ),
            GeometryIr::Mesh(i) => {
                let name = &ir.meshes.get(*i).map(|m| m.0.as_str()).unwrap_or("missing");
                writeln!(
                    out,
                    "type = \"mesh\"\nfile = {}",
                    quote(&format!("{mesh_dir}/{name}"))
                )
            }
        };
        if let Some(m) = &s.material {
            let _ = writeln!(out, "material = \"{m}\"");
        }
        if let Some(e) = s.emission {
            let _ = writeln!(out, "emission = {}", v3(e));
        }
        if s.transform != DMat4::IDENTITY {
            finite_matrix(&s.transform, &s.loc, "shape")?;
            let _ = writeln!(out, "transform = [{{ matrix = {} }}]", rows(&s.transform));
        }
        if let Some(end) = &s.transform_end {
            finite_matrix(end, &s.loc, "shape")?;
            let _ = writeln!(out, "transform_end = [{{ matrix = {} }}]", rows(end));
        }
    }
    for (l, loc) in &ir.lights {
        origins.push((line(&out), loc.clone()));
        let _ = writeln!(out, "\n# {loc}\n[[lights]]");
        let _ = match l {
            LightIr::Point {
                position,
                intensity,
            } => writeln!(
                out,
                "type = \"point\"\nposition = {}\nintensity = {}",
                v3(*position),
                v3(*intensity)
            ),
            LightIr::Distant {
                direction,
                irradiance,
            } => writeln!(
                out,
                "type = \"distant\"\ndirection = {}\nirradiance = {}",
                v3(*direction),
                v3(*irradiance)
            ),
            LightIr::Environment {
                radiance,
                file,
                transform,
            } => {
                let _ = writeln!(out, "type = \"environment\"\nradiance = {}", v3(*radiance));
                match file {
                    Some(MapIr::File(f)) => name_file(&mut out, "file", f),
                    Some(MapIr::Made(i)) => {
                        let name = ir.maps.get(*i).map_or("missing", |m| m.0.as_str());
                        let _ = writeln!(out, "file = {}", quote(&format!("{mesh_dir}/{name}")));
                    }
                    None => {}
                }
                match transform {
                    Some(t) if *t != DMat4::IDENTITY => {
                        finite_matrix(t, loc, "light")?;
                        writeln!(out, "transform = [{{ matrix = {} }}]", rows(t))
                    }
                    _ => Ok(()),
                }
            }
        };
    }
    Ok(Emitted {
        toml: out,
        origins,
        external,
    })
}

/// A mesh as OBJ text, every number written exactly (shortest round-trip form).
pub(crate) fn obj_text(mesh: &TriangleMesh) -> String {
    let mut out = String::from("# Written by obscura-import\n");
    for p in mesh.positions() {
        let _ = writeln!(out, "v {:?} {:?} {:?}", p.x, p.y, p.z);
    }
    if let Some(uvs) = mesh.uvs() {
        for t in uvs {
            let _ = writeln!(out, "vt {:?} {:?}", t.x, t.y);
        }
    }
    if let Some(normals) = mesh.normals() {
        for n in normals {
            let _ = writeln!(out, "vn {:?} {:?} {:?}", n.x, n.y, n.z);
        }
    }
    let (uv, n) = (mesh.uvs().is_some(), mesh.normals().is_some());
    for t in mesh.triangles() {
        out.push('f');
        for &v in t {
            let i = v + 1;
            let _ = match (uv, n) {
                (false, false) => write!(out, " {i}"),
                (true, false) => write!(out, " {i}/{i}"),
                (false, true) => write!(out, " {i}//{i}"),
                (true, true) => write!(out, " {i}/{i}/{i}"),
            };
        }
        out.push('\n');
    }
    out
}
