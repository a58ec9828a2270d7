//! obscura-render: scene files, film, integrators and image output (under construction).
#![deny(missing_docs)]

mod error;
mod film;
mod locate;
mod output;
mod scene;

pub use error::RenderError;
pub use film::{Film, Filter, Image, PixelRect, PixelSums, TileBuffer};
pub use output::{ImageInfo, OutputFormat, read_exr, srgb_8bit, temporary_beside, write_image};
pub use scene::*;
