//! Depth of field and motion blur as image post-processes (Potmesil and Chakravarty, 1981-83):
//! the approximation that Cook, Porter and Carpenter's distributed ray tracing replaced. It is
//! here so that the two can be compared on the same scene (the gallery does), not as a
//! recommended way to render.
//!
//! The inputs are a sharp pinhole image at shutter open and, per pixel, what the pixel-centre
//! ray sees: its camera-space depth and its screen-space velocity ([`screen_buffers`]). Both
//! blurs *scatter*: each source pixel spreads its colour over the pixels it would have reached
//! (a disc for defocus, a segment for motion), and each output pixel is the weighted mean of
//! what reached it. Known artefacts, all because one visible surface per pixel is all there is:
//!
//! - surfaces hidden behind a blurred foreground are never revealed (the true defocused edge is
//!   partly see-through; here it is an opaque smear of the foreground colour mixed with the
//!   colour in front of which it sits);
//! - a blurred background spreads over a sharp, in-focus foreground's edge (there is no depth
//!   test on the scatter), so a sharp object gets a halo of background colour;
//! - shadows, reflections and refractions of a moving object do not move: their pixels see a
//!   static floor or mirror, whose velocity is zero;
//! - where a moving object was at shutter open, the background it uncovers is unknown and has
//!   to be guessed from the still pixels around it.

use crate::RenderScene;
use crate::error::RenderError;
use crate::film::Image;
use glam::Vec2;
use obscura_camera::{AnyCamera, Camera, CameraSample};
use obscura_space::{Camera as CameraSpace, Point2, Point3, Raster};

/// How a depth maps to a circle of confusion: the projection, the lens and the film scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DepthOfField {
    /// The camera-space depth `f` of the plane in focus (> 0).
    pub focal_distance: f32,
    /// The lens radius `r` in world units (>= 0).
    pub lens_radius: f32,
    /// Raster pixels per camera-space unit on the plane `z = 1` (perspective) or on any plane
    /// (orthographic). For a perspective camera this is `s * width / (x_max - x_min)` with `s`
    /// the fov scale and `[x_min, x_max]` the screen window.
    pub pixels_per_unit: f32,
    /// Whether the camera is orthographic (its image scale does not depend on depth).
    pub orthographic: bool,
}

impl DepthOfField {
    /// The parameters of a projective camera's own lens and film. Errors: any other camera
    /// (it has no thin lens).
    pub fn for_camera(camera: &AnyCamera) -> Result<DepthOfField, RenderError> {
        let (projective, orthographic) = match camera {
            AnyCamera::Perspective(c) => (c.projective(), false),
            AnyCamera::Orthographic(c) => (c.projective(), true),
            _ => {
                return Err(RenderError::Setting {
                    name: "camera",
                    message: "depth of field post-processing needs a perspective or \
                              orthographic camera"
                        .into(),
                });
            }
        };
        // Measure the raster scale on the plane z = 1: the image of a unit step in camera x.
        let raster_from_camera = projective.raster_from_camera();
        let p0 = raster_from_camera.point(Point3::<CameraSpace>::new(0.0, 0.0, 1.0));
        let p1 = raster_from_camera.point(Point3::<CameraSpace>::new(1.0, 0.0, 1.0));
        let lens = projective.lens();
        let params = DepthOfField {
            focal_distance: lens.focal_distance,
            lens_radius: lens.radius,
            pixels_per_unit: (p1.x - p0.x).abs(),
            orthographic,
        };
        params.validate()?;
        Ok(params)
    }

