//! The ODS panorama: rays tangent to the viewing circle, the eyes' halves and sides, the
//! tangent construction of `project`, round trips.

use crate::ray_checks::{camera_ray, check_derivative, check_neighbours};
use crate::{assert_close2, assert_close3, base_at, identity_look, look_strategy, raster_in};
use obscura_camera::{Camera, CameraError, CameraSample, OdsCamera, OdsEye};
use obscura_space::{Point2, Point3};
use proptest::prelude::*;

fn ods_strategy() -> impl Strategy<Value = OdsCamera> {
    (
        look_strategy(),
        (1u32..2000, 1u32..1000),
        prop_oneof![Just(0.0f32), Just(0.064), 0.001f32..1.0],
    )
        .prop_map(|(look, (w, half), interaxial)| {
            OdsCamera::new(base_at(look, [w, 2 * half], None, 0.0, 1.0e30), interaxial).unwrap()
        })
}

/// 400 x 200 film, interaxial 0.064 (r = 0.032); each eye is 400 x 100.
/// - Left eye centre (200, 50): phi = 0, theta = pi/2: d = +z, o = -r (1, 0, 0) = (-0.032, 0, 0):
///   the left eye on the left (camera -x).
/// - Right eye centre (200, 150): d = +z, o = (0.032, 0, 0).
/// - Left eye (300, 50): phi = pi/2, d = +x, o = -r (0, 0, -1) = (0, 0, 0.032): facing right,
///   the left eye is forward (+z).
/// - A point straight ahead at distance 0.064 = 2 r: the left eye's tangent has
///   sin(0 - phi) = -r / 0.064 = -1/2, phi = pi/6, x = 400 (1/12 + 1/2) = 233.333, y = 50;
///   the right eye's phi = -pi/6, x = 166.667, y = 100 + 50 = 150.
#[test]
fn hand_computed_rays_and_projections() {
    let camera =
        OdsCamera::new(base_at(identity_look(), [400, 200], None, 0.0, 1e30), 0.064).unwrap();
    let cases = [
        (
            (200.0, 50.0),
            glam::Vec3::Z,
            glam::Vec3::new(-0.032, 0.0, 0.0),
        ),
        (
            (200.0, 150.0),
            glam::Vec3::Z,
            glam::Vec3::new(0.032, 0.0, 0.0),
        ),
        (
            (300.0, 50.0),
            glam::Vec3::X,
            glam::Vec3::new(0.0, 0.0, 0.032),
        ),
        (
            (300.0, 150.0),
            glam::Vec3::X,
            glam::Vec3::new(0.0, 0.0, -0.032),
        ),
        (
            (200.0, 0.0),
            glam::Vec3::Y,
            glam::Vec3::new(-0.032, 0.0, 0.0),
        ),
        (
            (200.0, 200.0),
            -glam::Vec3::Y,
            glam::Vec3::new(0.032, 0.0, 0.0),
        ),
    ];
    for ((x, y), d_expected, o_expected) in cases {
        let (o, d) = camera_ray(&camera, Point2::new(x, y)).unwrap();
        assert_close3(d, d_expected, 1e-6);
        assert_close3(o, o_expected, 1e-6);
    }
    assert_eq!(camera.eye_of(Point2::new(10.0, 99.9)), OdsEye::Left);
    assert_eq!(camera.eye_of(Point2::new(10.0, 100.0)), OdsEye::Right);
    let ahead = camera
        .world_from_camera()
        .at(0.0)
        .point(Point3::new(0.0, 0.0, 0.064));
    let left = camera.project(ahead, 0.0).unwrap();
    assert_close2(
        left.to_glam(),
        glam::Vec2::new(400.0 * (1.0 / 12.0 + 0.5), 50.0),
        1e-3,
    );
    let right = camera.project_eye(ahead, 0.0, OdsEye::Right).unwrap();
    assert_close2(
        right.to_glam(),
        glam::Vec2::new(400.0 * (0.5 - 1.0 / 12.0), 150.0),
        1e-3,
    );
    // Inside the viewing circle no ray passes.
    let inside = camera
        .world_from_camera()
        .at(0.0)
        .point(Point3::new(0.01, 5.0, 0.02));
    assert!(camera.project(inside, 0.0).is_none());
    assert!(camera.project_eye(inside, 0.0, OdsEye::Right).is_none());
}

