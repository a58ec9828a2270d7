//! The scene: instances of shapes under their placements, the two-level BVH over them, and the
//! ray queries. `builder.rs` makes a [`Scene`], `query.rs` answers rays, `record.rs` builds the
//! full [`Hit`](crate::Hit) from what a query found.

mod builder;
mod quads;
mod query;
mod record;

pub use builder::{BuildQuality, MAX_COORDINATE, SceneBuilder};
pub use query::PreliminaryHit;

use crate::geom::{AbsAffine, Parallelogram, QuadHit};
use crate::mesh::TriangleMesh;
use crate::wide::{BoxSet, WideBvh, WideHit};
use glam::{Mat4, Vec3, Vec3A};
use obscura_space::{AnimatedTransform, Bounds3, Object, Ray, Transform, World};
use obvhs::cwbvh::CwBvh;
use quads::QuadSet;
use std::sync::Arc;

/// A built scene, ready for ray queries from any number of threads.
#[derive(Debug)]
pub struct Scene {
    items: Vec<Item>,
    /// How rays find the items.
    tlas: Top,
    /// All static mesh triangles in world space; hits carry (triangle, instance).
    flat: Option<WideBvh>,
    /// One object-space BVH per distinct moving mesh.
    blases: Vec<WideBvh>,
    meshes: Vec<Option<Arc<TriangleMesh>>>,
    statics: Vec<Option<Transform<World, Object>>>,
    bounds: Bounds3<World>,
    /// Whether an item moves (see [`Scene::moves`]), found once at build time.
    moves: bool,
    /// Whether hits carry their surface coordinates ([`SceneBuilder::with_uv`]).
    uv: bool,
}

/// The top level of a [`Scene`]. One per scene, so its size does not matter; boxing the
/// larger variants would add a pointer chase to every ray.
#[derive(Debug)]
#[allow(clippy::large_enum_variant)]
enum Top {
    /// Zero or one item: no top level.
    One,
    /// A few items, their boxes tested at once. `sorted`: a closest-hit query visits the
    /// boxes entered nearest first (when an item is a mesh, whose BVH query the best hit so
    /// far prunes); otherwise in index order, which for a few spheres and quads costs less
    /// than the sort.
    Few { set: BoxSet, sorted: bool },
    /// Nine to sixteen spheres and quads (a Cornell box and its contents): two sets of boxes,
    /// items `0..8` and `8..`, visited in index order like `Few { sorted: false }`.
    Two([BoxSet; 2]),
    /// Spheres and quads only, among them up to sixteen static quads (carried to world space)
    /// and up to eight others: the static quads tested four at a time without their boxes,
    /// then the others through their boxes in index order (`others[lane]` is the item).
    Quads {
        quads: QuadSet,
        boxes: Option<BoxSet>,
        others: Vec<usize>,
    },
    /// obvhs's tree over the items, with its slot -> item map.
    Tree(CwBvh, Vec<u32>),
}

#[derive(Debug, Clone)]
enum Xform {
    /// Object space is world space: rays need no transform.
    Identity,
    Static(Placed),
    Moving(AnimatedTransform<World, Object>),
}

/// A static placement with what every ray and hit through it reads, computed once: the
/// absolute values of both matrices and of the inverse's residual, which the hit's error bound
/// is made of.
#[derive(Debug, Clone)]
struct Placed {
    world_from_object: Transform<World, Object>,
    abs: AbsAffine,
    abs_inverse: AbsAffine,
    abs_residual: AbsAffine,
}

impl Placed {
    fn new(world_from_object: Transform<World, Object>) -> Placed {
        Placed {
            world_from_object,
            abs: AbsAffine::of(&world_from_object.matrix()),
            abs_inverse: AbsAffine::of(&world_from_object.inverse_matrix()),
            abs_residual: AbsAffine::inverse_residual(
                &world_from_object.matrix(),
                &world_from_object.inverse_matrix(),
            ),
        }
    }
}

