//! pbrt-v4 scenes: camera defaults, handedness, the same image as the equivalent TOML, errors
//! that name the file and line, and no panic on any input.

use crate::{assert_images_close, render_aov, scratch, toml_scene, write};
use obscura_camera::Camera;
use obscura_import::{ImportError, parse_pbrt};
use obscura_render::{CameraKind, IntegratorKind, camera_of};
use obscura_space::{Point3, World};
use proptest::prelude::*;
use std::path::Path;

fn import(text: &str) -> obscura_import::Imported {
    parse_pbrt(Path::new("/nonexistent/test.pbrt"), text).expect("imports")
}

fn import_err(text: &str) -> ImportError {
    // Some errors are found by the importer, the rest when the renderer validates the result.
    parse_pbrt(Path::new("/nonexistent/test.pbrt"), text)
        .and_then(|i| i.description())
        .expect_err("must fail")
}

/// The line an error names.
fn line_of(e: &ImportError) -> Option<usize> {
    match e {
        ImportError::Scene { line, .. } => *line,
        ImportError::Render(obscura_render::RenderError::Scene { line, .. }) => *line,
        _ => None,
    }
}

#[test]
fn camera_defaults_are_pbrts() {
    // pbrt-v4's documented defaults: fov 90 on the shorter image axis, lensradius 0,
    // focaldistance 1e6, shutter [0, 1]; film 1280 x 720; zsobol at 16 spp; gaussian 1.5.
    let d = import("Camera \"perspective\"\nWorldBegin\nShape \"sphere\"")
        .description()
        .unwrap();
    assert_eq!(d.camera.kind, CameraKind::Perspective);
    assert_eq!(d.camera.fov, 90.0);
    assert_eq!(d.camera.fov_axis, obscura_camera::FovAxis::Smaller);
    assert_eq!(d.camera.lens.radius, 0.0);
    assert_eq!(d.camera.lens.focal_distance, 1.0e6);
    assert_eq!((d.camera.shutter.open, d.camera.shutter.close), (0.0, 1.0));
    assert_eq!(d.film.resolution, [1280, 720]);
    assert!(
        d.camera.screen_window.is_none(),
        "pbrt's default window is the scene format's"
    );
    // volpath with maxdepth 5, zsobol (Obscura's sobol) at 16 spp, gaussian of radius 1.5.
    assert_eq!((d.integrator.max_depth, d.sampler.spp), (5, 16));
    assert_eq!(d.sampler.kind.name(), "sobol");
    assert_eq!(d.film.filter, obscura_render::FilterSettings::gaussian(1.5));

    let d = import(
        "Camera \"orthographic\" \"float lensradius\" 0.1 \"float focaldistance\" 3 \
         \"float screenwindow\" [-2 2 -1 1] \"float shutteropen\" 0.25 \"float shutterclose\" 0.5\n\
         Film \"rgb\" \"integer xresolution\" 40 \"integer yresolution\" 20\nWorldBegin",
    )
    .description()
    .unwrap();
    assert_eq!(d.camera.kind, CameraKind::Orthographic);
    assert_eq!(d.camera.lens.radius, 0.1);
    assert_eq!(d.camera.lens.focal_distance, 3.0);
    assert_eq!(
        d.camera.screen_window.unwrap().to_array(),
        [-2.0, 2.0, -1.0, 1.0]
    );
    assert_eq!((d.camera.shutter.open, d.camera.shutter.close), (0.25, 0.5));
    assert_eq!(d.film.resolution, [40, 20]);
}

#[test]
fn film_sampler_filter_and_integrator_map() {
    let d = import(
        "Film \"rgb\" \"integer xresolution\" 30 \"integer yresolution\" 60 \"float cropwindow\" [0.25 0.75 0 0.5]\n\
         Sampler \"halton\" \"integer pixelsamples\" 7 \"integer seed\" 9\n\
         PixelFilter \"triangle\"\nIntegrator \"volpath\" \"integer maxdepth\" 3\n\
         Camera \"perspective\" \"float fov\" 30\nWorldBegin",
    )
    .description()
    .unwrap();
    assert_eq!(d.film.resolution, [30, 60]);
    assert_eq!(d.film.crop, Some([0.25, 0.75, 0.0, 0.5]));
    assert_eq!(d.sampler.kind.name(), "halton");
    assert_eq!((d.sampler.spp, d.sampler.seed), (7, 9));
    // pbrt's triangle filter has radius 2.
    assert_eq!(
        d.film.filter,
        obscura_render::FilterSettings::Triangle { radius: 2.0 }
    );
    assert_eq!(d.integrator.max_depth, 3);
}

/// pbrt-v4's Gaussian keeps its radius and its sigma (default 0.5); a sigma out of Obscura's
/// range is an error at the directive's line.
#[test]
fn gaussian_filters_keep_their_sigma() {
    use obscura_render::FilterSettings;
    let scene = |filter: &str| format!("{filter}\nCamera \"perspective\"\nWorldBegin");
    for (filter, want) in [
        (
            "PixelFilter \"gaussian\"",
            FilterSettings::Gaussian {
                radius: 1.5,
                sigma: 0.5,
            },
        ),
        (
            "PixelFilter \"gaussian\" \"float sigma\" 0.75 \"float xradius\" 2 \"float yradius\" 2",
            FilterSettings::Gaussian {
                radius: 2.0,
                sigma: 0.75,
            },
        ),
    ] {
        let imported = import(&scene(filter));
        assert!(
            imported.warnings.is_empty(),
            "{filter}: {:?}",
            imported.warnings
        );
        assert_eq!(
            imported.description().unwrap().film.filter,
            want,
            "{filter}"
        );
    }
    for sigma in ["0", "-1", "17", "40"] {
        let e = import_err(&scene(&format!(
            "\nPixelFilter \"gaussian\" \"float sigma\" {sigma}"
        )));
        assert_eq!(line_of(&e), Some(2), "{sigma}: {e}");
        assert!(
            e.to_string().contains("sigma must be in (0, 16]"),
            "{sigma}: {e}"
        );
    }
}

/// Where pbrt-v4 puts world point `p` on a `w` x `h` film, computed by hand from its
/// LookAt (camera +x = cross(up, dir)) and perspective projection (fov on the shorter axis),
/// optionally after `Scale -1 1 1`.
fn pbrt_raster(
    eye: [f64; 3],
    target: [f64; 3],
    up: [f64; 3],
    fov: f64,
    w: f64,
    h: f64,
    mirrored_world: bool,
    p: [f64; 3],
) -> [f64; 2] {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let norm = |a: [f64; 3]| {
        let l = dot(a, a).sqrt();
        [a[0] / l, a[1] / l, a[2] / l]
    };
    let dir = norm(sub(target, eye));
    let right = norm(cross(norm(up), dir));
    let new_up = cross(dir, right);
    let d = sub(p, eye);
    let (mut xc, yc, zc) = (dot(d, right), dot(d, new_up), dot(d, dir));
    if mirrored_world {
        xc = -xc;
    }
    let t = (fov.to_radians() / 2.0).tan();
    let (xs, ys) = (xc / zc / t, yc / zc / t);
    let a = w / h;
    let (sx, sy) = if a >= 1.0 { (a, 1.0) } else { (1.0, 1.0 / a) };
    [(xs + sx) / (2.0 * sx) * w, (sy - ys) / (2.0 * sy) * h]
}

