//! A ray, the per-ray constants of box and watertight triangle tests ([`BvhRay`]), the
//! surface hit record, and the rounding-error bounds that place spawned rays (pbrt-v4's
//! approach, "Managing Rounding Error", section 6.8 of the 4th edition).
//!
//! Every hit point carries a bound on its error, derived from the operations that computed it
//! ([`gamma`]). A spawned ray starts off the surface by that bound along the normal and carries
//! the bound on its own origin's error (`o_err`). Shape tests then apply one rule: a ray whose
//! origin lies within the error band of a surface starts *on* it, and does not meet it at its
//! start. That is what keeps a shadow ray from a crease between two walls from being blocked by
//! the neighbouring wall (seam acne), and a ray from re-hitting the surface it left, without any
//! epsilon. One exception: an *oriented* plane (`shape::Plane::side`, one no ray crosses) does
//! stop a ray that starts within its band and heads out of its side, which would otherwise
//! leak out of a room through a crease.

use glam::Vec3A;

/// The unit roundoff of `f32`: half of machine epsilon. Every correctly rounded operation has
/// a relative error of at most this.
pub const UNIT_ROUNDOFF: f32 = f32::EPSILON * 0.5;

/// `gamma(n) = n u / (1 - n u)`: a bound on the relative error accumulated by `n` successive
/// rounded operations (Higham; pbrt-v4's `gamma`).
#[inline]
pub const fn gamma(n: u32) -> f32 {
    let nu = n as f32 * UNIT_ROUNDOFF;
    nu / (1.0 - nu)
}

/// A half-line `o + t d` for `t` in `(0, t_max]`, with the bound on its origin's error: what
/// every query reads (48 bytes, so that the shaders' queues of rays stay small). The BVH and
/// the watertight triangle test add their per-ray constants only where a scene needs them
/// ([`Ray::for_bvh`]).
///
/// `d` is unit length.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Origin.
    pub o: Vec3A,
    /// Unit direction.
    pub d: Vec3A,
    /// Largest accepted hit distance.
    pub t_max: f32,
    /// Bound on the error of `o` in each coordinate, against the exact point it stands for
    /// (0 for camera rays, whose origin is exact).
    pub o_err: f32,
}

// The size the shaders' queues of rays are laid out for.
const _: () = assert!(std::mem::size_of::<Ray>() == 48);

/// A ray with the constants of the BVH's box tests and of the watertight triangle test,
/// computed once per query ([`Ray::for_bvh`], then [`BvhRay::sheared`] at its first leaf) and
/// read by every node and triangle it meets.
/// It reads as its [`Ray`] (`Deref`), so it also passes where a `&Ray` is asked: a triangle
/// test must be given it as a `BvhRay` (the shapes' `intersect_prepared`), or the shapes'
/// `intersect` computes the constants again.
#[derive(Clone, Copy, Debug)]
pub struct BvhRay {
    /// The ray.
    pub ray: Ray,
    /// Reciprocal of `d`, for slab tests against boxes.
    pub inv_d: Vec3A,
    /// Axis along which `|d|` is largest, and the two others (watertight triangle test).
    pub k: [usize; 3],
    /// Shear constants `(-dx/dz, -dy/dz, 1/dz)` in the permuted frame.
    pub shear: [f32; 3],
}

impl std::ops::Deref for BvhRay {
    type Target = Ray;

    #[inline(always)]
    fn deref(&self) -> &Ray {
        &self.ray
    }
}

impl BvhRay {
    /// `ray` with every constant: `1 / d`, and the axes and shear of the triangle test.
    #[inline]
    pub fn new(ray: Ray) -> Self {
        Self::boxes(ray).sheared()
    }

    /// `ray` with the box tests' constant, `1 / d`; the triangle test's are left unset
    /// (`[0, 1, 2]` and zeros) until [`BvhRay::sheared`] adds them.
    #[inline]
    pub fn boxes(ray: Ray) -> Self {
        BvhRay {
            inv_d: ray.d.recip(),
            ray,
            k: [0, 1, 2],
            shear: [0.0; 3],
        }
    }

    /// This ray with the axes and shear of the watertight triangle test, from its `1 / d`:
    /// what [`BvhRay::new`] gives. A query computes them when it first reaches a triangle
    /// (most rays of an incoherent set leave the tree before that).
    #[inline]
    pub fn sheared(&self) -> Self {
        let d = self.ray.d;
        // The axes by selects and array reads, not branches: an incoherent ray's axis and
        // sign are a coin toss to the branch predictor (about one misprediction a ray).
        // `kz` is `d.abs().max_position()` (the first of equal largest).
        let a = d.abs();
        let (y_over_x, m) = if a.y > a.x { (1, a.y) } else { (0, a.x) };
        let kz = if a.z > m { 2 } else { y_over_x };
        let da = d.to_array();
        // The next two axes in cyclic order, swapped if `d` runs down the `kz` axis.
        const NEXT: [[usize; 2]; 3] = [[1, 2], [2, 0], [0, 1]];
        let [x, y] = NEXT[kz];
        let down = (da[kz] < 0.0) as usize;
        let (kx, ky) = ([x, y][down], [y, x][down]);
        // `1 / d[kz]`, the box tests' division.
        let sz = self.inv_d.to_array()[kz];
        BvhRay {
            k: [kx, ky, kz],
            shear: [da[kx] * sz, da[ky] * sz, sz],
            ..*self
        }
    }
}

