//! The rays below the first Phong hit traced in waves: every ray of one depth together, so that the
//! geometry answers them in batches with a ray per SIMD lane, sixteen with AVX-512 and eight with
//! AVX2 ([`crate::accel::Geometry::intersect_batch`]); then the direct light of all their hits
//! together, with a hit per lane, light by light, shadow rays included ([`light_sums`]). In a scene
//! without a BVH (planes and a few spheres, as the course's box) the waves are traced and shaded in
//! lanes from the nearest hit to the children's rays, each chunk's light pass on its own lanes, the
//! rays queued in columns (`lanes.rs`).
//!
//! The result is the depth-first walk's ([`super::incident`]) to the bit. Each node of the tree
//! (one traced ray and the mirror or glass chain behind it) keeps the terms that walk would add
//! to `L_i`, in its order; the sums are taken at the end in depth-first order, so every
//! floating-point addition is the walk's. The waves change only the order in which rays are
//! traced, which nothing reads: point lights draw no random numbers. Area-light samples do, in
//! the walk's order, so a scene whose hits sample area lights is traced depth first
//! ([`applies`]).

mod lanes;

pub use lanes::hemisphere_rays;

use super::Global;
use crate::accel::lanes::dot;
use crate::accel::{Floats, Isa, MAX_LANES};
use crate::geometry::{Hit, Ray};
use crate::light::Light;
use crate::material::{Material, Model, Phong, reflect};
use crate::shader::Tracer;
use crate::shader::surface::{Interaction, SHADOW_END, emitted, reflectance, specular_bounce};
use crate::stats::RayKind;
use glam::Vec3A;
use std::f32::consts::PI;

/// The largest tree of one sample traced in waves: `2^D - 1` nodes, so up to `D = 8`. Deeper
/// trees are walked depth first, which needs memory for only `D + 1` rays.
pub const MAX_NODES: usize = 255;

/// The most point lights the waves take. The light pass keeps nothing per light, so this bounds
/// only the work a wave holds back before its first sum; more lights are walked depth first.
pub const MAX_LIGHTS: usize = 64;

/// Samples are traced in groups of at most about this many nodes: enough hits that most
/// chunks of a wave fill their lanes (sixteen with AVX-512: the course's box at n = 64, D = 3
/// fills 14.4 of them on average, 12.8 with 256 nodes), few enough that a group's buffers stay
/// small (about 48 KB of nodes: a `Node` is 96 bytes here).
const GROUP_NODES: usize = 512;

/// True if the waves give the depth-first walk's result, and fit their memory bounds: there is
/// a tree to trace (`D >= 1`), no hit draws random numbers (no area-light samples), one
/// sample's tree has at most [`MAX_NODES`] nodes, and there are at most [`MAX_LIGHTS`] point
/// lights, no environment light (the waves' escaped rays see the background), and no texture
/// (the waves read a hit's material from its primitive).
pub fn applies(tr: &Tracer, g: &Global) -> bool {
    let draws = tr.effects.emission && !tr.emitters.is_empty() && g.light_samples > 0;
    let sky = tr.effects.emission && tr.emitters.environment.is_some();
    g.max_depth >= 1
        && !draws
        && !sky
        && tr.textures.is_empty()
        && nodes_per_sample(g) <= MAX_NODES
        && tr.lights.len() <= MAX_LIGHTS
}

/// How many samples' trees are traced together: the `n` samples split into as few groups of
/// at most [`GROUP_NODES`] nodes as they fit in (one sample at least), of equal size but the
/// last, so that no group is left with a few samples' worth of rays.
pub fn group(g: &Global) -> usize {
    let n = (g.samples as usize).max(1);
    let per = nodes_per_sample(g).max(1);
    let groups = (n * per).div_ceil(GROUP_NODES).max(1);
    n.div_ceil(groups)
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
}

impl Node {
    /// The node's chain met the mirror or glass hit `si` (below the chain's limit):
    /// `follow_specular`'s step, which returns the next ray (counted by its kind), unless the
    /// effect is off (the chain is absorbed).
    fn bounce(&mut self, si: &Interaction, tr: &mut Tracer) -> Option<Ray> {
        let (next, tint, kind) = specular_bounce(si, tr.effects)?;
        self.tint *= tint;
        self.bounces += 1;
        tr.count(&next, kind);
        Some(next)
    }