#[test]
fn handedness_matches_pbrt_with_and_without_the_mirroring_scale() {
    let (eye, target, up) = ([1.0, 2.0, 6.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    for mirrored in [false, true] {
        let text = format!(
            "{}LookAt 1 2 6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 50\n\
             Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 48\nWorldBegin",
            if mirrored { "Scale -1 1 1\n" } else { "" }
        );
        let d = import(&text).description().unwrap();
        let camera = camera_of(&d).unwrap();
        for p in [[1.0, 0.0, 0.0], [-0.5, 1.0, 0.3], [0.2, -0.7, 1.5]] {
            let got = camera
                .project(
                    Point3::<World>::new(p[0] as f32, p[1] as f32, p[2] as f32),
                    0.0,
                )
                .unwrap();
            let want = pbrt_raster(eye, target, up, 50.0, 64.0, 48.0, mirrored, p);
            assert!(
                (got.x as f64 - want[0]).abs() < 1e-3 && (got.y as f64 - want[1]).abs() < 1e-3,
                "mirrored {mirrored}, point {p:?}: got ({}, {}), pbrt puts it at {want:?}",
                got.x,
                got.y
            );
        }
        // Without the scale, world +x (right of the look direction in a right-handed world)
        // lands on the image's left, as in pbrt.
        let r = camera
            .project(Point3::<World>::new(1.0, 0.0, 0.0), 0.0)
            .unwrap();
        let right_of_centre = {
            let c = camera
                .project(Point3::<World>::new(0.0, 0.0, 0.0), 0.0)
                .unwrap();
            // From eye (1, 2, 6) the point one unit along +x is to the right of the origin.
            r.x > c.x
        };
        assert_eq!(right_of_centre, mirrored);
    }
}

/// The same scene as pbrt-v4 text and as TOML (with an OBJ beside it), looked at from a
/// right-handed world (`Scale -1 1 1`).
const PBRT_SCENE: &str = r#"# The pbrt-v4 side of the equivalence test
Scale -1 1 1
LookAt 0.5 1.5 6  0 0.25 0  0 1 0
Camera "perspective" "float fov" [ 35 ]
Film "rgb" "integer xresolution" [ 48 ] "integer yresolution" [ 36 ]
PixelFilter "box"
Sampler "independent" "integer pixelsamples" 1
WorldBegin
AttributeBegin
  Translate 0.8 0.3 0
  Shape "sphere" "float radius" 0.6
AttributeEnd
AttributeBegin
  Translate -0.7 0 0.5
  Rotate 30 0 1 0
  Scale 0.5 0.5 0.5
  Shape "trianglemesh" "point3 P" [ -1 0 -1  1 0 -1  1 2 -1  -1 2 -1  0 1 1 ]
    "integer indices" [ 0 1 4  1 2 4  2 3 4  3 0 4 ]
AttributeEnd
Shape "bilinearmesh" "point3 P" [ -4 -0.5 -4  4 -0.5 -4  -4 -0.5 4  4 -0.5 4 ]
"#;

const TOML_SCENE: &str = r#"
[film]
resolution = [48, 36]
filter = "box"
[sampler]
type = "independent"
spp = 1
[camera]
eye = [0.5, 1.5, 6.0]
target = [0.0, 0.25, 0.0]
up = [0.0, 1.0, 0.0]
fov = 35.0
focal_distance = 1.0e6
[[shapes]]
type = "sphere"
radius = 0.6
transform = [{ translate = [0.8, 0.3, 0.0] }]
[[shapes]]
type = "mesh"
file = "pyramid.obj"
transform = [{ scale = [0.5, 0.5, 0.5] }, { rotate = [30.0, 0.0, 1.0, 0.0] }, { translate = [-0.7, 0.0, 0.5] }]
[[shapes]]
type = "quad"
origin = [-4.0, -0.5, -4.0]
edge_u = [8.0, 0.0, 0.0]
edge_v = [0.0, 0.0, 8.0]
"#;

const PYRAMID_OBJ: &str =
    "v -1 0 -1\nv 1 0 -1\nv 1 2 -1\nv -1 2 -1\nv 0 1 1\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n";

#[test]
fn a_pbrt_scene_renders_as_its_toml_equivalent() {
    let dir = scratch("pbrt-equivalent");
    write(&dir, "pyramid.obj", PYRAMID_OBJ);
    let reference = toml_scene(&dir, "reference.toml", TOML_SCENE);
    let pbrt = write(&dir, "scene.pbrt", PBRT_SCENE);
    let imported = obscura_import::import(&pbrt)
        .unwrap()
        .description()
        .unwrap();
    for kind in [IntegratorKind::Position, IntegratorKind::Depth] {
        let a = render_aov(imported.clone(), kind);
        let b = render_aov(reference.clone(), kind);
        // The pose arrives as a matrix rather than a look-at: equal up to f32 rounding.
        assert_images_close(&a, &b, 1e-4);
        // And the scene is really seen: most pixels hit something.
        let covered = (0..a.height)
            .flat_map(|y| (0..a.width).map(move |x| (x, y)))
            .filter(|&(x, y)| a.pixel(x, y)[3] > 0.0)
            .count();
        assert!(
            covered > (a.width * a.height / 2) as usize,
            "{covered} covered"
        );
    }
}

#[test]
fn convert_writes_toml_that_renders_the_same() {
    let dir = scratch("pbrt-convert");
    let pbrt = write(&dir, "scene.pbrt", PBRT_SCENE);
    let imported = obscura_import::import(&pbrt).unwrap();
    let out = dir.join("out").join("converted.toml");
    std::fs::create_dir_all(out.parent().unwrap()).unwrap();
    let written = imported.write(&out).unwrap();
    assert!(
        written
            .iter()
            .any(|p| p.extension().is_some_and(|e| e == "obj"))
    );
    let converted = obscura_render::load_description(&out).unwrap();
    for kind in [IntegratorKind::Position, IntegratorKind::Depth] {
        let a = render_aov(imported.description().unwrap(), kind);
        let b = render_aov(converted.clone(), kind);
        // OBJ numbers are written in their shortest exact form: bit for bit.
        assert_eq!(assert_images_close(&a, &b, 0.0), 0);
    }
}

#[test]
fn transforms_compose_as_pbrts() {
    // Transform gives the matrix column by column; ConcatTransform multiplies on the right;
    // CoordSysTransform restores a saved CTM.
    let d = import(
        "Camera \"perspective\"\nWorldBegin\n\
         Translate 1 2 3\nCoordinateSystem \"here\"\nIdentity\n\
         AttributeBegin\nTransform [1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1]\nConcatTransform [2 0 0 0  0 2 0 0  0 0 2 0  0 0 0 1]\nShape \"sphere\"\nAttributeEnd\n\
         CoordSysTransform \"here\"\nShape \"sphere\" \"float radius\" 0.5\n",
    )
    .description()
    .unwrap();
    let m0 = d.shapes[0].transform.matrix();
    assert_eq!(
        m0.transform_point3(glam::Vec3::new(1.0, 0.0, 0.0)),
        glam::Vec3::new(7.0, 6.0, 7.0)
    );
    let m1 = d.shapes[1].transform.matrix();
    assert_eq!(
        m1.transform_point3(glam::Vec3::ZERO),
        glam::Vec3::new(1.0, 2.0, 3.0)
    );
}

#[test]
fn active_transform_moves_shapes_and_the_camera() {
    let d = import(
        "ActiveTransform EndTime\nTranslate 0 0 -1\nActiveTransform All\n\
         LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n\
         ActiveTransform StartTime\nTranslate 1 0 0\nActiveTransform EndTime\nTranslate 2 0 0\n\
         ActiveTransform All\nShape \"sphere\"\n",
    )
    .description()
    .unwrap();
    let s = &d.shapes[0];
    let end = s.transform_end.expect("the sphere moves");
    assert_eq!(
        s.transform.matrix().transform_point3(glam::Vec3::ZERO).x,
        1.0
    );
    assert_eq!(end.matrix().transform_point3(glam::Vec3::ZERO).x, 2.0);
    let (_, pose_end) = d.camera.pose.expect("imported cameras carry their matrix");
    let pose_end = pose_end.expect("the camera moves");
    // At shutter close camera-from-world is Translate(0, 0, -1) * LookAt: the camera's origin
    // is the world point the look-at puts at camera z = +1, one unit in front of the eye.
    let eye = pose_end.matrix().transform_point3(glam::Vec3::ZERO);
    assert!(
        (eye - glam::Vec3::new(0.0, 0.0, 4.0)).length() < 1e-5,
        "{eye:?}"
    );
    let (pose, _) = d.camera.pose.unwrap();
    let eye = pose.matrix().transform_point3(glam::Vec3::ZERO);
    assert!(
        (eye - glam::Vec3::new(0.0, 0.0, 5.0)).length() < 1e-5,
        "{eye:?}"
    );
}

#[test]
fn instances_and_named_materials_and_area_lights() {
    let d = import(
        "Camera \"perspective\"\nWorldBegin\n\
         MakeNamedMaterial \"red\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.9 0.1 0.1]\n\
         ObjectBegin \"ball\"\nNamedMaterial \"red\"\nShape \"sphere\" \"float radius\" 0.25\nObjectEnd\n\
         Translate 3 0 0\nObjectInstance \"ball\"\nTranslate 0 3 0\nObjectInstance \"ball\"\n\
         AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [2 3 4] \"float scale\" 2\n\
         Shape \"sphere\"\nAttributeEnd\nShape \"sphere\"\n",
    )
    .description()
    .unwrap();
    assert_eq!(d.shapes.len(), 4);
    let at = |i: usize| {
        d.shapes[i]
            .transform
            .matrix()
            .transform_point3(glam::Vec3::ZERO)
    };
    assert_eq!(at(0), glam::Vec3::new(3.0, 0.0, 0.0));
    assert_eq!(at(1), glam::Vec3::new(3.0, 3.0, 0.0));
    let red = d.shapes[0].material.expect("named material");
    assert_eq!(
        d.materials[red].1,
        obscura_render::MaterialSettings::Diffuse {
            reflectance: [0.9, 0.1, 0.1]
        }
    );
    assert_eq!(d.shapes[2].emission, Some([4.0, 6.0, 8.0]));
    assert_eq!(
        d.shapes[3].emission, None,
        "AttributeEnd ends the area light"
    );
}

#[test]
fn lights_map_onto_obscuras() {
    let d = import(
        "Camera \"perspective\"\nWorldBegin\nTranslate 0 1 0\n\
         LightSource \"point\" \"rgb I\" [1 2 3] \"point3 from\" [0 4 0] \"float scale\" 2\n\
         LightSource \"distant\" \"point3 from\" [0 0 0] \"point3 to\" [0 -1 0] \"rgb L\" [3 3 3]\n\
         LightSource \"infinite\" \"rgb L\" [0.1 0.2 0.3]\n",
    )
    .description()
    .unwrap();
    use obscura_render::LightSettings as L;
    match &d.lights[0] {
        L::Point {
            position,
            intensity,
        } => {
            assert_eq!(*position, [0.0, 5.0, 0.0]);
            assert_eq!(*intensity, [2.0, 4.0, 6.0]);
        }
        other => panic!("{other:?}"),
    }
    match &d.lights[1] {
        L::Distant {
            direction,
            irradiance,
        } => {
            assert_eq!(*direction, [0.0, -1.0, 0.0]);
            assert_eq!(*irradiance, [3.0; 3]);
        }
        other => panic!("{other:?}"),
    }
    assert!(
        matches!(&d.lights[2], L::Environment { radiance, file: None, .. } if *radiance == [0.1, 0.2, 0.3])
    );
}

#[test]
fn materials_map_with_warnings_where_approximated() {
    let imported = import(
        "Camera \"perspective\"\nWorldBegin\n\
         Material \"conductor\" \"float roughness\" 0.0625\nShape \"sphere\"\n\
         Material \"dielectric\" \"float eta\" 1.33\nShape \"sphere\"\n\
         Material \"coateddiffuse\" \"rgb reflectance\" [0.2 0.4 0.6]\nShape \"sphere\"\n",
    );
    let d = imported.description().unwrap();
    use obscura_render::MaterialSettings as M;
    let m = |i: usize| d.materials[d.shapes[i].material.unwrap()].1;
    // pbrt remaps roughness r to alpha = sqrt(r) = 0.25; Obscura's alpha is roughness^2.
    assert!(matches!(m(0), M::RoughConductor { roughness, .. } if (roughness - 0.5).abs() < 1e-6));
    assert_eq!(m(1), M::Dielectric { ior: 1.33 });
    assert_eq!(
        m(2),
        M::Diffuse {
            reflectance: [0.2, 0.4, 0.6]
        }
    );
    assert!(
        imported
            .warnings
            .iter()
            .any(|w| w.contains(":7:") && w.contains("coateddiffuse"))
    );
}

#[test]
fn includes_are_read_relative_to_the_scene() {
    let dir = scratch("pbrt-include");
    std::fs::create_dir_all(dir.join("parts")).unwrap();
    write(
        &dir,
        "parts/geometry.pbrt",
        "Shape \"sphere\" \"float radius\" 2\nShape \"nonsense\"\n",
    );
    let main = write(
        &dir,
        "main.pbrt",
        "Camera \"perspective\"\nWorldBegin\nInclude \"parts/geometry.pbrt\"\n",
    );
    let imported = obscura_import::import(&main).unwrap();
    let d = imported.description().unwrap();
    assert_eq!(d.shapes.len(), 1);
    // The warning names the included file and its line.
    assert!(
        imported
            .warnings
            .iter()
            .any(|w| w.contains("geometry.pbrt:2") && w.contains("nonsense")),
        "{:?}",
        imported.warnings
    );
    // A file that includes itself stops with an error, not a stack overflow.
    let looped = write(&dir, "loop.pbrt", "Include \"loop.pbrt\"\n");
    assert!(obscura_import::import(&looped).is_err());
}

#[test]
fn a_ply_mesh_is_read() {
    let dir = scratch("pbrt-ply");
    write(
        &dir,
        "quad.ply",
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
         element face 1\nproperty list uchar int vertex_indices\nend_header\n\
         -1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n4 0 1 2 3\n",
    );
    let main = write(
        &dir,
        "s.pbrt",
        "LookAt 0 0 3 0 0 0 0 1 0\nCamera \"perspective\" \"float fov\" 30\n\
         Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\nWorldBegin\n\
         Shape \"plymesh\" \"string filename\" \"quad.ply\"\n",
    );
    let d = obscura_import::import(&main)
        .unwrap()
        .description()
        .unwrap();
    let depth = render_aov(d, IntegratorKind::Depth);
    assert!((depth.pixel(4, 4)[0] - 3.0).abs() < 1e-4);
    // A missing PLY names the scene line that asked for it.
    let bad = write(
        &dir,
        "bad.pbrt",
        "Camera \"perspective\"\nWorldBegin\n\nShape \"plymesh\" \"string filename\" \"nope.ply\"\n",
    );
    let e = obscura_import::import(&bad).unwrap_err();
    assert_eq!(line_of(&e), Some(4), "{e}");
}

#[test]
fn spherical_equirectangular_matches_pbrts_mapping() {
    // pbrt-v4: theta = pi v, phi = 2 pi u, d = (sin theta cos phi, cos theta, sin theta sin phi)
    // in camera space (after its y/z swap). The image centre looks along camera -x.
    let d = import(
        "Camera \"spherical\" \"string mapping\" \"equirectangular\"\n\
         Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 32\nWorldBegin",
    )
    .description()
    .unwrap();
    let camera = camera_of(&d).unwrap();
    // Default CTM: camera space is world space. Points along pbrt's directions:
    for (u, v) in [(0.5, 0.5), (0.25, 0.5), (0.1, 0.3), (0.8, 0.7)] {
        let (theta, phi) = (std::f64::consts::PI * v, 2.0 * std::f64::consts::PI * u);
        let dir = [
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        ];
        let p = Point3::<World>::new(
            dir[0] as f32 * 10.0,
            dir[1] as f32 * 10.0,
            dir[2] as f32 * 10.0,
        );
        let r = camera.project(p, 0.0).unwrap();
        assert!(
            (r.x as f64 - u * 64.0).abs() < 1e-2 && (r.y as f64 - v * 32.0).abs() < 1e-2,
            "({u}, {v}) -> ({}, {})",
            r.x,
            r.y
        );
    }
    // pbrt's default mapping (equal-area) is refused, naming the line.
    assert_eq!(
        line_of(&import_err("\nCamera \"spherical\"\nWorldBegin")),
        Some(2)
    );
}

#[test]
fn bad_input_names_file_and_line() {
    for (text, line) in [
        (
            "Camera \"perspective\"\nWorldBegin\nShape \"sphere\" \"float radius\" [ 1",
            3,
        ),
        (
            "Camera \"perspective\"\nWorldBegin\n\n  Shape \"sphere\" \"float radius\" -1",
            4,
        ),
        ("Camera \"perspective\" \"float fov\" 180\nWorldBegin", 1),
        ("LookAt 0 0 0  0 0 0  0 1 0\nCamera \"perspective\"", 1),
        ("Camera \"perspective\"\nWorldBegin\nAttributeEnd", 3),
        (
            "Camera \"perspective\"\nWorldBegin\nNamedMaterial \"nope\"",
            3,
        ),
        (
            "Camera \"perspective\"\nWorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 7]",
            3,
        ),
        ("Camera \"perspective\"\n\"float\" 3", 2),
        (
            "Camera \"perspective\"\nFilm \"rgb\" \"integer xresolution\" 0",
            2,
        ),
        ("Translate 1 2\nCamera \"perspective\"", 2),
        (
            "Camera \"perspective\"\nWorldBegin\nShape \"sphere\" \"float radius\" \"big\"",
            3,
        ),
    ] {
        let e = import_err(text);
        assert!(e.to_string().starts_with("/nonexistent/test.pbrt:"), "{e}");
        assert_eq!(line_of(&e), Some(line), "{text:?}: {e}");
    }
}

/// pbrt-ish text: directives, strings, numbers and brackets in any order.
fn pbrt_soup() -> impl Strategy<Value = String> {
    let token = prop_oneof![
        Just("Camera".to_string()),
        Just("\"perspective\"".to_string()),
        Just("\"spherical\"".to_string()),
        Just("Shape".to_string()),
        Just("\"sphere\"".to_string()),
        Just("\"trianglemesh\"".to_string()),
        Just("\"bilinearmesh\"".to_string()),
        Just("\"point3 P\"".to_string()),
        Just("\"integer indices\"".to_string()),
        Just("\"float radius\"".to_string()),
        Just("\"float fov\"".to_string()),
        Just("\"rgb L\"".to_string()),
        Just("LookAt".to_string()),
        Just("Translate".to_string()),
        Just("Rotate".to_string()),
        Just("Scale".to_string()),
        Just("Transform".to_string()),
        Just("ConcatTransform".to_string()),
        Just("AttributeBegin".to_string()),
        Just("AttributeEnd".to_string()),
        Just("ObjectBegin".to_string()),
        Just("ObjectEnd".to_string()),
        Just("ObjectInstance".to_string()),
        Just("\"o\"".to_string()),
        Just("ActiveTransform".to_string()),
        Just("EndTime".to_string()),
        Just("All".to_string()),
        Just("WorldBegin".to_string()),
        Just("Film".to_string()),
        Just("\"integer xresolution\"".to_string()),
        Just("Material".to_string()),
        Just("\"conductor\"".to_string()),
        Just("AreaLightSource".to_string()),
        Just("\"diffuse\"".to_string()),
        Just("LightSource".to_string()),
        Just("\"point\"".to_string()),
        Just("[".to_string()),
        Just("]".to_string()),
        Just("Include".to_string()),
        (-1e3f64..1e3).prop_map(|x| format!("{x}")),
        (0u32..10).prop_map(|x| x.to_string()),
        Just("1e38".to_string()),
        Just("0".to_string()),
        "\\PC{0,4}",
    ];
    proptest::collection::vec(token, 0..60).prop_map(|t| t.join(" "))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn no_pbrt_input_panics(text in pbrt_soup()) {
        if let Ok(imported) = parse_pbrt(Path::new("/nonexistent/fuzz.pbrt"), &text)
            && let Ok(d) = imported.description() {
                let _ = obscura_render::RenderScene::build(d);
            }
    }
}

#[test]
fn equal_anonymous_materials_are_shared_and_long_lines_are_cheap() {
    // Exporters write a Material per shape: equal ones become one scene material.
    let mut text = String::from("Camera \"perspective\"\nWorldBegin\n");
    for i in 0..200 {
        let r = if i % 2 == 0 {
            "0.5 0.5 0.5"
        } else {
            "0.1 0.2 0.3"
        };
        text += &format!(
            "AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [{r}]\nTranslate {i} 0 0\nShape \"sphere\"\nAttributeEnd\n"
        );
    }
    // One mesh of 200 000 triangles written on a single line, as exporters do.
    let n = 100_000;
    let mut p = String::new();
    let mut idx = String::new();
    for i in 0..n {
        p += &format!("{i} 0 0 {i} 1 0 {i} 0 1 ");
        idx += &format!("{} {} {} ", 3 * i, 3 * i + 1, 3 * i + 2);
    }
    text += &format!("Shape \"trianglemesh\" \"point3 P\" [{p}] \"integer indices\" [{idx}]\n");
    let start = std::time::Instant::now();
    let d = import(&text).description().unwrap();
    assert_eq!(d.materials.len(), 2);
    assert_eq!(d.shapes.len(), 201);
    // Linear work: well under a second even in a debug build on a shared machine.
    assert!(
        start.elapsed().as_secs_f64() < 10.0,
        "{:?}",
        start.elapsed()
    );
}

#[test]
fn a_sphere_at_world_plus_x_shows_left_in_pbrts_plain_look_at_and_right_after_scale() {
    for (prefix, on_right) in [("", false), ("Scale -1 1 1\n", true)] {
        let text = format!(
            "{prefix}LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n\
             Film \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 16\nWorldBegin\n\
             Translate 1.2 0 0\nShape \"sphere\" \"float radius\" 0.5\n"
        );
        let image = render_aov(import(&text).description().unwrap(), IntegratorKind::Depth);
        let (mut sum, mut count) = (0.0, 0.0);
        for y in 0..image.height {
            for x in 0..image.width {
                if image.pixel(x, y)[3] > 0.5 {
                    sum += x as f64 + 0.5;
                    count += 1.0;
                }
            }
        }
        assert!(count > 4.0, "the sphere is seen");
        assert_eq!(
            sum / count > 16.0,
            on_right,
            "{prefix:?}: centroid at x = {}",
            sum / count
        );
    }
}

#[test]
fn disks_and_cylinders_are_tessellated_facing_as_in_pbrt() {
    let imported = import(
        "Camera \"perspective\"\nWorldBegin\nShape \"disk\" \"float radius\" 2 \"float height\" 0.5\n\
         Shape \"cylinder\" \"float radius\" 0.5 \"float zmin\" 0 \"float zmax\" 3\n\
         Shape \"disk\" \"float innerradius\" 0.5 \"float phimax\" 90\n",
    );
    assert!(imported.warnings.iter().any(|w| w.contains("tessellated")));
    let d = imported.description().unwrap();
    let mesh = |i: usize| match &d.shapes[i].geometry {
        obscura_render::ShapeGeometry::Mesh { file } => d.meshes[file].clone(),
        other => panic!("{other:?}"),
    };
    let normals = |i: usize| {
        let m = mesh(i);
        let p = m.positions();
        m.triangles()
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| p[v as usize]);
                ((b - a).cross(c - a), (a + b + c) / 3.0)
            })
            .collect::<Vec<_>>()
    };
    // pbrt's disk faces +z at its height; its area is pi r^2 (to the tessellation's error).
    let area: f32 = normals(0)
        .iter()
        .map(|(n, c)| {
            assert!(n.z > 0.0 && (c.z - 0.5).abs() < 1e-6);
            0.5 * n.length()
        })
        .sum();
    assert!(
        (area - std::f32::consts::PI * 4.0).abs() < 0.01 * area,
        "{area}"
    );
    // The cylinder faces outwards.
    for (n, c) in normals(1) {
        assert!(n.x * c.x + n.y * c.y > 0.0);
    }
    // A quarter annulus: within radii 0.5 and 1, x and y >= 0.
    for (_, c) in normals(2) {
        let r = (c.x * c.x + c.y * c.y).sqrt();
        assert!(
            (0.45..=1.0).contains(&r) && c.x >= -1e-6 && c.y >= -1e-6,
            "{c:?}"
        );
    }
}

