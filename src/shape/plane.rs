//! Infinite planes.

use super::{Surface, point_error};
use crate::geometry::{Placement, Ray};
use glam::Vec3A;

/// The two-sided plane `{p : n.p = dist}` with unit normal `n`.
#[derive(Clone, Copy, Debug)]
pub struct Plane {
    /// Unit normal.
    pub n: Vec3A,
    /// Signed distance from the origin along `n`.
    pub dist: f32,
}

impl Plane {
    /// The plane through `point` with normal `normal` (scene units) placed by `at`.
    pub fn placed(point: glam::DVec3, normal: glam::DVec3, at: &Placement) -> Self {
        Plane::through(at.point(point), at.normal(normal))
    }

    /// The plane through `point` with unit normal `n`.
    pub fn through(point: Vec3A, n: Vec3A) -> Self {
        Plane {
            n,
            dist: n.dot(point),
        }
    }

    /// Distance to the plane in `(0, t_max]`; `None` for rays parallel to it.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        let denom = self.n.dot(ray.d);
        if denom == 0.0 {
            return None;
        }
        let t = (self.dist - self.n.dot(ray.o)) / denom;
        (t > 0.0 && t <= ray.t_max).then_some(t)
    }

    /// Hit point projected onto the plane, its normal, error bound.
    #[inline]
    pub fn surface(&self, ray: &Ray, t: f32) -> Surface {
        let p = ray.at(t);
        let p = p - (self.n.dot(p) - self.dist) * self.n;
        Surface {
            p,
            n: self.n,
            err: point_error(p.abs().max_element().max(self.dist.abs())),
        }
    }
}
