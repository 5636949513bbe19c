//! The closed set of shapes. Each variant lives in its own file; [`Shape`] dispatches by `match`.
//!
//! Adding a shape touches three places: its file here, the [`Shape`] enum (the compiler then
//! names every `match` that lacks it), and the scene-file enum `scene::file::ShapeDesc`.

mod plane;
mod sphere;
mod triangle;

pub use plane::Plane;
pub use sphere::Sphere;
pub use triangle::Triangle;

use crate::effects::kernel;
use crate::geometry::{Aabb, Ray};
use glam::Vec3A;

/// A prepared, camera-relative shape in single precision, ready for intersection.
#[derive(Clone, Copy, Debug)]
pub enum Shape {
    /// A sphere.
    Sphere(Sphere),
    /// An infinite, two-sided plane.
    Plane(Plane),
    /// A two-sided triangle.
    Triangle(Triangle),
}

/// The kind of a shape, for statistics and the effect analysis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ShapeKind {
    /// [`Sphere`].
    Sphere,
    /// [`Plane`].
    Plane,
    /// [`Triangle`].
    Triangle,
}

/// The local geometry at a hit: point, unit geometric normal, and the point's error bound.
#[derive(Clone, Copy, Debug)]
pub struct Surface {
    /// The hit point, refined onto the surface.
    pub p: Vec3A,
    /// Unit geometric normal (outward for spheres, as declared for planes, winding for triangles).
    pub n: Vec3A,
    /// Absolute error bound on `p`.
    pub err: f32,
}

/// Error bound of a refined hit point whose coordinates are at most `scale` in magnitude.
#[inline]
pub(crate) fn point_error(scale: f32) -> f32 {
    crate::geometry::OFFSET_ULPS * f32::EPSILON * scale.max(f32::MIN_POSITIVE)
}

impl Shape {
    /// Distance to the nearest intersection in `(0, ray.t_max]`, if any.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        self.intersect_in::<{ kernel::ALL }>(ray)
    }

    /// [`Shape::intersect`] in render kernel `K`: the tests of shape kinds the kernel leaves
    /// out are not compiled in (the scene has none of them).
    #[inline(always)]
    pub fn intersect_in<const K: u32>(&self, ray: &Ray) -> Option<f32> {
        match self {
            Shape::Sphere(s) if K & kernel::SPHERES != 0 => s.intersect(ray),
            Shape::Plane(p) => p.intersect(ray),
            Shape::Triangle(t) if K & kernel::TRIANGLES != 0 => t.intersect(ray),
            _ => None,
        }
    }

    /// The surface where `ray` meets this shape at distance `t` (from [`Shape::intersect`]).
    #[inline]
    pub fn surface(&self, ray: &Ray, t: f32) -> Surface {
        match self {
            Shape::Sphere(s) => s.surface(ray, t),
            Shape::Plane(p) => p.surface(ray, t),
            Shape::Triangle(tr) => tr.surface(ray, t),
        }
    }

    /// Bounding box, or `None` for unbounded shapes (kept outside the BVH).
    pub fn bounds(&self) -> Option<Aabb> {
        match self {
            Shape::Sphere(s) => Some(s.bounds()),
            Shape::Plane(_) => None,
            Shape::Triangle(t) => Some(t.bounds()),
        }
    }

    /// Which kind of shape this is.
    pub fn kind(&self) -> ShapeKind {
        match self {
            Shape::Sphere(_) => ShapeKind::Sphere,
            Shape::Plane(_) => ShapeKind::Plane,
            Shape::Triangle(_) => ShapeKind::Triangle,
        }
    }
}
