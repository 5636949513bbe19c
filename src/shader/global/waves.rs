//! The rays below the first Phong hit traced in waves: every ray of one depth together, then
//! every shadow ray of their hits together, light by light, so that the geometry answers them
//! in batches with a ray per SIMD lane, eight with AVX2
//! ([`crate::accel::Geometry::intersect_batch`]).
//!
//! The result is the depth-first walk's ([`super::incident`]) to the bit. Each node of the tree
//! (one traced ray and the mirror or glass chain behind it) keeps the terms that walk would add
//! to `L_i`, in its order; the sums are taken at the end in depth-first order, so every
//! floating-point addition is the walk's. The waves change only the order in which rays are
//! traced, which nothing reads: point lights draw no random numbers. Area-light samples do, in
//! the walk's order, so a scene whose hits sample area lights is traced depth first
//! ([`applies`]).

use super::Global;
use crate::geometry::{Hit, Ray};
use crate::material::{Material, reflect};
use crate::shader::Tracer;
use crate::shader::surface::{
    Interaction, emitted, point_light_ray, point_light_term, reflectance, specular_bounce,
};
use crate::stats::RayKind;
use glam::{BVec3A, Vec3A};
use std::f32::consts::PI;

/// The largest tree of one sample traced in waves: `2^D - 1` nodes, so up to `D = 8`. Deeper
/// trees are walked depth first, which needs memory for only `D + 1` rays.
pub const MAX_NODES: usize = 255;

/// The most point lights the waves take: a wave holds a shadow ray per light and hit, up to
/// `64 * 128` of them at `D = 8`, about a megabyte. More lights are walked depth first.
pub const MAX_LIGHTS: usize = 64;

/// Samples are traced in groups of about this many nodes: enough rays for full batches, few
/// enough that a group's buffers stay small (about 20 KB of nodes).
const GROUP_NODES: usize = 64;

/// True if the waves give the depth-first walk's result, and fit their memory bounds: there is
/// a tree to trace (`D >= 1`), no hit draws random numbers (no area-light samples), one
/// sample's tree has at most [`MAX_NODES`] nodes, and there are at most [`MAX_LIGHTS`] point
/// lights.
pub fn applies(tr: &Tracer, g: &Global) -> bool {
    let draws = tr.effects.emission && !tr.emitters.is_empty() && g.light_samples > 0;
    g.max_depth >= 1 && !draws && nodes_per_sample(g) <= MAX_NODES && tr.lights.len() <= MAX_LIGHTS
}

/// How many samples' trees are traced together: about [`GROUP_NODES`] nodes' worth.
pub fn group(g: &Global) -> usize {
    (GROUP_NODES / nodes_per_sample(g).max(1)).max(1)
}

/// Nodes of one sample's full tree: `2^D - 1`.
fn nodes_per_sample(g: &Global) -> usize {
    (1usize << g.max_depth.min(usize::BITS - 1)) - 1
}

/// One ray of the tree and the mirror or glass chain it starts: what they add to `L_i`.
#[derive(Clone, Copy)]
struct Node {
    /// Mirror and glass bounces so far.
    bounces: u32,
    /// The weight `beta` of the node's radiance in `L_i`.
    beta: Vec3A,
    /// The product of the chain's tints so far.
    tint: Vec3A,
    /// Light the chain's surfaces emit towards the node, weighted by `tint`.
    le: Vec3A,
    /// What the node adds to `L_i` after `beta le`: `beta` times the background it escapes
    /// to, or times its Phong hit's direct light (Eq. 3), plus the ambient term at depth `D`
    /// (Eq. 2); `None` if it is absorbed.
    rest: Option<Vec3A>,
    /// Index of its first child (the normal's ray; the reflection's follows), if it has two.
    children: Option<u32>,
}

impl Node {
    /// A node about to trace its first ray with weight `beta`.
    fn new(beta: Vec3A) -> Self {
        Node {
            bounces: 0,
            beta,
            tint: Vec3A::ONE,
            le: Vec3A::ZERO,
            rest: None,
            children: None,
        }
    }
}

/// A node whose chain ended at a Phong surface, waiting for its shadow rays.
struct Lit {
    /// The node.
    node: u32,
    /// `beta` times the chain's tints.
    beta: Vec3A,
    /// The ambient term `a_t kd` at depth `D` (Eq. 2), else `None`.
    ambient: Option<Vec3A>,
    /// False for a surface that reflects nothing: it has no light terms.
    reflects: bool,
}

