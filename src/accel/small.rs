//! The triangles of a small scene, each tested against a ray per lane.
//!
//! A scene made of at most [`SMALL_SCENE`] triangles and nothing else (Mitsuba's Cornell box:
//! its walls and cubes) is answered faster by meeting every triangle than by walking its BVH:
//! a shader that holds rays in lanes (the path tracer's waves, `shader/path/lanes.rs`, and the
//! Global shader's, through the batched queries of `batch.rs`) tests each triangle, splatted across the lanes, against a ray per lane, where the walk tests
//! one ray at a time, with a branch per node and per leaf. Only AVX-512's sixteen lanes pay
//! for it ([`Geometry::is_small`]): with fewer, the scene's rays walk the BVH.
//!
//! Each lane runs [`Block::test`]'s arithmetic for its pair, the watertight test of Woop et al.
//! (2013) as pbrt-v4 writes it (`Triangle::Intersect`): the axes and shear of its own ray,
//! chosen by selects, the same operations in the same order and no fused multiply-add. So a
//! lane accepts exactly the hits the BVH's leaf test accepts, at the same distances, with the
//! same self-intersection band. Two cases a lane cannot settle as the walk does are handed
//! back, for the one-ray query to answer: an edge function exactly zero (the scalar test's
//! top-left rule and its double-precision retry), and, for the nearest hit, two triangles met
//! at the same distance (the walk's order picks one). Every answer is therefore the one-ray
//! query's to the bit, given that the walk reaches every leaf holding a hit within the ray's
//! reach: its box tests are widened for their own rounding (`wide.rs`), and the tests here
//! compare the two on random scenes, grazing and spawned rays included.

use super::block::Block;
use super::lanes::{abs_max, array, dot};
use super::simd::{Floats, Isa};
use super::{Geometry, Tally};
use crate::geometry::{Hit, Ray, gamma};

/// Scenes of at most this many primitives, all triangles a BVH block holds in its lanes, also
/// keep them splatted for rays in lanes ([`Geometry::is_small`]).
pub const SMALL_SCENE: usize = 64;

/// One triangle of a small scene, as the lanes read it.
#[derive(Clone, Copy, Debug)]
pub struct TriangleEach {
    /// Its primitive (`4 * block + lane`).
    prim: u32,
    /// `v[j][axis]`: coordinate `axis` of vertex `j` (and a fourth, zero, for
    /// [`Floats::pick`]).
    v: [[f32; 4]; 3],
    /// `|v[0][axis]|`, the first vertex's share of the self-intersection band.
    v0_abs: [f32; 3],
    /// The unit normal, [`Block::normals`]'s to the bit.
    n: [f32; 3],
    /// `|n|`, coordinate by coordinate.
    n_abs: [f32; 3],
}

/// The triangles of `blocks` as [`Geometry::triangle_each`] lists them: each lane's triangle,
/// in block order, if every lane of every block holds one and there are at most
/// [`SMALL_SCENE`]; none otherwise.
pub fn triangle_each(blocks: &[Block]) -> Vec<TriangleEach> {
    let count: usize = blocks.iter().map(|b| b.count as usize).sum();
    if count > SMALL_SCENE || blocks.iter().any(|b| b.scalar != 0) {
        return Vec::new();
    }
    let mut out = Vec::with_capacity(count);
    for (b, block) in blocks.iter().enumerate() {
        let n = block.normals().map(|x| x.to_array());
        for lane in 0..block.count as usize {
            let v = [0, 1, 2].map(|j| block.v[j].map(|axis| axis.to_array()[lane]));
            let n = [n[0][lane], n[1][lane], n[2][lane]];
            out.push(TriangleEach {
                prim: (4 * b + lane) as u32,
                v: v.map(|[x, y, z]| [x, y, z, 0.0]),
                v0_abs: v[0].map(f32::abs),
                n,
                n_abs: n.map(f32::abs),
            });
        }
    }
    out
}

/// An axis chosen per lane: lanes of `x` take coordinate 0, lanes of `y` coordinate 1, the
/// others coordinate 2.
#[derive(Clone, Copy)]
struct AxisMasks<M> {
    x: M,
    y: M,
}

impl<M: Copy> AxisMasks<M> {
    /// Each lane's coordinate of `v`.
    #[inline(always)]
    fn of<L: Floats<Mask = M>>(self, v: [L; 3]) -> L {
        L::select(self.x, v[0], L::select(self.y, v[1], v[2]))
    }
}

