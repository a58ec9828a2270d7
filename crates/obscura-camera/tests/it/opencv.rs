//! The OpenCV models: hand-computed pixels from the published formulas (cv::projectPoints and
//! cv::fisheye::projectPoints) for every distortion length, the rvec/tvec pose, round trips
//! raster -> ray -> point -> raster, Newton's inverse, the fold, differentials.
//!
//! All hand-computed cases use fx = 500, fy = 400, cx = 320, cy = 240 on a 640 x 480 film and
//! the scene format's look-at example (eye at the origin, looking down world -z, y up), so an
//! OpenCV camera point (X, Y, Z) (y down) is the world point (X, -Y, -Z).

use crate::{assert_close2, base_at, identity_look, look_strategy};
use glam::{DVec2, DVec3};
use obscura_camera::{
    AnyCamera, Camera, CameraBase, CameraError, CameraSample, OpenCvCamera, OpenCvFisheyeCamera,
    OpenCvIntrinsics, Shutter, look_at_pose, opencv_pose,
};
use obscura_space::{Point2, Point3, Raster, Transform, World};
use proptest::prelude::*;

const K: OpenCvIntrinsics = OpenCvIntrinsics {
    fx: 500.0,
    fy: 400.0,
    cx: 320.0,
    cy: 240.0,
};

fn base() -> CameraBase {
    base_at(identity_look(), [640, 480], None, 0.001, 1.0e30)
}

fn pinhole(distortion: &[f64]) -> OpenCvCamera {
    OpenCvCamera::new(base(), K, distortion).unwrap()
}

fn fisheye(distortion: &[f64]) -> OpenCvFisheyeCamera {
    OpenCvFisheyeCamera::new(base(), K, distortion).unwrap()
}

/// The world point of OpenCV camera point (X, Y, Z) under the identity look-at.
fn cv_world(x: f32, y: f32, z: f32) -> Point3<World> {
    Point3::new(x, -y, -z)
}

/// Checks `project` (f32) and `project_camera` (f64) of OpenCV camera point `p` against the
/// hand-computed raster position.
#[track_caller]
fn check_pixel(camera: &AnyCamera, p: [f64; 3], raster: [f64; 2]) {
    let world = cv_world(p[0] as f32, p[1] as f32, p[2] as f32);
    let got = camera.project(world, 0.0).unwrap();
    // f32 raster positions near 500 are exact to ~3e-5.
    assert_close2(
        glam::Vec2::new(got.x, got.y),
        glam::Vec2::new(raster[0] as f32, raster[1] as f32),
        2e-4,
    );
    // In f64 through the model alone (Obscura camera frame: y flipped).
    let camera_p = DVec3::new(p[0], -p[1], p[2]);
    let got = match camera {
        AnyCamera::OpenCv(c) => c.project_camera(camera_p),
        AnyCamera::OpenCvFisheye(c) => c.project_camera(camera_p),
        _ => unreachable!(),
    }
    .unwrap();
    assert!(
        (got - DVec2::from(raster)).abs().max_element() < 1e-9,
        "{got:?} vs {raster:?}"
    );
    // And the ray through the hand-computed pixel looks at the point.
    let ray = camera
        .generate_ray(&CameraSample::at(Point2::new(
            raster[0] as f32,
            raster[1] as f32,
        )))
        .unwrap()
        .ray;
    let expected = world.to_glam().normalize();
    crate::assert_close3(ray.direction.to_glam(), expected, 2e-6);
}

/// Four coefficients k1 = -0.2, k2 = 0.05, p1 = 0.001, p2 = -0.002.
#[test]
fn hand_computed_four_coefficients() {
    let camera: AnyCamera = pinhole(&[-0.2, 0.05, 0.001, -0.002]).into();
    // (0.5, 0.25, 1): x' = 0.5, y' = 0.25, r^2 = 0.3125, r^4 = 0.09765625;
    // c = 1 - 0.2 * 0.3125 + 0.05 * 0.09765625 = 1 - 0.0625 + 0.0048828125 = 0.9423828125.
    // x'' = 0.5 c + 2 p1 x'y' + p2 (r^2 + 2 x'^2)
    //     = 0.47119140625 + 0.00025 - 0.002 * 0.8125 = 0.47119140625 + 0.00025 - 0.001625
    //     = 0.46981640625;
    // y'' = 0.25 c + p1 (r^2 + 2 y'^2) + 2 p2 x'y'
    //     = 0.235595703125 + 0.001 * 0.4375 - 0.0005 = 0.235533203125.
    // u = 500 x'' + 320 = 554.908203125, v = 400 y'' + 240 = 334.21328125; raster +0.5.
    check_pixel(&camera, [0.5, 0.25, 1.0], [555.408203125, 334.71328125]);
    // (-0.3, 0.4, 2): x' = -0.15, y' = 0.2, r^2 = 0.0625, r^4 = 0.00390625;
    // c = 1 - 0.0125 + 0.0001953125 = 0.9876953125.
    // x'' = -0.15 c + 2 (0.001)(-0.15)(0.2) - 0.002 (0.0625 + 0.045)
    //     = -0.148154296875 - 0.00006 - 0.000215 = -0.148429296875;
    // y'' = 0.2 c + 0.001 (0.0625 + 0.08) + 2 (-0.002)(-0.15)(0.2)
    //     = 0.1975390625 + 0.0001425 + 0.00012 = 0.1978015625.
    // u = -74.2146484375 + 320 = 245.7853515625, v = 79.120625 + 240 = 319.120625.
    check_pixel(&camera, [-0.3, 0.4, 2.0], [246.2853515625, 319.620625]);
    // On the axis: no distortion, the principal point.
    check_pixel(&camera, [0.0, 0.0, 3.0], [320.5, 240.5]);
}

