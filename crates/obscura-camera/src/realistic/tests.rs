use super::*;
use crate::aperture::{ApertureImage, ApertureShape};
use crate::{FilmGeometry, LookAt, Shutter, look_at_pose};
use obscura_space::Vector3;
use proptest::prelude::*;
use std::sync::OnceLock;

const DOUBLE_GAUSS: &str = include_str!("../../../../scenes/lenses/double-gauss-50mm.dat");
const WIDE: &str = include_str!("../../../../scenes/lenses/wide-angle-22mm.dat");
const TELEPHOTO: &str = include_str!("../../../../scenes/lenses/telephoto-250mm.dat");

/// A camera at the origin looking down world -z (camera +z), film `resolution`.
fn camera(text: &str, resolution: [u32; 2], lens: RealisticLens) -> RealisticCamera {
    let shutter = Shutter::new(0.0, 0.0).unwrap();
    let eye = LookAt::new(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(0.0, 0.0, -1.0),
        Vector3::new(0.0, 1.0, 0.0),
    );
    let base = CameraBase::new(
        look_at_pose(eye, None, shutter).unwrap(),
        shutter,
        FilmGeometry::new(resolution, None, None).unwrap(),
    );
    RealisticCamera::new(base, &LensPrescription::parse(text).unwrap(), lens).unwrap()
}

fn focused(text: &str, focus: f32) -> RealisticCamera {
    camera(
        text,
        [48, 32],
        RealisticLens {
            focus_distance: focus,
            ..RealisticLens::default()
        },
    )
}

/// The double Gauss focused at 2 m, shared by the tests that only read it.
fn double_gauss() -> &'static RealisticCamera {
    static CAMERA: OnceLock<RealisticCamera> = OnceLock::new();
    CAMERA.get_or_init(|| focused(DOUBLE_GAUSS, 2.0))
}

/// A small deterministic generator of uniforms in [0, 1) (SplitMix64).
struct Uniforms(u64);
impl Uniforms {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn parse_reads_rows_comments_and_air() {
    let lens = LensPrescription::parse(
        "# a comment\n\n 50  5  1.5  20 # trailing comment\n0 3 0 10\n-50 40 1 20\n",
    )
    .unwrap();
    assert_eq!(lens.surfaces().len(), 3);
    assert_eq!(lens.stop_index(), 1);
    assert_eq!(lens.stop_diameter(), 10.0);
    // The stop's 0 index is air.
    assert_eq!(lens.surfaces()[1].ior, 1.0);
    assert_eq!(
        lens.surfaces()[0],
        LensSurface {
            radius: 50.0,
            thickness: 5.0,
            ior: 1.5,
            aperture_diameter: 20.0
        }
    );
    for text in [DOUBLE_GAUSS, WIDE, TELEPHOTO] {
        assert!(LensPrescription::parse(text).is_ok());
    }
}

#[test]
fn parse_errors_name_the_line() {
    let line_of = |text: &str| match LensPrescription::parse(text) {
        Err(CameraError::LensPrescription { line, .. }) => line,
        other => panic!("{text:?}: {other:?}"),
    };
    assert_eq!(line_of("50 5 1.5 20\n0 3 0 10\n-50 40 1\n"), Some(3));
    assert_eq!(line_of("# x\n50 5 glass 20\n0 3 0 10\n"), Some(2));
    assert_eq!(line_of("50 -5 1.5 20\n0 3 0 10\n"), Some(1));
    assert_eq!(line_of("50 5 0.5 20\n0 3 0 10\n"), Some(1));
    assert_eq!(line_of("50 5 1.5 0\n0 3 0 10\n"), Some(1));
    assert_eq!(line_of("5 5 1.5 20\n0 3 0 10\n"), Some(1));
    assert_eq!(line_of("50 5 1.5 20\n0 3 0 10\n0 3 0 10\n"), Some(3));
    assert_eq!(line_of("50 5 1.5 inf\n0 3 0 10\n"), Some(1));
    assert_eq!(line_of("50 5 1.5 20\n"), None);
    assert_eq!(line_of("# only comments\n"), None);
    let message = LensPrescription::parse("50 5 1.5 20\n0 3 0 10\n-50 40 1\n")
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("line 3") && message.contains("4 numbers"),
        "{message}"
    );
}

