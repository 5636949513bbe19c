//! A BVH leaf's triangles in structure-of-arrays lanes, four to a block (Embree's triangle4),
//! so one SSE pass runs the watertight test's shear and edge functions for the whole leaf.
//!
//! A lane whose three edge functions are non-zero gets the same `u, v, w`, `det`, `t` and
//! self-intersection band as [`Triangle::intersect`](crate::shape::Triangle::intersect): the
//! same operations in the same order (glam's `dot` and `element_sum` sum x, y, then z), with no
//! fused multiply-add, so it accepts exactly the hits the scalar test accepts, at the same
//! distance. The rare lanes left (an edge function exactly zero, which needs the top-left rule
//! and the double-precision retry, or a shape that is not a triangle) go to the scalar test: on
//! the triangle rebuilt from the lane, or on the whole primitive kept for a lane without one.

use super::prim::Prim;
use crate::geometry::{BvhRay, Ray, gamma};
use crate::shape::{Shape, Triangle};
use glam::{Vec3A, Vec4};

/// The lane masks of each set of four bits (bit `k` for lane `k`).
const LANES: [glam::BVec4A; 16] = {
    let mut m = [glam::BVec4A::FALSE; 16];
    let mut bits = 0;
    while bits < 16 {
        m[bits] = glam::BVec4A::new(bits & 1 != 0, bits & 2 != 0, bits & 4 != 0, bits & 8 != 0);
        bits += 1;
    }
    m
};

/// Up to four consecutive primitives of a leaf; triangles' vertices in lanes.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct Block {
    /// `v[j][axis]`: coordinate `axis` of vertex `j` of each lane's triangle (NaN in lanes
    /// that hold no triangle; the test masks those lanes out).
    pub v: [[Vec4; 3]; 3],
    /// Where the lanes that hold no triangle (spheres, in order) keep their primitives, from
    /// this index on, in the array passed to the queries.
    pub other: u32,
    /// Number of primitives, 1 to 4.
    pub count: u32,
    /// Lanes (bits) that hold no triangle and go to the scalar test.
    pub scalar: u32,
    _pad: u32,
}

impl Block {
    /// The block of the primitives `leaf` (1 to 4), whose non-triangles the caller stores, in
    /// order, from index `other` on.
    pub fn new(leaf: &[&Prim], other: usize) -> Block {
        assert!(
            (1..=4).contains(&leaf.len()),
            "a block holds 1 to 4 primitives"
        );
        let mut v = [[[f32::NAN; 4]; 3]; 3];
        let mut scalar = 0;
        for (i, p) in leaf.iter().enumerate() {
            match lane_triangle(p) {
                Some(t) => {
                    for axis in 0..3 {
                        for (j, vertex) in t.v.iter().enumerate() {
                            v[j][axis][i] = vertex[axis];
                        }
                    }
                }
                None => scalar |= 1 << i,
            }
        }
        Block {
            v: v.map(|a| a.map(Vec4::from_array)),
            other: other as u32,
            count: leaf.len() as u32,
            scalar,
            _pad: 0,
        }
    }

    /// True if lane `lane` holds a triangle: not padding, and not a primitive left to the
    /// scalar test ([`Block::triangle`] gives it back: [`lane_triangle`] admitted only
    /// triangles that `Triangle::new` rebuilds).
    #[inline]
    pub fn has_triangle(&self, lane: usize) -> bool {
        lane < self.count as usize && self.scalar & (1 << lane) == 0
    }

    /// The triangle in lane `lane`, or `None` if the lane holds another shape or nothing.
    pub fn triangle(&self, lane: usize) -> Option<Triangle> {
        if !self.has_triangle(lane) {
            return None;
        }
        let [a, b, c] = self.vertices(lane);
        Triangle::new(a, b, c)
    }