    /// Checks every parameter: `focal_distance > 0`, `lens_radius >= 0`, `pixels_per_unit > 0`,
    /// all finite.
    pub fn validate(&self) -> Result<(), RenderError> {
        let bad = |name: &'static str, what: &str, got: f32| {
            Err(RenderError::Setting {
                name,
                message: format!("must be {what}, got {got}"),
            })
        };
        if !(self.focal_distance > 0.0 && self.focal_distance.is_finite()) {
            return bad("focal_distance", "finite and > 0", self.focal_distance);
        }
        if !(self.lens_radius >= 0.0 && self.lens_radius.is_finite()) {
            return bad("lens_radius", "finite and >= 0", self.lens_radius);
        }
        if !(self.pixels_per_unit > 0.0 && self.pixels_per_unit.is_finite()) {
            return bad("pixels_per_unit", "finite and > 0", self.pixels_per_unit);
        }
        Ok(())
    }

    /// The circle of confusion, in raster pixels, of a point at camera-space depth `depth`
    /// (`f32::INFINITY` for the sky). Errors: invalid parameters or a depth that is not > 0.
    pub fn radius(&self, depth: f32) -> Result<f32, RenderError> {
        if self.orthographic {
            circle_of_confusion_orthographic(
                depth,
                self.focal_distance,
                self.lens_radius,
                self.pixels_per_unit,
            )
        } else {
            circle_of_confusion(
                depth,
                self.focal_distance,
                self.lens_radius,
                self.pixels_per_unit,
            )
        }
    }
}

fn check_depth(depth: f32) -> Result<(), RenderError> {
    // NaN and non-positive depths are errors; +infinity (the sky) is allowed.
    if depth.is_nan() || depth <= 0.0 {
        return Err(RenderError::Setting {
            name: "depth",
            message: format!("must be > 0, got {depth}"),
        });
    }
    Ok(())
}

/// The radius, in raster pixels, of the disc that a point at camera-space depth `depth` spreads
/// into through a perspective camera's thin lens: `r |1/z - 1/f| k`.
///
/// Derivation, with Obscura's thin lens (a lens point `L` on the plane `z = 0`, the film point's
/// pinhole ray through the lens centre meeting the focal plane `z = f` at `a f`, where `a` is the
/// film point's position on the plane `z = 1`): the sample ray `L + (a f - L) z / f` reaches the
/// point `P` at depth `z` when `a = P / z - L (1/z - 1/f)`. So as `L` covers the disc of radius
/// `r`, the film positions that see `P` cover a disc of radius `r |1/z - 1/f|` on the plane
/// `z = 1`, centred on the pinhole image `P / z`; `k` (`pixels_per_unit_at_z1`) turns that into
/// raster pixels. Zero at `z = f`, `r k / f` for the sky (`z = infinity`).
///
/// Errors (never NaN): `depth` not > 0, `focal_distance` not finite and > 0, `lens_radius` not
/// finite and >= 0, `pixels_per_unit_at_z1` not finite and > 0.
///
/// ```
/// // r = 0.1, f = 2, a point at z = 4, 100 pixels per unit at z = 1: 0.1 * |1/4 - 1/2| * 100.
/// let c = obscura_render::circle_of_confusion(4.0, 2.0, 0.1, 100.0)?;
/// assert!((c - 2.5).abs() < 1e-6);
/// // In focus: no blur at all.
/// assert_eq!(obscura_render::circle_of_confusion(2.0, 2.0, 0.1, 100.0)?, 0.0);
/// # Ok::<(), obscura_render::RenderError>(())
/// ```
pub fn circle_of_confusion(
    depth: f32,
    focal_distance: f32,
    lens_radius: f32,
    pixels_per_unit_at_z1: f32,
) -> Result<f32, RenderError> {
    DepthOfField {
        focal_distance,
        lens_radius,
        pixels_per_unit: pixels_per_unit_at_z1,
        orthographic: false,
    }
    .validate()?;
    check_depth(depth)?;
    Ok(lens_radius * (1.0 / depth - 1.0 / focal_distance).abs() * pixels_per_unit_at_z1)
}

/// The same for an orthographic camera's thin lens: `r |1 - z/f| k`, with `k` raster pixels
/// per world unit. (The pinhole ray is parallel to +z, so `a = P - L (1 - z/f)`.) Errors as for
/// [`circle_of_confusion`].
pub fn circle_of_confusion_orthographic(
    depth: f32,
    focal_distance: f32,
    lens_radius: f32,
    pixels_per_unit: f32,
) -> Result<f32, RenderError> {
    DepthOfField {
        focal_distance,
        lens_radius,
        pixels_per_unit,
        orthographic: true,
    }
    .validate()?;
    check_depth(depth)?;
    if depth.is_infinite() {
        return Err(RenderError::Setting {
            name: "depth",
            message: "an orthographic lens blurs infinitely far points without bound".into(),
        });
    }
    Ok(lens_radius * (1.0 - depth / focal_distance).abs() * pixels_per_unit)
}