#[test]
fn validation() {
    let base = |h| base_at(identity_look(), [64, h], None, 0.0, 1.0e30);
    assert!(OdsCamera::new(base(32), 0.0).is_ok());
    assert_eq!(
        OdsCamera::new(base(32), -0.1).unwrap_err(),
        CameraError::Interaxial { got: -0.1 }
    );
    assert!(matches!(
        OdsCamera::new(base(32), f32::NAN),
        Err(CameraError::NonFinite {
            what: "interaxial",
            ..
        })
    ));
    assert_eq!(
        OdsCamera::new(base(33), 0.064).unwrap_err(),
        CameraError::FilmShape {
            model: "ods",
            need: "an even-height",
            got: [64, 33]
        }
    );
}

proptest! {
    #![proptest_config(crate::cases(4096))]

    /// Every ray is tangent to the viewing circle: its origin is on the circle (radius
    /// interaxial / 2, in the plane y = 0), its direction perpendicular to the radius there;
    /// the top half's rays start on the left of their horizontal direction, the bottom half's
    /// on the right; the direction is the environment camera's of the eye's own row.
    #[test]
    fn rays_are_tangent_to_the_viewing_circle(
        camera in ods_strategy(),
        fx in prop_oneof![Just(0.0f32), Just(1.0), 0f32..1.0],
        fy in prop_oneof![Just(0.0f32), Just(0.5), Just(1.0), 0f32..1.0],
    ) {
        let [w, h] = camera.film().resolution();
        let p = raster_in([w, h], fx, fy);
        let (o, d) = camera_ray(&camera, p).unwrap();
        let r = camera.interaxial() / 2.0;
        let scale = 1.0 + r;
        prop_assert!((o.length() - r).abs() <= 2e-5 * scale, "{o:?} vs radius {r}");
        prop_assert!(o.y.abs() <= 2e-5 * scale);
        prop_assert!(o.dot(d).abs() <= 2e-5 * scale, "{o:?} . {d:?}");
        // The eye's side: the left of horizontal direction (sin phi, 0, cos phi) is
        // (-cos phi, 0, sin phi) in the left-handed camera frame (x right, y up, z forward).
        let phi = std::f32::consts::TAU * (p.x / w as f32 - 0.5);
        let left = glam::Vec3::new(-phi.cos(), 0.0, phi.sin());
        let side = if fy < 0.5 { 1.0 } else { -1.0 };
        assert_close3(o, side * r * left, 2e-5 * scale);
        // The direction: theta = pi y' / (H / 2) from +y.
        let half = h as f32 / 2.0;
        let row = if fy < 0.5 { p.y } else { p.y - half };
        let theta = std::f32::consts::PI * row / half;
        let expected = glam::Vec3::new(theta.sin() * phi.sin(), theta.cos(), theta.sin() * phi.cos());
        assert_close3(d, expected, 2e-5);
    }

    /// raster -> ray -> point -> raster for both eyes (through `project_eye` for the right),
    /// the seam and the halves' edges included (poles excepted, where x is undefined).
    #[test]
    fn round_trip(
        camera in ods_strategy(),
        fx in prop_oneof![Just(0.0f32), Just(0.999), 0f32..1.0],
        fy in 0.01f32..0.99,
        right_eye in any::<bool>(),
        t in 0.5f32..50.0,
    ) {
        let [w, h] = camera.film().resolution();
        let (width, half) = (w as f32, h as f32 / 2.0);
        let p = Point2::new(fx * width, (fy + if right_eye { 1.0 } else { 0.0 }) * half);
        let eye = if right_eye { OdsEye::Right } else { OdsEye::Left };
        prop_assert_eq!(camera.eye_of(p), eye);
        let ray = camera.generate_ray(&CameraSample::at(p)).unwrap().ray;
        let back = camera.project_eye(ray.at(t), 0.0, eye);
        prop_assert!(back.is_some(), "{p:?}");
        let back = back.unwrap();
        let dx = (back.x - p.x).abs();
        let dx = dx.min((dx - width).abs());
        // As the environment camera: ~1e-6 rad per unit of distance, larger near the poles.
        let sin_theta = (std::f32::consts::PI * fy).sin();
        let tol = 2e-3 + 4e-6 * width.max(half) / sin_theta * (1.0 + 20.0 / t);
        prop_assert!(dx <= tol && (back.y - p.y).abs() <= tol, "{back:?} vs {p:?} (tol {tol})");
        if !right_eye {
            prop_assert_eq!(camera.project(ray.at(t), 0.0), Some(back));
        }
    }

    /// Differentials are the neighbouring rays of the same eye (at the seam between the
    /// halves, the row below the left eye's last continues the left panorama).
    #[test]
    fn differentials(camera in ods_strategy(), fx in 0f32..1.0, fy in 0f32..0.5) {
        let [w, h] = camera.film().resolution();
        let p = raster_in([w, h], fx, fy);
        // Only when the neighbour below stays in the same eye is it the plain next ray.
        if p.y + 1.0 < h as f32 / 2.0 {
            check_neighbours(&camera, p);
        }
        let eye = camera.eye_of(p);
        let below = camera.generate_ray_differential(&CameraSample::at(p)).unwrap();
        let pose = camera.world_from_camera().at(0.0);
        let (o, d) = camera.eye_ray(eye, Point2::new(p.x, p.y + 1.0));
        let o = pose.point(Point3::from_glam(o.as_vec3()));
        let d = pose.vector(obscura_space::Vector3::from_glam(d.as_vec3())).normalize();
        assert_close3(below.ry_origin.to_glam(), o.to_glam(), 1e-5);
        assert_close3(below.ry_direction.to_glam(), d.to_glam(), 1e-5);
    }
}

