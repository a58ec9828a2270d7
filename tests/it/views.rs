//! The issue-20 cameras from a scene file, end to end: a cube map's six faces, a stereo pair's
//! layouts, OpenCV extrinsics against the look-at they describe, pixels that no ray leaves.

use super::{obscura, render_image, scratch, write};
use obscura_render::{IntegratorKind, StereoLayout, compose_stereo, parse_description, read_exr};
use std::path::Path;

/// A floor and three spheres in front of a camera at the origin looking down -z.
fn scene(camera: &str) -> String {
    format!(
        r#"[film]
resolution = [24, 24]
[sampler]
spp = 2
[integrator]
type = "depth"
[camera]
{camera}
[[shapes]]
type = "sphere"
center = [0.0, 0.0, -4.0]
radius = 1.0
[[shapes]]
type = "sphere"
center = [2.0, 0.5, -5.0]
radius = 0.7
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 4.0]
radius = 1.0
[[shapes]]
type = "quad"
origin = [-20.0, -1.0, 20.0]
edge_u = [40.0, 0.0, 0.0]
edge_v = [0.0, 0.0, -40.0]
"#
    )
}

fn parse(text: &str) -> obscura_render::SceneDescription {
    parse_description(Path::new("views.toml"), text).expect("scene parses")
}

