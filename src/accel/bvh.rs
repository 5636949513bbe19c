//! A binary bounding volume hierarchy built with the binned surface-area heuristic (costs in
//! blocks of four primitives) into an array of 32-byte nodes, the root first and each interior
//! node's first child after it, in depth-first order. The renderer collapses the nodes
//! ([`Bvh::build_nodes`]) into the eight-wide tree of [`super::wide`]; [`Bvh::build`] keeps
//! them, and its `closest` and `any` traversals are the reference the wide tree is tested
//! against.

use super::prim::Prim;
use crate::geometry::{Aabb, BvhRay};
use glam::Vec3;
use rayon::prelude::*;
use std::mem::MaybeUninit;

/// A flattened node. An interior node's first child follows it; `index` is its second child.
/// A leaf holds `count > 0` primitives starting at `index`.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct Node {
    /// Box minimum.
    pub min: Vec3,
    /// Second child (interior) or first primitive (leaf).
    pub index: u32,
    /// Box maximum.
    pub max: Vec3,
    /// Primitive count; 0 for interior nodes.
    pub count: u32,
}

/// The hierarchy; empty when the scene has no finite primitives.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    /// Nodes, root first.
    pub nodes: Vec<Node>,
}

const BINS: usize = 16;
/// Most primitives in a leaf: one block of lanes ([`super::block::Block`]).
const MAX_LEAF: usize = 4;
/// Cost of a node visit relative to one leaf test (SAH).
const TRAVERSAL_COST: f32 = 1.0;
// `build_node` keeps a leaf's worth of primitives a leaf without binning them, which holds
// because no split can cost less than a one-block leaf: the traversal alone costs as much.
const _: () = assert!(TRAVERSAL_COST >= 1.0);

/// The SAH's cost of testing `n` primitives: the blocks of four they fill, each tested in one
/// pass (Embree's SAH for its triangle4 leaves counts blocks the same way).
#[inline]
fn blocks(n: usize) -> f32 {
    n.div_ceil(MAX_LEAF) as f32
}
/// Traversal stack size; the build keeps the tree shallower than this.
const STACK: usize = 128;
/// Below this depth the build stops trusting the SAH and splits at the median, which bounds the
/// tree's depth by `MEDIAN_DEPTH + log2(N)`.
const MEDIAN_DEPTH: usize = 48;

/// A primitive's box and index, 32 bytes, partitioned in place so the build reads memory in
/// order. Aligned so that each corner, with the field after it, is one SSE load.
#[derive(Clone, Copy)]
#[repr(C, align(16))]
struct Item {
    min: Vec3,
    prim: u32,
    max: Vec3,
    /// The bin `best_split` put the item in at the node being split, which the partition
    /// then reads instead of computing it again.
    bin: u32,
}

// The layout `Item::bounds` loads.
const _: () = assert!(std::mem::size_of::<Item>() == 32 && std::mem::align_of::<Item>() == 16);

impl Item {
    /// The item of primitive `p`, the `i`th (bounded).
    fn new((i, p): (usize, &Prim)) -> Item {
        let b = p
            .shape
            .bounds()
            .expect("only bounded primitives go in the BVH");
        Item {
            min: b.min.into(),
            prim: i as u32,
            max: b.max.into(),
            bin: 0,
        }
    }

