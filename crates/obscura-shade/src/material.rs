//! Materials and their BSDFs, written in the local shading frame (normal = +z).
//!
//! Conventions: `wo` points from the surface towards the viewer (the previous path vertex),
//! `wi` towards the light (the next vertex); both are unit vectors in the local frame. `eval`
//! returns `f(wo, wi)` without the cosine; the integrator multiplies by `|wi.z|`. Delta
//! (specular) lobes are never returned by `eval` or `pdf`; only `sample` produces them.
//!
//! Two-sidedness: diffuse, mirror and rough conductor reflect on whichever side `wo` is (the
//! shading normal is, in effect, flipped towards the viewer). The dielectric uses the true
//! side: `wo.z > 0` is outside (the side the shape's normal faces), `wo.z < 0` inside.

use crate::error::{ShadeError, check_unit};
use core::f32::consts::{FRAC_1_PI, PI, TAU};
use glam::{Vec2, Vec3};
use obscura_sample::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};

/// Rough conductors with `alpha = roughness^2` below this are treated as perfect mirrors (with
/// their Fresnel term): the GGX lobe is then too narrow to evaluate in f32.
pub const MIN_ALPHA: f32 = 1e-3;

/// A surface's material. Construct the variants directly and call [`Material::validate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Material {
    /// Lambertian reflection, `f = reflectance / pi`.
    Diffuse {
        /// Albedo per channel, in `[0, 1]`.
        reflectance: Vec3,
    },
    /// Perfect specular reflection, scaled by `reflectance`.
    Mirror {
        /// Reflectance per channel, in `[0, 1]`.
        reflectance: Vec3,
    },
    /// A smooth dielectric interface (glass): Fresnel reflection, refraction and total internal
    /// reflection. Non-absorbing.
    Dielectric {
        /// Index of refraction inside relative to outside; `> 0`. `1` is an invisible surface.
        ior: f32,
    },
    /// Extension: a rough conductor, GGX microfacet distribution with `alpha = roughness^2`,
    /// Smith height-correlated shadowing-masking, Schlick Fresnel, sampled by visible normals.
    RoughConductor {
        /// Reflectance at normal incidence (Schlick's `F0`) per channel, in `[0, 1]`.
        reflectance: Vec3,
        /// Perceptual roughness in `[0, 1]`; GGX `alpha = roughness^2`.
        roughness: f32,
    },
}

/// A direction sampled from a BSDF.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    /// The sampled incident direction, local frame, unit.
    pub wi: Vec3,
    /// The BSDF value `f(wo, wi)` (for a delta lobe: its weight divided by `|wi.z|`).
    pub f: Vec3,
    /// The density in solid angle; for a delta lobe, the discrete probability of choosing it.
    pub pdf: f32,
    /// True for a delta lobe (mirror, glass): MIS and light sampling do not apply.
    pub specular: bool,
    /// The relative index of refraction crossed, far side over near side: 1 for reflection.
    /// Radiance is scaled by `1 / eta^2` in `f`; Russian roulette undoes that scale (see
    /// [`crate::PathIntegrator`]).
    pub eta: f32,
}

impl Material {
    /// Checks the parameters: finite, reflectances in `[0, 1]`, `ior > 0`, roughness in `[0, 1]`.
    pub fn validate(&self) -> Result<(), ShadeError> {
        match *self {
            Material::Diffuse { reflectance } | Material::Mirror { reflectance } => {
                check_unit(reflectance, "reflectance")
            }
            Material::Dielectric { ior } => {
                if !ior.is_finite() {
                    return Err(ShadeError::NotFinite { parameter: "ior" });
                }
                if ior <= 0.0 {
                    return Err(ShadeError::OutOfRange {
                        parameter: "ior",
                        expected: "greater than 0",
                    });
                }
                Ok(())
            }
            Material::RoughConductor {
                reflectance,
                roughness,
            } => {
                check_unit(reflectance, "reflectance")?;
                if !roughness.is_finite() {
                    return Err(ShadeError::NotFinite {
                        parameter: "roughness",
                    });
                }
                if !(0.0..=1.0).contains(&roughness) {
                    return Err(ShadeError::OutOfRange {
                        parameter: "roughness",
                        expected: "in [0, 1]",
                    });
                }
                Ok(())
            }
        }
    }

