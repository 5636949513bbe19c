//! Ray queries over the prepared geometry: packets of four planes and (in small scenes) four
//! spheres tested with SSE, and a BVH over the remaining finite primitives.

mod batch;
pub mod block;
mod bvh;
pub mod lanes;
mod prim;
mod simd;
mod small;
pub mod tally;
pub mod wide;

pub use batch::{Nearest, NearestRows, SegmentRows, Segments};
pub use bvh::{Bvh, Node};
pub use prim::{FLAT, Prim};
#[cfg(target_arch = "x86_64")]
pub use simd::avx2::F8;
#[cfg(target_arch = "x86_64")]
pub use simd::avx512::F16;
pub use simd::{Floats, Isa, MAX_LANES, require_all_isas};
pub use small::{SMALL_SCENE, ShearLanes, SmallNearest, record_hit};
pub use tally::{Tally, Traversal};
pub use wide::{WideBvh, WideNode};

use crate::geometry::{BvhRay, Hit, Ray};
use crate::shape::{Shape, ShapeKind, Surface};
use block::{Block, BlockRay};
use lanes::{Lanes, PlaneLanes, RayLanes, SphereLanes};
use rayon::prelude::*;

/// Scenes with at most this many spheres test them in packets instead of a BVH.
pub const PACKED_SPHERES: usize = 16;

/// Append packed primitives to `others`; returns each shape with its index among all
/// primitives (after the `slots` of the BVH's blocks).
fn append<T>(others: &mut Vec<Prim>, slots: usize, packed: Vec<(Prim, T)>) -> Vec<(u32, T)> {
    packed
        .into_iter()
        .map(|(p, shape)| {
            others.push(p);
            ((slots + others.len() - 1) as u32, shape)
        })
        .collect()
}

/// What shading needs of a BVH triangle besides its vertices (which its block holds):
/// [`Prim`]'s other fields in 8 bytes. A smooth triangle's vertex normals are
/// [`Geometry::normals`]' entry at its lane's index.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attrs {
    /// Index into the prepared material array, with [`SMOOTH`] set for a smooth triangle.
    pub material: u32,
    /// Area light, or [`crate::light::NO_LIGHT`].
    pub light: u32,
}

/// Set in [`Attrs::material`] for a triangle with vertex normals.
pub const SMOOTH: u32 = 1 << 31;

impl Attrs {
    /// The attributes of a padding lane, which no ray hits.
    const NONE: Attrs = Attrs {
        material: !SMOOTH,
        light: crate::light::NO_LIGHT,
    };
}

/// The hit on primitive `prim` at distance `t` whose surface there is `s`.
#[inline(always)]
fn hit_on(s: Surface, prim: u32, t: f32) -> Hit {
    Hit {
        t,
        p: s.p,
        n: s.n,
        err: s.err,
        err_along: s.err_along,
        prim,
    }
}

/// The leaf tests' constants of one query's ray ([`BvhRay::sheared`] and [`BlockRay`]),
/// computed when it reaches its first leaf: most rays of an incoherent set leave the tree
/// before that, and the box tests need only `1 / d`.
#[derive(Default)]
struct LeafRay(Option<(BvhRay, BlockRay)>);

impl LeafRay {
    /// The ray `r` of the traversal (box constants only) with the triangle test's constants if
    /// `triangles`, and in lanes, as the first call made them: the ray keeps the first call's
    /// `t_max`, which a nearest-hit query does not read (its leaf tests take the current reach
    /// apart) and an any-hit query never shortens.
    #[inline(always)]
    fn get(&mut self, r: &BvhRay, triangles: bool) -> (&BvhRay, &BlockRay) {
        let (full, lanes) = self.0.get_or_insert_with(|| {
            let full = if triangles { r.sheared() } else { *r };
            (full, BlockRay::new(&full))
        });
        (full, lanes)
    }
}

/// The leaf test of [`Geometry::intersect`]'s walk: a block's nearest hit, the unit normal
/// of the last one kept. A type of its own (not a closure) so that its test is inlined into
/// the walk and compiled for the walk's instruction set (a closure may stay a call).
struct NearestBlock<'a, T> {
    geometry: &'a Geometry,
    r: &'a BvhRay,
    leaf_ray: LeafRay,
    lane_normal: Option<glam::Vec3A>,
    tally: &'a T,
}

