//! Ray queries in batches: a ray per SIMD lane, tested against one primitive at a time.
//!
//! A shader that holds many rays at once (the Global shader's tree of indirect rays) hands them
//! over together, or builds them in lanes itself (the shadow rays of its hits,
//! [`Geometry::occluded_lanes`]). Where every primitive is packed (planes, and the spheres of small
//! scenes), the rays fill the lanes (sixteen with AVX-512, eight with AVX2, four with SSE) and each
//! primitive is splatted across them ([`Geometry::sphere_each`], [`Geometry::plane_each`]): no lane
//! holds a padding primitive (only a batch's last chunk may repeat its last ray), no closest-lane
//! search runs per ray, and each ray's constants are computed once. Each lane runs the arithmetic
//! the one-ray query runs for its pair, in the same order of primitives and with the same tie rule,
//! and keeps the parameters of the primitive it hits, so that the hit records are computed in the
//! lanes too ([`Geometry::nearest_lanes`], which the Global shader's waves use as well); the
//! answers are bit-identical to [`Geometry::intersect`] and [`Geometry::occluded`] in every
//! instruction set. A small scene of triangles alone meets each of its triangles in AVX-512
//! lanes too ([`Geometry::nearest_small`], `small.rs`); other scenes with a BVH answer ray by
//! ray.
//!
//! The instruction set is the BVH's ([`super::WideBvh::isa`]): AVX-512 or AVX2 where the CPU
//! has it. Their copies are `#[target_feature]` functions around the generic code, which has
//! no closures, so every lane operation inlines into them.

use super::lanes::{RayLanes, SurfaceLanes, lane_mask, plane_surface, sphere_surface};
use super::simd::{Floats, Isa, MAX_LANES};
use super::wide::packet::{PACKET, octant};
use super::{Geometry, LeafRay, ShearLanes, Tally, Traversal};
use crate::geometry::BvhRay;
use crate::geometry::{Hit, Ray};
use glam::Vec4;

/// The nearest hits of up to `L::LANES` rays ([`Geometry::nearest_lanes`]).
#[derive(Clone, Copy)]
pub struct Nearest<L> {
    /// Distances (the rays' `t_max` where they hit nothing).
    pub t: L,
    /// Slots of the primitives hit ([`Geometry::slot_prim`]), as the bits of each lane.
    pub slot: L,
    /// Hit records.
    pub hit: SurfaceLanes<L>,
}

/// The records of a [`Nearest`] lane by lane: the distance, the slot's bits, the point, the
/// normal and the two error bounds, a row each.
pub struct NearestRows([[f32; MAX_LANES]; 10]);

impl<L: Floats> Nearest<L> {
    /// The lanes' records as rows, to be read lane by lane ([`Geometry::lane_hit`]).
    #[inline(always)]
    pub fn rows(&self) -> NearestRows {
        let h = &self.hit;
        let mut v = [[0.0f32; MAX_LANES]; 10];
        for (row, x) in [
            self.t,
            self.slot,
            h.p[0],
            h.p[1],
            h.p[2],
            h.n[0],
            h.n[1],
            h.n[2],
            h.err,
            h.err_along,
        ]
        .into_iter()
        .enumerate()
        {
            x.write_to(&mut v[row]);
        }
        NearestRows(v)
    }
}

/// Where `ok`, the lanes take `x` (a primitive's vector and number: a centre and radius, a
/// normal and offset) into `into`.
#[inline(always)]
fn keep<L: Floats>(ok: L::Mask, x: ([L; 3], L), into: (&mut [L; 3], &mut L)) {
    let (a, b) = into;
    *a = [
        L::select(ok, x.0[0], a[0]),
        L::select(ok, x.0[1], a[1]),
        L::select(ok, x.0[2], a[2]),
    ];
    *b = L::select(ok, x.1, *b);
}

/// The `L::LANES` rays of a batch's chunk starting at `k` (the last ray repeated past the end;
/// its answers are dropped), and their `t_max`.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn chunk<L: Floats>(rays: &[Ray], k: usize) -> ([&Ray; MAX_LANES], L) {
    let last = rays.len() - 1;
    let mut lanes = [&rays[last]; MAX_LANES];
    for (i, r) in lanes.iter_mut().enumerate().take(L::LANES) {
        *r = &rays[(k + i).min(last)];
    }
    // SAFETY: the caller vouches for the instruction set.
    (lanes, unsafe { L::from_array(lanes.map(|r| r.t_max)) })
}

