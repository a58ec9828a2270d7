//! From a validated [`SceneDescription`] to the objects that render it: the camera, the
//! accelerator's scene, the shading scene and the sampler.

use crate::error::RenderError;
use crate::film::{Filter, PixelRect};
use crate::scene::{
    CameraDescription, CameraKind, CameraSettings, IntegratorKind, LightSettings, MaterialSettings,
    SceneDescription, ShapeGeometry,
};
use crate::scene::{DEFAULT_INTERAXIAL, camera_key};
use glam::Vec3;
use obscura_accel::{Placement, Scene, SceneBuilder, Shape, TriangleMesh};
use obscura_camera::{
    AnyCamera, CameraBase, CameraError, CubeFaceCamera, CylindricalCamera, EnvironmentCamera,
    FilmGeometry, FisheyeCamera, LookAt, OctahedralCamera, OdsCamera, OpenCvCamera,
    OpenCvFisheyeCamera, OrthographicCamera, PerspectiveCamera, RealisticCamera, RealisticLens,
    ScreenWindow, look_at_pose, opencv_pose,
};
use obscura_sample::Sampler;
use obscura_shade::{EnvironmentLight, Light, Material, ShadingScene};
use obscura_space::AnimatedTransform;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Bytes of memory the renderer needs per pixel of the film: the f64 sums (40), the resolved
/// f32 image (16) and the 8-bit copy for PNG (4), plus a margin for tile buffers (1.5x sums).
pub const BYTES_PER_PIXEL: u64 = 40 + 16 + 4 + 60;

/// A scene ready to render.
pub struct RenderScene {
    /// What the file said (after command-line overrides).
    pub description: SceneDescription,
    /// The camera.
    pub camera: AnyCamera,
    /// The geometry and its BVHs.
    pub geometry: Scene,
    /// Materials and lights.
    pub shading: ShadingScene,
    /// The sampler.
    pub sampler: Sampler,
    /// The reconstruction filter.
    pub filter: Filter,
    /// The pixels to render (the crop window).
    pub pixel_bounds: PixelRect,
    /// Triangles skipped as degenerate while loading meshes, per file.
    pub skipped_triangles: Vec<(PathBuf, usize)>,
    /// The factor the path integrator's radiance is scaled by when the camera gives exposure
    /// settings ([`obscura_camera::Exposure::scale`]); None (no scaling at all) otherwise.
    pub exposure_scale: Option<f32>,
}

/// The grey diffuse that shapes without a `material` key get.
pub const DEFAULT_MATERIAL: Material = Material::Diffuse {
    reflectance: Vec3::splat(0.5),
};