/// Each lane's coordinate `k` of vertex `vertex`, less `o` (the ray's coordinate `k`).
#[inline(always)]
fn relative<L: Floats>(vertex: &[f32; 4], k: L::Axis, o: L) -> L {
    L::pick(vertex, k) - o
}

/// Rays in lanes with the constants of the watertight test, as [`crate::geometry::BvhRay::sheared`]
/// computes them ray by ray.
pub struct ShearLanes<L: Floats> {
    o_abs: [L; 3],
    d: [L; 3],
    o_err: L,
    /// The axes `kx`, `ky` and `kz`: `kz` where `|d|` is largest, the others after it.
    k: [L::Axis; 3],
    /// `o[kx]`, `o[ky]` and `o[kz]`.
    o_k: [L; 3],
    /// `(d[kx] / d[kz], d[ky] / d[kz], 1 / d[kz])`, each as the one-ray test computes it.
    shear: [L; 3],
}

impl<L: Floats> ShearLanes<L> {
    /// Rays from origins `o` along unit directions `d` with origin errors `o_err`.
    #[inline(always)]
    pub fn new(o: [L; 3], d: [L; 3], o_err: L) -> Self {
        // SAFETY: `o_err` is a value of `L`, so the CPU runs its instruction set.
        let (zero, one) = unsafe { (L::splat(0.0), L::splat(1.0)) };
        // `1 / d`, as `Vec3A::recip` divides.
        let inv_d = [one / d[0], one / d[1], one / d[2]];
        // `kz`: the first of the largest `|d|` (`BvhRay::sheared`'s selects, lane by lane).
        let a = [d[0].abs(), d[1].abs(), d[2].abs()];
        let y_over_x = a[1].cmpgt(a[0]);
        let z = a[2].cmpgt(L::select(y_over_x, a[1], a[0]));
        let kz = AxisMasks {
            x: !z & !y_over_x,
            y: !z & y_over_x,
        };
        // The next two axes in cyclic order, swapped if `d` runs down the `kz` axis.
        let down = kz.of(d).cmplt(zero);
        let (z0, z1) = (kz.x, kz.y);
        let z2 = !(z0 | z1);
        let kx = AxisMasks {
            x: (z1 & down) | (z2 & !down),
            y: (z0 & !down) | (z2 & down),
        };
        let ky = AxisMasks {
            x: (z1 & !down) | (z2 & down),
            y: (z0 & down) | (z2 & !down),
        };
        let sz = kz.of(inv_d);
        ShearLanes {
            o_abs: [o[0].abs(), o[1].abs(), o[2].abs()],
            d,
            o_err,
            k: [
                L::axis(kx.x, kx.y),
                L::axis(ky.x, ky.y),
                L::axis(kz.x, kz.y),
            ],
            o_k: [kx.of(o), ky.of(o), kz.of(o)],
            shear: [kx.of(d) * sz, ky.of(d) * sz, sz],
        }
    }
}

/// What one triangle's test tells the lanes.
struct Met<L: Floats> {
    /// Distances.
    t: L,
    /// Lanes that meet the triangle within `(0, t_max]`, off their ray's start.
    hit: L::Mask,
    /// Lanes with an edge function exactly zero, which only the one-ray test can decide.
    edge: L::Mask,
}

