//! A ray with precomputed data for watertight triangle tests, and the surface hit record.

use glam::Vec3A;

/// A half-line `o + t d` for `t` in `(0, t_max]`.
///
/// `d` is unit length. The shear constants of Woop et al.'s watertight triangle test are
/// computed once per ray here, so each triangle test reuses them.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Origin.
    pub o: Vec3A,
    /// Unit direction.
    pub d: Vec3A,
    /// Largest accepted hit distance.
    pub t_max: f32,
    /// Reciprocal of `d`, for slab tests against boxes.
    pub inv_d: Vec3A,
    /// Axis along which `|d|` is largest, and the two others (watertight triangle test).
    pub k: [usize; 3],
    /// Shear constants `(-dx/dz, -dy/dz, 1/dz)` in the permuted frame.
    pub shear: [f32; 3],
}

impl Ray {
    /// A ray from `o` along the unit vector `d`, unbounded.
    #[inline]
    pub fn new(o: Vec3A, d: Vec3A) -> Self {
        Self::segment(o, d, f32::INFINITY)
    }

    /// A ray from `o` along the unit vector `d` that stops at distance `t_max`.
    #[inline]
    pub fn segment(o: Vec3A, d: Vec3A, t_max: f32) -> Self {
        let kz = d.abs().max_position();
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let sz = 1.0 / d[kz];
        Ray {
            o,
            d,
            t_max,
            inv_d: d.recip(),
            k: [kx, ky, kz],
            shear: [d[kx] * sz, d[ky] * sz, sz],
        }
    }

    /// A ray with only origin, direction and extent set: what the shaders spawn. The
    /// geometry queries add the BVH's and the triangle test's data ([`Ray::for_bvh`]) only
    /// when the scene needs them.
    #[inline]
    pub fn bare(o: Vec3A, d: Vec3A, t_max: f32) -> Self {
        Ray {
            o,
            d,
            t_max,
            inv_d: Vec3A::ZERO,
            k: [0, 1, 2],
            shear: [0.0; 3],
        }
    }

    /// This ray, limited to `t_max`, with the reciprocal direction for box tests and, if
    /// `triangles`, the shear constants of the watertight triangle test.
    #[inline]
    pub fn for_bvh(&self, t_max: f32, triangles: bool) -> Ray {
        if triangles {
            Ray::segment(self.o, self.d, t_max)
        } else {
            Ray {
                t_max,
                inv_d: self.d.recip(),
                ..*self
            }
        }
    }

    /// The point at distance `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3A {
        self.o + t * self.d
    }
}

/// Where a ray meets a surface.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Distance along the ray.
    pub t: f32,
    /// Hit point.
    pub p: Vec3A,
    /// Unit geometric normal as the shape defines it (outward for spheres, the declared normal
    /// for planes, the winding normal for triangles). Shaders orient it towards the viewer.
    pub n: Vec3A,
    /// Absolute bound on the error of `p` in every coordinate; secondary rays start
    /// this far off the surface (see [`offset_origin`]).
    pub err: f32,
    /// Index of the primitive in the prepared scene.
    pub prim: u32,
}

/// How many machine epsilons of the hit point's magnitude a secondary ray is pushed off the
/// surface. Sized from the error analysis of the sphere, plane and triangle tests (each within a
/// few tens of ulps of the largest coordinate involved) with a safety factor.
pub const OFFSET_ULPS: f32 = 128.0;

/// The start of a secondary ray that leaves `hit` in direction `w`: the hit point moved off the
/// surface along the geometric normal, to the side `w` points to, by the hit's error bound.
///
/// The push is relative to the size of the coordinates, so it works at any scene scale (the
/// tests render the Cornell box scaled by 1e-3 and translated by 1e5). No fixed epsilon.
#[inline]
pub fn offset_origin(hit: &Hit, w: Vec3A) -> Vec3A {
    let push = hit.n * hit.err;
    if hit.n.dot(w) >= 0.0 {
        hit.p + push
    } else {
        hit.p - push
    }
}