impl RenderScene {
    /// Builds everything the description names: loads meshes and maps, makes the camera.
    pub fn build(description: SceneDescription) -> Result<RenderScene, RenderError> {
        let d = &description;
        check_memory(d)?;
        let camera = camera_of(d)?;
        let [x0, x1, y0, y1] = obscura_camera::Camera::film(&camera).pixel_bounds();
        let pixel_bounds = PixelRect { x0, y0, x1, y1 };

        // Materials: the file's, then the default grey for shapes that name none.
        let mut materials: Vec<Material> = d.materials.iter().map(|(_, m)| material(*m)).collect();
        let default_index = materials.len() as u32;
        materials.push(DEFAULT_MATERIAL);

        // No material or output reads a hit's surface coordinates.
        let mut builder = SceneBuilder::new().with_uv(false);
        let mut instance_material = Vec::new();
        let mut emitters = Vec::new();
        let mut placed = Vec::new();
        let mut meshes: HashMap<PathBuf, Arc<TriangleMesh>> = HashMap::new();
        let mut skipped_triangles = Vec::new();
        for s in &d.shapes {
            let key = format!("shapes[{}]", s.index);
            let shape = match &s.geometry {
                ShapeGeometry::Sphere { center, radius } => Shape::Sphere {
                    center: (*center).into(),
                    radius: *radius,
                },
                ShapeGeometry::Quad {
                    origin,
                    edge_u,
                    edge_v,
                } => Shape::Quad {
                    origin: (*origin).into(),
                    edge_u: (*edge_u).into(),
                    edge_v: (*edge_v).into(),
                },
                ShapeGeometry::Mesh { file: mesh_file } => {
                    let mesh = match meshes.get(mesh_file).or_else(|| d.meshes.get(mesh_file)) {
                        Some(m) => m.clone(),
                        None => {
                            let m = Arc::new(
                                obscura_accel::load_obj(mesh_file)
                                    .map_err(|e| d.error(format!("{key}.file"), e.to_string()))?,
                            );
                            if m.skipped_degenerate() > 0 {
                                skipped_triangles.push((mesh_file.clone(), m.skipped_degenerate()));
                            }
                            meshes.insert(mesh_file.clone(), m.clone());
                            m
                        }
                    };
                    Shape::Mesh(mesh)
                }
            };
            let placement = match s.transform_end {
                Some(end)
                    if end != s.transform && d.camera.shutter.open < d.camera.shutter.close =>
                {
                    Placement::Moving(
                        AnimatedTransform::new(
                            s.transform,
                            d.camera.shutter.open,
                            end,
                            d.camera.shutter.close,
                        )
                        .map_err(|e| d.error(format!("{key}.transform_end"), e.to_string()))?,
                    )
                }
                _ => Placement::Static(s.transform),
            };
            let instance = builder
                .add(shape.clone(), placement.clone())
                .map_err(|e| d.error(key.clone(), e.to_string()))?;
            instance_material.push(s.material.map_or(default_index, |m| m as u32));
            if let Some(e) = s.emission {
                emitters.push((instance, shape.clone(), placement.clone(), Vec3::from(e)));
            }
            placed.push((instance, shape, placement));
        }
        let geometry = builder
            .build()
            .map_err(|e| d.error("shapes", e.to_string()))?;

        let mut lights = Vec::new();
        for (i, l) in d.lights.iter().enumerate() {
            let key = format!("lights[{i}]");
            let light = match l {
                LightSettings::Point {
                    position,
                    intensity,
                } => Light::point((*position).into(), (*intensity).into()),
                LightSettings::Distant {
                    direction,
                    irradiance,
                } => Light::distant((*direction).into(), (*irradiance).into()),
                LightSettings::Environment {
                    radiance,
                    file: None,
                    transform: _,
                } => EnvironmentLight::constant((*radiance).into()).map(Light::Environment),
                LightSettings::Environment {
                    radiance,
                    file: Some(map),
                    transform,
                } => {
                    // A map given in memory (an imported scene's), else the file.
                    let at_file = |message| d.error(format!("{key}.file"), message);
                    let read;
                    let image = match d.maps.get(map) {
                        Some(image) => image.as_ref(),
                        None => {
                            read = read_exr_map(map).map_err(at_file)?;
                            &read
                        }
                    };
                    let (w, h, texels) = environment_texels(map, image).map_err(at_file)?;
                    let scale = Vec3::from(*radiance);
                    let texels = texels.into_iter().map(|t| t * scale).collect();
                    EnvironmentLight::from_texels(w, h, texels, transform.matrix())
                        .map(Light::Environment)
                }
            }
            .map_err(|e| d.error(key, e.to_string()))?;
            lights.push(light);
        }
        let mut shading = ShadingScene::new(materials, instance_material, lights, emitters)
            .map_err(|e| d.error("lights", e.to_string()))?;
        shading.aim_at_specular(placed.iter().map(|(i, s, p)| (*i, s, p)));
        shading.solve_through_glass(placed.iter().map(|(i, s, p)| (*i, s, p)));
        let sampler = Sampler::new(d.sampler.kind, d.sampler.spp, d.sampler.seed)
            .map_err(|e| d.error("sampler", e.to_string()))?;
        let filter = Filter::new(d.film.filter);
        let exposure_scale = d.camera.exposure.map(|e| e.scale());
        Ok(RenderScene {
            description,
            camera,
            geometry,
            shading,
            sampler,
            filter,
            pixel_bounds,
            skipped_triangles,
            exposure_scale,
        })
    }

    /// The integrator this scene renders with.
    pub fn integrator(&self) -> IntegratorKind {
        self.description.integrator.kind
    }
}

