//! The realistic camera: rays traced from the film through a lens system of spherical elements
//! and an aperture stop (Kolb, Mitchell and Hanrahan, "A Realistic Camera Model for Computer
//! Graphics", SIGGRAPH 1995).

use crate::aperture::Aperture;
use crate::camera::{Camera, CameraBase, CameraRay, CameraRayDifferential, CameraSample};
use crate::chain::{self, CameraRayParts, PoseCache};
use crate::error::{CameraError, finite};
use glam::{DMat3, DQuat, DVec2, DVec3};
use obscura_space::{Point2, Point3, Raster, Ray, World};

/// Millimetres per world unit: lens prescriptions are in millimetres and the realistic camera
/// reads one world unit as one metre (as pbrt-v4 does).
pub const MM_PER_UNIT: f64 = 1000.0;

/// The film diagonal in millimetres when the scene gives none: 35 mm, pbrt-v4's default.
pub const DEFAULT_FILM_DIAGONAL: f32 = 35.0;

/// The number of film-radius segments the exit-pupil bounds are precomputed for.
pub const PUPIL_SEGMENTS: usize = 64;

/// The tolerance of [`RealisticCamera::project`]'s chief-ray solve: the height (mm) at which the
/// solved ray may miss the stop's centre. A miss of `e` at the stop moves the film point by
/// about `e` times the pupil magnification, far below a pixel for any film size here.
pub const PROJECT_TOLERANCE_MM: f64 = 1e-9;

/// Film-radius samples per segment when bounding the exit pupil.
const BOUND_RADII: usize = 4;
/// Grid points per side on the rear plane when bounding the exit pupil.
const BOUND_GRID: usize = 32;
/// Grid points per side when estimating the centre's irradiance (the weights' normaliser).
const NORMALISER_GRID: usize = 128;
/// Grid points per side of the object-side bundle that refines the focus.
const FOCUS_GRID: usize = 24;

/// One surface of a lens prescription, millimetres, in the tabular form pbrt uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LensSurface {
    /// Curvature radius: positive when the centre of curvature lies on the film side of the
    /// vertex (a surface convex towards the scene); 0 for the aperture stop.
    pub radius: f64,
    /// Axial distance from this surface's vertex to the next surface's, towards the film.
    pub thickness: f64,
    /// Index of refraction of the medium behind the surface (towards the film); 1 for air
    /// (the files' 0 is read as 1).
    pub ior: f64,
    /// The clear aperture's diameter.
    pub aperture_diameter: f64,
}

impl LensSurface {
    /// True for the aperture stop (radius 0).
    #[inline]
    pub fn is_stop(&self) -> bool {
        self.radius == 0.0
    }
}

/// A lens system: its surfaces from the scene side (first row) to the film side (last row),
/// exactly one of them the aperture stop. The last row's thickness (the distance to the film)
/// is not used: the camera finds it by focusing.
#[derive(Debug, Clone, PartialEq)]
pub struct LensPrescription {
    surfaces: Vec<LensSurface>,
    stop: usize,
}

impl LensPrescription {
    /// Parses the tabular form: one row per surface, four numbers separated by white space
    /// (curvature radius, thickness, index of refraction, aperture diameter; millimetres),
    /// radius 0 for the stop; `#` starts a comment; blank lines are skipped.
    ///
    /// Errors ([`CameraError::LensPrescription`], with the 1-based line): a row without four
    /// numbers, a non-finite number, a negative thickness, an index below 1 (other than the 0
    /// that means air), a non-positive aperture, a curvature radius smaller than its surface's
    /// semi-aperture (the surface would not close), no rows, and a count of stops other than 1.
    pub fn parse(text: &str) -> Result<LensPrescription, CameraError> {
        let err = |line: usize, message: String| CameraError::LensPrescription {
            line: Some(line),
            message,
        };
        let mut surfaces = Vec::new();
        let mut stops = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = i + 1;
            let content = raw.split('#').next().unwrap_or("").trim();
            if content.is_empty() {
                continue;
            }
            let fields: Vec<&str> = content.split_whitespace().collect();
            if fields.len() != 4 {
                return Err(err(
                    line,
                    format!(
                        "expected 4 numbers (curvature radius, thickness, index of refraction, \
                         aperture diameter), got {} fields",
                        fields.len()
                    ),
                ));
            }
            let mut v = [0.0f64; 4];
            for (slot, field) in v.iter_mut().zip(&fields) {
                *slot = field
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| err(line, format!("`{field}` is not a finite number")))?;
            }
            let [radius, thickness, ior, aperture_diameter] = v;
            if thickness < 0.0 {
                return Err(err(
                    line,
                    format!("thickness must be >= 0, got {thickness}"),
                ));
            }
            if !(ior == 0.0 || ior >= 1.0) {
                return Err(err(
                    line,
                    format!("index of refraction must be >= 1 (or 0 for air), got {ior}"),
                ));
            }
            if aperture_diameter <= 0.0 {
                return Err(err(
                    line,
                    format!("aperture diameter must be > 0, got {aperture_diameter}"),
                ));
            }
            if radius != 0.0 && radius.abs() < 0.5 * aperture_diameter {
                return Err(err(
                    line,
                    format!(
                        "curvature radius {radius} is smaller than the semi-aperture {}",
                        0.5 * aperture_diameter
                    ),
                ));
            }
            if radius == 0.0 {
                stops.push(line);
            }
            surfaces.push(LensSurface {
                radius,
                thickness,
                ior: if ior == 0.0 { 1.0 } else { ior },
                aperture_diameter,
            });
        }
        if surfaces.is_empty() {
            return Err(CameraError::LensPrescription {
                line: None,
                message: "no surfaces: expected one row per surface".into(),
            });
        }
        match stops.as_slice() {
            [_] => {}
            [] => {
                return Err(CameraError::LensPrescription {
                    line: None,
                    message: "no aperture stop: one row must have curvature radius 0".into(),
                });
            }
            [_, second, ..] => {
                return Err(err(
                    *second,
                    "a second aperture stop: exactly one row may have radius 0".into(),
                ));
            }
        }
        let stop = surfaces.iter().position(LensSurface::is_stop).unwrap_or(0);
        if surfaces.len() < 2 {
            return Err(CameraError::LensPrescription {
                line: None,
                message: "a lens needs at least one refracting surface beside the stop".into(),
            });
        }
        Ok(LensPrescription { surfaces, stop })
    }

    /// The surfaces, scene side first.
    pub fn surfaces(&self) -> &[LensSurface] {
        &self.surfaces
    }

    /// The index of the aperture stop in [`LensPrescription::surfaces`].
    pub fn stop_index(&self) -> usize {
        self.stop
    }

    /// The stop's full diameter (mm): the largest `aperture_diameter` the camera takes.
    pub fn stop_diameter(&self) -> f64 {
        self.surfaces[self.stop].aperture_diameter
    }
}

