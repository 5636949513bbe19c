//! A BVH leaf's triangles in structure-of-arrays lanes, four to a block (Embree's triangle4),
//! so one SSE pass runs the watertight test's shear and edge functions for the whole leaf.
//!
//! A lane whose three edge functions are non-zero gets the same `u, v, w`, `det`, `t` and
//! self-intersection band as [`Triangle::intersect`](crate::shape::Triangle::intersect): the
//! same operations in the same order (glam's `dot` and `element_sum` sum x, y, then z), with no
//! fused multiply-add, so it accepts exactly the hits the scalar test accepts, at the same
//! distance. The rare lanes left (an edge function exactly zero, which needs the top-left rule
//! and the double-precision retry, or a shape that is not a triangle) go to the scalar test on
//! the primitive itself. A ray thus reads the block alone, not the primitives, until it has a
//! hit.

use super::Prim;
use crate::geometry::{Ray, gamma};
use crate::shape::Shape;
use glam::Vec4;

/// Up to four consecutive primitives of a leaf; triangles' vertices in lanes.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct Block {
    /// `v[j][axis]`: coordinate `axis` of vertex `j` of each lane's triangle (NaN in lanes
    /// that hold no triangle, which every comparison rejects).
    pub v: [[Vec4; 3]; 3],
    /// The triangles' unit normals, `n[axis]`.
    pub n: [Vec4; 3],
    /// Index of the first primitive; lane `i` is primitive `first + i`.
    pub first: u32,
    /// Number of primitives, 1 to 4.
    pub count: u32,
    /// Lanes (bits) that always go to the scalar test: the non-triangles.
    pub scalar: u32,
    _pad: u32,
}

impl Block {
    /// The block of `prims[first..first + count]` (`count` from 1 to 4).
    pub fn new(prims: &[Prim], first: usize, count: usize) -> Block {
        let mut v = [[[f32::NAN; 4]; 3]; 3];
        let mut n = [[f32::NAN; 4]; 3];
        let mut scalar = 0;
        for (i, p) in prims[first..first + count].iter().enumerate() {
            match p.shape {
                Shape::Triangle(t) => {
                    for axis in 0..3 {
                        for (j, vertex) in t.v.iter().enumerate() {
                            v[j][axis][i] = vertex[axis];
                        }
                        n[axis][i] = t.n[axis];
                    }
                }
                _ => scalar |= 1 << i,
            }
        }
        Block {
            v: v.map(|a| a.map(Vec4::from_array)),
            n: n.map(Vec4::from_array),
            first: first as u32,
            count: count as u32,
            scalar,
            _pad: 0,
        }
    }