impl TriangleEach {
    /// [`Block::test`] for one triangle and a ray per lane, within `(0, t_max]`. (No closures
    /// that compute in lanes: this inlines into code compiled for `L`'s instruction set.)
    #[inline(always)]
    fn test<L: Floats>(&self, r: &ShearLanes<L>, t_max: L) -> Met<L> {
        // SAFETY: `t_max` is a value of `L`, so the CPU runs its instruction set.
        let zero = unsafe { L::splat(0.0) };
        let [kx, ky, kz] = r.k;
        let [sx, sy, sz] = r.shear;
        // Vertices relative to the origin, sheared so the ray runs along +z.
        let v = &self.v;
        let (az, bz, cz) = (
            relative(&v[0], kz, r.o_k[2]),
            relative(&v[1], kz, r.o_k[2]),
            relative(&v[2], kz, r.o_k[2]),
        );
        let ax = relative(&v[0], kx, r.o_k[0]) - sx * az;
        let ay = relative(&v[0], ky, r.o_k[1]) - sy * az;
        let bx = relative(&v[1], kx, r.o_k[0]) - sx * bz;
        let by = relative(&v[1], ky, r.o_k[1]) - sy * bz;
        let cx = relative(&v[2], kx, r.o_k[0]) - sx * cz;
        let cy = relative(&v[2], ky, r.o_k[1]) - sy * cz;
        // Edge functions: all of one sign inside.
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let edge = !(u.cmpne(zero) & v.cmpne(zero) & w.cmpne(zero));
        // Outside: some edge function below zero and some above. Off the edges (none zero),
        // that is their sign bits differing; where one is NaN, so is `t` below, which then
        // meets nothing either way.
        let outside = L::signs_differ(u, v, w);
        // Distance, scaled by the determinant.
        let det = u + v + w;
        let t_scaled = u * (sz * az) + v * (sz * bz) + w * (sz * cz);
        let t = t_scaled / det;
        let met = !edge & !outside & t.cmpgt(zero) & t.cmple(t_max) & det.cmpne(zero);
        if !L::any(met) {
            return Met { t, hit: met, edge };
        }
        // A ray starting on the triangle's plane (within the error band of the origin's signed
        // distance) does not meet it at its start.
        // SAFETY: as above.
        let (n, an, g5) = unsafe {
            (
                [
                    L::splat(self.n[0]),
                    L::splat(self.n[1]),
                    L::splat(self.n[2]),
                ],
                [
                    L::splat(self.n_abs[0]),
                    L::splat(self.n_abs[1]),
                    L::splat(self.n_abs[2]),
                ],
                L::splat(gamma(5)),
            )
        };
        // SAFETY: as above.
        let v0_abs = unsafe {
            [
                L::splat(self.v0_abs[0]),
                L::splat(self.v0_abs[1]),
                L::splat(self.v0_abs[2]),
            ]
        };
        let reach = [
            v0_abs[0] + r.o_abs[0],
            v0_abs[1] + r.o_abs[1],
            v0_abs[2] + r.o_abs[2],
        ];
        let band = g5 * (an[0] * reach[0] + an[1] * reach[1] + an[2] * reach[2])
            + (an[0] + an[1] + an[2]) * r.o_err;
        let along = (n[0] * r.d[0] + n[1] * r.d[1] + n[2] * r.d[2]).abs();
        let hit = met & (t * along).cmpgt(band);
        Met { t, hit, edge }
    }
}

/// Lane `i`'s hit on primitive `prim` at distance `t` ([`Geometry::small_met`]), its record
/// read from the lanes' `records` ([`Geometry::small_records`]).
#[inline(always)]
pub fn record_hit(records: &[[f32; super::MAX_LANES]; 8], i: usize, (prim, t): (u32, f32)) -> Hit {
    let r = |row: usize| records[row][i];
    Hit {
        t,
        p: glam::Vec3A::new(r(0), r(1), r(2)),
        n: glam::Vec3A::new(r(3), r(4), r(5)),
        err: r(6),
        err_along: r(7),
        prim,
    }
}

/// The nearest hits of rays in lanes among a small scene's triangles
/// ([`Geometry::nearest_small`]).
pub struct SmallNearest {
    /// Each lane's distance (its `t_max` where it hit nothing).
    t: [f32; super::MAX_LANES],
    /// Each lane's triangle, as an index into the scene's splatted triangles (`u32::MAX` for
    /// none).
    slot: [u32; super::MAX_LANES],
    /// Lanes (bits) that the one-ray query answers.
    alone: u32,
}

impl Geometry {
    /// True if this scene's rays in lanes meet each of its triangles
    /// ([`Geometry::nearest_small`]): it has at most [`SMALL_SCENE`] primitives, all
    /// triangles, and its queries run in AVX-512's sixteen lanes. (In eight AVX2 lanes or four
    /// SSE lanes, the walk is faster: Mitsuba's Cornell box, 36 triangles, took 0.99 s in AVX2
    /// lanes against 0.85 s through the BVH, 1.74 s against 0.96 s in SSE; in AVX-512 lanes,
    /// 0.75 s against 0.91 s, and with 60 triangles 0.97 s against 1.08 s.)
    #[inline]
    pub fn is_small(&self) -> bool {
        !self.triangle_each.is_empty() && self.bvh.isa() == Isa::Avx512
    }

