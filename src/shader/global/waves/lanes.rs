//! The waves traced and shaded in SIMD lanes, for scenes whose primitives are all packed (no
//! BVH), and the first hit's directions in lanes for every scene the waves serve
//! ([`hemisphere_rays`]): a ray per lane from the nearest hit to its children, the rays queued
//! in columns ([`Columns`]) so that a chunk loads with one load per coordinate and the children
//! are written with one left-packing store per coordinate ([`crate::accel::Floats::compress`]).
//!
//! A wave's rays are one stream: a mirror or glass bounce is queued behind the rays of its depth
//! and traced in a later chunk of the same wave, so that most chunks fill their lanes (a chunk that
//! reaches the queue's end before the bounces of earlier chunks join it does not). The nearest hits
//! come with their records in lanes ([`crate::accel::Geometry::nearest_lanes`], which
//! `intersect_batch` runs too); the interaction (orientation, the origins and their error bound),
//! the light pass ([`super::point_sums`]), each Phong node's sum, the two rays of task 2 with
//! their weights, and the mirror and glass bounces ([`bounce_lanes`]) run in lanes. What each
//! primitive's material is comes from a table built once per call ([`Slot`]). Scalar, lane by
//! lane: the tree's bookkeeping (storing a node's sum, its children's nodes, a chain's tint), a
//! metal's bounce and any bounce with reflection or refraction off, the light emitted by a surface
//! a chain meets, and every reflectance but the course's diffuse one (a specular lobe, the
//! Physical model), in the light terms and the children's weights. Every lane computes what the
//! scalar code computes for its ray, operation for operation (`Geometry::intersect`'s order and
//! tie rule, `Sphere::surface`, `Plane::surface`, `Interaction::new`, `Origins`, `reflect`,
//! `Transmissive::refract`, `course_reflectance`), so the result is the depth-first walk's to the
//! bit.

use super::{LightLanes, Scratch, point_sums};
use crate::accel::Tally;
use crate::accel::lanes::{RayLanes, array, dot, lane_mask, origins};
use crate::accel::{Floats, Isa, MAX_LANES};
use crate::geometry::{Frame, Hit, Origins, Ray};
use crate::light::NO_LIGHT;
use crate::material::{Material, Model, Phong};
use crate::shader::Tracer;
use crate::shader::global::Global;
use crate::shader::surface::{Interaction, emitted, reflectance};
use crate::shader::warps::uniform_hemisphere;
use crate::stats::RayKind;
use glam::Vec3A;
use std::f32::consts::PI;

/// Columns of a [`Columns`] queue: origin, direction, the origin's error bound, `t_max`.
const OX: usize = 0;
const DX: usize = 3;
const OE: usize = 6;
const TM: usize = 7;

/// What each column of a [`Columns`] queue holds of a ray, in the columns' order.
const FIELDS: [fn(&Ray) -> f32; 8] = [
    |r| r.o.x,
    |r| r.o.y,
    |r| r.o.z,
    |r| r.d.x,
    |r| r.d.y,
    |r| r.d.z,
    |r| r.o_err,
    |r| r.t_max,
];

/// Rays waiting to be traced, with their nodes, a column per coordinate (structure of
/// arrays). Each column holds at least [`MAX_LANES`] values past the last ray, so that a
/// chunk of lanes loads whole and a left-packing store has room (values past the last ray are left
/// over from earlier rays, or zero, and only ever fill lanes that are dropped).
#[derive(Default)]
pub(super) struct Columns {
    /// `o.x`, `o.y`, `o.z`, `d.x`, `d.y`, `d.z`, `o_err`, `t_max`.
    rows: [Vec<f32>; 8],
    /// The rays' nodes.
    nodes: Vec<u32>,
    /// How many rays.
    len: usize,
}

impl Columns {
    /// No rays (the columns keep their memory).
    fn clear(&mut self) {
        self.len = 0;
    }

    /// Room for `n` more rays and a chunk of lanes past them.
    fn reserve(&mut self, n: usize) {
        let want = self.len + n + MAX_LANES;
        if self.nodes.len() < want {
            let want = want.next_power_of_two();
            for row in &mut self.rows {
                row.resize(want, 0.0);
            }
            self.nodes.resize(want, 0);
        }
    }