fn check_buffer(image: &Image, len: usize, name: &'static str) -> Result<(), RenderError> {
    let want = image.width as usize * image.height as usize;
    if image.pixels.len() != want || len != want {
        return Err(RenderError::Setting {
            name,
            message: format!(
                "needs one value per pixel of the {}x{} image, got {} (image has {})",
                image.width,
                image.height,
                len,
                image.pixels.len()
            ),
        });
    }
    Ok(())
}

/// Accumulates weighted colours and divides by the total weight at the end.
struct Splat {
    width: u32,
    height: u32,
    sums: Vec<[f32; 5]>,
}

impl Splat {
    fn new(width: u32, height: u32) -> Self {
        Splat {
            width,
            height,
            sums: vec![[0.0; 5]; width as usize * height as usize],
        }
    }
    #[inline]
    fn add(&mut self, x: i64, y: i64, c: [f32; 4], w: f32) {
        if x < 0 || y < 0 || x >= i64::from(self.width) || y >= i64::from(self.height) || w <= 0.0 {
            return;
        }
        let s = &mut self.sums[y as usize * self.width as usize + x as usize];
        for k in 0..4 {
            s[k] += c[k] * w;
        }
        s[4] += w;
    }
    fn finish(self, fallback: &Image) -> Image {
        let pixels = self
            .sums
            .iter()
            .zip(&fallback.pixels)
            .map(|(s, &f)| {
                if s[4] > 0.0 {
                    [s[0] / s[4], s[1] / s[4], s[2] / s[4], s[3] / s[4]]
                } else {
                    f
                }
            })
            .collect();
        Image {
            width: self.width,
            height: self.height,
            pixels,
        }
    }
}

/// Post-process depth of field: every pixel of the sharp `image` is scattered as a uniform disc
/// of radius [`DepthOfField::radius`] of its `depth` (camera-space z of what the pixel-centre
/// ray sees, `f32::INFINITY` where it sees nothing), with an anti-aliased one-pixel rim. Each
/// disc carries total weight 1 (energy normalisation: a large disc is dimmer per pixel), and
/// each output pixel is the weighted mean of the discs that cover it. All four channels are
/// blurred alike (alpha is coverage).
///
/// Scatter, not gather, so a blurred foreground does spread over its surroundings. Its known
/// artefacts, since each pixel keeps one visible surface: nothing hidden is revealed, and a
/// blurred background bleeds over a sharp foreground. Cost: the sum of the discs' areas.
///
/// Errors: `depth` not one value per pixel, a depth that is not > 0 (NaN included), invalid
/// parameters.
pub fn depth_of_field(
    image: &Image,
    depth: &[f32],
    params: &DepthOfField,
) -> Result<Image, RenderError> {
    check_buffer(image, depth.len(), "depth")?;
    params.validate()?;
    let mut splat = Splat::new(image.width, image.height);
    for (i, (&c, &z)) in image.pixels.iter().zip(depth).enumerate() {
        let (x, y) = (
            (i % image.width as usize) as i64,
            (i / image.width as usize) as i64,
        );
        // A disc never smaller than the pixel itself, never larger than the image.
        let radius = params
            .radius(z)?
            .clamp(0.5, (image.width.max(image.height)) as f32);
        // Pixel weights: 1 inside radius - 0.5, falling linearly to 0 at radius + 0.5.
        let reach = (radius + 0.5).ceil() as i64;
        let mut total = 0.0;
        for dy in -reach..=reach {
            for dx in -reach..=reach {
                let d = ((dx * dx + dy * dy) as f32).sqrt();
                total += (radius + 0.5 - d).clamp(0.0, 1.0);
            }
        }
        for dy in -reach..=reach {
            for dx in -reach..=reach {
                let d = ((dx * dx + dy * dy) as f32).sqrt();
                let w = (radius + 0.5 - d).clamp(0.0, 1.0) / total;
                splat.add(x + dx, y + dy, c, w);
            }
        }
    }
    Ok(splat.finish(image))
}

/// Pixels moving less than this many raster pixels over the shutter count as still.
const STILL: f32 = 0.5;