#[test]
fn bad_parameters_are_errors() {
    let lens = LensPrescription::parse(DOUBLE_GAUSS).unwrap();
    let base = double_gauss().base().clone();
    let with = |l: RealisticLens| RealisticCamera::new(base.clone(), &lens, l).map(|_| ());
    let d = RealisticLens::default();
    assert!(matches!(
        with(RealisticLens {
            aperture_diameter: Some(17.2),
            ..d.clone()
        }),
        Err(CameraError::ApertureDiameter { .. })
    ));
    assert!(matches!(
        with(RealisticLens {
            aperture_diameter: Some(0.0),
            ..d.clone()
        }),
        Err(CameraError::ApertureDiameter { .. })
    ));
    assert!(matches!(
        with(RealisticLens {
            focus_distance: 0.01,
            ..d.clone()
        }),
        Err(CameraError::FocusDistance { .. })
    ));
    assert!(matches!(
        with(RealisticLens {
            film_diagonal: 0.0,
            ..d.clone()
        }),
        Err(CameraError::FilmDiagonal { .. })
    ));
    assert!(matches!(
        with(RealisticLens {
            aperture: Aperture {
                shape: ApertureShape::Polygon {
                    blades: 2,
                    rotation_degrees: 0.0
                },
                anamorphic: 1.0
            },
            ..d.clone()
        }),
        Err(CameraError::Blades { .. })
    ));
    for tilt in [
        [90.0, 0.0],
        [0.0, -90.0],
        [f32::NAN, 0.0],
        [0.0, f32::INFINITY],
    ] {
        assert!(matches!(
            with(RealisticLens {
                focal_plane_tilt: tilt,
                ..d.clone()
            }),
            Err(CameraError::FocalPlaneTilt { .. })
        ));
    }
    // A tilted plane the fit cannot image: through the axis inside the lens, or so near that
    // its points' rays leave the rear element diverging.
    let camera = double_gauss();
    let front = camera.elements[0].z;
    assert_eq!(camera.film_slopes(0.5 * front, DVec2::new(0.0, 1.0)), None);
    assert_eq!(camera.film_slopes(front + 1.0, DVec2::new(0.0, 1.0)), None);
    assert!(camera.film_slopes(2000.0, DVec2::new(0.0, 1.0)).is_some());
    // A plane so steep that the film would tilt into the lens: at 2 m the double Gauss
    // magnifies 0.026 times, so 89.9 degrees (a slope of 573) needs a film slope of about 15.
    assert!(matches!(
        with(RealisticLens {
            focus_distance: 2.0,
            focal_plane_tilt: [89.9, 0.0],
            ..d.clone()
        }),
        Err(CameraError::TiltOutOfReach { .. })
    ));
    assert!(
        with(RealisticLens {
            focus_distance: 2.0,
            focal_plane_tilt: [80.0, 0.0],
            ..d.clone()
        })
        .is_ok()
    );
    assert!(matches!(
        with(RealisticLens {
            focus_distance: f32::NAN,
            ..d.clone()
        }),
        Err(CameraError::NonFinite { .. })
    ));
}

/// `[[A, B], [C, D]]` products, written here independently of the camera.
fn mul(p: [[f64; 2]; 2], q: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let mut m = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            m[i][j] = p[i][0] * q[0][j] + p[i][1] * q[1][j];
        }
    }
    m
}

/// The system matrix, front vertex to rear vertex, for light going from the scene to the film
/// in the usual sign convention (radius > 0: centre towards the film), on (height, angle).
fn system_matrix(lens: &LensPrescription) -> [[f64; 2]; 2] {
    let s = lens.surfaces();
    let mut m = [[1.0, 0.0], [0.0, 1.0]];
    let mut n1 = 1.0;
    for (i, surface) in s.iter().enumerate() {
        let n2 = surface.ior;
        if surface.radius != 0.0 {
            // Refraction: n2 u' = n1 u - y (n2 - n1) / R.
            let refraction = [[1.0, 0.0], [-(n2 - n1) / (surface.radius * n2), n1 / n2]];
            m = mul(refraction, m);
        }
        n1 = n2;
        if i + 1 < s.len() {
            // Translation to the next vertex: y' = y + t u.
            m = mul([[1.0, surface.thickness], [0.0, 1.0]], m);
        }
    }
    m
}

