//! `AnimatedTransform<To, From>`: a transform that moves over the shutter interval.

use crate::bounds::Bounds3;
use crate::error::SpaceError;
use crate::geometry::Point3;
use crate::ray::Ray;
use crate::spaces::Space;
use crate::transform::Transform;
use core::fmt;
use glam::{DMat3, DMat4, DQuat, DVec3, Mat4};

/// One keyframe, decomposed as `M = T * R * S`: translation, rotation and a symmetric
/// stretch (scale, with shear only if the keyframe itself had it).
#[derive(Clone, Copy, Debug)]
struct Decomposed {
    translation: DVec3,
    rotation: DQuat,
    stretch: DMat3,
}

/// A transform given at keyframe times and interpolated between them.
///
/// Each keyframe is decomposed into translation, rotation (a quaternion) and stretch (scale)
/// by a polar decomposition; between keyframes translation and stretch are interpolated
/// linearly and rotation by slerp, so rigid keyframes give rigid motion (no shear) all the way.
/// At a keyframe's own time, and before the first or after the last, the keyframe's transform
/// is returned exactly.
///
/// Keyframes that reverse orientation (a look-at camera frame does) are handled by moving the
/// reflection into the stretch; all keyframes must then agree on orientation.
pub struct AnimatedTransform<To: Space, From: Space> {
    times: Vec<f32>,
    keys: Vec<Transform<To, From>>,
    parts: Vec<Decomposed>,
    /// Per segment between neighbouring keyframes: the constants `at` would otherwise
    /// recompute for every call.
    segments: Vec<Segment>,
    animated: bool,
}

/// Constants of the segment between two decomposed keyframes `a` and `z`, computed once.
#[derive(Clone, Copy, Debug)]
struct Segment {
    /// The angle `theta` between the two rotation quaternions (half the rotation angle);
    /// `1 / sin(theta)`, or 0 when the rotations coincide (sin(theta) < 1e-12) and the
    /// quaternions are interpolated linearly instead.
    theta: f64,
    inv_sin_theta: f64,
    /// The stretch and its inverse when both keyframes have the same stretch up to the f32
    /// rounding of their matrices (a rigid motion: every look-at): their mean, so `at` needs
    /// neither the blend nor a 3x3 inverse per call.
    constant_stretch: Option<(DMat3, DMat3)>,
}

/// The mean of two stretches that agree to within f32 rounding (relative 2^-24 of the largest
/// entry), with its inverse; None otherwise. Replacing the linear blend by the mean moves the
/// interpolated matrix by at most that difference, below the rounding of the f32 result; at
/// the keyframes' own times `at` returns the keyframes as given anyway.
fn constant_stretch(a: &DMat3, z: &DMat3) -> Option<(DMat3, DMat3)> {
    let size = a.abs().to_cols_array().into_iter().fold(0.0, f64::max);
    let gap = (*z - *a)
        .abs()
        .to_cols_array()
        .into_iter()
        .fold(0.0, f64::max);
    if gap > size * f64::from(f32::EPSILON) * 0.5 {
        return None;
    }
    let mean = (*a + *z) * 0.5;
    Some((mean, mean.inverse()))
}

impl Segment {
    fn new(a: &Decomposed, z: &Decomposed) -> Segment {
        let theta = a.rotation.dot(z.rotation).clamp(-1.0, 1.0).acos();
        let sin_theta = theta.sin();
        Segment {
            theta,
            inv_sin_theta: if sin_theta < 1e-12 {
                0.0
            } else {
                1.0 / sin_theta
            },
            constant_stretch: constant_stretch(&a.stretch, &z.stretch),
        }
    }
}

impl<To: Space, From: Space> AnimatedTransform<To, From> {
    /// A transform that does not move.
    pub fn fixed(t: Transform<To, From>) -> Self {
        Self {
            times: vec![0.0],
            keys: vec![t],
            parts: Vec::new(),
            segments: Vec::new(),
            animated: false,
        }
    }

