//! The aperture: the shape a lens sample is warped onto, or that passes a lens system's rays.
//! One owner for every lens model (the thin lens, and the stop of a lens system): round, a
//! regular polygon of blades, or an image of weights, each optionally squeezed by an
//! anamorphic factor.

use crate::error::{CameraError, finite};
use glam::Vec2;
use obscura_sample::Distribution2D;
use std::sync::Arc;

/// The most aperture blades a polygonal aperture takes (more is indistinguishable from round).
pub const MAX_BLADES: u32 = 64;

/// An aperture given as an image: non-negative weights on a `width x height` grid (row 0 at
/// the top), sampled in proportion to their brightness by a piecewise-constant 2D
/// distribution (marginal over rows, conditional over columns). The image covers the square
/// `[-1, 1]^2` of the unit aperture (so its inscribed circle is the lens radius), image right
/// along camera +x and image up along camera +y.
///
/// The camera crate does no image I/O: a renderer decodes the file into weights (Obscura's
/// takes the luminance of a PNG).
#[derive(Debug, Clone, PartialEq)]
pub struct ApertureImage {
    width: usize,
    height: usize,
    distribution: Distribution2D,
    /// The distribution's density at the brightest texel: [`ApertureImage::transmission`]'s 1.
    peak: f32,
}

impl ApertureImage {
    /// An aperture from row-major weights (`weights[y * width + x]`). Errors unless the grid
    /// is non-empty, `weights.len() == width * height`, every weight is finite and `>= 0`, and
    /// at least one is positive.
    pub fn new(weights: &[f32], width: usize, height: usize) -> Result<ApertureImage, CameraError> {
        let bad = |reason: String| Err(CameraError::ApertureImage { reason });
        if width == 0 || height == 0 || width.checked_mul(height) != Some(weights.len()) {
            return bad(format!(
                "{} weights do not fill a {width} x {height} grid",
                weights.len()
            ));
        }
        if let Some(w) = weights.iter().find(|w| !(w.is_finite() && **w >= 0.0)) {
            return bad(format!("weights must be finite and >= 0, got {w}"));
        }
        if !weights.iter().any(|&w| w > 0.0) {
            return bad("the image is black: no light passes the aperture".to_string());
        }
        let distribution = Distribution2D::new(weights, width, height);
        let brightest = (0..weights.len())
            .max_by(|&a, &b| weights[a].total_cmp(&weights[b]))
            .unwrap_or(0);
        let centre = Vec2::new(
            ((brightest % width) as f32 + 0.5) / width as f32,
            ((brightest / width) as f32 + 0.5) / height as f32,
        );
        let peak = distribution.pdf(centre);
        Ok(ApertureImage {
            width,
            height,
            distribution,
            peak,
        })
    }

    /// Width and height of the grid.
    pub fn size(&self) -> [usize; 2] {
        [self.width, self.height]
    }

    /// A point of `[-1, 1]^2` drawn in proportion to the weights, from `u` in `[0, 1)^2`. Out
    /// of line: it is large, and inlined it would crowd the round and polygonal apertures'
    /// per-ray path.
    #[inline(never)]
    fn sample(&self, u: Vec2) -> Vec2 {
        let (uv, _) = self.distribution.sample(u);
        // Image x right -> +x; image row 0 (v = 0) is the top -> +y.
        Vec2::new(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y)
    }

    /// The density of [`ApertureImage::sample`] with respect to area on `[-1, 1]^2`.
    fn pdf(&self, p: Vec2) -> f32 {
        if p.x.abs() > 1.0 || p.y.abs() > 1.0 {
            return 0.0;
        }
        let uv = Vec2::new(0.5 * (p.x + 1.0), 0.5 * (1.0 - p.y));
        // The map from [0, 1)^2 onto [-1, 1]^2 stretches area by 4.
        0.25 * self
            .distribution
            .pdf(uv.min(Vec2::splat(obscura_sample::ONE_MINUS_EPSILON)))
    }
}

impl ApertureImage {
    /// The weight at `p` of `[-1, 1]^2` relative to the brightest, from 0 to 1 (0 outside).
    fn transmission(&self, p: Vec2) -> f32 {
        (4.0 * self.pdf(p) / self.peak).min(1.0)
    }
}

/// The outline of an aperture before the anamorphic squeeze.
#[derive(Debug, Clone, PartialEq)]
pub enum ApertureShape {
    /// Round: the unit disk (Shirley and Chiu's concentric map).
    Circle,
    /// A regular polygon inscribed in the unit circle, vertex 0 at `rotation_degrees`
    /// counter-clockwise from camera +x: the opening of a lens with straight blades.
    Polygon {
        /// Number of blades, 3 to [`MAX_BLADES`].
        blades: u32,
        /// Rotation in degrees, counter-clockwise from camera +x.
        rotation_degrees: f32,
    },
    /// An image of weights over `[-1, 1]^2`, shared (it can be large).
    Image(Arc<ApertureImage>),
}

