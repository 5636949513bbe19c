//! The BVH's structure and quality (src/accel/bvh.rs): every primitive in exactly one leaf,
//! boxes nested, and a surface-area-heuristic cost no worse than a plain object-median split
//! of the same primitives. A wrong split still gives right images (tests/integration/meshes.rs compares
//! hits with brute force) but a slower tree; the SAH cost sees it without timing anything.

use crate::common;

use glam::{Vec3, Vec3A};
use rtis::accel::{Bvh, Isa, Prim, WideBvh, require_all_isas, wide};
use rtis::geometry::{BvhRay, Ray};
use rtis::mesh::displaced_sphere;
use rtis::sampling::Sampler;
use rtis::sampling::warp::uniform_sphere;
use rtis::shape::{Shape, Triangle};

/// The binary tree and the primitives in its leaf order.
struct Built {
    bvh: Bvh,
    prims: Vec<Prim>,
}

fn build(prims: Vec<Prim>) -> Built {
    let (bvh, prims) = Bvh::build(prims);
    Built { bvh, prims }
}

fn mesh_prims(n: usize) -> Vec<Prim> {
    Prim::flat_triangles(&displaced_sphere(n, Vec3::ZERO, 1.0, 0.05))
}

fn area(min: Vec3, max: Vec3) -> f32 {
    let d = (max - min).max(Vec3::ZERO);
    2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
}

fn tri_box(p: &Prim) -> (Vec3, Vec3) {
    let Shape::Triangle(t) = p.shape else {
        unreachable!("the test builds triangles only")
    };
    let lo = t.v[0].min(t.v[1]).min(t.v[2]);
    let hi = t.v[0].max(t.v[1]).max(t.v[2]);
    (lo.into(), hi.into())
}

/// SAH cost of a top-down object-median tree (longest centroid axis, leaves of at most 4),
/// with one node visit costing as much as one leaf's block test, relative to the root's area.
fn median_cost(boxes: &mut [(Vec3, Vec3)], root_area: f32) -> f32 {
    let (lo, hi) = boxes.iter().fold((Vec3::MAX, Vec3::MIN), |(a, b), (l, h)| {
        (a.min(*l), b.max(*h))
    });
    let here = area(lo, hi) / root_area;
    if boxes.len() <= 4 {
        return here;
    }
    let c = |b: &(Vec3, Vec3)| (b.0 + b.1) * 0.5;
    let (clo, chi) = boxes.iter().fold((Vec3::MAX, Vec3::MIN), |(a, b), x| {
        (a.min(c(x)), b.max(c(x)))
    });
    let axis = (chi - clo).max_position();
    let k = boxes.len() / 2;
    boxes.select_nth_unstable_by(k, |a, b| c(a)[axis].total_cmp(&c(b)[axis]));
    let (l, r) = boxes.split_at_mut(k);
    here + median_cost(l, root_area) + median_cost(r, root_area)
}

#[test]
fn bvh_holds_every_primitive_once_in_nested_boxes_and_beats_a_median_split() {
    for n in [2_000, 20_000] {
        let prims = mesh_prims(n);
        let count = prims.len();
        let mut boxes: Vec<_> = prims.iter().map(tri_box).collect();
        let g = build(prims);
        let nodes = &g.bvh.nodes;
        let root_area = area(nodes[0].min, nodes[0].max);
        // Walk the tree: children inside parents, leaves cover 0..count once each.
        let mut seen = vec![0u32; count];
        let mut cost = 0.0f32;
        let mut stack = vec![0usize];
        let mut visited = 0;
        while let Some(i) = stack.pop() {
            visited += 1;
            let node = nodes[i];
            let rel = area(node.min, node.max) / root_area;
            if node.count > 0 {
                cost += rel * node.count.div_ceil(4) as f32;
                for k in node.index..node.index + node.count {
                    seen[k as usize] += 1;
                    let (lo, hi) = tri_box(&g.prims[k as usize]);
                    assert!(
                        lo.cmpge(node.min - Vec3::splat(1e-6)).all()
                            && hi.cmple(node.max + Vec3::splat(1e-6)).all(),
                        "primitive outside its leaf"
                    );
                }
            } else {
                cost += rel;
                for child in [i + 1, node.index as usize] {
                    let c = nodes[child];
                    assert!(
                        c.min.cmpge(node.min).all() && c.max.cmple(node.max).all(),
                        "child outside its parent"
                    );
                    stack.push(child);
                }
            }
        }
        assert!(
            seen.iter().all(|&s| s == 1),
            "a primitive is missing or repeated"
        );
        // Built in parallel pieces and joined, the array holds the tree and nothing else.
        assert_eq!(visited, nodes.len(), "nodes no walk from the root reaches");
        let median = median_cost(&mut boxes, root_area);
        // Measured: 21.6 against 24.8 at 2k triangles, 31.3 against 37.5 at 20k. A builder
        // that never finds a split better than a leaf falls back to the median split and ties
        // it.
        assert!(
            cost <= 0.9 * median,
            "{n} triangles: SAH cost {cost} against a median split's {median}"
        );
    }
}

