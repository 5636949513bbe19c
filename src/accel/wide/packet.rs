//! Coherent rays traced together: a packet of up to eight rays, one per lane, walks the wide
//! BVH once (Wald et al. 2001, "Interactive Rendering with Coherent Ray Tracing"; Embree's
//! packet traversal). An interior node's children are culled for the whole packet at once, in
//! one node test over the interval of the rays' origins and reciprocal directions (bounds on
//! every ray's own distances, so it is conservative); a leaf child's box is tested ray by ray,
//! the box splatted across the lanes; and each leaf is tested with each ray's own reach. For
//! rays that go through the same nodes (a camera's neighbouring pixels) a node is read and
//! tested once per packet instead of once per ray.
//!
//! The answers are the one-ray traversal's ([`WideBvh::closest`]) to the bit. A ray enters every
//! leaf whose box its own test would enter (the interval test keeps a superset of the
//! interior nodes; a leaf's rays are chosen by the one-ray arithmetic), and each leaf is tested
//! with the caller's one-ray test, so the nearest distance found is the same; which primitive
//! holds it is too, except where two leaves hold primitives at exactly that distance (a ray
//! through two coincident surfaces): the one-ray rule keeps the one visited last, so the answer
//! depends on the order of visits, which a packet changes. Such a tie is seen, as long as a
//! leaf's entry distance is never computed above its hits' distances by more than the
//! traversal's margin (`grown`), which the one-ray traversal assumes as well: then the second
//! leaf is visited and reports a hit at the reach the first set. The packet reports the ray as
//! tied, for its caller to trace it alone.

use super::{ChildRef, EMPTY, LEAF, Planes, STACK, TOP, WideBvh, exit_origin, grown};
use crate::accel::Tally;
use crate::accel::simd::{Isa, Lanes8, baseline::Halves};
use crate::geometry::BvhRay;
use glam::Vec3A;
use std::mem::MaybeUninit;

/// Rays per packet: the lanes of an AVX2 register (two SSE halves elsewhere).
pub const PACKET: usize = 8;

/// What a packet's traversal found: each ray's nearest hit (leaf test's answer and distance)
/// and the rays whose answer depends on the order of visits (see the module's notes).
#[derive(Clone, Copy, Debug, Default)]
pub struct PacketHits {
    /// Lane `i`: ray `i`'s nearest hit, `None` for a miss or a lane not traced.
    pub best: [Option<(u32, f32)>; PACKET],
    /// Bit `i` set: ray `i` met two leaves' primitives at its nearest distance; trace it alone.
    pub tied: u32,
}

/// A packet's rays in lanes: what [`super::RayBox`] splats, one ray per lane, and the bounds
/// of their origins and reciprocal directions, splatted across a node's children.
struct PacketBox<L> {
    o: [L; 3],
    /// As [`super::RayBox::o_exit`], lane by lane.
    o_exit: [L; 3],
    inv_d: [L; 3],
    /// As [`super::RayBox::inv_exit`], lane by lane.
    inv_exit: [L; 3],
    /// The rays' common direction signs (as [`super::RayBox::back`]).
    back: [usize; 3],
    /// Per axis, the live rays' origin coordinate that makes entry distances least (the
    /// largest if the rays run towards larger coordinates, else the smallest), and the one
    /// that makes exit distances greatest (the other, of their `o_exit`).
    o_entry: [L; 3],
    exit_from: [L; 3],
    /// Per axis, the least and the greatest of the live rays' `inv_d` and `inv_exit`.
    inv_d_range: [(L, L); 3],
    inv_exit_range: [(L, L); 3],
}

/// The sign bits of a ray's reciprocal direction (bit `a` set if it runs towards smaller
/// coordinates on axis `a`): rays traced in one packet must share them.
#[inline]
pub fn octant(ray: &BvhRay) -> u32 {
    ray.inv_d.is_negative_bitmask()
}

