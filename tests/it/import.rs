//! Imported scenes through the command line: the shipped .pbrt and .xml scenes render what
//! the shipped TOML renders, every flag applies to them, bad input exits 2 naming file and
//! line, and `obscura convert` writes TOML that renders the same image bit for bit.

use super::{obscura, render_image, root, scratch, shipped, write};
use obscura_render::{FilterSettings, IntegratorKind, SceneDescription};

fn run(args: &[&str]) -> (i32, String, String) {
    let out = obscura().args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn imported(name: &str) -> SceneDescription {
    obscura_import::import(&root().join("scenes").join(name))
        .unwrap()
        .description()
        .unwrap()
}

#[test]
fn shipped_pbrt_and_mitsuba_scenes_match_the_shipped_toml() {
    let reference = shipped("spheres-perspective.toml");
    for name in ["spheres-perspective.pbrt", "spheres-perspective.xml"] {
        // The same path length: pbrt counts bounces as we do, Mitsuba one more.
        assert_eq!(
            imported(name).integrator.max_depth,
            reference.integrator.max_depth,
            "{name}"
        );
        // pbrt's default Gaussian is the TOML's (radius 1.5, sigma 0.5); Mitsuba's has the
        // same sigma but runs to 4 sigma, radius 2.
        let filter = if name.ends_with(".xml") {
            FilterSettings::Gaussian {
                radius: 2.0,
                sigma: 0.5,
            }
        } else {
            reference.film.filter
        };
        assert_eq!(imported(name).film.filter, filter, "{name}");
        for kind in [IntegratorKind::Depth, IntegratorKind::Position] {
            // The same samples and filter on both sides: the formats' samplers differ, and
            // the filters of the XML and the TOML.
            let small = |mut d: SceneDescription| {
                d.sampler = reference.sampler;
                d.film.filter = reference.film.filter;
                d.sampler.spp = 1;
                d.integrator.kind = kind;
                d.film.resolution = [64, 48];
                d
            };
            let a = render_image(small(imported(name)), 1);
            let b = render_image(small(reference.clone()), 1);
            let mut worst = 0.0f32;
            for y in 0..a.height {
                for x in 0..a.width {
                    let (p, q) = (a.pixel(x, y), b.pixel(x, y));
                    for c in 0..4 {
                        worst = worst.max((p[c] - q[c]).abs() / p[c].abs().max(1.0));
                    }
                }
            }
            assert!(
                worst < 1e-4,
                "{name} {kind:?}: worst relative difference {worst}"
            );
        }
    }
}

#[test]
fn every_flag_applies_to_imported_scenes() {
    let dir = scratch("import-flags");
    for scene in ["spheres-perspective.pbrt", "spheres-perspective.xml"] {
        let scene = root().join("scenes").join(scene);
        for kind in IntegratorKind::ALL {
            let out = dir.join(format!("{}.exr", kind.name()));
            let (code, stdout, stderr) = run(&[
                "render",
                scene.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--spp",
                "1",
                "--seed",
                "3",
                "--resolution",
                "24x16",
                "--threads",
                "1",
                "--integrator",
                kind.name(),
            ]);
            assert_eq!(code, 0, "{stderr}");
            assert!(
                stdout.contains("24x16, 1 spp") && stdout.contains(kind.name()),
                "{stdout}"
            );
            let (image, _) = obscura_render::read_exr(&out).unwrap();
            assert_eq!((image.width, image.height), (24, 16));
        }
    }
    let (code, stdout, _) = run(&[
        "check",
        root()
            .join("scenes/spheres-perspective.xml")
            .to_str()
            .unwrap(),
    ]);
    assert_eq!(code, 0);
    assert!(
        stdout.contains("ok: 320x240 perspective camera, 4 shapes"),
        "{stdout}"
    );
}

#[test]
fn bad_imported_scenes_exit_2_naming_file_and_line() {
    let dir = scratch("import-bad");
    for (name, text, line) in [
        (
            "a.pbrt",
            "Camera \"perspective\"\nWorldBegin\n\nShape \"sphere\" \"float radius\" [ -1 ]\n",
            4,
        ),
        (
            "b.pbrt",
            "Camera \"perspective\" \"float fov\" [ 200 ]\nWorldBegin\n",
            1,
        ),
        (
            "c.pbrt",
            "Camera \"perspective\"\nWorldBegin\nShape \"plymesh\" \"string filename\" \"gone.ply\"\n",
            3,
        ),
        (
            "d.xml",
            "<scene version=\"3.0.0\">\n<sensor type=\"perspective\">\n</scene>\n",
            3,
        ),
        (
            "e.xml",
            "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n<bsdf type=\"dielectric\" id=\"g\"><string name=\"int_ior\" value=\"unobtainium\"/></bsdf>\n</scene>\n",
            3,
        ),
    ] {
        let scene = write(&dir, name, text);
        let out = dir.join("out.exr");
        for args in [
            vec![
                "render",
                scene.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
            ],
            vec!["check", scene.to_str().unwrap()],
            vec![
                "convert",
                scene.to_str().unwrap(),
                "-o",
                dir.join("out.toml").to_str().unwrap(),
            ],
        ] {
            let (code, _, stderr) = run(&args);
            assert_eq!(code, 2, "{name}: {stderr}");
            assert!(
                stderr.contains(&format!("{name}:{line}")),
                "{name}: the message must name the file and line {line}: {stderr}"
            );
            assert!(!stderr.contains("panicked"), "{stderr}");
            assert!(
                !out.exists() && !dir.join("out.toml").exists(),
                "nothing is written"
            );
        }
    }
}

#[test]
fn convert_writes_toml_that_renders_bit_for_bit_the_same() {
    let dir = scratch("import-convert");
    let scene = root().join("scenes").join("spheres-perspective.pbrt");
    let toml = dir.join("converted.toml");
    let (code, stdout, stderr) = run(&[
        "convert",
        scene.to_str().unwrap(),
        "-o",
        toml.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("converted.toml"), "{stdout}");
    assert!(
        dir.join("converted-meshes").is_dir(),
        "the bilinear floor becomes an OBJ"
    );
    let flags = ["--spp", "2", "--resolution", "40x30", "--threads", "1"];
    let render = |scene: &std::path::Path, out: &str| {
        let out = dir.join(out);
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend(flags);
        let (code, _, stderr) = run(&args);
        assert_eq!(code, 0, "{stderr}");
        obscura_render::read_exr(&out).unwrap().0
    };
    let a = render(&scene, "from-pbrt.exr");
    let b = render(&toml, "from-toml.exr");
    assert_eq!(a.pixels, b.pixels);
    // A TOML scene is not something to convert.
    let (code, _, stderr) = run(&[
        "convert",
        root()
            .join("scenes/spheres-perspective.toml")
            .to_str()
            .unwrap(),
    ]);
    assert_eq!(code, 2, "{stderr}");
}

/// `obscura ARGS` run in `dir`: exit status and stderr.
fn run_in(dir: &std::path::Path, args: &[&str]) -> (i32, String) {
    let out = obscura().current_dir(dir).args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn files_an_imported_scene_names_are_found_from_any_folder_and_after_convert() {
    // Every file a scene names (pbrt's lens file, PLY mesh and infinite-light image; Mitsuba's
    // PLY mesh and envmap) is relative to the scene file: `check` from the folder above it and
    // `check` of a copy converted into a subfolder must both find them.
    let dir = scratch("import-folders");
    let scene = dir.join("imp");
    std::fs::create_dir_all(scene.join("lenses")).unwrap();
    std::fs::copy(
        root().join("scenes/lenses/double-gauss-50mm.dat"),
        scene.join("lenses/dgauss.dat"),
    )
    .unwrap();
    write(
        &scene,
        "tri.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    );
    let sky = obscura_render::Image {
        width: 4,
        height: 4,
        pixels: vec![[0.5, 0.5, 0.5, 1.0]; 16],
    };
    let info = obscura_render::ImageInfo {
        partial: false,
        samples_per_pixel: 1,
    };
    obscura_render::write_image(&scene.join("sky.exr"), &sky, &info).unwrap();
    write(
        &scene,
        "real.pbrt",
        "LookAt 0 0 5  0 0 0  0 1 0\n\
         Camera \"realistic\" \"string lensfile\" \"lenses/dgauss.dat\" \
         \"float aperturediameter\" 5 \"float focusdistance\" 5\n\
         Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 8\nWorldBegin\n\
         LightSource \"infinite\" \"string filename\" \"sky.exr\"\n\
         Shape \"plymesh\" \"string filename\" \"tri.ply\"\n",
    );
    write(
        &scene,
        "env.xml",
        "<scene version=\"3.0.0\"><sensor type=\"perspective\"/>\
         <shape type=\"ply\"><string name=\"filename\" value=\"tri.ply\"/></shape>\
         <emitter type=\"envmap\"><string name=\"filename\" value=\"sky.exr\"/></emitter></scene>\n",
    );
    for name in ["real.pbrt", "env.xml"] {
        // From the folder above: `imp/real.pbrt`.
        let (code, stderr) = run_in(&dir, &["check", &format!("imp/{name}")]);
        assert_eq!(code, 0, "{name} from above: {stderr}");
        // Converted from inside, into a subfolder, then checked from inside and from above.
        let (code, stderr) = run_in(&scene, &["convert", name, "-o", "sub/out.toml"]);
        assert_eq!(code, 0, "{name} converted: {stderr}");
        let (code, stderr) = run_in(&scene, &["check", "sub/out.toml"]);
        assert_eq!(code, 0, "{name} converted, checked: {stderr}");
        let (code, stderr) = run_in(&dir, &["check", "imp/sub/out.toml"]);
        assert_eq!(code, 0, "{name} converted, checked from above: {stderr}");
    }
}

#[test]
fn deeply_nested_xml_exits_2_naming_file_and_line() {
    // 100,000 nested elements overflowed the XML parser's stack (an abort, exit 134). The
    // 256th shape inside <scene> (line 257 + 1, after the sensor's line) is one level too deep.
    let dir = scratch("import-deep");
    let mut text = String::from("<scene version=\"3.0.0\">\n<sensor type=\"perspective\"/>\n");
    text.push_str(&"<shape type=\"sphere\">\n".repeat(100_000));
    text.push_str(&"</shape>".repeat(100_000));
    text.push_str("</scene>\n");
    let scene = write(&dir, "deep.xml", &text);
    let out = dir.join("out.exr");
    let toml = dir.join("out.toml");
    for args in [
        vec!["check", scene.to_str().unwrap()],
        vec![
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        vec![
            "convert",
            scene.to_str().unwrap(),
            "-o",
            toml.to_str().unwrap(),
        ],
    ] {
        let (code, _, stderr) = run(&args);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(
            stderr.contains("deep.xml:258: elements nested more than 256 deep"),
            "{stderr}"
        );
        assert!(!out.exists() && !toml.exists(), "nothing is written");
    }
}

#[test]
fn a_motion_pbrt_cannot_be_given_exactly_exits_2_naming_transform_times() {
    // pbrt moves the sphere over the transform times [0, 0.5] and holds it for the rest of
    // the shutter [0, 1]: not expressible as a motion from shutter open to close.
    let dir = scratch("import-motion");
    let scene = write(
        &dir,
        "m.pbrt",
        "LookAt 0 0 5  0 0 0  0 1 0\nTransformTimes 0 0.5\nCamera \"perspective\"\n\
         WorldBegin\nActiveTransform EndTime\nTranslate 1 0 0\nActiveTransform All\n\
         Shape \"sphere\"\n",
    );
    let (code, _, stderr) = run(&["check", scene.to_str().unwrap()]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("m.pbrt:2: TransformTimes 0 0.5") && stderr.contains("m.pbrt:8"),
        "{stderr}"
    );
}
