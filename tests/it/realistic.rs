//! The realistic camera from scene files: each shipped lens renders the spheres upright and in
//! the places `project` gives, and a uniform sky renders as 1 at the image centre.

use super::{aov, render_image, root, shipped};
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
