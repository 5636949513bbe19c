//! The closed set of shapes. Each variant lives in its own file; [`Shape`] dispatches by `match`.
//!
//! A shape has two forms: [`WorldShape`], the ECS component in scene units and double
//! precision, and [`Shape`], the camera-relative single-precision form that rays are tested
//! against. [`WorldShape::extract`] turns one into the other.
//!
//! Adding a shape touches three places: its file here (its render form, with `intersect`,
//! `surface`, `bounds` and a constructor from scene units), this file (a variant of both enums;
//! the compiler then names every `match` here that lacks it), and the scene file's `ShapeDesc`
//! with its conversion (`scene/file.rs`, whose exhaustive `match` the compiler also names).

mod plane;
mod sphere;
mod triangle;

pub use plane::Plane;
pub use sphere::{Sphere, sphere_uv};
pub use triangle::Triangle;

use crate::geometry::{Aabb, BvhRay, Placement, Ray};
use crate::mesh::MeshData;
use glam::{DVec3, Vec3A};
use std::sync::Arc;

/// A shape as the world holds it: scene units, double precision, before its transform.
#[derive(Clone, Debug, PartialEq)]
pub enum WorldShape {
    /// A sphere of `radius > 0` around `center`.
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius, > 0.
        radius: f64,
    },
    /// The infinite two-sided plane through `point` with normal `normal` (non-zero).
    Plane {
        /// Any point of the plane.
        point: DVec3,
        /// Normal, non-zero (normalised when extracted).
        normal: DVec3,
    },
    /// A two-sided triangle.
    Triangle {
        /// Vertices; the normal follows the winding `(v1 - v0) x (v2 - v0)`.
        v: [DVec3; 3],
    },
    /// The parallelogram `corner + s u + t v`, `s, t` in [0, 1], two-sided, with normal
    /// `u x v`; rendered as two triangles.
    Rectangle {
        /// One corner.
        corner: DVec3,
        /// First edge from the corner.
        u: DVec3,
        /// Second edge from the corner.
        v: DVec3,
    },
    /// Indexed triangles with optional vertex normals (loaded from a file or written inline).
    Mesh(Arc<MeshData>),
}

impl WorldShape {
    /// Every point that describes this shape, for systems that move shapes around.
    pub fn points_mut(&mut self) -> Vec<&mut DVec3> {
        match self {
            WorldShape::Sphere { center, .. } => vec![center],
            WorldShape::Plane { point, .. } => vec![point],
            WorldShape::Triangle { v } => v.iter_mut().collect(),
            WorldShape::Rectangle { corner, .. } => vec![corner],
            WorldShape::Mesh(m) => Arc::make_mut(m).positions.iter_mut().collect(),
        }
    }

    /// The render shapes of this shape placed by `at`, each with its corners' attributes
    /// (vertex normals when smooth, texture coordinates when given), passed to `push`; returns
    /// how many zero-area triangles were dropped (they can never be hit).
    pub fn extract(&self, at: &Placement, push: &mut dyn FnMut(Shape, Corners)) -> usize {
        let mut dropped = 0;
        // A mirroring transform reverses the winding: swap two vertices to keep the normal.
        let mirrors = at.mirrors();
        let mut triangle = |v: [Vec3A; 3], c: Corners| {
            let (v, c) = if mirrors {
                // Coordinates follow their vertices; a triangle without them keeps the
                // barycentric (b1, b2) of its vertices as written, now the third and second.
                let bary = [glam::Vec2::ZERO, glam::Vec2::X, glam::Vec2::Y];
                let c = Corners {
                    normals: c.normals.map(|[a, b, c]| [a, c, b]),
                    uvs: Some(c.uvs.unwrap_or(bary)).map(|[a, b, c]| [a, c, b]),
                };
                ([v[0], v[2], v[1]], c)
            } else {
                (v, c)
            };
            match Triangle::new(v[0], v[1], v[2]) {
                Some(t) => push(Shape::Triangle(t), c),
                None => dropped += 1,
            }
        };
        match self {
            WorldShape::Sphere { center, radius } => push(
                Shape::Sphere(Sphere::placed(*center, *radius, at)),
                Corners::NONE,
            ),
            WorldShape::Plane { point, normal } => push(
                Shape::Plane(Plane::placed(*point, *normal, at)),
                Corners::NONE,
            ),
            WorldShape::Triangle { v } => triangle(v.map(|p| at.point(p)), Corners::NONE),
            WorldShape::Rectangle { corner, u, v } => {
                // Both triangles wind as u x v: (u, u + v) and (u + v, v). Texture coordinates
                // run from (0, 0) at the corner along u and v to (1, 1).
                let [a, b, c, d] = [*corner, corner + u, corner + u + v, corner + v];
                let uv = |s: f32, t: f32| glam::Vec2::new(s, t);
                let [ta, tb, tc, td] = [uv(0.0, 0.0), uv(1.0, 0.0), uv(1.0, 1.0), uv(0.0, 1.0)];
                let with = |uvs| Corners {
                    normals: None,
                    uvs: Some(uvs),
                };
                triangle([a, b, c].map(|p| at.point(p)), with([ta, tb, tc]));
                triangle([a, c, d].map(|p| at.point(p)), with([ta, tc, td]));
            }
            WorldShape::Mesh(m) => {
                let v: Vec<Vec3A> = m.positions.iter().map(|p| at.point(*p)).collect();
                let n: Vec<Vec3A> = m.normals.iter().map(|d| at.normal(*d)).collect();
                for f in &m.faces {
                    let idx = f.map(|i| i as usize);
                    let corners = Corners {
                        normals: (!n.is_empty()).then(|| idx.map(|i| n[i])),
                        uvs: (!m.uvs.is_empty()).then(|| idx.map(|i| m.uvs[i])),
                    };
                    triangle(idx.map(|i| v[i]), corners);
                }
            }
        }
        dropped
    }
}