impl<T: Tally> wide::NearestLeaf for &mut NearestBlock<'_, T> {
    #[inline(always)]
    fn nearest(&mut self, b: u32, t_max: f32) -> Option<(u32, f32)> {
        let g = self.geometry;
        let (r, br) = self.leaf_ray.get(self.r, g.has_triangles);
        let block = &g.blocks[b as usize];
        self.tally.prims(block.count as u64);
        let (lane, t, n) = block.closest(&g.others, br, r, t_max)?;
        // The last hit a leaf reports is the nearest: keep its normal.
        self.lane_normal = n;
        Some((4 * b + lane, t))
    }
}

/// All of a scene's primitives, ready for ray queries.
///
/// A primitive's index (what [`Hit::prim`] holds) below `4 * blocks.len()` is a lane of a BVH
/// block (`4 * block + lane`); a BVH triangle is stored only there, its vertices in the block
/// and the rest in `attrs`. Indices from `4 * blocks.len()` on are `others`' entries in order.
#[derive(Clone, Debug, Default)]
pub struct Geometry {
    /// The primitives that are not BVH triangles: the BVH's other shapes (spheres of large
    /// scenes, which blocks send to the scalar test), then the packed spheres and the planes.
    pub others: Vec<Prim>,
    /// How many primitives the BVH holds.
    pub in_bvh: usize,
    /// Eight-wide BVH; a leaf's payload indexes `blocks`.
    pub bvh: WideBvh,
    /// The BVH's leaves, each with its triangles in lanes.
    pub blocks: Vec<Block>,
    /// Material, smoothness and light of each block lane (`4 * block + lane`).
    pub attrs: Vec<Attrs>,
    /// Spheres in packets of four (small scenes).
    pub spheres: Lanes<SphereLanes>,
    /// Infinite planes in packets of four.
    pub planes: Lanes<PlaneLanes>,
    /// Each packed sphere alone, with its prim index, in the order of `spheres`: what a batch
    /// of rays in the lanes is tested against, splatted ([`Geometry::intersect_batch`]).
    pub sphere_each: Vec<(u32, SphereLanes<f32>)>,
    /// Each plane alone, with its prim index, in the order of `planes`.
    pub plane_each: Vec<(u32, PlaneLanes<f32>)>,
    /// Vertex normals of triangles with corner attributes (zero where a triangle has texture
    /// coordinates but no normals: it shades with its geometric normal), at their lane's index
    /// (empty if no triangle has any).
    pub normals: Vec<[glam::Vec3A; 3]>,
    /// Texture coordinates of the same triangles' corners, at the same indices (the barycentric
    /// defaults `(0, 0), (1, 0), (0, 1)` where a triangle has normals but no coordinates);
    /// empty if no triangle has coordinates.
    pub uvs: Vec<[glam::Vec2; 3]>,
    /// True if the BVH holds triangles: its rays then need the watertight test's shear
    /// constants.
    pub has_triangles: bool,
    /// In a scene of at most [`SMALL_SCENE`] primitives, all of them triangles in the BVH's
    /// lanes, each of them, for rays in lanes ([`Geometry::nearest_small`]); empty otherwise.
    triangle_each: Vec<small::TriangleEach>,
}

impl Geometry {
    /// Sort the primitives into packets and a BVH; `normals` holds the vertex normals that
    /// smooth primitives refer to.
    ///
    /// The build runs on one of rayon's worker threads (called from elsewhere, it waits for
    /// one): each parallel step started outside the pool hands its work over to a worker and
    /// sleeps until it is done, and the build has about ten such steps. Run whole on a worker,
    /// a build of 10k triangles took about 8% less time on two threads and 20% less on one.
    pub fn build(prims: Vec<Prim>, normals: Vec<[glam::Vec3A; 3]>) -> Self {
        Self::build_with_uvs(prims, normals, Vec::new())
    }

    /// [`Geometry::build`] with the corners' texture coordinates: `uvs` (empty, or as long as
    /// `normals`) at the same indices as `normals`.
    pub fn build_with_uvs(
        prims: Vec<Prim>,
        normals: Vec<[glam::Vec3A; 3]>,
        uvs: Vec<[glam::Vec2; 3]>,
    ) -> Self {
        rayon::scope(|_| Self::build_on_worker(prims, normals, uvs))
    }