#[test]
fn image_infinite_lights_keep_pbrts_equal_area_orientation() {
    // pbrt-v4's equal-area square: u > 1/2 is the +x hemisphere, the inner diamond
    // |u - 1/2| + |v - 1/2| < 1/2 the +z one. Paint the first red and the second blue.
    let dir = scratch("pbrt-envmap");
    let n = 64u32;
    let pixels = (0..n * n)
        .map(|i| {
            let (u, v) = (
                (f64::from(i % n) + 0.5) / f64::from(n),
                (f64::from(i / n) + 0.5) / f64::from(n),
            );
            let red = if u > 0.5 { 1.0 } else { 0.0 };
            let blue = if (u - 0.5).abs() + (v - 0.5).abs() < 0.5 {
                1.0
            } else {
                0.0
            };
            [red, 0.0, blue, 1.0]
        })
        .collect();
    obscura_render::write_image(
        &dir.join("sky.exr"),
        &obscura_render::Image {
            width: n,
            height: n,
            pixels,
        },
        &obscura_render::ImageInfo {
            partial: false,
            samples_per_pixel: 1,
        },
    )
    .unwrap();
    let scene = write(
        &dir,
        "sky.pbrt",
        "Camera \"perspective\"\nWorldBegin\nLightSource \"infinite\" \"string filename\" \"sky.exr\"\n",
    );
    let imported = obscura_import::import(&scene).unwrap();
    let look = |mut d: obscura_render::SceneDescription| {
        // An environment camera with the scene format's default look-at: the image centre
        // looks along world -z, the right half towards +x, the left and right edges along +z.
        d.camera.kind = CameraKind::Environment;
        d.camera.pose = None;
        d.film.resolution = [32, 16];
        d.sampler.spp = 1;
        d.integrator.kind = IntegratorKind::Path;
        let scene = obscura_render::RenderScene::build(d).unwrap();
        obscura_render::render(&scene, Default::default())
            .unwrap()
            .film
            .resolve()
    };
    let image = look(imported.description().unwrap());
    let [r, _, b, _] = image.pixel(24, 8); // towards +x, on the horizon
    assert!(r > 0.9, "+x is red: {r}");
    let [r, _, _, _] = image.pixel(8, 8); // towards -x
    assert!(r < 0.1, "-x is not red: {r}");
    let [_, _, b_front, _] = image.pixel(16, 8); // towards -z
    let [_, _, b_back, _] = image.pixel(0, 8); // towards +z
    assert!(
        b_front < 0.1 && b_back > 0.9,
        "+z is blue: {b_front} {b_back} ({b})"
    );
    // Converted, the map is written beside the TOML and renders the same.
    let out = dir.join("converted.toml");
    imported.write(&out).unwrap();
    let converted = look(obscura_render::load_description(&out).unwrap());
    assert_eq!(converted.pixels, image.pixels);
}

