//! The scene file: parsing (serde + toml) and validation into a [`SceneDescription`].
//!
//! Parsing is strict: unknown keys are errors, every number is checked for NaN and range, and
//! every error names the file, the key and the line. (The camera-only parser skips, unread,
//! the tables a camera does not need; those it reads are as strict.) Nothing here builds
//! cameras or BVHs; see [`crate::build`] for that.
//!
//! - `raw`: the serde structs, as TOML gives them;
//! - `settings`: the public, validated settings types;
//! - `parse`: the validating parser (film, sampler, integrator, materials, shapes, lights), and
//!   the camera-only parser that reads film, camera and sampler type alone;
//! - `camera`: the `[camera]` keys, mapped onto the camera crate's types and checks.

mod camera;
mod parse;
mod raw;
mod settings;

pub(crate) use camera::camera_key;
pub use camera::{DEFAULT_FOCUS_DISTANCE, DEFAULT_INTERAXIAL};
pub use parse::{
    load_camera_description, load_description, parse_camera_description, parse_description,
};
pub use settings::{
    CameraDescription, CameraKind, CameraPose, CameraSettings, Extrinsics, FilmSettings,
    FilterSettings, IntegratorKind, IntegratorSettings, LightSettings, MaterialSettings,
    RealisticSettings, SamplerSettings, SceneDescription, ShapeGeometry, ShapeSettings,
    StereoLayout, StereoSettings,
};