/// Leaves hold at most 4 primitives even when no split separates them (every centroid the
/// same: 100 copies of one triangle, split at the median instead), and a set that a leaf
/// serves best (2 overlapping triangles) stays one leaf.
#[test]
fn leaves_stay_small_when_no_split_helps() {
    let t = Triangle::new(Vec3::ZERO.into(), Vec3::X.into(), Vec3::Y.into()).unwrap();
    let prim = Prim::flat(Shape::Triangle(t));
    let g = build(vec![prim; 100]);
    let leaves: Vec<u32> = g
        .bvh
        .nodes
        .iter()
        .filter(|n| n.count > 0)
        .map(|n| n.count)
        .collect();
    assert_eq!(leaves.iter().sum::<u32>(), 100);
    assert!(leaves.iter().all(|&c| c <= 4), "leaf sizes {leaves:?}");
    let g = build(vec![prim; 2]);
    assert_eq!(g.bvh.nodes.len(), 1, "two primitives: one leaf");
}

/// The leaf-or-split choice follows the SAH counted in blocks of four: a leaf of up to four
/// costs one block test, so four tiny triangles at the corners of a large box stay one leaf
/// (a split costs a node visit on top), while eight in two far-apart clusters of four split
/// between the clusters, each cluster one leaf.
#[test]
fn sets_split_where_the_sah_in_blocks_says() {
    let tri = |o: Vec3, s: f32| {
        let a = o;
        Prim::flat(Shape::Triangle(
            Triangle::new(a.into(), (a + Vec3::X * s).into(), (a + Vec3::Y * s).into()).unwrap(),
        ))
    };
    let corners = [
        Vec3::ZERO,
        Vec3::new(10., 0., 0.),
        Vec3::new(0., 10., 0.),
        Vec3::new(10., 10., 10.),
    ];
    let g = build(corners.iter().map(|&o| tri(o, 0.01)).collect());
    assert_eq!(g.bvh.nodes.len(), 1, "four triangles split");
    let clusters: Vec<Prim> = (0..8)
        .map(|i| {
            let far = if i % 2 == 0 { 0.0 } else { 100.0 };
            tri(Vec3::new(far + i as f32 * 0.1, 0.0, 0.0), 1.0)
        })
        .collect();
    let g = build(clusters);
    let nodes = &g.bvh.nodes;
    assert_eq!(nodes.len(), 3, "root and two leaves");
    for leaf in [&nodes[1], &nodes[nodes[0].index as usize]] {
        assert_eq!(leaf.count, 4);
        let xs: Vec<f32> = (leaf.index..leaf.index + 4)
            .map(|k| tri_box(&g.prims[k as usize]).0.x)
            .collect();
        let side = xs[0] >= 50.0;
        assert!(xs.iter().all(|&x| (x >= 50.0) == side), "mixed leaf {xs:?}");
    }
}

/// Random rays through and around a displaced sphere of radius 1: origins in [-2, 2]^3,
/// directions uniform, every third one a segment that ends inside the box.
fn rays(n: usize, seed: u64) -> Vec<Ray> {
    let mut s = Sampler::new(seed, 7, 0);
    (0..n)
        .map(|i| {
            let o = Vec3A::new(s.next_f32(), s.next_f32(), s.next_f32()) * 4.0 - Vec3A::splat(2.0);
            let d = uniform_sphere(s.next_f32(), s.next_f32());
            let t_max = if i % 3 == 0 { 1.5 } else { f32::INFINITY };
            Ray::segment(o, d, t_max)
        })
        .collect()
}