    /// Two keyframes: `start` at `start_time`, `end` at `end_time`.
    pub fn new(
        start: Transform<To, From>,
        start_time: f32,
        end: Transform<To, From>,
        end_time: f32,
    ) -> Result<Self, SpaceError> {
        Self::from_keyframes(vec![(start_time, start), (end_time, end)])
    }

    /// Any number of keyframes (at least one), with strictly increasing finite times.
    pub fn from_keyframes(keyframes: Vec<(f32, Transform<To, From>)>) -> Result<Self, SpaceError> {
        if keyframes.is_empty() {
            return Err(SpaceError::BadKeyframes("no keyframes"));
        }
        if keyframes.iter().any(|(t, _)| !t.is_finite()) {
            return Err(SpaceError::BadKeyframes(
                "a keyframe time is NaN or infinite",
            ));
        }
        if keyframes.windows(2).any(|w| w[0].0 >= w[1].0) {
            // Equal times with equal transforms are harmless: a fixed transform.
            let all_same = keyframes.iter().all(|(_, k)| *k == keyframes[0].1);
            if all_same {
                return Ok(Self::fixed(keyframes[0].1));
            }
            return Err(SpaceError::BadKeyframes(
                "keyframe times must increase strictly",
            ));
        }
        let (times, keys): (Vec<f32>, Vec<Transform<To, From>>) = keyframes.into_iter().unzip();
        let animated = keys.iter().any(|k| *k != keys[0]);
        if !animated {
            return Ok(Self {
                times: vec![times[0]],
                keys: vec![keys[0]],
                parts: Vec::new(),
                segments: Vec::new(),
                animated,
            });
        }
        let mut parts = keys
            .iter()
            .map(|k| decompose(k.matrix()))
            .collect::<Result<Vec<_>, _>>()?;
        if parts
            .windows(2)
            .any(|w| (w[0].stretch.determinant() > 0.0) != (w[1].stretch.determinant() > 0.0))
        {
            return Err(SpaceError::BadKeyframes(
                "keyframes differ in orientation (one is mirrored): they cannot be interpolated",
            ));
        }
        // Slerp the short way round: neighbouring quaternions in the same hemisphere.
        for i in 1..parts.len() {
            if parts[i - 1].rotation.dot(parts[i].rotation) < 0.0 {
                parts[i].rotation = -parts[i].rotation;
            }
        }
        let segments = parts
            .windows(2)
            .map(|w| Segment::new(&w[0], &w[1]))
            .collect();
        Ok(Self {
            times,
            keys,
            parts,
            segments,
            animated,
        })
    }

    /// True when the transform changes over time.
    #[inline]
    pub fn is_animated(&self) -> bool {
        self.animated
    }

    /// The first keyframe's time.
    #[inline]
    pub fn start_time(&self) -> f32 {
        self.times[0]
    }

    /// The last keyframe's time.
    #[inline]
    pub fn end_time(&self) -> f32 {
        self.times[self.times.len() - 1]
    }