#[test]
fn focal_lengths_match_ray_transfer_matrices() {
    for (text, nominal) in [(DOUBLE_GAUSS, 50.0), (WIDE, 22.0), (TELEPHOTO, 250.0)] {
        let lens = LensPrescription::parse(text).unwrap();
        let [[a, _], [c, _]] = system_matrix(&lens);
        let (efl, bfl) = (-1.0 / c, -a / c);
        let camera = focused(text, 1000.0);
        assert!(
            (camera.focal_length() - efl).abs() < 1e-9 * efl,
            "{} vs {efl}",
            camera.focal_length()
        );
        assert!(
            (camera.back_focal_distance() - bfl).abs() < 1e-9 * efl,
            "{} vs {bfl}",
            camera.back_focal_distance()
        );
        // The files' nominal focal lengths, within 3% (the telephoto's is 254 mm).
        assert!(
            (efl - nominal).abs() < 0.03 * nominal,
            "EFL {efl} vs {nominal}"
        );
        // Stopped down to a near-paraxial pencil and focused far away, the traced focus sits at
        // the back focal distance.
        let pencil = camera_stopped(text, 1000.0, 0.05 * lens.stop_diameter());
        assert!(
            (pencil.film_distance() - bfl).abs() < 1e-3 * efl,
            "film {} vs BFL {bfl}",
            pencil.film_distance()
        );
    }
}

fn camera_stopped(text: &str, focus: f32, aperture: f64) -> RealisticCamera {
    camera(
        text,
        [48, 32],
        RealisticLens {
            focus_distance: focus,
            aperture_diameter: Some(aperture as f32),
            ..RealisticLens::default()
        },
    )
}

/// The RMS distance from their centroid at which the camera's rays of raster point `p` cross
/// the plane `z = focus + y tan(a) + x tan(b)` for `tilt = [a, b]` in degrees (camera space,
/// metres from the film; the test cameras' camera space is world space with z negated), over
/// a grid of lens samples; and how many rays there were.
fn spot_on_plane(
    camera: &RealisticCamera,
    p: Point2<Raster>,
    focus: f64,
    tilt: [f64; 2],
) -> (f64, usize) {
    let [ta, tb] = tilt.map(|d| d.to_radians().tan());
    let mut points = Vec::new();
    let n = 48;
    for i in 0..n {
        for j in 0..n {
            let u = glam::Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let sample = CameraSample {
                p_film: p,
                p_lens: u,
                time: 0.0,
            };
            if let Some(r) = camera.generate_ray(&sample) {
                let o = r.ray.origin.to_glam().as_dvec3() * DVec3::new(1.0, 1.0, -1.0);
                let d = r.ray.direction.to_glam().as_dvec3() * DVec3::new(1.0, 1.0, -1.0);
                // o + t d on z = focus + y ta + x tb.
                let t = (focus + o.y * ta + o.x * tb - o.z) / (d.z - d.y * ta - d.x * tb);
                points.push(o + t * d);
            }
        }
    }
    let centroid = points.iter().sum::<DVec3>() / points.len() as f64;
    let ms = points
        .iter()
        .map(|p| (*p - centroid).length_squared())
        .sum::<f64>()
        / points.len() as f64;
    (ms.sqrt(), points.len())
}

/// [`spot_on_plane`] for the untilted plane z = `focus`.
fn spot_rms(camera: &RealisticCamera, p: Point2<Raster>, focus: f32) -> (f64, usize) {
    spot_on_plane(camera, p, f64::from(focus), [0.0, 0.0])
}

#[test]
fn a_point_at_the_focus_distance_images_to_a_small_spot() {
    // At 2 m the double Gauss's magnification is about 50 / 1950, so 1 mm on the plane in
    // focus is 26 micrometres on the film: under a pixel of a 1000-pixel-wide 35 mm film.
    let camera = double_gauss();
    let centre = Point2::new(24.0, 16.0);
    let (rms, count) = spot_rms(camera, centre, 2.0);
    assert!(count > 500, "{count} rays");
    assert!(rms < 1.0e-3, "RMS spot {rms} m at the centre");
    // Stopped down the spot shrinks (spherical aberration goes as the aperture cubed).
    let stopped = camera_stopped(DOUBLE_GAUSS, 2.0, 6.0);
    let (rms_stopped, _) = spot_rms(&stopped, centre, 2.0);
    assert!(rms_stopped < 0.5 * rms, "{rms_stopped} vs {rms}");
    // A plane 20% nearer is out of focus by the geometric cone: rays through the entrance
    // pupil (radius a) that converge at the focus distance F cross the plane at z in a disc of
    // radius a (F - z) / F, whose RMS radius is that over sqrt(2) (uniform disc). Within 15%:
    // the pupil is not uniformly filled off the paraxial limit.
    let (_, pupil_radius) = camera.pupil(true).unwrap();
    let (plane, focus) = (
        1.6,
        f64::from(2.0f32) - camera.film_distance() / MM_PER_UNIT,
    );
    let predicted = pupil_radius / MM_PER_UNIT
        * (focus - (plane - camera.film_distance() / MM_PER_UNIT))
        / focus
        / 2f64.sqrt();
    let (blurred, _) = spot_rms(camera, centre, plane as f32);
    assert!(
        (blurred - predicted).abs() < 0.15 * predicted,
        "{blurred} vs predicted {predicted}"
    );
    assert!(blurred > 3.0 * rms);
}

