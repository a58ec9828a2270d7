//! Mitsuba 3 XML scenes, read with roxmltree: `<default>` and `$name` substitution, sensors,
//! shapes, BSDFs and emitters mapped onto the scene format.
//!
//! Conventions: Mitsuba's camera frame (its `lookat`) has +x = `cross(up, dir)`, to the
//! image's left, and its film flips x, so a Mitsuba image is not mirrored; the scene format's
//! camera has +x to the image's right, so the pose is `to_world * diag(-1, 1, 1)`. Its
//! environment maps turn the other way round from Obscura's (`u = atan2(x, -z) / 2 pi`), which
//! a mirroring light transform undoes.

use crate::error::{ImportError, Location};
use crate::scene::{
    CameraIr, FilmIr, FilterIr, GeometryIr, Imported, Ir, LightIr, MaterialIr, ShapeIr,
};
use glam::{DMat4, DVec3, DVec4, Vec2, Vec3};
use obscura_accel::TriangleMesh;
use obscura_render::FilterSettings;
use roxmltree::Node;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Reads a Mitsuba 3 XML scene file.
pub fn import_mitsuba(path: &Path) -> Result<Imported, ImportError> {
    let bytes = std::fs::read(path).map_err(|source| ImportError::Io {
        file: path.to_path_buf(),
        action: "cannot read",
        source,
    })?;
    let text = String::from_utf8(bytes).map_err(|_| ImportError::Scene {
        file: path.to_path_buf(),
        line: None,
        message: "the file is not UTF-8 text".into(),
    })?;
    parse_mitsuba(path, &text)
}

/// How deeply elements may nest. roxmltree parses an element's content by recursion, so a
/// deep enough file overflows the stack (an abort, not an error); Mitsuba scenes nest a handful
/// of levels, so this leaves room for any real one.
const MAX_XML_DEPTH: usize = 256;

/// Imports Mitsuba 3 XML text; `path` names it in messages and anchors relative files.
pub fn parse_mitsuba(path: &Path, text: &str) -> Result<Imported, ImportError> {
    check_depth(text, MAX_XML_DEPTH).map_err(|line| ImportError::Scene {
        file: path.to_path_buf(),
        line: Some(line),
        message: format!(
            "elements nested more than {MAX_XML_DEPTH} deep (a Mitsuba scene needs a few levels)"
        ),
    })?;
    let file = Arc::new(path.to_path_buf());
    let doc = roxmltree::Document::parse(text).map_err(|e| ImportError::Scene {
        file: path.to_path_buf(),
        line: Some(e.pos().row as usize),
        message: format!("not well-formed XML: {e}"),
    })?;
    let mut m = Mitsuba {
        ir: Ir::default(),
        doc: &doc,
        file,
        defaults: HashMap::new(),
        bsdfs: HashMap::new(),
        base: path.parent().map(Path::to_path_buf).unwrap_or_default(),
    };
    let root = doc.root_element();
    if root.tag_name().name() != "scene" {
        return Err(m.loc(root).error(format!(
            "<{}>: the root element must be <scene>",
            root.tag_name().name()
        )));
    }
    m.scene(root)?;
    Imported::new(path, m.ir)
}

/// Checks, before roxmltree sees the text, that no element is nested more than `limit` deep;
/// the error is the 1-based line of the first element too deep.
///
/// A scan of XML's lexical structure, enough to count open elements exactly in a well-formed
/// document: comments, CDATA sections, processing instructions and declarations are skipped,
/// and quoted attribute values may hold `>` and `/`. On malformed text the count may be off,
/// but roxmltree then stops at the first fault, no deeper than the scan has reached.
fn check_depth(text: &str, limit: usize) -> Result<(), usize> {
    let bytes = text.as_bytes();
    let line_at = |at: usize| bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
    // The position just after `end` searched from `from`, or the end of the text.
    let skip_past = |from: usize, end: &str| {
        text[from..]
            .find(end)
            .map_or(bytes.len(), |i| from + i + end.len())
    };
    let mut depth = 0usize;
    let mut at = 0;
    while let Some(i) = text[at..].find('<') {
        let start = at + i;
        let rest = &text[start..];
        if rest.starts_with("<!--") {
            at = skip_past(start + 4, "-->");
        } else if rest.starts_with("<![CDATA[") {
            at = skip_past(start + 9, "]]>");
        } else if rest.starts_with("<?") {
            at = skip_past(start + 2, "?>");
        } else if rest.starts_with("<!") {
            at = skip_past(start + 2, ">");
        } else if rest.starts_with("</") {
            depth = depth.saturating_sub(1);
            at = skip_past(start + 2, ">");
        } else {
            // A start tag: to its `>` or `/>`, past quoted attribute values.
            let mut j = start + 1;
            let mut empty = false;
            while j < bytes.len() {
                match bytes[j] {
                    q @ (b'"' | b'\'') => {
                        j = bytes[j + 1..]
                            .iter()
                            .position(|&b| b == q)
                            .map_or(bytes.len(), |k| j + 1 + k + 1);
                        continue;
                    }
                    b'>' => {
                        empty = bytes[j - 1] == b'/';
                        break;
                    }
                    _ => j += 1,
                }
            }
            if !empty {
                depth += 1;
                if depth > limit {
                    return Err(line_at(start));
                }
            }
            at = (j + 1).min(bytes.len());
        }
    }
    Ok(())
}

