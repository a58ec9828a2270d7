//! Points, vectors and normals tagged with their space.

use crate::spaces::Space;
use core::fmt;
use core::marker::PhantomData;
use core::ops::{Add, AddAssign, Div, Index, Mul, Neg, Sub, SubAssign};
use glam::{Vec2, Vec3};

/// The zero-sized tag field every typed value carries. `fn() -> S` keeps the wrapper `Send`,
/// `Sync` and variance-neutral whatever the marker type is.
type Tag<S> = PhantomData<fn() -> S>;

/// Implements Copy, Clone, PartialEq, Debug and Default by hand (so `S` needs no bounds), the
/// glam escape hatches and the component access shared by every three-component type.
macro_rules! common3 {
    ($ty:ident, $what:literal) => {
        impl<S: Space> $ty<S> {
            #[doc = concat!("A ", $what, " from its components.")]
            #[inline]
            pub const fn new(x: f32, y: f32, z: f32) -> Self {
                Self {
                    x,
                    y,
                    z,
                    space: PhantomData,
                }
            }
            #[doc = concat!("Tags a plain glam vector as a ", $what, " of this space.")]
            #[inline]
            pub const fn from_glam(v: Vec3) -> Self {
                Self::new(v.x, v.y, v.z)
            }
            /// The plain glam value, for boundaries where the space is tracked by hand.
            #[inline]
            pub const fn to_glam(self) -> Vec3 {
                Vec3::new(self.x, self.y, self.z)
            }
            /// The same components, re-tagged as another space. Use only where the two spaces
            /// coincide by construction; say why at the call site.
            #[inline]
            pub const fn cast_space<T: Space>(self) -> $ty<T> {
                $ty::new(self.x, self.y, self.z)
            }
            /// True when every component is finite.
            #[inline]
            pub fn is_finite(self) -> bool {
                self.to_glam().is_finite()
            }
            /// The components as an array.
            #[inline]
            pub const fn to_array(self) -> [f32; 3] {
                [self.x, self.y, self.z]
            }
        }
        impl<S: Space> Clone for $ty<S> {
            #[inline]
            fn clone(&self) -> Self {
                *self
            }
        }
        impl<S: Space> Copy for $ty<S> {}
        impl<S: Space> PartialEq for $ty<S> {
            #[inline]
            fn eq(&self, other: &Self) -> bool {
                self.x == other.x && self.y == other.y && self.z == other.z
            }
        }
        impl<S: Space> Default for $ty<S> {
            #[inline]
            fn default() -> Self {
                Self::new(0.0, 0.0, 0.0)
            }
        }
        impl<S: Space> fmt::Debug for $ty<S> {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(
                    f,
                    "{}<{}>({:?}, {:?}, {:?})",
                    stringify!($ty),
                    S::NAME,
                    self.x,
                    self.y,
                    self.z
                )
            }
        }
        impl<S: Space> Index<usize> for $ty<S> {
            type Output = f32;
            #[inline]
            fn index(&self, i: usize) -> &f32 {
                match i {
                    0 => &self.x,
                    1 => &self.y,
                    2 => &self.z,
                    _ => panic!("component index {i} out of range 0..3"),
                }
            }
        }
    };
}

