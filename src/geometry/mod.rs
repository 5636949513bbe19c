//! Leaf maths: rays, bounding boxes, orthonormal frames, placements, and the robust ray-offset
//! rule.

mod aabb;
mod frame;
mod placement;
mod ray;

pub use aabb::Aabb;
pub use frame::Frame;
pub use placement::{Placement, Transform};
pub use ray::{BvhRay, Hit, Origins, Ray, UNIT_ROUNDOFF, gamma};