/// The parameters of a [`RealisticCamera`] besides its base and prescription.
#[derive(Debug, Clone, PartialEq)]
pub struct RealisticLens {
    /// Diameter of the stop (mm) after stopping down; None for the stop's full diameter.
    pub aperture_diameter: Option<f32>,
    /// Distance (world units, metres) from the film plane to the plane in focus.
    pub focus_distance: f32,
    /// The film's diagonal (mm).
    pub film_diagonal: f32,
    /// The stop's opening, in units of its (stopped-down) radius: round, a regular polygon of
    /// blades inscribed in its circle, or an image of weights, each maybe squeezed by an
    /// anamorphic factor ([`Aperture`]). An image is the stop's transmission, its weights
    /// relative to the brightest, cut to the stop's circle: rays through a dimmer part carry
    /// less light.
    pub aperture: Aperture,
    /// The plane of focus's tilt in degrees about camera x and camera y, each in (-90, 90)
    /// (`[0, 0]` for none): the plane in focus becomes `z = focus_distance + y tan(a) +
    /// x tan(b)` in camera space, z measured from the film, as for a tilted
    /// [`ThinLens`](crate::ThinLens). The film is tilted to that plane's image (Scheimpflug).
    pub focal_plane_tilt: [f32; 2],
}

impl Default for RealisticLens {
    fn default() -> Self {
        RealisticLens {
            aperture_diameter: None,
            focus_distance: 10.0,
            film_diagonal: DEFAULT_FILM_DIAGONAL,
            aperture: Aperture::CIRCLE,
            focal_plane_tilt: [0.0, 0.0],
        }
    }
}

/// A surface placed on the axis, lens space (mm): the film is the plane z = 0 and the lens
/// lies towards +z, which is also camera +z (the view).
#[derive(Debug, Clone, Copy)]
struct Element {
    /// Axial position of the vertex.
    z: f64,
    /// Curvature radius (0: the stop); the centre is at `z - radius`.
    radius: f64,
    /// Half the clear aperture (for the stop: after stopping down).
    aperture_radius: f64,
    /// Index behind (film side) and in front (scene side).
    eta_film: f64,
    eta_scene: f64,
}

/// What ends a traced ray besides missing an element or total internal reflection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Clip {
    /// Nothing: the elements as unbounded spheres and planes.
    No,
    /// The elements' clear apertures and the stop's (stopped-down) circle: the same for a
    /// film point at any azimuth, so the exit-pupil bounds, found for film points on +x and
    /// turned to the others, are found with this.
    Circles,
    /// The circles and the stop's aperture inside its circle (blades, an image, a squeeze),
    /// whose transmission the ray then carries.
    Stop,
}

/// A ray in lens space (mm) with a unit direction.
#[derive(Debug, Clone, Copy)]
struct LensRay {
    o: DVec3,
    d: DVec3,
}

/// An axis-aligned rectangle on the rear plane, for a film point on the +x axis.
#[derive(Debug, Clone, Copy, PartialEq)]
struct PupilBound {
    min: DVec2,
    max: DVec2,
}

impl PupilBound {
    const EMPTY: PupilBound = PupilBound {
        min: DVec2::splat(f64::INFINITY),
        max: DVec2::splat(f64::NEG_INFINITY),
    };
    fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y)
    }
    fn area(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            (self.max - self.min).element_product()
        }
    }
    fn include(&mut self, p: DVec2) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }
    #[cfg(test)]
    fn contains(&self, p: DVec2) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }
}

/// A camera with a real lens system: each ray starts at its film point, aims at a point of the
/// exit pupil's bound on the plane of the rear element's vertex, and is traced through the
/// elements (refraction at spheres by Snell's law; a ray that misses an element, falls outside
/// its clear aperture or the stop, or is totally internally reflected gives no ray).
///
/// Lens space is camera space in millimetres: the film is the plane z = 0, the lens lies
/// towards +z (the view), rays leave from the front element. The lens inverts the image, so
/// raster point `p` is the film point `-(u, v)` with `(u, v)` its image-right, image-up offset
/// from the film centre in mm (the film is `film_diagonal` mm across its diagonal, with the
/// image's aspect ratio).
///
/// Formulas (docs/cameras.md has the derivations):
/// - Refraction at a sphere of radius `R` centred on the axis at `z_v - R`: the normal `n`
///   faces the incoming direction `d`, `eta = eta_i / eta_t`, `cos_i = -n.d`,
///   `sin2_t = eta^2 (1 - cos_i^2)` (> 1: total internal reflection),
///   `t = eta d + (eta cos_i - sqrt(1 - sin2_t)) n`.
/// - Focus: the paraxial system matrix `[[A, B], [C, D]]` of the lens (rear vertex to front
///   vertex) puts the film at the root `delta` of `C delta^2 + (D + C (L - F) - A) delta +
///   D (L - F) - B = 0` (`L` the lens length, `F` the focus distance from the film); the film is
///   then moved to the best (least RMS) focus of a traced bundle from the axial point at `F`.
/// - Exit pupil: per film radius segment (of [`PUPIL_SEGMENTS`]), the rectangle on the rear
///   vertex plane that holds every rear point through which a ray from the segment's film
///   points gets through, grown by one grid cell; a film point off the axis rotates its
///   segment's rectangle to its azimuth.
/// - Weight: `cos^4(theta) A / (Delta^2 E_0)` (on a tilted film `cos(theta_f) cos^3(theta)`,
///   `theta_f` the ray's angle to the film's normal) with `theta` the ray's angle to the axis,
///   `A` the bound's area (the inverse of the sample's density), `Delta` the film point's distance
///   from the rear vertex's plane (`delta` at the film centre), and `E_0` the film centre's
///   irradiance from a uniform unit sky, the same integral over the rear plane estimated at
///   construction. So a uniform white sky gives 1 at the image centre and the lens's relative
///   illumination elsewhere (vignetting included).
/// - Tilt (`focal_plane_tilt = [a, b]`): the plane in focus `z = F + y tan(a) + x tan(b)` is
///   imaged onto a tilted film `z = s_x x + s_y y` (Scheimpflug). Each slope is measured by
///   tracing: the best-focus images (least RMS spread of a traced bundle) of two points of
///   the plane on either side of the axis, the slope of the line through them. Paraxially
///   `s = m tan`, `m` the lateral magnification. The film is rigid, as a view camera's tilted
///   back is: the flat film turned about the axis through its centre that takes its normal to
///   the tilted plane's, so pixels keep their spacing along it. The exit-pupil bounds hold film
///   points at the ends of the depths a segment's radius reaches.
///
/// `project` finds the chief ray through the stop's centre (secant on the stop height, from
/// a paraxial estimate through the entrance pupil, to [`PROJECT_TOLERANCE_MM`]) and traces it
/// to the film, ignoring clear apertures (so vignetted points still have an image position).
#[derive(Debug, Clone)]
pub struct RealisticCamera {
    base: CameraBase,
    pose: PoseCache,
    prescription: LensPrescription,
    lens: RealisticLens,
    elements: Vec<Element>,
    stop: usize,
    /// Film width and height (mm).
    film_size: DVec2,
    /// Half the film diagonal (mm): the largest film radius.
    film_radius: f64,
    /// The rear vertex's distance from the film centre (mm).
    film_distance: f64,
    /// The film's slopes: film point `(x, y)` lies at `z = tilt.x x + tilt.y y` (zero when
    /// the plane of focus is not tilted).
    tilt: DVec2,
    /// The tilted film's frame: the turn taking a flat film point `(x, y, 0)` to its place on
    /// the tilted film (the identity when untilted).
    film_frame: DMat3,
    bounds: Vec<PupilBound>,
    /// `delta^2 / (delta^2 E_0) = 1 / E_0` with `E_0` as `centre_irradiance` gives it (the
    /// integral of `cos^4`, without the `1 / delta^2` both share): the weight's constant.
    weight_scale: f64,
    focal_length: f64,
    back_focal_distance: f64,
}