/// Segments in lanes: origins, unit directions, the origins' error bounds and the ends.
pub type Segments<L> = ([L; 3], [L; 3], L, L);

/// [`Segments`] written out as rows, to take lane by lane the rays of the lanes that go on
/// alone (the one-ray query's, or an audit's).
pub struct SegmentRows([[f32; MAX_LANES]; 8]);

impl SegmentRows {
    /// The rows of `segments`.
    #[inline(always)]
    pub fn new<L: Floats>((o, d, o_err, t_max): Segments<L>) -> Self {
        let mut v = [[0.0f32; MAX_LANES]; 8];
        for (row, x) in v
            .iter_mut()
            .zip([o[0], o[1], o[2], d[0], d[1], d[2], o_err, t_max])
        {
            x.write_to(row);
        }
        SegmentRows(v)
    }

    /// Lane `i`'s segment as a ray.
    #[inline(always)]
    pub fn ray(&self, i: usize) -> Ray {
        let v = &self.0;
        Ray {
            o: glam::Vec3A::new(v[0][i], v[1][i], v[2][i]),
            d: glam::Vec3A::new(v[3][i], v[4][i], v[5][i]),
            t_max: v[7][i],
            o_err: v[6][i],
        }
    }
}

/// The leaf test of a packet's walk in [`Geometry::intersect_packet`]: ray `i`'s nearest hit
/// in a block, the unit normal of the last one kept. A type of its own (not a closure) so that
/// its test is inlined into the walk and compiled for the walk's instruction set.
struct PacketBlocks<'a> {
    geometry: &'a Geometry,
    rays: &'a [&'a BvhRay; PACKET],
    leaf_rays: [LeafRay; PACKET],
    normals: [Option<glam::Vec3A>; PACKET],
}

impl super::wide::packet::PacketLeaf for &mut PacketBlocks<'_> {
    #[inline(always)]
    fn nearest(&mut self, i: usize, b: u32, t_max: f32) -> Option<(u32, f32)> {
        let g = self.geometry;
        let (r, br) = self.leaf_rays[i].get(self.rays[i], g.has_triangles);
        let (lane, t, n) = g.blocks[b as usize].closest(&g.others, br, r, t_max)?;
        self.normals[i] = n;
        Some((4 * b + lane, t))
    }
}

impl Geometry {
    /// True if the batched queries can put rays in the lanes: every primitive is packed.
    #[inline]
    fn all_packed(&self) -> bool {
        self.bvh.is_empty()
    }

    /// The nearest hit of each ray of `rays`, as [`Geometry::intersect`] finds it, into `hits`
    /// (cleared first, then one entry per ray).
    pub fn intersect_batch(&self, rays: &[Ray], hits: &mut Vec<Option<Hit>>) {
        self.intersect_batch_tallied(rays, hits, None);
    }

    /// [`Geometry::intersect_batch`], counting into `tally` if there is one (in lanes, every
    /// ray tests every packed primitive).
    pub fn intersect_batch_tallied(
        &self,
        rays: &[Ray],
        hits: &mut Vec<Option<Hit>>,
        tally: Option<&Traversal>,
    ) {
        hits.clear();
        if !self.all_packed() && !self.is_small() {
            // Ray by ray, the BVH's loop compiled with the counters or without them.
            match tally {
                Some(t) => hits.extend(rays.iter().map(|r| self.intersect_tallied(r, t))),
                None => hits.extend(rays.iter().map(|r| self.intersect(r))),
            }
            return;
        }
        tally.prims(rays.len() as u64 * self.lane_prims());
        match self.bvh.isa() {
            // SAFETY: the BVH's instruction set is one the CPU runs (`WideBvh::set_isa`).
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => unsafe { self.intersect_avx2(rays, hits, &tally) },
            // SAFETY: as above.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => unsafe { self.intersect_avx512(rays, hits, &tally) },
            // SAFETY: `Vec4` runs on every CPU.
            _ => unsafe { self.intersect_in::<Vec4>(rays, hits, &tally) },
        }
    }

