//! Spheres.

use super::{Surface, point_error};
use crate::geometry::{Aabb, Placement, Ray};
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

    /// Nearest root of `|o + t d - c|^2 = r^2` in `(0, t_max]`.
    ///
    /// Uses the cancellation-free form of Haines et al. (Ray Tracing Gems, ch. 7): the
    /// discriminant is `r^2 - |f - (f.d) d|^2` and the two roots are `c/q` and `q`, so grazing
    /// rays and far-away spheres stay accurate.
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
        let c = f.length_squared() - r2;
        let q = b + disc.sqrt().copysign(b);
        if q == 0.0 {
            // Origin at the centre of a zero-size configuration: no usable root.
            return None;
        }
        let (t0, t1) = {
            let (a, b) = (c / q, q);
            if a <= b { (a, b) } else { (b, a) }
        };
        if t0 > 0.0 && t0 <= ray.t_max {
            Some(t0)
        } else if t1 > 0.0 && t1 <= ray.t_max {
            Some(t1)
        } else {
            None
        }
    }

    /// Hit point projected back onto the sphere, outward normal, error bound.
    #[inline]
    pub fn surface(&self, ray: &Ray, t: f32) -> Surface {
        let n = (ray.at(t) - self.c).normalize();
        let p = self.c + self.r * n;
        Surface {
            p,
            n,
            err: point_error(self.c.abs().max_element() + self.r),
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
