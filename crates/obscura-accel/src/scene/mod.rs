//! Shapes, instances, the two-level BVH and the ray queries.

use crate::error::AccelError;

use crate::geom::{
    Parallelogram, QuadHit, TriangleHit, gamma, intersect_sphere, object_space_error,
    transform_point_with_error,
};
use crate::hit::Hit;
use crate::mesh::TriangleMesh;
use crate::wide::{BoxSet, WideBvh, WideHit};
use glam::{Vec2, Vec3, Vec3A};
use obscura_space::{
    AnimatedTransform, Bounds3, Normal3, Object, Point3, Ray, Transform, Vector3, World,
};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::ray::RayHit;
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Duration;

/// A shape in its own object space.
#[derive(Debug, Clone)]
pub enum Shape {
    /// A triangle mesh, shared between instances.
    Mesh(Arc<TriangleMesh>),
    /// An analytic sphere (exact ray-sphere intersection, not a tessellation).
    Sphere {
        /// The centre, in object space.
        center: Vec3,
        /// The radius, > 0.
        radius: f32,
    },
    /// The parallelogram `origin + s * edge_u + t * edge_v`, `s, t` in `[0, 1]`; its normal is
    /// `normalize(cross(edge_u, edge_v))`.
    Quad {
        /// One corner, in object space.
        origin: Vec3,
        /// The first edge from `origin`.
        edge_u: Vec3,
        /// The second edge from `origin`.
        edge_v: Vec3,
    },
}

/// Where an instance sits in the world.
#[derive(Debug, Clone)]
pub enum Placement {
    /// A fixed `world_from_object` transform.
    Static(Transform<World, Object>),
    /// A `world_from_object` transform that moves over the shutter interval; rays meet the
    /// object where it is at the ray's own time.
    Moving(AnimatedTransform<World, Object>),
}

/// How much effort to spend building the per-mesh BVHs: obvhs's presets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BuildQuality {
    /// `BvhBuildParams::fast_build()`: PLOC with a short search radius, little reinsertion.
    Fast,
    /// `BvhBuildParams::medium_build()` (the default): documented by obvhs as about embree's
    /// build time with faster traversal; a renderer traces far more rays than it builds.
    #[default]
    Medium,
    /// `BvhBuildParams::slow_build()`: spatial pre-splits and more reinsertion, for very
    /// large renders of static scenes.
    Slow,
}

impl BuildQuality {
    fn params(self) -> BvhBuildParams {
        match self {
            BuildQuality::Fast => BvhBuildParams::fast_build(),
            BuildQuality::Medium => BvhBuildParams::medium_build(),
            BuildQuality::Slow => BvhBuildParams::slow_build(),
        }
    }
}

/// Collects instances, then builds a [`Scene`].
#[derive(Debug, Clone, Default)]
pub struct SceneBuilder {
    instances: Vec<(Shape, Placement)>,
    quality: BuildQuality,
    /// Set by `with_uv(false)`.
    no_uv: bool,
}

/// How far from the origin (in world units, per axis) any shape may reach, at any time.
pub const MAX_COORDINATE: f32 = 1e18;

impl SceneBuilder {
    /// An empty builder with [`BuildQuality::Medium`].
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the build quality of the per-mesh BVHs.
    pub fn with_quality(mut self, quality: BuildQuality) -> Self {
        self.quality = quality;
        self
    }

    /// Whether hits carry surface coordinates ([`Hit::uv`]; on by default). Off, every hit's
    /// `uv` is zero and costs nothing: a sphere's takes an arccosine and an arctangent, a
    /// mesh's a read of its uv array (on a large mesh, one more cache miss per hit). For
    /// callers that read no textures, such as Obscura's own renderer.
    /// [`PreliminaryHit::primitive_uv`] is not affected.
    pub fn with_uv(mut self, uv: bool) -> Self {
        self.no_uv = !uv;
        self
    }

