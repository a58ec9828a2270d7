//! The equal-area octahedral panorama: equal solid angle per pixel, orientation, coverage of
//! the sphere, round trips.

use crate::ray_checks::{camera_ray, check_derivative, check_neighbours};
use crate::{assert_close3, base_at, identity_look, look_strategy, raster_in};
use glam::DVec3;
use obscura_camera::{Camera, CameraError, CameraSample, OctahedralCamera};
use obscura_space::{Point2, Point3, Vector3};
use proptest::prelude::*;

fn octahedral_strategy() -> impl Strategy<Value = OctahedralCamera> {
    (
        look_strategy(),
        1u32..2000,
        prop_oneof![Just(0.0f32), 0.001f32..0.5],
    )
        .prop_map(|(look, n, near)| {
            OctahedralCamera::new(base_at(look, [n, n], None, near, 1.0e30)).unwrap()
        })
}

/// Signed solid angle of the geodesic triangle a, b, c of unit vectors (Van Oosterom and
/// Strackee, "The Solid Angle of a Plane Triangle", IEEE TBME 30(2), 1983).
fn triangle_solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    2.0 * a
        .dot(b.cross(c))
        .atan2(1.0 + a.dot(b) + b.dot(c) + c.dot(a))
}

/// Every pixel of a 16 x 16 image subtends 4 pi / 256 sr within 1%.
///
/// How: each pixel is cut into 32 x 32 sub-squares whose corners are mapped to the sphere;
/// each sub-square counts as the two geodesic triangles on its corners. Interior sub-square
/// edges are shared, so the sum is exactly the area of the geodesic polygon through the 128
/// mapped points of the pixel's boundary. The true pixel region differs from it only by the
/// slivers between each boundary curve and its chord: a chord spans about (pi/16)/32 = 6e-3 rad
/// and the curves bend by O(1) per radian, so each sliver is O(chord^3) ~ 3e-7 sr and the 128
/// of them at most ~4e-5 sr, under 0.1% of a pixel's 4.9e-2 sr. So a 1% tolerance is ten times
/// the quadrature error, while the plain (not equal-area) octahedral map would miss it by far
/// (its pixels vary by more than a factor 2). The pixel areas also sum to 4 pi.
#[test]
fn solid_angle_per_pixel_is_equal() {
    let (n, sub) = (16usize, 32usize);
    let expected = 4.0 * std::f64::consts::PI / (n * n) as f64;
    let square = |i: usize, k: usize| -1.0 + 2.0 * (i * sub + k) as f64 / (n * sub) as f64;
    let mut total = 0.0;
    for py in 0..n {
        for px in 0..n {
            let mut area = 0.0;
            for j in 0..sub {
                for i in 0..sub {
                    let (u0, u1) = (square(px, i), square(px, i + 1));
                    let (v0, v1) = (square(py, j), square(py, j + 1));
                    let a = OctahedralCamera::square_to_sphere(u0, v0);
                    let b = OctahedralCamera::square_to_sphere(u1, v0);
                    let c = OctahedralCamera::square_to_sphere(u1, v1);
                    let d = OctahedralCamera::square_to_sphere(u0, v1);
                    area += triangle_solid_angle(a, b, c) + triangle_solid_angle(a, c, d);
                }
            }
            let area = area.abs();
            assert!(
                (area / expected - 1.0).abs() < 0.01,
                "pixel ({px}, {py}): {area} sr vs {expected}"
            );
            total += area;
        }
    }
    assert!((total - 4.0 * std::f64::consts::PI).abs() < 1e-9, "{total}");
}

/// The camera's own rays, on a 64 x 64 film, agree with the map: the centre looks forward,
/// the middle of the right edge right, of the top edge up, of the left edge left, of the bottom
/// edge down (all on the diamond |u| + |v| = 1, so z = 0), the corners straight back; the
/// diamond's edge midpoints (u, v) = (1/2, 1/2) look at (1, 1, 0) / sqrt 2.
#[test]
fn orientation() {
    let camera =
        OctahedralCamera::new(base_at(identity_look(), [64, 64], None, 0.0, 1e30)).unwrap();
    let s = 0.5f32.sqrt();
    let cases = [
        ((32.0, 32.0), glam::Vec3::Z),
        ((64.0, 32.0), glam::Vec3::X),
        ((32.0, 0.0), glam::Vec3::Y),
        ((0.0, 32.0), -glam::Vec3::X),
        ((32.0, 64.0), -glam::Vec3::Y),
        ((0.0, 0.0), -glam::Vec3::Z),
        ((64.0, 64.0), -glam::Vec3::Z),
        ((48.0, 16.0), glam::Vec3::new(s, s, 0.0)),
        ((16.0, 48.0), glam::Vec3::new(-s, -s, 0.0)),
    ];
    for ((x, y), expected) in cases {
        let (origin, d) = camera_ray(&camera, Point2::new(x, y)).unwrap();
        assert_close3(d, expected, 1e-6);
        assert_close3(origin, glam::Vec3::ZERO, 1e-6);
    }
}