/// Operations that vectors and normals share: scaling, negation, length and dot products.
macro_rules! linear3 {
    ($ty:ident) => {
        impl<S: Space> $ty<S> {
            /// Euclidean length.
            #[inline]
            pub fn length(self) -> f32 {
                self.to_glam().length()
            }
            /// Squared length.
            #[inline]
            pub fn length_squared(self) -> f32 {
                self.to_glam().length_squared()
            }
            /// Unit length in the same direction. Zero or non-finite input gives non-finite
            /// output; use [`Self::try_normalize`] where the input may be degenerate.
            #[inline]
            pub fn normalize(self) -> Self {
                Self::from_glam(self.to_glam().normalize())
            }
            /// Unit length in the same direction, or `None` for a zero or non-finite value.
            #[inline]
            pub fn try_normalize(self) -> Option<Self> {
                self.to_glam().try_normalize().map(Self::from_glam)
            }
            /// Dot product with a vector of the same space.
            #[inline]
            pub fn dot(self, v: Vector3<S>) -> f32 {
                self.to_glam().dot(v.to_glam())
            }
        }
        impl<S: Space> Neg for $ty<S> {
            type Output = Self;
            #[inline]
            fn neg(self) -> Self {
                Self::from_glam(-self.to_glam())
            }
        }
        impl<S: Space> Mul<f32> for $ty<S> {
            type Output = Self;
            #[inline]
            fn mul(self, s: f32) -> Self {
                Self::from_glam(self.to_glam() * s)
            }
        }
        impl<S: Space> Mul<$ty<S>> for f32 {
            type Output = $ty<S>;
            #[inline]
            fn mul(self, v: $ty<S>) -> $ty<S> {
                v * self
            }
        }
        impl<S: Space> Div<f32> for $ty<S> {
            type Output = Self;
            #[inline]
            fn div(self, s: f32) -> Self {
                Self::from_glam(self.to_glam() / s)
            }
        }
        impl<S: Space> Add for $ty<S> {
            type Output = Self;
            #[inline]
            fn add(self, o: Self) -> Self {
                Self::from_glam(self.to_glam() + o.to_glam())
            }
        }
        impl<S: Space> Sub for $ty<S> {
            type Output = Self;
            #[inline]
            fn sub(self, o: Self) -> Self {
                Self::from_glam(self.to_glam() - o.to_glam())
            }
        }
    };
}

/// A position in space `S`. Transforms apply translation and the homogeneous divide to it.
pub struct Point3<S: Space> {
    /// x component.
    pub x: f32,
    /// y component.
    pub y: f32,
    /// z component.
    pub z: f32,
    space: Tag<S>,
}
common3!(Point3, "point");

/// A displacement in space `S`. Transforms ignore translation for it.
pub struct Vector3<S: Space> {
    /// x component.
    pub x: f32,
    /// y component.
    pub y: f32,
    /// z component.
    pub z: f32,
    space: Tag<S>,
}
common3!(Vector3, "vector");
linear3!(Vector3);

/// A surface normal in space `S`. Transforms apply the inverse transpose to it, so it stays
/// perpendicular to the surface's tangents.
pub struct Normal3<S: Space> {
    /// x component.
    pub x: f32,
    /// y component.
    pub y: f32,
    /// z component.
    pub z: f32,
    space: Tag<S>,
}
common3!(Normal3, "normal");
linear3!(Normal3);

impl<S: Space> Point3<S> {
    /// The origin of the space.
    pub const ORIGIN: Self = Self::new(0.0, 0.0, 0.0);

    /// Distance to another point.
    #[inline]
    pub fn distance(self, p: Self) -> f32 {
        (self - p).length()
    }
    /// Linear interpolation: `self` at `t = 0`, `p` at `t = 1`.
    #[inline]
    pub fn lerp(self, p: Self, t: f32) -> Self {
        Self::from_glam(self.to_glam().lerp(p.to_glam(), t))
    }
    /// Componentwise minimum.
    #[inline]
    pub fn min(self, p: Self) -> Self {
        Self::from_glam(self.to_glam().min(p.to_glam()))
    }
    /// Componentwise maximum.
    #[inline]
    pub fn max(self, p: Self) -> Self {
        Self::from_glam(self.to_glam().max(p.to_glam()))
    }
    /// The vector from the origin to this point.
    #[inline]
    pub fn to_vector(self) -> Vector3<S> {
        Vector3::from_glam(self.to_glam())
    }
}

impl<S: Space> Vector3<S> {
    /// Cross product. Note that the handedness of the result follows the handedness of the
    /// space: in camera space (a left-handed frame when the world is right-handed) `x.cross(y)`
    /// is still `+z` numerically, which is `-view` in world terms after a reflection.
    #[inline]
    pub fn cross(self, v: Self) -> Self {
        Self::from_glam(self.to_glam().cross(v.to_glam()))
    }
    /// Reinterprets this vector as a normal (e.g. a cross product of tangents).
    #[inline]
    pub fn to_normal(self) -> Normal3<S> {
        Normal3::from_glam(self.to_glam())
    }
}

impl<S: Space> Normal3<S> {
    /// Reinterprets this normal as a vector.
    #[inline]
    pub fn to_vector(self) -> Vector3<S> {
        Vector3::from_glam(self.to_glam())
    }
    /// This normal flipped, if needed, to lie in the same hemisphere as `v`.
    #[inline]
    pub fn face_forward(self, v: Vector3<S>) -> Self {
        if self.dot(v) < 0.0 { -self } else { self }
    }
}

