//! Meshes generated in code, for obscura-accel's tests, benchmarks and profiling example (not
//! part of the crate's API: each of them includes this file with `#[path]`).
//!
//! - [`icosphere`]: a geodesic sphere of radius 1 at the origin, `20 * 4^n` triangles
//!   (n = 6: 81,920; n = 7: 327,680; n = 8: 1,310,720), with smooth per-vertex normals.
//! - [`displaced_grid`]: an `n x n` grid of quads (`2 n^2` triangles) over `[-1, 1]^2` in the
//!   xy plane, z displaced by a sum of sines, with per-vertex uvs; n = 708 gives about a
//!   million triangles.
//! - [`primary_rays`] and [`random_rays`]: the coherent and incoherent ray sets the benchmarks
//!   and profiling examples trace at these meshes.

use obscura_accel::{AccelError, TriangleMesh};
use obscura_space::glam::{Vec2, Vec3};
use obscura_space::{Point3, Ray, Vector3, World};
use std::collections::HashMap;

/// The largest subdivision level [`icosphere`] accepts (20 * 4^10, about 21 million triangles).
pub const MAX_ICOSPHERE_SUBDIVISIONS: u32 = 10;

/// A geodesic sphere of radius 1 centred at the origin: an icosahedron whose triangles are
/// split in four `subdivisions` times, new vertices pushed out onto the sphere. Triangles wind
/// counter-clockwise seen from outside, so their winding normals point outward; the vertex
/// normals are the unit positions.
pub fn icosphere(subdivisions: u32) -> Result<TriangleMesh, AccelError> {
    if subdivisions > MAX_ICOSPHERE_SUBDIVISIONS {
        return Err(AccelError::Mesh(format!(
            "icosphere: {subdivisions} subdivisions is more than {MAX_ICOSPHERE_SUBDIVISIONS}"
        )));
    }
    // The icosahedron: three orthogonal golden rectangles.
    let phi = (1.0 + 5.0f32.sqrt()) / 2.0;
    let mut positions: Vec<Vec3> = [
        (-1.0, phi, 0.0),
        (1.0, phi, 0.0),
        (-1.0, -phi, 0.0),
        (1.0, -phi, 0.0),
        (0.0, -1.0, phi),
        (0.0, 1.0, phi),
        (0.0, -1.0, -phi),
        (0.0, 1.0, -phi),
        (phi, 0.0, -1.0),
        (phi, 0.0, 1.0),
        (-phi, 0.0, -1.0),
        (-phi, 0.0, 1.0),
    ]
    .into_iter()
    .map(|(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, positions: &mut Vec<Vec3>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let m = (positions[a as usize] + positions[b as usize]).normalize();
                positions.push(m);
                positions.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(triangles.len() * 4);
        for [a, b, c] in triangles {
            let ab = midpoint(a, b, &mut positions);
            let bc = midpoint(b, c, &mut positions);
            let ca = midpoint(c, a, &mut positions);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    let normals = positions.clone();
    TriangleMesh::new(positions, triangles, Some(normals), None)
}

/// An `n x n` grid of quads over `[-1, 1]^2` in the xy plane (`2 n^2` triangles, `(n + 1)^2`
/// vertices), each vertex lifted to `z = 0.1 (sin 7x + sin 5y) + 0.05 sin 23(x + y)`, with uvs
/// in `[0, 1]^2`. Triangles wind counter-clockwise seen from +z. `n` must be in `1..=4096`.
pub fn displaced_grid(n: u32) -> Result<TriangleMesh, AccelError> {
    if !(1..=4096).contains(&n) {
        return Err(AccelError::Mesh(format!(
            "displaced grid: n = {n} is outside 1..=4096"
        )));
    }
    let side = n + 1;
    let mut positions = Vec::with_capacity((side * side) as usize);
    let mut uvs = Vec::with_capacity((side * side) as usize);
    for j in 0..side {
        for i in 0..side {
            let u = i as f32 / n as f32;
            let v = j as f32 / n as f32;
            let (x, y) = (2.0 * u - 1.0, 2.0 * v - 1.0);
            let z = 0.1 * ((7.0 * x).sin() + (5.0 * y).sin()) + 0.05 * (23.0 * (x + y)).sin();
            positions.push(Vec3::new(x, y, z));
            uvs.push(Vec2::new(u, v));
        }
    }
    let mut triangles = Vec::with_capacity(2 * (n * n) as usize);
    for j in 0..n {
        for i in 0..n {
            let v00 = j * side + i;
            let v10 = v00 + 1;
            let v01 = v00 + side;
            let v11 = v01 + 1;
            triangles.push([v00, v10, v11]);
            triangles.push([v00, v11, v01]);
        }
    }
    TriangleMesh::new(positions, triangles, None, Some(uvs))
}

/// A 256 x 256 pinhole grid of rays from (0, 0, 3) looking down -z over a 60-degree square
/// field: coherent primary rays at meshes within the unit cube around the origin.
pub fn primary_rays() -> Vec<Ray<World>> {
    let n = 256;
    let half = (30.0f32).to_radians().tan();
    let mut rays = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let x = ((i as f32 + 0.5) / n as f32 * 2.0 - 1.0) * half;
            let y = (1.0 - (j as f32 + 0.5) / n as f32 * 2.0) * half;
            let d = Vector3::new(x, y, -1.0).normalize();
            rays.push(Ray::new(Point3::new(0.0, 0.0, 3.0), d, 0.0));
        }
    }
    rays
}

/// 65,536 incoherent rays from random points on a sphere of radius 3 towards random points in
/// the unit cube (a fixed xorshift sequence, so every run traces the same rays).
pub fn random_rays() -> Vec<Ray<World>> {
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut u = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    (0..65_536)
        .map(|_| {
            let on_sphere = loop {
                let v = Vector3::<World>::new(2.0 * u() - 1.0, 2.0 * u() - 1.0, 2.0 * u() - 1.0);
                let l = v.length();
                if l > 0.1 && l <= 1.0 {
                    break v * (3.0 / l);
                }
            };
            let origin = Point3::ORIGIN + on_sphere;
            let target = Point3::new(2.0 * u() - 1.0, 2.0 * u() - 1.0, 2.0 * u() - 1.0);
            Ray::new(origin, (target - origin).normalize(), 0.0)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    // Paths through `super::` rather than a glob import: a benchmark that includes this file
    // compiles the module without its tests, where the import would be unused.

    #[test]
    fn icosphere_counts_and_orientation() {
        for n in 0..3 {
            let mesh = super::icosphere(n).unwrap();
            // Each subdivision splits every triangle in four; Euler: V = T / 2 + 2.
            assert_eq!(mesh.triangle_count(), 20 * 4usize.pow(n));
            assert_eq!(mesh.positions().len(), mesh.triangle_count() / 2 + 2);
            assert_eq!(mesh.skipped_degenerate(), 0);
            for tri in mesh.triangles() {
                let [a, b, c] = tri.map(|v| mesh.positions()[v as usize]);
                // Outward winding: the normal points away from the centre.
                assert!((b - a).cross(c - a).dot(a + b + c) > 0.0);
            }
        }
        assert!(super::icosphere(super::MAX_ICOSPHERE_SUBDIVISIONS + 1).is_err());
    }

    #[test]
    fn grid_counts() {
        let mesh = super::displaced_grid(3).unwrap();
        assert_eq!(mesh.triangle_count(), 18);
        assert_eq!(mesh.positions().len(), 16);
        assert!(super::displaced_grid(0).is_err());
    }

    #[test]
    fn ray_sets_are_unit_rays_aimed_as_documented() {
        let (primary, random) = (super::primary_rays(), super::random_rays());
        assert_eq!((primary.len(), random.len()), (256 * 256, 65_536));
        for ray in primary.iter().chain(&random) {
            let d = ray.direction.to_glam();
            assert!((d.length() - 1.0).abs() < 1e-5, "{d}");
        }
        // Primary rays: from (0, 0, 3), within 30 degrees of -z along each image axis.
        let half = 30.0f32.to_radians().tan();
        for ray in &primary {
            let (o, d) = (ray.origin.to_glam(), ray.direction.to_glam());
            assert_eq!(o, super::Vec3::new(0.0, 0.0, 3.0));
            assert!(d.z < 0.0 && (d.x / -d.z).abs() <= half && (d.y / -d.z).abs() <= half);
        }
        // Random rays: from radius 3 towards the unit cube, so they pass within its
        // circumscribed sphere (radius sqrt(3)).
        for ray in &random {
            let (o, d) = (ray.origin.to_glam(), ray.direction.to_glam());
            assert!((o.length() - 3.0).abs() < 1e-4, "{o}");
            assert!(
                (o - d * o.dot(d)).length() <= 3.0f32.sqrt() + 1e-4,
                "{o} {d}"
            );
        }
    }
}
