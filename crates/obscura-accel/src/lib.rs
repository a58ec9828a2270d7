//! Geometry and ray queries for Obscura: triangle meshes (loaded from OBJ files with tobj),
//! analytic spheres and quads, placed as static or moving instances, and a two-level BVH (built
//! by binned surface area here, on rayon's threads, or by obvhs's PLOC for
//! [`BuildQuality::Fast`]; laid out as 8-wide nodes with 4-triangle SIMD leaves and traversed
//! here, compiled for AVX2 where the CPU has it) that answers closest-hit and any-hit (shadow)
//! queries.
//!
//! This is the only Obscura crate that knows about BVHs. It is not a renderer: it knows nothing
//! of materials, lights, cameras or films, and it speaks the typed spaces of `obscura_space` at
//! its boundary ([`Ray<World>`](obscura_space::Ray) in, [`Hit`] out).
//!
//! - Shapes: [`TriangleMesh`] (built by [`TriangleMesh::new`] or [`load_obj`]), and the
//!   variants of [`Shape`].
//! - Scenes: [`SceneBuilder`] takes shapes with a [`Placement`] and builds a [`Scene`], which
//!   answers [`Scene::intersect`] and [`Scene::occluded`] from any number of threads;
//!   [`Scene::intersect_preliminary`] finds the same closest hit without building its full
//!   record (distance, ids and barycentrics only, like Embree's `rtcIntersect1`);
//!   [`Scene::intersect_batch`], [`Scene::intersect_preliminary_batch`] and
//!   [`Scene::occluded_batch`] answer many rays at once, the same answers, faster on large
//!   meshes (their BVH traversals take turns so that their cache misses overlap);
//!   [`SceneBuilder::with_uv`] turns off the hits' surface coordinates for callers that read
//!   no textures.
//! - Hits: [`Hit`] carries the world-space point with a conservative error bound, and
//!   [`Hit::spawn_ray`] / [`Hit::spawn_ray_to`] offset new rays by that bound (pbrt's method), so
//!   a surface does not shadow itself.
//! - Memory: [`Pages`] keeps a large read-only array on transparent huge pages where the system
//!   gives them (the BVH and the meshes live in them; obscura-shade puts environment maps there
//!   too), so that a ray's random reads do not also miss the TLB.
//!
//! The decision to know: visibility is decided at the ray's own time. Static meshes are
//! flattened into world space once and share one BVH; a moving instance is bounded in the top
//! level by its motion bounds over the whole shutter interval, and a ray that reaches it is
//! carried into object space with the instance transform interpolated at `ray.time`. That is
//! what makes distributed-ray-tracing motion blur correct rather than approximate.
//!
//! ```
//! use obscura_accel::{Placement, SceneBuilder, Shape};
//! use obscura_space::{AnimatedTransform, Point3, Ray, Transform, Vector3, World, Object};
//! use obscura_space::glam::Vec3;
//!
//! let mut scene = SceneBuilder::new();
//! // A unit sphere that moves from x = 0 at time 0 to x = 4 at time 1.
//! let start = Transform::<World, Object>::translate(Vec3::ZERO)?;
//! let end = Transform::<World, Object>::translate(Vec3::new(4.0, 0.0, 0.0))?;
//! let moving = AnimatedTransform::new(start, 0.0, end, 1.0)?;
//! let sphere = Shape::Sphere { center: Vec3::ZERO, radius: 1.0 };
//! let id = scene.add(sphere, Placement::Moving(moving))?;
//! let scene = scene.build()?;
//!
//! // A ray down the z axis at x = 4 meets the sphere only at the end of the shutter.
//! let ray_at = |time| Ray::<World>::new(Point3::new(4.0, 0.0, 5.0), Vector3::new(0.0, 0.0, -1.0), time);
//! assert!(scene.intersect(&ray_at(0.0)).is_none());
//! let hit = scene.intersect(&ray_at(1.0)).expect("the sphere has arrived");
//! assert_eq!(hit.instance, id);
//! assert!((hit.t - 4.0).abs() < 1e-5); // from z = 5 to the sphere's top at z = 1
//! // A shadow ray spawned upwards from the hit does not hit its own sphere.
//! let up = hit.spawn_ray(Vector3::new(0.0, 0.0, 1.0));
//! assert!(!scene.occluded(&up));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

mod error;
mod geom;
mod hit;
mod mesh;
mod obj;
mod pages;
mod scene;
mod shape;
mod simd;
mod wide;

pub use error::AccelError;
pub use hit::{Hit, SHADOW_EPSILON};
pub use mesh::TriangleMesh;
pub use obj::{load_obj, parse_obj};
pub use pages::Pages;
pub use scene::{BuildQuality, MAX_COORDINATE, PreliminaryHit, Scene, SceneBuilder};
pub use shape::{Placement, Shape};
pub use simd::prefetch;