    /// The reflectance shown by the albedo AOV (the dielectric's is 1).
    pub fn albedo(&self) -> Vec3 {
        match *self {
            Material::Diffuse { reflectance }
            | Material::Mirror { reflectance }
            | Material::RoughConductor { reflectance, .. } => reflectance,
            Material::Dielectric { .. } => Vec3::ONE,
        }
    }

    /// True when every lobe is a delta: `eval` and `pdf` are then always zero, and light
    /// sampling is pointless.
    pub fn is_specular(&self) -> bool {
        match *self {
            Material::Diffuse { .. } => false,
            Material::Mirror { .. } | Material::Dielectric { .. } => true,
            Material::RoughConductor { roughness, .. } => roughness * roughness < MIN_ALPHA,
        }
    }

    /// True when [`Material::sample`] reads its `u`, the choice between lobes (reflect or
    /// refract, for glass). For every other material any `u` gives the same sample, and the
    /// path tracer skips drawing it.
    pub fn reads_lobe_choice(&self) -> bool {
        matches!(self, Material::Dielectric { .. })
    }

    /// True when the material tells inside from outside by the side of the normal (the
    /// integrator must then not flip the shading normal towards the viewer).
    pub fn is_oriented(&self) -> bool {
        matches!(self, Material::Dielectric { .. })
    }

    /// `f(wo, wi)` for local unit directions, without the cosine; zero for delta lobes.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match *self {
            Material::Diffuse { reflectance } => {
                if same_side(wo, wi) {
                    reflectance * FRAC_1_PI
                } else {
                    Vec3::ZERO
                }
            }
            Material::Mirror { .. } | Material::Dielectric { .. } => Vec3::ZERO,
            Material::RoughConductor {
                reflectance,
                roughness,
            } => {
                let alpha = roughness * roughness;
                if alpha < MIN_ALPHA || !same_side(wo, wi) {
                    return Vec3::ZERO;
                }
                // Mirror both directions into the upper hemisphere: reflection on both sides.
                let (wo, wi) = upper(wo, wi);
                let h = wo + wi;
                if h.length_squared() < 1e-12 {
                    return Vec3::ZERO;
                }
                let h = h.normalize();
                let d = ggx_d(h, alpha);
                let g = ggx_g(wo, wi, alpha);
                let f = schlick(reflectance, wo.dot(h));
                f * (d * g / (4.0 * wo.z * wi.z))
            }
        }
    }

    /// The density in solid angle with which `sample` returns `wi` given `wo`; zero for delta lobes.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match *self {
            Material::Diffuse { .. } => {
                if same_side(wo, wi) {
                    cosine_hemisphere_pdf(wi.z.abs())
                } else {
                    0.0
                }
            }
            Material::Mirror { .. } | Material::Dielectric { .. } => 0.0,
            Material::RoughConductor { roughness, .. } => {
                let alpha = roughness * roughness;
                if alpha < MIN_ALPHA || !same_side(wo, wi) {
                    return 0.0;
                }
                let (wo, wi) = upper(wo, wi);
                let h = wo + wi;
                if h.length_squared() < 1e-12 {
                    return 0.0;
                }
                let h = h.normalize();
                // Visible-normal density of h, times the Jacobian of reflection 1 / (4 wo.h).
                let wo_h = wo.dot(h);
                if wo_h <= 0.0 || wo.z <= 0.0 {
                    return 0.0;
                }
                let d_visible = ggx_g1(wo, alpha) * wo_h * ggx_d(h, alpha) / wo.z;
                d_visible / (4.0 * wo_h)
            }
        }
    }

    /// Samples `wi` given `wo` from the canonical numbers `u` (lobe choice) and `u2`
    /// (direction). `None` when the sample carries no energy (e.g. grazing `wo`).
    pub fn sample(&self, wo: Vec3, u: f32, u2: Vec2) -> Option<BsdfSample> {
        if !wo.is_finite() || wo.z == 0.0 {
            return None;
        }
        match *self {
            Material::Diffuse { reflectance } => {
                let mut wi = square_to_cosine_hemisphere(u2);
                if wo.z < 0.0 {
                    wi.z = -wi.z;
                }
                let pdf = cosine_hemisphere_pdf(wi.z.abs());
                if pdf <= 0.0 {
                    return None;
                }
                Some(BsdfSample {
                    wi,
                    f: reflectance * FRAC_1_PI,
                    pdf,
                    specular: false,
                    eta: 1.0,
                })
            }
            Material::Mirror { reflectance } => Some(BsdfSample {
                wi: reflect_z(wo),
                f: reflectance / wo.z.abs(),
                pdf: 1.0,
                specular: true,
                eta: 1.0,
            }),
            Material::Dielectric { ior } => sample_dielectric(ior, wo, u),
            Material::RoughConductor {
                reflectance,
                roughness,
            } => {
                let alpha = roughness * roughness;
                if alpha < MIN_ALPHA {
                    return Some(BsdfSample {
                        wi: reflect_z(wo),
                        f: schlick(reflectance, wo.z.abs()) / wo.z.abs(),
                        pdf: 1.0,
                        specular: true,
                        eta: 1.0,
                    });
                }
                let flip = wo.z < 0.0;
                let wo_up = if flip { -wo } else { wo };
                let h = sample_ggx_visible(wo_up, alpha, u2);
                let wi_up = 2.0 * wo_up.dot(h) * h - wo_up;
                if wi_up.z <= 0.0 {
                    return None;
                }
                let wi = if flip { -wi_up } else { wi_up };
                let pdf = self.pdf(wo, wi);
                let f = self.eval(wo, wi);
                if pdf <= 0.0 || !pdf.is_finite() {
                    return None;
                }
                Some(BsdfSample {
                    wi,
                    f,
                    pdf,
                    specular: false,
                    eta: 1.0,
                })
            }
        }
    }
}

