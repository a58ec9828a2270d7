//! Lights: point and distant (here, as plain variants of [`Light`]), area (any emissive shape
//! of obscura-accel, `area.rs`) and environment (`environment.rs`); `solid_angle.rs` holds the
//! density conversions the area light shares.

mod area;
mod environment;
pub(crate) mod solid_angle;

pub use area::AreaLight;
pub use environment::{EnvironmentLight, direction_to_uv, uv_to_direction};

use crate::error::{ShadeError, check_non_negative};
use glam::{Vec2, Vec3};

/// Linear-RGB luminance (Rec. 709 primaries), the weight for importance sampling.
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Cosines and pdfs below this are treated as zero (the sample is dropped, not divided by).
const TINY: f32 = 1e-9;

/// A light sample seen from a reference point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// Unit world direction from the reference point towards the light.
    pub wi: Vec3,
    /// Radiance arriving along `wi` (for delta lights: the irradiance on a surface facing them).
    pub radiance: Vec3,
    /// Density in solid angle; 1 for delta lights (see `delta`).
    pub pdf: f32,
    /// The sampled point on the light, for the shadow ray; `None` for lights at infinity.
    pub p_light: Option<Vec3>,
    /// True for point and distant lights: they cannot be hit by BSDF sampling, so no MIS.
    pub delta: bool,
}

/// A light source. Build with the constructors, which validate.
#[derive(Debug, Clone)]
pub enum Light {
    /// An isotropic point light.
    Point {
        /// World position.
        position: Vec3,
        /// Radiant intensity in W/sr per channel: irradiance at distance `r` facing it is `intensity / r^2`.
        intensity: Vec3,
    },
    /// A directional light at infinity.
    Distant {
        /// Unit direction the light travels in.
        direction: Vec3,
        /// Irradiance on a surface facing the light.
        irradiance: Vec3,
    },
    /// An emissive shape.
    Area(AreaLight),
    /// Light arriving from infinitely far in every direction.
    Environment(EnvironmentLight),
}

impl Light {
    /// A point light; errors on non-finite or negative values.
    pub fn point(position: Vec3, intensity: Vec3) -> Result<Light, ShadeError> {
        if !position.is_finite() {
            return Err(ShadeError::NotFinite {
                parameter: "position",
            });
        }
        check_non_negative(intensity, "intensity")?;
        Ok(Light::Point {
            position,
            intensity,
        })
    }

    /// A distant light travelling along `direction` (normalised here; must not be zero).
    pub fn distant(direction: Vec3, irradiance: Vec3) -> Result<Light, ShadeError> {
        if !direction.is_finite() {
            return Err(ShadeError::NotFinite {
                parameter: "direction",
            });
        }
        let direction = direction.try_normalize().ok_or(ShadeError::OutOfRange {
            parameter: "direction",
            expected: "a non-zero vector",
        })?;
        check_non_negative(irradiance, "irradiance")?;
        Ok(Light::Distant {
            direction,
            irradiance,
        })
    }

    /// True for lights that BSDF sampling cannot hit (point, distant).
    pub fn is_delta(&self) -> bool {
        matches!(self, Light::Point { .. } | Light::Distant { .. })
    }

    /// Samples incident light at world point `p_ref` at instant `time` from canonical `u2`.
    /// `None` when this sample carries nothing (e.g. the back of an area light).
    pub fn sample_li(&self, p_ref: Vec3, time: f32, u2: Vec2) -> Option<LightSample> {
        match self {
            Light::Point {
                position,
                intensity,
            } => {
                let to_light = *position - p_ref;
                let d2 = to_light.length_squared();
                if d2 <= TINY {
                    return None;
                }
                Some(LightSample {
                    wi: to_light / d2.sqrt(),
                    radiance: *intensity / d2,
                    pdf: 1.0,
                    p_light: Some(*position),
                    delta: true,
                })
            }
            Light::Distant {
                direction,
                irradiance,
            } => Some(LightSample {
                wi: -*direction,
                radiance: *irradiance,
                pdf: 1.0,
                p_light: None,
                delta: true,
            }),
            Light::Area(area) => area.sample_li(p_ref, time, u2),
            Light::Environment(env) => env.sample_li(u2),
        }
    }
}