    /// Adds an instance. Returns the instance index (0, 1, 2... in call order):
    /// [`Hit::instance`] reports it. Errors for invalid shape parameters (non-finite values, a
    /// radius <= 0, a quad of zero area) or a non-finite placement.
    pub fn add(&mut self, shape: Shape, placement: Placement) -> Result<u32, AccelError> {
        match &shape {
            Shape::Mesh(_) => {}
            Shape::Sphere { center, radius } => {
                if !center.is_finite() || !radius.is_finite() || *radius <= 0.0 {
                    return Err(AccelError::Shape(format!(
                        "sphere: the centre must be finite and the radius finite and > 0 (got centre {:?}, radius {radius})",
                        center.to_array()
                    )));
                }
            }
            Shape::Quad {
                origin,
                edge_u,
                edge_v,
            } => {
                let n = edge_u.cross(*edge_v);
                if !origin.is_finite() || !edge_u.is_finite() || !edge_v.is_finite() {
                    return Err(AccelError::Shape(
                        "quad: origin and edges must be finite".to_string(),
                    ));
                }
                if n.length_squared() == 0.0 || !n.length_squared().is_finite() {
                    return Err(AccelError::Shape(format!(
                        "quad: edges {:?} and {:?} are parallel or zero (the quad has no area)",
                        edge_u.to_array(),
                        edge_v.to_array()
                    )));
                }
            }
        }
        let finite =
            |t: &Transform<World, Object>| t.matrix().is_finite() && t.inverse_matrix().is_finite();
        let ok = match &placement {
            Placement::Static(t) => finite(t),
            Placement::Moving(a) => a
                .keyframes()
                .all(|(time, t)| time.is_finite() && finite(&t)),
        };
        if !ok {
            return Err(AccelError::Placement(
                "a transform has a NaN or infinite entry".to_string(),
            ));
        }
        // Every coordinate the BVH and the intersection tests see must stay far from f32's
        // overflow: products of two coordinates (cross products, squared distances) must be
        // finite, or bounds turn infinite and the BVH build and hit tests break down.
        let object_bounds = match &shape {
            Shape::Mesh(mesh) => mesh.bounds(),
            Shape::Sphere { center, radius } => Bounds3::new(
                Point3::from_glam(*center - Vec3::splat(*radius)),
                Point3::from_glam(*center + Vec3::splat(*radius)),
            ),
            Shape::Quad {
                origin,
                edge_u,
                edge_v,
            } => Bounds3::from_points(
                [
                    *origin,
                    *origin + *edge_u,
                    *origin + *edge_v,
                    *origin + *edge_u + *edge_v,
                ]
                .map(Point3::from_glam),
            ),
        };
        let world_bounds = match &placement {
            Placement::Static(t) => t.bounds(object_bounds),
            Placement::Moving(a) => a.motion_bounds(object_bounds),
        };
        let extent = world_bounds
            .min
            .to_glam()
            .abs()
            .max(world_bounds.max.to_glam().abs())
            .max_element();
        if extent.is_nan() || extent > MAX_COORDINATE {
            return Err(AccelError::Shape(format!(
                "the shape reaches {extent:e} units from the origin; shapes must lie within {MAX_COORDINATE:e} (f32 products of coordinates would overflow)"
            )));
        }
        let index = u32::try_from(self.instances.len())
            .map_err(|_| AccelError::Placement("more than 2^32 instances".to_string()))?;
        self.instances.push((shape, placement));
        Ok(index)
    }