impl RealisticCamera {
    /// The camera of a prescription focused at `lens.focus_distance`.
    ///
    /// Errors: non-finite numbers; an aperture diameter not in (0, the stop's diameter]
    /// ([`CameraError::ApertureDiameter`]); a film diagonal <= 0
    /// ([`CameraError::FilmDiagonal`]); a bad aperture ([`Aperture::validate`]); a lens that
    /// cannot focus at that distance ([`CameraError::FocusDistance`]); the base's errors.
    pub fn new(
        base: CameraBase,
        prescription: &LensPrescription,
        lens: RealisticLens,
    ) -> Result<RealisticCamera, CameraError> {
        base.validate(false)?;
        finite("focus_distance", lens.focus_distance)?;
        finite("film_diagonal", lens.film_diagonal)?;
        let stop_diameter = prescription.stop_diameter();
        let aperture = match lens.aperture_diameter {
            Some(a) => {
                finite("aperture_diameter", a)?;
                if !(a > 0.0 && f64::from(a) <= stop_diameter) {
                    return Err(CameraError::ApertureDiameter {
                        got: a,
                        stop: stop_diameter as f32,
                    });
                }
                f64::from(a)
            }
            None => stop_diameter,
        };
        if lens.film_diagonal <= 0.0 {
            return Err(CameraError::FilmDiagonal {
                got: lens.film_diagonal,
            });
        }
        lens.aperture.validate()?;
        let tilt = lens.focal_plane_tilt;
        crate::camera::validate_tilt(tilt)?;
        let focus_mm = f64::from(lens.focus_distance) * MM_PER_UNIT;
        if lens.focus_distance <= 0.0 {
            return Err(CameraError::FocusDistance {
                got: lens.focus_distance,
            });
        }

        // The elements, placed with the rear vertex at z = 0 for now.
        let surfaces = prescription.surfaces();
        let n = surfaces.len();
        let mut elements = Vec::with_capacity(n);
        let mut z = 0.0;
        for i in (0..n).rev() {
            if i + 1 < n {
                z += surfaces[i].thickness;
            }
            let eta_scene = if i == 0 { 1.0 } else { surfaces[i - 1].ior };
            elements.push(Element {
                z,
                radius: surfaces[i].radius,
                aperture_radius: if i == prescription.stop_index() {
                    0.5 * aperture
                } else {
                    0.5 * surfaces[i].aperture_diameter
                },
                eta_film: surfaces[i].ior,
                eta_scene,
            });
        }
        elements.reverse();

        let [width, height] = base.film.resolution().map(f64::from);
        let diagonal = f64::from(lens.film_diagonal);
        let film_size = DVec2::new(width, height) * (diagonal / width.hypot(height));
        let mut camera = RealisticCamera {
            pose: PoseCache::new(&base),
            base,
            prescription: prescription.clone(),
            lens: RealisticLens {
                aperture_diameter: Some(aperture as f32),
                ..lens
            },
            elements,
            stop: prescription.stop_index(),
            film_size,
            film_radius: 0.5 * diagonal,
            film_distance: 0.0,
            tilt: DVec2::ZERO,
            film_frame: DMat3::IDENTITY,
            bounds: Vec::new(),
            weight_scale: 0.0,
            focal_length: 0.0,
            back_focal_distance: 0.0,
        };

        // Paraxial cardinal quantities, then the film distance for the focus distance.
        let [[a, b], [c, d]] = camera.paraxial_matrix(0, n);
        if c.abs() < 1e-12 {
            return Err(CameraError::FocusDistance {
                got: lens.focus_distance,
            });
        }
        camera.focal_length = -1.0 / c;
        camera.back_focal_distance = -d / c;
        let length = camera.elements[0].z;
        let (qa, qb, qc) = (
            c,
            d + c * (length - focus_mm) - a,
            d * (length - focus_mm) - b,
        );
        let disc = qb * qb - 4.0 * qa * qc;
        let paraxial = if disc >= 0.0 {
            let sq = disc.sqrt();
            [(-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa)]
                .into_iter()
                .filter(|r| *r > 0.0 && r + length < focus_mm)
                .fold(f64::INFINITY, f64::min)
        } else {
            f64::INFINITY
        };
        if !paraxial.is_finite() {
            return Err(CameraError::FocusDistance {
                got: lens.focus_distance,
            });
        }
        camera.set_film_distance(paraxial);
        camera.refine_focus(focus_mm);
        if !(camera.film_distance > 0.0 && camera.elements[0].z < focus_mm) {
            return Err(CameraError::FocusDistance {
                got: lens.focus_distance,
            });
        }

        if tilt != [0.0, 0.0] {
            camera.tilt = camera
                .film_slopes(focus_mm, crate::camera::tilt_slopes(tilt))
                .ok_or(CameraError::TiltOutOfReach { got: tilt })?;
            // The film's corners may come at most halfway to the rear vertex (a film tilted
            // by up to 45 degrees behind the double Gauss): nearer, its rays would start
            // beside or inside the rear element.
            if camera.film_radius * camera.tilt.length() > 0.5 * camera.film_distance {
                return Err(CameraError::TiltOutOfReach { got: tilt });
            }
            let normal = (-camera.tilt).extend(1.0).normalize();
            camera.film_frame = DMat3::from_quat(DQuat::from_rotation_arc(DVec3::Z, normal));
        }

        // Exit-pupil bounds, then the weights' normaliser at the film centre.
        camera.bounds = (0..PUPIL_SEGMENTS)
            .map(|k| camera.bound_segment(k))
            .collect();
        let e0 = camera.centre_irradiance();
        if e0.is_nan() || e0 <= 0.0 {
            return Err(CameraError::FocusDistance {
                got: lens.focus_distance,
            });
        }
        camera.weight_scale = 1.0 / e0;
        Ok(camera)
    }