    /// Queue `rays` for the nodes from `node` on, one each.
    fn push(&mut self, node: u32, rays: &[Ray]) {
        self.reserve(rays.len());
        let (k, n) = (self.len, rays.len());
        // A column at a time, each a slice bounds-checked once.
        for (column, value) in self.rows.iter_mut().zip(FIELDS) {
            for (x, r) in column[k..k + n].iter_mut().zip(rays) {
                *x = value(r);
            }
        }
        for (j, slot) in self.nodes[k..k + n].iter_mut().enumerate() {
            *slot = node + j as u32;
        }
        self.len += n;
    }

    /// Ray `k` of the queue.
    fn ray(&self, k: usize) -> Ray {
        let v = |row: usize| self.rows[row][k];
        Ray {
            o: Vec3A::new(v(OX), v(OX + 1), v(OX + 2)),
            d: Vec3A::new(v(DX), v(DX + 1), v(DX + 2)),
            o_err: v(OE),
            t_max: v(TM),
        }
    }

    /// `L::LANES` values of column `row` from ray `k` on.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn load<L: Floats>(&self, row: usize, k: usize) -> L {
        // SAFETY: the caller vouches for the instruction set; the column holds `MAX_LANES`
        // values past `len` (`reserve`).
        unsafe { L::from_slice(&self.rows[row][k..]) }
    }
}

/// What the kernel reads of the primitive in one slot of
/// [`crate::accel::Geometry::nearest_lanes`], looked up once per call.
#[derive(Clone, Copy)]
pub(super) struct Slot {
    /// The primitive.
    prim: u32,
    /// Its material's index in the render's table.
    material: u32,
    /// Its area light, or [`NO_LIGHT`].
    light: u32,
    /// A Phong material's parameters (black for the others, whose lanes never read them: the
    /// Phong, lit and parent lanes are chosen by `is_phong` and `lit`).
    phong: Phong,
    /// A Phong material.
    is_phong: bool,
    /// A Phong material that reflects light (`point_lights` has terms for it).
    lit: bool,
    /// A Phong material whose reflectance is the course's diffuse `kd max(w.n, 0)` (the Course
    /// model, `ks` zero): computed in lanes.
    lambert: bool,
    /// A mirror or the course's glass, whose bounces run in lanes; `None` for the other
    /// materials (a metal's bounce is the scalar `specular_bounce`).
    bounce: Option<Bounce>,
}

/// The specular materials whose bounces the lanes compute: `specular_bounce`'s mirror and glass.
#[derive(Clone, Copy)]
enum Bounce {
    /// A mirror of this tint.
    Mirror(Vec3A),
    /// The course's glass: its index of refraction and its tint.
    Glass(f32, Vec3A),
}

impl Bounce {
    /// The tint a chain takes at the bounce.
    fn tint(self) -> Vec3A {
        match self {
            Bounce::Mirror(tint) | Bounce::Glass(_, tint) => tint,
        }
    }
}

/// The slot table of `tr`'s packed primitives, into `slots`.
fn slot_table(tr: &Tracer, slots: &mut Vec<Slot>) {
    slots.clear();
    let geometry = tr.geometry;
    while let Some(prim) = geometry.slot_prim(slots.len() as u32) {
        let p = geometry.prim(prim);
        let phong = match tr.materials[p.material as usize] {
            Material::Phong(phong) => Some(phong),
            _ => None,
        };
        slots.push(Slot {
            prim,
            material: p.material,
            light: p.light,
            phong: phong.unwrap_or(Phong {
                kd: Vec3A::ZERO,
                ks: Vec3A::ZERO,
                shininess: 1.0,
            }),
            is_phong: phong.is_some(),
            lit: phong.is_some_and(|p| !p.is_black()),
            lambert: phong.is_some_and(|p| tr.model == Model::Course && p.ks == Vec3A::ZERO),
            bounce: match tr.materials[p.material as usize] {
                Material::Mirror(m) => Some(Bounce::Mirror(m.color)),
                Material::Transmissive(g) => Some(Bounce::Glass(g.ior, g.color)),
                _ => None,
            },
        });
    }
}