/// True when both directions lie strictly on the same side of the surface.
#[inline]
fn same_side(wo: Vec3, wi: Vec3) -> bool {
    wo.z * wi.z > 0.0
}

/// Both directions mirrored through the surface when `wo` is below it.
#[inline]
fn upper(wo: Vec3, wi: Vec3) -> (Vec3, Vec3) {
    if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) }
}

/// Mirror reflection about the local normal.
#[inline]
fn reflect_z(w: Vec3) -> Vec3 {
    Vec3::new(-w.x, -w.y, w.z)
}

/// Schlick's Fresnel approximation for a conductor with normal-incidence reflectance `f0`.
#[inline]
fn schlick(f0: Vec3, cos_theta: f32) -> Vec3 {
    let m = (1.0 - cos_theta.clamp(0.0, 1.0)).powi(5);
    f0 + (Vec3::ONE - f0) * m
}

/// Unpolarised Fresnel reflectance of a smooth dielectric interface for light arriving at
/// cosine `cos_i` (positive: from the outside, where the normal points) with relative index
/// `eta` (inside over outside). Returns 1 under total internal reflection.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let (cos_i, eta) = if cos_i < 0.0 {
        (-cos_i, 1.0 / eta)
    } else {
        (cos_i, eta)
    };
    let cos_i = cos_i.min(1.0);
    // Snell: sin_t = sin_i / eta.
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// Smooth dielectric: reflect with probability F, else refract. Radiance is scaled by
/// `1 / eta^2` on refraction (it is compressed into a smaller solid angle on entering a denser
/// medium and expanded on leaving, so a closed object in a uniform field stays invisible).
fn sample_dielectric(ior: f32, wo: Vec3, u: f32) -> Option<BsdfSample> {
    let fresnel = fresnel_dielectric(wo.z, ior);
    let cos_o = wo.z.abs();
    if u < fresnel {
        return Some(BsdfSample {
            wi: reflect_z(wo),
            f: Vec3::splat(fresnel / cos_o),
            pdf: fresnel,
            specular: true,
            eta: 1.0,
        });
    }
    // Refraction: eta is the ratio of the index on the far side to the near side.
    let eta = if wo.z > 0.0 { ior } else { 1.0 / ior };
    let sin2_t = (1.0 - cos_o * cos_o).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        // Total internal reflection: fresnel was 1, so u < fresnel held; only rounding lands here.
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let wi_xy = -Vec2::new(wo.x, wo.y) / eta;
    let wi = Vec3::new(wi_xy.x, wi_xy.y, -cos_t.copysign(wo.z)).normalize();
    let transmit = 1.0 - fresnel;
    Some(BsdfSample {
        wi,
        f: Vec3::splat(transmit / (eta * eta) / cos_t),
        pdf: transmit,
        specular: true,
        eta,
    })
}

