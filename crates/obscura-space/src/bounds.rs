//! Axis-aligned bounding boxes.

use crate::geometry::{Point3, Vector3};
use crate::spaces::Space;
use core::fmt;

/// An axis-aligned box `[min, max]` in space `S`. The empty box has `min = +inf`,
/// `max = -inf`, so that it is the identity of [`Bounds3::union`].
pub struct Bounds3<S: Space> {
    /// The corner with the smallest coordinates.
    pub min: Point3<S>,
    /// The corner with the largest coordinates.
    pub max: Point3<S>,
}

impl<S: Space> Bounds3<S> {
    /// The empty box.
    pub const EMPTY: Self = Self {
        min: Point3::new(f32::INFINITY, f32::INFINITY, f32::INFINITY),
        max: Point3::new(f32::NEG_INFINITY, f32::NEG_INFINITY, f32::NEG_INFINITY),
    };

    /// The smallest box holding both points (in any order).
    #[inline]
    pub fn new(a: Point3<S>, b: Point3<S>) -> Self {
        Self {
            min: a.min(b),
            max: a.max(b),
        }
    }
    /// The box of a single point.
    #[inline]
    pub fn from_point(p: Point3<S>) -> Self {
        Self { min: p, max: p }
    }
    /// The smallest box holding every point of the iterator (empty for none).
    pub fn from_points(points: impl IntoIterator<Item = Point3<S>>) -> Self {
        points
            .into_iter()
            .fold(Self::EMPTY, |b, p| b.union_point(p))
    }
    /// True when the box holds no point.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }
    /// The smallest box holding this box and `p`.
    #[inline]
    pub fn union_point(self, p: Point3<S>) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }
    /// The smallest box holding both boxes.
    #[inline]
    pub fn union(self, b: Self) -> Self {
        Self {
            min: self.min.min(b.min),
            max: self.max.max(b.max),
        }
    }
    /// True when `p` lies inside or on the boundary.
    #[inline]
    pub fn contains(&self, p: Point3<S>) -> bool {
        p.x >= self.min.x
            && p.x <= self.max.x
            && p.y >= self.min.y
            && p.y <= self.max.y
            && p.z >= self.min.z
            && p.z <= self.max.z
    }
    /// True when `b` lies wholly inside this box (an empty `b` always does).
    #[inline]
    pub fn contains_bounds(&self, b: &Self) -> bool {
        b.is_empty() || (self.contains(b.min) && self.contains(b.max))
    }
    /// `max - min`.
    #[inline]
    pub fn diagonal(&self) -> Vector3<S> {
        self.max - self.min
    }
    /// The centre of the box.
    #[inline]
    pub fn centroid(&self) -> Point3<S> {
        self.min.lerp(self.max, 0.5)
    }
    /// The box grown by `delta` on every side.
    #[inline]
    pub fn expand(self, delta: f32) -> Self {
        let d = Vector3::new(delta, delta, delta);
        Self {
            min: self.min - d,
            max: self.max + d,
        }
    }
    /// Volume; zero for an empty or flat box.
    #[inline]
    pub fn volume(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.diagonal();
        d.x * d.y * d.z
    }
    /// Surface area; zero for an empty box.
    #[inline]
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.diagonal();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }
    /// Corner `i` in 0..8: bit 0 picks max x, bit 1 max y, bit 2 max z.
    #[inline]
    pub fn corner(&self, i: usize) -> Point3<S> {
        Point3::new(
            if i & 1 == 0 { self.min.x } else { self.max.x },
            if i & 2 == 0 { self.min.y } else { self.max.y },
            if i & 4 == 0 { self.min.z } else { self.max.z },
        )
    }
    /// The eight corners.
    #[inline]
    pub fn corners(&self) -> [Point3<S>; 8] {
        core::array::from_fn(|i| self.corner(i))
    }
}

impl<S: Space> Clone for Bounds3<S> {
    #[inline]
    fn clone(&self) -> Self {
        *self
    }
}
impl<S: Space> Copy for Bounds3<S> {}
impl<S: Space> PartialEq for Bounds3<S> {
    fn eq(&self, o: &Self) -> bool {
        self.min == o.min && self.max == o.max
    }
}
impl<S: Space> fmt::Debug for Bounds3<S> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "Bounds3<{}>[{:?} .. {:?}]",
            S::NAME,
            self.min.to_array(),
            self.max.to_array()
        )
    }
}