#[test]
fn every_ray_that_gets_through_starts_inside_the_pupil_bound() {
    // Also a stop that is not round (six blades, squeezed by 2): the bounds are found for film
    // points on +x and turned to each film point's azimuth, so they must hold the rays of the
    // stop's circle, which any turn of the stop stays inside.
    let squeezed = camera(
        DOUBLE_GAUSS,
        [48, 32],
        RealisticLens {
            focus_distance: 2.0,
            aperture: Aperture::polygon(6, 15.0)
                .and_then(|a| a.with_anamorphic(2.0))
                .unwrap(),
            ..RealisticLens::default()
        },
    );
    // And a tilted film, whose points lie off the plane z = 0 by up to r |tilt|.
    for camera in [
        double_gauss(),
        &focused(WIDE, 3.0),
        &focused(TELEPHOTO, 20.0),
        &squeezed,
        steep(),
    ] {
        let rear = 1.5 * camera.elements.last().unwrap().aperture_radius;
        let mut u = Uniforms(7);
        let mut through = 0;
        for _ in 0..200 {
            let r = u.next() * camera.film_radius;
            let phi = u.next() * std::f64::consts::TAU;
            let film = DVec2::new(r * phi.cos(), r * phi.sin());
            let bound = camera.bounds[camera.segment(r)];
            for _ in 0..400 {
                // Anywhere on the rear element's plane, well beyond its clear aperture.
                let q = DVec2::new(2.0 * u.next() - 1.0, 2.0 * u.next() - 1.0) * rear;
                if camera
                    .trace_from_film(camera.film_ray(camera.film_at(film), q), Clip::Stop)
                    .is_some()
                {
                    through += 1;
                    // Back to the frame of a film point on +x.
                    let azimuth = DVec2::new(phi.cos(), -phi.sin());
                    let local = azimuth.rotate(q);
                    assert!(bound.contains(local), "r {r}: {local} outside {bound:?}");
                }
            }
        }
        assert!(through > 1000, "{through} rays got through");
    }
}

/// The film irradiance of a uniform unit sky at film point `film`, up to a constant, by
/// sampling the rear element's whole plane (not the pupil bounds): the radiometric
/// `E = int cos(theta_film) cos(theta_rear) / r^2 dA` over rays that get through, with
/// `theta_film` the ray's angle to the film's unit `normal`, `theta_rear` its angle to the axis
/// (the rear plane's normal) and `r` the distance from the film point to the rear-plane point;
/// times `delta^2`, the film centre's distance from the rear plane squared, which makes it
/// `cos^4(theta)` on a flat film. Returns the mean times the sampled area, and the standard
/// error.
fn irradiance_brute(
    camera: &RealisticCamera,
    film: DVec2,
    normal: DVec3,
    n: usize,
    seed: u64,
) -> (f64, f64) {
    let rear = 1.5 * camera.elements.last().unwrap().aperture_radius;
    let area = 4.0 * rear * rear;
    let delta = camera.film_distance;
    let mut u = Uniforms(seed);
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let q = DVec2::new(2.0 * u.next() - 1.0, 2.0 * u.next() - 1.0) * rear;
        let o = camera.film_at(film);
        let ray = camera.film_ray(o, q);
        let to = q.extend(delta) - o;
        let f = if camera.trace_from_film(ray, Clip::Stop).is_some() {
            let (cos_film, cos_rear) = (normal.dot(to) / to.length(), to.z / to.length());
            area * cos_film * cos_rear * delta * delta / to.length_squared()
        } else {
            0.0
        };
        sum += f;
        sum2 += f * f;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}

/// The renderer's estimate: the mean weight of the camera's rays at raster point `p` (no ray
/// counts 0), and its standard error.
fn irradiance_camera(
    camera: &RealisticCamera,
    p: Point2<Raster>,
    n: usize,
    seed: u64,
) -> (f64, f64) {
    let mut u = Uniforms(seed);
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let sample = CameraSample {
            p_film: p,
            p_lens: glam::Vec2::new(u.next() as f32, u.next() as f32),
            time: 0.0,
        };
        let w = camera
            .generate_ray(&sample)
            .map_or(0.0, |r| f64::from(r.weight));
        sum += w;
        sum2 += w * w;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}

