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
//!
//! No recursion: mirror and glass chains are loops carrying their tint (`follow_specular`), and
//! the tree of two-direction rays below the first Phong hit is walked with an explicit stack of
//! rays and throughputs (at most `D + 1` deep, `D` at most [`MAX_DEPTH`]). Where no hit draws
//! random numbers, the trees of all `n` directions are traced together instead, one depth at a
//! time ([`Order::Waves`]), so that the geometry answers their rays and shadow rays in SIMD
//! batches; the sums keep the depth-first order, so the image is the same to the bit.

mod waves;

pub use waves::hemisphere_rays;

use super::Tracer;
use super::surface::{ChainEnd, Interaction, direct_light, follow_specular, reflectance};
use crate::geometry::{Frame, Ray};
use crate::material::{Phong, reflect};
use crate::sampling::hemisphere;
use crate::stats::RayKind;
use glam::Vec3A;
use std::f32::consts::PI;

/// Largest `D`: the rays below the first Phong hit number `n 2^(D-1)` per pixel.
pub const MAX_DEPTH: u32 = 16;

/// Parameters of the global shader.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Global {
    /// Hemisphere samples `n` at the first Phong hit.
    pub samples: u32,
    /// `D`: the depth at which the ambient term replaces traced indirect light, at most
    /// [`MAX_DEPTH`].
    pub max_depth: u32,
    /// Ambient radiance `a_t`.
    pub ambient: Vec3A,
    /// Longest chain of consecutive mirror/glass bounces, at most [`super::MAX_SPECULAR`].
    pub max_specular: u32,
    /// Area-light samples per shading point (Eq. 3 with area lights).
    pub light_samples: u32,
}

/// Radiance along a camera ray (depth 0).
pub fn radiance(tr: &mut Tracer, ray: &Ray, g: &Global) -> Vec3A {
    // Follow mirrors and glass to the first Phong hit; they keep the depth. The camera sees
    // the emitters on the way.
    let (end, le) = follow_specular(tr, ray, RayKind::Camera, g.max_specular, true);
    le + match end {
        ChainEnd::Phong { si, phong, beta } => beta * first_hit(tr, g, &si, &phong),
        ChainEnd::Escaped { beta, sky } => beta * sky,
        // Eq. 1-4 are Phong's: a BSDF surface is black, as in the waves (scene files with
        // one are refused with Global; see `docs/transport.md`).
        ChainEnd::Bsdf { .. } | ChainEnd::Absorbed => Vec3A::ZERO,
    }
}

/// Eq. 1 at the first Phong hit (depth 0).
fn first_hit(tr: &mut Tracer, g: &Global, si: &Interaction, phong: &Phong) -> Vec3A {
    let (wo, n, model) = (si.wo, si.n, tr.model);

    // Eq. 3: direct light from the point lights (and the area lights).
    let l_dir = direct_light(tr, si, phong, g.light_samples);

    // Indirect light.
    let l_ind = if g.max_depth == 0 || !tr.effects.indirect {
        // Eq. 2: the ambient term (D = 0, section 2).
        g.ambient * phong.kd
    } else {
        // Eq. 4: n uniform directions on the hemisphere around the normal, each traced at
        // depth 1.
        let frame = Frame::from_normal(n);
        let mut sum = Vec3A::ZERO;
        if waves::applies(tr, g) {
            // The same directions, drawn in order, and the same sums; each group's rays
            // traced together in waves.
            let group = waves::group(g);
            let (mut us, mut w, mut rays) = (
                Vec::with_capacity(group),
                Vec::with_capacity(group),
                Vec::with_capacity(group),
            );
            let mut left = g.samples as usize;
            while left > 0 {
                let k = left.min(group);
                left -= k;
                // The numbers drawn in order; the directions and their rays made in lanes.
                us.clear();
                us.extend((0..k).map(|_| tr.sampler.next_2d()));
                w.clear();
                rays.clear();
                waves::hemisphere_rays(tr, &frame, &si.origins, &us, (&mut w, &mut rays));
                let l = incident_all(tr, g, &rays, Order::Waves);
                for (l_i, &wj) in l.iter().zip(&w) {
                    sum += *l_i * reflectance(model, phong, wj, wo, n);
                }
            }
        } else {
            // Where the waves do not apply (light samples at the hits below draw random
            // numbers, or the tree or the lights exceed their bounds), each direction's tree
            // is walked before the next direction is drawn.
            let mut stack = Vec::with_capacity(g.max_depth as usize + 1);
            for _ in 0..g.samples {
                let (u1, u2) = tr.sampler.next_2d();
                let wj = frame.to_world(hemisphere::uniform(u1, u2));
                // A normal-mapped surface takes no light through itself.
                if si.leaks(wj) {
                    continue;
                }
                let l_i = incident(tr, g, si.spawn(wj), &mut stack);
                sum += l_i * reflectance(model, phong, wj, wo, n);
            }
        }
        sum / (2.0 * PI * g.samples as f32)
    };

    // Eq. 1.
    l_dir + l_ind
}