impl<L: Lanes8> PacketBox<L> {
    /// The lanes of `rays[i]`, and the bounds over those in `live`.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn new(rays: &[&BvhRay; PACKET], live: u32, back: u32) -> Self {
        // As `RayBox::new`, ray by ray: the same two clamps of the same products.
        let finite = |v: Vec3A| v.clamp(Vec3A::splat(-f32::MAX), Vec3A::splat(f32::MAX));
        let mut o = [[0.0; PACKET]; 3];
        let mut o_exit = [[0.0; PACKET]; 3];
        let mut inv_d = [[0.0; PACKET]; 3];
        let mut inv_exit = [[0.0; PACKET]; 3];
        let (mut o_lo, mut o_hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        let (mut e_lo, mut e_hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        let (mut d_lo, mut d_hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        let (mut x_lo, mut x_hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        for (i, r) in rays.iter().enumerate() {
            let exit = finite(r.inv_d * (1.0 + 4.0 * f32::EPSILON));
            let inv = finite(r.inv_d);
            let oe = exit_origin(r.ray.o, r.inv_d);
            for a in 0..3 {
                o[a][i] = r.ray.o[a];
                o_exit[a][i] = oe[a];
                inv_d[a][i] = inv[a];
                inv_exit[a][i] = exit[a];
            }
            if live & (1 << i) != 0 {
                (o_lo, o_hi) = (o_lo.min(r.ray.o), o_hi.max(r.ray.o));
                (e_lo, e_hi) = (e_lo.min(oe), e_hi.max(oe));
                (d_lo, d_hi) = (d_lo.min(inv), d_hi.max(inv));
                (x_lo, x_hi) = (x_lo.min(exit), x_hi.max(exit));
            }
        }
        let back = [
            (back & 1) as usize,
            ((back >> 1) & 1) as usize,
            (back >> 2) as usize,
        ];
        // SAFETY: the caller's.
        unsafe {
            let load = |x: &[[f32; PACKET]; 3]| [L::load(&x[0]), L::load(&x[1]), L::load(&x[2])];
            let per_axis =
                |f: &dyn Fn(usize) -> f32| [L::splat(f(0)), L::splat(f(1)), L::splat(f(2))];
            let pair = |lo: Vec3A, hi: Vec3A| {
                [
                    (L::splat(lo.x), L::splat(hi.x)),
                    (L::splat(lo.y), L::splat(hi.y)),
                    (L::splat(lo.z), L::splat(hi.z)),
                ]
            };
            PacketBox {
                o: load(&o),
                o_exit: load(&o_exit),
                inv_d: load(&inv_d),
                inv_exit: load(&inv_exit),
                back,
                o_entry: per_axis(&|a| if back[a] == 0 { o_hi[a] } else { o_lo[a] }),
                exit_from: per_axis(&|a| if back[a] == 0 { e_lo[a] } else { e_hi[a] }),
                inv_d_range: pair(d_lo, d_hi),
                inv_exit_range: pair(x_lo, x_hi),
            }
        }
    }

    /// The children of `node` that some live ray may enter within the reach `reach` (the
    /// largest of the live rays', [`grown`]), and a bound below every live ray's entry
    /// distance into each: the node test of [`Planes::hit`] over the interval of the rays.
    ///
    /// Bounds, not estimates: each side's distance `fl(fl(p - o) * inv)` that a ray's own
    /// test computes is, rounding being monotonic, monotonic in `o` and, for a fixed
    /// difference, in `inv`, so over the rays' box of origins and reciprocals its least value
    /// is at a corner: at the origin bound that makes the difference least along the ray
    /// (`o_entry`), the lesser of its products with the two reciprocal bounds. The exits'
    /// greatest, likewise. So a ray's entry is never below the bound and its exit never above
    /// the exit bound: a child that some ray's own test enters passes this one.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn node<N: Planes>(&self, node: &N, reach: f32) -> (L, u32, [L; 6]) {
        // SAFETY: the caller's.
        unsafe {
            let entry = |a: usize| node.planes::<L>(a, self.back[a]);
            let exit = |a: usize| node.planes::<L>(a, self.back[a] ^ 1);
            let planes = [entry(0), exit(0), entry(1), exit(1), entry(2), exit(2)];
            let near = |a: usize| {
                let d = planes[2 * a].sub(self.o_entry[a]);
                let (lo, hi) = self.inv_d_range[a];
                d.mul(lo).min(d.mul(hi))
            };
            let far = |a: usize| {
                let e = planes[2 * a + 1].sub(self.exit_from[a]);
                let (lo, hi) = self.inv_exit_range[a];
                e.mul(lo).max(e.mul(hi))
            };
            let n = near(0).max(near(1)).max(near(2).max(L::splat(0.0)));
            let f = far(0).min(far(1)).min(far(2).min(L::splat(reach)));
            (n, n.le(f) & L::ne_u32(node.children(), EMPTY), planes)
        }
    }

    /// Each ray's entry distance into child `c`, whose sides `planes` (as [`PacketBox::node`]
    /// gives them, in lanes over the children) hold in lane `c`, and the rays among `live`
    /// that enter it within their reach `reach` ([`grown`]): [`Planes::hit`]'s arithmetic for
    /// each ray alone, to the bit, with the roles of rays and boxes exchanged.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn child(&self, sides: &[[f32; 8]; 6], c: usize, reach: L, live: u32) -> (L, u32) {
        // SAFETY: the caller's.
        unsafe {
            let near = |a: usize| L::splat(sides[2 * a][c]).sub(self.o[a]).mul(self.inv_d[a]);
            let far = |a: usize| {
                L::splat(sides[2 * a + 1][c])
                    .sub(self.o_exit[a])
                    .mul(self.inv_exit[a])
            };
            let n = near(0).max(near(1)).max(near(2).max(L::splat(0.0)));
            let f = far(0).min(far(1)).min(far(2).min(reach));
            (n, n.le(f) & live)
        }
    }
}

/// The leaf test of a packet's walk ([`WideBvh::closest_packet`]): ray `i`'s nearest hit
/// among leaf `leaf`'s primitives within `(0, t_max]`. A closure is one; a type of its own
/// can have its test inlined into the walk, as [`super::NearestLeaf`].
pub trait PacketLeaf {
    /// Ray `i`'s nearest hit in leaf `leaf` within `(0, t_max]`.
    fn nearest(&mut self, i: usize, leaf: u32, t_max: f32) -> Option<(u32, f32)>;
}

impl<F: FnMut(usize, u32, f32) -> Option<(u32, f32)>> PacketLeaf for F {
    #[inline(always)]
    fn nearest(&mut self, i: usize, leaf: u32, t_max: f32) -> Option<(u32, f32)> {
        self(i, leaf, t_max)
    }
}

impl WideBvh {
    /// Nearest hits of the rays `rays[i]` for `i` in `live` (a bit mask; `rays` holds a ray
    /// in every lane, those outside `live` repeating a live one), which must all have the
    /// same [`octant`] `back`. `test(i, leaf, t_max)` is ray `i`'s nearest hit among the
    /// primitives of the leaf with payload `leaf` within `(0, t_max]`, as for
    /// [`WideBvh::closest`] (and the last hit it returns for a ray is that ray's answer).
    /// `tally` is told each ray's node tests.
    pub fn closest_packet(
        &self,
        rays: &[&BvhRay; PACKET],
        live: u32,
        back: u32,
        test: impl PacketLeaf,
        tally: &impl Tally,
    ) -> PacketHits {
        debug_assert!(self.isa.available());
        debug_assert!(
            (0..PACKET).all(|i| live & (1 << i) == 0 || octant(rays[i]) == back),
            "the live rays share the octant `back`"
        );
        match self.isa {
            // SAFETY: as in `closest_tallied`.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 | Isa::Avx512 => unsafe { self.packet_avx2(rays, live, back, test, tally) },
            _ => self.packet_baseline(rays, live, back, test, tally),
        }
    }