    /// The triangle in lane `lane`, which holds one, whose unit normal [`Block::closest`]
    /// returned as `n`: [`Block::triangle`]'s, without computing the normal again.
    #[inline]
    pub fn triangle_with_normal(&self, lane: usize, n: Vec3A) -> Triangle {
        debug_assert!(self.has_triangle(lane));
        Triangle {
            v: self.vertices(lane),
            n,
        }
    }

    /// The vertices in lane `lane`.
    #[inline(always)]
    fn vertices(&self, lane: usize) -> [Vec3A; 3] {
        [0, 1, 2].map(|j| Vec3A::new(self.v[j][0][lane], self.v[j][1][lane], self.v[j][2][lane]))
    }

    /// The lanes' unit normals, `[x, y, z]`: `Triangle::new`'s operations, lane by lane, so
    /// each is its triangle's normal to the bit (NaN in lanes without a triangle).
    #[inline(always)]
    pub fn normals(&self) -> [Vec4; 3] {
        let e1 = [0, 1, 2].map(|axis| self.v[1][axis] - self.v[0][axis]);
        let e2 = [0, 1, 2].map(|axis| self.v[2][axis] - self.v[0][axis]);
        let c = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let len = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        c.map(|c| c / len)
    }

    /// Index, in the array of other primitives, of the shape in scalar lane `lane`.
    #[inline]
    pub fn other_index(&self, lane: u32) -> usize {
        (self.other + (self.scalar & ((1 << lane) - 1)).count_ones()) as usize
    }

    /// The lanes' distances, the lanes (bits) whose triangle the ray meets at those distances
    /// within `(0, t_max]`, the lanes whose distance lies beyond the self-intersection band
    /// (the ray does not start on their triangle; a lane hits if it is in both masks, the
    /// second means nothing outside the first), the lanes only the scalar test can decide,
    /// and the lanes' unit normals ([`Block::normals`]), computed when some lane passes the
    /// edge and range tests (zeros otherwise).
    ///
    /// The band is a mask of its own so that [`Block::closest`] can choose the nearest lane
    /// without waiting for it and check the band on that lane alone, a branch that almost
    /// always holds: the band needs the normals, a square root and a division after the
    /// distances, and the traversal waits on the leaf's answer.
    #[inline(always)]
    fn test(&self, r: &BlockRay, t_max: f32) -> (Vec4, u32, u32, u32, [Vec4; 3]) {
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
        let lanes = (1 << self.count) - 1;
        let scalar = (on_edge.bitmask() | self.scalar) & lanes;
        let hits = (!on_edge & !outside & in_range).bitmask() & lanes & !self.scalar;
        if hits == 0 {
            return (t, 0, 0, scalar, [zero; 3]);
        }
        // A ray starting on the triangle's plane (within the error band of the origin's signed
        // distance) does not meet it at its start. Few tests get here, so the normal is
        // computed now rather than stored.
        let n = self.normals();
        let an = n.map(Vec4::abs);
        let reach = [0, 1, 2].map(|axis| self.v[0][axis].abs() + r.o_abs[axis]);
        let band = Vec4::splat(gamma(5)) * (an[0] * reach[0] + an[1] * reach[1] + an[2] * reach[2])
            + (an[0] + an[1] + an[2]) * r.o_err;
        let along = (n[0] * r.d[0] + n[1] * r.d[1] + n[2] * r.d[2]).abs();
        let off_start = (t * along).cmpgt(band).bitmask();
        (t, hits, off_start, scalar, n)
    }

