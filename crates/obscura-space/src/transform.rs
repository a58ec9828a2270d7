//! `Transform<To, From>`: a matrix and its inverse, typed by the spaces it maps between.

use crate::bounds::Bounds3;
use crate::error::SpaceError;
use crate::geometry::{Normal3, Point3, Vector3};
use crate::ray::Ray;
use crate::spaces::Space;
use core::fmt;
use core::marker::PhantomData;
use core::ops::Mul;
use glam::{Mat3, Mat4, Vec3, Vec4};

/// A map from space `From` to space `To`, holding the matrix and its inverse.
///
/// The destination comes first, like the matrix it holds: `Transform<World, Camera>` maps
/// camera-space values to world space and is named `world_from_camera`. Composition cancels the
/// inner names: `Transform<A, B> * Transform<B, C>` is a `Transform<A, C>`, and nothing else
/// type-checks.
///
/// Application: points get the full matrix and the homogeneous divide, vectors only the linear
/// part, normals the inverse transpose, rays their origin and direction (the `t` range is kept,
/// which is exact for affine transforms), and bounds the box of their eight transformed corners.
pub struct Transform<To: Space, From: Space> {
    m: Mat4,
    m_inv: Mat4,
    spaces: PhantomData<fn(From) -> To>,
}

/// Largest entry of `m * m_inv - I` accepted for a matrix to count as invertible in f32.
const INVERSE_TOLERANCE: f32 = 1e-3;

impl<To: Space, From: Space> Transform<To, From> {
    /// The identity map. Between two different spaces it asserts that they coincide.
    pub const IDENTITY: Self = Self {
        m: Mat4::IDENTITY,
        m_inv: Mat4::IDENTITY,
        spaces: PhantomData,
    };

    /// The identity map (see [`Transform::IDENTITY`]).
    #[inline]
    pub const fn identity() -> Self {
        Self::IDENTITY
    }

    /// A transform from a matrix (column-major glam `Mat4` acting on column vectors). Errors if
    /// an entry is not finite or the matrix cannot be inverted accurately in f32.
    pub fn from_matrix(m: Mat4) -> Result<Self, SpaceError> {
        Self::checked(m, "matrix")
    }

    /// A transform from sixteen numbers in row-major order (as a scene file writes them).
    pub fn from_rows(rows: [f32; 16]) -> Result<Self, SpaceError> {
        Self::checked(Mat4::from_cols_array(&rows).transpose(), "matrix")
    }

    /// A transform from a matrix and its inverse, trusted as given (no check). Use it where the
    /// inverse is known in closed form and more accurate than a numerical inversion.
    #[inline]
    pub const fn from_matrix_and_inverse(m: Mat4, m_inv: Mat4) -> Self {
        Self {
            m,
            m_inv,
            spaces: PhantomData,
        }
    }

    fn checked(m: Mat4, what: &'static str) -> Result<Self, SpaceError> {
        if !m.is_finite() {
            return Err(SpaceError::NonFinite { what });
        }
        let det = m.determinant();
        if det == 0.0 || !det.is_finite() {
            return Err(SpaceError::Singular { what });
        }
        let m_inv = m.inverse();
        if !m_inv.is_finite() {
            return Err(SpaceError::Singular { what });
        }
        // An inverse that does not invert (an ill-conditioned matrix) is as bad as none.
        let residual = (m * m_inv - Mat4::IDENTITY).to_cols_array();
        if residual.iter().any(|r| r.abs() > INVERSE_TOLERANCE) {
            return Err(SpaceError::Singular { what });
        }
        Ok(Self::from_matrix_and_inverse(m, m_inv))
    }

    /// A translation by `delta`.
    pub fn translate(delta: Vec3) -> Result<Self, SpaceError> {
        if !delta.is_finite() {
            return Err(SpaceError::NonFinite {
                what: "translation",
            });
        }
        Ok(Self::from_matrix_and_inverse(
            Mat4::from_translation(delta),
            Mat4::from_translation(-delta),
        ))
    }

