//! The OpenCV camera models against OpenCV itself: `cv2.projectPoints` and
//! `cv2.fisheye.projectPoints` (Python, `pip install opencv-python-headless numpy`) project a
//! fixed set of points through several poses and distortion vectors of every length; Obscura's
//! `project` must agree within 1e-3 px (with Obscura raster = OpenCV pixel + 0.5), and the ray
//! through each of OpenCV's image points must look at the original point.
//!
//! This test needs `python3` with `cv2`: it fails (it does not skip) when they are missing, so
//! a CI without them shows it.

use obscura_camera::{
    AnyCamera, Camera, CameraBase, CameraSample, FilmGeometry, OpenCvCamera, OpenCvFisheyeCamera,
    OpenCvIntrinsics, Shutter, opencv_pose,
};
use obscura_space::{Point2, Point3, World};
use std::process::Command;

/// One camera for OpenCV: the model, fx fy cx cy, distortion, rvec, tvec.
struct Case {
    fisheye: bool,
    k: [f64; 4],
    distortion: Vec<f64>,
    rvec: [f64; 3],
    tvec: [f64; 3],
}

fn cases() -> Vec<Case> {
    let poses = [
        ([0.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
        ([0.1, -0.2, 0.05], [0.3, -0.1, 0.5]),
        ([2.0, 0.5, -1.0], [-1.0, 2.0, 4.0]),
    ];
    let pinhole: [&[f64]; 4] = [
        &[-0.28, 0.07, 0.0008, -0.0012],
        &[-0.28, 0.07, 0.0008, -0.0012, -0.01],
        &[0.5, -0.1, 0.001, 0.0005, 0.02, 0.6, -0.05, 0.01],
        &[
            -0.1, 0.02, 0.001, 0.002, 0.0, 0.05, 0.0, 0.0, 0.001, 0.0005, -0.002, 0.0003,
        ],
    ];
    let fisheye: [&[f64]; 2] = [&[0.05, -0.01, 0.002, -0.0003], &[-0.02, 0.003, 0.0, 0.0]];
    let mut cases = Vec::new();
    for (i, d) in pinhole.iter().enumerate() {
        for (rvec, tvec) in poses {
            cases.push(Case {
                fisheye: false,
                k: [500.0 + 10.0 * i as f64, 480.0, 319.5, 241.25],
                distortion: d.to_vec(),
                rvec,
                tvec,
            });
        }
    }
    for d in fisheye {
        for (rvec, tvec) in poses {
            cases.push(Case {
                fisheye: true,
                k: [280.0, 290.0, 322.0, 238.5],
                distortion: d.to_vec(),
                rvec,
                tvec,
            });
        }
    }
    cases
}

/// OpenCV camera-frame points (x right, y down, z forward): normalised image positions up to
/// 0.8 for the pinhole (inside every test distortion's valid radius) and angles up to about 70
/// degrees for the fisheye, at three depths.
fn camera_points(fisheye: bool) -> Vec<[f64; 3]> {
    let extent = if fisheye { 2.6 } else { 0.55 };
    let mut points = Vec::new();
    for z in [1.0, 2.5, 7.0] {
        for i in -2..=2 {
            for j in -2..=2 {
                let (x, y) = (extent * i as f64 / 2.0, extent * j as f64 / 2.0 * 0.9);
                points.push([x * z, y * z, z]);
            }
        }
    }
    points
}

fn camera_of(case: &Case) -> AnyCamera {
    let shutter = Shutter::new(0.0, 1.0).unwrap();
    let film = FilmGeometry::new([640, 480], None, None).unwrap();
    let base = CameraBase::new(opencv_pose(case.rvec, case.tvec).unwrap(), shutter, film);
    let [fx, fy, cx, cy] = case.k;
    let k = OpenCvIntrinsics { fx, fy, cx, cy };
    if case.fisheye {
        OpenCvFisheyeCamera::new(base, k, &case.distortion)
            .unwrap()
            .into()
    } else {
        OpenCvCamera::new(base, k, &case.distortion).unwrap().into()
    }
}

/// World points for a case: its camera-frame points moved out with the pose (Obscura's camera
/// frame is OpenCV's with y flipped). OpenCV then maps them back with rvec and tvec itself, so
/// a wrong pose shows as a mismatch.
fn world_points(camera: &AnyCamera, fisheye: bool) -> Vec<Point3<World>> {
    let pose = camera.world_from_camera().at(0.0);
    camera_points(fisheye)
        .iter()
        .map(|p| pose.point(Point3::new(p[0] as f32, -p[1] as f32, p[2] as f32)))
        .collect()
}

/// The Python list literal of numbers.
fn list(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| format!("{x:?}")).collect();
    format!("[{}]", items.join(", "))
}

/// Runs OpenCV on every case; returns per case the (u, v) of each point.
fn opencv_projections(cases: &[Case], points: &[Vec<Point3<World>>]) -> Vec<Vec<[f64; 2]>> {
    let mut script = String::from(
        "import numpy as np, cv2\n\
         def run(fisheye, k, d, rvec, tvec, pts):\n\
         \x20   K = np.array([[k[0], 0, k[2]], [0, k[1], k[3]], [0, 0, 1]], dtype=np.float64)\n\
         \x20   P = np.array(pts, dtype=np.float64)\n\
         \x20   r = np.array(rvec, dtype=np.float64); t = np.array(tvec, dtype=np.float64)\n\
         \x20   D = np.array(d, dtype=np.float64)\n\
         \x20   if fisheye:\n\
         \x20       img, _ = cv2.fisheye.projectPoints(P.reshape(1, -1, 3), r, t, K, D)\n\
         \x20   else:\n\
         \x20       img, _ = cv2.projectPoints(P, r, t, K, D)\n\
         \x20   print(' '.join(repr(float(x)) for x in img.reshape(-1)))\n",
    );
    for (case, pts) in cases.iter().zip(points) {
        let flat: Vec<String> = pts
            .iter()
            .map(|p| list(&[f64::from(p.x), f64::from(p.y), f64::from(p.z)]))
            .collect();
        script.push_str(&format!(
            "run({}, {}, {}, {}, {}, [{}])\n",
            if case.fisheye { "True" } else { "False" },
            list(&case.k),
            list(&case.distortion),
            list(&case.rvec),
            list(&case.tvec),
            flat.join(", ")
        ));
    }
    let output = Command::new("python3")
        .arg("-c")
        .arg(&script)
        .output()
        .expect("this test needs python3 with OpenCV: pip install opencv-python-headless numpy");
    assert!(
        output.status.success(),
        "python3 with cv2 failed (pip install opencv-python-headless numpy):\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = String::from_utf8(output.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), cases.len(), "one line per case:\n{text}");
    lines
        .iter()
        .map(|line| {
            let numbers: Vec<f64> = line
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            numbers.chunks(2).map(|c| [c[0], c[1]]).collect()
        })
        .collect()
}

#[test]
fn opencv_models_match_cv2() {
    let cases = cases();
    let cameras: Vec<AnyCamera> = cases.iter().map(camera_of).collect();
    let points: Vec<Vec<Point3<World>>> = cameras
        .iter()
        .zip(&cases)
        .map(|(c, case)| world_points(c, case.fisheye))
        .collect();
    let reference = opencv_projections(&cases, &points);
    let mut max_px = 0.0f64;
    let mut max_angle = 0.0f64;
    for ((camera, case), (pts, cv)) in cameras
        .iter()
        .zip(&cases)
        .zip(points.iter().zip(&reference))
    {
        assert_eq!(pts.len(), cv.len());
        let eye = camera
            .world_from_camera()
            .at(0.0)
            .point(Point3::ORIGIN)
            .to_glam();
        for (p, uv) in pts.iter().zip(cv) {
            let raster = [uv[0] + 0.5, uv[1] + 0.5];
            let got = camera
                .project(*p, 0.0)
                .unwrap_or_else(|| panic!("no projection of {p:?} (case {:?})", case.distortion));
            let px = (f64::from(got.x) - raster[0])
                .abs()
                .max((f64::from(got.y) - raster[1]).abs());
            assert!(
                px < 1e-3,
                "{p:?}: Obscura {got:?}, OpenCV + 0.5 {raster:?} (distortion {:?}, rvec {:?})",
                case.distortion,
                case.rvec
            );
            max_px = max_px.max(px);
            // The ray through OpenCV's image point looks at the point.
            let ray = camera
                .generate_ray(&CameraSample::at(Point2::new(
                    raster[0] as f32,
                    raster[1] as f32,
                )))
                .unwrap_or_else(|| panic!("no ray through {raster:?}"))
                .ray;
            // The angle from |a x b| in f64 (an f32 acos of a dot product near 1 is too coarse).
            let to_point = (p.to_glam() - eye).as_dvec3().normalize();
            let angle = ray
                .direction
                .to_glam()
                .as_dvec3()
                .normalize()
                .cross(to_point)
                .length();
            assert!(
                angle < 2e-5,
                "ray through {raster:?} misses {p:?} by {angle} rad"
            );
            max_angle = max_angle.max(angle);
        }
    }
    println!("cv2 agreement: max {max_px:.2e} px, rays within {max_angle:.2e} rad");
}

/// Found by the `camera` fuzz target: extreme but finite intrinsics and distortion carried a
/// projected point past f32's range, and `project` returned an infinite raster position. Such
/// a point now projects to None; every position returned is finite.
#[test]
fn projections_beyond_f32_range_are_none_not_infinite() {
    let text = r#"[film]
resolution = [33, 102]
[camera]
type = "opencv"
fx = 2.6185948e20
fy = 2.7946379e20
cx = 1.7750712e28
cy = 2.7943687e20
distortion = [1.9443517e31, 1.567235e-1, 8.480155e-33, 4.2324086e21]
rvec = [1.2397067e28, 7.1433342e31, 1.3043435e-11]
tvec = [1.8887691e31, 1.6634979e22, 5.5356084e-11]
shutter = [5.5356084e-11, 1.148167e27]
near = 1.5773086e-19
"#;
    let d = obscura_render::parse_description(std::path::Path::new("fuzz.toml"), text).unwrap();
    let camera = obscura_render::camera_of(&d).unwrap();
    // Film points far outside the image too, as the fuzzer drew them.
    let coords: Vec<f32> = [0.5f32, 16.0, 1e3, 1e6, 1e12, 1e20, 1e28, 1e32]
        .iter()
        .flat_map(|&c| [c, -c])
        .collect();
    let mut rays = 0;
    for &x in &coords {
        for &y in &coords {
            let Some(r) = camera.generate_ray(&CameraSample::at(Point2::new(x, y))) else {
                continue;
            };
            rays += 1;
            let p = r.ray.origin + r.ray.direction * 2.0;
            if let Some(xy) = camera.project(p, camera.shutter().open) {
                assert!(xy.x.is_finite() && xy.y.is_finite(), "({x}, {y}) -> {xy:?}");
            }
        }
    }
    assert!(
        rays > 0,
        "the camera made no ray: the check above ran on nothing"
    );
    // The fuzzer's point: its projection overflowed to (8.6e33, inf) before the fix.
    let r = camera
        .generate_ray(&CameraSample::at(Point2::new(0.5, -1e20)))
        .expect("a ray leaves there");
    let p = r.ray.origin + r.ray.direction * 2.0;
    assert_eq!(camera.project(p, camera.shutter().open), None);
}
