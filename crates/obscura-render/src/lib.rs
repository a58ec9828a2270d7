//! obscura-render: scene files, film, integrators and image output (under construction).
#![deny(missing_docs)]

mod build;
mod error;
mod film;
mod locate;
mod output;
mod render;
mod scene;

pub use build::{BYTES_PER_PIXEL, DEFAULT_MATERIAL, RenderScene, human_bytes};
pub use error::RenderError;
pub use film::{Film, Filter, Image, PixelRect, PixelSums, TileBuffer};
pub use output::{ImageInfo, OutputFormat, read_exr, srgb_8bit, temporary_beside, write_image};
pub use render::{
    RenderOptions, RenderOutcome, RenderStats, TILE_SIZE, render, sample_value, tiles,
};
pub use scene::*;
