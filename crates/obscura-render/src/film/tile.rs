//! Per-tile accumulation: a tile's samples splatted into its pixels and a filter-wide margin.

use super::PixelRect;
use super::filter::{Filter, SPAN};
use glam::{Vec2, Vec3, Vec4};

/// One tile's sums: the tile's pixels and the margin its samples reach ([`Filter::margin`]),
/// clipped to the film.
///
/// A tile holds one pass, so each of its pixels sums at most the few samples its filter
/// reaches (nine for the default Gaussian): f32 is exact enough there (relative error about
/// 1e-6), and it lets a splat be one four-lane multiply-add. The film sums passes in f64.
pub struct TileBuffer {
    pub(super) rect: PixelRect,
    filter: Filter,
    pub(super) sums: Vec<TileSums>,
}

/// A tile pixel's sums: `(w r, w g, w b, w)` and the weight of samples that hit geometry.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct TileSums {
    pub(super) weighted: Vec4,
    pub(super) coverage: f32,
}

impl TileBuffer {
    /// A zeroed buffer for samples of the pixels in `tile`, on a film covering `film`.
    pub fn new(tile: PixelRect, film: PixelRect, filter: Filter) -> Self {
        let mut buffer = Self {
            rect: tile,
            filter,
            sums: Vec::new(),
        };
        buffer.reset(tile, film);
        buffer
    }

    /// Makes this buffer a zeroed one for `tile`, as [`TileBuffer::new`] would, keeping its
    /// memory (the renderer recycles buffers instead of allocating one per tile and pass).
    pub fn reset(&mut self, tile: PixelRect, film: PixelRect) {
        let m = self.filter.margin();
        self.rect = PixelRect {
            x0: tile.x0.saturating_sub(m).max(film.x0),
            y0: tile.y0.saturating_sub(m).max(film.y0),
            x1: (tile.x1 + m).min(film.x1),
            y1: (tile.y1 + m).min(film.y1),
        };
        self.sums.clear();
        self.sums
            .resize(self.rect.area() as usize, TileSums::default());
    }

    /// Adds a sample at raster position `p` with radiance `l` into every pixel the filter
    /// reaches. `hit` says whether its camera ray hit geometry. `l` must be finite (the
    /// renderer counts and drops other samples before they get here): a NaN would reach every
    /// pixel of the footprint, zero-weight ones included.
    pub fn add_sample(&mut self, p: Vec2, l: Vec3, hit: bool) {
        let r = self.filter.radius();
        // Pixels whose centre i + 0.5 lies in (p - r, p + r].
        let lo = (floor(p - Vec2::splat(r + 0.5)) + Vec2::ONE)
            .max(Vec2::new(self.rect.x0 as f32, self.rect.y0 as f32));
        let hi = floor(p + Vec2::splat(r - 0.5)).min(Vec2::new(
            self.rect.x1 as f32 - 1.0,
            self.rect.y1 as f32 - 1.0,
        ));
        if lo.x > hi.x || lo.y > hi.y {
            return;
        }
        let (l, coverage) = (l.extend(1.0), if hit { 1.0 } else { 0.0 });
        let (x0, x1) = (lo.x as u32, hi.x as u32);
        let (y0, y1) = (lo.y as u32, hi.y as u32);
        // The profile is separable: evaluate each column's and each row's weight once (for
        // footprints up to SPAN wide, which covers every filter at its default radius).
        let (nx, ny) = ((x1 - x0) as usize + 1, (y1 - y0) as usize + 1);
        if nx > SPAN || ny > SPAN {
            return self.add_sample_wide(p, l, coverage, [x0, x1], [y0, y1]);
        }
        let wx = self.filter.weights(p.x, x0, nx);
        let wy = self.filter.weights(p.y, y0, ny);
        let width = self.rect.width() as usize;
        let first = (y0 - self.rect.y0) as usize * width + (x0 - self.rect.x0) as usize;
        for (j, &w_row) in wy[..ny].iter().enumerate() {
            if w_row == 0.0 {
                continue;
            }
            let row = first + j * width;
            // No test for a zero weight: l is finite (the renderer drops other samples), so
            // such a pixel gains a signed zero, and sums that start at +0 keep their bits.
            for (s, &w_col) in self.sums[row..row + nx].iter_mut().zip(&wx) {
                let w = w_row * w_col;
                s.weighted += l * w;
                s.coverage += w * coverage;
            }
        }
    }