/// Five coefficients: the same plus k3 = -0.01.
#[test]
fn hand_computed_five_coefficients() {
    let camera: AnyCamera = pinhole(&[-0.2, 0.05, 0.001, -0.002, -0.01]).into();
    // (0.5, 0.25, 1): r^6 = 0.030517578125, so c = 0.9423828125 - 0.00030517578125
    // = 0.94207763671875. x'' = 0.5 c + 0.00025 - 0.001625 = 0.469663818359375;
    // y'' = 0.25 c + 0.0004375 - 0.0005 = 0.2354569091796875.
    // u = 234.8319091796875 + 320, v = 94.182763671875 + 240; raster +0.5.
    check_pixel(
        &camera,
        [0.5, 0.25, 1.0],
        [555.3319091796875, 334.682763671875],
    );
    // (-0.3, 0.4, 2): r^6 = 0.000244140625, c = 0.9876953125 - 0.00000244140625
    // = 0.98769287109375. x'' = -0.15 c - 0.00006 - 0.000215 = -0.1484289306640625;
    // y'' = 0.2 c + 0.0001425 + 0.00012 = 0.19780107421875.
    // u = -74.21446533203125 + 320 = 245.78553466796875, v = 79.1204296875 + 240.
    check_pixel(
        &camera,
        [-0.3, 0.4, 2.0],
        [246.28553466796875, 319.6204296875],
    );
}

/// Eight coefficients (rational model): k1 = 0.1, k2 = 0.01, p = 0, k3 = 0.001, k4 = 0.3,
/// k5 = 0.02, k6 = 0.001.
#[test]
fn hand_computed_eight_coefficients() {
    let camera: AnyCamera = pinhole(&[0.1, 0.01, 0.0, 0.0, 0.001, 0.3, 0.02, 0.001]).into();
    // (0.5, 0.25, 1): r^2 = 0.3125, r^4 = 0.09765625, r^6 = 0.030517578125.
    // N = 1 + 0.03125 + 0.0009765625 + 0.000030517578125 = 1.032257080078125;
    // D = 1 + 0.09375 + 0.001953125 + 0.000030517578125 = 1.095733642578125;
    // c = N / D = 0.94206934967...; x'' = 0.5 c = 0.4710346748363738, y'' = 0.25 c
    // = 0.2355173374181869. u = 235.5173374181869 + 320, v = 94.20693496727476 + 240.
    check_pixel(
        &camera,
        [0.5, 0.25, 1.0],
        [556.0173374181869, 334.7069349672748],
    );
    // (-0.3, 0.4, 2): r^2 = 0.0625, r^4 = 0.00390625, r^6 = 0.000244140625.
    // N = 1 + 0.00625 + 0.0000390625 + 0.000000244140625 = 1.006289306640625;
    // D = 1 + 0.01875 + 0.000078125 + 0.000000244140625 = 1.018828369140625;
    // c = 0.98769266455...; x'' = -0.15 c = -0.1481538996832347, y'' = 0.2 c
    // = 0.19753853291097961. u = -74.07694984161735 + 320, v = 79.01541316439184 + 240.
    check_pixel(
        &camera,
        [-0.3, 0.4, 2.0],
        [246.42305015838264, 319.5154131643918],
    );
}

