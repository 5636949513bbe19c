//! Hemisphere warps: uniform (the course's sampler) and cosine-weighted, with their pdfs.
//!
//! Each warp returns a direction in the local frame (z = normal); use
//! [`crate::geometry::Frame`] to take it to world space.

use super::sin_cos_turns;
use glam::Vec3A;
use std::f32::consts::{FRAC_1_PI, PI, TAU};

/// Uniform direction on the hemisphere z >= 0: `cos(theta) = u1`, `phi = 2 pi u2` (the course's).
#[inline]
pub fn uniform(u1: f32, u2: f32) -> Vec3A {
    let cos_t = u1;
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let (sin_p, cos_p) = sin_cos_turns(u2);
    Vec3A::new(sin_t * cos_p, sin_t * sin_p, cos_t)
}

/// Density of [`uniform`] per unit solid angle: `1 / (2 pi)`.
pub const UNIFORM_PDF: f32 = 1.0 / TAU;

/// Cosine-weighted direction on the hemisphere z >= 0 (Malley's method: a uniform disk point
/// lifted onto the hemisphere).
#[inline]
pub fn cosine(u1: f32, u2: f32) -> Vec3A {
    let r = u1.sqrt();
    let (sin_p, cos_p) = sin_cos_turns(u2);
    let (x, y) = (r * cos_p, r * sin_p);
    Vec3A::new(x, y, (1.0 - x * x - y * y).max(0.0).sqrt())
}

/// Density of [`cosine`] per unit solid angle: `cos(theta) / pi`.
#[inline]
pub fn cosine_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// Direction around the z axis with density proportional to `cos(alpha)^s`, `alpha` the angle to
/// z (the normalised Phong lobe, sampled for the physically based model).
#[inline]
pub fn phong_lobe(u1: f32, u2: f32, s: f32) -> Vec3A {
    let cos_a = u1.powf(1.0 / (s + 1.0));
    let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
    let (sin_p, cos_p) = sin_cos_turns(u2);
    Vec3A::new(sin_a * cos_p, sin_a * sin_p, cos_a)
}

/// Density of [`phong_lobe`] per unit solid angle: `(s + 1) / (2 pi) cos(alpha)^s`.
#[inline]
pub fn phong_lobe_pdf(cos_alpha: f32, s: f32) -> f32 {
    if cos_alpha <= 0.0 {
        0.0
    } else {
        (s + 1.0) / (2.0 * PI) * cos_alpha.powf(s)
    }
}