#[test]
fn relative_illumination_matches_brute_force_and_is_one_at_the_centre() {
    // Both estimates are means of n independent bounded samples, so each is normal to a good
    // approximation with the standard error measured; the difference of the two is compared
    // at 5 standard errors (a false failure about once in 1.7 million). The brute-force
    // centre value (the normaliser's reference) carries its own error, propagated to first
    // order into the ratio.
    let n = 40_000;
    for camera in [double_gauss(), &focused(WIDE, 3.0), steep()] {
        let [w, h] = camera.base.film.resolution().map(|v| v as f32);
        // The normaliser is the flat film's centre; a tilted film's own normal, from its slopes.
        let (e0, s0) = irradiance_brute(camera, DVec2::ZERO, DVec3::Z, 4 * n, 11);
        let normal = (-camera.tilt).extend(1.0).normalize();
        let mut previous = f64::INFINITY;
        for (i, t) in [0.0f32, 0.3, 0.6, 0.8, 0.95].into_iter().enumerate() {
            // Along the film's diagonal from the centre.
            let p = Point2::new(0.5 * w * (1.0 + t), 0.5 * h * (1.0 + t));
            let film = camera.film_point(p);
            let (e, s) = irradiance_brute(camera, film, normal, n, 100 + i as u64);
            let relative = e / e0;
            let relative_se = relative * ((s / e).powi(2) + (s0 / e0).powi(2)).sqrt();
            let (mean, se) = irradiance_camera(camera, p, n, 200 + i as u64);
            let bound = 5.0 * (relative_se * relative_se + se * se).sqrt();
            assert!(
                (mean - relative).abs() < bound,
                "t {t}: camera {mean} +- {se}, brute force {relative} +- {relative_se}"
            );
            if t == 0.0 && camera.tilt == DVec2::ZERO {
                assert!((mean - 1.0).abs() < 5.0 * se.max(1e-3), "centre {mean}");
            }
            // Falls off towards the corner (cos^4 and vignetting).
            assert!(relative <= previous + 3.0 * relative_se);
            previous = relative;
        }
    }
}

/// The double Gauss focused at 2 m, stopped down to 8 mm, with the stop's `aperture`.
fn stopped_down(aperture: Aperture) -> RealisticCamera {
    camera(
        DOUBLE_GAUSS,
        [48, 32],
        RealisticLens {
            focus_distance: 2.0,
            aperture_diameter: Some(8.0),
            aperture,
            ..RealisticLens::default()
        },
    )
}

#[test]
fn the_stop_is_the_samplers_polygon() {
    let camera = stopped_down(Aperture::polygon(6, 15.0).unwrap());
    let r = 4.0;
    let inside = |p: DVec2| camera.stop_passes(p, Clip::Stop) > 0.0;
    for i in 0..32 {
        for j in 0..32 {
            let u = glam::Vec2::new((i as f32 + 0.5) / 32.0, (j as f32 + 0.5) / 32.0);
            let p = obscura_sample::square_to_polygon(u, 6, 15.0).as_dvec2() * r;
            assert!(inside(p * 0.999), "{p}");
        }
    }
    // The vertices are on the circle at 15 + 60 k degrees; the edge midpoints at the inradius.
    for k in 0..6 {
        let vertex = (15.0 + 60.0 * k as f64).to_radians();
        let v = DVec2::new(vertex.cos(), vertex.sin()) * r;
        assert!(inside(v * 0.999) && !inside(v * 1.001));
        let mid = (45.0 + 60.0 * k as f64).to_radians();
        let m = DVec2::new(mid.cos(), mid.sin()) * r * (std::f64::consts::PI / 6.0).cos();
        assert!(inside(m * 0.999) && !inside(m * 1.001));
    }
}

/// The film centre's rays through the stop on a grid of lens samples: where each crosses
/// the stop's plane, and its weight.
fn centre_rays_at_the_stop(camera: &RealisticCamera, n: usize) -> Vec<(DVec2, f64)> {
    let mut out = Vec::new();
    let bound = camera.bounds[0];
    for i in 0..n {
        for j in 0..n {
            let u = glam::Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let Some((_, weight)) = camera.lens_ray(DVec2::ZERO, u) else {
                continue;
            };
            // The same ray as lens_ray's, followed from the rear element to the stop.
            let q = bound.min + (bound.max - bound.min) * u.as_dvec2();
            let mut ray = camera.film_ray(DVec3::ZERO, q);
            for k in (camera.stop..camera.elements.len()).rev() {
                camera.interact(k, &mut ray, Clip::No).unwrap();
            }
            out.push((ray.o.truncate(), weight));
        }
    }
    out
}

