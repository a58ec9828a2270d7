//! A stereo pair's two images laid out as one: side by side, or a red-cyan anaglyph.

use crate::film::Image;
use crate::scene::StereoLayout;

/// The left and right eyes' images (same size) as one image: `SideBySide` is twice as wide,
/// left eye on the left; `Anaglyph` is a half-colour red-cyan anaglyph (red = the left eye's
/// luminance, green and blue = the right eye's), alpha the mean of the two coverages.
/// `Separate` has no single image: None.
pub fn compose_stereo(left: &Image, right: &Image, layout: StereoLayout) -> Option<Image> {
    match layout {
        StereoLayout::Separate => None,
        StereoLayout::SideBySide => {
            let (w, h) = (left.width, left.height);
            let mut pixels = Vec::with_capacity(2 * left.pixels.len());
            for y in 0..h {
                let row = (y * w) as usize..((y + 1) * w) as usize;
                pixels.extend_from_slice(&left.pixels[row.clone()]);
                pixels.extend_from_slice(&right.pixels[row]);
            }
            Some(Image {
                width: 2 * w,
                height: h,
                pixels,
            })
        }
        StereoLayout::Anaglyph => {
            let pixels = left
                .pixels
                .iter()
                .zip(&right.pixels)
                .map(|(l, r)| {
                    // Red is the left eye's luminance, so that red-filtered viewing sees the
                    // left image in full, not only its red.
                    let luminance = obscura_shade::luminance(glam::Vec3::new(l[0], l[1], l[2]));
                    [luminance, r[1], r[2], 0.5 * (l[3] + r[3])]
                })
                .collect();
            Some(Image {
                width: left.width,
                height: left.height,
                pixels,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> [f32; 4]) -> Image {
        Image {
            width: w,
            height: h,
            pixels: (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| f(x, y))
                .collect(),
        }
    }

    #[test]
    fn side_by_side_puts_the_left_eye_on_the_left() {
        let left = image(3, 2, |x, y| [x as f32, y as f32, 0.0, 1.0]);
        let right = image(3, 2, |x, y| [x as f32, y as f32, 1.0, 1.0]);
        let both = compose_stereo(&left, &right, StereoLayout::SideBySide).unwrap();
        assert_eq!((both.width, both.height), (6, 2));
        assert_eq!(both.pixel(1, 1), [1.0, 1.0, 0.0, 1.0]);
        assert_eq!(both.pixel(4, 1), [1.0, 1.0, 1.0, 1.0]);
    }

    #[test]
    fn anaglyph_takes_red_from_the_left_luminance_and_cyan_from_the_right() {
        let left = image(1, 1, |_, _| [1.0, 0.0, 0.0, 1.0]);
        let right = image(1, 1, |_, _| [0.3, 0.4, 0.5, 0.0]);
        let a = compose_stereo(&left, &right, StereoLayout::Anaglyph).unwrap();
        assert_eq!(a.pixel(0, 0), [0.2126, 0.4, 0.5, 0.5]);
        assert!(compose_stereo(&left, &right, StereoLayout::Separate).is_none());
    }
}