    /// The nearest hits of the rays in `r` within `t_max` among the triangles of a small scene
    /// ([`Geometry::is_small`]), as [`Geometry::intersect`] finds them (each lane tests
    /// [`Geometry::lane_prims`] triangles). Read a lane's hit with [`Geometry::small_hit`],
    /// from the lanes' [`Geometry::small_records`].
    #[inline(always)]
    pub fn nearest_small<L: Floats>(&self, r: &ShearLanes<L>, t_max: L) -> SmallNearest {
        // SAFETY: `t_max` is a value of `L`, so the CPU runs its instruction set.
        let none = unsafe { L::splat(f32::from_bits(u32::MAX)) };
        let (mut t, mut slot) = (t_max, none);
        // Lanes that met a triangle, that met two at their nearest distance, and that need the
        // one-ray test.
        // (No lane is both below and above itself: no lane set, NaN included.)
        let no = t_max.cmplt(t_max) & t_max.cmpgt(t_max);
        // (An edge anywhere sends the lane alone, even beyond its nearest hit: rare, and
        // never wrong.)
        let (mut found, mut tied, mut edge) = (no, no, no);
        for (j, tri) in self.triangle_each.iter().enumerate() {
            let met = tri.test(r, t);
            edge = edge | met.edge;
            // A hit at the distance of one kept is a tie (the walk keeps whichever it meets
            // last); a nearer one ends the tie.
            let same = met.hit & found & !met.t.cmpne(t);
            let nearer = met.hit & met.t.cmplt(t);
            tied = (tied & !nearer) | same;
            found = found | met.hit;
            t = L::select(met.hit, met.t, t);
            // SAFETY: as above.
            slot = L::select(met.hit, unsafe { L::splat(f32::from_bits(j as u32)) }, slot);
        }
        SmallNearest {
            t: array(t),
            slot: array(slot).map(f32::to_bits),
            alone: L::bitmask(tied | edge),
        }
    }

    /// Lane `i`'s nearest hit in `near` ([`Geometry::nearest_small`]) of `ray`, the lane's
    /// ray, with `records` the lanes' [`Geometry::small_records`]: its record as
    /// [`Geometry::intersect`] computes it, or that query's answer for a lane the lanes could
    /// not settle.
    #[inline(always)]
    pub fn small_hit(
        &self,
        near: &SmallNearest,
        records: &[[f32; super::MAX_LANES]; 8],
        i: usize,
        ray: &Ray,
        tally: &impl Tally,
    ) -> Option<Hit> {
        match self.small_met(near, i) {
            None => self.intersect_tallied(ray, tally),
            Some(met) => met.map(|met| record_hit(records, i, met)),
        }
    }

    /// What lane `i` of `near` ([`Geometry::nearest_small`]) found: `None` where the one-ray
    /// query must answer it, else the primitive and distance of the triangle it met, if any.
    #[inline(always)]
    pub fn small_met(&self, near: &SmallNearest, i: usize) -> Option<Option<(u32, f32)>> {
        if near.alone & (1 << i) != 0 {
            return None;
        }
        Some(
            self.triangle_each
                .get(near.slot[i] as usize)
                .map(|tri| (tri.prim, near.t[i])),
        )
    }