#[test]
fn differentials_against_finite_differences() {
    let camera =
        OdsCamera::new(base_at(identity_look(), [720, 360], None, 0.0, 1e30), 0.064).unwrap();
    for (x, y) in [
        (10.5, 30.5),
        (360.0, 90.0),
        (700.2, 170.7),
        (200.0, 250.0),
        (500.0, 300.0),
    ] {
        let p = Point2::new(x, y);
        let eye = camera.eye_of(p);
        check_derivative(&camera, p, |x, y| {
            camera.eye_ray(eye, Point2::new(x as f32, y as f32)).1
        });
    }
}

/// Every new model dispatches through `AnyCamera` unchanged.
#[test]
fn any_camera_dispatch() {
    use obscura_camera::{
        AnyCamera, CubeFace, CubeFaceCamera, CylindricalCamera, FisheyeCamera, FisheyeProjection,
        OctahedralCamera,
    };
    let base = || base_at(identity_look(), [32, 32], None, 0.0, 1.0e30);
    let cameras: [AnyCamera; 5] = [
        FisheyeCamera::new(base(), FisheyeProjection::Stereographic, 200.0, [0.0, 0.0])
            .unwrap()
            .into(),
        CylindricalCamera::new(base(), 90.0).unwrap().into(),
        OctahedralCamera::new(base()).unwrap().into(),
        CubeFaceCamera::new(base(), CubeFace::NegativeY)
            .unwrap()
            .into(),
        OdsCamera::new(base(), 0.064).unwrap().into(),
    ];
    let sample = CameraSample::at(Point2::new(11.5, 7.25));
    let direct = [
        FisheyeCamera::new(base(), FisheyeProjection::Stereographic, 200.0, [0.0, 0.0])
            .unwrap()
            .generate_ray(&sample),
        CylindricalCamera::new(base(), 90.0)
            .unwrap()
            .generate_ray(&sample),
        OctahedralCamera::new(base()).unwrap().generate_ray(&sample),
        CubeFaceCamera::new(base(), CubeFace::NegativeY)
            .unwrap()
            .generate_ray(&sample),
        OdsCamera::new(base(), 0.064).unwrap().generate_ray(&sample),
    ];
    for (camera, direct) in cameras.iter().zip(direct) {
        assert_eq!(camera.generate_ray(&sample), direct);
        assert!(!camera.uses_lens_sample());
        assert!(camera.uses_time_sample());
    }
}
