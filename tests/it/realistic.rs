//! The realistic camera from scene files: each shipped lens renders the spheres upright and in
//! the places `project` gives, and a uniform sky renders as 1 at the image centre.

use super::{aov, miss_rms, render_image, root, shipped};
use obscura_camera::{AnyCamera, Camera, LensPrescription};
use obscura_render::{
    FilterSettings, Image, IntegratorKind, LightSettings, RenderScene, SceneDescription,
};
use obscura_space::{Point3, Transform, World};

/// The shipped realistic scene with another of the shipped lenses.
fn with_lens(file: &str) -> SceneDescription {
    let mut d = shipped("spheres-realistic.toml");
    let r = d.camera.realistic.as_mut().expect("a realistic camera");
    let path = root().join("scenes").join("lenses").join(file);
    r.prescription = LensPrescription::parse(&std::fs::read_to_string(&path).unwrap()).unwrap();
    r.lens_file = path;
    d
}

const LENSES: [&str; 3] = [
    "double-gauss-50mm.dat",
    "wide-angle-22mm.dat",
    "telephoto-250mm.dat",
];

fn pixel(image: &Image, x: u32, y: u32) -> [f32; 3] {
    let p = image.pixels[(y * image.width + x) as usize];
    [p[0], p[1], p[2]]
}

#[test]
fn each_lens_renders_the_spheres_where_project_puts_them() {
    for lens in LENSES {
        let mut d = aov(with_lens(lens), IntegratorKind::Albedo, [96, 64], 8);
        d.film.filter = FilterSettings::Box { radius: 0.5 };
        let scene = RenderScene::build(d.clone()).unwrap();
        let image = render_image(d, 2);
        let at = |p: [f32; 3]| {
            scene
                .camera
                .project(Point3::<World>::new(p[0], p[1], p[2]), 0.0)
                .unwrap_or_else(|| panic!("{lens}: {p:?} does not project"))
        };
        // The green sphere (in focus) is green where its centre projects.
        let g = at([0.0, 0.7, 0.0]);
        assert!(
            (0.0..96.0).contains(&g.x) && (0.0..64.0).contains(&g.y),
            "{lens}: {g:?}"
        );
        let [r, gr, b] = pixel(&image, g.x as u32, g.y as u32);
        assert!(
            (gr - 0.7).abs() < 0.05 && (r - 0.2).abs() < 0.05 && (b - 0.25).abs() < 0.05,
            "{lens}: {:?} at {g:?}",
            [r, gr, b]
        );
        // Upright and unmirrored: the red sphere (world -x) left of the green, the blue one
        // (+x, nearer) right of it and lower. (The telephoto's field holds the green sphere
        // only: the others lie beyond the angles its chief rays reach.)
        if lens == "telephoto-250mm.dat" {
            continue;
        }
        let (red, blue) = (at([-1.6, 0.7, -1.5]), at([1.6, 0.7, 1.5]));
        assert!(red.x < g.x && g.x < blue.x && blue.y > g.y, "{lens}");
        let [r, gr, b] = pixel(&image, red.x as u32, red.y as u32);
        assert!(r > gr && r > b, "{lens}: red sphere {:?}", [r, gr, b]);
    }
}

/// The scene's camera alone under a uniform sky of radiance 1: 9 x 9 pixels, 4096 samples.
fn under_a_uniform_sky(d: SceneDescription) -> Image {
    let mut d = aov(d, IntegratorKind::Path, [9, 9], 4096);
    d.film.filter = FilterSettings::Box { radius: 0.5 };
    d.shapes.clear();
    d.lights = vec![LightSettings::Environment {
        radiance: [1.0, 1.0, 1.0],
        file: None,
        transform: Transform::<World, World>::IDENTITY,
    }];
    render_image(d, 2)
}

#[test]
fn a_uniform_sky_renders_as_one_at_the_centre_and_darker_in_the_corners() {
    for lens in LENSES {
        let image = under_a_uniform_sky(with_lens(lens));
        // About 4096 samples of values in [0, ~2]: a standard error near 0.01.
        let centre = pixel(&image, 4, 4)[0];
        assert!((centre - 1.0).abs() < 0.05, "{lens}: centre {centre}");
        let corner = pixel(&image, 0, 0)[0];
        assert!(
            corner < centre,
            "{lens}: corner {corner} vs centre {centre}"
        );
    }
}

