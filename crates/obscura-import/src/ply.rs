//! PLY meshes, ASCII and binary, read with the `ply-rs-bw` crate (a maintained fork of
//! `ply-rs`): vertex positions, optional normals and texture coordinates, and faces (polygons
//! fanned into triangles).

use glam::{Vec2, Vec3};
use obscura_accel::TriangleMesh;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};
use std::path::Path;

/// One scalar of a PLY property as a number.
fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => v.into(),
        Property::UChar(v) => v.into(),
        Property::Short(v) => v.into(),
        Property::UShort(v) => v.into(),
        Property::Int(v) => v.into(),
        Property::UInt(v) => v.into(),
        Property::Float(v) => v.into(),
        Property::Double(v) => v,
        _ => return None,
    })
}

/// A list property as vertex indices.
fn indices(p: &Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListUChar(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListShort(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListUShort(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListInt(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListUInt(v) => v.iter().map(|&x| x.into()).collect(),
        _ => return None,
    })
}

/// Reads a PLY mesh from bytes; `path` only names the file in messages (the error is the
/// message alone).
pub fn parse_ply(bytes: &[u8], path: &Path) -> Result<TriangleMesh, String> {
    let name = path.display();
    let parser = Parser::<DefaultElement>::new();
    let ply = parser
        .read_ply(&mut std::io::Cursor::new(bytes))
        .map_err(|e| format!("{name}: not a PLY file this reader understands: {e}"))?;
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or_else(|| format!("{name}: no `vertex` element"))?;
    let get = |v: &DefaultElement, k: &str| v.get(k).and_then(scalar);
    let mut positions = Vec::with_capacity(vertices.len());
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let has = |k: &str| vertices.first().is_some_and(|v| v.contains_key(k));
    let uv_keys = [
        ("u", "v"),
        ("s", "t"),
        ("texture_u", "texture_v"),
        ("texture_s", "texture_t"),
    ]
    .into_iter()
    .find(|(u, v)| has(u) && has(v));
    let with_normals = has("nx") && has("ny") && has("nz");
    for (i, v) in vertices.iter().enumerate() {
        let p = match (get(v, "x"), get(v, "y"), get(v, "z")) {
            (Some(x), Some(y), Some(z)) => Vec3::new(x as f32, y as f32, z as f32),
            _ => return Err(format!("{name}: vertex {i} lacks x, y or z")),
        };
        positions.push(p);
        if with_normals {
            let n = [get(v, "nx"), get(v, "ny"), get(v, "nz")];
            match n {
                [Some(x), Some(y), Some(z)] => {
                    normals.push(Vec3::new(x as f32, y as f32, z as f32))
                }
                _ => return Err(format!("{name}: vertex {i} lacks nx, ny or nz")),
            }
        }
        if let Some((ku, kv)) = uv_keys {
            match (get(v, ku), get(v, kv)) {
                (Some(u), Some(w)) => uvs.push(Vec2::new(u as f32, w as f32)),
                _ => return Err(format!("{name}: vertex {i} lacks {ku} or {kv}")),
            }
        }
    }
    let faces = ply
        .payload
        .get("face")
        .ok_or_else(|| format!("{name}: no `face` element"))?;
    let mut triangles = Vec::with_capacity(faces.len());
    for (i, f) in faces.iter().enumerate() {
        let list = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .and_then(indices)
            .ok_or_else(|| format!("{name}: face {i} has no vertex_indices list"))?;
        if list.len() < 3 {
            return Err(format!(
                "{name}: face {i} has {} vertices (at least 3)",
                list.len()
            ));
        }
        let list: Vec<u32> = list
            .iter()
            .map(|&x| {
                u32::try_from(x)
                    .ok()
                    .filter(|&x| (x as usize) < positions.len())
                    .ok_or_else(|| format!("{name}: face {i} uses vertex {x}, out of range"))
            })
            .collect::<Result<_, _>>()?;
        // A fan: exact for the convex planar polygons PLY files hold.
        for k in 1..list.len() - 1 {
            triangles.push([list[0], list[k], list[k + 1]]);
        }
    }
    TriangleMesh::new(
        positions,
        triangles,
        with_normals.then_some(normals),
        uv_keys.map(|_| uvs),
    )
    .map_err(|e| format!("{name}: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const ASCII: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";

    #[test]
    fn ascii_quad_is_two_triangles() {
        let m = parse_ply(ASCII.as_bytes(), Path::new("q.ply")).unwrap();
        assert_eq!(m.triangles(), &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.positions()[2], Vec3::new(1.0, 1.0, 0.0));
    }

    #[test]
    fn binary_little_endian_reads_the_same() {
        let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n".to_vec();
        for v in [[0.0f32, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.5]] {
            for x in v {
                b.extend_from_slice(&x.to_le_bytes());
            }
        }
        b.push(3);
        for i in [0u32, 1, 2] {
            b.extend_from_slice(&i.to_le_bytes());
        }
        let m = parse_ply(&b, Path::new("t.ply")).unwrap();
        assert_eq!(m.positions()[2], Vec3::new(0.0, 3.0, 0.5));
        assert_eq!(m.triangles(), &[[0, 1, 2]]);
    }

    #[test]
    fn bad_index_is_an_error() {
        let bad = ASCII.replace("4 0 1 2 3", "3 0 1 9");
        assert!(
            parse_ply(bad.as_bytes(), Path::new("q.ply"))
                .unwrap_err()
                .contains("out of range")
        );
    }

    proptest! {
        #[test]
        fn any_bytes_give_a_mesh_or_an_error(cut in 0usize..ASCII.len(), junk in proptest::collection::vec(any::<u8>(), 0..40)) {
            let mut b = ASCII.as_bytes()[..cut].to_vec();
            b.extend(junk);
            let _ = parse_ply(&b, Path::new("f.ply"));
        }
    }
}