/// Twelve coefficients (rational + thin prism): k1 = -0.1, k2 = 0.02, p1 = 0.001, p2 =
/// 0.002, k3 = 0, k4 = 0.05, k5 = k6 = 0, s1 = 0.001, s2 = 0.0005, s3 = -0.002, s4 = 0.0003.
#[test]
fn hand_computed_twelve_coefficients() {
    let camera: AnyCamera = pinhole(&[
        -0.1, 0.02, 0.001, 0.002, 0.0, 0.05, 0.0, 0.0, 0.001, 0.0005, -0.002, 0.0003,
    ])
    .into();
    // (0.5, 0.25, 1): r^2 = 0.3125, r^4 = 0.09765625.
    // N = 1 - 0.03125 + 0.001953125 = 0.970703125; D = 1 + 0.015625 = 1.015625;
    // c = 0.9557692307692308.
    // x'' = 0.5 c + 2 p1 x'y' (0.00025) + p2 (r^2 + 2 x'^2) (0.002 * 0.8125 = 0.001625)
    //     + s1 r^2 + s2 r^4 (0.0003125 + 0.000048828125 = 0.000361328125)
    //     = 0.4778846153846154 + 0.002236328125 = 0.48012094350961537;
    // y'' = 0.25 c + p1 (r^2 + 2 y'^2) (0.0004375) + 2 p2 x'y' (0.0005)
    //     + s3 r^2 + s4 r^4 (-0.000625 + 0.000029296875 = -0.000595703125)
    //     = 0.2389423076923077 + 0.000341796875 = 0.23928410456730773.
    // u = 240.06047175480768 + 320, v = 95.71364182692309 + 240; raster +0.5.
    check_pixel(
        &camera,
        [0.5, 0.25, 1.0],
        [560.5604717548076, 336.2136418269231],
    );
    // (-0.3, 0.4, 2): x' = -0.15, y' = 0.2, r^2 = 0.0625, r^4 = 0.00390625.
    // N = 1 - 0.00625 + 0.000078125 = 0.993828125; D = 1.003125; c = 0.9907320872274143.
    // x'' = -0.15 c (-0.14860981308411215) - 0.00006 + 0.002 * 0.1075 (0.000215)
    //     + 0.001 * 0.0625 + 0.0005 * 0.00390625 (0.000064453125) = -0.14839035995911215;
    // y'' = 0.2 c (0.19814641744548287) + 0.001 * 0.1425 (0.0001425) + 2 (0.002)(-0.03)
    //     (-0.00012) - 0.002 * 0.0625 + 0.0003 * 0.00390625 (-0.000123828125)
    //     = 0.1980450893204829.
    // u = -74.19517997955608 + 320, v = 79.21803572819316 + 240; raster +0.5.
    check_pixel(
        &camera,
        [-0.3, 0.4, 2.0],
        [246.3048200204439, 319.7180357281932],
    );
}

/// Kannala-Brandt with k = (0.1, -0.02, 0.003, -0.0004), and a wide one past 90 degrees.
#[test]
fn hand_computed_fisheye() {
    let camera: AnyCamera = fisheye(&[0.1, -0.02, 0.003, -0.0004]).into();
    // (0.5, 0.25, 1): r = sqrt(0.3125) = 0.5590169943749475, theta = atan2(r, 1)
    // = 0.509739678831507, theta^2 = 0.2598345401752479;
    // 1 + 0.1 t^2 - 0.02 t^4 + 0.003 t^6 - 0.0004 t^8 = 1 + 0.02598345 - 0.00135028
    // + 0.00005263 - 0.00000182 = 1.0246839783950092; theta_d = 0.5223220820508628;
    // x' = theta_d / r * 0.5 = 0.4671790726459808, y' = 0.2335895363229904.
    // u = 233.5895363229904 + 320, v = 93.43581452919616 + 240; raster +0.5.
    check_pixel(
        &camera,
        [0.5, 0.25, 1.0],
        [554.0895363229904, 333.93581452919614],
    );

    let wide: AnyCamera = fisheye(&[0.02, -0.003, 0.0002, -0.00001]).into();
    // Behind the camera, (1, 0, -1): r = 1, theta = atan2(1, -1) = 3 pi / 4 = 2.356194490192345,
    // theta^2 = 5.551652475612764; 1 + 0.02 t^2 - 0.003 t^4 + 0.0002 t^6 - 0.00001 t^8
    // = 1 + 0.11103305 - 0.09246252 + 0.03422155 - 0.00949949 = 1.0432925932098391;
    // theta_d = 2.4582002597795065 = x' (y' = 0). u = 1229.1001298897532 + 320, v = 240.
    check_pixel(&wide, [1.0, 0.0, -1.0], [1549.6001298897534, 240.5]);
    // In the image plane, (0, -2, 0): theta = pi / 2, theta^2 = 2.4674011002723395;
    // 1 + 0.04934802 - 0.01826431 + 0.00300456 - 0.00037076 = 1.0337175129236789;
    // theta_d = 1.6237596722440708; y' = theta_d / 2 * (-2) = -1.6237596722440708.
    // v = -649.5038688976283 + 240 = -409.5038688976283; raster +0.5.
    check_pixel(&wide, [0.0, -2.0, 0.0], [320.5, -409.0038688976283]);
}

/// rvec/tvec: a quarter turn about OpenCV z and a translation, worked by hand; the pose that
/// equals the identity look-at; and any rvec/tvec against an independent rotation.
#[test]
fn rvec_tvec_pose_by_hand() {
    let shutter = Shutter::new(0.0, 1.0).unwrap();
    let film = obscura_camera::FilmGeometry::new([640, 480], None, None).unwrap();
    let pose = opencv_pose([0.0, 0.0, core::f64::consts::FRAC_PI_2], [0.1, -0.2, 3.0]).unwrap();
    let camera = OpenCvCamera::new(CameraBase::new(pose, shutter, film), K, &[0.0; 4]).unwrap();
    // World (0.25, -0.5, 0): R turns (x, y) into (-y, x): (0.5, 0.25, 0); + t = (0.6, 0.05, 3).
    // u = 500 * 0.6 / 3 + 320 = 420, v = 400 * 0.05 / 3 + 240 = 246.666...; raster +0.5.
    let p = camera.project(Point3::new(0.25, -0.5, 0.0), 0.0).unwrap();
    assert_close2(
        glam::Vec2::new(p.x, p.y),
        glam::Vec2::new(420.5, 240.5 + 20.0 / 3.0),
        2e-4,
    );
    // The camera centre is -R^T t: R^T (0.1, -0.2, 3) = (-0.2, -0.1, 3), so the eye is at
    // (0.2, 0.1, -3).
    let ray = camera
        .generate_ray(&CameraSample::at(Point2::new(100.0, 100.0)))
        .unwrap()
        .ray;
    crate::assert_close3(ray.origin.to_glam(), glam::Vec3::new(0.2, 0.1, -3.0), 1e-6);

    // rvec = (pi, 0, 0) turns world (x, y, z) into OpenCV (x, -y, -z): the identity look-at.
    let cv = opencv_pose([core::f64::consts::PI, 0.0, 0.0], [0.0; 3]).unwrap();
    let look = look_at_pose(identity_look(), None, shutter).unwrap();
    let (a, b) = (cv.at(0.0).matrix(), look.at(0.0).matrix());
    assert!(a.abs_diff_eq(b, 1e-6), "{a:?} vs {b:?}");
    assert!(cv.at(0.0).swaps_handedness());
}