    /// [`Geometry::build_with_uvs`], run where it is called.
    fn build_on_worker(
        prims: Vec<Prim>,
        normals: Vec<[glam::Vec3A; 3]>,
        uvs: Vec<[glam::Vec2; 3]>,
    ) -> Self {
        // What goes to packets instead of the BVH, counted in parallel: planes, and spheres in
        // small scenes.
        let (n_spheres, n_planes) = prims
            .par_iter()
            .map(|p| match p.shape.kind() {
                ShapeKind::Sphere => (1, 0),
                ShapeKind::Plane => (0, 1),
                _ => (0, 0),
            })
            .reduce(|| (0usize, 0usize), |a, b| (a.0 + b.0, a.1 + b.1));
        let pack_spheres = n_spheres <= PACKED_SPHERES;
        // One pass, if anything goes to packets: planes to theirs, spheres to theirs in small
        // scenes, the rest to the BVH. The packets keep each shape with its primitive, so no
        // kind is lost. (A mesh has nothing to move and skips the pass.)
        let (mut planes, mut spheres) = (Vec::new(), Vec::new());
        let mut for_bvh = prims;
        if n_planes > 0 || (pack_spheres && n_spheres > 0) {
            for_bvh.retain(|p| match p.shape {
                Shape::Plane(pl) => {
                    planes.push((*p, pl));
                    false
                }
                Shape::Sphere(s) if pack_spheres => {
                    spheres.push((*p, s));
                    false
                }
                _ => true,
            });
        }
        let has_triangles = for_bvh
            .iter()
            .any(|p| p.shape.kind() == ShapeKind::Triangle);
        let (binary, order) = Bvh::build_nodes(&for_bvh);
        // The wide tree first, each leaf named by its rank; then the leaves' blocks and
        // attributes in parallel, in that order (the reads of the primitives, in leaf order,
        // are most of the work).
        let (bvh, ranges) = WideBvh::collapse(&binary);
        drop(binary);
        // A leaf's primitives, by reference (no copies of the 96-byte primitives); lanes
        // past `count` repeat the first. The leaves come in the order of `order`, whose
        // primitives lie scattered: each leaf asks for those `AHEAD` places further on, so
        // that their cache misses overlap with this leaf's work.
        const AHEAD: usize = 32;
        let leaf = |(first, count): (usize, usize)| {
            for k in first..first + count {
                let ahead = order[(k + AHEAD).min(order.len() - 1)] as usize;
                wide::prefetch(&for_bvh[ahead]);
            }
            let mut leaf = [&for_bvh[order[first] as usize]; 4];
            for (k, p) in leaf.iter_mut().enumerate().take(count) {
                *p = &for_bvh[order[first + k] as usize];
            }
            (leaf, count)
        };
        // Each leaf's block and lane attributes from one read of its primitives. A lane holds
        // a triangle unless its block marks it scalar.
        let in_lane = |b: &Block, k: usize| k < b.count as usize && b.scalar & (1 << k) == 0;
        let (mut blocks, lanes): (Vec<Block>, Vec<[Attrs; 4]>) = ranges
            .par_iter()
            .map(|&range| {
                let (leaf, count) = leaf(range);
                let block = Block::new(&leaf[..count], 0);
                let attrs = [0, 1, 2, 3].map(|k| match in_lane(&block, k) {
                    true => {
                        let p = leaf[k];
                        assert!(p.material < SMOOTH, "at most 2^31 materials");
                        let smooth = if p.smooth == FLAT { 0 } else { SMOOTH };
                        Attrs {
                            material: p.material | smooth,
                            light: p.light,
                        }
                    }
                    false => Attrs::NONE,
                });
                (block, attrs)
            })
            .unzip();
        // The lanes' attributes in block order, in place (no copy).
        let attrs: Vec<Attrs> = lanes.into_flattened();
        // The primitives of scalar lanes, kept whole in `others` in leaf order; each block
        // notes where its own start.
        let mut others: Vec<Prim> = Vec::new();
        for (block, &(first, _)) in blocks
            .iter_mut()
            .zip(&ranges)
            .filter(|(b, _)| b.scalar != 0)
        {
            block.other = others.len() as u32;
            let mut scalar = block.scalar;
            while scalar != 0 {
                let k = scalar.trailing_zeros() as usize;
                scalar &= scalar - 1;
                others.push(for_bvh[order[first + k] as usize]);
            }
        }
        let (normals, uvs) = (&normals, &uvs);
        // Corner attributes move to their lane's index; a primitive with them kept whole (a
        // triangle a lane cannot hold exactly) gets them appended after the lanes'.
        let any = attrs.iter().any(|a| a.material & SMOOTH != 0)
            || others.iter().any(|p| p.smooth != FLAT);
        // Each lane's index into the tables, or FLAT.
        let sources: Vec<u32> = if any {
            ranges
                .par_iter()
                .zip(&blocks)
                .flat_map_iter(|(&range, block)| {
                    let (leaf, _) = leaf(range);
                    (0..4).map(move |k| match in_lane(block, k) {
                        true => leaf[k].smooth,
                        false => FLAT,
                    })
                })
                .collect()
        } else {
            Vec::new()
        };
        fn to_lanes<T: Copy + Send + Sync>(sources: &[u32], table: &[T], none: T) -> Vec<T> {
            if table.is_empty() {
                return Vec::new();
            }
            sources
                .par_iter()
                .map(|&i| if i == FLAT { none } else { table[i as usize] })
                .collect()
        }
        let mut lane_normals = to_lanes(&sources, normals, [glam::Vec3A::ZERO; 3]);
        let mut lane_uvs = to_lanes(&sources, uvs, [glam::Vec2::ZERO; 3]);
        drop(sources);
        for p in others.iter_mut().filter(|p| p.smooth != FLAT) {
            lane_normals.push(normals[p.smooth as usize]);
            if !uvs.is_empty() {
                lane_uvs.push(uvs[p.smooth as usize]);
            }
            p.smooth = (lane_normals.len() - 1) as u32;
        }
        let in_bvh = for_bvh.len();
        drop(for_bvh);
        // A small scene of triangles alone keeps each for rays in lanes.
        let triangle_each = match others.is_empty() && spheres.is_empty() && planes.is_empty() {
            true => small::triangle_each(&blocks),
            false => Vec::new(),
        };
        let slots = attrs.len();
        let sphere_items = append(&mut others, slots, spheres);
        let plane_items = append(&mut others, slots, planes);
        let spheres = lanes::pack(&sphere_items, SphereLanes::pack);
        let planes = lanes::pack(&plane_items, PlaneLanes::pack);
        Geometry {
            others,
            in_bvh,
            bvh,
            blocks,
            attrs,
            sphere_each: spheres.each(SphereLanes::lane),
            plane_each: planes.each(PlaneLanes::lane),
            spheres,
            planes,
            normals: lane_normals,
            uvs: lane_uvs,
            has_triangles,
            triangle_each,
        }
    }