    /// [`WideBvh::closest_packet`] in SSE halves.
    #[inline(never)]
    fn packet_baseline(
        &self,
        rays: &[&BvhRay; PACKET],
        live: u32,
        back: u32,
        test: impl PacketLeaf,
        tally: &impl Tally,
    ) -> PacketHits {
        // SAFETY: the baseline runs on every CPU.
        unsafe { self.packet_in::<Halves>(rays, live, back, test, tally) }
    }

    /// [`WideBvh::closest_packet`] compiled for AVX2.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline(never)]
    unsafe fn packet_avx2(
        &self,
        rays: &[&BvhRay; PACKET],
        live: u32,
        back: u32,
        test: impl PacketLeaf,
        tally: &impl Tally,
    ) -> PacketHits {
        // SAFETY: the caller's.
        unsafe { self.packet_in::<crate::accel::simd::avx2::Avx2>(rays, live, back, test, tally) }
    }

    /// [`WideBvh::closest_packet`] with the lanes `L`.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn packet_in<L: Lanes8>(
        &self,
        rays: &[&BvhRay; PACKET],
        live: u32,
        back: u32,
        mut test: impl PacketLeaf,
        tally: &impl Tally,
    ) -> PacketHits {
        let mut out = PacketHits::default();
        if self.is_empty() || live == 0 {
            return out;
        }
        // SAFETY: the caller's.
        let pb = unsafe { PacketBox::<L>::new(rays, live, back) };
        // Each ray's reach, shortened by its hits, as numbers and (grown) in lanes, and the
        // greatest of the live rays'.
        let mut t_max = [0.0f32; PACKET];
        for (t, r) in t_max.iter_mut().zip(rays) {
            *t = r.ray.t_max;
        }
        // SAFETY: the caller's.
        let grow = |t: &[f32; PACKET]| unsafe { L::load(&t.map(grown)) };
        let widest = |t: &[f32; PACKET], live: u32| {
            let mut m = f32::NEG_INFINITY;
            for (i, &t) in t.iter().enumerate() {
                if live & (1 << i) != 0 {
                    m = m.max(grown(t));
                }
            }
            m
        };
        let (mut reach, mut reach_max) = (grow(&t_max), widest(&t_max, live));
        // The stack: a node or leaf, the rays that may need it, and bounds below their entry
        // distances (each ray's own for a leaf, one for all for an interior node).
        let mut stack = [MaybeUninit::<(ChildRef, u32, L)>::uninit(); STACK + 1];
        let mut sp = 0usize;
        let mut cur = (self.root(), live);
        loop {
            let (node, mask) = cur;
            if node & LEAF != 0 {
                // Each ray that entered the leaf tests it with its own reach.
                let mut m = mask;
                while m != 0 {
                    let i = m.trailing_zeros() as usize;
                    m &= m - 1;
                    if let Some((p, t)) = test.nearest(i, node & !LEAF, t_max[i]) {
                        // A hit at the reach a hit of another leaf set: a tie.
                        if out.best[i].is_some() && t == t_max[i] {
                            out.tied |= 1 << i;
                        }
                        t_max[i] = t;
                        out.best[i] = Some((p, t));
                    }
                }
                (reach, reach_max) = (grow(&t_max), widest(&t_max, live));
            } else {
                tally.nodes(mask.count_ones() as u64);
                // SAFETY: the caller's.
                let ((near, enter, planes), child) = unsafe {
                    if node & TOP != 0 {
                        let n = &self.top[(node & !TOP) as usize];
                        (pb.node(n, reach_max), &n.child)
                    } else {
                        let n = &self.nodes[node as usize];
                        (pb.node(n, reach_max), &n.child)
                    }
                };
                // SAFETY: the caller's.
                let near = unsafe { near.to_array() };
                // The children entered, each with the rays that may need it and the key of
                // their order: an interior child with every ray of the node and the bound
                // below their entries; a leaf with the rays its own test lets in (the leaf
                // tests cost more than a box) and the first one's entry.
                let mut sides: Option<[[f32; 8]; 6]> = None;
                let mut found: [(f32, ChildRef, u32, MaybeUninit<L>); 8] =
                    [(0.0, EMPTY, 0, MaybeUninit::uninit()); 8];
                let mut k = 0;
                let mut e = enter;
                while e != 0 {
                    let c = e.trailing_zeros() as usize;
                    e &= e - 1;
                    let r = child[c];
                    // SAFETY: the caller's.
                    let (key, rays_in, bound) = unsafe {
                        if r & LEAF != 0 {
                            let sides = sides.get_or_insert_with(|| planes.map(|p| p.to_array()));
                            let (n, m) = pb.child(sides, c, reach, mask);
                            if m == 0 {
                                continue;
                            }
                            (n.to_array()[m.trailing_zeros() as usize], m, n)
                        } else {
                            (near[c], mask, L::splat(near[c]))
                        }
                    };
                    found[k] = (key, r, rays_in, MaybeUninit::new(bound));
                    k += 1;
                }
                // Farthest first onto the stack, so that the nearest is visited next.
                let found = &mut found[..k];
                found.sort_unstable_by(|a, b| b.0.total_cmp(&a.0));
                for &(_, r, rays_in, bound) in found.iter() {
                    // SAFETY: `bound` was written with the entry; at most seven more entries
                    // than the stack held before a level (see `STACK`).
                    stack[sp].write((r, rays_in, unsafe { bound.assume_init() }));
                    sp += 1;
                }
            }
            // The next entry some of whose rays can still need it.
            loop {
                if sp == 0 {
                    return out;
                }
                sp -= 1;
                // SAFETY: entries below `sp` were written before `sp` was raised past them.
                let (r, m, near) = unsafe { stack[sp].assume_init() };
                // SAFETY: the caller's.
                let m = m & unsafe { near.le(reach) };
                if m != 0 {
                    cur = (r, m);
                    break;
                }
            }
        }
    }
}