/// Refuses, up front, a film that would not fit in memory, saying how much it needs.
fn check_memory(d: &SceneDescription) -> Result<(), RenderError> {
    let resolution = d.film.resolution;
    let pixels = u64::from(resolution[0]) * u64::from(resolution[1]);
    let need = pixels.saturating_mul(BYTES_PER_PIXEL);
    let available = available_memory();
    if need > available {
        return Err(d.error(
            "film.resolution",
            format!(
                "a {}x{} film needs {} of memory, more than the {} available",
                resolution[0],
                resolution[1],
                human_bytes(need),
                human_bytes(available)
            ),
        ));
    }
    Ok(())
}

/// MemAvailable from /proc/meminfo, else 16 GiB.
fn available_memory() -> u64 {
    let fallback = 16 << 30;
    let Ok(info) = std::fs::read_to_string("/proc/meminfo") else {
        return fallback;
    };
    info.lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map_or(fallback, |kb| kb * 1024)
}

/// `1.5 GiB`, `320.0 MiB`.
pub fn human_bytes(b: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = b as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{b} B")
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}

fn material(m: MaterialSettings) -> Material {
    match m {
        MaterialSettings::Diffuse { reflectance } => Material::Diffuse {
            reflectance: reflectance.into(),
        },
        MaterialSettings::Mirror { reflectance } => Material::Mirror {
            reflectance: reflectance.into(),
        },
        MaterialSettings::Dielectric { ior } => Material::Dielectric { ior },
        MaterialSettings::RoughConductor {
            reflectance,
            roughness,
        } => Material::RoughConductor {
            reflectance: reflectance.into(),
            roughness,
        },
    }
}

/// The camera of a scene description alone, with the errors [`RenderScene::build`] gives for
/// it (naming the file, the `camera.*` or `film.*` key and the line); builds no geometry.
pub fn camera_of(d: &SceneDescription) -> Result<AnyCamera, RenderError> {
    build_camera(&d.camera, d.film.resolution, d.film.crop)
        .map_err(|e| d.error(camera_key(&e), e.to_string()))
}

impl CameraDescription {
    /// The camera, with the errors [`camera_of`] gives (naming the file, the `camera.*` or
    /// `film.*` key and the line).
    pub fn camera(&self) -> Result<AnyCamera, RenderError> {
        build_camera(&self.camera, self.film.resolution, self.film.crop).map_err(|e| {
            RenderError::at_key(&self.file, &self.source, camera_key(&e), e.to_string())
        })
    }
}