/// The wide tree over a binary one, each leaf's payload indexing its `(first, count)`.
fn collapse(bvh: &Bvh) -> (WideBvh, Vec<(usize, usize)>) {
    WideBvh::collapse(&bvh.nodes)
}

/// The tree once per instruction set this CPU runs (baseline first), so that every query is
/// checked in each.
fn each_isa(wide: &WideBvh) -> Vec<WideBvh> {
    Isa::all_available()
        .into_iter()
        .map(|isa| {
            let mut w = wide.clone();
            assert!(w.set_isa(isa));
            assert_eq!(w.isa(), isa);
            w
        })
        .collect()
}

/// The eight-wide tree holds every primitive of the binary one once, in the same leaves; each
/// child box contains the binary subtree's exact box: a top node's is that box, a quantised
/// node's decoded box is at most a grid step (1/255 of the parent's extent) larger on each side.
#[test]
fn wide_tree_holds_the_binary_leaves_in_boxes_that_contain_them() {
    let g = build(mesh_prims(20_000));
    let (wide, ranges) = collapse(&g.bvh);
    let binary_leaves = g.bvh.nodes.iter().filter(|n| n.count > 0).count();
    let mut seen = vec![0u32; g.prims.len()];
    let mut leaves = 0;
    // (wide node, the binary boxes of its children are checked through the leaves and the
    // nesting of their contents).
    let mut stack = vec![wide.root()];
    let mut top_nodes = 0;
    while let Some(i) = stack.pop() {
        let (child, boxes, step) = wide.child_boxes(i);
        top_nodes += (i & wide::TOP != 0) as usize;
        for slot in 0..wide::WIDTH {
            let c = child[slot];
            let Some((lo, hi)) = boxes[slot] else {
                assert_eq!(c, wide::EMPTY);
                continue;
            };
            // Everything below this slot must lie in its box.
            let mut below = vec![c];
            let (mut tight_lo, mut tight_hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
            while let Some(d) = below.pop() {
                if d & wide::LEAF != 0 {
                    let (first, count) = ranges[(d & !wide::LEAF) as usize];
                    for p in &g.prims[first..first + count] {
                        let (a, b) = tri_box(p);
                        tight_lo = tight_lo.min(a);
                        tight_hi = tight_hi.max(b);
                    }
                } else {
                    below.extend(wide.child_boxes(d).0.iter().filter(|&&x| x != wide::EMPTY));
                }
            }
            assert!(
                tight_lo.cmpge(lo).all() && tight_hi.cmple(hi).all(),
                "contents {tight_lo}..{tight_hi} outside the decoded box {lo}..{hi}"
            );
            // A top node's boxes are exact (a step of 0).
            assert!(
                (tight_lo - lo).cmple(step * 1.001).all()
                    && (hi - tight_hi).cmple(step * 1.001).all(),
                "decoded box {lo}..{hi} looser than a step {step} around {tight_lo}..{tight_hi}"
            );
            if c & wide::LEAF != 0 {
                leaves += 1;
                let (first, count) = ranges[(c & !wide::LEAF) as usize];
                for s in &mut seen[first..first + count] {
                    *s += 1;
                }
            } else {
                stack.push(c);
            }
        }
    }
    // The top levels are full over 20k triangles: 1 + 8 + 64 nodes.
    assert_eq!((top_nodes, wide.top.len()), (73, 73));
    assert!(
        seen.iter().all(|&s| s == 1),
        "a primitive missing or repeated"
    );
    assert_eq!(leaves, binary_leaves);
    assert_eq!(ranges.len(), binary_leaves);
    // Measured: 1,122 wide nodes for 5,505 binary interior ones (1,339 with the greedy
    // collapse that opened the largest children first, 1,701 when it did not open twigs first;
    // 2,626 four-wide). A wide node replaces up to seven binary ones, but only one where both
    // children are leaves; one that never opened a child would replace one each.
    let interior = g.bvh.nodes.len() - binary_leaves;
    assert!(
        wide.node_count() * 100 < interior * 22,
        "{} wide nodes for {interior} binary interior nodes",
        wide.node_count()
    );
    assert_eq!(
        std::mem::size_of::<rtis::accel::WideNode>(),
        128,
        "two cache lines"
    );
    assert_eq!(
        std::mem::size_of::<rtis::accel::wide::TopNode>(),
        256,
        "four cache lines"
    );
    assert_eq!(
        wide.node_bytes(),
        128 * wide.nodes.len() + 256 * wide.top.len()
    );
}

/// Boxes far from the origin, tiny, huge and flat keep containing what they hold after
/// quantisation: a wide tree over a mesh scaled by 1e-6 to 1e9 and moved up to 1e12 away
/// (every triangle keeping a non-zero area in single precision). Every leaf slot of both kinds
/// of node is checked; most hang off quantised nodes (the top levels hold at most 73 nodes).
#[test]
fn quantised_boxes_contain_their_triangles_at_every_scale() {
    for (scale, offset) in [
        (1e-6f32, 0.0f32),
        (1e-6, 3e-4),
        (1.0, 1e5),
        (1e9, 0.0),
        (1e9, -1e12),
    ] {
        let prims: Vec<Prim> = mesh_prims(20_000)
            .iter()
            .filter_map(|p| {
                let Shape::Triangle(t) = p.shape else {
                    unreachable!()
                };
                let v = t.v.map(|v| v * scale + Vec3A::splat(offset));
                Triangle::new(v[0], v[1], v[2]).map(|t| Prim::flat(Shape::Triangle(t)))
            })
            .collect();
        assert!(
            prims.len() > 15_000,
            "{scale} {offset}: {} triangles",
            prims.len()
        );
        let g = build(prims);
        let (wide, ranges) = collapse(&g.bvh);
        let refs = (0..wide.top.len() as u32).map(|i| wide::TOP | i);
        let mut quantised = 0;
        for r in refs.chain(0..wide.nodes.len() as u32) {
            let (child, boxes, _) = wide.child_boxes(r);
            for slot in 0..wide::WIDTH {
                let (Some((lo, hi)), c) = (boxes[slot], child[slot]) else {
                    continue;
                };
                if c & wide::LEAF != 0 {
                    quantised += (r & wide::TOP == 0) as usize;
                    let (first, count) = ranges[(c & !wide::LEAF) as usize];
                    for p in &g.prims[first..first + count] {
                        let (a, b) = tri_box(p);
                        assert!(
                            a.cmpge(lo).all() && b.cmple(hi).all(),
                            "scale {scale}: {a}..{b} outside {lo}..{hi}"
                        );
                    }
                }
            }
        }
        assert!(
            quantised > 3_000,
            "{quantised} leaves under quantised nodes"
        );
    }
}

/// `r` with its reach `t_max` (what the wide tree's traversal gives a leaf test).
fn reach(r: &BvhRay, t_max: f32) -> BvhRay {
    BvhRay {
        ray: Ray { t_max, ..r.ray },
        ..*r
    }
}

/// The nearest hit among `prims[first..first + count]` by the scalar loop (a later primitive
/// wins at equal distance).
fn scalar_leaf(prims: &[Prim], first: usize, count: usize, r: &Ray) -> Option<(u32, f32)> {
    common::nearest(&prims[first..first + count], r).map(|(k, t)| (first as u32 + k, t))
}

/// The wide tree answers every query as the binary one does: the same nearest primitive at the
/// bit-identical distance, and the same any-hit answer, for 20,000 random rays and segments.
#[test]
fn wide_tree_finds_what_the_binary_tree_finds() {
    let g = build(mesh_prims(20_000));
    let (wide, ranges) = collapse(&g.bvh);
    let leaf = |b: u32, r: &BvhRay| {
        let (first, count) = ranges[b as usize];
        scalar_leaf(&g.prims, first, count, r)
    };
    let any = |b: u32, r: &BvhRay| leaf(b, r).is_some();
    let (mut hits, mut blocked) = (0, 0);
    let trees = each_isa(&wide);
    for r in rays(20_000, 3) {
        let r = BvhRay::new(r);
        let expect = g.bvh.closest(&g.prims, &r);
        let occluded = g.bvh.any(&g.prims, &r);
        for wide in &trees {
            assert_eq!(
                wide.closest(&r, |b, t| leaf(b, &reach(&r, t)), |_| {}),
                expect,
                "{:?} {r:?}",
                wide.isa()
            );
            assert_eq!(wide.any(&r, any), occluded, "{:?} {r:?}", wide.isa());
        }
        hits += expect.is_some() as usize;
        blocked += occluded as usize;
    }
    assert!(
        hits > 2_000 && blocked == hits,
        "{hits} hits, {blocked} blocked"
    );
}

/// Rays aimed at the triangles' vertices, which lie on the corners and edges of the leaves'
/// boxes, where a ray's entry into a box and its exit are the same distance in exact arithmetic:
/// the node test's margins for rounding ([`wide`]'s exit reciprocal raised by `1 + 4 eps`, and
/// the reach a computed entry is compared with, raised alike) keep every such box, so the wide
/// tree finds what testing every triangle finds. (Without either margin, some of these rays
/// lose their hit or find one an ulp farther.)
#[test]
fn rays_aimed_at_vertices_find_what_every_triangle_finds() {
    let g = build(mesh_prims(2_000));
    let (wide, ranges) = collapse(&g.bvh);
    let leaf = |b: u32, r: &BvhRay| {
        let (first, count) = ranges[b as usize];
        scalar_leaf(&g.prims, first, count, r)
    };
    let trees = each_isa(&wide);
    let mut s = Sampler::new(11, 5, 0);
    let mut hits = 0;
    for _ in 0..20_000 {
        let o = Vec3A::new(s.next_f32(), s.next_f32(), s.next_f32()) * 4.0 - Vec3A::splat(2.0);
        let k = ((s.next_f32() * g.prims.len() as f32) as usize).min(g.prims.len() - 1);
        let Shape::Triangle(t) = g.prims[k].shape else {
            unreachable!("a mesh of triangles")
        };
        let v = t.v[(s.next_f32() * 3.0) as usize % 3];
        let r = BvhRay::new(Ray::new(o, (v - o).normalize()));
        let expect = scalar_leaf(&g.prims, 0, g.prims.len(), &r);
        for wide in &trees {
            // The distance; of the triangles meeting at a vertex, two can claim it at the
            // same distance, and the tree's order of leaves decides which one it names.
            let found = wide.closest(&r, |b, t| leaf(b, &reach(&r, t)), |_| {});
            let t = |hit: Option<(u32, f32)>| hit.map(|(_, t)| t.to_bits());
            assert_eq!(t(found), t(expect), "{:?} {r:?}", wide.isa());
            if let Some((p, d)) = found {
                assert_eq!(g.prims[p as usize].shape.intersect(&r), Some(d), "{p}");
            }
            let any = |b: u32, r: &BvhRay| leaf(b, r).is_some();
            assert_eq!(
                wide.any(&r, any),
                expect.is_some(),
                "{:?} {r:?}",
                wide.isa()
            );
        }
        hits += expect.is_some() as usize;
    }
    assert!(hits > 15_000, "{hits} hits");
}

/// Every instruction set runs the same node test to the bit: the leaves a ray visits, in
/// order, and the leaves it prefetches are the same in each, for nearest-hit and any-hit
/// queries, rays from inside and outside the mesh, very short and very long, and rays
/// parallel to the axes. (Where the CPU has only the baseline, there is nothing to compare,
/// and the test says so.)
#[test]
fn every_instruction_set_visits_the_same_leaves() {
    require_all_isas();
    let g = build(mesh_prims(20_000));
    let (wide, ranges) = collapse(&g.bvh);
    let trees = each_isa(&wide);
    if trees.len() < 2 {
        eprintln!("only the baseline instruction set here: nothing to compare");
        return;
    }
    let mut rays = rays(5_000, 11);
    for (k, r) in rays.clone().iter().enumerate() {
        let axis = [
            Vec3A::X,
            Vec3A::Y,
            Vec3A::Z,
            -Vec3A::X,
            -Vec3A::Y,
            -Vec3A::Z,
        ][k % 6];
        rays.push(Ray::new(r.o, axis));
        rays.push(Ray::segment(r.o, r.d, 1e-4));
        rays.push(Ray::new(r.o * 1e-3, r.d));
    }
    let mut visits = 0;
    for r in &rays {
        let r = &BvhRay::new(*r);
        let trace = |wide: &WideBvh| {
            let log = std::cell::RefCell::new(Vec::new());
            let leaf = |b: u32, r: &BvhRay| {
                log.borrow_mut().push(b);
                let (first, count) = ranges[b as usize];
                scalar_leaf(&g.prims, first, count, r)
            };
            let hit = wide.closest(
                r,
                |b, t| leaf(b, &reach(r, t)),
                |b| log.borrow_mut().push(b | 1 << 31),
            );
            let blocked = wide.any(r, |b, r| {
                log.borrow_mut().push(b | 1 << 30);
                leaf(b, r).is_some()
            });
            // The distance to the bit.
            let hit = hit.map(|(p, t)| (p, t.to_bits()));
            (hit, blocked, log.into_inner())
        };
        let base = trace(&trees[0]);
        visits += base.2.len();
        for wide in &trees[1..] {
            assert_eq!(
                trace(wide),
                base,
                "{:?} against the baseline: {r:?}",
                wide.isa()
            );
        }
    }
    assert!(
        visits > rays.len(),
        "{visits} visits for {} rays",
        rays.len()
    );
}

/// A tree of one leaf is a root (a top node) with one child, and an empty set gives an empty
/// tree that no ray hits.
#[test]
fn small_wide_trees() {
    let t = Triangle::new(Vec3A::ZERO, Vec3A::X, Vec3A::Y).unwrap();
    let g = build(vec![Prim::flat(Shape::Triangle(t)); 3]);
    let (wide, ranges) = collapse(&g.bvh);
    assert_eq!((wide.top.len(), wide.nodes.len()), (1, 0), "a top node");
    assert_eq!(wide.top[0].child[1..], [wide::EMPTY; wide::WIDTH - 1]);
    assert_eq!(ranges, [(0, 3)], "the one leaf holds all three");
    let down = BvhRay::new(Ray::new(Vec3A::new(0.2, 0.2, 1.0), -Vec3A::Z));
    let hit = wide.closest(&down, |b, _| Some((b, 1.0)), |_| {});
    assert_eq!(hit, Some((0, 1.0)));
    let (empty, no_leaves) = WideBvh::collapse(&[]);
    assert!(no_leaves.is_empty());
    assert!(
        empty
            .closest(&down, |_, _| Some((0, 1.0)), |_| {})
            .is_none()
    );
    assert!(!empty.any(&down, |_, _| true));
}

/// Rays parallel to two axes whose origins lie exactly on the sides of boxes (`0 * inf` is NaN
/// in the slab test) find what testing every triangle finds, in both trees: a 16 x 16 grid of
/// unit squares at z = 0 (two triangles each), rays along +z and -z from every grid point and
/// cell centre. (The binary tree's slab test once took a NaN for an exit at infinity and missed
/// the grid's corner.)
#[test]
fn axis_parallel_rays_on_box_sides_agree() {
    let mut prims = Vec::new();
    for i in 0..16 {
        for j in 0..16 {
            let p = |x: i32, y: i32| Vec3A::new((i + x) as f32, (j + y) as f32, 0.0);
            for [a, b, c] in [[p(0, 0), p(1, 0), p(1, 1)], [p(0, 0), p(1, 1), p(0, 1)]] {
                prims.push(Prim::flat(Shape::Triangle(Triangle::new(a, b, c).unwrap())));
            }
        }
    }
    let g = build(prims);
    let (wide, ranges) = collapse(&g.bvh);
    let leaf = |b: u32, r: &BvhRay| {
        let (first, count) = ranges[b as usize];
        scalar_leaf(&g.prims, first, count, r)
    };
    let mut hits = 0;
    for x in 0..=32 {
        for y in 0..=32 {
            for dz in [1.0f32, -1.0] {
                let o = Vec3A::new(x as f32 * 0.5, y as f32 * 0.5, -dz);
                let r = BvhRay::new(Ray::new(o, Vec3A::new(0.0, 0.0, dz)));
                let expect = scalar_leaf(&g.prims, 0, g.prims.len(), &r);
                assert_eq!(g.bvh.closest(&g.prims, &r), expect, "{r:?}");
                for wide in each_isa(&wide) {
                    assert_eq!(
                        wide.closest(&r, |b, t| leaf(b, &reach(&r, t)), |_| {}),
                        expect,
                        "{r:?}"
                    );
                    assert_eq!(wide.any(&r, |b, r| leaf(b, r).is_some()), expect.is_some());
                }
                hits += expect.is_some() as usize;
            }
        }
    }
    // Every point of the grid's interior and its lower and left border belongs to a square.
    assert!(hits >= 2 * 32 * 32, "{hits} hits");
}

/// The wide tree's top levels are collapsed in parallel and joined in order: the tree, its
/// leaf order and the blocks are the same on 1, 2 and 3 threads.
#[test]
fn wide_tree_does_not_depend_on_the_thread_count() {
    let g = build(mesh_prims(20_000));
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let (wide, ranges) = pool.install(|| collapse(&g.bvh));
        let geometry =
            pool.install(|| rtis::accel::Geometry::build(mesh_prims(20_000), Vec::new()));
        (
            format!("{:?}", wide.nodes),
            ranges,
            format!("{:?} {:?}", geometry.blocks, geometry.attrs),
        )
    };
    let one = on(1);
    assert!(one.0.len() > 1000 && one.1.len() > 1000);
    assert!(
        on(2) == one && on(3) == one,
        "the thread count changed the tree"
    );
}