proptest! {
    #![proptest_config(crate::cases(2000))]

    /// Any rvec/tvec: `project` equals the pinhole formula applied to `R X + t` with R built
    /// independently (obscura-space's axis-angle rotation).
    #[test]
    fn rvec_tvec_pose_matches_rotation(
        r in (-3f64..3.0, -3f64..3.0, -3f64..3.0),
        t in (-1f64..1.0, -1f64..1.0, 4f64..6.0),
        x in (-1f32..1.0, -1f32..1.0, -1f32..1.0),
    ) {
        let rvec = DVec3::new(r.0, r.1, r.2);
        prop_assume!(rvec.length() > 1e-3);
        let shutter = Shutter::new(0.0, 1.0).unwrap();
        let film = obscura_camera::FilmGeometry::new([640, 480], None, None).unwrap();
        let pose = opencv_pose([r.0, r.1, r.2], [t.0, t.1, t.2]).unwrap();
        let camera = OpenCvCamera::new(CameraBase::new(pose, shutter, film), K, &[0.0; 4]).unwrap();
        let rotation = Transform::<World, World>::rotate(
            rvec.length().to_degrees() as f32,
            rvec.as_vec3(),
        ).unwrap();
        let world = Point3::<World>::new(x.0, x.1, x.2);
        let cv = rotation.point(world).to_glam().as_dvec3() + DVec3::new(t.0, t.1, t.2);
        let expected = (K.fx * cv.x / cv.z + K.cx + 0.5, K.fy * cv.y / cv.z + K.cy + 0.5);
        let got = camera.project(world, 0.0).unwrap();
        // f32 rotation and pose: ~1e-6 relative over a depth >= 2.2, times 500 px.
        prop_assert!((f64::from(got.x) - expected.0).abs() < 5e-3, "{got:?} vs {expected:?}");
        prop_assert!((f64::from(got.y) - expected.1).abs() < 5e-3, "{got:?} vs {expected:?}");
    }
}

/// Random distortion coefficients of each length, moderate enough that the image is mostly
/// inside the fold and strong enough to fold in some images.
fn distortion_strategy() -> impl Strategy<Value = Vec<f64>> {
    let base = || (-0.5f64..0.5, -0.1f64..0.1, -0.01f64..0.01, -0.01f64..0.01);
    prop_oneof![
        base().prop_map(|(k1, k2, p1, p2)| vec![k1, k2, p1, p2]),
        (base(), -0.05f64..0.05).prop_map(|((k1, k2, p1, p2), k3)| vec![k1, k2, p1, p2, k3]),
        (
            base(),
            -0.05f64..0.05,
            (-0.2f64..0.5, -0.05f64..0.05, -0.01f64..0.01)
        )
            .prop_map(|((k1, k2, p1, p2), k3, (k4, k5, k6))| vec![k1, k2, p1, p2, k3, k4, k5, k6]),
        (
            base(),
            -0.05f64..0.05,
            (-0.2f64..0.5, -0.05f64..0.05, -0.01f64..0.01),
            (
                -0.005f64..0.005,
                -0.005f64..0.005,
                -0.005f64..0.005,
                -0.005f64..0.005
            )
        )
            .prop_map(|((k1, k2, p1, p2), k3, (k4, k5, k6), (s1, s2, s3, s4))| {
                vec![k1, k2, p1, p2, k3, k4, k5, k6, s1, s2, s3, s4]
            }),
    ]
}

/// Random intrinsics for a film of `res`: fx in [200, 1000], fy within 25% of it, the
/// principal point within 10% of the centre.
fn intrinsics_strategy(res: [u32; 2]) -> impl Strategy<Value = OpenCvIntrinsics> {
    (200f64..1000.0, 0.8f64..1.25, -0.1f64..0.1, -0.1f64..0.1).prop_map(move |(fx, a, ox, oy)| {
        let (w, h) = (f64::from(res[0]), f64::from(res[1]));
        OpenCvIntrinsics {
            fx,
            fy: fx * a,
            cx: w * (0.5 + ox) - 0.5,
            cy: h * (0.5 + oy) - 0.5,
        }
    })
}

fn film_strategy() -> impl Strategy<Value = [u32; 2]> {
    (16u32..1600, 16u32..1600).prop_map(|(w, h)| [w, h])
}

