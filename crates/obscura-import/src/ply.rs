//! PLY meshes, ASCII and binary, read with the `ply-rs-bw` crate (a maintained fork of
//! `ply-rs`): vertex positions, optional normals and texture coordinates, and faces (polygons
//! fanned into triangles).

use glam::{Vec2, Vec3};
use obscura_accel::TriangleMesh;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property, PropertyAccess};
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

/// The properties of a vertex the renderer reads: position, normal, texture coordinates
/// (NaN where the file has none). A plain struct, not ply-rs's map per element, so a mesh of a
/// million triangles reads in a fraction of the time and memory.
#[derive(Clone, Copy)]
struct Vertex([f64; 8]);

/// Slots of [`Vertex`]: x, y, z, nx, ny, nz, u, v.
fn vertex_slot(name: &str) -> Option<usize> {
    Some(match name {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        "nx" => 3,
        "ny" => 4,
        "nz" => 5,
        "u" | "s" | "texture_u" | "texture_s" => 6,
        "v" | "t" | "texture_v" | "texture_t" => 7,
        _ => return None,
    })
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Vertex([f64::NAN; 8])
    }
    fn set_property(&mut self, name: &str, property: Property) {
        if let (Some(i), Some(x)) = (vertex_slot(name), scalar(&property)) {
            self.0[i] = x;
        }
    }
}

/// A face's vertex indices (`vertex_indices` or `vertex_index`).
struct Face(Option<Vec<i64>>);

impl PropertyAccess for Face {
    fn new() -> Self {
        Face(None)
    }
    fn set_property(&mut self, name: &str, property: Property) {
        if name == "vertex_indices" || name == "vertex_index" {
            self.0 = indices(&property);
        }
    }
}

/// Reads a PLY mesh from bytes; `path` only names the file in messages (the error is the
/// message alone).
pub fn parse_ply(bytes: &[u8], path: &Path) -> Result<TriangleMesh, String> {
    let name = path.display();
    let bad = |e: std::io::Error| format!("{name}: not a PLY file this reader understands: {e}");
    let mut reader = std::io::Cursor::new(bytes);
    let vertex_parser = Parser::<Vertex>::new();
    let face_parser = Parser::<Face>::new();
    let other_parser = Parser::<DefaultElement>::new();
    let header = vertex_parser.read_header(&mut reader).map_err(bad)?;
    let (mut vertices, mut faces) = (None, None);
    let (mut with_normals, mut with_uvs) = (false, false);
    // Elements come in the header's order; those not read here are still read past.
    for (_, element) in &header.elements {
        match element.name.as_str() {
            "vertex" => {
                let has = |k: &[&str]| k.iter().any(|k| element.properties.contains_key(*k));
                with_normals = has(&["nx"]) && has(&["ny"]) && has(&["nz"]);
                with_uvs = has(&["u", "s", "texture_u", "texture_s"])
                    && has(&["v", "t", "texture_v", "texture_t"]);
                vertices = Some(
                    vertex_parser
                        .read_payload_for_element(&mut reader, element, &header)
                        .map_err(bad)?,
                );
            }
            "face" => {
                faces = Some(
                    face_parser
                        .read_payload_for_element(&mut reader, element, &header)
                        .map_err(bad)?,
                );
            }
            _ => {
                other_parser
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(bad)?;
            }
        }
    }
    let vertices = vertices.ok_or_else(|| format!("{name}: no `vertex` element"))?;
    let faces = faces.ok_or_else(|| format!("{name}: no `face` element"))?;
    let mut positions = Vec::with_capacity(vertices.len());
    let mut normals = Vec::with_capacity(if with_normals { vertices.len() } else { 0 });
    let mut uvs = Vec::with_capacity(if with_uvs { vertices.len() } else { 0 });
    for (i, Vertex(v)) in vertices.iter().enumerate() {
        // NaN marks a missing property (a NaN in the file is refused by the mesh anyway).
        if v[..3].iter().any(|x| x.is_nan()) {
            return Err(format!("{name}: vertex {i} lacks x, y or z (or is NaN)"));
        }
        positions.push(Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32));
        if with_normals {
            normals.push(Vec3::new(v[3] as f32, v[4] as f32, v[5] as f32));
        }
        if with_uvs {
            uvs.push(Vec2::new(v[6] as f32, v[7] as f32));
        }
    }
    let mut triangles = Vec::with_capacity(faces.len());
    for (i, Face(list)) in faces.iter().enumerate() {
        let list = list
            .as_ref()
            .ok_or_else(|| format!("{name}: face {i} has no vertex_indices list"))?;
        if list.len() < 3 {
            return Err(format!(
                "{name}: face {i} has {} vertices (at least 3)",
                list.len()
            ));
        }
        let index = |x: i64| {
            u32::try_from(x)
                .ok()
                .filter(|&x| (x as usize) < positions.len())
                .ok_or_else(|| format!("{name}: face {i} uses vertex {x}, out of range"))
        };
        // A fan: exact for the convex planar polygons PLY files hold.
        let first = index(list[0])?;
        for k in 1..list.len() - 1 {
            triangles.push([first, index(list[k])?, index(list[k + 1])?]);
        }
    }
    TriangleMesh::new(
        positions,
        triangles,
        with_normals.then_some(normals),
        with_uvs.then_some(uvs),
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
    fn normals_uvs_and_other_elements() {
        let text = "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\nelement edge 1\nproperty int vertex1\nproperty int vertex2\nelement face 1\nproperty list uchar uint vertex_index\nend_header\n0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n0 1 0 0 0 1 0 1\n0 1\n3 0 1 2\n";
        let m = parse_ply(text.as_bytes(), Path::new("n.ply")).unwrap();
        assert_eq!(m.normals().unwrap()[1], Vec3::Z);
        assert_eq!(m.uvs().unwrap()[2], Vec2::new(0.0, 1.0));
        assert_eq!(m.triangles(), &[[0, 1, 2]]);
        // Without normals and uvs in the header, the mesh has none.
        assert!(
            parse_ply(ASCII.as_bytes(), Path::new("q.ply"))
                .unwrap()
                .normals()
                .is_none()
        );
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