pub(crate) fn build_camera(
    c: &CameraSettings,
    resolution: [u32; 2],
    crop: Option<[f32; 4]>,
) -> Result<AnyCamera, CameraError> {
    // The pose: OpenCV extrinsics, or the look-at(s), moved to one eye for a stereo pair.
    let rig = c.stereo.map(|s| s.rig);
    let eye = c.eye.zip(rig);
    let pose = match (c.pose, c.extrinsics) {
        (Some((start, Some(end))), _) if c.shutter.open < c.shutter.close => {
            AnimatedTransform::new(start, c.shutter.open, end, c.shutter.close)?
        }
        (Some((start, _)), _) => AnimatedTransform::fixed(start),
        (None, Some(x)) => opencv_pose(x.rvec, x.tvec)?,
        (None, None) => {
            let for_eye = |look: LookAt| match eye {
                Some((eye, rig)) => rig.eye_look_at(eye, look),
                None => Ok(look),
            };
            let end = c.end.map(for_eye).transpose()?;
            look_at_pose(for_eye(c.start)?, end, c.shutter)?
        }
    };
    // The screen window, lens-shifted and, for one eye of a pair, shifted off axis.
    let projective = matches!(c.kind, CameraKind::Perspective | CameraKind::Orthographic);
    let mut window = c.screen_window;
    if projective && (c.lens_shift != [0.0, 0.0] || eye.is_some()) {
        let mut w = window
            .unwrap_or_else(|| ScreenWindow::default_for(resolution))
            .lens_shifted(c.lens_shift)?;
        if let Some((eye, rig)) = eye {
            w = rig.eye_window(eye, w, c.fov, c.fov_axis, resolution)?;
        }
        window = Some(w);
    }
    let film = FilmGeometry::new(resolution, window, crop)?;
    let base = CameraBase::new(pose, c.shutter, film)
        .with_clip(c.near, c.far)
        .with_timing(c.timing.clone());
    // The OpenCV models always have intrinsics from a parsed file; a description built in code
    // without them gets the error a missing fx would.
    let intrinsics = || {
        c.intrinsics.ok_or(CameraError::NonFinite {
            what: "fx",
            got: f32::NAN,
        })
    };
    Ok(match c.kind {
        CameraKind::Perspective => {
            PerspectiveCamera::new(base, c.fov, c.fov_axis, c.lens.clone())?.into()
        }
        CameraKind::Orthographic => OrthographicCamera::new(base, c.lens.clone())?.into(),
        CameraKind::Environment => EnvironmentCamera::new(base)?.into(),
        CameraKind::OpenCv => OpenCvCamera::new(base, intrinsics()?, &c.distortion)?.into(),
        CameraKind::OpenCvFisheye => {
            OpenCvFisheyeCamera::new(base, intrinsics()?, &c.distortion)?.into()
        }
        CameraKind::Fisheye => FisheyeCamera::new(base, c.projection, c.fov, c.lens_shift)?.into(),
        CameraKind::Cylindrical => CylindricalCamera::new(base, c.fov)?.into(),
        CameraKind::Octahedral => OctahedralCamera::new(base)?.into(),
        CameraKind::CubeFace => CubeFaceCamera::new(base, c.face)?.into(),
        CameraKind::Ods => {
            let interaxial = rig.map_or(DEFAULT_INTERAXIAL, |r| r.interaxial);
            OdsCamera::new(base, interaxial)?.into()
        }
        CameraKind::Realistic => {
            // A parsed file always has the lens; a description built in code without one gets
            // the error a file without rows would.
            let r = c
                .realistic
                .as_ref()
                .ok_or_else(|| CameraError::LensPrescription {
                    line: None,
                    message: "no lens_file".into(),
                })?;
            // The stop takes the aperture the scene layer built for the thin lens (blades, an
            // image, a squeeze), in units of the stop's radius.
            let lens = RealisticLens {
                aperture_diameter: r.aperture_diameter,
                focus_distance: r.focus_distance,
                film_diagonal: r.film_diagonal,
                aperture: c.lens.aperture.clone(),
                focal_plane_tilt: r.focal_plane_tilt,
            };
            RealisticCamera::new(base, &r.prescription, lens)?.into()
        }
    })
}

/// Reads an equirectangular EXR map.
fn read_exr_map(path: &Path) -> Result<crate::film::Image, String> {
    let (image, _) = crate::output::read_exr(path).map_err(|e| match e {
        RenderError::Encode { message, .. } if !path.exists() => {
            format!("{}: file not found ({message})", path.display())
        }
        other => other.to_string(),
    })?;
    Ok(image)
}

/// The texels of an equirectangular EXR's bytes (`path` names it in errors): width, height and
/// linear RGB texels, row 0 at the top; an error for a texel that is negative, NaN or infinite.
pub fn environment_map_texels(bytes: &[u8], path: &Path) -> Result<(u32, u32, Vec<Vec3>), String> {
    let (image, _) = crate::output::decode_exr(bytes, path).map_err(|e| e.to_string())?;
    environment_texels(path, &image)
}

/// An equirectangular map's texels as linear RGB, row 0 at the top, checked.
fn environment_texels(
    path: &Path,
    image: &crate::film::Image,
) -> Result<(u32, u32, Vec<Vec3>), String> {
    let texels: Vec<Vec3> = image
        .pixels
        .iter()
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect();
    if let Some(i) = texels
        .iter()
        .position(|t| !t.is_finite() || t.min_element() < 0.0)
    {
        return Err(format!(
            "{}: texel ({}, {}) is negative, NaN or infinite",
            path.display(),
            i as u32 % image.width,
            i as u32 / image.width
        ));
    }
    Ok((image.width, image.height, texels))
}