/// A point light's term at a hit before its shadow ray is answered: `L_i r(wi, wo)`, and the
/// shadow ray's index among the light's ([`SEEN`] if none is traced).
type Term = (Vec3A, u32);

/// The index of a term whose light counts without a shadow ray (shadows off), or that adds
/// nothing whatever the visibility.
const SEEN: u32 = u32::MAX;

/// Rays waiting to be traced, with their nodes.
#[derive(Default)]
struct Rays {
    rays: Vec<Ray>,
    nodes: Vec<u32>,
}

impl Rays {
    fn clear(&mut self) {
        self.rays.clear();
        self.nodes.clear();
    }

    fn push(&mut self, node: u32, ray: Ray) {
        self.rays.push(ray);
        self.nodes.push(node);
    }
}

/// Buffers of one sample group, kept between waves and calls.
#[derive(Default)]
struct Scratch {
    nodes: Vec<Node>,
    /// The rays traced now, the chains' next rays (same depth), the children (next depth).
    now: Rays,
    bounced: Rays,
    children: Rays,
    hits: Vec<Option<Hit>>,
    lit: Vec<Lit>,
    terms: Vec<Term>,
    /// Each light's shadow rays, and whether each is blocked.
    shadow: Vec<Vec<Ray>>,
    blocked: Vec<Vec<bool>>,
    stack: Vec<u32>,
}

/// `L_i` along each ray of `rays` (the indirect rays leaving the first Phong hit, traced at
/// depth 1), as [`super::incident`] gives it for each in turn.
pub fn incident(tr: &mut Tracer, g: &Global, rays: &[Ray]) -> Vec<Vec3A> {
    // The buffers stay with the thread: allocated afresh for each first hit they would cost
    // page faults.
    thread_local! {
        static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::default();
    }
    SCRATCH.with_borrow_mut(|s| {
        let mut out = Vec::with_capacity(rays.len());
        for chunk in rays.chunks(group(g)) {
            trace_tree(tr, g, chunk, s);
            out.extend((0..chunk.len()).map(|root| sum_tree(s, root as u32)));
        }
        out
    })
}

/// The depth-first sum of the tree at `root`: a node, its normal's subtree, its reflection's.
fn sum_tree(s: &mut Scratch, root: u32) -> Vec3A {
    let mut l = Vec3A::ZERO;
    s.stack.clear();
    s.stack.push(root);
    while let Some(i) = s.stack.pop() {
        let node = &s.nodes[i as usize];
        l += node.beta * node.le;
        if let Some(rest) = node.rest {
            l += rest;
        }
        if let Some(c) = node.children {
            s.stack.push(c + 1);
            s.stack.push(c);
        }
    }
    l
}

/// Trace the trees of `roots` wave by wave into `s.nodes` (the roots first, in order).
fn trace_tree(tr: &mut Tracer, g: &Global, roots: &[Ray], s: &mut Scratch) {
    s.nodes.clear();
    s.children.clear();
    for (i, r) in roots.iter().enumerate() {
        s.nodes.push(Node::new(Vec3A::ONE));
        s.children.push(i as u32, *r);
        tr.stats.count(RayKind::Indirect);
    }
    for depth in 1..=g.max_depth {
        if s.children.rays.is_empty() {
            break;
        }
        std::mem::swap(&mut s.now, &mut s.children);
        s.children.clear();
        s.lit.clear();
        s.terms.clear();
        s.shadow.resize_with(tr.lights.len(), Vec::new);
        s.shadow.iter_mut().for_each(Vec::clear);
        // Each bounce of the mirror and glass chains in one batch, until every chain ends.
        while !s.now.rays.is_empty() {
            tr.geometry.intersect_batch(&s.now.rays, &mut s.hits);
            s.bounced.clear();
            for k in 0..s.now.rays.len() {
                let i = s.now.nodes[k];
                match s.hits[k] {
                    Some(hit) => shade(tr, g, s, depth, k, hit),
                    None => {
                        let node = &mut s.nodes[i as usize];
                        node.rest = Some(node.beta * node.tint * tr.background);
                    }
                }
            }
            std::mem::swap(&mut s.now, &mut s.bounced);
        }
        finish_direct_light(tr, s);
    }
}

