//! Generates `N` camera rays with one model, for counting instructions per ray under
//! callgrind (deterministic, unlike wall-clock timings on a shared machine):
//!
//! ```text
//! cargo build --release -p obscura-camera --example ray_count
//! valgrind --tool=callgrind target/release/examples/ray_count perspective 1000000
//! valgrind --tool=callgrind target/release/examples/ray_count perspective 0
//! valgrind --tool=callgrind target/release/examples/ray_count perspective 1000000 diff
//! ```
//!
//! The difference of the two totals over `N` is the cost of one ray plus making its sample;
//! the model `samples` only makes the samples, to subtract. Models: `perspective`,
//! `perspective-lens`, `orthographic`, `orthographic-lens`, `environment`, each optionally
//! with a `-moving` suffix (the eye slides along x over the shutter). A third argument `diff`
//! generates ray differentials instead of rays, from the same samples.

use obscura_camera::{
    AnyCamera, Camera, CameraBase, CameraRay, CameraSample, EnvironmentCamera, FilmGeometry,
    FovAxis, LookAt, OrthographicCamera, PerspectiveCamera, Shutter, ThinLens, look_at_pose,
};
use obscura_space::{Point2, Point3, Vector3};
use std::hint::black_box;

fn camera(name: &str) -> Option<AnyCamera> {
    let (model, moving) = match name.strip_suffix("-moving") {
        Some(model) => (model, true),
        None => (name, false),
    };
    let shutter = Shutter::new(0.0, 1.0).ok()?;
    let start = LookAt::new(
        Point3::new(0.0, 1.0, 5.0),
        Point3::new(0.0, 0.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0),
    );
    let end = LookAt {
        eye: Point3::new(1.0, 1.0, 5.0),
        ..start
    };
    let base = CameraBase::new(
        look_at_pose(start, moving.then_some(end), shutter).ok()?,
        shutter,
        FilmGeometry::new([640, 480], None, None).ok()?,
    );
    let lens = ThinLens::new(0.1, 5.0).ok()?;
    let pinhole = ThinLens::PINHOLE;
    Some(match model {
        "perspective" => PerspectiveCamera::new(base, 45.0, FovAxis::Smaller, pinhole)
            .ok()?
            .into(),
        "perspective-lens" => PerspectiveCamera::new(base, 45.0, FovAxis::Smaller, lens)
            .ok()?
            .into(),
        "orthographic" => OrthographicCamera::new(base, pinhole).ok()?.into(),
        "orthographic-lens" => OrthographicCamera::new(base, lens).ok()?.into(),
        "environment" => EnvironmentCamera::new(base).ok()?.into(),
        _ => return None,
    })
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: ray_count MODEL[-moving] N [diff]";
    let (Some(name), Some(n)) = (args.get(1), args.get(2).and_then(|n| n.parse::<u32>().ok()))
    else {
        eprintln!("{usage}");
        std::process::exit(2);
    };
    let differential = match args.get(3).map(String::as_str) {
        None => false,
        Some("diff") => true,
        Some(mode) => {
            eprintln!("unknown mode {mode}; {usage}");
            std::process::exit(2);
        }
    };
    let camera = camera(name);
    if camera.is_none() && name != "samples" {
        eprintln!("unknown model {name}; {usage}");
        std::process::exit(2);
    }
    let mut hits = 0u32;
    for k in 0..n {
        // Film positions over a 640 x 480 image, lens and time samples spread over [0, 1).
        let kf = k as f32;
        let sample = CameraSample {
            p_film: Point2::new((k % 640) as f32 + 0.5, ((k / 640) % 480) as f32 + 0.5),
            p_lens: glam::Vec2::new((kf * 0.618_034).fract(), (kf * 0.754_877_7).fract()),
            time: (kf * 0.569_840_3).fract(),
        };
        // Each result goes through `black_box` whole, so none of its fields is optimised away.
        let generated = match &camera {
            Some(camera) if differential => {
                black_box(camera.generate_ray_differential(black_box(&sample))).is_some()
            }
            Some(camera) => black_box(camera.generate_ray(black_box(&sample))).is_some(),
            None => black_box(None::<CameraRay>).is_some(),
        };
        if generated {
            hits += 1;
        }
    }
    println!("{name}: {hits} rays");
}