    /// True if no plane can block a segment from any ray's origin to `p`: every plane is
    /// oriented ([`crate::shape::Plane::side`]) and `p` is on its side, beyond its error band.
    /// A shadow ray towards such a point skips the planes ([`Geometry::occluded_in_room`]).
    pub fn in_room(&self, p: glam::Vec3A) -> bool {
        self.others.iter().all(|prim| match prim.shape {
            Shape::Plane(plane) => plane.side != 0.0 && plane.side_of(p, 0.0) == plane.side,
            _ => true,
        })
    }

    /// The shading normal at point `p` of primitive `prim` whose geometric normal is `n`:
    /// the vertex normals interpolated with `p`'s barycentric coordinates for smooth
    /// triangles, `n` otherwise.
    #[inline]
    pub fn shading_normal(&self, prim: &Prim, p: glam::Vec3A, n: glam::Vec3A) -> glam::Vec3A {
        match (prim.smooth, prim.shape) {
            (FLAT, _) => n,
            (i, Shape::Triangle(t)) => {
                let [n0, n1, n2] = self.normals[i as usize];
                let (b1, b2) = barycentric(&t, p);
                let ns = ((1.0 - b1 - b2) * n0 + b1 * n1 + b2 * n2).normalize_or_zero();
                if ns == glam::Vec3A::ZERO { n } else { ns }
            }
            _ => n,
        }
    }

    /// The texture coordinates `(u, v)` at point `p` of primitive `prim` (Mitsuba 3's
    /// conventions; `docs/scene-format.md`, "Texture coordinates"):
    ///
    /// - a triangle: its corners' coordinates interpolated with `p`'s barycentric coordinates
    ///   `(b1, b2)`, or `(b1, b2)` itself when it has none;
    /// - a sphere: `u = phi / (2 pi)` with `phi = atan2(y, x)` in [0, 2 pi), `v = theta / pi`
    ///   with `theta = acos(z)`, of the unit direction from its centre to `p`;
    /// - a plane: `p` less the plane's point, along the two world axes other than the one its
    ///   normal leans on most (`x, z` for a floor, `z, y` for a wall facing x, `x, y` for one
    ///   facing z), one unit per scene unit.
    #[inline]
    pub fn uv(&self, prim: &Prim, p: glam::Vec3A) -> glam::Vec2 {
        use glam::Vec2;
        match prim.shape {
            Shape::Triangle(t) => {
                let (b1, b2) = barycentric_by_areas(&t, p);
                match self.uvs.get(prim.smooth as usize) {
                    Some(&[t0, t1, t2]) if prim.smooth != FLAT => {
                        (1.0 - b1 - b2) * t0 + b1 * t1 + b2 * t2
                    }
                    _ => Vec2::new(b1, b2),
                }
            }
            Shape::Sphere(s) => crate::shape::sphere_uv((p - s.c) / s.r),
            Shape::Plane(pl) => {
                let d = p - pl.origin;
                let a = pl.n.abs();
                if a.y >= a.x && a.y >= a.z {
                    Vec2::new(d.x, d.z)
                } else if a.x >= a.z {
                    Vec2::new(d.z, d.y)
                } else {
                    Vec2::new(d.x, d.y)
                }
            }
        }
    }

