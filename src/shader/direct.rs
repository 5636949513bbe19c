//! The direct shader (assignments 3 and 4): point lights with hard shadows at Phong surfaces
//! (and at rough materials and plastics, weighted by their BSDF),
//! area lights with soft shadows from `light_samples` samples; mirrors and glass pass on what
//! their single scattered ray sees; emitters are seen directly and through mirrors and glass.

use super::Tracer;
use super::surface::{ChainEnd, direct_light, follow_specular};
use crate::geometry::Ray;
use crate::stats::RayKind;
use glam::Vec3A;

/// Radiance along a camera ray under direct lighting only.
pub fn radiance(tr: &mut Tracer, ray: &Ray, max_specular: u32, light_samples: u32) -> Vec3A {
    // Follow mirrors and glass to the first Phong surface, carrying their tint and collecting
    // the emitters they see.
    let (end, le) = follow_specular(tr, ray, RayKind::Camera, max_specular, true);
    le + match end {
        // Eq. 3 at the Phong surface.
        ChainEnd::Phong { si, phong, beta } => beta * direct_light(tr, &si, &phong, light_samples),
        // Eq. 3 with the BSDF's f |cos| in place of r.
        ChainEnd::Bsdf { si, shading, beta } => {
            beta * direct_light(tr, &si, &shading, light_samples)
        }
        // A ray that leaves the scene sees the background or the environment.
        ChainEnd::Escaped { beta, sky } => beta * sky,
        ChainEnd::Absorbed => Vec3A::ZERO,
    }
}
