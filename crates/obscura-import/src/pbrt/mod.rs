//! pbrt-v4 scenes: directives, the graphics state and its transforms, mapped onto the scene
//! format. pbrt's matrices act on column vectors like glam's; the current transform (CTM) is
//! world-from-object for shapes and lights and camera-from-world at `Camera`.
//!
//! Handedness: pbrt's `LookAt` builds a camera frame whose +x is `cross(up, dir)`, the
//! opposite of the scene format's look-at, so a right-handed world looks mirrored in pbrt
//! unless the file starts with `Scale -1 1 1`. The camera is therefore passed on as its exact
//! matrix (`camera.pose`), never re-derived as a look-at: the image is pbrt's, mirror included.

mod equal_area;
mod lexer;
mod params;

use crate::error::{ImportError, Location};
use crate::scene::{
    CameraIr, FilmIr, FilterIr, GeometryIr, Imported, Ir, LightIr, MaterialIr, RealisticIr,
    ShapeIr, StopIr,
};
use glam::{DMat4, DVec3, Vec2, Vec3};
use lexer::{Kind, Token};
use obscura_accel::TriangleMesh;
use obscura_render::FilterSettings;
use obscura_space::{AnimatedTransform, Object, Transform, World};
use params::{Param, Params, Value};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How deeply `Include`/`Import` may nest (a file including itself stops here).
const MAX_INCLUDE_DEPTH: usize = 32;

/// Reads a pbrt-v4 scene file (and the files it includes, PLY meshes included).
pub fn import_pbrt(path: &Path) -> Result<Imported, ImportError> {
    let text = read_text(path)?;
    parse_pbrt(path, &text)
}

/// Imports pbrt-v4 text; `path` names it in messages and anchors `Include`d and mesh files.
pub fn parse_pbrt(path: &Path, text: &str) -> Result<Imported, ImportError> {
    let mut p = Pbrt::new(path);
    p.file(path, text, 0)?;
    p.finish()?;
    Imported::new(path, p.ir)
}

fn read_text(path: &Path) -> Result<String, ImportError> {
    let bytes = std::fs::read(path).map_err(|source| ImportError::Io {
        file: path.to_path_buf(),
        action: "cannot read",
        source,
    })?;
    String::from_utf8(bytes).map_err(|e| ImportError::Scene {
        file: path.to_path_buf(),
        line: Some(
            e.as_bytes()[..e.utf8_error().valid_up_to()]
                .iter()
                .filter(|&&b| b == b'\n')
                .count()
                + 1,
        ),
        message: "the file is not UTF-8 text".into(),
    })
}

/// The graphics state that `AttributeBegin`/`AttributeEnd` save and restore.
#[derive(Clone, Debug)]
struct State {
    /// The CTM at the start and end transform times.
    ctm: [DMat4; 2],
    /// Which of the two the transform directives change.
    active: [bool; 2],
    /// The material's name in the scene format (None: pbrt's default, a 0.5 diffuse, which is
    /// also the scene format's default).
    material: Option<String>,
    /// The area light shapes get: emitted radiance.
    area: Option<[f32; 3]>,
    reverse: bool,
}

struct Pbrt {
    ir: Ir,
    main: PathBuf,
    state: State,
    stack: Vec<(State, Location)>,
    coords: HashMap<String, [DMat4; 2]>,
    named_materials: HashMap<String, Option<String>>,
    objects: HashMap<String, Vec<ShapeIr>>,
    object: Option<(String, Vec<ShapeIr>, Location)>,
    /// `TransformTimes`: when the two CTMs hold, and where it was said (None: pbrt's 0 1).
    times: [f64; 2],
    times_loc: Option<Location>,
    camera: Option<(String, Params, [DMat4; 2], Location)>,
    film: Option<(Params, Location)>,
    plys: HashMap<PathBuf, usize>,
    world: bool,
}

/// A token cursor over one file.
struct Cursor<'t> {
    tokens: &'t [Token],
    at: usize,
    file: Arc<PathBuf>,
}

impl Cursor<'_> {
    fn loc(&self, t: &Token) -> Location {
        Location {
            file: self.file.clone(),
            line: t.line,
        }
    }
    fn here(&self) -> Location {
        let t = self.tokens.get(self.at).or(self.tokens.last());
        Location {
            file: self.file.clone(),
            line: t.map_or(1, |t| t.line),
        }
    }
    fn err(&self, message: impl Into<String>) -> ImportError {
        self.here().error(message)
    }
    fn num(&mut self, directive: &str) -> Result<f64, ImportError> {
        match self.tokens.get(self.at).map(|t| &t.kind) {
            Some(Kind::Num(x)) => {
                self.at += 1;
                Ok(*x)
            }
            _ => Err(self.err(format!("{directive}: expected a number"))),
        }
    }
    fn nums<const N: usize>(&mut self, directive: &str) -> Result<[f64; N], ImportError> {
        let mut out = [0.0; N];
        for x in &mut out {
            *x = self.num(directive)?;
        }
        Ok(out)
    }
    /// 16 numbers, bracketed or not.
    fn matrix(&mut self, directive: &str) -> Result<[f64; 16], ImportError> {
        let bracket = matches!(self.tokens.get(self.at).map(|t| &t.kind), Some(Kind::Open));
        if bracket {
            self.at += 1;
        }
        let m = self.nums::<16>(directive)?;
        if bracket {
            match self.tokens.get(self.at).map(|t| &t.kind) {
                Some(Kind::Close) => self.at += 1,
                _ => return Err(self.err(format!("{directive}: expected `]` after 16 numbers"))),
            }
        }
        Ok(m)
    }
    fn string(&mut self, directive: &str) -> Result<String, ImportError> {
        match self.tokens.get(self.at).map(|t| &t.kind) {
            Some(Kind::Str(s)) => {
                self.at += 1;
                Ok(s.clone())
            }
            _ => Err(self.err(format!("{directive}: expected a quoted string"))),
        }
    }
    fn word(&mut self, directive: &str) -> Result<String, ImportError> {
        match self.tokens.get(self.at).map(|t| &t.kind) {
            Some(Kind::Word(s)) | Some(Kind::Str(s)) => {
                self.at += 1;
                Ok(s.clone())
            }
            _ => Err(self.err(format!("{directive}: expected a word"))),
        }
    }
    /// A parameter list: pairs of `"type name"` and a value or bracketed values.
    fn params(&mut self, directive: &str) -> Result<Params, ImportError> {
        let mut out = Vec::new();
        while let Some(t) = self.tokens.get(self.at) {
            let Kind::Str(decl) = &t.kind else { break };
            let loc = self.loc(t);
            let mut parts = decl.split_whitespace();
            let (Some(ty), Some(name), None) = (parts.next(), parts.next(), parts.next()) else {
                return Err(loc.error(format!(
                    "{directive}: expected a parameter declaration \"type name\", got \"{decl}\""
                )));
            };
            self.at += 1;
            let value = |k: &Kind| match k {
                Kind::Num(x) => Some(Value::Num(*x)),
                Kind::Str(s) => Some(Value::Str(s.clone())),
                Kind::Word(w) if w == "true" => Some(Value::Bool(true)),
                Kind::Word(w) if w == "false" => Some(Value::Bool(false)),
                _ => None,
            };
            let mut values = Vec::new();
            match self.tokens.get(self.at).map(|t| &t.kind) {
                Some(Kind::Open) => {
                    self.at += 1;
                    loop {
                        match self.tokens.get(self.at).map(|t| &t.kind) {
                            Some(Kind::Close) => {
                                self.at += 1;
                                break;
                            }
                            Some(k) => match value(k) {
                                Some(v) => {
                                    values.push(v);
                                    self.at += 1;
                                }
                                None => {
                                    return Err(self.err(format!(
                                        "{directive}: parameter \"{decl}\": unexpected token in its values"
                                    )));
                                }
                            },
                            None => {
                                return Err(loc.error(format!(
                                    "{directive}: parameter \"{decl}\": `[` without `]`"
                                )));
                            }
                        }
                    }
                }
                Some(k) if value(k).is_some() => {
                    values.extend(value(k));
                    self.at += 1;
                }
                _ => {
                    return Err(
                        loc.error(format!("{directive}: parameter \"{decl}\" has no value"))
                    );
                }
            }
            // Numbers must be numbers and strings strings, per the declared type.
            let numeric = matches!(
                ty,
                "integer"
                    | "float"
                    | "point"
                    | "point2"
                    | "point3"
                    | "vector"
                    | "vector2"
                    | "vector3"
                    | "normal"
                    | "normal3"
                    | "rgb"
                    | "color"
                    | "blackbody"
            );
            if numeric && values.iter().any(|v| !matches!(v, Value::Num(_))) {
                return Err(loc.error(format!(
                    "{directive}: parameter \"{decl}\": expected numbers"
                )));
            }
            out.push(Param {
                ty: ty.to_string(),
                name: name.to_string(),
                values,
                loc,
                used: Default::default(),
            });
        }
        Ok(Params(out))
    }
}

