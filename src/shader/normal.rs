//! The normal shader: the surface normal as a colour.

use super::Tracer;
use crate::geometry::Ray;
use crate::stats::RayKind;
use glam::Vec3A;

/// `(n + 1) / 2` with `n` the unit normal on the side facing the camera; background on a miss.
pub fn radiance(tr: &mut Tracer, ray: &Ray) -> Vec3A {
    match tr.trace(ray, RayKind::Camera) {
        Some(hit) => {
            let n = if hit.n.dot(ray.d) > 0.0 {
                -hit.n
            } else {
                hit.n
            };
            0.5 * (n + Vec3A::ONE)
        }
        None => tr.background,
    }
}