    /// Builds the BVHs: one over every static mesh triangle, flattened to world space; one per
    /// distinct moving mesh, in object space; and a top-level one over the flattened triangles,
    /// the spheres, the quads and the moving meshes (each bounded over all times).
    pub fn build(self) -> Result<Scene, AccelError> {
        let params = self.quality.params();
        let instance_count = self.instances.len();
        let mut items = Vec::new();
        let mut item_bounds: Vec<Bounds3<World>> = Vec::new();
        let mut meshes = Vec::with_capacity(instance_count);
        let mut statics = Vec::with_capacity(instance_count);
        let mut flat_tris: Vec<[Vec3A; 3]> = Vec::new();
        let mut flat_ids: Vec<[u32; 2]> = Vec::new();
        let mut blases: Vec<WideBvh> = Vec::new();
        let mut blas_of_mesh: HashMap<*const TriangleMesh, usize> = HashMap::new();

        for (instance, (shape, placement)) in self.instances.into_iter().enumerate() {
            let instance = instance as u32;
            // A "moving" transform that does not move is static.
            let placement = match placement {
                Placement::Moving(a) if !a.is_animated() => Placement::Static(a.at(0.0)),
                p => p,
            };
            let xform = match &placement {
                Placement::Static(t) if t.is_identity() => Xform::Identity,
                Placement::Static(t) => Xform::Static(*t),
                Placement::Moving(a) => Xform::Moving(a.clone()),
            };
            statics.push(match &placement {
                Placement::Static(t) => Some(*t),
                Placement::Moving(_) => None,
            });
            meshes.push(match &shape {
                Shape::Mesh(m) => Some(m.clone()),
                _ => None,
            });
            match shape {
                Shape::Mesh(mesh) => match placement {
                    Placement::Static(world_from_object) => {
                        // Flatten: carry the triangles to world space once.
                        let m = world_from_object.matrix();
                        for (i, _) in mesh.triangles().iter().enumerate() {
                            let corners =
                                mesh.corners(i).map(|p| Vec3A::from(m.transform_point3(p)));
                            flat_tris.push(corners);
                            flat_ids.push([i as u32, instance]);
                        }
                    }
                    Placement::Moving(world_from_object) => {
                        let key = Arc::as_ptr(&mesh);
                        let blas = *blas_of_mesh.entry(key).or_insert_with(|| {
                            let tris = (0..mesh.triangle_count())
                                .map(|i| mesh.corners(i).map(Vec3A::from))
                                .collect::<Vec<_>>();
                            let ids = (0..tris.len() as u32).map(|i| [i, 0]).collect::<Vec<_>>();
                            blases.push(WideBvh::build(&tris, &ids, params));
                            blases.len() - 1
                        });
                        item_bounds.push(world_from_object.motion_bounds(mesh.bounds()));
                        items.push(Item::MovingMesh {
                            instance,
                            blas,
                            world_from_object,
                        });
                    }
                },
                Shape::Sphere { center, radius } => {
                    let r = Vec3::splat(radius);
                    let b =
                        Bounds3::new(Point3::from_glam(center - r), Point3::from_glam(center + r));
                    item_bounds.push(xform.bounds(b));
                    items.push(Item::Analytic {
                        instance,
                        shape: Analytic::Sphere { center, radius },
                        xform,
                    });
                }
                Shape::Quad {
                    origin,
                    edge_u,
                    edge_v,
                } => {
                    let b = Bounds3::from_points(
                        [
                            origin,
                            origin + edge_u,
                            origin + edge_v,
                            origin + edge_u + edge_v,
                        ]
                        .map(Point3::from_glam),
                    );
                    item_bounds.push(xform.bounds(b));
                    items.push(Item::Analytic {
                        instance,
                        shape: Analytic::Quad(Parallelogram::new(origin, edge_u, edge_v)),
                        xform,
                    });
                }
            }
        }

        let flat = if flat_tris.is_empty() {
            None
        } else {
            let b = Bounds3::from_points(
                flat_tris
                    .iter()
                    .flatten()
                    .map(|&p| Point3::from_glam(Vec3::from(p))),
            );
            item_bounds.push(b);
            items.push(Item::Flat);
            Some(WideBvh::build(&flat_tris, &flat_ids, params))
        };
        if item_bounds
            .iter()
            .any(|b| !b.min.is_finite() || !b.max.is_finite())
        {
            return Err(AccelError::Placement(
                "an instance's world bounds overflow (a transform is too large)".to_string(),
            ));
        }
        let bounds = item_bounds.iter().fold(Bounds3::EMPTY, |a, b| a.union(*b));

        // The top level: none for a single item (one mesh, the common benchmark), one SIMD
        // test of up to eight boxes for a few, obvhs's tree for more.
        let aabbs = item_bounds
            .iter()
            .map(|b| {
                // Pad flat boxes (a quad in an axis plane) by a relative hair.
                let d = b.diagonal().to_glam().abs().max_element();
                let pad = Vec3A::splat(d * 1e-6 + f32::MIN_POSITIVE);
                Aabb::new(
                    Vec3A::from(b.min.to_glam()) - pad,
                    Vec3A::from(b.max.to_glam()) + pad,
                )
            })
            .collect::<Vec<_>>();
        let tlas = if items.len() <= 1 {
            Top::One
        } else if let Some(set) = BoxSet::new(&aabbs) {
            let sorted = items.iter().any(|i| !matches!(i, Item::Analytic { .. }));
            Top::Few { set, sorted }
        } else {
            let bvh = build_cwbvh(
                &aabbs,
                BvhBuildParams::fast_build(),
                &mut Duration::default(),
            );
            let order = bvh.primitive_indices.clone();
            Top::Tree(bvh, order)
        };

        let moves = items.iter().any(|item| match item {
            Item::Flat => false,
            Item::Analytic { xform, .. } => matches!(xform, Xform::Moving(_)),
            Item::MovingMesh { .. } => true,
        });
        Ok(Scene {
            items,
            tlas,
            flat,
            blases,
            meshes,
            statics,
            bounds,
            moves,
            uv: !self.no_uv,
        })
    }
}

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