    /// A scale by `factors` along the axes. A zero factor is singular, hence an error.
    pub fn scale(factors: Vec3) -> Result<Self, SpaceError> {
        if !factors.is_finite() {
            return Err(SpaceError::NonFinite { what: "scale" });
        }
        let inv = factors.recip();
        if factors.cmpeq(Vec3::ZERO).any() || !inv.is_finite() {
            return Err(SpaceError::Singular { what: "scale" });
        }
        Ok(Self::from_matrix_and_inverse(
            Mat4::from_scale(factors),
            Mat4::from_scale(inv),
        ))
    }

    /// A rotation by `degrees` about `axis` (through the origin), counter-clockwise when
    /// looking from the tip of `axis` towards the origin (the right-hand rule).
    pub fn rotate(degrees: f32, axis: Vec3) -> Result<Self, SpaceError> {
        if !degrees.is_finite() || !axis.is_finite() {
            return Err(SpaceError::NonFinite { what: "rotation" });
        }
        let axis = axis.try_normalize().ok_or(SpaceError::ZeroAxis)?;
        let m = Mat4::from_axis_angle(axis, degrees.to_radians());
        // A rotation's inverse is its transpose.
        Ok(Self::from_matrix_and_inverse(m, m.transpose()))
    }

    /// The look-at frame of SCENE_FORMAT.md, as the map from the local frame `From` (camera
    /// space, say) to the outer space `To` (world space): `dir = normalize(target - eye)`,
    /// `right = normalize(cross(dir, up))`, `true_up = cross(right, dir)`; local +x = right,
    /// +y = true_up, +z = dir, and the local origin sits at `eye`.
    ///
    /// The frame (right, true_up, dir) is left-handed in a right-handed world, so the result
    /// has determinant -1 and [`Transform::swaps_handedness`] is true.
    ///
    /// Errors: non-finite input, `eye == target`, a zero-length `up`, or `up` parallel to the
    /// view direction.
    pub fn look_at(
        eye: Point3<To>,
        target: Point3<To>,
        up: Vector3<To>,
    ) -> Result<Self, SpaceError> {
        if !(eye.is_finite() && target.is_finite() && up.is_finite()) {
            return Err(SpaceError::NonFinite { what: "look-at" });
        }
        let dir = (target - eye)
            .to_glam()
            .try_normalize()
            .ok_or(SpaceError::DegenerateLookAt(
                "eye and target are the same point",
            ))?;
        let up = up.to_glam();
        let up_len = up.length();
        if up_len == 0.0 || !up_len.is_finite() {
            return Err(SpaceError::DegenerateLookAt("up has zero length"));
        }
        let side = dir.cross(up / up_len);
        // |cross(dir, up_unit)| is the sine of the angle between them.
        if side.length() < 1e-6 {
            return Err(SpaceError::DegenerateLookAt(
                "up is parallel to the view direction",
            ));
        }
        let right = side.normalize();
        let true_up = right.cross(dir);
        let eye = eye.to_glam();
        let m = Mat4::from_cols(
            right.extend(0.0),
            true_up.extend(0.0),
            dir.extend(0.0),
            eye.extend(1.0),
        );
        // The 3x3 part is orthogonal, so the inverse is its transpose with the eye moved back.
        let r_t = Mat3::from_cols(right, true_up, dir).transpose();
        let m_inv = Mat4::from_mat3(r_t) * Mat4::from_translation(-eye);
        Ok(Self::from_matrix_and_inverse(m, m_inv))
    }

    /// The matrix (column-major glam, acting on column vectors).
    #[inline]
    pub const fn matrix(&self) -> Mat4 {
        self.m
    }

    /// The inverse matrix.
    #[inline]
    pub const fn inverse_matrix(&self) -> Mat4 {
        self.m_inv
    }

    /// The inverse map, `Transform<From, To>`; free, since the inverse is stored.
    #[inline]
    pub const fn inverse(&self) -> Transform<From, To> {
        Transform::from_matrix_and_inverse(self.m_inv, self.m)
    }

