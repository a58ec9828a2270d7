//! The full hit record built from what a query found: world point with its error bound,
//! normals, surface coordinates.

use super::{Analytic, Found, Item, Placed, PlainRay, Scene, Xform};
use crate::geom::{
    Parallelogram, TriangleHit, gamma, object_space_error, transform_point_with_error,
};
use crate::hit::Hit;
use crate::mesh::TriangleMesh;
use crate::wide::WideHit;
use glam::{Vec2, Vec3};
use obscura_space::{Normal3, Object, Point3, Transform, Vector3, World};

impl Scene {
    /// Builds the full world-space hit record from what the traversal found.
    pub(super) fn finish(&self, r: &PlainRay, found: Found) -> Hit {
        match found {
            Found::Flat { hit } => {
                let [primitive, instance] = hit.ids;
                let world_from_object =
                    self.statics[instance as usize].expect("flattened meshes are static");
                let mesh = self.meshes[instance as usize]
                    .as_ref()
                    .expect("flattened instances are meshes");
                let cross = hit.e1.cross(hit.e2);
                let (p, p_error) = edge_point(&hit, cross);
                // The world edges already carry the transform: (M a) x (M b) =
                // det(M) M^-T (a x b), so flip for a mirroring transform to match the inverse
                // transpose of the object-space winding normal.
                let mut n_geo = cross.normalize();
                if world_from_object.swaps_handedness() {
                    n_geo = -n_geo;
                }
                self.triangle_hit(
                    r,
                    hit.tri,
                    p,
                    p_error,
                    n_geo,
                    mesh,
                    primitive,
                    instance,
                    &world_from_object,
                )
            }
            Found::Moving { item, hit } => {
                let Item::MovingMesh {
                    instance,
                    world_from_object,
                    ..
                } = &self.items[item]
                else {
                    unreachable!("Found::Moving comes from a moving mesh")
                };
                let mesh = self.meshes[*instance as usize]
                    .as_ref()
                    .expect("moving mesh instances are meshes");
                let placed = Placed::new(world_from_object.at(r.time));
                let cross = hit.e1.cross(hit.e2);
                let (p_object, err_object) = edge_point(&hit, cross);
                let (p, p_error, n_geo) = placed.hit_to_world(p_object, err_object, cross);
                self.triangle_hit(
                    r,
                    hit.tri,
                    p,
                    p_error,
                    n_geo,
                    mesh,
                    hit.ids[0],
                    *instance,
                    &placed.world_from_object,
                )
            }
            Found::Sphere { item, t } => {
                let (instance, shape, xform) = self.analytic(item);
                let Analytic::Sphere { center, radius } = shape else {
                    unreachable!("Found::Sphere comes from a sphere")
                };
                let (o, d) = xform.ray_to_object(r);
                let p_hit = Vec3::from(o + d * t);
                // Reproject onto the surface: the error is then that of the projection.
                let mut rel = p_hit - center;
                let len = rel.length();
                rel = if len > 0.0 {
                    rel * (radius / len)
                } else {
                    Vec3::new(0.0, 0.0, radius)
                };
                let p_object = center + rel;
                let err_object = gamma(5) * rel.abs() + gamma(2) * p_object.abs();
                let n_object = rel / radius;
                let uv = if self.uv {
                    let theta = (rel.z / radius).clamp(-1.0, 1.0).acos();
                    let mut phi = rel.y.atan2(rel.x);
                    if phi < 0.0 {
                        phi += 2.0 * core::f32::consts::PI;
                    }
                    Vec2::new(
                        phi / (2.0 * core::f32::consts::PI),
                        theta / core::f32::consts::PI,
                    )
                } else {
                    Vec2::ZERO
                };
                self.analytic_hit(r, t, p_object, err_object, n_object, uv, instance, xform)
            }
            Found::Quad { item, quad } => {
                let (instance, shape, xform) = self.analytic(item);
                let Analytic::Quad(Parallelogram {
                    origin,
                    edge_u,
                    edge_v,
                    n,
                    ..
                }) = shape
                else {
                    unreachable!("Found::Quad comes from a quad")
                };
                let (su, sv) = (edge_u * quad.s, edge_v * quad.v);
                let p_object = origin + su + sv;
                let err_object = gamma(5) * (origin.abs() + su.abs() + sv.abs());
                let n_object = n;
                let uv = if self.uv {
                    Vec2::new(quad.s, quad.v)
                } else {
                    Vec2::ZERO
                };
                self.analytic_hit(
                    r, quad.t, p_object, err_object, n_object, uv, instance, xform,
                )
            }
        }
    }

    fn analytic(&self, item: usize) -> (u32, Analytic, &Xform) {
        match &self.items[item] {
            Item::Analytic {
                instance,
                shape,
                xform,
            } => (*instance, *shape, xform),
            _ => unreachable!("analytic hits come from analytic items"),
        }
    }

    /// A sphere's or quad's object-space hit carried to world space as its placement says.
    /// Always inlined into `finish`: out of line, its frame cost every hit more than the
    /// transform's own work costs the transformed ones.
    #[inline(always)]
    fn analytic_hit(
        &self,
        r: &PlainRay,
        t: f32,
        p_object: Vec3,
        err_object: Vec3,
        n_object: Vec3,
        uv: Vec2,
        instance: u32,
        xform: &Xform,
    ) -> Hit {
        let (p, p_error, n) = match xform {
            // Object space is world space: nothing to carry, no rounding to add.
            Xform::Identity => (p_object, err_object, n_object.normalize()),
            Xform::Static(placed) => placed.hit_to_world(p_object, err_object, n_object),
            Xform::Moving(a) => {
                Placed::new(a.at(r.time)).hit_to_world(p_object, err_object, n_object)
            }
        };
        let n = Normal3::from_glam(n);
        Hit {
            t,
            p: Point3::from_glam(p),
            p_error: Vector3::from_glam(p_error),
            n_geometric: n,
            n_shading: n,
            uv,
            instance,
            primitive: 0,
            time: r.time,
        }
    }