    /// A node about to trace its first ray with weight `beta`.
    fn new(beta: Vec3A) -> Self {
        Node {
            bounces: 0,
            beta,
            tint: Vec3A::ONE,
            le: Vec3A::ZERO,
            rest: None,
        }
    }
}

/// A node whose chain ended at a Phong surface, waiting for its direct light.
struct Lit {
    /// The node.
    node: u32,
    /// `beta` times the chain's tints.
    beta: Vec3A,
    /// The ambient term `a_t kd` at depth `D` (Eq. 2), else `None`.
    ambient: Option<Vec3A>,
    /// The point lights' sum of Eq. 3 (zero for a surface that reflects nothing, which has no
    /// light terms), once [`light_sums`] has run.
    point: Vec3A,
}

/// A Phong hit that reflects light, waiting for its point lights' terms: what the light pass
/// reads of its [`Interaction`] and material, in 128 bytes, and its [`Lit`].
struct End {
    /// The hit point.
    p: Vec3A,
    /// The shading normal on the viewer's side.
    n: Vec3A,
    /// The geometric normal that tells the origins' sides apart.
    ng: Vec3A,
    /// Start of rays leaving on `ng`'s side.
    front: Vec3A,
    /// Start of rays leaving on the other side.
    back: Vec3A,
    /// The material's `kd`.
    kd: Vec3A,
    /// Unit direction towards the viewer.
    wo: Vec3A,
    /// The origins' error bound.
    o_err: f32,
    /// Index of its [`Lit`] in the wave.
    lit: u32,
    /// Index of its Phong material in the wave's `phongs`, which the scalar reflectance reads.
    phong: u32,
    /// True under the Course model for a material without a specular lobe (`ks` zero): the
    /// light pass computes its reflectance `kd max(wi.n, 0)` in lanes.
    lambert: bool,
}

// The size the light pass's reads were cut to.
const _: () = assert!(std::mem::size_of::<End>() == 128);

impl End {
    /// The light pass's part of `si`, a hit on the Phong material `phong` under `model`, whose
    /// parameters are at `index` in the wave's `phongs`.
    #[inline(always)]
    fn new(si: &Interaction, phong: &Phong, index: u32, model: Model, lit: u32) -> Self {
        End {
            p: si.hit.p,
            n: si.n,
            ng: si.origins.n,
            front: si.origins.front,
            back: si.origins.back,
            kd: phong.kd,
            wo: si.wo,
            o_err: si.origins.o_err,
            lit,
            phong: index,
            lambert: model == Model::Course && phong.ks == Vec3A::ZERO,
        }
    }
}

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

/// The first child of a node without children.
const NO_KIDS: u32 = u32::MAX;

impl Scratch {
    /// A new node about to trace its first ray with weight `beta` (its index is the count
    /// before).
    fn add_node(&mut self, beta: Vec3A) {
        self.nodes.push(Node::new(beta));
        self.kids.push(NO_KIDS);
    }
}

/// Buffers of one sample group, kept between waves and calls.
#[derive(Default)]
struct Scratch {
    nodes: Vec<Node>,
    /// Each node's first child (the normal's ray; the reflection's follows), or [`NO_KIDS`],
    /// kept apart from the nodes: the sum's walk from node to node reads 4 bytes a step.
    kids: Vec<u32>,
    /// The rays traced now, the chains' next rays (same depth), the children (next depth):
    /// the queues of scenes with a BVH (the lanes kernel has its own, `queue` and `next`).
    now: Rays,
    bounced: Rays,
    children: Rays,
    hits: Vec<Option<Hit>>,
    lit: Vec<Lit>,
    ends: Vec<End>,
    /// The Phong parameters of the ends, in their order (kept apart from the 128 bytes the
    /// light pass reads of each; only the scalar reflectance reads them).
    phongs: Vec<Phong>,
    /// The lanes kernel's queues: the wave traced now (and its bounces), the next depth.
    queue: lanes::Columns,
    next: lanes::Columns,
    /// The lanes kernel's table of the packed primitives' materials.
    slots: Vec<lanes::Slot>,
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
            out.extend((0..chunk.len()).map(|root| sum_tree(&s.nodes, &s.kids, root as u32)));
        }
        out
    })
}