#[test]
fn an_image_stop_passes_light_in_proportion_to_its_weights() {
    // A 2 x 1 image: the left half of the stop (camera -x) passes everything, the right half
    // half of it. The stop is cut to its circle (the image's square reaches beyond it).
    let image = ApertureImage::new(&[1.0, 0.5], 2, 1).unwrap();
    let camera = stopped_down(Aperture::image(image));
    let r = 4.0;
    assert_eq!(
        camera.stop_passes(DVec2::new(-0.5 * r, 0.2), Clip::Stop),
        1.0
    );
    assert_eq!(
        camera.stop_passes(DVec2::new(0.5 * r, -0.2), Clip::Stop),
        0.5
    );
    assert_eq!(
        camera.stop_passes(DVec2::new(-0.8 * r, 0.8 * r), Clip::Stop),
        0.0
    );
    // The same rays as through the round stop of the same size (its circle bounds the
    // pupil alike), each weighted by its half's transmission over the mean transmission
    // (both normalise the film centre to 1): 1 / 0.75 on the left, 0.5 / 0.75 on the right.
    let rays = centre_rays_at_the_stop(&camera, 96);
    let plain = centre_rays_at_the_stop(&camera_with(&camera, Aperture::CIRCLE), 96);
    assert_eq!(plain.len(), rays.len());
    assert!(rays.len() > 1000, "{}", rays.len());
    let c = rays[0].1 / plain[0].1 * if rays[0].0.x < 0.0 { 1.0 } else { 2.0 };
    assert!((c - 1.0 / 0.75).abs() < 0.02, "{c}");
    for ((p, w), (q, w_round)) in rays.iter().zip(&plain) {
        assert_eq!(p, q);
        let expected = if p.x < 0.0 { c } else { 0.5 * c };
        assert!(
            (w / w_round - expected).abs() < 1e-9 * expected,
            "{p} {w} {w_round}"
        );
    }
}

/// `camera` with another stop aperture.
fn camera_with(camera: &RealisticCamera, aperture: Aperture) -> RealisticCamera {
    RealisticCamera::new(
        camera.base().clone(),
        camera.prescription(),
        RealisticLens {
            aperture,
            ..camera.lens().clone()
        },
    )
    .unwrap()
}

#[test]
fn an_anamorphic_stop_is_an_oval() {
    // Squeezed by 2: the round stop of radius 4 becomes the ellipse of semi-axes 2 (x) and
    // 4 (y). The exit-pupil bounds stay the round stop's: they are turned to each film
    // point's azimuth, which only a round outline survives.
    let camera = stopped_down(Aperture::CIRCLE.with_anamorphic(2.0).unwrap());
    assert_eq!(camera.stop_passes(DVec2::new(1.9, 0.0), Clip::Stop), 1.0);
    assert_eq!(camera.stop_passes(DVec2::new(2.1, 0.0), Clip::Stop), 0.0);
    assert_eq!(camera.stop_passes(DVec2::new(0.0, 3.9), Clip::Stop), 1.0);
    let size = camera.bounds[0].max - camera.bounds[0].min;
    assert!((size.x / size.y - 1.0).abs() < 0.05, "{size}");
    // Every ray from the film centre crosses the stop inside the ellipse.
    let rays = centre_rays_at_the_stop(&camera, 64);
    assert!(rays.len() > 1000, "{}", rays.len());
    for (p, _) in &rays {
        assert!(
            (p.x / 2.0).powi(2) + (p.y / 4.0).powi(2) <= 1.0 + 1e-9,
            "{p}"
        );
    }
    // The round stop's rays reach x = 3.9, past the ellipse.
    let round = centre_rays_at_the_stop(&camera_with(&camera, Aperture::CIRCLE), 64);
    assert!(round.iter().any(|(p, _)| p.x > 3.5));
}

