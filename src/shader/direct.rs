//! The direct shader (assignments 3 and 4): point lights with hard shadows at Phong surfaces;
//! mirrors and glass pass on what their single scattered ray sees.

use super::Tracer;
use super::surface::{Interaction, direct_light, specular_bounce};
use crate::geometry::Ray;
use crate::material::Material;
use crate::render::stats::RayKind;
use glam::Vec3A;

/// Radiance along a camera ray under direct lighting only.
pub fn radiance<const K: u32>(tr: &mut Tracer, ray: &Ray, max_specular: u32) -> Vec3A {
    li::<K>(tr, ray, RayKind::Camera, 0, max_specular)
}

/// `chain` counts the consecutive specular bounces that led here.
fn li<const K: u32>(
    tr: &mut Tracer,
    ray: &Ray,
    kind: RayKind,
    chain: u32,
    max_specular: u32,
) -> Vec3A {
    // A ray that leaves the scene sees the background.
    let Some(hit) = tr.trace::<K>(ray, kind) else {
        return tr.scene.background;
    };
    let si = Interaction::new(tr, ray, hit);
    match si.material {
        // Eq. 3 at a Phong surface.
        Material::Phong(phong) => direct_light::<K>(tr, &si, &phong),
        // Mirror or glass: follow the scattered ray, tinted, unless the chain is too long.
        _ => {
            if chain >= max_specular {
                return Vec3A::ZERO;
            }
            match specular_bounce::<K>(&si) {
                Some((next, tint, kind)) => {
                    tint * li::<K>(tr, &next, kind, chain + 1, max_specular)
                }
                None => Vec3A::ZERO,
            }
        }
    }
}