/// The shape of a lens's opening in units of its radius, which a lens sample in `[0, 1)^2` is
/// warped onto: [`Aperture::sample`] gives a point of the unit aperture, and a lens model
/// scales it by its radius. Plain data, so any lens model can hold one.
///
/// The anamorphic squeeze `s` divides the aperture's x by `s` (camera +x, the image's
/// horizontal): an anamorphic lens squeezes the horizontal field onto the film by `s`, and the
/// de-squeezed picture shows its out-of-focus highlights as ovals `s` times taller than wide.
/// Here the picture is what the film records, so the opening itself is made that oval: a
/// round aperture becomes the ellipse with semi-axes `1/s` (x) and `1` (y).
#[derive(Debug, Clone, PartialEq)]
pub struct Aperture {
    /// The outline.
    pub shape: ApertureShape,
    /// The anamorphic squeeze, `>= 1` (1: none).
    pub anamorphic: f32,
}

impl Aperture {
    /// The round aperture without a squeeze.
    pub const CIRCLE: Aperture = Aperture {
        shape: ApertureShape::Circle,
        anamorphic: 1.0,
    };

    /// A regular polygon of `blades` blades (0 for round) rotated by `rotation_degrees`.
    /// Errors as [`Aperture::validate`].
    pub fn polygon(blades: u32, rotation_degrees: f32) -> Result<Aperture, CameraError> {
        let aperture = Aperture {
            shape: if blades == 0 {
                ApertureShape::Circle
            } else {
                ApertureShape::Polygon {
                    blades,
                    rotation_degrees,
                }
            },
            anamorphic: 1.0,
        };
        finite("aperture_rotation", rotation_degrees)?;
        aperture.validate()?;
        Ok(aperture)
    }

    /// An aperture of an image of weights.
    pub fn image(image: ApertureImage) -> Aperture {
        Aperture {
            shape: ApertureShape::Image(Arc::new(image)),
            anamorphic: 1.0,
        }
    }

    /// The same aperture squeezed by `anamorphic` (see [`Aperture`]). Errors as
    /// [`Aperture::validate`].
    pub fn with_anamorphic(self, anamorphic: f32) -> Result<Aperture, CameraError> {
        let aperture = Aperture { anamorphic, ..self };
        aperture.validate()?;
        Ok(aperture)
    }

    /// Checks the parameters: blades 3 to [`MAX_BLADES`], a finite rotation, a finite
    /// squeeze `>= 1`.
    pub fn validate(&self) -> Result<(), CameraError> {
        if let ApertureShape::Polygon {
            blades,
            rotation_degrees,
        } = self.shape
        {
            finite("aperture_rotation", rotation_degrees)?;
            if !(3..=MAX_BLADES).contains(&blades) {
                return Err(CameraError::Blades { got: blades });
            }
        }
        finite("anamorphic", self.anamorphic)?;
        if self.anamorphic < 1.0 {
            return Err(CameraError::Anamorphic {
                got: self.anamorphic,
            });
        }
        Ok(())
    }

    /// Number of blades: 0 unless the aperture is a polygon.
    pub fn blades(&self) -> u32 {
        match self.shape {
            ApertureShape::Polygon { blades, .. } => blades,
            _ => 0,
        }
    }

    /// The point of the unit aperture (camera space, plane z = 0, in units of the lens
    /// radius) of a lens sample `u` in `[0, 1)^2`, uniform over the outline's area (in
    /// proportion to the weights for an image), then squeezed.
    #[inline(always)]
    pub fn sample(&self, u: Vec2) -> Vec2 {
        let p = match &self.shape {
            ApertureShape::Circle => obscura_sample::square_to_concentric_disk(u),
            ApertureShape::Polygon {
                blades,
                rotation_degrees,
            } => obscura_sample::square_to_polygon(u, *blades, *rotation_degrees),
            ApertureShape::Image(image) => image.sample(u),
        };
        if self.anamorphic == 1.0 {
            p
        } else {
            Vec2::new(p.x / self.anamorphic, p.y)
        }
    }

    /// The density of [`Aperture::sample`] at `p` with respect to area on the plane of the
    /// unit aperture.
    pub fn pdf(&self, p: Vec2) -> f32 {
        // Undo the squeeze: x was divided by s, so densities grow by s.
        let s = self.anamorphic;
        let q = Vec2::new(p.x * s, p.y);
        let unsqueezed = match &self.shape {
            ApertureShape::Circle if q.length_squared() <= 1.0 => {
                obscura_sample::concentric_disk_pdf()
            }
            ApertureShape::Circle => 0.0,
            ApertureShape::Polygon {
                blades,
                rotation_degrees,
            } if inside_polygon(q, *blades, *rotation_degrees) => {
                obscura_sample::polygon_pdf(*blades)
            }
            ApertureShape::Polygon { .. } => 0.0,
            ApertureShape::Image(image) => image.pdf(q),
        };
        unsqueezed * s
    }
}

