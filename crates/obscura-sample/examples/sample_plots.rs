//! Writes scatter plots of each sampler's first 256 samples of one pixel: film points, lens
//! points in the square and on the concentric disk, and film x against lens x, next to a
//! deliberately correlated sampler for comparison.
//!
//! ```text
//! cargo run -p obscura-sample --example sample_plots -- [OUT_DIR]   # default docs/samplers
//! ```

use std::path::{Path, PathBuf};

use glam::Vec2;
use image::{Rgb, RgbImage};
use obscura_sample::{Sampler, SamplerKind, square_to_concentric_disk};

/// Plot size in pixels, and the number of samples plotted.
const SIZE: u32 = 256;
const SAMPLES: u32 = 256;
/// The pixel whose samples are plotted, and the seed.
const PIXEL: [u32; 2] = [7, 3];
const SEED: u64 = 0;

const BACKGROUND: Rgb<u8> = Rgb([255, 255, 255]);
const GRID: Rgb<u8> = Rgb([222, 226, 235]);
const FRAME: Rgb<u8> = Rgb([150, 150, 160]);
const DOT: Rgb<u8> = Rgb([25, 30, 60]);

/// A blank plot of the unit square with a light `cells x cells` grid.
fn canvas(cells: u32) -> RgbImage {
    let mut img = RgbImage::from_pixel(SIZE, SIZE, BACKGROUND);
    for k in 1..cells {
        let line = k * SIZE / cells;
        for t in 0..SIZE {
            img.put_pixel(line, t, GRID);
            img.put_pixel(t, line, GRID);
        }
    }
    for t in 0..SIZE {
        for (x, y) in [(0, t), (SIZE - 1, t), (t, 0), (t, SIZE - 1)] {
            img.put_pixel(x, y, FRAME);
        }
    }
    img
}

/// A 3x3 dot at `u` in `[0, 1)^2`, y up (row 0 of the image is the top, u.y = 1).
fn dot(img: &mut RgbImage, u: Vec2) {
    let cx = (u.x * SIZE as f32) as i64;
    let cy = ((1.0 - u.y) * SIZE as f32) as i64;
    for dy in -1..=1 {
        for dx in -1..=1 {
            let (x, y) = (cx + dx, cy + dy);
            if (0..SIZE as i64).contains(&x) && (0..SIZE as i64).contains(&y) {
                img.put_pixel(x as u32, y as u32, DOT);
            }
        }
    }
}

/// A plot of points in `[0, 1)^2` over a `cells x cells` grid.
fn scatter(points: impl IntoIterator<Item = Vec2>, cells: u32) -> RgbImage {
    let mut img = canvas(cells);
    for u in points {
        dot(&mut img, u);
    }
    img
}

/// A plot of points on the unit disk, with the circle drawn.
fn disk_scatter(points: impl IntoIterator<Item = Vec2>) -> RgbImage {
    let mut img = canvas(2);
    for k in 0..2048 {
        let angle = std::f32::consts::TAU * k as f32 / 2048.0;
        let on_circle = 0.5 * (Vec2::new(angle.cos(), angle.sin()) * 0.995 + Vec2::ONE);
        let x = (on_circle.x * SIZE as f32) as u32;
        let y = ((1.0 - on_circle.y) * SIZE as f32) as u32;
        img.put_pixel(x.min(SIZE - 1), y.min(SIZE - 1), FRAME);
    }
    for p_disk in points {
        dot(&mut img, 0.5 * (p_disk + Vec2::ONE));
    }
    img
}

/// The naive stratified sampler the shipped one avoids: the lens uses the film's stratum
/// (same cell index for both pairs), with its own jitter. Jitter comes from the shipped
/// independent sampler so this stays a few lines.
fn correlated_film_and_lens(index: u32) -> (Vec2, Vec2) {
    let jitter = Sampler::new(SamplerKind::Independent, SAMPLES, SEED).expect("valid sampler");
    let j = |d| jitter.value(PIXEL, index, d);
    let cell = Vec2::new((index % 16) as f32, (index / 16) as f32);
    let film = (cell + Vec2::new(j(0), j(1))) / 16.0;
    let lens = (cell + Vec2::new(j(2), j(3))) / 16.0;
    (film, lens)
}

fn save(img: &RgbImage, dir: &Path, name: &str) -> Result<(), Box<dyn std::error::Error>> {
    let path = dir.join(name);
    img.save(&path)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    println!("wrote {}", path.display());
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .map_or_else(|| PathBuf::from("docs/samplers"), PathBuf::from);
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;

    for kind in SamplerKind::ALL {
        let sampler = Sampler::new(kind, SAMPLES, SEED)?;
        let pair = |index, first| {
            Vec2::new(
                sampler.value(PIXEL, index, first),
                sampler.value(PIXEL, index, first + 1),
            )
        };
        let film: Vec<Vec2> = (0..SAMPLES).map(|i| pair(i, 0)).collect();
        let lens: Vec<Vec2> = (0..SAMPLES).map(|i| pair(i, 2)).collect();
        let name = kind.name();
        save(
            &scatter(film.iter().copied(), 16),
            &dir,
            &format!("{name}_film.png"),
        )?;
        save(
            &scatter(lens.iter().copied(), 16),
            &dir,
            &format!("{name}_lens.png"),
        )?;
        save(
            &disk_scatter(lens.iter().map(|&u| square_to_concentric_disk(u))),
            &dir,
            &format!("{name}_lens_disk.png"),
        )?;
        let film_x_lens_x = film.iter().zip(&lens).map(|(f, l)| Vec2::new(f.x, l.x));
        save(
            &scatter(film_x_lens_x, 16),
            &dir,
            &format!("{name}_film_x_vs_lens_x.png"),
        )?;
    }

    let correlated: Vec<(Vec2, Vec2)> = (0..SAMPLES).map(correlated_film_and_lens).collect();
    save(
        &scatter(correlated.iter().map(|(f, l)| Vec2::new(f.x, l.x)), 16),
        &dir,
        "correlated_film_x_vs_lens_x.png",
    )?;
    Ok(())
}
