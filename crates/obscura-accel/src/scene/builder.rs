//! Collecting shapes and building the scene: validation, flattening static meshes, one BVH per
//! moving mesh, and the top level over everything.

use super::{Analytic, Item, Placed, QuadSet, Scene, Top, Xform};
use crate::error::AccelError;
use crate::geom::Parallelogram;
use crate::mesh::TriangleMesh;
use crate::shape::{Placement, Shape};
use crate::wide::{Binary, BoxSet, WideBvh};
use glam::{Vec3, Vec3A};
use obscura_space::{Bounds3, Object, Point3, Transform, World};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::builder::build_cwbvh;
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Duration;

/// How much effort to spend building the per-mesh BVHs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BuildQuality {
    /// obvhs's PLOC with its `fast_build()` preset (a short search radius, little
    /// reinsertion): the quickest build, for scenes traced with few rays.
    Fast,
    /// A top-down binned surface-area build whose splits are charged by the four-triangle
    /// packets each side fills (the default): about Embree's build time, and its trees need
    /// 10-30% fewer node and packet visits than PLOC's (docs/performance.md).
    #[default]
    Medium,
    /// The same build with twice the bins, over large triangles first split into several
    /// boxes (obvhs's pre-splits, meant for long thin triangles whose boxes are mostly
    /// empty), at a build a fifth to a third longer.
    Slow,
}

impl BuildQuality {
    /// The binary build this quality collapses.
    pub(crate) fn binary(self) -> Binary {
        match self {
            BuildQuality::Fast => Binary::Ploc(BvhBuildParams::fast_build()),
            BuildQuality::Medium => Binary::Sah {
                bins: 32,
                pre_split: false,
            },
            BuildQuality::Slow => Binary::Sah {
                bins: 64,
                pre_split: true,
            },
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

    /// Whether hits carry surface coordinates ([`Hit::uv`](crate::Hit::uv); on by default).
    /// Off, every hit's `uv` is zero and costs nothing: a sphere's takes an arccosine and an
    /// arctangent, a mesh's a read of its uv array (on a large mesh, one more cache miss per
    /// hit). For callers that read no textures, such as Obscura's own renderer.
    /// [`PreliminaryHit::primitive_uv`](crate::PreliminaryHit::primitive_uv) is not affected.
    pub fn with_uv(mut self, uv: bool) -> Self {
        self.no_uv = !uv;
        self
    }

    /// Adds an instance. Returns the instance index (0, 1, 2... in call order):
    /// [`Hit::instance`](crate::Hit::instance) reports it. Errors for invalid shape parameters
    /// (non-finite values, a radius <= 0, a quad of zero area) or a non-finite placement.
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
        let object_bounds = shape.object_bounds();
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
    /// the spheres, the quads and the moving meshes (each bounded over all times). The
    /// surface-area builds run their large subtrees on rayon's current pool (the global one
    /// unless called inside [`rayon::ThreadPool::install`]); the trees are the same for any
    /// number of threads.
    pub fn build(self) -> Result<Scene, AccelError> {
        let binary = self.quality.binary();
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
                Placement::Static(t) => Xform::Static(Placed::new(*t)),
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
                            blases.push(WideBvh::build(&tris, &ids, binary));
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
                    // A static quad is carried to world space once, as static triangles are:
                    // its rays then need no transform and its hits no carrying back. An affine
                    // map takes a parallelogram to one, with the same (s, v) at each point.
                    let (quad, xform) = match (&placement, xform) {
                        (Placement::Static(t), Xform::Static(_)) => {
                            let m = t.matrix();
                            let quad = Parallelogram::new(
                                m.transform_point3(origin),
                                m.transform_vector3(edge_u),
                                m.transform_vector3(edge_v),
                            );
                            let quad = if t.swaps_handedness() {
                                quad.mirrored()
                            } else {
                                quad
                            };
                            (quad, Xform::Identity)
                        }
                        (_, xform) => (Parallelogram::new(origin, edge_u, edge_v), xform),
                    };
                    let b = Bounds3::from_points(
                        [
                            quad.origin,
                            quad.origin + quad.edge_u,
                            quad.origin + quad.edge_v,
                            quad.origin + quad.edge_u + quad.edge_v,
                        ]
                        .map(Point3::from_glam),
                    );
                    item_bounds.push(xform.bounds(b));
                    items.push(Item::Analytic {
                        instance,
                        shape: Analytic::Quad(quad),
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
            Some(WideBvh::build(&flat_tris, &flat_ids, binary))
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

        // The top level: none for a single item (one mesh, the common benchmark); for spheres
        // and quads with static quads among them, the quads' own tests four at a time and
        // the others' boxes; one SIMD test of up to eight boxes for a few items, two for up
        // to sixteen spheres and quads (a tree over them costs more: docs/performance.md),
        // obvhs's tree for more.
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
        } else if let Some(top) = quads_first(&items, &aabbs) {
            top
        } else if let Some(set) = BoxSet::new(&aabbs) {
            let sorted = items.iter().any(|i| !matches!(i, Item::Analytic { .. }));
            Top::Few { set, sorted }
        } else if let (Some(lo), Some(hi), true) = (
            BoxSet::new(&aabbs[..BoxSet::CAPACITY]),
            BoxSet::new(&aabbs[BoxSet::CAPACITY..]),
            items.iter().all(|i| matches!(i, Item::Analytic { .. })),
        ) {
            Top::Two([lo, hi])
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

/// The top level that tests a scene's static quads (those carried to world space) four at a
/// time, without boxes, and its other items through their boxes: for a scene of spheres and
/// quads only, with at least one static quad, at most [`QuadSet::CAPACITY`] of them and at
/// most eight other items. `None` for any other scene.
fn quads_first(items: &[Item], aabbs: &[Aabb]) -> Option<Top> {
    let mut quads = Vec::new();
    let mut others = Vec::new();
    for (index, item) in items.iter().enumerate() {
        match item {
            Item::Analytic {
                shape: Analytic::Quad(quad),
                xform: Xform::Identity,
                ..
            } => quads.push((index, *quad)),
            Item::Analytic { .. } => others.push(index),
            Item::Flat | Item::MovingMesh { .. } => return None,
        }
    }
    if quads.is_empty() {
        return None;
    }
    let boxes = if others.is_empty() {
        None
    } else {
        let boxes: Vec<Aabb> = others.iter().map(|&i| aabbs[i]).collect();
        Some(BoxSet::new(&boxes)?)
    };
    Some(Top::Quads {
        quads: QuadSet::new(&quads)?,
        boxes,
        others,
    })
}
