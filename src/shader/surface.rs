//! Shading pieces shared by the Direct, Global and Path shaders: the local frame at a hit, the
//! direct light from point lights (Eq. 3), the reflectance under each model, the single
//! scattered ray of a mirror or glass, and the loop that follows a chain of them.

use super::Tracer;
use crate::effects::Effects;
use crate::geometry::{Hit, Origins, Ray};
use crate::material::{Material, Model, Phong};
use crate::stats::RayKind;
use glam::Vec3A;

/// A hit seen from the ray that found it.
#[derive(Clone, Copy, Debug)]
pub struct Interaction {
    /// The hit.
    pub hit: Hit,
    /// Unit direction back along the incoming ray (towards the viewer).
    pub wo: Vec3A,
    /// Unit shading normal on the side of `wo` (two-sided shading): the geometric normal, or
    /// the interpolated vertex normal of a smooth triangle.
    pub n: Vec3A,
    /// The surface's material.
    pub material: Material,
    /// Where rays leaving the hit start.
    pub origins: Origins,
}

impl Interaction {
    /// The interaction of `ray` with its nearest hit.
    #[inline]
    pub fn new(tr: &Tracer, ray: &Ray, hit: Hit) -> Self {
        let wo = -ray.d;
        let prim = tr.geometry.prim(hit.prim);
        let ng = if hit.n.dot(wo) < 0.0 { -hit.n } else { hit.n };
        // The shading normal stays on the viewer's side of the surface.
        let ns = tr.geometry.shading_normal(prim, hit.p, ng);
        let n = if ns.dot(ng) < 0.0 { -ns } else { ns };
        Interaction {
            hit,
            wo,
            n,
            material: tr.materials[prim.material as usize],
            origins: Origins::new(&hit),
        }
    }

    /// A ray leaving the surface in unit direction `w`, started off the surface on `w`'s side.
    #[inline]
    pub fn spawn(&self, w: Vec3A) -> Ray {
        self.origins.ray(w, f32::INFINITY)
    }
}

/// The reflectance that weights incident radiance under `model`: the course's `r(wi, wo)`, or the
/// BRDF times the cosine `f(wi, wo) (wi.n)` for the physically based model.
#[inline]
pub fn reflectance(model: Model, phong: &Phong, wi: Vec3A, wo: Vec3A, n: Vec3A) -> Vec3A {
    match model {
        Model::Course => phong.course_reflectance(wi, wo, n),
        Model::Physical => phong.brdf(wi, wo, n) * wi.dot(n).max(0.0),
    }
}

/// Eq. 3: `L_dir = sum_s L_i^s r(wi^s, wo) V^s` over the point lights. A light counts only when
/// it is above the surface (`wi.n > 0`) and the shadow ray reaches it.
///
/// Without shadows (`effects: (shadows: false)`) every light facing the point counts.
#[inline]
pub fn direct_light(tr: &mut Tracer, si: &Interaction, phong: &Phong) -> Vec3A {
    let mut l_dir = Vec3A::ZERO;
    let model = tr.model;
    for light in tr.lights {
        let Some(inc) = light.incident(si.hit.p) else {
            continue;
        };
        if inc.wi.dot(si.n) <= 0.0 {
            continue;
        }
        // Shadow ray V^s: stop just short of the light, so that a surface the light sits on
        // does not block it.
        let visible = !tr.effects.shadows || {
            tr.unoccluded(&si.origins.ray(inc.wi, inc.dist * SHADOW_END))
        };
        if visible {
            l_dir += inc.li * reflectance(model, phong, inc.wi, si.wo, si.n);
        }
    }
    l_dir
}

/// Shadow rays end at this fraction of the distance to the light.
const SHADOW_END: f32 = 1.0 - 1e-4;

/// The one ray a mirror or glass surface sends on, its tint, and its kind, in the course's
/// model; `None` for Phong, and for an effect that is off (the surface is then black).
///
/// Mirrors reflect `wo` about the normal. Glass refracts with Snell's law (`eta = 1 / ior`
/// entering, `ior` leaving) and reflects under total internal reflection.
#[inline]
pub fn specular_bounce(si: &Interaction, effects: Effects) -> Option<(Ray, Vec3A, RayKind)> {
    match si.material {
        Material::Phong(_) => None,
        Material::Mirror(m) => {
            if !effects.reflection {
                return None;
            }
            let wr = m.reflect(si.wo, si.n);
            Some((si.spawn(wr), m.color, RayKind::Reflection))
        }
        Material::Transmissive(g) => {
            let r = g.refract(si.wo, si.hit.n);
            let (kind, on) = if r.total_internal_reflection {
                (RayKind::Reflection, effects.reflection)
            } else {
                (RayKind::Refraction, effects.refraction)
            };
            if !on {
                return None;
            }
            Some((si.spawn(r.wt), g.color, kind))
        }
    }
}

/// Where a chain of mirror and glass bounces ends.
#[derive(Clone, Copy, Debug)]
#[allow(
    clippy::large_enum_variant,
    reason = "returned by value and matched at once by the caller; boxing the Phong variant \
              would allocate once per chain"
)]
pub enum ChainEnd {
    /// At a Phong surface, reached with throughput `beta` (the product of the tints).
    Phong {
        /// The Phong hit.
        si: Interaction,
        /// Its material.
        phong: Phong,
        /// Throughput of the chain.
        beta: Vec3A,
    },
    /// The chain left the scene with throughput `beta`: it sees the background.
    Escaped {
        /// Throughput of the chain.
        beta: Vec3A,
    },
    /// The chain carries no light: an effect that is off, or longer than its cap.
    Absorbed,
}

/// Trace `ray` (counted as `kind`) and follow mirrors and glass, as a loop carrying the
/// throughput, until a Phong surface, an escape, or `max_specular` consecutive specular
/// bounces (the course's model: mirrors reflect, glass refracts or reflects totally, tinted).
#[inline]
pub fn follow_specular(tr: &mut Tracer, ray: &Ray, kind: RayKind, max_specular: u32) -> ChainEnd {
    let (mut ray, mut kind, mut beta) = (*ray, kind, Vec3A::ONE);
    // `chain` counts the specular bounces that led to this ray.
    for chain in 0..=max_specular {
        let Some(hit) = tr.trace(&ray, kind) else {
            return ChainEnd::Escaped { beta };
        };
        let si = Interaction::new(tr, &ray, hit);
        if let Material::Phong(phong) = si.material {
            return ChainEnd::Phong { si, phong, beta };
        }
        if chain == max_specular {
            break;
        }
        let Some((next, tint, next_kind)) = specular_bounce(&si, tr.effects) else {
            break;
        };
        beta *= tint;
        (ray, kind) = (next, next_kind);
    }
    ChainEnd::Absorbed
}