/// GGX (Trowbridge-Reitz) normal distribution for the microfacet normal `h` (upper hemisphere).
fn ggx_d(h: Vec3, alpha: f32) -> f32 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let denom = h.z * h.z * (a2 - 1.0) + 1.0;
    a2 / (PI * denom * denom)
}

/// Smith's Lambda for GGX.
fn ggx_lambda(w: Vec3, alpha: f32) -> f32 {
    let cos2 = w.z * w.z;
    if cos2 <= 0.0 {
        return f32::INFINITY;
    }
    let tan2 = (1.0 - cos2).max(0.0) / cos2;
    0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
}

/// Smith masking of one direction.
fn ggx_g1(w: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(w, alpha))
}

/// Height-correlated Smith shadowing-masking of a pair (symmetric in its arguments).
fn ggx_g(wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha))
}

/// A microfacet normal distributed as the normals visible from `wo` (Heitz 2018,
/// "Sampling the GGX distribution of visible normals"). `wo.z > 0`.
fn sample_ggx_visible(wo: Vec3, alpha: f32, u2: Vec2) -> Vec3 {
    // Stretch the view direction to the hemisphere configuration (alpha = 1).
    let v = Vec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
    // An orthonormal basis around it.
    let len2 = v.x * v.x + v.y * v.y;
    let t1 = if len2 > 0.0 {
        Vec3::new(-v.y, v.x, 0.0) / len2.sqrt()
    } else {
        Vec3::X
    };
    let t2 = v.cross(t1);
    // A uniform point on the disk, warped onto the visible half of the projected hemisphere.
    let r = u2.x.sqrt();
    let phi = TAU * u2.y;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + v.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
    // Lift it onto the hemisphere and unstretch.
    let n_h = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * v;
    Vec3::new(alpha * n_h.x, alpha * n_h.y, n_h.z.max(1e-6)).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_hand_values() {
        // Normal incidence: ((n - 1) / (n + 1))^2 = (0.5 / 2.5)^2 = 0.04 for n = 1.5.
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        // The same from inside (cos < 0): the interface is symmetric at normal incidence.
        assert!((fresnel_dielectric(-1.0, 1.5) - 0.04).abs() < 1e-6);
        // Inside glass at 60 degrees from the normal: sin = 0.866 > 1 / 1.5, so TIR.
        assert_eq!(fresnel_dielectric(-0.5, 1.5), 1.0);
        // eta = 1: no interface.
        assert!(fresnel_dielectric(0.3, 1.0).abs() < 1e-6);
    }

    #[test]
    fn ggx_d_hand_value() {
        // At h = +z: D = a^2 / (pi (a^2 - 1 + 1)^2) = 1 / (pi a^2); a = 0.5 gives 4 / pi.
        assert!((ggx_d(Vec3::Z, 0.5) - 4.0 / PI).abs() < 1e-5);
    }

    #[test]
    fn validate_rejects_bad_parameters() {
        let bad = [
            Material::Diffuse {
                reflectance: Vec3::new(1.1, 0.0, 0.0),
            },
            Material::Mirror {
                reflectance: Vec3::new(f32::NAN, 0.0, 0.0),
            },
            Material::Dielectric { ior: 0.0 },
            Material::Dielectric { ior: f32::INFINITY },
            Material::RoughConductor {
                reflectance: Vec3::ONE,
                roughness: 1.5,
            },
        ];
        for m in bad {
            assert!(m.validate().is_err(), "{m:?}");
        }
        assert_eq!(
            Material::Dielectric { ior: -1.0 }
                .validate()
                .unwrap_err()
                .to_string(),
            "ior must be greater than 0"
        );
        assert!(Material::Dielectric { ior: 1.5 }.validate().is_ok());
    }
}
