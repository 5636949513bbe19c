//! A bounding volume hierarchy built with the binned surface-area heuristic and flattened into
//! an array of 32-byte nodes in depth-first order.

use super::Prim;
use crate::geometry::{Aabb, Ray};
use glam::{Vec3, Vec3A};
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
const MAX_LEAF: usize = 4;
/// Cost of a node visit relative to one primitive test (SAH).
const TRAVERSAL_COST: f32 = 1.0;
/// Traversal stack size; the build keeps the tree shallower than this.
const STACK: usize = 128;
/// Below this depth the build stops trusting the SAH and splits at the median, which bounds the
/// tree's depth by `MEDIAN_DEPTH + log2(N)`.
const MEDIAN_DEPTH: usize = 48;

struct Item {
    bounds: Aabb,
    centroid: Vec3A,
}

impl Bvh {
    /// Build over `prims` (all bounded); returns the BVH and the primitives reordered to match.
    pub fn build(prims: Vec<Prim>) -> (Bvh, Vec<Prim>) {
        if prims.is_empty() {
            return (Bvh::default(), prims);
        }
        let items: Vec<Item> = prims
            .iter()
            .map(|p| {
                let bounds = p
                    .shape
                    .bounds()
                    .expect("only bounded primitives go in the BVH");
                Item {
                    bounds,
                    centroid: bounds.centroid(),
                }
            })
            .collect();
        let mut order: Vec<u32> = (0..prims.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * prims.len());
        build_node(&items, &mut order, 0, 0, &mut nodes);
        let sorted = order.iter().map(|&i| prims[i as usize]).collect();
        (Bvh { nodes }, sorted)
    }

    /// Nearest primitive hit: its index in `prims` and distance.
    #[inline]
    pub fn closest<const K: u32>(&self, prims: &[Prim], ray: &Ray) -> Option<(u32, f32)> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut t_max = ray.t_max;
        let mut best = None;
        let mut stack = [MaybeUninit::<u32>::uninit(); STACK];
        let mut sp = 0usize;
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            if n.count > 0 {
                let first = n.index as usize;
                for (k, p) in prims[first..first + n.count as usize].iter().enumerate() {
                    let r = Ray { t_max, ..*ray };
                    if let Some(t) = p.shape.intersect_in::<K>(&r) {
                        t_max = t;
                        best = Some(((first + k) as u32, t));
                    }
                }
            } else {
                let (a, b) = (node + 1, n.index as usize);
                let ta = self.box_hit(a, ray, t_max);
                let tb = self.box_hit(b, ray, t_max);
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
            while self.box_hit(node, ray, t_max).is_none() {
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
    pub fn any<const K: u32>(&self, prims: &[Prim], ray: &Ray) -> bool {
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
                        .any(|p| p.shape.intersect_in::<K>(ray).is_some())
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
    fn box_hit(&self, i: usize, ray: &Ray, t_max: f32) -> Option<f32> {
        let n = &self.nodes[i];
        Aabb {
            min: n.min.into(),
            max: n.max.into(),
        }
        .hit(ray.o, ray.inv_d, t_max)
    }
}

/// Build the subtree over `order` (indices into `items`); `offset` is where `order` starts in
/// the final primitive array. Returns the node's index.
fn build_node(
    items: &[Item],
    order: &mut [u32],
    offset: usize,
    depth: usize,
    nodes: &mut Vec<Node>,
) -> usize {
    let bounds = order
        .iter()
        .fold(Aabb::EMPTY, |b, &i| b.union(items[i as usize].bounds));
    let me = nodes.len();
    nodes.push(Node {
        min: bounds.min.into(),
        index: offset as u32,
        max: bounds.max.into(),
        count: order.len() as u32,
    });
    if order.len() <= 1 {
        return me;
    }
    let cbounds = order
        .iter()
        .fold(Aabb::EMPTY, |b, &i| b.grow(items[i as usize].centroid));
    let extent = cbounds.max - cbounds.min;
    let axis = extent.max_position();
    let split = if extent[axis] > 0.0 && depth < MEDIAN_DEPTH {
        best_split(items, order, &cbounds, axis, bounds.area())
    } else {
        None
    };
    let mid = match split {
        Some(bin) => {
            let (lo, w) = (cbounds.min[axis], extent[axis]);
            partition(order, |&i| {
                bin_of(items[i as usize].centroid[axis], lo, w) <= bin
            })
        }
        // No split beats a leaf: keep a leaf if it is small enough, else split the middle.
        None if order.len() <= MAX_LEAF && depth < MEDIAN_DEPTH => return me,
        None => {
            order.sort_by(|&a, &b| {
                items[a as usize].centroid[axis].total_cmp(&items[b as usize].centroid[axis])
            });
            order.len() / 2
        }
    };
    let mid = if mid == 0 || mid == order.len() {
        order.len() / 2
    } else {
        mid
    };
    let (left, right) = order.split_at_mut(mid);
    build_node(items, left, offset, depth + 1, nodes);
    let r = build_node(items, right, offset + mid, depth + 1, nodes);
    nodes[me].index = r as u32;
    nodes[me].count = 0;
    me
}

#[inline]
fn bin_of(c: f32, lo: f32, w: f32) -> usize {
    (((c - lo) / w * BINS as f32) as usize).min(BINS - 1)
}

/// The bin after which to split along `axis`, if splitting is cheaper than a leaf by the SAH.
fn best_split(items: &[Item], order: &[u32], cb: &Aabb, axis: usize, area: f32) -> Option<usize> {
    let (lo, w) = (cb.min[axis], cb.max[axis] - cb.min[axis]);
    let mut bins = [(Aabb::EMPTY, 0usize); BINS];
    for &i in order {
        let it = &items[i as usize];
        let b = &mut bins[bin_of(it.centroid[axis], lo, w)];
        b.0 = b.0.union(it.bounds);
        b.1 += 1;
    }
    // Sweep from the right to get the cost of every right side, then from the left.
    let mut right = [(0.0f32, 0usize); BINS];
    let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
    for k in (1..BINS).rev() {
        acc = acc.union(bins[k].0);
        cnt += bins[k].1;
        right[k] = (acc.area(), cnt);
    }
    let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
    let mut best = (f32::INFINITY, None);
    for k in 0..BINS - 1 {
        acc = acc.union(bins[k].0);
        cnt += bins[k].1;
        let (ra, rc) = right[k + 1];
        if cnt == 0 || rc == 0 {
            continue;
        }
        let cost = TRAVERSAL_COST
            + (acc.area() * cnt as f32 + ra * rc as f32) / area.max(f32::MIN_POSITIVE);
        if cost < best.0 {
            best = (cost, Some(k));
        }
    }
    let leaf_cost = order.len() as f32;
    if best.0 < leaf_cost || order.len() > MAX_LEAF {
        best.1
    } else {
        None
    }
}

/// Moves the elements for which `pred` holds to the front; returns how many there are.
fn partition(v: &mut [u32], pred: impl Fn(&u32) -> bool) -> usize {
    let mut i = 0;
    for j in 0..v.len() {
        if pred(&v[j]) {
            v.swap(i, j);
            i += 1;
        }
    }
    i
}
