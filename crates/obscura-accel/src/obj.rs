//! Wavefront OBJ loading with tobj, with a line-numbered validation pass of our own.
//!
//! tobj reports what went wrong but not where, so the file is first scanned line by line:
//! every vertex must have three finite coordinates and every face at least three vertices
//! whose indices are in range. Only a file that passes is handed to tobj, which triangulates
//! polygons and gathers groups and objects; we merge them into one mesh.

use crate::error::AccelError;
use crate::mesh::TriangleMesh;
use glam::{Vec2, Vec3};
use std::path::Path;

/// Loads an OBJ file as one [`TriangleMesh`] (all groups and objects merged; polygons fanned
/// into triangles; shading normals and uvs kept when every face has them). Materials are
/// ignored. Malformed or missing files are errors naming the file and, where the problem sits
/// on one line, the line; zero-area triangles are skipped and counted, not fatal.
pub fn load_obj(path: &Path) -> Result<TriangleMesh, AccelError> {
    let bytes = std::fs::read(path).map_err(|e| AccelError::Io {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    parse_obj(&bytes, path)
}

/// Parses the bytes of an OBJ file as [`load_obj`] does; `path` only names the file in errors.
/// Any bytes give a mesh or an error, never a panic (the fuzz target `obj` feeds it).
pub fn parse_obj(bytes: &[u8], path: &Path) -> Result<TriangleMesh, AccelError> {
    let obj_error = |line: Option<usize>, reason: String| AccelError::Obj {
        path: path.to_path_buf(),
        line,
        reason,
    };
    if let Some(at) = bytes.iter().position(|&b| b == 0) {
        let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
        return Err(obj_error(
            Some(line),
            "binary data (a NUL byte): this is not a text OBJ file".to_string(),
        ));
    }
    let text = match std::str::from_utf8(bytes) {
        Ok(text) => text,
        Err(e) => {
            let at = e.valid_up_to();
            let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
            return Err(obj_error(
                Some(line),
                "bytes that are not UTF-8 text: this is not a text OBJ file".to_string(),
            ));
        }
    };
    scan(text).map_err(|(line, reason)| obj_error(Some(line), reason))?;

    // tobj adds fields behind its "merging" and "reordering" features; keep their defaults if
    // another crate in the build enables them.
    #[allow(clippy::needless_update)]
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let (models, _materials) =
        tobj::load_obj_buf(&mut std::io::Cursor::new(text.as_bytes()), &options, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        })
        .map_err(|e| obj_error(None, format!("tobj could not parse the file: {e}")))?;

    // Merge every model into one mesh, offsetting indices.
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut triangles = Vec::new();
    let mut all_normals = true;
    let mut all_uvs = true;
    for model in &models {
        let mesh = &model.mesh;
        let base = positions.len() as u32;
        let count = mesh.positions.len() / 3;
        positions.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2])),
        );
        if mesh.normals.len() == count * 3 && count > 0 {
            normals.extend(
                mesh.normals
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2])),
            );
        } else if count > 0 {
            all_normals = false;
        }
        if mesh.texcoords.len() == count * 2 && count > 0 {
            uvs.extend(
                mesh.texcoords
                    .chunks_exact(2)
                    .map(|c| Vec2::new(c[0], c[1])),
            );
        } else if count > 0 {
            all_uvs = false;
        }
        triangles.extend(
            mesh.indices
                .chunks_exact(3)
                .map(|c| [c[0] + base, c[1] + base, c[2] + base]),
        );
    }
    if triangles.is_empty() {
        return Err(obj_error(
            None,
            "the file has no faces (an empty mesh)".to_string(),
        ));
    }
    let normals = (all_normals && !normals.is_empty()).then_some(normals);
    let uvs = (all_uvs && !uvs.is_empty()).then_some(uvs);
    TriangleMesh::new(positions, triangles, normals, uvs).map_err(|e| e.in_file(path))
}

/// Checks every line tobj will read; `Err((line, reason))` at the first problem.
fn scan(text: &str) -> Result<(), (usize, String)> {
    // First pass: how many positions, texture coordinates and normals the file defines, so
    // that a face may refer forward (tobj resolves indices at the end).
    let mut totals = [0usize; 3];
    for line in text.lines() {
        match line.split_whitespace().next() {
            Some("v") => totals[0] += 1,
            Some("vt") => totals[1] += 1,
            Some("vn") => totals[2] += 1,
            _ => {}
        }
    }
    let mut seen = [0usize; 3];
    for (i, line) in text.lines().enumerate() {
        let number = i + 1;
        let line = line.split('#').next().unwrap_or("");
        let mut tokens = line.split_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        let args: Vec<&str> = tokens.collect();
        match keyword {
            "v" | "vn" | "vt" => {
                let (kind, slot, needed) = match keyword {
                    "v" => ("vertex position", 0, 3),
                    "vt" => ("texture coordinate", 1, 1),
                    _ => ("normal", 2, 3),
                };
                if args.len() < needed {
                    return Err((
                        number,
                        format!(
                            "{kind} has {} numbers, {needed} needed (truncated line?)",
                            args.len()
                        ),
                    ));
                }
                for a in &args {
                    let value: f32 = a
                        .parse()
                        .map_err(|_| (number, format!("{kind}: cannot parse {a:?} as a number")))?;
                    if !value.is_finite() {
                        return Err((number, format!("{kind} has a NaN or infinite value {a:?}")));
                    }
                }
                seen[slot] += 1;
            }
            "f" => {
                if args.len() < 3 {
                    return Err((
                        number,
                        format!("a face of {} vertices (at least 3 are needed)", args.len()),
                    ));
                }
                for a in &args {
                    let parts: Vec<&str> = a.split('/').collect();
                    if parts.len() > 3 || parts[0].is_empty() {
                        return Err((number, format!("cannot parse face vertex {a:?}")));
                    }
                    let names = ["", " texture coordinate", " normal"];
                    let plurals = ["vertices", "texture coordinates", "normals"];
                    for (k, part) in parts.iter().enumerate() {
                        if k > 0 && part.is_empty() {
                            continue;
                        }
                        let index: i64 = part
                            .parse()
                            .map_err(|_| (number, format!("cannot parse face vertex {a:?}")))?;
                        let total = totals[k];
                        // Negative indices count back from the last one defined so far.
                        let resolved = if index < 0 {
                            seen[k] as i64 + index + 1
                        } else {
                            index
                        };
                        if resolved < 1 || resolved > total as i64 {
                            return Err((
                                number,
                                format!(
                                    "face{} index {index} out of range (the file has {total} {})",
                                    names[k], plurals[k]
                                ),
                            ));
                        }
                    }
                }
            }
            "l" | "p" | "o" | "g" | "s" | "mtllib" | "usemtl" => {}
            other => {
                // Unknown statements are what a truncated or garbled file looks like.
                return Err((number, format!("unknown statement {other:?}")));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::scan;

    #[test]
    fn scan_names_the_line() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n\nf 1 2 3\nf 1 2 9\n";
        let (line, reason) = scan(text).unwrap_err();
        assert_eq!(line, 7);
        assert_eq!(
            reason,
            "face index 9 out of range (the file has 4 vertices)"
        );
    }

    #[test]
    fn scan_accepts_slashes_and_negative_indices() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf -3//1 -2//1 -1//1\n";
        assert!(scan(text).is_ok());
    }
}