    /// The primitive with index `index` (what a hit refers to).
    #[inline(always)]
    pub fn prim(&self, index: u32) -> Prim {
        let i = index as usize;
        if i >= self.attrs.len() {
            return self.others[i - self.attrs.len()];
        }
        let (block, lane) = (&self.blocks[i / 4], i % 4);
        match block.triangle(lane) {
            Some(t) => {
                let a = self.attrs[i];
                Prim {
                    shape: Shape::Triangle(t),
                    material: a.material & !SMOOTH,
                    smooth: if a.material & SMOOTH != 0 {
                        index
                    } else {
                        FLAT
                    },
                    light: a.light,
                }
            }
            None => self.others[block.other_index(lane as u32)],
        }
    }

    /// What shades primitive `index` (as [`Geometry::prim`] gives it, without its shape): its
    /// material, whether it is a smooth triangle (with vertex normals), and its area light.
    #[inline]
    pub fn shading_of(&self, index: u32) -> (u32, bool, u32) {
        let i = index as usize;
        let other = |p: &Prim| (p.material, p.smooth != FLAT, p.light);
        if i >= self.attrs.len() {
            return other(&self.others[i - self.attrs.len()]);
        }
        let (block, lane) = (&self.blocks[i / 4], i % 4);
        if block.has_triangle(lane) {
            let a = self.attrs[i];
            (a.material & !SMOOTH, a.material & SMOOTH != 0, a.light)
        } else {
            other(&self.others[block.other_index(lane as u32)])
        }
    }

