//! Rays, bounding boxes, orthonormal frames and the robust ray-offset rule.

mod aabb;
mod frame;
mod ray;

pub use aabb::Aabb;
pub use frame::Frame;
pub use ray::{Hit, OFFSET_ULPS, Ray, offset_origin};
