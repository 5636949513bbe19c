//! Ray queries in batches: four rays in the SIMD lanes, tested against one primitive at a time.
//!
//! A shader that holds many rays at once (the Global shader's tree of indirect rays, the shadow
//! rays of all its hits) hands them over together. Where every primitive is packed (planes,
//! and the spheres of small scenes), four rays fill the lanes and each primitive is splatted
//! across them ([`Geometry::sphere_each`], [`Geometry::plane_each`]): no lane is padding, no
//! closest-lane search runs per ray, and the ray's constants are computed once. Each lane runs
//! the arithmetic the one-ray query runs for its pair, in the same order of primitives and with
//! the same tie rule, so the answers are bit-identical to [`Geometry::intersect`] and
//! [`Geometry::occluded`]. Scenes with a BVH answer ray by ray.

use super::Geometry;
use super::lanes::RayLanes;
use crate::geometry::{Hit, Ray};
use glam::{BVec4A, Vec4};

/// The four rays of a batch's chunk starting at `k` (the last ray repeated past the end; its
/// answers are dropped).
#[inline(always)]
fn chunk(rays: &[Ray], k: usize) -> [&Ray; 4] {
    let last = rays.len() - 1;
    [0, 1, 2, 3].map(|i| &rays[(k + i).min(last)])
}

impl Geometry {
    /// True if the batched queries can put rays in the lanes: every primitive is packed.
    #[inline]
    fn all_packed(&self) -> bool {
        self.bvh.nodes.is_empty()
    }

    /// The nearest hit of each ray of `rays`, as [`Geometry::intersect`] finds it, into `hits`
    /// (cleared first, then one entry per ray).
    pub fn intersect_batch(&self, rays: &[Ray], hits: &mut Vec<Option<Hit>>) {
        hits.clear();
        if !self.all_packed() {
            hits.extend(rays.iter().map(|r| self.intersect(r)));
            return;
        }
        for k in (0..rays.len()).step_by(4) {
            let four = chunk(rays, k);
            let lanes = RayLanes::gather(four);
            let mut t_max = Vec4::from_array(four.map(|r| r.t_max));
            // Each lane's best primitive index, as the bits of a float lane (selects move bits
            // unchanged), so that no lane takes a branch.
            let mut best = Vec4::splat(f32::from_bits(u32::MAX));
            // Spheres, then planes, as the one-ray query; a later primitive at equal distance
            // wins. A lane's `ok` holds only hits within its current `t_max`.
            let take = |id: u32, (t, ok): (Vec4, BVec4A), t_max: &mut Vec4, best: &mut Vec4| {
                *t_max = Vec4::select(ok, t, *t_max);
                *best = Vec4::select(ok, Vec4::splat(f32::from_bits(id)), *best);
            };
            for (id, sphere) in &self.sphere_each {
                take(*id, sphere.hit(&lanes, t_max), &mut t_max, &mut best);
            }
            for (id, plane) in &self.plane_each {
                take(*id, plane.hit(&lanes, t_max), &mut t_max, &mut best);
            }
            let (t, best) = (t_max.to_array(), best.to_array().map(f32::to_bits));
            let n = (rays.len() - k).min(4);
            hits.extend(
                (0..n).map(|i| {
                    (best[i] != u32::MAX).then(|| self.hit_record(four[i], best[i], t[i]))
                }),
            );
        }
    }

    /// Whether each ray of `rays` is blocked, as [`Geometry::occluded`] answers it, or as
    /// [`Geometry::occluded_in_room`] does if not `planes`, into `blocked` (cleared first,
    /// then one entry per ray).
    pub fn occluded_batch(&self, rays: &[Ray], planes: bool, blocked: &mut Vec<bool>) {
        blocked.clear();
        if !self.all_packed() {
            blocked.extend(rays.iter().map(|r| match planes {
                true => self.occluded(r),
                false => self.occluded_in_room(r),
            }));
            return;
        }
        for k in (0..rays.len()).step_by(4) {
            let four = chunk(rays, k);
            let lanes = RayLanes::gather(four);
            let t_max = Vec4::from_array(four.map(|r| r.t_max));
            let mut hit = BVec4A::FALSE;
            for (_, sphere) in &self.sphere_each {
                hit |= sphere.hit(&lanes, t_max).1;
            }
            // The planes only if asked, and while a lane is not blocked yet.
            if planes && !hit.all() {
                for (_, plane) in &self.plane_each {
                    hit |= plane.hit(&lanes, t_max).1;
                }
            }
            let n = (rays.len() - k).min(4);
            let mask = hit.bitmask();
            blocked.extend((0..n).map(|i| mask & (1 << i) != 0));
        }
    }
}