#[test]
fn refuses_non_square_films() {
    assert_eq!(
        OctahedralCamera::new(base_at(identity_look(), [64, 32], None, 0.0, 1e30)).unwrap_err(),
        CameraError::FilmShape {
            model: "octahedral",
            need: "a square",
            got: [64, 32]
        }
    );
    assert_eq!(
        CameraError::FilmShape {
            model: "octahedral",
            need: "a square",
            got: [64, 32]
        }
        .to_string(),
        "the octahedral camera needs a square film, got 64 x 32"
    );
}

proptest! {
    #![proptest_config(crate::cases(4096))]

    /// raster -> ray -> point -> raster. The map turns at least 1.11 rad per unit of the
    /// [-1, 1]^2 square in every direction (radially d theta / dr = 2 / sqrt(2 - r^2) >= sqrt 2,
    /// along a diamond sqrt(2 - r^2) pi / (2 sqrt 2) >= 1.11), so an angular error e moves the
    /// raster point by at most e W / 2 / 1.11 < 0.5 W e. On the square's border, which folds
    /// onto itself, the ray of the returned point is compared instead.
    #[test]
    fn round_trip(
        camera in octahedral_strategy(),
        fx in prop_oneof![Just(0.0f32), Just(1.0), Just(0.5), 0f32..1.0],
        fy in prop_oneof![Just(0.0f32), Just(1.0), Just(0.5), 0f32..1.0],
        t in 0.5f32..50.0,
    ) {
        let res = camera.film().resolution();
        let width = res[0] as f32;
        let p = raster_in(res, fx, fy);
        let ray = camera.generate_ray(&CameraSample::at(p)).unwrap().ray;
        prop_assert!((ray.direction.length() - 1.0).abs() < 1e-5);
        let back = camera.project(ray.at(t), 0.0).unwrap();
        let on_border = [fx, fy].iter().any(|&f| f == 0.0 || f == 1.0);
        if on_border {
            let again = camera.generate_ray(&CameraSample::at(back)).unwrap().ray;
            assert_close3(again.direction.to_glam(), ray.direction.to_glam(), 1e-4);
        } else {
            let tol = 2e-3 + 0.5 * width * 4e-6 * (1.0 + 20.0 / t);
            prop_assert!((back.x - p.x).abs() <= tol && (back.y - p.y).abs() <= tol,
                "{back:?} vs {p:?} (tol {tol})");
        }
    }

    /// Every direction projects into the image, and the ray there looks that way.
    #[test]
    fn covers_the_sphere(camera in octahedral_strategy(), w in (-1f32..1.0, -1f32..1.0, -1f32..1.0)) {
        let w = glam::Vec3::new(w.0, w.1, w.2);
        prop_assume!(w.length() > 0.1);
        let d_world = Vector3::from_glam(w.normalize());
        let eye = camera.world_from_camera().at(0.0).point(Point3::ORIGIN);
        let p = camera.project(eye + d_world * 5.0, 0.0).unwrap();
        let n = camera.film().resolution()[0] as f32;
        prop_assert!(p.x >= 0.0 && p.x <= n && p.y >= 0.0 && p.y <= n, "{p:?}");
        let ray = camera.generate_ray(&CameraSample::at(p)).unwrap().ray;
        assert_close3(ray.direction.to_glam(), d_world.to_glam(), 1e-4);
    }

    /// Differentials are the neighbouring rays (past the border: the fold's continuation).
    #[test]
    fn differentials(camera in octahedral_strategy(), fx in 0f32..1.0, fy in 0f32..1.0) {
        check_neighbours(&camera, raster_in(camera.film().resolution(), fx, fy));
    }
}

/// Differentials against the derivative of the direction, away from the map's creases (the
/// axes u = 0, v = 0, and the diamond |u| + |v| = 1).
#[test]
fn differentials_against_finite_differences() {
    let camera =
        OctahedralCamera::new(base_at(identity_look(), [256, 256], None, 0.0, 1e30)).unwrap();
    for (x, y) in [
        (150.3, 100.2),
        (40.0, 60.0),
        (200.5, 220.5),
        (100.0, 180.0),
        (10.0, 240.0),
    ] {
        check_derivative(&camera, Point2::new(x, y), |x, y| {
            camera.direction(Point2::new(x as f32, y as f32))
        });
    }
}