/// Post-process motion blur, in two layers like a compositor's. The *moving layer*: every pixel
/// of the sharp `image` (taken at shutter open) whose screen-space `velocity` (raster pixels
/// moved over the shutter interval) is at least half a pixel is scattered along the segment from
/// its centre to its centre plus its velocity: a line integral sampled at least twice per pixel
/// of length, each sample splatted bilinearly, the segment's total weight 1. The *still layer*:
/// the other pixels as they are; where a moving pixel was, the background it hides is unknown and
/// is guessed from the nearest still pixel behind it (along minus its velocity, else ahead).
/// Each output pixel is the moving layer's sum plus the still layer times the weight the moving
/// layer left uncovered (`1 - a`, or the moving sum over `a` where `a > 1`).
///
/// Known artefacts, since each pixel keeps one visible surface: shadows and reflections of a
/// moving object stay sharp (their pixels see a still floor or mirror), the guessed background
/// behind a moving object is a stretched copy of its neighbours, and a moving object's own
/// shading (its highlights, its shadow on itself) moves with it instead of staying with the
/// light.
///
/// Errors: `velocity` not one value per pixel, or a velocity that is not finite.
pub fn motion_blur(image: &Image, velocity: &[Vec2]) -> Result<Image, RenderError> {
    check_buffer(image, velocity.len(), "velocity")?;
    if let Some(v) = velocity.iter().find(|v| !v.is_finite()) {
        return Err(RenderError::Setting {
            name: "velocity",
            message: format!("must be finite, got ({}, {})", v.x, v.y),
        });
    }
    let (width, height) = (image.width as usize, image.height as usize);
    let moving = |i: usize| velocity[i].length() >= STILL;
    let position = |i: usize| Vec2::new((i % width) as f32, (i / width) as f32);

    // The moving layer: each moving pixel spread along its segment with total weight 1.
    let mut layer = Splat::new(image.width, image.height);
    let limit = (image.width + image.height) as f32;
    for (i, (&c, &v)) in image.pixels.iter().zip(velocity).enumerate() {
        if !moving(i) {
            continue;
        }
        // Clamp absurd velocities to the image's size: they would only cost time.
        let v = v.clamp_length_max(limit);
        let n = (2.0 * v.length()).ceil().max(1.0) as usize;
        let w = 1.0 / n as f32;
        let p = position(i);
        for k in 0..n {
            // Midpoints of n equal parts of the segment [p, p + v].
            let q = p + v * ((k as f32 + 0.5) / n as f32);
            let (x0, y0) = (q.x.floor(), q.y.floor());
            let (fx, fy) = (q.x - x0, q.y - y0);
            let (x0, y0) = (x0 as i64, y0 as i64);
            layer.add(x0, y0, c, w * (1.0 - fx) * (1.0 - fy));
            layer.add(x0 + 1, y0, c, w * fx * (1.0 - fy));
            layer.add(x0, y0 + 1, c, w * (1.0 - fx) * fy);
            layer.add(x0 + 1, y0 + 1, c, w * fx * fy);
        }
    }

    // The still layer, with the background behind moving pixels guessed from still neighbours.
    let still_behind = |i: usize| -> [f32; 4] {
        let v = velocity[i].clamp_length_max(limit);
        let steps = (2.0 * v.length()).ceil() as usize + 2;
        let p = position(i);
        for direction in [-v.normalize(), v.normalize()] {
            for k in 1..=steps {
                let q = (p + direction * k as f32).round();
                if q.x < 0.0 || q.y < 0.0 || q.x >= width as f32 || q.y >= height as f32 {
                    break;
                }
                let j = q.y as usize * width + q.x as usize;
                if !moving(j) {
                    return image.pixels[j];
                }
            }
        }
        image.pixels[i]
    };

    // Composite: the moving layer over the still one.
    let pixels = layer
        .sums
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let a = s[4];
            if a >= 1.0 {
                return [s[0] / a, s[1] / a, s[2] / a, s[3] / a];
            }
            let still = if moving(i) {
                still_behind(i)
            } else {
                image.pixels[i]
            };
            std::array::from_fn(|k| s[k] + (1.0 - a) * still[k])
        })
        .collect();
    Ok(Image {
        width: image.width,
        height: image.height,
        pixels,
    })
}