impl<S: Space> Sub for Point3<S> {
    type Output = Vector3<S>;
    #[inline]
    fn sub(self, p: Self) -> Vector3<S> {
        Vector3::from_glam(self.to_glam() - p.to_glam())
    }
}
impl<S: Space> Add<Vector3<S>> for Point3<S> {
    type Output = Self;
    #[inline]
    fn add(self, v: Vector3<S>) -> Self {
        Self::from_glam(self.to_glam() + v.to_glam())
    }
}
impl<S: Space> Sub<Vector3<S>> for Point3<S> {
    type Output = Self;
    #[inline]
    fn sub(self, v: Vector3<S>) -> Self {
        Self::from_glam(self.to_glam() - v.to_glam())
    }
}
impl<S: Space> AddAssign<Vector3<S>> for Point3<S> {
    #[inline]
    fn add_assign(&mut self, v: Vector3<S>) {
        *self = *self + v;
    }
}
impl<S: Space> SubAssign<Vector3<S>> for Point3<S> {
    #[inline]
    fn sub_assign(&mut self, v: Vector3<S>) {
        *self = *self - v;
    }
}

/// Two-component types: film and raster positions and their offsets.
macro_rules! common2 {
    ($ty:ident, $what:literal) => {
        impl<S: Space> $ty<S> {
            #[doc = concat!("A ", $what, " from its components.")]
            #[inline]
            pub const fn new(x: f32, y: f32) -> Self {
                Self {
                    x,
                    y,
                    space: PhantomData,
                }
            }
            #[doc = concat!("Tags a plain glam vector as a ", $what, " of this space.")]
            #[inline]
            pub const fn from_glam(v: Vec2) -> Self {
                Self::new(v.x, v.y)
            }
            /// The plain glam value.
            #[inline]
            pub const fn to_glam(self) -> Vec2 {
                Vec2::new(self.x, self.y)
            }
            /// True when both components are finite.
            #[inline]
            pub fn is_finite(self) -> bool {
                self.x.is_finite() && self.y.is_finite()
            }
        }
        impl<S: Space> Clone for $ty<S> {
            #[inline]
            fn clone(&self) -> Self {
                *self
            }
        }
        impl<S: Space> Copy for $ty<S> {}
        impl<S: Space> PartialEq for $ty<S> {
            #[inline]
            fn eq(&self, other: &Self) -> bool {
                self.x == other.x && self.y == other.y
            }
        }
        impl<S: Space> Default for $ty<S> {
            #[inline]
            fn default() -> Self {
                Self::new(0.0, 0.0)
            }
        }
        impl<S: Space> fmt::Debug for $ty<S> {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(
                    f,
                    "{}<{}>({:?}, {:?})",
                    stringify!($ty),
                    S::NAME,
                    self.x,
                    self.y
                )
            }
        }
    };
}

/// A position in a two-dimensional space such as [`Raster`](crate::Raster).
pub struct Point2<S: Space> {
    /// x component.
    pub x: f32,
    /// y component.
    pub y: f32,
    space: Tag<S>,
}
common2!(Point2, "2D point");

/// A displacement in a two-dimensional space.
pub struct Vector2<S: Space> {
    /// x component.
    pub x: f32,
    /// y component.
    pub y: f32,
    space: Tag<S>,
}
common2!(Vector2, "2D vector");

impl<S: Space> Vector2<S> {
    /// Euclidean length.
    #[inline]
    pub fn length(self) -> f32 {
        self.to_glam().length()
    }
}
impl<S: Space> Sub for Point2<S> {
    type Output = Vector2<S>;
    #[inline]
    fn sub(self, p: Self) -> Vector2<S> {
        Vector2::from_glam(self.to_glam() - p.to_glam())
    }
}
impl<S: Space> Add<Vector2<S>> for Point2<S> {
    type Output = Self;
    #[inline]
    fn add(self, v: Vector2<S>) -> Self {
        Self::from_glam(self.to_glam() + v.to_glam())
    }
}
impl<S: Space> Mul<f32> for Vector2<S> {
    type Output = Self;
    #[inline]
    fn mul(self, s: f32) -> Self {
        Self::from_glam(self.to_glam() * s)
    }
}
