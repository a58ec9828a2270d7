//! Mitsuba 3 scenes: sensor defaults, Mitsuba's (unmirrored) image orientation and principal
//! point, the same image as the equivalent TOML, `<default>` substitution, errors with lines.

use crate::{assert_images_close, render_aov, scratch, toml_scene, write};
use obscura_camera::Camera;
use obscura_import::{ImportError, parse_mitsuba};
use obscura_render::{CameraKind, IntegratorKind, camera_of};
use obscura_space::{Point3, World};
use proptest::prelude::*;
use std::path::Path;

fn import(text: &str) -> obscura_import::Imported {
    parse_mitsuba(Path::new("/nonexistent/test.xml"), text).expect("imports")
}

fn import_err(text: &str) -> ImportError {
    parse_mitsuba(Path::new("/nonexistent/test.xml"), text)
        .and_then(|i| i.description())
        .expect_err("must fail")
}

fn line_of(e: &ImportError) -> Option<usize> {
    match e {
        ImportError::Scene { line, .. } => *line,
        ImportError::Render(obscura_render::RenderError::Scene { line, .. }) => *line,
        _ => None,
    }
}

#[test]
fn sensor_defaults_are_mitsubas() {
    // Mitsuba 3's documented defaults: a 50 mm lens (its fov spans the 36 x 24 mm diagonal),
    // near_clip 0.01, far_clip 10000, focus_distance = far_clip, shutter [0, 0]; hdrfilm
    // 768 x 576; the independent sampler at 4 spp.
    let d = import(r#"<scene version="3.0.0"><sensor type="perspective"/></scene>"#)
        .description()
        .unwrap();
    let diagonal = 2.0 * (43.266615305567875f64 / 100.0).atan().to_degrees();
    assert_eq!(d.camera.kind, CameraKind::Perspective);
    assert!(
        (f64::from(d.camera.fov) - diagonal).abs() < 1e-4,
        "{}",
        d.camera.fov
    );
    assert_eq!(d.camera.fov_axis, obscura_camera::FovAxis::Diagonal);
    assert_eq!((d.camera.near, d.camera.far), (0.01, 1.0e4));
    assert_eq!(d.camera.lens.focal_distance, 1.0e4);
    assert_eq!((d.camera.shutter.open, d.camera.shutter.close), (0.0, 0.0));
    assert_eq!(d.film.resolution, [768, 576]);
    assert_eq!(d.sampler.kind.name(), "independent");
    assert_eq!(d.sampler.spp, 4);
    // hdrfilm's default rfilter: a Gaussian of stddev 0.5, cut at 4 stddev.
    assert_eq!(
        d.film.filter,
        obscura_render::FilterSettings::Gaussian {
            radius: 2.0,
            sigma: 0.5
        }
    );

    // fov_axis defaults to x; thinlens reads aperture_radius and focus_distance.
    let d = import(
        r#"<scene version="3.0.0"><sensor type="thinlens">
            <float name="fov" value="30"/><float name="aperture_radius" value="0.2"/>
            <float name="focus_distance" value="4"/></sensor></scene>"#,
    )
    .description()
    .unwrap();
    assert_eq!(d.camera.fov_axis, obscura_camera::FovAxis::X);
    assert_eq!(
        (d.camera.lens.radius, d.camera.lens.focal_distance),
        (0.2, 4.0)
    );
}

/// Each rfilter becomes Obscura's filter of the same profile: Mitsuba 3's `gaussian` is
/// `e^(-x^2 / 2 stddev^2) - e^(-8)` cut at 4 stddev (its source, `rfilters/gaussian.cpp`),
/// `tent` falls to 0 at its radius (default 1), and `box` covers its own pixel.
#[test]
fn rfilters_map_to_the_same_profile() {
    use obscura_render::FilterSettings;
    let scene = |rfilter: &str| {
        format!(
            "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><film type=\"hdrfilm\">\n\
             {rfilter}\n</film></sensor></scene>"
        )
    };
    for (rfilter, want) in [
        (
            "<rfilter type=\"gaussian\"/>",
            FilterSettings::Gaussian {
                radius: 2.0,
                sigma: 0.5,
            },
        ),
        (
            "<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"0.25\"/></rfilter>",
            FilterSettings::Gaussian {
                radius: 1.0,
                sigma: 0.25,
            },
        ),
        (
            "<rfilter type=\"tent\"><float name=\"radius\" value=\"1.5\"/></rfilter>",
            FilterSettings::Triangle { radius: 1.5 },
        ),
        (
            "<rfilter type=\"tent\"/>",
            FilterSettings::Triangle { radius: 1.0 },
        ),
        (
            "<rfilter type=\"box\"/>",
            FilterSettings::Box { radius: 0.5 },
        ),
        (
            "<rfilter type=\"mitchell\"><float name=\"B\" value=\"0.33333333\"/></rfilter>",
            FilterSettings::Mitchell { radius: 2.0 },
        ),
    ] {
        let imported = import(&scene(rfilter));
        assert!(
            imported.warnings.is_empty(),
            "{rfilter}: {:?}",
            imported.warnings
        );
        let d = imported.description().unwrap();
        assert_eq!(d.film.filter, want, "{rfilter}");
    }
    // Imported with a warning at the rfilter's line: a Gaussian wider than Obscura's widest
    // filter, cut at 16 pixels, and a Mitchell-Netravali other than B = C = 1/3.
    for (rfilter, warned, want) in [
        (
            "<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"5\"/></rfilter>",
            "cut at Obscura's widest radius",
            FilterSettings::Gaussian {
                radius: 16.0,
                sigma: 5.0,
            },
        ),
        (
            "<rfilter type=\"mitchell\"><float name=\"B\" value=\"0\"/><float name=\"C\" value=\"0.5\"/></rfilter>",
            "B = 0, C = 0.5",
            FilterSettings::Mitchell { radius: 2.0 },
        ),
    ] {
        let imported = import(&scene(rfilter));
        let w = &imported.warnings;
        assert!(
            w.len() == 1 && w[0].contains("test.xml:3") && w[0].contains(warned),
            "{rfilter}: {w:?}"
        );
        assert_eq!(
            imported.description().unwrap().film.filter,
            want,
            "{rfilter}"
        );
    }
    for stddev in ["0", "-0.5"] {
        let e = import_err(&scene(&format!(
            "<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"{stddev}\"/></rfilter>"
        )));
        assert_eq!(line_of(&e), Some(3), "{stddev}: {e}");
        assert!(
            e.to_string().contains("stddev must be > 0"),
            "{stddev}: {e}"
        );
    }
}

/// Where Mitsuba 3 puts world point `p`, by hand: its look-at frame (left = cross(up, dir)),
/// the horizontal fov `x_fov`, and its sample mapping u = (1 - x/z / t) / 2,
/// v = (1 - aspect y/z / t) / 2 with t = tan(x_fov / 2), shifted by the principal point.
fn mitsuba_raster(
    origin: [f64; 3],
    target: [f64; 3],
    up: [f64; 3],
    x_fov: f64,
    w: f64,
    h: f64,
    ppo: [f64; 2],
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
    let dir = norm(sub(target, origin));
    let left = norm(cross(up, dir));
    let new_up = cross(dir, left);
    let d = sub(p, origin);
    let (x, y, z) = (dot(d, left), dot(d, new_up), dot(d, dir));
    let t = (x_fov.to_radians() / 2.0).tan();
    let aspect = w / h;
    let u = (1.0 - x / z / t) / 2.0 - ppo[0];
    let v = (1.0 - aspect * y / z / t) / 2.0 - ppo[1];
    [u * w, v * h]
}

#[test]
fn orientation_fov_axes_and_principal_point_match_mitsuba() {
    let (origin, target, up) = ([1.0, 2.0, 6.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let (w, h) = (64.0, 48.0);
    let aspect = w / h;
    for (axis, fov, x_fov) in [
        ("x", 50.0f64, 50.0f64),
        (
            "y",
            40.0,
            2.0 * ((20.0f64).to_radians().tan() * aspect).atan().to_degrees(),
        ),
        (
            "smaller",
            40.0,
            2.0 * ((20.0f64).to_radians().tan() * aspect).atan().to_degrees(),
        ),
    ] {
        for ppo in [[0.0, 0.0], [0.1, -0.05]] {
            let text = format!(
                r#"<scene version="3.0.0"><sensor type="perspective">
                <float name="fov" value="{fov}"/><string name="fov_axis" value="{axis}"/>
                <float name="principal_point_offset_x" value="{}"/>
                <float name="principal_point_offset_y" value="{}"/>
                <transform name="to_world"><lookat origin="1, 2, 6" target="0, 0, 0" up="0, 1, 0"/></transform>
                <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="48"/></film>
                </sensor></scene>"#,
                ppo[0], ppo[1]
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
                let want = mitsuba_raster(origin, target, up, x_fov, w, h, ppo, p);
                assert!(
                    (got.x as f64 - want[0]).abs() < 2e-3 && (got.y as f64 - want[1]).abs() < 2e-3,
                    "axis {axis}, ppo {ppo:?}, point {p:?}: got ({}, {}), Mitsuba puts it at {want:?}",
                    got.x,
                    got.y
                );
            }
            // Not mirrored: from (1, 2, 6), world +x of the origin is right of it in the image.
            let r = camera
                .project(Point3::<World>::new(1.0, 0.0, 0.0), 0.0)
                .unwrap();
            let c = camera
                .project(Point3::<World>::new(0.0, 0.0, 0.0), 0.0)
                .unwrap();
            assert!(r.x > c.x);
        }
    }
}

const XML_SCENE: &str = r#"<scene version="3.0.0">
    <default name="res_x" value="48"/>
    <sensor type="perspective">
        <float name="fov" value="35"/>
        <string name="fov_axis" value="y"/>
        <transform name="to_world">
            <lookat origin="0.5, 1.5, 6" target="0, 0.25, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent"><integer name="sample_count" value="1"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="$res_x"/><integer name="height" value="36"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <bsdf type="twosided" id="grey"><bsdf type="diffuse"/></bsdf>
    <shape type="sphere">
        <point name="center" x="0.8" y="0.3" z="0"/>
        <float name="radius" value="0.6"/>
        <ref id="grey"/>
    </shape>
    <shape type="obj">
        <string name="filename" value="pyramid.obj"/>
        <transform name="to_world">
            <scale value="0.5"/>
            <rotate y="1" angle="30"/>
            <translate x="-0.7" y="0" z="0.5"/>
        </transform>
    </shape>
    <shape type="rectangle">
        <transform name="to_world">
            <rotate x="1" angle="-90"/>
            <scale value="4"/>
            <translate y="-0.5"/>
        </transform>
    </shape>
</scene>
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
fov_axis = "y"
near = 0.01
far = 1.0e4
[[shapes]]
type = "sphere"
center = [0.8, 0.3, 0.0]
radius = 0.6
[[shapes]]
type = "mesh"
file = "pyramid.obj"
transform = [{ scale = [0.5, 0.5, 0.5] }, { rotate = [30.0, 0.0, 1.0, 0.0] }, { translate = [-0.7, 0.0, 0.5] }]
[[shapes]]
type = "quad"
origin = [-4.0, -0.5, 4.0]
edge_u = [8.0, 0.0, 0.0]
edge_v = [0.0, 0.0, -8.0]
"#;

const PYRAMID_OBJ: &str =
    "v -1 0 -1\nv 1 0 -1\nv 1 2 -1\nv -1 2 -1\nv 0 1 1\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n";

#[test]
fn a_mitsuba_scene_renders_as_its_toml_equivalent() {
    let dir = scratch("mitsuba-equivalent");
    write(&dir, "pyramid.obj", PYRAMID_OBJ);
    let reference = toml_scene(&dir, "reference.toml", TOML_SCENE);
    let xml = write(&dir, "scene.xml", XML_SCENE);
    let imported = obscura_import::import(&xml).unwrap();
    let d = imported.description().unwrap();
    assert_eq!(d.film.resolution, [48, 36], "$res_x substituted");
    for kind in [
        IntegratorKind::Position,
        IntegratorKind::Depth,
        IntegratorKind::Normal,
    ] {
        let a = render_aov(d.clone(), kind);
        let b = render_aov(reference.clone(), kind);
        assert_images_close(&a, &b, 1e-4);
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
fn bsdfs_and_emitters_map() {
    let d = import(
        r#"<scene version="3.0.0"><sensor type="perspective"/>
        <bsdf type="roughconductor" id="metal"><float name="alpha" value="0.25"/><string name="distribution" value="ggx"/></bsdf>
        <bsdf type="dielectric" id="glass"><string name="int_ior" value="water"/><float name="ext_ior" value="1"/></bsdf>
        <shape type="sphere"><ref id="metal"/></shape>
        <shape type="sphere"><ref id="glass"/><emitter type="area"><rgb name="radiance" value="1, 2, 3"/></emitter></shape>
        <shape type="cube"/>
        <emitter type="point"><point name="position" value="0, 5, 0"/><rgb name="intensity" value="7"/></emitter>
        <emitter type="directional"><vector name="direction" value="0, -2, 0"/></emitter>
        <emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>
        </scene>"#,
    )
    .description()
    .unwrap();
    use obscura_render::{LightSettings as L, MaterialSettings as M};
    let m = |i: usize| d.materials[d.shapes[i].material.unwrap()].1;
    // Mitsuba's GGX alpha 0.25 is Obscura's roughness 0.5.
    assert!(matches!(m(0), M::RoughConductor { roughness, .. } if (roughness - 0.5).abs() < 1e-6));
    assert_eq!(m(1), M::Dielectric { ior: 1.333 });
    assert_eq!(d.shapes[1].emission, Some([1.0, 2.0, 3.0]));
    assert!(matches!(
        d.lights[0],
        L::Point {
            position: [0.0, 5.0, 0.0],
            intensity: [7.0, 7.0, 7.0]
        }
    ));
    assert!(matches!(
        d.lights[1],
        L::Distant {
            direction: [0.0, -1.0, 0.0],
            irradiance: [1.0, 1.0, 1.0]
        }
    ));
    assert!(matches!(
        d.lights[2],
        L::Environment {
            radiance: [0.5, 0.5, 0.5],
            file: None,
            ..
        }
    ));
    assert_eq!(d.shapes.len(), 3);
}

#[test]
fn bad_input_names_file_and_line() {
    for (text, line) in [
        (
            "<scene version=\"3.0.0\">\n<sensor type=\"perspective\">\n</scene>",
            3,
        ),
        (
            "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n<shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape></scene>",
            3,
        ),
        (
            "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n\n<shape type=\"sphere\"><ref id=\"nope\"/></shape></scene>",
            4,
        ),
        (
            "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><float name=\"fov\" value=\"190\"/></sensor></scene>",
            2,
        ),
        (
            "<scene version=\"3.0.0\">\n<sensor type=\"fisheye\"/></scene>",
            2,
        ),
        (
            "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n<shape type=\"obj\"><string name=\"filename\" value=\"missing.obj\"/></shape></scene>",
            3,
        ),
        (
            "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n<shape type=\"sphere\"><float name=\"radius\" value=\"x\"/></shape></scene>",
            3,
        ),
    ] {
        let e = import_err(text);
        assert!(e.to_string().starts_with("/nonexistent/test.xml:"), "{e}");
        assert_eq!(line_of(&e), Some(line), "{text:?}: {e}");
    }
    // No sensor: an error naming the file.
    assert!(
        import_err("<scene version=\"3.0.0\"/>")
            .to_string()
            .contains("no <sensor>")
    );
}

/// XML-ish text built from Mitsuba's vocabulary.
fn xml_soup() -> impl Strategy<Value = String> {
    let token = prop_oneof![
        Just("<sensor type=\"perspective\">".to_string()),
        Just("<sensor type=\"orthographic\">".to_string()),
        Just("</sensor>".to_string()),
        Just("<shape type=\"sphere\">".to_string()),
        Just("<shape type=\"rectangle\">".to_string()),
        Just("<shape type=\"cube\"/>".to_string()),
        Just("</shape>".to_string()),
        Just("<transform name=\"to_world\">".to_string()),
        Just("</transform>".to_string()),
        Just("<scale value=\"0\"/>".to_string()),
        Just("<rotate x=\"1\" angle=\"$a\"/>".to_string()),
        Just("<lookat origin=\"0,0,0\" target=\"0,0,0\"/>".to_string()),
        Just("<matrix value=\"1 2 3\"/>".to_string()),
        Just("<float name=\"fov\" value=\"1e40\"/>".to_string()),
        Just("<float name=\"radius\" value=\"-1\"/>".to_string()),
        Just("<default name=\"a\" value=\"3\"/>".to_string()),
        Just("<emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter>".to_string()),
        Just("<emitter type=\"point\"/>".to_string()),
        Just("<bsdf type=\"twosided\" id=\"b\">".to_string()),
        Just("</bsdf>".to_string()),
        Just("<ref id=\"b\"/>".to_string()),
        Just("<film type=\"hdrfilm\"><integer name=\"width\" value=\"0\"/></film>".to_string()),
        "\\PC{0,5}",
    ];
    proptest::collection::vec(token, 0..30)
        .prop_map(|t| format!("<scene version=\"3.0.0\">{}</scene>", t.join("")))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn no_mitsuba_input_panics(text in xml_soup()) {
        if let Ok(imported) = parse_mitsuba(Path::new("/nonexistent/fuzz.xml"), &text)
            && let Ok(d) = imported.description() {
                let _ = obscura_render::RenderScene::build(d);
            }
    }
}

#[test]
fn orthographic_takes_its_extent_from_to_worlds_scale() {
    // Mitsuba's orthographic camera sees [-1, 1] x [-1/aspect, 1/aspect] in its local frame,
    // scaled by to_world: sample u = (1 - x/s) / 2, v = (1 - aspect y/s) / 2, x along its
    // `left` axis.
    let d = import(
        r#"<scene version="3.0.0"><sensor type="orthographic">
        <transform name="to_world"><scale value="2"/><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="40"/><integer name="height" value="20"/></film>
        </sensor></scene>"#,
    )
    .description()
    .unwrap();
    assert_eq!(d.camera.kind, CameraKind::Orthographic);
    let camera = camera_of(&d).unwrap();
    for (x, y) in [(0.5f64, 0.25f64), (-1.5, -0.6), (0.0, 0.0)] {
        // From (0, 0, 5) looking at -z with up +y, Mitsuba's `left` is cross(up, dir) = -x.
        let left = -x;
        let (u, v) = ((1.0 - left / 2.0) / 2.0, (1.0 - 2.0 * y / 2.0) / 2.0);
        let r = camera
            .project(Point3::<World>::new(x as f32, y as f32, 0.0), 0.0)
            .unwrap();
        assert!(
            (r.x as f64 - 40.0 * u).abs() < 1e-3 && (r.y as f64 - 20.0 * v).abs() < 1e-3,
            "({x}, {y}) -> ({}, {})",
            r.x,
            r.y
        );
    }
}

#[test]
fn envmaps_keep_mitsubas_orientation() {
    // A map red where u < 0.5, green elsewhere. Mitsuba looks a direction d up at
    // u = atan2(d.x, -d.z) / 2 pi (mod 1): the +x hemisphere is red.
    let dir = scratch("mitsuba-envmap");
    let (w, h) = (8u32, 4u32);
    let pixels = (0..w * h)
        .map(|i| {
            if i % w < w / 2 {
                [1.0, 0.0, 0.0, 1.0]
            } else {
                [0.0, 1.0, 0.0, 1.0]
            }
        })
        .collect();
    let map = obscura_render::Image {
        width: w,
        height: h,
        pixels,
    };
    obscura_render::write_image(
        &dir.join("map.exr"),
        &map,
        &obscura_render::ImageInfo {
            partial: false,
            samples_per_pixel: 1,
        },
    )
    .unwrap();
    let xml = write(
        &dir,
        "env.xml",
        r#"<scene version="3.0.0"><sensor type="perspective"/>
        <emitter type="envmap"><string name="filename" value="map.exr"/></emitter></scene>"#,
    );
    let mut d = obscura_import::import(&xml).unwrap().description().unwrap();
    // Look at it with an environment camera: image centre along -z, right half towards +x.
    d.camera.kind = CameraKind::Environment;
    d.camera.pose = None;
    d.film.resolution = [16, 8];
    d.sampler.spp = 1;
    d.integrator.kind = IntegratorKind::Path;
    let scene = obscura_render::RenderScene::build(d).unwrap();
    let image = obscura_render::render(&scene, Default::default())
        .unwrap()
        .film
        .resolve();
    let towards_plus_x = image.pixel(12, 4);
    let towards_minus_x = image.pixel(4, 4);
    assert!(
        towards_plus_x[0] > 0.9 && towards_plus_x[1] < 0.1,
        "{towards_plus_x:?}"
    );
    assert!(
        towards_minus_x[1] > 0.9 && towards_minus_x[0] < 0.1,
        "{towards_minus_x:?}"
    );
}

#[test]
fn max_depth_counts_the_emitter_vertex_as_mitsuba_does() {
    // Mitsuba 3's documentation: max_depth 1 renders only directly visible emitters, 2 adds
    // direct illumination. Obscura's max_depth counts bounces (1 is direct illumination) and
    // has no emitters-only setting, so Mitsuba's 1 is refused with the line.
    for (mitsuba, ours) in [(2, 1), (3, 2), (7, 6)] {
        let d = import(&format!(
            r#"<scene version="3.0.0"><integrator type="path">
                <integer name="max_depth" value="{mitsuba}"/></integrator>
                <sensor type="perspective"/></scene>"#
        ))
        .description()
        .unwrap();
        assert_eq!(d.integrator.max_depth, ours, "Mitsuba max_depth {mitsuba}");
    }
    let d = import(
        r#"<scene version="3.0.0"><integrator type="direct"/><sensor type="perspective"/></scene>"#,
    )
    .description()
    .unwrap();
    assert_eq!(d.integrator.max_depth, 1);
    let e = import_err(
        r#"<scene version="3.0.0"><integrator type="path">
            <integer name="max_depth" value="1"/></integrator><sensor type="perspective"/></scene>"#,
    );
    assert!(e.to_string().contains("max_depth 1"), "{e}");
    assert_eq!(line_of(&e), Some(1));
}

#[test]
fn deep_nesting_is_an_error_at_its_line_not_a_stack_overflow() {
    // `<scene>` holding `n` nested shapes, one element per line: the root is level 1 on line
    // 1, the sensor line 2, and the k-th nested shape (level k + 1) is on line k + 2. Attribute
    // values, a comment and a CDATA section hold tag-like text that must not count.
    let nested = |n: usize| {
        let mut s = String::from("<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n");
        for _ in 0..n {
            s.push_str("<shape type=\"sphere\" id='a>b/>'><!-- <x> --><![CDATA[<y>]]>\n");
        }
        for _ in 0..n {
            s.push_str("</shape>");
        }
        s + "</scene>\n"
    };
    // 255 nested shapes reach level 256, the limit: imported.
    import(&nested(255)).description().unwrap();
    // One more is refused at the 256th shape's line; far more (enough to overflow the stack
    // of the recursive XML parser) fails the same way, as the CLI's exit status 2.
    for n in [256, 200_000] {
        let e =
            parse_mitsuba(Path::new("/nonexistent/deep.xml"), &nested(n)).expect_err("too deep");
        assert_eq!(line_of(&e), Some(258), "{e}");
        assert!(
            e.to_string()
                .starts_with("/nonexistent/deep.xml:258: elements nested more than 256"),
            "{e}"
        );
    }
}
