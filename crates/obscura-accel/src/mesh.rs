//! Triangle meshes in object space.

use crate::error::AccelError;
use crate::pages::Pages;
use glam::{Vec2, Vec3};
use obscura_space::{Bounds3, Object, Point3};

/// A triangle mesh in object space: positions, triangles as index triples, and optional
/// per-vertex shading normals and texture coordinates.
///
/// Built only through [`TriangleMesh::new`], which validates everything, so a mesh that exists is
/// well formed: finite positions, every index in range, attribute arrays as long as the
/// position array, and no zero-area triangle (those are dropped and counted).
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleMesh {
    // On huge pages when large: a hit's record reads the triangle's indices and vertices at
    // random (see `Pages`).
    positions: Pages<Vec3>,
    triangles: Pages<[u32; 3]>,
    normals: Option<Pages<Vec3>>,
    uvs: Option<Pages<Vec2>>,
    skipped_degenerate: usize,
    bounds: Bounds3<Object>,
}

impl TriangleMesh {
    /// Validates (finite positions, indices in range, normals/uvs lengths match); skips
    /// degenerate (zero-area) triangles and reports how many in
    /// [`skipped_degenerate()`](Self::skipped_degenerate). A mesh with no triangle left is an
    /// error.
    pub fn new(
        positions: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        normals: Option<Vec<Vec3>>,
        uvs: Option<Vec<Vec2>>,
    ) -> Result<TriangleMesh, AccelError> {
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(AccelError::Mesh(format!(
                "vertex {i} has a NaN or infinite coordinate {:?}",
                positions[i].to_array()
            )));
        }
        if let Some(normals) = &normals {
            if normals.len() != positions.len() {
                return Err(AccelError::Mesh(format!(
                    "{} normals for {} vertices (they must match one to one)",
                    normals.len(),
                    positions.len()
                )));
            }
            if let Some(i) = normals.iter().position(|n| !n.is_finite()) {
                return Err(AccelError::Mesh(format!(
                    "normal {i} has a NaN or infinite component"
                )));
            }
        }
        if let Some(uvs) = &uvs {
            if uvs.len() != positions.len() {
                return Err(AccelError::Mesh(format!(
                    "{} texture coordinates for {} vertices (they must match one to one)",
                    uvs.len(),
                    positions.len()
                )));
            }
            if let Some(i) = uvs.iter().position(|uv| !uv.is_finite()) {
                return Err(AccelError::Mesh(format!(
                    "texture coordinate {i} has a NaN or infinite component"
                )));
            }
        }
        if u32::try_from(positions.len()).is_err() || u32::try_from(triangles.len()).is_err() {
            return Err(AccelError::Mesh(
                "more than 2^32 - 1 vertices or triangles".to_string(),
            ));
        }
        let vertex_count = positions.len();
        let mut kept = Vec::with_capacity(triangles.len());
        let mut skipped_degenerate = 0;
        for (i, tri) in triangles.iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&v| v as usize >= vertex_count) {
                return Err(AccelError::Mesh(format!(
                    "triangle {i} uses vertex index {bad}, out of range (the mesh has {vertex_count} vertices)"
                )));
            }
            let [p0, p1, p2] = tri.map(|v| positions[v as usize]);
            // Zero area: the cross product of two edges vanishes (or overflows).
            let area2 = (p1 - p0).cross(p2 - p0).length_squared();
            if area2 == 0.0 || !area2.is_finite() {
                skipped_degenerate += 1;
            } else {
                kept.push(*tri);
            }
        }
        if kept.is_empty() {
            return Err(AccelError::Mesh(if skipped_degenerate > 0 {
                format!("no triangles left: all {skipped_degenerate} have zero area")
            } else {
                "the mesh has no triangles".to_string()
            }));
        }
        let bounds = Bounds3::from_points(
            kept.iter()
                .flatten()
                .map(|&v| Point3::from_glam(positions[v as usize])),
        );
        Ok(TriangleMesh {
            positions: Pages::new(positions),
            triangles: Pages::new(kept),
            normals: normals.map(Pages::new),
            uvs: uvs.map(Pages::new),
            skipped_degenerate,
            bounds,
        })
    }

    /// The number of (non-degenerate) triangles kept.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }
    /// How many zero-area triangles [`TriangleMesh::new`] dropped.
    pub fn skipped_degenerate(&self) -> usize {
        self.skipped_degenerate
    }
    /// The box of the vertices the kept triangles use, in object space.
    pub fn bounds(&self) -> Bounds3<Object> {
        self.bounds
    }
    /// Vertex positions in object space.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }
    /// The kept triangles; [`Hit::primitive`](crate::Hit::primitive) indexes this slice.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }
    /// Per-vertex shading normals, if the mesh has them.
    pub fn normals(&self) -> Option<&[Vec3]> {
        self.normals.as_deref()
    }
    /// Per-vertex texture coordinates, if the mesh has them.
    pub fn uvs(&self) -> Option<&[Vec2]> {
        self.uvs.as_deref()
    }
    /// The three corners of triangle `i` in object space.
    #[inline]
    pub(crate) fn corners(&self, i: usize) -> [Vec3; 3] {
        self.triangles[i].map(|v| self.positions[v as usize])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad_positions() -> Vec<Vec3> {
        vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ]
    }

    #[test]
    fn degenerate_triangles_are_skipped_and_counted() {
        // Triangle [0, 1, 1] repeats a vertex and [0, 1, 4] has a collinear third vertex
        // (x = 2 on the x axis): both have zero area.
        let mut p = quad_positions();
        p.push(Vec3::new(2.0, 0.0, 0.0));
        let mesh = TriangleMesh::new(
            p,
            vec![[0, 1, 2], [0, 1, 1], [0, 2, 3], [0, 1, 4]],
            None,
            None,
        )
        .unwrap();
        assert_eq!(mesh.triangle_count(), 2);
        assert_eq!(mesh.skipped_degenerate(), 2);
        assert_eq!(mesh.triangles(), &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(mesh.bounds().min, Point3::new(0.0, 0.0, 0.0));
        assert_eq!(mesh.bounds().max, Point3::new(1.0, 1.0, 0.0));
    }

    #[test]
    fn invalid_input_is_an_error() {
        let bad_index = TriangleMesh::new(quad_positions(), vec![[0, 1, 9]], None, None);
        assert!(bad_index.unwrap_err().to_string().contains("index 9"));
        let mut p = quad_positions();
        p[2].y = f32::NAN;
        let nan = TriangleMesh::new(p, vec![[0, 1, 2]], None, None);
        assert!(nan.unwrap_err().to_string().contains("NaN"));
        let short_normals =
            TriangleMesh::new(quad_positions(), vec![[0, 1, 2]], Some(vec![Vec3::Z]), None);
        assert!(
            short_normals
                .unwrap_err()
                .to_string()
                .contains("1 normals for 4")
        );
        let empty = TriangleMesh::new(quad_positions(), vec![], None, None);
        assert!(empty.is_err());
        let all_degenerate = TriangleMesh::new(quad_positions(), vec![[0, 0, 1]], None, None);
        assert!(
            all_degenerate
                .unwrap_err()
                .to_string()
                .contains("zero area")
        );
    }
}
