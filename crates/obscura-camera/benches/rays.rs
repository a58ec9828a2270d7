//! Camera rays generated per second for each model, with and without a lens, on one thread.
//!
//! Run with `cargo bench -p obscura-camera --bench rays`.
#![allow(
    missing_docs,
    reason = "criterion_group! generates an undocumented public function"
)]

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use obscura_camera::{
    AnyCamera, Camera, CameraBase, CameraSample, EnvironmentCamera, FilmGeometry, FovAxis,
    LensPrescription, LookAt, OrthographicCamera, PerspectiveCamera, RealisticCamera,
    RealisticLens, Shutter, ThinLens, look_at_pose,
};
use obscura_space::{Point2, Point3, Vector3};
use std::hint::black_box;

const RESOLUTION: [u32; 2] = [64, 64];

fn cameras(moving: bool) -> Vec<(String, AnyCamera)> {
    let shutter = Shutter::new(0.0, 1.0).unwrap();
    let start = LookAt::new(
        Point3::new(0.0, 1.0, 5.0),
        Point3::new(0.0, 0.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0),
    );
    let end = LookAt {
        eye: Point3::new(1.0, 1.0, 5.0),
        ..start
    };
    let base = || {
        CameraBase::new(
            look_at_pose(start, moving.then_some(end), shutter).unwrap(),
            shutter,
            FilmGeometry::new(RESOLUTION, None, None).unwrap(),
        )
    };
    let lens = ThinLens::new(0.1, 5.0).unwrap();
    let suffix = if moving { " moving" } else { "" };
    vec![
        (
            format!("perspective pinhole{suffix}"),
            PerspectiveCamera::new(base(), 45.0, FovAxis::Smaller, ThinLens::PINHOLE)
                .unwrap()
                .into(),
        ),
        (
            format!("perspective lens{suffix}"),
            PerspectiveCamera::new(base(), 45.0, FovAxis::Smaller, lens.clone())
                .unwrap()
                .into(),
        ),
        (
            format!("orthographic pinhole{suffix}"),
            OrthographicCamera::new(base(), ThinLens::PINHOLE)
                .unwrap()
                .into(),
        ),
        (
            format!("orthographic lens{suffix}"),
            OrthographicCamera::new(base(), lens).unwrap().into(),
        ),
        (
            format!("environment{suffix}"),
            EnvironmentCamera::new(base()).unwrap().into(),
        ),
        (
            format!("realistic double gauss{suffix}"),
            double_gauss(base(), 5.0, [0.0, 0.0]),
        ),
        (
            // The film tilted for a plane of focus at 0.5 m tilted by 30 degrees.
            format!("realistic double gauss tilted{suffix}"),
            double_gauss(base(), 0.5, [30.0, 0.0]),
        ),
    ]
}

/// The shipped double Gauss focused at `focus` metres, its plane of focus tilted by `tilt`.
fn double_gauss(base: CameraBase, focus: f32, tilt: [f32; 2]) -> AnyCamera {
    let lens = include_str!("../../../scenes/lenses/double-gauss-50mm.dat");
    RealisticCamera::new(
        base,
        &LensPrescription::parse(lens).unwrap(),
        RealisticLens {
            focus_distance: focus,
            focal_plane_tilt: tilt,
            ..RealisticLens::default()
        },
    )
    .unwrap()
    .into()
}

/// One sample per pixel of the image, with lens and time samples spread over [0, 1).
fn samples() -> Vec<CameraSample> {
    let [w, h] = RESOLUTION;
    let mut out = Vec::with_capacity((w * h) as usize);
    for j in 0..h {
        for i in 0..w {
            let k = (j * w + i) as f32;
            out.push(CameraSample {
                p_film: Point2::new(i as f32 + 0.5, j as f32 + 0.5),
                p_lens: glam::Vec2::new((k * 0.618_034).fract(), (k * 0.754_877_7).fract()),
                time: (k * 0.569_840_3).fract(),
            });
        }
    }
    out
}

fn rays(c: &mut Criterion) {
    let samples = samples();
    let mut group = c.benchmark_group("rays");
    group.throughput(Throughput::Elements(samples.len() as u64));
    for moving in [false, true] {
        for (name, camera) in cameras(moving) {
            group.bench_function(&name, |b| {
                b.iter(|| {
                    for s in &samples {
                        black_box(camera.generate_ray(black_box(s)));
                    }
                })
            });
        }
    }
    for (name, camera) in cameras(false) {
        group.bench_function(format!("{name} differential"), |b| {
            b.iter(|| {
                for s in &samples {
                    black_box(camera.generate_ray_differential(black_box(s)));
                }
            })
        });
    }
    group.finish();
}

criterion_group!(benches, rays);
criterion_main!(benches);
