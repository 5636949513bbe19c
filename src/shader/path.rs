//! The reference integrator: an iterative path tracer over throughput and depth.
//!
//! At each Phong vertex it adds the direct light of every point light (next-event estimation,
//! Eq. 3 under the scene's model), then samples one direction and continues; mirrors and glass
//! are followed exactly; Russian roulette ends paths after `rr_depth` bounces; escaped rays see
//! the background.
//!
//! Under each model a bounce estimates an integral over the hemisphere of `L_i(wi) g(wi) dwi`,
//! with weight `g(wi) / pdf(wi)`:
//!
//! - `Course`: `g = r(wi, wo) / (2 pi)^2`. With uniform sampling the weight is `r / (2 pi)`: the
//!   assignment's Eq. 4 with one sample, applied at every bounce. This is the infinite-depth
//!   limit of the Global shader's depth-0 estimator: the ground truth for measuring what the
//!   ambient term and the two-direction rule cost.
//! - `Physical`: `g = f(wi, wo) cos(theta_i)` with the normalised Phong BRDF: the rendering
//!   equation, unbiased; glass reflects with Fresnel probability and scales transmitted radiance
//!   by `eta^2 = (n_wo / n_wi)^2`, as radiance does (`docs/transport.md`).

use super::Tracer;
use super::surface::{Interaction, direct_light, reflectance, specular_bounce};
use crate::geometry::{Frame, Ray};
use crate::material::{Material, Model, Phong, fresnel_dielectric, reflect};
use crate::sampling::{Sampling, hemisphere};
use crate::stats::RayKind;
use glam::Vec3A;
use std::f32::consts::{PI, TAU};

/// Parameters of the path tracer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Path {
    /// Largest number of bounces (any surface); `None` for unbounded (Russian roulette ends paths).
    pub max_depth: Option<u32>,
    /// Bounces before Russian roulette starts.
    pub rr_depth: u32,
    /// Direction sampling at Phong vertices.
    pub sampling: Sampling,
}

/// Hard cap on bounces even without `max_depth` (two perfect mirrors facing each other), and
/// the largest `max_depth` and `rr_depth` a scene may ask for.
pub const MAX_DEPTH: u32 = 1024;

/// Radiance along a camera ray. Scattering into an effect that is off ends the path.
pub fn radiance(tr: &mut Tracer, camera_ray: &Ray, p: &Path) -> Vec3A {
    let model = tr.model;
    let max_depth = p.max_depth.unwrap_or(MAX_DEPTH).min(MAX_DEPTH);
    let mut l = Vec3A::ZERO;
    let mut beta = Vec3A::ONE;
    let mut ray = *camera_ray;
    let mut kind = RayKind::Camera;
    let mut depth = 0;
    loop {
        // Escaped rays see the background.
        let Some(hit) = tr.trace(&ray, kind) else {
            l += beta * tr.background;
            break;
        };
        let si = Interaction::new(tr, &ray, hit);
        if depth >= max_depth {
            break;
        }
        // Scatter: the next ray, its weight g(wi) / pdf(wi) and its kind.
        let (next_ray, weight, next) = match (si.material, model) {
            (Material::Phong(phong), _) => {
                // Next-event estimation: Eq. 3 under the model.
                l += beta * direct_light(tr, &si, &phong);
                if !tr.effects.indirect {
                    break;
                }
                let Some((wi, weight)) = sample_phong(tr, &phong, &si, model, p.sampling) else {
                    break;
                };
                (si.spawn(wi), weight, RayKind::Indirect)
            }
            // Fresnel-weighted choice between reflection and refraction.
            (Material::Transmissive(g), Model::Physical) => {
                let r = g.refract(si.wo, si.hit.n);
                let f = fresnel_dielectric(r.cos_i.abs(), r.eta);
                let (wi, weight, kind, on) = if tr.sampler.next_f32() < f {
                    let wr = reflect(si.wo, si.n);
                    (wr, Vec3A::ONE, RayKind::Reflection, tr.effects.reflection)
                } else {
                    // Radiance crossing into the wo side is scaled by (n_wo / n_wi)^2 = eta^2.
                    let w = g.color * (r.eta * r.eta);
                    (r.wt, w, RayKind::Refraction, tr.effects.refraction)
                };
                // An effect that is off ends the path.
                if !on {
                    break;
                }
                (si.spawn(wi), weight, kind)
            }
            // Mirrors, and the course's glass: the one scattered ray, as in Direct and Global.
            _ => match specular_bounce(&si, tr.effects) {
                Some(bounce) => bounce,
                None => break,
            },
        };
        beta *= weight;
        depth += 1;
        // Russian roulette: survive with probability q, divide by q to stay unbiased.
        if depth >= p.rr_depth {
            let q = beta.max_element().min(0.95);
            if q <= 0.0 || tr.sampler.next_f32() >= q {
                break;
            }
            beta /= q;
        }
        ray = next_ray;
        kind = next;
    }
    l
}

/// Sample a direction at a Phong vertex; `None` when it falls below the surface or has no weight.
fn sample_phong(
    tr: &mut Tracer,
    phong: &Phong,
    si: &Interaction,
    model: Model,
    sampling: Sampling,
) -> Option<(Vec3A, Vec3A)> {
    let (wo, n) = (si.wo, si.n);
    let frame = Frame::from_normal(n);
    let (u1, u2) = tr.sampler.next_2d();
    let wi = match sampling {
        Sampling::Uniform => frame.to_world(hemisphere::uniform(u1, u2)),
        Sampling::Cosine => frame.to_world(hemisphere::cosine(u1, u2)),
        Sampling::Brdf => {
            let pd = diffuse_probability(phong);
            if tr.sampler.next_f32() < pd {
                frame.to_world(hemisphere::cosine(u1, u2))
            } else {
                let lobe = Frame::from_normal(reflect(wo, n));
                lobe.to_world(hemisphere::phong_lobe(u1, u2, phong.shininess))
            }
        }
    };
    let cos_i = wi.dot(n);
    if cos_i <= 0.0 {
        return None;
    }
    let pdf = pdf(phong, wo, n, wi, sampling);
    if pdf <= 0.0 {
        return None;
    }
    let g = match model {
        Model::Course => reflectance(model, phong, wi, wo, n) / (TAU * TAU),
        Model::Physical => reflectance(model, phong, wi, wo, n),
    };
    Some((wi, g / pdf))
}

/// Probability of picking the diffuse lobe in BRDF sampling: the lobes' share of `kd + ks`.
pub fn diffuse_probability(phong: &Phong) -> f32 {
    let (d, s) = (phong.kd.element_sum(), phong.ks.element_sum());
    if d + s <= 0.0 { 1.0 } else { d / (d + s) }
}

/// Density per solid angle of direction `wi` under each strategy.
pub fn pdf(phong: &Phong, wo: Vec3A, n: Vec3A, wi: Vec3A, sampling: Sampling) -> f32 {
    let cos_i = wi.dot(n);
    if cos_i <= 0.0 {
        return 0.0;
    }
    match sampling {
        Sampling::Uniform => hemisphere::UNIFORM_PDF,
        Sampling::Cosine => hemisphere::cosine_pdf(cos_i),
        Sampling::Brdf => {
            let pd = diffuse_probability(phong);
            let cos_a = wi.dot(reflect(wo, n));
            pd * cos_i / PI + (1.0 - pd) * hemisphere::phong_lobe_pdf(cos_a, phong.shininess)
        }
    }
}
