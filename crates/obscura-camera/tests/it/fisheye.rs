//! The ideal fisheyes: the angle from the optical axis against the radius in pixels, the image
//! circle, lens shift, round trips through `project`, differentials, validation.

use crate::ray_checks::{camera_ray, check_derivative, check_neighbours};
use crate::{assert_close3, base_at, identity_look, look_strategy};
use obscura_camera::{
    Camera, CameraError, CameraSample, FisheyeCamera, FisheyeProjection, FovAxis,
    PerspectiveCamera, ScreenWindow, ThinLens,
};
use obscura_space::{Point2, Point3};
use proptest::prelude::*;

const PROJECTIONS: [FisheyeProjection; 4] = [
    FisheyeProjection::Equidistant,
    FisheyeProjection::Equisolid,
    FisheyeProjection::Stereographic,
    FisheyeProjection::Orthographic,
];

/// A fisheye at the scene format's example pose (the tests read rays back in camera space).
fn fisheye(
    res: [u32; 2],
    projection: FisheyeProjection,
    fov: f32,
    shift: [f32; 2],
) -> FisheyeCamera {
    FisheyeCamera::new(
        base_at(identity_look(), res, None, 0.0, 1.0e30),
        projection,
        fov,
        shift,
    )
    .unwrap()
}

/// The angle (degrees) between the camera-space ray of `p` and the optical axis +z.
fn angle_from_axis(camera: &FisheyeCamera, p: Point2<obscura_space::Raster>) -> f32 {
    let (_, d) = camera_ray(camera, p).unwrap();
    d.z.clamp(-1.0, 1.0).acos().to_degrees()
}

/// A 1000 x 1000 film: image circle radius R = 500 px about (500, 500). A point 250 px right
/// of the centre, raster (750, 500), is at r = 250. Worked out from the published formulas:
/// - equidistant, fov 180: f = R / (pi/2) = 318.310 px; theta = r / f = pi/4 = 45 degrees;
/// - equisolid, fov 180: f = R / (2 sin 45) = 353.553; theta = 2 asin(r / 2f)
///   = 2 asin(0.353553) = 41.409622 degrees;
/// - stereographic, fov 180: f = R / (2 tan 45) = 250; theta = 2 atan(250 / 500)
///   = 53.130102 degrees;
/// - orthographic, fov 120: f = R / sin 60 = 577.350; theta = asin(250 / 577.350)
///   = 25.658906 degrees.
///
/// And the rim, r = R = 500, is at half the field of view for every one.
#[test]
fn angle_against_radius_hand_computed() {
    let cases = [
        (FisheyeProjection::Equidistant, 180.0, 45.0),
        (FisheyeProjection::Equisolid, 180.0, 41.409_622),
        (FisheyeProjection::Stereographic, 180.0, 53.130_1),
        (FisheyeProjection::Orthographic, 120.0, 25.658_906),
    ];
    for (projection, fov, theta) in cases {
        let camera = fisheye([1000, 1000], projection, fov, [0.0, 0.0]);
        let got = angle_from_axis(&camera, Point2::new(750.0, 500.0));
        assert!(
            (got - theta).abs() < 1e-3,
            "{projection:?}: {got} vs {theta}"
        );
        // Right of the centre is camera +x, with no y.
        let (_, d) = camera_ray(&camera, Point2::new(750.0, 500.0)).unwrap();
        assert!(d.x > 0.0 && d.y.abs() < 1e-6, "{d:?}");
        // The same radius straight up (raster y smaller) is camera +y.
        let (_, d) = camera_ray(&camera, Point2::new(500.0, 250.0)).unwrap();
        assert!(d.y > 0.0 && d.x.abs() < 1e-6, "{d:?}");
        let up = d.z.clamp(-1.0, 1.0).acos().to_degrees();
        assert!((up - theta).abs() < 1e-3);
        // The rim is at fov / 2; the centre looks along +z.
        let rim = angle_from_axis(&camera, Point2::new(500.0, 1000.0));
        assert!((rim - fov / 2.0).abs() < 1e-3, "{projection:?}: rim {rim}");
        let (_, d) = camera_ray(&camera, Point2::new(500.0, 500.0)).unwrap();
        assert_close3(d, glam::Vec3::Z, 1e-6);
    }
}

