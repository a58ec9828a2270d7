//! Integration tests of obscura-camera: round trips through the projective chain, ray
//! generation against projection for every model, thin-lens focus, clipping, motion, and
//! hand-computed pixels.
//!
//! Tolerances. f32 carries 24 bits (epsilon 1.19e-7). Raster coordinates are at most a few
//! thousand, so a raster round trip through two composed 4x4 maps (entries of size ~resolution)
//! rounds to within ~1e-3 pixel; 2e-3 pixel still catches any real error (a flipped axis or a
//! half-pixel shift moves results by >= 0.5). Directions are compared within 1e-5.

mod cube_face;
mod cylindrical;
mod environment;
mod exact;
mod fisheye;
mod motion;
mod octahedral;
mod ods;
mod opencv;
mod photo;
mod projective;
mod ray_checks;
mod sample_use;
mod stereo;
mod thin_lens;
mod validation;

use obscura_camera::{
    AnyCamera, CameraBase, EnvironmentCamera, FilmGeometry, FovAxis, LookAt, OrthographicCamera,
    PerspectiveCamera, ScreenWindow, Shutter, ThinLens, look_at_pose,
};
use obscura_space::{Point3, Vector3};
use proptest::prelude::*;

/// A proptest config of `cases` cases, unless `PROPTEST_CASES` is set (for stress runs such as
/// `PROPTEST_CASES=20000 cargo test -p obscura-camera --test it clip`): proptest reads that
/// variable only in `Config::default()`, and `with_cases` would override it.
pub fn cases(cases: u32) -> ProptestConfig {
    let from_env = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok());
    ProptestConfig::with_cases(from_env.unwrap_or(cases))
}

/// Asserts two glam vectors agree within `tol`.
#[track_caller]
pub fn assert_close3(a: glam::Vec3, b: glam::Vec3, tol: f32) {
    assert!(
        (a - b).abs().max_element() <= tol,
        "{a:?} != {b:?} (tolerance {tol})"
    );
}

/// Asserts two 2D values agree within `tol`.
#[track_caller]
pub fn assert_close2(a: glam::Vec2, b: glam::Vec2, tol: f32) {
    assert!(
        (a - b).abs().max_element() <= tol,
        "{a:?} != {b:?} (tolerance {tol})"
    );
}

/// The scene format's look-at example: eye at the origin looking down world -z, y up.
pub fn identity_look() -> LookAt {
    LookAt::new(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(0.0, 0.0, -1.0),
        Vector3::new(0.0, 1.0, 0.0),
    )
}

/// A fixed camera base at `look` with the given film and clip range.
pub fn base_at(
    look: LookAt,
    resolution: [u32; 2],
    window: Option<ScreenWindow>,
    near: f32,
    far: f32,
) -> CameraBase {
    let shutter = Shutter::new(0.0, 1.0).unwrap();
    CameraBase::new(
        look_at_pose(look, None, shutter).unwrap(),
        shutter,
        FilmGeometry::new(resolution, window, None).unwrap(),
    )
    .with_clip(near, far)
}

/// A random look-at: eye within 10 of the origin, target at unit-ish distance, up not parallel.
pub fn look_strategy() -> impl Strategy<Value = LookAt> {
    let v = || (-1f32..1.0, -1f32..1.0, -1f32..1.0);
    ((-10f32..10.0, -10f32..10.0, -10f32..10.0), v(), v()).prop_filter_map(
        "degenerate look-at",
        |(e, d, u)| {
            let eye = glam::Vec3::new(e.0, e.1, e.2);
            let dir = glam::Vec3::new(d.0, d.1, d.2);
            let up = glam::Vec3::new(u.0, u.1, u.2);
            if dir.length() < 0.3
                || up.length() < 0.3
                || dir.normalize().cross(up.normalize()).length() < 0.2
            {
                return None;
            }
            Some(LookAt::new(
                Point3::from_glam(eye),
                Point3::from_glam(eye + dir),
                Vector3::from_glam(up),
            ))
        },
    )
}

/// A random resolution between 1 and 2000 per axis.
pub fn resolution_strategy() -> impl Strategy<Value = [u32; 2]> {
    (1u32..2000, 1u32..2000).prop_map(|(w, h)| [w, h])
}

/// A random projective camera (perspective or orthographic) with a random pose, film,
/// fov, fov axis, clip range and lens (`with_lens`: radius > 0; otherwise pinhole).
pub fn projective_strategy(with_lens: bool) -> impl Strategy<Value = AnyCamera> {
    (
        look_strategy(),
        resolution_strategy(),
        1f32..170.0,
        0usize..5,
        prop_oneof![
            Just((0.001f32, 1.0e30f32)),
            Just((0.1, 1000.0)),
            (0.01f32..1.0, 2f32..100.0)
        ],
        (0.01f32..0.5, 0.5f32..20.0),
        any::<bool>(),
    )
        .prop_map(
            move |(look, res, fov, axis, (near, far), (radius, focus), ortho)| {
                let lens = if with_lens {
                    ThinLens::new(radius, focus).unwrap()
                } else {
                    ThinLens::PINHOLE
                };
                let base = base_at(look, res, None, near, far);
                if ortho {
                    OrthographicCamera::new(base, lens).unwrap().into()
                } else {
                    let axis = [
                        FovAxis::Smaller,
                        FovAxis::Larger,
                        FovAxis::X,
                        FovAxis::Y,
                        FovAxis::Diagonal,
                    ][axis];
                    PerspectiveCamera::new(base, fov, axis, lens)
                        .unwrap()
                        .into()
                }
            },
        )
}

/// A random environment camera.
pub fn environment_strategy() -> impl Strategy<Value = EnvironmentCamera> {
    (
        look_strategy(),
        resolution_strategy(),
        prop_oneof![Just(0.0f32), 0.001f32..0.5],
    )
        .prop_map(|(look, res, near)| {
            EnvironmentCamera::new(base_at(look, res, None, near, 1.0e30)).unwrap()
        })
}

/// The three models over one base: perspective (60 degrees) and orthographic with `lens`,
/// and the environment camera (which has none).
pub fn models(base: CameraBase, lens: ThinLens) -> [AnyCamera; 3] {
    [
        PerspectiveCamera::new(base.clone(), 60.0, FovAxis::Smaller, lens.clone())
            .unwrap()
            .into(),
        OrthographicCamera::new(base.clone(), lens).unwrap().into(),
        EnvironmentCamera::new(base).unwrap().into(),
    ]
}

/// A raster position anywhere on the film of `resolution` (fractions in [0, 1)).
pub fn raster_in(
    resolution: [u32; 2],
    fx: f32,
    fy: f32,
) -> obscura_space::Point2<obscura_space::Raster> {
    obscura_space::Point2::new(fx * resolution[0] as f32, fy * resolution[1] as f32)
}