#[test]
fn differentials_carry_the_weight_and_neighbours() {
    let camera = double_gauss();
    let sample = CameraSample {
        p_film: Point2::new(30.5, 10.5),
        p_lens: glam::Vec2::new(0.4, 0.6),
        time: 0.0,
    };
    let ray = camera.generate_ray(&sample).unwrap();
    let d = camera.generate_ray_differential(&sample).unwrap();
    assert_eq!(d.ray, ray.ray);
    assert_eq!(d.weight, ray.weight);
    let right = camera
        .generate_ray(&CameraSample {
            p_film: Point2::new(31.5, 10.5),
            ..sample
        })
        .unwrap();
    assert_eq!(d.rx_direction, right.ray.direction);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Points along a film point's chief ray project back onto the film point.
    #[test]
    fn project_inverts_the_chief_ray(
        x in 0.0f32..48.0,
        y in 0.0f32..32.0,
        distance in 0.3f64..50.0,
        lens in 0usize..4,
    ) {
        static CAMERAS: OnceLock<[RealisticCamera; 4]> = OnceLock::new();
        let cameras = CAMERAS.get_or_init(|| {
            [
                focused(DOUBLE_GAUSS, 2.0),
                focused(WIDE, 3.0),
                focused(TELEPHOTO, 20.0),
                steep().clone(),
            ]
        });
        let camera = &cameras[lens];
        let p = Point2::new(x, y);
        let chief = camera.chief_ray(p);
        prop_assume!(chief.is_some());
        let chief = chief.unwrap();
        // Camera space (metres) at `distance` from the front element; the pose maps camera
        // (x, y, z) to world (-x, y, -z)... through the camera's own pose.
        let q = chief.0 + distance * chief.1;
        let pose = camera.base.world_from_camera.at(0.0);
        let world = pose.point(Point3::<obscura_space::Camera>::new(q.x as f32, q.y as f32, q.z as f32));
        let back = camera.project(world, 0.0);
        prop_assert!(back.is_some());
        let back = back.unwrap();
        // f32 world points: a relative 1e-7 of 50 m is 5 micrometres, ~1e-4 of a pixel here.
        prop_assert!((back.x - x).abs() < 2e-3 && (back.y - y).abs() < 2e-3, "{:?} vs {:?}", back, p);
    }
}

#[test]
fn the_centre_ray_looks_down_the_axis_and_images_are_upright() {
    let camera = double_gauss();
    let centre = CameraSample::at(Point2::new(24.0, 16.0));
    let r = camera.generate_ray(&centre).unwrap();
    // World -z is the view.
    assert!(r.ray.direction.to_glam().z < -0.99);
    // A film point right of and above the centre sees to the right (+x) and up (+y).
    let upper_right = camera
        .generate_ray(&CameraSample::at(Point2::new(40.0, 4.0)))
        .unwrap();
    let d = upper_right.ray.direction.to_glam();
    assert!(d.x > 0.05 && d.y > 0.05, "{d}");
    // Weights are positive and finite.
    assert!(r.weight > 0.0 && upper_right.weight.is_finite());
}

/// The double Gauss focused at 2 m with its plane of focus tilted by `tilt` degrees.
fn tilted(tilt: [f32; 2]) -> RealisticCamera {
    camera(
        DOUBLE_GAUSS,
        [48, 32],
        RealisticLens {
            focus_distance: 2.0,
            focal_plane_tilt: tilt,
            ..RealisticLens::default()
        },
    )
}

/// The double Gauss focused at 0.3 m, where it magnifies about 0.25 times, with its plane
/// of focus tilted by 60 and -45 degrees: a film tilted by about 24 and 14 degrees, whose
/// corners lie about 10 mm off the plane z = 0.
fn steep() -> &'static RealisticCamera {
    static CAMERA: OnceLock<RealisticCamera> = OnceLock::new();
    CAMERA.get_or_init(|| {
        camera(
            DOUBLE_GAUSS,
            [48, 32],
            RealisticLens {
                focus_distance: 0.3,
                focal_plane_tilt: [60.0, -45.0],
                ..RealisticLens::default()
            },
        )
    })
}

#[test]
fn a_tilted_film_is_rigid() {
    // A view camera's tilted back keeps its pixels' spacing: the raster's corners, placed on
    // the tilted film, are a film width, a film height and a diagonal apart, as on the flat
    // film; every placed point lies in the film's plane through the centre; and a raster
    // point comes back from its film point.
    let camera = steep();
    assert!(camera.tilt.length() > 0.3, "{}", camera.tilt);
    let [w, h] = camera.base.film.resolution().map(|v| v as f32);
    let at = |x: f32, y: f32| camera.film_at(camera.film_point(Point2::new(x, y)));
    let (a, b, c) = (at(0.0, 0.0), at(w, 0.0), at(0.0, h));
    let size = camera.film_size;
    let close = |got: f64, want: f64| (got - want).abs() < 1e-9 * want;
    assert!(
        close((b - a).length(), size.x),
        "{} against {}",
        (b - a).length(),
        size.x
    );
    assert!(
        close((c - a).length(), size.y),
        "{} against {}",
        (c - a).length(),
        size.y
    );
    assert!(close((c - b).length(), size.length()));
    assert!(at(0.5 * w, 0.5 * h).length() < 1e-12);
    let normal = (-camera.tilt).extend(1.0).normalize();
    let mut u = Uniforms(5);
    for _ in 0..200 {
        let p = Point2::new(
            (u.next() * f64::from(w)) as f32,
            (u.next() * f64::from(h)) as f32,
        );
        let film = at(p.x, p.y);
        assert!(normal.dot(film).abs() < 1e-12, "{film}");
        let back = camera.raster_point(camera.film_point(p));
        assert!(
            (back.x - p.x).abs() < 1e-4 && (back.y - p.y).abs() < 1e-4,
            "{p:?} {back:?}"
        );
    }
}

