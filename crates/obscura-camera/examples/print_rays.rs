//! Prints the rays of a few pixels for each camera model: a 4 x 3 image seen from
//! eye (0, 1, 5) looking at the origin, pinhole and thin lens, and the environment camera.
//!
//! Run with `cargo run -p obscura-camera --example print_rays`.

use obscura_camera::{
    AnyCamera, Camera, CameraBase, CameraError, CameraSample, EnvironmentCamera, FilmGeometry,
    FovAxis, LookAt, OrthographicCamera, PerspectiveCamera, ScreenWindow, Shutter, ThinLens,
    look_at_pose,
};
use obscura_space::{Point2, Point3, Vector3};

fn main() -> Result<(), CameraError> {
    let resolution = [4, 3];
    let shutter = Shutter::new(0.0, 1.0)?;
    let look = LookAt::new(
        Point3::new(0.0, 1.0, 5.0),
        Point3::new(0.0, 0.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0),
    );
    let base = |window: Option<ScreenWindow>| -> Result<CameraBase, CameraError> {
        Ok(CameraBase::new(
            look_at_pose(look, None, shutter)?,
            shutter,
            FilmGeometry::new(resolution, window, None)?,
        ))
    };
    let lens = ThinLens::new(0.1, 5.0)?;
    let ortho_window = Some(ScreenWindow::new(-2.0, 2.0, -1.5, 1.5)?);
    let cameras: Vec<(&str, AnyCamera)> = vec![
        (
            "perspective, fov 45 (pinhole)",
            PerspectiveCamera::new(base(None)?, 45.0, FovAxis::Smaller, ThinLens::PINHOLE)?.into(),
        ),
        (
            "perspective, fov 45, lens radius 0.1 focused at 5",
            PerspectiveCamera::new(base(None)?, 45.0, FovAxis::Smaller, lens.clone())?.into(),
        ),
        (
            "orthographic, window 4 x 3 (pinhole)",
            OrthographicCamera::new(base(ortho_window)?, ThinLens::PINHOLE)?.into(),
        ),
        (
            "orthographic, window 4 x 3, lens radius 0.1 focused at 5",
            OrthographicCamera::new(base(ortho_window)?, lens)?.into(),
        ),
        ("environment", EnvironmentCamera::new(base(None)?)?.into()),
    ];
    let pixels = [[0, 0], [3, 0], [1, 1], [0, 2], [3, 2]];
    for (name, camera) in &cameras {
        println!("{name}:");
        for [i, j] in pixels {
            let sample = CameraSample {
                p_film: Point2::new(i as f32 + 0.5, j as f32 + 0.5),
                p_lens: glam::Vec2::new(0.9, 0.3),
                time: 0.5,
            };
            let Some(cr) = camera.generate_ray(&sample) else {
                println!("  pixel ({i}, {j}): no ray");
                continue;
            };
            let r = cr.ray;
            println!(
                "  pixel ({i}, {j}): origin ({:+.4}, {:+.4}, {:+.4})  direction ({:+.4}, {:+.4}, {:+.4})  t in [{:.4}, {:.3e}]",
                r.origin.x,
                r.origin.y,
                r.origin.z,
                r.direction.x,
                r.direction.y,
                r.direction.z,
                r.t_min,
                r.t_max
            );
        }
    }
    Ok(())
}