    /// The lanes' distances, the lanes (bits) that certainly hit at those distances within
    /// `(0, t_max]`, and the lanes only the scalar test can decide.
    #[inline(always)]
    fn test(&self, r: &BlockRay, t_max: f32) -> (Vec4, u32, u32) {
        let [kx, ky, kz] = r.k;
        let [sx, sy, sz] = r.shear;
        // Vertices relative to the origin, sheared so the ray runs along +z.
        let rel = |j: usize, axis: usize| self.v[j][axis] - r.o[axis];
        let (az, bz, cz) = (rel(0, kz), rel(1, kz), rel(2, kz));
        let (ax, ay) = (rel(0, kx) - sx * az, rel(0, ky) - sy * az);
        let (bx, by) = (rel(1, kx) - sx * bz, rel(1, ky) - sy * bz);
        let (cx, cy) = (rel(2, kx) - sx * cz, rel(2, ky) - sy * cz);
        // Edge functions: all of one sign inside.
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = Vec4::ZERO;
        let on_edge = u.cmpeq(zero) | v.cmpeq(zero) | w.cmpeq(zero);
        let outside = (u.cmplt(zero) | v.cmplt(zero) | w.cmplt(zero))
            & (u.cmpgt(zero) | v.cmpgt(zero) | w.cmpgt(zero));
        // Distance, scaled by the determinant.
        let det = u + v + w;
        let t_scaled = u * (sz * az) + v * (sz * bz) + w * (sz * cz);
        let t = t_scaled / det;
        let in_range = t.cmpgt(zero) & t.cmple(Vec4::splat(t_max)) & det.cmpne(zero);
        // A ray starting on the triangle's plane (within the error band of the origin's signed
        // distance) does not meet it at its start.
        let an = self.n.map(Vec4::abs);
        let reach = [
            self.v[0][0].abs() + r.o_abs[0],
            self.v[0][1].abs() + r.o_abs[1],
            self.v[0][2].abs() + r.o_abs[2],
        ];
        let band = Vec4::splat(gamma(5)) * (an[0] * reach[0] + an[1] * reach[1] + an[2] * reach[2])
            + (an[0] + an[1] + an[2]) * r.o_err;
        let along = (self.n[0] * r.d[0] + self.n[1] * r.d[1] + self.n[2] * r.d[2]).abs();
        let off_start = (t * along).cmpgt(band);
        let lanes = (1 << self.count) - 1;
        let exact = (!on_edge & !outside & in_range & off_start).bitmask() & !self.scalar;
        let scalar = (on_edge.bitmask() | self.scalar) & lanes;
        (t, exact & lanes, scalar)
    }

    /// Nearest hit among the block's primitives within `(0, ray.t_max]`, with the scalar
    /// loop's tie rule (a later primitive at equal distance wins).
    #[inline(always)]
    pub fn closest(&self, prims: &[Prim], br: &BlockRay, ray: &Ray) -> Option<(u32, f32)> {
        let (t, exact, mut scalar) = self.test(br, ray.t_max);
        let t = t.to_array();
        let mut best: Option<(u32, f32)> = None;
        let mut t_max = ray.t_max;
        let mut mask = exact | scalar;
        while mask != 0 {
            let i = mask.trailing_zeros();
            mask &= mask - 1;
            let hit = if scalar & (1 << i) != 0 {
                scalar &= !(1 << i);
                prims[(self.first + i) as usize]
                    .shape
                    .intersect(&Ray { t_max, ..*ray })
            } else {
                Some(t[i as usize]).filter(|&t| t <= t_max)
            };
            if let Some(t) = hit {
                t_max = t;
                best = Some((self.first + i, t));
            }
        }
        best
    }

    /// True if any of the block's primitives is hit within `(0, ray.t_max]`.
    #[inline(always)]
    pub fn any(&self, prims: &[Prim], br: &BlockRay, ray: &Ray) -> bool {
        let (_, exact, mut scalar) = self.test(br, ray.t_max);
        if exact != 0 {
            return true;
        }
        while scalar != 0 {
            let i = scalar.trailing_zeros();
            scalar &= scalar - 1;
            if prims[(self.first + i) as usize]
                .shape
                .intersect(ray)
                .is_some()
            {
                return true;
            }
        }
        false
    }
}

/// A ray's origin splatted across lanes, with its watertight-test permutation and shear.
#[derive(Clone, Copy)]
pub struct BlockRay {
    o: [Vec4; 3],
    o_abs: [Vec4; 3],
    d: [Vec4; 3],
    o_err: Vec4,
    k: [usize; 3],
    shear: [Vec4; 3],
}

impl BlockRay {
    /// Splat `ray` (which carries the shear constants: [`Ray::for_bvh`] with triangles).
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let splat = |v: glam::Vec3A| [Vec4::splat(v.x), Vec4::splat(v.y), Vec4::splat(v.z)];
        BlockRay {
            o: splat(ray.o),
            o_abs: splat(ray.o.abs()),
            d: splat(ray.d),
            o_err: Vec4::splat(ray.o_err),
            k: ray.k,
            shear: ray.shear.map(Vec4::splat),
        }
    }
}