/// A scratch folder holding `lenses/dgauss.dat` (the shipped double-Gauss 50 mm), as a pbrt
/// scene beside it names its lens file.
fn lens_scratch(name: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    let lens = include_str!("../../../../scenes/lenses/double-gauss-50mm.dat");
    std::fs::create_dir_all(dir.join("lenses")).unwrap();
    write(&dir.join("lenses"), "dgauss.dat", lens);
    dir
}

#[test]
fn the_realistic_camera_takes_pbrts_parameters_and_defaults() {
    let dir = lens_scratch("pbrt-realistic");
    let scene = "LookAt 0 0 5  0 0 0  0 1 0\n\
                 Camera \"realistic\" \"string lensfile\" \"lenses/dgauss.dat\" \
                 \"float aperturediameter\" 6 \"float focusdistance\" 5\n\
                 Film \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 24 \
                 \"float diagonal\" 30\nWorldBegin\nShape \"sphere\"";
    let path = write(&dir, "realistic.pbrt", scene);
    let d = parse_pbrt(&path, scene).unwrap().description().unwrap();
    assert_eq!(d.camera.kind, CameraKind::Realistic);
    let r = d.camera.realistic.as_ref().unwrap();
    assert_eq!(r.lens_file, dir.join("lenses/dgauss.dat"));
    assert_eq!(
        (r.aperture_diameter, r.focus_distance, r.film_diagonal),
        (Some(6.0), 5.0, 30.0)
    );
    // The film centre's ray through the lens centre looks down the LookAt line.
    let camera = camera_of(&d).unwrap();
    let ray = (0..64)
        .find_map(|k| {
            let u = (k as f32 + 0.5) / 64.0;
            camera.generate_ray(&obscura_camera::CameraSample {
                p_film: obscura_space::Point2::new(16.0, 12.0),
                p_lens: glam::Vec2::new(u, 0.5),
                time: 0.0,
            })
        })
        .expect("some lens sample passes the stop")
        .ray;
    assert!(ray.direction.z < -0.99, "{:?}", ray.direction);

    // pbrt's defaults: aperture 1 mm, focus 10, diagonal 35; the lens file is required.
    let scene = "Camera \"realistic\" \"string lensfile\" \"lenses/dgauss.dat\"\nWorldBegin";
    let path = write(&dir, "defaults.pbrt", scene);
    let d = parse_pbrt(&path, scene).unwrap().description().unwrap();
    let r = d.camera.realistic.as_ref().unwrap();
    assert_eq!(
        (r.aperture_diameter, r.focus_distance, r.film_diagonal),
        (Some(1.0), 10.0, 35.0)
    );
    let e = import_err("Camera \"realistic\"\nWorldBegin");
    assert!(e.to_string().contains("lensfile"), "{e}");
}

