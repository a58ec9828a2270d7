//! Writes the procedural sky of `camera_obscura::sky` as an EXR (the shipped `scenes/sky.exr`).
//!
//! `cargo run --release --example make_sky -- [OUT.exr]` (default `scenes/sky.exr`).

use camera_obscura::render::{ImageInfo, write_image};
use camera_obscura::sky::{SKY_HEIGHT, SKY_WIDTH, procedural_sky};

fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "scenes/sky.exr".into());
    let image = procedural_sky(SKY_WIDTH, SKY_HEIGHT);
    if let Err(e) = write_image(
        out.as_ref(),
        &image,
        &ImageInfo {
            partial: false,
            samples_per_pixel: 1,
        },
    ) {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
    println!("wrote {out} ({SKY_WIDTH}x{SKY_HEIGHT})");
}
