//! The triangles of a small scene tested against a batch of rays in SIMD lanes (a ray per
//! lane, one triangle at a time), instead of each ray walking the BVH alone.
//!
//! A scene of at most [`FEW`] primitives, all of them triangles that BVH blocks hold in lanes
//! (no sphere, plane or other shape), keeps each triangle's vertices, unit normal and first
//! vertex's magnitude here. A batch tests every triangle with the block test's operations
//! ([`super::block::Block`]: the watertight test's shear and edge functions, the distance, the
//! self-intersection band), each lane with its own ray's permutation and shear, so each lane
//! accepts exactly the hits the one-ray query accepts, at the same distances. The nearest is
//! then the one-ray query's, except where two triangles are met at one distance (the one-ray
//! query keeps the last it visits) or an edge function is exactly zero (the scalar test and its
//! double-precision retry decide): such a ray is traced alone, with the one-ray query. The hit
//! records are the one-ray query's ([`Geometry::nearest_record`]), so the answers are the same
//! to the bit (`tests/integration/few.rs`).
//!
//! The BVH still holds the triangles, for one-ray queries and for counted traversals.

use super::block::Block;
use super::{Floats, Geometry, MAX_LANES};
use crate::geometry::{Hit, Ray, gamma};

/// The most primitives a scene may have for its triangles to be tested in lanes. A ray meets
/// the BVH's few nodes and leaves of such a scene in about as much time as its lanes' share
/// of this many triangle tests.
pub const FEW: usize = 64;

/// One triangle as the lanes test it: its vertices `v[j][axis]`, its unit normal (the block's,
/// to the bit), the magnitude of its first vertex, and its primitive index.
#[derive(Clone, Copy, Debug)]
pub struct FewTriangle {
    v: [[f32; 3]; 3],
    n: [f32; 3],
    v0_abs: [f32; 3],
    prim: u32,
}

/// The triangles of a small scene ([`FEW`]); empty for any other scene.
#[derive(Clone, Debug, Default)]
pub struct Few(Vec<FewTriangle>);

impl Few {
    /// The triangles of `blocks`, if they are all the scene's `in_bvh + packed` primitives,
    /// at most [`FEW`] of them, and every one is a lane triangle; else none.
    pub fn of(blocks: &[Block], in_bvh: usize, packed: usize) -> Few {
        if packed > 0 || in_bvh > FEW || blocks.iter().any(|b| b.scalar != 0) {
            return Few::default();
        }
        let mut triangles = Vec::new();
        for (b, block) in blocks.iter().enumerate() {
            let n = block.normals().map(|x| x.to_array());
            let v = block.v.map(|vertex| vertex.map(|axis| axis.to_array()));
            triangles.extend((0..block.count as usize).map(|lane| {
                let v = v.map(|vertex| vertex.map(|axis| axis[lane]));
                FewTriangle {
                    v,
                    n: n.map(|axis| axis[lane]),
                    v0_abs: v[0].map(f32::abs),
                    prim: (4 * b + lane) as u32,
                }
            }));
        }
        Few(triangles)
    }

    /// True if the scene is not small: its rays go through the BVH.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

/// Up to `L::LANES` rays in lanes, each with its watertight test's permutation (as masks:
/// `kx == 0`, `kx == 1`, and so on) and shear.
struct ShearedLanes<L: Floats> {
    o: [L; 3],
    o_abs: [L; 3],
    d: [L; 3],
    o_err: L,
    t_max: L,
    /// `k[c][a]`: the lanes whose axis `c` (x, y, z of the sheared frame) is `a` (0 or 1).
    k: [[L::Mask; 2]; 3],
    shear: [L; 3],
}

impl<L: Floats> ShearedLanes<L> {
    /// `rays` (at most `L::LANES`; the lanes past them repeat the last).
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn new(rays: &[Ray]) -> Self {
        let mut v = [[0.0f32; MAX_LANES]; 17];
        for i in 0..L::LANES {
            let ray = &rays[i.min(rays.len() - 1)];
            let r = ray.for_bvh(ray.t_max).sheared();
            for x in 0..3 {
                v[x][i] = r.o[x];
                v[3 + x][i] = r.o[x].abs();
                v[6 + x][i] = r.d[x];
                v[9 + x][i] = r.shear[x];
                v[14 + x][i] = r.k[x] as f32;
            }
            (v[12][i], v[13][i]) = (r.o_err, r.t_max);
        }
        // SAFETY: the caller's.
        let mut x = [unsafe { L::splat(0.0) }; 17];
        for (row, x) in x.iter_mut().enumerate() {
            *x = unsafe { L::from_slice(&v[row]) };
        }
        let (zero, one) = unsafe { (L::splat(0.0), L::splat(1.0)) };
        let is = |k: L| [!k.cmpne(zero), !k.cmpne(one)];
        ShearedLanes {
            o: [x[0], x[1], x[2]],
            o_abs: [x[3], x[4], x[5]],
            d: [x[6], x[7], x[8]],
            shear: [x[9], x[10], x[11]],
            o_err: x[12],
            t_max: x[13],
            k: [is(x[14]), is(x[15]), is(x[16])],
        }
    }