impl Xform {
    /// The ray's origin and direction in object space at the ray's time.
    #[inline]
    fn ray_to_object(&self, r: &PlainRay) -> (Vec3A, Vec3A) {
        match self {
            Xform::Identity => (r.o, r.d),
            Xform::Static(placed) => to_object(&placed.world_from_object.inverse_matrix(), r),
            Xform::Moving(a) => to_object(&a.at(r.time).inverse_matrix(), r),
        }
    }

    fn bounds(&self, b: Bounds3<Object>) -> Bounds3<World> {
        match self {
            Xform::Identity => Transform::IDENTITY.bounds(b),
            Xform::Static(placed) => placed.world_from_object.bounds(b),
            Xform::Moving(a) => a.motion_bounds(b),
        }
    }
}

#[derive(Debug, Clone, Copy)]
enum Analytic {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    /// A parallelogram; a static one is carried to world space when the scene is built (see
    /// the builder).
    Quad(Parallelogram),
}

/// One entry of the top level. A scene has few, and every ray reads some, so the large
/// variants are not boxed (a box would add a pointer chase to every item test).
#[derive(Debug)]
#[allow(clippy::large_enum_variant)]
enum Item {
    /// The flattened static triangles.
    Flat,
    Analytic {
        instance: u32,
        shape: Analytic,
        xform: Xform,
    },
    MovingMesh {
        instance: u32,
        blas: usize,
        world_from_object: AnimatedTransform<World, Object>,
    },
}

/// What a traversal found, enough to build the [`Hit`] afterwards.
#[derive(Clone, Copy, Debug)]
enum Found {
    /// A flattened triangle; the ids are (triangle, instance).
    Flat {
        hit: WideHit,
    },
    /// A triangle of a moving mesh, in object space; the first id is the triangle.
    Moving {
        item: usize,
        hit: WideHit,
    },
    Sphere {
        item: usize,
        t: f32,
    },
    Quad {
        item: usize,
        quad: QuadHit,
    },
}

impl Found {
    fn t(&self) -> f32 {
        match self {
            Found::Flat { hit } | Found::Moving { hit, .. } => hit.tri.t,
            Found::Sphere { t, .. } => *t,
            Found::Quad { quad, .. } => quad.t,
        }
    }
}

/// A world ray as plain glam values, checked once.
#[derive(Clone, Copy, Debug)]
struct PlainRay {
    o: Vec3A,
    d: Vec3A,
    time: f32,
    t_min: f32,
    t_max: f32,
}

impl PlainRay {
    /// `None` for a ray that can hit nothing: non-finite or zero direction, NaN or empty range.
    fn new(ray: &Ray<World>) -> Option<Self> {
        let o = Vec3A::from(ray.origin.to_glam());
        let d = Vec3A::from(ray.direction.to_glam());
        let ok = o.is_finite()
            && d.is_finite()
            && d != Vec3A::ZERO
            && !ray.t_min.is_nan()
            && !ray.t_max.is_nan()
            && ray.t_min <= ray.t_max;
        ok.then_some(PlainRay {
            o,
            d,
            time: ray.time,
            t_min: ray.t_min,
            t_max: ray.t_max,
        })
    }
}

impl From<&PlainRay> for crate::wide::BatchRay {
    fn from(r: &PlainRay) -> Self {
        crate::wide::BatchRay {
            o: r.o,
            d: r.d,
            t_min: r.t_min,
            t_max: r.t_max,
        }
    }
}

/// The ray's origin and direction carried into object space by the matrix
/// `object_from_world`.
#[inline]
fn to_object(m: &Mat4, r: &PlainRay) -> (Vec3A, Vec3A) {
    (
        Vec3A::from(m.transform_point3(Vec3::from(r.o))),
        Vec3A::from(m.transform_vector3(Vec3::from(r.d))),
    )
}

// The renderer shares one scene between its worker threads.
const _: () = {
    const fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<Scene>();
};
