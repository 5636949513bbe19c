//! Axis-aligned bounding boxes.

use glam::Vec3A;

/// An axis-aligned box; the empty box has `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3A,
    /// Largest corner.
    pub max: Vec3A,
}

impl Aabb {
    /// The box that contains nothing.
    pub const EMPTY: Aabb = Aabb {
        min: Vec3A::splat(f32::INFINITY),
        max: Vec3A::splat(f32::NEG_INFINITY),
    };

    /// The smallest box holding both boxes.
    #[inline]
    pub fn union(self, other: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The smallest box holding this box and a point.
    #[inline]
    pub fn grow(self, p: Vec3A) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// Centre of the box.
    #[inline]
    pub fn centroid(&self) -> Vec3A {
        0.5 * (self.min + self.max)
    }

    /// Surface area (0 for an empty box).
    #[inline]
    pub fn area(&self) -> f32 {
        let e = (self.max - self.min).max(Vec3A::ZERO);
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// Entry distance of a ray into the box if it enters within `(0, t_max]`, else `None`.
    ///
    /// The slab test with each slab's entry and exit sides chosen by the sign of the direction.
    /// A ray parallel to a slab and inside it stays in, also when its origin lies exactly on one
    /// of the slab's sides: the `0 * inf` there is NaN, which `f32::max` and `f32::min` drop.
    #[inline]
    pub fn hit(&self, o: Vec3A, inv_d: Vec3A, t_max: f32) -> Option<f32> {
        let (mut near, mut far) = (0.0f32, f32::INFINITY);
        for axis in 0..3 {
            let (enter, exit) = if inv_d[axis].is_sign_negative() {
                (self.max[axis], self.min[axis])
            } else {
                (self.min[axis], self.max[axis])
            };
            near = near.max((enter - o[axis]) * inv_d[axis]);
            far = far.min((exit - o[axis]) * inv_d[axis]);
        }
        // Robust far distance (Ize 2013): widened by a few ulps for the rounding of both.
        let far = far * (1.0 + 4.0 * f32::EPSILON);
        (near <= far && near <= t_max).then_some(near)
    }
}