    /// The nearest hit of each ray of `rays`, as [`Geometry::intersect`] finds it, into `hits`
    /// (cleared first, then one entry per ray), for rays that run close together, as a camera's
    /// do: in a scene whose only primitives are in the BVH, eight rays in a row that run into
    /// the same octant walk the tree together ([`super::WideBvh::closest_packet`]); the others, and
    /// every ray of other scenes, are traced alone. The answers are the same to the bit.
    pub fn intersect_coherent(&self, rays: &[Ray], hits: &mut Vec<Option<Hit>>) {
        hits.clear();
        for chunk in rays.chunks(PACKET) {
            let found = self.intersect_packet(chunk);
            hits.extend_from_slice(&found[..chunk.len()]);
        }
    }

    /// True if rays that run close together are traced faster as a group
    /// ([`Geometry::intersect_group`]) than one by one: where every primitive is in the BVH
    /// (packets) or none is (lanes).
    #[inline]
    pub fn groups_pay(&self) -> bool {
        self.packets_pay() || self.all_packed()
    }

    /// The nearest hits of `rays`, which run close together (a pixel's camera rays), into
    /// `hits` (cleared first, then one entry per ray): in lanes where every primitive is packed
    /// ([`Geometry::intersect_batch`]), else as [`Geometry::intersect_coherent`] traces them.
    /// The one-ray hits to the bit, either way.
    pub fn intersect_group(&self, rays: &[Ray], hits: &mut Vec<Option<Hit>>) {
        if self.all_packed() {
            self.intersect_batch(rays, hits);
        } else {
            self.intersect_coherent(rays, hits);
        }
    }

    /// True if [`Geometry::intersect_packet`] traces packets here: every primitive is in the
    /// BVH (elsewhere it traces ray by ray).
    #[inline]
    pub fn packets_pay(&self) -> bool {
        !self.has_packets() && !self.bvh.is_empty()
    }

    /// The nearest hits of up to [`PACKET`] rays that run close together (lanes past
    /// `rays.len()` are `None`), as [`Geometry::intersect_coherent`] finds them.
    pub fn intersect_packet(&self, rays: &[Ray]) -> [Option<Hit>; PACKET] {
        assert!(rays.len() <= PACKET, "at most {PACKET} rays in a packet");
        let mut out = [None; PACKET];
        if !self.packets_pay() || rays.is_empty() {
            for (o, r) in out.iter_mut().zip(rays) {
                *o = self.intersect(r);
            }
            return out;
        }
        let boxes: [BvhRay; PACKET] =
            std::array::from_fn(|i| BvhRay::boxes(rays[i.min(rays.len() - 1)]));
        // The packet: the rays of the first ray's octant.
        let back = octant(&boxes[0]);
        let mut live = 0;
        for (i, b) in boxes.iter().enumerate().take(rays.len()) {
            if octant(b) == back {
                live |= 1 << i;
            }
        }
        let refs: [&BvhRay; PACKET] = std::array::from_fn(|i| {
            if live & (1 << i) != 0 {
                &boxes[i]
            } else {
                &boxes[0]
            }
        });
        // Each ray's leaf constants when it reaches its first leaf, and the normal of its
        // nearest lane hit, as in `intersect`.
        let mut leaf = PacketBlocks {
            geometry: self,
            rays: &refs,
            leaf_rays: Default::default(),
            normals: [None; PACKET],
        };
        let found = self.bvh.closest_packet(&refs, live, back, &mut leaf, &());
        let normals = leaf.normals;
        for (i, (ray, hit)) in rays.iter().zip(out.iter_mut()).enumerate() {
            // Rays of other octants, and ties, alone.
            let alone = live & (1 << i) == 0 || found.tied & (1 << i) != 0;
            *hit = if alone {
                self.intersect(ray)
            } else {
                found.best[i].map(|(prim, t)| self.nearest_record(ray, prim, t, normals[i]))
            };
        }
        out
    }

    /// Whether each ray of `rays` is blocked, as [`Geometry::occluded`] answers it, or as
    /// [`Geometry::occluded_in_room`] does if not `planes`, into `blocked` (cleared first,
    /// then one entry per ray).
    pub fn occluded_batch(&self, rays: &[Ray], planes: bool, blocked: &mut Vec<bool>) {
        self.occluded_batch_tallied(rays, planes, blocked, None);
    }