/// pbrt-v4's realistic `aperture`: its built-in square and pentagon are polygons of the stop,
/// an image file is the stop's `aperture_image`; "gaussian" and "star" warn and stay round.
#[test]
fn pbrts_aperture_shapes_map_onto_the_stop() {
    use obscura_camera::ApertureShape;
    let dir = lens_scratch("pbrt-aperture");
    // The middle half of the square white, the rest black: pbrt's "square" drawn as a file.
    let mut pixels = vec![[0.0, 0.0, 0.0, 1.0]; 64 * 64];
    for y in 16..48 {
        for x in 16..48 {
            pixels[y * 64 + x] = [1.0, 1.0, 1.0, 1.0];
        }
    }
    let image = obscura_render::Image {
        width: 64,
        height: 64,
        pixels,
    };
    obscura_render::write_image(
        &dir.join("square.png"),
        &image,
        &obscura_render::ImageInfo::default(),
    )
    .unwrap();
    let load = |aperture: &str| {
        let scene = format!(
            "Camera \"realistic\" \"string lensfile\" \"lenses/dgauss.dat\" \
             \"float aperturediameter\" 10 \"string aperture\" \"{aperture}\"\nWorldBegin"
        );
        let path = write(&dir, "aperture.pbrt", &scene);
        let imported = parse_pbrt(&path, &scene).unwrap();
        let warnings = imported.warnings.clone();
        let d = imported.description().unwrap();
        camera_of(&d).expect("the camera builds");
        let diameter = d
            .camera
            .realistic
            .as_ref()
            .unwrap()
            .aperture_diameter
            .unwrap();
        (diameter, d.camera.lens.aperture.shape.clone(), warnings)
    };
    // Square: side r (the middle half of the stop's square), so it sits on the circle of
    // radius r / sqrt(2): diameter 10 / sqrt(2) = 7.0711 mm, corners at 45 degrees.
    let (diameter, shape, _) = load("square");
    assert!((diameter - 7.0711).abs() < 1e-4, "{diameter}");
    let square = ApertureShape::Polygon {
        blades: 4,
        rotation_degrees: 45.0,
    };
    assert_eq!(shape, square);
    // Pentagon: on 0.8 of the stop's circle, a vertex at lens -y (pbrt flips its image).
    let (diameter, shape, _) = load("pentagon");
    assert!((diameter - 8.0).abs() < 1e-5, "{diameter}");
    let pentagon = ApertureShape::Polygon {
        blades: 5,
        rotation_degrees: 270.0,
    };
    assert_eq!(shape, pentagon);
    // The square as a file: the stop's full diameter, the image as its shape.
    let (diameter, shape, _) = load("square.png");
    assert_eq!(diameter, 10.0);
    assert!(matches!(shape, ApertureShape::Image(_)), "{shape:?}");
    // No polygon or file for these: round, and a warning that says so.
    for name in ["gaussian", "star"] {
        let (diameter, shape, warnings) = load(name);
        assert_eq!((diameter, shape), (10.0, ApertureShape::Circle));
        assert!(
            warnings
                .iter()
                .any(|w| w.contains(name) && w.contains("round")),
            "{warnings:?}"
        );
    }
    // A file that is not there is an error naming it.
    let scene = "Camera \"realistic\" \"string lensfile\" \"lenses/dgauss.dat\" \
                 \"string aperture\" \"nothere.png\"\nWorldBegin";
    let path = write(&dir, "missing.pbrt", scene);
    let e = parse_pbrt(&path, scene).expect_err("must fail");
    assert!(e.to_string().contains("nothere.png"), "{e}");
}

