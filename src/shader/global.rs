//! The assignment's global shader (Imatge Sintetica, assignment 5), with its exact weights.
//!
//! At a Phong hit the outgoing radiance is (Eq. 1) `L_o = L_dir + L_ind`, where `L_dir` is the
//! direct light of Eq. 3 and `L_ind` depends on `depth`, the number of Phong hits before this one
//! (camera rays start at depth 0; mirror and glass keep the depth):
//!
//! - `depth == D`:     `L_ind = a_t kd` (Eq. 2, the ambient term). `D = 0` is section 2.
//! - `depth == 0 < D`: `L_ind = 1/(2 pi n) sum_j L_i(w_j) r(w_j, wo)` with `n` directions uniform
//!   on the hemisphere (Eq. 4), each traced at `depth + 1`. `D = 1` is task 1 (two bounces).
//! - `0 < depth < D`:  `L_ind = 1/(4 pi) (L_i(w_n) r(w_n, wo) + L_i(w_r) r(w_r, wo))` with `w_n`
//!   the normal and `w_r` the perfect reflection of `wo`. This is task 2 (n bounces).
//!
//! **These are the course's weights, not an unbiased estimate.** With the uniform pdf
//! `1/(2 pi)`, Monte Carlo integration of `int L_i r dw` weights each sample by `2 pi / n`; Eq. 4
//! weights it by `1 / (2 pi n)`, a factor `4 pi^2` (about 39.5) smaller. Since the course's `r`
//! holds the cosine and no `1/pi`, the estimate of a diffuse surface's indirect light under a
//! uniform sky `b` is `b kd / (4 pi)` where the rendering equation gives `b kd`. The two-direction
//! step is a deterministic stand-in for the same integral. `docs/transport.md` compares them with
//! the physically based `Path` integrator.

use super::Tracer;
use super::surface::{Interaction, direct_light, reflectance, specular_bounce};
use crate::effects::kernel;
use crate::geometry::{Frame, Ray};
use crate::material::Material;
use crate::material::reflect;
use crate::render::stats::RayKind;
use crate::sampling::hemisphere;
use glam::Vec3A;
use std::f32::consts::PI;

/// Parameters of the global shader.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Global {
    /// Hemisphere samples `n` at the first Phong hit.
    pub samples: u32,
    /// `D`: the depth at which the ambient term replaces traced indirect light.
    pub max_depth: u32,
    /// Ambient radiance `a_t`.
    pub ambient: Vec3A,
    /// Longest chain of consecutive mirror/glass bounces.
    pub max_specular: u32,
}

/// Radiance along a camera ray (depth 0).
pub fn radiance<const K: u32>(tr: &mut Tracer, ray: &Ray, g: &Global) -> Vec3A {
    li::<K>(tr, g, ray, RayKind::Camera, 0, 0)
}

/// Radiance arriving along `ray`. `depth` counts Phong hits so far; `chain` counts consecutive
/// specular bounces (a safety cap, not part of the assignment).
/// `K` is the render kernel: without indirect light the ambient term stands in at every depth.
fn li<const K: u32>(
    tr: &mut Tracer,
    g: &Global,
    ray: &Ray,
    kind: RayKind,
    depth: u32,
    chain: u32,
) -> Vec3A {
    // A ray that leaves the scene: the background is its radiance.
    let Some(hit) = tr.trace::<K>(ray, kind) else {
        return tr.scene.background;
    };
    let si = Interaction::new(tr, ray, hit);
    let phong = match si.material {
        Material::Phong(p) => p,
        // Mirror or glass: follow the one scattered ray at the same depth.
        _ => {
            if chain >= g.max_specular {
                return Vec3A::ZERO;
            }
            return match specular_bounce::<K>(&si) {
                Some((next, tint, kind)) => tint * li::<K>(tr, g, &next, kind, depth, chain + 1),
                None => Vec3A::ZERO,
            };
        }
    };
    let (wo, n, model) = (si.wo, si.n, tr.scene.model);

    // Eq. 3: direct light from the point lights.
    let l_dir = direct_light::<K>(tr, &si, &phong);

    // Indirect light.
    let l_ind = if depth == g.max_depth || K & kernel::INDIRECT == 0 {
        // Eq. 2: the ambient term.
        g.ambient * phong.kd
    } else if depth == 0 {
        // Eq. 4: n uniform directions on the hemisphere around the normal.
        let frame = Frame::from_normal(n);
        let mut sum = Vec3A::ZERO;
        for _ in 0..g.samples {
            let (u1, u2) = tr.sampler.next_2d();
            let wj = frame.to_world(hemisphere::uniform(u1, u2));
            let l_i = li::<K>(tr, g, &si.spawn(wj), RayKind::Indirect, depth + 1, 0);
            sum += l_i * reflectance(model, &phong, wj, wo, n);
        }
        sum / (2.0 * PI * g.samples as f32)
    } else {
        // Task 2: Eq. 4 with the directions fixed to the normal w_n and the reflection w_r.
        let (wn, wr) = (n, reflect(wo, n));
        let l_n = li::<K>(tr, g, &si.spawn(wn), RayKind::Indirect, depth + 1, 0);
        let l_r = li::<K>(tr, g, &si.spawn(wr), RayKind::Indirect, depth + 1, 0);
        (l_n * reflectance(model, &phong, wn, wo, n) + l_r * reflectance(model, &phong, wr, wo, n))
            / (4.0 * PI)
    };

    // Eq. 1.
    l_dir + l_ind
}