/// A 360-degree equidistant lens sees straight back at its rim, and sideways (theta = 90
/// degrees, r = f pi/2 = R/2) half way out; a 360-degree equisolid one too (r = 2 f sin 45 =
/// R / sqrt 2 for theta = 90).
#[test]
fn full_sphere_lenses() {
    let camera = fisheye(
        [400, 400],
        FisheyeProjection::Equidistant,
        360.0,
        [0.0, 0.0],
    );
    let (_, d) = camera_ray(&camera, Point2::new(200.0, 0.0)).unwrap();
    assert_close3(d, -glam::Vec3::Z, 1e-6);
    let (_, d) = camera_ray(&camera, Point2::new(300.0, 200.0)).unwrap();
    assert_close3(d, glam::Vec3::X, 1e-6);
    let camera = fisheye([400, 400], FisheyeProjection::Equisolid, 360.0, [0.0, 0.0]);
    let r = 200.0 / 2f32.sqrt();
    let (_, d) = camera_ray(&camera, Point2::new(200.0 - r, 200.0)).unwrap();
    assert_close3(d, -glam::Vec3::X, 1e-6);
    // Back pole projects onto the rim.
    let eye = camera.world_from_camera().at(0.0);
    let back = eye.point(obscura_space::Point3::new(0.0, 0.0, -3.0));
    let p = camera.project(back, 0.0).unwrap();
    assert!(
        ((p.x - 200.0).hypot(p.y - 200.0) - 200.0).abs() < 1e-3,
        "{p:?}"
    );
}

/// The image circle: its diameter is the smaller dimension, centred, moved against the lens
/// shift (which, +x right and +y up, shifts the view as for the perspective camera); outside it
/// no ray leaves (generate_ray and the differential give None).
#[test]
fn image_circle_and_lens_shift() {
    // 1000 x 500: R = 250. Shift [0.125, 0.25] (exact in binary): the view moves right and
    // up, so the axis lands left of and below the middle: centre (500 - 125, 250 + 125) =
    // (375, 375).
    let camera = fisheye(
        [1000, 500],
        FisheyeProjection::Equidistant,
        180.0,
        [0.125, 0.25],
    );
    let (centre, radius) = camera.image_circle();
    assert_eq!((centre.x, centre.y, radius), (375.0, 375.0, 250.0));
    let (_, d) = camera_ray(&camera, Point2::new(375.0, 375.0)).unwrap();
    assert_close3(d, glam::Vec3::Z, 1e-6);
    // The rim (x = 625) looks along +x (theta = 90 degrees), just past it there is no ray.
    let (_, d) = camera_ray(&camera, Point2::new(625.0, 375.0)).unwrap();
    assert_close3(d, glam::Vec3::X, 1e-6);
    for p in [
        Point2::new(625.01, 375.0),
        Point2::new(375.0, 124.99),
        Point2::new(0.5, 0.5),
        Point2::new(999.5, 499.5),
    ] {
        let sample = CameraSample::at(p);
        assert!(camera.generate_ray(&sample).is_none(), "{p:?}");
        assert!(camera.generate_ray_differential(&sample).is_none());
    }
}

#[test]
fn a_lens_shift_moves_the_fisheye_as_it_moves_the_perspective_camera() {
    // The same shift on a perspective camera moves its screen window right and up, so the
    // picture moves by (-sx W, +sy H) and the optical axis lands at (500 - 125, 250 + 125):
    // where the fisheye's image circle is centred, so both show more to the right and above.
    let (resolution, shift) = ([1000, 500], [0.125, 0.25]);
    let window = ScreenWindow::default_for(resolution)
        .lens_shifted(shift)
        .unwrap();
    let base = base_at(identity_look(), resolution, Some(window), 0.001, 1.0e30);
    let perspective =
        PerspectiveCamera::new(base, 90.0, FovAxis::Smaller, ThinLens::PINHOLE).unwrap();
    let fisheye = fisheye(resolution, FisheyeProjection::Equidistant, 180.0, shift);
    // identity_look: the axis is world -z.
    let axis = Point3::new(0.0, 0.0, -10.0);
    for p in [
        perspective.project(axis, 0.0).unwrap(),
        fisheye.project(axis, 0.0).unwrap(),
    ] {
        assert!(
            (p.x - 375.0).abs() < 1e-3 && (p.y - 375.0).abs() < 1e-3,
            "{p:?}"
        );
    }
}