/// Trace the trees of `roots` wave by wave into `s.nodes`, whose roots (one per ray of
/// `roots`, in order) the caller has made: what `trace_tree`'s waves and `shade` do for a
/// scene without a BVH, each Phong hit's light pass and sum included (its node's `rest`).
pub fn trace(tr: &mut Tracer, g: &Global, roots: &[Ray], s: &mut Scratch) {
    match tr.geometry.bvh.isa() {
        // SAFETY: the BVH's instruction set is one the CPU runs (`WideBvh::set_isa`).
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { trace_avx2(tr, g, roots, s) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { trace_avx512(tr, g, roots, s) },
        // SAFETY: `Vec4` runs on every CPU.
        _ => unsafe { trace_in::<glam::Vec4>(tr, g, roots, s) },
    }
}

/// The rays of Eq. 4 at a first hit for the numbers `us`, drawn in order: each direction
/// `frame.to_world(hemisphere::uniform(u1, u2))` made in `tr`'s lanes
/// ([`crate::shader::warps::uniform_hemisphere`], the scalar warp's bits), into `w`, and its
/// ray from `origins` (`Interaction::spawn`), into `rays`.
pub fn hemisphere_rays(
    tr: &Tracer,
    frame: &Frame,
    origins: &Origins,
    us: &[(f32, f32)],
    (w, rays): (&mut Vec<Vec3A>, &mut Vec<Ray>),
) {
    match tr.geometry.bvh.isa() {
        // SAFETY: the BVH's instruction set is one the CPU runs (`WideBvh::set_isa`).
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { hemisphere_avx2(frame, origins, us, w, rays) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { hemisphere_avx512(frame, origins, us, w, rays) },
        // SAFETY: `Vec4` runs on every CPU.
        _ => unsafe { hemisphere_in::<glam::Vec4>(frame, origins, us, w, rays) },
    }
}

/// [`hemisphere_rays`] in eight AVX2 lanes.
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn hemisphere_avx2(
    frame: &Frame,
    origins: &Origins,
    us: &[(f32, f32)],
    w: &mut Vec<Vec3A>,
    rays: &mut Vec<Ray>,
) {
    // SAFETY: this function runs only where AVX2 was found.
    unsafe { hemisphere_in::<crate::accel::F8>(frame, origins, us, w, rays) }
}

/// [`hemisphere_rays`] in sixteen AVX-512 lanes.
///
/// # Safety
/// The CPU must have AVX-512F.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn hemisphere_avx512(
    frame: &Frame,
    origins: &Origins,
    us: &[(f32, f32)],
    w: &mut Vec<Vec3A>,
    rays: &mut Vec<Ray>,
) {
    // SAFETY: this function runs only where AVX-512F was found.
    unsafe { hemisphere_in::<crate::accel::F16>(frame, origins, us, w, rays) }
}

/// [`hemisphere_rays`], `L::LANES` directions at a time.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn hemisphere_in<L: Floats>(
    frame: &Frame,
    origins: &Origins,
    us: &[(f32, f32)],
    w: &mut Vec<Vec3A>,
    rays: &mut Vec<Ray>,
) {
    let mut rows = [[0.0f32; MAX_LANES]; 3];
    for chunk in us.chunks(L::LANES) {
        let (mut u1, mut u2) = ([0.0f32; MAX_LANES], [0.0f32; MAX_LANES]);
        for (i, &(a, b)) in chunk.iter().enumerate() {
            (u1[i], u2[i]) = (a, b);
        }
        // SAFETY: the caller vouches for the instruction set.
        let wl = unsafe { uniform_hemisphere(frame, L::from_array(u1), L::from_array(u2)) };
        for (row, x) in rows.iter_mut().zip(wl) {
            x.write_to(row);
        }
        for ((&x, &y), &z) in rows[0].iter().zip(&rows[1]).zip(&rows[2]).take(chunk.len()) {
            let wj = Vec3A::new(x, y, z);
            w.push(wj);
            rays.push(origins.ray(wj, f32::INFINITY));
        }
    }
}