impl Ray {
    /// A ray from `o` along the unit vector `d`, unbounded.
    #[inline]
    pub fn new(o: Vec3A, d: Vec3A) -> Self {
        Self::segment(o, d, f32::INFINITY)
    }

    /// A ray from `o` along the unit vector `d` that stops at distance `t_max`, with an exact
    /// origin.
    #[inline]
    pub fn segment(o: Vec3A, d: Vec3A, t_max: f32) -> Self {
        Ray {
            o,
            d,
            t_max,
            o_err: 0.0,
        }
    }

    /// A ray leaving the surface of `hit` in unit direction `w` and stopping at `t_max`: it
    /// starts at [`Origins`] and carries that origin's error bound.
    #[inline]
    pub fn spawn(hit: &Hit, w: Vec3A, t_max: f32) -> Self {
        Origins::new(hit).ray(w, t_max)
    }

    /// This ray, limited to `t_max`, with the reciprocal direction for box tests
    /// ([`BvhRay::boxes`]); a query adds the triangle test's constants ([`BvhRay::sheared`])
    /// when it first reaches a triangle.
    #[inline]
    pub fn for_bvh(&self, t_max: f32) -> BvhRay {
        BvhRay::boxes(Ray { t_max, ..*self })
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
    /// Bound on the error of `p` in each coordinate across the surface (how far off the
    /// surface it can be); spawned rays start off the surface by it (see [`Origins`]).
    pub err: f32,
    /// Bound on the error of `p` along the surface (how far from the ray's exact crossing).
    pub err_along: f32,
    /// Index of the primitive in the prepared scene.
    pub prim: u32,
}

/// The starts of rays leaving a hit on either side of its surface, and their error bound.
///
/// The hit point is moved along the geometric normal, to the side a ray leaves by, by the
/// projection of its error box onto the normal (`sum |n_i| err`), so the origin is off the
/// surface whatever the error of the point (pbrt-v4's `OffsetRayOrigin`). Rounding the sum
/// `p + offset` could take back up to `u max |p_i|` per coordinate; pbrt rounds each coordinate
/// away from the surface instead, rtis adds twice that to the offset, which needs no branch.
/// Both sides are computed once per hit; every ray leaving it picks one.
#[derive(Clone, Copy, Debug)]
pub struct Origins {
    /// Start of rays leaving on the side the normal points to.
    pub front: Vec3A,
    /// Start of rays leaving on the other side.
    pub back: Vec3A,
    /// The geometric normal that tells the sides apart.
    pub n: Vec3A,
    /// Bound on either start's error against the exact crossing point: the point's error
    /// across and along the surface (along it twice: the nearest-hit choice between two
    /// surfaces within error of each other can add as much again), the offset, and the
    /// rounding of the sum.
    pub o_err: f32,
}

impl Origins {
    /// The starts of rays leaving `hit`.
    #[inline]
    pub fn new(hit: &Hit) -> Self {
        let d =
            hit.n.abs().element_sum() * hit.err + 2.0 * UNIT_ROUNDOFF * hit.p.abs().max_element();
        let (front, back) = (hit.p + d * hit.n, hit.p - d * hit.n);
        let o_max = front.abs().max(back.abs()).max_element();
        Origins {
            front,
            back,
            n: hit.n,
            o_err: hit.err + d + 2.0 * hit.err_along + UNIT_ROUNDOFF * o_max,
        }
    }

    /// The ray leaving in unit direction `w`, stopping at `t_max`.
    #[inline]
    pub fn ray(&self, w: Vec3A, t_max: f32) -> Ray {
        let o = if self.n.dot(w) >= 0.0 {
            self.front
        } else {
            self.back
        };
        Ray {
            o,
            d: w,
            t_max,
            o_err: self.o_err,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The branch-free axis choice gives what the plain form gives, to the bit: the largest
    /// axis (the first of equal ones), the next two in cyclic order swapped for a negative
    /// direction, and `1 / d[kz]`. Directions with ties, zeros of both signs, infinities, NaN
    /// and random ones.
    #[test]
    fn axes_and_shear_match_the_plain_form() {
        let plain = |d: Vec3A| {
            let kz = d.abs().max_position();
            let mut kx = (kz + 1) % 3;
            let mut ky = (kx + 1) % 3;
            if d[kz] < 0.0 {
                std::mem::swap(&mut kx, &mut ky);
            }
            let sz = 1.0 / d[kz];
            ([kx, ky, kz], [d[kx] * sz, d[ky] * sz, sz].map(f32::to_bits))
        };
        let values = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            -0.5,
            f32::INFINITY,
            f32::NAN,
            1e-40,
            -3.0,
        ];
        let mut dirs = Vec::new();
        for x in values {
            for y in values {
                for z in values {
                    dirs.push(Vec3A::new(x, y, z));
                }
            }
        }
        let mut s = crate::sampling::Sampler::new(3, 1, 4);
        dirs.extend(
            (0..100_000)
                .map(|_| Vec3A::new(s.next_f32(), s.next_f32(), s.next_f32()) * 2.0 - Vec3A::ONE),
        );
        for d in dirs {
            let r = BvhRay::new(Ray::new(Vec3A::ZERO, d));
            assert_eq!((r.k, r.shear.map(f32::to_bits)), plain(d), "{d}");
        }
    }
}
