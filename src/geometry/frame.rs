//! Orthonormal frames around a unit normal.

use glam::Vec3A;

/// A right-handed orthonormal basis `(s, t, n)`; `n` is the local +z axis.
///
/// Built with Duff et al.'s branchless construction (glam's `any_orthonormal_pair`), which stays
/// orthonormal for every unit normal, unlike a cross product with a fixed axis.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// First tangent.
    pub s: Vec3A,
    /// Second tangent.
    pub t: Vec3A,
    /// The normal.
    pub n: Vec3A,
}

impl Frame {
    /// The frame whose z axis is the unit vector `n`.
    #[inline]
    pub fn from_normal(n: Vec3A) -> Self {
        let (s, t) = n.any_orthonormal_pair();
        Frame { s, t, n }
    }

    /// Local coordinates to world.
    #[inline]
    pub fn to_world(&self, v: Vec3A) -> Vec3A {
        v.x * self.s + v.y * self.t + v.z * self.n
    }

    /// World coordinates to local.
    #[inline]
    pub fn to_local(&self, v: Vec3A) -> Vec3A {
        Vec3A::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }
}