/// [`trace`] in eight AVX2 lanes.
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn trace_avx2(tr: &mut Tracer, g: &Global, roots: &[Ray], s: &mut Scratch) {
    // SAFETY: this function runs only where AVX2 was found.
    unsafe { trace_in::<crate::accel::F8>(tr, g, roots, s) }
}

/// [`trace`] in sixteen AVX-512 lanes.
///
/// # Safety
/// The CPU must have AVX-512F.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn trace_avx512(tr: &mut Tracer, g: &Global, roots: &[Ray], s: &mut Scratch) {
    // SAFETY: this function runs only where AVX-512F was found.
    unsafe { trace_in::<crate::accel::F16>(tr, g, roots, s) }
}

/// [`trace`], `L::LANES` rays at a time.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn trace_in<L: Floats>(tr: &mut Tracer, g: &Global, roots: &[Ray], s: &mut Scratch) {
    slot_table(tr, &mut s.slots);
    debug_assert_eq!(s.nodes.len(), roots.len(), "the roots are nodes 0 to n - 1");
    s.queue.clear();
    s.queue.push(0, roots);
    for depth in 1..=g.max_depth {
        if s.queue.len == 0 {
            break;
        }
        s.next.clear();
        // The wave's rays, chunk by chunk; bounces join the queue behind them.
        let mut k = 0;
        while k < s.queue.len {
            // SAFETY: the caller vouches for the instruction set.
            k += unsafe { chunk::<L>(tr, g, s, depth, k) };
        }
        std::mem::swap(&mut s.queue, &mut s.next);
    }
}

/// The mirror and glass bounces of a chunk's lanes `mirror` and `glass` (glass of index of
/// refraction `ior`, lane by lane), queued behind the wave's rays with their nodes (`nodes`),
/// and counted: what `specular_bounce` computes for each, operation for operation. A mirror
/// reflects `wo` about the shading normal `ns` (`reflect`); glass refracts `wo` through the
/// geometric normal `nh` (`Transmissive::refract`: Snell's law, `eta = 1 / ior` entering and
/// `ior` leaving, the direction normalised as glam divides, and the mirror direction under
/// total internal reflection). Each ray leaves from the origin on its side (`Origins::ray`).
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn bounce_lanes<L: Floats>(
    tr: &mut Tracer,
    s: &mut Scratch,
    nodes: &[u32; MAX_LANES],
    (mirror, glass, ior): (u32, u32, [f32; MAX_LANES]),
    (wo, ns, nh): ([L; 3], [L; 3], [L; 3]),
    (front, back, o_err): ([L; 3], [L; 3], L),
) {
    // SAFETY: the caller vouches for the instruction set; so for every `unsafe` block below.
    let (zero, one, two, inf) = unsafe {
        (
            L::splat(0.0),
            L::splat(1.0),
            L::splat(2.0),
            L::splat(f32::INFINITY),
        )
    };
    // `Transmissive::refract(wo, nh)`: the normal on `wo`'s side and the ratio of indices.
    let ior = unsafe { L::from_array(ior) };
    let entering = dot(wo, nh).cmpgt(zero);
    let eta = L::select(entering, one / ior, ior);
    let n = [
        L::select(entering, nh[0], -nh[0]),
        L::select(entering, nh[1], -nh[1]),
        L::select(entering, nh[2], -nh[2]),
    ];
    // Snell: sin^2(theta_t) = eta^2 sin^2(theta_i) (`max` gives 0 for NaN, as `f32::max`).
    let cos_i = dot(wo, n);
    let sin2_t = eta * eta * (one - cos_i * cos_i).max(zero);
    let tir = sin2_t.cmpgt(one);
    // `(-wo eta + (eta cos_i - cos_t) n).normalize()`, each coordinate divided by the length.
    let cos_t = (one - sin2_t).sqrt();
    let k = eta * cos_i - cos_t;
    let v = [
        -wo[0] * eta + k * n[0],
        -wo[1] * eta + k * n[1],
        -wo[2] * eta + k * n[2],
    ];
    let len = dot(v, v).sqrt();
    // Under total internal reflection, `reflect(wo, n)`: `2 (n.wo) n - wo`.
    let two_cos = two * dot(n, wo);
    let wt = [
        L::select(tir, two_cos * n[0] - wo[0], v[0] / len),
        L::select(tir, two_cos * n[1] - wo[1], v[1] / len),
        L::select(tir, two_cos * n[2] - wo[2], v[2] / len),
    ];
    // A mirror's `reflect(wo, ns)`.
    let is_mirror = unsafe { lane_mask::<L>(mirror) };
    let two_cos = two * dot(ns, wo);
    let w = [
        L::select(is_mirror, two_cos * ns[0] - wo[0], wt[0]),
        L::select(is_mirror, two_cos * ns[1] - wo[1], wt[1]),
        L::select(is_mirror, two_cos * ns[2] - wo[2], wt[2]),
    ];
    // `Origins::ray(w, inf)`: the origin on the side `w` leaves by.
    let side = dot(nh, w).cmpge(zero);
    let bounced = mirror | glass;
    let n_rays = bounced.count_ones() as usize;
    let queue = &mut s.queue;
    queue.reserve(n_rays);
    let at = queue.len;
    for x in 0..3 {
        L::select(side, front[x], back[x]).compress(bounced, &mut queue.rows[OX + x][at..]);
        w[x].compress(bounced, &mut queue.rows[DX + x][at..]);
    }
    o_err.compress(bounced, &mut queue.rows[OE][at..]);
    inf.compress(bounced, &mut queue.rows[TM][at..]);
    let mut bits = bounced;
    let mut k = at;
    while bits != 0 {
        let i = bits.trailing_zeros() as usize;
        bits &= bits - 1;
        queue.nodes[k] = nodes[i];
        k += 1;
    }
    queue.len += n_rays;
    // The rays counted by kind: a mirror's and a totally reflected one are reflections.
    let reflected = mirror | (glass & L::bitmask(tir));
    tr.stats.reflection += u64::from(reflected.count_ones());
    tr.stats.refraction += u64::from((glass & !reflected).count_ones());
    if let Some(audit) = tr.audit {
        let mut bits = bounced;
        let mut k = at;
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let kind = match reflected & (1 << i) != 0 {
                true => RayKind::Reflection,
                false => RayKind::Refraction,
            };
            audit(&queue.ray(k), kind);
            k += 1;
        }
    }
}

