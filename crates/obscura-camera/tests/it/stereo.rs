//! Off-axis stereo and lens shift: the convergence plane has zero parallax, a point at infinity
//! has the parallax of the interaxial over the frustum's width there, and a lens shift moves the
//! image by the stated fraction without bending it.

use crate::{base_at, cases, identity_look, look_strategy};
use obscura_camera::{
    Camera, FovAxis, LookAt, PerspectiveCamera, ScreenWindow, StereoEye, StereoRig, ThinLens,
};
use obscura_space::{Point3, Vector3};
use proptest::prelude::*;

/// One eye of a perspective rig at `look`, fov along the smaller axis, `resolution`.
fn eye_camera(
    rig: StereoRig,
    eye: StereoEye,
    look: LookAt,
    fov: f32,
    resolution: [u32; 2],
) -> PerspectiveCamera {
    let window = ScreenWindow::default_for(resolution);
    let eye_look = rig.eye_look_at(eye, look).unwrap();
    let eye_window = rig
        .eye_window(eye, window, fov, FovAxis::Smaller, resolution)
        .unwrap();
    let base = base_at(eye_look, resolution, Some(eye_window), 0.001, 1e30);
    PerspectiveCamera::new(base, fov, FovAxis::Smaller, ThinLens::PINHOLE).unwrap()
}

/// The world point at camera-space `(x, y, z)` of the rig centre at `look` (camera +x = right,
/// +y = true up, +z = the view).
fn rig_point(look: LookAt, x: f32, y: f32, z: f32) -> Point3<obscura_space::World> {
    let dir = (look.target - look.eye).to_glam().normalize();
    let right = dir.cross(look.up.to_glam()).normalize();
    let up = right.cross(dir);
    look.eye + Vector3::from_glam(right * x + up * y + dir * z)
}

proptest! {
    #![proptest_config(cases(2000))]

    /// Points on the convergence plane land on the same raster position in both eyes.
    #[test]
    fn convergence_plane_has_zero_parallax(
        look in look_strategy(),
        interaxial in 0.0f32..2.0,
        convergence in 0.5f32..50.0,
        fov in 20.0f32..120.0,
        fx in -0.9f32..0.9,
        fy in -0.9f32..0.9,
    ) {
        let rig = StereoRig::new(interaxial, convergence).unwrap();
        let resolution = [320, 200];
        let left = eye_camera(rig, StereoEye::Left, look, fov, resolution);
        let right = eye_camera(rig, StereoEye::Right, look, fov, resolution);
        // A point inside the frustum at depth C: screen half-extents tan(fov/2) * (a, 1) there.
        let t = (0.5 * fov).to_radians().tan() * convergence;
        let p = rig_point(look, fx * 1.6 * t, fy * t, convergence);
        let (l, r) = (left.project(p, 0.0).unwrap(), right.project(p, 0.0).unwrap());
        let tol = 2e-3 * (1.0 + interaxial * 100.0 / convergence);
        prop_assert!((l.x - r.x).abs() < tol && (l.y - r.y).abs() < tol, "{l:?} {r:?}");
    }
}

/// Worked by hand: 400 x 200, fov 90 along the smaller axis (y), so s = 1 / tan 45 = 1 and
/// the window is [-2, 2] x [-1, 1]. At the convergence distance C = 5 the frustum is
/// 4 C = 20 wide; the interaxial b = 0.5 is 0.5 / 20 of it, 10 pixels of 400. The left eye
/// sees a point straight ahead at infinity 5 pixels left of centre, the right eye 5 right.
#[test]
fn parallax_at_infinity_is_the_interaxial_over_the_screen_width() {
    let rig = StereoRig::new(0.5, 5.0).unwrap();
    let look = identity_look();
    let left = eye_camera(rig, StereoEye::Left, look, 90.0, [400, 200]);
    let right = eye_camera(rig, StereoEye::Right, look, 90.0, [400, 200]);
    let far = Point3::new(0.0, 0.0, -1.0e7);
    let (l, r) = (
        left.project(far, 0.0).unwrap(),
        right.project(far, 0.0).unwrap(),
    );
    assert!((l.x - 195.0).abs() < 1e-2, "{l:?}");
    assert!((r.x - 205.0).abs() < 1e-2, "{r:?}");
    assert!((l.y - 100.0).abs() < 1e-3 && (r.y - 100.0).abs() < 1e-3);
}

/// The eyes sit interaxial apart along camera +x, left eye on the left, views parallel.
#[test]
fn eyes_are_offset_along_camera_right() {
    let rig = StereoRig::new(0.4, 3.0).unwrap();
    let look = identity_look();
    let l = rig.eye_look_at(StereoEye::Left, look).unwrap();
    let r = rig.eye_look_at(StereoEye::Right, look).unwrap();
    assert_eq!(l.eye, Point3::new(-0.2, 0.0, 0.0));
    assert_eq!(r.eye, Point3::new(0.2, 0.0, 0.0));
    assert_eq!(l.target - l.eye, look.target - look.eye);
    assert_eq!(r.target - r.eye, look.target - look.eye);
}

#[test]
fn rig_validation() {
    assert!(StereoRig::new(-0.1, 1.0).is_err());
    assert!(StereoRig::new(0.1, 0.0).is_err());
    assert!(StereoRig::new(f32::NAN, 1.0).is_err());
    assert!(StereoRig::new(0.0, 1.0).is_ok());
}

proptest! {
    #![proptest_config(cases(2000))]

    /// A lens shift [sx, sy] moves every projected point by (sx W, -sy H) pixels: +y up in the
    /// shift is raster -y, and the content moves the other way (the window moves up, so what it
    /// shows moves down in the image: +sy H in raster y). Straight lines stay straight because
    /// the map is the unshifted one plus a constant.
    #[test]
    fn lens_shift_translates_the_image(
        sx in -0.5f32..0.5,
        sy in -0.5f32..0.5,
        x in -1.0f32..1.0,
        y in -1.0f32..1.0,
        z in 1.0f32..20.0,
    ) {
        let resolution = [300, 200];
        let look = identity_look();
        let window = ScreenWindow::default_for(resolution);
        let plain = PerspectiveCamera::new(
            base_at(look, resolution, Some(window), 0.001, 1e30), 60.0, FovAxis::Smaller,
            ThinLens::PINHOLE).unwrap();
        let shifted_window = window.lens_shifted([sx, sy]).unwrap();
        let shifted = PerspectiveCamera::new(
            base_at(look, resolution, Some(shifted_window), 0.001, 1e30), 60.0, FovAxis::Smaller,
            ThinLens::PINHOLE).unwrap();
        let p = Point3::new(x * z, y * z, -z);
        let (a, b) = (plain.project(p, 0.0).unwrap(), shifted.project(p, 0.0).unwrap());
        prop_assert!((b.x - (a.x - sx * 300.0)).abs() < 2e-2, "{a:?} {b:?}");
        prop_assert!((b.y - (a.y + sy * 200.0)).abs() < 2e-2, "{a:?} {b:?}");
    }
}