    /// Its box.
    #[inline]
    fn bounds(&self) -> Aabb {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{__m128, _mm_and_ps, _mm_castsi128_ps, _mm_set_epi32};
            // SAFETY: `Item` is `repr(C)`, 32 bytes and 16-byte aligned (asserted after it), so
            // bytes 0..16 (`min`, `prim`) and 16..32 (`max`, `bin`) are two aligned `__m128`s.
            // The fourth lane holds an integer, which glam's `Vec3A` ignores; it is cleared to
            // 0.0 so that no arithmetic meets its bits as a float (they can be subnormal,
            // which is slow). SSE2 is in the x86-64 baseline.
            unsafe {
                let corners = &*(self as *const Item as *const [__m128; 2]);
                let xyz = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
                Aabb {
                    min: _mm_and_ps(corners[0], xyz).into(),
                    max: _mm_and_ps(corners[1], xyz).into(),
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        Aabb {
            min: self.min.into(),
            max: self.max.into(),
        }
    }
    /// The centroid's coordinate on `axis`. Read through arrays: glam's `Vec3` index is a
    /// `match`, three compares per read, and binning reads this once per item and level.
    #[inline]
    fn centroid(&self, axis: usize) -> f32 {
        let (min, max): (&[f32; 3], &[f32; 3]) = (self.min.as_ref(), self.max.as_ref());
        0.5 * (min[axis] + max[axis])
    }
}

impl Bvh {
    /// Build over `prims` (all bounded); returns the BVH and the primitives reordered to match.
    pub fn build(prims: Vec<Prim>) -> (Bvh, Vec<Prim>) {
        let (nodes, order) = Bvh::build_nodes(&prims);
        let sorted = order.par_iter().map(|&i| prims[i as usize]).collect();
        (Bvh { nodes }, sorted)
    }

    /// Build over `prims` (all bounded) without moving them: the nodes of [`Bvh::nodes`] (the
    /// root first, then depth-first, an interior node's first child after it and its second at
    /// `index`), and the order of the primitives that leaves' `index..index + count` ranges
    /// refer to.
    pub fn build_nodes(prims: &[Prim]) -> (Vec<Node>, Vec<u32>) {
        if prims.is_empty() {
            return (Vec::new(), Vec::new());
        }
        let mut items: Vec<Item> = prims.par_iter().enumerate().map(Item::new).collect();
        let bounds = items.par_chunks(PARALLEL_MIN).map(fold_bounds).reduce(
            || (Aabb::EMPTY, Aabb::EMPTY),
            |a, b| (a.0.union(b.0), a.1.union(b.1)),
        );
        let mut pieces = Pieces::for_items(items.len());
        build_node(&mut items, 0, 0, &mut pieces, bounds);
        (pieces.join(), items.par_iter().map(|it| it.prim).collect())
    }

    /// Nearest primitive hit: its index in `prims` and distance.
    #[inline]
    pub fn closest(&self, prims: &[Prim], ray: &BvhRay) -> Option<(u32, f32)> {
        if self.nodes.is_empty() {
            return None;
        }
        // One working copy of the ray whose `t_max` shrinks with each closer hit.
        let mut r = *ray;
        let mut best = None;
        let mut stack = [MaybeUninit::<u32>::uninit(); STACK];
        let mut sp = 0usize;
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            if n.count > 0 {
                let first = n.index as usize;
                for (k, p) in prims[first..first + n.count as usize].iter().enumerate() {
                    if let Some(t) = p.shape.intersect_prepared(&r) {
                        r.ray.t_max = t;
                        best = Some(((first + k) as u32, t));
                    }
                }
            } else {
                let (a, b) = (node + 1, n.index as usize);
                let ta = self.box_hit(a, &r, r.t_max);
                let tb = self.box_hit(b, &r, r.t_max);
                match (ta, tb) {
                    (Some(ta), Some(tb)) => {
                        let (near, far) = if ta <= tb { (a, b) } else { (b, a) };
                        stack[sp].write(far as u32);
                        sp += 1;
                        node = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node = a;
                        continue;
                    }
                    (None, Some(_)) => {
                        node = b;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            // SAFETY: entries below `sp` were written before `sp` was raised past them.
            node = unsafe { stack[sp].assume_init() } as usize;
            // Skip nodes that a closer hit found meanwhile has made irrelevant.
            while self.box_hit(node, &r, r.t_max).is_none() {
                if sp == 0 {
                    return best;
                }
                sp -= 1;
                // SAFETY: entries below `sp` were written before `sp` was raised past them.
                node = unsafe { stack[sp].assume_init() } as usize;
            }
        }
        best
    }

    /// True if any primitive is hit within `(0, ray.t_max]`.
    #[inline]
    pub fn any(&self, prims: &[Prim], ray: &BvhRay) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let mut stack = [MaybeUninit::<u32>::uninit(); STACK];
        let mut sp = 0usize;
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            if self.box_hit(node, ray, ray.t_max).is_some() {
                if n.count > 0 {
                    let first = n.index as usize;
                    if prims[first..first + n.count as usize]
                        .iter()
                        .any(|p| p.shape.intersect_prepared(ray).is_some())
                    {
                        return true;
                    }
                } else {
                    stack[sp].write(n.index);
                    sp += 1;
                    node += 1;
                    continue;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: entries below `sp` were written before `sp` was raised past them.
            node = unsafe { stack[sp].assume_init() } as usize;
        }
    }

    #[inline]
    fn box_hit(&self, i: usize, ray: &BvhRay, t_max: f32) -> Option<f32> {
        let n = &self.nodes[i];
        Aabb {
            min: n.min.into(),
            max: n.max.into(),
        }
        .hit(ray.o, ray.inv_d, t_max)
    }
}

/// A tree's nodes in depth-first order, held in pieces built apart (one per subtree built in
/// parallel, and the nodes above them) and joined once at the end, so that no array sized for
/// the worst case is written and no subtree is copied at each level. While the nodes are in
/// pieces, an interior node's `index` is the distance from it to its second child (one more
/// than the size of its first subtree), which joining does not change.
struct Pieces {
    pieces: Vec<Vec<Node>>,
    /// Nodes in all the pieces.
    len: usize,
}

impl Pieces {
    /// No nodes yet, with room in a first piece for what a subtree over `items` items puts
    /// there: its root alone if it is built in parallel (its sides bring pieces of their
    /// own), else all its nodes, which are fewer than its items unless its leaves are small
    /// (the piece then grows).
    fn for_items(items: usize) -> Pieces {
        let room = if items > PARALLEL_MIN { 1 } else { items };
        Pieces {
            pieces: vec![Vec::with_capacity(room)],
            len: 0,
        }
    }

    /// Append `node`; returns its place: its piece and its index there, and its position in
    /// the joined array.
    fn push(&mut self, node: Node) -> (usize, usize, usize) {
        let last = self.pieces.len() - 1;
        let piece = &mut self.pieces[last];
        piece.push(node);
        self.len += 1;
        (last, piece.len() - 1, self.len - 1)
    }

    /// Make the node at `(piece, slot, at)` ([`Pieces::push`]) interior, its second child the
    /// next node to come.
    fn link(&mut self, (piece, slot, at): (usize, usize, usize)) {
        let n = &mut self.pieces[piece][slot];
        n.index = u32::try_from(self.len - at).expect("at most 2^32 nodes");
        n.count = 0;
    }

    /// Append the nodes of `other`, in order; the next push goes to a new piece.
    fn append(&mut self, other: Pieces) {
        self.len += other.len;
        self.pieces
            .extend(other.pieces.into_iter().filter(|p| !p.is_empty()));
        self.pieces.push(Vec::new());
    }

    /// The nodes in one array, each interior node's `index` made the position of its second
    /// child; the pieces are copied in parallel.
    fn join(self) -> Vec<Node> {
        let mut out = Vec::with_capacity(self.len);
        let mut rest = &mut out.spare_capacity_mut()[..self.len];
        let mut jobs = Vec::with_capacity(self.pieces.len());
        let mut start = 0;
        for piece in &self.pieces {
            let (dst, after) = rest.split_at_mut(piece.len());
            jobs.push((dst, piece, start));
            rest = after;
            start += piece.len();
        }
        // What `push` and `append` keep: `len` counts the pieces' nodes.
        assert_eq!(start, self.len, "the pieces' nodes against their count");
        jobs.into_par_iter().for_each(|(dst, piece, start)| {
            for (k, (d, &n)) in dst.iter_mut().zip(piece).enumerate() {
                let index = match n.count {
                    0 => n.index + (start + k) as u32,
                    _ => n.index,
                };
                d.write(Node { index, ..n });
            }
        });
        // SAFETY: the jobs wrote every one of the first `self.len` elements: the pieces hold
        // `self.len` nodes in all (asserted above), and each was given its own part of them.
        unsafe { out.set_len(self.len) };
        out
    }
}

/// Subtrees over more primitives than this are built in parallel.
const PARALLEL_MIN: usize = 4096;

/// Append the subtree over `order` to `out`, in depth-first order: the node, then its first
/// subtree, then its second. `offset` is where `order` starts in the final primitive array.
///
/// `(bounds, cbounds)` are the boxes of the items and of their centroids, passed down from the
/// split that made this subtree so no pass over the items recomputes them.
fn build_node(
    order: &mut [Item],
    offset: usize,
    depth: usize,
    out: &mut Pieces,
    (bounds, cbounds): (Aabb, Aabb),
) {
    let me = out.push(Node {
        min: bounds.min.into(),
        index: offset as u32,
        max: bounds.max.into(),
        count: order.len() as u32,
    });
    if order.len() <= 1 {
        return;
    }
    let extent = cbounds.max - cbounds.min;
    let axis = extent.max_position();
    // A leaf's worth of primitives stays a leaf without binning: any split costs at least
    // the traversal (`TRAVERSAL_COST`, at least 1) plus the children's non-negative share, so
    // never less than the leaf (one block, cost 1).
    let split = if extent[axis] > 0.0 && depth < MEDIAN_DEPTH && order.len() > MAX_LEAF {
        best_split(order, &cbounds, axis, bounds.area())
    } else {
        None
    };
    let (mid, sides) = match split {
        Some((bin, left, right)) => {
            // Each item's bin, as binning found it.
            let (mid, lc, rc) = partition(order, bin as u32);
            (mid, Some(((left, lc), (right, rc))))
        }
        // A leaf's worth, a flat centroid box, the depth limit, or every item in one bin:
        // keep a leaf if it is small enough, else split the middle.
        None if order.len() <= MAX_LEAF && depth < MEDIAN_DEPTH => return,
        None => {
            let k = order.len() / 2;
            order.select_nth_unstable_by(k, |a, b| a.centroid(axis).total_cmp(&b.centroid(axis)));
            (k, None)
        }
    };
    let (mid, sides) = if mid == 0 || mid == order.len() {
        (order.len() / 2, None)
    } else {
        (mid, sides)
    };
    let (left_bounds, right_bounds) =
        sides.unwrap_or_else(|| (fold_bounds(&order[..mid]), fold_bounds(&order[mid..])));
    let parallel = order.len() > PARALLEL_MIN;
    let n = order.len();
    let (left_order, right_order) = order.split_at_mut(mid);
    let mut left = |out: &mut Pieces| build_node(left_order, offset, depth + 1, out, left_bounds);
    let mut right =
        |out: &mut Pieces| build_node(right_order, offset + mid, depth + 1, out, right_bounds);
    if parallel {
        // Each side into pieces of its own, joined in order.
        let (mut l, mut r) = (Pieces::for_items(mid), Pieces::for_items(n - mid));
        rayon::join(|| left(&mut l), || right(&mut r));
        out.append(l);
        out.link(me);
        out.append(r);
    } else {
        left(out);
        out.link(me);
        right(out);
    }
}

/// The bin of centroid coordinate `c` on `BINS` bins from `lo`, `scale` bins per unit: the
/// floor of `(c - lo) scale`, at most `BINS - 1`, and 0 for NaN (`0 * inf` on a one-ulp-wide
/// range), as `(x as usize).min(BINS - 1)` gives it.
#[inline]
fn bin_of(c: f32, lo: f32, scale: f32) -> usize {
    let x = (c - lo) * scale;
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{
            _mm_cvttss_si32, _mm_max_ss, _mm_min_ss, _mm_set_ss, _mm_setzero_ps,
        };
        // `maxss` returns its second operand when either is NaN, so NaN becomes 0 and the value
        // is clamped to [0, BINS - 1] before the truncation: three instructions where Rust's
        // saturating `as usize` takes a dozen, a fifth of the build's binning time.
        // SAFETY: SSE2 is in the x86-64 baseline; these intrinsics only compute on registers.
        unsafe {
            let clamped = _mm_min_ss(
                _mm_max_ss(_mm_set_ss(x), _mm_setzero_ps()),
                _mm_set_ss((BINS - 1) as f32),
            );
            _mm_cvttss_si32(clamped) as usize
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        (x as usize).min(BINS - 1)
    }
}

/// Boxes of a set of items and of their centroids.
fn fold_bounds(items: &[Item]) -> (Aabb, Aabb) {
    items.iter().fold((Aabb::EMPTY, Aabb::EMPTY), |(b, c), it| {
        let ib = it.bounds();
        (b.union(ib), c.grow(ib.centroid()))
    })
}

/// Nodes over more items than this bin them in parallel.
const PARALLEL_BINNING_MIN: usize = 1 << 16;

/// Per bin: the box of the items and their count. (Not the box of their centroids: the
/// partition gathers those for the sides it makes, so that binning, the build's larger part,
/// loads and stores one box per item instead of two: at 1M triangles, a sixth off the whole
/// build's time, measured.)
type Bins = [(Aabb, usize); BINS];

/// A split the SAH chose: the bin after which it falls, then the box of the left side's items
/// and that of the right side's.
type Chosen = (usize, Aabb, Aabb);

/// The bins of `items` along `axis`, the first from `lo`, `scale` bins per unit; each item
/// keeps its bin in `Item::bin`.
fn bin_items(items: &mut [Item], axis: usize, lo: f32, scale: f32) -> Bins {
    let mut bins = [(Aabb::EMPTY, 0usize); BINS];
    for it in items {
        let ib = it.bounds();
        let bin = bin_of(it.centroid(axis), lo, scale);
        it.bin = bin as u32;
        let b = &mut bins[bin];
        b.0 = b.0.union(ib);
        b.1 += 1;
    }
    bins
}

/// [`bin_items`], in parallel by chunks for a node over more than [`PARALLEL_BINNING_MIN`]
/// items, merged in order: the counts are sums, and on NaN-free boxes (scenes hold finite
/// values, and `Triangle::new` refuses the rest) the minima and maxima of the chunks' minima
/// and maxima are those of one pass, to the bit (of equal values, `minps` and `maxps` keep
/// the later, in either order of work), so the merged bins are the ones one pass fills.
fn bins_of(items: &mut [Item], axis: usize, lo: f32, scale: f32) -> Bins {
    let fill = |items: &mut [Item]| bin_items(items, axis, lo, scale);
    if items.len() <= PARALLEL_BINNING_MIN {
        return fill(items);
    }
    let merge = |a: Bins, b: Bins| -> Bins {
        std::array::from_fn(|k| (a[k].0.union(b[k].0), a[k].1 + b[k].1))
    };
    // At least four chunks per node binned in parallel: enough to share among the threads,
    // few enough that merging costs nothing.
    items
        .par_chunks_mut(PARALLEL_BINNING_MIN / 4)
        .map(fill)
        .reduce(|| [(Aabb::EMPTY, 0); BINS], merge)
}

/// The bin after which to split more than a leaf's worth of items along `axis` at the least
/// SAH cost, with the items' boxes of both sides; `None` if every item falls in one
/// bin. (A leaf's worth never gets here: see `build_node`.) Each item keeps its bin in
/// `Item::bin` for the partition.
fn best_split(order: &mut [Item], cb: &Aabb, axis: usize, area: f32) -> Option<Chosen> {
    let (lo, scale) = (cb.min[axis], BINS as f32 / (cb.max[axis] - cb.min[axis]));
    sweep(&bins_of(order, axis, lo, scale), area)
}

/// The SAH cost of splitting a node whose box has surface `area` into sides with the given
/// item boxes' surfaces and counts: a visit, plus each side's blocks weighted by the chance that
/// a ray through the node enters that side's box.
#[inline]
fn split_cost((left, nl): (f32, usize), (right, nr): (f32, usize), area: f32) -> f32 {
    TRAVERSAL_COST + (left * blocks(nl) + right * blocks(nr)) / area.max(f32::MIN_POSITIVE)
}

/// The SAH's choice among the splits between `bins` of a node whose box has surface `area`:
/// the bin after which to split, and the items' boxes of both sides; `None` if every item
/// falls in one bin. Of equal costs the first is kept.
fn sweep(bins: &Bins, area: f32) -> Option<Chosen> {
    // The bins that hold items, in order. On NaN-free boxes an empty bin changes no union and
    // no count, and the split after it has the same sides as the split after the last full
    // bin before it (whose cost is the same operations on the same boxes, kept as the first
    // of equal costs), or an empty left side: skipping empty bins finds the same split, and
    // small nodes leave most bins empty.
    let mut full = [0usize; BINS];
    let mut m = 0;
    for (k, bin) in bins.iter().enumerate() {
        if bin.1 > 0 {
            full[m] = k;
            m += 1;
        }
    }
    // Sweep from the right for every right side's surface and count (`right[i]`: the full
    // bins from the `i`th on), then from the left over the splits after each full bin but the
    // last; only the chosen split's right box is built again, at the end, in the same order
    // of unions.
    let mut right = [(0.0f32, 0usize); BINS];
    let mut acc = (Aabb::EMPTY, 0);
    for i in (1..m).rev() {
        let b = &bins[full[i]];
        acc = (acc.0.union(b.0), acc.1 + b.1);
        right[i] = (acc.0.area(), acc.1);
    }
    let mut acc = (Aabb::EMPTY, 0);
    // The least cost so far, and the position among the full bins, the bin and the left
    // side's box of its split.
    let (mut least, mut best) = (f32::INFINITY, None);
    for i in 0..m.saturating_sub(1) {
        let (k, b) = (full[i], &bins[full[i]]);
        acc = (acc.0.union(b.0), acc.1 + b.1);
        let cost = split_cost((acc.0.area(), acc.1), right[i + 1], area);
        if cost < least {
            (least, best) = (cost, Some((i, k, acc.0)));
        }
    }
    let (i, k, left) = best?;
    let mut rb = Aabb::EMPTY;
    for &j in full[i + 1..m].iter().rev() {
        rb = rb.union(bins[j].0);
    }
    Some((k, left, rb))
}

/// Moves the items binned in `bin` or before to the front; returns how many there are, and
/// the boxes of the centroids of those and of the others.
fn partition(v: &mut [Item], bin: u32) -> (usize, Aabb, Aabb) {
    let mut i = 0;
    let (mut lc, mut rc) = (Aabb::EMPTY, Aabb::EMPTY);
    for j in 0..v.len() {
        let c = v[j].bounds().centroid();
        if v[j].bin <= bin {
            lc = lc.grow(c);
            v.swap(i, j);
            i += 1;
        } else {
            rc = rc.grow(c);
        }
    }
    (i, lc, rc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::displaced_sphere;
    use glam::Vec3A;

    /// A box's bits, to compare boxes exactly (signed zeros apart).
    fn bits(b: &Aabb) -> [u32; 6] {
        let (lo, hi) = (b.min.to_array(), b.max.to_array());
        [lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]].map(f32::to_bits)
    }

    /// Bins' boxes and counts as bits.
    fn bin_bits(bins: &Bins) -> Vec<([u32; 6], usize)> {
        bins.iter().map(|b| (bits(&b.0), b.1)).collect()
    }

    /// Binning by chunks in parallel fills the bins one pass fills, to the bit (signed zeros
    /// included, where the order of the minima and maxima decides which comes out), and gives
    /// each item the same bin.
    #[test]
    fn parallel_binning_equals_one_pass() {
        let mesh = displaced_sphere(3 * PARALLEL_BINNING_MIN, Vec3::ZERO, 1.0, 0.05);
        let prims = Prim::flat_triangles(&mesh);
        let mut items: Vec<Item> = prims.iter().enumerate().map(Item::new).collect();
        assert!(items.len() > PARALLEL_BINNING_MIN);
        // Every item's smallest x and largest z a zero, of either sign by turns: each bin's
        // box then has zeros there, whose signs depend on the order of the unions.
        for (k, it) in items.iter_mut().enumerate() {
            let zero = if k % 3 == 0 { -0.0 } else { 0.0 };
            (it.min.x, it.max.z) = (zero, -zero);
        }
        let mut again = items.clone();
        let (parallel, one) = (
            bins_of(&mut items, 1, -1.0, 7.5),
            bin_items(&mut again, 1, -1.0, 7.5),
        );
        assert_eq!(bin_bits(&parallel), bin_bits(&one));
        assert!(items.iter().zip(&again).all(|(a, b)| a.bin == b.bin));
        assert!(
            one.iter().filter(|b| b.1 > 0).count() == BINS,
            "every bin filled"
        );
    }

    /// The SAH sweep as it was before it skipped empty bins: every split after bins 0 to
    /// 14 with two non-empty sides costed in turn.
    fn sweep_every_bin(bins: &Bins, area: f32) -> Option<Chosen> {
        let mut right = [(Aabb::EMPTY, 0usize); BINS];
        let mut acc = (Aabb::EMPTY, 0);
        for k in (1..BINS).rev() {
            let b = &bins[k];
            acc = (acc.0.union(b.0), acc.1 + b.1);
            right[k] = acc;
        }
        let mut acc = (Aabb::EMPTY, 0);
        let mut best = (f32::INFINITY, None);
        for k in 0..BINS - 1 {
            let b = &bins[k];
            acc = (acc.0.union(b.0), acc.1 + b.1);
            let (rb, rc) = right[k + 1];
            if acc.1 == 0 || rc == 0 {
                continue;
            }
            let cost = split_cost((acc.0.area(), acc.1), (rb.area(), rc), area);
            if cost < best.0 {
                best = (cost, Some((k, acc.0, rb)));
            }
        }
        best.1
    }

    /// The sweep over the full bins chooses what the sweep over every bin chooses, to the
    /// bit: on bins mostly empty (as in small nodes), drawn from a few boxes and counts so
    /// that equal costs are common (the first is kept), with signed zeros among the corners.
    #[test]
    fn sweeping_full_bins_equals_sweeping_every_bin() {
        let mut s = crate::sampling::Sampler::new(9, 0, 0);
        let corner = |s: &mut crate::sampling::Sampler| {
            let pick = [0.0, -0.0, 0.25, 1.0, 2.5][(s.next_f32() * 5.0) as usize % 5];
            if s.next_f32() < 0.5 {
                pick
            } else {
                s.next_f32() * 4.0 - 2.0
            }
        };
        let (mut ties, mut splits) = (0, 0);
        for case in 0..20_000 {
            let empty = [0.3, 0.6, 0.9][case % 3];
            let bins: Bins = std::array::from_fn(|_| {
                if s.next_f32() < empty {
                    return (Aabb::EMPTY, 0);
                }
                let a = Vec3A::new(corner(&mut s), corner(&mut s), corner(&mut s));
                let b = Vec3A::new(corner(&mut s), corner(&mut s), corner(&mut s));
                let bounds = Aabb::EMPTY.grow(a).grow(b);
                let count = 1 + (s.next_f32() * 9.0) as usize;
                (bounds, count)
            });
            let area = bins.iter().fold(Aabb::EMPTY, |a, b| a.union(b.0)).area();
            let show = |c: Option<Chosen>| c.map(|(k, l, r)| (k, bits(&l), bits(&r)));
            let (new, old) = (sweep(&bins, area), sweep_every_bin(&bins, area));
            assert_eq!(show(new), show(old), "case {case}");
            splits += new.is_some() as usize;
            // A later split of the same cost as the one kept.
            let costs: Vec<f32> = (0..BINS - 1)
                .filter_map(|k| {
                    let (l, r) = bins.split_at(k + 1);
                    let side = |b: &[(Aabb, usize)]| {
                        b.iter()
                            .fold((Aabb::EMPTY, 0), |(a, n), b| (a.union(b.0), n + b.1))
                    };
                    let ((la, ln), (ra, rn)) = (side(l), side(r));
                    (ln > 0 && rn > 0).then(|| split_cost((la.area(), ln), (ra.area(), rn), area))
                })
                .collect();
            let least = costs.iter().copied().fold(f32::INFINITY, f32::min);
            ties += (costs.iter().filter(|&&c| c == least).count() > 1) as usize;
        }
        assert!(
            splits > 10_000 && ties > 500,
            "{splits} splits, {ties} with tied costs"
        );
    }

    /// The fast bin index equals the saturating conversion it replaces on every kind of value:
    /// NaN, infinities, signed zeros, negatives, bin edges and their neighbours, and a sweep.
    #[test]
    fn bin_of_matches_saturating_conversion() {
        let reference = |x: f32| (x as usize).min(BINS - 1);
        let mut xs = vec![
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            0.0,
            -0.0,
            -1.0,
            f32::MAX,
            f32::MIN_POSITIVE,
            1e-45,
            4e9,
            2f32.powi(31),
            2f32.powi(63),
        ];
        for b in 0..=BINS + 1 {
            let e = b as f32;
            xs.extend([e, e.next_down(), e.next_up()]);
        }
        xs.extend((0..100_000).map(|k| k as f32 * 0.000_17 - 0.5));
        for x in xs {
            // bin_of computes (c - lo) * scale: with lo = 0 and scale = 1 that is x itself.
            assert_eq!(bin_of(x, 0.0, 1.0), reference(x), "{x}");
        }
        // 0 * inf: a centroid at the low end of a range too thin for its scale.
        assert_eq!(bin_of(1.0, 1.0, f32::INFINITY), reference(f32::NAN));
    }
}