/// pbrt's `LookAt`: camera-from-world, with camera +x = cross(up, dir) (left-handed camera
/// space in a right-handed world).
fn pbrt_look_at(pos: DVec3, look: DVec3, up: DVec3) -> Option<DMat4> {
    let dir = (look - pos).normalize();
    let right = up.normalize().cross(dir);
    if !dir.is_finite() || !right.is_finite() || right.length() == 0.0 {
        return None;
    }
    let right = right.normalize();
    let new_up = dir.cross(right);
    let world_from_camera = DMat4::from_cols(
        right.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        pos.extend(1.0),
    );
    Some(world_from_camera.inverse())
}

fn f3(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

/// An invertible, finite matrix (a CTM that can stand for a pose or a shape's placement).
fn usable(m: &DMat4) -> bool {
    m.is_finite() && m.determinant().abs() > 1e-300 && m.inverse().is_finite()
}

impl Pbrt {
    fn new(main: &Path) -> Pbrt {
        let identity = [DMat4::IDENTITY; 2];
        Pbrt {
            ir: Ir::default(),
            main: main.to_path_buf(),
            state: State {
                ctm: identity,
                active: [true, true],
                material: None,
                area: None,
                reverse: false,
            },
            stack: Vec::new(),
            coords: HashMap::new(),
            named_materials: HashMap::new(),
            objects: HashMap::new(),
            object: None,
            times: [0.0, 1.0],
            times_loc: None,
            camera: None,
            film: None,
            plys: HashMap::new(),
            world: false,
        }
    }

    /// Applies `m` after the CTM (pbrt's `ctm = ctm * m`) at the active times.
    fn concat(&mut self, m: DMat4) {
        for i in 0..2 {
            if self.state.active[i] {
                self.state.ctm[i] *= m;
            }
        }
    }

    fn set(&mut self, m: DMat4) {
        for i in 0..2 {
            if self.state.active[i] {
                self.state.ctm[i] = m;
            }
        }
    }

    fn file(&mut self, path: &Path, text: &str, depth: usize) -> Result<(), ImportError> {
        let tokens =
            lexer::tokenize(text).map_err(|(line, column, message)| ImportError::Scene {
                file: path.to_path_buf(),
                line: Some(line),
                message: format!("column {column}: {message}"),
            })?;
        let mut c = Cursor {
            tokens: &tokens,
            at: 0,
            file: Arc::new(path.to_path_buf()),
        };
        while let Some(t) = tokens.get(c.at) {
            let loc = c.loc(t);
            let Kind::Word(d) = &t.kind else {
                return Err(loc.error("expected a directive (a bare word such as Shape or LookAt)"));
            };
            c.at += 1;
            self.directive(d, &mut c, loc, depth)?;
        }
        Ok(())
    }

    fn directive(
        &mut self,
        d: &str,
        c: &mut Cursor,
        loc: Location,
        depth: usize,
    ) -> Result<(), ImportError> {
        match d {
            "Identity" => self.set(DMat4::IDENTITY),
            "Translate" => {
                let v = c.nums::<3>(d)?;
                self.concat(DMat4::from_translation(DVec3::from(v)));
            }
            "Scale" => {
                let v = c.nums::<3>(d)?;
                self.concat(DMat4::from_scale(DVec3::from(v)));
            }
            "Rotate" => {
                let [angle, x, y, z] = c.nums::<4>(d)?;
                let axis = DVec3::new(x, y, z).normalize_or_zero();
                if axis == DVec3::ZERO {
                    return Err(loc.error("Rotate: the axis is zero"));
                }
                self.concat(DMat4::from_axis_angle(axis, angle.to_radians()));
            }
            "LookAt" => {
                let v = c.nums::<9>(d)?;
                let m = pbrt_look_at(
                    DVec3::new(v[0], v[1], v[2]),
                    DVec3::new(v[3], v[4], v[5]),
                    DVec3::new(v[6], v[7], v[8]),
                )
                .ok_or_else(|| {
                    loc.error("LookAt: eye and target coincide, or up is parallel to the view")
                })?;
                self.concat(m);
            }
            "Transform" => {
                let m = c.matrix(d)?;
                self.set(DMat4::from_cols_array(&m));
            }
            "ConcatTransform" => {
                let m = c.matrix(d)?;
                self.concat(DMat4::from_cols_array(&m));
            }
            "CoordinateSystem" => {
                let name = c.string(d)?;
                self.coords.insert(name, self.state.ctm);
            }
            "CoordSysTransform" => {
                let name = c.string(d)?;
                match self.coords.get(&name) {
                    Some(m) => self.state.ctm = *m,
                    None => self.ir.warn(
                        &loc,
                        format!("CoordSysTransform: unknown coordinate system \"{name}\", ignored"),
                    ),
                }
            }
            "TransformTimes" => {
                let [a, b] = c.nums::<2>(d)?;
                if self.world {
                    // pbrt-v4 refuses it too: the times are an option, fixed before the world.
                    return Err(loc.error(
                        "TransformTimes: not allowed after WorldBegin (pbrt-v4 takes it only before)",
                    ));
                }
                if !(a.is_finite() && b.is_finite()) {
                    return Err(loc.error("TransformTimes: the times must be finite"));
                }
                if a > b {
                    return Err(loc.error("TransformTimes: start after end"));
                }
                self.times = [a, b];
                self.times_loc = Some(loc);
            }
            "ActiveTransform" => {
                let w = c.word(d)?;
                self.state.active = match w.as_str() {
                    "StartTime" => [true, false],
                    "EndTime" => [false, true],
                    "All" => [true, true],
                    _ => {
                        return Err(loc.error(format!(
                            "ActiveTransform: expected StartTime, EndTime or All, got {w}"
                        )));
                    }
                };
            }
            "ReverseOrientation" => self.state.reverse = !self.state.reverse,
            "AttributeBegin" | "TransformBegin" => self.stack.push((self.state.clone(), loc)),
            "AttributeEnd" | "TransformEnd" => {
                let (saved, _) = self
                    .stack
                    .pop()
                    .ok_or_else(|| loc.error(format!("{d} without a matching begin")))?;
                if d == "TransformEnd" {
                    self.state.ctm = saved.ctm;
                    self.state.active = saved.active;
                } else {
                    self.state = saved;
                }
            }
            "Option" => {
                let p = c.params(d)?;
                p.unused(d, &mut self.ir.warnings);
            }
            "ColorSpace" => {
                let name = c.string(d)?;
                if name != "srgb" {
                    self.ir.warn(
                        &loc,
                        format!("ColorSpace \"{name}\": colours are taken as linear sRGB"),
                    );
                }
            }
            "Camera" => {
                let kind = c.string(d)?;
                let p = c.params(d)?;
                self.coords
                    .insert("camera".into(), self.state.ctm.map(|m| m.inverse()));
                self.camera = Some((kind, p, self.state.ctm, loc));
            }
            "Film" => {
                let _kind = c.string(d)?;
                self.film = Some((c.params(d)?, loc));
            }
            "Sampler" => {
                let kind = c.string(d)?;
                let p = c.params(d)?;
                self.sampler(&kind, &p, &loc)?;
                p.unused(&format!("Sampler \"{kind}\""), &mut self.ir.warnings);
            }
            "PixelFilter" => {
                let kind = c.string(d)?;
                let p = c.params(d)?;
                self.filter(&kind, &p, &loc)?;
                p.unused(&format!("PixelFilter \"{kind}\""), &mut self.ir.warnings);
            }
            "Integrator" => {
                let kind = c.string(d)?;
                let p = c.params(d)?;
                if !matches!(kind.as_str(), "volpath" | "path") {
                    self.ir.warn(
                        &loc,
                        format!("Integrator \"{kind}\": rendered with Obscura's path tracer"),
                    );
                }
                let depth = p.num("maxdepth")?.unwrap_or(5.0);
                if !(1.0..=1e6).contains(&depth) {
                    return Err(
                        loc.error(format!("Integrator: maxdepth must be >= 1, got {depth}"))
                    );
                }
                p.unused(&format!("Integrator \"{kind}\""), &mut self.ir.warnings);
                self.ir.integrator = Some(("path", Some(depth as u32), loc));
            }
            "Accelerator" => {
                let _ = c.string(d)?;
                let _ = c.params(d)?;
            }
            "MakeNamedMedium" | "MediumInterface" | "Texture" | "Attribute" => {
                let n = if d == "Texture" { 3 } else { 1 };
                for _ in 0..n {
                    let _ = c.string(d)?;
                }
                if d == "MediumInterface"
                    && matches!(c.tokens.get(c.at).map(|t| &t.kind), Some(Kind::Str(_)))
                {
                    // The optional second name (exterior); a parameter declaration has a space.
                    if let Some(Kind::Str(s)) = c.tokens.get(c.at).map(|t| &t.kind)
                        && !s.contains(' ')
                    {
                        c.at += 1;
                    }
                }
                let _ = c.params(d)?;
                self.ir.warn(&loc, format!("{d}: not supported, ignored"));
            }
            "WorldBegin" => {
                self.world = true;
                self.state.ctm = [DMat4::IDENTITY; 2];
                self.state.active = [true, true];
                self.coords.insert("world".into(), self.state.ctm);
            }
            "WorldEnd" => {}
            "Material" => {
                let kind = c.string(d)?;
                let p = c.params(d)?;
                let wanted = format!("{kind}-{}", loc.line);
                self.state.material = self.material(&wanted, &kind, &p, &loc, true)?;
            }
            "MakeNamedMaterial" => {
                let name = c.string(d)?;
                let p = c.params(d)?;
                let kind = p.string("type")?.ok_or_else(|| {
                    loc.error(format!(
                        "MakeNamedMaterial \"{name}\": needs \"string type\""
                    ))
                })?;
                let m = self.material(&name, &kind, &p, &loc, false)?;
                self.named_materials.insert(name, m);
            }
            "NamedMaterial" => {
                let name = c.string(d)?;
                match self.named_materials.get(&name) {
                    Some(m) => self.state.material = m.clone(),
                    None => {
                        return Err(
                            loc.error(format!("NamedMaterial: no material named \"{name}\""))
                        );
                    }
                }
            }
            "LightSource" => {
                let kind = c.string(d)?;
                let p = c.params(d)?;
                self.light(&kind, &p, &loc)?;
                p.unused(&format!("LightSource \"{kind}\""), &mut self.ir.warnings);
            }
            "AreaLightSource" => {
                let kind = c.string(d)?;
                let p = c.params(d)?;
                if kind != "diffuse" {
                    return Err(loc.error(format!(
                        "AreaLightSource \"{kind}\": only \"diffuse\" exists"
                    )));
                }
                let l = p.rgb("L", &mut self.ir.warnings)?.unwrap_or([1.0; 3]);
                let scale = p.num_or("scale", 1.0)?;
                if p.boolean("twosided")? == Some(true) {
                    self.ir.warn(
                        &loc,
                        "AreaLightSource: twosided: Obscura's area lights emit on one side only",
                    );
                }
                p.unused("AreaLightSource \"diffuse\"", &mut self.ir.warnings);
                self.state.area = Some(f3(l.map(|x| x * scale)));
            }
            "Shape" => {
                let kind = c.string(d)?;
                let p = c.params(d)?;
                self.shape(&kind, &p, &loc)?;
                p.unused(&format!("Shape \"{kind}\""), &mut self.ir.warnings);
            }
            "ObjectBegin" => {
                let name = c.string(d)?;
                if self.object.is_some() {
                    return Err(loc.error("ObjectBegin inside another ObjectBegin"));
                }
                self.stack.push((self.state.clone(), loc.clone()));
                self.object = Some((name, Vec::new(), loc));
            }
            "ObjectEnd" => {
                let (name, shapes, _) = self
                    .object
                    .take()
                    .ok_or_else(|| loc.error("ObjectEnd without ObjectBegin"))?;
                self.objects.insert(name, shapes);
                if let Some((saved, _)) = self.stack.pop() {
                    self.state = saved;
                }
            }
            "ObjectInstance" => {
                let name = c.string(d)?;
                let shapes = self
                    .objects
                    .get(&name)
                    .ok_or_else(|| {
                        loc.error(format!("ObjectInstance: no object named \"{name}\""))
                    })?
                    .clone();
                let [start, end] = self.state.ctm;
                for mut s in shapes {
                    let object_end = s.transform_end.unwrap_or(s.transform);
                    s.transform = start * s.transform;
                    let e = end * object_end;
                    s.transform_end = (e != s.transform).then_some(e);
                    s.loc = loc.clone();
                    self.ir.shapes.push(s);
                }
            }
            "Include" | "Import" => {
                let name = c.string(d)?;
                if depth >= MAX_INCLUDE_DEPTH {
                    return Err(loc.error(format!(
                        "{d}: files nested more than {MAX_INCLUDE_DEPTH} deep"
                    )));
                }
                let path = self.resolve(&name);
                let text = read_text(&path).map_err(|e| match e {
                    ImportError::Io { source, .. } => loc.error(format!(
                        "{d} \"{name}\": cannot read {}: {source}",
                        path.display()
                    )),
                    other => other,
                })?;
                self.file(&path, &text, depth + 1)?;
            }
            other => {
                // Skip its arguments: everything up to the next bare word.
                while c.tokens.get(c.at).is_some_and(
                    |t| !matches!(t.kind, Kind::Word(ref w) if w != "true" && w != "false"),
                ) {
                    c.at += 1;
                }
                self.ir
                    .warn(&loc, format!("{other}: unknown directive, ignored"));
            }
        }
        Ok(())
    }

    /// A file named in the scene: relative to the main file's folder, as pbrt does.
    fn resolve(&self, name: &str) -> PathBuf {
        let base = self.main.parent().unwrap_or(Path::new(""));
        base.join(name)
    }

    /// pbrt-v4's realistic `aperture` as the scene format's stop. pbrt scales every aperture
    /// image to pass the round stop's light; Obscura's realistic camera makes the film's
    /// centre see the scene's radiance whatever the stop's shape, so the light needs nothing.
    ///
    /// pbrt draws its built-in shapes into an image over the stop's square and flips it
    /// vertically before use, so a shape drawn with a vertex up has it at lens -y:
    /// - `"square"`: the middle half of the square, side r for stop radius r: the polygon of
    ///   4 blades at 45 degrees on the circle of radius r / sqrt(2);
    /// - `"pentagon"`: the regular pentagon on the circle of radius 0.8 r, a vertex at lens
    ///   -y (rotation 270 degrees);
    /// - an image file: the stop's `aperture_image` (read as luminance where pbrt averages
    ///   the channels: the same for a grey image);
    /// - `"gaussian"` and `"star"` have no polygon and no file: a warning, and the round stop.
    ///
    /// The polygons scale `aperture_diameter` to their circles.
    fn stop(
        &mut self,
        name: &str,
        loc: &Location,
        aperture_diameter: &mut f32,
    ) -> Result<Option<StopIr>, ImportError> {
        Ok(match name {
            "" => None,
            "square" => {
                *aperture_diameter *= std::f32::consts::FRAC_1_SQRT_2;
                Some(StopIr::Blades(4, 45.0))
            }
            "pentagon" => {
                *aperture_diameter *= 0.8;
                Some(StopIr::Blades(5, 270.0))
            }
            "gaussian" | "star" => {
                self.ir.warn(
                    loc,
                    format!(
                        "Camera \"realistic\": \"string aperture\" \"{name}\" is not carried over; the stop stays round"
                    ),
                );
                None
            }
            file => {
                let path = self.resolve(file);
                if !path.is_file() {
                    return Err(loc.error(format!(
                        "Camera \"realistic\": \"string aperture\": no image file {}",
                        path.display()
                    )));
                }
                Some(StopIr::Image(path))
            }
        })
    }

    fn sampler(&mut self, kind: &str, p: &Params, loc: &Location) -> Result<(), ImportError> {
        let (ours, spp) = match kind {
            "zsobol" | "sobol" | "paddedsobol" => ("sobol", p.num("pixelsamples")?.unwrap_or(16.0)),
            "pmj02bn" => {
                self.ir.warn(
                    loc,
                    "Sampler \"pmj02bn\": rendered with Obscura's Sobol sampler",
                );
                ("sobol", p.num("pixelsamples")?.unwrap_or(16.0))
            }
            "halton" => ("halton", p.num("pixelsamples")?.unwrap_or(16.0)),
            "independent" => ("independent", p.num("pixelsamples")?.unwrap_or(4.0)),
            "stratified" => {
                let (x, y) = (p.num_or("xsamples", 4.0)?, p.num_or("ysamples", 4.0)?);
                let _ = p.boolean("jitter")?;
                ("stratified", x * y)
            }
            other => {
                self.ir.warn(
                    loc,
                    format!("Sampler \"{other}\": unknown, using Obscura's default"),
                );
                return Ok(());
            }
        };
        if !(1.0..=f64::from(u32::MAX)).contains(&spp) {
            return Err(loc.error(format!(
                "Sampler: samples per pixel must be >= 1, got {spp}"
            )));
        }
        let seed = match p.num("seed")? {
            Some(s) if s >= 0.0 && s.fract() == 0.0 && s < 1.8e19 => Some(s as u64),
            Some(s) => {
                return Err(loc.error(format!(
                    "Sampler: seed must be a whole number >= 0, got {s}"
                )));
            }
            None => None,
        };
        self.ir.sampler = Some((ours, spp as u32, seed, loc.clone()));
        Ok(())
    }

    fn filter(&mut self, kind: &str, p: &Params, loc: &Location) -> Result<(), ImportError> {
        let (ours, default) = match kind {
            "box" => ("box", 0.5),
            "gaussian" => ("gaussian", 1.5),
            "triangle" => ("triangle", 2.0),
            "mitchell" => ("mitchell", 2.0),
            other => {
                self.ir.warn(
                    loc,
                    format!("PixelFilter \"{other}\": not supported, using a gaussian"),
                );
                ("gaussian", 1.5)
            }
        };
        let (x, y) = (p.num_or("xradius", default)?, p.num_or("yradius", default)?);
        if x != y {
            self.ir.warn(
                loc,
                format!(
                    "PixelFilter: xradius {x} and yradius {y} differ; using {}",
                    x.max(y)
                ),
            );
        }
        if kind == "mitchell"
            && (p.num("B")?.is_some_and(|b| b != 1.0 / 3.0)
                || p.num("C")?.is_some_and(|c| c != 1.0 / 3.0))
        {
            self.ir
                .warn(loc, "PixelFilter: Obscura's mitchell has B = C = 1/3");
        }
        let radius = x.max(y);
        let widest = f64::from(FilterSettings::MAX_RADIUS);
        if !(radius > 0.0 && radius <= widest) {
            return Err(loc.error(format!(
                "PixelFilter: radius must be in (0, {widest}], got {radius}"
            )));
        }
        let film = self.ir.film.get_or_insert(FilmIr {
            resolution: [1280, 720],
            crop: None,
            filter: None,
            loc: None,
        });
        let mut filter = FilterIr::new(ours, radius as f32);
        if kind == "gaussian" {
            // pbrt-v4's Gaussian: its radius and sigma (default 0.5) are Obscura's.
            let sigma = p.num_or("sigma", 0.5)?;
            if !FilterSettings::sigma_fits(radius as f32, sigma as f32) {
                return Err(loc.error(format!(
                    "PixelFilter \"gaussian\": sigma must be in (0, {}] and at most {} x \
                     radius ({radius}), got {sigma}",
                    FilterSettings::MAX_RADIUS,
                    FilterSettings::MAX_SIGMA_PER_RADIUS
                )));
            }
            filter.sigma = Some(sigma as f32);
        }
        film.filter = Some(filter);
        Ok(())
    }

    /// A material, added to the scene; its name there (None for pbrt's default diffuse).
    fn material(
        &mut self,
        wanted: &str,
        kind: &str,
        p: &Params,
        loc: &Location,
        anonymous: bool,
    ) -> Result<Option<String>, ImportError> {
        let directive = format!("material \"{kind}\"");
        let w = &mut self.ir.warnings;
        let textured = |p: &Params, name: &str, w: &mut Vec<String>| {
            if p.type_of(name) == Some("texture") {
                let _ = p.string(name);
                w.push(format!("{loc}: {directive}: parameter \"{name}\" is a texture, which is not supported; using the default"));
            }
        };
        let clamp = |r: [f64; 3]| f3(r.map(|x| x.clamp(0.0, 1.0)));
        let m = match kind {
            "" | "none" | "interface" => {
                w.push(format!(
                    "{loc}: {directive}: not supported, shapes get the default diffuse"
                ));
                return Ok(None);
            }
            "diffuse" | "coateddiffuse" => {
                textured(p, "reflectance", w);
                let r = p.rgb("reflectance", w)?.unwrap_or([0.5; 3]);
                if kind == "coateddiffuse" {
                    w.push(format!(
                        "{loc}: {directive}: approximated by its diffuse base (no coating)"
                    ));
                    for k in [
                        "roughness",
                        "uroughness",
                        "vroughness",
                        "thickness",
                        "eta",
                        "albedo",
                        "g",
                        "maxdepth",
                        "nsamples",
                        "remaproughness",
                    ] {
                        let _ = p.type_of(k).map(|_| {
                            p.0.iter()
                                .filter(|q| q.name == k)
                                .for_each(|q| q.used.set(true))
                        });
                    }
                }
                MaterialIr::Diffuse(clamp(r))
            }
            "conductor" | "coatedconductor" => {
                if kind == "coatedconductor" {
                    w.push(format!(
                        "{loc}: {directive}: approximated by a bare conductor"
                    ));
                }
                let f0 = match p.rgb("reflectance", w)? {
                    Some(r) => r,
                    None => {
                        let named = |n: &str| match n {
                            "metal-Au-eta" | "metal-Au-k" => Some([1.0, 0.782, 0.344]),
                            "metal-Ag-eta" | "metal-Ag-k" => Some([0.972, 0.960, 0.915]),
                            "metal-Al-eta" | "metal-Al-k" => Some([0.913, 0.922, 0.924]),
                            "metal-Cu-eta" | "metal-Cu-k" => Some([0.955, 0.638, 0.538]),
                            _ => None,
                        };
                        let eta_ty = p.type_of("eta").map(str::to_string);
                        match eta_ty.as_deref() {
                            Some("spectrum") => {
                                let n = p.string("eta")?.unwrap_or_default();
                                p.0.iter()
                                    .filter(|q| q.name == "k")
                                    .for_each(|q| q.used.set(true));
                                named(&n).unwrap_or_else(|| {
                                    w.push(format!("{loc}: {directive}: spectrum \"{n}\" is not known; using copper"));
                                    [0.955, 0.638, 0.538]
                                })
                            }
                            Some(_) => {
                                let eta = p.rgb("eta", w)?.unwrap_or([0.2, 0.9, 1.1]);
                                let k = p.rgb("k", w)?.unwrap_or([3.9, 2.45, 2.14]);
                                std::array::from_fn(|i| {
                                    let (n, k) = (eta[i], k[i]);
                                    ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
                                })
                            }
                            // pbrt's default conductor is copper.
                            None => [0.955, 0.638, 0.538],
                        }
                    }
                };
                let rough = p.num("roughness")?;
                let (u, v) = (
                    p.num("uroughness")?.or(rough).unwrap_or(0.0),
                    p.num("vroughness")?.or(rough).unwrap_or(0.0),
                );
                if u != v {
                    w.push(format!(
                        "{loc}: {directive}: anisotropic roughness averaged"
                    ));
                }
                let r = 0.5 * (u + v);
                let remap = p.boolean("remaproughness")?.unwrap_or(true);
                // pbrt's alpha: sqrt(r) when remapped, else r; Obscura's alpha is roughness^2.
                let alpha = if remap { r.max(0.0).sqrt() } else { r.max(0.0) };
                if alpha == 0.0 {
                    w.push(format!("{loc}: {directive}: a smooth conductor is a mirror of its normal-incidence reflectance"));
                    MaterialIr::Mirror(clamp(f0))
                } else {
                    MaterialIr::RoughConductor(clamp(f0), (alpha.sqrt().min(1.0)) as f32)
                }
            }
            "dielectric" | "thindielectric" => {
                let eta = match p.type_of("eta") {
                    Some("float") | None => p.num("eta")?.unwrap_or(1.5),
                    Some(_) => {
                        w.push(format!(
                            "{loc}: {directive}: a spectral eta is not supported; using 1.5"
                        ));
                        p.0.iter()
                            .filter(|q| q.name == "eta")
                            .for_each(|q| q.used.set(true));
                        1.5
                    }
                };
                if eta.is_nan() || eta <= 0.0 {
                    return Err(loc.error(format!("{directive}: eta must be > 0, got {eta}")));
                }
                let rough = [
                    p.num("roughness")?,
                    p.num("uroughness")?,
                    p.num("vroughness")?,
                ];
                if rough.iter().flatten().any(|&r| r != 0.0) {
                    w.push(format!("{loc}: {directive}: rough glass rendered smooth"));
                }
                if kind == "thindielectric" {
                    w.push(format!("{loc}: {directive}: rendered as solid glass"));
                }
                MaterialIr::Dielectric(eta as f32)
            }
            other => {
                w.push(format!(
                    "{loc}: {directive}: not supported (material \"{other}\"), using a 0.5 diffuse"
                ));
                for q in &p.0 {
                    q.used.set(true);
                }
                MaterialIr::Diffuse([0.5; 3])
            }
        };
        // MakeNamedMaterial's own parameter; normal and displacement maps warn as unused.
        let _ = p.string("type");
        p.unused(&directive, &mut self.ir.warnings);
        Ok(Some(self.ir.add_material(wanted, m, loc, anonymous)))
    }

    fn light(&mut self, kind: &str, p: &Params, loc: &Location) -> Result<(), ImportError> {
        let w = &mut self.ir.warnings;
        let scale = p.num_or("scale", 1.0)?;
        if p.num("power")?.is_some() {
            w.push(format!("{loc}: LightSource \"{kind}\": power is not supported; using the spectrum and scale"));
        }
        let ctm = self.state.ctm[0];
        let light = match kind {
            "point" | "spot" => {
                if kind == "spot" {
                    w.push(format!(
                        "{loc}: LightSource \"spot\": rendered as a point light (no cone)"
                    ));
                    for k in ["to", "coneangle", "conedeltaangle"] {
                        let _ = p.nums(k)?;
                    }
                }
                let i = p.rgb("I", w)?.unwrap_or([1.0; 3]);
                let from = DVec3::from(p.fixed::<3>("from")?.unwrap_or([0.0; 3]));
                LightIr::Point {
                    position: f3(ctm.transform_point3(from).to_array()),
                    intensity: f3(i.map(|x| x * scale)),
                }
            }
            "distant" => {
                let l = p.rgb("L", w)?.unwrap_or([1.0; 3]);
                let from = DVec3::from(p.fixed::<3>("from")?.unwrap_or([0.0; 3]));
                let to = DVec3::from(p.fixed::<3>("to")?.unwrap_or([0.0, 0.0, 1.0]));
                let dir = ctm.transform_vector3(to - from);
                if (dir.length().is_nan() || dir.length() <= 0.0) || !dir.is_finite() {
                    return Err(loc.error("LightSource \"distant\": from and to coincide"));
                }
                LightIr::Distant {
                    direction: f3(dir.normalize().to_array()),
                    irradiance: f3(l.map(|x| x * scale)),
                }
            }
            "infinite" => {
                if let Some(f) = p.string("filename")? {
                    // pbrt-v4's maps are equal-area squares: resampled into an
                    // equirectangular map in the light's own frame.
                    let path = self.resolve(&f);
                    let (image, _) = obscura_render::read_exr(&path).map_err(|e| {
                        loc.error(format!("LightSource \"infinite\": image \"{f}\": {e} (only EXR images are read)"))
                    })?;
                    if image.width != image.height || image.width == 0 {
                        return Err(loc.error(format!(
                            "LightSource \"infinite\": image \"{f}\" is {}x{}: pbrt-v4 needs a square equal-area image",
                            image.width, image.height
                        )));
                    }
                    if p.type_of("L").is_some() {
                        return Err(
                            loc.error("LightSource \"infinite\": give L or filename, not both")
                        );
                    }
                    let map = equal_area::equirect_from_equal_area(&image);
                    let i = self.ir.maps.len();
                    self.ir
                        .maps
                        .push((format!("{i:04}-environment.exr"), Arc::new(map)));
                    self.ir.lights.push((
                        LightIr::Environment {
                            radiance: [scale as f32; 3],
                            file: Some(crate::scene::MapIr::Made(i)),
                            transform: Some(ctm),
                        },
                        loc.clone(),
                    ));
                    return Ok(());
                }
                let l = p.rgb("L", w)?.unwrap_or([1.0; 3]);
                LightIr::Environment {
                    radiance: f3(l.map(|x| x * scale)),
                    file: None,
                    transform: None,
                }
            }
            other => {
                w.push(format!(
                    "{loc}: LightSource \"{other}\": not supported, ignored"
                ));
                for q in &p.0 {
                    q.used.set(true);
                }
                return Ok(());
            }
        };
        self.ir.lights.push((light, loc.clone()));
        Ok(())
    }

    fn shape(&mut self, kind: &str, p: &Params, loc: &Location) -> Result<(), ImportError> {
        let directive = format!("Shape \"{kind}\"");
        let geometry = match kind {
            "sphere" => {
                let radius = p.num_or("radius", 1.0)?;
                if radius.is_nan() || radius <= 0.0 {
                    return Err(loc.error(format!("{directive}: radius must be > 0, got {radius}")));
                }
                let partial = p.num("zmin")?.is_some_and(|z| z > -radius)
                    || p.num("zmax")?.is_some_and(|z| z < radius)
                    || p.num("phimax")?.is_some_and(|f| f < 360.0);
                if partial {
                    return Err(loc.error(format!(
                        "{directive}: partial spheres (zmin, zmax, phimax) are not supported"
                    )));
                }
                if self.state.reverse && self.state.area.is_some() {
                    self.ir.warn(loc, format!("{directive}: ReverseOrientation: Obscura's emitting spheres emit outwards"));
                }
                GeometryIr::Sphere {
                    center: [0.0; 3],
                    radius: radius as f32,
                }
            }
            "disk" | "cylinder" => {
                let radius = p.num_or("radius", 1.0)?;
                let phimax = p.num_or("phimax", 360.0)?.clamp(0.0, 360.0);
                if radius.is_nan() || radius <= 0.0 || phimax <= 0.0 {
                    return Err(loc.error(format!("{directive}: radius and phimax must be > 0")));
                }
                let mesh = if kind == "disk" {
                    let (h, inner) = (p.num_or("height", 0.0)?, p.num_or("innerradius", 0.0)?);
                    if inner.is_nan() || inner < 0.0 || inner >= radius {
                        return Err(
                            loc.error(format!("{directive}: innerradius must be in [0, radius)"))
                        );
                    }
                    lathe(&[(inner, h), (radius, h)], phimax, true)
                } else {
                    let (z0, z1) = (p.num_or("zmin", -1.0)?, p.num_or("zmax", 1.0)?);
                    if z0 == z1 {
                        return Err(loc.error(format!("{directive}: zmin equals zmax")));
                    }
                    lathe(&[(radius, z0.min(z1)), (radius, z0.max(z1))], phimax, false)
                };
                let mesh = mesh.map_err(|e| loc.error(format!("{directive}: {e}")))?;
                self.ir.warn(
                    loc,
                    format!(
                        "{directive}: tessellated into {} triangles",
                        mesh.triangle_count()
                    ),
                );
                let mesh = if self.state.reverse {
                    flipped(mesh)
                } else {
                    mesh
                };
                let i = self.ir.meshes.len();
                self.ir
                    .meshes
                    .push((format!("{i:04}-{kind}.obj"), Arc::new(mesh)));
                GeometryIr::Mesh(i)
            }
            "trianglemesh" | "bilinearmesh" | "plymesh" => {
                let mesh = match kind {
                    "plymesh" => {
                        let name = p.string("filename")?.ok_or_else(|| {
                            loc.error(format!("{directive}: needs \"string filename\""))
                        })?;
                        if p.type_of("displacement").is_some() {
                            p.0.iter()
                                .filter(|q| q.name == "displacement" || q.name == "edgelength")
                                .for_each(|q| q.used.set(true));
                            self.ir.warn(
                                loc,
                                format!("{directive}: displacement is not supported, ignored"),
                            );
                        }
                        let path = self.resolve(&name);
                        if let Some(&i) = self.plys.get(&path).filter(|_| !self.state.reverse) {
                            self.place(GeometryIr::Mesh(i), loc);
                            return Ok(());
                        }
                        let bytes = std::fs::read(&path).map_err(|e| {
                            loc.error(format!("{directive}: cannot read {}: {e}", path.display()))
                        })?;
                        crate::ply::parse_ply(&bytes, &path)
                            .map_err(|e| loc.error(format!("{directive}: {e}")))?
                    }
                    _ => self.inline_mesh(kind, p, loc)?,
                };
                let mesh = if self.state.reverse {
                    flipped(mesh)
                } else {
                    mesh
                };
                let stem = match kind {
                    "plymesh" => p
                        .string("filename")?
                        .map(|f| {
                            Path::new(&f)
                                .file_stem()
                                .map_or("mesh".into(), |s| s.to_string_lossy().into_owned())
                        })
                        .unwrap_or_default(),
                    _ => kind.to_string(),
                };
                let i = self.ir.meshes.len();
                let name: String = stem
                    .chars()
                    .map(|c| {
                        if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                            c
                        } else {
                            '_'
                        }
                    })
                    .collect();
                self.ir
                    .meshes
                    .push((format!("{i:04}-{name}.obj"), Arc::new(mesh)));
                if kind == "plymesh"
                    && !self.state.reverse
                    && let Some(f) = p.string("filename")?
                {
                    self.plys.insert(self.resolve(&f), i);
                }
                GeometryIr::Mesh(i)
            }
            other => {
                self.ir.warn(
                    loc,
                    format!("{directive}: not supported (shape \"{other}\"), ignored"),
                );
                for q in &p.0 {
                    q.used.set(true);
                }
                return Ok(());
            }
        };
        for k in ["alpha", "emissionfilename"] {
            if p.type_of(k).is_some() {
                p.0.iter()
                    .filter(|q| q.name == k)
                    .for_each(|q| q.used.set(true));
                self.ir.warn(
                    loc,
                    format!("{directive}: parameter \"{k}\" is not supported, ignored"),
                );
            }
        }
        self.place(geometry, loc);
        Ok(())
    }

    /// Adds a shape with the current transform, material and area light (or to the object
    /// being defined).
    fn place(&mut self, geometry: GeometryIr, loc: &Location) {
        let [start, end] = self.state.ctm;
        let shape = ShapeIr {
            loc: loc.clone(),
            geometry,
            material: self.state.material.clone(),
            emission: self.state.area,
            transform: start,
            transform_end: (end != start).then_some(end),
        };
        if self.state.area.is_some() && self.object.is_some() {
            self.ir.warn(
                loc,
                "area lights inside ObjectBegin: pbrt ignores them; so does the import",
            );
        }
        match &mut self.object {
            Some((_, shapes, _)) => shapes.push(ShapeIr {
                emission: None,
                ..shape
            }),
            None => self.ir.shapes.push(shape),
        }
    }

    fn inline_mesh(
        &mut self,
        kind: &str,
        p: &Params,
        loc: &Location,
    ) -> Result<TriangleMesh, ImportError> {
        let directive = format!("Shape \"{kind}\"");
        let points = p
            .nums("P")?
            .ok_or_else(|| loc.error(format!("{directive}: needs \"point3 P\"")))?;
        if points.len() % 3 != 0 {
            return Err(loc.error(format!(
                "{directive}: P has {} numbers, not a multiple of 3",
                points.len()
            )));
        }
        let positions: Vec<Vec3> = points
            .chunks(3)
            .map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
            .collect();
        let per = if kind == "bilinearmesh" { 4 } else { 3 };
        let indices: Vec<f64> =
            match p.nums("indices")? {
                Some(i) => i,
                None if positions.len() == per => (0..per).map(|i| i as f64).collect(),
                None => return Err(loc.error(format!(
                    "{directive}: needs \"integer indices\" (only {per} vertices may go without)"
                ))),
            };
        if !indices.len().is_multiple_of(per) {
            return Err(loc.error(format!(
                "{directive}: {} indices, not a multiple of {per}",
                indices.len()
            )));
        }
        let index = |x: f64| -> Result<u32, ImportError> {
            if x >= 0.0 && x.fract() == 0.0 && (x as usize) < positions.len() {
                Ok(x as u32)
            } else {
                Err(loc.error(format!(
                    "{directive}: index {x} is out of range ({} vertices)",
                    positions.len()
                )))
            }
        };
        let mut triangles = Vec::new();
        let mut nonplanar = false;
        for c in indices.chunks(per) {
            let v: Vec<u32> = c.iter().map(|&x| index(x)).collect::<Result<_, _>>()?;
            if per == 3 {
                triangles.push([v[0], v[1], v[2]]);
            } else {
                // pbrt's patch p00, p10, p01, p11: two triangles, exact when it is planar.
                let [p00, p10, p01, p11] = [v[0], v[1], v[2], v[3]].map(|i| positions[i as usize]);
                let n = (p10 - p00).cross(p01 - p00);
                nonplanar |=
                    n.dot(p11 - p00).abs() > 1e-6 * n.length() * (p11 - p00).length().max(1e-30);
                triangles.push([v[0], v[1], v[3]]);
                triangles.push([v[0], v[3], v[2]]);
            }
        }
        if nonplanar {
            self.ir.warn(
                loc,
                format!(
                    "{directive}: non-planar bilinear patches approximated by two triangles each"
                ),
            );
        }
        let normals = match p.nums("N")? {
            Some(n) if n.len() == points.len() => Some(
                n.chunks(3)
                    .map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
                    .collect(),
            ),
            Some(n) => {
                return Err(loc.error(format!(
                    "{directive}: N has {} numbers for {} vertices",
                    n.len(),
                    positions.len()
                )));
            }
            None => None,
        };
        let uvs = match p.nums("uv")? {
            Some(t) if t.len() == 2 * positions.len() => Some(
                t.chunks(2)
                    .map(|c| Vec2::new(c[0] as f32, c[1] as f32))
                    .collect(),
            ),
            Some(t) => {
                return Err(loc.error(format!(
                    "{directive}: uv has {} numbers for {} vertices",
                    t.len(),
                    positions.len()
                )));
            }
            None => None,
        };
        let _ = p.nums("S");
        let _ = p.nums("faceIndices");
        TriangleMesh::new(positions, triangles, normals, uvs)
            .map_err(|e| loc.error(format!("{directive}: {e}")))
    }

    /// After the last directive: the camera and film.
    fn finish(&mut self) -> Result<(), ImportError> {
        if let Some((_, _, loc)) = &self.object {
            return Err(loc.error("ObjectBegin without ObjectEnd"));
        }
        if let Some((_, loc)) = self.stack.last() {
            self.ir.warn(loc, "AttributeBegin without AttributeEnd");
        }
        let film_loc = self.film.as_ref().map(|f| f.1.clone());
        // pbrt's film diagonal in mm, which only its realistic camera reads.
        let mut film_diagonal = 35.0;
        let mut film = self.ir.film.take().unwrap_or(FilmIr {
            resolution: [1280, 720],
            crop: None,
            filter: None,
            loc: None,
        });
        if let Some((p, loc)) = self.film.take() {
            let res = |name: &str, default: f64| -> Result<u32, ImportError> {
                let v = p.num_or(name, default)?;
                if v >= 1.0 && v <= f64::from(u32::MAX) && v.fract() == 0.0 {
                    Ok(v as u32)
                } else {
                    Err(loc.error(format!("Film: {name} must be a whole number >= 1, got {v}")))
                }
            };
            film.resolution = [res("xresolution", 1280.0)?, res("yresolution", 720.0)?];
            if let Some(c) = p.fixed::<4>("cropwindow")? {
                film.crop = Some(
                    f3([c[0], c[1], c[2]])
                        .into_iter()
                        .chain([c[3] as f32])
                        .collect::<Vec<_>>()
                        .try_into()
                        .unwrap_or([0.0, 1.0, 0.0, 1.0]),
                );
            }
            let _ = p.string("filename")?;
            film_diagonal = p.num_or("diagonal", 35.0)?;
            for k in [
                "iso",
                "exposuretime",
                "whitebalance",
                "sensor",
                "savefp16",
                "maxcomponentvalue",
            ] {
                p.0.iter()
                    .filter(|q| q.name == k)
                    .for_each(|q| q.used.set(true));
            }
            p.unused("Film", &mut self.ir.warnings);
            film.loc = Some(loc);
        }
        let _ = film_loc;
        let res = film.resolution;
        self.ir.film = Some(film);

        let Some((kind, p, ctm, loc)) = self.camera.take() else {
            return Err(ImportError::Scene {
                file: self.main.clone(),
                line: None,
                message: "no Camera directive (pbrt's default camera is not imported)".into(),
            });
        };
        if !usable(&ctm[0]) || !usable(&ctm[1]) {
            return Err(loc.error("Camera: the camera transform is singular or not finite"));
        }
        let shutter = [
            p.num_or("shutteropen", 0.0)?,
            p.num_or("shutterclose", 1.0)?,
        ];
        if shutter[0] > shutter[1] {
            return Err(loc.error("Camera: shutteropen is after shutterclose"));
        }
        // The scene format moves things from shutter open to close; pbrt from the start to the
        // end transform time. Carry each motion over to the shutter's ends.
        let over_shutter = |start: DMat4, end: DMat4, what: &Location, kind: &str| {
            motion_over_shutter(start, end, self.times, shutter).map_err(|message| {
                let [t0, t1] = self.times;
                let (at, times) = match &self.times_loc {
                    Some(at) => (at, format!("TransformTimes {t0} {t1}")),
                    None => (&loc, format!("no TransformTimes (pbrt's {t0} {t1})")),
                };
                at.error(format!(
                    "{times} with the shutter {} {} (Camera at {loc}): the {kind} at {what} {message}",
                    shutter[0], shutter[1]
                ))
            })
        };
        let (pose, pose_end) = over_shutter(ctm[0].inverse(), ctm[1].inverse(), &loc, "camera")?;
        let mut shapes = std::mem::take(&mut self.ir.shapes);
        for s in &mut shapes {
            if let Some(end) = s.transform_end {
                (s.transform, s.transform_end) = over_shutter(s.transform, end, &s.loc, "shape")?;
            }
        }
        self.ir.shapes = shapes;
        let mut cam = CameraIr {
            loc: loc.clone(),
            kind: "perspective",
            pose,
            pose_end,
            fov: None,
            fov_axis: None,
            screen_window: None,
            lens_radius: 0.0,
            focal_distance: None,
            shutter: [shutter[0] as f32, shutter[1] as f32],
            near: None,
            far: None,
            realistic: None,
        };
        let window = |p: &Params| -> Result<Option<[f32; 4]>, ImportError> {
            if let Some(w) = p.fixed::<4>("screenwindow")? {
                return Ok(Some(
                    f3([w[0], w[1], w[2]])
                        .into_iter()
                        .chain([w[3] as f32])
                        .collect::<Vec<_>>()
                        .try_into()
                        .unwrap_or([-1.0, 1.0, -1.0, 1.0]),
                ));
            }
            // pbrt's default window, from frameaspectratio when given.
            Ok(match p.num("frameaspectratio")? {
                Some(a) if a > 0.0 => Some(if a >= 1.0 {
                    [-a as f32, a as f32, -1.0, 1.0]
                } else {
                    [-1.0, 1.0, (-1.0 / a) as f32, (1.0 / a) as f32]
                }),
                _ => None,
            })
        };
        match kind.as_str() {
            "perspective" | "orthographic" => {
                if kind == "perspective" {
                    cam.fov = Some(p.num_or("fov", 90.0)? as f32);
                    cam.fov_axis = Some("smaller");
                } else {
                    cam.kind = "orthographic";
                }
                cam.screen_window = window(&p)?;
                cam.lens_radius = p.num_or("lensradius", 0.0)? as f32;
                cam.focal_distance = Some(p.num_or("focaldistance", 1e6)? as f32);
            }
            "spherical" => {
                let mapping = p.string("mapping")?.unwrap_or_else(|| "equalarea".into());
                if mapping != "equirectangular" {
                    return Err(loc.error(format!(
                        "Camera \"spherical\": mapping \"{mapping}\" is not supported (pbrt's default is equalarea); use \"string mapping\" \"equirectangular\""
                    )));
                }
                cam.kind = "environment";
                // pbrt's equirectangular image centre looks along camera -x, its left edge
                // along +x; Obscura's centre looks along +z: d_pbrt = P d_obscura.
                let p_from_obscura = DMat4::from_cols(
                    glam::DVec4::new(0.0, 0.0, -1.0, 0.0),
                    glam::DVec4::new(0.0, 1.0, 0.0, 0.0),
                    glam::DVec4::new(-1.0, 0.0, 0.0, 0.0),
                    glam::DVec4::W,
                );
                cam.pose *= p_from_obscura;
                cam.pose_end = cam.pose_end.map(|m| m * p_from_obscura);
            }
            "realistic" => {
                // pbrt-v4's parameters and defaults: lensfile (relative to the main scene
                // file's folder, as pbrt resolves every file name), aperturediameter 1 mm,
                // focusdistance 10; the film's diagonal (35 mm); aperture (round when absent).
                let Some(file) = p.string("lensfile")? else {
                    return Err(loc.error("Camera \"realistic\": \"string lensfile\" is required"));
                };
                cam.kind = "realistic";
                let mut aperture_diameter = p.num_or("aperturediameter", 1.0)? as f32;
                let stop = match p.string("aperture")? {
                    None => None,
                    Some(name) => self.stop(&name, &loc, &mut aperture_diameter)?,
                };
                cam.realistic = Some(RealisticIr {
                    lens_file: self.resolve(&file),
                    aperture_diameter,
                    focus_distance: p.num_or("focusdistance", 10.0)? as f32,
                    film_diagonal: film_diagonal as f32,
                    stop,
                });
            }
            other => {
                return Err(loc.error(format!(
                    "Camera \"{other}\": not supported (perspective, orthographic, spherical, realistic)"
                )));
            }
        }
        let _ = res;
        if self.ir.integrator.is_none() {
            // pbrt's default integrator: volpath with maxdepth 5.
            self.ir.integrator = Some(("path", Some(5), loc.clone()));
        }
        p.unused(&format!("Camera \"{kind}\""), &mut self.ir.warnings);
        self.ir.camera = Some(cam);
        Ok(())
    }
}