    /// [`Geometry::occluded_batch`], counting into `tally` if there is one.
    pub fn occluded_batch_tallied(
        &self,
        rays: &[Ray],
        planes: bool,
        blocked: &mut Vec<bool>,
        tally: Option<&Traversal>,
    ) {
        blocked.clear();
        if !self.all_packed() && !self.is_small() {
            match tally {
                Some(t) => blocked.extend(rays.iter().map(|r| self.occluded_tallied(r, planes, t))),
                None => blocked.extend(rays.iter().map(|r| self.occluded_tallied(r, planes, &()))),
            }
            return;
        }
        match self.bvh.isa() {
            // SAFETY: as in `intersect_batch`.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => unsafe { self.occluded_avx2(rays, planes, blocked, &tally) },
            // SAFETY: as above.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => unsafe { self.occluded_avx512(rays, planes, blocked, &tally) },
            // SAFETY: `Vec4` runs on every CPU.
            _ => unsafe { self.occluded_in::<Vec4>(rays, planes, blocked, &tally) },
        }
    }

    /// Primitives each ray in lanes tests for its nearest hit: every packed sphere and plane,
    /// or every triangle of a small scene ([`Geometry::is_small`]).
    #[inline]
    pub fn lane_prims(&self) -> u64 {
        (self.sphere_each.len() + self.plane_each.len() + self.triangle_each.len()) as u64
    }

