//! Obscura: camera models for ray tracing, and a physically based renderer that composes them.
//!
//! This facade re-exports the workspace's crates for users who want all of them; take a single
//! crate (say `obscura-camera`) when that is all you need. The `obscura` command-line tool is
//! built from this package too.
//!
//! - [`space`]: typed coordinate spaces and transforms (`Transform<To, From>`).
//! - [`sample`]: samplers for film, lens and time, and warps.
//! - [`camera`]: orthographic, perspective (each with a thin lens) and environment cameras.
//! - [`accel`]: meshes, spheres, quads, moving instances and BVHs (obvhs).
//! - [`shade`]: materials, lights and the path tracer.
//! - [`render`]: scene files, film, integrators and image output.
//! - [`import`]: pbrt-v4 and Mitsuba 3 scenes (and PLY meshes) read into the renderer's scene
//!   description.
//!
//! ```
//! use camera_obscura::camera::{Camera, CameraSample};
//! use camera_obscura::space::{Point2, Raster};
//!
//! // Render a scene description held in memory and look at its centre pixel.
//! let toml = r#"
//!     [film]
//!     resolution = [8, 8]
//!     [integrator]
//!     type = "depth"
//!     [camera]
//!     eye = [0.0, 0.0, 5.0]
//!     target = [0.0, 0.0, 0.0]
//!     [[shapes]]
//!     type = "sphere"
//!     radius = 1.0
//! "#;
//! let description = camera_obscura::render::parse_description("inline.toml".as_ref(), toml)?;
//! let scene = camera_obscura::render::RenderScene::build(description)?;
//! // The camera ray through the image centre hits the sphere's front at z = 4.
//! let ray = scene.camera.generate_ray(&CameraSample::at(Point2::<Raster>::new(4.0, 4.0))).unwrap();
//! let hit = scene.geometry.intersect(&ray.ray).unwrap();
//! assert!((hit.t - 4.0).abs() < 1e-4);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

pub use obscura_accel as accel;
pub use obscura_camera as camera;
pub use obscura_import as import;
pub use obscura_render as render;
pub use obscura_sample as sample;
pub use obscura_shade as shade;
pub use obscura_space as space;

pub mod gallery;
pub mod sky;

/// The README's examples, compiled and run as doctests so they stay true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
