//! Shapes and their placement in the world: what a scene is made of (and what an area light in
//! obscura-shade emits from).

use crate::mesh::TriangleMesh;
use glam::Vec3;
use obscura_space::{AnimatedTransform, Bounds3, Object, Point3, Transform, World};
use std::sync::Arc;

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

impl Shape {
    /// The box around the shape in its own object space.
    pub fn object_bounds(&self) -> Bounds3<Object> {
        match self {
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
        }
    }
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

impl Placement {
    /// The `world_from_object` transform at `time` (the same at every time when static).
    #[inline]
    pub fn at(&self, time: f32) -> Transform<World, Object> {
        match self {
            Placement::Static(t) => *t,
            Placement::Moving(a) => a.at(time),
        }
    }
}
