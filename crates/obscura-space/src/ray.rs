//! Rays with a time and a parametric range.

use crate::geometry::{Point3, Vector3};
use crate::spaces::Space;
use core::fmt;

/// A ray `origin + t * direction` for `t` in `[t_min, t_max]`, at instant `time`.
///
/// The direction need not be unit length; `t` is measured in multiples of it. Transforms keep
/// `t` meaningful: a hit at `t` in one space is the same point at the same `t` in another.
pub struct Ray<S: Space> {
    /// Where the ray starts (at `t = 0`).
    pub origin: Point3<S>,
    /// The direction; `t` counts multiples of it.
    pub direction: Vector3<S>,
    /// The instant the ray samples, in the shutter's time unit.
    pub time: f32,
    /// The smallest `t` that counts as a hit.
    pub t_min: f32,
    /// The largest `t` that counts as a hit.
    pub t_max: f32,
}

impl<S: Space> Ray<S> {
    /// A ray over `t` in `[0, inf)` at the given time.
    #[inline]
    pub fn new(origin: Point3<S>, direction: Vector3<S>, time: f32) -> Self {
        Self {
            origin,
            direction,
            time,
            t_min: 0.0,
            t_max: f32::INFINITY,
        }
    }
    /// The same ray restricted to `t` in `[t_min, t_max]`.
    #[inline]
    pub fn with_range(self, t_min: f32, t_max: f32) -> Self {
        Self {
            t_min,
            t_max,
            ..self
        }
    }
    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Point3<S> {
        self.origin + self.direction * t
    }
}

impl<S: Space> Clone for Ray<S> {
    #[inline]
    fn clone(&self) -> Self {
        *self
    }
}
impl<S: Space> Copy for Ray<S> {}
impl<S: Space> PartialEq for Ray<S> {
    fn eq(&self, o: &Self) -> bool {
        self.origin == o.origin
            && self.direction == o.direction
            && self.time == o.time
            && self.t_min == o.t_min
            && self.t_max == o.t_max
    }
}
impl<S: Space> fmt::Debug for Ray<S> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Ray")
            .field("origin", &self.origin)
            .field("direction", &self.direction)
            .field("time", &self.time)
            .field("t_min", &self.t_min)
            .field("t_max", &self.t_max)
            .finish()
    }
}