/// A scene with more spheres than the packets take puts spheres and triangles in the same
/// leaves: every hit names the primitive a test of every primitive finds, at the same
/// distance, and the geometry counts and lists each primitive once. Smooth triangles keep
/// their vertex normals through the move to lanes, also one whose stored normal differs from
/// what its vertices give (kept whole).
#[test]
fn mixed_leaves_of_spheres_and_triangles() {
    use rtis::geometry::Hit;
    use rtis::shape::{ShapeKind, Sphere};
    let mut s = Sampler::new(5, 0, 0);
    let mut prims = mesh_prims(2_000);
    let triangles = prims.len();
    for _ in 0..40 {
        let c = Vec3A::new(s.next_f32(), s.next_f32(), s.next_f32()) * 3.0 - Vec3A::splat(1.5);
        prims.push(Prim::flat(Shape::Sphere(Sphere { c, r: 0.1 })));
    }
    // Vertex normals for every tenth triangle, one of them with a flipped stored normal.
    let mut normals = Vec::new();
    for (k, p) in prims.iter_mut().enumerate().take(triangles).step_by(10) {
        let Shape::Triangle(t) = &mut p.shape else {
            unreachable!()
        };
        if k == 50 {
            t.n = -t.n;
        }
        p.smooth = normals.len() as u32;
        normals.push([Vec3A::X, Vec3A::Y, Vec3A::Z * (k as f32 + 1.0)]);
    }
    let g = rtis::accel::Geometry::build(prims.clone(), normals.clone());
    assert_eq!(g.count(ShapeKind::Sphere), 40);
    assert_eq!(g.count(ShapeKind::Triangle), triangles);
    assert_eq!(g.indices().count(), prims.len());
    // Each smooth triangle finds its own normals: the third one's z names it.
    for i in g.indices() {
        let p = g.prim(i);
        if p.smooth != rtis::accel::FLAT {
            let z = g.normals[p.smooth as usize][2].z;
            let original = &prims[z as usize - 1];
            let (Shape::Triangle(a), Shape::Triangle(b)) = (original.shape, p.shape) else {
                panic!("a smooth primitive that is not a triangle")
            };
            assert_eq!(
                (a.v, a.n),
                (b.v, b.n),
                "normals moved with another triangle"
            );
        }
    }
    let mut hits = 0;
    for r in rays(5_000, 9) {
        let brute = prims
            .iter()
            .filter_map(|p| p.shape.intersect(&r).map(|t| (t, p.shape)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let got: Option<Hit> = g.intersect(&r);
        match (brute, got) {
            (None, None) => {}
            (Some((t, shape)), Some(h)) => {
                assert_eq!(h.t, t, "{r:?}");
                assert_eq!(format!("{:?}", g.prim(h.prim).shape), format!("{shape:?}"));
                // The record is the shape's surface there, to the bit, whether the lane test
                // handed over its normal or the primitive was rebuilt.
                let s = shape.surface(&r, t);
                assert_eq!(
                    format!("{:?}", (s.p, s.n, s.err, s.err_along)),
                    format!("{:?}", (h.p, h.n, h.err, h.err_along)),
                    "{r:?}"
                );
                hits += 1;
            }
            (b, h) => panic!("brute force {b:?}, geometry {h:?} for {r:?}"),
        }
        assert_eq!(g.occluded(&r), brute.is_some());
    }
    assert!(hits > 500, "{hits} hits");
}
