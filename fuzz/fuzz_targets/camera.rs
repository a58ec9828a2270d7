//! Arbitrary floats (NaN, infinities and extremes included) into every camera model's keys,
//! through the scene layer's validation and the constructors: an error or a camera. A camera
//! that is built must give, for any film, lens and time sample, either no ray or a ray with a
//! finite origin and a finite unit direction, and its projections must be finite or none.
#![no_main]

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use obscura_camera::{Camera, CameraSample};
use std::path::Path;

#[derive(Debug, Arbitrary)]
struct Input {
    model: u8,
    resolution: (u8, u8),
    params: [f32; 16],
    samples: Vec<[f32; 5]>,
}

/// A float as TOML writes it (nan, inf and -inf are TOML floats).
fn f(x: f32) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf".into() } else { "-inf".into() }
    } else {
        format!("{:e}", x)
    }
}

const PROJECTIONS: [&str; 4] = ["equidistant", "equisolid", "stereographic", "orthographic"];
const FACES: [&str; 6] = ["+x", "-x", "+y", "-y", "+z", "-z"];

fn camera_table(model: u8, p: &[f32; 16]) -> String {
    let look = format!(
        "eye = [{}, {}, {}]\ntarget = [{}, {}, {}]\nshutter = [{}, {}]\nnear = {}\n",
        f(p[0]),
        f(p[1]),
        f(p[2]),
        f(p[3]),
        f(p[4]),
        f(p[5]),
        f(p[6]),
        f(p[7]),
        f(p[8].abs())
    );
    let model = match model % 12 {
        0 => format!(
            "type = \"perspective\"\nfov = {}\nlens_radius = {}\nfocal_distance = {}\naperture_blades = {}\nlens_shift = [{}, {}]",
            f(p[9]),
            f(p[10]),
            f(p[11]),
            (p[12].abs() as u32) % 12,
            f(p[13]),
            f(p[14])
        ),
        1 => format!(
            "type = \"orthographic\"\nscreen_window = [{}, {}, {}, {}]\nlens_radius = {}\nfocal_distance = {}",
            f(p[9]),
            f(p[10]),
            f(p[11]),
            f(p[12]),
            f(p[13]),
            f(p[14])
        ),
        2 => "type = \"environment\"".into(),
        3 => format!(
            "type = \"fisheye\"\nprojection = \"{}\"\nfov = {}\nlens_shift = [{}, {}]",
            PROJECTIONS[(p[9].abs() as usize) % 4],
            f(p[10]),
            f(p[11]),
            f(p[12])
        ),
        4 => format!("type = \"cylindrical\"\nfov = {}", f(p[9])),
        5 => "type = \"octahedral\"".into(),
        6 => format!(
            "type = \"cube_face\"\nface = \"{}\"",
            FACES[(p[9].abs() as usize) % 6]
        ),
        7 => format!("type = \"ods\"\n[camera.stereo]\ninteraxial = {}", f(p[9])),
        8 => format!(
            "type = \"opencv\"\nfx = {}\nfy = {}\ncx = {}\ncy = {}\ndistortion = [{}, {}, {}, {}, {}]",
            f(p[9]),
            f(p[10]),
            f(p[11]),
            f(p[12]),
            f(p[13]),
            f(p[14]),
            f(p[15]),
            f(p[0]),
            f(p[1])
        ),
        9 => format!(
            "type = \"opencv_fisheye\"\nfx = {}\nfy = {}\ncx = {}\ncy = {}\ndistortion = [{}, {}, {}, {}]",
            f(p[9]),
            f(p[10]),
            f(p[11]),
            f(p[12]),
            f(p[13]),
            f(p[14]),
            f(p[15]),
            f(p[0])
        ),
        10 => format!(
            "type = \"perspective\"\nfov = {}\n[camera.stereo]\ninteraxial = {}\nconvergence = {}",
            f(p[9]),
            f(p[10]),
            f(p[11])
        ),
        _ => format!(
            "type = \"opencv\"\nfx = {}\nfy = {}\ncx = {}\ncy = {}\ndistortion = [{}, {}, {}, {}]\nrvec = [{}, {}, {}]\ntvec = [{}, {}, {}]",
            f(p[9]),
            f(p[10]),
            f(p[11]),
            f(p[12]),
            f(p[13]),
            f(p[14]),
            f(p[15]),
            f(p[0]),
            f(p[1]),
            f(p[2]),
            f(p[3]),
            f(p[4]),
            f(p[5]),
            f(p[6])
        ),
    };
    // Sub-tables ([camera.stereo]) come after the camera's own keys.
    match model.split_once("\n[") {
        Some((own, sub)) => format!("{own}\n{look}[{sub}"),
        None => format!("{model}\n{look}"),
    }
}

fuzz_target!(|input: Input| {
    let (w, h) = (u32::from(input.resolution.0) + 1, u32::from(input.resolution.1) + 1);
    // OpenCV rvec/tvec replace the look-at: drop eye/target for that case.
    let mut table = camera_table(input.model, &input.params);
    if table.contains("rvec") {
        table = table
            .lines()
            .filter(|l| !l.starts_with("eye") && !l.starts_with("target"))
            .collect::<Vec<_>>()
            .join("\n");
    }
    let text = format!("[film]\nresolution = [{w}, {h}]\n[camera]\n{table}\n");
    let Ok(d) = obscura_render::parse_description(Path::new("fuzz.toml"), &text) else {
        return;
    };
    let Ok(camera) = obscura_render::camera_of(&d) else {
        return;
    };
    for s in input.samples.iter().take(64) {
        if !s.iter().all(|x| x.is_finite()) {
            continue;
        }
        let sample = CameraSample {
            p_film: obscura_space::Point2::new(s[0], s[1]),
            p_lens: glam::Vec2::new(s[2].rem_euclid(1.0), s[3].rem_euclid(1.0)),
            time: s[4].rem_euclid(1.0),
        };
        if let Some(r) = camera.generate_ray(&sample) {
            let (o, dir) = (r.ray.origin, r.ray.direction);
            assert!(
                [o.x, o.y, o.z, dir.x, dir.y, dir.z].iter().all(|v| v.is_finite()),
                "non-finite ray {r:?} from {sample:?} of\n{text}"
            );
            let len = (dir.x * dir.x + dir.y * dir.y + dir.z * dir.z).sqrt();
            assert!((len - 1.0).abs() < 1e-3, "direction of length {len} of\n{text}");
            assert!(r.weight.is_finite(), "weight {} of\n{text}", r.weight);
            let p = o + dir * 2.0;
            if let Some(xy) = camera.project(p, camera.shutter().open) {
                assert!(xy.x.is_finite() && xy.y.is_finite(), "projection {xy:?} of\n{text}");
            }
        }
    }
});