    fn triangle_hit(
        &self,
        r: &PlainRay,
        tri: TriangleHit,
        p: Vec3,
        p_error: Vec3,
        n_geo: Vec3,
        mesh: &TriangleMesh,
        primitive: u32,
        instance: u32,
        world_from_object: &Transform<World, Object>,
    ) -> Hit {
        let b = [1.0 - tri.b1 - tri.b2, tri.b1, tri.b2];
        // The vertex indices are read only for what needs them: on a mesh of megabytes the
        // read is a cache miss, and a mesh without normals or uvs has no use for it.
        let vertices = || mesh.triangles()[primitive as usize];
        let n_shading = mesh
            .normals()
            .and_then(|normals| {
                let vertices = vertices();
                let n_object: Vec3 = (0..3).map(|k| normals[vertices[k] as usize] * b[k]).sum();
                let n = world_from_object
                    .normal(Normal3::from_glam(n_object))
                    .to_glam()
                    .try_normalize()?;
                Some(if n.dot(n_geo) < 0.0 { -n } else { n })
            })
            .unwrap_or(n_geo);
        let uv = if !self.uv {
            Vec2::ZERO
        } else {
            mesh.uvs()
                .map(|uvs| {
                    let vertices = vertices();
                    (0..3).map(|k| uvs[vertices[k] as usize] * b[k]).sum()
                })
                .unwrap_or(Vec2::new(tri.b1, tri.b2))
        };
        Hit {
            t: tri.t,
            p: Point3::from_glam(p),
            p_error: Vector3::from_glam(p_error),
            n_geometric: Normal3::from_glam(n_geo),
            n_shading: Normal3::from_glam(n_shading),
            uv,
            instance,
            primitive,
            time: r.time,
        }
    }
}

impl Placed {
    /// A hit point found in object space, carried to world space with its error bound: the
    /// rounding of the transform itself plus that of having carried the ray into object space.
    #[inline]
    fn point_to_world(&self, p_object: Vec3, err_object: Vec3) -> (Vec3, Vec3) {
        let m = self.world_from_object.matrix();
        let (p, p_error) = transform_point_with_error(&m, &self.abs, p_object, err_object);
        (
            p,
            p_error
                + object_space_error(
                    &self.abs,
                    &self.abs_inverse,
                    &self.abs_residual,
                    p,
                    p_object,
                ),
        )
    }

    /// [`Placed::point_to_world`] and the unit world normal of `n_object`.
    #[inline]
    fn hit_to_world(&self, p_object: Vec3, err_object: Vec3, n_object: Vec3) -> (Vec3, Vec3, Vec3) {
        let (p, p_error) = self.point_to_world(p_object, err_object);
        (
            p,
            p_error,
            normal_to_world(&self.world_from_object, n_object),
        )
    }
}

/// A unit world normal from an object-space normal, by the inverse transpose.
#[inline]
fn normal_to_world(world_from_object: &Transform<World, Object>, n_object: Vec3) -> Vec3 {
    world_from_object
        .normal(Normal3::from_glam(n_object))
        .to_glam()
        .normalize()
}

/// The hit point `v0 + b1 e1 + b2 e2` on the triangle as the BVH stores it, and a bound on its
/// error: the sum rounds at most three times and each edge was rounded once when it was
/// stored, so `gamma(4) (|v0| + |b1 e1| + |b2 e2|)` covers it; pbrt's `gamma(7)` on the same
/// terms is kept for margin (the barycentrics themselves carry error within the plane, which
/// moves the point along the surface, not off it).
///
/// The bound is widened along the normal by how far off the plane the four-wide
/// Möller–Trumbore test can place a spawned ray's origin, so that the spawned ray cannot meet
/// the triangle again. The test's `t` numerator is `e2 . ((o - v0) x e1)`, the origin's signed
/// distance from the plane times `|e1 x e2|`. With `w = o - v0` rounded (`gamma(1) |w|`), the
/// cross product (`gamma(2)`) and the dot product (`gamma(3)`), its error is at most
/// `gamma(5) |e2|_1 |w|_1 |e1|_1 + gamma(1) |w|_1 |e1 x e2|`; divided by `|e1 x e2|`, as a
/// distance, that is `gamma(6) |w|_1 (|e1|_1 |e2|_1 / |e1 x e2| + 1)` with
/// `|w|_1 <= b1 |e1|_1 + b2 |e2|_1`. It grows as the triangle thins (`|e1 x e2|` small
/// beside its edges); the point's own bound alone let thin triangles be met again. `cross` is
/// `e1 x e2`, which the caller needs for the normal too.
#[inline]
fn edge_point(hit: &WideHit, cross: Vec3) -> (Vec3, Vec3) {
    let (a, b, c) = (hit.v0, hit.e1 * hit.tri.b1, hit.e2 * hit.tri.b2);
    let p = a + b + c;
    let mut err = gamma(7) * (a.abs() + b.abs() + c.abs());
    let area = cross.length();
    if area > 0.0 {
        let (l1, l2) = (hit.e1.abs().element_sum(), hit.e2.abs().element_sum());
        let reach = hit.tri.b1.abs() * l1 + hit.tri.b2.abs() * l2;
        let plane = gamma(6) * reach * (l1 * l2 / area + 1.0);
        err += (cross / area).abs() * plane;
    }
    (p, err)
}