    /// The pose, shutter, film and clip range.
    pub fn base(&self) -> &CameraBase {
        &self.base
    }

    /// The prescription (the last row's thickness as given, not the focused film distance).
    pub fn prescription(&self) -> &LensPrescription {
        &self.prescription
    }

    /// The lens parameters, with the aperture diameter resolved (mm).
    pub fn lens(&self) -> &RealisticLens {
        &self.lens
    }

    /// The paraxial effective focal length (mm).
    pub fn focal_length(&self) -> f64 {
        self.focal_length
    }

    /// The paraxial back focal distance (mm): from the rear vertex to the focus of rays from
    /// infinity.
    pub fn back_focal_distance(&self) -> f64 {
        self.back_focal_distance
    }

    /// The focused distance (mm) from the rear vertex to the film.
    pub fn film_distance(&self) -> f64 {
        self.film_distance
    }

    /// The film's width and height (mm).
    pub fn film_size(&self) -> [f64; 2] {
        self.film_size.to_array()
    }

    /// The exit-pupil bound of a film radius (mm) as `[x_min, x_max, y_min, y_max]` on the rear
    /// vertex plane, for a film point on the +x axis; None where no ray gets through.
    pub fn exit_pupil_bound(&self, film_radius: f64) -> Option<[f64; 4]> {
        let b = self.bounds[self.segment(film_radius)];
        (!b.is_empty()).then_some([b.min.x, b.max.x, b.min.y, b.max.y])
    }

    /// The chief ray of a raster point: from the film point through the stop's centre, out of
    /// the front element, as camera-space origin (world units) and unit direction; clear
    /// apertures are ignored (a vignetted film point still has one). None when no such ray
    /// exists (the secant solve fails, or the ray misses an element or is totally internally
    /// reflected). [`Camera::project`] inverts it.
    pub fn chief_ray(&self, p_film: Point2<Raster>) -> Option<(DVec3, DVec3)> {
        let ray = self.chief_ray_lens(self.film_point(p_film))?;
        Some((ray.o / MM_PER_UNIT, ray.d))
    }

    /// The world-space chief ray of `sample`'s film point at `sample`'s time: [`Self::chief_ray`]
    /// carried through the pose as [`Camera::generate_ray`] carries a traced ray
    /// (`sample.p_lens` is not used). It is the ray [`Camera::project`] inverts, so any point
    /// along it projects back to the film point: the ray to use for one ray per film point.
    pub fn generate_chief_ray(&self, sample: &CameraSample) -> Option<Ray<World>> {
        let time = crate::camera::ray_time(&self.base, sample)?;
        let (o, d) = self.chief_ray(sample.p_film)?;
        let parts = CameraRayParts::by_distance(o, d, &self.base);
        let world_from_camera = self.pose.world_from_camera(&self.base, time);
        Some(chain::to_world(&world_from_camera, parts, time))
    }

    /// The axial position (mm from the film) of the rear element's vertex.
    fn rear_z(&self) -> f64 {
        self.elements[self.elements.len() - 1].z
    }

    /// Moves the film: the rear vertex at `delta` mm from it.
    fn set_film_distance(&mut self, delta: f64) {
        let shift = delta - self.rear_z();
        for e in &mut self.elements {
            e.z += shift;
        }
        self.film_distance = delta;
    }

    /// The segment of a film radius.
    fn segment(&self, film_radius: f64) -> usize {
        let k = (film_radius / self.film_radius * PUPIL_SEGMENTS as f64) as usize;
        k.min(PUPIL_SEGMENTS - 1)
    }

    /// The paraxial matrix `[[A, B], [C, D]]` acting on (height, angle) of a ray going towards
    /// the scene, from the vertex of surface `last - 1` to the vertex of surface `first`.
    fn paraxial_matrix(&self, first: usize, last: usize) -> [[f64; 2]; 2] {
        let mut m = [[1.0, 0.0], [0.0, 1.0]];
        let mul = |p: [[f64; 2]; 2], q: [[f64; 2]; 2]| {
            [
                [
                    p[0][0] * q[0][0] + p[0][1] * q[1][0],
                    p[0][0] * q[0][1] + p[0][1] * q[1][1],
                ],
                [
                    p[1][0] * q[0][0] + p[1][1] * q[1][0],
                    p[1][0] * q[0][1] + p[1][1] * q[1][1],
                ],
            ]
        };
        for i in (first..last).rev() {
            let e = &self.elements[i];
            if i + 1 < last {
                let t = e.z - self.elements[i + 1].z;
                m = mul([[1.0, t], [0.0, 1.0]], m);
            }
            if e.radius != 0.0 {
                // n' u' = n u - y (n' - n) / R_t, with R_t = -radius for a ray going +z.
                let (n1, n2) = (e.eta_film, e.eta_scene);
                m = mul([[1.0, 0.0], [(n2 - n1) / (e.radius * n2), n1 / n2]], m);
            }
        }
        m
    }