/// `--cube-map` writes the six faces, each equal to the scene rendered with that `face`;
/// a film that is not square is refused before anything is written.
#[test]
fn cube_map_writes_six_faces_each_a_cube_face_render() {
    let dir = scratch("cube-map");
    let path = write(&dir, "s.toml", &scene("fov = 60.0"));
    let out = dir.join("env.exr");
    let status = obscura()
        .args(["render", "--cube-map", "--threads", "2", "-o"])
        .arg(&out)
        .arg(&path)
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(0));
    for (suffix, face) in ["px", "nx", "py", "ny", "pz", "nz"]
        .iter()
        .zip(["+x", "-x", "+y", "-y", "+z", "-z"])
    {
        let (image, _) = read_exr(&dir.join(format!("env-{suffix}.exr"))).unwrap();
        let expected = render_image(
            parse(&scene(&format!("type = \"cube_face\"\nface = \"{face}\""))),
            1,
        );
        assert_eq!(image.pixels, expected.pixels, "face {face}");
    }
    // The +z face looks at the sphere ahead, the -z face at the one behind, 3 away in both:
    // the depth AOV is the camera-space z of the rig, +3 ahead and -3 behind. The +y face sees
    // nothing (alpha 0) at its centre.
    let centre = |s: &str| {
        read_exr(&dir.join(format!("env-{s}.exr")))
            .unwrap()
            .0
            .pixel(12, 12)
    };
    assert!((centre("pz")[0] - 3.0).abs() < 0.05, "{:?}", centre("pz"));
    assert!((centre("nz")[0] + 3.0).abs() < 0.05, "{:?}", centre("nz"));
    assert_eq!(centre("py")[3], 0.0);

    let wide = write(
        &dir,
        "wide.toml",
        &scene("fov = 60.0").replace("[24, 24]", "[32, 24]"),
    );
    let out = obscura()
        .args(["render", "--cube-map", "-o"])
        .arg(dir.join("wide.exr"))
        .arg(&wide)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("film.resolution"));
    assert!(!dir.join("wide-px.exr").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A stereo pair side by side is the two eyes' renders, left on the left; `separate` writes the
/// same two images as files; the left eye sees the centre sphere right of where the right eye
/// does (it sits nearer than the convergence plane: crossed parallax).
#[test]
fn stereo_layouts_hold_the_two_eyes() {
    let dir = scratch("stereo");
    let camera = "fov = 60.0\n[camera.stereo]\ninteraxial = 0.5\nconvergence = 8.0\n";
    let path = write(&dir, "pair.toml", &scene(camera));
    let out = dir.join("pair.exr");
    let run = |path: &Path, out: &Path| {
        obscura()
            .args(["render", "--threads", "1", "-o"])
            .arg(out)
            .arg(path)
            .status()
            .unwrap()
    };
    assert_eq!(run(&path, &out).code(), Some(0));
    let (both, _) = read_exr(&out).unwrap();
    assert_eq!((both.width, both.height), (48, 24));

    let d = parse(&scene(camera));
    let [left, right] = d.stereo_eyes().expect("a perspective pair");
    let (left, right) = (render_image(left, 1), render_image(right, 1));
    let expected = compose_stereo(&left, &right, StereoLayout::SideBySide).unwrap();
    assert_eq!(both.pixels, expected.pixels);

    let separate = write(
        &dir,
        "sep.toml",
        &scene(&format!("{camera}layout = \"separate\"\n")),
    );
    assert_eq!(run(&separate, &dir.join("sep.exr")).code(), Some(0));
    assert_eq!(
        read_exr(&dir.join("sep-left.exr")).unwrap().0.pixels,
        left.pixels
    );
    assert_eq!(
        read_exr(&dir.join("sep-right.exr")).unwrap().0.pixels,
        right.pixels
    );

    // The centre sphere's covered columns on row 12: its centre in each eye.
    let centre_x = |image: &obscura_render::Image| {
        let xs: Vec<f32> = (0..image.width)
            .filter(|&x| {
                let p = image.pixel(x, 12);
                p[3] > 0.99 && p[0] < 3.5
            })
            .map(|x| x as f32)
            .collect();
        xs.iter().sum::<f32>() / xs.len() as f32
    };
    assert!(
        centre_x(&left) > centre_x(&right) + 0.5,
        "{} {}",
        centre_x(&left),
        centre_x(&right)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// OpenCV extrinsics: rvec = (pi, 0, 0), tvec = 0 is the camera at the origin looking down -z
/// with y up (OpenCV's y points down, z forward: a half turn about x), the scene format's
/// default look-at; an undistorted OpenCV camera with fx = fy = (W / 2) / tan(fov / 2) and the
/// centre at (W - 1) / 2 then sees what the perspective camera of that fov sees.
#[test]
fn opencv_extrinsics_and_intrinsics_match_the_perspective_camera() {
    let f = 12.0 / (30.0f64).to_radians().tan();
    let opencv = format!(
        "type = \"opencv\"\nfx = {f}\nfy = {f}\ncx = 11.5\ncy = 11.5\n\
         rvec = [3.141592653589793, 0.0, 0.0]\ntvec = [0.0, 0.0, 0.0]"
    );
    let a = render_image(parse(&scene(&opencv)), 1);
    let b = render_image(parse(&scene("fov = 60.0")), 1);
    let mean_diff: f32 = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| (p[0] - q[0]).abs())
        .sum::<f32>()
        / a.pixels.len() as f32;
    assert!(mean_diff < 1e-3, "mean depth difference {mean_diff}");
    assert_eq!(
        a.pixels.iter().map(|p| p[3]).sum::<f32>(),
        b.pixels.iter().map(|p| p[3]).sum::<f32>()
    );
}

/// A fisheye's pixels outside its image circle give no ray: alpha 0 and radiance 0, never NaN;
/// with the path integrator too.
#[test]
fn pixels_outside_the_image_circle_are_empty() {
    let mut d = parse(&scene("type = \"fisheye\"\nfov = 180.0"));
    d.film.resolution = [32, 16];
    for kind in [IntegratorKind::Depth, IntegratorKind::Path] {
        d.integrator.kind = kind;
        let image = render_image(d.clone(), 2);
        assert!(image.pixels.iter().all(|p| p.iter().all(|v| v.is_finite())));
        // Corners of the 32 x 16 film lie far outside the centred circle of diameter 16.
        for (x, y) in [(0, 0), (31, 0), (0, 15), (31, 15), (2, 8), (29, 8)] {
            assert_eq!(image.pixel(x, y), [0.0; 4], "{kind:?} ({x}, {y})");
        }
        assert!(image.pixel(16, 8)[3] > 0.99);
    }
}
