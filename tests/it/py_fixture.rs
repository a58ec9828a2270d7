//! The expected values the Python bindings are checked against, bit for bit: rays and
//! projections of every camera model computed here by the Rust crates and kept in
//! `crates/obscura-py/tests/data/rays.json`, which `test_obscura.py` reads.
//!
//! This test fails when the file differs from what the crates compute now; after a deliberate
//! change of a camera's numbers, `OBSCURA_BLESS=1 cargo test --test it py_fixture` rewrites it.

use super::root;
use obscura_camera::{Camera, CameraSample};
use obscura_render::{camera_of, parse_description};
use obscura_space::{Point2, Point3};
use serde_json::{Value, json};

const LOOK: &str = "eye = [0.5, 1.0, 3.0]\ntarget = [0.0, 0.2, -1.0]";

/// Every camera model of the scene format, as the `[camera]` table of a scene.
fn cameras() -> Vec<(&'static str, String)> {
    let mut cams = vec![
        ("perspective", "type = \"perspective\"\nfov = 50.0".to_string()),
        (
            "thin_lens",
            "type = \"perspective\"\nfov = 40.0\nlens_radius = 0.2\nfocal_distance = 3.0\naperture_blades = 6".to_string(),
        ),
        (
            "lens_shift",
            "type = \"perspective\"\nfov = 60.0\nlens_shift = [0.1, -0.2]".to_string(),
        ),
        (
            "orthographic",
            "type = \"orthographic\"\nscreen_window = [-2.0, 2.0, -1.5, 1.5]\nlens_radius = 0.1\nfocal_distance = 2.0".to_string(),
        ),
        ("environment", "type = \"environment\"".to_string()),
        ("cylindrical", "type = \"cylindrical\"\nfov = 100.0".to_string()),
        ("octahedral", "type = \"octahedral\"".to_string()),
        ("cube_face", "type = \"cube_face\"\nface = \"-x\"".to_string()),
        ("ods", "type = \"ods\"\n[camera.stereo]\ninteraxial = 0.2".to_string()),
        (
            "opencv",
            "type = \"opencv\"\nfx = 60.0\nfy = 62.0\ncx = 31.5\ncy = 23.5\ndistortion = [-0.2, 0.05, 0.001, -0.002, 0.01, 0.001, -0.002, 0.003]".to_string(),
        ),
        (
            "opencv_fisheye",
            "type = \"opencv_fisheye\"\nfx = 20.0\nfy = 20.0\ncx = 31.5\ncy = 23.5\ndistortion = [0.04, -0.012, 0.003, -0.0005]".to_string(),
        ),
    ];
    for p in ["equidistant", "equisolid", "stereographic", "orthographic"] {
        let fov = if p == "orthographic" { 170.0 } else { 190.0 };
        cams.push((
            match p {
                "equidistant" => "fisheye_equidistant",
                "equisolid" => "fisheye_equisolid",
                "stereographic" => "fisheye_stereographic",
                _ => "fisheye_orthographic",
            },
            format!("type = \"fisheye\"\nprojection = \"{p}\"\nfov = {fov:.1}"),
        ));
    }
    cams
}

/// A scene file around a camera table: film, camera (with the shared look-at), one quad.
fn scene(camera: &str) -> String {
    // The look-at goes before any sub-table of [camera] (ODS's [camera.stereo]).
    let (own, sub) = camera
        .split_once("\n[")
        .map_or((camera, String::new()), |(a, b)| (a, format!("[{b}")));
    let shutter = if own.contains("cube_face") || own.contains("ods") {
        ""
    } else {
        "shutter = [0.0, 1.0]\n"
    };
    format!(
        "[film]\nresolution = [64, 64]\n[camera]\n{own}\n{LOOK}\n{shutter}{sub}\n[[shapes]]\ntype = \"quad\"\norigin = [-10.0, -10.0, -5.0]\nedge_u = [20.0, 0.0, 0.0]\nedge_v = [0.0, 20.0, 0.0]\n"
    )
}

