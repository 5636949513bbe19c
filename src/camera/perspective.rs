//! The perspective camera: a pinhole, or a thin lens that focuses on a plane (depth of field).

use super::{Basis, plane_offset};
use crate::geometry::Ray;
use crate::sampling::warp::concentric_disk;
use glam::Vec3A;

/// A thin lens of radius `radius` centred on the camera's origin, in the plane spanned by
/// `right` and `up`, focused on the plane at distance `focus_distance` along `forward` (as
/// Mitsuba 3's `thinlens` and pbrt-v4's `PerspectiveCamera` with a lens radius).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    /// Radius of the aperture, scene units, > 0 (a radius of 0 is the pinhole: no lens).
    pub radius: f32,
    /// Distance from the lens to the plane in focus, along the viewing direction, > 0.
    pub focus_distance: f32,
}

/// A perspective camera at `origin` with an image plane at distance 1 whose vertical extent is
/// `2 tan(fov / 2)` and horizontal extent that times `aspect`; a pinhole unless it has a lens.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Perspective {
    /// Centre of projection (the lens's centre).
    pub origin: Vec3A,
    /// Orientation.
    pub basis: Basis,
    /// `tan(fov / 2)` of the vertical field of view.
    pub tan_half_fov: f32,
    /// `width / height`.
    pub aspect: f32,
    /// The lens, or `None` for a pinhole.
    pub lens: Option<ThinLens>,
}

impl Perspective {
    /// The ray through image point `(u, v)`. A pinhole draws nothing from `lens_sample`; a
    /// thin lens draws one 2D sample from it, its point on the lens.
    #[inline]
    pub fn ray(&self, u: f32, v: f32, lens_sample: impl FnOnce() -> (f32, f32)) -> Ray {
        let half_h = self.tan_half_fov;
        let d = self.basis.forward + plane_offset(&self.basis, u, v, half_h * self.aspect, half_h);
        let pinhole = Ray::new(self.origin, d.normalize());
        let Some(lens) = self.lens else {
            return pinhole;
        };
        // The point of the plane in focus that the pinhole ray meets: every ray through the
        // lens for this image point passes through it (pbrt-v4, `PerspectiveCamera`).
        let t_focus = lens.focus_distance / pinhole.d.dot(self.basis.forward);
        let focus = self.origin + pinhole.d * t_focus;
        // A uniform point on the lens.
        let (u1, u2) = lens_sample();
        let (lx, ly) = concentric_disk(u1, u2);
        let o = self.origin + lens.radius * (lx * self.basis.right + ly * self.basis.up);
        Ray::new(o, (focus - o).normalize())
    }
}