fn opencv_strategy() -> impl Strategy<Value = OpenCvCamera> {
    (look_strategy(), film_strategy())
        .prop_flat_map(|(look, res)| {
            (
                Just(look),
                Just(res),
                intrinsics_strategy(res),
                distortion_strategy(),
            )
        })
        .prop_map(|(look, res, k, d)| {
            OpenCvCamera::new(base_at(look, res, None, 0.001, 1.0e30), k, &d).unwrap()
        })
}

fn fisheye_strategy() -> impl Strategy<Value = OpenCvFisheyeCamera> {
    (
        look_strategy(),
        film_strategy(),
        (
            -0.3f64..0.3,
            -0.05f64..0.05,
            -0.01f64..0.01,
            -0.002f64..0.002,
        ),
    )
        .prop_flat_map(|(look, res, k)| (Just(look), Just(res), intrinsics_strategy(res), Just(k)))
        .prop_map(|(look, res, mut i, k)| {
            // Fisheye focal lengths are smaller: 200 px per radian and below cover wide angles.
            i.fx *= 0.4;
            i.fy *= 0.4;
            OpenCvFisheyeCamera::new(
                base_at(look, res, None, 0.001, 1.0e30),
                i,
                &[k.0, k.1, k.2, k.3],
            )
            .unwrap()
        })
}

/// A fraction along an image axis, the edges (0 and 1) included on purpose.
fn edge_or_inside() -> impl Strategy<Value = f32> {
    prop_oneof![1 => Just(0.0f32), 1 => Just(1.0f32), 8 => 0f32..1.0]
}

fn raster(res: [u32; 2], fx: f32, fy: f32) -> Point2<Raster> {
    Point2::new(fx * res[0] as f32, fy * res[1] as f32)
}

/// The re-projection error in pixels of an f64 camera-space direction.
fn reprojection_px(raster: Point2<Raster>, back: DVec2) -> f64 {
    (back - DVec2::new(f64::from(raster.x), f64::from(raster.y)))
        .abs()
        .max_element()
}

