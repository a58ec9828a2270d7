//! Orthonormal shading frames: world directions to and from the local frame where the normal
//! is +z and BSDFs are written.

use glam::Vec3;

/// An orthonormal basis `(s, t, n)`, right-handed, with `n` the local +z axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// First tangent (local +x).
    pub s: Vec3,
    /// Second tangent (local +y).
    pub t: Vec3,
    /// The normal (local +z).
    pub n: Vec3,
}

impl Frame {
    /// A frame around the unit vector `n` (Duff et al. 2017, branchless and continuous away from
    /// `n.z = 0`'s sign flip).
    pub fn from_normal(n: Vec3) -> Frame {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }

    /// A world vector in local coordinates.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// A local vector in world coordinates.
    #[inline]
    pub fn from_local(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(500))]
        #[test]
        fn frames_are_orthonormal_and_round_trip(
            x in -1.0f32..1.0, y in -1.0f32..1.0, z in -1.0f32..1.0,
            vx in -2.0f32..2.0, vy in -2.0f32..2.0, vz in -2.0f32..2.0,
        ) {
            let n = Vec3::new(x, y, z);
            prop_assume!(n.length() > 0.1);
            let f = Frame::from_normal(n.normalize());
            prop_assert!((f.s.length() - 1.0).abs() < 1e-5);
            prop_assert!((f.t.length() - 1.0).abs() < 1e-5);
            prop_assert!(f.s.dot(f.t).abs() < 1e-5 && f.s.dot(f.n).abs() < 1e-5 && f.t.dot(f.n).abs() < 1e-5);
            // Right-handed: s x t = n.
            prop_assert!((f.s.cross(f.t) - f.n).length() < 1e-5);
            let v = Vec3::new(vx, vy, vz);
            prop_assert!((f.from_local(f.to_local(v)) - v).length() < 1e-5);
        }
    }

    #[test]
    fn the_normal_is_local_z() {
        // n = -z is the branch's edge case: the frame must still be orthonormal.
        let f = Frame::from_normal(Vec3::NEG_Z);
        assert!((f.to_local(Vec3::NEG_Z) - Vec3::Z).length() < 1e-6);
        assert!(f.s.dot(f.t).abs() < 1e-6);
    }
}
