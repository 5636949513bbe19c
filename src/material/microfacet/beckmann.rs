//! The Beckmann distribution: Gaussian slopes, `D = exp(-e) / (pi ax ay cos^4(theta_m))` with
//! `e` the roughness-scaled squared slope (Walter et al. 2007, section 5.1).

use crate::sampling::erf_inv;
use glam::Vec3A;
use std::f64::consts::PI;

/// `D` without its factor `1 / (pi ax ay cos^4(theta_m))`, from the scaled squared slope `e`.
#[inline]
pub(super) fn d(e: f32) -> f32 {
    (-e).exp()
}

/// Smith's `Lambda` from `t2 = alpha(phi)^2 tan^2(theta)`: with `a = 1 / sqrt(t2)`,
/// `(erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi))` (the exact form: Walter et al. 2007,
/// section 5.1; Heitz 2014, eq. 80), written with `erfc` and in double precision, where the two
/// terms nearly cancel for large `a`.
#[inline]
pub(super) fn lambda(t2: f32) -> f32 {
    if t2 <= 0.0 {
        return 0.0;
    }
    let a = 1.0 / (t2 as f64).sqrt();
    if a > 26.0 {
        // Both terms are below 1e-290, far below what an f32 holds: no facet is hidden.
        return 0.0;
    }
    (((-a * a).exp() / (a * PI.sqrt()) - libm::erfc(a)) / 2.0).max(0.0) as f32
}

/// The squared radius of a unit-roughness slope of density `P22 = exp(-r^2) / pi`, from `u` in
/// `[0, 1)`: its radial CDF is `1 - exp(-r^2)`.
#[inline]
pub(super) fn slope_radius2(u: f32) -> f32 {
    -(-u).ln_1p()
}

/// A normal visible from `w` (above the surface): the viewer is stretched to unit roughness,
/// its visible slopes are drawn in the plane of incidence ([`visible_slopes`]), turned to its
/// azimuth and stretched back (Heitz and d'Eon 2014, section 4).
#[inline]
pub(super) fn sample_visible(w: Vec3A, ax: f32, ay: f32, u1: f32, u2: f32) -> Vec3A {
    let wh = Vec3A::new(ax * w.x, ay * w.y, w.z).normalize();
    let (x, y) = visible_slopes(wh.z as f64, u1 as f64, u2 as f64);
    // The azimuth of the stretched viewer.
    let r = (wh.x * wh.x + wh.y * wh.y).sqrt();
    let (cos_p, sin_p) = if r > 0.0 {
        ((wh.x / r) as f64, (wh.y / r) as f64)
    } else {
        (1.0, 0.0)
    };
    let sx = (cos_p * x - sin_p * y) as f32 * ax;
    let sy = (sin_p * x + cos_p * y) as f32 * ay;
    super::from_slopes(sx, sy)
}

/// Unit-roughness slopes `(x, y)` visible from a viewer at `cos(theta) = cos_t` in the `xz`
/// plane (towards +x). `y` is Gaussian (`P2(y) = exp(-y^2) / sqrt(pi)`) and independent; `x` has
/// the density of slopes weighted by their projected area `(1 - x tan(theta))` for `x <
/// cot(theta)`, whose CDF is
/// `C(x) = (1 + erf(x) + tan(theta) exp(-x^2) / sqrt(pi)) / (1 + erf(cot) + tan(theta)
/// exp(-cot^2) / sqrt(pi))`; it is inverted by Newton's method kept inside a bracket.
pub(super) fn visible_slopes(cos_t: f64, u1: f64, u2: f64) -> (f64, f64) {
    // The ends of [0, 1) map to infinite slopes (a normal of NaN): keep the numbers 1e-12
    // inside, which moves a slope past 5 standard deviations by less than rounding.
    let (u1, u2) = (u1.clamp(1e-12, 1.0 - 1e-12), u2.clamp(1e-12, 1.0 - 1e-12));
    let y = erf_inv(2.0 * u2 - 1.0);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    if sin_t < 1e-6 {
        // Normal incidence: every slope is visible, the Gaussian itself.
        return (erf_inv(2.0 * u1 - 1.0), y);
    }
    let tan_t = sin_t / cos_t;
    let cot = cos_t / sin_t;
    let k = 1.0 / PI.sqrt();
    let unnormalised = |x: f64| 1.0 + libm::erf(x) + tan_t * k * (-x * x).exp();
    let target = u1 * unnormalised(cot);
    // The bracket: C is 1 at cot, and below -7 it is 0 to 1e-22.
    let (mut lo, mut hi) = (-7.0f64, cot);
    let mut x = 0.5 * (lo + hi);
    for _ in 0..64 {
        let f = unnormalised(x) - target;
        if f.abs() < 1e-12 {
            break;
        }
        if f > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        // C'(x) is proportional to exp(-x^2) (1 - x tan(theta)).
        let df = 2.0 * k * (-x * x).exp() * (1.0 - x * tan_t);
        let next = x - f / df;
        x = if df > 0.0 && next > lo && next < hi {
            next
        } else {
            0.5 * (lo + hi)
        };
        if hi - lo < 1e-13 {
            break;
        }
    }
    (x, y)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The visible slopes' CDF is inverted: `C(x(u)) = u`, at incidences from near-normal to
    /// grazing.
    #[test]
    fn visible_slopes_invert_their_cdf() {
        for cos_t in [0.999_999, 0.9, 0.5, 0.1, 0.01] {
            let sin_t = (1.0f64 - cos_t * cos_t).sqrt();
            let (tan_t, cot) = (sin_t / cos_t, cos_t / sin_t);
            let c = |x: f64| 1.0 + libm::erf(x) + tan_t / PI.sqrt() * (-x * x).exp();
            for i in 0..100 {
                let u = (i as f64 + 0.5) / 100.0;
                let (x, _) = visible_slopes(cos_t, u, 0.5);
                assert!(x <= cot + 1e-12, "cos {cos_t} u {u}: x {x} above cot {cot}");
                let got = c(x) / c(cot);
                assert!((got - u).abs() < 1e-9, "cos {cos_t} u {u}: C(x) = {got}");
            }
        }
    }
}