/// Node `i`'s ray met `hit`: as [`crate::shader::surface::follow_specular`], a mirror or glass
/// sends the chain on (into `s.bounced`); at a Phong surface, Eq. 3's light terms and shadow
/// rays are queued and, below depth `D`, the two rays of task 2 (into `s.children`).
fn shade(tr: &mut Tracer, g: &Global, s: &mut Scratch, depth: u32, k: usize, hit: Hit) {
    let i = s.now.nodes[k];
    let si = Interaction::new(tr, &s.now.rays[k], hit);
    let node = &mut s.nodes[i as usize];
    // The emitter a node's own ray hits is the direct light of the hit it left.
    if node.bounces > 0 {
        node.le += node.tint * emitted(tr, &si);
    }
    let Material::Phong(phong) = si.material else {
        if node.bounces == g.max_specular {
            return;
        }
        if let Some((next, tint, kind)) = specular_bounce(&si, tr.effects) {
            node.tint *= tint;
            node.bounces += 1;
            tr.stats.count(kind);
            s.bounced.push(i, next);
        }
        return;
    };
    let beta = node.beta * node.tint;
    // Eq. 3: each point light's term, its shadow ray answered in the wave's batch. A surface
    // that reflects nothing has none (`point_lights`).
    let reflects = !phong.is_black();
    if reflects {
        let lights = tr.lights;
        for (light, rays) in lights.iter().zip(&mut s.shadow) {
            s.terms.push(match point_light_ray(&si, light) {
                None => (Vec3A::ZERO, SEEN),
                Some((inc, shadow)) => {
                    let term = point_light_term(tr.model, &si, &phong, &inc, true);
                    if tr.effects.shadows {
                        rays.push(shadow);
                        (term, rays.len() as u32 - 1)
                    } else {
                        (term, SEEN)
                    }
                }
            });
        }
    }
    // Eq. 2 at depth D ends the path; above it, task 2: Eq. 4 with the directions fixed to
    // the normal w_n and the reflection w_r, weighted by 1 / (4 pi).
    let end = depth >= g.max_depth || !tr.effects.indirect;
    s.lit.push(Lit {
        node: i,
        beta,
        ambient: end.then(|| g.ambient * phong.kd),
        reflects,
    });
    if end {
        return;
    }
    let first = s.nodes.len() as u32;
    s.nodes[i as usize].children = Some(first);
    let (wo, n) = (si.wo, si.n);
    for (k, w) in [n, reflect(wo, n)].into_iter().enumerate() {
        let b = beta * reflectance(tr.model, &phong, w, wo, n) / (4.0 * PI);
        s.nodes.push(Node::new(b));
        s.children.push(first + k as u32, si.spawn(w));
        tr.stats.count(RayKind::Indirect);
    }
}

/// Answer the wave's shadow rays in one batch and set each Phong node's `rest`: Eq. 3 as
/// `direct_light` sums it (the lights' terms in order, then the area lights' zero), plus the
/// ambient term at depth `D`.
fn finish_direct_light(tr: &mut Tracer, s: &mut Scratch) {
    // Light by light: rays towards one light from nearby hits run close together, so the
    // lanes of a batch tend to agree, and all or none test the planes.
    s.blocked.resize_with(s.shadow.len(), Vec::new);
    for ((light, rays), blocked) in tr.lights.iter().zip(&s.shadow).zip(&mut s.blocked) {
        tr.stats.shadow += rays.len() as u64;
        tr.geometry.occluded_batch(rays, !light.in_room(), blocked);
    }
    let lights = tr.lights.len();
    let mut at = 0;
    for lit in &s.lit {
        // `point_lights`: nothing for a surface that reflects nothing, else the lights'
        // terms in order, each seen or not.
        let point = match lit.reflects {
            false => Vec3A::ZERO,
            true => {
                at += lights;
                s.terms[at - lights..at]
                    .iter()
                    .zip(&s.blocked)
                    .map(|(&(term, k), blocked)| {
                        let seen = k == SEEN || !blocked[k as usize];
                        Vec3A::select(BVec3A::splat(seen), term, Vec3A::ZERO)
                    })
                    .sum()
            }
        };
        // `area_lights` adds an exact zero here: no hit samples them ([`applies`]).
        let l_dir = point + Vec3A::ZERO;
        s.nodes[lit.node as usize].rest = Some(match lit.ambient {
            Some(ambient) => lit.beta * (l_dir + ambient),
            None => lit.beta * l_dir,
        });
    }
}
