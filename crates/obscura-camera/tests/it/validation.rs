//! Every constructor refuses bad parameters with an error naming them, never a NaN camera;
//! extreme but valid parameters give finite rays.

use crate::{base_at, identity_look};
use obscura_camera::{
    Camera, CameraError, CameraSample, EnvironmentCamera, FilmGeometry, FovAxis,
    OrthographicCamera, PerspectiveCamera, Shutter, ThinLens,
};
use obscura_space::Point2;

fn perspective(
    fov: f32,
    near: f32,
    far: f32,
    lens: ThinLens,
) -> Result<PerspectiveCamera, CameraError> {
    PerspectiveCamera::new(
        base_at(identity_look(), [8, 8], None, near, far),
        fov,
        FovAxis::Smaller,
        lens,
    )
}

#[test]
fn perspective_rejects_bad_parameters() {
    let ok = ThinLens::PINHOLE;
    for fov in [0.0, 180.0, -10.0, 200.0] {
        let e = perspective(fov, 0.1, 10.0, ok.clone()).unwrap_err();
        assert_eq!(e, CameraError::Fov { got: fov });
    }
    assert_eq!(
        perspective(180.0, 0.1, 10.0, ok.clone())
            .unwrap_err()
            .to_string(),
        "fov must be in (0, 180) degrees, got 180"
    );
    assert!(
        perspective(f32::NAN, 0.1, 10.0, ok.clone())
            .unwrap_err()
            .to_string()
            .starts_with("fov ")
    );
    assert!(matches!(
        perspective(45.0, 0.0, 10.0, ok.clone()),
        Err(CameraError::Near { positive: true, .. })
    ));
    assert!(matches!(
        perspective(45.0, 10.0, 10.0, ok.clone()),
        Err(CameraError::NearFar { .. })
    ));
    assert!(matches!(
        perspective(45.0, 0.1, f32::INFINITY, ok.clone()),
        Err(CameraError::NonFinite { what: "far", .. })
    ));
    assert!(matches!(
        perspective(45.0, f32::NAN, 1.0, ok.clone()),
        Err(CameraError::NonFinite { what: "near", .. })
    ));
    let bad_lens = ThinLens {
        radius: -1.0,
        ..ThinLens::PINHOLE
    };
    assert!(
        perspective(45.0, 0.1, 10.0, bad_lens)
            .unwrap_err()
            .to_string()
            .contains("lens_radius")
    );
    let bad_focus = ThinLens {
        radius: 0.1,
        focal_distance: 0.0,
        ..ThinLens::PINHOLE
    };
    assert!(
        perspective(45.0, 0.1, 10.0, bad_focus)
            .unwrap_err()
            .to_string()
            .contains("focal_distance")
    );
    let bad_blades = ThinLens {
        aperture: obscura_camera::Aperture {
            shape: obscura_camera::ApertureShape::Polygon {
                blades: 2,
                rotation_degrees: 0.0,
            },
            anamorphic: 1.0,
        },
        ..ThinLens::PINHOLE
    };
    assert!(matches!(
        perspective(45.0, 0.1, 10.0, bad_blades),
        Err(CameraError::Blades { got: 2 })
    ));
}

#[test]
fn other_models_and_base_reject_bad_parameters() {
    // Orthographic and environment accept near = 0, not near < 0 or near >= far.
    let base = |near, far| base_at(identity_look(), [8, 8], None, near, far);
    assert!(OrthographicCamera::new(base(0.0, 1.0), ThinLens::PINHOLE).is_ok());
    assert!(EnvironmentCamera::new(base(0.0, 1.0)).is_ok());
    assert!(matches!(
        OrthographicCamera::new(base(-1.0, 1.0), ThinLens::PINHOLE),
        Err(CameraError::Near {
            positive: false,
            ..
        })
    ));
    assert!(matches!(
        EnvironmentCamera::new(base(2.0, 1.0)),
        Err(CameraError::NearFar { .. })
    ));
    // A shutter built by hand that closes before it opens.
    let mut b = base(0.0, 1.0);
    b.shutter = Shutter {
        open: 1.0,
        close: 0.0,
    };
    assert!(matches!(
        EnvironmentCamera::new(b),
        Err(CameraError::Shutter { .. })
    ));
    assert!(matches!(
        FilmGeometry::new([0, 1], None, None),
        Err(CameraError::Resolution { .. })
    ));
}

/// Every model builds its rays from an affine pose: a projective one (bottom row not
/// `[0 0 0 1]`) is refused at construction, while the look-at poses are accepted.
#[test]
fn projective_poses_are_refused() {
    let mut m = glam::Mat4::IDENTITY;
    m.x_axis.w = 0.5;
    let projective = obscura_space::Transform::from_matrix(m).unwrap();
    let mut b = base_at(identity_look(), [8, 8], None, 0.01, 1.0);
    b.world_from_camera = obscura_space::AnimatedTransform::fixed(projective);
    assert!(matches!(
        PerspectiveCamera::new(b.clone(), 60.0, FovAxis::Smaller, ThinLens::PINHOLE),
        Err(CameraError::ProjectivePose)
    ));
    assert!(matches!(
        OrthographicCamera::new(b.clone(), ThinLens::PINHOLE),
        Err(CameraError::ProjectivePose)
    ));
    assert!(matches!(
        EnvironmentCamera::new(b),
        Err(CameraError::ProjectivePose)
    ));
}

#[test]
fn extreme_valid_cameras_give_finite_rays() {
    for fov in [1e-3, 0.5, 179.9] {
        for (near, far) in [(1e-6, 1e30), (0.001, 1e30), (100.0, 100.001)] {
            let camera = perspective(fov, near, far, ThinLens::new(0.5, 1e-3).unwrap()).unwrap();
            for (x, y) in [(0.0, 0.0), (8.0, 8.0), (4.0, 4.0), (-100.0, 50.0)] {
                let sample = CameraSample {
                    p_film: Point2::new(x, y),
                    p_lens: glam::Vec2::new(0.99, 0.01),
                    time: 0.5,
                };
                let r = camera.generate_ray_differential(&sample).unwrap();
                for v in [
                    r.ray.origin.to_glam(),
                    r.ray.direction.to_glam(),
                    r.rx_direction.to_glam(),
                    r.ry_direction.to_glam(),
                ] {
                    assert!(v.is_finite(), "fov {fov} near {near} far {far}: {r:?}");
                }
                assert!(
                    r.ray.t_min.is_finite() && r.ray.t_max.is_finite() && r.ray.t_min < r.ray.t_max
                );
            }
        }
    }
}
