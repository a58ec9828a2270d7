//! Cube-map faces: the OpenGL orientation, face centres, the six faces tiling the sphere, the
//! +z face against a 90-degree perspective camera, round trips.

use crate::ray_checks::{camera_ray, check_derivative, check_neighbours};
use crate::{assert_close2, assert_close3, base_at, identity_look, look_strategy, raster_in};
use obscura_camera::{
    Camera, CameraError, CameraSample, CubeFace, CubeFaceCamera, FovAxis, PerspectiveCamera,
    ThinLens,
};
use obscura_space::{Point2, Point3, Vector3};
use proptest::prelude::*;

fn face_camera(look: obscura_camera::LookAt, n: u32, face: CubeFace) -> CubeFaceCamera {
    CubeFaceCamera::new(base_at(look, [n, n], None, 0.01, 1.0e30), face).unwrap()
}

/// The six faces of one random pose and square film.
fn cube_strategy() -> impl Strategy<Value = [CubeFaceCamera; 6]> {
    (look_strategy(), 1u32..2000)
        .prop_map(|(look, n)| CubeFace::ALL.map(|face| face_camera(look, n, face)))
}

/// Face centres look along the face axes; the top-left corner (s, t) = (0, 0), i.e.
/// (sc, tc) = (-1, -1), read from the OpenGL table (ma = 1):
/// - +x: sc = -rz, tc = -ry -> r = (1, 1, 1);
/// - -x: sc = +rz, tc = -ry -> r = (-1, 1, -1);
/// - +y: sc = +rx, tc = +rz -> r = (-1, 1, -1);
/// - -y: sc = +rx, tc = -rz -> r = (-1, -1, 1);
/// - +z: sc = +rx, tc = -ry -> r = (-1, 1, 1);
/// - -z: sc = -rx, tc = -ry -> r = (1, 1, -1).
///
/// So the side faces have +y at the top, +z (forward) is the camera's own view, and the
/// bottom-right corner is the opposite corner of the face's square.
#[test]
fn face_centres_and_corners_follow_the_opengl_table() {
    let cases = [
        (
            CubeFace::PositiveX,
            "+x",
            glam::Vec3::X,
            glam::Vec3::new(1.0, 1.0, 1.0),
        ),
        (
            CubeFace::NegativeX,
            "-x",
            -glam::Vec3::X,
            glam::Vec3::new(-1.0, 1.0, -1.0),
        ),
        (
            CubeFace::PositiveY,
            "+y",
            glam::Vec3::Y,
            glam::Vec3::new(-1.0, 1.0, -1.0),
        ),
        (
            CubeFace::NegativeY,
            "-y",
            -glam::Vec3::Y,
            glam::Vec3::new(-1.0, -1.0, 1.0),
        ),
        (
            CubeFace::PositiveZ,
            "+z",
            glam::Vec3::Z,
            glam::Vec3::new(-1.0, 1.0, 1.0),
        ),
        (
            CubeFace::NegativeZ,
            "-z",
            -glam::Vec3::Z,
            glam::Vec3::new(1.0, 1.0, -1.0),
        ),
    ];
    for (face, name, axis, corner) in cases {
        assert_eq!(name.parse::<CubeFace>(), Ok(face));
        let camera = face_camera(identity_look(), 64, face);
        let (_, d) = camera_ray(&camera, Point2::new(32.0, 32.0)).unwrap();
        assert_close3(d, axis, 1e-6);
        let (_, d) = camera_ray(&camera, Point2::new(0.0, 0.0)).unwrap();
        assert_close3(d, corner.normalize(), 1e-6);
        // The opposite corner mirrors the in-face components.
        let opposite = 2.0 * axis - corner;
        let (_, d) = camera_ray(&camera, Point2::new(64.0, 64.0)).unwrap();
        assert_close3(d, opposite.normalize(), 1e-6);
    }
}

/// The +z face is the 90-degree perspective view of the same pose, ray for ray.
#[test]
fn positive_z_is_the_perspective_view() {
    let base = base_at(identity_look(), [48, 48], None, 0.01, 1.0e30);
    let face = CubeFaceCamera::new(base.clone(), CubeFace::PositiveZ).unwrap();
    let perspective =
        PerspectiveCamera::new(base, 90.0, FovAxis::Smaller, ThinLens::PINHOLE).unwrap();
    for (x, y) in [(0.0, 0.0), (13.3, 40.1), (24.0, 24.0), (48.0, 2.5)] {
        let sample = CameraSample::at(Point2::new(x, y));
        let a = face.generate_ray(&sample).unwrap().ray;
        let b = perspective.generate_ray(&sample).unwrap().ray;
        assert_close3(a.direction.to_glam(), b.direction.to_glam(), 1e-6);
        // Both clip the depth along +z: the same points.
        assert_close3(a.at(a.t_min).to_glam(), b.at(b.t_min).to_glam(), 1e-6);
    }
}

