//! The GGX (Trowbridge-Reitz) distribution: `D = 1 / (pi ax ay cos^4(theta_m) (1 + e)^2)` with
//! `e` the roughness-scaled squared slope (Walter et al. 2007, section 5.2; Heitz 2014, eq. 85
//! for the anisotropic form).

use glam::Vec3A;

/// `D` without its factor `1 / (pi ax ay cos^4(theta_m))`, from the scaled squared slope `e`.
#[inline]
pub(super) fn d(e: f32) -> f32 {
    let k = 1.0 + e;
    1.0 / (k * k)
}

/// Smith's `Lambda` from `t2 = alpha(phi)^2 tan^2(theta)`: `(sqrt(1 + t2) - 1) / 2` (Heitz 2014,
/// eq. 86), written as `t2 / (2 (sqrt(1 + t2) + 1))` so that small slopes lose no digits.
#[inline]
pub(super) fn lambda(t2: f32) -> f32 {
    if t2.is_infinite() {
        return f32::INFINITY;
    }
    t2 / (2.0 * ((1.0 + t2).sqrt() + 1.0))
}

/// The squared radius of a unit-roughness slope of density `P22 = 1 / (pi (1 + r^2)^2)`, from
/// `u` in `[0, 1)`: its radial CDF is `1 - 1 / (1 + r^2)`.
#[inline]
pub(super) fn slope_radius2(u: f32) -> f32 {
    u / (1.0 - u)
}

/// A normal visible from `w` (above the surface), by spherical caps (Dupuy and Benyoub 2023):
/// in the configuration stretched to unit roughness, the visible normals of the hemisphere are
/// the halfway vectors between `w` and a uniform point of the spherical cap `z >= -w.z`; the
/// normal is then stretched back (Heitz 2018, "Sampling the GGX distribution of visible
/// normals", section 3).
#[inline]
pub(super) fn sample_visible(w: Vec3A, ax: f32, ay: f32, u1: f32, u2: f32) -> Vec3A {
    // The viewer in the unit-roughness configuration.
    let wh = Vec3A::new(ax * w.x, ay * w.y, w.z).normalize();
    // A uniform point of the cap: `z` uniform on [-wh.z, 1], `phi` uniform.
    let z = (1.0 - u2) * (1.0 + wh.z) - wh.z;
    let sin_t = (1.0 - z * z).clamp(0.0, 1.0).sqrt();
    let (sin_p, cos_p) = crate::sampling::sin_cos_turns(u1);
    let h = Vec3A::new(sin_t * cos_p, sin_t * sin_p, z) + wh;
    // Back to the rough configuration (normals stretch like the viewer here).
    Vec3A::new(ax * h.x, ay * h.y, h.z.max(0.0)).normalize()
}