/// A motion given as pbrt gives it (`start` at transform time `times[0]`, `end` at `times[1]`)
/// as the scene format takes it: the transforms at shutter open and close (None at close: no
/// motion during the shutter). The error says why it cannot be carried over exactly.
///
/// pbrt-v4's `AnimatedTransform` decomposes each transform into translation, rotation (a
/// quaternion, by polar decomposition) and stretch, and between the two times interpolates
/// translation and stretch linearly and rotation by slerp the short way; before `times[0]` it
/// holds `start`, after `times[1]` `end`. Obscura's `AnimatedTransform` interpolates the same
/// way between the shutter's ends. Linear interpolation and slerp restricted to a
/// sub-interval are the same functions of time over it, and a decomposition of an
/// interpolated transform gives back its interpolated parts (a polar decomposition is unique,
/// and a blend of two positive stretches is positive), so the transforms at the shutter's ends
/// reproduce pbrt's motion exactly whenever the shutter lies within the transform times. A
/// shutter reaching beyond them would see pbrt's motion stop part way, which two transforms
/// cannot express. (Mirrored transforms, such as a camera after `Scale -1 1 1`, are the one
/// difference already there with matching times: pbrt-v4 leaves a reflection in its polar
/// factor unhandled, Obscura moves it into the stretch; the carrying over keeps Obscura's.)
fn motion_over_shutter(
    start: DMat4,
    end: DMat4,
    times: [f64; 2],
    shutter: [f64; 2],
) -> Result<(DMat4, Option<DMat4>), String> {
    let ([t0, t1], [open, close]) = (times, shutter);
    if start == end {
        return Ok((start, None));
    }
    if times == shutter {
        return Ok((start, Some(end)));
    }
    // A shutter wholly before or after the transform times sees one transform, held.
    if close <= t0 {
        return Ok((start, None));
    }
    if open >= t1 {
        return Ok((end, None));
    }
    if open < t0 || close > t1 {
        return Err(format!(
            "moves only from {t0} to {t1}, held still for the rest of the shutter in pbrt, which \
             Obscura's motion (from shutter open to close) cannot express; give the transforms \
             at the shutter's times (TransformTimes {open} {close})"
        ));
    }
    // Here t0 < t1 (t0 = t1 would have the shutter wholly before or after them).
    let key = |m: DMat4| {
        Transform::<World, Object>::from_matrix(m.as_mat4())
            .map_err(|e| format!("cannot be interpolated: {e}"))
    };
    let motion = AnimatedTransform::new(key(start)?, t0 as f32, key(end)?, t1 as f32)
        .map_err(|e| format!("cannot be interpolated: {e}"))?;
    let at = |time: f64| match time {
        t if t == t0 => start,
        t if t == t1 => end,
        t => motion.at(t as f32).matrix().as_dmat4(),
    };
    Ok(if open == close {
        (at(open), None)
    } else {
        (at(open), Some(at(close)))
    })
}