/// What a triangle's corners carry besides their positions: shading normals and texture
/// coordinates, each optional.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Corners {
    /// Unit vertex normals, interpolated for shading.
    pub normals: Option<[Vec3A; 3]>,
    /// Texture coordinates, interpolated at hits.
    pub uvs: Option<[glam::Vec2; 3]>,
}

impl Corners {
    /// Nothing beyond the positions: a flat triangle with barycentric coordinates.
    pub const NONE: Corners = Corners {
        normals: None,
        uvs: None,
    };
}

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
    /// Bound on the error of `p` in each coordinate, across the surface: how far the point can
    /// be off the surface. Spawned rays start off the surface by it.
    pub err: f32,
    /// Bound on the error of `p` along the surface, from the error of `t`: how far the point
    /// can be from where the ray truly crosses the surface. Only the start rule reads it.
    pub err_along: f32,
}

impl Shape {
    /// Distance to the nearest intersection in `(0, ray.t_max]`, if any. A triangle computes
    /// the ray's constants for the one test ([`BvhRay::new`]); many tests of one ray share
    /// them through [`Shape::intersect_prepared`].
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        match self {
            Shape::Sphere(s) => s.intersect(ray),
            Shape::Plane(p) => p.intersect(ray),
            Shape::Triangle(t) => t.intersect(&BvhRay::new(*ray)),
        }
    }

    /// [`Shape::intersect`] for a ray that carries the triangle test's constants
    /// ([`BvhRay::new`] or [`BvhRay::sheared`]; not [`BvhRay::boxes`], whose constants are
    /// placeholders).
    #[inline(always)]
    pub fn intersect_prepared(&self, ray: &BvhRay) -> Option<f32> {
        match self {
            Shape::Sphere(s) => s.intersect(ray),
            Shape::Plane(p) => p.intersect(ray),
            Shape::Triangle(t) => t.intersect(ray),
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

    /// The direction at `p` along which a rough material's `alpha_u` applies (not unit, not
    /// yet orthogonal to a shading normal): on a sphere `dp/du` as Mitsuba 3 parametrises it,
    /// the azimuth about the world `z` axis; on a flat shape, until shapes carry texture
    /// coordinates, the first tangent of Duff et al.'s frame around its normal, the same over a
    /// whole rectangle or plane (`x` for a normal along `y` or `z`, `-z` for one along `x`).
    #[inline]
    pub fn tangent(&self, p: Vec3A) -> Vec3A {
        match self {
            Shape::Sphere(s) => {
                let d = p - s.c;
                Vec3A::new(-d.y, d.x, 0.0)
            }
            Shape::Plane(pl) => pl.n.any_orthonormal_vector(),
            Shape::Triangle(t) => t.n.any_orthonormal_vector(),
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