/// The depth-first sum of the tree at `root`: a node, its normal's subtree, its reflection's.
///
/// The pending subtrees wait in a local array (the sum stays in a register): nodes have
/// children only above depth `D`, so a tree is at most `D` levels deep and at most `D`
/// subtrees wait at once; the waves take `D <= 8` ([`applies`]), and no shader has more than
/// [`super::MAX_DEPTH`].
fn sum_tree(nodes: &[Node], kids: &[u32], root: u32) -> Vec3A {
    let mut l = Vec3A::ZERO;
    let (mut stack, mut sp) = ([0u32; super::MAX_DEPTH as usize], 1);
    stack[0] = root;
    while sp > 0 {
        sp -= 1;
        let i = stack[sp] as usize;
        let node = &nodes[i];
        l += node.beta * node.le;
        if let Some(rest) = node.rest {
            l += rest;
        }
        let c = kids[i];
        if c != NO_KIDS {
            stack[sp] = c + 1;
            stack[sp + 1] = c;
            sp += 2;
        }
    }
    l
}

/// Trace the trees of `roots` wave by wave into `s.nodes` (the roots first, in order).
fn trace_tree(tr: &mut Tracer, g: &Global, roots: &[Ray], s: &mut Scratch) {
    s.nodes.clear();
    s.kids.clear();
    for root in roots {
        s.add_node(Vec3A::ONE);
        tr.count(root, RayKind::Indirect);
    }
    if tr.geometry.bvh.is_empty() {
        // Every primitive packed: each wave traced and shaded in lanes.
        lanes::trace(tr, g, roots, s);
        return;
    }
    s.children.clear();
    for (i, r) in roots.iter().enumerate() {
        s.children.push(i as u32, *r);
    }
    for depth in 1..=g.max_depth {
        if s.children.rays.is_empty() {
            break;
        }
        std::mem::swap(&mut s.now, &mut s.children);
        s.children.clear();
        s.lit.clear();
        s.ends.clear();
        s.phongs.clear();
        // Each bounce of the mirror and glass chains in one batch, until every chain ends.
        while !s.now.rays.is_empty() {
            tr.geometry
                .intersect_batch_tallied(&s.now.rays, &mut s.hits, tr.traversal);
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
        light_sums(tr, s);
        finish_direct_light(s);
    }
}

/// Node `i`'s ray met `hit`: as [`crate::shader::surface::follow_specular`], a mirror or glass
/// sends the chain on (into `s.bounced`); a Phong hit is queued for the wave's light pass
/// (into `s.ends`, if it reflects light) and, below depth `D`, sends the two rays of task 2
/// (into `s.children`).
fn shade(tr: &mut Tracer, g: &Global, s: &mut Scratch, depth: u32, k: usize, hit: Hit) {
    let i = s.now.nodes[k];
    let si = Interaction::new(tr, &s.now.rays[k], hit);
    let node = &mut s.nodes[i as usize];
    // The emitter a node's own ray hits is the direct light of the hit it left.
    if node.bounces > 0 {
        node.le += node.tint * emitted(tr, &si);
    }
    let Material::Phong(phong) = si.material else {
        if node.bounces < g.max_specular
            && let Some(next) = node.bounce(&si, tr)
        {
            s.bounced.push(i, next);
        }
        return;
    };
    let beta = node.beta * node.tint;
    // Eq. 3 waits for the wave's light pass ([`light_sums`]). A surface that reflects nothing
    // has no light terms (`point_lights`).
    if !phong.is_black() {
        let index = s.phongs.len() as u32;
        s.ends
            .push(End::new(&si, phong, index, tr.model, s.lit.len() as u32));
        s.phongs.push(*phong);
    }
    // Eq. 2 at depth D ends the path; above it, task 2: Eq. 4 with the directions fixed to
    // the normal w_n and the reflection w_r, weighted by 1 / (4 pi).
    let end = depth >= g.max_depth || !tr.effects.indirect;
    s.lit.push(Lit {
        node: i,
        beta,
        ambient: end.then(|| g.ambient * phong.kd),
        point: Vec3A::ZERO,
    });
    if end {
        return;
    }
    let first = s.nodes.len() as u32;
    s.kids[i as usize] = first;
    let (wo, n) = (si.wo, si.n);
    for (k, w) in [n, reflect(wo, n)].into_iter().enumerate() {
        let b = beta * reflectance(tr.model, phong, w, wo, n) / (4.0 * PI);
        s.add_node(b);
        let ray = si.spawn(w);
        s.children.push(first + k as u32, ray);
        tr.count(&ray, RayKind::Indirect);
    }
}

/// Set each Phong node's `rest`: Eq. 3 as `direct_light` sums it (the point lights' sum, then
/// the area lights' zero), plus the ambient term at depth `D`.
fn finish_direct_light(s: &mut Scratch) {
    for lit in &s.lit {
        // `area_lights` adds an exact zero here: no hit samples them ([`applies`]).
        let l_dir = lit.point + Vec3A::ZERO;
        s.nodes[lit.node as usize].rest = Some(match lit.ambient {
            Some(ambient) => lit.beta * (l_dir + ambient),
            None => lit.beta * l_dir,
        });
    }
}

/// Eq. 3's point-light sum at every hit of `s.ends`, into its [`Lit`]: the hits in SIMD lanes
/// (sixteen with AVX-512, eight with AVX2), each light's terms and shadow rays computed and
/// answered lane by lane, added in the lights' order as `point_lights` adds them.
fn light_sums(tr: &mut Tracer, s: &mut Scratch) {
    match tr.geometry.bvh.isa() {
        // SAFETY: the BVH's instruction set is one the CPU runs (`WideBvh::set_isa`).
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { light_sums_avx2(tr, s) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { light_sums_avx512(tr, s) },
        // SAFETY: `Vec4` runs on every CPU.
        _ => unsafe { light_sums_in::<glam::Vec4>(tr, s) },
    }
}

/// [`light_sums`] in eight AVX2 lanes.
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn light_sums_avx2(tr: &mut Tracer, s: &mut Scratch) {
    // SAFETY: this function runs only where AVX2 was found.
    unsafe { light_sums_in::<crate::accel::F8>(tr, s) }
}

/// [`light_sums`] in sixteen AVX-512 lanes.
///
/// # Safety
/// The CPU must have AVX-512F.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn light_sums_avx512(tr: &mut Tracer, s: &mut Scratch) {
    // SAFETY: this function runs only where AVX-512F was found.
    unsafe { light_sums_in::<crate::accel::F16>(tr, s) }
}

/// [`light_sums`] with the hits `L::LANES` at a time, each chunk's sums by [`point_sums`].
/// No closures that compute in lanes, so that this inlines whole into the AVX2 and AVX-512
/// copies.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn light_sums_in<L: Floats>(tr: &mut Tracer, s: &mut Scratch) {
    // SAFETY: the caller vouches for the instruction set.
    let zero = unsafe { L::splat(0.0) };
    for k in (0..s.ends.len()).step_by(L::LANES) {
        let last = s.ends.len() - 1;
        let mut e = [&s.ends[last]; MAX_LANES];
        for (i, slot) in e.iter_mut().enumerate().take(L::LANES) {
            *slot = &s.ends[(k + i).min(last)];
        }
        let count = (s.ends.len() - k).min(L::LANES);
        // The lanes that hold a hit (the rest repeat the last one): only they trace.
        let mut filled = [0.0f32; MAX_LANES];
        for f in filled.iter_mut().take(count) {
            *f = 1.0;
        }
        // The hits in lanes.
        let h = unsafe {
            let diffuse = e.map(|e| if e.lambert { 1.0f32 } else { 0.0 });
            let filled = L::from_array(filled).cmpne(zero);
            let diffuse = L::from_array(diffuse).cmpne(zero);
            LightLanes {
                p: L::transpose3(&e.map(|e| &e.p)),
                n: L::transpose3(&e.map(|e| &e.n)),
                ng: L::transpose3(&e.map(|e| &e.ng)),
                front: L::transpose3(&e.map(|e| &e.front)),
                back: L::transpose3(&e.map(|e| &e.back)),
                kd: L::transpose3(&e.map(|e| &e.kd)),
                o_err: L::from_array(e.map(|e| e.o_err)),
                filled,
                scalar: L::bitmask(filled & !diffuse),
            }
        };
        let model = tr.model;
        let phongs = &s.phongs;
        // SAFETY: the caller vouches for the instruction set.
        let out = unsafe {
            point_sums(tr, &h, |i, w, l| {
                let end = e[i];
                l * reflectance(model, &phongs[end.phong as usize], w, end.wo, end.n)
            })
        };
        for (i, end) in e.iter().enumerate().take(count) {
            s.lit[end.lit as usize].point = Vec3A::new(out[0][i], out[1][i], out[2][i]);
        }
    }
}

