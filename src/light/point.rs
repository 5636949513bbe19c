//! Point lights.

use super::Incident;
use glam::Vec3A;

/// An isotropic point light at `position` with radiant intensity `intensity` (W/sr per channel).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// Position (camera-relative once prepared).
    pub position: Vec3A,
    /// Radiant intensity, W/sr.
    pub intensity: Vec3A,
    /// True if no plane can block a shadow ray towards the light: it is on the side of every
    /// plane that rays are kept on (`Geometry::in_room` in `accel`). Set by extraction;
    /// shadow rays towards it then skip the planes.
    pub in_room: bool,
}

/// The unit direction from `p` to a light at `x`, the distance and its square (NaN directions
/// when `p` is `x`, or when the distance overflows): what a point or spot light's `incident`
/// and the choice by importance read alike.
#[inline]
pub fn toward(x: Vec3A, p: Vec3A) -> (Vec3A, f32, f32) {
    let to = x - p;
    let d2 = to.length_squared();
    let dist = d2.sqrt();
    (to / dist, dist, d2)
}

impl PointLight {
    /// Emitted power `4 pi I`, averaged over the channels: its weight when one light is chosen
    /// per vertex.
    pub fn power(&self) -> f32 {
        4.0 * std::f32::consts::PI * self.intensity.element_sum() / 3.0
    }

    /// `L_i = I / d^2` along the unit direction to the light.
    #[inline]
    pub fn incident(&self, p: Vec3A) -> Option<Incident> {
        let (wi, dist, d2) = self.toward(p);
        if d2 == 0.0 || !d2.is_finite() {
            return None;
        }
        Some(Incident {
            wi,
            dist,
            li: self.intensity / d2,
        })
    }

    /// The unit direction from `p` to the light, the distance and its square, as
    /// [`PointLight::incident`] computes them (NaN directions when `p` is the light's position
    /// or the distance overflows: `incident` then gives no light). Choosing a light by its
    /// contribution (`light::importance`) reads the same bits, so a light whose term is not
    /// zero always has a weight.
    #[inline]
    pub fn toward(&self, p: Vec3A) -> (Vec3A, f32, f32) {
        toward(self.position, p)
    }
}
