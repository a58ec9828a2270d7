//! One face of a cube map, as a 90-degree perspective camera.

use crate::camera::{Camera, CameraBase, CameraRay, CameraRayDifferential, CameraSample};
use crate::chain::{self, CameraRayParts, PoseCache};
use crate::error::CameraError;
use core::str::FromStr;
use glam::DVec3;
use obscura_space::{Point2, Point3, Raster, World};

/// A face of a cube map, named by its major axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CubeFace {
    /// `"+x"`: camera right.
    PositiveX,
    /// `"-x"`: camera left.
    NegativeX,
    /// `"+y"`: camera up.
    PositiveY,
    /// `"-y"`: camera down.
    NegativeY,
    /// `"+z"`: camera forward.
    PositiveZ,
    /// `"-z"`: camera back.
    NegativeZ,
}

impl CubeFace {
    /// The six faces in OpenGL's order (`GL_TEXTURE_CUBE_MAP_POSITIVE_X` + 0..5).
    pub const ALL: [CubeFace; 6] = [
        CubeFace::PositiveX,
        CubeFace::NegativeX,
        CubeFace::PositiveY,
        CubeFace::NegativeY,
        CubeFace::PositiveZ,
        CubeFace::NegativeZ,
    ];

    /// The scene format's name: `"+x"`, `"-x"`, `"+y"`, `"-y"`, `"+z"` or `"-z"`.
    pub fn name(self) -> &'static str {
        match self {
            CubeFace::PositiveX => "+x",
            CubeFace::NegativeX => "-x",
            CubeFace::PositiveY => "+y",
            CubeFace::NegativeY => "-y",
            CubeFace::PositiveZ => "+z",
            CubeFace::NegativeZ => "-z",
        }
    }

    /// The face's major axis (the direction its centre looks at), in the camera frame.
    pub fn axis(self) -> DVec3 {
        match self {
            CubeFace::PositiveX => DVec3::X,
            CubeFace::NegativeX => -DVec3::X,
            CubeFace::PositiveY => DVec3::Y,
            CubeFace::NegativeY => -DVec3::Y,
            CubeFace::PositiveZ => DVec3::Z,
            CubeFace::NegativeZ => -DVec3::Z,
        }
    }

    /// The direction `r` with `|ma| = 1` of the face coordinates `sc`, `tc` in `[-1, 1]`: the
    /// OpenGL table read backwards.
    #[inline]
    pub fn direction(self, sc: f64, tc: f64) -> DVec3 {
        match self {
            CubeFace::PositiveX => DVec3::new(1.0, -tc, -sc),
            CubeFace::NegativeX => DVec3::new(-1.0, -tc, sc),
            CubeFace::PositiveY => DVec3::new(sc, 1.0, tc),
            CubeFace::NegativeY => DVec3::new(sc, -1.0, -tc),
            CubeFace::PositiveZ => DVec3::new(sc, -tc, 1.0),
            CubeFace::NegativeZ => DVec3::new(-sc, -tc, -1.0),
        }
    }

    /// The OpenGL table: `(sc, tc, ma)` of a direction `r` for this face, `ma` the component
    /// along the face's axis (positive in front of the face).
    #[inline]
    pub fn coordinates(self, r: DVec3) -> (f64, f64, f64) {
        match self {
            CubeFace::PositiveX => (-r.z, -r.y, r.x),
            CubeFace::NegativeX => (r.z, -r.y, -r.x),
            CubeFace::PositiveY => (r.x, r.z, r.y),
            CubeFace::NegativeY => (r.x, -r.z, -r.y),
            CubeFace::PositiveZ => (r.x, -r.y, r.z),
            CubeFace::NegativeZ => (-r.x, -r.y, -r.z),
        }
    }
}

impl FromStr for CubeFace {
    type Err = CameraError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        CubeFace::ALL
            .into_iter()
            .find(|face| face.name() == s)
            .ok_or_else(|| CameraError::UnknownCubeFace(s.to_owned()))
    }
}