    /// Every primitive's index: the occupied block lanes, then the primitives outside the BVH.
    pub fn indices(&self) -> impl Iterator<Item = u32> + '_ {
        let lanes = self
            .blocks
            .iter()
            .enumerate()
            .flat_map(|(b, block)| (0..block.count).map(move |lane| (4 * b) as u32 + lane));
        // The BVH's other shapes come first in `others`; its lanes already name them.
        let in_blocks: usize = self
            .blocks
            .iter()
            .map(|b| b.scalar.count_ones() as usize)
            .sum();
        let rest = (in_blocks..self.others.len()).map(|k| (self.attrs.len() + k) as u32);
        lanes.chain(rest)
    }

    /// Every primitive, in the order of [`Geometry::indices`].
    pub fn prims(&self) -> impl Iterator<Item = Prim> + '_ {
        self.indices().map(|i| self.prim(i))
    }

    /// True if any sphere or plane is tested in packets.
    #[inline]
    fn has_packets(&self) -> bool {
        !self.spheres.packs.is_empty() || !self.planes.packs.is_empty()
    }

    /// True if the scene has no primitive at all.
    pub fn is_empty(&self) -> bool {
        self.others.is_empty() && self.blocks.is_empty()
    }

    /// Number of primitives of each kind.
    pub fn count(&self, kind: ShapeKind) -> usize {
        self.prims().filter(|p| p.shape.kind() == kind).count()
    }

    /// The nearest hit along `ray` within `(0, ray.t_max]`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_tallied(ray, &())
    }

    /// [`Geometry::intersect`], telling `tally` the nodes and primitives it tests.
    #[inline]
    pub fn intersect_tallied(&self, ray: &Ray, tally: &impl Tally) -> Option<Hit> {
        #[cfg(target_arch = "x86_64")]
        if matches!(self.bvh.isa(), Isa::Avx2 | Isa::Avx512) {
            // SAFETY: the BVH's instruction set is one the CPU runs (`WideBvh::set_isa`).
            return unsafe { self.nearest_avx2(ray, tally) };
        }
        self.nearest_baseline(ray, tally)
    }

    /// [`Geometry::intersect_tallied`] in the baseline instruction set, out of line (as the
    /// AVX2 one is: inlined, it made its callers' code twice as large).
    #[inline(never)]
    fn nearest_baseline(&self, ray: &Ray, tally: &impl Tally) -> Option<Hit> {
        // SAFETY: with `false`, no instruction set beyond the baseline.
        unsafe { self.nearest_in::<false>(ray, tally) }
    }

    /// [`Geometry::intersect_tallied`] compiled for AVX2: the traversal and its leaf tests in
    /// one body.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn nearest_avx2(&self, ray: &Ray, tally: &impl Tally) -> Option<Hit> {
        // SAFETY: the caller's.
        unsafe { self.nearest_in::<true>(ray, tally) }
    }

    /// [`Geometry::intersect_tallied`]'s body, its BVH walked by AVX2's node test inlined if
    /// `AVX2`.
    ///
    /// # Safety
    /// With `AVX2`, the CPU must have AVX2 (and the caller should be compiled for it).
    #[inline(always)]
    unsafe fn nearest_in<const AVX2: bool>(&self, ray: &Ray, tally: &impl Tally) -> Option<Hit> {
        let mut t_max = ray.t_max;
        let mut best: Option<u32> = None;
        // The BVH's nearest hit, and its unit normal if a block's lane test found it.
        let (mut bvh_best, mut lane_normal) = (None, None);
        // The ray in lanes only for scenes with packets (a mesh scene has none).
        let lanes = self.has_packets().then(|| RayLanes::new(ray));
        if let Some(lanes) = &lanes {
            tally.prims(self.spheres.count as u64);
            self.spheres
                .closest(lanes, &mut t_max, &mut best, SphereLanes::hit);
        }
        if !self.bvh.is_empty() {
            let r = ray.for_bvh(t_max);
            let mut leaf = NearestBlock {
                geometry: self,
                r: &r,
                leaf_ray: LeafRay::default(),
                lane_normal: None,
                tally,
            };
            let touch = |b: u32| wide::prefetch(self.blocks.as_ptr().wrapping_add(b as usize));
            let found = match AVX2 {
                // SAFETY: the caller's.
                #[cfg(target_arch = "x86_64")]
                true => unsafe { self.bvh.closest_avx2_inline(&r, &mut leaf, touch, tally) },
                _ => self.bvh.closest_tallied(&r, &mut leaf, touch, tally),
            };
            lane_normal = leaf.lane_normal;
            if let Some((i, t)) = found {
                t_max = t;
                best = Some(i);
                bvh_best = best;
            }
        }
        if let Some(lanes) = &lanes {
            tally.prims(self.planes.count as u64);
            self.planes
                .closest(lanes, &mut t_max, &mut best, PlaneLanes::hit);
        }
        let prim = best?;
        Some(self.nearest_record(ray, prim, t_max, lane_normal.filter(|_| best == bvh_best)))
    }

    /// The hit record of `ray`'s nearest hit, on primitive `prim` at `t`, with the unit normal
    /// the BVH's lane test computed for it if it did.
    #[inline(always)]
    fn nearest_record(
        &self,
        ray: &Ray,
        prim: u32,
        t: f32,
        lane_normal: Option<glam::Vec3A>,
    ) -> Hit {
        match lane_normal {
            // A lane triangle whose normal the lane test computed: its record without
            // rebuilding the triangle (a cross product, a square root and three divisions on
            // the ray's last steps).
            Some(n) => {
                let block = &self.blocks[prim as usize / 4];
                let tri = block.triangle_with_normal(prim as usize % 4, n);
                hit_on(tri.surface(ray, t), prim, t)
            }
            None => self.hit_record(ray, prim, t),
        }
    }

    /// The hit of `ray` on primitive `prim` at distance `t`.
    #[inline]
    fn hit_record(&self, ray: &Ray, prim: u32, t: f32) -> Hit {
        hit_on(self.prim(prim).shape.surface(ray, t), prim, t)
    }

    /// True if anything blocks `ray` within `(0, ray.t_max]` (any-hit query for shadow rays).
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_by(ray, true, &())
    }

    /// [`Geometry::occluded`] for a segment that ends at a point [`Geometry::in_room`]: no
    /// plane can block it, so the planes are not tested.
    #[inline]
    pub fn occluded_in_room(&self, ray: &Ray) -> bool {
        self.occluded_by(ray, false, &())
    }

    /// [`Geometry::occluded`] (all planes, or none if not `planes`), telling `tally` the nodes
    /// and primitives it tests.
    #[inline]
    pub fn occluded_tallied(&self, ray: &Ray, planes: bool, tally: &impl Tally) -> bool {
        self.occluded_by(ray, planes, tally)
    }

    /// The any-hit query, testing the planes if `planes`. Kept out of line: inlined into the
    /// shaders' light loops it measured slower.
    #[inline(never)]
    fn occluded_by(&self, ray: &Ray, planes: bool, tally: &impl Tally) -> bool {
        #[cfg(target_arch = "x86_64")]
        if matches!(self.bvh.isa(), Isa::Avx2 | Isa::Avx512) {
            // SAFETY: the BVH's instruction set is one the CPU runs (`WideBvh::set_isa`).
            return unsafe { self.blocked_avx2(ray, planes, tally) };
        }
        // SAFETY: with `false`, no instruction set beyond the baseline.
        unsafe { self.blocked_in::<false>(ray, planes, tally) }
    }

    /// [`Geometry::occluded_by`] compiled for AVX2: the traversal and its leaf tests in one
    /// body.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn blocked_avx2(&self, ray: &Ray, planes: bool, tally: &impl Tally) -> bool {
        // SAFETY: the caller's.
        unsafe { self.blocked_in::<true>(ray, planes, tally) }
    }

    /// [`Geometry::occluded_by`]'s body, its BVH walked by AVX2's node test inlined if `AVX2`.
    ///
    /// # Safety
    /// With `AVX2`, the CPU must have AVX2 (and the caller should be compiled for it).
    #[inline(always)]
    unsafe fn blocked_in<const AVX2: bool>(
        &self,
        ray: &Ray,
        planes: bool,
        tally: &impl Tally,
    ) -> bool {
        (self.has_packets() && {
            let lanes = RayLanes::new(ray);
            self.spheres.any(&lanes, ray.t_max, SphereLanes::hit, tally)
                || (planes && self.planes.any(&lanes, ray.t_max, PlaneLanes::hit, tally))
        }) || (!self.bvh.is_empty() && {
            let r = ray.for_bvh(ray.t_max);
            let leaf = AnyBlock {
                geometry: self,
                leaf_ray: LeafRay::default(),
                tally,
            };
            match AVX2 {
                // SAFETY: the caller's.
                #[cfg(target_arch = "x86_64")]
                true => unsafe { self.bvh.any_avx2_inline(&r, leaf, tally) },
                _ => self.bvh.any_tallied(&r, leaf, tally),
            }
        })
    }
}