    /// [`TileBuffer::add_sample`] for footprints wider than its fixed weight arrays (filters
    /// given a large radius).
    fn add_sample_wide(&mut self, p: Vec2, l: Vec4, coverage: f32, xs: [u32; 2], ys: [u32; 2]) {
        for y in ys[0]..=ys[1] {
            let wy = self.filter.eval_1d(p.y - (y as f32 + 0.5));
            if wy == 0.0 {
                continue;
            }
            for x in xs[0]..=xs[1] {
                let w = wy * self.filter.eval_1d(p.x - (x as f32 + 0.5));
                if w == 0.0 {
                    continue;
                }
                let i = ((y - self.rect.y0) * self.rect.width() + (x - self.rect.x0)) as usize;
                let s = &mut self.sums[i];
                s.weighted += l * w;
                s.coverage += w * coverage;
            }
        }
    }
}

/// `v.floor()` per lane without a libm call (x86-64's baseline has no rounding instruction):
/// exact for `|x| < 2^31`, which raster positions are.
#[inline]
fn floor(v: Vec2) -> Vec2 {
    let f = |x: f32| {
        let t = x as i32 as f32;
        if t > x { t - 1.0 } else { t }
    };
    Vec2::new(f(v.x), f(v.y))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::tests::film_rect;
    use crate::film::{Film, to_fixed};
    use crate::scene::FilterSettings;

    #[test]
    fn box_filter_puts_each_sample_in_exactly_one_pixel() {
        let filter = Filter::new(FilterSettings::Box { radius: 0.5 });
        let mut tile = TileBuffer::new(film_rect(4, 4), film_rect(4, 4), filter);
        // On the boundary between pixels 1 and 2 (x = 2.0): it belongs to pixel 2 only.
        tile.add_sample(Vec2::new(2.0, 1.5), Vec3::ONE, true);
        let mut film = Film::new(film_rect(4, 4));
        film.merge(&tile);
        let touched: Vec<(usize, i128)> = film
            .sums()
            .iter()
            .enumerate()
            .filter(|(_, s)| s.weight > 0)
            .map(|(i, s)| (i, s.weight))
            .collect();
        // Weight 1 in fixed point: 2^64.
        assert_eq!(touched, vec![(4 + 2, 1i128 << 64)]);
    }

    #[test]
    fn wide_filters_reach_neighbouring_tiles_through_the_margin() {
        let filter = Filter::new(FilterSettings::gaussian(1.5));
        let film_r = film_rect(8, 8);
        let mut tile = TileBuffer::new(
            PixelRect {
                x0: 4,
                y0: 4,
                x1: 8,
                y1: 8,
            },
            film_r,
            filter,
        );
        tile.add_sample(Vec2::new(4.1, 4.1), Vec3::ONE, true);
        let mut film = Film::new(film_r);
        film.merge(&tile);
        // Pixel (3, 3), centre (3.5, 3.5), is 0.6 away on each axis: inside the radius.
        assert!(film.sums()[3 * 8 + 3].weight > 0);
        // Pixel (2, 2), centre (2.5, 2.5), is 1.6 away: outside.
        assert_eq!(film.sums()[2 * 8 + 2].weight, 0);
    }

    #[test]
    fn floor_matches_the_library_floor() {
        for x in [
            -3.0f32,
            -2.5,
            -1.0,
            -0.75,
            -0.0,
            0.0,
            0.25,
            1.0,
            1.999_999,
            2.0,
            1e6 + 0.5,
        ] {
            let got = floor(Vec2::new(x, -x));
            assert_eq!(got, Vec2::new(x.floor(), (-x).floor()), "{x}");
        }
    }

    proptest::proptest! {
        /// A tile's buffer holds every pixel its samples give a weight to: a sample splatted
        /// into the tile's buffer and into one covering the whole film gives the same film,
        /// for samples on the tile's edges, including one whose position rounds onto the far
        /// edge (far from the origin, where `pixel + offset` rounds up to the next pixel).
        #[test]
        fn the_margin_keeps_every_weight_of_a_tile_sample(
            kind in 0usize..4,
            radius in proptest::sample::select(
                vec![0.25f32, 0.5, 0.75, 1.0, 1.5, 2.0, 2.5, 3.0, 5.3]
            ),
            far in proptest::bool::ANY,
            pixel in (0u32..16, 0u32..16),
            place in (0usize..3, 0usize..5, 0usize..3, 0usize..5),
            offset in (0.0f32..1.0, 0.0f32..1.0),
        ) {
            let settings = match kind {
                0 => FilterSettings::Box { radius },
                1 => FilterSettings::Triangle { radius },
                2 => FilterSettings::gaussian(radius),
                _ => FilterSettings::Mitchell { radius },
            };
            let filter = Filter::new(settings);
            // At 2^20 an f32 steps by 2^-3, so offsets of 15/16 and more round up.
            let origin = if far { 1u32 << 20 } else { 8 };
            let square = |start: u32, size: u32| PixelRect {
                x0: start,
                y0: start,
                x1: start + size,
                y1: start + size,
            };
            let (film_r, tile_r) = (square(origin - 8, 32), square(origin, 16));
            // Each axis: the first or last pixel of the tile, or a random one; an offset of 0,
            // the largest below 1, one just above 0, one half, or a random one.
            let offsets = [0.0, 1.0 - f32::EPSILON / 2.0, 1e-7, 0.5];
            let coordinate = |which: usize, random_pixel: u32, at: usize, random: f32| {
                let pixel = [0, 15, random_pixel][which];
                (origin + pixel) as f32 + offsets.get(at).copied().unwrap_or(random)
            };
            let p = Vec2::new(
                coordinate(place.0, pixel.0, place.1, offset.0),
                coordinate(place.2, pixel.1, place.3, offset.1),
            );
            let mut films = [Film::new(film_r), Film::new(film_r)];
            for (film, rect) in films.iter_mut().zip([tile_r, film_r]) {
                let mut buffer = TileBuffer::new(rect, film_r, filter);
                buffer.add_sample(p, Vec3::new(1.0, 2.0, 3.0), true);
                film.merge(&buffer);
            }
            proptest::prop_assert!(films[0] == films[1], "{:?} at {:?}", settings, p);
        }
    }

    #[test]
    fn margins_by_hand() {
        let margin = |settings| Filter::new(settings).margin();
        // A centre 0.5 beyond the edge is reached by a box of radius 0.5 (at exactly -r).
        assert_eq!(margin(FilterSettings::Box { radius: 0.5 }), 1);
        assert_eq!(margin(FilterSettings::Box { radius: 0.25 }), 0);
        assert_eq!(margin(FilterSettings::Box { radius: 1.5 }), 2);
        // The Gaussian of radius 1.5 is zero 1.5 from a centre: the second ring gets nothing.
        assert_eq!(margin(FilterSettings::gaussian(1.5)), 1);
        assert_eq!(margin(FilterSettings::Triangle { radius: 1.0 }), 1);
        assert_eq!(margin(FilterSettings::Mitchell { radius: 2.0 }), 2);
        assert_eq!(margin(FilterSettings::Triangle { radius: 5.3 }), 5);
    }

    /// Every pixel gets exactly the separable weight `f(dx) f(dy)` of the sample, for a
    /// footprint within the fixed weight arrays and for one wider than them.
    #[test]
    fn splat_weights_are_the_filter_product_narrow_and_wide() {
        for settings in [
            FilterSettings::gaussian(1.5),
            FilterSettings::Triangle { radius: 5.3 },
        ] {
            let filter = Filter::new(settings);
            let film_r = film_rect(24, 24);
            let mut tile = TileBuffer::new(film_r, film_r, filter);
            let p = Vec2::new(11.3, 12.8);
            tile.add_sample(p, Vec3::new(2.0, 0.0, 0.0), true);
            let mut film = Film::new(film_r);
            film.merge(&tile);
            let mut touched = 0;
            for y in 0..24u32 {
                for x in 0..24u32 {
                    let want = filter.eval_1d(p.x - (x as f32 + 0.5))
                        * filter.eval_1d(p.y - (y as f32 + 0.5));
                    let s = film.sums()[(y * 24 + x) as usize];
                    assert_eq!(s.weight, to_fixed(want), "{settings:?} at ({x}, {y})");
                    assert_eq!(s.radiance[0], to_fixed(want * 2.0));
                    touched += usize::from(want != 0.0);
                }
            }
            assert!(touched >= 9, "{settings:?}: {touched} pixels");
        }
    }
}
