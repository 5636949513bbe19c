//! The closed set of lights. Each variant lives in its own file; [`Light`] dispatches by `match`.

mod point;

pub use point::PointLight;

use glam::Vec3A;

/// Light arriving at a point from one light: unit direction towards the light, distance to it,
/// and incident radiance.
#[derive(Clone, Copy, Debug)]
pub struct Incident {
    /// Unit direction from the shaded point towards the light.
    pub wi: Vec3A,
    /// Distance to the light.
    pub dist: f32,
    /// Incident radiance `L_i` (for a point light `I / d^2`).
    pub li: Vec3A,
}

/// A prepared light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// An isotropic point light.
    Point(PointLight),
}

impl Light {
    /// Light arriving at `p` from this light, ignoring occlusion; `None` when `p` coincides
    /// with the light.
    #[inline]
    pub fn incident(&self, p: Vec3A) -> Option<Incident> {
        match self {
            Light::Point(l) => l.incident(p),
        }
    }
}