/// The top level of a [`Scene`].
#[derive(Debug)]
enum Top {
    /// Zero or one item: no top level.
    One,
    /// A few items, their boxes tested at once. `sorted`: a closest-hit query visits the
    /// boxes entered nearest first (when an item is a mesh, whose BVH query the best hit so
    /// far prunes); otherwise in index order, which for a few spheres and quads costs less
    /// than the sort.
    Few { set: BoxSet, sorted: bool },
    /// obvhs's tree over the items, with its slot -> item map.
    Tree(CwBvh, Vec<u32>),
}

#[derive(Debug, Clone)]
enum Xform {
    /// Object space is world space: rays need no transform.
    Identity,
    Static(Transform<World, Object>),
    Moving(AnimatedTransform<World, Object>),
}

impl Xform {
    #[inline]
    fn at(&self, time: f32) -> Transform<World, Object> {
        match self {
            Xform::Identity => Transform::IDENTITY,
            Xform::Static(t) => *t,
            Xform::Moving(a) => a.at(time),
        }
    }
    /// The ray's origin and direction in object space at the ray's time.
    #[inline]
    fn ray_to_object(&self, r: &PlainRay) -> (Vec3A, Vec3A) {
        match self {
            Xform::Identity => (r.o, r.d),
            _ => to_object(&self.at(r.time).inverse(), r),
        }
    }

    fn bounds(&self, b: Bounds3<Object>) -> Bounds3<World> {
        match self {
            Xform::Identity => Transform::IDENTITY.bounds(b),
            Xform::Static(t) => t.bounds(b),
            Xform::Moving(a) => a.motion_bounds(b),
        }
    }
}

#[derive(Debug, Clone, Copy)]
enum Analytic {
    Sphere { center: Vec3, radius: f32 },
    Quad(Parallelogram),
}

#[derive(Debug)]
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

/// The closest hit a [`Scene::intersect_preliminary`] query found, before the full [`Hit`] is
/// built: cheap to get (no mesh data is read) and turned into the `Hit` by
/// [`complete`](PreliminaryHit::complete), exactly as [`Scene::intersect`] would have
/// returned it. It borrows the scene, so it cannot be completed against another.
#[derive(Clone, Copy, Debug)]
pub struct PreliminaryHit<'a> {
    scene: &'a Scene,
    ray: PlainRay,
    found: Found,
}

impl PreliminaryHit<'_> {
    /// The ray parameter of the hit (as [`Hit::t`]).
    pub fn t(&self) -> f32 {
        self.found.t()
    }

    /// The instance hit (as [`Hit::instance`]).
    pub fn instance(&self) -> u32 {
        match self.found {
            Found::Flat { hit } => hit.ids[1],
            Found::Moving { item, .. } | Found::Sphere { item, .. } | Found::Quad { item, .. } => {
                match &self.scene.items[item] {
                    Item::Analytic { instance, .. } | Item::MovingMesh { instance, .. } => {
                        *instance
                    }
                    Item::Flat => unreachable!("flattened triangles are found as Found::Flat"),
                }
            }
        }
    }

    /// The triangle hit within its mesh, 0 for spheres and quads (as [`Hit::primitive`]).
    pub fn primitive(&self) -> u32 {
        match self.found {
            Found::Flat { hit } | Found::Moving { hit, .. } => hit.ids[0],
            Found::Sphere { .. } | Found::Quad { .. } => 0,
        }
    }

    /// The primitive's own coordinates of the hit: for a triangle the barycentrics `(b1, b2)`
    /// of its vertices 1 and 2, for a quad `(s, t)` along `edge_u` and `edge_v`; zero for a
    /// sphere, whose coordinates need the hit point (see [`Hit::uv`]).
    pub fn primitive_uv(&self) -> Vec2 {
        match self.found {
            Found::Flat { hit } | Found::Moving { hit, .. } => Vec2::new(hit.tri.b1, hit.tri.b2),
            Found::Quad { quad, .. } => Vec2::new(quad.s, quad.v),
            Found::Sphere { .. } => Vec2::ZERO,
        }
    }

    /// The full hit record: point and error bound, normals, surface coordinates.
    pub fn complete(&self) -> Hit {
        self.scene.finish(&self.ray, self.found)
    }
}