struct Mitsuba<'d, 'i> {
    ir: Ir,
    doc: &'d roxmltree::Document<'i>,
    file: Arc<PathBuf>,
    defaults: HashMap<String, String>,
    /// Top-level BSDFs by id: their material name (None: the default diffuse).
    bsdfs: HashMap<String, Option<String>>,
    base: PathBuf,
}

/// The perfect mirror and named metals' normal-incidence reflectance (linear sRGB).
fn metal(name: &str) -> Option<[f64; 3]> {
    Some(match name {
        "none" => [1.0; 3],
        "Au" => [1.0, 0.782, 0.344],
        "Ag" => [0.972, 0.960, 0.915],
        "Al" => [0.913, 0.922, 0.924],
        "Cu" | "CuZn" => [0.955, 0.638, 0.538],
        "Cr" => [0.549, 0.556, 0.554],
        "Fe" => [0.562, 0.565, 0.578],
        "Ti" => [0.542, 0.497, 0.449],
        _ => return None,
    })
}

/// Mitsuba's named indices of refraction.
fn named_ior(name: &str) -> Option<f64> {
    Some(match name {
        "vacuum" => 1.0,
        "helium" => 1.000036,
        "hydrogen" => 1.000132,
        "air" => 1.000277,
        "carbon dioxide" => 1.00045,
        "water" => 1.333,
        "acetone" => 1.36,
        "ethanol" => 1.361,
        "carbon tetrachloride" => 1.461,
        "glycerol" => 1.4729,
        "benzene" => 1.501,
        "silicone oil" => 1.52045,
        "bromine" => 1.661,
        "water ice" => 1.31,
        "fused quartz" => 1.458,
        "pyrex" => 1.47,
        "acrylic glass" => 1.49,
        "polypropylene" => 1.49,
        "bk7" => 1.5046,
        "sodium chloride" => 1.544,
        "amber" => 1.55,
        "pet" => 1.575,
        "diamond" => 2.419,
        _ => return None,
    })
}

impl<'d, 'i> Mitsuba<'d, 'i> {
    fn loc(&self, n: Node) -> Location {
        Location {
            file: self.file.clone(),
            line: self.doc.text_pos_at(n.range().start).row as usize,
        }
    }

    /// An attribute with `$name` defaults substituted.
    fn attr(&self, n: Node, name: &str) -> Result<Option<String>, ImportError> {
        let Some(v) = n.attribute(name) else {
            return Ok(None);
        };
        if !v.contains('$') {
            return Ok(Some(v.to_string()));
        }
        let mut out = String::new();
        let mut rest = v;
        while let Some(i) = rest.find('$') {
            out.push_str(&rest[..i]);
            let after = &rest[i + 1..];
            let len = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            let key = &after[..len];
            let value = self.defaults.get(key).ok_or_else(|| {
                self.loc(n).error(format!(
                    "<{}>: ${key} has no <default> and no value",
                    n.tag_name().name()
                ))
            })?;
            out.push_str(value);
            rest = &after[len..];
        }
        out.push_str(rest);
        Ok(Some(out))
    }

    fn need(&self, n: Node, name: &str) -> Result<String, ImportError> {
        self.attr(n, name)?.ok_or_else(|| {
            self.loc(n).error(format!(
                "<{}>: needs the attribute `{name}`",
                n.tag_name().name()
            ))
        })
    }