/// Up to `L::LANES` Phong hits in lanes, as the light pass reads them.
struct LightLanes<L: Floats> {
    /// Hit points.
    p: [L; 3],
    /// Shading normals on the viewer's side.
    n: [L; 3],
    /// Geometric normals that tell the origins' sides apart.
    ng: [L; 3],
    /// Starts of rays leaving on `ng`'s side.
    front: [L; 3],
    /// Starts of rays leaving on the other side.
    back: [L; 3],
    /// The materials' `kd`.
    kd: [L; 3],
    /// The origins' error bounds.
    o_err: L,
    /// The lanes that hold a hit to light: only they trace shadow rays.
    filled: L::Mask,
    /// The lanes (bits) whose reflectance is not the course's diffuse one, computed by the
    /// scalar `reflectance`.
    scalar: u32,
}

/// `PointLight::toward` in lanes: the unit direction from the points `p` to `x`, `d^2` and
/// the distance.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn toward<L: Floats>(x: Vec3A, p: [L; 3]) -> ([L; 3], L, L) {
    // SAFETY: the caller vouches for the instruction set.
    let to = unsafe {
        [
            L::splat(x.x) - p[0],
            L::splat(x.y) - p[1],
            L::splat(x.z) - p[2],
        ]
    };
    let d2 = dot(to, to);
    let dist = d2.sqrt();
    ([to[0] / dist, to[1] / dist, to[2] / dist], d2, dist)
}

