//! Spot lights: a point light whose intensity falls off with the angle from its axis, as
//! Mitsuba 3's `spot` (linear in the angle from the beam's edge to the cutoff).

use super::Incident;
use glam::Vec3A;

/// A spot light at `position` pointing along `axis`, with radiant intensity `intensity` (W/sr
/// per channel) within `beam` of the axis, falling linearly in the angle to zero at `cutoff`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotLight {
    /// Position (camera-relative once prepared).
    pub position: Vec3A,
    /// Unit direction the light points along.
    pub axis: Vec3A,
    /// Radiant intensity on the axis, W/sr.
    pub intensity: Vec3A,
    /// Half-angle of the full beam, radians, `0 < beam <= cutoff`.
    pub beam: f32,
    /// Half-angle beyond which the light is black, radians, `cutoff <= pi / 2`.
    pub cutoff: f32,
    /// As [`super::PointLight::in_room`]: no plane can block a shadow ray towards it.
    pub in_room: bool,
}

impl SpotLight {
    /// The share of the axis's intensity sent at angle `theta` from the axis, given
    /// `cos_theta`: 1 within the beam, `(cutoff - theta) / (cutoff - beam)` up to the cutoff,
    /// 0 beyond (Mitsuba 3, `SpotLight::falloff_curve`).
    #[inline]
    pub fn falloff(&self, cos_theta: f32) -> f32 {
        if cos_theta <= self.cutoff.cos() {
            0.0
        } else if cos_theta >= self.beam.cos() {
            1.0
        } else {
            ((self.cutoff - cos_theta.min(1.0).acos()) / (self.cutoff - self.beam)).clamp(0.0, 1.0)
        }
    }

    /// Emitted power averaged over the channels: `2 pi I [1 - (sin c - sin b) / (c - b)]` for
    /// beam `b` and cutoff `c` (the integral of the falloff over the sphere, by parts), `2 pi I
    /// (1 - cos c)` when they are equal.
    pub fn power(&self) -> f32 {
        let (b, c) = (self.beam as f64, self.cutoff as f64);
        let share = if c - b > 1e-6 {
            1.0 - (c.sin() - b.sin()) / (c - b)
        } else {
            1.0 - c.cos()
        };
        (std::f64::consts::TAU * share * self.intensity.element_sum() as f64 / 3.0) as f32
    }

    /// `L_i = I falloff(theta) / d^2` along the unit direction to the light; `None` when `p` is
    /// the light's position (or the distance overflows), or outside the cone (no light, so no
    /// shadow ray).
    #[inline]
    pub fn incident(&self, p: Vec3A) -> Option<Incident> {
        let (wi, dist, d2) = self.toward(p);
        let falloff = self.falloff(-wi.dot(self.axis));
        if d2 == 0.0 || !d2.is_finite() || falloff == 0.0 {
            return None;
        }
        Some(Incident {
            wi,
            dist,
            li: self.intensity * (falloff / d2),
        })
    }

    /// The unit direction from `p` to the light, the distance and its square (as
    /// [`super::PointLight::toward`]).
    #[inline]
    pub fn toward(&self, p: Vec3A) -> (Vec3A, f32, f32) {
        super::point::toward(self.position, p)
    }
}