#[test]
fn validation() {
    let base = || base_at(identity_look(), [64, 48], None, 0.0, 1.0e30);
    let make = |p, fov| FisheyeCamera::new(base(), p, fov, [0.0, 0.0]);
    assert!(make(FisheyeProjection::Equidistant, 360.0).is_ok());
    assert!(make(FisheyeProjection::Equisolid, 360.0).is_ok());
    assert!(make(FisheyeProjection::Stereographic, 359.0).is_ok());
    assert!(make(FisheyeProjection::Orthographic, 179.0).is_ok());
    for (p, fov) in [
        (FisheyeProjection::Equidistant, 360.5),
        (FisheyeProjection::Equisolid, 0.0),
        (FisheyeProjection::Stereographic, 360.0),
        (FisheyeProjection::Orthographic, 180.0),
        (FisheyeProjection::Orthographic, -10.0),
    ] {
        assert!(
            matches!(make(p, fov), Err(CameraError::FisheyeFov { got, .. }) if got == fov),
            "{p:?} {fov}"
        );
    }
    assert!(matches!(
        make(FisheyeProjection::Equidistant, f32::NAN),
        Err(CameraError::NonFinite { what: "fov", .. })
    ));
    assert!(matches!(
        FisheyeCamera::new(
            base(),
            FisheyeProjection::Equidistant,
            90.0,
            [f32::INFINITY, 0.0]
        ),
        Err(CameraError::NonFinite {
            what: "lens_shift",
            ..
        })
    ));
    assert_eq!(
        CameraError::FisheyeFov {
            projection: "orthographic",
            max: 180.0,
            max_inclusive: false,
            got: 180.0
        }
        .to_string(),
        "fov of the orthographic fisheye must be in (0, 180) degrees, got 180"
    );
}

/// A random fisheye: pose, film, projection, a field of view in its range (from 10 degrees;
/// the full 360 included where allowed), lens shift.
fn fisheye_strategy() -> impl Strategy<Value = FisheyeCamera> {
    (
        look_strategy(),
        (1u32..2000, 1u32..2000),
        0usize..4,
        prop_oneof![Just(1.0f32), 0.03f32..1.0],
        (-0.3f32..0.3, -0.3f32..0.3),
    )
        .prop_map(|(look, (w, h), i, fov_frac, shift)| {
            let projection = PROJECTIONS[i];
            // Stereographic and orthographic exclude their maximum: stay below it.
            let max = match projection {
                FisheyeProjection::Equidistant | FisheyeProjection::Equisolid => 360.0,
                FisheyeProjection::Stereographic => 300.0,
                FisheyeProjection::Orthographic => 179.0,
            };
            FisheyeCamera::new(
                base_at(look, [w, h], None, 0.0, 1.0e30),
                projection,
                max * fov_frac,
                [shift.0, shift.1],
            )
            .unwrap()
        })
}

/// The test's own radial derivative `dr/dtheta / f` of each projection, for the round-trip
/// tolerance.
fn radial_derivative(projection: FisheyeProjection, theta: f32) -> f32 {
    match projection {
        FisheyeProjection::Equidistant => 1.0,
        FisheyeProjection::Equisolid => (0.5 * theta).cos(),
        FisheyeProjection::Stereographic => 1.0 / (0.5 * theta).cos().powi(2),
        FisheyeProjection::Orthographic => theta.cos(),
    }
}