    /// The records of the nearest hits in `near` ([`Geometry::nearest_small`]) of the rays
    /// from `o` along `d` in lanes, as rows: the point (rows 0 to 2), the normal (3 to 5), and
    /// the error bounds across and along the surface (6 and 7). `Triangle::surface`'s
    /// operations in lanes, each lane on its own triangle, so a lane that met one (and that
    /// the one-ray query need not answer) has the record [`Geometry::intersect`] computes, to
    /// the bit ([`Geometry::small_hit`] reads it); the other lanes hold zeros.
    #[inline(always)]
    pub fn small_records<L: Floats>(
        &self,
        near: &SmallNearest,
        o: [L; 3],
        d: [L; 3],
    ) -> [[f32; super::MAX_LANES]; 8] {
        // Each lane's triangle: its vertices and normal, a column per coordinate.
        let (mut v, mut n) = (
            [[0.0f32; super::MAX_LANES]; 9],
            [[0.0f32; super::MAX_LANES]; 3],
        );
        let mut met = 0u32;
        for i in 0..L::LANES {
            // (The lanes `small_met` reads as having met a triangle.)
            let tri = self.triangle_each.get(near.slot[i] as usize);
            let Some(tri) = tri.filter(|_| near.alone & (1 << i) == 0) else {
                continue;
            };
            for axis in 0..3 {
                for (j, vertex) in tri.v.iter().enumerate() {
                    v[3 * j + axis][i] = vertex[axis];
                }
                n[axis][i] = tri.n[axis];
            }
            met |= 1 << i;
        }
        // SAFETY: `o` holds values of `L`, so the CPU runs its instruction set; so for every
        // `unsafe` block below, each makes values of `L`.
        let (v, n, t): ([L; 9], [L; 3], L) = unsafe {
            (
                super::lanes::rows(&v),
                super::lanes::rows(&n),
                L::from_slice(&near.t),
            )
        };
        let v0 = [v[0], v[1], v[2]];
        // `Ray::at`, then the point moved onto the triangle's plane along its normal.
        let p = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
        let s = dot(n, [p[0] - v0[0], p[1] - v0[1], p[2] - v0[2]]);
        let p = [p[0] - s * n[0], p[1] - s * n[1], p[2] - s * n[2]];
        // The error bounds: across the surface, by the largest coordinate of the vertices and
        // the point; along it, by the distance's error (`gamma(5)` of the plane's terms over
        // the cosine) and the point's. (Maxima in glam's operand order, `Vec3A::max` then
        // `max_element`: the same even where a NaN makes the order matter.)
        let mut m = [p[0].abs(), p[1].abs(), p[2].abs()];
        for (axis, m) in m.iter_mut().enumerate() {
            *m = v[axis]
                .abs()
                .max(v[3 + axis].abs())
                .max(v[6 + axis].abs())
                .max(*m);
        }
        let scale = m[0].max(m[2]).max(m[1].max(m[2]));
        let an = [n[0].abs(), n[1].abs(), n[2].abs()];
        let ao = [o[0].abs(), o[1].abs(), o[2].abs()];
        // SAFETY: as above.
        let (g3, g5, g7) = unsafe { (L::splat(gamma(3)), L::splat(gamma(5)), L::splat(gamma(7))) };
        let reach = [
            v0[0].abs() + ao[0],
            v0[1].abs() + ao[1],
            v0[2].abs() + ao[2],
        ];
        let dt = g5 * dot(an, reach) / dot(n, d).abs();
        let err = g7 * scale;
        let err_along = dt + g3 * (abs_max(o) + t.abs());
        // Zeros where no triangle was met.
        // SAFETY: as above.
        let (zero, met) = unsafe { (L::splat(0.0), super::lanes::lane_mask::<L>(met)) };
        let mut out = [[0.0f32; super::MAX_LANES]; 8];
        for (row, x) in [p[0], p[1], p[2], n[0], n[1], n[2], err, err_along]
            .into_iter()
            .enumerate()
        {
            L::select(met, x, zero).write_to(&mut out[row]);
        }
        out
    }

    /// Which rays in `r`, of the lanes of `live`, are blocked within `t_max` by the
    /// triangles of a small scene ([`Geometry::is_small`]), as [`Geometry::occluded`] answers,
    /// as far as the lanes can tell: the lanes met, and the live lanes an edge left unsure,
    /// which the one-ray query answers ([`Geometry::occluded_lanes`]). Bit `i` for lane `i`.
    #[inline(always)]
    pub fn blocked_small<L: Floats>(
        &self,
        r: &ShearLanes<L>,
        t_max: L,
        live: L::Mask,
        tally: &impl Tally,
    ) -> (u32, u32) {
        // No lane blocked or on an edge yet (no lane is both below and above itself).
        let mut hit = t_max.cmplt(t_max) & t_max.cmpgt(t_max);
        let mut edge = hit;
        let asked = L::bitmask(live).count_ones() as u64;
        for tri in &self.triangle_each {
            tally.prims(asked);
            let met = tri.test(r, t_max);
            hit = hit | met.hit;
            edge = edge | met.edge;
            // Stop once every lane asked is blocked.
            if L::all(hit | !live) {
                break;
            }
        }
        (L::bitmask(hit & live), L::bitmask(edge & !hit & live))
    }
}
