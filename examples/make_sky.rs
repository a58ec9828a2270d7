//! Writes the procedural sky of `camera_obscura::sky` as an EXR (the shipped `scenes/sky.exr`).
//!
//! `cargo run --release --example make_sky -- [OUT.exr] [WIDTHxHEIGHT]` (default
//! `scenes/sky.exr` at the shipped 256x128; `bench/equal_error.py` asks for a finer one).

use camera_obscura::render::{ImageInfo, write_image};
use camera_obscura::sky::{SKY_HEIGHT, SKY_WIDTH, procedural_sky};

fn main() {
    let mut args = std::env::args().skip(1);
    let out = args.next().unwrap_or_else(|| "scenes/sky.exr".into());
    let (width, height) = match args.next() {
        None => (SKY_WIDTH, SKY_HEIGHT),
        Some(size) => match size
            .split_once('x')
            .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)))
        {
            Some((w, h)) if (1..=16384).contains(&w) && (1..=16384).contains(&h) => (w, h),
            _ => {
                eprintln!("error: {size}: expected WIDTHxHEIGHT, each 1 to 16384");
                std::process::exit(2);
            }
        },
    };
    let image = procedural_sky(width, height);
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
    println!("wrote {out} ({width}x{height})");
}