proptest! {
    #![proptest_config(crate::cases(3000))]

    /// raster -> ray -> point -> raster. In f64 through the model, the stated tolerance: the
    /// ray re-projects within 1e-4 px. In f32 through the world (pose, ray, point at distance
    /// t, project), within the rounding of f32 directions times pixels per radian.
    #[test]
    fn opencv_round_trip(camera in opencv_strategy(), fx in edge_or_inside(), fy in edge_or_inside(), t in 1f32..20.0) {
        let res = camera.film().resolution();
        let p = raster(res, fx, fy);
        if let Some(d) = camera.direction(p) {
            prop_assert!((d.length() - 1.0).abs() < 1e-12);
            let back64 = camera.project_camera(d * 3.0).unwrap();
            prop_assert!(reprojection_px(p, back64) < 1e-4, "{p:?} -> {back64:?}");

            let ray = camera.generate_ray(&CameraSample::at(p)).unwrap().ray;
            prop_assert!((ray.direction.length() - 1.0).abs() < 1e-5);
            // Clipped in camera z: t_min = near / d.z.
            prop_assert!((f64::from(ray.t_min) - 0.001 / d.z).abs() < 1e-6 / d.z);
            let back = camera.project(ray.at(t), 0.0).unwrap();
            // Pixels per radian here, measured in f64 by turning the direction 1e-7 rad two
            // ways: fx (1 + r^2) times the distortion's local stretch, which grows without
            // bound next to the fold. The f32 error is ~ 3e-7 rad at t >= 1 from a world point
            // 10 away.
            let e1 = d.any_orthonormal_vector();
            let e2 = d.cross(e1);
            let stretch = [e1, e2]
                .iter()
                .filter_map(|e| camera.project_camera((d + *e * 1e-7) * 3.0))
                .map(|q| (q - back64).length() / 1e-7)
                .fold(0.0, f64::max);
            let r2 = (d.x * d.x + d.y * d.y) / (d.z * d.z);
            let at_least = camera.intrinsics().fx.max(camera.intrinsics().fy) * (1.0 + r2);
            let tol = 2e-3 + 1e-6 * stretch.max(at_least) * 3.0 * (1.0 + 10.0 / f64::from(t));
            prop_assert!(f64::from((back.x - p.x).abs().max((back.y - p.y).abs())) < tol, "{p:?} -> {back:?} (tol {tol})");
        } else {
            prop_assert!(camera.generate_ray(&CameraSample::at(p)).is_none());
            prop_assert!(camera.generate_ray_differential(&CameraSample::at(p)).is_none());
        }
    }

    /// Newton converges for every point inside the valid radius (and for points close to the
    /// fold): distort, undistort, and the result re-projects within 1e-4 px.
    #[test]
    fn newton_converges_inside_the_valid_radius(camera in opencv_strategy(), angle in 0f64..std::f64::consts::TAU, s in prop_oneof![0f64..0.95, 0.95f64..0.999]) {
        let radius = s * camera.valid_radius().min(5.0);
        let q = DVec2::new(angle.cos(), angle.sin()) * radius;
        // Skip where the tangential/prism terms fold the map (the model refuses it there).
        let Some(target) = camera.distort(q) else { return Ok(()); };
        let found = camera.undistort(target);
        prop_assert!(found.is_some(), "no ray for q = {q:?} (r_max {})", camera.valid_radius());
        let again = camera.distort(found.unwrap()).unwrap();
        let k = camera.intrinsics();
        let px = ((again - target) * DVec2::new(k.fx, k.fy)).abs().max_element();
        prop_assert!(px < 1e-4, "{px} px");
    }

    /// Differentials: the rays one pixel right and down against the central finite difference
    /// of generate_ray (h = 0.05 px): they agree to first order.
    #[test]
    fn opencv_differentials(camera in opencv_strategy(), fx in 0.05f32..0.95, fy in 0.05f32..0.95) {
        check_differential(&AnyCamera::from(camera), fx, fy)?;
    }

    /// Fisheye round trip raster -> ray -> point -> raster, as the pinhole's.
    #[test]
    fn fisheye_round_trip(camera in fisheye_strategy(), fx in edge_or_inside(), fy in edge_or_inside(), t in 1f32..20.0) {
        let res = camera.film().resolution();
        let p = raster(res, fx, fy);
        if let Some(d) = camera.direction(p) {
            prop_assert!((d.length() - 1.0).abs() < 1e-12);
            let back = camera.project_camera(d * 3.0).unwrap();
            prop_assert!(reprojection_px(p, back) < 1e-4, "{p:?} -> {back:?}");
            let ray = camera.generate_ray(&CameraSample::at(p)).unwrap().ray;
            prop_assert_eq!(ray.t_min, 0.001);
            let back = camera.project(ray.at(t), 0.0).unwrap();
            // Pixels per radian: f times the polynomial's slope (< 3 here) radially, f theta_d /
            // sin(theta) around the axis (large towards the back pole); f32 error ~ 3e-7 rad.
            let sin_theta = d.x.hypot(d.y);
            let theta_d = camera.intrinsics().normalised(p).length();
            let stretch = (theta_d / sin_theta.max(1e-12)).max(3.0);
            let tol = 2e-3 + 1e-6 * camera.intrinsics().fx.max(camera.intrinsics().fy) * stretch * (1.0 + 10.0 / f64::from(t));
            prop_assert!(f64::from((back.x - p.x).abs().max((back.y - p.y).abs())) < tol, "{p:?} -> {back:?} (tol {tol})");
        } else {
            // No ray: the distorted radius is at or past theta_d(theta_max).
            let q = camera.intrinsics().normalised(p);
            let t = camera.max_angle();
            let [k1, k2, k3, k4] = camera.distortion();
            let t2 = t * t;
            let td_max = t * (1.0 + k1 * t2 + k2 * t2 * t2 + k3 * t2 * t2 * t2 + k4 * t2 * t2 * t2 * t2);
            prop_assert!(q.length() >= td_max * (1.0 - 1e-9), "{q:?} vs {td_max}");
        }
    }

    /// Fisheye: every direction inside the fold angle projects and comes back (the whole
    /// sphere but the back pole for a fisheye without a fold).
    #[test]
    fn fisheye_inverse_inside_the_fold(camera in fisheye_strategy(), theta_frac in 0f64..0.999, phi in 0f64..std::f64::consts::TAU) {
        let theta = theta_frac * camera.max_angle();
        let d = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
        let p = camera.project_camera(d * 2.0).unwrap();
        let p = Point2::new(p.x as f32, p.y as f32);
        // Skip raster positions f32 cannot hold to 1e-4 px.
        prop_assume!(p.x.abs() < 1e4 && p.y.abs() < 1e4);
        let back = camera.direction(p).unwrap();
        // The f32 rounding of the raster position (half an ulp, |p| 6e-8 px) moves the angle
        // by that over f * theta_d'(theta), the polynomial's slope (small near the fold).
        let [k1, k2, k3, k4] = camera.distortion();
        let t2 = theta * theta;
        let slope = 1.0 + t2 * (3.0 * k1 + t2 * (5.0 * k2 + t2 * (7.0 * k3 + t2 * 9.0 * k4)));
        let k = camera.intrinsics();
        let rounding = f64::from(p.x.abs().max(p.y.abs())) * 6e-8 + 1e-6;
        let tol = 1e-9 + 2.0 * rounding / (k.fx.min(k.fy) * slope.min(1.0));
        prop_assert!((back - d).length() < tol, "{back:?} vs {d:?} (tol {tol})");
    }
    #[test]
    fn fisheye_differentials(camera in fisheye_strategy(), fx in 0.05f32..0.95, fy in 0.05f32..0.95) {
        check_differential(&AnyCamera::from(camera), fx, fy)?;
    }
}

