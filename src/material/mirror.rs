//! Perfect mirrors.

use super::phong::reflect;
use glam::Vec3A;

/// A perfect specular reflector whose reflected radiance is tinted by `color`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mirror {
    /// Tint per channel, in [0, inf) (1 reflects everything).
    pub color: Vec3A,
}

impl Mirror {
    /// The reflected direction `wr = 2 (n.wo) n - wo`.
    #[inline]
    pub fn reflect(&self, wo: Vec3A, n: Vec3A) -> Vec3A {
        reflect(wo, n)
    }
}