#[test]
fn a_tilted_film_follows_scheimpflug() {
    // Paraxially the image of a plane tilted by slope s is tilted by m s, m the lateral
    // magnification (negative: the image is inverted). With the system matrix M from the front
    // vertex to the rear vertex, an object s_o in front and the image s_i behind,
    // T(s_i) M T(s_o) images when its B is 0: s_i = -(A s_o + B) / (C s_o + D); its A, which
    // is then m, is A + s_i C.
    let lens = LensPrescription::parse(DOUBLE_GAUSS).unwrap();
    let [[a, b], [c, d]] = system_matrix(&lens);
    let length: f64 = lens.surfaces()[..lens.surfaces().len() - 1]
        .iter()
        .map(|s| s.thickness)
        .sum();
    for tilt in [[20.0f32, 0.0], [0.0, -35.0], [10.0, 25.0]] {
        let camera = tilted(tilt);
        let s_o = 2000.0 - camera.film_distance() - length;
        let s_i = -(a * s_o + b) / (c * s_o + d);
        let m = a + s_i * c;
        assert!(
            m < 0.0 && (s_i - camera.film_distance()).abs() < 0.5,
            "{m} {s_i}"
        );
        let [ta, tb] = tilt.map(|t| f64::from(t).to_radians().tan());
        let want = DVec2::new(m * tb, m * ta);
        let got = camera.tilt;
        assert!(
            (got - want).abs().max_element() < 0.03 * want.abs().max_element(),
            "tilt {tilt:?}: film slopes {got} vs paraxial {want}"
        );
    }
}

#[test]
fn points_on_a_tilted_plane_image_to_points() {
    // Stopped down to 8 mm, so that the lens's own aberrations (a spot of about 0.05 mm RMS on
    // the axis, 0.2 mm at the field's edge) are well below the blur of a point 0.2 m or more
    // off the plane z = 2 m (the cone: about 4 mm of entrance pupil over 2 m, times the depth,
    // over sqrt(2)). Points of the tilted plane that far off it: the tilted camera's rays from
    // each point's image meet again on the plane; the untilted camera's are spread there.
    let lens = |tilt: [f64; 2]| RealisticLens {
        focus_distance: 2.0,
        aperture_diameter: Some(8.0),
        focal_plane_tilt: tilt.map(|a| a as f32),
        ..RealisticLens::default()
    };
    let flat = camera(DOUBLE_GAUSS, [48, 32], lens([0.0, 0.0]));
    let mut checked = 0;
    for tilt in [[45.0f64, 0.0], [0.0, -40.0], [20.0, 30.0]] {
        let tilted = camera(DOUBLE_GAUSS, [48, 32], lens(tilt));
        let [ta, tb] = tilt.map(|a| a.to_radians().tan());
        for (x, y) in [(0.0, 0.3), (0.0, -0.3), (0.4, 0.1), (-0.4, -0.1)] {
            let depth = y * ta + x * tb;
            if depth.abs() < 0.2 {
                continue;
            }
            // The world point of camera-space (x, y, 2 + depth).
            let world = Point3::new(x as f32, y as f32, -(2.0 + depth) as f32);
            let spot = |c: &RealisticCamera| {
                let (rms, count) = spot_on_plane(c, c.project(world, 0.0).unwrap(), 2.0, tilt);
                assert!(count > 500, "{count} rays");
                rms
            };
            let (sharp, blurred) = (spot(&tilted), spot(&flat));
            assert!(
                sharp < 2.5e-4 && sharp < 0.4 * blurred,
                "tilt {tilt:?}, point ({x}, {y}): RMS {sharp} m tilted, {blurred} m untilted"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 6);
}