/// The rays one pixel right and down: exactly the rays of those film points, and their step
/// from the main ray is the integral over the pixel of the derivative, which Simpson's rule
/// gives from central differences (h = 0.05 px) at p + i / 8, i = 0..8: the differential
/// against finite differences, without assuming the ray field is nearly linear over a pixel.
fn check_differential(camera: &AnyCamera, fx: f32, fy: f32) -> Result<(), TestCaseError> {
    let p = raster(camera.film().resolution(), fx, fy);
    let dir = |dx: f32, dy: f32| {
        camera
            .generate_ray(&CameraSample::at(Point2::new(p.x + dx, p.y + dy)))
            .map(|r| r.ray.direction.to_glam())
    };
    let h = 0.05;
    let tangent = |s: f32, axis: glam::Vec2| -> Option<glam::Vec3> {
        let at = axis * s;
        let plus = dir(at.x + axis.x * h, at.y + axis.y * h)?;
        let minus = dir(at.x - axis.x * h, at.y - axis.y * h)?;
        Some((plus - minus) / (2.0 * h))
    };
    let Some(d) = dir(0.0, 0.0) else {
        return Ok(());
    };
    let diff = camera
        .generate_ray_differential(&CameraSample::at(p))
        .unwrap();
    prop_assert_eq!(diff.ray.direction.to_glam(), d);
    prop_assert_eq!(diff.rx_origin, diff.ray.origin);
    prop_assert_eq!(diff.ry_origin, diff.ray.origin);
    for (got, axis) in [
        (diff.rx_direction.to_glam(), glam::Vec2::X),
        (diff.ry_direction.to_glam(), glam::Vec2::Y),
    ] {
        let Some(neighbour) = dir(axis.x, axis.y) else {
            continue;
        };
        prop_assert_eq!(got, neighbour);
        // Composite Simpson over 8 sub-intervals: weights 1 4 2 4 2 4 2 4 1, over 24.
        let mut simpson = glam::Vec3::ZERO;
        let mut complete = true;
        // The largest change of the tangent between sub-samples: Simpson's error (and the
        // central differences') grows with it next to the fold, where the inverse's slope
        // diverges.
        let mut variation = 0.0f32;
        let mut previous: Option<glam::Vec3> = None;
        for i in 0..=8 {
            let weight = if i == 0 || i == 8 {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            match tangent(i as f32 / 8.0, axis) {
                Some(t) => {
                    simpson += weight / 24.0 * t;
                    if let Some(prev) = previous {
                        variation = variation.max((t - prev).length());
                    }
                    previous = Some(t);
                }
                None => complete = false,
            }
        }
        if !complete {
            continue;
        }
        let step = got - d;
        prop_assert!(
            (step - simpson).length() <= 0.01 * step.length() + 0.1 * variation + 2e-5,
            "step {step:?} vs Simpson's integral of the tangents {simpson:?}"
        );
    }
    Ok(())
}

/// The fold: k1 < 0 alone folds where g'(r) = 1 + 3 k1 r^2 = 0, r_max = 1 / sqrt(-3 k1), and
/// g(r_max) = r_max (1 + k1 r_max^2) = 2 r_max / 3 is the largest distorted radius with a ray.
#[test]
fn past_the_fold_gives_no_ray() {
    for k1 in [-0.05, -0.2, -0.5] {
        let camera = pinhole(&[k1, 0.0, 0.0, 0.0]);
        let r_max = 1.0 / (-3.0f64 * k1).sqrt();
        assert!((camera.valid_radius() - r_max).abs() < 1e-9 * r_max);
        let g_max = 2.0 * r_max / 3.0;
        // Along image x (y = 0 in the image centre row): raster x = 500 g + 320.5.
        for (g, has_ray) in [
            (0.99 * g_max, true),
            (1.01 * g_max, false),
            (3.0 * g_max, false),
        ] {
            let p = Point2::new((500.0 * g + 320.5) as f32, 240.5);
            assert_eq!(
                camera.generate_ray(&CameraSample::at(p)).is_some(),
                has_ray,
                "k1 {k1}, g {g} (g_max {g_max})"
            );
        }
        // A world point just inside the fold radius projects, one past it does not.
        for (r, seen) in [(0.999 * r_max, true), (1.001 * r_max, false)] {
            let world = cv_world(r as f32, 0.0, 1.0);
            assert_eq!(camera.project(world, 0.0).is_some(), seen, "k1 {k1}, r {r}");
        }
    }
    // Fisheye: theta_d' = 1 + 3 k1 theta^2 folds at theta = 1 for k1 = -1/3, where
    // theta_d = 1 - 1/3 = 2/3.
    let camera = fisheye(&[-1.0 / 3.0, 0.0, 0.0, 0.0]);
    assert!((camera.max_angle() - 1.0).abs() < 1e-12);
    for (rho, has_ray) in [(0.66, true), (0.67, false)] {
        let p = Point2::new((500.0 * rho + 320.5) as f32, 240.5);
        assert_eq!(camera.generate_ray(&CameraSample::at(p)).is_some(), has_ray);
    }
    for (theta, seen) in [(0.99f32, true), (1.01, false)] {
        let world = cv_world(theta.sin(), 0.0, theta.cos());
        assert_eq!(camera.project(world, 0.0).is_some(), seen);
    }
    // A pinhole sees nothing behind it; an equidistant fisheye sees everything but straight back.
    assert!(
        pinhole(&[0.0; 4])
            .project(cv_world(0.1, 0.0, -1.0), 0.0)
            .is_none()
    );
    let equidistant = fisheye(&[0.0; 4]);
    assert_eq!(equidistant.max_angle(), std::f64::consts::PI);
    assert!(equidistant.project(cv_world(0.1, 0.0, -1.0), 0.0).is_some());
    assert!(equidistant.project(cv_world(0.0, 0.0, -1.0), 0.0).is_none());
}

/// With the look-at pose the image is the right way round: world up at the top, world right
/// (+x for the look-at example) on the right, for both models.
#[test]
fn look_at_orientation() {
    let cameras: [AnyCamera; 2] = [
        pinhole(&[-0.1, 0.0, 0.0, 0.0]).into(),
        fisheye(&[0.0; 4]).into(),
    ];
    for camera in cameras {
        let up = camera.project(Point3::new(0.0, 1.0, -3.0), 0.0).unwrap();
        let right = camera.project(Point3::new(1.0, 0.0, -3.0), 0.0).unwrap();
        assert!(up.y < 240.5 && (up.x - 320.5).abs() < 1e-3, "{up:?}");
        assert!(
            right.x > 320.5 && (right.y - 240.5).abs() < 1e-3,
            "{right:?}"
        );
    }
}

#[test]
fn validation() {
    let bad = |k: OpenCvIntrinsics, d: &[f64]| OpenCvCamera::new(base(), k, d).unwrap_err();
    assert!(matches!(
        bad(OpenCvIntrinsics { fx: 0.0, ..K }, &[0.0; 4]),
        CameraError::FocalLength { what: "fx", .. }
    ));
    assert!(matches!(
        bad(OpenCvIntrinsics { fy: -1.0, ..K }, &[0.0; 4]),
        CameraError::FocalLength { what: "fy", .. }
    ));
    assert!(matches!(
        bad(OpenCvIntrinsics { cx: f64::NAN, ..K }, &[0.0; 4]),
        CameraError::NonFinite { what: "cx", .. }
    ));
    for n in [0, 3, 6, 7, 9, 14] {
        let e = bad(K, &vec![0.0; n]);
        assert_eq!(
            e,
            CameraError::DistortionLength {
                model: "opencv",
                got: n
            }
        );
        assert!(e.to_string().contains("4, 5, 8 or 12"), "{e}");
    }
    assert!(matches!(
        bad(K, &[0.0, f64::INFINITY, 0.0, 0.0]),
        CameraError::NonFinite {
            what: "distortion",
            ..
        }
    ));
    let e = OpenCvFisheyeCamera::new(base(), K, &[0.0; 5]).unwrap_err();
    assert_eq!(
        e,
        CameraError::DistortionLength {
            model: "opencv_fisheye",
            got: 5
        }
    );
    assert!(matches!(
        OpenCvFisheyeCamera::new(
            base(),
            OpenCvIntrinsics {
                fx: f64::INFINITY,
                ..K
            },
            &[0.0; 4]
        ),
        Err(CameraError::NonFinite { what: "fx", .. })
    ));
    assert!(matches!(
        opencv_pose([0.0, f64::NAN, 0.0], [0.0; 3]),
        Err(CameraError::NonFinite { what: "rvec", .. })
    ));
    assert!(matches!(
        opencv_pose([0.0; 3], [0.0, 0.0, f64::INFINITY]),
        Err(CameraError::NonFinite { what: "tvec", .. })
    ));
    // Non-finite samples give no ray.
    let camera = pinhole(&[0.0; 4]);
    assert!(
        camera
            .generate_ray(&CameraSample::at(Point2::new(f32::NAN, 1.0)))
            .is_none()
    );
}

proptest! {
    #![proptest_config(crate::cases(2000))]

    /// Without distortion, the OpenCV model is a perspective camera: 90 degrees across the
    /// smaller side of 640 x 480 puts 240 px per unit on the plane z = 1, so fx = fy = 240 and
    /// the principal point at the image centre, (320, 240) in Obscura raster, is OpenCV
    /// (319.5, 239.5). Same pose (a random look-at): the same rays, the same projections.
    #[test]
    fn undistorted_equals_perspective(look in look_strategy(), fx in edge_or_inside(), fy in edge_or_inside()) {
        let base = base_at(look, [640, 480], None, 0.001, 1.0e30);
        let k = OpenCvIntrinsics { fx: 240.0, fy: 240.0, cx: 319.5, cy: 239.5 };
        let opencv = OpenCvCamera::new(base.clone(), k, &[0.0; 5]).unwrap();
        let perspective = obscura_camera::PerspectiveCamera::new(
            base,
            90.0,
            obscura_camera::FovAxis::Smaller,
            obscura_camera::ThinLens::PINHOLE,
        )
        .unwrap();
        let p = raster([640, 480], fx, fy);
        let a = opencv.generate_ray(&CameraSample::at(p)).unwrap().ray;
        let b = perspective.generate_ray(&CameraSample::at(p)).unwrap().ray;
        crate::assert_close3(a.direction.to_glam(), b.direction.to_glam(), 2e-6);
        crate::assert_close3(a.origin.to_glam(), b.origin.to_glam(), 1e-5);
        let world = b.at(4.0);
        let (pa, pb) = (opencv.project(world, 0.0).unwrap(), perspective.project(world, 0.0).unwrap());
        assert_close2(glam::Vec2::new(pa.x, pa.y), glam::Vec2::new(pb.x, pb.y), 2e-3);
    }
}
