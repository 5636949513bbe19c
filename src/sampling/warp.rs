//! Warps onto shapes, for sampling area lights and lenses: the whole sphere, a cone of
//! directions, a triangle and a disk, each uniform in its own measure.

use glam::Vec3A;

/// Uniform direction on the unit sphere: `z = 1 - 2 u1`, `phi = 2 pi u2`. Density `1 / (4 pi)`.
#[inline]
pub fn uniform_sphere(u1: f32, u2: f32) -> Vec3A {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin_p, cos_p) = super::sin_cos_turns(u2);
    Vec3A::new(r * cos_p, r * sin_p, z)
}

/// Uniform barycentric coordinates `(b0, b1, b2)` on a triangle (Heitz 2019, the low-distortion
/// map pbrt-v4 uses): a point `b0 v0 + b1 v1 + b2 v2` is uniform in area.
#[inline]
pub fn uniform_triangle(u1: f32, u2: f32) -> [f32; 3] {
    // Both halves computed and one kept by a select, not a branch: `u1 < u2` is a coin toss
    // to the branch predictor.
    let (h1, h2) = (u1 / 2.0, u2 / 2.0);
    let lower = u1 < u2;
    let b0 = select(lower, h1, u1 - h2);
    let b1 = select(lower, u2 - h1, h2);
    [b0, b1, (1.0 - b0 - b1).max(0.0)]
}

/// `a` if `c`, else `b`, without a branch (as a conditional move).
#[inline(always)]
fn select(c: bool, a: f32, b: f32) -> f32 {
    let m = (c as u32).wrapping_neg();
    f32::from_bits((a.to_bits() & m) | (b.to_bits() & !m))
}

/// A uniform point on the unit disk by Shirley and Chiu's concentric map ("A Low Distortion Map
/// Between Disk and Square", 1997, as pbrt-v4's `SampleUniformDiskConcentric`): the square
/// `[-1, 1]^2` is cut into four triangles and each is mapped to a quarter of the disk, so
/// nearby samples stay nearby. Density `1 / pi`.
#[inline]
pub fn concentric_disk(u1: f32, u2: f32) -> (f32, f32) {
    let (a, b) = (2.0 * u1 - 1.0, 2.0 * u2 - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let (r, theta) = if a.abs() > b.abs() {
        (a, std::f32::consts::FRAC_PI_4 * (b / a))
    } else {
        (
            b,
            std::f32::consts::FRAC_PI_2 - std::f32::consts::FRAC_PI_4 * (a / b),
        )
    };
    let (sin_t, cos_t) = theta.sin_cos();
    (r * cos_t, r * sin_t)
}

/// `1 - cos(theta_max)` of the cone a sphere of radius `r` subtends from a point at squared
/// distance `d2 > r^2` from its centre, with `sin^2(theta_max) = r^2 / d2`: computed as
/// `sin^2 / (1 + cos)`, which is the same number without the cancellation of `1 - cos` for
/// small cones (a light of radius 0.03 at distance 6 has `sin^2 = 2.5e-5`).
#[inline]
pub fn cone_one_minus_cos(sin2_max: f32) -> f32 {
    sin2_max / (1.0 + (1.0 - sin2_max).max(0.0).sqrt())
}
