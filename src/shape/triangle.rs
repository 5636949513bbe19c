//! Triangles with the watertight test of Woop, Benthin and Wald (JCGT 2013).

use super::Surface;
use crate::geometry::{Aabb, BvhRay, Ray, gamma};
use glam::Vec3A;

/// A two-sided triangle with vertices `v0, v1, v2` and unit winding normal
/// `n = normalize((v1 - v0) x (v2 - v0))`.
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    /// Vertices.
    pub v: [Vec3A; 3],
    /// Unit normal by winding order.
    pub n: Vec3A,
}

impl Triangle {
    /// The triangle with these vertices, or `None` if it has zero area (it would never be hit).
    pub fn new(v0: Vec3A, v1: Vec3A, v2: Vec3A) -> Option<Self> {
        let (e1, e2) = (v1 - v0, v2 - v0);
        // The cross product and its length written out: the leaf blocks of the BVH compute
        // the same normal in lanes with these operations, in this order, to the same bits.
        let c = Vec3A::new(
            e1.y * e2.z - e1.z * e2.y,
            e1.z * e2.x - e1.x * e2.z,
            e1.x * e2.y - e1.y * e2.x,
        );
        let len = (c.x * c.x + c.y * c.y + c.z * c.z).sqrt();
        (len > 0.0 && len.is_finite()).then(|| Triangle {
            v: [v0, v1, v2],
            n: c / len,
        })
    }

    /// Distance to the triangle in `(0, t_max]`.
    ///
    /// Watertight: vertices are translated to the ray origin and sheared so the ray runs along
    /// +z; the three 2D edge functions are exact negations across a shared edge, and an edge
    /// function that is exactly zero is decided by a top-left rule, so a ray through an edge
    /// shared by two triangles hits exactly one of them, and never falls through the crack.
    ///
    /// `ray` must carry the test's axes and shear: from [`BvhRay::new`] or [`BvhRay::sheared`]
    /// (without, they are placeholders and the answer is wrong).
    #[inline]
    pub fn intersect(&self, ray: &BvhRay) -> Option<f32> {
        let [kx, ky, kz] = ray.k;
        let [sx, sy, sz] = ray.shear;
        let a = self.v[0] - ray.o;
        let b = self.v[1] - ray.o;
        let c = self.v[2] - ray.o;
        let (ax, ay) = (a[kx] - sx * a[kz], a[ky] - sy * a[kz]);
        let (bx, by) = (b[kx] - sx * b[kz], b[ky] - sy * b[kz]);
        let (cx, cy) = (c[kx] - sx * c[kz], c[ky] - sy * c[kz]);
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // Retry the edge functions in double precision, as the paper does.
            let e = |px: f32, py: f32, qx: f32, qy: f32| {
                (qx as f64 * py as f64 - qy as f64 * px as f64) as f32
            };
            u = e(bx, by, cx, cy);
            v = e(cx, cy, ax, ay);
            w = e(ax, ay, bx, by);
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        // On an edge (edge function exactly 0): keep the hit only for a top-left edge, judged in
        // the triangle's own orientation so that the two owners of an edge disagree.
        let s = det.signum();
        let top_left = |px: f32, py: f32, qx: f32, qy: f32| {
            let (ex, ey) = (s * (qx - px), s * (qy - py));
            ey > 0.0 || (ey == 0.0 && ex < 0.0)
        };
        if (u == 0.0 && !top_left(bx, by, cx, cy))
            || (v == 0.0 && !top_left(cx, cy, ax, ay))
            || (w == 0.0 && !top_left(ax, ay, bx, by))
        {
            return None;
        }
        let (az, bz, cz) = (sz * a[kz], sz * b[kz], sz * c[kz]);
        let t_scaled = u * az + v * bz + w * cz;
        let t = t_scaled / det;
        if t <= 0.0 || t > ray.t_max {
            return None;
        }
        // A ray that starts on the triangle's plane (within the error band of the origin's
        // signed distance `n.(v0 - o)`, as for planes) does not meet it at its start.
        let an = self.n.abs();
        let band = gamma(5) * an.dot(self.v[0].abs() + ray.o.abs()) + an.element_sum() * ray.o_err;
        (t * self.n.dot(ray.d).abs() > band).then_some(t)
    }

    /// Hit point projected onto the triangle's plane, the winding normal, and its error
    /// bounds, as for a plane: `gamma(7)` of the coordinates involved across the plane (one
    /// more rounding for `p - v0`), and the error of `t` along it.
    #[inline]
    pub fn surface(&self, ray: &Ray, t: f32) -> Surface {
        let p = ray.at(t);
        let p = p - self.n.dot(p - self.v[0]) * self.n;
        let scale = self.v[0]
            .abs()
            .max(self.v[1].abs())
            .max(self.v[2].abs())
            .max(p.abs())
            .max_element();
        let an = self.n.abs();
        let dt = gamma(5) * an.dot(self.v[0].abs() + ray.o.abs()) / self.n.dot(ray.d).abs();
        Surface {
            p,
            n: self.n,
            err: gamma(7) * scale,
            err_along: dt + gamma(3) * (ray.o.abs().max_element() + t.abs()),
        }
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        Aabb::EMPTY.grow(self.v[0]).grow(self.v[1]).grow(self.v[2])
    }
}
