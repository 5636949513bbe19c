//! The pinhole perspective camera.

use super::{Basis, plane_offset};
use crate::geometry::Ray;
use glam::Vec3A;

/// A pinhole camera at `origin` with an image plane at distance 1 whose vertical extent is
/// `2 tan(fov / 2)` and horizontal extent that times `aspect`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Perspective {
    /// Centre of projection.
    pub origin: Vec3A,
    /// Orientation.
    pub basis: Basis,
    /// `tan(fov / 2)` of the vertical field of view.
    pub tan_half_fov: f32,
    /// `width / height`.
    pub aspect: f32,
}

impl Perspective {
    /// The ray through image point `(u, v)`.
    #[inline]
    pub fn ray(&self, u: f32, v: f32) -> Ray {
        let half_h = self.tan_half_fov;
        let d = self.basis.forward + plane_offset(&self.basis, u, v, half_h * self.aspect, half_h);
        Ray::new(self.origin, d.normalize())
    }
}