    /// The fraction of light the stop passes at a point of its plane, as `clip` tests it:
    /// 1 without clipping; else 0 outside its (stopped-down) circle, and inside it 1 for
    /// [`Clip::Circles`] or the aperture's transmission for [`Clip::Stop`]
    /// ([`Aperture::transmission`], in units of the stop's radius).
    fn stop_passes(&self, p: DVec2, clip: Clip) -> f64 {
        if clip == Clip::No {
            return 1.0;
        }
        let r = self.elements[self.stop].aperture_radius;
        if p.length_squared() > r * r {
            return 0.0;
        }
        if clip == Clip::Circles {
            return 1.0;
        }
        f64::from(self.lens.aperture.transmission((p / r).as_vec2()))
    }

    /// Moves `ray` to element `i` and through it (refraction; clear-aperture and stop tests
    /// as `clip` says), giving the fraction of its light that passes (below 1 only at a stop
    /// whose aperture is an image). None: missed, clipped, or totally internally reflected.
    fn interact(&self, i: usize, ray: &mut LensRay, clip: Clip) -> Option<f64> {
        let e = &self.elements[i];
        if e.radius == 0.0 {
            // The stop: a plane.
            if ray.d.z == 0.0 {
                return None;
            }
            let t = (e.z - ray.o.z) / ray.d.z;
            let p = ray.o + t * ray.d;
            let passed = self.stop_passes(p.truncate(), clip);
            if t < 0.0 || passed <= 0.0 {
                return None;
            }
            ray.o = p;
            return Some(passed);
        }
        // A sphere centred on the axis at z - radius: the root on the vertex's side.
        let centre = DVec3::new(0.0, 0.0, e.z - e.radius);
        let oc = ray.o - centre;
        let b = oc.dot(ray.d);
        let c = oc.length_squared() - e.radius * e.radius;
        let disc = b * b - c;
        if disc < 0.0 {
            return None;
        }
        let sq = disc.sqrt();
        let far = (ray.d.z > 0.0) != (e.radius < 0.0);
        let t = if far { -b + sq } else { -b - sq };
        if t <= 0.0 {
            return None;
        }
        let p = ray.o + t * ray.d;
        if clip != Clip::No && p.x * p.x + p.y * p.y > e.aperture_radius * e.aperture_radius {
            return None;
        }
        // Snell's law with the normal facing the incoming ray.
        let mut normal = (p - centre) / e.radius.abs();
        if normal.dot(ray.d) > 0.0 {
            normal = -normal;
        }
        let eta = if ray.d.z > 0.0 {
            e.eta_film / e.eta_scene
        } else {
            e.eta_scene / e.eta_film
        };
        let cos_i = -normal.dot(ray.d);
        let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
        if sin2_t > 1.0 {
            return None;
        }
        let d = eta * ray.d + (eta * cos_i - (1.0 - sin2_t).sqrt()) * normal;
        ray.o = p;
        ray.d = d.normalize();
        Some(1.0)
    }

    /// Traces a ray leaving the film through every element to the scene, with the fraction
    /// of its light that passes.
    fn trace_from_film(&self, mut ray: LensRay, clip: Clip) -> Option<(LensRay, f64)> {
        let mut passed = 1.0;
        for i in (0..self.elements.len()).rev() {
            passed *= self.interact(i, &mut ray, clip)?;
        }
        Some((ray, passed))
    }

    /// Traces a ray from the scene through every element to the film side, with the fraction
    /// of its light that passes.
    fn trace_from_scene(&self, mut ray: LensRay, clip: Clip) -> Option<(LensRay, f64)> {
        let mut passed = 1.0;
        for i in 0..self.elements.len() {
            passed *= self.interact(i, &mut ray, clip)?;
        }
        Some((ray, passed))
    }

    /// The film point (mm) at film position `film`: on the plane z = 0, or on the tilted
    /// film's plane.
    fn film_at(&self, film: DVec2) -> DVec3 {
        film.extend(self.tilt.dot(film))
    }

    /// The ray from film point `o` (mm) towards rear-plane point `rear`.
    fn film_ray(&self, o: DVec3, rear: DVec2) -> LensRay {
        LensRay {
            o,
            d: (rear.extend(self.film_distance) - o).normalize(),
        }
    }

    /// The rays of a bundle from the scene point `object` (mm) aimed over a disc a little
    /// wider than the entrance pupil, traced to the film side: each as the line `a + z b` of
    /// its xy against z. Empty when the lens has no entrance pupil.
    fn bundle(&self, object: DVec3) -> Vec<(DVec2, DVec2)> {
        let Some((pupil_z, pupil_radius)) = self.pupil(true) else {
            return Vec::new();
        };
        let reach = 1.2 * pupil_radius;
        let g = |k: usize| ((k as f64 + 0.5) / FOCUS_GRID as f64 * 2.0 - 1.0) * reach;
        let mut lines = Vec::with_capacity(FOCUS_GRID * FOCUS_GRID);
        for i in 0..FOCUS_GRID {
            for j in 0..FOCUS_GRID {
                let target = DVec3::new(g(i), g(j), pupil_z);
                let ray = LensRay {
                    o: object,
                    d: (target - object).normalize(),
                };
                let Some((out, _)) = self.trace_from_scene(ray, Clip::Stop) else {
                    continue;
                };
                if out.d.z >= 0.0 {
                    continue;
                }
                let slope = out.d.truncate() / out.d.z;
                lines.push((out.o.truncate() - out.o.z * slope, slope));
            }
        }
        lines
    }

    /// The best-focus image (mm) of the scene point `object`: where its bundle's rays are
    /// least spread about their centroid (least squares over z), and the centroid there.
    fn best_image(&self, object: DVec3) -> Option<DVec3> {
        let lines = self.bundle(object);
        if lines.len() < 4 {
            return None;
        }
        let n = lines.len() as f64;
        let (a0, b0) = lines
            .iter()
            .fold((DVec2::ZERO, DVec2::ZERO), |(a, b), (la, lb)| {
                (a + *la, b + *lb)
            });
        let (a0, b0) = (a0 / n, b0 / n);
        let (ab, bb) = lines.iter().fold((0.0, 0.0), |(ab, bb), (a, b)| {
            let (a, b) = (*a - a0, *b - b0);
            (ab + a.dot(b), bb + b.dot(b))
        });
        let z = -ab / bb;
        (bb > 0.0 && z.is_finite()).then(|| (a0 + z * b0).extend(z))
    }