    /// The keyframes as given: `(time, transform)`.
    pub fn keyframes(&self) -> impl Iterator<Item = (f32, Transform<To, From>)> + '_ {
        self.times.iter().copied().zip(self.keys.iter().copied())
    }

    /// The transform at `time`: a keyframe exactly at its own time, before the first and after
    /// the last; interpolated in between.
    pub fn at(&self, time: f32) -> Transform<To, From> {
        match self.locate(time) {
            Ok(k) => self.keys[k],
            Err((k, u)) => {
                let (linear, translation, stretch_inverse, rot) =
                    interpolate_parts(&self.parts[k], &self.parts[k + 1], &self.segments[k], u);
                let (m, m_inv) = matrices(linear, translation, stretch_inverse, rot);
                Transform::from_matrix_and_inverse(m.as_mat4(), m_inv.as_mat4())
            }
        }
    }

    /// The matrix of [`AnimatedTransform::at`] alone, bit for bit `at(time).matrix()`, without
    /// the work of the inverse: for per-sample callers that only map forwards (camera rays).
    pub fn matrix_at(&self, time: f32) -> Mat4 {
        match self.locate(time) {
            Ok(k) => self.keys[k].matrix(),
            Err((k, u)) => {
                let (linear, translation, _, _) =
                    interpolate_parts(&self.parts[k], &self.parts[k + 1], &self.segments[k], u);
                DMat4::from_mat3_translation(linear, translation).as_mat4()
            }
        }
    }

    /// Where `time` falls: `Ok(k)` for keyframe `k` as given (at its own time, before the first,
    /// after the last, or a fixed transform), `Err((k, u))` for fraction `u` into segment `k`.
    #[inline]
    fn locate(&self, time: f32) -> Result<usize, (usize, f64)> {
        if !self.animated || time.is_nan() || time <= self.times[0] {
            return Ok(0);
        }
        let last = self.times.len() - 1;
        if time >= self.times[last] {
            return Ok(last);
        }
        // The segment [times[k], times[k + 1]) holding `time`.
        let k = self.times.partition_point(|&t| t <= time) - 1;
        if time == self.times[k] {
            return Ok(k);
        }
        let u = f64::from(time - self.times[k]) / f64::from(self.times[k + 1] - self.times[k]);
        Err((k, u))
    }

    /// Maps a point as it is at `time`.
    #[inline]
    pub fn point(&self, p: Point3<From>, time: f32) -> Point3<To> {
        self.at(time).point(p)
    }

    /// Maps a ray with the transform at the ray's own time.
    #[inline]
    pub fn ray(&self, r: Ray<From>) -> Ray<To> {
        self.at(r.time).ray(r)
    }

    /// A box holding `b` as mapped at every time of the keyframes' interval, rotations included.
    ///
    /// Between keyframes without rotation every corner moves on a straight line, so the
    /// keyframes' boxes bound it exactly. With rotation, each segment is sampled at `n` evenly
    /// spaced times and the box is grown by the largest distance a corner can stray from the
    /// chord between two samples: `h^2 / 8 * max |x''|`, with `h = 1 / n` and, for angular
    /// speed `theta` (the segment's rotation angle), `|x''| <= theta^2 |S p| + 2 theta |dS p|`.
    /// The result is conservative and, for half a turn, within about 0.05% of the true extent.
    pub fn motion_bounds(&self, b: Bounds3<From>) -> Bounds3<To> {
        if b.is_empty() {
            return Bounds3::EMPTY;
        }
        if !self.animated {
            return self.keys[0].bounds(b);
        }
        let corners = b.corners().map(|c| c.to_glam().as_dvec3());
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        let mut grow = 0.0f64;
        for ((a, z), segment) in self.parts.iter().zip(&self.parts[1..]).zip(&self.segments) {
            let theta = 2.0 * segment.theta;
            let steps = if theta < 1e-9 {
                1
            } else {
                (theta * 20.0).ceil().max(2.0) as usize
            };
            for i in 0..=steps {
                let (linear, translation, _, _) =
                    interpolate_parts(a, z, segment, i as f64 / steps as f64);
                let m = DMat4::from_mat3_translation(linear, translation);
                for c in &corners {
                    let p = m.transform_point3(*c);
                    lo = lo.min(p);
                    hi = hi.max(p);
                }
            }
            if steps > 1 {
                let h = 1.0 / steps as f64;
                for c in &corners {
                    let stretched = (a.stretch * *c).length().max((z.stretch * *c).length());
                    let d_stretch = ((z.stretch - a.stretch) * *c).length();
                    let accel = theta * theta * stretched + 2.0 * theta * d_stretch;
                    grow = grow.max(h * h / 8.0 * accel);
                }
            }
        }
        // Round outwards: the f32 transforms of `at` may differ from these f64 ones by a few ulps.
        let scale = lo.abs().max(hi.abs()).max_element().max(1.0);
        let pad = grow + 4.0 * f64::from(f32::EPSILON) * scale;
        Bounds3::new(
            Point3::from_glam((lo - pad).as_vec3()),
            Point3::from_glam((hi + pad).as_vec3()),
        )
    }
}