proptest! {
    #![proptest_config(crate::cases(4096))]

    /// raster -> ray -> point -> raster, over the whole image circle and its rim. Near the
    /// back pole of a 360-degree lens the whole rim is one direction, so there the directions
    /// are compared instead.
    #[test]
    fn round_trip(
        camera in fisheye_strategy(),
        rho in prop_oneof![Just(1.0f32), Just(0.0), 0f32..1.0],
        psi in 0f32..std::f32::consts::TAU,
        t in 0.5f32..50.0,
    ) {
        let (centre, radius) = camera.image_circle();
        let p = Point2::new(centre.x + rho * radius * psi.cos(), centre.y - rho * radius * psi.sin());
        let Some(main) = camera.generate_ray(&CameraSample::at(p)) else {
            // Only rounding of p at the rim may put it outside.
            prop_assert!(rho == 1.0);
            return Ok(());
        };
        let ray = main.ray;
        prop_assert!((ray.direction.length() - 1.0).abs() < 1e-5);
        let back = camera.project(ray.at(t), 0.0);
        prop_assert!(back.is_some(), "{p:?} did not project back");
        let back = back.unwrap();
        let theta = (rho * radius) as f64 / camera.focal_length();
        let theta = camera.projection().angle(theta) as f32;
        if theta < std::f32::consts::PI - 0.05 {
            // Pixels per radian: radially f r'(theta), tangentially r / sin theta.
            let f = camera.focal_length() as f32;
            let tangential = if theta > 1e-3 { rho * radius / theta.sin() } else { f };
            let per_radian = (f * radial_derivative(camera.projection(), theta)).max(tangential);
            let tol = 2e-3 + per_radian * 4e-6 * (1.0 + 20.0 / t);
            prop_assert!((back.x - p.x).abs() <= tol && (back.y - p.y).abs() <= tol,
                "{back:?} vs {p:?} (tol {tol})");
        } else {
            // (The back pole projects onto the rim, which f32 rounding may put just outside:
            // step inwards by e pixels, 1e-5 of the radius plus a few f32 steps of the
            // raster coordinates.)
            let e = 1e-5 * radius + 4e-7 * (centre.x.abs() + centre.y.abs() + radius);
            let k = 1.0 - e / radius;
            let inward = Point2::new(
                centre.x + (back.x - centre.x) * k,
                centre.y + (back.y - centre.y) * k,
            );
            let again = camera.generate_ray(&CameraSample::at(inward)).unwrap().ray;
            // The raster error 2 e (that step plus f32 rounding of raster positions) is an
            // angle error 2 e / f for equidistant; for equisolid, whose r = 2 f sin(theta / 2)
            // is flat at theta = pi (r = 2 f - f (pi - theta)^2 / 4), it is 2 sqrt(2 e / f).
            let f = camera.focal_length() as f32;
            let e = 2.0 * e;
            let tol = 1e-3 + match camera.projection() {
                FisheyeProjection::Equisolid => 2.0 * (e / f).sqrt(),
                _ => e / f,
            };
            assert_close3(again.direction.to_glam(), ray.direction.to_glam(), tol);
        }
    }

    /// Outside the image circle no ray leaves; world points farther than fov / 2 from the axis
    /// do not project.
    #[test]
    fn nothing_outside_the_circle(
        camera in fisheye_strategy(),
        rho in 1.001f32..3.0,
        psi in 0f32..std::f32::consts::TAU,
    ) {
        let (centre, radius) = camera.image_circle();
        let p = Point2::new(centre.x + rho * radius * psi.cos(), centre.y - rho * radius * psi.sin());
        prop_assume!((p.x - centre.x).hypot(p.y - centre.y) > radius * 1.0001);
        prop_assert!(camera.generate_ray(&CameraSample::at(p)).is_none());
        let half = (camera.fov_degrees() / 2.0) as f32;
        // A direction 1 degree past the rim's angle, if that is still on the sphere.
        if half + 1.0 < 180.0 {
            let theta = (half + 1.0).to_radians();
            let d = glam::Vec3::new(theta.sin() * psi.cos(), theta.sin() * psi.sin(), theta.cos());
            let pose = camera.world_from_camera().at(0.0);
            let q = pose.point(obscura_space::Point3::from_glam(d * 3.0));
            prop_assert!(camera.project(q, 0.0).is_none());
        }
    }

    /// Differentials are the neighbouring rays, inside the circle and at its rim.
    #[test]
    fn differentials(camera in fisheye_strategy(), rho in prop_oneof![Just(1.0f32), 0f32..1.0], psi in 0f32..std::f32::consts::TAU) {
        let (centre, radius) = camera.image_circle();
        let p = Point2::new(centre.x + rho * radius * psi.cos(), centre.y - rho * radius * psi.sin());
        check_neighbours(&camera, p);
    }
}