    /// Coordinate `c` of the sheared frame of `x` (a vector given by its axes).
    #[inline(always)]
    fn axis(&self, c: usize, x: [L; 3]) -> L {
        let [is0, is1] = self.k[c];
        L::select(is0, x[0], L::select(is1, x[1], x[2]))
    }
}

/// What one triangle's test gives the lanes: the distances, the lanes met (within the rays'
/// `t_max`, beyond the self-intersection band), and the lanes where an edge function is
/// exactly zero. (Against each ray's own reach, not its nearest hit so far: so the triangles'
/// tests do not wait on one another.)
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn test<L: Floats>(tri: &FewTriangle, r: &ShearedLanes<L>) -> (L, L::Mask, L::Mask) {
    // (No closures that compute in lanes: they would not inline into the AVX2 and AVX-512
    // copies.)
    // SAFETY: the caller's; so for every `unsafe` block below, each makes values of `L`.
    let zero = unsafe { L::splat(0.0) };
    // Vertices relative to the origin, sheared so the ray runs along +z (`Block::test`).
    let mut rel = [[zero; 3]; 3];
    for (rel, v) in rel.iter_mut().zip(&tri.v) {
        for ((rel, &v), &o) in rel.iter_mut().zip(v).zip(&r.o) {
            *rel = unsafe { L::splat(v) } - o;
        }
    }
    let [a, b, c] = rel;
    let [sx, sy, sz] = r.shear;
    let (az, bz, cz) = (r.axis(2, a), r.axis(2, b), r.axis(2, c));
    let (ax, ay) = (r.axis(0, a) - sx * az, r.axis(1, a) - sy * az);
    let (bx, by) = (r.axis(0, b) - sx * bz, r.axis(1, b) - sy * bz);
    let (cx, cy) = (r.axis(0, c) - sx * cz, r.axis(1, c) - sy * cz);
    // Edge functions: all of one sign inside.
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    let on_edge = !u.cmpne(zero) | !v.cmpne(zero) | !w.cmpne(zero);
    let outside = (u.cmplt(zero) | v.cmplt(zero) | w.cmplt(zero))
        & (u.cmpgt(zero) | v.cmpgt(zero) | w.cmpgt(zero));
    let inside = !on_edge & !outside;
    if !L::any(inside) {
        // No lane's ray passes inside the edges: no distance to compute.
        return (zero, inside, on_edge);
    }
    // Distance, scaled by the determinant.
    let det = u + v + w;
    let t_scaled = u * (sz * az) + v * (sz * bz) + w * (sz * cz);
    let t = t_scaled / det;
    let in_range = t.cmpgt(zero) & t.cmple(r.t_max) & det.cmpne(zero);
    let met = inside & in_range;
    // The self-intersection band of a ray starting on the triangle's plane.
    let (n, an) = (tri.n, tri.n.map(f32::abs));
    let (n, an) = unsafe {
        (
            [L::splat(n[0]), L::splat(n[1]), L::splat(n[2])],
            [L::splat(an[0]), L::splat(an[1]), L::splat(an[2])],
        )
    };
    let mut reach = [zero; 3];
    for ((reach, &v), &o) in reach.iter_mut().zip(&tri.v0_abs).zip(&r.o_abs) {
        *reach = unsafe { L::splat(v) } + o;
    }
    let band = unsafe { L::splat(gamma(5)) }
        * (an[0] * reach[0] + an[1] * reach[1] + an[2] * reach[2])
        + (an[0] + an[1] + an[2]) * r.o_err;
    let along = (n[0] * r.d[0] + n[1] * r.d[1] + n[2] * r.d[2]).abs();
    let off_start = (t * along).cmpgt(band);
    (t, met & off_start, on_edge)
}

impl Geometry {
    /// True if this scene's triangles are tested in lanes ([`Few`]).
    #[inline]
    pub fn few(&self) -> bool {
        !self.few.is_empty()
    }