#[test]
fn validation() {
    assert_eq!(
        CubeFaceCamera::new(
            base_at(identity_look(), [64, 63], None, 0.0, 1e30),
            CubeFace::PositiveX
        )
        .unwrap_err(),
        CameraError::FilmShape {
            model: "cube_face",
            need: "a square",
            got: [64, 63]
        }
    );
    assert_eq!(
        "z".parse::<CubeFace>(),
        Err(CameraError::UnknownCubeFace("z".into()))
    );
    assert!(
        CameraError::UnknownCubeFace("z".into())
            .to_string()
            .contains("\"+x\"")
    );
}

proptest! {
    #![proptest_config(crate::cases(4096))]

    /// The six faces tile the sphere: every direction lands inside [0, n]^2 of at least one
    /// face, and of more than one only on an edge between faces (where its two largest
    /// components are equal in size), and its ray there looks back along it.
    #[test]
    fn faces_tile_the_sphere(faces in cube_strategy(), w in (-1f32..1.0, -1f32..1.0, -1f32..1.0)) {
        let w = glam::Vec3::new(w.0, w.1, w.2);
        prop_assume!(w.length() > 0.1);
        let pose = faces[0].world_from_camera().at(0.0);
        let d_world = pose.vector(Vector3::from_glam(w)).normalize();
        let eye = pose.point(Point3::ORIGIN);
        let n = faces[0].film().resolution()[0] as f32;
        let slack = 1e-3 * n.max(1.0);
        let mut hits = 0;
        for face in &faces {
            let Some(p) = face.project(eye + d_world * 5.0, 0.0) else { continue };
            if p.x >= -slack && p.x <= n + slack && p.y >= -slack && p.y <= n + slack {
                hits += 1;
                let ray = face.generate_ray(&CameraSample::at(p)).unwrap().ray;
                assert_close3(ray.direction.to_glam(), d_world.to_glam(), 1e-4);
            }
        }
        let mut a = w.abs().to_array();
        a.sort_by(f32::total_cmp);
        let on_edge = a[2] - a[1] <= 3e-3 * a[2];
        prop_assert!(hits == 1 || (hits > 1 && on_edge), "{hits} faces for {w:?}");
    }

    /// raster -> ray -> point -> raster on every face, the film's edges included.
    #[test]
    fn round_trip(
        faces in cube_strategy(),
        fx in prop_oneof![Just(0.0f32), Just(1.0), 0f32..1.0],
        fy in prop_oneof![Just(0.0f32), Just(1.0), 0f32..1.0],
        t in 0.5f32..50.0,
    ) {
        for face in &faces {
            let res = face.film().resolution();
            let p = raster_in(res, fx, fy);
            let ray = face.generate_ray(&CameraSample::at(p)).unwrap().ray;
            let back = face.project(ray.at(t.max(ray.t_min * 1.01)), 0.0).unwrap();
            // At most 1.5 n pixels per radian: n / 2 per unit of the face plane, and the plane
            // coordinate tan(a) turns 1 + tan^2(a) <= 3 units per radian (at the corners).
            let tol = 2e-3 + 1.5 * res[0] as f32 * 4e-6 * (1.0 + 20.0 / t);
            assert_close2(back.to_glam(), p.to_glam(), tol);
        }
    }

    /// Differentials are the neighbouring rays.
    #[test]
    fn differentials(faces in cube_strategy(), fx in 0f32..1.0, fy in 0f32..1.0) {
        for face in &faces {
            check_neighbours(face, raster_in(face.film().resolution(), fx, fy));
        }
    }
}

/// Nothing behind a face projects; depth clipping is along the face's axis.
#[test]
fn behind_and_depth_range() {
    let camera = CubeFaceCamera::new(
        base_at(identity_look(), [32, 32], None, 1.0, 10.0),
        CubeFace::PositiveX,
    )
    .unwrap();
    let pose = camera.world_from_camera().at(0.0);
    let at = |x, y, z| pose.point(Point3::new(x, y, z));
    assert!(camera.project(at(-2.0, 0.0, 0.0), 0.0).is_none());
    assert!(camera.project(at(0.5, 0.0, 0.0), 0.0).is_none());
    assert!(camera.project(at(11.0, 0.0, 0.0), 0.0).is_none());
    // 5 along +x and 0.9 across: depth 5 is inside [1, 10] although the distance is not 5.
    assert!(camera.project(at(5.0, 0.9, 0.0), 0.0).is_some());
    // The corner ray starts at depth 1: t_min = sqrt 3.
    let ray = camera
        .generate_ray(&CameraSample::at(Point2::new(0.0, 0.0)))
        .unwrap()
        .ray;
    assert!(
        (ray.t_min - 3f32.sqrt()).abs() < 1e-5 && (ray.t_max - 10.0 * 3f32.sqrt()).abs() < 1e-4
    );
}

#[test]
fn differentials_against_finite_differences() {
    for face in CubeFace::ALL {
        let camera = face_camera(identity_look(), 128, face);
        for (x, y) in [(3.3, 7.7), (64.0, 64.0), (120.0, 20.0)] {
            check_derivative(&camera, Point2::new(x, y), |x, y| {
                camera.direction(Point2::new(x as f32, y as f32))
            });
        }
    }
}