    /// True when the map reverses orientation (the linear part has a negative determinant):
    /// cross products of mapped vectors then point the opposite way from mapped cross products.
    #[inline]
    pub fn swaps_handedness(&self) -> bool {
        Mat3::from_mat4(self.m).determinant() < 0.0
    }

    /// True when the map is exactly the identity.
    #[inline]
    pub fn is_identity(&self) -> bool {
        self.m == Mat4::IDENTITY
    }

    /// Maps a point, with the homogeneous divide.
    #[inline]
    pub fn point(&self, p: Point3<From>) -> Point3<To> {
        let h = self.m * Vec4::new(p.x, p.y, p.z, 1.0);
        if h.w == 1.0 {
            Point3::new(h.x, h.y, h.z)
        } else {
            Point3::from_glam(h.truncate() / h.w)
        }
    }

    /// Maps a vector (the linear part only).
    #[inline]
    pub fn vector(&self, v: Vector3<From>) -> Vector3<To> {
        Vector3::from_glam(self.m.transform_vector3(v.to_glam()))
    }

    /// Maps a normal by the inverse transpose, so it stays perpendicular to mapped tangents.
    /// The result is not normalised.
    #[inline]
    pub fn normal(&self, n: Normal3<From>) -> Normal3<To> {
        let inv = self.m_inv;
        let n = n.to_glam();
        // (M^-1)^T n: row i of the transpose is column i of M^-1.
        Normal3::new(
            inv.x_axis.truncate().dot(n),
            inv.y_axis.truncate().dot(n),
            inv.z_axis.truncate().dot(n),
        )
    }

    /// Maps a ray: origin as a point, direction as a vector; time and `t` range are kept, so a
    /// hit at `t` is the same point in both spaces (exact for affine maps).
    #[inline]
    pub fn ray(&self, r: Ray<From>) -> Ray<To> {
        Ray {
            origin: self.point(r.origin),
            direction: self.vector(r.direction),
            time: r.time,
            t_min: r.t_min,
            t_max: r.t_max,
        }
    }

    /// The smallest box holding the mapped box (the box of its eight mapped corners).
    pub fn bounds(&self, b: Bounds3<From>) -> Bounds3<To> {
        if b.is_empty() {
            return Bounds3::EMPTY;
        }
        Bounds3::from_points(b.corners().map(|c| self.point(c)))
    }
}

impl<To: Space, From: Space> Clone for Transform<To, From> {
    #[inline]
    fn clone(&self) -> Self {
        *self
    }
}
impl<To: Space, From: Space> Copy for Transform<To, From> {}
impl<To: Space, From: Space> PartialEq for Transform<To, From> {
    fn eq(&self, o: &Self) -> bool {
        self.m == o.m && self.m_inv == o.m_inv
    }
}
impl<To: Space, From: Space> fmt::Debug for Transform<To, From> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "Transform<{}, {}>{:?}",
            To::NAME,
            From::NAME,
            self.m.transpose().to_cols_array_2d()
        )
    }
}

impl<A: Space, B: Space, C: Space> Mul<Transform<B, C>> for Transform<A, B> {
    type Output = Transform<A, C>;
    /// `a_from_b * b_from_c = a_from_c`: apply the right-hand transform first.
    #[inline]
    fn mul(self, rhs: Transform<B, C>) -> Transform<A, C> {
        Transform::from_matrix_and_inverse(self.m * rhs.m, rhs.m_inv * self.m_inv)
    }
}

macro_rules! apply_op {
    ($ty:ident, $method:ident) => {
        impl<To: Space, From: Space> Mul<$ty<From>> for Transform<To, From> {
            type Output = $ty<To>;
            #[inline]
            fn mul(self, x: $ty<From>) -> $ty<To> {
                self.$method(x)
            }
        }
        impl<To: Space, From: Space> Mul<$ty<From>> for &Transform<To, From> {
            type Output = $ty<To>;
            #[inline]
            fn mul(self, x: $ty<From>) -> $ty<To> {
                self.$method(x)
            }
        }
    };
}
apply_op!(Point3, point);
apply_op!(Vector3, vector);
apply_op!(Normal3, normal);
apply_op!(Ray, ray);
apply_op!(Bounds3, bounds);
