//! The cylindrical panorama: azimuth by column, height on the cylinder by row, the inverse.

use crate::ray_checks::{camera_ray, check_derivative, check_neighbours};
use crate::{assert_close3, base_at, identity_look, look_strategy, raster_in};
use obscura_camera::{Camera, CameraError, CameraSample, CylindricalCamera};
use obscura_space::{Point2, Point3};
use proptest::prelude::*;

fn cylindrical_strategy() -> impl Strategy<Value = CylindricalCamera> {
    (
        look_strategy(),
        (1u32..2000, 1u32..2000),
        1f32..179.0,
        prop_oneof![Just(0.0f32), 0.001f32..0.5],
    )
        .prop_map(|(look, (w, h), fov, near)| {
            CylindricalCamera::new(base_at(look, [w, h], None, near, 1.0e30), fov).unwrap()
        })
}

/// A 360 x 180 film, fov 90 (tan 45 = 1): phi = 2 pi (x / 360 - 0.5), h = 1 - 2 y / 180.
/// - (180, 90): phi = 0, h = 0 -> +z;
/// - (270, 90): phi = pi/2, h = 0 -> +x;
/// - (180, 0): phi = 0, h = 1 -> (0, 1, 1) / sqrt 2 (the top edge at fov/2 = 45 degrees up);
/// - (90, 135): phi = -pi/2, h = -1/2 -> (-1, -1/2, 0) / sqrt(5/4);
/// - (0, 90): phi = -pi -> -z (the seam looks back).
#[test]
fn hand_computed_directions() {
    let camera =
        CylindricalCamera::new(base_at(identity_look(), [360, 180], None, 0.0, 1e30), 90.0)
            .unwrap();
    let s = 0.5f32.sqrt();
    let cases = [
        ((180.0, 90.0), glam::Vec3::Z),
        ((270.0, 90.0), glam::Vec3::X),
        ((180.0, 0.0), glam::Vec3::new(0.0, s, s)),
        (
            (90.0, 135.0),
            glam::Vec3::new(-1.0, -0.5, 0.0) / 1.25f32.sqrt(),
        ),
        ((0.0, 90.0), -glam::Vec3::Z),
    ];
    for ((x, y), expected) in cases {
        let (origin, d) = camera_ray(&camera, Point2::new(x, y)).unwrap();
        assert_close3(d, expected, 1e-6);
        assert_close3(origin, glam::Vec3::ZERO, 1e-6);
    }
    // Straight up and down have no azimuth: no raster position.
    let eye = camera.world_from_camera().at(0.0);
    for y in [2.0, -2.0] {
        assert!(
            camera
                .project(eye.point(Point3::new(0.0, y, 0.0)), 0.0)
                .is_none()
        );
    }
}

#[test]
fn validation() {
    let base = || base_at(identity_look(), [64, 48], None, 0.0, 1.0e30);
    assert!(CylindricalCamera::new(base(), 179.0).is_ok());
    for fov in [0.0, 180.0, -5.0] {
        assert_eq!(
            CylindricalCamera::new(base(), fov).unwrap_err(),
            CameraError::Fov { got: fov }
        );
    }
    assert!(matches!(
        CylindricalCamera::new(base(), f32::NAN),
        Err(CameraError::NonFinite { what: "fov", .. })
    ));
}

proptest! {
    #![proptest_config(crate::cases(4096))]

    /// Rows are linear in height on the unit cylinder: the camera-space direction's
    /// elevation tangent is tan(fov/2) (1 - 2 y / H), its azimuth 2 pi (x / W - 1/2), for any
    /// film point including the edges.
    #[test]
    fn rows_linear_in_height(
        camera in cylindrical_strategy(),
        fov in 1f32..179.0,
        fx in prop_oneof![Just(0.0f32), Just(1.0), 0f32..1.0],
        fy in prop_oneof![Just(0.0f32), Just(1.0), 0f32..1.0],
    ) {
        let camera = CylindricalCamera::new(camera.base().clone(), fov).unwrap();
        let res = camera.film().resolution();
        let p = raster_in(res, fx, fy);
        let (_, d) = camera_ray(&camera, p).unwrap();
        let horizontal = d.x.hypot(d.z);
        let expected_h = (fov.to_radians() / 2.0).tan() * (1.0 - 2.0 * p.y / res[1] as f32);
        prop_assert!((d.y / horizontal - expected_h).abs() <= 2e-4 * (1.0 + expected_h.abs()),
            "{} vs {expected_h}", d.y / horizontal);
        let phi = std::f32::consts::TAU * (p.x / res[0] as f32 - 0.5);
        let expected = glam::Vec2::new(phi.sin(), phi.cos());
        prop_assert!((glam::Vec2::new(d.x, d.z) / horizontal - expected).length() < 1e-4);
    }

    /// raster -> ray -> point -> raster over the whole film (the seam x = 0 ~ x = W wraps).
    #[test]
    fn round_trip(
        camera in cylindrical_strategy(),
        fov in 1f32..150.0,
        fx in prop_oneof![Just(0.0f32), Just(1.0), 0f32..1.0],
        fy in prop_oneof![Just(0.0f32), Just(1.0), 0f32..1.0],
        t in 0.5f32..50.0,
    ) {
        let camera = CylindricalCamera::new(camera.base().clone(), fov).unwrap();
        let res = camera.film().resolution();
        let [width, height] = res.map(|r| r as f32);
        let p = raster_in(res, fx, fy);
        let ray = camera.generate_ray(&CameraSample::at(p)).unwrap().ray;
        prop_assert!(ray.t_min == camera.base().near && ray.t_max == camera.base().far);
        let back = camera.project(ray.at(t), 0.0).unwrap();
        let dx = (back.x - p.x).abs();
        let dx = dx.min((dx - width).abs());
        // Pixels per radian of direction error: across, W / 2 pi / cos(elevation); up,
        // dy/dh * dh/d(elevation) = H / (2 tan(fov/2)) * (1 + h^2).
        let tan_half = (fov.to_radians() / 2.0).tan();
        let h = tan_half * (1.0 - 2.0 * p.y / height);
        let per_radian = (width / std::f32::consts::TAU * (1.0 + h * h).sqrt())
            .max(height / (2.0 * tan_half) * (1.0 + h * h));
        let tol = 2e-3 + per_radian * 4e-6 * (1.0 + 20.0 / t);
        prop_assert!(dx <= tol && (back.y - p.y).abs() <= tol, "{back:?} vs {p:?} (tol {tol})");
    }

    /// Differentials are the neighbouring rays.
    #[test]
    fn differentials(camera in cylindrical_strategy(), fx in 0f32..1.0, fy in 0f32..1.0) {
        check_neighbours(&camera, raster_in(camera.film().resolution(), fx, fy));
    }
}

/// Differentials against the derivative of the direction.
#[test]
fn differentials_against_finite_differences() {
    let camera =
        CylindricalCamera::new(base_at(identity_look(), [720, 240], None, 0.0, 1e30), 100.0)
            .unwrap();
    for (x, y) in [(10.5, 10.5), (360.0, 120.0), (700.2, 230.7), (200.0, 50.0)] {
        check_derivative(&camera, Point2::new(x, y), |x, y| {
            camera.direction(Point2::new(x as f32, y as f32))
        });
    }
}
