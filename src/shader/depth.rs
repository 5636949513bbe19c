//! The depth shader: a colour that fades linearly with the hit distance.

use super::Tracer;
use crate::geometry::Ray;
use crate::stats::RayKind;
use glam::Vec3A;

/// `color * max(0, 1 - t / max_distance)` at the hit distance `t`; the background on a miss.
pub fn radiance(tr: &mut Tracer, ray: &Ray, max_distance: f32, color: Vec3A) -> Vec3A {
    match tr.trace(ray, RayKind::Camera) {
        Some(hit) => color * (1.0 - hit.t / max_distance).max(0.0),
        None => tr.background,
    }
}