/// pbrt's rule for its aperture images, that any shape passes the light of the round stop,
/// holds in the render of the imported scene: under a uniform sky of radiance 1 the film's
/// centre sees 1 with the round stop, the square and the pentagon alike (Obscura's realistic
/// camera weighs each ray by the pupil it was drawn from, so the centre sees the sky's
/// radiance whatever the stop's shape). The Monte Carlo error of the 64-pixel centre at 256
/// samples each, for a pupil that passes 0.4 to 0.8 of its bounding samples, is below 0.3%
/// (binomial: sqrt(0.6 / (0.4 * 16384))); the tolerance of 3% leaves room for the lens's
/// transmission at the centre, which is 1 only to within its glass's geometry.
#[test]
fn a_pbrt_aperture_shape_passes_the_round_stops_light() {
    let dir = lens_scratch("pbrt-aperture-light");
    let centre = |aperture: &str| {
        let scene = format!(
            "Camera \"realistic\" \"string lensfile\" \"lenses/dgauss.dat\" \
             \"float aperturediameter\" 12 {aperture}\n\
             Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16\n\
             Sampler \"zsobol\" \"integer pixelsamples\" 256\n\
             WorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1]\n"
        );
        let path = write(&dir, "light.pbrt", &scene);
        let d = parse_pbrt(&path, &scene).unwrap().description().unwrap();
        let scene = obscura_render::RenderScene::build(d).unwrap();
        let image = obscura_render::render(
            &scene,
            obscura_render::RenderOptions {
                threads: Some(1),
                ..Default::default()
            },
        )
        .unwrap()
        .film
        .resolve();
        let mut sum = 0.0;
        for y in 4..12 {
            for x in 4..12 {
                sum += f64::from(image.pixel(x, y)[1]);
            }
        }
        sum / 64.0
    };
    let round = centre("");
    assert!((round - 1.0).abs() < 0.03, "the round stop: {round}");
    for shape in ["square", "pentagon"] {
        let shaped = centre(&format!("\"string aperture\" \"{shape}\""));
        assert!(
            (shaped / round - 1.0).abs() < 0.03,
            "{shape}: {shaped} against round {round}"
        );
    }
}

