//! Spheres.

use super::Surface;
use crate::geometry::{Aabb, Placement, Ray, gamma};
use glam::Vec3A;

/// A sphere of centre `c` and radius `r > 0`.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    /// Centre.
    pub c: Vec3A,
    /// Radius.
    pub r: f32,
}

impl Sphere {
    /// The sphere of `radius` around `center` (scene units) placed by `at`.
    pub fn placed(center: glam::DVec3, radius: f64, at: &Placement) -> Self {
        Sphere {
            c: at.point(center),
            r: at.length(radius),
        }
    }

    /// Nearest root of `|o + t d - c|^2 = r^2` in `(0, t_max]`, not counting the start of a
    /// ray that starts on the sphere.
    ///
    /// Uses the cancellation-free form of Haines et al. (Ray Tracing Gems, ch. 7): the
    /// discriminant is `r^2 - |f - (f.d) d|^2` and the two roots are `c/q` and `q`, so grazing
    /// rays and far-away spheres stay accurate.
    ///
    /// `c = |f|^2 - r^2` says where the origin is: its rounding error is at most
    /// `gamma(5) (|f|^2 + r^2)`, and the error `e_f` of `f` (the origin's `o_err` and the
    /// rounding of `o - c`) moves it by at most `4 |f| e_f <= 2 e_f (|f|^2 / r + r)`. Within
    /// that band the origin is on the sphere, and the root nearer zero is the ray's own start:
    /// only the other root can be a hit, and only beyond the band's distance (a ray tangent at
    /// its start meets nothing).
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        let f = ray.o - self.c;
        let b = -f.dot(ray.d);
        let l = f + b * ray.d;
        let r2 = self.r * self.r;
        let disc = r2 - l.length_squared();
        if disc < 0.0 {
            return None;
        }
        let f2 = f.length_squared();
        let c = f2 - r2;
        let q = b + disc.sqrt().copysign(b);
        if q == 0.0 {
            // Origin at the centre of a zero-size configuration: no usable root.
            return None;
        }
        let (t0, t1) = {
            let (a, b) = (c / q, q);
            if a <= b { (a, b) } else { (b, a) }
        };
        let band = self.band(ray, f2);
        if c.abs() <= band {
            // The origin is on the sphere: the root nearer zero is where the ray starts.
            let t = if t0.abs() <= t1.abs() { t1 } else { t0 };
            let t_min = band / (f2.sqrt() + self.r);
            return (t > t_min && t <= ray.t_max).then_some(t);
        }
        if t0 > 0.0 && t0 <= ray.t_max {
            Some(t0)
        } else if t1 > 0.0 && t1 <= ray.t_max {
            Some(t1)
        } else {
            None
        }
    }

    /// The error band of `c = |f|^2 - r^2` for a ray whose `|f|^2` is `f2` (see
    /// [`Sphere::intersect`]).
    #[inline]
    pub fn band(&self, ray: &Ray, f2: f32) -> f32 {
        let e_f = ray.o_err
            + gamma(1) * ray.o.abs().max_element()
            + gamma(1) * self.c.abs().max_element();
        gamma(5) * (f2 + self.r * self.r) + 2.0 * e_f * (f2 * (1.0 / self.r) + self.r)
    }

    /// Hit point projected back onto the sphere, outward normal, and its error bounds.
    ///
    /// The reprojection `c + r normalize(o + t d - c)` puts the point on the sphere up to the
    /// roundings of the normalisation, the scaling and the sum: `gamma(6) (|c| + r)` across
    /// the surface. Along it the point keeps the error of `t`: the rounding of
    /// `c = |f|^2 - r^2`, divided by the rate `2 r |cos|` at which `c` changes along the ray
    /// (large for grazing rays, where the root is ill-conditioned; at most the diameter).
    #[inline]
    pub fn surface(&self, ray: &Ray, t: f32) -> Surface {
        let n = (ray.at(t) - self.c).normalize();
        let p = self.c + self.r * n;
        let f = ray.o - self.c;
        let ec = gamma(5) * (f.length_squared() + self.r * self.r);
        let rate = 2.0 * self.r * n.dot(ray.d).abs();
        let dt = if ec < rate * 2.0 * self.r {
            ec / rate
        } else {
            2.0 * self.r
        };
        Surface {
            p,
            n,
            err: gamma(6) * (self.c.abs().max_element() + self.r),
            err_along: dt + gamma(3) * (ray.o.abs().max_element() + t.abs()),
        }
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: self.c - Vec3A::splat(self.r),
            max: self.c + Vec3A::splat(self.r),
        }
    }
}

/// A sphere's texture coordinates (Mitsuba 3's) at the unit direction `d` from its centre:
/// `u = phi / (2 pi)` with `phi = atan2(y, x)` in [0, 2 pi), `v = theta / pi` with `theta =
/// acos(z)`.
#[inline]
pub fn sphere_uv(d: Vec3A) -> glam::Vec2 {
    let d = d.clamp(Vec3A::splat(-1.0), Vec3A::ONE);
    let phi = d.y.atan2(d.x).rem_euclid(std::f32::consts::TAU);
    let u = phi / std::f32::consts::TAU;
    glam::Vec2::new(
        if u >= 1.0 { 0.0 } else { u },
        d.z.acos() / std::f32::consts::PI,
    )
}