    /// The film's slopes (`tilt`) for the plane of focus `z = focus_mm + slopes.x x +
    /// slopes.y y`: along each axis, the slope of the line through the best-focus images of
    /// two points of that plane seen on either side of the axis. The two points sit on the
    /// lines from the entrance pupil's centre at field slope `+-w` (0.4 of the film radius
    /// over the focal length, less where the plane is steep), so a curvature of the field,
    /// which moves both images alike, drops out. Paraxially this is Scheimpflug's rule: the
    /// image plane's slope is the lateral magnification times the object plane's. None
    /// when a point lies inside the lens or has no real image behind the rear element.
    fn film_slopes(&self, focus_mm: f64, slopes: DVec2) -> Option<DVec2> {
        let (pupil_z, _) = self.pupil(true)?;
        let front_z = self.elements[0].z;
        let mut out = DVec2::ZERO;
        for axis in 0..2 {
            let s = slopes[axis];
            let w = (0.4 * self.film_radius / self.focal_length.abs()).min(0.25 / s.abs());
            let dir = if axis == 0 { DVec2::X } else { DVec2::Y };
            let mut images = [DVec3::ZERO; 2];
            for (image, side) in images.iter_mut().zip([-1.0, 1.0]) {
                // From the pupil's centre along (side w, 1): z = pupil_z + t meets the plane
                // where pupil_z + t = focus_mm + s side w t.
                let t = (focus_mm - pupil_z) / (1.0 - s * side * w);
                let object = (dir * (side * w * t)).extend(pupil_z + t);
                if !(t > 0.0 && object.z > front_z) {
                    return None;
                }
                *image = self
                    .best_image(object)
                    .filter(|i| i.z < self.film_distance)?;
            }
            let across = (images[1] - images[0]).truncate().dot(dir);
            out[axis] = (images[1].z - images[0].z) / across;
        }
        out.is_finite().then_some(out)
    }

    /// Best focus of the traced bundle from the axial point at `focus_mm`: moves the film by
    /// the least-squares plane of the bundle's rays on the film side, a few times (moving the
    /// lens changes the object distance a little).
    fn refine_focus(&mut self, focus_mm: f64) {
        for _ in 0..12 {
            let lines = self.bundle(DVec3::new(0.0, 0.0, focus_mm));
            let (ab, bb) = lines.iter().fold((0.0, 0.0), |(ab, bb), (a, b)| {
                (ab + a.dot(*b), bb + b.dot(*b))
            });
            if lines.len() < 4 || bb == 0.0 {
                return;
            }
            let best = -ab / bb;
            if !best.is_finite() || self.film_distance - best <= 0.0 {
                return;
            }
            self.set_film_distance(self.film_distance - best);
            if best.abs() < 1e-9 {
                return;
            }
        }
    }

    /// The exit-pupil bound of segment `k`: the rear-plane points through which rays from
    /// film points of the segment's radii get through, found on a grid over the rear element
    /// (1.5 times its clear aperture, as a ray may reach the curved element's aperture from
    /// outside it on the vertex plane) and over the paraxial exit pupil's footprint (which a
    /// small stop makes finer than that grid), then on a grid over what that found; grown by
    /// a cell, since a ray between grid points may get through where none of them did. On a
    /// tilted film a point at radius `r` lies anywhere within `r |tilt|` of the plane z = 0,
    /// depending on its azimuth, so the film points are taken at both ends of that range (the
    /// rear points that pass move steadily with the depth, so the two ends' rectangle holds
    /// the middle's; the brute-force test checks it on a steep tilt).
    fn bound_segment(&self, k: usize) -> PupilBound {
        let depth = self.tilt.length();
        let films: Vec<DVec3> = (0..BOUND_RADII)
            .flat_map(|a| {
                let t = (k as f64 + a as f64 / (BOUND_RADII - 1) as f64) / PUPIL_SEGMENTS as f64;
                let r = t * self.film_radius;
                let heights: &[f64] = if depth > 0.0 { &[-1.0, 1.0] } else { &[0.0] };
                heights
                    .iter()
                    .map(move |h| DVec3::new(r, 0.0, h * r * depth))
            })
            .collect();
        let scan = |bound: &mut PupilBound, films: &[DVec3], min: DVec2, max: DVec2| -> f64 {
            let cell = (max - min) / BOUND_GRID as f64;
            for &film in films {
                for i in 0..BOUND_GRID {
                    for j in 0..BOUND_GRID {
                        let q = min + cell * DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
                        if self
                            .trace_from_film(self.film_ray(film, q), Clip::Circles)
                            .is_some()
                        {
                            bound.include(q);
                        }
                    }
                }
            }
            cell.max_element()
        };
        // First pass: the rear element, and the exit pupil's footprint for each radius.
        let rear = 1.5 * self.elements[self.elements.len() - 1].aperture_radius;
        let mut coarse = PupilBound::EMPTY;
        let mut cell = scan(&mut coarse, &films, DVec2::splat(-rear), DVec2::splat(rear));
        if let Some((z, radius)) = self.pupil(false) {
            for &film in &films {
                // The cone from the film point to the pupil disc at z, on the rear plane.
                if (z - film.z).abs() <= 1e-9 {
                    continue;
                }
                let scale = (self.film_distance - film.z) / (z - film.z);
                let centre = DVec2::new(film.x * (1.0 - scale), 0.0);
                let half = DVec2::splat(1.5 * radius * scale.abs() + 1e-6);
                let footprint = scan(&mut coarse, &[film], centre - half, centre + half);
                cell = cell.max(footprint.min(cell));
            }
        }
        if coarse.is_empty() {
            return coarse;
        }
        // Second pass: a finer grid over what the first found, grown by its cell.
        let (min, max) = (
            coarse.min - DVec2::splat(cell),
            coarse.max + DVec2::splat(cell),
        );
        let mut fine = coarse;
        let fine_cell = scan(&mut fine, &films, min, max);
        let grow = DVec2::splat(fine_cell);
        PupilBound {
            min: fine.min - grow,
            max: fine.max + grow,
        }
    }