/// Film, lens and time samples: a fixed low-discrepancy spread over the film (edges included).
fn samples(n: usize) -> Vec<CameraSample> {
    (0..n)
        .map(|k| {
            let k = k as f32;
            CameraSample {
                p_film: Point2::new(
                    (k * 0.618_034).fract() * 64.0,
                    (k * 0.754_877_7).fract() * 64.0,
                ),
                p_lens: glam::Vec2::new((k * 0.569_840_3).fract(), (k * 0.362_465_6).fract()),
                time: (k * 0.281_323_8).fract(),
            }
        })
        .collect()
}

fn bits(v: &[f32]) -> Value {
    json!(v.iter().map(|x| x.to_bits()).collect::<Vec<_>>())
}

/// The expected values of every model: inputs and outputs as f32 bit patterns.
fn expected() -> Value {
    let mut out = Vec::new();
    for (name, table) in cameras() {
        let toml = scene(&table);
        let d = parse_description(std::path::Path::new("fixture.toml"), &toml)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let camera = camera_of(&d).unwrap_or_else(|e| panic!("{name}: {e}"));
        let samples = samples(48);
        let (mut o, mut dir, mut valid, mut points) = (vec![], vec![], vec![], vec![]);
        for s in &samples {
            match camera.generate_ray(s) {
                Some(r) => {
                    let (p, w) = (r.ray.origin, r.ray.direction);
                    o.extend([p.x, p.y, p.z]);
                    dir.extend([w.x, w.y, w.z]);
                    valid.push(true);
                    let q = p + w * 2.5;
                    points.extend([q.x, q.y, q.z]);
                }
                None => {
                    o.extend([f32::NAN; 3]);
                    dir.extend([f32::NAN; 3]);
                    valid.push(false);
                }
            }
        }
        let open = camera.shutter().open;
        let (mut xy, mut seen) = (vec![], vec![]);
        for q in points.chunks_exact(3) {
            match camera.project(Point3::new(q[0], q[1], q[2]), open) {
                Some(r) => {
                    xy.extend([r.x, r.y]);
                    seen.push(true);
                }
                None => {
                    xy.extend([f32::NAN; 2]);
                    seen.push(false);
                }
            }
        }
        let column = |f: fn(&CameraSample) -> [f32; 2]| {
            bits(&samples.iter().flat_map(f).collect::<Vec<_>>())
        };
        out.push(json!({
            "name": name,
            "toml": toml,
            "raster_xy": column(|s| [s.p_film.x, s.p_film.y]),
            "lens_uv": column(|s| [s.p_lens.x, s.p_lens.y]),
            "time": bits(&samples.iter().map(|s| s.time).collect::<Vec<_>>()),
            "origins": bits(&o),
            "directions": bits(&dir),
            "valid": valid,
            "points": bits(&points),
            "raster_of_points": bits(&xy),
            "points_valid": seen,
        }));
    }
    json!({ "about": "Written by tests/it/py_fixture.rs from the Rust crates; read by crates/obscura-py/tests/test_obscura.py. Floats are f32 bit patterns.", "cameras": out })
}

#[test]
fn python_fixture_matches_the_rust_crates() {
    let path = root().join("crates/obscura-py/tests/data/rays.json");
    let text = serde_json::to_string(&expected()).unwrap() + "\n";
    if std::env::var_os("OBSCURA_BLESS").is_some() {
        std::fs::write(&path, &text).unwrap();
    }
    let stored = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        stored == text,
        "{} differs from what the camera crates compute; if the change is deliberate, rewrite it with OBSCURA_BLESS=1 cargo test --test it py_fixture",
        path.display()
    );
    // The fixture exercises the interesting cases: rays that leave and rays that do not.
    let v = expected();
    let cams = v["cameras"].as_array().unwrap();
    assert!(cams.len() >= 15);
    let none = cams
        .iter()
        .filter(|c| c["valid"].as_array().unwrap().iter().any(|b| b == false));
    assert!(none.count() >= 1);
}
