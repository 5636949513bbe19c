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
    /// The slab test with NaN-safe min/max: a ray parallel to a slab and inside it stays in.
    #[inline]
    pub fn hit(&self, o: Vec3A, inv_d: Vec3A, t_max: f32) -> Option<f32> {
        let t0 = (self.min - o) * inv_d;
        let t1 = (self.max - o) * inv_d;
        // Robust near/far (Ize 2013): widen the far distance by 2 ulps-ish.
        let near = t0.min(t1).max_element().max(0.0);
        let far = t0.max(t1).min_element() * (1.0 + 4.0 * f32::EPSILON);
        (near <= far && near <= t_max).then_some(near)
    }
}