/// `path` (absolute) as a path relative to the working folder, as a user in another folder
/// would type it.
fn relative_to_cwd(path: &Path) -> std::path::PathBuf {
    let cwd = std::env::current_dir().unwrap().canonicalize().unwrap();
    let path = path.canonicalize().unwrap();
    let mut rel = std::path::PathBuf::new();
    let common = cwd
        .components()
        .zip(path.components())
        .take_while(|(a, b)| a == b)
        .count();
    for _ in common..cwd.components().count() {
        rel.push("..");
    }
    rel.extend(path.components().skip(common));
    rel
}

#[test]
fn the_lens_file_is_found_from_any_working_folder_and_after_convert() {
    // pbrt-v4 resolves `lensfile` (like every file name) against the folder of the main scene
    // file, whatever the working folder and whichever file the Camera is in. The files go
    // under the target folder, so the relative path from the working folder (the crate's) does
    // not climb to the root, where a doubled prefix (`a/../a/b`) would still find them.
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("obscura-import-{}-lens-folder", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let lens = include_str!("../../../../scenes/lenses/double-gauss-50mm.dat");
    std::fs::create_dir_all(dir.join("scene/lenses")).unwrap();
    std::fs::create_dir_all(dir.join("scene/parts")).unwrap();
    write(&dir.join("scene/lenses"), "dgauss.dat", lens);
    let camera = "LookAt 0 0 5  0 0 0  0 1 0\n\
                  Camera \"realistic\" \"string lensfile\" \"lenses/dgauss.dat\" \
                  \"float aperturediameter\" 5 \"float focusdistance\" 5\n\
                  Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 8\n";
    let direct = write(
        &dir.join("scene"),
        "real.pbrt",
        &format!("{camera}WorldBegin\nShape \"sphere\"\n"),
    );
    write(&dir.join("scene/parts"), "camera.pbrt", camera);
    let included = write(
        &dir.join("scene"),
        "included.pbrt",
        "Include \"parts/camera.pbrt\"\nWorldBegin\nShape \"sphere\"\n",
    );
    let want = dir.join("scene/lenses/dgauss.dat").canonicalize().unwrap();
    for scene in [&direct, &included] {
        // Named from the working folder by a relative path that does not start at the scene.
        let relative = relative_to_cwd(scene);
        let cwd_depth = std::env::current_dir().unwrap().components().count();
        let ups = relative
            .components()
            .filter(|c| *c == std::path::Component::ParentDir)
            .count();
        assert!(ups + 1 < cwd_depth, "{}", relative.display());
        let imported = obscura_import::import(&relative).unwrap();
        let d = imported.description().expect("the lens file is found");
        let found = &d.camera.realistic.as_ref().unwrap().lens_file;
        assert_eq!(found.canonicalize().unwrap(), want, "{}", scene.display());
        camera_of(&d).expect("the lens system builds");

        // Converted into another folder, the TOML names the lens file so that it is found
        // from there; converted beside the scene, it keeps the relative name.
        let elsewhere = dir.join("out/sub/real.toml");
        std::fs::create_dir_all(elsewhere.parent().unwrap()).unwrap();
        imported
            .write(&relative_to_cwd(&dir.join("out/sub")).join("real.toml"))
            .unwrap();
        let d = obscura_render::load_description(&elsewhere).expect("the copy loads");
        let found = &d.camera.realistic.as_ref().unwrap().lens_file;
        assert_eq!(found.canonicalize().unwrap(), want);
        let beside = dir.join("scene/beside.toml");
        imported.write(&beside).unwrap();
        let text = std::fs::read_to_string(&beside).unwrap();
        assert!(text.contains("lens_file = \"lenses/dgauss.dat\""), "{text}");
        obscura_render::load_description(&beside).expect("the copy beside loads");
    }
}

/// The world position of object point `p` under a shape's transform.
fn placed(t: &obscura_space::Transform<World, obscura_space::Object>, p: [f32; 3]) -> glam::Vec3 {
    t.matrix().transform_point3(glam::Vec3::from(p))
}

fn assert_near(got: glam::Vec3, want: [f64; 3], what: &str) {
    let want = glam::DVec3::from(want).as_vec3();
    assert!(
        (got - want).length() < 1e-5,
        "{what}: {got:?}, want {want:?}"
    );
}

#[test]
fn transform_times_place_the_motion_on_the_shutter_as_pbrt_does() {
    // pbrt-v4's AnimatedTransform: the transform at time t is the start and end transforms'
    // decompositions (translation T, rotation quaternion R, stretch S) blended at
    // u = (t - t0) / (t1 - t0): T and S linearly, R by slerp. Here t0 = 0, t1 = 2 and the
    // shutter is [0, 1], so at shutter close u = 1/2:
    // - the camera's eye moves from (0, 0, 5) to (2, 0, 5) without turning: (1, 0, 5);
    // - the sphere goes from the identity to T(0, 2, 0) R_z(90) S(3): T = (0, 1, 0),
    //   R = R_z(45), S = 2, so object point (1, 0, 0) is at (2 cos 45, 1 + 2 sin 45, 0).
    // At t = 0.5 (u = 1/4): T = (0, 0.5, 0), R = R_z(22.5), S = 1.5.
    let text = "TransformTimes 0 2\n\
                ActiveTransform StartTime\nLookAt 0 0 5  0 0 0  0 1 0\n\
                ActiveTransform EndTime\nLookAt 2 0 5  2 0 0  0 1 0\n\
                ActiveTransform All\n\
                Camera \"perspective\" \"float shutteropen\" 0 \"float shutterclose\" 1\n\
                WorldBegin\nAttributeBegin\nActiveTransform EndTime\n\
                Translate 0 2 0\nRotate 90 0 0 1\nScale 3 3 3\nActiveTransform All\n\
                Shape \"sphere\"\nAttributeEnd\n";
    let d = import(text).description().unwrap();
    let (pose, pose_end) = d.camera.pose.unwrap();
    let eye = |t: &obscura_space::Transform<World, obscura_space::Camera>| {
        t.matrix().transform_point3(glam::Vec3::ZERO)
    };
    assert_near(eye(&pose), [0.0, 0.0, 5.0], "eye at shutter open");
    assert_near(
        eye(&pose_end.unwrap()),
        [1.0, 0.0, 5.0],
        "eye at shutter close",
    );
    let s = &d.shapes[0];
    let end = s.transform_end.expect("the sphere moves");
    assert_near(
        placed(&s.transform, [1.0, 0.0, 0.0]),
        [1.0, 0.0, 0.0],
        "open",
    );
    let h = std::f64::consts::FRAC_1_SQRT_2;
    assert_near(
        placed(&end, [1.0, 0.0, 0.0]),
        [2.0 * h, 1.0 + 2.0 * h, 0.0],
        "close",
    );
    // In between, the renderer's motion from open to close is pbrt's.
    let motion = obscura_space::AnimatedTransform::new(s.transform, 0.0, end, 1.0).unwrap();
    let (c, sn) = (22.5f64.to_radians().cos(), 22.5f64.to_radians().sin());
    assert_near(
        placed(&motion.at(0.5), [1.0, 0.0, 0.0]),
        [1.5 * c, 0.5 + 1.5 * sn, 0.0],
        "t = 0.5",
    );

    // A shutter inside the transform times: TransformTimes 0 4, shutter [1, 3], a move from
    // x = 0 to x = 4 is at x = 1 at open and x = 3 at close.
    let d = import(
        "TransformTimes 0 4\nCamera \"perspective\" \"float shutteropen\" 1 \"float shutterclose\" 3\n\
         WorldBegin\nActiveTransform EndTime\nTranslate 4 0 0\nActiveTransform All\nShape \"sphere\"\n",
    )
    .description()
    .unwrap();
    let s = &d.shapes[0];
    assert_near(placed(&s.transform, [0.0; 3]), [1.0, 0.0, 0.0], "open");
    assert_near(
        placed(&s.transform_end.unwrap(), [0.0; 3]),
        [3.0, 0.0, 0.0],
        "close",
    );

    // A shutter wholly after the transform times sees pbrt's end transform, held: no motion.
    let d = import(
        "TransformTimes 0 0.5\nCamera \"perspective\" \"float shutteropen\" 1 \"float shutterclose\" 2\n\
         WorldBegin\nActiveTransform EndTime\nTranslate 4 0 0\nActiveTransform All\nShape \"sphere\"\n",
    )
    .description()
    .unwrap();
    assert!(d.shapes[0].transform_end.is_none());
    assert_near(
        placed(&d.shapes[0].transform, [0.0; 3]),
        [4.0, 0.0, 0.0],
        "held",
    );
}

#[test]
fn a_shutter_beyond_the_transform_times_is_an_error_naming_transform_times() {
    // pbrt holds the end transform after t1 = 0.5, so over the shutter [0, 1] the camera (or
    // the sphere) moves, then stops: two transforms at shutter open and close cannot say that.
    for (what, text) in [
        (
            "camera",
            "LookAt 0 0 5  0 0 0  0 1 0\nTransformTimes 0 0.5\nActiveTransform EndTime\n\
             Translate 1 0 0\nActiveTransform All\nCamera \"perspective\"\nWorldBegin\n\
             Shape \"sphere\"\n",
        ),
        (
            "shape",
            "LookAt 0 0 5  0 0 0  0 1 0\nTransformTimes 0 0.5\nCamera \"perspective\"\n\
             WorldBegin\nActiveTransform EndTime\nTranslate 1 0 0\nActiveTransform All\n\
             Shape \"sphere\"\n",
        ),
    ] {
        let e = import_err(text);
        assert_eq!(line_of(&e), Some(2), "{what}: {e}");
        let message = e.to_string();
        assert!(
            message.contains("test.pbrt:2") && message.contains("TransformTimes"),
            "{what}: {message}"
        );
        assert!(message.contains(what), "{what}: {message}");
    }
    // Nothing moves: the times do not matter.
    import("TransformTimes 0 0.5\nCamera \"perspective\"\nWorldBegin\nShape \"sphere\"\n")
        .description()
        .unwrap();
    // pbrt-v4 takes TransformTimes only before WorldBegin.
    let e = import_err("Camera \"perspective\"\nWorldBegin\nTransformTimes 0 2\n");
    assert_eq!(line_of(&e), Some(3), "{e}");
    assert!(e.to_string().contains("WorldBegin"), "{e}");
}
