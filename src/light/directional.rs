//! Directional lights: a sun at infinity, sending parallel light of a given irradiance, as
//! Mitsuba 3's `directional` and pbrt-v4's `DistantLight`.

use super::Incident;
use glam::Vec3A;

/// Light arriving from infinitely far along `-direction`: irradiance `irradiance` (W/m^2 per
/// channel) on a surface facing it, `irradiance cos(theta)` on one tilted by `theta`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// Unit direction the light travels in.
    pub direction: Vec3A,
    /// Irradiance on a surface facing the light, W/m^2.
    pub irradiance: Vec3A,
    /// Radius of a sphere bounding the scene's finite parts (its shapes, lights and camera):
    /// the light's power is what crosses its disk, `pi r^2 E` (pbrt-v4, `DistantLight::Phi`).
    pub scene_radius: f32,
}

impl DirectionalLight {
    /// Power averaged over the channels, `pi r^2 E` with `r` the scene's bounding radius, in
    /// double precision and at most `f32::MAX` (a bright sun over a scene 1e9 wide would
    /// overflow, and the choice by power divide infinities).
    pub fn power(&self) -> f32 {
        let r = self.scene_radius as f64;
        let p = std::f64::consts::PI * r * r * self.irradiance.element_sum() as f64 / 3.0;
        p.min(f32::MAX as f64) as f32
    }

    /// The light at any point: towards `-direction`, at infinite distance (a shadow ray runs
    /// to infinity), with `L_i = E`, so that the term `L_i f cos(theta)` is the reflected
    /// radiance.
    #[inline]
    pub fn incident(&self) -> Incident {
        Incident {
            wi: -self.direction,
            dist: f32::INFINITY,
            li: self.irradiance,
        }
    }
}