    /// Nearest hit among the block's primitives within `(0, t_max]` (`ray`'s own `t_max` is
    /// not read): its lane and distance, with the scalar loop's tie rule (a later lane at equal
    /// distance wins), and, if the lane test decided it, the lane's triangle's unit normal
    /// (the one [`Block::triangle`] gives it, to the bit), so that the hit's record need not
    /// compute it again. `others` holds the shapes of the scalar lanes from [`Block::other`] on.
    #[inline(always)]
    pub fn closest(
        &self,
        others: &[Prim],
        br: &BlockRay,
        ray: &BvhRay,
        mut t_max: f32,
    ) -> Option<(u32, f32, Option<Vec3A>)> {
        let (t, met, off_start, mut scalar, n) = self.test(br, t_max);
        let normal = |lane: u32| {
            let (i, [x, y, z]) = (lane as usize, n);
            Vec3A::new(x[i], y[i], z[i])
        };
        if scalar == 0 {
            if met == 0 {
                return None;
            }
            // Lanes only (the common case): the nearest lane met and its distance, without a
            // branch per lane, the later lane of equal distances, as the loop below keeps it.
            // (The distance is the minimum itself: reading it back by the lane measured 4-6%
            // slower on hit rays.)
            let d = Vec4::select(LANES[met as usize], t, Vec4::INFINITY);
            let least = d.min_element();
            let lane = 31 - (d.cmpeq(Vec4::splat(least)).bitmask() & met).leading_zeros();
            // It is the nearest hit unless the ray starts on its triangle (rarely): then the
            // loop below finds the nearest of the others.
            if off_start & (1 << lane) != 0 {
                return Some((lane, least, Some(normal(lane))));
            }
        }
        let exact = met & off_start;
        let t = t.to_array();
        let mut best: Option<(u32, f32)> = None;
        let mut mask = exact | scalar;
        while mask != 0 {
            let i = mask.trailing_zeros();
            mask &= mask - 1;
            let hit = if scalar & (1 << i) != 0 {
                scalar &= !(1 << i);
                self.scalar_hit(
                    others,
                    i,
                    &BvhRay {
                        ray: Ray { t_max, ..ray.ray },
                        ..*ray
                    },
                )
            } else {
                Some(t[i as usize]).filter(|&t| t <= t_max)
            };
            if let Some(t) = hit {
                t_max = t;
                best = Some((i, t));
            }
        }
        let (lane, t) = best?;
        Some((lane, t, (exact & (1 << lane) != 0).then(|| normal(lane))))
    }

    /// True if any of the block's primitives is hit within `(0, ray.t_max]`.
    #[inline(always)]
    pub fn any(&self, others: &[Prim], br: &BlockRay, ray: &BvhRay) -> bool {
        let (_, met, off_start, mut scalar, _) = self.test(br, ray.t_max);
        if met & off_start != 0 {
            return true;
        }
        while scalar != 0 {
            let i = scalar.trailing_zeros();
            scalar &= scalar - 1;
            if self.scalar_hit(others, i, ray).is_some() {
                return true;
            }
        }
        false
    }

    /// The scalar test of lane `lane`: its triangle's, or its other shape's.
    #[inline(never)]
    fn scalar_hit(&self, others: &[Prim], lane: u32, ray: &BvhRay) -> Option<f32> {
        match self.triangle(lane as usize) {
            Some(t) => t.intersect(ray),
            None => others[self.other_index(lane)].shape.intersect_prepared(ray),
        }
    }
}

/// The triangle primitive `p` puts in a block lane: its triangle, if `Triangle::new` gives it
/// back to the bit (a block keeps only the vertices and recomputes the normal). A triangle
/// built otherwise (through its public fields, with a zero area or another normal), like every
/// other shape, stays a whole primitive for the scalar test.
pub fn lane_triangle(p: &Prim) -> Option<Triangle> {
    let Shape::Triangle(t) = p.shape else {
        return None;
    };
    let again = Triangle::new(t.v[0], t.v[1], t.v[2])?;
    // `Triangle::new` keeps the vertices it is given: only the normal can differ.
    let bits = |v: Vec3A| v.to_array().map(f32::to_bits);
    (bits(again.n) == bits(t.n)).then_some(t)
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
    /// Splat `ray` (which carries the shear constants: [`BvhRay::new`] or
    /// [`BvhRay::sheared`]).
    #[inline(always)]
    pub fn new(ray: &BvhRay) -> Self {
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