    /// The film centre's irradiance from a uniform unit sky, up to the constant `delta^2`:
    /// the integral over the rear plane of `cos^4(theta)` times the light that gets through,
    /// by the midpoint rule over the centre's bound.
    fn centre_irradiance(&self) -> f64 {
        let b = self.bounds[0];
        if b.is_empty() {
            return 0.0;
        }
        let size = (b.max - b.min) / NORMALISER_GRID as f64;
        let mut sum = 0.0;
        for i in 0..NORMALISER_GRID {
            for j in 0..NORMALISER_GRID {
                let q = b.min + size * DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
                let ray = self.film_ray(DVec3::ZERO, q);
                if let Some((_, passed)) = self.trace_from_film(ray, Clip::Stop) {
                    sum += ray.d.z.powi(4) * passed;
                }
            }
        }
        sum * size.element_product()
    }

    /// The film point (mm) of a raster position: the lens inverts the image. On a tilted
    /// film, the `(x, y)` of the raster position's place on the rigid film.
    fn film_point(&self, p: Point2<Raster>) -> DVec2 {
        let [w, h] = self.base.film.resolution().map(f64::from);
        let u = (f64::from(p.x) / w - 0.5) * self.film_size.x;
        let v = (0.5 - f64::from(p.y) / h) * self.film_size.y;
        let flat = DVec2::new(-u, -v);
        if self.tilt == DVec2::ZERO {
            flat
        } else {
            (self.film_frame * flat.extend(0.0)).truncate()
        }
    }

    /// The raster position of a film point (mm).
    fn raster_point(&self, film: DVec2) -> Point2<Raster> {
        let flat = if self.tilt == DVec2::ZERO {
            film
        } else {
            (self.film_frame.transpose() * self.film_at(film)).truncate()
        };
        let [w, h] = self.base.film.resolution().map(f64::from);
        let x = (-flat.x / self.film_size.x + 0.5) * w;
        let y = (0.5 + flat.y / self.film_size.y) * h;
        Point2::new(x as f32, y as f32)
    }

    /// The lens-space ray of a film point and lens sample through the lens, with its weight.
    fn lens_ray(&self, film: DVec2, u: glam::Vec2) -> Option<(LensRay, f64)> {
        // The pupil bound of the film radius, rotated to the film point's azimuth.
        let r = film.length();
        let bound = self.bounds[self.segment(r)];
        if bound.is_empty() {
            return None;
        }
        let q = bound.min + (bound.max - bound.min) * u.as_dvec2();
        let azimuth = if r > 0.0 { film / r } else { DVec2::X };
        let rear = azimuth.rotate(q);
        // Trace; weight cos^4(theta) A T / (Delta^2 E_0), T the light the stop passes and
        // Delta the film point's distance from the rear plane (delta, but on a tilted film,
        // where one cosine is to the film's normal).
        let o = self.film_at(film);
        let ray = self.film_ray(o, rear);
        let (out, passed) = self.trace_from_film(ray, Clip::Stop)?;
        let near = self.film_distance / (self.film_distance - o.z);
        // cos at the film times cos^3 at the rear plane: on a tilted film the first is to the
        // film's own normal.
        let cosines = if self.tilt == DVec2::ZERO {
            ray.d.z.powi(4)
        } else {
            let facing = self.film_frame.z_axis.dot(ray.d);
            if facing <= 0.0 {
                return None;
            }
            facing * ray.d.z.powi(3)
        };
        let weight = cosines * bound.area() * passed * self.weight_scale * near * near;
        Some((out, weight))
    }

    /// The camera-space ray (world units) of a raster point and lens sample, with its weight.
    fn ray_at(&self, p: Point2<Raster>, u: glam::Vec2) -> Option<(CameraRayParts, f32)> {
        let (out, weight) = self.lens_ray(self.film_point(p), u)?;
        Some((
            CameraRayParts::by_distance(out.o / MM_PER_UNIT, out.d, &self.base),
            weight as f32,
        ))
    }

    /// The height along `axis` at which `ray` crosses the stop's plane, tracing the elements
    /// `range` (in that order) without clipping; with the ray at the stop.
    fn stop_height(
        &self,
        mut ray: LensRay,
        range: impl Iterator<Item = usize>,
        axis: DVec2,
    ) -> Option<(f64, LensRay)> {
        for i in range {
            self.interact(i, &mut ray, Clip::No)?;
        }
        Some((ray.o.truncate().dot(axis), ray))
    }

    /// Secant iterations on `f(h) = 0` from `h0`, to [`PROJECT_TOLERANCE_MM`]; a step to
    /// where `f` has no value (the ray misses an element) is halved until it has one.
    /// `reach` is the aperture the solution lies within: when `h0` gives no value, the start
    /// is the point nearest to it, on a grid over `[-1.5, 1.5] reach`, that does.
    fn solve(h0: f64, reach: f64, f: impl Fn(f64) -> Option<f64>) -> Option<f64> {
        let start = std::iter::once(h0)
            .chain({
                let mut grid: Vec<f64> = (0..=64)
                    .map(|i| (f64::from(i) / 32.0 - 1.0) * 1.5 * reach)
                    .collect();
                grid.sort_by(|a, b| (a - h0).abs().total_cmp(&(b - h0).abs()));
                grid
            })
            .find_map(|x| f(x).map(|v| (x, v)));
        let (mut x0, mut f0) = start?;
        let step = 1e-4 * reach;
        let (mut x1, mut f1) = match f(x0 + step) {
            Some(v) => (x0 + step, v),
            None => (x0 - step, f(x0 - step)?),
        };
        for _ in 0..60 {
            if f1.abs() < PROJECT_TOLERANCE_MM {
                return Some(x1);
            }
            if f1 == f0 {
                return None;
            }
            let mut x2 = x1 - f1 * (x1 - x0) / (f1 - f0);
            let mut f2 = f(x2);
            for _ in 0..40 {
                if f2.is_some() {
                    break;
                }
                x2 = 0.5 * (x1 + x2);
                f2 = f(x2);
            }
            (x0, f0) = (x1, f1);
            (x1, f1) = (x2, f2?);
        }
        (f1.abs() < PROJECT_TOLERANCE_MM).then_some(x1)
    }