    /// Numbers separated by commas and/or spaces.
    fn numbers(&self, n: Node, s: &str) -> Result<Vec<f64>, ImportError> {
        s.split(|c: char| c == ',' || c.is_whitespace())
            .filter(|t| !t.is_empty())
            .map(|t| {
                t.parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| {
                        self.loc(n).error(format!(
                            "<{}>: `{t}` is not a finite number",
                            n.tag_name().name()
                        ))
                    })
            })
            .collect()
    }

    fn number(&self, n: Node, attr: &str) -> Result<f64, ImportError> {
        let s = self.need(n, attr)?;
        match self.numbers(n, &s)?.as_slice() {
            [x] => Ok(*x),
            _ => Err(self.loc(n).error(format!(
                "<{}>: `{attr}` must be one number, got `{s}`",
                n.tag_name().name()
            ))),
        }
    }

    /// A `point` or `vector`: `value="x, y, z"` or `x=`, `y=`, `z=` attributes (missing ones 0).
    fn triple(&self, n: Node) -> Result<[f64; 3], ImportError> {
        if let Some(v) = self.attr(n, "value")? {
            return match self.numbers(n, &v)?.as_slice() {
                [x] => Ok([*x; 3]),
                [x, y, z] => Ok([*x, *y, *z]),
                _ => Err(self.loc(n).error(format!(
                    "<{}>: expected 1 or 3 numbers, got `{v}`",
                    n.tag_name().name()
                ))),
            };
        }
        let mut out = [0.0; 3];
        for (i, k) in ["x", "y", "z"].iter().enumerate() {
            if n.attribute(*k).is_some() {
                out[i] = self.number(n, k)?;
            }
        }
        Ok(out)
    }

    /// The child property `<TAG name="NAME" .../>`.
    fn prop<'a>(&self, n: Node<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
        n.children()
            .find(|c| c.is_element() && c.attribute("name") == Some(name))
    }

    fn float(&self, n: Node, name: &str) -> Result<Option<f64>, ImportError> {
        match self.prop(n, name) {
            None => Ok(None),
            Some(p) => match p.tag_name().name() {
                "float" | "integer" => self.number(p, "value").map(Some),
                other => Err(self
                    .loc(p)
                    .error(format!("`{name}` must be a float, got <{other}>"))),
            },
        }
    }

    fn string(&self, n: Node, name: &str) -> Result<Option<String>, ImportError> {
        match self.prop(n, name) {
            None => Ok(None),
            Some(p) => self.need(p, "value").map(Some),
        }
    }

    /// A colour: `<rgb>`, a float, or a single-valued `<spectrum>`; anything else warns and
    /// gives None.
    fn colour(&mut self, n: Node, name: &str) -> Result<Option<[f64; 3]>, ImportError> {
        let Some(p) = self.prop(n, name) else {
            return Ok(None);
        };
        let loc = self.loc(p);
        match p.tag_name().name() {
            "rgb" | "float" => self.triple(p).map(Some),
            "spectrum" => {
                let v = self.need(p, "value")?;
                match self.numbers(p, &v) {
                    Ok(x) if x.len() == 1 => Ok(Some([x[0]; 3])),
                    _ => {
                        self.ir.warn(&loc, format!("<spectrum name=\"{name}\">: only constant spectra are supported; using the default"));
                        Ok(None)
                    }
                }
            }
            other => {
                self.ir.warn(&loc, format!("<{other} name=\"{name}\">: not supported (textures are not), using the default"));
                Ok(None)
            }
        }
    }

    /// The `<transform name="to_world">` child, composed (later operations on the left).
    fn to_world(&self, n: Node) -> Result<Option<DMat4>, ImportError> {
        let Some(t) = n.children().find(|c| c.has_tag_name("transform")) else {
            return Ok(None);
        };
        let mut m = DMat4::IDENTITY;
        for op in t.children().filter(Node::is_element) {
            let loc = self.loc(op);
            let step = match op.tag_name().name() {
                "translate" => DMat4::from_translation(DVec3::from(self.triple(op)?)),
                "scale" => DMat4::from_scale(DVec3::from(match self.attr(op, "value")? {
                    Some(_) => self.triple(op)?,
                    None => {
                        let mut s = [1.0; 3];
                        for (i, k) in ["x", "y", "z"].iter().enumerate() {
                            if op.attribute(*k).is_some() {
                                s[i] = self.number(op, k)?;
                            }
                        }
                        s
                    }
                })),
                "rotate" => {
                    let axis = match self.attr(op, "value")? {
                        Some(_) => self.triple(op)?,
                        None => {
                            let mut a = [0.0; 3];
                            for (i, k) in ["x", "y", "z"].iter().enumerate() {
                                if op.attribute(*k).is_some() {
                                    a[i] = self.number(op, k)?;
                                }
                            }
                            a
                        }
                    };
                    let axis = DVec3::from(axis).normalize_or_zero();
                    if axis == DVec3::ZERO {
                        return Err(loc.error("<rotate>: the axis is zero"));
                    }
                    DMat4::from_axis_angle(axis, self.number(op, "angle")?.to_radians())
                }
                "matrix" => {
                    let v = self.need(op, "value")?;
                    let x = self.numbers(op, &v)?;
                    match x.len() {
                        16 => {
                            DMat4::from_cols_array(&x.try_into().unwrap_or([0.0; 16])).transpose()
                        }
                        9 => {
                            let r = |i: usize, j: usize| x[3 * i + j];
                            DMat4::from_cols(
                                DVec4::new(r(0, 0), r(1, 0), r(2, 0), 0.0),
                                DVec4::new(r(0, 1), r(1, 1), r(2, 1), 0.0),
                                DVec4::new(r(0, 2), r(1, 2), r(2, 2), 0.0),
                                DVec4::W,
                            )
                        }
                        n => {
                            return Err(
                                loc.error(format!("<matrix>: expected 16 (or 9) numbers, got {n}"))
                            );
                        }
                    }
                }
                "lookat" => {
                    let point = |k: &str| -> Result<DVec3, ImportError> {
                        let s = self.need(op, k)?;
                        match self.numbers(op, &s)?.as_slice() {
                            [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
                            _ => Err(loc.error(format!("<lookat>: `{k}` needs 3 numbers"))),
                        }
                    };
                    let (o, t) = (point("origin")?, point("target")?);
                    let up = if op.attribute("up").is_some() {
                        point("up")?
                    } else {
                        DVec3::Y
                    };
                    let dir = (t - o).normalize_or_zero();
                    let left = up.cross(dir).normalize_or_zero();
                    if dir == DVec3::ZERO || left == DVec3::ZERO {
                        return Err(loc.error(
                            "<lookat>: origin and target coincide, or up is parallel to the view",
                        ));
                    }
                    let new_up = dir.cross(left);
                    DMat4::from_cols(
                        left.extend(0.0),
                        new_up.extend(0.0),
                        dir.extend(0.0),
                        o.extend(1.0),
                    )
                }
                other => return Err(loc.error(format!("<{other}>: not a transform operation"))),
            };
            m = step * m;
        }
        Ok(Some(m))
    }

    fn scene(&mut self, root: Node) -> Result<(), ImportError> {
        for n in root.children().filter(Node::is_element) {
            let loc = self.loc(n);
            match n.tag_name().name() {
                "default" => {
                    let name = self.need(n, "name")?;
                    let value = self.need(n, "value")?;
                    self.defaults.entry(name).or_insert(value);
                }
                "integrator" => self.integrator(n)?,
                "sensor" => self.sensor(n)?,
                "bsdf" => {
                    let id = self.attr(n, "id")?;
                    let m = self.bsdf(n)?;
                    match id {
                        Some(id) => {
                            self.bsdfs.insert(id, m);
                        }
                        None => self
                            .ir
                            .warn(&loc, "<bsdf> without an id at the top level: unused"),
                    }
                }
                "shape" => self.shape(n)?,
                "emitter" => self.emitter(n, None)?,
                other => self
                    .ir
                    .warn(&loc, format!("<{other}>: not supported, ignored")),
            }
        }
        if self.ir.camera.is_none() {
            return Err(ImportError::Scene {
                file: self.file.as_ref().clone(),
                line: None,
                message: "the scene has no <sensor>".into(),
            });
        }
        Ok(())
    }

    fn integrator(&mut self, n: Node) -> Result<(), ImportError> {
        let loc = self.loc(n);
        let kind = self.need(n, "type")?;
        if !matches!(kind.as_str(), "path" | "volpath" | "prb" | "direct") {
            self.ir.warn(
                &loc,
                format!("<integrator type=\"{kind}\">: rendered with Obscura's path tracer"),
            );
        }
        let depth = match (kind.as_str(), self.float(n, "max_depth")?) {
            ("direct", _) => 1.0,
            // Mitsuba counts path vertices after the camera, the emitter's included (1 shows
            // emitters only, 2 adds direct light); Obscura counts bounces (0 and 1).
            (_, Some(d)) if d >= 2.0 => d - 1.0,
            (_, Some(d)) if d >= 1.0 => {
                return Err(loc.error(
                    "<integrator>: max_depth 1 (emitters only, no bounce) has no Obscura \
                     equivalent: its path tracer takes at least one bounce (Mitsuba's 2)",
                ));
            }
            (_, Some(-1.0)) => {
                self.ir.warn(
                    &loc,
                    "max_depth -1 (unbounded): Obscura stops at 64 bounces",
                );
                64.0
            }
            (_, Some(d)) => {
                return Err(loc.error(format!(
                    "<integrator>: max_depth must be >= 1 or -1, got {d}"
                )));
            }
            (_, None) => {
                self.ir.warn(
                    &loc,
                    "max_depth defaults to -1 (unbounded) in Mitsuba: Obscura stops at 64 bounces",
                );
                64.0
            }
        };
        self.ir.integrator = Some(("path", Some(depth.min(1e6) as u32), loc));
        Ok(())
    }

    fn sensor(&mut self, n: Node) -> Result<(), ImportError> {
        let loc = self.loc(n);
        if self.ir.camera.is_some() {
            self.ir
                .warn(&loc, "<sensor>: only the first sensor is rendered");
            return Ok(());
        }
        let kind = self.need(n, "type")?;
        // Film and sampler first: the field of view needs the aspect ratio.
        let mut film = FilmIr {
            resolution: [768, 576],
            crop: None,
            // hdrfilm's default: a Gaussian of stddev 0.5.
            filter: Some(mitsuba_gaussian(0.5)),
            loc: None,
        };
        if let Some(f) = n.children().find(|c| c.has_tag_name("film")) {
            film.loc = Some(self.loc(f));
            let whole = |v: Option<f64>, default: u32, what: &str| -> Result<u32, ImportError> {
                match v {
                    None => Ok(default),
                    Some(x) if x >= 1.0 && x <= f64::from(u32::MAX) && x.fract() == 0.0 => {
                        Ok(x as u32)
                    }
                    Some(x) => Err(self.loc(f).error(format!(
                        "<film>: {what} must be a whole number >= 1, got {x}"
                    ))),
                }
            };
            film.resolution = [
                whole(self.float(f, "width")?, 768, "width")?,
                whole(self.float(f, "height")?, 576, "height")?,
            ];
            let [w, h] = film.resolution.map(f64::from);
            let crop = [
                self.float(f, "crop_offset_x")?,
                self.float(f, "crop_offset_y")?,
                self.float(f, "crop_width")?,
                self.float(f, "crop_height")?,
            ];
            if crop.iter().any(Option::is_some) {
                let (x0, y0) = (crop[0].unwrap_or(0.0), crop[1].unwrap_or(0.0));
                let (cw, ch) = (crop[2].unwrap_or(w - x0), crop[3].unwrap_or(h - y0));
                film.crop = Some([
                    (x0 / w) as f32,
                    ((x0 + cw) / w) as f32,
                    (y0 / h) as f32,
                    ((y0 + ch) / h) as f32,
                ]);
            }
            if let Some(r) = f.children().find(|c| c.has_tag_name("rfilter")) {
                let rloc = self.loc(r);
                film.filter = Some(match self.need(r, "type")?.as_str() {
                    "box" => FilterIr::new("box", 0.5),
                    "tent" => {
                        FilterIr::new("triangle", self.float(r, "radius")?.unwrap_or(1.0) as f32)
                    }
                    "mitchell" => {
                        let b = self.float(r, "B")?.unwrap_or(1.0 / 3.0);
                        let c = self.float(r, "C")?.unwrap_or(1.0 / 3.0);
                        if (b - 1.0 / 3.0).abs() > 1e-6 || (c - 1.0 / 3.0).abs() > 1e-6 {
                            self.ir.warn(
                                &rloc,
                                format!(
                                    "<rfilter type=\"mitchell\">: B = {b}, C = {c}; \
                                     Obscura's mitchell has B = C = 1/3"
                                ),
                            );
                        }
                        FilterIr::new("mitchell", 2.0)
                    }
                    "gaussian" => {
                        let s = self.float(r, "stddev")?.unwrap_or(0.5);
                        if !(s > 0.0 && s.is_finite()) {
                            return Err(rloc.error(format!(
                                "<rfilter type=\"gaussian\">: stddev must be > 0, got {s}"
                            )));
                        }
                        let widest = FilterSettings::MAX_RADIUS;
                        if 4.0 * s > f64::from(widest) {
                            self.ir.warn(
                                &rloc,
                                format!(
                                    "<rfilter type=\"gaussian\">: stddev {s} reaches {} \
                                     pixels; cut at Obscura's widest radius, {widest}",
                                    4.0 * s
                                ),
                            );
                        }
                        mitsuba_gaussian(s)
                    }
                    other => {
                        self.ir.warn(
                            &rloc,
                            format!("<rfilter type=\"{other}\">: not supported, using a gaussian"),
                        );
                        mitsuba_gaussian(0.5)
                    }
                });
            }
        }
        if let Some(s) = n.children().find(|c| c.has_tag_name("sampler")) {
            let sloc = self.loc(s);
            let kind = self.need(s, "type")?;
            let ours = match kind.as_str() {
                "independent" => "independent",
                "stratified" => "stratified",
                "ldsampler" | "multijitter" | "orthogonal" => {
                    self.ir.warn(
                        &sloc,
                        format!("<sampler type=\"{kind}\">: rendered with Obscura's Sobol sampler"),
                    );
                    "sobol"
                }
                other => {
                    self.ir.warn(
                        &sloc,
                        format!(
                            "<sampler type=\"{other}\">: rendered with Obscura's Sobol sampler"
                        ),
                    );
                    "sobol"
                }
            };
            let spp = self.float(s, "sample_count")?.unwrap_or(4.0);
            if !(spp >= 1.0 && spp <= f64::from(u32::MAX)) {
                return Err(sloc.error(format!("<sampler>: sample_count must be >= 1, got {spp}")));
            }
            let seed = self
                .float(s, "seed")?
                .filter(|s| *s >= 0.0)
                .map(|s| s as u64);
            self.ir.sampler = Some((ours, spp as u32, seed, sloc));
        } else {
            self.ir.sampler = Some(("independent", 4, None, loc.clone()));
        }
        let [w, h] = film.resolution.map(f64::from);
        let aspect = w / h;
        self.ir.film = Some(film);

        let to_world = self.to_world(n)?.unwrap_or(DMat4::IDENTITY);
        let flip = DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
        let near = self.float(n, "near_clip")?.unwrap_or(1e-2);
        let far = self.float(n, "far_clip")?.unwrap_or(1e4);
        let shutter = [
            self.float(n, "shutter_open")?.unwrap_or(0.0),
            self.float(n, "shutter_close")?.unwrap_or(0.0),
        ];
        let mut cam = CameraIr {
            loc: loc.clone(),
            kind: "perspective",
            pose: to_world * flip,
            pose_end: None,
            fov: None,
            fov_axis: None,
            screen_window: None,
            lens_radius: 0.0,
            focal_distance: None,
            shutter: shutter.map(|x| x as f32),
            near: Some(near as f32),
            far: Some(far as f32),
            realistic: None,
        };
        match kind.as_str() {
            "perspective" | "thinlens" => {
                let (fov, axis) = match (self.float(n, "fov")?, self.string(n, "focal_length")?) {
                    (Some(_), Some(_)) => {
                        return Err(loc.error("<sensor>: give fov or focal_length, not both"));
                    }
                    (Some(fov), None) => {
                        let axis = self
                            .string(n, "fov_axis")?
                            .unwrap_or_else(|| "x".into())
                            .to_lowercase();
                        if !matches!(axis.as_str(), "x" | "y" | "diagonal" | "smaller" | "larger") {
                            return Err(loc.error(format!("<sensor>: fov_axis must be x, y, diagonal, smaller or larger, got {axis}")));
                        }
                        (fov, axis)
                    }
                    (None, f) => {
                        let f = f.unwrap_or_else(|| "50mm".into());
                        let mm: f64 = f
                            .trim_end_matches("mm")
                            .parse()
                            .ok()
                            .filter(|x: &f64| *x > 0.0)
                            .ok_or_else(|| {
                                loc.error(format!(
                                    "<sensor>: focal_length must look like 50mm, got {f}"
                                ))
                            })?;
                        // The diagonal of 36 x 24 mm film.
                        (
                            2.0 * ((36.0f64 * 36.0 + 24.0 * 24.0).sqrt() / (2.0 * mm))
                                .atan()
                                .to_degrees(),
                            "diagonal".into(),
                        )
                    }
                };
                cam.fov = Some(fov as f32);
                cam.fov_axis = Some(match axis.as_str() {
                    "x" => "x",
                    "y" => "y",
                    "diagonal" => "diagonal",
                    "smaller" => "smaller",
                    _ => "larger",
                });
                // The principal point offset moves the film over the image plane, in
                // fractions of the film (y down): the screen window moves with it.
                let (px, py) = (
                    self.float(n, "principal_point_offset_x")?.unwrap_or(0.0),
                    self.float(n, "principal_point_offset_y")?.unwrap_or(0.0),
                );
                if px != 0.0 || py != 0.0 {
                    let (hx, hy) = if aspect >= 1.0 {
                        (aspect, 1.0)
                    } else {
                        (1.0, 1.0 / aspect)
                    };
                    let (dx, dy) = (2.0 * hx * px, -2.0 * hy * py);
                    cam.screen_window = Some([
                        (-hx + dx) as f32,
                        (hx + dx) as f32,
                        (-hy + dy) as f32,
                        (hy + dy) as f32,
                    ]);
                }
                if kind == "thinlens" {
                    let r = self.float(n, "aperture_radius")?.ok_or_else(|| {
                        loc.error("<sensor type=\"thinlens\">: needs aperture_radius")
                    })?;
                    cam.lens_radius = r as f32;
                }
                cam.focal_distance = Some(self.float(n, "focus_distance")?.unwrap_or(far) as f32);
            }
            "orthographic" => {
                cam.kind = "orthographic";
                // The camera sees [-1, 1] x [-1/aspect, 1/aspect] before to_world's scale: take
                // the scale into the window, keep the pose rigid.
                let (sx, sy, sz) = (
                    to_world.x_axis.truncate().length(),
                    to_world.y_axis.truncate().length(),
                    to_world.z_axis.truncate().length(),
                );
                if !(sx > 0.0 && sy > 0.0 && sz > 0.0) {
                    return Err(loc.error("<sensor>: to_world is singular"));
                }
                let rigid = to_world * DMat4::from_scale(DVec3::new(1.0 / sx, 1.0 / sy, 1.0 / sz));
                cam.pose = rigid * flip;
                cam.screen_window = Some([
                    -sx as f32,
                    sx as f32,
                    (-sy / aspect) as f32,
                    (sy / aspect) as f32,
                ]);
                cam.near = Some((near * sz) as f32);
                cam.far = Some((far * sz) as f32);
            }
            other => {
                return Err(loc.error(format!(
                    "<sensor type=\"{other}\">: not supported (perspective, thinlens, orthographic)"
                )));
            }
        }
        self.ir.camera = Some(cam);
        Ok(())
    }

    /// A BSDF: its material name in the scene (None for the default diffuse).
    fn bsdf(&mut self, n: Node) -> Result<Option<String>, ImportError> {
        let loc = self.loc(n);
        let kind = self.need(n, "type")?;
        let clamp = |r: [f64; 3]| r.map(|x| x.clamp(0.0, 1.0) as f32);
        let m = match kind.as_str() {
            "twosided" => {
                // Obscura's materials are two-sided already.
                return match n.children().find(|c| c.has_tag_name("bsdf")) {
                    Some(inner) => self.bsdf(inner),
                    None => Err(loc.error("<bsdf type=\"twosided\">: needs a nested <bsdf>")),
                };
            }
            "diffuse" => {
                MaterialIr::Diffuse(clamp(self.colour(n, "reflectance")?.unwrap_or([0.5; 3])))
            }
            "conductor" | "roughconductor" => {
                let f0 = match (self.colour(n, "eta")?, self.colour(n, "k")?) {
                    (Some(eta), Some(k)) => std::array::from_fn(|i| {
                        let (e, k) = (eta[i], k[i]);
                        ((e - 1.0).powi(2) + k * k) / ((e + 1.0).powi(2) + k * k)
                    }),
                    _ => {
                        let name = self.string(n, "material")?.unwrap_or_else(|| "none".into());
                        metal(&name).unwrap_or_else(|| {
                            self.ir.warn(&loc, format!("<bsdf>: material \"{name}\" is not known; using a perfect mirror"));
                            [1.0; 3]
                        })
                    }
                };
                let scale = self.colour(n, "specular_reflectance")?.unwrap_or([1.0; 3]);
                let r = clamp(std::array::from_fn(|i| f0[i] * scale[i]));
                if kind == "conductor" {
                    MaterialIr::Mirror(r)
                } else {
                    let dist = self
                        .string(n, "distribution")?
                        .unwrap_or_else(|| "beckmann".into());
                    if dist != "ggx" {
                        self.ir.warn(
                            &loc,
                            format!("<bsdf>: distribution \"{dist}\" rendered as GGX"),
                        );
                    }
                    let alpha = match (
                        self.float(n, "alpha")?,
                        self.float(n, "alpha_u")?,
                        self.float(n, "alpha_v")?,
                    ) {
                        (Some(a), _, _) => a,
                        (None, Some(u), Some(v)) => {
                            self.ir.warn(&loc, "<bsdf>: anisotropic roughness averaged");
                            0.5 * (u + v)
                        }
                        _ => 0.1,
                    };
                    // Obscura's GGX alpha is roughness^2.
                    let roughness = alpha.max(1e-4).sqrt().min(1.0);
                    MaterialIr::RoughConductor(r, roughness as f32)
                }
            }
            "dielectric" | "thindielectric" | "roughdielectric" => {
                let ior = |name: &str, default: f64| -> Result<f64, ImportError> {
                    match self.prop(n, name) {
                        None => Ok(default),
                        Some(p) if p.has_tag_name("string") => {
                            let v = self.need(p, "value")?;
                            named_ior(&v.to_lowercase()).ok_or_else(|| {
                                self.loc(p)
                                    .error(format!("<bsdf>: unknown material \"{v}\" for {name}"))
                            })
                        }
                        Some(p) => self.number(p, "value"),
                    }
                };
                let (int, ext) = (ior("int_ior", 1.5046)?, ior("ext_ior", 1.000277)?);
                if !(int > 0.0 && ext > 0.0) {
                    return Err(loc.error("<bsdf>: indices of refraction must be > 0"));
                }
                if kind != "dielectric" {
                    self.ir.warn(
                        &loc,
                        format!("<bsdf type=\"{kind}\">: rendered as smooth solid glass"),
                    );
                }
                MaterialIr::Dielectric((int / ext) as f32)
            }
            other => {
                self.ir.warn(
                    &loc,
                    format!("<bsdf type=\"{other}\">: not supported, using a 0.5 diffuse"),
                );
                MaterialIr::Diffuse([0.5; 3])
            }
        };
        let id = self.attr(n, "id")?;
        let anonymous = id.is_none();
        let wanted = id.unwrap_or_else(|| format!("{kind}-{}", loc.line));
        Ok(Some(self.ir.add_material(&wanted, m, &loc, anonymous)))
    }

    fn file(&self, n: Node, name: &str) -> Result<PathBuf, ImportError> {
        let f = self.string(n, name)?.ok_or_else(|| {
            self.loc(n).error(format!(
                "<{}>: needs <string name=\"{name}\">",
                n.tag_name().name()
            ))
        })?;
        Ok(self.base.join(f))
    }

    fn shape(&mut self, n: Node) -> Result<(), ImportError> {
        let loc = self.loc(n);
        let kind = self.need(n, "type")?;
        let to_world = self.to_world(n)?.unwrap_or(DMat4::IDENTITY);
        let flip_normals = matches!(
            self.prop(n, "flip_normals")
                .and_then(|p| p.attribute("value")),
            Some("true")
        );
        let mesh = |m: TriangleMesh, name: &str, ir: &mut Ir| {
            let m = if flip_normals { flipped(m) } else { m };
            let i = ir.meshes.len();
            ir.meshes.push((format!("{i:04}-{name}.obj"), Arc::new(m)));
            GeometryIr::Mesh(i)
        };
        let stem = |p: &Path| -> String {
            p.file_stem().map_or("mesh".into(), |s| {
                s.to_string_lossy()
                    .chars()
                    .map(|c| {
                        if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                            c
                        } else {
                            '_'
                        }
                    })
                    .collect()
            })
        };
        let geometry = match kind.as_str() {
            "sphere" => {
                let center = match self.prop(n, "center") {
                    Some(p) => self.triple(p)?,
                    None => [0.0; 3],
                };
                let radius = self.float(n, "radius")?.unwrap_or(1.0);
                if radius.is_nan() || radius <= 0.0 {
                    return Err(loc.error(format!(
                        "<shape type=\"sphere\">: radius must be > 0, got {radius}"
                    )));
                }
                if flip_normals {
                    self.ir.warn(&loc, "<shape type=\"sphere\">: flip_normals: Obscura's emitting spheres emit outwards");
                }
                GeometryIr::Sphere {
                    center: center.map(|x| x as f32),
                    radius: radius as f32,
                }
            }
            "rectangle" => {
                let (o, u, v) = if flip_normals {
                    ([-1.0, 1.0, 0.0], [2.0, 0.0, 0.0], [0.0, -2.0, 0.0])
                } else {
                    ([-1.0, -1.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0])
                };
                GeometryIr::Quad {
                    origin: o,
                    edge_u: u,
                    edge_v: v,
                }
            }
            "cube" => mesh(cube(), "cube", &mut self.ir),
            "disk" => {
                self.ir.warn(
                    &loc,
                    "<shape type=\"disk\">: tessellated into 128 triangles",
                );
                mesh(disk(128), "disk", &mut self.ir)
            }
            "obj" => {
                let path = self.file(n, "filename")?;
                let m = obscura_accel::load_obj(&path)
                    .map_err(|e| loc.error(format!("<shape type=\"obj\">: {e}")))?;
                let s = stem(&path);
                mesh(m, &s, &mut self.ir)
            }
            "ply" => {
                let path = self.file(n, "filename")?;
                let bytes = std::fs::read(&path).map_err(|e| {
                    loc.error(format!(
                        "<shape type=\"ply\">: cannot read {}: {e}",
                        path.display()
                    ))
                })?;
                let m = crate::ply::parse_ply(&bytes, &path)
                    .map_err(|e| loc.error(format!("<shape type=\"ply\">: {e}")))?;
                let s = stem(&path);
                mesh(m, &s, &mut self.ir)
            }
            other => {
                self.ir.warn(
                    &loc,
                    format!("<shape type=\"{other}\">: not supported, ignored"),
                );
                return Ok(());
            }
        };
        // The BSDF: a reference or a nested one; the area emitter.
        let mut material = None;
        let mut emission = None;
        for c in n.children().filter(Node::is_element) {
            match c.tag_name().name() {
                "ref" => {
                    let id = self.need(c, "id")?;
                    material = self.bsdfs.get(&id).cloned().ok_or_else(|| {
                        self.loc(c)
                            .error(format!("<ref>: no <bsdf> with id \"{id}\" before it"))
                    })?;
                }
                "bsdf" => material = self.bsdf(c)?,
                "emitter" => {
                    let cloc = self.loc(c);
                    if self.need(c, "type")? != "area" {
                        return Err(cloc.error("<shape>: a nested <emitter> must be of type area"));
                    }
                    emission = Some(
                        self.colour(c, "radiance")?
                            .unwrap_or([1.0; 3])
                            .map(|x| x as f32),
                    );
                }
                _ => {}
            }
        }
        self.ir.shapes.push(ShapeIr {
            loc,
            geometry,
            material,
            emission,
            transform: to_world,
            transform_end: None,
        });
        Ok(())
    }

    fn emitter(&mut self, n: Node, _shape: Option<()>) -> Result<(), ImportError> {
        let loc = self.loc(n);
        let kind = self.need(n, "type")?;
        let to_world = self.to_world(n)?;
        let scale = self.float(n, "scale")?.unwrap_or(1.0);
        let f = |c: [f64; 3]| c.map(|x| (x * scale) as f32);
        let light = match kind.as_str() {
            "point" => {
                let p = match (self.prop(n, "position"), to_world) {
                    (Some(p), _) => DVec3::from(self.triple(p)?),
                    (None, Some(m)) => m.transform_point3(DVec3::ZERO),
                    (None, None) => DVec3::ZERO,
                };
                LightIr::Point {
                    position: p.to_array().map(|x| x as f32),
                    intensity: f(self.colour(n, "intensity")?.unwrap_or([1.0; 3])),
                }
            }
            "directional" => {
                let d = match (self.prop(n, "direction"), to_world) {
                    (Some(p), _) => DVec3::from(self.triple(p)?),
                    (None, Some(m)) => m.transform_vector3(DVec3::Z),
                    (None, None) => DVec3::Z,
                };
                if d.length().is_nan() || d.length() <= 0.0 {
                    return Err(loc.error("<emitter type=\"directional\">: the direction is zero"));
                }
                LightIr::Distant {
                    direction: d.normalize().to_array().map(|x| x as f32),
                    irradiance: f(self.colour(n, "irradiance")?.unwrap_or([1.0; 3])),
                }
            }
            "constant" => LightIr::Environment {
                radiance: f(self.colour(n, "radiance")?.unwrap_or([1.0; 3])),
                file: None,
                transform: None,
            },
            "envmap" => {
                let file = self.file(n, "filename")?;
                if file
                    .extension()
                    .and_then(|e| e.to_str())
                    .map(str::to_ascii_lowercase)
                    .as_deref()
                    != Some("exr")
                {
                    return Err(loc.error(format!("<emitter type=\"envmap\">: {}: Obscura reads environment maps from EXR files only", file.display())));
                }
                // Mitsuba's u = atan2(x, -z) / 2 pi is Obscura's mirrored in x.
                let mirror = DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
                LightIr::Environment {
                    radiance: [scale as f32; 3],
                    file: Some(crate::scene::MapIr::File(file)),
                    transform: Some(to_world.unwrap_or(DMat4::IDENTITY) * mirror),
                }
            }
            "area" => return Err(loc.error("<emitter type=\"area\">: must be inside a <shape>")),
            other => {
                self.ir.warn(
                    &loc,
                    format!("<emitter type=\"{other}\">: not supported, ignored"),
                );
                return Ok(());
            }
        };
        self.ir.lights.push((light, loc));
        Ok(())
    }
}

