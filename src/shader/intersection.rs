//! The intersection shader: a flat colour wherever the ray hits something.

use super::Tracer;
use crate::geometry::Ray;
use crate::stats::RayKind;
use glam::Vec3A;

/// `color` if the camera ray hits anything, the background otherwise.
pub fn radiance(tr: &mut Tracer, ray: &Ray, color: Vec3A) -> Vec3A {
    match tr.trace(ray, RayKind::Camera) {
        Some(_) => color,
        None => tr.background,
    }
}
