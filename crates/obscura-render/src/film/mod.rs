//! The film: reconstruction filters, per-tile accumulation and the final pixel values.
//!
//! Every sample is splatted into each pixel whose filter support holds it, with the filter's
//! weight. A pixel's value is the weighted mean of its samples' radiance (misses count as 0),
//! and its alpha the weighted fraction of samples whose camera ray hit geometry.
//!
//! Tiles accumulate into their own buffers (their pixels plus a margin as wide as the filter)
//! and are merged into the film in tile order, so the sums, and the image, are bit-identical
//! whatever the number of threads or the order tiles finish in.

mod filter;
mod tile;

pub use filter::Filter;
pub use tile::TileBuffer;

use rayon::prelude::*;

/// The running sums of one pixel. f64, so that long renders and resumed renders add exactly.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelSums {
    /// Sum of weight times radiance.
    pub radiance: [f64; 3],
    /// Sum of weights.
    pub weight: f64,
    /// Sum of weights of samples whose camera ray hit geometry.
    pub coverage: f64,
}

impl PixelSums {
    fn add(&mut self, o: &PixelSums) {
        for c in 0..3 {
            self.radiance[c] += o.radiance[c];
        }
        self.weight += o.weight;
        self.coverage += o.coverage;
    }

    /// The pixel's value: weighted mean radiance and coverage, (0, 0, 0, 0) with no weight.
    pub fn resolve(&self) -> [f32; 4] {
        if self.weight == 0.0 {
            return [0.0; 4];
        }
        let inv = 1.0 / self.weight;
        [
            (self.radiance[0] * inv) as f32,
            (self.radiance[1] * inv) as f32,
            (self.radiance[2] * inv) as f32,
            (self.coverage * inv) as f32,
        ]
    }
}

/// A rectangle of pixels `[x0, x1) x [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl PixelRect {
    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }
    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }
    /// Number of pixels.
    pub fn area(&self) -> u64 {
        u64::from(self.width()) * u64::from(self.height())
    }
}

/// The whole film's sums over its pixel bounds (the crop window).
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    bounds: PixelRect,
    sums: Vec<PixelSums>,
}

impl Film {
    /// A zeroed film covering `bounds`.
    pub fn new(bounds: PixelRect) -> Self {
        Self {
            bounds,
            sums: vec![PixelSums::default(); bounds.area() as usize],
        }
    }

    /// The pixels this film covers.
    pub fn bounds(&self) -> PixelRect {
        self.bounds
    }

    /// The sums, row by row over [`Film::bounds`].
    pub fn sums(&self) -> &[PixelSums] {
        &self.sums
    }

    /// A film from saved sums (a checkpoint); `None` if the count does not match.
    pub fn from_sums(bounds: PixelRect, sums: Vec<PixelSums>) -> Option<Self> {
        (sums.len() as u64 == bounds.area()).then_some(Self { bounds, sums })
    }

    /// Adds a tile's sums. Merge tiles in a fixed order for bit-identical results.
    pub fn merge(&mut self, tile: &TileBuffer) {
        let t = tile.rect;
        let (width, film_width) = (t.width() as usize, self.bounds.width() as usize);
        if width == 0 {
            return;
        }
        // Row by row: one slice of each per row, no index arithmetic per pixel.
        let first =
            (t.y0 - self.bounds.y0) as usize * film_width + (t.x0 - self.bounds.x0) as usize;
        for (j, src_row) in tile.sums.chunks_exact(width).enumerate() {
            let start = first + j * film_width;
            for (d, src) in self.sums[start..start + width].iter_mut().zip(src_row) {
                let [r, g, b, w] = src.weighted.to_array().map(f64::from);
                d.radiance[0] += r;
                d.radiance[1] += g;
                d.radiance[2] += b;
                d.weight += w;
                d.coverage += f64::from(src.coverage);
            }
        }
    }

    /// Adds `other`'s sums pixel by pixel (films of the same bounds). Each pixel gets one
    /// addition, so the result does not depend on how the work is split between threads.
    pub fn add(&mut self, other: &Film) {
        debug_assert_eq!(self.bounds, other.bounds);
        self.sums
            .par_chunks_mut(4096)
            .zip(other.sums.par_chunks(4096))
            .for_each(|(a, b)| a.iter_mut().zip(b).for_each(|(a, b)| a.add(b)));
    }

    /// Sets every sum back to zero.
    pub fn clear(&mut self) {
        self.sums
            .par_chunks_mut(4096)
            .for_each(|a| a.fill(PixelSums::default()));
    }

    /// The image: RGBA per pixel, row 0 at the top.
    pub fn resolve(&self) -> Image {
        Image {
            width: self.bounds.width(),
            height: self.bounds.height(),
            pixels: self.sums.iter().map(PixelSums::resolve).collect(),
        }
    }
}

/// A finished image of linear RGBA floats, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` RGBA values.
    pub pixels: Vec<[f32; 4]>,
}

impl Image {
    /// The pixel at column `x`, row `y`.
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 4] {
        self.pixels[(y * self.width + x) as usize]
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::scene::FilterSettings;
    use glam::{Vec2, Vec3};

    /// The film rectangle `[0, w) x [0, h)`.
    pub(crate) fn film_rect(w: u32, h: u32) -> PixelRect {
        PixelRect {
            x0: 0,
            y0: 0,
            x1: w,
            y1: h,
        }
    }

    #[test]
    fn pixel_value_is_the_weighted_mean_and_alpha_the_coverage() {
        // Two samples in pixel (0, 0) with the box filter: radiance 1 (hit) and 0 (miss).
        let filter = Filter::new(FilterSettings::Box { radius: 0.5 });
        let mut tile = TileBuffer::new(film_rect(1, 1), film_rect(1, 1), filter);
        tile.add_sample(Vec2::new(0.25, 0.25), Vec3::new(1.0, 2.0, 3.0), true);
        tile.add_sample(Vec2::new(0.75, 0.75), Vec3::ZERO, false);
        let mut film = Film::new(film_rect(1, 1));
        film.merge(&tile);
        assert_eq!(film.resolve().pixel(0, 0), [0.5, 1.0, 1.5, 0.5]);
    }
}
