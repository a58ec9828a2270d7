//! The Obscura renderer: scene files, the film, the integrators, the parallel tile scheduler and
//! image output. It composes the other crates and is the only one that knows the scene format.
//!
//! - [`load_description`] / [`parse_description`] read a TOML scene file strictly into a
//!   [`SceneDescription`] (unknown keys, NaNs and out-of-range values are [`RenderError`]s that
//!   name the file, the key and the line); [`parse_camera_description`] reads only the
//!   camera's part of one into a [`CameraDescription`], skipping the scene it looks at;
//! - [`RenderScene::build`] turns it into a camera (`obscura-camera`), geometry
//!   (`obscura-accel`), materials and lights (`obscura-shade`) and a sampler;
//! - [`render`] takes the samples in passes of one per pixel over 16x16 tiles, in parallel,
//!   splatting each into a [`Film`] through its reconstruction [`Filter`];
//! - [`write_image`] writes EXR or PNG atomically;
//! - [`depth_of_field`] and [`motion_blur`] are Potmesil and Chakravarty's post-process blurs of
//!   a pinhole image by its [`screen_buffers`], for comparison with the distributed ray tracing
//!   that the renderer does.
//!
//! The decision to know: tiles accumulate into their own buffers, merged into a pass
//! accumulator that is added to the film once the pass is complete, and the film's sums are
//! exact fixed-point integers. So the image is bit-identical for any thread count and any tile
//! completion order, and a render split into slices of passes or tiles ([`Slice`], written as
//! [`Partial`] files) merges ([`merge_partials`]) to exactly the one-process image.
//!
//! Not for: camera models, BVHs or BSDFs themselves (their crates), nor the command line (the
//! `camera-obscura` package's `obscura` binary).
//!
//! ```
//! use obscura_render::{parse_description, render, RenderOptions, RenderScene};
//!
//! let toml = r#"
//!     [film]
//!     resolution = [16, 16]
//!     [integrator]
//!     type = "distance"
//!     [camera]
//!     eye = [0.0, 0.0, 3.0]
//!     target = [0.0, 0.0, 0.0]
//!     fov = 30.0
//!     [[shapes]]
//!     type = "quad"
//!     origin = [-10.0, -10.0, 0.0]
//!     edge_u = [20.0, 0.0, 0.0]
//!     edge_v = [0.0, 20.0, 0.0]
//! "#;
//! let scene = RenderScene::build(parse_description("inline.toml".as_ref(), toml)?)?;
//! let outcome = render(&scene, RenderOptions { threads: Some(1), ..Default::default() })?;
//! let image = outcome.film.resolve();
//! // The wall fills the view 3 units away; at the centre the distance is 3 (alpha 1: covered).
//! let [d, _, _, alpha] = image.pixel(8, 8);
//! assert!((d - 3.0).abs() < 0.01 && alpha == 1.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

mod build;
mod checkpoint;
mod error;
mod film;
mod locate;
mod output;
mod partial;
mod postprocess;
mod render;
mod scene;
mod stereo;

pub use build::{
    BYTES_PER_PIXEL, DEFAULT_MATERIAL, RenderScene, camera_of, environment_map_texels, human_bytes,
};
pub use checkpoint::{CHECKPOINT_MAGIC, CHECKPOINT_VERSION, Checkpoint, scene_fingerprint};
pub use error::RenderError;
pub use film::{FIXED_FRACTION_BITS, Film, Filter, Image, PixelRect, PixelSums, TileBuffer};
pub use output::{
    ImageInfo, OutputFormat, decode_exr, read_exr, srgb_8bit, temporary_beside, write_image,
};
pub use partial::{
    PARTIAL_MAGIC, PARTIAL_VERSION, PartSet, Partial, Slice, SliceBy, merge_partials,
};
pub use postprocess::{
    DepthOfField, ScreenBuffers, circle_of_confusion, circle_of_confusion_orthographic,
    depth_of_field, motion_blur, screen_buffers,
};
pub use render::{
    RenderOptions, RenderOutcome, RenderStats, TILE_SIZE, TILE_WINDOW, render, sample_value, tiles,
};
pub use scene::{
    CameraDescription, CameraKind, CameraPose, CameraSettings, DEFAULT_FOCUS_DISTANCE,
    DEFAULT_INTERAXIAL, Extrinsics, FilmSettings, FilterSettings, IntegratorKind,
    IntegratorSettings, LightSettings, MaterialSettings, RealisticSettings, SamplerSettings,
    SceneDescription, ShapeGeometry, ShapeSettings, StereoLayout, StereoSettings,
    load_camera_description, load_description, parse_camera_description, parse_description,
};
pub use stereo::compose_stereo;