/// The surface swept by turning the polyline `profile` of (radius, z) points about +z by
/// `phimax` degrees, in 128 steps per full turn: pbrt's disk (`disk`: facing +z) and cylinder
/// (facing outwards), wound as pbrt orients them.
fn lathe(profile: &[(f64, f64)], phimax: f64, disk: bool) -> Result<TriangleMesh, String> {
    let steps = ((128.0 * phimax / 360.0).ceil() as u32).max(1);
    let mut positions = Vec::new();
    for i in 0..=steps {
        let phi = (phimax * f64::from(i) / f64::from(steps)).to_radians();
        for &(r, z) in profile {
            positions.push(Vec3::new(
                (r * phi.cos()) as f32,
                (r * phi.sin()) as f32,
                z as f32,
            ));
        }
    }
    let k = profile.len() as u32;
    let mut triangles = Vec::new();
    for i in 0..steps {
        for j in 0..k - 1 {
            let (a, b) = (i * k + j, (i + 1) * k + j);
            let (c, d) = (b + 1, a + 1);
            if disk {
                // Outer ring d -> c at larger radius: (a, d, c), (a, c, b) face +z; at the
                // centre a and b coincide and one triangle is enough.
                triangles.push([a, d, c]);
                if profile[j as usize].0 > 0.0 {
                    triangles.push([a, c, b]);
                }
            } else {
                // a, b at the lower z, d, c at the upper: (a, b, c), (a, c, d) face outwards.
                triangles.extend([[a, b, c], [a, c, d]]);
            }
        }
    }
    TriangleMesh::new(positions, triangles, None, None).map_err(|e| e.to_string())
}

/// The same mesh with each triangle's winding reversed (pbrt's `ReverseOrientation`).
fn flipped(mesh: TriangleMesh) -> TriangleMesh {
    let triangles = mesh
        .triangles()
        .iter()
        .map(|t| [t[0], t[2], t[1]])
        .collect();
    TriangleMesh::new(
        mesh.positions().to_vec(),
        triangles,
        mesh.normals().map(|n| n.iter().map(|v| -*v).collect()),
        mesh.uvs().map(<[Vec2]>::to_vec),
    )
    .unwrap_or(mesh)
}
