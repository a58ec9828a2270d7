//! Typed coordinate spaces for ray tracing: points, vectors, normals, rays and boxes tagged
//! with the space they live in, and the transforms between spaces.
//!
//! This crate is the bottom of Obscura: the camera models, the accelerator and the renderer all
//! speak its types. It depends on glam only and knows nothing of cameras, BVHs or files.
//!
//! - The spaces: [`World`], [`Object`], [`Camera`], [`Screen`], [`Ndc`], [`Raster`] (add your
//!   own with [`Space`]).
//! - The values: [`Point3`], [`Vector3`], [`Normal3`], [`Point2`], [`Vector2`], [`Ray`],
//!   [`Bounds3`], all zero-cost wrappers over glam's `f32` types.
//! - The maps: [`Transform<To, From>`](Transform), holding its matrix and inverse, and
//!   [`AnimatedTransform<To, From>`](AnimatedTransform), keyframed over the shutter interval.
//!
//! The one decision to know: a transform names its destination first, like the matrix it
//! holds, so composition cancels the inner names and the compiler checks every change of
//! space. `world_from_camera * camera_from_raster` is a `Transform<World, Raster>`;
//! `camera_from_raster * world_from_camera` does not compile.
//!
//! ```
//! use obscura_space::{Camera, Point3, Transform, Vector3, World};
//!
//! // The look-at of the scene format: eye at the origin looking down world -z, y up.
//! let world_from_camera = Transform::<World, Camera>::look_at(
//!     Point3::new(0.0, 0.0, 0.0),
//!     Point3::new(0.0, 0.0, -1.0),
//!     Vector3::new(0.0, 1.0, 0.0),
//! )?;
//! // Camera +z is the viewing direction, camera +x is world +x (the image's right).
//! let p_world = world_from_camera * Point3::<Camera>::new(1.0, 0.0, 2.0);
//! assert_eq!(p_world, Point3::new(1.0, 0.0, -2.0));
//! // A right-handed world seen through a camera frame is a reflection.
//! assert!(world_from_camera.swaps_handedness());
//! // Going back is free: the inverse is stored.
//! let camera_from_world = world_from_camera.inverse();
//! assert_eq!(camera_from_world * p_world, Point3::new(1.0, 0.0, 2.0));
//! # Ok::<(), obscura_space::SpaceError>(())
//! ```
//!
//! Composing in the wrong order is a type error, not a wrong picture:
//!
//! ```compile_fail
//! use obscura_space::{Camera, Raster, Transform, World};
//! let world_from_camera = Transform::<World, Camera>::IDENTITY;
//! let camera_from_raster = Transform::<Camera, Raster>::IDENTITY;
//! let wrong = camera_from_raster * world_from_camera; // Raster != World: does not compile
//! ```
#![deny(missing_docs)]

mod animated;
mod bounds;
mod error;
mod geometry;
mod ray;
mod spaces;
mod transform;

pub use animated::AnimatedTransform;
pub use bounds::Bounds3;
pub use error::SpaceError;
pub use geometry::{Normal3, Point2, Point3, Vector2, Vector3};
pub use ray::Ray;
pub use spaces::{Camera, Ndc, Object, Raster, Screen, Space, World};
pub use transform::Transform;

/// Maps camera space to world space (the camera's pose).
pub type WorldFromCamera = Transform<World, Camera>;
/// Maps world space to camera space.
pub type CameraFromWorld = Transform<Camera, World>;
/// Maps an object's space to world space (its instance transform).
pub type WorldFromObject = Transform<World, Object>;
/// Maps world space to an object's space.
pub type ObjectFromWorld = Transform<Object, World>;

/// Re-export of the glam version these types wrap, for the escape hatches.
pub use glam;