    /// The nearest hit of each ray of `rays` (at most `L::LANES`) into `hits`, as
    /// [`Geometry::intersect`] finds it, in a scene whose triangles are tested in lanes
    /// ([`Geometry::few`]).
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    pub unsafe fn nearest_few<L: Floats>(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        debug_assert!(self.few() && !rays.is_empty() && rays.len() <= L::LANES);
        // SAFETY: the caller's.
        let r = unsafe { ShearedLanes::<L>::new(rays) };
        // The nearest distance so far and its triangle's number (its bits), the lanes that
        // met one, those met twice at one distance (the one-ray query keeps the triangle it
        // visits last), and those with an edge function exactly zero.
        let none = r.t_max.cmplt(r.t_max);
        let (mut best, mut slot) = (r.t_max, unsafe { L::splat(0.0) });
        let (mut found, mut tie, mut edge) = (none, none, none);
        for (j, tri) in self.few.0.iter().enumerate() {
            // SAFETY: the caller's.
            let (t, met, on_edge) = unsafe { test(tri, &r) };
            edge = edge | on_edge;
            tie = tie | (met & found & !t.cmpne(best));
            let nearer = met & (t.cmplt(best) | !found);
            best = L::select(nearer, t, best);
            slot = L::select(nearer, unsafe { L::splat(f32::from_bits(j as u32)) }, slot);
            found = found | met;
        }
        let (found, alone) = (L::bitmask(found), L::bitmask(tie | edge));
        let mut slots = [0.0f32; MAX_LANES];
        slot.write_to(&mut slots);
        let slot = slots.map(f32::to_bits);
        let mut t = [0.0f32; MAX_LANES];
        best.write_to(&mut t);
        for (i, (hit, ray)) in hits.iter_mut().zip(rays).enumerate() {
            *hit = if alone & (1 << i) != 0 {
                self.intersect(ray)
            } else if found & (1 << i) != 0 {
                let tri = &self.few.0[slot[i] as usize];
                let n = glam::Vec3A::from_array(tri.n);
                Some(self.nearest_record(ray, tri.prim, t[i], Some(n)))
            } else {
                None
            };
        }
    }

    /// Whether each ray of `rays` (at most `L::LANES`, those of the bits of `live`) is
    /// blocked, as [`Geometry::occluded`] answers, in a scene whose triangles are tested in
    /// lanes ([`Geometry::few`]): bit `i` for ray `i`.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    pub unsafe fn occluded_few<L: Floats>(&self, rays: &[Ray], live: u32) -> u32 {
        debug_assert!(self.few() && !rays.is_empty() && rays.len() <= L::LANES);
        // SAFETY: the caller's.
        let r = unsafe { ShearedLanes::<L>::new(rays) };
        let (mut blocked, mut alone) = (0u32, 0u32);
        for tri in &self.few.0 {
            // SAFETY: the caller's.
            let (_, met, edge) = unsafe { test(tri, &r) };
            blocked |= L::bitmask(met) & live;
            alone |= L::bitmask(edge) & live & !blocked;
            if blocked | alone == live {
                break;
            }
        }
        // A ray on an edge that no lane test blocked: the one-ray query decides.
        for i in super::lanes::bits(alone & !blocked) {
            if self.occluded(&rays[i]) {
                blocked |= 1 << i;
            }
        }
        blocked
    }
}