impl Aperture {
    /// How much light the unit aperture passes at `p` (the plane of [`Aperture::sample`], in
    /// units of the radius, after the squeeze), from 0 to 1: 1 inside a round or polygonal
    /// outline and 0 outside it; an image's weight there relative to its brightest. A lens
    /// model whose rays cannot start on the aperture (a lens system's stop, reached through
    /// the rear elements) weights them by this instead of sampling it.
    pub fn transmission(&self, p: Vec2) -> f32 {
        let q = Vec2::new(p.x * self.anamorphic, p.y);
        let inside = match &self.shape {
            ApertureShape::Circle => q.length_squared() <= 1.0,
            ApertureShape::Polygon {
                blades,
                rotation_degrees,
            } => inside_polygon(q, *blades, *rotation_degrees),
            ApertureShape::Image(image) => return image.transmission(q),
        };
        if inside { 1.0 } else { 0.0 }
    }
}

/// True when `p` lies in the regular polygon of `blades` vertices on the unit circle, vertex 0
/// at `rotation_degrees`: its distance from the centre is at most the apothem `cos(pi / n)`
/// over the cosine of its angle from the nearest edge's midpoint direction.
fn inside_polygon(p: Vec2, blades: u32, rotation_degrees: f32) -> bool {
    let sector = std::f32::consts::TAU / blades as f32;
    let angle = (p.y.atan2(p.x) - rotation_degrees.to_radians()).rem_euclid(sector);
    let apothem = (0.5 * sector).cos();
    p.length() * (angle - 0.5 * sector).cos() <= apothem * (1.0 + 1e-6)
}

impl Default for Aperture {
    fn default() -> Self {
        Aperture::CIRCLE
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation() {
        assert!(Aperture::polygon(0, 0.0).is_ok());
        assert!(Aperture::polygon(2, 0.0).is_err());
        assert!(Aperture::polygon(MAX_BLADES + 1, 0.0).is_err());
        assert!(Aperture::polygon(6, f32::NAN).is_err());
        assert!(Aperture::CIRCLE.with_anamorphic(0.5).is_err());
        assert!(Aperture::CIRCLE.with_anamorphic(f32::INFINITY).is_err());
        assert!(Aperture::CIRCLE.with_anamorphic(1.33).is_ok());
        assert!(ApertureImage::new(&[1.0; 5], 2, 2).is_err());
        assert!(ApertureImage::new(&[0.0; 4], 2, 2).is_err());
        assert!(ApertureImage::new(&[1.0, -1.0, 0.0, 0.0], 2, 2).is_err());
        assert!(ApertureImage::new(&[1.0, f32::NAN, 0.0, 0.0], 2, 2).is_err());
        assert!(ApertureImage::new(&[], 0, 0).is_err());
    }

    #[test]
    fn image_hand_case() {
        // Only the top-right cell of a 2 x 2 image is lit: every sample lands in x > 0, y > 0,
        // and the centre of u maps to the cell's centre (0.5, 0.5).
        let image = ApertureImage::new(&[0.0, 1.0, 0.0, 0.0], 2, 2).unwrap();
        let aperture = Aperture::image(image);
        let p = aperture.sample(Vec2::splat(0.5));
        assert!((p - Vec2::new(0.5, 0.5)).length() < 1e-6, "{p}");
        // Density: all the mass on a cell of area 1: pdf 1 there, 0 elsewhere.
        assert!((aperture.pdf(Vec2::new(0.5, 0.5)) - 1.0).abs() < 1e-6);
        assert_eq!(aperture.pdf(Vec2::new(-0.5, 0.5)), 0.0);
    }

    #[test]
    fn squeeze_hand_case() {
        // u = (1, 0.5) is the disk's rightmost point (1, 0); squeezed by 2 it is (0.5, 0).
        let squeezed = Aperture::CIRCLE.with_anamorphic(2.0).unwrap();
        let p = squeezed.sample(Vec2::new(1.0, 0.5));
        assert!((p - Vec2::new(0.5, 0.0)).length() < 1e-6, "{p}");
        // The ellipse has area pi / 2, so the uniform density is 2 / pi.
        assert!((squeezed.pdf(Vec2::new(0.1, 0.1)) - 2.0 / std::f32::consts::PI).abs() < 1e-6);
    }
}