/// The leaf test of [`Geometry::occluded`]'s walk: whether a block blocks the ray. A type of
/// its own, as [`NearestBlock`].
struct AnyBlock<'a, T> {
    geometry: &'a Geometry,
    leaf_ray: LeafRay,
    tally: &'a T,
}

impl<T: Tally> wide::AnyLeaf for AnyBlock<'_, T> {
    #[inline(always)]
    fn any(&mut self, b: u32, r: &BvhRay) -> bool {
        let g = self.geometry;
        let (r, br) = self.leaf_ray.get(r, g.has_triangles);
        let block = &g.blocks[b as usize];
        self.tally.prims(block.count as u64);
        block.any(&g.others, br, r)
    }
}

impl Geometry {
    /// How fast the texture coordinates change along the surface of `prim` at `p`: the
    /// largest of `|grad u|` and `|grad v|` there, per scene unit (a footprint's width in
    /// coordinates is its width in scene units times this).
    #[inline]
    pub fn uv_rate(&self, prim: &Prim, p: glam::Vec3A) -> f32 {
        match prim.shape {
            Shape::Plane(_) => 1.0,
            Shape::Sphere(s) => {
                // u turns once around a circle of radius r sin(theta), v half a great circle.
                let d = ((p - s.c) / s.r).clamp(glam::Vec3A::splat(-1.0), glam::Vec3A::ONE);
                let sin = (1.0 - d.z * d.z).max(0.0).sqrt().max(1e-3);
                let tau = std::f32::consts::TAU;
                (1.0 / (tau * s.r * sin)).max(2.0 / (tau * s.r))
            }
            Shape::Triangle(t) => {
                // grad b1 and grad b2 in the triangle's plane, then u and v by their corners.
                let (e1, e2) = (t.v[1] - t.v[0], t.v[2] - t.v[0]);
                let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
                let det = d00 * d11 - d01 * d01;
                let g1 = (d11 * e1 - d01 * e2) / det;
                let g2 = (d00 * e2 - d01 * e1) / det;
                let [t0, t1, t2] = match self.uvs.get(prim.smooth as usize) {
                    Some(&c) if prim.smooth != FLAT => c,
                    _ => [glam::Vec2::ZERO, glam::Vec2::X, glam::Vec2::Y],
                };
                let (a, b) = (t1 - t0, t2 - t0);
                let gu = a.x * g1 + b.x * g2;
                let gv = a.y * g1 + b.y * g2;
                let rate = gu.length().max(gv.length());
                if rate.is_finite() { rate } else { 0.0 }
            }
        }
    }
}