impl Scene {
    /// The closest hit with `t` in `[t_min, t_max]`, moving instances placed at the ray's time.
    /// `None` for a miss, and for rays that cannot hit anything (non-finite origin or
    /// direction, zero direction, NaN or empty range).
    ///
    /// The same as [`intersect_preliminary`](Scene::intersect_preliminary) followed by
    /// [`PreliminaryHit::complete`].
    pub fn intersect(&self, ray: &Ray<World>) -> Option<Hit> {
        // Written out rather than as `intersect_preliminary(ray)?.complete()`: moving the
        // `PreliminaryHit` through costs 1% of a render's instructions (callgrind).
        let r = PlainRay::new(ray)?;
        let found = self.found(&r)?;
        Some(self.finish(&r, found))
    }

    /// The closest hit as [`intersect`](Scene::intersect) finds it, before its full record is
    /// built: the distance, the instance and primitive, and the primitive's own coordinates,
    /// with no mesh data read (the role of Embree's `rtcIntersect1` or Mitsuba's preliminary
    /// intersection). For queries that need only what was hit and how far away (depth and id
    /// buffers, lidar returns), and for deciding which hits deserve
    /// [`complete`](PreliminaryHit::complete).
    ///
    /// ```
    /// use obscura_accel::{Placement, SceneBuilder, Shape};
    /// use obscura_space::{Point3, Ray, Transform, Vector3, World};
    /// use obscura_space::glam::Vec3;
    ///
    /// let mut builder = SceneBuilder::new();
    /// let quad = Shape::Quad {
    ///     origin: Vec3::new(-1.0, -1.0, 0.0),
    ///     edge_u: Vec3::new(2.0, 0.0, 0.0),
    ///     edge_v: Vec3::new(0.0, 2.0, 0.0),
    /// };
    /// let id = builder.add(quad, Placement::Static(Transform::IDENTITY))?;
    /// let scene = builder.build()?;
    /// let ray = Ray::<World>::new(Point3::new(0.5, 0.0, 3.0), Vector3::new(0.0, 0.0, -1.0), 0.0);
    /// let found = scene.intersect_preliminary(&ray).expect("the ray meets the quad");
    /// assert_eq!((found.instance(), found.t()), (id, 3.0));
    /// assert_eq!(found.primitive_uv().to_array(), [0.75, 0.5]);
    /// assert_eq!(found.complete(), scene.intersect(&ray).unwrap());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn intersect_preliminary(&self, ray: &Ray<World>) -> Option<PreliminaryHit<'_>> {
        let r = PlainRay::new(ray)?;
        let found = self.found(&r)?;
        Some(PreliminaryHit {
            scene: self,
            ray: r,
            found,
        })
    }

    /// The closest hit on any item, before its record is built.
    #[inline]
    fn found(&self, r: &PlainRay) -> Option<Found> {
        match &self.tlas {
            Top::One if self.items.len() == 1 => self.intersect_item(0, r, r.t_max),
            Top::One => None,
            Top::Few { set, sorted: true } => {
                let mut entered = [(0, 0.0); BoxSet::CAPACITY];
                let n = set.entered(r.o, r.d, r.t_min, r.t_max, &mut entered);
                // The best distance is kept beside the best hit, not read back from it: a
                // `Found` is a 72-byte enum, and matching it for its `t` before every item
                // was a jump table and stack copies on the hottest loop of small scenes.
                let mut best: Option<Found> = None;
                let mut t_best = r.t_max;
                for &(item, t_entry) in &entered[..n] {
                    if t_entry > t_best {
                        break;
                    }
                    if let Some(f) = self.intersect_item(item, r, t_best) {
                        t_best = f.t();
                        best = Some(f);
                    }
                }
                best
            }
            Top::Few { set, sorted: false } => {
                // Spheres and quads in index order: the sort (and the zeroed array it fills)
                // cost more than the item tests it spared. One entered beyond the best hit so
                // far is still skipped.
                let (t_near, mut mask) = set.test(r.o, r.d, r.t_min, r.t_max);
                let mut best: Option<Found> = None;
                let mut t_best = r.t_max;
                while mask != 0 {
                    let item = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    if t_near[item & 7] > t_best {
                        continue;
                    }
                    if let Some(f) = self.intersect_item(item, r, t_best) {
                        t_best = f.t();
                        best = Some(f);
                    }
                }
                best
            }
            Top::Tree(tlas, order) => {
                let top = obvhs::ray::Ray::new(r.o, r.d, r.t_min, r.t_max);
                let mut ray_hit = RayHit::none();
                let mut best = None;
                tlas.ray_traverse(top, &mut ray_hit, |top, slot| {
                    match self.intersect_item(order[slot] as usize, r, top.tmax) {
                        Some(f) => {
                            best = Some(f);
                            f.t()
                        }
                        None => f32::INFINITY,
                    }
                });
                best
            }
        }
    }

    /// True when anything is hit with `t` in `[t_min, t_max]` (for shadow rays); stops at the
    /// first hit found.
    pub fn occluded(&self, ray: &Ray<World>) -> bool {
        let Some(r) = PlainRay::new(ray) else {
            return false;
        };
        match &self.tlas {
            Top::One if self.items.len() == 1 => self.occluded_item(0, &r),
            Top::One => false,
            Top::Few { set, .. } => {
                // Any order will do for a shadow ray.
                let mut mask = set.entered_mask(r.o, r.d, r.t_min, r.t_max);
                while mask != 0 {
                    let item = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    if self.occluded_item(item, &r) {
                        return true;
                    }
                }
                false
            }
            Top::Tree(tlas, order) => {
                let top = obvhs::ray::Ray::new(r.o, r.d, r.t_min, r.t_max);
                !tlas.ray_traverse_miss(top, |_, slot| {
                    if self.occluded_item(order[slot] as usize, &r) {
                        f32::NEG_INFINITY
                    } else {
                        f32::INFINITY
                    }
                })
            }
        }
    }

    /// True when some instance moves (a placement given at shutter close): only then does a
    /// ray's time change what it hits. Constant time (found at build), so a renderer may ask
    /// per tile.
    pub fn moves(&self) -> bool {
        self.moves
    }

    /// The box of everything in the scene, over all times.
    pub fn bounds(&self) -> Bounds3<World> {
        self.bounds
    }

    /// The number of instances added.
    pub fn instance_count(&self) -> usize {
        self.meshes.len()
    }

    /// Bytes held by the triangle BVHs (nodes and leaf triangles; the meshes themselves and
    /// the few-box top level are not counted), for memory budgets and the performance notes.
    pub fn bvh_bytes(&self) -> usize {
        let flat = self.flat.as_ref().map_or(0, WideBvh::heap_bytes);
        flat + self.blases.iter().map(WideBvh::heap_bytes).sum::<usize>()
    }

    /// The closest hit on one item with `t` in `[r.t_min, t_max]`.
    #[inline]
    fn intersect_item(&self, item: usize, r: &PlainRay, t_max: f32) -> Option<Found> {
        match &self.items[item] {
            Item::Flat => {
                let hit = self.flat.as_ref()?.closest(r.o, r.d, r.t_min, t_max)?;
                Some(Found::Flat { hit })
            }
            Item::MovingMesh {
                blas,
                world_from_object,
                ..
            } => {
                let object_from_world = world_from_object.at(r.time).inverse();
                let (o, d) = to_object(&object_from_world, r);
                let hit = self.blases[*blas].closest(o, d, r.t_min, t_max)?;
                Some(Found::Moving { item, hit })
            }
            Item::Analytic { shape, xform, .. } => {
                let (o, d) = xform.ray_to_object(r);
                let (o, d) = (Vec3::from(o), Vec3::from(d));
                match *shape {
                    Analytic::Sphere { center, radius } => {
                        let t = intersect_sphere(o, d, r.t_min, t_max, center, radius)?;
                        Some(Found::Sphere { item, t })
                    }
                    Analytic::Quad(parallelogram) => {
                        let quad = parallelogram.intersect(o, d, r.t_min, t_max)?;
                        Some(Found::Quad { item, quad })
                    }
                }
            }
        }
    }

    /// True when one item is hit with `t` in `[r.t_min, r.t_max]`.
    #[inline]
    fn occluded_item(&self, item: usize, r: &PlainRay) -> bool {
        match &self.items[item] {
            Item::Flat => self
                .flat
                .as_ref()
                .is_some_and(|blas| blas.any(r.o, r.d, r.t_min, r.t_max)),
            Item::MovingMesh {
                blas,
                world_from_object,
                ..
            } => {
                let object_from_world = world_from_object.at(r.time).inverse();
                let (o, d) = to_object(&object_from_world, r);
                self.blases[*blas].any(o, d, r.t_min, r.t_max)
            }
            Item::Analytic { .. } => self.intersect_item(item, r, r.t_max).is_some(),
        }
    }

    /// Builds the full world-space hit record from what the traversal found.
    fn finish(&self, r: &PlainRay, found: Found) -> Hit {
        match found {
            Found::Flat { hit } => {
                let [primitive, instance] = hit.ids;
                let world_from_object =
                    self.statics[instance as usize].expect("flattened meshes are static");
                let mesh = self.meshes[instance as usize]
                    .as_ref()
                    .expect("flattened instances are meshes");
                let (p, p_error) = edge_point(&hit);
                // The world edges already carry the transform: (M a) x (M b) =
                // det(M) M^-T (a x b), so flip for a mirroring transform to match the inverse
                // transpose of the object-space winding normal.
                let mut n_geo = hit.e1.cross(hit.e2).normalize();
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
                let world_from_object = world_from_object.at(r.time);
                let (p_object, err_object) = edge_point(&hit);
                let (p, p_error) = point_to_world(&world_from_object, p_object, err_object);
                let n_geo = normal_to_world(&world_from_object, hit.e1.cross(hit.e2));
                self.triangle_hit(
                    r,
                    hit.tri,
                    p,
                    p_error,
                    n_geo,
                    mesh,
                    hit.ids[0],
                    *instance,
                    &world_from_object,
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
            _ => {
                let world_from_object = xform.at(r.time);
                let (p, p_error) = point_to_world(&world_from_object, p_object, err_object);
                (p, p_error, normal_to_world(&world_from_object, n_object))
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
        let vertices = mesh.triangles()[primitive as usize];
        let n_shading = mesh
            .normals()
            .and_then(|normals| {
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
                .map(|uvs| (0..3).map(|k| uvs[vertices[k] as usize] * b[k]).sum())
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

/// The ray's origin and direction carried into object space.
#[inline]
fn to_object(object_from_world: &Transform<Object, World>, r: &PlainRay) -> (Vec3A, Vec3A) {
    let m = object_from_world.matrix();
    (
        Vec3A::from(m.transform_point3(Vec3::from(r.o))),
        Vec3A::from(m.transform_vector3(Vec3::from(r.d))),
    )
}

/// A hit point found in object space, carried to world space with its error bound: the
/// rounding of the transform itself plus that of having carried the ray into object space.
#[inline]
fn point_to_world(
    world_from_object: &Transform<World, Object>,
    p_object: Vec3,
    err_object: Vec3,
) -> (Vec3, Vec3) {
    let m = world_from_object.matrix();
    let (p, p_error) = transform_point_with_error(&m, p_object, err_object);
    (
        p,
        p_error + object_space_error(&m, &world_from_object.inverse_matrix(), p),
    )
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
#[inline]
fn edge_point(hit: &WideHit) -> (Vec3, Vec3) {
    let (a, b, c) = (hit.v0, hit.e1 * hit.tri.b1, hit.e2 * hit.tri.b2);
    let p = a + b + c;
    let err = gamma(7) * (a.abs() + b.abs() + c.abs());
    (p, err)
}

// The renderer shares one scene between its worker threads.
const _: () = {
    const fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<Scene>();
};
