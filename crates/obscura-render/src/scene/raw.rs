//! The scene file's raw serde structs: what TOML gives before any check. Unknown keys are
//! errors.

use super::settings::V3;
use serde::Deserialize;
use std::collections::BTreeMap;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawScene {
    pub(super) film: RawFilm,
    #[serde(default)]
    pub(super) sampler: RawSampler,
    #[serde(default)]
    pub(super) integrator: RawIntegrator,
    pub(super) camera: RawCamera,
    #[serde(default)]
    pub(super) materials: BTreeMap<String, RawMaterial>,
    #[serde(default)]
    pub(super) shapes: Vec<RawShape>,
    #[serde(default)]
    pub(super) lights: Vec<RawLight>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawFilm {
    pub(super) resolution: [u32; 2],
    pub(super) filter: Option<toml::Value>,
    pub(super) crop: Option<[f32; 4]>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSampler {
    #[serde(rename = "type")]
    pub(super) kind: Option<String>,
    pub(super) spp: Option<u32>,
    pub(super) seed: Option<u64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawIntegrator {
    #[serde(rename = "type")]
    pub(super) kind: Option<String>,
    pub(super) max_depth: Option<u32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawCamera {
    #[serde(rename = "type")]
    pub(super) kind: Option<String>,
    pub(super) eye: Option<V3>,
    pub(super) target: Option<V3>,
    pub(super) up: Option<V3>,
    pub(super) fov: Option<f32>,
    pub(super) fov_axis: Option<String>,
    pub(super) screen_window: Option<[f32; 4]>,
    pub(super) near: Option<f32>,
    pub(super) far: Option<f32>,
    pub(super) lens_radius: Option<f32>,
    pub(super) focal_distance: Option<f32>,
    pub(super) aperture_blades: Option<u32>,
    pub(super) aperture_rotation: Option<f32>,
    pub(super) shutter: Option<[f32; 2]>,
    pub(super) eye_end: Option<V3>,
    pub(super) target_end: Option<V3>,
    pub(super) up_end: Option<V3>,
    pub(super) fx: Option<f64>,
    pub(super) fy: Option<f64>,
    pub(super) cx: Option<f64>,
    pub(super) cy: Option<f64>,
    pub(super) distortion: Option<Vec<f64>>,
    pub(super) rvec: Option<[f64; 3]>,
    pub(super) tvec: Option<[f64; 3]>,
    pub(super) projection: Option<String>,
    pub(super) face: Option<String>,
    pub(super) lens_shift: Option<[f32; 2]>,
    pub(super) stereo: Option<RawStereo>,
    pub(super) pose: Option<[f32; 16]>,
    pub(super) pose_end: Option<[f32; 16]>,
    pub(super) lens_file: Option<String>,
    pub(super) aperture_diameter: Option<f32>,
    pub(super) focus_distance: Option<f32>,
    pub(super) film_diagonal: Option<f32>,
    pub(super) aperture_image: Option<String>,
    pub(super) anamorphic: Option<f32>,
    pub(super) shutter_curve: Option<Vec<[f32; 2]>>,
    pub(super) rolling_shutter: Option<RawRollingShutter>,
    pub(super) focal_plane_tilt: Option<[f32; 2]>,
    pub(super) f_number: Option<f32>,
    pub(super) shutter_time: Option<f32>,
    pub(super) iso: Option<f32>,
    pub(super) exposure_compensation: Option<f32>,
    pub(super) focal_length: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawRollingShutter {
    pub(super) readout: Option<f32>,
    pub(super) direction: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawStereo {
    pub(super) interaxial: Option<f32>,
    pub(super) convergence: Option<f32>,
    pub(super) layout: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMaterial {
    #[serde(rename = "type")]
    pub(super) kind: String,
    pub(super) reflectance: Option<V3>,
    pub(super) ior: Option<f32>,
    pub(super) roughness: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawShape {
    #[serde(rename = "type")]
    pub(super) kind: String,
    pub(super) center: Option<V3>,
    pub(super) radius: Option<f32>,
    pub(super) origin: Option<V3>,
    pub(super) edge_u: Option<V3>,
    pub(super) edge_v: Option<V3>,
    pub(super) file: Option<String>,
    pub(super) material: Option<String>,
    pub(super) emission: Option<V3>,
    pub(super) transform: Option<Vec<RawOp>>,
    pub(super) transform_end: Option<Vec<RawOp>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawOp {
    pub(super) scale: Option<V3>,
    pub(super) rotate: Option<[f32; 4]>,
    pub(super) translate: Option<V3>,
    pub(super) matrix: Option<[f32; 16]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawLight {
    #[serde(rename = "type")]
    pub(super) kind: String,
    pub(super) position: Option<V3>,
    pub(super) intensity: Option<V3>,
    pub(super) direction: Option<V3>,
    pub(super) irradiance: Option<V3>,
    pub(super) radiance: Option<V3>,
    pub(super) file: Option<String>,
    pub(super) transform: Option<Vec<RawOp>>,
}