impl Geometry {
    /// The direction in which `u` grows along the surface of `prim` at `p`, `dp/du` (not
    /// unit; Mitsuba 3's `dp_du`), for textured surfaces' shading frames: a triangle's from
    /// its corners' texture coordinates (pbrt-v4's `Triangle::InteractionFromIntersection`);
    /// the shape's tangent ([`Shape::tangent`], Mitsuba's frame for a mesh without
    /// coordinates) for a triangle without them (none kept, or the barycentric defaults a
    /// triangle without coordinates is given, in either order: whatever else the scene holds)
    /// or whose coordinates do not span the plane; a sphere's azimuth; a plane's `u` axis
    /// ([`Geometry::uv`]).
    #[inline]
    pub fn dp_du(&self, prim: &Prim, p: glam::Vec3A) -> glam::Vec3A {
        use glam::Vec2;
        match prim.shape {
            Shape::Triangle(t) => {
                let uvs = match self.uvs.get(prim.smooth as usize) {
                    Some(&c) if prim.smooth != FLAT => c,
                    _ => return prim.shape.tangent(p),
                };
                let barycentric = uvs[0] == Vec2::ZERO
                    && ((uvs[1], uvs[2]) == (Vec2::X, Vec2::Y)
                        || (uvs[1], uvs[2]) == (Vec2::Y, Vec2::X));
                if barycentric {
                    return prim.shape.tangent(p);
                }
                let (d02, d12) = (uvs[0] - uvs[2], uvs[1] - uvs[2]);
                let (p02, p12) = (t.v[0] - t.v[2], t.v[1] - t.v[2]);
                let det = d02.x * d12.y - d02.y * d12.x;
                let dpdu = (d12.y * p02 - d02.y * p12) / det;
                if det.abs() > 1e-12 && dpdu.is_finite() && dpdu != glam::Vec3A::ZERO {
                    dpdu
                } else {
                    prim.shape.tangent(p)
                }
            }
            Shape::Sphere(_) => prim.shape.tangent(p),
            Shape::Plane(pl) => {
                let a = pl.n.abs();
                if a.y >= a.x && a.y >= a.z || a.x < a.z {
                    glam::Vec3A::X
                } else {
                    glam::Vec3A::Z
                }
            }
        }
    }
}

/// The barycentric coordinates `(b1, b2)` of point `p` in triangle `t` as ratios of signed
/// areas, `((p - v0) x e2) . c / c . c` and `(e1 x (p - v0)) . c / c . c` with `c = e1 x e2`:
/// accurate on thin triangles, where the normal equations of [`barycentric`] cancel (texture
/// coordinates need it; shading normals keep [`barycentric`], whose bits the goldens hold).
/// Zero for a triangle of no area.
#[inline]
fn barycentric_by_areas(t: &crate::shape::Triangle, p: glam::Vec3A) -> (f32, f32) {
    let (e1, e2, ep) = (t.v[1] - t.v[0], t.v[2] - t.v[0], p - t.v[0]);
    let c = e1.cross(e2);
    let cc = c.dot(c);
    if cc.is_nan() || cc <= 0.0 {
        return (0.0, 0.0);
    }
    (ep.cross(e2).dot(c) / cc, e1.cross(ep).dot(c) / cc)
}

/// The barycentric coordinates `(b1, b2)` of point `p` in triangle `t` (the weights of its
/// second and third vertices), by the normal equations of `p - v0 = b1 e1 + b2 e2`.
#[inline]
fn barycentric(t: &crate::shape::Triangle, p: glam::Vec3A) -> (f32, f32) {
    let (e1, e2, ep) = (t.v[1] - t.v[0], t.v[2] - t.v[0], p - t.v[0]);
    let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d20, d21) = (ep.dot(e1), ep.dot(e2));
    let det = d00 * d11 - d01 * d01;
    let b1 = (d11 * d20 - d01 * d21) / det;
    let b2 = (d00 * d21 - d01 * d20) / det;
    (b1, b2)
}