    /// [`Geometry::intersect_batch`] in eight AVX2 lanes.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn intersect_avx2(
        &self,
        rays: &[Ray],
        hits: &mut Vec<Option<Hit>>,
        tally: &Option<&Traversal>,
    ) {
        // SAFETY: this function runs only where AVX2 was found.
        unsafe { self.intersect_in::<super::simd::avx2::F8>(rays, hits, tally) }
    }

    /// [`Geometry::occluded_batch`] in eight AVX2 lanes.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn occluded_avx2(
        &self,
        rays: &[Ray],
        planes: bool,
        blocked: &mut Vec<bool>,
        tally: &impl Tally,
    ) {
        // SAFETY: this function runs only where AVX2 was found.
        unsafe { self.occluded_in::<super::simd::avx2::F8>(rays, planes, blocked, tally) }
    }

    /// [`Geometry::intersect_batch`] in sixteen AVX-512 lanes.
    ///
    /// # Safety
    /// The CPU must have AVX-512F.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    unsafe fn intersect_avx512(
        &self,
        rays: &[Ray],
        hits: &mut Vec<Option<Hit>>,
        tally: &Option<&Traversal>,
    ) {
        // SAFETY: this function runs only where AVX-512F was found.
        unsafe { self.intersect_in::<super::simd::avx512::F16>(rays, hits, tally) }
    }

    /// [`Geometry::occluded_batch`] in sixteen AVX-512 lanes.
    ///
    /// # Safety
    /// The CPU must have AVX-512F.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    unsafe fn occluded_avx512(
        &self,
        rays: &[Ray],
        planes: bool,
        blocked: &mut Vec<bool>,
        tally: &impl Tally,
    ) {
        // SAFETY: this function runs only where AVX-512F was found.
        unsafe { self.occluded_in::<super::simd::avx512::F16>(rays, planes, blocked, tally) }
    }

    /// Which of the segments in the lanes are blocked, as [`Geometry::occluded`] answers each
    /// (or [`Geometry::occluded_in_room`] if not `planes`): from origins `o` (with errors
    /// `o_err`) along unit directions `d` to `t_max`. Only the lanes of `live` are asked; the
    /// others answer false; `tally` is told the primitives they test. For a shader that builds
    /// its rays in lanes (no gathering).
    #[inline(always)]
    pub fn occluded_lanes<L: Floats>(
        &self,
        (o, d, o_err, t_max): Segments<L>,
        planes: bool,
        live: L::Mask,
        tally: &impl Tally,
    ) -> L::Mask {
        if !self.all_packed() {
            // A small scene's triangles met in the lanes, which leave to the one-ray query only
            // the lanes they cannot settle; in other scenes, every live lane through the BVH.
            let (mut blocked, mut alone) = match self.is_small() {
                true => self.blocked_small(&ShearLanes::new(o, d, o_err), t_max, live, tally),
                false => (0, L::bitmask(live)),
            };
            if alone != 0 {
                let rows = SegmentRows::new((o, d, o_err, t_max));
                while alone != 0 {
                    let i = alone.trailing_zeros() as usize;
                    alone &= alone - 1;
                    if self.occluded_tallied(&rows.ray(i), planes, tally) {
                        blocked |= 1 << i;
                    }
                }
            }
            // SAFETY: `t_max` is a value of `L`, so the CPU runs `L`'s instruction set.
            return unsafe { lane_mask::<L>(blocked) };
        }
        let lanes = RayLanes::from_parts(o, d, o_err);
        // No lane blocked yet (nothing is below itself, NaN included).
        let mut hit = t_max.cmplt(t_max);
        let asked = L::bitmask(live).count_ones() as u64;
        tally.prims(asked * self.sphere_each.len() as u64);
        for (_, sphere) in &self.sphere_each {
            // SAFETY: as above.
            hit = hit | unsafe { sphere.splat::<L>() }.hit(&lanes, t_max).1;
        }
        // The planes only if asked, and while a live lane is not blocked yet.
        if planes && !L::all(hit | !live) {
            tally.prims(asked * self.plane_each.len() as u64);
            for (_, plane) in &self.plane_each {
                hit = hit | unsafe { plane.splat::<L>() }.hit(&lanes, t_max).1;
            }
        }
        hit & live
    }

    /// The nearest hits of `rays`, `L::LANES` at a time ([`Geometry::nearest_lanes`], or
    /// [`Geometry::nearest_small`] in a small scene, whose rays the lanes cannot settle go to
    /// the one-ray query, told to `tally`).
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn intersect_in<L: Floats>(
        &self,
        rays: &[Ray],
        hits: &mut Vec<Option<Hit>>,
        tally: &Option<&Traversal>,
    ) {
        for k in (0..rays.len()).step_by(L::LANES) {
            // SAFETY: the caller vouches for the instruction set.
            let (eight, t_max) = unsafe { chunk::<L>(rays, k) };
            let n = (rays.len() - k).min(L::LANES);
            if self.is_small() {
                let (o, d, o_err) = unsafe {
                    (
                        L::transpose3(&eight.map(|r| &r.o)),
                        L::transpose3(&eight.map(|r| &r.d)),
                        L::from_array(eight.map(|r| r.o_err)),
                    )
                };
                let near = self.nearest_small(&ShearLanes::new(o, d, o_err), t_max);
                let records = self.small_records(&near, o, d);
                hits.extend((0..n).map(|i| self.small_hit(&near, &records, i, eight[i], tally)));
                continue;
            }
            let lanes = unsafe { RayLanes::<L>::gather(&eight) };
            let rows = unsafe { self.nearest_lanes(&lanes, t_max) }.rows();
            hits.extend((0..n).map(|i| self.lane_hit(&rows, i)));
        }
    }

    /// The nearest hits of the rays in `lanes` within `t_max`, as [`Geometry::intersect`]
    /// finds them (spheres, then planes; a later primitive at equal distance wins), with
    /// their hit records: each lane keeps the parameters of the primitive it hits (a centre
    /// and radius, or a normal and offset) as the tests go, so that its record is computed in
    /// the lanes ([`sphere_surface`], [`plane_surface`]: `Sphere::surface` and
    /// `Plane::surface` lane by lane) with nothing gathered. For scenes whose primitives are
    /// all packed; lanes that hit nothing have a slot no primitive has
    /// ([`Geometry::slot_prim`]) and a record to be dropped.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    pub unsafe fn nearest_lanes<L: Floats>(&self, lanes: &RayLanes<L>, t_max: L) -> Nearest<L> {
        // SAFETY: the caller vouches for the instruction set (so for each block below).
        let (zero, one) = unsafe { (L::splat(0.0), L::splat(1.0)) };
        let mut t_max = t_max;
        // Each lane's slot, as the bits of a float lane (selects move bits unchanged), so
        // that no lane takes a branch. A lane's `ok` holds only hits within its `t_max`.
        let mut slot = unsafe { L::splat(f32::from_bits(u32::MAX)) };
        let (mut a, mut b, mut on_sphere) = ([zero; 3], zero, zero);
        for (j, (_, sphere)) in self.sphere_each.iter().enumerate() {
            let sphere = unsafe { sphere.splat::<L>() };
            let (t, ok) = sphere.hit(lanes, t_max);
            t_max = L::select(ok, t, t_max);
            slot = L::select(ok, unsafe { L::splat(f32::from_bits(j as u32)) }, slot);
            keep(ok, sphere.center_radius(), (&mut a, &mut b));
            on_sphere = L::select(ok, one, on_sphere);
        }
        for (j, (_, plane)) in self.plane_each.iter().enumerate() {
            let plane = unsafe { plane.splat::<L>() };
            let (t, ok) = plane.hit(lanes, t_max);
            t_max = L::select(ok, t, t_max);
            let j = (self.sphere_each.len() + j) as u32;
            slot = L::select(ok, unsafe { L::splat(f32::from_bits(j)) }, slot);
            keep(ok, plane.normal_dist(), (&mut a, &mut b));
            on_sphere = L::select(ok, zero, on_sphere);
        }
        // The spheres' and the planes' formulas, each where it applies.
        let sphere_lanes = on_sphere.cmpne(zero);
        let hit = if L::all(sphere_lanes) {
            sphere_surface(a, b, lanes, t_max)
        } else if !L::any(sphere_lanes) {
            plane_surface(a, b, lanes, t_max)
        } else {
            let (on_s, on_p) = (
                sphere_surface(a, b, lanes, t_max),
                plane_surface(a, b, lanes, t_max),
            );
            SurfaceLanes {
                p: [
                    L::select(sphere_lanes, on_s.p[0], on_p.p[0]),
                    L::select(sphere_lanes, on_s.p[1], on_p.p[1]),
                    L::select(sphere_lanes, on_s.p[2], on_p.p[2]),
                ],
                n: [
                    L::select(sphere_lanes, on_s.n[0], on_p.n[0]),
                    L::select(sphere_lanes, on_s.n[1], on_p.n[1]),
                    L::select(sphere_lanes, on_s.n[2], on_p.n[2]),
                ],
                err: L::select(sphere_lanes, on_s.err, on_p.err),
                err_along: L::select(sphere_lanes, on_s.err_along, on_p.err_along),
            }
        };
        Nearest {
            t: t_max,
            slot,
            hit,
        }
    }

    /// Lane `i`'s nearest hit in `rows` ([`Nearest::rows`]), or `None` if it hit nothing.
    #[inline(always)]
    pub fn lane_hit(&self, rows: &NearestRows, i: usize) -> Option<Hit> {
        let v = &rows.0;
        self.slot_prim(v[1][i].to_bits()).map(|prim| Hit {
            t: v[0][i],
            p: glam::Vec3A::new(v[2][i], v[3][i], v[4][i]),
            n: glam::Vec3A::new(v[5][i], v[6][i], v[7][i]),
            err: v[8][i],
            err_along: v[9][i],
            prim,
        })
    }

    /// The primitive of a slot of [`Geometry::nearest_lanes`] (the packed spheres in order,
    /// then the planes), or `None` for a lane that hit nothing.
    #[inline]
    pub fn slot_prim(&self, slot: u32) -> Option<u32> {
        let (j, spheres) = (slot as usize, self.sphere_each.len());
        match self.sphere_each.get(j) {
            Some(&(prim, _)) => Some(prim),
            None => self
                .plane_each
                .get(j.wrapping_sub(spheres))
                .map(|&(prim, _)| prim),
        }
    }

    /// Whether `rays` are blocked, `L::LANES` at a time.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn occluded_in<L: Floats>(
        &self,
        rays: &[Ray],
        planes: bool,
        blocked: &mut Vec<bool>,
        tally: &impl Tally,
    ) {
        for k in (0..rays.len()).step_by(L::LANES) {
            // SAFETY: the caller vouches for the instruction set.
            let (four, t_max) = unsafe { chunk::<L>(rays, k) };
            let (o, d, o_err) = unsafe {
                (
                    L::transpose3(&four.map(|r| &r.o)),
                    L::transpose3(&four.map(|r| &r.d)),
                    L::from_array(four.map(|r| r.o_err)),
                )
            };
            // The lanes of the rays ask; the padding (the last ray again) does not.
            let n = (rays.len() - k).min(L::LANES);
            let real = unsafe {
                L::from_array(std::array::from_fn::<f32, MAX_LANES, _>(|i| i as f32))
                    .cmplt(L::splat(n as f32))
            };
            let hit = self.occluded_lanes((o, d, o_err, t_max), planes, real, tally);
            let mask = L::bitmask(hit);
            for i in 0..(rays.len() - k).min(L::LANES) {
                blocked.push(mask & (1 << i) != 0);
            }
        }
    }
}