/// Rows of a chunk's lane arrays, for the lanes whose whole interaction is built (a metal's
/// bounce, a bounce with an effect off, an emitter a chain meets): hit point, geometric
/// normal, shading normal (the geometric one on the viewer's side), front and back origins
/// (three each), then the origins' error, the distance and the hit's two error bounds.
const P: usize = 0;
const NH: usize = 3;
const NS: usize = 6;
const FRONT: usize = 9;
const BACK: usize = 12;
const O_ERR: usize = 15;
const T: usize = 16;
const ERR: usize = 17;
const ERR_ALONG: usize = 18;
const ROWS: usize = 19;

/// Trace and shade the queue's rays from `k` on, `L::LANES` of them at most, at depth `depth`:
/// their nodes' sums into `s.nodes`, bounces into `s.queue`, children into `s.next`. Returns
/// how many rays it took. No closures that compute in lanes, so that this inlines whole into
/// the AVX2 and AVX-512 copies.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn chunk<L: Floats>(
    tr: &mut Tracer,
    g: &Global,
    s: &mut Scratch,
    depth: u32,
    k: usize,
) -> usize {
    let geometry = tr.geometry;
    // SAFETY: the caller vouches for the instruction set; so for every `unsafe` block below,
    // each makes values of `L`.
    let (zero, two) = unsafe { (L::splat(0.0), L::splat(2.0)) };
    let end = depth >= g.max_depth || !tr.effects.indirect;
    let q = &s.queue;
    let count = (q.len - k).min(L::LANES);
    let (o, d, o_err, t_max) = unsafe {
        (
            [q.load(OX, k), q.load(OX + 1, k), q.load(OX + 2, k)],
            [q.load(DX, k), q.load(DX + 1, k), q.load(DX + 2, k)],
            q.load::<L>(OE, k),
            q.load::<L>(TM, k),
        )
    };
    let nodes: [u32; MAX_LANES] = q.nodes[k..k + MAX_LANES]
        .try_into()
        .expect("a chunk of nodes");
    let lanes = RayLanes::from_parts(o, d, o_err);
    // The nearest hits and their records, in the lanes.
    let near = unsafe { geometry.nearest_lanes(&lanes, t_max) };
    tr.traversal.prims(count as u64 * geometry.lane_prims());
    let (hit, t_max, slot) = (near.hit, near.t, array(near.slot));
    // `Interaction::new`: the normal on the viewer's side (a flat shape's shading normal),
    // and `Origins::new`: the point moved off the surface by its error's projection on the
    // normal, to either side, with the origins' error bound.
    let wo = [-d[0], -d[1], -d[2]];
    let (p, nh) = (hit.p, hit.n);
    let flip = dot(nh, wo).cmplt(zero);
    let ns = [
        L::select(flip, -nh[0], nh[0]),
        L::select(flip, -nh[1], nh[1]),
        L::select(flip, -nh[2], nh[2]),
    ];
    let (front, back, o_err) = origins(p, nh, hit.err, hit.err_along);
    // The tree's bookkeeping, lane by lane (`shade`): misses end at the background; a chain's
    // ray adds what its surface emits; Phong hits gather their weights and `kd`; mirror and
    // glass bounces take their tint (`Node::bounce`), their rays made in lanes below; the rest
    // (metals, emitters a chain meets, effects off) wait for their whole interaction below.
    let (mut phong_lanes, mut lit_lanes, mut lambert, mut whole) = (0u32, 0u32, 0u32, 0u32);
    // The chains' rays that meet an emitter (a subset of `whole`).
    let mut emitting = 0u32;
    // The mirror and glass bounces made in lanes, and each glass lane's index of refraction.
    let (mut mirror, mut glass, mut ior) = (0u32, 0u32, [1.0f32; MAX_LANES]);
    // A mirror bounces with reflection on; glass refracts or reflects, so it needs both.
    let (lane_mirror, lane_glass) = (
        tr.effects.reflection,
        tr.effects.reflection && tr.effects.refraction,
    );
    let mut beta = [Vec3A::ZERO; MAX_LANES];
    let mut kd = [Vec3A::ZERO; MAX_LANES];
    for i in 0..count {
        let node = &mut s.nodes[nodes[i] as usize];
        let Some(e) = s.slots.get(slot[i].to_bits() as usize) else {
            node.rest = Some(node.beta * node.tint * tr.background);
            continue;
        };
        // The emitter a node's own ray hits is the direct light of the hit it left.
        let emits = e.light != NO_LIGHT && tr.effects.emission;
        if node.bounces > 0 {
            if emits {
                emitting |= 1 << i;
                whole |= 1 << i;
            } else {
                node.le += node.tint * Vec3A::ZERO;
            }
        }
        if !e.is_phong {
            match e.bounce {
                // With its effects on, `specular_bounce` always bounces a mirror or glass.
                Some(b)
                    if match b {
                        Bounce::Mirror(_) => lane_mirror,
                        Bounce::Glass(..) => lane_glass,
                    } && emitting & (1 << i) == 0
                        && node.bounces < g.max_specular =>
                {
                    node.tint *= b.tint();
                    node.bounces += 1;
                    match b {
                        Bounce::Mirror(_) => mirror |= 1 << i,
                        Bounce::Glass(x, _) => {
                            glass |= 1 << i;
                            ior[i] = x;
                        }
                    }
                }
                _ => whole |= 1 << i,
            }
            continue;
        }
        beta[i] = node.beta * node.tint;
        kd[i] = e.phong.kd;
        phong_lanes |= 1 << i;
        lit_lanes |= u32::from(e.lit) << i;
        lambert |= u32::from(e.lambert) << i;
    }
    let parents = if end { 0 } else { phong_lanes };
    if mirror | glass != 0 {
        // SAFETY: as above.
        unsafe {
            bounce_lanes::<L>(
                tr,
                s,
                &nodes,
                (mirror, glass, ior),
                (wo, ns, nh),
                (front, back, o_err),
            )
        };
    }
    // The lanes that need their whole interaction: emitters a chain meets, metals' bounces and
    // bounces with an effect off, queued behind this wave's rays.
    if whole != 0 {
        let mut v = [[0.0f32; MAX_LANES]; ROWS];
        for (row, x) in [
            p[0],
            p[1],
            p[2],
            nh[0],
            nh[1],
            nh[2],
            ns[0],
            ns[1],
            ns[2],
            front[0],
            front[1],
            front[2],
            back[0],
            back[1],
            back[2],
            o_err,
            t_max,
            hit.err,
            hit.err_along,
        ]
        .into_iter()
        .enumerate()
        {
            x.write_to(&mut v[row]);
        }
        let (mut dv, vec3) = (
            [[0.0f32; MAX_LANES]; 3],
            |v: &[[f32; MAX_LANES]], row: usize, i: usize| {
                Vec3A::new(v[row][i], v[row + 1][i], v[row + 2][i])
            },
        );
        for (c, x) in d.into_iter().enumerate() {
            x.write_to(&mut dv[c]);
        }
        let materials = tr.materials;
        let mut bits = whole;
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let e = s.slots[slot[i].to_bits() as usize];
            let si = Interaction {
                hit: Hit {
                    t: v[T][i],
                    p: vec3(&v, P, i),
                    n: vec3(&v, NH, i),
                    err: v[ERR][i],
                    err_along: v[ERR_ALONG][i],
                    prim: e.prim,
                },
                wo: -vec3(&dv, 0, i),
                n: vec3(&v, NS, i),
                material: &materials[e.material as usize],
                // The waves do not run where materials have textures.
                textured: None,
                bent: false,
                origins: Origins {
                    front: vec3(&v, FRONT, i),
                    back: vec3(&v, BACK, i),
                    n: vec3(&v, NH, i),
                    o_err: v[O_ERR][i],
                },
                light: e.light,
            };
            let node = &mut s.nodes[nodes[i] as usize];
            if emitting & (1 << i) != 0 {
                node.le += node.tint * emitted(tr, &si);
            }
            if !e.is_phong
                && node.bounces < g.max_specular
                && let Some(next) = node.bounce(&si, tr)
            {
                s.queue.push(nodes[i], &[next]);
            }
        }
    }
    // The rows the scalar reflectance reads (`wo` and the shading normal), where a Phong lane
    // is not the course's diffuse one.
    let scalar = phong_lanes & !lambert;
    let mut sv = [[0.0f32; MAX_LANES]; 6];
    if scalar != 0 {
        for (row, x) in [wo[0], wo[1], wo[2], ns[0], ns[1], ns[2]]
            .into_iter()
            .enumerate()
        {
            x.write_to(&mut sv[row]);
        }
    }
    let wo_n = |i: usize| {
        (
            Vec3A::new(sv[0][i], sv[1][i], sv[2][i]),
            Vec3A::new(sv[3][i], sv[4][i], sv[5][i]),
        )
    };
    let (beta_l, kd_l) = unsafe {
        (
            L::transpose3(&beta.each_ref()),
            L::transpose3(&kd.each_ref()),
        )
    };
    // Eq. 3: the point lights' sums of the chunk's Phong hits (zero where a surface reflects
    // nothing).
    let mut point = [[0.0f32; MAX_LANES]; 3];
    if lit_lanes != 0 {
        let h = LightLanes {
            p,
            n: ns,
            ng: nh,
            front,
            back,
            kd: kd_l,
            o_err,
            filled: unsafe { lane_mask::<L>(lit_lanes) },
            scalar: lit_lanes & !lambert,
        };
        let (model, slots) = (tr.model, &s.slots);
        point = unsafe {
            point_sums(tr, &h, |i, w, l| {
                let phong = &slots[slot[i].to_bits() as usize].phong;
                let (wo, n) = wo_n(i);
                l * reflectance(model, phong, w, wo, n)
            })
        };
    }
    // What each Phong node adds after `beta le` (`finish_direct_light`): `beta` times Eq. 3
    // as `direct_light` sums it (the point lights' sum, then the area lights' zero), plus the
    // ambient term at depth D (Eq. 2).
    let mut rest = [[0.0f32; MAX_LANES]; 3];
    for c in 0..3 {
        let l_dir = unsafe { L::from_array(point[c]) } + zero;
        rest[c] = array(match end {
            true => beta_l[c] * (l_dir + unsafe { L::splat(g.ambient[c]) } * kd_l[c]),
            false => beta_l[c] * l_dir,
        });
    }
    let mut bits = phong_lanes;
    while bits != 0 {
        let i = bits.trailing_zeros() as usize;
        bits &= bits - 1;
        let node = &mut s.nodes[nodes[i] as usize];
        node.rest = Some(Vec3A::new(rest[0][i], rest[1][i], rest[2][i]));
    }
    if parents == 0 {
        return count;
    }
    // Task 2: Eq. 4 with the directions fixed to the normal w_n and the reflection w_r of
    // `wo` (`reflect`: `2 (n.wo) n - wo`), weighted by 1 / (4 pi); each ray leaves from the
    // origin on its side. The parents' rays are packed into the next wave's columns, the
    // normals' first, then the reflections'. (`bounce_lanes` computes `w_r` for its mirrors
    // again: kept live across this function's lane loops, it cost 2.5%.)
    let two_cos = two * dot(ns, wo);
    let wr = [
        two_cos * ns[0] - wo[0],
        two_cos * ns[1] - wo[1],
        two_cos * ns[2] - wo[2],
    ];
    let (four_pi, inf) = unsafe { (L::splat(4.0 * PI), L::splat(f32::INFINITY)) };
    let n_parents = parents.count_ones() as usize;
    let next = &mut s.next;
    next.reserve(2 * n_parents);
    let at = next.len;
    let mut weights = [[[0.0f32; MAX_LANES]; 3]; 2];
    let mut dirs = [[[0.0f32; MAX_LANES]; 3]; 2];
    for (c, w) in [ns, wr].into_iter().enumerate() {
        // `course_reflectance` of a diffuse material: `kd max(w.n, 0)`, `max` as a select.
        let cos = dot(w, ns);
        let cos = L::select(cos.cmpgt(zero), cos, zero);
        let side = dot(nh, w).cmpge(zero);
        let start = at + c * n_parents;
        for x in 0..3 {
            weights[c][x] = array((beta_l[x] * (kd_l[x] * cos)) / four_pi);
            L::select(side, front[x], back[x]).compress(parents, &mut next.rows[OX + x][start..]);
            w[x].compress(parents, &mut next.rows[DX + x][start..]);
            if scalar != 0 {
                w[x].write_to(&mut dirs[c][x]);
            }
        }
        o_err.compress(parents, &mut next.rows[OE][start..]);
        inf.compress(parents, &mut next.rows[TM][start..]);
    }
    // The children's nodes, parent by parent in lane order, each parent's normal first.
    let first = s.nodes.len() as u32;
    let mut bits = parents;
    let mut r = 0;
    while bits != 0 {
        let i = bits.trailing_zeros() as usize;
        bits &= bits - 1;
        let child = first + 2 * r as u32;
        s.kids[nodes[i] as usize] = child;
        for c in 0..2 {
            let b = if lambert & (1 << i) != 0 {
                Vec3A::new(weights[c][0][i], weights[c][1][i], weights[c][2][i])
            } else {
                let phong = &s.slots[slot[i].to_bits() as usize].phong;
                let (wo, n) = wo_n(i);
                let w = Vec3A::new(dirs[c][0][i], dirs[c][1][i], dirs[c][2][i]);
                beta[i] * reflectance(tr.model, phong, w, wo, n) / (4.0 * PI)
            };
            s.add_node(b);
            s.next.nodes[at + c * n_parents + r] = child + c as u32;
        }
        r += 1;
    }
    s.next.len += 2 * n_parents;
    tr.stats.indirect += 2 * n_parents as u64;
    if let Some(audit) = tr.audit {
        for k in at..at + 2 * n_parents {
            audit(&s.next.ray(k), RayKind::Indirect);
        }
    }
    count
}