/// Differentials against the derivative of the direction, well inside the circle.
#[test]
fn differentials_against_finite_differences() {
    for projection in PROJECTIONS {
        let camera = fisheye([640, 480], projection, 170.0, [0.05, -0.05]);
        let (centre, radius) = camera.image_circle();
        for (rho, psi) in [(0.1f32, 0.3f32), (0.5, 2.0), (0.8, 4.0), (0.3, 5.5)] {
            let p = Point2::new(
                centre.x + rho * radius * psi.cos(),
                centre.y - rho * radius * psi.sin(),
            );
            check_derivative(&camera, p, |x, y| {
                camera.direction(Point2::new(x as f32, y as f32)).unwrap()
            });
        }
    }
}

/// At the rim, a neighbour outside the circle is the reflection of the opposite neighbour
/// through the main ray: rx = normalize(2 d(p) - d(p - (1, 0))).
#[test]
fn differential_at_the_rim_reflects_the_inner_neighbour() {
    let camera = fisheye(
        [200, 200],
        FisheyeProjection::Equidistant,
        180.0,
        [0.0, 0.0],
    );
    // The rim's right end (200, 100): the neighbour (201, 100) is outside.
    let p = Point2::new(200.0, 100.0);
    assert!(
        camera
            .generate_ray(&CameraSample::at(Point2::new(201.0, 100.0)))
            .is_none()
    );
    let diff = camera
        .generate_ray_differential(&CameraSample::at(p))
        .unwrap();
    let d = camera
        .generate_ray(&CameraSample::at(p))
        .unwrap()
        .ray
        .direction
        .to_glam();
    let inner = camera
        .generate_ray(&CameraSample::at(Point2::new(199.0, 100.0)))
        .unwrap()
        .ray
        .direction
        .to_glam();
    assert_close3(
        diff.rx_direction.to_glam(),
        (2.0 * d - inner).normalize(),
        1e-6,
    );
    // Theta steps by 1 / f = pi / 200 per pixel: the reflected step is the same size.
    let step = diff.rx_direction.to_glam().angle_between(d);
    assert!((step - std::f32::consts::PI / 200.0).abs() < 1e-4, "{step}");
}

/// A moving camera: the ray of time sample u starts at the eye of time u (shutter [0, 1]).
#[test]
fn moving_pose_is_evaluated_at_the_ray_time() {
    let shutter = obscura_camera::Shutter::new(0.0, 1.0).unwrap();
    let start = identity_look();
    let end = obscura_camera::LookAt::new(
        obscura_space::Point3::new(2.0, 0.0, 0.0),
        obscura_space::Point3::new(2.0, 0.0, -1.0),
        start.up,
    );
    let base = obscura_camera::CameraBase::new(
        obscura_camera::look_at_pose(start, Some(end), shutter).unwrap(),
        shutter,
        obscura_camera::FilmGeometry::new([64, 64], None, None).unwrap(),
    );
    let camera = FisheyeCamera::new(base, FisheyeProjection::Equisolid, 200.0, [0.0, 0.0]).unwrap();
    let sample = CameraSample {
        time: 0.25,
        ..CameraSample::at(Point2::new(32.0, 32.0))
    };
    let ray = camera.generate_ray(&sample).unwrap().ray;
    assert_eq!(ray.time, 0.25);
    assert_close3(ray.origin.to_glam(), glam::Vec3::new(0.5, 0.0, 0.0), 1e-6);
    assert_close3(
        ray.direction.to_glam(),
        glam::Vec3::new(0.0, 0.0, -1.0),
        1e-6,
    );
    let diff = camera.generate_ray_differential(&sample).unwrap();
    assert_eq!(diff.ray, ray);
}
