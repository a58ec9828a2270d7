//! Surface hits and the rays spawned from them.

use crate::geom::offset_ray_origin;
use obscura_space::{Normal3, Point3, Ray, Vector3, World};

/// How far short of its target a shadow ray stops, as a fraction of the segment (pbrt's
/// `ShadowEpsilon`), so that the target's own surface does not occlude it.
pub const SHADOW_EPSILON: f32 = 1e-4;

/// The closest surface a ray met, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// The ray parameter (distance = `t * |direction|`).
    pub t: f32,
    /// The hit point.
    pub p: Point3<World>,
    /// A conservative absolute error bound of `p`, per axis (pbrt style): of `p` itself, and of
    /// where the intersection tests place the surface relative to a ray leaving `p` (a
    /// triangle's test, a transform's rounded inverse), so that [`Hit::spawn_ray`] clears it.
    pub p_error: Vector3<World>,
    /// Unit geometric normal with the shape's own orientation, not flipped towards the ray:
    /// spheres outward, quads `normalize(cross(edge_u, edge_v))`, triangles by winding
    /// `(p1 - p0) x (p2 - p0)`; carried to world space with the inverse transpose.
    pub n_geometric: Normal3<World>,
    /// Unit shading normal: interpolated vertex normals where the mesh has them, else
    /// `n_geometric`; always on the same side as `n_geometric`.
    pub n_shading: Normal3<World>,
    /// Surface coordinates. Sphere: `(phi / 2pi, theta / pi)` with theta measured from the
    /// object's +z axis and phi from +x towards +y; quad: `(s, t)` along `edge_u`, `edge_v`;
    /// triangle: interpolated vertex uvs, or the barycentrics `(b1, b2)` of vertices 1 and 2.
    /// Zero for every hit of a scene built
    /// [`with_uv(false)`](crate::SceneBuilder::with_uv).
    pub uv: glam::Vec2,
    /// The instance index [`SceneBuilder::add`](crate::SceneBuilder::add) returned.
    pub instance: u32,
    /// The triangle index within the mesh's [`triangles()`](crate::TriangleMesh::triangles)
    /// (0 for spheres and quads).
    pub primitive: u32,
    /// The ray's time.
    pub time: f32,
}

impl Hit {
    /// A ray leaving the surface towards `direction`, origin offset along `n_geometric` by
    /// `p_error` (to the side `direction` points to), so it cannot re-hit the surface it starts
    /// on. Its range is `[0, inf)` and its time the hit's.
    pub fn spawn_ray(&self, direction: Vector3<World>) -> Ray<World> {
        let origin = offset_ray_origin(
            self.p.to_glam(),
            self.p_error.to_glam(),
            self.n_geometric.to_glam(),
            direction.to_glam(),
        );
        Ray::new(Point3::from_glam(origin), direction, self.time)
    }

    /// A shadow ray from the surface to `target`, `t` in `[0, 1 - SHADOW_EPSILON]`, with
    /// `direction = target - origin` (so `t = 1` is the target).
    pub fn spawn_ray_to(&self, target: Point3<World>) -> Ray<World> {
        let origin = offset_ray_origin(
            self.p.to_glam(),
            self.p_error.to_glam(),
            self.n_geometric.to_glam(),
            (target - self.p).to_glam(),
        );
        let origin = Point3::from_glam(origin);
        Ray::new(origin, target - origin, self.time).with_range(0.0, 1.0 - SHADOW_EPSILON)
    }
}