/// The same mesh with each triangle's winding reversed (`flip_normals`).
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

/// Mitsuba's cube: [-1, 1]^3, faces wound so their normals point outwards.
fn cube() -> TriangleMesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = positions.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let mut p = [0.0f32; 3];
                p[axis] = sign;
                p[u] = a;
                p[v] = b;
                positions.push(Vec3::from(p));
            }
            // cross(e_u, e_v) = +e_axis: keep the order for the + face, reverse it for the -.
            if sign > 0.0 {
                triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
            } else {
                triangles.extend([[base, base + 2, base + 1], [base, base + 3, base + 2]]);
            }
        }
    }
    TriangleMesh::new(positions, triangles, None, None).expect("the unit cube is a valid mesh")
}

/// Mitsuba's disk: the unit disk in the xy plane, normal +z, as a fan of `n` triangles.
fn disk(n: u32) -> TriangleMesh {
    let mut positions = vec![Vec3::ZERO];
    for i in 0..n {
        let a = std::f32::consts::TAU * i as f32 / n as f32;
        positions.push(Vec3::new(a.cos(), a.sin(), 0.0));
    }
    let triangles = (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
    TriangleMesh::new(positions, triangles, None, None).expect("the disk is a valid mesh")
}

/// Mitsuba 3's `gaussian` of standard deviation `stddev`: `e^(-x^2 / 2 s^2) - e^(-8)`, cut at
/// its radius of 4 s, which is Obscura's Gaussian of that radius and sigma (both capped at
/// Obscura's widest filter).
fn mitsuba_gaussian(stddev: f64) -> FilterIr {
    let widest = f64::from(FilterSettings::MAX_RADIUS);
    FilterIr {
        kind: "gaussian",
        radius: (4.0 * stddev).min(widest) as f32,
        sigma: Some(stddev.min(widest) as f32),
    }
}