/// What the pixel-centre rays of a scene see at shutter open, for the post-processes.
#[derive(Debug, Clone, PartialEq)]
pub struct ScreenBuffers {
    /// Width of the film's pixel bounds.
    pub width: u32,
    /// Height of the film's pixel bounds.
    pub height: u32,
    /// Camera-space z (at shutter open) of the first hit, `f32::INFINITY` where there is none.
    pub depth: Vec<f32>,
    /// Raster displacement over the shutter of the point each pixel sees: the point is carried by
    /// its instance's motion, `world_from_object(close) * object_from_world(open) * p`, and
    /// projected by the camera at open and at close. Zero where nothing is hit or a projection
    /// fails.
    pub velocity: Vec<Vec2>,
}

/// Casts one ray through each pixel centre of `scene`'s film, through the lens centre at shutter
/// open, and records the depth and screen-space velocity of what it hits ([`ScreenBuffers`]).
/// Instance `i` of the geometry is the scene description's `shapes[i]`, whose `transform` and
/// `transform_end` give its motion.
pub fn screen_buffers(scene: &RenderScene) -> ScreenBuffers {
    let camera = &scene.camera;
    let bounds = scene.pixel_bounds;
    let shutter = camera.shutter();
    let camera_from_world = camera.world_from_camera().at(shutter.open).inverse();
    let (width, height) = (bounds.width(), bounds.height());
    let mut depth = Vec::with_capacity(width as usize * height as usize);
    let mut velocity = Vec::with_capacity(depth.capacity());
    for y in bounds.y0..bounds.y1 {
        for x in bounds.x0..bounds.x1 {
            let p_film = Point2::<Raster>::new(x as f32 + 0.5, y as f32 + 0.5);
            let hit = camera
                .generate_ray(&CameraSample::at(p_film))
                .and_then(|r| scene.geometry.intersect(&r.ray));
            let Some(hit) = hit else {
                depth.push(f32::INFINITY);
                velocity.push(Vec2::ZERO);
                continue;
            };
            depth.push(camera_from_world.point(hit.p).z);
            // Carry the point by its instance's motion from open to close.
            let p_end = scene
                .description
                .shapes
                .get(hit.instance as usize)
                .and_then(|s| s.transform_end.map(|end| (s.transform, end)))
                .map_or(hit.p, |(start, end)| (end * start.inverse()).point(hit.p));
            let v = match (
                camera.project(hit.p, shutter.open),
                camera.project(p_end, shutter.close),
            ) {
                (Some(a), Some(b)) => Vec2::new(b.x - a.x, b.y - a.y),
                _ => Vec2::ZERO,
            };
            velocity.push(if v.is_finite() { v } else { Vec2::ZERO });
        }
    }
    ScreenBuffers {
        width,
        height,
        depth,
        velocity,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(width: u32, height: u32, f: impl Fn(u32, u32) -> [f32; 4]) -> Image {
        let pixels = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        Image {
            width,
            height,
            pixels,
        }
    }

    fn params(focal_distance: f32, lens_radius: f32) -> DepthOfField {
        DepthOfField {
            focal_distance,
            lens_radius,
            pixels_per_unit: 100.0,
            orthographic: false,
        }
    }

    #[test]
    fn circle_of_confusion_matches_the_thin_lens_formula() {
        // r = 0.1, f = 2, z = 4, k = 100: 0.1 * |1/4 - 1/2| * 100 = 0.1 * 0.25 * 100 = 2.5.
        let c = circle_of_confusion(4.0, 2.0, 0.1, 100.0).unwrap();
        assert!((c - 2.5).abs() < 1e-6, "{c}");
        // Nearer than focus, z = 1: 0.1 * |1 - 1/2| * 100 = 5.
        let c = circle_of_confusion(1.0, 2.0, 0.1, 100.0).unwrap();
        assert!((c - 5.0).abs() < 1e-6, "{c}");
        // The sky, z = infinity: 0.1 * 1/2 * 100 = 5.
        let c = circle_of_confusion(f32::INFINITY, 2.0, 0.1, 100.0).unwrap();
        assert!((c - 5.0).abs() < 1e-6, "{c}");
        // Orthographic, z = 3, f = 2: 0.1 * |1 - 3/2| * 100 = 5.
        let c = circle_of_confusion_orthographic(3.0, 2.0, 0.1, 100.0).unwrap();
        assert!((c - 5.0).abs() < 1e-5, "{c}");
    }

    #[test]
    fn a_point_at_the_focal_distance_has_no_blur() {
        assert_eq!(circle_of_confusion(2.5, 2.5, 0.3, 320.0).unwrap(), 0.0);
        assert_eq!(
            circle_of_confusion_orthographic(2.5, 2.5, 0.3, 320.0).unwrap(),
            0.0
        );
    }

    #[test]
    fn invalid_inputs_are_errors_not_nan() {
        assert!(circle_of_confusion(0.0, 1.0, 0.1, 1.0).is_err());
        assert!(circle_of_confusion(f32::NAN, 1.0, 0.1, 1.0).is_err());
        assert!(circle_of_confusion(1.0, 0.0, 0.1, 1.0).is_err());
        assert!(circle_of_confusion(1.0, 1.0, -0.1, 1.0).is_err());
        assert!(circle_of_confusion(1.0, 1.0, 0.1, f32::INFINITY).is_err());
        assert!(circle_of_confusion_orthographic(f32::INFINITY, 1.0, 0.1, 1.0).is_err());
        let img = image(2, 2, |_, _| [1.0; 4]);
        assert!(depth_of_field(&img, &[1.0; 3], &params(1.0, 0.1)).is_err());
        assert!(depth_of_field(&img, &[1.0, 1.0, -1.0, 1.0], &params(1.0, 0.1)).is_err());
        assert!(motion_blur(&img, &[Vec2::ZERO; 5]).is_err());
        assert!(motion_blur(&img, &[Vec2::ZERO, Vec2::NAN, Vec2::ZERO, Vec2::ZERO]).is_err());
    }

    #[test]
    fn the_camera_s_own_lens_rays_spread_a_point_over_the_circle_of_confusion() {
        // Eye at the origin looking down world -z, so camera (x, y, z) = world (x, y, -z).
        // 200x100 film: window [-2, 2] x [-1, 1]; fov 90 on the smaller (y) axis: s = 1, so
        // k = s * width / (x_max - x_min) = 200 / 4 = 50 pixels per unit at z = 1.
        let toml = r#"
            [film]
            resolution = [200, 100]
            [camera]
            eye = [0.0, 0.0, 0.0]
            target = [0.0, 0.0, -1.0]
            fov = 90.0
            lens_radius = 0.2
            focal_distance = 2.0
        "#;
        let scene =
            RenderScene::build(crate::parse_description("t.toml".as_ref(), toml).unwrap()).unwrap();
        let params = DepthOfField::for_camera(&scene.camera).unwrap();
        assert!((params.pixels_per_unit - 50.0).abs() < 1e-3, "{params:?}");
        // P at camera (0.3, 0.1, 4): c = 0.2 * |1/4 - 1/2| * 50 = 2.5 pixels.
        let c = params.radius(4.0).unwrap();
        assert!((c - 2.5).abs() < 1e-4, "{c}");
        // The lens edge point L = (0.2, 0) sees P from the film point a = P/z - L (1/z - 1/f)
        // = (0.075 + 0.05, 0.025) on z = 1: raster x = (0.125 + 2) / 4 * 200 = 106.25,
        // y = (1 - 0.025) / 2 * 100 = 48.75; the pinhole image of P is at x = 103.75: 2.5 away.
        let sample = CameraSample {
            p_film: Point2::new(106.25, 48.75),
            // The concentric disk maps (1, 0.5) to the disk's edge at (1, 0).
            p_lens: Vec2::new(1.0, 0.5),
            time: 0.0,
        };
        let ray = scene.camera.generate_ray(&sample).unwrap().ray;
        let p_world = glam::Vec3::new(0.3, 0.1, -4.0);
        let (o, d) = (ray.origin.to_glam(), ray.direction.to_glam());
        let miss = (p_world - o).cross(d).length();
        assert!(miss < 1e-4, "the lens-edge ray misses P by {miss}");
        // And the pinhole ray of P lands 2.5 pixels to the left.
        let pinhole = scene
            .camera
            .project(obscura_space::Point3::new(0.3, 0.1, -4.0), 0.0);
        let pinhole = pinhole.unwrap();
        assert!((106.25 - pinhole.x - c).abs() < 1e-3, "{}", pinhole.x);
    }

    #[test]
    fn pixels_in_focus_stay_sharp() {
        // A checkerboard all at the focal distance: every disc is one pixel, the image unchanged.
        let img = image(8, 6, |x, y| {
            let v = ((x + y) % 2) as f32;
            [v, 1.0 - v, 0.5, 1.0]
        });
        let out = depth_of_field(&img, &[2.0; 48], &params(2.0, 0.5)).unwrap();
        for (a, b) in out.pixels.iter().zip(&img.pixels) {
            for k in 0..4 {
                assert!((a[k] - b[k]).abs() < 1e-6, "{a:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn an_out_of_focus_point_spreads_over_its_circle_of_confusion() {
        // One white pixel at (10, 10) on black, everything at z = 1 with f = 2, r = 0.06,
        // k = 100: radius 0.06 * 0.5 * 100 = 3 pixels. Every disc has radius 3 and weight 1 and
        // covers the same relative pixels, so each output pixel's total weight is 1 (away from
        // the border) and the white disc lands on pixels within about 3.5 pixels of (10, 10).
        let img = image(21, 21, |x, y| {
            if (x, y) == (10, 10) {
                [1.0, 1.0, 1.0, 1.0]
            } else {
                [0.0, 0.0, 0.0, 1.0]
            }
        });
        let out = depth_of_field(&img, &[1.0; 21 * 21], &params(2.0, 0.06)).unwrap();
        let lit: Vec<(i32, i32)> = (0..21)
            .flat_map(|y| (0..21).map(move |x| (x, y)))
            .filter(|&(x, y)| out.pixel(x as u32, y as u32)[0] > 1e-6)
            .map(|(x, y)| (x - 10, y - 10))
            .collect();
        assert!(lit.contains(&(3, 0)) && lit.contains(&(0, -3)));
        assert!(lit.iter().all(|&(dx, dy)| dx * dx + dy * dy <= 12));
        // Energy is kept: the sum over the image of the white spread is 1 (weights are all 1).
        let total: f32 = out.pixels.iter().map(|p| p[0]).sum();
        assert!((total - 1.0).abs() < 1e-4, "{total}");
    }

    #[test]
    fn motion_blur_spreads_a_pixel_along_its_velocity() {
        // A white pixel at (2, 2) moving 4 pixels right on a static black image: its segment
        // [2, 6] in x is sampled at 8 midpoints 2.25, 2.75, ..., 5.75, each of weight 1/8,
        // split bilinearly between columns 2..6. The black pixels keep weight 1 of themselves.
        let img = image(10, 5, |x, y| {
            if (x, y) == (2, 2) {
                [1.0; 4]
            } else {
                [0.0, 0.0, 0.0, 1.0]
            }
        });
        let mut velocity = vec![Vec2::ZERO; 50];
        velocity[2 * 10 + 2] = Vec2::new(4.0, 0.0);
        let out = motion_blur(&img, &velocity).unwrap();
        // Samples at 2.25 (0.75 to column 2, 0.25 to 3), 2.75 (0.25, 0.75), 3.25 (0.75 to 3,
        // 0.25 to 4), ..., 5.75 (0.25 to 5, 0.75 to 6), each times 1/8. So the moving layer
        // puts 1/8 of white on column 2, 2/8 on columns 3, 4, 5 and 1/8 on column 6; the still
        // black layer fills the rest of each pixel's weight (at column 2, the hidden background
        // is guessed from column 1: black).
        let expect = [
            (2, 0.125),
            (3, 0.25),
            (4, 0.25),
            (5, 0.25),
            (6, 0.125),
            (7, 0.0),
        ];
        for (x, want) in expect {
            let got = out.pixel(x, 2);
            assert!((got[0] - want).abs() < 1e-6, "x={x}: {got:?}");
            assert!(
                (got[3] - 1.0).abs() < 1e-6,
                "alpha stays 1 at x={x}: {got:?}"
            );
        }
        assert_eq!(out.pixel(7, 2)[0], 0.0);
        assert_eq!(out.pixel(2, 1)[0], 0.0);
    }

    #[test]
    fn zero_velocity_leaves_the_image_unchanged() {
        let img = image(5, 4, |x, y| [x as f32, y as f32, 0.25, 1.0]);
        let out = motion_blur(&img, &[Vec2::ZERO; 20]).unwrap();
        assert_eq!(out, img);
    }
}
