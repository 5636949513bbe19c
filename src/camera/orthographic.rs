//! The orthographic (parallel projection) camera.

use super::{Basis, plane_offset};
use crate::geometry::Ray;
use glam::Vec3A;

/// Parallel rays along `forward` from an image rectangle centred on `origin`, `height` world
/// units tall and `height * aspect` wide.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orthographic {
    /// Centre of the image rectangle.
    pub origin: Vec3A,
    /// Orientation.
    pub basis: Basis,
    /// Vertical extent in world units.
    pub height: f32,
    /// `width / height` of the film.
    pub aspect: f32,
}

impl Orthographic {
    /// The ray through image point `(u, v)`.
    #[inline]
    pub fn ray(&self, u: f32, v: f32) -> Ray {
        let half_h = 0.5 * self.height;
        let o = self.origin + plane_offset(&self.basis, u, v, half_h * self.aspect, half_h);
        Ray::new(o, self.basis.forward)
    }
}