/// The order in which the rays below the first Phong hit are traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Order {
    /// Each direction's tree depth first, one ray at a time: the reference.
    DepthFirst,
    /// All trees together, one depth at a time, rays in batches (`waves.rs`); the same bits
    /// where [`Order::applies`].
    Waves,
}

impl Order {
    /// True if this order gives the depth-first walk's bits for `g` in `tr`'s scene: always for
    /// the walk; for the waves, when `D >= 1`, no hit draws random numbers (no area-light
    /// samples), `D <= 8` and there are at most 64 point lights (their memory bounds).
    pub fn applies(self, tr: &Tracer, g: &Global) -> bool {
        match self {
            Order::DepthFirst => true,
            Order::Waves => waves::applies(tr, g),
        }
    }
}

/// `L_i` along each of `rays` (indirect rays leaving the first Phong hit, traced at depth 1)
/// in `order`, with no random numbers drawn between them. Where `order` applies, every order
/// gives the same bits and counts the same rays (`tests/integration/global_waves.rs` checks it).
pub fn incident_all(tr: &mut Tracer, g: &Global, rays: &[Ray], order: Order) -> Vec<Vec3A> {
    assert!(order.applies(tr, g), "{order:?} does not apply");
    match order {
        Order::DepthFirst => {
            let mut stack = Vec::with_capacity(g.max_depth as usize + 1);
            rays.iter()
                .map(|r| incident(tr, g, *r, &mut stack))
                .collect()
        }
        Order::Waves => waves::incident(tr, g, rays),
    }
}

/// A ray still to be traced below the first Phong hit, with the weight `beta` its radiance
/// carries into the pixel's estimate and the depth it is traced at.
#[derive(Clone, Copy)]
pub struct Pending {
    ray: Ray,
    beta: Vec3A,
    depth: u32,
}

/// `L_i` along `ray`, an indirect ray leaving the first Phong hit (traced at depth 1).
///
/// Each Phong hit at `0 < depth < D` adds its direct light and sends two rays (task 2); at
/// depth `D` the ambient term stands in for the rest (Eq. 2). The tree is walked depth first
/// with `stack` (empty on entry and on return): each step pops one ray and pushes at most two,
/// so it never holds more than `D + 1`.
fn incident(tr: &mut Tracer, g: &Global, ray: Ray, stack: &mut Vec<Pending>) -> Vec3A {
    stack.push(Pending {
        ray,
        beta: Vec3A::ONE,
        depth: 1,
    });
    let mut l = Vec3A::ZERO;
    let model = tr.model;
    while let Some(Pending { ray, beta, depth }) = stack.pop() {
        // Mirrors and glass keep the depth. An emitter this ray hits first is the direct light
        // of the hit it left (counted there); one seen through mirrors or glass counts here.
        let (end, le) = follow_specular(tr, &ray, RayKind::Indirect, g.max_specular, false);
        l += beta * le;
        let (si, phong, beta) = match end {
            ChainEnd::Phong { si, phong, beta: b } => (si, phong, beta * b),
            ChainEnd::Escaped { beta: b, sky } => {
                l += beta * b * sky;
                continue;
            }
            ChainEnd::Bsdf { .. } | ChainEnd::Absorbed => continue,
        };
        // Eq. 3 at this hit.
        let l_dir = direct_light(tr, &si, &phong, g.light_samples);
        if depth >= g.max_depth || !tr.effects.indirect {
            // Eq. 2: the ambient term ends the path.
            l += beta * (l_dir + g.ambient * phong.kd);
            continue;
        }
        l += beta * l_dir;
        // Task 2: Eq. 4 with the directions fixed to the normal w_n and the reflection w_r,
        // weighted by 1 / (4 pi).
        let (wo, n) = (si.wo, si.n);
        for w in [reflect(wo, n), n] {
            stack.push(Pending {
                ray: si.spawn(w),
                beta: beta * reflectance(model, &phong, w, wo, n) / (4.0 * PI),
                depth: depth + 1,
            });
        }
    }
    l
}