#[test]
fn the_stop_takes_the_aperture_keys_of_the_scene_file() {
    // `anamorphic` and `aperture_blades` on a realistic camera reach its stop (they were once
    // noted as ignored), and the image centre of a uniform sky still renders as 1: the
    // normaliser counts the squeezed stop's smaller opening.
    let path = root().join("scenes").join("spheres-realistic.toml");
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "film_diagonal = 35.0",
        "film_diagonal = 35.0\nanamorphic = 2.0\naperture_blades = 6",
    );
    let d = obscura_render::parse_description(&path, &text).unwrap();
    assert!(d.ignored.is_empty(), "{:?}", d.ignored);
    let scene = RenderScene::build(d.clone()).unwrap();
    let AnyCamera::Realistic(camera) = &scene.camera else {
        panic!("not a realistic camera");
    };
    assert_eq!(camera.lens().aperture.anamorphic, 2.0);
    assert_eq!(camera.lens().aperture.blades(), 6);

    let centre = pixel(&under_a_uniform_sky(d), 4, 4)[0];
    assert!((centre - 1.0).abs() < 0.05, "centre {centre}");
}

/// A realistic camera at the origin looking down world -z (camera +z), focused 0.5 m away
/// with `extra` camera keys, and three small spheres whose camera-space centres are
/// (-0.1, 0, 0.416), (0, 0, 0.5) and (0.1, 0, 0.584): on the plane z = 0.5 + x tan(40 deg).
fn macro_scene(extra: &str) -> SceneDescription {
    let text = format!(
        r#"
[film]
resolution = [96, 64]
[camera]
type = "realistic"
eye = [0.0, 0.0, 0.0]
target = [0.0, 0.0, -1.0]
lens_file = "lenses/double-gauss-50mm.dat"
focus_distance = 0.5
{extra}
[materials.grey]
type = "diffuse"
reflectance = [0.5, 0.5, 0.5]
[[shapes]]
type = "sphere"
center = [-0.1, 0.0, -0.416]
radius = 0.01
material = "grey"
[[shapes]]
type = "sphere"
center = [0.0, 0.0, -0.5]
radius = 0.01
material = "grey"
[[shapes]]
type = "sphere"
center = [0.1, 0.0, -0.584]
radius = 0.01
material = "grey"
[[lights]]
type = "environment"
radiance = [1.0, 1.0, 1.0]
"#
    );
    let path = root().join("scenes").join("macro.toml");
    obscura_render::parse_description(&path, &text).unwrap()
}

#[test]
fn the_film_tilts_to_the_scene_files_focal_plane_tilt() {
    // `focal_plane_tilt` on a realistic camera tilts its plane of focus (it was once noted as
    // ignored): with the tilt the spheres' centres lie on, the rays from each centre's image
    // meet at the centre; untilted, the near and far centres are out of focus. (At 0.5 m the
    // lens magnifies about 0.11 times, so the film's tilt is well above the lens's own field
    // curvature; at the metres of spheres-realistic.toml it would be lost in it.)
    let tilted_scene = macro_scene("focal_plane_tilt = [0.0, 40.0]");
    assert!(
        tilted_scene.ignored.is_empty(),
        "{:?}",
        tilted_scene.ignored
    );
    let tilted = RenderScene::build(tilted_scene.clone()).unwrap().camera;
    let AnyCamera::Realistic(camera) = &tilted else {
        panic!("not a realistic camera");
    };
    assert_eq!(camera.lens().focal_plane_tilt, [0.0, 40.0]);
    let flat = RenderScene::build(macro_scene("")).unwrap().camera;
    for centre in [[-0.1, 0.0, -0.416], [0.1, 0.0, -0.584]] {
        let (sharp, blurred) = (miss_rms(&tilted, centre), miss_rms(&flat, centre));
        // Untilted, the geometric cone: the entrance pupil's 12.5 mm radius times 0.084 / 0.5,
        // over sqrt(2) for the RMS, about 1.5 mm. Tilted, what is left is the f/2 lens's own
        // spot off the axis, about 0.2-0.3 mm.
        assert!(
            sharp < 0.3 * blurred,
            "{centre:?}: rays miss by {sharp} m tilted, {blurred} m untilted"
        );
    }
    // The middle sphere, on the tilt's axis, is in focus either way.
    let middle = [0.0, 0.0, -0.5];
    assert!(miss_rms(&tilted, middle) < 2.0 * miss_rms(&flat, middle));

    // The film's centre still sees a uniform sky as about 1: the film tilts by about 5 degrees
    // here (slope m tan 40, m about 0.11), and its cosine takes about 0.4%.
    let centre = pixel(&under_a_uniform_sky(tilted_scene), 4, 4)[0];
    assert!((centre - 1.0).abs() < 0.05, "centre {centre}");
}
