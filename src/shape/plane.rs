//! Infinite planes.

use super::Surface;
use crate::geometry::{Placement, Ray, gamma};
use glam::Vec3A;

/// The two-sided plane `{p : n.p = dist}` with unit normal `n`.
///
/// A plane that no ray may cross (one that does not refract) and that has every camera ray
/// start strictly on one side is *oriented* towards that side (`side`): every ray then starts
/// on that side, or within the plane's error band (see [`Plane::intersect`]).
#[derive(Clone, Copy, Debug)]
pub struct Plane {
    /// Unit normal.
    pub n: Vec3A,
    /// Signed distance from the origin along `n`.
    pub dist: f32,
    /// The side rays are kept on: `1` where `n.p > dist`, `-1` where `n.p < dist`, `0` for
    /// none (the plane is not oriented: rays may be on either side).
    pub side: f32,
    /// The point it was given with, where its texture coordinates start.
    pub origin: Vec3A,
}

impl Plane {
    /// The plane through `point` with normal `normal` (scene units) placed by `at`.
    pub fn placed(point: glam::DVec3, normal: glam::DVec3, at: &Placement) -> Self {
        // The distance is taken in double precision and rounded once, so the plane is the one
        // through `point` for the rounded normal, to one rounding.
        let n = at.normal(normal);
        Plane {
            n,
            dist: n.as_dvec3().dot(at.point_f64(point)) as f32,
            side: 0.0,
            origin: at.point(point),
        }
    }

    /// The plane through `point` with unit normal `n`.
    pub fn through(point: Vec3A, n: Vec3A) -> Self {
        Plane {
            n,
            dist: n.dot(point),
            side: 0.0,
            origin: point,
        }
    }

    /// This plane oriented towards `side` (`1`, `-1`, or `0` for none).
    pub fn oriented(self, side: f32) -> Self {
        Plane { side, ..self }
    }

    /// The side every point of `starts` lies on beyond the band (`1` or `-1`), or `0` when one
    /// is within it or they lie on both sides: the side to orient a plane no ray crosses
    /// towards, given the corners of the region camera rays start from.
    ///
    /// Why every ray then stays on that side, not only camera rays: a ray that starts on a
    /// plane's side stays there until it meets the plane, so its nearest hit is on that side
    /// too. A ray spawned at that hit starts within its `o_err` of it (on either side of the
    /// surface it leaves: glass and smooth normals send rays out of the back), and the band
    /// holds `sum |n_i| o_err`; so an origin is never beyond the band on the wrong side. What
    /// rounding leaves is an origin within the band of a plane it did not start on (at a
    /// crease); an oriented plane stops such a ray if it heads out ([`Plane::intersect`]).
    pub fn facing(&self, starts: &[Vec3A]) -> f32 {
        let mut sides = starts.iter().map(|&o| self.side_of(o, 0.0));
        match sides.next() {
            Some(first) if first != 0.0 && sides.all(|x| x == first) => first,
            _ => 0.0,
        }
    }

    /// The side of the plane `p` lies on beyond the error band of a ray starting there with
    /// origin error `o_err`: `1` where `n.p > dist`, `-1` where `n.p < dist`, `0` within the
    /// band.
    pub fn side_of(&self, p: Vec3A, o_err: f32) -> f32 {
        let s = self.n.dot(p) - self.dist;
        if s.abs() <= self.band_at(p, o_err) {
            0.0
        } else {
            s.signum()
        }
    }

    /// Distance to the plane in `(0, t_max]`; `None` for rays parallel to it, and for a ray
    /// that starts on it, unless that ray leaves an oriented plane's side (below).
    ///
    /// `s = dist - n.o` is the signed distance from the origin to the plane. Its rounding error
    /// is at most `gamma(4) (|n|.|o| + |dist|)`, and the origin's own error moves it by at most
    /// `(sum |n_i|) o_err`; with `|n|.|o| <= (sum |n_i|) max |o_i|` both fit in
    /// [`Plane::band`]. Within that band the origin is on the plane: a ray that starts on a
    /// plane does not meet it there, unless it leaves an oriented plane's side. Such a ray
    /// started at a crease, on a neighbouring surface within the band, and runs into this
    /// plane: it meets it where it crosses, or at the smallest positive distance if the
    /// rounded crossing is not ahead, instead of leaking through to the other side.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        let denom = self.n.dot(ray.d);
        let s = self.dist - self.n.dot(ray.o);
        let t = if s.abs() <= self.band(ray) {
            // On the plane: only a ray leaving the side rays are kept on meets it (not a ray
            // parallel to the plane, nor a NaN direction).
            let leaving = self.side * denom < 0.0;
            if !leaving {
                return None;
            }
            (s / denom).max(f32::MIN_POSITIVE)
        } else {
            // `s` on the side `d` goes to (t > 0).
            if s * denom <= 0.0 {
                return None;
            }
            s / denom
        };
        (t <= ray.t_max).then_some(t)
    }

    /// The error band of the origin's signed distance to the plane (see [`Plane::intersect`]).
    #[inline]
    pub fn band(&self, ray: &Ray) -> f32 {
        self.band_at(ray.o, ray.o_err)
    }

    /// [`Plane::band`] for a ray from `o` whose origin error is `o_err`.
    #[inline]
    fn band_at(&self, o: Vec3A, o_err: f32) -> f32 {
        let k = gamma(4) * o.abs().max_element() + o_err;
        self.n.abs().element_sum() * k + gamma(4) * self.dist.abs()
    }

    /// Hit point projected onto the plane, its normal, and its error bounds.
    ///
    /// The projection puts the point on the plane up to the roundings of `n.p - dist`, the
    /// product and the subtraction: `gamma(6) (|p| + |dist|)` across the plane. Along the plane
    /// the point keeps the error of `t`: the rounding of `s` (`gamma(4) (|n|.|o| + |dist|)`)
    /// divided by `|n.d|`, and a few roundings of `o + t d`.
    #[inline]
    pub fn surface(&self, ray: &Ray, t: f32) -> Surface {
        let p = ray.at(t);
        let p = p - (self.n.dot(p) - self.dist) * self.n;
        let an = self.n.abs();
        let dt = gamma(4) * (an.dot(ray.o.abs()) + self.dist.abs()) / self.n.dot(ray.d).abs();
        Surface {
            p,
            n: self.n,
            err: gamma(6) * (p.abs().max_element() + self.dist.abs()),
            err_along: dt + gamma(3) * (ray.o.abs().max_element() + t.abs()),
        }
    }
}