/// `I / d^2` in lanes: one division where the light is grey (the same operands give the same
/// quotient), three otherwise.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn over_d2<L: Floats>(intensity: Vec3A, d2: L) -> [L; 3] {
    let bits = intensity.to_array().map(f32::to_bits);
    // SAFETY: the caller vouches for the instruction set.
    unsafe {
        let x = L::splat(intensity.x) / d2;
        if bits[0] == bits[1] && bits[1] == bits[2] {
            [x, x, x]
        } else {
            [x, L::splat(intensity.y) / d2, L::splat(intensity.z) / d2]
        }
    }
}

/// Eq. 3's point-light sums of the hits of `h`, lane by lane, each light's terms and shadow
/// rays in lanes, added in the lights' order as `point_lights` adds them. Returns the sums, a
/// row per channel (zero in lanes not filled).
///
/// Each lane computes what `point_light_ray` and `point_light_term` compute for its hit, for
/// each kind of light as its `incident` does: `wi = (x - p) / |x - p|` and `L_i = I / d^2` for
/// a point light, `I falloff / d^2` for a spot (no term outside its cone), `wi = -direction`
/// and `L_i = E` at infinity for a sun; no term where `d^2` is 0 or not finite or `wi.n <= 0`,
/// the shadow ray from the origin on `wi`'s side to `SHADOW_END` of the distance, and
/// `L_i r(wi, wo)`, in lanes for the course's diffuse reflectance `kd (wi.n)` and by
/// `other(lane, wi, L_i)` for the lanes of `h.scalar` (a specular lobe, the Physical model).
/// The lanes' sums add `+0` where the walk adds `ZERO` for a light that adds nothing, as it
/// does.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn point_sums<L: Floats>(
    tr: &mut Tracer,
    h: &LightLanes<L>,
    mut other: impl FnMut(usize, Vec3A, Vec3A) -> Vec3A,
) -> [[f32; MAX_LANES]; 3] {
    let (lights, shadows) = (tr.lights, tr.effects.shadows);
    // SAFETY: the caller vouches for the instruction set.
    let (zero, inf, end) =
        unsafe { (L::splat(0.0), L::splat(f32::INFINITY), L::splat(SHADOW_END)) };
    let (p, n, ng, front, back, kd, o_err) = (h.p, h.n, h.ng, h.front, h.back, h.kd, h.o_err);
    let mut sum = [zero; 3];
    for light in lights {
        // The direction to the light, `d^2`, the distance and `L_i`, lane by lane, as each
        // light's `incident` computes them.
        // `in_cone` is 1 in the lanes the light reaches at all (a spot's cone), else 0.
        // SAFETY: the caller vouches for the instruction set.
        let one = unsafe { L::splat(1.0) };
        let (wi, d2, dist, li, in_room, in_cone) = match light {
            Light::Point(pl) => {
                // SAFETY: the caller vouches for the instruction set.
                let (wi, d2, dist) = unsafe { toward::<L>(pl.position, p) };
                let li = unsafe { over_d2::<L>(pl.intensity, d2) };
                (wi, d2, dist, li, pl.in_room, one)
            }
            // `SpotLight::incident`, `I (falloff / d^2)`, lane by lane with the same operands.
            Light::Spot(sl) => {
                // SAFETY: the caller vouches for the instruction set.
                let (wi, d2, dist) = unsafe { toward::<L>(sl.position, p) };
                let mut v = [[0.0f32; MAX_LANES]; 4];
                for (c, x) in [wi[0], wi[1], wi[2], d2].into_iter().enumerate() {
                    x.write_to(&mut v[c]);
                }
                let mut out = [[0.0f32; MAX_LANES]; 4];
                for lane in 0..L::LANES {
                    let w = Vec3A::new(v[0][lane], v[1][lane], v[2][lane]);
                    let falloff = sl.falloff(-w.dot(sl.axis));
                    let l = sl.intensity * (falloff / v[3][lane]);
                    for c in 0..3 {
                        out[c][lane] = l[c];
                    }
                    out[3][lane] = if falloff > 0.0 { 1.0 } else { 0.0 };
                }
                // SAFETY: the caller vouches for the instruction set.
                let [r, g, b, cone] = unsafe { out.map(|c| L::from_slice(&c)) };
                (wi, d2, dist, [r, g, b], sl.in_room, cone)
            }
            // `DirectionalLight::incident`: the same direction everywhere, at infinity, `L_i =
            // E`; `d^2 = 1` keeps the lanes valid.
            // SAFETY: the caller vouches for the instruction set.
            Light::Directional(dl) => unsafe {
                let w = dl.incident();
                (
                    [L::splat(w.wi.x), L::splat(w.wi.y), L::splat(w.wi.z)],
                    L::splat(1.0),
                    inf,
                    [L::splat(w.li.x), L::splat(w.li.y), L::splat(w.li.z)],
                    false,
                    one,
                )
            },
        };
        // `point_light_ray`: a term unless `d^2` is 0 or not finite, or `wi.n <= 0`.
        let cos = dot(wi, n);
        let valid =
            d2.cmpne(zero) & d2.cmplt(inf) & !cos.cmple(zero) & in_cone.cmpgt(zero) & h.filled;
        // `Origins::ray`: the side `wi` leaves by.
        let on_front = dot(ng, wi).cmpge(zero);
        let o = [
            L::select(on_front, front[0], back[0]),
            L::select(on_front, front[1], back[1]),
            L::select(on_front, front[2], back[2]),
        ];
        let seen = if shadows {
            tr.count_shadow_lanes((o, wi, o_err, dist * end), L::bitmask(valid));
            let planes = !in_room;
            // Counted only in an inspected render; a render's queries have no counters.
            let segments = (o, wi, o_err, dist * end);
            let blocked = match tr.traversal {
                None => tr.geometry.occluded_lanes(segments, planes, valid, &()),
                Some(t) => tr.geometry.occluded_lanes(segments, planes, valid, t),
            };
            valid & !blocked
        } else {
            valid
        };
        // `point_light_term`: `L_i r(wi, wo)`; the course's diffuse `r = kd max(wi.n, 0)` in
        // lanes, any other by the scalar reflectance. `max(wi.n, 0)` as a select: `cos` where
        // it is positive, else +0, as `f32::max` gives it on every target (NaN: 0).
        let cos_i = L::select(cos.cmpgt(zero), cos, zero);
        let mut term = [
            li[0] * (kd[0] * cos_i),
            li[1] * (kd[1] * cos_i),
            li[2] * (kd[2] * cos_i),
        ];
        if h.scalar != 0 {
            let mut v = [[0.0f32; MAX_LANES]; 9];
            for (c, x) in [
                term[0], term[1], term[2], wi[0], wi[1], wi[2], li[0], li[1], li[2],
            ]
            .into_iter()
            .enumerate()
            {
                x.write_to(&mut v[c]);
            }
            let mut lanes = h.scalar;
            while lanes != 0 {
                let i = lanes.trailing_zeros() as usize;
                lanes &= lanes - 1;
                let w = Vec3A::new(v[3][i], v[4][i], v[5][i]);
                let l = Vec3A::new(v[6][i], v[7][i], v[8][i]);
                let t = other(i, w, l);
                (v[0][i], v[1][i], v[2][i]) = (t.x, t.y, t.z);
            }
            term = unsafe {
                [
                    L::from_array(v[0]),
                    L::from_array(v[1]),
                    L::from_array(v[2]),
                ]
            };
        }
        for c in 0..3 {
            sum[c] = sum[c] + L::select(seen, term[c], zero);
        }
    }
    let mut out = [[0.0f32; MAX_LANES]; 3];
    for c in 0..3 {
        sum[c].write_to(&mut out[c]);
    }
    out
}