/// One face of a cube map: a 90-degree perspective camera looking along the face's axis, in
/// the OpenGL cube-map orientation (OpenGL 4.6 core specification, section 8.13 "Cube Map
/// Texture Selection", the table "Selection of cube map images"). The cube's frame is the
/// camera frame (+x right, +y up, +z forward), so the `+z` face is the camera's forward view,
/// exactly what a 90-degree perspective camera of the same pose sees, and `-z` looks back.
///
/// For a direction `r`, the table gives the major axis `ma` and the face coordinates `sc`,
/// `tc`:
///
/// | face | ma  | sc  | tc  |
/// |------|-----|-----|-----|
/// | +x   | +rx | -rz | -ry |
/// | -x   | -rx | +rz | -ry |
/// | +y   | +ry | +rx | +rz |
/// | -y   | -ry | +rx | -rz |
/// | +z   | +rz | +rx | -ry |
/// | -z   | -rz | -rx | -ry |
///
/// and `s = (sc / ma + 1) / 2`, `t = (tc / ma + 1) / 2`, with `s` along the image's columns
/// (left to right) and `t` along its rows from the first (top) row down, as cube-map images are
/// stored: raster `(x, y) = (s W, t H)`. So the side faces have +y up, the `+y` face has +z
/// down its image (its top row looks back, towards -z), and the `-y` face has +z up.
///
/// The six faces tile the sphere, meeting at their edges. Rays start at the eye; as for the
/// perspective camera, `[near, far]` clips the depth along the face's axis (so
/// `t_min = near / ma` for a unit direction), and [`Camera::project`] gives None behind the
/// face (`ma <= 0`) or outside that depth range, and returns points beyond the face's edges
/// (outside the image) otherwise.
#[derive(Debug, Clone)]
pub struct CubeFaceCamera {
    base: CameraBase,
    pose: PoseCache,
    face: CubeFace,
}

impl CubeFaceCamera {
    /// The camera of one cube-map face. Errors: a non-square film
    /// ([`CameraError::FilmShape`]) and the base's errors (`near < 0`, `near >= far`, a bad
    /// shutter).
    pub fn new(base: CameraBase, face: CubeFace) -> Result<CubeFaceCamera, CameraError> {
        base.validate(false)?;
        let [width, height] = base.film.resolution();
        if width != height {
            return Err(CameraError::FilmShape {
                model: "cube_face",
                need: "a square",
                got: [width, height],
            });
        }
        Ok(CubeFaceCamera {
            pose: PoseCache::new(&base),
            base,
            face,
        })
    }

    /// The pose, shutter, film and clip range.
    pub fn base(&self) -> &CameraBase {
        &self.base
    }

    /// The face.
    pub fn face(&self) -> CubeFace {
        self.face
    }

    /// The camera-space unit direction of a film point.
    pub fn direction(&self, p_film: Point2<Raster>) -> DVec3 {
        let [width, height] = self.base.film.resolution().map(f64::from);
        let sc = 2.0 * f64::from(p_film.x) / width - 1.0;
        let tc = 2.0 * f64::from(p_film.y) / height - 1.0;
        self.face.direction(sc, tc).normalize()
    }

    /// The camera-space ray of a film point, clipped by depth along the face's axis.
    #[inline]
    fn ray_at(&self, p_film: Point2<Raster>) -> Option<CameraRayParts> {
        let direction = self.direction(p_film);
        let ma = direction.dot(self.face.axis());
        Some(CameraRayParts {
            origin: DVec3::ZERO,
            direction,
            t_min: (f64::from(self.base.near) / ma) as f32,
            t_max: (f64::from(self.base.far) / ma) as f32,
        })
    }
}

impl Camera for CubeFaceCamera {
    #[inline]
    fn base(&self) -> &CameraBase {
        &self.base
    }

    fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        chain::generate(&self.base, &self.pose, sample, |p| self.ray_at(p))
    }

    fn generate_ray_differential(&self, sample: &CameraSample) -> Option<CameraRayDifferential> {
        chain::generate_differential(&self.base, &self.pose, sample, |p| self.ray_at(p))
    }

    fn project(&self, p: Point3<World>, time: f32) -> Option<Point2<Raster>> {
        // World -> camera.
        let r = chain::camera_point(&self.base, &self.pose, p, time);
        // The face's coordinates; nothing behind it or outside the depth range.
        let (sc, tc, ma) = self.face.coordinates(r);
        let (near, far) = (f64::from(self.base.near), f64::from(self.base.far));
        if !(ma > 0.0 && ma >= near && ma <= far) {
            return None;
        }
        let [width, height] = self.base.film.resolution().map(f64::from);
        Some(Point2::new(
            (0.5 * width * (sc / ma + 1.0)) as f32,
            (0.5 * height * (tc / ma + 1.0)) as f32,
        ))
    }

    fn uses_lens_sample(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_table_inverts() {
        for face in CubeFace::ALL {
            assert_eq!(face.name().parse::<CubeFace>(), Ok(face));
            for (sc, tc) in [(0.3, -0.7), (-1.0, 1.0), (0.0, 0.0)] {
                let (sc2, tc2, ma) = face.coordinates(face.direction(sc, tc));
                assert_eq!((sc2, tc2, ma), (sc, tc, 1.0), "{face:?}");
            }
        }
        assert_eq!(
            "x".parse::<CubeFace>(),
            Err(CameraError::UnknownCubeFace("x".into()))
        );
    }
}