/// Polar decomposition `M3 = R S` of the linear part (R a rotation, S symmetric), by Newton's
/// iteration `Q <- (Q + Q^-T) / 2`, in f64. A mirrored keyframe keeps a rotation and a negative
/// stretch.
fn decompose(m: Mat4) -> Result<Decomposed, SpaceError> {
    let m = m.as_dmat4();
    if m.row(3) != glam::DVec4::new(0.0, 0.0, 0.0, 1.0) {
        return Err(SpaceError::BadKeyframes(
            "a keyframe is a projective transform",
        ));
    }
    let linear = DMat3::from_mat4(m);
    let det = linear.determinant();
    if det == 0.0 || !det.is_finite() {
        return Err(SpaceError::Singular {
            what: "animated transform keyframe",
        });
    }
    let mut q = linear;
    for _ in 0..100 {
        let next = (q + q.inverse().transpose()) * 0.5;
        let change = (next - q)
            .to_cols_array()
            .iter()
            .map(|d| d.abs())
            .fold(0.0, f64::max);
        q = next;
        if change < 1e-14 {
            break;
        }
    }
    let mut stretch = q.transpose() * linear;
    if det < 0.0 {
        // Q is a rotation times a reflection; -Q is a proper rotation and -S takes the sign.
        q = -q;
        stretch = -stretch;
    }
    Ok(Decomposed {
        translation: m.w_axis.truncate(),
        rotation: DQuat::from_mat3(&q).normalize(),
        stretch,
    })
}

/// The parts of the transform at fraction `u` between two decomposed keyframes, with the
/// segment's constants: the linear part `R S`, the translation, `S^-1` and `R`.
#[inline]
fn interpolate_parts(
    a: &Decomposed,
    z: &Decomposed,
    segment: &Segment,
    u: f64,
) -> (DMat3, DVec3, DMat3, DMat3) {
    let translation = a.translation.lerp(z.translation, u);
    // Slerp with the angle and 1 / sin(theta) of the segment (the quaternions are in the same
    // hemisphere): (sin((1 - u) theta) a + sin(u theta) z) / sin(theta); coinciding rotations
    // interpolate linearly.
    let rotation = if segment.inv_sin_theta == 0.0 {
        a.rotation.lerp(z.rotation, u).normalize()
    } else {
        let wa = ((1.0 - u) * segment.theta).sin() * segment.inv_sin_theta;
        let wz = (u * segment.theta).sin() * segment.inv_sin_theta;
        a.rotation * wa + z.rotation * wz
    };
    let rot = DMat3::from_quat(rotation);
    let (stretch, stretch_inverse) = match segment.constant_stretch {
        Some(pair) => pair,
        None => {
            let stretch = a.stretch * (1.0 - u) + z.stretch * u;
            (stretch, stretch.inverse())
        }
    };
    (rot * stretch, translation, stretch_inverse, rot)
}

/// The matrix `T R S` and its inverse from the parts of [`interpolate_parts`].
fn matrices(
    linear: DMat3,
    translation: DVec3,
    stretch_inverse: DMat3,
    rot: DMat3,
) -> (DMat4, DMat4) {
    let m = DMat4::from_mat3_translation(linear, translation);
    // (T R S)^-1 = S^-1 R^T T^-1.
    let linear_inv = stretch_inverse * rot.transpose();
    let m_inv = DMat4::from_mat3_translation(linear_inv, -(linear_inv * translation));
    (m, m_inv)
}

impl<To: Space, From: Space> Clone for AnimatedTransform<To, From> {
    fn clone(&self) -> Self {
        Self {
            times: self.times.clone(),
            keys: self.keys.clone(),
            parts: self.parts.clone(),
            segments: self.segments.clone(),
            animated: self.animated,
        }
    }
}
impl<To: Space, From: Space> fmt::Debug for AnimatedTransform<To, From> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("AnimatedTransform")
            .field("times", &self.times)
            .field("keys", &self.keys)
            .finish()
    }
}
impl<To: Space, Fr: Space> core::convert::From<Transform<To, Fr>> for AnimatedTransform<To, Fr> {
    fn from(t: Transform<To, Fr>) -> Self {
        Self::fixed(t)
    }
}
