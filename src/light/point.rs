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
        let to = self.position - p;
        let d2 = to.length_squared();
        if d2 == 0.0 || !d2.is_finite() {
            return None;
        }
        let dist = d2.sqrt();
        Some(Incident {
            wi: to / dist,
            dist,
            li: self.intensity / d2,
        })
    }
}