    /// The chief ray of a film point (mm): from the film point through the stop's centre, out
    /// of the front element (clear apertures ignored).
    fn chief_ray_lens(&self, film: DVec2) -> Option<LensRay> {
        let n = self.elements.len();
        let r = film.length();
        let axis = if r > 0.0 { film / r } else { DVec2::X };
        // Paraxial estimate: the line from the film point through the exit pupil's centre
        // (the stop's image seen from the film), at the rear vertex plane; h is the height
        // there along the film point's radial axis.
        let rear_z = self.film_distance;
        let exit_z = self
            .pupil(false)
            .map_or(self.elements[self.stop].z, |(z, _)| z);
        let h0 = if exit_z.abs() > 1e-9 {
            r * (1.0 - rear_z / exit_z)
        } else {
            0.0
        };
        let o = self.film_at(film);
        let ray_to = |h: f64| self.film_ray(o, axis * h);
        let height = |h: f64| -> Option<f64> {
            self.stop_height(ray_to(h), (self.stop..n).rev(), axis)
                .map(|(s, _)| s)
        };
        let h = Self::solve(h0, self.elements[n - 1].aperture_radius, height)?;
        let (_, mut at_stop) = self.stop_height(ray_to(h), (self.stop..n).rev(), axis)?;
        for i in (0..self.stop).rev() {
            self.interact(i, &mut at_stop, Clip::No)?;
        }
        Some(at_stop)
    }

    /// The entrance (`towards_scene`) or exit pupil: the axial position (mm) and radius of
    /// the stopped-down stop's paraxial image through the elements in front of or behind it,
    /// from near-axial traced rays.
    fn pupil(&self, towards_scene: bool) -> Option<(f64, f64)> {
        let n = self.elements.len();
        let stop = &self.elements[self.stop];
        let dz = if towards_scene { 1.0 } else { -1.0 };
        let through = |mut ray: LensRay| -> Option<LensRay> {
            if towards_scene {
                for i in (0..self.stop).rev() {
                    self.interact(i, &mut ray, Clip::No)?;
                }
            } else {
                for i in self.stop + 1..n {
                    self.interact(i, &mut ray, Clip::No)?;
                }
            }
            Some(ray)
        };
        // The image of the stop's centre: where a ray from it at a small angle crosses the
        // axis (extended backwards), and the height there of a ray leaving the stop's plane
        // parallel to the axis at a small height, which gives the magnification.
        let eps = 1e-6;
        let centre = through(LensRay {
            o: DVec3::new(0.0, 0.0, stop.z),
            d: DVec3::new(eps, 0.0, dz).normalize(),
        })?;
        if centre.d.x == 0.0 {
            return None;
        }
        let z = centre.o.z - centre.o.x * centre.d.z / centre.d.x;
        let parallel = through(LensRay {
            o: DVec3::new(eps, 0.0, stop.z),
            d: DVec3::new(0.0, 0.0, dz),
        })?;
        let height = parallel.o.x + (z - parallel.o.z) * parallel.d.x / parallel.d.z;
        let radius = (height / eps).abs() * stop.aperture_radius;
        (z.is_finite() && radius.is_finite()).then_some((z, radius))
    }

    /// The film point (mm) of a lens-space point `p` (mm): the chief ray through it.
    fn project_lens(&self, p: DVec3) -> Option<DVec2> {
        let front_z = self.elements[0].z;
        if p.z <= front_z {
            return None;
        }
        let rho = p.truncate().length();
        let axis = if rho > 0.0 {
            p.truncate() / rho
        } else {
            DVec2::X
        };
        // Paraxial estimate: the line from p to the entrance pupil's centre, at the front
        // vertex plane.
        let entrance = self
            .pupil(true)
            .map_or(self.elements[self.stop].z, |(z, _)| z);
        let h0 = if p.z != entrance {
            rho * (front_z - entrance) / (p.z - entrance)
        } else {
            0.0
        };
        let ray_to = |h: f64| LensRay {
            o: p,
            d: ((axis * h).extend(front_z) - p).normalize(),
        };
        let height = |h: f64| -> Option<f64> {
            self.stop_height(ray_to(h), 0..=self.stop, axis)
                .map(|(s, _)| s)
        };
        let h = Self::solve(h0, self.elements[0].aperture_radius, height)?;
        let (_, mut ray) = self.stop_height(ray_to(h), 0..=self.stop, axis)?;
        for i in self.stop + 1..self.elements.len() {
            self.interact(i, &mut ray, Clip::No)?;
        }
        // Where the ray meets the film: z = tilt . xy, i.e. (-tilt, 1) . p = 0.
        let normal = (-self.tilt).extend(1.0);
        let towards = normal.dot(ray.d);
        if towards >= 0.0 {
            return None;
        }
        let t = -normal.dot(ray.o) / towards;
        Some((ray.o + t * ray.d).truncate())
    }
}

impl Camera for RealisticCamera {
    #[inline]
    fn base(&self) -> &CameraBase {
        &self.base
    }

    fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        let time = crate::camera::ray_time(&self.base, sample)?;
        let (parts, weight) = self.ray_at(sample.p_film, sample.p_lens)?;
        let ray = chain::to_world(&self.pose.world_from_camera(&self.base, time), parts, time);
        Some(CameraRay { ray, weight })
    }

    fn generate_ray_differential(&self, sample: &CameraSample) -> Option<CameraRayDifferential> {
        // Finite differences of traced rays with the same lens sample (the chain's rule for
        // neighbours without a ray), and the main ray's weight.
        let (_, weight) = self.ray_at(sample.p_film, sample.p_lens)?;
        let differential = chain::generate_differential(&self.base, &self.pose, sample, |p| {
            self.ray_at(p, sample.p_lens).map(|(parts, _)| parts)
        })?;
        Some(CameraRayDifferential {
            weight,
            ..differential
        })
    }

    fn project(&self, p: Point3<World>, time: f32) -> Option<Point2<Raster>> {
        let v = chain::camera_point(&self.base, &self.pose, p, time) * MM_PER_UNIT;
        let distance = (v - DVec3::new(0.0, 0.0, self.elements[0].z)).length() / MM_PER_UNIT;
        if !(distance >= f64::from(self.base.near) && distance <= f64::from(self.base.far)) {
            return None;
        }
        let film = self.project_lens(v)?;
        Some(self.raster_point(film))
    }
}

#[cfg(test)]
mod tests;
